//! Lambertian reflection: `f = albedo/π`, sampled with a cosine-weighted hemisphere
//! (pbrt-v4 `DiffuseBxDF`), here one-sided.

use std::f32::consts::FRAC_1_PI;

use raylab_core::sampling::{cosine_hemisphere, cosine_hemisphere_pdf};
use raylab_core::{Rgb, Vec2, Vec3};

pub(super) fn eval(albedo: Rgb, wo: Vec3, wi: Vec3) -> Rgb {
    if wo.z > 0.0 && wi.z > 0.0 {
        albedo * FRAC_1_PI
    } else {
        Rgb::ZERO
    }
}

pub(super) fn pdf(wo: Vec3, wi: Vec3) -> f32 {
    if wo.z > 0.0 {
        cosine_hemisphere_pdf(wi.z)
    } else {
        0.0
    }
}

pub(super) fn sample(wo: Vec3, u: Vec2) -> Option<Vec3> {
    (wo.z > 0.0).then(|| cosine_hemisphere(u))
}
