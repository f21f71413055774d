//! The generators' geometry, not only their counts: positions, sizes and contacts follow
//! from each construction, and the expected values are worked out here.

use raylab_core::{Rgb, Vec2, Vec3};
use raylab_render::Light;
use raylab_procedural::{generate, Size};

fn size(size: u32) -> Size {
    Size { size, strands: 0, segments: 0 }
}

/// The spheres of a generated scene, `(centre, radius)` in order of generation.
fn spheres(name: &str, n: u32) -> Vec<(Vec3, f32)> {
    generate(name, size(n)).unwrap().scene.geometry.spheres.iter().map(|s| (s.center, s.radius)).collect()
}

/// Vertices and 0-based triangles of the generated scene's first mesh (the floor is last).
fn mesh(name: &str, n: u32) -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let g = generate(name, size(n)).unwrap();
    let m = &g.scene.geometry.meshes[0];
    (m.positions.clone(), m.indices.iter().map(|t| t.map(|k| k as usize)).collect())
}

#[test]
fn sphereflake_children_touch_their_parent() {
    let s = spheres("balls", 1);
    assert_eq!(s.len(), 10);
    assert_eq!(s[0], (Vec3::ZERO, 1.0));
    // Nine children of radius 1/3 resting on the unit sphere: centres at 1 + 1/3 from the origin;
    // six on the equator (y = 0, 60° apart), three on the cap at 0.6 rad from +y.
    let children = &s[1..];
    for (c, r) in children {
        assert!((r - 1.0 / 3.0).abs() < 1e-6 && (c.length() - 4.0 / 3.0).abs() < 1e-5, "{c} {r}");
    }
    for k in 0..6 {
        let (a, b) = (children[k].0, children[(k + 1) % 6].0);
        assert!(a.y.abs() < 1e-5, "{a}");
        assert!((a.angle_between(b) - std::f32::consts::FRAC_PI_3).abs() < 1e-5);
    }
    for (c, _) in &children[6..] {
        assert!((c.y - 4.0 / 3.0 * 0.6f32.cos()).abs() < 1e-5, "{c}");
    }
    // No two children overlap.
    for i in 0..9 {
        for j in i + 1..9 {
            assert!(children[i].0.distance(children[j].0) >= 2.0 / 3.0 - 1e-5, "{i} {j}");
        }
    }
    // Depth 2: every grandchild (radius 1/9) touches one child.
    let s = spheres("balls", 2);
    let (kids, grandkids): (Vec<_>, Vec<_>) = s[1..].iter().partition(|(_, r)| (r - 1.0 / 3.0).abs() < 1e-6);
    assert_eq!((kids.len(), grandkids.len()), (9, 81));
    for (g, r) in &grandkids {
        assert!((r - 1.0 / 9.0).abs() < 1e-6);
        assert!(kids.iter().any(|(k, _)| (k.distance(*g) - (1.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-5), "{g} touches no child");
    }
}

#[test]
fn rings_sit_on_their_circles() {
    let s = spheres("rings", 3);
    assert_eq!(s.len(), 12 + 24 + 36);
    // Ring i: 12i spheres of radius π·2i/(12i) = π/6 on the circle of radius 2i, lifted to r + 0.2i.
    let mut start = 0;
    for ring in 1..=3 {
        let count = 12 * ring;
        for (c, r) in &s[start..start + count] {
            let r_expected = std::f32::consts::PI / 6.0;
            assert!((r - r_expected).abs() < 1e-6);
            assert!(((c.x * c.x + c.z * c.z).sqrt() - 2.0 * ring as f32).abs() < 1e-5, "ring {ring}: {c}");
            assert!((c.y - (r_expected + 0.2 * ring as f32)).abs() < 1e-5);
        }
        start += count;
    }
}

#[test]
fn sierpinski_tetrahedron_keeps_its_surface_area_and_bounds() {
    for depth in 1..=3 {
        let (v, f) = mesh("tetra", depth);
        assert_eq!(f.len(), 4usize.pow(depth + 1));
        // Each level halves the edges and quadruples the tetrahedra: the total area stays that
        // of the unit-corner tetrahedron, 4 · (√3/4)(2√2)² = 8√3.
        let area: f32 = f.iter().map(|t| 0.5 * (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).length()).sum();
        assert!((area - 8.0 * 3f32.sqrt()).abs() < 1e-3, "depth {depth}: area {area}");
        // Every edge is 2√2 / 2^depth long and every vertex inside the corners' cube [−1, 1]³.
        let edge = 2.0 * 2f32.sqrt() / (1 << depth) as f32;
        for t in &f {
            for k in 0..3 {
                assert!((v[t[k]].distance(v[t[(k + 1) % 3]]) - edge).abs() < 1e-5);
            }
        }
        assert!(v.iter().all(|p| p.abs().max_element() <= 1.0 + 1e-6));
    }
}

#[test]
fn mountain_is_a_height_field_over_the_square_facing_up() {
    let (v, f) = mesh("mount", 3);
    let n = 8;
    assert_eq!((v.len(), f.len()), ((n + 1) * (n + 1), 2 * n * n));
    // Grid vertices at x, z = −2 + 4i/n; the ground projection of the triangles tiles the 4 × 4 square.
    for (i, p) in v.iter().enumerate() {
        let (x, z) = (i % (n + 1), i / (n + 1));
        assert_eq!((p.x, p.z), (x as f32 / n as f32 * 4.0 - 2.0, z as f32 / n as f32 * 4.0 - 2.0));
        assert!(p.y >= -0.3 && p.y < 2.0, "{p}");
    }
    let mut projected = 0.0;
    for t in &f {
        let normal = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
        assert!(normal.y > 0.0, "face {t:?} faces down");
        projected += 0.5 * normal.y;
    }
    assert!((projected - 16.0f32).abs() < 1e-4, "{projected}");
    // The four spheres (radius 0.25) are in the scene as written.
    assert_eq!(spheres("mount", 3).iter().filter(|(_, r)| *r == 0.25).count(), 4);
}

#[test]
fn hair_strands_start_inside_the_ball_and_advance_in_equal_steps() {
    let (strands, segments) = (40u32, 4u32);
    let g = generate("hair", Size { size: 0, strands, segments }).unwrap();
    let step = 0.6 / segments as f32;
    let curves = &g.scene.geometry.curves;
    assert_eq!(curves.len(), strands as usize);
    for (k, c) in curves.iter().enumerate() {
        assert_eq!(c.segments.len(), segments as usize);
        // The Catmull–Rom points p1..p(segments+1) are the Bézier segments' ends; the phantom
        // p0 comes back from the first segment, whose second control point is p1 + (p2 − p0)/6.
        let cp = c.segments[0].control_points();
        let phantom = cp[3].truncate() - 6.0 * (cp[1].truncate() - cp[0].truncate());
        // It is one step inside the ball, on the Fibonacci lattice's normal: its height is
        // (1 − step)(1 − 2(k + ½)/strands).
        assert!((phantom.length() - (1.0 - step)).abs() < 2e-5, "strand {k}: {phantom}");
        assert!((phantom.y - (1.0 - step) * (1.0 - 2.0 * (k as f32 + 0.5) / strands as f32)).abs() < 2e-5);
        assert!((phantom.distance(cp[0].truncate()) - step).abs() < 2e-5, "strand {k}: uneven first step");
        let ends: Vec<_> = c.segments.iter().map(|s| s.control_points()[0]).chain([c.segments.last().unwrap().control_points()[3]]).collect();
        for w in ends.windows(2) {
            assert!((w[0].truncate().distance(w[1].truncate()) - step).abs() < 1e-5, "strand {k}: uneven step");
        }
        // Radii taper from the root's to a third of it at the tip (1 − 0.67).
        let (root, tip) = (ends[0].w, ends.last().unwrap().w);
        assert!((tip - 0.33 * root).abs() < 1e-6 * root.max(1.0), "strand {k}: {root} → {tip}");
    }
}

#[test]
fn sphereflake_levels_alternate_materials_and_the_cap_is_turned_half_a_radian() {
    let g = generate("balls", size(2)).unwrap();
    let name = |s: &raylab_render::shape::Sphere| g.scene.material_names[s.material.0 as usize].clone();
    let s = &g.scene.geometry.spheres;
    // Depth 2 at the root: mirror, then `a` for the 9 children, mirror for the 81 grandchildren.
    assert_eq!(name(&s[0]), "mirror");
    let by_radius = |r: f32| s.iter().filter(|x| (x.radius - r).abs() < 1e-6).map(name).collect::<Vec<_>>();
    assert!(by_radius(1.0 / 3.0).iter().all(|n| n == "a") && by_radius(1.0 / 3.0).len() == 9);
    assert!(by_radius(1.0 / 9.0).iter().all(|n| n == "mirror") && by_radius(1.0 / 9.0).len() == 81);
    let g1 = generate("balls", size(1)).unwrap();
    assert_eq!(g1.scene.material_names[g1.scene.geometry.spheres[0].material.0 as usize], "a");

    // The root's children (the first of each subtree in generation order): six on the
    // equator at 60° steps, three on the cap at 120° steps starting 0.5 rad past the first
    // equator child, azimuths measured around +y in the equator's own direction of turning.
    let kids: Vec<Vec3> = generate("balls", size(1)).unwrap().scene.geometry.spheres[1..].iter().map(|x| x.center).collect();
    let flat = |p: Vec3| Vec3::new(p.x, 0.0, p.z).normalize();
    let e0 = flat(kids[0]);
    let e90 = (flat(kids[1]) - 0.5 * e0).normalize();
    let azimuth = |p: Vec3| flat(p).dot(e90).atan2(flat(p).dot(e0)).rem_euclid(std::f32::consts::TAU);
    for (j, k) in kids[6..].iter().enumerate() {
        let expected = 0.5 + j as f32 * std::f32::consts::TAU / 3.0;
        assert!((azimuth(*k) - expected).abs() < 1e-4, "cap child {j}: azimuth {} against {expected}", azimuth(*k));
    }
    // The viewpoint is SPD balls' direction (2.1, 1.3, 1.7), 1.6 times as far.
    assert_eq!(g.scene.camera.from, Vec3::new(2.1, 1.3, 1.7) * 1.6);
}

#[test]
fn the_floor_is_a_quad_of_the_second_material_with_its_corners_uvs() {
    let g = generate("balls", size(1)).unwrap();
    let floor = g.scene.geometry.meshes.last().unwrap();
    assert_eq!(floor.positions, [Vec3::new(-20.0, -1.0, -20.0), Vec3::new(20.0, -1.0, -20.0), Vec3::new(20.0, -1.0, 20.0), Vec3::new(-20.0, -1.0, 20.0)]);
    assert_eq!(floor.uvs, [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)]);
    assert_eq!(floor.indices, [[0, 1, 2], [0, 2, 3]]);
    assert_eq!(g.scene.material_names[floor.material.0 as usize], "b");
    // Lit as every SPD scene here: a point light up, left and in front, and an ambient term.
    assert_eq!(g.scene.lights, [Light::Point { position: Vec3::new(-40.0, 60.0, 50.0), intensity: Rgb::splat(6000.0) }, Light::Ambient { intensity: Rgb::ONE }]);
}

#[test]
fn sizes_up_to_each_limit_are_accepted_and_beyond_refused() {
    assert_eq!(generate("rings", size(64)).unwrap().scene.geometry.spheres.len(), 12 * (64 * 65 / 2));
    assert_eq!(generate("rings", size(65)).err().unwrap(), "--size for `rings` must be between 1 and 64, found 65");
    assert_eq!(generate("balls", size(0)).err().unwrap(), "--size for `balls` must be between 1 and 6, found 0");
    assert_eq!(generate("cubes", size(1)).err().unwrap(), "unknown generator `cubes` (valid: balls, rings, tetra, mount, hair)");
}

#[test]
fn rings_turn_in_equal_steps_and_alternate_materials() {
    // Size 3 (extent 6): at size 2, `size·2` and `size + 2` agree.
    let g = generate("rings", size(3)).unwrap();
    let s = &g.scene.geometry.spheres;
    for (ring, range) in [(1usize, 0..12), (2, 12..36)] {
        let count = 12 * ring;
        let step = std::f32::consts::TAU / count as f32;
        for k in range.clone() {
            let c = s[k].center;
            let angle = c.z.atan2(c.x).rem_euclid(std::f32::consts::TAU);
            let expected = (k - range.start) as f32 * step;
            assert!((angle - expected).abs() < 1e-4, "ring {ring}, sphere {k}: angle {angle} against {expected}");
            let material = &g.scene.material_names[s[k].material.0 as usize];
            assert_eq!(material, if ring % 2 == 0 { "a" } else { "mirror" });
        }
    }
    // The camera looks down from above and in front, at 1.2 and 1.8 times the extent (2 per
    // ring); the floor reaches 3 extents out.
    let from = g.scene.camera.from;
    assert!(from.x == 0.0 && (from.y - 7.2).abs() < 1e-5 && (from.z - 10.8).abs() < 1e-5 && g.scene.camera.at == Vec3::ZERO, "{from}");
    let floor = g.scene.geometry.meshes.last().unwrap();
    assert_eq!((floor.positions[0], floor.positions[2]), (Vec3::new(-18.0, 0.0, -18.0), Vec3::new(18.0, 0.0, 18.0)));
}

#[test]
fn sierpinski_children_are_the_corners_and_edge_midpoints() {
    let g = generate("tetra", size(1)).unwrap();
    let m = &g.scene.geometry.meshes[0];
    assert_eq!((m.name.as_str(), g.scene.material_names[m.material.0 as usize].as_str()), ("sierpinski", "a"));
    let corners = [Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, -1.0, 1.0), Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, -1.0, -1.0)];
    let mut expected: Vec<[i32; 3]> = corners.iter().map(|c| c.as_ivec3().to_array()).collect();
    for i in 0..4 {
        for j in i + 1..4 {
            expected.push(((corners[i] + corners[j]) * 0.5).as_ivec3().to_array());
        }
    }
    let mut got: Vec<[i32; 3]> = m.positions.iter().map(|p| p.as_ivec3().to_array()).collect();
    assert!(m.positions.iter().all(|p| *p == p.round()), "vertices off the integer lattice");
    expected.sort();
    got.sort();
    got.dedup();
    assert_eq!(got, expected);
    assert_eq!(g.scene.camera.from, Vec3::new(1.6, 2.2, 3.6));
    let floor = g.scene.geometry.meshes.last().unwrap();
    assert_eq!((floor.positions[0], floor.positions[2]), (Vec3::new(-20.0, -1.0, -20.0), Vec3::new(20.0, -1.0, 20.0)));
}

/// Diamond-square: the grid's corners are never displaced; every height is an average of
/// earlier heights plus at most the level's amplitude (0.5, then ×0.55 per level), so no
/// height exceeds 0.5 / (1 − 0.55); heights below −0.3 are clamped there.
#[test]
fn the_mountain_is_midpoint_displacement_within_its_amplitudes() {
    let g = generate("mount", size(6)).unwrap();
    let m = &g.scene.geometry.meshes[0];
    let n = 64usize;
    let y = |x: usize, z: usize| m.positions[z * (n + 1) + x].y;
    assert_eq!([y(0, 0), y(n, 0), y(0, n), y(n, n)], [0.0; 4]);
    let (lo, hi) = m.positions.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    assert!(hi <= 0.5 / 0.45 + 1e-5 && hi > 0.3, "highest {hi}");
    assert_eq!(lo, -0.3, "lowest {lo}");
    // Level 1 alone (a 2 × 2 grid): the centre is displaced from 0 by at most 0.5; each edge
    // midpoint from the mean of its three neighbours (two corners at 0, the centre) by at most 0.5.
    let g = generate("mount", size(1)).unwrap();
    let p = &g.scene.geometry.meshes[0].positions;
    let centre = p[4].y;
    assert!(centre.abs() <= 0.5);
    for k in [1, 3, 5, 7] {
        if p[k].y > -0.3 && centre > -0.3 {
            assert!((p[k].y - centre / 3.0).abs() <= 0.5 + 1e-6, "edge {k}: {} against centre {centre}", p[k].y);
        }
    }
    // Finer levels are smoother: neighbouring heights differ less than the first level's
    // amplitude almost everywhere.
    let rough = (0..n).flat_map(|z| (0..n).map(move |x| (x, z))).filter(|&(x, z)| (y(x + 1, z) - y(x, z)).abs() > 0.25).count();
    assert!(rough < n * n / 100, "{rough} steep steps");
    assert_eq!(g.scene.camera.from, Vec3::new(0.0, 2.2, 4.0));
}

/// Level 2 of the diamond-square (a 5 × 5 grid), height by height. The draws come from the
/// generator's own stream (`Pcg32::new(1987, size)`), taken here in the order the algorithm
/// visits the points: a level's diamond centres row by row, then its edge midpoints row by
/// row. Each height is the mean of the neighbours listed by hand (diagonal corners for a
/// centre; the in-grid ones of left, right, up, down for an edge midpoint) plus the level's
/// amplitude (0.5, then 0.5·0.55 = 0.275) times a draw mapped to [−1, 1).
#[test]
fn mountain_level_two_heights_are_the_neighbours_means_plus_the_draws() {
    let n = 4usize;
    let mut rng = raylab_core::Pcg32::new(1987, 2);
    let mut h = [[0.0f32; 5]; 5]; // h[y][x]; the four corners stay 0
    // (x, y), its neighbours (x, y) in the order summed, the amplitude.
    type Displaced = ((usize, usize), &'static [(usize, usize)], f32);
    let order: [Displaced; 21] = [
        // Level 1, step 4, half 2: the centre from the four corners...
        ((2, 2), &[(0, 0), (4, 0), (0, 4), (4, 4)], 0.5),
        // ...the edge midpoints from the three neighbours inside the grid (two corners, the centre).
        ((2, 0), &[(0, 0), (4, 0), (2, 2)], 0.5),
        ((0, 2), &[(2, 2), (0, 0), (0, 4)], 0.5),
        ((4, 2), &[(2, 2), (4, 0), (4, 4)], 0.5),
        ((2, 4), &[(0, 4), (4, 4), (2, 2)], 0.5),
        // Level 2, step 2, half 1: four diamond centres from their diagonal neighbours...
        ((1, 1), &[(0, 0), (2, 0), (0, 2), (2, 2)], 0.275),
        ((3, 1), &[(2, 0), (4, 0), (2, 2), (4, 2)], 0.275),
        ((1, 3), &[(0, 2), (2, 2), (0, 4), (2, 4)], 0.275),
        ((3, 3), &[(2, 2), (4, 2), (2, 4), (4, 4)], 0.275),
        // ...then the twelve edge midpoints, rows 0 to 4 (even rows start at x = 1, odd rows at 0).
        ((1, 0), &[(0, 0), (2, 0), (1, 1)], 0.275),
        ((3, 0), &[(2, 0), (4, 0), (3, 1)], 0.275),
        ((0, 1), &[(1, 1), (0, 0), (0, 2)], 0.275),
        ((2, 1), &[(1, 1), (3, 1), (2, 0), (2, 2)], 0.275),
        ((4, 1), &[(3, 1), (4, 0), (4, 2)], 0.275),
        ((1, 2), &[(0, 2), (2, 2), (1, 1), (1, 3)], 0.275),
        ((3, 2), &[(2, 2), (4, 2), (3, 1), (3, 3)], 0.275),
        ((0, 3), &[(1, 3), (0, 2), (0, 4)], 0.275),
        ((2, 3), &[(1, 3), (3, 3), (2, 2), (2, 4)], 0.275),
        ((4, 3), &[(3, 3), (4, 2), (4, 4)], 0.275),
        ((1, 4), &[(0, 4), (2, 4), (1, 3)], 0.275),
        ((3, 4), &[(2, 4), (4, 4), (3, 3)], 0.275),
    ];
    for ((x, y), neighbours, amp) in order {
        let mean = neighbours.iter().map(|&(i, j)| h[j][i]).sum::<f32>() / neighbours.len() as f32;
        h[y][x] = mean + amp * (2.0 * rng.next_f32() - 1.0);
    }
    let (v, _) = mesh("mount", 2);
    for y in 0..=n {
        for x in 0..=n {
            // Heights below −0.3 are clamped there.
            let expected = h[y][x].max(-0.3);
            assert!((v[y * (n + 1) + x].y - expected).abs() < 1e-6, "({x}, {y}): {} against {expected}", v[y * (n + 1) + x].y);
        }
    }
    // The test would be weak where the clamp hides a height: none is clamped here.
    assert!(h.iter().flatten().all(|&y| y > -0.3), "{h:?}");
    // The four spheres resting on it, as written, alternating mirror and `a`.
    let g = generate("mount", size(2)).unwrap();
    let balls: Vec<_> = g.scene.geometry.spheres.iter().map(|s| (s.center, s.radius, g.scene.material_names[s.material.0 as usize].as_str())).collect();
    let centres = [Vec3::new(-0.8, 0.9, 0.3), Vec3::new(0.7, 0.8, -0.4), Vec3::new(0.1, 1.1, -1.0), Vec3::new(-0.2, 0.8, 0.9)];
    assert_eq!(balls, centres.iter().zip(["mirror", "a", "mirror", "a"]).map(|(&c, m)| (c, 0.25, m)).collect::<Vec<_>>());
    let m = &g.scene.geometry.meshes[0];
    assert_eq!((m.name.as_str(), g.scene.material_names[m.material.0 as usize].as_str()), ("mountain", "b"));
}

/// The Catmull–Rom points of a strand, p0 ..= p(segments + 2), recovered from its Bézier
/// segments: segment i is [p(i+1), p(i+1) + (p(i+2) − p(i))/6, p(i+2) − (p(i+3) − p(i+1))/6, p(i+2)].
fn catmull_rom_points(c: &raylab_render::shape::Curve) -> Vec<raylab_core::Vec4> {
    let s = &c.segments;
    let mut p: Vec<_> = s.iter().map(|b| b.control_points()[0]).chain([s.last().unwrap().control_points()[3]]).collect();
    let first = p[1] - 6.0 * (s[0].control_points()[1] - p[0]);
    let m = p.len();
    let last = p[m - 2] + 6.0 * (p[m - 1] - s.last().unwrap().control_points()[2]);
    p.insert(0, first);
    p.push(last);
    p
}

/// The furry ball strand by strand, from its construction written out here: roots on the
/// Fibonacci lattice (height 1 − 2(k + ½)/N, azimuth k times the golden angle
/// π(3 − √5) = 137.5077640500378°), a phantom point one step inside, then steps of 0.6/S along
/// n − 1.2·along·ŷ + w·(sin a·x̂ + cos a·ŷ) normalised, with (x̂, ŷ) the frame around n, a the
/// strand's phase plus 2.5 rad per point, w = 0.3 + 0.4·u and phase 2π·u from the strand's
/// two draws of `Pcg32::new(2018, N)`; radii from 0.25/√N (inside [0.001, 0.02]) tapering by
/// 0.67·along. N = 400 gives a root radius of 0.0125, inside the clamp.
#[test]
fn hair_strands_follow_the_fibonacci_lattice_and_their_waves() {
    let (strands, segments) = (400u32, 3u32);
    let g = generate("hair", Size { size: 0, strands, segments }).unwrap();
    let curves = &g.scene.geometry.curves;
    assert_eq!(curves.len(), strands as usize);
    let golden = 137.507_764_050_037_85f64.to_radians();
    assert!((golden - std::f64::consts::PI * (3.0 - 5f64.sqrt())).abs() < 1e-14);
    let step = 0.6 / segments as f32;
    let root_radius = 0.25 / (strands as f32).sqrt();
    assert_eq!(root_radius, 0.0125);
    // Framed from slightly above, looking a little below the ball's centre, 40° high.
    let camera = &g.scene.camera;
    assert_eq!((camera.from, camera.at, camera.vfov), (Vec3::new(0.0, 0.9, 4.6), Vec3::new(0.0, -0.1, 0.0), 40.0));
    let mut rng = raylab_core::Pcg32::new(2018, strands as u64);
    for (k, c) in curves.iter().enumerate() {
        // The azimuth in f64: the generator's f32 golden angle times k (up to 399) is off by up
        // to ~10⁻⁴ rad, hence the tolerance on positions below (a changed lattice or wave moves
        // points by 10⁻³ or more).
        let y = 1.0 - 2.0 * (k as f64 + 0.5) / strands as f64;
        let theta = golden * k as f64;
        let ring = (1.0 - y * y).sqrt();
        let n = Vec3::new((ring * theta.cos()) as f32, y as f32, (ring * theta.sin()) as f32);
        let frame = raylab_core::Frame::from_z(n);
        let phase = std::f32::consts::TAU * rng.next_f32();
        let wave = 0.3 + 0.4 * rng.next_f32();
        let p = catmull_rom_points(c);
        assert_eq!(p.len(), segments as usize + 3);
        let mut q = (1.0 - step) * n;
        for (j, got) in p.iter().enumerate() {
            // The first two points (the phantom and the root) both have along = 0.
            let along = j.saturating_sub(1) as f32 / segments as f32;
            let radius = root_radius * (1.0 - 0.67 * along.min(1.0));
            assert!(got.truncate().distance(q) < 2e-4, "strand {k}, point {j}: {got} against {q}");
            assert!((got.w - radius).abs() < 1e-7, "strand {k}, point {j}: radius {} against {radius}", got.w);
            let a = phase + 2.5 * j as f32;
            let dir = n - 1.2 * along * Vec3::Y + wave * (a.sin() * frame.x + a.cos() * frame.y);
            q += step * dir.normalize();
        }
    }
}
