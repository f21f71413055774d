//! Shadow acne on spheres: a shadow ray leaving a sphere towards a light it faces must never
//! hit that same sphere again. Counted pixel by pixel on `scenes/spheres_phong.toml`, where
//! a few dozen ambient-only pixels showed on the green sphere before spheres bounded the
//! error of their hit distance (pbrt-v4 §6.8.5).

use std::path::PathBuf;

use raylab_accel::Counters;
use raylab_core::{Pcg32, Vec2};
use raylab_loader::{load_scene, Overrides};
use raylab_render::shape::PrimRef;
use raylab_render::Light;

#[test]
fn spheres_phong_has_no_self_shadowed_pixels() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/spheres_phong.toml");
    let scene = load_scene(&path, &Overrides { accel: Some(raylab_accel::AccelKind::None), ..Default::default() }).unwrap();
    let lights: Vec<_> = scene.lights.iter().filter_map(|l| if let Light::Point { position, .. } = l { Some(*position) } else { None }).collect();
    assert_eq!(lights.len(), 2);
    let (w, h) = (320, 240);
    let mut counters = Counters::default();
    let mut rng = Pcg32::new(7, 0);
    let (mut sphere_pixels, mut acne) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            // A random point in the pixel, as the jittered sampler would pick.
            let film = Vec2::new((x as f32 + rng.next_f32()) / w as f32, (y as f32 + rng.next_f32()) / h as f32);
            let Some(hit) = scene.intersect(&scene.camera.ray(film, Vec2::ZERO), &mut counters) else { continue };
            if !matches!(scene.geometry.prim(hit.prim), PrimRef::Sphere(_)) {
                continue; // the ground
            }
            sphere_pixels += 1;
            for &light in &lights {
                let to = light - hit.geom.p;
                let wi = to.normalize();
                if wi.dot(hit.geom.ng) <= 0.0 {
                    continue; // facing away: shadowed by itself, correctly
                }
                let shadow = hit.spawn_to(wi, to.length());
                if scene.intersect(&shadow, &mut counters).is_some_and(|s| s.prim == hit.prim) {
                    acne += 1;
                }
            }
        }
    }
    assert!(sphere_pixels > 10_000, "{sphere_pixels}");
    assert_eq!(acne, 0, "{acne} shadow rays of {sphere_pixels} sphere pixels hit their own sphere");
}
