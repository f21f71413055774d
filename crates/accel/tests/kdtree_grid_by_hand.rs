//! The simpler structures on scenes worked out by hand: the per-object boxes (`aabb`) and
//! the uniform grid, with their statistics, counters and validation written out, and the
//! kd-tree's depth limit. (Issue 15: mutation testing found these outcomes unchecked; the
//! oracle tests check only that hits agree.)

use std::ops::Range;

use raylab_accel::{Accel, BuildOptions, Counters, Grid, Hit, KdTree, ObjectBoxes, PrimHit, Primitives};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit as kit;

/// Boxes as primitives (a hit is the entry into the box), grouped into the objects given.
struct Boxes {
    boxes: Vec<Aabb>,
    objects: Vec<Range<u32>>,
}

impl Primitives for Boxes {
    fn len(&self) -> usize {
        self.boxes.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        self.boxes[i as usize]
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        let (t0, _) = self.boxes[i as usize].intersect_ray(ray)?;
        (t0 > ray.t_min && t0 <= ray.t_max).then_some(PrimHit { t: t0, u: 0.0, v: 0.0 })
    }
    fn objects(&self) -> Vec<Range<u32>> {
        self.objects.clone()
    }
}

fn aabb(min: [f32; 3], max: [f32; 3]) -> Aabb {
    Aabb::new(Vec3::from_array(min), Vec3::from_array(max))
}

fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
    Ray::new(Vec3::from_array(o), Vec3::from_array(d))
}

// ---------------------------------------------------------------- per-object boxes

/// Two objects of two unit cubes each: A = cubes at x 0..1 and 2..3 (box 3 x 1 x 1, half
/// area 3 + 1 + 3 = 7), B = cubes at z 4..5 and 6..7 (box 1 x 1 x 3, half area 7). The
/// empty range and the range past the end are dropped or clamped.
fn two_objects(objects: Vec<Range<u32>>) -> Boxes {
    Boxes {
        boxes: vec![aabb([0.0; 3], [1.0; 3]), aabb([2.0, 0.0, 0.0], [3.0, 1.0, 1.0]), aabb([0.0, 0.0, 4.0], [1.0, 1.0, 5.0]), aabb([0.0, 0.0, 6.0], [1.0, 1.0, 7.0])],
        objects,
    }
}

#[test]
fn object_boxes_statistics_by_hand() {
    let prims = two_objects(vec![0..2, 2..2, 2..9]);
    let a = ObjectBoxes::build(&prims);
    let s = a.stats();
    assert_eq!((s.name.as_str(), s.primitives, s.leaves, s.references, s.max_depth), ("aabb", 4, 2, 4, 1));
    // Scene box 3 x 1 x 7: half area 3 + 7 + 21 = 31. Every ray tests both boxes (2), and a
    // box hit costs its 2 primitives with probability 7/31: 2 + 2·(7/31)·2 = 2 + 28/31.
    assert!((s.sah_cost - (2.0 + 28.0 / 31.0)).abs() < 1e-6, "{}", s.sah_cost);
    assert_eq!(s.memory_bytes, 2 * (std::mem::size_of::<Aabb>() + std::mem::size_of::<Range<u32>>()));
    a.validate(&prims).unwrap();
    let none = ObjectBoxes::build(&two_objects(vec![]));
    assert_eq!((none.stats().leaves, none.stats().max_depth), (0, 0));
}

#[test]
fn object_boxes_test_each_box_then_its_primitives() {
    let prims = two_objects(vec![0..2, 2..4]);
    let a = ObjectBoxes::build(&prims);
    // Along x at y = z = 0.5: box A is hit (box B, at z 4..7, is not); both cubes of A are
    // tested, the nearer entered at t = 1.
    let r = ray([-1.0, 0.5, 0.5], [1.0, 0.0, 0.0]);
    let mut c = Counters::default();
    let h = a.intersect(&prims, &r, &mut c).unwrap();
    assert_eq!((h.prim, h.t), (0, 1.0));
    assert_eq!((c.rays, c.object_tests, c.nodes_visited, c.prim_tests), (1, 2, 1, 2));
    // Any hit stops at the first cube hit, before testing box B.
    let mut c = Counters::default();
    assert!(a.occluded(&prims, &r, &mut c));
    assert_eq!((c.rays, c.object_tests, c.nodes_visited, c.prim_tests), (1, 1, 1, 1));
    // Down z at x = y = 0.5 from z = 10: both boxes are hit and tested in list order, all
    // four cubes but cube 1 are hit; the nearest is cube 3, entered at z = 7 (t = 3).
    let r = ray([0.5, 0.5, 10.0], [0.0, 0.0, -1.0]);
    let mut c = Counters::default();
    let h = a.intersect(&prims, &r, &mut c).unwrap();
    assert_eq!((h.prim, h.t), (3, 3.0));
    assert_eq!((c.object_tests, c.nodes_visited, c.prim_tests), (2, 2, 4));
    // A ray passing between the objects hits nothing.
    let miss = ray([-1.0, 0.5, 2.5], [1.0, 0.0, 0.0]);
    let mut c = Counters::default();
    assert!(a.intersect(&prims, &miss, &mut c).is_none());
    assert!(!a.occluded(&prims, &miss, &mut c));
    assert_eq!((c.rays, c.object_tests, c.nodes_visited, c.prim_tests), (2, 4, 0, 0));
}

#[test]
fn object_boxes_validation_reports_each_broken_invariant() {
    let msg = |prims: &Boxes, other: &Boxes| ObjectBoxes::build(prims).validate(other).unwrap_err().message;
    let good = two_objects(vec![0..2, 2..4]);
    ObjectBoxes::build(&good).validate(&good).unwrap();
    let mut three = two_objects(vec![0..2, 2..3]);
    three.boxes.pop();
    assert_eq!(msg(&good, &three), "built for 4 primitives, given 3");
    assert_eq!(msg(&two_objects(vec![0..2, 1..4]), &good), "primitive 1 is in two objects");
    assert_eq!(msg(&two_objects(vec![0..1, 2..4]), &good), "primitive 1 is in no object");
    let mut moved = two_objects(vec![0..2, 2..4]);
    moved.boxes[3] = aabb([0.0, 0.0, 6.0], [1.0, 1.0, 7.5]);
    assert_eq!(msg(&good, &moved), "primitive 3 sticks out of object box 1");
}

// ---------------------------------------------------------------- uniform grid

/// Primitives made of boxes: a hit is the entry into the nearest box, the bounds are the
/// boxes' union, and the clipped bounds hold only what the boxes have inside the clip box
/// (so a primitive of two boxes apart is listed only in the cells its boxes reach, as a
/// thin diagonal triangle is listed only in the cells it crosses).
struct Parts(Vec<Vec<Aabb>>);

impl Primitives for Parts {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        self.0[i as usize].iter().fold(Aabb::EMPTY, |b, p| b.union(*p))
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        let t = self.0[i as usize].iter().filter_map(|p| p.intersect_ray(ray)).map(|(t0, _)| t0).filter(|&t| t > ray.t_min && t <= ray.t_max).min_by(f32::total_cmp)?;
        Some(PrimHit { t, u: 0.0, v: 0.0 })
    }
    fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
        self.0[i as usize].iter().map(|p| p.intersection(*clip)).filter(|b| !b.is_empty()).fold(Aabb::EMPTY, Aabb::union)
    }
}

/// Scene G: eight primitives in [0, 4]³. The margin is m = 4/2¹⁸ + 4 ulp(4) = 2⁻¹⁶ + 2⁻¹⁹ =
/// 9·2⁻¹⁹ (about 1.7e-5), the grid's box [−m, 4 + m]³; at λ = 8 (64 cells for 8 primitives)
/// the resolution is (4 + 2m)·∛(64 / (4 + 2m)³) = 4 per axis, cells of 1 + m/2, so the cell
/// boundaries lie at −m, 1 − m/2, 2, 3 + m/2 and 4 + m (all exact in f32). Cell (x, y, z):
///
/// - 0: [0, ½]³, cell (0, 0, 0); 1: [3.5, 4]³, cell (3, 3, 3);
/// - 2: a bar x 0.25..3.75, y 1.25..1.75, z 0.25..0.75, cells (0..3, 1, 0); 3: the same bar at
///   z 0.85..0.9, in the same cells;
/// - 4: x 2 + 2⁻²⁰..2.5, y and z 2.25..2.75: it starts within the margin above the boundary
///   x = 2, so it is listed in cells (1, 2, 2) and (2, 2, 2);
/// - 5: x 1.5..2 − 2⁻²⁰, y 2.25..2.75, z 0.25..0.75: it ends within the margin below x = 2,
///   cells (1, 2, 0) and (2, 2, 0);
/// - 6: two boxes, x 0.25..0.75 and 2.25..2.75, y and z 3.25..3.75: bounds over cells
///   (0..2, 3, 3), listed in (0, 3, 3) and (2, 3, 3) only;
/// - 7: x 1.25..1.75, y and z 0.25..0.75, cell (1, 0, 0).
fn scene_g() -> (Parts, BuildOptions) {
    let b = |min: [f32; 3], max: [f32; 3]| aabb(min, max);
    let e = (2.0f32).powi(-20);
    let prims = Parts(vec![
        vec![b([0.0; 3], [0.5; 3])],
        vec![b([3.5; 3], [4.0; 3])],
        vec![b([0.25, 1.25, 0.25], [3.75, 1.75, 0.75])],
        vec![b([0.25, 1.25, 0.85], [3.75, 1.75, 0.9])],
        vec![b([2.0 + e, 2.25, 2.25], [2.5, 2.75, 2.75])],
        vec![b([1.5, 2.25, 0.25], [2.0 - e, 2.75, 0.75])],
        vec![b([0.25, 3.25, 3.25], [0.75, 3.75, 3.75]), b([2.25, 3.25, 3.25], [2.75, 3.75, 3.75])],
        vec![b([1.25, 0.25, 0.25], [1.75, 0.75, 0.75])],
    ]);
    (prims, BuildOptions { grid_density: 8.0, ..BuildOptions::default() })
}

#[test]
fn grid_statistics_by_hand() {
    let (prims, opts) = scene_g();
    let g = Grid::build(&prims, &opts);
    assert_eq!(g.resolution(), [4, 4, 4]);
    assert_eq!(g.cell_count(), 64);
    let s = g.stats();
    // References: 1 + 1 + 4 + 4 + 2 + 2 + 2 + 1 = 17 in 13 cells: (0,0,0), (1,0,0), the four
    // bar cells (two each), (1,2,0), (2,2,0), (1,2,2), (2,2,2), (0,3,3), (2,3,3), (3,3,3).
    assert_eq!((s.name.as_str(), s.primitives, s.leaves, s.references, s.interior_nodes, s.max_depth), ("grid", 8, 64, 17, 13, 1));
    assert_eq!(s.leaf_histogram[..4], [51, 9, 4, 0]);
    // 65 offsets and 17 indices of 4 bytes.
    assert_eq!(s.memory_bytes, (65 + 17) * 4);
    let notes: Vec<(&str, &str)> = s.notes.iter().map(|(a, b)| (a.as_str(), b.as_str())).collect();
    assert_eq!(notes, vec![("resolution", "4x4x4"), ("density", "8"), ("cells", "64"), ("non-empty cells", "13")]);
    g.validate(&prims).unwrap();
    // No primitives: one empty cell, nothing hit, nothing visited.
    let none = Grid::build(&Parts(vec![]), &opts);
    assert_eq!(none.resolution(), [1, 1, 1]);
    let s = none.stats();
    assert_eq!((s.primitives, s.leaves, s.references, s.interior_nodes, s.memory_bytes), (0, 1, 0, 0, 8));
    none.validate(&Parts(vec![])).unwrap();
    let mut c = Counters::default();
    assert_eq!(none.intersect(&Parts(vec![]), &ray([0.5; 3], [1.0, 0.0, 0.0]), &mut c), None);
    assert_eq!((c.rays, c.nodes_visited, c.prim_tests), (1, 0, 0));
}

type Answer = (Option<(u32, f32)>, u64, u64);

fn grid_closest(g: &Grid, prims: &Parts, r: &Ray) -> Answer {
    let mut c = Counters::default();
    let h: Option<Hit> = g.intersect(prims, r, &mut c);
    assert_eq!(c.rays, 1);
    (h.map(|h| (h.prim, h.t)), c.nodes_visited, c.prim_tests)
}

fn grid_any(g: &Grid, prims: &Parts, r: &Ray) -> (bool, u64, u64) {
    let mut c = Counters::default();
    let h = g.occluded(prims, r, &mut c);
    assert_eq!(c.rays, 1);
    (h, c.nodes_visited, c.prim_tests)
}

/// The 3D-DDA on scene G, every answer and count by hand (cells visited, primitives tested).
#[test]
fn grid_walk_by_hand() {
    let (prims, opts) = scene_g();
    let g = Grid::build(&prims, &opts);
    let e = (2.0f32).powi(-20);
    let cases: Vec<(Ray, Answer, (bool, u64, u64))> = vec![
        // +x along the bars from x = −1: entered at x = −m, cell (0,1,0): prim 2 at t = 1.25,
        // prim 3 (z 0.85..0.9) missed; the cell's exit (t = 2 − m/2) lies beyond the hit.
        // Any hit stops at prim 2.
        (ray([-1.0, 1.5, 0.5], [1.0, 0.0, 0.0]), (Some((2, 1.25)), 1, 2), (true, 1, 1)),
        // The same from x = 5 along −x: cell (3,1,0) first.
        (ray([5.0, 1.5, 0.5], [-1.0, 0.0, 0.0]), (Some((2, 1.25)), 1, 2), (true, 1, 1)),
        // From inside bar 2 (no hit: its entry lies behind the origin): all four bar cells,
        // prims 2 and 3 tested once each (the mailbox skips them in the next three cells).
        (ray([0.5, 1.5, 0.5], [1.0, 0.0, 0.0]), (None, 4, 2), (false, 4, 2)),
        // The same along −x from x = 3.5, down to cell (0,1,0) and out through x = −m.
        (ray([3.5, 1.5, 0.5], [-1.0, 0.0, 0.0]), (None, 4, 2), (false, 4, 2)),
        // The same ending at t = 1.5, exactly on the boundary x = 2: cells (0,1,0), (1,1,0).
        (Ray::segment(Vec3::new(0.5, 1.5, 0.5), Vec3::X, 0.0, 1.5), (None, 2, 2), (false, 2, 2)),
        // Diagonal (1, 1, 0) from (¼, ¼) at z = 0.95, above every primitive: the x and y
        // boundaries are crossed at the same t each time (1 − m/2, 2, 3 + m/2, 4 + m) and x is
        // stepped first: cells (0,0,0) prim 0, (1,0,0) prim 7, (1,1,0) prims 2 and 3, (2,1,0)
        // (both already tested), (2,2,0) prim 5, (3,2,0), (3,3,0): 7 cells, 5 tests.
        (ray([0.25, 0.25, 0.95], [1.0, 1.0, 0.0]), (None, 7, 5), (false, 7, 5)),
        // +z up the column x = y = 3.75: cells (3,3,0) to (3,3,3), prim 1 at z = 3.5, t = 4.5.
        (ray([3.75, 3.75, -1.0], [0.0, 0.0, 1.0]), (Some((1, 4.5)), 4, 1), (true, 4, 1)),
        // −y at x = 2.375, z = 2.5 from y = 5: cells (2,3,2), then (2,2,2): prim 4 at y = 2.75.
        (ray([2.375, 5.0, 2.5], [0.0, -1.0, 0.0]), (Some((4, 2.25)), 2, 1), (true, 2, 1)),
        // −y at x = 2.5, z = 3.5: cell (2,3,3), prim 6's second box at y = 3.75.
        (ray([2.5, 5.0, 3.5], [0.0, -1.0, 0.0]), (Some((6, 1.25)), 1, 1), (true, 1, 1)),
        // Skimming the scene's faces, inside the grid only by its margin: −y at x = 4 − 2⁻²⁰
        // hits prim 1's face y = 4 (t = 1), +y at x = 2⁻²⁰ prim 0's face y = 0.
        (ray([4.0 - e, 5.0, 3.75], [0.0, -1.0, 0.0]), (Some((1, 1.0)), 1, 1), (true, 1, 1)),
        (ray([e, -1.0, 0.25], [0.0, 1.0, 0.0]), (Some((0, 1.0)), 1, 1), (true, 1, 1)),
        // Away from the grid: nothing visited.
        (ray([-1.0, -1.0, -1.0], [-1.0, 0.0, 0.0]), (None, 0, 0), (false, 0, 0)),
        (ray([-1.0, 1.5, 0.5], [0.0, 1.0, 0.0]), (None, 0, 0), (false, 0, 0)),
    ];
    for (k, (r, want, want_any)) in cases.into_iter().enumerate() {
        assert_eq!(grid_closest(&g, &prims, &r), want, "ray {k}");
        assert_eq!(grid_any(&g, &prims, &r), want_any, "ray {k}: any hit");
    }
}

/// Too many references for the budget (2²⁵ = 33,554,432) by the primitives' bounds: prim 0 a
/// tiny box [0, 2⁻¹⁰]³, then 130 primitives of two tiny boxes each, [½ + δ, ½ + 2δ]³ and
/// [1 − 2⁻¹⁰, 1]³ with δ = 2⁻⁹, whose bounds [½ + δ, 1]³ cover an eighth of the scene. The
/// scene is [0, 1]³, the grid's box [−m, 1 + m]³ with m = 2⁻¹⁸ + 4 ulp(1) = 9·2⁻²¹. At
/// λ = 10⁶ the resolution is ∛(1.31e8) = 508, clamped to 128 per axis: each pair's bounds
/// then span cells floor(128·(½ + δ)) = 64 to 127, 64³ = 262,144 cells, and
/// 130 · 262,144 + 1 = 34,078,721 references exceed the budget. Coarsened by 0.8 to 102 per
/// axis: cells 51 (floor(102·0.502) = 51) to 101, 51³ = 132,651, and 130 · 51³ + 1 =
/// 17,244,631 fit. Each pair is then listed only in the two cells its boxes reach, (51, 51,
/// 51) and (101, 101, 101) (cells are 1/102 wide, from ½ to 0.5098 for cell 51): 261
/// references in 3 cells.
#[test]
fn grid_is_coarsened_when_bounds_would_overflow_the_reference_budget() {
    let (t, d) = ((2.0f32).powi(-10), (2.0f32).powi(-9));
    let pair = vec![aabb([0.5 + d; 3], [0.5 + 2.0 * d; 3]), aabb([1.0 - t; 3], [1.0; 3])];
    let mut parts = vec![vec![aabb([0.0; 3], [t; 3])]];
    parts.extend(std::iter::repeat_n(pair, 130));
    let prims = Parts(parts);
    let g = Grid::build(&prims, &BuildOptions { grid_density: 1e6, ..BuildOptions::default() });
    assert_eq!(g.resolution(), [102, 102, 102]);
    let s = g.stats();
    assert_eq!((s.leaves, s.references, s.interior_nodes), (102 * 102 * 102, 261, 3));
    g.validate(&prims).unwrap();
}

// ---------------------------------------------------------------- kd-tree depth

/// pbrt's depth limit, round(8 + 1.3 log₂ N), holds and is reached on the bunny: N = 4968,
/// log₂ N = 12.28, 8 + 15.96 = 23.96, so 24 levels (the SAH alone would go deeper).
#[test]
fn kdtree_depth_limit_on_the_bunny() {
    let bunny = kit::read_obj_triangles(&kit::asset("bunny_4968.obj"));
    assert_eq!(bunny.prims.len(), 4968);
    let t = KdTree::build(&bunny, &BuildOptions::default());
    assert_eq!(t.stats().max_depth, 24);
}
