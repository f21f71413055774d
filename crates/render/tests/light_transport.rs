//! Monte Carlo light transport against closed forms: every light-sampling strategy must
//! converge to the same, known radiance (seeded, so the estimates are deterministic).

use raylab_accel::BuildOptions;
use raylab_core::{Rgb, Transform, Vec3};
use raylab_render::light::LightSampling;
use raylab_render::material::TexColor;
use raylab_render::{render, Camera, IntegratorKind, Material, RenderSettings, SamplerKind, Scene, Sphere, TriangleMesh};

fn floor(material: raylab_render::MaterialId, half: f32) -> TriangleMesh {
    let v = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    // Wound so that the normal points up (+y).
    TriangleMesh { name: "floor".into(), positions: vec![v(-half, -half), v(-half, half), v(half, half), v(half, -half)], indices: vec![[0, 1, 2], [0, 2, 3]], material, ..Default::default() }
}

fn mean(pixels: &[Rgb]) -> f32 {
    pixels.iter().map(|p| p.y).sum::<f32>() / pixels.len() as f32
}

/// A Lambertian floor (ρ = 0.5) seen straight down through a 1° camera, under a sphere light
/// of radius r = 0.5 and radiance Le = 4 centred at height d = 2 (the camera sits below it).
/// Irradiance facing a sphere light is E = π Le (r/d)², so L = ρ/π · E = ρ Le (r/d)² = 0.125.
fn sphere_light_scene(strategy: LightSampling, integrator: IntegratorKind) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 8, height: 8, spp: 256, sampler: SamplerKind::Sobol, integrator, light_sampling: strategy, max_depth: 2, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("floor", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) });
    let black = scene.add_material("light", Material::Diffuse { albedo: TexColor::Constant(Rgb::ZERO) });
    scene.geometry.add_mesh(floor(m, 50.0));
    scene.geometry.add_sphere(Sphere { center: Vec3::new(0.0, 2.0, 0.0), radius: 0.5, to_world: Transform::IDENTITY, material: black, emission: Rgb::splat(4.0) });
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn every_strategy_converges_to_the_sphere_light_closed_form() {
    for (strategy, tolerance) in [(LightSampling::Uniform, 0.03), (LightSampling::SolidAngle, 0.01), (LightSampling::Mis, 0.01), (LightSampling::Bsdf, 0.08)] {
        for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
            let img = render(&sphere_light_scene(strategy, integrator), &|_| {});
            let l = mean(&img.pixels);
            assert!((l - 0.125).abs() < 0.125 * tolerance, "{strategy} {integrator}: {l} (expected 0.125)");
        }
    }
    // The balance heuristic weighs the same two samples differently, to the same mean.
    let mut scene = sphere_light_scene(LightSampling::Mis, IntegratorKind::Direct);
    scene.settings.mis_heuristic = raylab_render::integrator::MisHeuristic::Balance;
    let l = mean(&render(&scene, &|_| {}).pixels);
    assert!((l - 0.125).abs() < 0.125 * 0.01, "balance heuristic: {l} (expected 0.125)");
    {
        {
        }
    }
}

#[test]
fn solid_angle_sampling_has_less_variance_than_area_sampling() {
    // Per-pixel spread of the estimates: cone sampling never wastes a sample on the far
    // half of the sphere, area sampling does.
    let spread = |s| {
        let img = render(&sphere_light_scene(s, IntegratorKind::Direct), &|_| {});
        let m = mean(&img.pixels);
        img.pixels.iter().map(|p| (p.y - m).powi(2)).sum::<f32>() / img.pixels.len() as f32
    };
    let (area, cone) = (spread(LightSampling::Uniform), spread(LightSampling::SolidAngle));
    assert!(cone < 0.5 * area, "cone {cone}, area {area}");
}

#[test]
fn max_depth_one_sees_only_emitters() {
    // Looking up at the sphere light from below: depth 1 shows its radiance, nothing else.
    let camera = Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 2.0, 0.0), Vec3::Z, 1.0, 1.0, 0.0, None).unwrap();
    let mut scene = sphere_light_scene(LightSampling::Mis, IntegratorKind::Path);
    scene.camera = camera;
    scene.settings.max_depth = 1;
    let img = render(&scene, &|_| {});
    assert!(img.pixels.iter().all(|p| *p == Rgb::splat(4.0)), "{:?}", img.pixels[0]);
}

/// A closed box, every face emitting Le = 1 inwards and reflecting with albedo ρ: the
/// radiance everywhere is Le / (1 - ρ) (the "furnace"). Tests the path tracer's
/// throughput, Russian roulette and MIS over many bounces.
#[test]
fn path_tracer_passes_the_emitting_furnace() {
    let rho = 0.5;
    let camera = Camera::new(Vec3::ZERO, Vec3::new(0.3, 0.2, 1.0), Vec3::Y, 60.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 8, height: 8, spp: 64, sampler: SamplerKind::Sobol, integrator: IntegratorKind::Path, max_depth: 200, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("wall", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(rho)) });
    let c = |i: u32| Vec3::new(if i & 1 == 0 { -1.0 } else { 1.0 }, if i & 2 == 0 { -1.0 } else { 1.0 }, if i & 4 == 0 { -1.0 } else { 1.0 });
    // Faces wound so that their normals point into the box.
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let mut mesh = TriangleMesh { name: "box".into(), positions: (0..8).map(c).collect(), material: m, emission: Rgb::ONE, ..Default::default() };
    for f in faces {
        mesh.indices.push([f[0], f[1], f[2]]);
        mesh.indices.push([f[0], f[2], f[3]]);
    }
    scene.geometry.add_mesh(mesh);
    scene.build_accel(&BuildOptions::default());
    let l = mean(&render(&scene, &|_| {}).pixels);
    let expected = 1.0 / (1.0 - rho);
    assert!((l - expected).abs() < 0.03 * expected, "{l} (expected {expected})");
}

/// The floor under a one-sided 1×1 rect light facing down at height h = 2, radiance 4:
/// irradiance at the point below its centre is 4·π·Le·F(A, B) with the form factor of a
/// corner-aligned rectangle F = (1/2π)[A/√(1+A²)·atan(B/√(1+A²)) + B/√(1+B²)·atan(A/√(1+B²))],
/// A = B = 0.5/h; the floor's radiance is ρ/π·E = 0.146956.
#[test]
fn every_strategy_converges_to_the_rect_light_closed_form() {
    let (a, h) = (0.5f64, 2.0f64);
    let x = a / h;
    let f = (2.0 * x / (1.0 + x * x).sqrt() * (x / (1.0 + x * x).sqrt()).atan()) / (2.0 * std::f64::consts::PI);
    let expected = (0.5 / std::f64::consts::PI * 4.0 * std::f64::consts::PI * 4.0 * f) as f32;
    assert!((expected - 0.146956).abs() < 1e-5, "{expected}");
    for (strategy, tolerance) in [(LightSampling::Uniform, 0.02), (LightSampling::Cells, 0.02), (LightSampling::SolidAngle, 0.02), (LightSampling::Mis, 0.02), (LightSampling::Bsdf, 0.1)] {
        let l = mean(&render(&rect_light_scene(strategy, 0.5, 2.0, 256), &|_| {}).pixels);
        assert!((l - expected).abs() < expected * tolerance, "{strategy}: {l} (expected {expected})");
    }
}

/// The floor seen from straight above under a square light of half-size `half` at height
/// `h`, radiance 4, one-sided facing down.
fn rect_light_scene(strategy: LightSampling, half: f32, h: f32, spp: u32) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, h / 2.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 8, height: 8, spp, sampler: SamplerKind::Random, integrator: IntegratorKind::Direct, light_sampling: strategy, max_depth: 2, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("floor", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) });
    let black = scene.add_material("light", Material::Diffuse { albedo: TexColor::Constant(Rgb::ZERO) });
    scene.geometry.add_mesh(floor(m, 50.0));
    // A sphere out of the way, added before the light: primitive indices no longer follow
    // mesh order (the `cells` strategy once lost its rects that way).
    scene.geometry.add_sphere(Sphere { center: Vec3::new(40.0, 1.0, 40.0), radius: 0.5, to_world: Transform::IDENTITY, material: m, emission: Rgb::ZERO });
    // Vertices in order with (v1 - v0) × (v2 - v0) pointing down.
    let v = |x: f32, z: f32| Vec3::new(x, h, z);
    let positions = vec![v(-half, -half), v(half, -half), v(half, half), v(-half, half)];
    scene.geometry.add_mesh(TriangleMesh { name: "rect".into(), positions, indices: vec![[0, 1, 2], [0, 2, 3]], material: black, emission: Rgb::splat(4.0), ..Default::default() });
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn cells_importance_sampling_beats_uniform_under_a_large_close_light() {
    // A 10×10 light 0.3 above the floor: uniform area samples mostly land far away where
    // they contribute little; the cells' CDF puts them above the point.
    let spread = |s| {
        let img = render(&rect_light_scene(s, 5.0, 0.3, 16), &|_| {});
        let m = mean(&img.pixels);
        (m, img.pixels.iter().map(|p| (p.y - m).powi(2)).sum::<f32>() / img.pixels.len() as f32)
    };
    let ((_, vu), (mc, vc), (ms, vs)) = (spread(LightSampling::Uniform), spread(LightSampling::Cells), spread(LightSampling::SolidAngle));
    // Closed form as above with A = B = 5 / 0.3: L = 1.99416.
    assert!((mc - 1.99416).abs() < 0.03 * 1.99416, "cells mean {mc}");
    assert!(vc < 0.25 * vu, "variance: cells {vc}, uniform {vu}");
    // Spherical-rectangle sampling spreads samples evenly over the solid angle.
    assert!((ms - 1.99416).abs() < 0.03 * 1.99416, "solid-angle mean {ms}");
    assert!(vs < 0.25 * vu, "variance: solid angle {vs}, uniform {vu}");
}

#[test]
fn finer_cell_grids_stay_unbiased_and_cut_variance_under_a_large_close_light() {
    // The report's experiment with the number of light partitions: 1 cell is uniform area
    // sampling; more cells follow the irradiance better.
    let spread = |k| {
        let mut scene = rect_light_scene(LightSampling::Cells, 5.0, 0.3, 16);
        scene.settings.light_cells = k;
        scene.build_accel(&BuildOptions::default());
        let img = render(&scene, &|_| {});
        let m = mean(&img.pixels);
        (m, img.pixels.iter().map(|p| (p.y - m).powi(2)).sum::<f32>() / img.pixels.len() as f32)
    };
    let variances: Vec<f32> = [1, 4, 16]
        .into_iter()
        .map(|k| {
            let (m, v) = spread(k);
            // Unbiased: within four standard errors of the mean of 64 independent pixels.
            let se = (v / 64.0).sqrt();
            assert!((m - 1.99416).abs() < 4.0 * se + 0.005, "{k}×{k} cells: mean {m} ± {se}");
            v
        })
        .collect();
    assert!(variances[1] < 0.5 * variances[0] && variances[2] < 0.5 * variances[1], "variance by grid 1, 4, 16: {variances:?}");
}

#[test]
fn textured_rect_lights_scale_their_radiance_by_the_texture() {
    use raylab_render::texture::{Checker, CheckerSpace, Texture};
    // A constant texture of 0.5 halves the closed form of the 1×1 light above (0.146956).
    let mut estimates = Vec::new();
    for strategy in [LightSampling::Uniform, LightSampling::Cells, LightSampling::Mis] {
        let mut scene = rect_light_scene(strategy, 0.5, 2.0, 256);
        scene.settings.sampler = SamplerKind::Sobol;
        let t = scene.add_texture("half", Texture::Constant(Rgb::splat(0.5)));
        scene.geometry.meshes.last_mut().unwrap().emission_texture = Some(t);
        let l = mean(&render(&scene, &|_| {}).pixels);
        assert!((l - 0.073478).abs() < 0.02 * 0.073478, "{strategy}: {l}");
        // A window of 4×4 panes, alternately clear and black: strategies must agree.
        let mut scene = rect_light_scene(strategy, 0.5, 2.0, 1024);
        scene.settings.sampler = SamplerKind::Sobol;
        let panes = Checker { even: Rgb::ONE, odd: Rgb::ZERO, scale: 4.0, space: CheckerSpace::Uv };
        let t = scene.add_texture("window", Texture::Checker(panes));
        scene.geometry.meshes.last_mut().unwrap().emission_texture = Some(t);
        estimates.push((strategy, mean(&render(&scene, &|_| {}).pixels)));
    }
    let (_, reference) = estimates[0];
    // Half the panes are black and the light is symmetric about the point: about half.
    assert!((reference - 0.073478).abs() < 0.1 * 0.073478, "{reference}");
    for (strategy, l) in estimates {
        assert!((l - reference).abs() < 0.03 * reference, "{strategy}: {l} against uniform {reference}");
    }
}

/// The Lambertian floor (ρ = 0.5) seen straight down, lit only by an environment map.
fn environment_scene(image: raylab_render::texture::ImageTexture, strategy: LightSampling, spp: u32) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, Vec3::Z, 1.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 8, height: 8, spp, sampler: SamplerKind::Sobol, integrator: IntegratorKind::Direct, light_sampling: strategy, max_depth: 2, ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("floor", Material::Diffuse { albedo: TexColor::Constant(Rgb::splat(0.5)) });
    scene.geometry.add_mesh(floor(m, 50.0));
    scene.environment = Some(raylab_render::light::EnvironmentLight::new(image, Rgb::ONE));
    scene.build_accel(&BuildOptions::default());
    scene
}

fn env_image(w: u32, h: u32, texel: impl Fn(u32, u32) -> Rgb) -> raylab_render::texture::ImageTexture {
    use raylab_render::texture::{Filter, ImageTexture, Wrap};
    let texels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| texel(x, y)).collect();
    ImageTexture::new(w, h, texels, Wrap::Repeat, Filter::Bilinear).unwrap()
}

#[test]
fn every_strategy_sees_albedo_times_a_constant_environment() {
    // Under uniform radiance L from the whole sky, L_o = ρ/π · L · π = ρ L = 1.
    for strategy in [LightSampling::Uniform, LightSampling::Cells, LightSampling::Bsdf, LightSampling::Mis] {
        let img = render(&environment_scene(env_image(16, 8, |_, _| Rgb::splat(2.0)), strategy, 64), &|_| {});
        let l = mean(&img.pixels);
        assert!((l - 1.0).abs() < 0.01, "{strategy}: {l}");
    }
}

#[test]
fn environment_importance_sampling_agrees_with_bsdf_sampling_and_beats_it_under_a_sun() {
    // A dim sky and a 2×2-texel sun high above the floor.
    let sun = |x: u32, y: u32| if (10..12).contains(&x) && (3..5).contains(&y) { Rgb::splat(500.0) } else { Rgb::splat(0.2) };
    let stats = |strategy, spp| {
        let img = render(&environment_scene(env_image(32, 16, sun), strategy, spp), &|_| {});
        let m = mean(&img.pixels);
        (m, img.pixels.iter().map(|p| (p.y - m).powi(2)).sum::<f32>() / img.pixels.len() as f32)
    };
    let (reference, _) = stats(LightSampling::Bsdf, 1024);
    let (_, bsdf_var) = stats(LightSampling::Bsdf, 64);
    for strategy in [LightSampling::Uniform, LightSampling::Mis] {
        let (m, var) = stats(strategy, 64);
        assert!((m - reference).abs() < 0.03 * reference, "{strategy}: {m}, bsdf sampling at 1024 spp: {reference}");
        // Per-pixel spread at equal sample counts.
        assert!(var * 10.0 < bsdf_var, "{strategy}: variance {var}, bsdf {bsdf_var}");
    }
}

#[test]
fn cells_follow_the_receiver_and_keep_a_defensive_share_elsewhere() {
    // A receiver that reflects only light arriving from +x: cells on the −x half get only
    // their part of the 10 % uniform share, 0.1 × 32/64 = 5 % of the samples.
    let scene = rect_light_scene(LightSampling::Cells, 0.5, 2.0, 1);
    let receiver = |wi: Vec3| if wi.x > 0.0 { 1.0 } else { 0.0 };
    let mut rng = raylab_core::Pcg32::new(5, 0);
    let n = 40_000;
    let mut left = 0;
    for _ in 0..n {
        let s = scene.area_lights.sample(&scene.geometry, &scene.textures, Vec3::ZERO, &receiver, LightSampling::Cells, rng.next_f32(), rng.next_vec2()).unwrap();
        left += usize::from(s.wi.x < 0.0);
    }
    let share = left as f32 / n as f32;
    assert!((share - 0.05).abs() < 0.006, "share of samples from the −x half: {share}");
}
