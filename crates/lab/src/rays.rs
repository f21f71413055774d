//! Ray sets: primary camera rays, diffuse bounces from their hits, shadow rays towards the
//! lights. Generated once per scene (with a reference structure) and traced by every
//! structure, so that all of them answer exactly the same queries.

use rayon::prelude::*;
use raylab_accel::Counters;
use raylab_core::{sampling, Frame, Pcg32, Ray, Vec2};
use raylab_render::light::LightSampling;
use raylab_render::{Light, Scene};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RayKind {
    /// One camera ray through each pixel centre: coherent.
    Primary,
    /// A cosine-distributed bounce from each primary hit: incoherent.
    Diffuse,
    /// From each primary hit towards a light, stopping at it: any-hit queries.
    Shadow,
}

raylab_core::named_enum!(RayKind, "ray kind", {
    Primary => "primary",
    Diffuse => "diffuse",
    Shadow => "shadow",
});

impl RayKind {
    /// Shadow rays ask "is anything there?", the others "what is hit first?".
    pub fn any_hit(self) -> bool {
        self == RayKind::Shadow
    }
}

/// A named list of rays.
#[derive(Clone, Debug)]
pub struct RaySet {
    pub kind: RayKind,
    pub rays: Vec<Ray>,
}

/// One camera ray through the centre of each pixel of a `width × height` grid, row by row
/// from the top.
pub fn primary(scene: &Scene, width: u32, height: u32) -> Vec<Ray> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| scene.camera.ray(Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32), Vec2::splat(0.5)))
        .collect()
}

/// Generates the requested ray sets for `scene` at `width × height` camera rays, using the
/// scene's own structure to find the primary hits. Deterministic for a given `seed`.
pub fn generate(scene: &Scene, width: u32, height: u32, kinds: &[RayKind], seed: u64) -> Vec<RaySet> {
    let primary = primary(scene, width, height);
    let lights: Vec<&Light> = scene.lights.iter().filter(|l| !matches!(l, Light::Ambient { .. })).collect();
    let secondary: Vec<(Option<Ray>, Option<Ray>)> = primary
        .par_iter()
        .enumerate()
        .map(|(i, ray)| {
            let mut c = Counters::default();
            let Some(hit) = scene.intersect(ray, &mut c) else { return (None, None) };
            let mut rng = Pcg32::new(seed, i as u64);
            let wo = -ray.dir;
            let n = if hit.geom.ng.dot(wo) < 0.0 { -hit.geom.ng } else { hit.geom.ng };
            let d = Frame::from_z(n).to_world(sampling::cosine_hemisphere(rng.next_vec2()));
            let diffuse = hit.spawn(d);
            // One light, chosen uniformly among the delta lights and (as one) the area lights.
            let area = usize::from(!scene.area_lights.is_empty());
            let shadow = match rng.below((lights.len() + area).max(1) as u32) as usize {
                _ if lights.len() + area == 0 => None,
                k if k < lights.len() => {
                    let light = lights[k];
                    let (cell, u) = if light.is_jittered() { (rng.below(light.sample_count()), rng.next_vec2()) } else { (0, Vec2::ZERO) };
                    light.sample(hit.geom.p, cell, u).map(|s| hit.spawn_to(s.wi, s.dist.min(1e30)))
                }
                _ => scene
                    .area_lights
                    .sample(&scene.geometry, &scene.textures, hit.geom.p, &|_| 1.0, LightSampling::Uniform, rng.next_f32(), rng.next_vec2())
                    .map(|s| hit.spawn_to(s.wi, s.dist)),
            };
            (Some(diffuse), shadow)
        })
        .collect();
    kinds
        .iter()
        .map(|&kind| RaySet {
            kind,
            rays: match kind {
                RayKind::Primary => primary.clone(),
                RayKind::Diffuse => secondary.iter().filter_map(|s| s.0).collect(),
                RayKind::Shadow => secondary.iter().filter_map(|s| s.1).collect(),
            },
        })
        .collect()
}
