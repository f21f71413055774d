//! Smooth dielectric interface (pbrt-v4 `DielectricBxDF::Sample_f`, specular case):
//! reflection with the exact unpolarised Fresnel reflectance F, Snell refraction with 1 − F,
//! one of the two chosen with probability F; total internal reflection gives F = 1.
//! Transmitted radiance is scaled by 1/η² (pbrt's `TransportMode::Radiance`),
//! η being the relative index across the interface as seen from `wo`.

use raylab_core::{Rgb, Vec3};

use super::{delta_sample, BsdfSample};
use super::fresnel::{fresnel_dielectric, refract};

pub(super) fn sample(ior: f32, wo: Vec3, u_lobe: f32) -> Option<BsdfSample> {
    let r = fresnel_dielectric(wo.z, ior);
    if u_lobe < r {
        return delta_sample(Vec3::new(-wo.x, -wo.y, wo.z), Rgb::splat(r), r);
    }
    // Normal and relative index on `wo`'s side: η = n_transmitted / n_incident.
    let (n, eta) = if wo.z > 0.0 { (Vec3::Z, ior) } else { (-Vec3::Z, 1.0 / ior) };
    let wi = refract(wo, n, eta)?;
    let t = 1.0 - r;
    delta_sample(wi, Rgb::splat(t / (eta * eta)), t)
}
