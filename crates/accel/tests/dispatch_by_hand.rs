//! `AnyAccel`'s dispatch (`lib.rs`), the oracle (`brute.rs`) and the defaults of the
//! `Primitives` trait (`primitives.rs`), with every answer worked out by hand. (Issue 15.)
//!
//! The scene is testkit's cube: `[−½, ½]³` in 12 triangles. Its bottom face z = −½ is
//! prims 0 (corners (−½, −½), (½, −½), (½, ½): the half where x ≥ y) and 1 (corners
//! (−½, −½), (½, ½), (−½, ½): y ≥ x), its top face z = ½ prims 2 and 3. A ray along +z from
//! z = −3 meets the bottom face at t = 2.5 and the top face at 3.5.

use std::time::{Duration, Instant};

use raylab_accel::primitives::total_bounds;
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Hit, PrimHit, Primitives, PACKET};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit::{self as kit, Boxes, Soup};

/// Every kind with the name its statistics and errors carry, and whether it traverses
/// packets together (the wide BVHs).
const KINDS: [(AccelKind, &str, bool); 15] = [
    (AccelKind::None, "none", false),
    (AccelKind::Bvh, "bvh", false),
    (AccelKind::BvhMedian, "bvh-median", false),
    (AccelKind::BvhMidpoint, "bvh-midpoint", false),
    (AccelKind::Aabb, "aabb", false),
    (AccelKind::Grid, "grid", false),
    (AccelKind::Lbvh, "lbvh", false),
    (AccelKind::LbvhPloc, "lbvh-ploc", false),
    (AccelKind::KdTree, "kdtree", false),
    (AccelKind::SphereBvh, "sphere-bvh", false),
    (AccelKind::Sbvh, "sbvh", false),
    (AccelKind::Bvh8, "bvh8", true),
    (AccelKind::Bvh4, "bvh4", true),
    (AccelKind::Bvh8Sbvh, "bvh8-sbvh", true),
    (AccelKind::Bvh8Q, "bvh8q", true),
];

fn up(x: f32, y: f32, t_max: f32) -> Ray {
    Ray::segment(Vec3::new(x, y, -3.0), Vec3::Z, 0.0, t_max)
}

/// `(prim, t)` of a hit.
fn pt(h: Option<Hit>) -> Option<(u32, f32)> {
    h.map(|h| (h.prim, h.t))
}

#[test]
fn the_kinds_table_lists_every_kind_once() {
    assert_eq!(AccelKind::ALL.len(), KINDS.len());
    for (k, (kind, name, _)) in KINDS.iter().enumerate() {
        assert_eq!(AccelKind::ALL[k], *kind);
        assert_eq!(kind.name(), *name);
    }
}

/// Each kind's statistics carry its name and the cube's 12 primitives; each validates
/// against the cube and rejects 11 of its triangles, naming itself.
#[test]
fn every_kind_reports_its_name_and_checks_its_count() {
    let cube = kit::cube();
    let eleven = Soup::new(cube.prims[..11].to_vec());
    for (kind, name, packets) in KINDS {
        let accel = AnyAccel::build(kind, &cube, &BuildOptions::default());
        let s = accel.stats();
        assert_eq!((s.name.as_str(), s.primitives), (name, 12), "{kind:?}");
        assert_eq!(accel.validate(&cube), Ok(()), "{kind:?}");
        assert_eq!(accel.validate(&eleven).unwrap_err().to_string(), format!("{name}: built for 12 primitives, given 11"));
        assert_eq!(accel.has_packets(), packets, "{name}");
        assert_eq!(accel.kernel().is_some(), packets, "{name}");
    }
}

/// Every entry point of every kind gives the hand answers: the ray at (¼, −¼) hits prim 0
/// at t = 2.5, the one at (−¼, ¼) prim 1, the one at (2, 2) nothing; a segment ending at
/// t = 2 stops short of the face. Each ray is counted once, by `intersect` and `occluded`
/// and by the counted packet.
#[test]
fn every_kind_answers_through_each_entry_point() {
    let cube = kit::cube();
    let inf = f32::INFINITY;
    let rays = [up(0.25, -0.25, inf), up(-0.25, 0.25, inf), up(2.0, 2.0, inf), up(0.25, -0.25, 2.0)];
    let want = [Some((0, 2.5)), Some((1, 2.5)), None, None];
    for (kind, name, _) in KINDS {
        let accel = AnyAccel::build(kind, &cube, &BuildOptions::default());
        for (ray, want) in rays.iter().zip(want) {
            let mut c = Counters::default();
            assert_eq!(pt(accel.intersect(&cube, ray, &mut c)), want, "{name}: {ray:?}");
            assert_eq!(c.rays, 1, "{name}");
            assert_eq!(accel.occluded(&cube, ray, &mut c), want.is_some(), "{name}: {ray:?}");
            assert_eq!(c.rays, 2, "{name}");
            assert_eq!(pt(accel.intersect_fast(&cube, ray)), want, "{name}: {ray:?} fast");
            assert_eq!(accel.occluded_fast(&cube, ray), want.is_some(), "{name}: {ray:?} fast");
        }
        // Packets: filled in whatever `out` held before.
        let mut out = [Some(Hit { t: -1.0, prim: 99, u: 0.0, v: 0.0 }); 4];
        accel.intersect_packet(&cube, &rays, &mut out);
        assert_eq!(out.map(pt), want, "{name}: packet");
        let mut out = [Some(Hit { t: -1.0, prim: 99, u: 0.0, v: 0.0 }); 4];
        let mut c = Counters::default();
        accel.intersect_packet_counted(&cube, &rays, &mut out, &mut c);
        assert_eq!(out.map(pt), want, "{name}: counted packet");
        assert_eq!(c.rays, 4, "{name}: counted packet");
        // A full packet of 16: the four rays four times.
        let full: Vec<Ray> = (0..PACKET).map(|k| rays[k % 4]).collect();
        let mut out = [None; PACKET];
        accel.intersect_packet(&cube, &full, &mut out);
        assert_eq!(out.map(pt).to_vec(), (0..PACKET).map(|k| want[k % 4]).collect::<Vec<_>>(), "{name}: 16 rays");
        let mut out = [None; PACKET];
        accel.intersect_packet_counted(&cube, &full, &mut out, &mut Counters::default());
        assert_eq!(out.map(pt).to_vec(), (0..PACKET).map(|k| want[k % 4]).collect::<Vec<_>>(), "{name}: 16 rays counted");
    }
}

/// The oracle tests every primitive for a closest hit (12 tests, the top face behind the
/// bottom one dropped by the shrinking `t_max`) and stops at the first hit for any hit:
/// prim 0 at once for the ray at (¼, −¼), prim 1 second for the one at (−¼, ¼).
#[test]
fn the_oracle_counts_by_hand() {
    let cube = kit::cube();
    let brute = AnyAccel::build(AccelKind::None, &cube, &BuildOptions::default());
    let count = |f: &dyn Fn(&mut Counters)| {
        let mut c = Counters::default();
        f(&mut c);
        (c.rays, c.nodes_visited, c.prim_tests, c.object_tests)
    };
    let inf = f32::INFINITY;
    for (ray, want, any_tests) in [(up(0.25, -0.25, inf), Some((0, 2.5)), 1), (up(-0.25, 0.25, inf), Some((1, 2.5)), 2), (up(2.0, 2.0, inf), None, 12)] {
        assert_eq!(count(&|c| assert_eq!(pt(brute.intersect(&cube, &ray, c)), want)), (1, 0, 12, 0));
        assert_eq!(count(&|c| assert_eq!(brute.occluded(&cube, &ray, c), want.is_some())), (1, 0, any_tests, 0));
    }
    let s = brute.stats();
    assert_eq!((s.primitives, s.references, s.leaves, s.interior_nodes, s.memory_bytes), (12, 12, 0, 0, 0));
    assert_eq!(raylab_accel::Brute::build(&cube).validate(&Soup::default()).unwrap_err().message, "built for 12 primitives, given 0");
}

/// Primitives whose `len` sleeps: a build lasts at least that long, so the build time
/// recorded is at least the sleep and at most the time measured around the build.
struct Slow;

const NAP: Duration = Duration::from_millis(10);

impl Primitives for Slow {
    fn len(&self) -> usize {
        std::thread::sleep(NAP);
        0
    }
    fn bounds(&self, _: u32) -> Aabb {
        unreachable!("no primitives")
    }
    fn intersect(&self, _: u32, _: &Ray) -> Option<PrimHit> {
        unreachable!("no primitives")
    }
}

#[test]
fn build_time_is_recorded_in_milliseconds() {
    for (kind, name, _) in KINDS {
        let start = Instant::now();
        let accel = AnyAccel::build(kind, &Slow, &BuildOptions::default());
        let around = start.elapsed().as_secs_f64() * 1e3;
        let ms = accel.stats().build_ms;
        assert!(ms >= NAP.as_secs_f64() * 1e3 && ms <= around, "{name}: {ms} ms recorded, {around} ms around the build");
    }
}

// `intersect_packet`'s and `intersect_packet_counted`'s limits: at most 16 rays, and as
// many answers as rays. The oracle answers packets ray by ray, so only `AnyAccel`'s own
// check can panic here.

fn oracle() -> (Soup, AnyAccel) {
    let cube = kit::cube();
    let brute = AnyAccel::build(AccelKind::None, &cube, &BuildOptions::default());
    (cube, brute)
}

#[test]
#[should_panic(expected = "a packet holds at most 16 rays and as many answers")]
fn a_packet_of_seventeen_panics() {
    let (cube, brute) = oracle();
    brute.intersect_packet(&cube, &[up(0.0, 0.0, 1.0); 17], &mut [None; 17]);
}

#[test]
#[should_panic(expected = "a packet holds at most 16 rays and as many answers")]
fn a_packet_with_more_answers_than_rays_panics() {
    let (cube, brute) = oracle();
    brute.intersect_packet(&cube, &[up(0.0, 0.0, 1.0); 2], &mut [None; 3]);
}

#[test]
#[should_panic(expected = "a packet holds at most 16 rays and as many answers")]
fn a_counted_packet_of_seventeen_panics() {
    let (cube, brute) = oracle();
    brute.intersect_packet_counted(&cube, &[up(0.0, 0.0, 1.0); 17], &mut [None; 17], &mut Counters::default());
}

#[test]
#[should_panic(expected = "a packet holds at most 16 rays and as many answers")]
fn a_counted_packet_with_fewer_answers_than_rays_panics() {
    let (cube, brute) = oracle();
    brute.intersect_packet_counted(&cube, &[up(0.0, 0.0, 1.0); 3], &mut [None; 2], &mut Counters::default());
}

/// The trait's defaults, on boxes (which override none of them): the centroid of a box,
/// `bounds ∩ clip`, one object per primitive, no triangles; and `total_bounds`.
#[test]
fn primitives_defaults_by_hand() {
    let boxes = Boxes(vec![
        Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 4.0, 6.0)),
        Aabb::new(Vec3::new(-3.0, 1.0, 1.0), Vec3::new(-1.0, 2.0, 5.0)),
        Aabb::new(Vec3::new(5.0, -2.0, 0.5), Vec3::new(6.0, -1.0, 1.5)),
    ]);
    assert_eq!(boxes.centroid(0), Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(boxes.centroid(1), Vec3::new(-2.0, 1.5, 3.0));
    let clip = Aabb::new(Vec3::new(1.0, -10.0, 2.0), Vec3::new(10.0, 3.0, 10.0));
    assert_eq!(boxes.clipped_bounds(0, &clip), Aabb::new(Vec3::new(1.0, 0.0, 2.0), Vec3::new(2.0, 3.0, 6.0)));
    // Box 2 lies below the clip in z: the intersection is empty (its z range 2 > 1.5).
    let outside = boxes.clipped_bounds(2, &clip);
    assert_eq!(outside, Aabb { min: Vec3::new(5.0, -2.0, 2.0), max: Vec3::new(6.0, -1.0, 1.5) });
    assert!(outside.is_empty());
    assert_eq!(boxes.objects(), vec![0..1, 1..2, 2..3]);
    assert_eq!((0..3).map(|i| boxes.triangle(i)).collect::<Vec<_>>(), vec![None; 3]);
    assert!(!boxes.is_empty());
    assert!(Boxes(vec![]).is_empty());
    assert_eq!(Boxes(vec![]).objects(), vec![]);
    assert_eq!(total_bounds(&boxes), Aabb::new(Vec3::new(-3.0, -2.0, 0.0), Vec3::new(6.0, 4.0, 6.0)));
    assert_eq!(total_bounds(&Boxes(vec![])), Aabb::EMPTY);
    // A hit keeps the primitive's distance and surface parameters.
    assert_eq!(Hit::new(7, PrimHit { t: 1.5, u: 0.25, v: 0.5 }), Hit { t: 1.5, prim: 7, u: 0.25, v: 0.5 });
}
