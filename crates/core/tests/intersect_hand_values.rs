//! The ray–triangle and ray–sphere kernels against values worked out by hand: the sheared
//! ray's axes and constants, barycentrics, both ends of the ray's interval, hits behind
//! the origin, and every root of the sphere.

use raylab_core::intersect::{sphere, triangle, triangle_plane_t, ShearedRay};
use raylab_core::{Ray, Vec3};

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

fn sheared(d: Vec3) -> (usize, usize, usize, f32, f32, f32) {
    let s = ShearedRay::new(&Ray::new(Vec3::ZERO, d));
    (s.kx, s.ky, s.kz, s.sx, s.sy, s.sz)
}

#[test]
fn the_sheared_frame_follows_the_dominant_axis_and_keeps_the_winding() {
    // kz is the largest |d| component; kx, ky follow it cyclically, swapped when d[kz] < 0.
    assert_eq!(sheared(v(1.0, 2.0, 4.0)), (0, 1, 2, 0.25, 0.5, 0.25));
    assert_eq!(sheared(v(-4.0, 1.0, 2.0)), (2, 1, 0, -0.5, -0.25, -0.25));
    assert_eq!(sheared(v(1.0, -4.0, 2.0)), (0, 2, 1, -0.25, -0.5, -0.25));
    assert_eq!(sheared(v(4.0, 1.0, -2.0)).2, 0);
    assert_eq!(sheared(v(1.0, 4.0, 2.0)).2, 1);
    // Ties go to the later axis: x = y -> y, x = z -> z, y = z -> z.
    assert_eq!([sheared(v(1.0, 1.0, 0.0)).2, sheared(v(1.0, 0.0, 1.0)).2, sheared(v(0.0, 1.0, 1.0)).2], [1, 2, 2]);
    // The projection of a vertex: (a[kx] - sx·a[kz], a[ky] - sy·a[kz]) with a = p - origin.
    let s = ShearedRay::new(&Ray::new(v(1.0, 1.0, 1.0), v(1.0, 2.0, 4.0)));
    assert_eq!(s.project(v(3.0, 4.0, 5.0)), (1.0, 1.0));
    assert_eq!(s.project(v(1.0, 1.0, 9.0)), (-2.0, -4.0));
}

#[test]
fn barycentrics_and_distance_by_hand() {
    // A right triangle in the plane z = 1 seen from the origin along a slanted ray:
    // the ray (0.2, 0.3, 1)·t meets z = 1 at t = 1, the point (0.2, 0.3) = 0.2·p1 + 0.3·p2.
    let (p0, p1, p2) = (v(0.0, 0.0, 1.0), v(1.0, 0.0, 1.0), v(0.0, 1.0, 1.0));
    let (t, b1, b2) = triangle(&Ray::new(Vec3::ZERO, v(0.2, 0.3, 1.0)), p0, p1, p2).unwrap();
    assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.2).abs() < 1e-6 && (b2 - 0.3).abs() < 1e-6, "{t} {b1} {b2}");
    // Twice as long a direction halves t; the barycentrics do not change.
    let (t, b1, b2) = triangle(&Ray::new(Vec3::ZERO, v(0.4, 0.6, 2.0)), p0, p1, p2).unwrap();
    assert!((t - 0.5).abs() < 1e-6 && (b1 - 0.2).abs() < 1e-6 && (b2 - 0.3).abs() < 1e-6, "{t} {b1} {b2}");
    // Along each dominant axis and sign, the same triangle rotated: the same answers.
    let rot: [fn(Vec3) -> Vec3; 4] = [|p| p, |p| v(p.z, p.x, p.y), |p| v(p.y, p.z, p.x), |p| -p];
    for r in rot {
        let (t, b1, b2) = triangle(&Ray::new(Vec3::ZERO, r(v(0.2, 0.3, 1.0))), r(p0), r(p1), r(p2)).unwrap();
        assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.2).abs() < 1e-6 && (b2 - 0.3).abs() < 1e-6, "{t} {b1} {b2}");
    }
    // Twice as large a triangle (det 4, not 1, where v·(1/det) = v/(1/det)): the same weights.
    let (q1, q2) = (v(2.0, 0.0, 1.0), v(0.0, 2.0, 1.0));
    let (t, b1, b2) = triangle(&Ray::new(Vec3::ZERO, v(0.4, 0.6, 1.0)), p0, q1, q2).unwrap();
    assert!((t - 1.0).abs() < 1e-6 && (b1 - 0.2).abs() < 1e-6 && (b2 - 0.3).abs() < 1e-6, "{t} {b1} {b2}");
    // The corners' weights: p0 (0, 0), p1 (1, 0), p2 (0, 1).
    for (p, w) in [(p0, (0.0, 0.0)), (p1, (1.0, 0.0)), (p2, (0.0, 1.0))] {
        let (_, b1, b2) = triangle(&Ray::new(p + Vec3::Z, -Vec3::Z), p0, p1, p2).unwrap();
        assert_eq!((b1, b2), w, "{p}");
    }
}

#[test]
fn the_interval_is_open_below_and_closed_above() {
    let (p0, p1, p2) = (v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0));
    let down = |t_min, t_max| triangle(&Ray::segment(v(0.0, 0.0, 2.0), -Vec3::Z, t_min, t_max), p0, p1, p2).map(|h| h.0);
    assert_eq!(down(0.0, f32::INFINITY), Some(2.0));
    assert_eq!(down(0.0, 2.0), Some(2.0));
    assert_eq!(down(2.0, 5.0), None);
    assert_eq!(down(1.0, 1.999), None);
    // Behind the origin: no hit, at any distance.
    let up = Ray::new(v(0.0, 0.0, 2.0), Vec3::Z);
    assert_eq!(triangle(&up, p0, p1, p2), None);
    let just_above = Ray::new(v(0.0, 0.0, 1e-3), Vec3::Z);
    assert_eq!(triangle(&just_above, p0, p1, p2), None);
    // A ray that starts on the plane just below and leaves upwards misses; downwards from
    // just above it hits at the height.
    let (t, ..) = triangle(&Ray::new(v(0.0, 0.0, 1e-3), -Vec3::Z), p0, p1, p2).unwrap();
    assert_eq!(t, 1e-3);
    // Outside each of the three edges: a miss.
    for o in [v(0.0, -1.5, 1.0), v(0.8, 0.5, 1.0), v(-0.8, 0.5, 1.0)] {
        assert_eq!(triangle(&Ray::new(o, -Vec3::Z), p0, p1, p2), None, "{o}");
    }
}

#[test]
fn the_double_precision_plane_distance_by_hand() {
    // The plane x + y + z = 3 from the origin along (1, 1, 1): t = 1; along (1, 0, 0): t = 3.
    let (p0, p1, p2) = (v(3.0, 0.0, 0.0), v(0.0, 3.0, 0.0), v(0.0, 0.0, 3.0));
    assert_eq!(triangle_plane_t(&Ray::new(Vec3::ZERO, Vec3::ONE), p0, p1, p2), 1.0);
    assert_eq!(triangle_plane_t(&Ray::new(Vec3::ZERO, Vec3::X), p0, p1, p2), 3.0);
    assert_eq!(triangle_plane_t(&Ray::new(v(1.0, 1.0, -2.0), Vec3::Z), p0, p1, p2), 3.0);
}

#[test]
fn sphere_roots_by_hand() {
    // Centre (1, 2, 3), radius 2; from (1, 2, -3) along +z: roots 4 and 8.
    let (c, r) = (v(1.0, 2.0, 3.0), 2.0);
    let at = |o: Vec3, d: Vec3, t_min: f32, t_max: f32| sphere(&Ray::segment(o, d, t_min, t_max), c, r);
    let o = v(1.0, 2.0, -3.0);
    assert_eq!(at(o, Vec3::Z, 0.0, f32::INFINITY), Some(4.0));
    // The interval: (t_min, t_max], the far root when the near one is cut.
    assert_eq!(at(o, Vec3::Z, 0.0, 4.0), Some(4.0));
    assert_eq!(at(o, Vec3::Z, 4.0, f32::INFINITY), Some(8.0));
    assert_eq!(at(o, Vec3::Z, 5.0, 8.0), Some(8.0));
    assert_eq!(at(o, Vec3::Z, 8.0, f32::INFINITY), None);
    assert_eq!(at(o, Vec3::Z, 0.0, 3.9), None);
    // From the other side (along -z from z = 9): the same roots 4 and 8, in that order.
    assert_eq!(at(v(1.0, 2.0, 9.0), -Vec3::Z, 0.0, f32::INFINITY), Some(4.0));
    // Both roots behind: nothing.
    assert_eq!(at(o, -Vec3::Z, 0.0, f32::INFINITY), None);
    // Off-axis by 1.2 (a 3-4-5 triangle scaled by 0.4): half-chord 1.6, roots 6 ∓ 1.6.
    let t = at(v(2.2, 2.0, -3.0), Vec3::Z, 0.0, f32::INFINITY).unwrap();
    assert!((t - 4.4).abs() < 1e-5, "{t}");
    let t = at(v(2.2, 2.0, -3.0), Vec3::Z, 5.0, f32::INFINITY).unwrap();
    assert!((t - 7.6).abs() < 1e-5, "{t}");
    // A direction of length 4: t in units of it.
    assert_eq!(at(o, 4.0 * Vec3::Z, 0.0, f32::INFINITY), Some(1.0));
    // ... and its far root, 2, when the interval cuts the near one.
    assert_eq!(at(o, 4.0 * Vec3::Z, 1.0, f32::INFINITY), Some(2.0));
}

/// Where single precision rounds an edge function to exactly 0, its sign comes from double
/// precision. Here the ray (the origin, along +z) passes outside the edge p1–p2 by about
/// 2⁻²⁵: exactly, `cx·by − cy·bx = −(1 + 2⁻¹¹) + (1 + 2⁻¹²)² = −2⁻²⁴`, but
/// `(1 + 2⁻¹²)²` rounds to `1 + 2⁻¹¹` (a tie, to even) and the f32 difference is 0, which
/// alone would count as inside. Each rotation of the corners puts that edge in another of
/// the three edge functions.
#[test]
fn an_edge_function_rounded_to_zero_takes_its_sign_from_double_precision() {
    let (e11, e12) = (2f32.powi(-11), 2f32.powi(-12));
    let (p0, p1, p2) = (v(-1.0, 1.0, 1.0), v(1.0, 1.0 + e12, 1.0), v(-(1.0 + e12), -(1.0 + e11), 1.0));
    assert_eq!((1.0 + e12) * (1.0 + e12), 1.0 + e11, "the product this test relies on rounds");
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    for (a, b, c) in [(p0, p1, p2), (p1, p2, p0), (p2, p0, p1)] {
        assert_eq!(triangle(&ray, a, b, c), None, "{a} {b} {c}");
    }
    // The mirror case: inside by 2⁻²⁵, `(1 + 2⁻¹²)² − (1 + 2⁻¹¹) = +2⁻²⁴` exactly, 0 in f32:
    // a hit in every rotation.
    let (q0, q1, q2) = (v(-1.0, 1.0, 1.0), v(1.0 + e12, 1.0, 1.0), v(-(1.0 + e11), -(1.0 + e12), 1.0));
    for (a, b, c) in [(q0, q1, q2), (q1, q2, q0), (q2, q0, q1)] {
        assert_eq!(triangle(&ray, a, b, c).map(|h| h.0), Some(1.0), "{a} {b} {c}");
    }
    // Moved inside the edge by 2⁻²⁰ (far more than the rounding), the ray hits, in every rotation.
    let inside = Ray::new(v(-(2f32.powi(-20)), 2f32.powi(-20), 0.0), Vec3::Z);
    for (a, b, c) in [(p0, p1, p2), (p1, p2, p0), (p2, p0, p1)] {
        assert_eq!(triangle(&inside, a, b, c).map(|h| h.0), Some(1.0), "{a} {b} {c}");
    }
}

/// A point outside a triangle is outside one edge (one edge function of the wrong sign) or
/// beyond a corner (two of them); with the winding reversed every sign flips. Each of the
/// twelve cases, with each of the three edge functions as the odd one out, is a miss.
#[test]
fn every_outside_region_in_both_windings_is_a_miss() {
    let (p0, p1, p2) = (v(-1.0, -1.0, 0.0), v(1.0, -1.0, 0.0), v(0.0, 1.0, 0.0));
    // Across the edges p0p1, p1p2, p2p0, and beyond the corners p0, p1, p2.
    let outside = [v(0.0, -1.5, 1.0), v(0.8, 0.5, 1.0), v(-0.8, 0.5, 1.0), v(-1.5, -1.2, 1.0), v(1.5, -1.2, 1.0), v(0.0, 1.5, 1.0)];
    for o in outside {
        let ray = Ray::new(o, -Vec3::Z);
        assert_eq!(triangle(&ray, p0, p1, p2), None, "{o}");
        assert_eq!(triangle(&ray, p0, p2, p1), None, "{o}, reversed");
    }
    // Exactly on each edge and corner (an edge function exactly 0, the others of one sign),
    // in both windings: hits.
    for o in [v(0.0, -1.0, 1.0), v(0.5, 0.0, 1.0), v(-0.5, 0.0, 1.0), v(-1.0, -1.0, 1.0), v(1.0, -1.0, 1.0), v(0.0, 1.0, 1.0)] {
        let ray = Ray::new(o, -Vec3::Z);
        assert_eq!(triangle(&ray, p0, p1, p2).map(|h| h.0), Some(1.0), "{o}");
        assert_eq!(triangle(&ray, p0, p2, p1).map(|h| h.0), Some(1.0), "{o}, reversed");
    }
    // Inside, in both windings and from both sides: hits.
    for (o, d) in [(v(0.0, -0.2, 1.0), -Vec3::Z), (v(0.0, -0.2, -1.0), Vec3::Z)] {
        assert_eq!(triangle(&Ray::new(o, d), p0, p1, p2).map(|h| h.0), Some(1.0));
        assert_eq!(triangle(&Ray::new(o, d), p0, p2, p1).map(|h| h.0), Some(1.0));
    }
}

/// From just outside a sphere, the near root is the difference of two nearly equal numbers
/// in the textbook form (`-b - √disc`: about 0.8 minus 0.8 here), which keeps only a few
/// bits of it; the kernel's form (`c / q`, q of the sign of `-b`) divides instead. Origin
/// 2⁻¹⁰ outside the unit sphere on the -z axis, so that `c = |o|² − 1 = 2⁻⁹ + 2⁻²⁰` is
/// exact, and slanted directions, so that `b` is not. Reference: the root in f64.
#[test]
fn the_near_root_from_just_outside_keeps_its_precision() {
    let origin = v(0.0, 0.0, -(1.0 + 2f32.powi(-10)));
    for degrees in [10.0f32, 25.0, 37.0, 50.0, 60.0] {
        let (sin, cos) = degrees.to_radians().sin_cos();
        let d = v(0.0, sin, cos);
        let t = sphere(&Ray::new(origin, d), Vec3::ZERO, 1.0).unwrap();
        let (o64, d64) = (origin.as_dvec3(), d.as_dvec3());
        let (a, half_b, c) = (d64.length_squared(), o64.dot(d64), o64.length_squared() - 1.0);
        let exact = c / (-half_b + (half_b * half_b - a * c).sqrt());
        assert!((t as f64 - exact).abs() <= 1e-6 * exact, "{degrees}°: t {t} against {exact}");
    }
}
