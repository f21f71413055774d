//! Ideal specular reflection (pbrt-v4 `ConductorBxDF` in the smooth case, with a
//! constant reflectance in place of the conductor Fresnel term).

use raylab_core::{Rgb, Vec3};

use super::{delta_sample, BsdfSample};

pub(super) fn sample(reflectance: Rgb, wo: Vec3) -> Option<BsdfSample> {
    if wo.z <= 0.0 {
        return None;
    }
    delta_sample(Vec3::new(-wo.x, -wo.y, wo.z), reflectance, 1.0)
}
