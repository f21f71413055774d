//! `sphere-bvh` built over boxes placed by hand: the tree's statistics and every ray's
//! answer and counts (nodes visited, primitives tested) worked out in the comments.
//! (Issue 15; `validate` and the exact spheres are checked by `sphere_bvh.rs`' unit tests.)
//!
//! Boxes are hit where a ray enters them (`testkit::Boxes`). A box of extent `e` has a
//! bounding sphere of radius `|e|/2` about its centre; the builder grows each leaf sphere by
//! the scene's largest extent · 2⁻¹⁸, and a parent's sphere is the union of its children's.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, SphereBvh};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit::Boxes;

/// `(prim, t)`, nodes visited, primitives tested.
fn closest(b: &SphereBvh, boxes: &Boxes, ray: &Ray) -> (Option<(u32, f32)>, u64, u64) {
    let mut c = Counters::default();
    let h = b.intersect(boxes, ray, &mut c);
    assert_eq!((c.rays, c.object_tests), (1, 0));
    (h.map(|h| (h.prim, h.t)), c.nodes_visited, c.prim_tests)
}

fn any(b: &SphereBvh, boxes: &Boxes, ray: &Ray) -> (bool, u64, u64) {
    let mut c = Counters::default();
    let h = b.occluded(boxes, ray, &mut c);
    assert_eq!(c.rays, 1);
    (h, c.nodes_visited, c.prim_tests)
}

fn along_x(x: f32, y: f32, sign: f32, t_max: f32) -> Ray {
    Ray::segment(Vec3::new(x, y, 0.5), Vec3::new(sign, 0.0, 0.0), 0.0, t_max)
}

/// Two unit cubes, A = [10, 11] × [0, 1]² (prim 0) and B = [13, 14] × [0, 1]² (prim 1). The
/// scene's extent is 4, so leaves grow by 2⁻¹⁶: radius r = √3/2 + 2⁻¹⁶ ≈ 0.866 about
/// (10.5, ½, ½) and (13.5, ½, ½). The root's sphere: centre (12, ½, ½), radius
/// R = (1.5 + r)(1 + 4ε) ≈ 2.366. A leaf of both would cost 2R² ≈ 11.2, the split
/// R² + 2r² ≈ 7.1: the root over one leaf each (one interior node, two leaves, depth 2).
fn two_cubes() -> Boxes {
    Boxes(vec![Aabb::new(Vec3::new(10.0, 0.0, 0.0), Vec3::new(11.0, 1.0, 1.0)), Aabb::new(Vec3::new(13.0, 0.0, 0.0), Vec3::new(14.0, 1.0, 1.0))])
}

/// SAH cost with sphere areas (∝ r²) relative to the root's: 1 for the root, r²/R² per
/// leaf of one primitive. Memory: 3 nodes of 24 bytes and 2 indices of 4.
#[test]
fn two_cubes_statistics_by_hand() {
    let boxes = two_cubes();
    let b = SphereBvh::build(&boxes, &BuildOptions::default());
    b.validate(&boxes).unwrap();
    let s = b.stats();
    assert_eq!(s.name, "sphere-bvh");
    assert_eq!((s.primitives, s.interior_nodes, s.leaves, s.references, s.max_depth, s.memory_bytes), (2, 1, 2, 2, 2, 3 * 24 + 2 * 4));
    assert_eq!(s.leaf_histogram[..3], [0, 2, 0]);
    let r = 0.75f64.sqrt() + 2f64.powi(-16);
    let big = (1.5 + r) * (1.0 + 4.0 * f32::EPSILON as f64);
    let want = 1.0 + 2.0 * r * r / (big * big);
    assert!((s.sah_cost - want).abs() < 1e-6, "SAH {} vs {want}", s.sah_cost);
}

/// Rays along x at y = z = ½ through both cubes, and beside them.
#[test]
fn two_cubes_rays_by_hand() {
    let boxes = two_cubes();
    let b = SphereBvh::build(&boxes, &BuildOptions::default());
    let inf = f32::INFINITY;
    // +x from x = 0: A's sphere entered at 10.5 − r ≈ 9.63, B's at 12.63: A first, its cube
    // hit at t = 10; B's sphere then begins beyond t_max = 10: dropped. Root and A: 2 visits,
    // 1 test. Any hit: the same, stopping at A's hit.
    assert_eq!(closest(&b, &boxes, &along_x(0.0, 0.5, 1.0, inf)), (Some((0, 10.0)), 2, 1));
    assert_eq!(any(&b, &boxes, &along_x(0.0, 0.5, 1.0, inf)), (true, 2, 1));
    // −x from x = 20: B first (entered at 20 − 14.37 ≈ 5.63), its cube at t = 6; A's sphere
    // (from 8.63) dropped.
    assert_eq!(closest(&b, &boxes, &along_x(20.0, 0.5, -1.0, inf)), (Some((1, 6.0)), 2, 1));
    assert_eq!(any(&b, &boxes, &along_x(20.0, 0.5, -1.0, inf)), (true, 2, 1));
    // From x = 12, between the cubes, +x: inside the root's sphere (entered at t = 0), A's
    // sphere behind, B's entered at 13.5 − r − 12 ≈ 0.63: B's cube at t = 1.
    assert_eq!(closest(&b, &boxes, &along_x(12.0, 0.5, 1.0, inf)), (Some((1, 1.0)), 2, 1));
    // +x from 0 ending at t = 9.7: A's sphere entered (9.63), its cube (t = 10) beyond the
    // end; B's sphere not reached: 2 visits, 1 test, no hit.
    assert_eq!(closest(&b, &boxes, &along_x(0.0, 0.5, 1.0, 9.7)), (None, 2, 1));
    assert_eq!(any(&b, &boxes, &along_x(0.0, 0.5, 1.0, 9.7)), (false, 2, 1));
    // At y = 1.7: 1.2 from the leaves' centres (more than r), inside the root's sphere (less
    // than R): the root alone.
    assert_eq!(closest(&b, &boxes, &along_x(0.0, 1.7, 1.0, inf)), (None, 1, 0));
    assert_eq!(any(&b, &boxes, &along_x(0.0, 1.7, 1.0, inf)), (false, 1, 0));
    // At y = 5: 4.5 from the root's centre: nothing visited.
    assert_eq!(closest(&b, &boxes, &along_x(0.0, 5.0, 1.0, inf)), (None, 0, 0));
    assert_eq!(any(&b, &boxes, &along_x(0.0, 5.0, 1.0, inf)), (false, 0, 0));
    // The same answers through `AnyAccel`.
    let any_accel = AnyAccel::build(AccelKind::SphereBvh, &boxes, &BuildOptions::default());
    assert_eq!(any_accel.intersect(&boxes, &along_x(20.0, 0.5, -1.0, inf), &mut Counters::default()).map(|h| (h.prim, h.t)), Some((1, 6.0)));
}

/// Two overlapping cubes, C = [0, 1]³ (prim 0) and D = [½, 1½] × [0, 1]² (prim 1): centres
/// ½ apart, r = √3/2 + 1.5·2⁻¹⁸, the union's radius R ≈ ¼ + r ≈ 1.116. A leaf of both costs
/// 2R² ≈ 2.49, the split R² + 2r² ≈ 2.75: one leaf of two (no interior node, depth 1, SAH 2,
/// 24 + 8 bytes).
#[test]
fn a_leaf_of_two_by_hand() {
    let boxes = Boxes(vec![Aabb::new(Vec3::ZERO, Vec3::ONE), Aabb::new(Vec3::new(0.5, 0.0, 0.0), Vec3::new(1.5, 1.0, 1.0))]);
    let b = SphereBvh::build(&boxes, &BuildOptions::default());
    b.validate(&boxes).unwrap();
    let s = b.stats();
    assert_eq!((s.interior_nodes, s.leaves, s.references, s.max_depth, s.memory_bytes), (0, 1, 2, 1, 24 + 8));
    assert_eq!(s.leaf_histogram[..3], [0, 0, 1]);
    assert!((s.sah_cost - 2.0).abs() < 1e-12, "SAH {}", s.sah_cost);
    let inf = f32::INFINITY;
    // +x from −5: C at t = 5, D at 5.5: both tested, C kept.
    assert_eq!(closest(&b, &boxes, &along_x(-5.0, 0.5, 1.0, inf)), (Some((0, 5.0)), 1, 2));
    // −x from 5: D entered at x = 1.5 (t = 3.5), C at x = 1 (t = 4): D, whichever is tested first.
    assert_eq!(closest(&b, &boxes, &along_x(5.0, 0.5, -1.0, inf)), (Some((1, 3.5)), 1, 2));
    // The same ending at t = 3.75: D only; any hit tests C (the first index, missed) and D.
    assert_eq!(closest(&b, &boxes, &along_x(5.0, 0.5, -1.0, 3.75)), (Some((1, 3.5)), 1, 2));
    assert_eq!(any(&b, &boxes, &along_x(5.0, 0.5, -1.0, 3.75)), (true, 1, 2));
}
