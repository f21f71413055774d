//! Uniform sampling of the solid angle subtended by a rectangle (Ureña, Fajardo & King
//! 2013, "An Area-Preserving Parametrization for Spherical Rectangles"), following
//! pbrt-v4's `SampleSphericalRectangle`. Every direction towards the light is equally
//! likely, which removes the `cos θ_l / d²` variance of area sampling near large lights.

use std::f32::consts::PI;

use raylab_core::{Vec2, Vec3};

/// A rectangle `corner + s·ex + t·ey`, `s, t ∈ [0, 1]`, seen from a point.
pub(super) struct SphericalRect {
    /// Solid angle subtended (steradians).
    pub solid_angle: f32,
    x: Vec3,
    y: Vec3,
    z: Vec3,
    x0: f32,
    x1: f32,
    y0: f32,
    y1: f32,
    z0: f32,
    b0: f32,
    b1: f32,
    g2_plus_g3: f32,
}

/// Solid angles below this are sampled by area instead (the parametrisation loses
/// precision, and area sampling is then as good).
pub(super) const MIN_SOLID_ANGLE: f32 = 1e-4;

impl SphericalRect {
    /// The rectangle as seen from `p`; `ex` and `ey` must be orthogonal.
    pub fn new(p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Self {
        let (exl, eyl) = (ex.length(), ey.length());
        let x = ex / exl;
        let y = ey / eyl;
        let mut z = x.cross(y);
        let d = corner - p;
        let mut z0 = d.dot(z);
        // Flip z so that it points away from the rectangle (z0 < 0).
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + exl, y0 + eyl);
        // The corners' directions, scaled to about unit size: the normals below need only
        // directions, and the cross products of unscaled corners square their lengths,
        // which overflows f32 beyond ~1e19 (a rect light in a scene of scale 1e10 rendered
        // black: |v × v|² = 1e40 = ∞, normalised to zero) and underflows below ~1e-19.
        let size = x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()).max(z0.abs());
        let k = if size > 0.0 && size.is_finite() { 1.0 / size } else { 1.0 };
        let v00 = Vec3::new(x0, y0, z0) * k;
        let v01 = Vec3::new(x0, y1, z0) * k;
        let v10 = Vec3::new(x1, y0, z0) * k;
        let v11 = Vec3::new(x1, y1, z0) * k;
        let n0 = v00.cross(v10).normalize_or_zero();
        let n1 = v10.cross(v11).normalize_or_zero();
        let n2 = v11.cross(v01).normalize_or_zero();
        let n3 = v01.cross(v00).normalize_or_zero();
        let angle = |a: Vec3, b: Vec3| a.dot(b).clamp(-1.0, 1.0).acos();
        let (g0, g1, g2, g3) = (angle(-n0, n1), angle(-n1, n2), angle(-n2, n3), angle(-n3, n0));
        let solid_angle = g0 + g1 + g2 + g3 - 2.0 * PI;
        Self { solid_angle, x, y, z, x0, x1, y0, y1, z0, b0: n0.z, b1: n2.z, g2_plus_g3: g2 + g3 }
    }

    /// The point on the rectangle in direction `u` of the uniform solid-angle density
    /// `1 / solid_angle`, relative to the viewing point.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        // pbrt's `u·(g0 + g1 - 2π) + (u - 1)·(g2 + g3)`.
        let au = u.x * self.solid_angle - self.g2_plus_g3;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        // |cu| is kept below 1 so that `xu` stays finite (pbrt-v4's clamp; see the survivors
        // in docs/testing.md for why its exact bound does not matter).
        let cu = (1.0 / (fu * fu + self.b0 * self.b0).sqrt()).copysign(fu).clamp(-1.0 + 1e-7, 1.0 - 1e-7);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        let dd = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (dd * dd + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (dd * dd + self.y1 * self.y1).sqrt();
        let hv = h0 + u.y * (h1 - h0);
        // pbrt-v4 takes `yv = y1` where `hv² ≥ 1 − 10⁻⁶`: right for hv ≈ +1, but for hv ≈ −1
        // (an edge y0 more than ~10³·dd below the point) the far end instead of y0, so the first
        // ~10⁻⁶ of u.y jumped across the rectangle. Without the cut, |hv| at (or, rounded, past)
        // 1 makes the quotient ±∞ with hv's sign (dd ≥ |z0| > 0), which the clamp puts on the
        // right edge; nearer, the quotient keeps f32's precision (a few % at 10³·dd).
        let yv = (hv * dd) / (1.0 - hv * hv).max(0.0).sqrt();
        xu * self.x + yv.clamp(self.y0, self.y1) * self.y + self.z0 * self.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angle_of_a_square_seen_from_its_axis() {
        // A square of side 2a at distance d subtends 4·asin(a² / (a² + d²)).
        let (a, d) = (0.5f32, 2.0f32);
        let r = SphericalRect::new(Vec3::ZERO, Vec3::new(-a, d, -a), Vec3::new(2.0 * a, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0 * a));
        let expected = 4.0 * (a * a / (a * a + d * d)).asin();
        assert!((r.solid_angle - expected).abs() < 1e-5, "{} against {expected}", r.solid_angle);
    }

    #[test]
    fn solid_angle_does_not_depend_on_the_scene_scale() {
        // The same configuration scaled by 1e-12..1e15: the solid angle is scale-free.
        let at = |s: f32| SphericalRect::new(Vec3::splat(0.3) * s, Vec3::new(-0.5, 2.0, -0.5) * s, Vec3::new(1.0, 0.0, 0.0) * s, Vec3::new(0.0, 0.0, 1.0) * s).solid_angle;
        let unit = at(1.0);
        assert!(unit > 0.1, "{unit}");
        for s in [1e-12f32, 1e-10, 1e-5, 1e5, 1e9, 1e10, 1e12, 1e15] {
            assert!((at(s) - unit).abs() <= 1e-4 * unit, "scale {s}: {} against {unit}", at(s));
        }
    }

    /// Solid angle of the rectangle `[x0, x1] × [y0, y1]` in a plane at distance `d` from the
    /// point, the foot of the perpendicular at the plane's origin, in f64: by inclusion and
    /// exclusion of the four rectangles with a corner at the foot, of which `[0, x] × [0, y]`
    /// subtends `atan(x·y / (d·√(x² + y² + d²)))` (odd in x and in y, so the signs take care
    /// of feet outside the rectangle).
    fn rect_solid_angle(x0: f64, x1: f64, y0: f64, y1: f64, d: f64) -> f64 {
        let f = |x: f64, y: f64| (x * y / (d * (x * x + y * y + d * d).sqrt())).atan();
        f(x1, y1) - f(x0, y1) - f(x1, y0) + f(x0, y0)
    }

    #[test]
    fn solid_angle_of_cube_faces_and_off_axis_rectangles() {
        // A cube face seen from the centre is a sixth of the sphere, 4π/6; seen from one of the
        // four vertices not on it, a third of the eighth of the sphere that corner looks into,
        // π/6 (the side-1 square at distance 1 with the foot at its corner: atan(1/√3) = π/6).
        let face = |p: Vec3| SphericalRect::new(p, Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)).solid_angle;
        assert!((face(Vec3::splat(0.5)) - 4.0 * PI / 6.0).abs() < 2e-6, "{}", face(Vec3::splat(0.5)));
        for v in [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)] {
            assert!((face(v) - PI / 6.0).abs() < 2e-6, "from {v}: {}", face(v));
        }
        // A 2 × 0.7 rectangle, tilted out of the axes, whose plane's foot (at distance 0.9 on
        // either side) lies outside it: local x in [0.3, 2.3], y in [-0.4, 0.3]. Edges of
        // different lengths and a corner away from the foot catch swapped or misplaced edges.
        let (ux, uy) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 1.0, 0.0));
        let n = ux.cross(uy);
        let p = Vec3::new(-1.0, 2.0, 0.5);
        for side in [0.9f32, -0.9] {
            let corner = p + 0.3 * ux - 0.4 * uy + side * n;
            let expected = rect_solid_angle(0.3, 2.3, -0.4, 0.3, 0.9);
            for (ex, ey, c) in [(2.0 * ux, 0.7 * uy, corner), (0.7 * uy, 2.0 * ux, corner), (-2.0 * ux, 0.7 * uy, corner + 2.0 * ux)] {
                let got = SphericalRect::new(p, c, ex, ey).solid_angle;
                assert!((got as f64 - expected).abs() < 1e-5, "side {side}, edges {ex} {ey}: {got} against {expected}");
            }
        }
        // Nearly a half space: a 2000 × 2000 square at distance 1 (its four angles are near π,
        // where f32's acos keeps ~10⁻⁴).
        let big = SphericalRect::new(Vec3::ZERO, Vec3::new(-1e3, -1e3, -1.0), Vec3::new(2e3, 0.0, 0.0), Vec3::new(0.0, 2e3, 0.0)).solid_angle;
        let expected = rect_solid_angle(-1e3, 1e3, -1e3, 1e3, 1.0);
        assert!((big as f64 - expected).abs() < 3e-4 && expected > 2.0 * std::f64::consts::PI - 1e-2, "{big} against {expected}");
    }

    /// The point `sample(u)` in the rectangle's own coordinates (s, t) in [0, 1]², for the
    /// rectangle `corner + s·ex + t·ey` seen from `p`.
    fn sample_st(p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3, u: Vec2) -> (f32, f32) {
        let q = p + SphericalRect::new(p, corner, ex, ey).sample(u);
        ((q - corner).dot(ex) / ex.length_squared(), (q - corner).dot(ey) / ey.length_squared())
    }

    /// Rectangles seen from the origin at distance 1 below them (plane z = 1), ordinary and
    /// reaching 10⁴ distances along y: (corner, ex, ey). (Along x, f32 cannot place points
    /// beyond ~10³ distances: see the survivors of `:73` in docs/testing.md.)
    fn long_rectangles() -> [(Vec3, Vec3, Vec3); 4] {
        [
            (Vec3::new(-0.7, -0.4, 1.0), Vec3::new(1.5, 0.0, 0.0), Vec3::new(0.0, 1.2, 0.0)),
            (Vec3::new(-100.0, -1e4, 1.0), Vec3::new(200.0, 0.0, 0.0), Vec3::new(0.0, 2e4, 0.0)),
            // Far below the point in y (the edge y0 = −10⁴), 1 above.
            (Vec3::new(-1.0, -1e4, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1e4 + 1.0, 0.0)),
            // Off to one side in x, from 0.5 to 3000.5 above in y.
            (Vec3::new(-50.0, 0.5, 1.0), Vec3::new(130.0, 0.0, 0.0), Vec3::new(0.0, 3e3, 0.0)),
        ]
    }

    #[test]
    fn the_unit_squares_edges_map_to_the_rectangles_edges() {
        // The parametrisation's u.x is the fraction of the solid angle left of the point's
        // column, and u.y that of the column below the point: u = 0 is the rectangle's first
        // edge whatever its extent, and u = 1 − 2⁻²⁴ the opposite edge where less than 2⁻²⁴ of
        // the solid angle lies within 10⁻³ of it: along x here (at most 130 distances), and
        // along y on the ordinary rectangle. (A column's last 2⁻²⁴ starts ~2000·dd out: along
        // a column 10⁴ long, u.y = 1 − 2⁻²⁴ is not its end.)
        let one = 1.0 - f32::EPSILON / 2.0;
        for (i, (corner, ex, ey)) in long_rectangles().into_iter().enumerate() {
            for v in [0.0, 0.25, 0.5, 0.75, one] {
                let (s, _) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(0.0, v));
                assert!(s.abs() < 1e-3, "{corner} {ex} {ey}: u = (0, {v}) at s = {s}");
                let (s, _) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(one, v));
                assert!((s - 1.0).abs() < 1e-3, "{corner} {ex} {ey}: u = (1, {v}) at s = {s}");
                let (_, t) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(v, 0.0));
                assert!(t.abs() < 1e-3, "{corner} {ex} {ey}: u = ({v}, 0) at t = {t}");
                let (_, t) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(v, one));
                assert!(i > 0 || (t - 1.0).abs() < 1e-3, "{corner} {ex} {ey}: u = ({v}, 1) at t = {t}");
            }
        }
    }

    #[test]
    fn long_rectangles_map_u_monotonically_onto_the_rectangle() {
        // Both coordinates are inverse CDFs: the point moves the same way as u, never back,
        // including u within 10⁻⁷ of either end, where a rectangle 10⁴ distances long puts
        // points more than 10³ distances away.
        let mut us = vec![0.0f32, 1e-9, 1e-8, 3e-8, 1e-7, 2e-7, 5e-7, 1e-6, 1e-5, 1e-4, 1e-3, 0.01, 0.1, 0.5, 0.9, 0.99];
        us.extend([1e-3f32, 1e-4, 1e-5, 1e-6, 5e-7, 2e-7, 1e-7].map(|e| 1.0 - e));
        us.push(1.0 - f32::EPSILON / 2.0);
        for (corner, ex, ey) in long_rectangles() {
            for w in [0.01f32, 0.5, 0.99] {
                let mut prev = (-1.0f32, -1.0f32);
                for &v in &us {
                    let (s, _) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(v, w));
                    let (_, t) = sample_st(Vec3::ZERO, corner, ex, ey, Vec2::new(w, v));
                    assert!(s >= prev.0 - 1e-6 && t >= prev.1 - 1e-6, "{corner} {ex} {ey}: at {v} (other {w}) s, t = {s}, {t} after {prev:?}");
                    prev = (s, t);
                }
            }
        }
    }

    #[test]
    fn a_column_is_sampled_uniformly_in_the_sine_of_elevation() {
        // Within a column at horizontal distance dd, the solid angle of [y0, y] is
        // ∝ ∫ dd dy / (dd² + y²)^(3/2) = (h(y) − h(y0)) / dd with h(y) = y / √(dd² + y²): u.y is
        // that fraction of the column's. The rectangle [−1, 1] × [−10⁴, 1] at distance 1 is
        // symmetric about x = 0, so u.x = 1/2 is the column x = 0, dd = 1. Points 1500 below,
        // beyond the old cut at hv² = 1 − 10⁻⁶ (|y| ≈ 10³), came out at the top edge, y1.
        let (corner, ex, ey) = (Vec3::new(-1.0, -1e4, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 1e4 + 1.0, 0.0));
        let h = |y: f64| y / (1.0 + y * y).sqrt();
        let (h0, h1) = (h(-1e4), h(1.0));
        // f32 resolves hv near −1 to ~6·10⁻⁸ of the ~2·10⁻⁷ that separates y = −1500 from
        // the end: a loose tolerance there, tight ones nearer.
        for (y, tol) in [(-1500.0f64, 0.2), (-900.0, 0.05), (-300.0, 0.01), (-10.0, 1e-3), (-1.0, 1e-4), (0.0, 1e-4), (0.5, 1e-4)] {
            let v = ((h(y) - h0) / (h1 - h0)) as f32;
            let q = SphericalRect::new(Vec3::ZERO, corner, ex, ey).sample(Vec2::new(0.5, v));
            assert!(q.x.abs() < 1e-4 && (q.z - 1.0).abs() < 1e-5, "off the column x = 0: {q}");
            assert!((q.y as f64 - y).abs() <= tol * y.abs().max(1.0), "u.y = {v}: y = {} against {y}", q.y);
        }
    }

    #[test]
    fn samples_invert_the_solid_angle_fractions() {
        // u.x is the fraction of the solid angle in [x0, X] × [y0, y1] (inclusion and
        // exclusion above), u.y the fraction of the column at X below Y (the column test's
        // sin-elevation form, with dd² = X² + d²): so u built from a chosen (X, Y) must come
        // back as that point. Off-axis, at distance 2 (at distance 1, z0·z0 and z0/z0 agree).
        let (x0, x1, y0, y1, d) = (-1.0f64, 3.0, -0.5, 2.0, 2.0);
        let r = SphericalRect::new(Vec3::ZERO, Vec3::new(-1.0, -0.5, 2.0), Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 2.5, 0.0));
        let total = rect_solid_angle(x0, x1, y0, y1, d);
        for x in [-0.5f64, 0.0, 1.0, 2.5] {
            let dd2 = x * x + d * d;
            let h = |y: f64| y / (dd2 + y * y).sqrt();
            for y in [-0.25f64, 0.0, 1.0, 1.9] {
                let u = Vec2::new((rect_solid_angle(x0, x, y0, y1, d) / total) as f32, ((h(y) - h(y0)) / (h(y1) - h(y0))) as f32);
                let q = r.sample(u);
                assert!((q - Vec3::new(x as f32, y as f32, 2.0)).length() < 1e-4, "u = {u}: {q} against ({x}, {y}, 2)");
            }
        }
    }

    #[test]
    fn samples_lie_on_the_rectangle_and_cover_it_by_solid_angle() {
        // Count samples per quarter of a rectangle seen off-axis: each quarter must get its
        // share of the solid angle, found by subdividing it.
        let p = Vec3::new(0.3, 0.0, -0.2);
        let (corner, ex, ey) = (Vec3::new(-1.0, 1.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0));
        let r = SphericalRect::new(p, corner, ex, ey);
        let mut counts = [0u32; 4];
        let mut rng = raylab_core::Pcg32::new(5, 1);
        let n = 200_000;
        for _ in 0..n {
            let q = p + r.sample(rng.next_vec2());
            let (s, t) = ((q - corner).dot(ex) / ex.length_squared(), (q - corner).dot(ey) / ey.length_squared());
            assert!((q - corner).dot(ex.cross(ey)).abs() < 1e-4, "off the plane: {q}");
            assert!((-1e-4..=1.0001).contains(&s) && (-1e-4..=1.0001).contains(&t), "outside: {s}, {t}");
            counts[(s >= 0.5) as usize + 2 * (t >= 0.5) as usize] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let sub = SphericalRect::new(p, corner + 0.5 * ((i % 2) as f32 * ex + (i / 2) as f32 * ey), 0.5 * ex, 0.5 * ey);
            let share = sub.solid_angle / r.solid_angle;
            let got = c as f32 / n as f32;
            assert!((got - share).abs() < 0.005, "quarter {i}: {got} against {share}");
        }
    }
}
