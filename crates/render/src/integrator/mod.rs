//! Integrators: how radiance along a camera ray is estimated.

pub mod heatmap;
mod path;
mod whitted;

use std::fmt;
use std::str::FromStr;

use raylab_accel::Counters;
use raylab_core::{Ray, Rgb};

use crate::sampler::PixelSampler;
use crate::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Recursive ray tracing (Whitted 1980): Phong with point lights, shadows, mirror
    /// reflection and Fresnel-weighted refraction.
    Whitted,
    /// Direct lighting: one bounce of light, MIS between light and BSDF samples
    /// (specular chains are followed to the first non-specular surface).
    Direct,
    /// Path tracing: next-event estimation, MIS, Russian roulette.
    Path,
    /// Shading normals as colours (`0.5 · (n + 1)`), for checking geometry.
    Normals,
    /// The first hit's diffuse colour (an AOV for denoisers and checks).
    Albedo,
    /// Distance to the first hit along the camera ray (0 where nothing is hit).
    Depth,
    /// Acceleration-structure nodes visited by each camera ray, in false colour.
    Heatmap,
    /// Ray–primitive tests made by each camera ray, in false colour.
    HeatmapTests,
}

impl IntegratorKind {
    pub const ALL: &'static [IntegratorKind] = &[
        IntegratorKind::Whitted,
        IntegratorKind::Direct,
        IntegratorKind::Path,
        IntegratorKind::Normals,
        IntegratorKind::Albedo,
        IntegratorKind::Depth,
        IntegratorKind::Heatmap,
        IntegratorKind::HeatmapTests,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Direct => "direct",
            IntegratorKind::Path => "path",
            IntegratorKind::Normals => "normals",
            IntegratorKind::Albedo => "albedo",
            IntegratorKind::Depth => "depth",
            IntegratorKind::Heatmap => "heatmap",
            IntegratorKind::HeatmapTests => "heatmap-tests",
        }
    }

    /// Whether the output holds raw costs to be colourised by [`heatmap::colorize`].
    pub fn is_heatmap(self) -> bool {
        matches!(self, IntegratorKind::Heatmap | IntegratorKind::HeatmapTests)
    }

    pub fn names() -> String {
        Self::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
    }

    /// Radiance arriving along `ray` (a camera ray).
    pub fn radiance(self, scene: &Scene, ray: &Ray, sampler: &mut PixelSampler, counters: &mut Counters) -> Rgb {
        match self {
            IntegratorKind::Whitted => whitted::radiance(scene, ray, 1, sampler, counters),
            IntegratorKind::Direct => path::radiance(scene, ray, sampler, counters, true),
            IntegratorKind::Path => path::radiance(scene, ray, sampler, counters, false),
            IntegratorKind::Albedo => match scene.intersect(ray, counters) {
                Some(h) => scene.materials[h.material.0 as usize].albedo(&scene.textures, h.geom.uv, h.geom.p),
                None => Rgb::ZERO,
            },
            IntegratorKind::Depth => scene.intersect(ray, counters).map_or(Rgb::ZERO, |h| Rgb::splat(h.t * ray.dir.length())),
            IntegratorKind::Normals => match scene.intersect(ray, counters) {
                Some(h) => 0.5 * (h.geom.ns + Rgb::ONE),
                None => Rgb::ZERO,
            },
            IntegratorKind::Heatmap => heatmap::cost(scene, ray, heatmap::HeatMetric::NodesVisited, counters),
            IntegratorKind::HeatmapTests => heatmap::cost(scene, ray, heatmap::HeatMetric::PrimTests, counters),
        }
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| format!("unknown integrator `{s}` (valid: {})", Self::names()))
    }
}
