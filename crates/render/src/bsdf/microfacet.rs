//! Microfacet building blocks for Cook–Torrance, in the local frame (z = macro normal):
//! normal distributions D, masking–shadowing G and Schlick's Fresnel approximation.
//!
//! `alpha`: for Beckmann the RMS slope of the microsurface; for GGX, whose slope variance is
//! infinite, the width parameter with the same role (both peak at D(z) = 1/(πα²)).

use std::f32::consts::{FRAC_1_PI, PI};

use raylab_core::{Rgb, Vec2, Vec3};

/// Smallest roughness used. Below it the lobe is narrower than f32 directions resolve (a
/// unit vector carries ~1e-7 of angular error, and D peaks at 1/(πα²)), Beckmann's
/// `tan²θ/α²` and GGX's `1/α⁴` head for overflow, and α = 0 itself is 0/0. For a perfectly
/// smooth surface use `Bsdf::Mirror`.
pub(super) const MIN_ALPHA: f32 = 1e-3;

/// Microfacet normal distribution D(h).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Distribution {
    /// Beckmann (1963): Gaussian slopes.
    Beckmann,
    /// GGX / Trowbridge–Reitz (Walter et al. 2007): a longer tail.
    Ggx,
}

raylab_core::named_enum!(Distribution, "microfacet distribution", {
    Beckmann => "beckmann",
    Ggx => "ggx",
});

/// Masking–shadowing term G(wo, wi).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Smith's height-correlated G2 = 1 / (1 + Λ(wo) + Λ(wi)) (Heitz 2014, "Understanding
    /// the Masking-Shadowing Function in Microfacet-Based BRDFs"), with GGX's exact Λ and
    /// Walter et al. 2007's rational approximation of Beckmann's Λ. Height-correlated
    /// rather than separable G1·G1: it accounts for the correlation between masking and
    /// shadowing, so less energy is lost spuriously.
    Smith,
    /// The V-cavity model (Torrance & Sparrow 1967, Cook & Torrance 1982).
    VCavity,
}

raylab_core::named_enum!(Geometry, "geometry term", {
    Smith => "smith",
    VCavity => "v-cavity",
});

impl Distribution {
    /// D(h) for a unit half vector `h`; zero below the horizon.
    pub(super) fn d(self, h: Vec3, alpha: f32) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a2 = alpha * alpha;
        let sin2 = h.x * h.x + h.y * h.y;
        let cos2 = h.z * h.z;
        match self {
            // exp(−tan²θ/α²) / (π α² cos⁴θ) (Walter et al. 2007, eq. 25). Where cos⁴θ
            // underflows the exponential is already 0 (pbrt-v4 makes the same cut).
            Distribution::Beckmann => {
                let cos4 = cos2 * cos2;
                if cos4 < 1e-16 {
                    return 0.0;
                }
                (-sin2 / cos2 / a2).exp() / (PI * a2 * cos4)
            }
            // α² / (π cos⁴θ (α² + tan²θ)²) (Walter et al. 2007, eq. 33), written as
            // 1 / (π α² (cos²θ + sin²θ/α²)²) so that nothing cancels or divides by zero.
            Distribution::Ggx => {
                let t = cos2 + sin2 / a2;
                FRAC_1_PI / (a2 * t * t)
            }
        }
    }

    /// Smith's Λ(w): the masking of direction `w` is G1 = 1 / (1 + Λ).
    fn lambda(self, w: Vec3, alpha: f32) -> f32 {
        let tan2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        match self {
            // Λ = 1/G1 − 1 of Walter et al. 2007's rational fit of G1 in a = 1/(α tanθ)
            // (eq. 27; G1 = 1 from a = 1.6 on), as pbrt-v3 writes it.
            Distribution::Beckmann => {
                let a = 1.0 / (alpha * tan2.sqrt());
                if a >= 1.6 {
                    0.0
                } else {
                    (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a)
                }
            }
            // Exact: Λ = 1/G1 − 1 of Walter et al. 2007, eq. 34 (pbrt-v4 `TrowbridgeReitz`).
            Distribution::Ggx => 0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0),
        }
    }

    /// A half vector drawn with density D(h)·cos θh (Walter et al. 2007, eqs. 28–29 and
    /// 35–36): invert the CDF of tan²θ, φ uniform.
    pub(super) fn sample(self, u: Vec2, alpha: f32) -> Vec3 {
        let a2 = alpha * alpha;
        let tan2 = match self {
            Distribution::Beckmann => -a2 * (1.0 - u.x).ln(),
            Distribution::Ggx => a2 * u.x / (1.0 - u.x),
        };
        let cos = 1.0 / (1.0 + tan2).sqrt();
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
    }
}

impl Geometry {
    /// G(wo, wi) for a reflection configuration: `wo.z, wi.z > 0`, `h` their half vector.
    pub(super) fn g(self, distribution: Distribution, alpha: f32, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        match self {
            Geometry::Smith => 1.0 / (1.0 + distribution.lambda(wo, alpha) + distribution.lambda(wi, alpha)),
            // min(1, 2(n·h)(n·o)/(o·h), 2(n·h)(n·i)/(o·h)) (Cook & Torrance 1982).
            // wo·h = wi·h, written symmetrically so that G is exactly reciprocal.
            Geometry::VCavity => {
                let k = 4.0 * h.z / (wo + wi).dot(h);
                (k * wo.z).min(k * wi.z).min(1.0)
            }
        }
    }
}

/// Schlick's approximation of the Fresnel reflectance (Schlick 1994):
/// `F = f0 + (1 − f0)(1 − cos θ)⁵`, `cos θ` between the view direction and the microfacet normal.
pub(super) fn schlick(f0: Rgb, cos: f32) -> Rgb {
    let m = 1.0 - cos.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Rgb::ONE - f0) * (m2 * m2 * m)
}

