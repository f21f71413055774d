//! Tessellation of a strand into a closed triangle tube: rings of `sides` vertices at
//! `segments` steps along each Bézier segment, oriented by rotation-minimising frames so
//! the tube neither twists nor flips (a Frenet frame flips at every inflection point),
//! closed by hemispheres like the round ends of direct intersection.

use raylab_core::{Frame, Vec3};

use super::Bezier;
use crate::material::MaterialId;
use crate::shape::TriangleMesh;

/// Unit normals `r_i ⊥ t_i` transported along the polyline `points` with unit tangents
/// `tangents` by the double-reflection method (Wang, Jüttler, Zheng & Liu 2008,
/// "Computation of rotation minimizing frames"): reflect the frame in the bisector plane
/// of the chord, then in the plane that maps the reflected tangent onto the next one.
pub fn rotation_minimising_normals(points: &[Vec3], tangents: &[Vec3]) -> Vec<Vec3> {
    let Some(&t0) = tangents.first() else { return Vec::new() };
    let mut normals = vec![Frame::from_z(t0).x];
    for i in 0..points.len() - 1 {
        let (r, t) = (normals[i], tangents[i]);
        let v1 = points[i + 1] - points[i];
        let c1 = v1.length_squared();
        // Without a chord (a repeated sample) reflect in the plane normal to t, the limit of a
        // vanishing chord: leaving the frame as it is would make the whole step one reflection,
        // turning r half a turn about the next tangent more than the rotation does.
        let (r_l, t_l) = if c1 > 0.0 { (r - (2.0 / c1) * v1.dot(r) * v1, t - (2.0 / c1) * v1.dot(t) * v1) } else { (r, -t) };
        let v2 = tangents[i + 1] - t_l;
        let c2 = v2.length_squared();
        let next = if c2 > 0.0 { r_l - (2.0 / c2) * v2.dot(r_l) * v2 } else { r_l };
        // Renormalise against drift over thousands of rings.
        let next = (next - tangents[i + 1] * tangents[i + 1].dot(next)).try_normalize().unwrap_or(next);
        normals.push(next);
    }
    normals
}

/// A closed tube around the strand `segments` (Bézier segments joined end to end):
/// `steps` rings per segment, `sides` vertices per ring, and a hemisphere at each end
/// (rings at `sides / 4` latitudes and a pole), the round ends of direct intersection.
/// Every vertex is shared, so every edge belongs to exactly two triangles (watertight).
/// Vertex normals are the exact normals of the round tube. Triangles are ordered so that
/// `p1 - p0` runs along the strand: without UVs a mesh's `dpdu` is `p1 - p0`, which gives
/// the hair material its fibre direction.
pub fn tessellate(segments: &[Bezier], steps: u32, sides: u32, material: MaterialId) -> TriangleMesh {
    let (steps, sides) = (steps.max(1), sides.max(3));
    let mut samples = Vec::new();
    for (k, seg) in segments.iter().enumerate() {
        let first = if k == 0 { 0 } else { 1 };
        for j in first..=steps {
            let u = j as f32 / steps as f32;
            samples.push((seg.eval(u), seg.derivative(u).truncate()));
        }
    }
    let points: Vec<Vec3> = samples.iter().map(|(p, _)| p.truncate()).collect();
    let n = points.len();
    // A zero derivative (coincident control points at an end) falls back to the chord.
    let tangents: Vec<Vec3> = (0..n)
        .map(|i| {
            let chord = points[(i + 1).min(n - 1)] - points[i.saturating_sub(1)];
            samples[i].1.try_normalize().or(chord.try_normalize()).unwrap_or(Vec3::X)
        })
        .collect();
    let normals = rotation_minimising_normals(&points, &tangents);

    let mut mesh = TriangleMesh { name: "curve".into(), material, ..Default::default() };
    // A ring around `centre` in the plane of the frame of sample `i`, its normals tilted
    // by `latitude` towards `t` (an end's outward tangent).
    let add_ring = |mesh: &mut TriangleMesh, i: usize, centre: Vec3, radius: f32, t: Vec3, latitude: f32| {
        let first = mesh.positions.len() as u32;
        let (r, s) = (normals[i], tangents[i].cross(normals[i]));
        for k in 0..sides {
            let phi = 2.0 * std::f32::consts::PI * k as f32 / sides as f32;
            let radial = phi.cos() * r + phi.sin() * s;
            mesh.positions.push(centre + radius * radial);
            mesh.normals.push(latitude.cos() * radial + latitude.sin() * t);
        }
        first
    };
    let side_rings: Vec<u32> = (0..n).map(|i| add_ring(&mut mesh, i, points[i], samples[i].0.w, tangents[i], 0.0)).collect();
    let latitudes = (sides / 4).max(1);
    let cap = |mesh: &mut TriangleMesh, i: usize, dir: f32| -> (Vec<u32>, u32) {
        let (centre, radius, t) = (points[i], samples[i].0.w, dir * tangents[i]);
        let rings = (1..latitudes).map(|j| {
            let a = std::f32::consts::FRAC_PI_2 * j as f32 / latitudes as f32;
            add_ring(mesh, i, centre + radius * a.sin() * t, radius * a.cos(), t, a)
        }).collect();
        mesh.positions.push(centre + radius * t);
        mesh.normals.push(t);
        (rings, mesh.positions.len() as u32 - 1)
    };
    let (start_rings, start_pole) = cap(&mut mesh, 0, -1.0);
    let (end_rings, end_pole) = cap(&mut mesh, n - 1, 1.0);
    // Every ring from the start pole to the end pole, in order along the strand.
    let rings: Vec<u32> = start_rings.iter().rev().chain(&side_rings).chain(&end_rings).copied().collect();
    let at = |ring: u32, k: u32| ring + k % sides;
    for pair in rings.windows(2) {
        for k in 0..sides {
            let (a, b, c, d) = (at(pair[0], k), at(pair[1], k), at(pair[1], k + 1), at(pair[0], k + 1));
            // Outward winding, with the first edge along the strand (see above).
            mesh.indices.push([b, a, c]);
            mesh.indices.push([d, c, a]);
        }
    }
    let (first, last) = (rings[0], rings[rings.len() - 1]);
    for k in 0..sides {
        mesh.indices.push([start_pole, at(first, k + 1), at(first, k)]);
        mesh.indices.push([end_pole, at(last, k), at(last, k + 1)]);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use glam::Vec4;

    use super::*;
    use crate::shape::curve::{to_bezier_segments, Basis};

    /// A planar S: two cubic arcs bending opposite ways, an inflection where they meet.
    fn s_curve() -> Vec<Bezier> {
        let p = [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0), (1.0, -1.0), (2.0, -1.0), (2.0, 0.0)];
        to_bezier_segments(Basis::Bezier, 3, &p.map(|(x, y)| Vec4::new(x, y, 0.0, 0.1))).unwrap()
    }

    #[test]
    fn tubes_are_closed() {
        for (steps, sides) in [(2, 3), (4, 4), (8, 16)] {
            let mesh = tessellate(&s_curve(), steps, sides, MaterialId::default());
            // Side rings, then `sides / 4 - 1` more rings and a pole on each hemisphere.
            let rings = 2 * steps + 1 + 2 * ((sides / 4).max(1) - 1);
            assert_eq!(mesh.len() as u32, 2 * sides * (rings - 1) + 2 * sides);
            let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
            for t in &mesh.indices {
                for e in 0..3 {
                    let (a, b) = (t[e], t[(e + 1) % 3]);
                    *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                }
            }
            assert!(edges.values().all(|&c| c == 2), "steps {steps} sides {sides}: an edge is not shared by exactly two triangles");
            // Every directed edge appears once: the windings agree (an oriented surface).
            let mut directed = std::collections::HashSet::new();
            for t in &mesh.indices {
                for e in 0..3 {
                    assert!(directed.insert((t[e], t[(e + 1) % 3])), "inconsistent winding");
                }
            }
            // The winding faces outwards: positive signed volume (divergence theorem),
            // close to Pappus' π r² L plus a ball for the two ends once the tube is fine.
            let volume: f32 = (0..mesh.len() as u32).map(|t| {
                let [a, b, c] = mesh.vertices(t);
                a.dot(b.cross(c)) / 6.0
            }).sum();
            assert!(volume > 0.0, "steps {steps} sides {sides}: the tube is inside out ({volume})");
            if sides == 16 {
                let length: f32 = s_curve().iter().map(|s| (0..1000).map(|j| (s.point((j + 1) as f32 / 1000.0) - s.point(j as f32 / 1000.0)).length()).sum::<f32>()).sum();
                let pappus = std::f32::consts::PI * (0.01 * length + 4.0 / 3.0 * 0.001);
                assert!((volume / pappus - 1.0).abs() < 0.05, "volume {volume} vs π r² L + 4/3 π r³ = {pappus}");
            }
        }
    }

    #[test]
    fn frames_are_continuous_through_an_inflection() {
        let segs = s_curve();
        let mut points = Vec::new();
        let mut tangents = Vec::new();
        for seg in &segs {
            for j in 0..64 {
                let u = j as f32 / 64.0;
                points.push(seg.point(u));
                tangents.push(seg.derivative(u).truncate().normalize());
            }
        }
        let normals = rotation_minimising_normals(&points, &tangents);
        for i in 0..normals.len() {
            assert!((normals[i].length() - 1.0).abs() < 1e-4 && normals[i].dot(tangents[i]).abs() < 1e-4, "ring {i}");
            if i > 0 {
                // Adjacent frames turn by no more than the tangent does (a few degrees).
                let turn = normals[i].angle_between(normals[i - 1]);
                assert!(turn <= tangents[i].angle_between(tangents[i - 1]) + 1e-3, "ring {i}: frame turned {turn} rad");
            }
            // In a plane, the rotation-minimising frame keeps its angles to the plane's
            // normal and to the in-plane side `z × t`: no flip at the inflection, where a
            // Frenet normal reverses.
            let side = |i: usize| normals[i].dot(Vec3::Z.cross(tangents[i]));
            assert!((normals[i].z - normals[0].z).abs() < 1e-3 && (side(i) - side(0)).abs() < 1e-3, "ring {i}: {} vs {}", normals[i], normals[0]);
        }
    }

    #[test]
    fn rings_lie_on_the_tube() {
        let segs = s_curve();
        let mesh = tessellate(&segs, 4, 8, MaterialId::default());
        // Ring 3 is at u = 3/4 of the first segment; its vertices are one radius from it.
        let c = segs[0].point(0.75);
        let t = segs[0].derivative(0.75).truncate().normalize();
        for k in 0..8 {
            let offset = mesh.positions[3 * 8 + k] - c;
            assert!((offset.length() - 0.1).abs() < 1e-5 && offset.dot(t).abs() < 1e-5, "{offset}");
        }
    }

    fn near(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    /// Straight segments from the points `p` (`w` the radius), degree 1.
    fn polyline(p: &[[f32; 4]]) -> Vec<Bezier> {
        to_bezier_segments(Basis::Bezier, 1, &p.iter().map(|&q| Vec4::from(q)).collect::<Vec<_>>()).unwrap()
    }

    #[test]
    fn one_step_of_double_reflection_by_hand() {
        // Duff et al.'s frame for t0 = x̂ (sign 1, a = −1, b = 0): r0 = (1 − 1, 0, −1) = −ẑ.
        // The chord v1 = (1, 1, −1), c1 = 3: v1·r0 = 1, v1·t0 = 1, so
        // r_L = −ẑ − ⅔(1, 1, −1) = (−⅔, −⅔, −⅓) and t_L = x̂ − ⅔(1, 1, −1) = (⅓, −⅔, ⅔).
        // With t1 = ŷ: v2 = t1 − t_L = (−⅓, 5/3, −⅔), c2 = 30/9 = 10/3, v2·r_L = (2 − 10 + 2)/9 = −⅔,
        // r1 = r_L − (2/c2)(v2·r_L) v2 = r_L + ⅖ v2 = (−⅔ − 2/15, −⅔ + ⅔, −⅓ − 4/15) = (−⅘, 0, −⅗):
        // unit and ⟂ t1, as a rotation keeps it. The points are off the origin so that p0 matters.
        let p0 = Vec3::new(1.0, 2.0, 3.0);
        let normals = rotation_minimising_normals(&[p0, p0 + Vec3::new(1.0, 1.0, -1.0)], &[Vec3::X, Vec3::Y]);
        assert_eq!(normals.len(), 2);
        assert!(near(normals[0], -Vec3::Z) && near(normals[1], Vec3::new(-0.8, 0.0, -0.6)), "{normals:?}");
        // A second step back to x̂ along the chord (1, −1, 0) (c1 = 2): v1·r1 = −⅘, v1·t1 = −1,
        // r_L = r1 − (−⅘)(1, −1, 0) = (0, −⅘, −⅗), t_L = ŷ + (1, −1, 0) = x̂ = t2: c2 = 0, no
        // second reflection, r2 = r_L.
        let p1 = p0 + Vec3::new(1.0, 1.0, -1.0);
        let normals = rotation_minimising_normals(&[p0, p1, p1 + Vec3::new(1.0, -1.0, 0.0)], &[Vec3::X, Vec3::Y, Vec3::X]);
        assert!(near(normals[2], Vec3::new(0.0, -0.8, -0.6)), "{normals:?}");
        // A hairpin: t turns from x̂ to −x̂ over the chord x̂. t_L = −x̂ = t1 (c2 = 0), r_L = r0.
        let normals = rotation_minimising_normals(&[p0, p0 + Vec3::X], &[Vec3::X, -Vec3::X]);
        assert!(near(normals[1], -Vec3::Z), "{normals:?}");
        assert!(rotation_minimising_normals(&[], &[]).is_empty());
    }

    #[test]
    fn on_a_helix_the_frame_turns_against_the_torsion() {
        // The helix (a cos θ, a sin θ, bθ), a = 1, b = ½, has torsion τ = b/(a² + b²) and arc length
        // s = θ√(a² + b²). A rotation-minimising normal r = cos φ N + sin φ B (N, B Frenet's) has
        // r′ ∥ T only if φ′ = −τ (with N′ = −κT + τB, B′ = −τN), so φ falls by bθ/√(a² + b²).
        let c = 1.25f32.sqrt();
        let theta = |k: usize| 0.05 + 0.02 * k as f32;
        let points: Vec<Vec3> = (0..150).map(|k| Vec3::new(theta(k).cos(), theta(k).sin(), 0.5 * theta(k))).collect();
        let tangents: Vec<Vec3> = (0..150).map(|k| Vec3::new(-theta(k).sin(), theta(k).cos(), 0.5) / c).collect();
        let normals = rotation_minimising_normals(&points, &tangents);
        let phi = |k: usize| {
            let (n, b) = (Vec3::new(-theta(k).cos(), -theta(k).sin(), 0.0), Vec3::new(0.5 * theta(k).sin(), -0.5 * theta(k).cos(), 1.0) / c);
            normals[k].dot(b).atan2(normals[k].dot(n))
        };
        for k in 0..150 {
            assert!((normals[k].length() - 1.0).abs() < 1e-5 && normals[k].dot(tangents[k]).abs() < 1e-5, "{k}: {}", normals[k]);
            let want = -0.5 / c * (theta(k) - theta(0));
            let off = (phi(k) - phi(0) - want + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
            assert!(off.abs() < 1e-3, "{k}: turned {} vs {want}", phi(k) - phi(0));
        }
    }

    #[test]
    fn coincident_samples_turn_the_frame_like_a_vanishing_chord() {
        // t turns from x̂ to ẑ. Over a short chord along t0 = x̂, v1 = εx̂: v1·r0 = 0, so r_L = r0 = −ẑ,
        // t_L = −x̂; v2 = ẑ + x̂, c2 = 2, v2·r_L = −1, r1 = −ẑ + (1, 0, 1) = x̂: the quarter turn about
        // −ŷ = t0 × t1 that takes x̂ to ẑ takes −ẑ to x̂. With no chord at all (a sample repeated,
        // as at a zero-length segment) the frame must turn the same way, not by a reflection
        // (which gives −x̂, a half turn about t1 more, twisting the tube between the two rings).
        let p0 = Vec3::new(1.0, 2.0, 3.0);
        for p1 in [p0 + Vec3::new(1e-3, 0.0, 0.0), p0] {
            let normals = rotation_minimising_normals(&[p0, p1], &[Vec3::X, Vec3::Z]);
            assert!(near(normals[1], Vec3::X), "{p1}: {normals:?}");
        }
    }

    #[test]
    fn straight_tube_vertices_by_hand() {
        // Along x̂ from (1, 2, 3) to (3, 2, 3), the radius tapering from ½ to ¼. The frame is
        // r = −ẑ (Duff et al. for x̂) and s = t × r = x̂ × (−ẑ) = ŷ all along; vertex k of a ring is
        // at angle φ = 2πk/8 from r. Rings at u = 0, ½, 1: centres x = 1, 2, 3, radii ½, ⅜, ¼.
        let mesh = tessellate(&polyline(&[[1.0, 2.0, 3.0, 0.5], [3.0, 2.0, 3.0, 0.25]]), 2, 8, MaterialId(3));
        assert_eq!((mesh.name.as_str(), mesh.material), ("curve", MaterialId(3)));
        // 3 side rings, one ring at latitude π/4 on each end (8 / 4 = 2 latitudes) and 2 poles.
        assert_eq!((mesh.positions.len(), mesh.normals.len()), (5 * 8 + 2, 5 * 8 + 2));
        // 5 rings: 4 bands of 8 quads, and 2 fans of 8.
        assert_eq!(mesh.len(), 4 * 16 + 2 * 8);
        let radial = |k: usize| {
            let phi = std::f32::consts::FRAC_PI_4 * k as f32;
            phi.cos() * -Vec3::Z + phi.sin() * Vec3::Y
        };
        let h = std::f32::consts::FRAC_1_SQRT_2;
        for k in 0..8 {
            for (ring, x, r) in [(0, 1.0, 0.5), (1, 2.0, 0.375), (2, 3.0, 0.25)] {
                let i = 8 * ring + k;
                assert!(near(mesh.positions[i], Vec3::new(x, 2.0, 3.0) + r * radial(k)), "ring {ring} vertex {k}: {}", mesh.positions[i]);
                assert!(near(mesh.normals[i], radial(k)), "ring {ring} normal {k}: {}", mesh.normals[i]);
            }
            // The start's hemisphere at latitude π/4: centre moved r·sin(π/4) along −x̂, radius
            // r·cos(π/4), normals tilted by π/4 towards −x̂; the end's likewise along +x̂.
            let (start, end) = (mesh.positions[24 + k], mesh.positions[33 + k]);
            assert!(near(start, Vec3::new(1.0 - 0.5 * h, 2.0, 3.0) + 0.5 * h * radial(k)), "start ring {k}: {start}");
            assert!(near(mesh.normals[24 + k], h * radial(k) - h * Vec3::X), "{}", mesh.normals[24 + k]);
            assert!(near(end, Vec3::new(3.0 + 0.25 * h, 2.0, 3.0) + 0.25 * h * radial(k)), "end ring {k}: {end}");
            assert!(near(mesh.normals[33 + k], h * radial(k) + h * Vec3::X), "{}", mesh.normals[33 + k]);
        }
        // The poles, one radius beyond each end.
        assert!(near(mesh.positions[32], Vec3::new(0.5, 2.0, 3.0)) && near(mesh.normals[32], -Vec3::X));
        assert!(near(mesh.positions[41], Vec3::new(3.25, 2.0, 3.0)) && near(mesh.normals[41], Vec3::X));
        // Every triangle faces away from the axis (y = 2, z = 3, x from 1 to 3), or along it
        // beyond its ends.
        for tri in 0..mesh.len() as u32 {
            let [a, b, c] = mesh.vertices(tri);
            let centroid = (a + b + c) / 3.0;
            let out = centroid - Vec3::new(centroid.x.clamp(1.0, 3.0), 2.0, 3.0);
            assert!(mesh.winding_normal(tri).dot(out) > 0.0 && mesh.area(tri) > 1e-4, "triangle {tri}");
        }
    }

    #[test]
    fn square_tube_triangles_by_hand() {
        // 4 sides (one latitude: no ring on the ends, only poles), one step: ring 0 is vertices
        // 0–3 at x = 0, ring 1 is 4–7 at x = 2, the start pole 8 and the end pole 9. Vertex k
        // points along −ẑ, ŷ, ẑ, −ŷ for k = 0..3. Each quad (ring 0: k, k + 1; ring 1: k, k + 1)
        // is two triangles whose first edge p0 → p1 runs along the strand (x̂ or −x̂), wound
        // outwards: e.g. [4, 0, 5] has (0 − 4) × (5 − 4) = (−2, 0, 0) × (0, ½, ½) = (0, 1, −1), between
        // −ẑ and ŷ. The start fan turns the other way round the axis than the end fan.
        let mesh = tessellate(&polyline(&[[0.0, 0.0, 0.0, 0.5], [2.0, 0.0, 0.0, 0.5]]), 1, 4, MaterialId::default());
        assert_eq!(mesh.positions.len(), 10);
        #[rustfmt::skip]
        let want = [
            [4, 0, 5], [1, 5, 0], [5, 1, 6], [2, 6, 1], [6, 2, 7], [3, 7, 2], [7, 3, 4], [0, 4, 3],
            [8, 1, 0], [9, 4, 5], [8, 2, 1], [9, 5, 6], [8, 3, 2], [9, 6, 7], [8, 0, 3], [9, 7, 4],
        ];
        assert_eq!(mesh.indices, want);
        assert!(near(mesh.positions[8], Vec3::new(-0.5, 0.0, 0.0)) && near(mesh.positions[9], Vec3::new(2.5, 0.0, 0.0)));
        assert!(near(mesh.positions[1], Vec3::new(0.0, 0.5, 0.0)) && near(mesh.positions[7], Vec3::new(2.0, -0.5, 0.0)));
        let [a, b, c] = mesh.vertices(0);
        assert!(near((b - a).cross(c - a), Vec3::new(0.0, 1.0, -1.0)));
    }

    #[test]
    fn segments_share_their_joint_ring() {
        // Two straight segments, (1, 2, 3) → (3, 2, 3) → (3, 4, 3), 2 steps each: samples at
        // u = 0, ½, 1 of the first and ½, 1 of the second (its u = 0 is the joint, not repeated).
        // The strand lies in the plane z = 3, so its frame keeps r = −ẑ, the plane's normal: the
        // ring of sample i has vertex 0 at its centre − r_i ẑ, vertex 2 (φ = π) at centre + r_i ẑ.
        let mesh = tessellate(&polyline(&[[1.0, 2.0, 3.0, 0.5], [3.0, 2.0, 3.0, 0.25], [3.0, 4.0, 3.0, 0.125]]), 2, 4, MaterialId::default());
        assert_eq!(mesh.positions.len(), 5 * 4 + 2);
        let centres = [(Vec3::new(1.0, 2.0, 3.0), 0.5), (Vec3::new(2.0, 2.0, 3.0), 0.375), (Vec3::new(3.0, 2.0, 3.0), 0.25), (Vec3::new(3.0, 3.0, 3.0), 0.1875), (Vec3::new(3.0, 4.0, 3.0), 0.125)];
        for (i, (c, r)) in centres.into_iter().enumerate() {
            assert!(near(mesh.positions[4 * i], c - r * Vec3::Z) && near(mesh.positions[4 * i + 2], c + r * Vec3::Z), "ring {i}: {} {}", mesh.positions[4 * i], mesh.positions[4 * i + 2]);
        }
        // The poles: the start one along −x̂ from (1, 2, 3), the end one along +ŷ from (3, 4, 3).
        assert!(near(mesh.positions[20], Vec3::new(0.5, 2.0, 3.0)) && near(mesh.positions[21], Vec3::new(3.0, 4.125, 3.0)));
    }

    #[test]
    fn a_vanishing_tangent_falls_back_to_the_chord() {
        // The quadratic (1, 1, 1), (1, 1, 1), (1, 5, 1): p(u) = (1, 1 + 4u², 1), p'(0) = 0. The
        // first ring's tangent is then the chord to the next sample, +ŷ, so the ring lies in the
        // plane y = 1 around (1, 1, 1); likewise at the end, where a doubled last point gives
        // p'(1) = 0 and the chord from the sample before, +ŷ, puts the last ring in y = 5.
        for cp in [[[1.0, 1.0, 1.0, 0.5], [1.0, 1.0, 1.0, 0.5], [1.0, 5.0, 1.0, 0.5]], [[1.0, 1.0, 1.0, 0.5], [1.0, 5.0, 1.0, 0.5], [1.0, 5.0, 1.0, 0.5]]] {
            let segs = to_bezier_segments(Basis::Bezier, 2, &cp.map(Vec4::from)).unwrap();
            let mesh = tessellate(&segs, 4, 4, MaterialId::default());
            for (ring, y) in [(0, 1.0), (4, 5.0)] {
                for k in 0..4 {
                    let offset = mesh.positions[4 * ring + k] - Vec3::new(1.0, y, 1.0);
                    assert!(offset.y.abs() < 1e-6 && (offset.length() - 0.5).abs() < 1e-6, "{cp:?} ring {ring} vertex {k}: {offset}");
                }
            }
            // The poles one radius beyond the ends, along the chords.
            assert!(near(mesh.positions[20], Vec3::new(1.0, 0.5, 1.0)) && near(mesh.positions[21], Vec3::new(1.0, 5.5, 1.0)), "{cp:?}");
        }
    }
}
