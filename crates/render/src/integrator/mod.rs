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
use crate::scene::SurfaceHit;
use crate::Scene;

impl IntegratorKind {
    /// Radiance arriving along `ray` (a camera ray).
    pub fn radiance(self, scene: &Scene, ray: &Ray, sampler: &mut PixelSampler, counters: &mut Counters) -> Rgb {
        self.radiance_from(scene, ray, None, sampler, counters)
    }

    /// Whether the camera rays' closest hits may be traced ahead, in packets
    /// ([`IntegratorKind::radiance_traced`]): every integrator but the heat maps, whose
    /// pixels show what one ray's own traversal costs.
    pub fn traces_ahead(self) -> bool {
        !matches!(self, IntegratorKind::Heatmap | IntegratorKind::HeatmapTests)
    }

    /// [`IntegratorKind::radiance`] of a camera ray whose closest hit `hit` the caller has
    /// already traced (see [`IntegratorKind::traces_ahead`]).
    pub fn radiance_traced(self, scene: &Scene, ray: &Ray, hit: Option<SurfaceHit>, sampler: &mut PixelSampler, counters: &mut Counters) -> Rgb {
        debug_assert!(self.traces_ahead());
        self.radiance_from(scene, ray, Some(hit), sampler, counters)
    }

    /// `first`: the camera ray's closest hit if already traced, `None` to trace it here.
    fn radiance_from(self, scene: &Scene, ray: &Ray, first: Option<Option<SurfaceHit>>, sampler: &mut PixelSampler, counters: &mut Counters) -> Rgb {
        let mut closest = || first.unwrap_or_else(|| scene.intersect(ray, counters));
        match self {
            IntegratorKind::Whitted => whitted::radiance(scene, ray, first, 1, sampler, counters),
            IntegratorKind::Direct => path::radiance(scene, ray, first, sampler, counters, true),
            IntegratorKind::Path => path::radiance(scene, ray, first, sampler, counters, false),
            IntegratorKind::Albedo => match closest() {
                Some(h) => scene.materials[h.material.0 as usize].albedo(&scene.textures, h.geom.uv, h.geom.p),
                None => Rgb::ZERO,
            },
            IntegratorKind::Depth => closest().map_or(Rgb::ZERO, |h| Rgb::splat(h.t * ray.dir.length())),
            // Facing the camera, as Cycles' Normal pass (a floor seen from above looks up
            // whichever way its triangles wind); where nothing is hit, the zero normal (grey),
            // so that `2c - 1` decodes every pixel, edges included, to the mean normal.
            IntegratorKind::Normals => match closest() {
                Some(h) => 0.5 * (if h.geom.ng.dot(ray.dir) > 0.0 { -h.geom.ns } else { h.geom.ns } + Rgb::ONE),
                None => Rgb::splat(0.5),
            },
            IntegratorKind::Heatmap => heatmap::cost(scene, ray, heatmap::HeatMetric::NodesVisited, counters),
            IntegratorKind::HeatmapTests => heatmap::cost(scene, ray, heatmap::HeatMetric::PrimTests, counters),
        }
    }
}
