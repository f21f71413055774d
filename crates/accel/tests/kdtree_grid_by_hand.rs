//! The simpler structures on scenes worked out by hand: the per-object boxes (`aabb`), with
//! their statistics, counters and validation written out. (Issue 15: mutation testing found
//! these outcomes unchecked; the oracle tests check only that hits agree.)

use std::ops::Range;

use raylab_accel::{Accel, Counters, ObjectBoxes, PrimHit, Primitives};
use raylab_core::{Aabb, Ray, Vec3};

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
