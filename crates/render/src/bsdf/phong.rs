//! Energy-normalised modified Phong (Lafortune & Willems 1994, "Using the modified Phong
//! reflectance model for physically based rendering"):
//!
//! `f = kd/π + ks·(n+2)/(2π)·cosⁿα`, α the angle between `wi` and the mirror direction of
//! `wo`. The (n+2)/(2π) factor makes `∫ f_s cos θi dωi = 1` at normal incidence and less
//! elsewhere, so `kd + ks ≤ 1` conserves energy; `cos α` is symmetric in `wo` and `wi`, so
//! `f` is reciprocal. Sampling picks the diffuse or the specular lobe in proportion to the
//! luminance of `kd` and `ks`; the specular lobe draws `cos α = u^(1/(n+1))` about the
//! mirror direction, pdf `(n+1)/(2π)·cosⁿα`; directions below the horizon are rejected.

use std::f32::consts::{FRAC_1_PI, PI};

use raylab_core::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use raylab_core::{Frame, Rgb, Vec2, Vec3};

use super::lobe_probability;
use super::fresnel::reflect;

pub(super) struct Phong {
    pub kd: Rgb,
    pub ks: Rgb,
    pub exponent: f32,
}

impl Phong {
    /// `(n, cosⁿα)`, with `n` clamped to ≥ 0.
    fn lobe(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        let n = self.exponent.max(0.0);
        let cos_alpha = wi.dot(reflect(wo, Vec3::Z)).clamp(0.0, 1.0);
        (n, cos_alpha.powf(n))
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (n, cos_n) = self.lobe(wo, wi);
        self.kd * FRAC_1_PI + self.ks * ((n + 2.0) / (2.0 * PI) * cos_n)
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(p_spec) = lobe_probability(self.kd, self.ks) else { return 0.0 };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let (n, cos_n) = self.lobe(wo, wi);
        (1.0 - p_spec) * cosine_hemisphere_pdf(wi.z) + p_spec * (n + 1.0) / (2.0 * PI) * cos_n
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<Vec3> {
        let p_spec = lobe_probability(self.kd, self.ks)?;
        if wo.z <= 0.0 {
            return None;
        }
        if u_lobe >= p_spec {
            return Some(cosine_hemisphere(u));
        }
        let cos_alpha = u.x.powf(1.0 / (self.exponent.max(0.0) + 1.0));
        let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let local = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
        let wi = Frame::from_z(reflect(wo, Vec3::Z)).to_world(local);
        (wi.z > 0.0).then_some(wi)
    }
}
