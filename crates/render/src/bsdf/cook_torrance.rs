//! Cook–Torrance microfacet reflection (Cook & Torrance 1982; Walter et al. 2007) over a
//! Lambertian base:
//!
//! `f = diffuse/π + specular · D(h)·G(wo, wi)·F(wo·h) / (4 cos θi cos θo)`, h = (wo+wi)/|wo+wi|,
//!
//! D and G from `microfacet.rs`, F Schlick's with `f0` (f0 = 1 gives F ≡ 1) or a conductor's
//! exact Fresnel (`fresnel.rs`). The two terms
//! are simply added, as in the original model: energy is conserved only if
//! `diffuse + specular ≤ 1`. Sampling picks the diffuse lobe (cosine hemisphere) or the
//! specular one (h with density D(h) cos θh, reflected about h: pdf D cos θh / (4 wo·h),
//! Walter et al. 2007, eq. 14) in proportion to the luminance of `diffuse` and `specular`.

use raylab_core::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use raylab_core::{Rgb, Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::lobe_probability;
use super::fresnel::{reflect, Fresnel};
use super::microfacet::{Distribution, Geometry, MIN_ALPHA};

pub(super) struct CookTorrance {
    pub diffuse: Rgb,
    pub specular: Rgb,
    pub alpha: f32,
    pub distribution: Distribution,
    pub geometry: Geometry,
    pub fresnel: Fresnel,
}

impl CookTorrance {
    fn alpha(&self) -> f32 {
        self.alpha.max(MIN_ALPHA)
    }

    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        let Some((h, cos_oh)) = half_vector(wo, wi) else { return Rgb::ZERO };
        let alpha = self.alpha();
        let d = self.distribution.d(h, alpha);
        let g = self.geometry.g(self.distribution, alpha, wo, wi, h);
        self.diffuse * FRAC_1_PI + self.specular * self.fresnel.eval(cos_oh) * (d * g / (4.0 * wo.z * wi.z))
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some(p_spec) = lobe_probability(self.diffuse, self.specular) else { return 0.0 };
        let Some((h, cos_oh)) = half_vector(wo, wi) else { return 0.0 };
        (1.0 - p_spec) * cosine_hemisphere_pdf(wi.z) + p_spec * self.distribution.d(h, self.alpha()) * h.z / (4.0 * cos_oh)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<Vec3> {
        let p_spec = lobe_probability(self.diffuse, self.specular)?;
        if wo.z < MIN_COS {
            return None;
        }
        let wi = if u_lobe >= p_spec { cosine_hemisphere(u) } else { reflect(wo, self.distribution.sample(u, self.alpha())) };
        (wi.z >= MIN_COS).then_some(wi)
    }
}

/// Directions closer to the horizon than this carry no light. Below it 1/(4 cos θi cos θo)
/// and D/(4 wo·h) overflow f32 (V-cavity masking, unlike Smith's, does not vanish there),
/// while the projected solid angle such directions cover is ~1e-12 of the hemisphere.
const MIN_COS: f32 = 1e-6;

/// The half vector h of a reflection configuration and `wo·h = wi·h = |wo + wi|/2`
/// (symmetric in `wo` and `wi`, so `f` is exactly reciprocal); `None` unless both
/// directions are at least `MIN_COS` above the horizon.
fn half_vector(wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
    if wo.z < MIN_COS || wi.z < MIN_COS {
        return None;
    }
    let sum = wo + wi;
    let len = sum.length();
    Some((sum / len, 0.5 * len))
}
