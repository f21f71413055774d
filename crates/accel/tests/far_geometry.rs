//! Structures keep their cost far from the origin (issue 12: an icosphere offset by 1e5 made
//! sbvh, lbvh, lbvh-ploc, kdtree, grid and sphere-bvh do 5,000-98,000 primitive tests per ray
//! against about 1 for bvh). The same scene, shifted by 1e3..1e5, must cost every structure
//! at most twice its primitive tests per ray at the origin; at 1e6, where the coordinates'
//! spacing (0.0625) is an eighth of a triangle and the grid's and kd-tree's margin of four
//! ulps (see `robust_margin`) half of one, three times.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters};
use raylab_core::{Aabb, Pcg32, Ray, Vec3};
use raylab_testkit::{self as kit, Prim, Soup};

/// A closed-looking shell: 3,000 small triangles centred on a sphere of radius 10 (their
/// size, 0.5, stays well above the float spacing at 1e6, 0.0625).
fn shell(offset: Vec3) -> Soup {
    let mut rng = Pcg32::new(5, 8);
    Soup::triangles((0..3000).map(|_| {
        let c = 10.0 * kit::random_dir(&mut rng);
        [0, 1, 2].map(|_| c + 0.5 * kit::random_dir(&mut rng) + offset)
    }))
}

/// Primitive tests per ray, and the hits (to check the shift moved nothing else). Every
/// answer must also agree with the brute-force oracle: a smaller margin must not lose hits.
fn tests_per_ray(kind: AccelKind, soup: &Soup, rays: &[Ray]) -> (f64, usize) {
    let accel = AnyAccel::build(kind, soup, &BuildOptions::default());
    accel.validate(soup).unwrap_or_else(|e| panic!("{kind}: {e}"));
    let oracle = AnyAccel::build(AccelKind::None, soup, &BuildOptions::default());
    let (mut c, mut oracle_counters) = (Counters::default(), Counters::default());
    let mut hits = 0;
    for (k, r) in rays.iter().enumerate() {
        let got = accel.intersect(soup, r, &mut c);
        let want = oracle.intersect(soup, r, &mut oracle_counters);
        kit::agrees_with_oracle(soup, r, want, got).unwrap_or_else(|e| panic!("{kind} ray {k}: {e}"));
        assert_eq!(accel.occluded(soup, r, &mut oracle_counters), want.is_some(), "{kind} ray {k}: any hit");
        hits += usize::from(got.is_some());
    }
    (c.prim_tests as f64 / rays.len() as f64, hits)
}

/// The cost ratio allowed at offset `d` (see the module's documentation).
fn allowed(d: f32) -> f64 {
    if d < 1e6 { 2.0 } else { 3.0 }
}

#[test]
fn every_structure_costs_the_same_far_from_the_origin() {
    let near = shell(Vec3::ZERO);
    let b = near.bounds();
    let outer = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let rays = kit::random_rays(&mut Pcg32::new(3, 4), 400, &outer, &b);
    let mut slow = Vec::new();
    for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::None) {
        let (at_origin, hits) = tests_per_ray(kind, &near, &rays);
        for d in [1e3f32, 1e4, 1e5, 1e6] {
            let offset = Vec3::new(d, -0.5 * d, 0.25 * d);
            let far = shell(offset);
            let moved: Vec<Ray> = rays.iter().map(|r| Ray::new(r.origin + offset, r.dir)).collect();
            let (cost, far_hits) = tests_per_ray(kind, &far, &moved);
            if cost > allowed(d) * at_origin + 1.0 {
                slow.push(format!("{kind} at offset {d}: {cost:.1} primitive tests per ray against {at_origin:.1} at the origin"));
            }
            // Rounding of the shifted vertices may move a grazing hit, not more.
            assert!(far_hits.abs_diff(hits) <= rays.len() / 50, "{kind} at offset {d}: {far_hits} hits against {hits}");
        }
    }
    assert!(slow.is_empty(), "{}", slow.join("\n"));
}

#[test]
fn spheres_far_from_the_origin() {
    let spheres = |offset: Vec3| {
        let mut rng = Pcg32::new(9, 2);
        Soup::new((0..1500).map(|_| Prim::Sphere { center: 10.0 * kit::random_dir(&mut rng) + offset, radius: 0.3 }).collect())
    };
    let near = spheres(Vec3::ZERO);
    let b = near.bounds();
    let outer = Aabb::new(b.min - b.extent(), b.max + b.extent());
    let rays = kit::random_rays(&mut Pcg32::new(3, 5), 400, &outer, &b);
    let mut slow = Vec::new();
    for &kind in AccelKind::ALL.iter().filter(|&&k| k != AccelKind::None) {
        let (at_origin, _) = tests_per_ray(kind, &near, &rays);
        for d in [1e3f32, 1e5, 1e6] {
            let offset = Vec3::new(-d, d, 0.5 * d);
            let moved: Vec<Ray> = rays.iter().map(|r| Ray::new(r.origin + offset, r.dir)).collect();
            let (cost, _) = tests_per_ray(kind, &spheres(offset), &moved);
            if cost > allowed(d) * at_origin + 1.0 {
                slow.push(format!("{kind} spheres at offset {d}: {cost:.1} primitive tests per ray against {at_origin:.1} at the origin"));
            }
        }
    }
    assert!(slow.is_empty(), "{}", slow.join("\n"));
}
