//! Delta lights (point and directional, invisible to camera rays), the Phong model's constant
//! ambient term, and area lights (`area.rs`): emitting geometry.

mod area;

pub use area::{AreaLights, AreaSample, LightSampling};

use raylab_core::{Rgb, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Radiant intensity `intensity` (W/sr per channel) from `position`: the irradiance at
    /// distance `d` facing the light is `intensity / d²` (inverse-square law).
    Point { position: Vec3, intensity: Rgb },
    /// Parallel light travelling along `direction` (unit) with irradiance `irradiance` on a
    /// surface facing it (the sun).
    Directional { direction: Vec3, irradiance: Rgb },
    /// The constant ambient term `I_ambient` of the Phong model (weighted by `ka`).
    Ambient { intensity: Rgb },
}

/// Light arriving at a point from one light.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light (∞ for directional lights).
    pub dist: f32,
    /// Irradiance on a surface facing the light (before the cosine factor).
    pub irradiance: Rgb,
}

impl Light {
    pub fn type_name(&self) -> &'static str {
        match self {
            Light::Point { .. } => "point",
            Light::Directional { .. } => "directional",
            Light::Ambient { .. } => "ambient",
        }
    }

    /// The light reaching `p`, or `None` for lights without a direction (ambient) or when
    /// `p` coincides with a point light.
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point { position, intensity } => {
                let d = position - p;
                let d2 = d.length_squared();
                if d2 == 0.0 {
                    return None;
                }
                let dist = d2.sqrt();
                Some(LightSample { wi: d / dist, dist, irradiance: intensity / d2 })
            }
            Light::Directional { direction, irradiance } => Some(LightSample { wi: -direction, dist: f32::INFINITY, irradiance }),
            Light::Ambient { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_light_falls_off_with_the_square_of_distance() {
        let l = Light::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(8.0) };
        let s = l.sample(Vec3::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Y);
        assert_eq!(s.dist, 2.0);
        assert_eq!(s.irradiance, Rgb::splat(2.0));
        assert!(l.sample(Vec3::new(0.0, 2.0, 0.0)).is_none());
    }
}
