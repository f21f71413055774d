//! Kajiya–Kay hair shading (Kajiya & Kay 1989, "Rendering fur with three dimensional
//! textures", §4), in a local frame whose x axis is the fibre's tangent `T`
//! ([`fibre_frame`]) and z the shading normal:
//!
//! `f = (colour·kd·sin(T, ωi) + ks·cos^p θ') / π`, with
//! `cos θ' = sin(T, ωi)·sin(T, ωo) − (T·ωi)(T·ωo)` clamped at 0,
//!
//! the diffuse term of a thin cylinder lit from `ωi`, and a specular cone around the
//! mirror directions of `ωi` about the fibre (θ' is `ωo`'s angle to the cone, `p` the
//! exponent). The specular term is symmetric in `ωo` and `ωi`; the diffuse one, as in the
//! original, depends on `ωi` only, so `f` is not reciprocal (which paths traced from the
//! camera do not need). The integrators multiply it by `|cos θi|` like any BSDF, which on a round tube is the
//! foreshortening the strand's own surface supplies. One-sided like the other opaque
//! models; sampled with a cosine-weighted hemisphere (correct for any `f` that vanishes
//! below the horizon, if noisier for sharp highlights).

use std::f32::consts::FRAC_1_PI;

use raylab_core::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use raylab_core::{Frame, Rgb, Vec2, Vec3};

pub(super) struct KajiyaKay {
    pub color: Rgb,
    pub kd: f32,
    pub ks: f32,
    pub exponent: f32,
}

impl KajiyaKay {
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        // T = x in the local frame.
        let sin_i = (1.0 - wi.x * wi.x).max(0.0).sqrt();
        let sin_o = (1.0 - wo.x * wo.x).max(0.0).sqrt();
        let cos_cone = (sin_i * sin_o - wi.x * wo.x).max(0.0);
        (self.color * (self.kd * sin_i) + Rgb::splat(self.ks * cos_cone.powf(self.exponent.max(0.0)))) * FRAC_1_PI
    }

    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 { cosine_hemisphere_pdf(wi.z) } else { 0.0 }
    }

    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        (wo.z > 0.0).then(|| cosine_hemisphere(u))
    }
}

/// The shading frame of a fibre: `z` the normal `n`, `x` the tangent (`∂p/∂u` of curves
/// and tubes) made orthogonal to it. Falls back to an arbitrary tangent where `tangent`
/// is zero or along `n`.
pub fn fibre_frame(n: Vec3, tangent: Vec3) -> Frame {
    match (tangent - n * n.dot(tangent)).try_normalize() {
        Some(x) => Frame { x, y: n.cross(x), z: n },
        None => Frame::from_z(n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_values() {
        let kk = KajiyaKay { color: Rgb::new(1.0, 0.5, 0.25), kd: 0.6, ks: 0.3, exponent: 4.0 };
        // Light across the fibre (sin = 1), viewer at 60° to it: the cone of mirror
        // directions of a perpendicular ray is the normal plane; cos θ' = sin 60°.
        let wi = Vec3::Z;
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let f = kk.eval(wo, wi);
        let spec = 0.3 * 0.75f32.sqrt().powi(4);
        let want = (Rgb::new(1.0, 0.5, 0.25) * 0.6 + Rgb::splat(spec)) / std::f32::consts::PI;
        assert!((f - want).abs().max_element() < 1e-6, "{f} vs {want}");
        // The mirror direction about the fibre sits on the cone: cos θ' = 1.
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let wo = Vec3::new(-0.6, 0.0, 0.8);
        let f = kk.eval(wo, wi);
        let want = (Rgb::new(1.0, 0.5, 0.25) * 0.6 * 0.8 + Rgb::splat(0.3)) / std::f32::consts::PI;
        assert!((f - want).abs().max_element() < 1e-6, "{f} vs {want}");
        // Light along the fibre: no diffuse light, and the cone is T itself.
        assert_eq!(KajiyaKay { ks: 0.0, ..kk }.eval(wo, Vec3::X), Rgb::ZERO);
    }

    #[test]
    fn hand_value_off_every_axis() {
        // wi = (0.36, 0.48, 0.8), wo = (−0.6, 0, 0.8), T = x: sin(T, wi) = √(1 − 0.36²),
        // sin(T, wo) = 0.8, cos θ' = sin_i·0.8 − 0.36·(−0.6) = sin_i·0.8 + 0.216; exponent 3.
        let kk = KajiyaKay { color: Rgb::new(0.9, 0.6, 0.3), kd: 0.7, ks: 0.4, exponent: 3.0 };
        let (wi, wo) = (Vec3::new(0.36, 0.48, 0.8), Vec3::new(-0.6, 0.0, 0.8));
        let sin_i = (1.0f64 - 0.36 * 0.36).sqrt();
        let cone = sin_i * 0.8 + 0.216;
        for (c, got) in [0.9f64, 0.6, 0.3].into_iter().zip(kk.eval(wo, wi).to_array()) {
            let want = (c * 0.7 * sin_i + 0.4 * cone.powi(3)) / std::f64::consts::PI;
            assert!((got as f64 - want).abs() < 1e-6 * want, "{got} vs {want}");
        }
    }

    #[test]
    fn one_sided_with_a_cosine_density() {
        // Reflects only with both directions above the surface (module doc), z = 0 included.
        let kk = KajiyaKay { color: Rgb::ONE, kd: 0.7, ks: 0.4, exponent: 3.0 };
        let (up, flat, down) = (Vec3::new(0.36, 0.48, 0.8), Vec3::new(0.6, 0.8, 0.0), Vec3::new(0.36, 0.48, -0.8));
        for (wo, wi) in [(up, down), (down, up), (up, flat), (flat, up), (down, down)] {
            assert_eq!(kk.eval(wo, wi), Rgb::ZERO, "f({wo}, {wi})");
        }
        assert!(kk.eval(up, up).min_element() > 0.0);
        // Cosine-weighted hemisphere: pdf = cos θi / π whatever wo above the surface.
        assert!((kk.pdf(Vec3::new(-0.6, 0.0, 0.8), up) - 0.8 / std::f32::consts::PI).abs() < 1e-7);
        for wo in [down, flat] {
            assert_eq!(kk.pdf(wo, up), 0.0, "pdf from {wo}");
            assert!(kk.sample(wo, Vec2::new(0.3, 0.6)).is_none(), "sample from {wo}");
        }
        let wi = kk.sample(up, Vec2::new(0.3, 0.6)).unwrap();
        assert!(wi.z > 0.0 && (wi.length() - 1.0).abs() < 1e-6, "{wi}");
    }

    #[test]
    fn fibre_frame_puts_the_tangent_on_x() {
        let n = Vec3::new(0.0, 0.6, 0.8);
        let f = fibre_frame(n, Vec3::new(2.0, 0.3, 0.0));
        assert!(f.z == n && f.x.dot(n).abs() < 1e-6 && (f.x.length() - 1.0).abs() < 1e-6 && f.x.x > 0.9);
        assert!((f.x.cross(f.y) - f.z).length() < 1e-5, "right-handed");
        // x is the tangent's part across n, t − n(n·t) = (2, 0.3 − 0.6·0.18, −0.8·0.18), normalised.
        let want = Vec3::new(2.0, 0.192, -0.144) / (4.0f32 + 0.192 * 0.192 + 0.144 * 0.144).sqrt();
        assert!((f.x - want).length() < 1e-6, "{} vs {want}", f.x);
        let fallback = fibre_frame(n, n);
        assert!(fallback.x.dot(n).abs() < 1e-6);
    }
}
