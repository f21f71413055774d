//! Watertightness (after pbrt-v4's test): rays from inside a closed, jittered mesh must hit
//! it, including rays aimed exactly at its vertices and along its edges.

use raylab_accel::{AccelKind, BuildOptions, Counters};
use raylab_core::{sampling, Pcg32, Ray, Vec3};
use raylab_render::{Camera, RenderSettings, Scene, TriangleMesh};

/// A subdivided icosahedron projected on the unit sphere, each vertex pushed in or out by
/// up to `jitter`, so that triangles meet at arbitrary angles and positions.
fn jittered_icosphere(levels: u32, jitter: f32, rng: &mut Pcg32) -> TriangleMesh {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut pos: Vec<Vec3> = [
        [-1., t, 0.], [1., t, 0.], [-1., -t, 0.], [1., -t, 0.], [0., -1., t], [0., 1., t],
        [0., -1., -t], [0., 1., -t], [t, 0., -1.], [t, 0., 1.], [-t, 0., -1.], [-t, 0., 1.],
    ]
    .iter()
    .map(|p| Vec3::from_array(*p).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<Vec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push((pos[a as usize] + pos[b as usize]).normalize());
                pos.len() as u32 - 1
            })
        };
        for [a, b, c] in tris {
            let (ab, bc, ca) = (midpoint(a, b, &mut pos), midpoint(b, c, &mut pos), midpoint(c, a, &mut pos));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    for p in &mut pos {
        *p *= 1.0 + jitter * (2.0 * rng.next_f32() - 1.0);
    }
    TriangleMesh { name: "icosphere".into(), positions: pos, indices: tris, ..Default::default() }
}

fn scene_with(mesh: TriangleMesh, accel: AccelKind) -> Scene {
    let camera = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings { accel, ..Default::default() });
    scene.geometry.add_mesh(mesh);
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn no_ray_escapes_a_closed_mesh() {
    let mut rng = Pcg32::new(2024, 7);
    for accel in [AccelKind::Bvh, AccelKind::None] {
        let mesh = jittered_icosphere(if accel == AccelKind::None { 2 } else { 4 }, 0.1, &mut rng);
        let targets: Vec<Vec3> = mesh.positions.clone();
        let edges: Vec<(Vec3, Vec3)> = mesh.indices.iter().map(|t| (mesh.positions[t[0] as usize], mesh.positions[t[1] as usize])).collect();
        let scene = scene_with(mesh, accel);
        let mut c = Counters::default();
        let rays = if accel == AccelKind::None { 10_000 } else { 100_000 };
        let mut misses = 0;
        for k in 0..rays {
            // Origins inside the inner radius (0.9) of the jittered sphere.
            let o = 0.5 * sampling::uniform_sphere(rng.next_vec2()) * rng.next_f32();
            let d = match k % 3 {
                0 => sampling::uniform_sphere(rng.next_vec2()),
                1 => targets[rng.below(targets.len() as u32) as usize] - o,
                _ => {
                    let (a, b) = edges[rng.below(edges.len() as u32) as usize];
                    a + (b - a) * rng.next_f32() - o
                }
            };
            if scene.intersect(&Ray::new(o, d), &mut c).is_none() {
                misses += 1;
            }
        }
        assert_eq!(misses, 0, "{accel}: {misses} of {rays} rays escaped");
    }
}
