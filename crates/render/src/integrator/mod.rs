//! Integrators: how radiance along a camera ray is estimated.

pub mod heatmap;
pub(crate) mod kind;
pub mod mis;
mod path;
mod whitted;

pub use kind::IntegratorKind;
pub use mis::MisHeuristic;

use raylab_accel::Counters;
use raylab_core::{Ray, Rgb};

use crate::sampler::PixelSampler;
use crate::Scene;

impl IntegratorKind {
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
            // Facing the camera, as Cycles' Normal pass (a floor seen from above looks up
            // whichever way its triangles wind); where nothing is hit, the zero normal (grey),
            // so that `2c - 1` decodes every pixel, edges included, to the mean normal.
            IntegratorKind::Normals => match scene.intersect(ray, counters) {
                Some(h) => 0.5 * (if h.geom.ng.dot(ray.dir) > 0.0 { -h.geom.ns } else { h.geom.ns } + Rgb::ONE),
                None => Rgb::splat(0.5),
            },
            IntegratorKind::Heatmap => heatmap::cost(scene, ray, heatmap::HeatMetric::NodesVisited, counters),
            IntegratorKind::HeatmapTests => heatmap::cost(scene, ray, heatmap::HeatMetric::PrimTests, counters),
        }
    }
}
