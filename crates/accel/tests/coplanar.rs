//! Overlapping coplanar triangles, where "the closest hit" is a tie up to rounding: every
//! structure must agree with the oracle in the sense of `testkit::agrees_with_oracle` (a
//! genuine hit, never in front of the true closest, at most `ORACLE_ULPS` behind it), and
//! that definition must still reject real bugs.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Hit};
use raylab_core::{Pcg32, Ray, Vec3};
use raylab_testkit::{self as kit, agrees_with_oracle, Soup};

/// Three overlapping fans in one tilted plane (each blade overlaps its neighbours), plus
/// every blade of the first fan duplicated with its vertices rotated.
fn overlapping_fans() -> Soup {
    let (e1, e2) = (Vec3::new(1.0, 0.3, 0.2).normalize(), Vec3::new(-0.2, 0.1, 1.0).normalize());
    let e2 = (e2 - e1 * e1.dot(e2)).normalize();
    let at = |c: Vec3, r: f32, a: f32| c + r * (a.cos() * e1 + a.sin() * e2);
    let mut tris = Vec::new();
    for (k, centre) in [Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.6, 0.35, 0.4), Vec3::new(0.3, 0.3, 0.9)].into_iter().enumerate() {
        let blades = 24;
        for i in 0..blades {
            let a = i as f32 / blades as f32 * std::f32::consts::TAU + k as f32 * 0.1;
            // Each blade spans three steps: every point is covered by about three blades.
            let tri = [centre, at(centre, 0.7, a), at(centre, 0.7, a + 3.0 * std::f32::consts::TAU / blades as f32)];
            tris.push(tri);
            if k == 0 {
                tris.push([tri[1], tri[2], tri[0]]);
            }
        }
    }
    Soup::triangles(tris)
}

#[test]
fn every_structure_agrees_on_overlapping_coplanar_triangles() {
    let soup = overlapping_fans();
    let b = soup.bounds();
    let mut rng = Pcg32::new(41, 2);
    let rays: Vec<Ray> = (0..4000)
        .map(|_| {
            let target = kit::random_point(&mut rng, &b);
            let origin = target + 3.0 * kit::random_dir(&mut rng);
            Ray::new(origin, (target - origin).normalize())
        })
        .collect();
    let oracle = AnyAccel::build(AccelKind::None, &soup, &BuildOptions::default());
    let mut c = Counters::default();
    let hits = rays.iter().filter(|r| oracle.intersect(&soup, r, &mut c).is_some()).count();
    assert!(hits > 1000, "only {hits} rays hit the fans");
    for &kind in AccelKind::ALL {
        let accel = AnyAccel::build(kind, &soup, &BuildOptions::default());
        accel.validate(&soup).unwrap_or_else(|e| panic!("{kind}: {e}"));
        let (mut exact, mut tied) = (0, 0);
        for (k, ray) in rays.iter().enumerate() {
            let (want, got) = (oracle.intersect(&soup, ray, &mut c), accel.intersect(&soup, ray, &mut c));
            agrees_with_oracle(&soup, ray, want, got).unwrap_or_else(|e| panic!("{kind} ray {k}: {e}"));
            assert_eq!(accel.occluded(&soup, ray, &mut c), want.is_some(), "{kind} ray {k}: any hit");
            match (want, got) {
                (Some(w), Some(g)) if w.t == g.t => exact += 1,
                (Some(_), Some(_)) => tied += 1,
                _ => {}
            }
        }
        println!("{kind}: {exact} hits at exactly the oracle's t, {tied} near ties resolved to another blade");
    }
}

#[test]
fn the_agreement_rule_still_rejects_real_bugs() {
    let soup = Soup::triangles([[Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0)], [Vec3::new(-1.0, -1.0, 5.0), Vec3::new(1.0, -1.0, 5.0), Vec3::new(0.0, 1.0, 5.0)]]);
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let hit = |prim: u32, t: f32| Some(Hit { t, prim, u: 0.0, v: 0.0 });
    let near = hit(0, 2.0);
    assert_eq!(agrees_with_oracle(&soup, &ray, near, near), Ok(()));
    // The far triangle when the near one is in front: a missed surface.
    assert_eq!(agrees_with_oracle(&soup, &ray, near, hit(1, 5.0)), Err("t = 5 (prim 1) is 10485760 ulps behind the oracle's 2 (prim 0)".into()));
    // A distance the primitive does not give: an invented hit.
    assert_eq!(agrees_with_oracle(&soup, &ray, near, hit(0, 2.0000002)), Err("prim 0 reported at t = 2.0000002 but intersects at Some(2.0)".into()));
    // A hit where the oracle sees none, and the reverse.
    assert_eq!(agrees_with_oracle(&soup, &ray, None, near), Err(format!("{near:?} vs oracle None")));
    assert!(agrees_with_oracle(&soup, &ray, near, None).is_err());
    // In front of the oracle's closest: impossible for a correct oracle, rejected.
    assert!(agrees_with_oracle(&soup, &ray, hit(1, 5.0), near).unwrap_err().contains("nearer than the oracle's closest"));
}
