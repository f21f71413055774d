//! Delta lights (point and directional, invisible to camera rays), the Phong model's constant
//! ambient term, area lights (`area.rs`): emitting geometry, and the importance-sampled
//! environment map (`environment.rs`).

mod area;
mod environment;
mod spherical_rect;

pub use area::{AreaLights, AreaSample, LightSampling, DEFAULT_CELLS, MAX_CELLS};
pub use environment::{EnvironmentLight, EnvironmentSample};

use raylab_core::{sampling, Rgb, Vec2, Vec3};

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
    /// The first report's area light: an `n × n` grid of point lights over the
    /// parallelogram `corner + s·edge_u + t·edge_v`, each jittered inside its cell and
    /// carrying `intensity / n²` (so the total stays that of one point light).
    Grid { corner: Vec3, edge_u: Vec3, edge_v: Vec3, n: u32, intensity: Rgb },
    /// A point light shining into a cone along unit `direction` (glTF's
    /// `KHR_lights_punctual` spot): full `intensity` within `cos_inner` of the axis, none
    /// beyond `cos_outer`, and between them the extension's falloff, the square of a linear
    /// ramp in the cosine.
    Spot { position: Vec3, direction: Vec3, intensity: Rgb, cos_inner: f32, cos_outer: f32 },
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
            Light::Grid { .. } => "grid",
            Light::Spot { .. } => "spot",
        }
    }

    /// How many samples [`Light::sample`] takes per shading point: `n²` for grids.
    pub fn sample_count(&self) -> u32 {
        match *self {
            Light::Grid { n, .. } => n * n,
            _ => 1,
        }
    }

    /// Whether samples need a jitter value (`u` of [`Light::sample`]).
    pub fn is_jittered(&self) -> bool {
        matches!(self, Light::Grid { .. })
    }

    /// Sample `k` of [`Light::sample_count`] of the light reaching `p` (`u` jitters grid
    /// cells), or `None` for lights without a direction (ambient) or when `p` coincides with
    /// a point light.
    pub fn sample(&self, p: Vec3, k: u32, u: Vec2) -> Option<LightSample> {
        match *self {
            Light::Point { position, intensity } => point(p, position, intensity),
            Light::Grid { corner, edge_u, edge_v, n, intensity } => {
                let cell = sampling::jittered(k, n, u);
                point(p, corner + cell.x * edge_u + cell.y * edge_v, intensity / (n * n) as f32)
            }
            Light::Directional { direction, irradiance } => Some(LightSample { wi: -direction, dist: f32::INFINITY, irradiance }),
            Light::Ambient { .. } => None,
            Light::Spot { position, direction, intensity, cos_inner, cos_outer } => {
                let s = point(p, position, intensity)?;
                let falloff = spot_falloff(direction.dot(-s.wi), cos_inner, cos_outer);
                (falloff > 0.0).then(|| LightSample { irradiance: s.irradiance * falloff, ..s })
            }
        }
    }
}

/// `KHR_lights_punctual`'s spot attenuation at angle cosine `cos` from the axis:
/// `clamp((cos - cos_outer) / max(1e-3, cos_inner - cos_outer), 0, 1)²`.
pub fn spot_falloff(cos: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let t = ((cos - cos_outer) / (cos_inner - cos_outer).max(1e-3)).clamp(0.0, 1.0);
    t * t
}

fn point(p: Vec3, position: Vec3, intensity: Rgb) -> Option<LightSample> {
    let d = position - p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let dist = d2.sqrt();
    Some(LightSample { wi: d / dist, dist, irradiance: intensity / d2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spot_light_is_a_point_light_inside_its_cone() {
        // Axis straight down from (0, 2, 0); inner cone 30°, outer 60°.
        let (ci, co) = (30f32.to_radians().cos(), 60f32.to_radians().cos());
        let l = Light::Spot { position: Vec3::new(0.0, 2.0, 0.0), direction: -Vec3::Y, intensity: Rgb::splat(8.0), cos_inner: ci, cos_outer: co };
        assert_eq!(l.sample(Vec3::ZERO, 0, Vec2::ZERO).unwrap().irradiance, Rgb::splat(2.0));
        // 45° off the axis (distance² 8): halfway in cosine between the cones' gives the ramp's
        // value ((cos 45° - cos 60°) / (cos 30° - cos 60°))².
        let s = l.sample(Vec3::new(2.0, 0.0, 0.0), 0, Vec2::ZERO).unwrap();
        let t = (45f32.to_radians().cos() - co) / (ci - co);
        assert!((s.irradiance.x - 1.0 * t * t).abs() < 1e-6, "{}", s.irradiance);
        // Beyond the outer cone: no light.
        assert!(l.sample(Vec3::new(4.0, 1.0, 0.0), 0, Vec2::ZERO).is_none());
    }

    #[test]
    fn point_light_falls_off_with_the_square_of_distance() {
        let l = Light::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(8.0) };
        let s = l.sample(Vec3::ZERO, 0, Vec2::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Y);
        assert_eq!(s.dist, 2.0);
        assert_eq!(s.irradiance, Rgb::splat(2.0));
        assert!(l.sample(Vec3::new(0.0, 2.0, 0.0), 0, Vec2::ZERO).is_none());
    }

    #[test]
    fn light_kinds_report_their_names_counts_and_jitter() {
        let grid = Light::Grid { corner: Vec3::ZERO, edge_u: Vec3::X, edge_v: Vec3::Z, n: 3, intensity: Rgb::ONE };
        let point = Light::Point { position: Vec3::ZERO, intensity: Rgb::ONE };
        let sun = Light::Directional { direction: -Vec3::Y, irradiance: Rgb::ONE };
        let ambient = Light::Ambient { intensity: Rgb::ONE };
        let spot = Light::Spot { position: Vec3::ZERO, direction: -Vec3::Y, intensity: Rgb::ONE, cos_inner: 0.9, cos_outer: 0.5 };
        let names: Vec<_> = [&point, &sun, &ambient, &grid, &spot].iter().map(|l| l.type_name()).collect();
        assert_eq!(names, ["point", "directional", "ambient", "grid", "spot"]);
        // A 3 × 3 grid takes 9 jittered samples (n² and not 2n: they agree at n = 2); the
        // others one, unjittered.
        assert_eq!(grid.sample_count(), 9);
        assert!(grid.is_jittered());
        for l in [&point, &sun, &ambient, &spot] {
            assert_eq!(l.sample_count(), 1, "{}", l.type_name());
            assert!(!l.is_jittered(), "{}", l.type_name());
        }
        assert!(ambient.sample(Vec3::X, 0, Vec2::ZERO).is_none());
    }

    #[test]
    fn directional_light_arrives_against_its_direction_from_infinitely_far() {
        let l = Light::Directional { direction: Vec3::new(0.0, -0.6, 0.8), irradiance: Rgb::new(1.0, 2.0, 3.0) };
        let s = l.sample(Vec3::new(5.0, -7.0, 1.0), 0, Vec2::splat(0.3)).unwrap();
        assert_eq!(s.wi, Vec3::new(0.0, 0.6, -0.8));
        assert_eq!(s.dist, f32::INFINITY);
        assert_eq!(s.irradiance, Rgb::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn grid_cell_positions_and_shares_on_a_three_by_three_grid() {
        // Corner (1, 2, 3), edges (3, 0, 0) and (0, 0, 1.5), n = 3: sample k = 5 is cell
        // (k mod 3, k div 3) = (2, 1), and jitter (0.25, 0.75) puts it at fractions
        // ((2 + 0.25)/3, (1 + 0.75)/3) = (0.75, 7/12) of the edges: (1 + 2.25, 2, 3 + 0.875).
        // Seen from 3 below, it carries 36/9 = 4 at distance 3: irradiance 4/9.
        let l = Light::Grid { corner: Vec3::new(1.0, 2.0, 3.0), edge_u: Vec3::new(3.0, 0.0, 0.0), edge_v: Vec3::new(0.0, 0.0, 1.5), n: 3, intensity: Rgb::splat(36.0) };
        let s = l.sample(Vec3::new(3.25, -1.0, 3.875), 5, Vec2::new(0.25, 0.75)).unwrap();
        assert!((s.wi - Vec3::Y).length() < 1e-6, "{}", s.wi);
        assert!((s.dist - 3.0).abs() < 1e-6, "{}", s.dist);
        assert!((s.irradiance - Rgb::splat(4.0 / 9.0)).abs().max_element() < 1e-6, "{}", s.irradiance);
    }

    #[test]
    fn spot_falloff_by_hand() {
        // cos_inner 0.9, cos_outer 0.5: at cos 0.8, t = (0.8 − 0.5)/(0.9 − 0.5) = 0.75, t² = 0.5625;
        // clamped to 1 inside the inner cone and to 0 outside the outer one.
        assert!((spot_falloff(0.8, 0.9, 0.5) - 0.5625).abs() < 1e-6, "{}", spot_falloff(0.8, 0.9, 0.5));
        assert_eq!(spot_falloff(0.95, 0.9, 0.5), 1.0);
        assert_eq!(spot_falloff(0.3, 0.9, 0.5), 0.0);
        // Equal cones: the ramp's width is floored at 10⁻³, so 0.0005 past the edge is
        // halfway, 0.25.
        assert!((spot_falloff(0.5005, 0.5, 0.5) - 0.25).abs() < 1e-3, "{}", spot_falloff(0.5005, 0.5, 0.5));
        // Exactly on the outer cone the falloff is 0, and the spot gives no sample there: the
        // point (0, −3, 4) is at distance 5 with cos 3/5 from the axis, which f32 computes
        // exactly as the literal 0.6.
        let l = Light::Spot { position: Vec3::ZERO, direction: -Vec3::Y, intensity: Rgb::ONE, cos_inner: 0.9, cos_outer: 0.6 };
        assert!(l.sample(Vec3::new(0.0, -3.0, 4.0), 0, Vec2::ZERO).is_none());
        let inside = l.sample(Vec3::new(0.0, -3.0, 3.9), 0, Vec2::ZERO).unwrap();
        assert!(inside.irradiance.x > 0.0);
        // Straight down the axis at distance 2: the full intensity over d² = 4, wi back up.
        let s = l.sample(Vec3::new(0.0, -2.0, 0.0), 0, Vec2::ZERO).unwrap();
        assert_eq!((s.wi, s.dist, s.irradiance), (Vec3::Y, 2.0, Rgb::splat(0.25)));
    }

    #[test]
    fn grid_light_splits_its_intensity_over_jittered_cells() {
        // A 2×2 grid over [0,2]×[0,2] at height 1: cell k with jitter u lies at
        // ((k % 2 + u.x), 1, (k / 2 + u.y)), and carries a quarter of the intensity.
        let l = Light::Grid { corner: Vec3::new(0.0, 1.0, 0.0), edge_u: Vec3::new(2.0, 0.0, 0.0), edge_v: Vec3::new(0.0, 0.0, 2.0), n: 2, intensity: Rgb::splat(8.0) };
        assert_eq!(l.sample_count(), 4);
        let s = l.sample(Vec3::new(1.5, 0.0, 0.5), 1, Vec2::splat(0.5)).unwrap();
        assert!((s.wi - Vec3::Y).length() < 1e-6, "{}", s.wi);
        assert_eq!(s.irradiance, Rgb::splat(2.0));
        let s = l.sample(Vec3::new(0.0, 0.0, 0.0), 3, Vec2::ZERO).unwrap();
        assert!((s.dist - 3f32.sqrt()).abs() < 1e-6);
    }
}
