//! Whole-image properties of the renderer, on scenes built in code: analytic radiance,
//! independence from scale (no acne, no light leaks), determinism across thread counts.

use raylab_accel::{AccelKind, BuildOptions};
use raylab_core::{Rgb, Vec3};
use raylab_render::material::TexColor;
use raylab_render::{render, Camera, Light, Material, RenderSettings, SamplerKind, Scene, Sphere, TriangleMesh};

fn quad(scale: f32, y: f32, half: f32) -> TriangleMesh {
    let v = |x: f32, z: f32| Vec3::new(x, y, z) * scale;
    TriangleMesh { name: "floor".into(), positions: vec![v(-half, -half), v(half, -half), v(half, half), v(-half, half)], indices: vec![[0, 1, 2], [0, 2, 3]], ..Default::default() }
}

/// A diffuse floor, a sphere resting on it and a point light, all scaled by `s` (the light's
/// intensity by `s²`, so that irradiance, hence the image, does not change).
fn scaled_scene(s: f32, width: u32, height: u32) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 1.5, 4.0) * s, Vec3::new(0.0, 0.5, 0.0) * s, Vec3::Y, 45.0, width as f32 / height as f32, 0.0, None).unwrap();
    let settings = RenderSettings { width, height, spp: 4, sampler: SamplerKind::Jittered, max_depth: 4, accel: AccelKind::Bvh, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let floor = scene.add_material("floor", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.8)) });
    let ball = scene.add_material("ball", Material::Phong { ka: Rgb::ZERO.into(), kd: Rgb::new(0.7, 0.3, 0.2).into(), ks: Rgb::splat(0.3).into(), exponent: 30.0 });
    scene.geometry.add_mesh(TriangleMesh { material: floor, ..quad(s, 0.0, 5.0) });
    scene.geometry.add_sphere(Sphere { center: Vec3::new(0.0, 0.5, 0.0) * s, radius: 0.5 * s, to_world: raylab_core::Transform::IDENTITY, material: ball, emission: raylab_core::Rgb::ZERO });
    scene.lights.push(Light::Point { position: Vec3::new(1.5, 3.0, 2.0) * s, intensity: Rgb::splat(20.0 * s * s) });
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn diffuse_plane_under_a_point_light_matches_the_closed_form() {
    // Camera straight down at a Lambertian plane (albedo ρ = 0.5) lit by a point light of
    // intensity I = 4 W/sr at height d = 2 right above the centre: L = ρ/π · I cos θ / d².
    let camera = Camera::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings { width: 9, height: 9, spp: 1, ..Default::default() });
    let m = scene.add_material("plane", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) });
    scene.geometry.add_mesh(TriangleMesh { material: m, ..quad(1.0, 0.0, 10.0) });
    scene.lights.push(Light::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(4.0) });
    scene.build_accel(&BuildOptions::default());
    let img = render(&scene, &|_| {});
    let centre = img.pixels[4 * 9 + 4];
    let expected = 0.5 / std::f32::consts::PI * 4.0 / 4.0;
    // The centre pixel spans a 1 cm patch; cos θ / d² varies by under 1e-5 across it.
    assert!((centre.x - expected).abs() < 1e-4 * expected, "{} vs {expected}", centre.x);
    // Off-centre pixels are darker: cos θ / d² = h / (h² + r²)^{3/2}.
    assert!(img.pixels[0].x < centre.x);
}

#[test]
fn same_image_at_every_scale() {
    let (w, h) = (64, 48);
    let reference = render(&scaled_scene(1.0, w, h), &|_| {});
    for s in [1e-3f32, 1e3] {
        let img = render(&scaled_scene(s, w, h), &|_| {});
        let mut max_diff = 0.0f32;
        let mut big = 0;
        for (a, b) in img.pixels.iter().zip(&reference.pixels) {
            let d = (*a - *b).abs().max_element();
            max_diff = max_diff.max(d);
            if d > 0.02 {
                big += 1;
            }
        }
        // Acne or light leaks show as many pixels far off; rounding moves a few edge pixels.
        assert!(big <= 3, "scale {s}: {big} pixels differ by more than 0.02 (max {max_diff})");
    }
    // And the unit scene is not trivially black.
    assert!(reference.pixels.iter().map(|p| p.max_element()).fold(0.0, f32::max) > 0.2);
}

#[test]
fn bit_identical_whatever_the_thread_count() {
    for sampler in [SamplerKind::Jittered, SamplerKind::Random] {
        let mut scene = scaled_scene(1.0, 40, 30);
        scene.settings.sampler = sampler;
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| render(&scene, &|_| {}));
        let three = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap().install(|| render(&scene, &|_| {}));
        assert_eq!(one.pixels, three.pixels, "{sampler}");
        assert_eq!(one.counters, three.counters, "{sampler}");
    }
}
