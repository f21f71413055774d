//! Regression: large triangles were missed by the watertight kernel (issue 12). A two-triangle
//! floor quad of ±1e6 missed 27 % of rays at 30-60° to it and one of ±3e6 all of them: the
//! conservative error bound on `t` grows with the vertices' distance from the ray origin, so a
//! near hit on a huge triangle fell below it and was rejected as a possible self-intersection.

use raylab_core::intersect::{triangle, triangle_plane_t};
use raylab_core::{Pcg32, Ray, Vec3};

/// Oblique rays (30-60° to the floor) from heights 1e-5..10 times the unit (at most a
/// quarter of the quad), over the middle
/// of the quad, aimed at the quad of half-size `s` at y = 0 made of two triangles.
fn misses(s: f32, unit: f32) -> (usize, usize) {
    let quad = [
        [Vec3::new(-s, 0.0, -s), Vec3::new(s, 0.0, -s), Vec3::new(s, 0.0, s)],
        [Vec3::new(-s, 0.0, -s), Vec3::new(s, 0.0, s), Vec3::new(-s, 0.0, s)],
    ];
    let mut rng = Pcg32::new(7, 3);
    let (mut missed, n) = (0, 2000);
    for _ in 0..n {
        // Low enough that the hit stays on the quad (it travels at most 1.8 h sideways).
        let h = (unit * 10f32.powf(rng.next_f32() * 6.0 - 5.0)).min(0.25 * s);
        let elevation = (30.0 + 30.0 * rng.next_f32()).to_radians();
        let azimuth = rng.next_f32() * std::f32::consts::TAU;
        let dir = Vec3::new(elevation.cos() * azimuth.cos(), -elevation.sin(), elevation.cos() * azimuth.sin());
        let origin = Vec3::new((rng.next_f32() - 0.5) * s, h, (rng.next_f32() - 0.5) * s);
        let ray = Ray::new(origin, dir);
        let hits: Vec<f32> = quad.iter().filter_map(|t| triangle(&ray, t[0], t[1], t[2]).map(|h| h.0)).collect();
        match hits.first() {
            None => missed += 1,
            Some(&t) => {
                // The distance is right to a few ulps of the scene's size (the coordinates'
                // precision), against the double-precision plane distance.
                let exact = triangle_plane_t(&ray, quad[0][0], quad[0][1], quad[0][2]);
                assert!((t as f64 - exact).abs() < 1e-6 * (s as f64 + exact), "size {s}: t {t} against {exact}");
            }
        }
    }
    (missed, n)
}

#[test]
fn quads_from_1e_minus_4_to_1e13_are_hit_by_every_oblique_ray() {
    for s in [1e-4f32, 1e-2, 1.0, 1e2, 1e4, 1e6, 3e6, 1e7, 1e10, 1e12, 1e13] {
        // Heights relative to the quad's own size, and to the unit size while that is
        // above 1e-12 of the quad (double precision's own bound on t is ~1e-15 of it).
        // From 1e12 the kernel's single-precision `t` overflowed: rays missed.
        for unit in if s <= 1e7 { vec![s, 1.0] } else { vec![s] } {
            let (missed, n) = misses(s, unit);
            assert_eq!(missed, 0, "quad ±{s}, heights around {unit}: {missed} of {n} rays missed");
        }
    }
}

#[test]
fn rays_leaving_a_large_quad_do_not_hit_it_again() {
    // A ray leaving the ±1e6 floor upwards from a point offset as `offset_ray_origin` does
    // (by the error bound of the point, then one ulp) must not find the floor again, in single
    // or double precision.
    let s = 1e6f32;
    let (a, b, c) = (Vec3::new(-s, 0.0, -s), Vec3::new(s, 0.0, -s), Vec3::new(s, 0.0, s));
    for x in [123.25f32, 5.0e5, -2.5e5] {
        let origin = Vec3::new(x, f32::from_bits(1), -x * 0.5);
        let up = Ray::new(origin, Vec3::new(0.3, 0.5, -0.8).normalize());
        assert_eq!(triangle(&up, a, b, c), None, "x = {x}");
    }
}
