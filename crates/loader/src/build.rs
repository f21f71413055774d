//! The one builder: a [`SceneDescription`] and the command line's overrides to a render
//! [`Scene`] with its acceleration structure.

use raylab_render::{Camera, IntegratorKind, Light, RenderSettings, SamplerKind, Scene};

use crate::description::SceneDescription;
use crate::error::LoadError;
use raylab_render::Overrides;

/// Settings: the defaults, then the description's, then the command line's.
pub fn settings(desc: &SceneDescription, overrides: &Overrides) -> Result<RenderSettings, LoadError> {
    let mut s = RenderSettings::default();
    desc.settings.apply(&mut s);
    overrides.apply(&mut s);
    if let Some(note) = round_up_jittered_spp(&mut s) {
        eprintln!("note: {note}");
    }
    if let Err(e) = s.sampler.check_spp(s.spp) {
        return Err(match (overrides.spp, &desc.spp_span) {
            (None, Some(span)) => span.err(e),
            (Some(_), _) => LoadError::new(&desc.file, None, "--spp", e),
            _ => LoadError::new(&desc.file, None, "render.spp", e),
        });
    }
    Ok(s)
}

/// Stratification needs n × n samples: a non-square `spp` with the jittered sampler is
/// rounded up, as Mitsuba's stratified sampler does, and said once rather than failed.
/// Returns what to say, when it rounded.
pub fn round_up_jittered_spp(s: &mut RenderSettings) -> Option<String> {
    let n = jittered_strata(s.sampler, s.spp)?;
    let note = format!("the jittered sampler stratifies {n}×{n}: {} samples per pixel rounded up to {}", s.spp, n * n);
    s.spp = n * n;
    Some(note)
}

/// The side of the square grid of strata a non-square `spp` is rounded up to, for the
/// jittered sampler; `None` when nothing needs rounding.
pub fn jittered_strata(sampler: SamplerKind, spp: u32) -> Option<u32> {
    if sampler != SamplerKind::Jittered || spp == 0 {
        return None;
    }
    let n = (spp as f64).sqrt().ceil() as u32;
    (n * n != spp).then_some(n)
}

/// Builds the scene the description describes, with the acceleration structure and build
/// options the settings and overrides name.
pub fn build_scene(desc: SceneDescription, overrides: &Overrides) -> Result<Scene, LoadError> {
    let settings = settings(&desc, overrides)?;
    let c = &desc.camera;
    let camera = Camera::new(c.from, c.at, c.up, c.vfov, settings.width as f32 / settings.height as f32, c.aperture, c.focus_distance).map_err(|e| {
        let (field, msg) = e.split_once(": ").unwrap_or(("camera", &e));
        let span = if field == "camera.up" { &c.up_span } else { &c.at_span };
        LoadError::new(&span.file, span.line, field, msg)
    })?;
    let mut scene = Scene::new(camera, settings);
    scene.geometry = desc.geometry;
    scene.materials = desc.materials;
    scene.material_names = desc.material_names;
    scene.material_perturbations = desc.material_perturbations;
    scene.textures = desc.textures;
    scene.texture_names = desc.texture_names;
    scene.lights = desc.lights;
    scene.background = desc.background;
    scene.environment = desc.environment;
    let opts = overrides.build.clone().or(desc.settings.build.clone()).unwrap_or_default();
    scene.build_accel(&opts);
    Ok(scene)
}

/// Why a render of `scene` is certain to come out black, if it is: said once, before
/// rendering, so that a user does not wait for a black image.
pub fn black_render_warnings(scene: &Scene) -> Vec<String> {
    let s = &scene.settings;
    let lit = matches!(s.integrator, IntegratorKind::Whitted | IntegratorKind::Direct | IntegratorKind::Path);
    if !lit {
        return Vec::new();
    }
    let has_emitters = !scene.area_lights.is_empty();
    let has_env = scene.environment.is_some();
    let background_lit = !matches!(scene.background, raylab_render::Background::Color(c) if c == raylab_core::Rgb::ZERO);
    let delta_lights = scene.lights.iter().any(|l| !matches!(l, Light::Ambient { intensity } if *intensity == raylab_core::Rgb::ZERO));
    let mut out = Vec::new();
    if !delta_lights && !has_emitters && !has_env && !background_lit {
        out.push(format!("the scene has no lights and a black background: the `{}` integrator will render a black image", s.integrator));
    } else if s.integrator == IntegratorKind::Whitted && !delta_lights && has_emitters && !has_env {
        out.push("the scene is lit only by area lights (emitters), which `whitted` does not sample: only the emitters themselves will show; use --integrator path or direct".to_string());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jittered_spp_rounds_up_to_the_next_square() {
        assert_eq!(jittered_strata(SamplerKind::Jittered, 5), Some(3));
        assert_eq!(jittered_strata(SamplerKind::Jittered, 10), Some(4));
        assert_eq!(jittered_strata(SamplerKind::Jittered, 16), None);
        assert_eq!(jittered_strata(SamplerKind::Jittered, 1), None);
        assert_eq!(jittered_strata(SamplerKind::Sobol, 5), None);
    }
}

