//! Monte Carlo light transport: `path` (unidirectional path tracing with next-event
//! estimation, multiple importance sampling and Russian roulette, as in pbrt-v4's
//! `PathIntegrator`) and `direct` (the same path cut after the first non-specular bounce).
//!
//! `max_depth` counts path segments from the camera: 1 shows only emitters seen directly,
//! 2 adds direct lighting, and so on. Delta lights (point, directional) are always sampled;
//! area lights by the scene's `light_sampling` strategy. A plain background is radiance from
//! infinity found by BSDF sampling; an environment light is also sampled by luminance (every
//! strategy but `bsdf`) and weighted against BSDF sampling under `mis`
//! (power heuristic by default, `[render] mis_heuristic`).

use raylab_accel::Counters;
use raylab_core::color::luminance;
use raylab_core::{Frame, Ray, Rgb, Vec2, Vec3};

use crate::bsdf::{fibre_frame, Bsdf};
use crate::light::LightSampling;
use crate::sampler::PixelSampler;
use crate::scene::SurfaceHit;
use crate::Scene;

/// The shading frame at a hit: for opaque BSDFs the shading normal turned towards `wo`
/// (two-sided surfaces); for dielectrics oriented like the geometric normal, so that the
/// local `wo.z < 0` means "inside". Hair puts the fibre's tangent on the local x axis.
fn shading_frame(hit: &SurfaceHit, bsdf: &Bsdf, wo: Vec3) -> Frame {
    let g = &hit.geom;
    let n = match bsdf {
        Bsdf::Dielectric { .. } => {
            if g.ns.dot(g.ng) < 0.0 {
                -g.ns
            } else {
                g.ns
            }
        }
        _ => {
            if g.ns.dot(wo) < 0.0 {
                -g.ns
            } else {
                g.ns
            }
        }
    };
    match bsdf {
        Bsdf::KajiyaKay { .. } => fibre_frame(n, g.dpdu),
        _ => Frame::from_z(n),
    }
}

pub(super) fn radiance(scene: &Scene, camera_ray: &Ray, mut first: Option<Option<SurfaceHit>>, sampler: &mut PixelSampler, c: &mut Counters, direct_only: bool) -> Rgb {
    let s = &scene.settings;
    let strategy = s.light_sampling;
    let mut l = Rgb::ZERO;
    let mut beta = Rgb::ONE;
    let mut ray = *camera_ray;
    // What the previous bounce knows for weighting emission found by BSDF sampling.
    let mut specular = true;
    let mut prev_pdf = 0.0f32;
    let mut prev_p = ray.origin;
    for depth in 1..=s.max_depth {
        let Some(hit) = first.take().unwrap_or_else(|| scene.intersect(&ray, c)) else {
            l += beta * scene.background(ray.dir) * environment_weight(scene, specular, prev_pdf, ray.dir);
            break;
        };
        let wo = -ray.dir.normalize();
        let le = scene.emitted(&hit, wo);
        if le != Rgb::ZERO {
            let weight = if specular || strategy == LightSampling::Bsdf {
                1.0
            } else if strategy == LightSampling::Mis {
                let light_pdf = scene.area_lights.pdf(&scene.geometry, strategy, hit.prim, prev_p, hit.geom.p, hit.geom.ng);
                s.mis_heuristic.weight(prev_pdf, light_pdf)
            } else {
                0.0 // counted by light sampling at the previous vertex
            };
            l += beta * le * weight;
        }
        if depth == s.max_depth || (direct_only && !specular && depth > 1) {
            break;
        }
        let material = &scene.materials[hit.material.0 as usize];
        let bsdf = material.bsdf(&scene.textures, hit.geom.uv, hit.geom.p);
        let frame = shading_frame(&hit, &bsdf, wo);
        let wo_local = frame.to_local(wo);
        if !bsdf.is_delta() {
            l += beta * direct_light(scene, &hit, &bsdf, &frame, wo, sampler, c);
        }
        let Some(bs) = bsdf.sample(wo_local, sampler.get_1d(), sampler.get_2d()) else { break };
        if bs.pdf <= 0.0 || bs.f == Rgb::ZERO {
            break;
        }
        let wi = frame.to_world(bs.wi);
        // Reflection must stay on `wo`'s side of the real surface, transmission cross it:
        // otherwise interpolated normals would let light through.
        let reflect = bs.wi.z * wo_local.z > 0.0;
        if reflect != (wi.dot(hit.geom.ng) * wo.dot(hit.geom.ng) > 0.0) {
            break;
        }
        beta *= bs.f * bs.wi.z.abs() / bs.pdf;
        specular = bs.delta;
        prev_pdf = bs.pdf;
        prev_p = hit.geom.p;
        ray = hit.spawn(wi);
        // Russian roulette after three bounces (pbrt-v4): unbiased, bounded weights.
        if depth >= 3 {
            let q = (1.0 - beta.max_element()).max(0.05);
            if sampler.get_1d() < q {
                break;
            }
            beta /= 1.0 - q;
        }
    }
    l
}

/// The share of background radiance found by BSDF sampling: all of it without an environment
/// light or after a specular bounce; under MIS the power heuristic against environment
/// sampling; none under the other light-sampling strategies, whose environment samples
/// already counted it.
fn environment_weight(scene: &Scene, specular: bool, prev_pdf: f32, dir: Vec3) -> f32 {
    let strategy = scene.settings.light_sampling;
    match &scene.environment {
        Some(env) if !specular && strategy.samples_lights() => {
            if strategy == LightSampling::Mis {
                scene.settings.mis_heuristic.weight(prev_pdf, env.pdf(dir.normalize()))
            } else {
                0.0
            }
        }
        _ => 1.0,
    }
}

/// Direct light at a non-specular hit: every delta light, plus one area-light sample and,
/// for MIS, the BSDF sample's share is added when that path hits the emitter.
fn direct_light(scene: &Scene, hit: &SurfaceHit, bsdf: &Bsdf, frame: &Frame, wo: Vec3, sampler: &mut PixelSampler, c: &mut Counters) -> Rgb {
    let wo_local = frame.to_local(wo);
    let ng = hit.geom.ng;
    let same_side = |wi: Vec3| wi.dot(ng) * wo.dot(ng) > 0.0 || matches!(bsdf, Bsdf::Dielectric { .. });
    let mut l = Rgb::ZERO;
    for light in &scene.lights {
        for k in 0..light.sample_count() {
            let u = if light.is_jittered() { sampler.get_2d() } else { Vec2::ZERO };
            let Some(ls) = light.sample(hit.geom.p, k, u) else { continue };
            if !same_side(ls.wi) {
                continue;
            }
            let wi_local = frame.to_local(ls.wi);
            let f = bsdf.eval(wo_local, wi_local);
            if f == Rgb::ZERO || scene.occluded(&hit.spawn_to(ls.wi, ls.dist), c) {
                continue;
            }
            l += f * ls.irradiance * wi_local.z.abs();
        }
    }
    let strategy = scene.settings.light_sampling;
    if let Some(env) = &scene.environment {
        let u = sampler.get_2d();
        if let Some(es) = env.sample(u).filter(|es| strategy.samples_lights() && same_side(es.wi)) {
            let wi_local = frame.to_local(es.wi);
            let f = bsdf.eval(wo_local, wi_local);
            if f != Rgb::ZERO && !scene.occluded(&hit.spawn_to(es.wi, f32::INFINITY), c) {
                let weight = if strategy == LightSampling::Mis { scene.settings.mis_heuristic.weight(es.pdf, bsdf.pdf(wo_local, wi_local)) } else { 1.0 };
                l += f * es.le * (wi_local.z.abs() * weight / es.pdf);
            }
        }
    }
    let (u_choice, u) = (sampler.get_1d(), sampler.get_2d());
    if scene.area_lights.is_empty() || !strategy.samples_lights() {
        return l;
    }
    let receiver = |wi: Vec3| {
        let wi_local = frame.to_local(wi);
        luminance(bsdf.eval(wo_local, wi_local)) * wi_local.z.abs()
    };
    let Some(ls) = scene.area_lights.sample(&scene.geometry, &scene.textures, hit.geom.p, &receiver, strategy, u_choice, u) else { return l };
    if ls.pdf <= 0.0 || !same_side(ls.wi) {
        return l;
    }
    let wi_local = frame.to_local(ls.wi);
    let f = bsdf.eval(wo_local, wi_local);
    if f == Rgb::ZERO || scene.occluded(&hit.spawn_to(ls.wi, ls.dist), c) {
        return l;
    }
    let weight = if strategy == LightSampling::Mis { scene.settings.mis_heuristic.weight(ls.pdf, bsdf.pdf(wo_local, wi_local)) } else { 1.0 };
    l + f * ls.le * (wi_local.z.abs() * weight / ls.pdf)
}
