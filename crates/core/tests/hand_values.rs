//! Hand-computed values for the small helpers of `raylab-core` (written for survivors of
//! mutation testing, docs/testing.md): every expected value is worked out in the test.

use raylab_core::color::luminance;
use raylab_core::offset::{gamma, offset_ray_origin};
use raylab_core::{Ray, Rgb, Vec3};

#[test]
fn rec709_luminance() {
    // Rec. 709 / sRGB primaries: Y = 0.2126 R + 0.7152 G + 0.0722 B; white has Y = 1.
    assert_eq!(luminance(Rgb::new(1.0, 0.0, 0.0)), 0.2126);
    assert_eq!(luminance(Rgb::new(0.0, 1.0, 0.0)), 0.7152);
    assert_eq!(luminance(Rgb::new(0.0, 0.0, 1.0)), 0.0722);
    assert!((luminance(Rgb::ONE) - 1.0).abs() < 1e-6);
    assert!((luminance(Rgb::new(2.0, 0.5, 4.0)) - (0.4252 + 0.3576 + 0.2888)).abs() < 1e-6);
}

#[test]
fn gamma_is_higham_bound() {
    // γₙ = nu / (1 − nu), u = 2⁻²⁴ (half an ulp of 1 in f32).
    for n in [1u32, 3, 5, 7] {
        let u = (2.0f64).powi(-24);
        let expected = n as f64 * u / (1.0 - n as f64 * u);
        // nu and 1 − nu are exact in f32 and the division is correctly rounded, so γₙ is
        // exactly the f32 nearest the true value (it differs from nu by ~nu² already).
        assert_eq!(gamma(n), expected as f32, "γ{n}");
        assert_ne!(gamma(n), (n as f64 * u) as f32, "γ{n} is not nu");
    }
}

#[test]
fn offset_moves_by_the_projected_error_then_one_ulp() {
    // No error: only the one-ulp push, along the normal's non-zero components only.
    let p = Vec3::new(1.0, 2.0, 3.0);
    let o = offset_ray_origin(p, Vec3::ZERO, Vec3::Z, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(o, Vec3::new(1.0, 2.0, 3.0f32.next_up()), "a tangent direction keeps the normal's side");
    let o = offset_ray_origin(p, Vec3::ZERO, Vec3::Z, Vec3::new(0.0, 0.3, -1.0));
    assert_eq!(o, Vec3::new(1.0, 2.0, 3.0f32.next_down()), "a direction below flips the normal");
    // With an error box (0.1, 0.2, 0.3) and n = (0, 0.6, 0.8): d = 0.2·0.6 + 0.3·0.8 = 0.36.
    let n = Vec3::new(0.0, 0.6, 0.8);
    let o = offset_ray_origin(p, Vec3::new(0.1, 0.2, 0.3), n, n);
    let moved = p + 0.36 * n;
    assert_eq!(o.x, 1.0);
    assert!((o.y - moved.y.next_up()).abs() <= 2.0 * f32::EPSILON * 3.0 && o.y > moved.y - 1e-6, "{o} vs {moved}");
    assert!((o.z - moved.z.next_up()).abs() <= 2.0 * f32::EPSILON * 4.0, "{o} vs {moved}");
    // Negative normal components move down.
    let o = offset_ray_origin(p, Vec3::ZERO, -Vec3::X, -Vec3::X);
    assert_eq!(o, Vec3::new(1.0f32.next_down(), 2.0, 3.0));
}

#[test]
fn ray_points_and_validity() {
    let r = Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, -1.0, 2.0));
    assert_eq!(r.at(2.0), Vec3::new(2.0, 0.0, 7.0));
    assert_eq!(r.at(0.0), r.origin);
    assert!(r.is_valid());
    assert!(!Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X).is_valid(), "NaN origin");
    assert!(!Ray::new(Vec3::ZERO, Vec3::new(0.0, f32::INFINITY, 0.0)).is_valid(), "infinite direction");
    assert!(!Ray::new(Vec3::ZERO, Vec3::ZERO).is_valid(), "zero direction");
    assert!(!Ray::segment(Vec3::ZERO, Vec3::X, f32::NAN, 1.0).is_valid(), "NaN t_min");
    assert!(!Ray::segment(Vec3::ZERO, Vec3::X, 0.0, f32::NAN).is_valid(), "NaN t_max");
    assert!(Ray::segment(Vec3::ZERO, Vec3::X, 0.5, f32::INFINITY).is_valid());
}

#[test]
fn distributions_at_the_edges_of_the_unit_interval() {
    use raylab_core::{Distribution1D, Distribution2D, Vec2};
    // Weights (1, 3): densities 0.5 and 1.5 (mean 2); x = 1 belongs to the last step.
    let d = Distribution1D::new(&[1.0, 3.0]);
    assert!(!d.is_empty() && d.len() == 2);
    assert_eq!((d.pdf(0.0), d.pdf(0.49), d.pdf(0.5), d.pdf(1.0)), (0.5, 0.5, 1.5, 1.5));
    // CDF (0, 1/4, 1): u = 0.25 + 0.75·0.5 is the middle of the second step.
    let (x, pdf, step) = d.sample(0.625);
    assert_eq!((step, pdf), (1, 1.5));
    assert!((x - 0.75).abs() < 1e-6, "{x}");
    // u = 1 (outside [0, 1), from rounding elsewhere) still lands inside [0, 1).
    let (x, pdf, step) = d.sample(1.0);
    assert_eq!((step, pdf), (1, 1.5));
    assert!(x < 1.0 && x > 0.999, "{x}");
    // A zero-width last step reached only by clamping: its middle, not NaN.
    let (x, pdf, step) = Distribution1D::new(&[1.0, 0.0]).sample(1.0);
    assert_eq!((x, pdf, step), (0.75, 0.0, 1));
    // 2 × 2 weights (1, 3 / 0, 4): rows' integrals 2 and 2, marginal densities 1 and 1.
    let d2 = Distribution2D::new(&[1.0, 3.0, 0.0, 4.0], 2, 2);
    assert_eq!(d2.integral(), 2.0);
    assert_eq!(d2.pdf(Vec2::new(0.2, 0.2)), 0.5);
    assert_eq!(d2.pdf(Vec2::new(1.0, 1.0)), 2.0);
    assert_eq!(d2.pdf(Vec2::new(0.2, 1.0)), 0.0);
}

#[test]
fn pcg32_below_is_lemires_method() {
    use raylab_core::Pcg32;
    // Lemire 2019, "Fast random integer generation in an interval", written out here and
    // fed the same 32-bit stream: the results must match draw for draw, rejections included
    // (n = 3·2³⁰ rejects a quarter of the draws).
    let (mut a, mut b) = (Pcg32::new(5, 6), Pcg32::new(5, 6));
    let mut rejected = 0;
    for k in 0..20_000u32 {
        let n = [1, 3, 10, 1000, 3 << 30, u32::MAX][k as usize % 6];
        let mut m = b.next_u32() as u64 * n as u64;
        let threshold = (u32::MAX - n + 1) % n; // 2³² mod n
        while (m as u32) < threshold {
            rejected += 1;
            m = b.next_u32() as u64 * n as u64;
        }
        let got = a.below(n);
        assert_eq!(got, (m >> 32) as u32, "draw {k}, n = {n}");
        assert!(got < n);
    }
    assert!(rejected > 500, "{rejected}");
}

#[test]
fn mix64_is_splitmix64s_finaliser() {
    // SplitMix64 from seed 0: the first output is mix64(0x9E3779B97F4A7C15) = 0xE220A8397B1DCDAF
    // (Steele, Lea & Flood 2014; the reference sequence of Vigna's splitmix64.c).
    assert_eq!(raylab_core::rng::mix64(0x9E37_79B9_7F4A_7C15), 0xE220_A839_7B1D_CDAF);
}

#[test]
fn transforms_by_hand() {
    use raylab_core::{Aabb, Transform};
    let t = Transform::translate(Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(t.point(Vec3::ONE), Vec3::new(2.0, 3.0, 4.0));
    assert_eq!(t.vector(Vec3::new(0.5, -1.0, 2.0)), Vec3::new(0.5, -1.0, 2.0), "vectors ignore translation");
    assert!(Transform::IDENTITY.is_identity() && !t.is_identity());
    // A stretch by 2 along x: normals by the inverse transpose, (1, 1, 0) → (0.5, 1, 0).
    let s = Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap();
    assert_eq!(s.vector(Vec3::new(1.0, 1.0, 0.0)), Vec3::new(2.0, 1.0, 0.0));
    assert_eq!(s.normal(Vec3::new(1.0, 1.0, 0.0)), Vec3::new(0.5, 1.0, 0.0));
    assert!(!s.swaps_handedness());
    assert!(Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap().swaps_handedness());
    assert!(Transform::scale(Vec3::new(0.0, 1.0, 1.0)).is_none(), "singular");
    // 90° about +z (right-handed) takes x to y.
    let r = Transform::rotate(Vec3::Z, 90.0).unwrap();
    assert!((r.point(Vec3::X) - Vec3::Y).length() < 1e-6);
    assert!(Transform::rotate(Vec3::ZERO, 90.0).is_none());
    // The unit cube turned 45° about z: x in ±√½, y in [0, √2], z unchanged.
    let b = Transform::rotate(Vec3::Z, 45.0).unwrap().bounds(&Aabb::new(Vec3::ZERO, Vec3::ONE));
    let h = 0.5f32.sqrt();
    assert!((b.min - Vec3::new(-h, 0.0, 0.0)).length() < 1e-6 && (b.max - Vec3::new(h, 2.0 * h, 1.0)).length() < 1e-6, "{b:?}");
    // An asymmetric box under a translation: each corner moves, nothing else.
    let b = t.bounds(&Aabb::new(Vec3::new(0.0, -1.0, 2.0), Vec3::new(0.5, 1.0, 4.0)));
    assert_eq!((b.min, b.max), (Vec3::new(1.0, 1.0, 5.0), Vec3::new(1.5, 3.0, 7.0)));
    assert!(t.bounds(&Aabb::EMPTY).is_empty());
    // About x, every corner counts: the box of the eight transformed corners, listed here.
    let rx = Transform::rotate(Vec3::new(1.0, 0.2, 0.0), 50.0).unwrap();
    let (lo, hi) = (Vec3::new(0.0, -1.0, 2.0), Vec3::new(0.5, 1.0, 4.0));
    let corners = [(lo.x, lo.y, lo.z), (hi.x, lo.y, lo.z), (lo.x, hi.y, lo.z), (hi.x, hi.y, lo.z), (lo.x, lo.y, hi.z), (hi.x, lo.y, hi.z), (lo.x, hi.y, hi.z), (hi.x, hi.y, hi.z)];
    let (mut min, mut max) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (x, y, z) in corners {
        let p = rx.point(Vec3::new(x, y, z));
        (min, max) = (min.min(p), max.max(p));
    }
    let b = rx.bounds(&Aabb::new(lo, hi));
    assert_eq!((b.min, b.max), (min, max));
    // Singular means |det| below 1e-30: a scale of exactly 1e-30 is still invertible.
    assert!(Transform::scale(Vec3::new(1e-30, 1.0, 1.0)).is_some());
}

#[test]
fn aabb_measures_by_hand() {
    use raylab_core::Aabb;
    // A 1 × 2 × 4 box from (1, −1, 2): areas 2, 8, 4 per face pair.
    let b = Aabb::new(Vec3::new(1.0, -1.0, 2.0), Vec3::new(2.0, 1.0, 6.0));
    assert_eq!((b.half_area(), b.surface_area(), b.volume()), (14.0, 28.0, 8.0));
    assert_eq!((b.extent(), b.centroid()), (Vec3::new(1.0, 2.0, 4.0), Vec3::new(1.5, 0.0, 4.0)));
    assert_eq!(b.max_axis(), 2);
    assert_eq!(Aabb::new(Vec3::ZERO, Vec3::new(3.0, 2.0, 1.0)).max_axis(), 0);
    assert_eq!(Aabb::new(Vec3::ZERO, Vec3::new(1.0, 3.0, 2.0)).max_axis(), 1);
    assert_eq!((Aabb::EMPTY.half_area(), Aabb::EMPTY.surface_area()), (0.0, 0.0));
    // Closed box: faces belong to it.
    assert!(b.contains(Vec3::new(1.0, 1.0, 6.0)) && b.contains(Vec3::new(1.5, 0.0, 3.0)));
    assert!(!b.contains(Vec3::new(0.99, 0.0, 3.0)) && !b.contains(Vec3::new(1.5, 0.0, 6.01)));
    assert!(b.contains_box(&Aabb::new(Vec3::new(1.0, 0.0, 3.0), Vec3::new(2.0, 1.0, 4.0))));
    assert!(!b.contains_box(&Aabb::new(Vec3::new(1.0, 0.0, 3.0), Vec3::new(2.5, 1.0, 4.0))));
    assert!(b.contains_box(&Aabb::EMPTY));
    // Relative position: 0 at min, 1 at max; a flat axis gives 0.
    assert_eq!(b.offset(Vec3::new(1.5, 1.0, 3.0)), Vec3::new(0.5, 1.0, 0.25));
    let flat = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 4.0));
    assert_eq!(flat.offset(Vec3::new(1.0, 0.0, 1.0)), Vec3::new(0.5, 0.0, 0.25));
}
