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
        let cu = (1.0 / (fu * fu + self.b0 * self.b0).sqrt()).copysign(fu).clamp(-1.0 + 1e-7, 1.0 - 1e-7);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        let dd = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (dd * dd + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (dd * dd + self.y1 * self.y1).sqrt();
        let hv = h0 + u.y * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-6 { (hv * dd) / (1.0 - hv2).sqrt() } else { self.y1 };
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
