//! Perturbed normals against hand-computed ones, through `Scene::intersect` as the
//! integrators see them.

use raylab_accel::{BuildOptions, Counters};
use raylab_core::{Pcg32, Ray, Rgb, Transform, Vec2, Vec3};

use super::*;
use crate::texture::{Checker, CheckerSpace, Filter, ImageTexture, Wrap};
use crate::{Camera, Material, RenderSettings, Scene, Sphere, TriangleMesh};

fn scene() -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0, 0.0, None).unwrap();
    Scene::new(camera, RenderSettings::default())
}

/// The unit square in the xy plane facing +z, with the given corner UVs.
fn square(uvs: [Vec2; 4]) -> TriangleMesh {
    TriangleMesh {
        positions: vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
        uvs: uvs.to_vec(),
        indices: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    }
}

const UP: [Vec2; 4] = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
/// The same square with `v` running down (-y).
const V_FLIPPED: [Vec2; 4] = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];

/// A scene with `mesh` under a material perturbed by `p(texture)` for a texture `tex`.
fn with_map(mut mesh: TriangleMesh, tex: Texture, p: impl Fn(TextureId) -> ShadingPerturbation) -> Scene {
    let mut s = scene();
    let t = s.add_texture("map", tex);
    let m = s.add_material("m", Material::default_diffuse());
    s.material_perturbations[m.0 as usize] = Some(p(t));
    mesh.material = m;
    s.geometry.add_mesh(mesh);
    s.build_accel(&BuildOptions::default());
    s
}

fn tangent_map(t: TextureId) -> ShadingPerturbation {
    ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Tangent }
}

/// Shading normal seen by a ray from `from` towards `at`.
fn ns_at(s: &Scene, from: Vec3, at: Vec3) -> Vec3 {
    s.intersect(&Ray::new(from, at - from), &mut Counters::default()).expect("hit").geom.ns
}

fn assert_close(a: Vec3, b: Vec3, tol: f32) {
    assert!((a - b).length() < tol, "{a} vs {b}");
}

fn constant(n: Vec3) -> Texture {
    Texture::Constant(encode_normal(n))
}

#[test]
fn tangent_space_normal_map_gives_the_hand_computed_normal() {
    let from = Vec3::new(0.3, 0.4, 2.0);
    let at = Vec3::new(0.3, 0.4, 0.0);
    // u along +x, v along +y: t = x, b = +(z × x) = y.
    let s = with_map(square(UP), constant(Vec3::new(0.6, 0.0, 0.8)), tangent_map);
    assert_close(ns_at(&s, from, at), Vec3::new(0.6, 0.0, 0.8), 1e-5);
    let s = with_map(square(UP), constant(Vec3::new(0.0, 0.6, 0.8)), tangent_map);
    assert_close(ns_at(&s, from, at), Vec3::new(0.0, 0.6, 0.8), 1e-5);
    // v running down -y: the bitangent sign flips, so the map's +y is the world's -y.
    let s = with_map(square(V_FLIPPED), constant(Vec3::new(0.0, 0.6, 0.8)), tangent_map);
    assert_eq!(s.geometry.meshes[0].tangents.iter().map(|t| t.w).collect::<Vec<_>>(), vec![-1.0; 4]);
    assert_close(ns_at(&s, from, at), Vec3::new(0.0, -0.6, 0.8), 1e-5);
    let s = with_map(square(V_FLIPPED), constant(Vec3::new(0.6, 0.0, 0.8)), tangent_map);
    assert_close(ns_at(&s, from, at), Vec3::new(0.6, 0.0, 0.8), 1e-5);
}

#[test]
fn tangent_space_normal_map_on_a_sphere_uses_dpdu() {
    let mut s = scene();
    let t = s.add_texture("map", constant(Vec3::new(0.6, 0.0, 0.8)));
    let m = s.add_material("m", Material::default_diffuse());
    s.material_perturbations[m.0 as usize] = Some(tangent_map(t));
    s.geometry.add_sphere(Sphere { center: Vec3::ZERO, radius: 1.0, to_world: Transform::IDENTITY, material: m, emission: Rgb::ZERO });
    s.build_accel(&BuildOptions::default());
    // At +x on the equator ∂p/∂u points along -z and ∂p/∂v along +y = n × t.
    assert_close(ns_at(&s, Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO), Vec3::new(0.8, 0.0, -0.6), 1e-4);
}

#[test]
fn flat_normal_map_leaves_interpolated_normals_unchanged() {
    let mut mesh = square(UP);
    mesh.normals = [Vec3::new(0.3, 0.0, 1.0), Vec3::new(-0.2, 0.1, 1.0), Vec3::new(0.0, -0.4, 1.0), Vec3::new(0.1, 0.2, 1.0)].map(Vec3::normalize).to_vec();
    let plain = {
        let mut s = scene();
        s.geometry.add_mesh(mesh.clone());
        s.build_accel(&BuildOptions::default());
        s
    };
    let mapped = with_map(mesh, Texture::Constant(Rgb::new(0.5, 0.5, 1.0)), tangent_map);
    let mut rng = Pcg32::new(3, 4);
    for _ in 0..100 {
        let at = Vec3::new(rng.next_f32(), rng.next_f32(), 0.0);
        let from = at + Vec3::new(0.1, -0.2, 1.0);
        assert_close(ns_at(&mapped, from, at), ns_at(&plain, from, at), 1e-5);
    }
}

#[test]
fn object_space_normal_map_follows_the_shape_transform() {
    // The square turned by 90° about y faces +x; object +x becomes world -z, +z world +x.
    let to_world = Transform::rotate(Vec3::Y, 90.0).unwrap();
    let mut mesh = square(UP);
    mesh.positions = mesh.positions.iter().map(|&p| to_world.point(p)).collect();
    mesh.object_to_world = to_world;
    let s = with_map(mesh, constant(Vec3::new(0.6, 0.0, 0.8)), |t| ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Object });
    assert_close(ns_at(&s, Vec3::new(2.0, 0.5, -0.5), Vec3::new(0.0, 0.5, -0.5)), Vec3::new(0.8, 0.0, -0.6), 1e-5);
}

#[test]
fn bump_map_of_a_linear_ramp_tilts_the_normal() {
    // Height 0 at u = 0.25 and 1 at u = 0.75 (texel centres), bilinear: slope 2 per unit u.
    let ramp = ImageTexture::new(2, 1, vec![Rgb::ZERO, Rgb::ONE], Wrap::Clamp, Filter::Bilinear).unwrap();
    let mut mesh = square(UP);
    mesh.positions.iter_mut().for_each(|p| *p *= 2.0);
    let s = with_map(mesh, Texture::Image(ramp), |t| ShadingPerturbation::Bump { texture: t, scale: 0.1 });
    // ∂p/∂u = (2, 0, 0) + 0.1·2·z, ∂p/∂v = (0, 2, 0): n ∝ (-0.4, 0, 4).
    let expected = Vec3::new(-0.4, 0.0, 4.0).normalize();
    assert_close(ns_at(&s, Vec3::new(1.0, 1.0, 3.0), Vec3::new(1.0, 1.0, 0.0)), expected, 1e-3);
}

#[test]
fn perturbed_normals_never_leave_the_geometric_hemisphere() {
    let mut rng = Pcg32::new(11, 2);
    let extreme = |rng: &mut Pcg32| {
        let texels = (0..64).map(|_| Rgb::new(rng.next_f32(), rng.next_f32(), rng.next_f32()).map(|c| if c < 0.3 { 0.0 } else if c > 0.7 { 1.0 } else { c })).collect();
        Texture::Image(ImageTexture::new(8, 8, texels, Wrap::Repeat, Filter::Bilinear).unwrap())
    };
    let maps: [fn(TextureId) -> ShadingPerturbation; 3] = [
        tangent_map,
        |t| ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Object },
        |t| ShadingPerturbation::Bump { texture: t, scale: 50.0 },
    ];
    for map in maps {
        for uvs in [UP, V_FLIPPED] {
            let s = with_map(square(uvs), extreme(&mut rng), map);
            for _ in 0..2000 {
                let at = Vec3::new(rng.next_f32(), rng.next_f32(), 0.0);
                let hit = s.intersect(&Ray::new(at + Vec3::new(0.3, 0.2, 1.0), Vec3::new(-0.3, -0.2, -1.0)), &mut Counters::default()).unwrap();
                let (ns, ng) = (hit.geom.ns, hit.geom.ng);
                assert!((ns.length() - 1.0).abs() < 1e-4, "{ns}");
                assert!(ns.dot(ng) >= MIN_COS_TO_NG - 1e-4, "ns {ns} ng {ng}");
            }
        }
    }
    assert_close(keep_above_surface(-Vec3::Z, Vec3::Z), Vec3::Z, 1e-6);
    let clamped = keep_above_surface(Vec3::new(1.0, 0.0, -1.0).normalize(), Vec3::Z);
    assert!((clamped.z - MIN_COS_TO_NG).abs() < 1e-6 && clamped.x > 0.99, "{clamped}");
}

#[test]
fn normal_map_texels_decode_and_encode_by_hand() {
    // n = 2c − 1, renormalised: a texel shortened by filtering, (0.65, 0.5, 0.7) → (0.3, 0, 0.4),
    // decodes to the unit (0.6, 0, 0.8); (1, ½, ½) is +x, (½, ½, 1) the unperturbed +z.
    assert_close(decode_normal(Rgb::new(0.65, 0.5, 0.7)), Vec3::new(0.6, 0.0, 0.8), 1e-6);
    assert_close(decode_normal(Rgb::new(1.0, 0.5, 0.5)), Vec3::X, 1e-6);
    assert_close(decode_normal(Rgb::new(0.5, 0.5, 1.0)), Vec3::Z, 1e-6);
    assert_close(decode_normal(Rgb::new(0.25, 0.5, 0.5)), -Vec3::X, 1e-6);
    // Mid-grey is the zero vector: +z. Black is (−1, −1, −1)/√3, below the surface.
    assert_eq!(decode_normal(Rgb::splat(0.5)), Vec3::Z);
    assert_close(decode_normal(Rgb::ZERO), -Vec3::ONE / 3f32.sqrt(), 1e-6);
    // c = (n + 1) / 2: (0.6, 0, 0.8) → (0.8, 0.5, 0.9), −z → (½, ½, 0).
    assert_close(encode_normal(Vec3::new(0.6, 0.0, 0.8)), Rgb::new(0.8, 0.5, 0.9), 1e-6);
    assert_close(encode_normal(-Vec3::Z), Rgb::new(0.5, 0.5, 0.0), 1e-6);
}

#[test]
fn tangent_frame_by_hand() {
    // n = (0, 0.6, 0.8) and a tangent 3x + n: Gram–Schmidt leaves t = x; with the bitangent
    // sign −1, b = −(n × x) = −(0, 0.8, −0.6).
    let n = Vec3::new(0.0, 0.6, 0.8);
    let f = TangentFrame::new(n, Vec3::new(3.0, 0.6, 0.8), -1.0);
    assert_close(f.t, Vec3::X, 1e-6);
    assert_close(f.b, Vec3::new(0.0, -0.8, 0.6), 1e-6);
    assert_eq!(f.n, n);
    // (0.36, 0.48, 0.8) → 0.36·x + 0.48·b + 0.8·n = (0.36, −0.384 + 0.48, 0.288 + 0.64).
    let v = Vec3::new(0.36, 0.48, 0.8);
    let w = Vec3::new(0.36, 0.096, 0.928);
    assert_close(f.to_world(v), w, 1e-6);
    assert_close(f.to_local(w), v, 1e-6);
    // The sign +1 turns b over: (0.36, 0.384 + 0.48, −0.288 + 0.64).
    let f = TangentFrame::new(n, Vec3::new(3.0, 0.6, 0.8), 1.0);
    assert_close(f.to_world(v), Vec3::new(0.36, 0.864, 0.352), 1e-6);
    assert_close(f.to_local(Vec3::new(0.36, 0.864, 0.352)), v, 1e-6);
    // A tangent along n: any unit vector across n.
    let f = TangentFrame::new(Vec3::Z, Vec3::Z * 2.0, 1.0);
    assert!(f.t.dot(Vec3::Z).abs() < 1e-6 && (f.t.length() - 1.0).abs() < 1e-6, "{}", f.t);
}

/// The 2 × 2 square (u along +x, ∂p/∂u = (2, 0, 0); the geometric normal +z), every vertex
/// normal `n`, bump-mapped by `scale` 0.1 with `height`.
fn tilted_bump_square(uvs: [Vec2; 4], n: Vec3, height: Texture) -> Scene {
    let mut mesh = square(uvs);
    mesh.positions.iter_mut().for_each(|p| *p *= 2.0);
    mesh.normals = vec![n; 4];
    with_map(mesh, height, |t| ShadingPerturbation::Bump { texture: t, scale: 0.1 })
}

#[test]
fn bump_map_slopes_in_u_and_v_on_a_tilted_shading_normal() {
    // A 2 × 2 bilinear map whose heights (the mean of the channels, which here differ:
    // (m/2, m, 3m/2)) are 0.8·2(u − ¼) + 0.4·2(v − ¼) at the texel centres u, v ∈ {¼, ¾}:
    // bottom row (v = ¼) 0 and 0.8, top row (v = ¾) 0.4 and 1.2; linear between the centres,
    // so the heights h_u = 1.6 and h_v = 0.8 per unit of u and v, d = 0.1·h: 0.16 and 0.08.
    let texel = |m: f32| Rgb::new(0.5 * m, m, 1.5 * m);
    let map = || Texture::Image(ImageTexture::new(2, 2, vec![texel(0.4), texel(1.2), texel(0.0), texel(0.8)], Wrap::Clamp, Filter::Bilinear).unwrap());
    // The shading normal n leans off +z across v (first) or across u (second). ∂p/∂u and
    // ∂p/∂v = (0, ±2, 0) (v up or down) are projected onto n's plane (minus n(n·∂p)) and kept
    // 2 long: 2t and ±2b, with t the unit projection of x and b = n × t:
    // for n = (0, 0.6, 0.8), t = x and ∂p/∂v loses ±1.2n: ±2·(0, 0.8, −0.6) = ±2b;
    // for n = (0.6, 0, 0.8), ∂p/∂u loses 1.2n: (1.28, 0, −0.96), 2t with t = (0.8, 0, −0.6),
    // and b = y. Then ∂p'/∂u = 2t + 0.16n, ∂p'/∂v = ±2b + 0.08n, and their cross product,
    // turned to n's side (t × b = n, t × n = −b, n × b = −t): ±(4n − 0.32t ∓ 0.16b).
    let at = Vec3::new(1.1, 0.9, 0.0);
    for (n, t, b) in [(Vec3::new(0.0, 0.6, 0.8), Vec3::X, Vec3::new(0.0, 0.8, -0.6)), (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.8, 0.0, -0.6), Vec3::Y)] {
        // v up (u = 0.55, v = 0.45).
        let s = tilted_bump_square(UP, n, map());
        assert_close(ns_at(&s, at + Vec3::new(0.0, 0.0, 3.0), at), (4.0 * n - 0.32 * t - 0.16 * b).normalize(), 1e-4);
        // v running down (u = 0.55, v = 0.55): ∂p'/∂u × ∂p'/∂v points against n, turned over.
        let s = tilted_bump_square(V_FLIPPED, n, map());
        assert_close(ns_at(&s, at + Vec3::new(0.0, 0.0, 3.0), at), (4.0 * n - 0.32 * t + 0.16 * b).normalize(), 1e-4);
        // A constant height: the shading normal stays n on either winding of the uvs.
        for uvs in [UP, V_FLIPPED] {
            let s = tilted_bump_square(uvs, n, Texture::Constant(Rgb::new(0.1, 0.7, 0.3)));
            assert_close(ns_at(&s, at + Vec3::new(0.0, 0.0, 3.0), at), n, 1e-5);
        }
    }
}

#[test]
fn bump_map_of_a_solid_texture_steps_the_point_along_the_surface() {
    // A solid checker of unit cells, 0 on the cell at the origin and 0.0008 on its neighbours
    // across x = 1 and y = 1, on the 2 × 2 square (∂p/∂u = (2, 0, 0), ∂p/∂v = (0, 2, 0), so
    // the finite differences look 0.001 further along x and along y). Hit at
    // (0.9993, 0.9991, 0): each step crosses into a neighbour (1.0003, 1.0001), a step of a
    // quarter of that would not. d slopes 0.1·0.0008/0.0005 = 0.16 in u and in v: the normal
    // 4z − 0.32x − 0.32y.
    let checker = Checker { even: Rgb::ZERO, odd: Rgb::splat(0.0008), scale: 1.0, space: CheckerSpace::Solid };
    let mut mesh = square(UP);
    mesh.positions.iter_mut().for_each(|p| *p *= 2.0);
    let s = with_map(mesh, Texture::Checker(checker), |t| ShadingPerturbation::Bump { texture: t, scale: 0.1 });
    let at = Vec3::new(0.9993, 0.9991, 0.0);
    assert_close(ns_at(&s, at + Vec3::new(0.0, 0.0, 3.0), at), Vec3::new(-0.32, -0.32, 4.0).normalize(), 1e-3);
}

#[test]
fn only_tangent_space_maps_need_tangents() {
    let t = TextureId(0);
    assert!(tangent_map(t).needs_tangents());
    assert!(!ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Object }.needs_tangents());
    assert!(!ShadingPerturbation::Bump { texture: t, scale: 0.1 }.needs_tangents());
    // So `build_accel` computes per-vertex tangents (one per position) for the first only.
    let tangents = |p: fn(TextureId) -> ShadingPerturbation| with_map(square(UP), Texture::Constant(Rgb::new(0.5, 0.5, 1.0)), p).geometry.meshes[0].tangents.len();
    assert_eq!(tangents(tangent_map), 4);
    assert_eq!(tangents(|t| ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Object }), 0);
    assert_eq!(tangents(|t| ShadingPerturbation::Bump { texture: t, scale: 0.1 }), 0);
}

#[test]
fn a_normal_below_the_surface_is_clamped_to_a_unit_vector_at_the_minimum_cosine() {
    // ns = (1, 0, −1)/√2 under ng = z: its tangential direction x, lifted to the cosine 0.01:
    // (√(1 − 0.01²), 0, 0.01) = (0.99994999..., 0, 0.01), of unit length.
    let clamped = keep_above_surface(Vec3::new(1.0, 0.0, -1.0).normalize(), Vec3::Z);
    assert_close(clamped, Vec3::new((1.0f64 - 1e-4).sqrt() as f32, 0.0, 0.01), 1e-6);
    assert!((clamped.length() - 1.0).abs() < 1e-6, "{clamped}");
    // Tilted off every axis: ng = (0, 0.6, 0.8), ns = −ng + 0.5·(1, 0, 0) normalised; its
    // component across ng is along x, so the result is √(1 − 10⁻⁴)·x + 0.01·ng.
    let ng = Vec3::new(0.0, 0.6, 0.8);
    let clamped = keep_above_surface((Vec3::X * 0.5 - ng).normalize(), ng);
    assert_close(clamped, (1.0f64 - 1e-4).sqrt() as f32 * Vec3::X + 0.01 * ng, 1e-6);
    // Above the cosine, unchanged; exactly below the surface, ng itself.
    let above = Vec3::new(0.6, 0.0, 0.8);
    assert_eq!(keep_above_surface(above, Vec3::Z), above);
    assert_eq!(keep_above_surface(-Vec3::Z, Vec3::Z), Vec3::Z);
}
