//! Whitted-style recursive ray tracing.
//!
//! `depth` counts path segments from the camera (the camera ray is segment 1). Light from
//! a point light reaches the camera over two segments, so direct lighting at a hit reached
//! by segment `d` needs `d + 1 ≤ max_depth`, and so does a reflected or refracted ray.

use raylab_accel::Counters;
use raylab_core::{Frame, Ray, Rgb, Vec2, Vec3};

use crate::sampler::PixelSampler;

use crate::light::Light;
use crate::bsdf::{fibre_frame, fresnel_dielectric, reflect, refract};
use crate::material::Material;
use crate::scene::SurfaceHit;
use crate::Scene;

pub(super) fn radiance(scene: &Scene, ray: &Ray, first: Option<Option<SurfaceHit>>, depth: u32, sampler: &mut PixelSampler, c: &mut Counters) -> Rgb {
    let Some(hit) = first.unwrap_or_else(|| scene.intersect(ray, c)) else {
        return scene.background(ray.dir);
    };
    let wo = -ray.dir.normalize();
    let g = &hit.geom;
    let le = scene.emitted(&hit, wo);
    if depth + 1 > scene.settings.max_depth {
        return le;
    }
    let tex = &scene.textures;
    le + match &scene.materials[hit.material.0 as usize] {
        Material::Diffuse { albedo } => {
            let kd = albedo.eval(tex, g.uv, g.p) * std::f32::consts::FRAC_1_PI;
            direct(scene, &hit, wo, sampler, c, |_wi, _n| kd)
        }
        Material::Phong { ka, kd, ks, exponent } => {
            let (ka, kd, ks) = (ka.eval(tex, g.uv, g.p), kd.eval(tex, g.uv, g.p), ks.eval(tex, g.uv, g.p));
            let ambient: Rgb = scene.lights.iter().map(|l| if let Light::Ambient { intensity } = l { *intensity } else { Rgb::ZERO }).sum();
            // Classic Phong is not a BRDF: `kd` multiplies cos θ directly. Dividing by cos θ
            // here makes `direct` (which multiplies by it) produce exactly the textbook sum.
            ka * ambient
                + direct(scene, &hit, wo, sampler, c, |wi, n| {
                    let cos = n.dot(wi).max(1e-8);
                    let spec = reflect(wi, n).dot(wo).max(0.0).powf(*exponent);
                    kd + ks * (spec / cos)
                })
        }
        m @ (Material::CookTorrance { .. } | Material::Conductor { .. } | Material::MetallicRoughness { .. }) => {
            // Microfacet reflection of the delta lights, by the physically based BSDF.
            let bsdf = m.bsdf(tex, g.uv, g.p);
            let frame = Frame::from_z(facing(g.ns, wo));
            let wo_local = frame.to_local(wo);
            direct(scene, &hit, wo, sampler, c, |wi, _n| bsdf.eval(wo_local, frame.to_local(wi)))
        }
        m @ Material::Hair { .. } => {
            // Kajiya–Kay needs the fibre's direction: the frame's x is the tangent.
            let bsdf = m.bsdf(tex, g.uv, g.p);
            let frame = fibre_frame(facing(g.ns, wo), g.dpdu);
            let wo_local = frame.to_local(wo);
            direct(scene, &hit, wo, sampler, c, |wi, _n| bsdf.eval(wo_local, frame.to_local(wi)))
        }
        Material::Mirror { reflectance } => {
            let n = facing(g.ns, wo);
            let r = reflectance.eval(tex, g.uv, g.p);
            r * radiance(scene, &hit.spawn(reflect(wo, n)), None, depth + 1, sampler, c)
        }
        Material::Dielectric { ior } => {
            // Which side are we on? The geometric normal decides; the shading normal bends.
            let entering = g.ng.dot(wo) > 0.0;
            let n = if entering { g.ns } else { -g.ns };
            let eta = if entering { *ior } else { 1.0 / *ior };
            let f = fresnel_dielectric(wo.dot(n).clamp(-1.0, 1.0), eta);
            let mut l = f * radiance(scene, &hit.spawn(reflect(wo, n)), None, depth + 1, sampler, c);
            if f < 1.0 {
                if let Some(wt) = refract(wo, n, eta) {
                    l += (1.0 - f) * radiance(scene, &hit.spawn(wt), None, depth + 1, sampler, c);
                }
            }
            l
        }
    }
}

/// Sum over the delta lights of `f(wi, n) · E · cos θ`, with shadow rays. Surfaces are
/// two-sided: the shading normal is turned towards the viewer.
fn direct(scene: &Scene, hit: &SurfaceHit, wo: Vec3, sampler: &mut PixelSampler, c: &mut Counters, f: impl Fn(Vec3, Vec3) -> Rgb) -> Rgb {
    let n = facing(hit.geom.ns, wo);
    let ng = facing(hit.geom.ng, wo);
    let mut l = Rgb::ZERO;
    for light in &scene.lights {
        for k in 0..light.sample_count() {
            let u = if light.is_jittered() { sampler.get_2d() } else { Vec2::ZERO };
            let Some(s) = light.sample(hit.geom.p, k, u) else { continue };
            let cos = n.dot(s.wi);
            // Light below the geometric surface would leak through it.
            if cos <= 0.0 || ng.dot(s.wi) <= 0.0 {
                continue;
            }
            if scene.occluded(&hit.spawn_to(s.wi, s.dist), c) {
                continue;
            }
            l += f(s.wi, n) * s.irradiance * cos;
        }
    }
    l
}

fn facing(n: Vec3, wo: Vec3) -> Vec3 {
    if n.dot(wo) < 0.0 {
        -n
    } else {
        n
    }
}
