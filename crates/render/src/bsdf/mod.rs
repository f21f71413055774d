//! Physically based BSDFs with `eval` / `pdf` / `sample`, for Monte Carlo light transport.
//!
//! Everything works in the LOCAL shading frame: `z` is the shading normal (use
//! [`raylab_core::Frame`] to go to and from world space). Conventions follow pbrt-v4 (`BxDF`, chapter 9):
//! `wo` and `wi` are unit vectors pointing AWAY from the surface, `f` excludes the cosine
//! factor, and `pdf` is a density in solid angle over `wi`, except for delta (specular)
//! lobes, where `pdf` is the discrete probability of the chosen lobe and `f` includes
//! `1/|cos θi|` so that `f·|cos θi|/pdf` is the lobe's weight.
//!
//! The opaque models (Lambert, Phong, CookTorrance, KajiyaKay, Mirror) are one-sided: they reflect only
//! when `wo.z > 0` and `wi.z > 0`. An integrator shading a two-sided surface flips the frame
//! to `wo`'s side first, as the Whitted integrator does with its `facing` normal.
//! `Dielectric` is two-sided: `wo.z < 0` means `wo` is inside the medium.

mod cook_torrance;
mod dielectric;
mod fresnel;
mod kajiya_kay;
mod lambert;
mod microfacet;
mod mirror;
mod phong;
#[cfg(test)]
mod tests;

pub use fresnel::{fresnel_dielectric, reflect, refract, Fresnel};
pub use kajiya_kay::fibre_frame;
pub use microfacet::{Distribution, Geometry};

use raylab_core::color::luminance;
use raylab_core::{Rgb, Vec2, Vec3};

/// A BSDF with its parameters. An enum rather than trait objects: `Copy`, no allocation,
/// and one `match` per call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflection, `f = albedo / π`.
    Lambert { albedo: Rgb },
    /// Energy-normalised modified Phong (Lafortune & Willems 1994), see `phong.rs`.
    /// `exponent ≥ 0`; energy is conserved when `kd + ks ≤ 1` per channel.
    Phong { kd: Rgb, ks: Rgb, exponent: f32 },
    /// Ideal specular reflection scaled by `reflectance`.
    Mirror { reflectance: Rgb },
    /// Smooth dielectric interface; `ior` is inside over outside (outside = +z side).
    Dielectric { ior: f32 },
    /// Cook–Torrance microfacet reflection plus a Lambertian base, see `cook_torrance.rs`.
    /// `alpha` is the roughness (for Beckmann the RMS slope), clamped to ≥ 1e-3.
    CookTorrance { diffuse: Rgb, specular: Rgb, alpha: f32, distribution: Distribution, geometry: Geometry, fresnel: Fresnel },
    /// Kajiya–Kay hair, see `kajiya_kay.rs`; the local x axis is the fibre's tangent
    /// ([`fibre_frame`]).
    KajiyaKay { color: Rgb, kd: f32, ks: f32, exponent: f32 },
}

/// One sampled direction with the BSDF value and density there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub f: Rgb,
    /// Solid-angle density, or the discrete lobe probability when `delta`.
    pub pdf: f32,
    /// A specular lobe: `wi` is the only direction, `eval`/`pdf` cannot reproduce it.
    pub delta: bool,
}

impl Bsdf {
    /// The BSDF value `f(wo, wi)` (no cosine); zero for delta lobes.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        match *self {
            Bsdf::Lambert { albedo } => lambert::eval(albedo, wo, wi),
            Bsdf::Phong { kd, ks, exponent } => phong::Phong { kd, ks, exponent }.eval(wo, wi),
            Bsdf::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel } => {
                cook_torrance::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel }.eval(wo, wi)
            }
            Bsdf::KajiyaKay { color, kd, ks, exponent } => kajiya_kay::KajiyaKay { color, kd, ks, exponent }.eval(wo, wi),
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => Rgb::ZERO,
        }
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns `wi`; zero for delta lobes.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match *self {
            Bsdf::Lambert { .. } => lambert::pdf(wo, wi),
            Bsdf::Phong { kd, ks, exponent } => phong::Phong { kd, ks, exponent }.pdf(wo, wi),
            Bsdf::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel } => {
                cook_torrance::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel }.pdf(wo, wi)
            }
            Bsdf::KajiyaKay { color, kd, ks, exponent } => kajiya_kay::KajiyaKay { color, kd, ks, exponent }.pdf(wo, wi),
            Bsdf::Mirror { .. } | Bsdf::Dielectric { .. } => 0.0,
        }
    }

    /// Samples `wi` given `wo`: `u_lobe` picks the lobe, `u` the direction within it (both
    /// uniform in `[0,1)`). `None` where no direction carries light (e.g. `wo` below an
    /// opaque surface, or a sampled direction that falls below the horizon).
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: Vec2) -> Option<BsdfSample> {
        let wi = match *self {
            Bsdf::Lambert { .. } => lambert::sample(wo, u)?,
            Bsdf::Phong { kd, ks, exponent } => phong::Phong { kd, ks, exponent }.sample(wo, u_lobe, u)?,
            Bsdf::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel } => {
                cook_torrance::CookTorrance { diffuse, specular, alpha, distribution, geometry, fresnel }.sample(wo, u_lobe, u)?
            }
            Bsdf::KajiyaKay { color, kd, ks, exponent } => kajiya_kay::KajiyaKay { color, kd, ks, exponent }.sample(wo, u)?,
            Bsdf::Mirror { reflectance } => return mirror::sample(reflectance, wo),
            Bsdf::Dielectric { ior } => return dielectric::sample(ior, wo, u_lobe),
        };
        // `f` and `pdf` come from `eval` and `pdf` themselves, so a sample agrees exactly
        // with them (multiple importance sampling relies on that).
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BsdfSample { wi, f: self.eval(wo, wi), pdf, delta: false })
    }

    /// Whether every lobe is a delta: `eval` and `pdf` are then identically zero.
    pub fn is_delta(&self) -> bool {
        matches!(self, Bsdf::Mirror { .. } | Bsdf::Dielectric { .. })
    }
}

/// Probability of choosing lobe `b` over lobe `a`, proportional to their luminance;
/// `None` when both are black.
fn lobe_probability(a: Rgb, b: Rgb) -> Option<f32> {
    let (la, lb) = (luminance(a).max(0.0), luminance(b).max(0.0));
    (la + lb > 0.0).then(|| lb / (la + lb))
}

/// A delta sample carrying the fraction `weight` of the light: `f = weight/|cos θi|`, so
/// that `f·|cos θi|/pdf` is the throughput factor. `None` where `f` would overflow.
fn delta_sample(wi: Vec3, weight: Rgb, pdf: f32) -> Option<BsdfSample> {
    let f = weight / wi.z.abs();
    (f.is_finite() && pdf > 0.0).then_some(BsdfSample { wi, f, pdf, delta: true })
}
