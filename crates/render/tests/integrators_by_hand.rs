//! The integrators ray by ray, against values worked by hand: one camera ray traced through
//! `IntegratorKind::radiance` with a seeded sampler per sample, on scenes small enough that the
//! answer is a formula. Where the estimator has no variance (a point light on a Lambertian
//! floor, a mirror, a furnace under BSDF sampling) every single sample must give the value;
//! elsewhere the mean of a few thousand samples must be within four standard errors of it.

use raylab_accel::{BuildOptions, Counters};
use raylab_core::{Ray, Rgb, Transform, Vec2, Vec3};
use raylab_render::integrator::MisHeuristic;
use raylab_render::light::{EnvironmentLight, LightSampling};
use raylab_render::material::TexColor;
use raylab_render::texture::{Filter, ImageTexture, Wrap};
use raylab_render::{Background, Camera, IntegratorKind, Light, Material, MaterialId, PixelSampler, RenderSettings, SamplerKind, Scene, Sphere, TriangleMesh};

const PI: f32 = std::f32::consts::PI;
const STRATEGIES: [LightSampling; 5] = [LightSampling::Uniform, LightSampling::SolidAngle, LightSampling::Cells, LightSampling::Bsdf, LightSampling::Mis];

fn empty_scene(integrator: IntegratorKind, strategy: LightSampling, max_depth: u32) -> Scene {
    // The camera is not used: rays are traced one by one.
    let camera = Camera::new(Vec3::new(0.0, 1.0, 0.0), Vec3::ZERO, Vec3::Z, 45.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 1, height: 1, spp: 1, sampler: SamplerKind::Random, integrator, light_sampling: strategy, max_depth, ..Default::default() };
    Scene::new(camera, settings)
}

fn diffuse(scene: &mut Scene, albedo: Rgb) -> MaterialId {
    scene.add_material("diffuse", Material::Diffuse { albedo: TexColor::Constant(albedo) })
}

/// The rectangle [x0, x1] × [z0, z1] in the plane y = `y`, its winding normal up (+y) or down.
fn rect(material: MaterialId, y: f32, (x0, x1): (f32, f32), (z0, z1): (f32, f32), up: bool) -> TriangleMesh {
    let v = |x: f32, z: f32| Vec3::new(x, y, z);
    // (v1 − v0) × (v2 − v0) = (0, 0, dz) × (dx, 0, dz) = (0, dx·dz, 0): up.
    let indices = if up { vec![[0, 1, 2], [0, 2, 3]] } else { vec![[0, 2, 1], [0, 3, 2]] };
    TriangleMesh { name: "rect".into(), positions: vec![v(x0, z0), v(x0, z1), v(x1, z1), v(x1, z0)], indices, material, ..Default::default() }
}

fn floor(material: MaterialId, y: f32, half: f32, up: bool) -> TriangleMesh {
    rect(material, y, (-half, half), (-half, half), up)
}

/// The cube [−1, 1]³, faces wound so that their normals point inwards.
fn inward_box(material: MaterialId, emission: Rgb) -> TriangleMesh {
    let c = |i: u32| Vec3::new(if i & 1 == 0 { -1.0 } else { 1.0 }, if i & 2 == 0 { -1.0 } else { 1.0 }, if i & 4 == 0 { -1.0 } else { 1.0 });
    let faces = [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]];
    let mut mesh = TriangleMesh { name: "box".into(), positions: (0..8).map(c).collect(), material, emission, ..Default::default() };
    for f in faces {
        mesh.indices.push([f[0], f[1], f[2]]);
        mesh.indices.push([f[0], f[2], f[3]]);
    }
    mesh
}

fn constant_environment(radiance: f32, scale: Rgb) -> EnvironmentLight {
    let texels = vec![Rgb::splat(radiance); 8 * 4];
    EnvironmentLight::new(ImageTexture::new(8, 4, texels, Wrap::Repeat, Filter::Bilinear).unwrap(), scale)
}

/// Sample `index` of the ray (its own sampler stream), and the rays it traced.
fn trace_counted(scene: &Scene, ray: &Ray, index: u32) -> (Rgb, Counters) {
    let mut sampler = PixelSampler::new(SamplerKind::Random, 1, 11, 3, 5, index);
    let mut counters = Counters::default();
    let l = scene.settings.integrator.radiance(scene, ray, &mut sampler, &mut counters);
    (l, counters)
}

fn trace(scene: &Scene, ray: &Ray, index: u32) -> Rgb {
    trace_counted(scene, ray, index).0
}

fn close(a: Rgb, b: Rgb, rel: f32) -> bool {
    (a - b).abs().max_element() <= rel * b.abs().max_element() + 1e-7
}

/// Every one of `n` samples is `want` (to rounding).
fn assert_every_sample(scene: &Scene, ray: &Ray, n: u32, want: Rgb, what: &str) {
    for i in 0..n {
        let l = trace(scene, ray, i);
        assert!(close(l, want, 2e-5), "{what}, sample {i}: {l} (expected {want})");
    }
}

/// The mean of `n` samples, per channel, and the standard error of the green channel's.
fn mean_and_error(scene: &Scene, ray: &Ray, n: u32) -> (Rgb, f32) {
    let (mut sum, mut sum2) = (Rgb::ZERO, 0.0f64);
    for i in 0..n {
        let l = trace(scene, ray, i);
        assert!(l.is_finite() && l.min_element() >= 0.0, "sample {i}: {l}");
        sum += l;
        sum2 += (l.y as f64).powi(2);
    }
    let mean = sum / n as f32;
    let var = (sum2 / n as f64 - (mean.y as f64).powi(2)).max(0.0);
    (mean, (var / n as f64).sqrt() as f32)
}

fn assert_mean(scene: &Scene, ray: &Ray, n: u32, want: f32, what: &str) {
    let (m, se) = mean_and_error(scene, ray, n);
    assert!((m.y - want).abs() <= 4.0 * se + 1e-4 * want, "{what}: {} ± {se} (expected {want})", m.y);
}

/// A ray from `from` to `to`, its direction of length ½ (the integrators must normalise).
fn ray_between(from: Vec3, to: Vec3) -> Ray {
    Ray::new(from, 0.5 * (to - from).normalize())
}

/// The Lambertian floor ρ = (0.5, 0.25, 0.125) at y = 0 under a point light of intensity 4
/// at (0, 2, 0) (or (0, −2, 0) with `below`), a constant background `c`, and a ray arriving
/// at p = (1, 0, 0) from the direction (0.6, ±0.8, 0) on the light's side.
const ALBEDO: Rgb = Rgb::new(0.5, 0.25, 0.125);
const BACKGROUND: Rgb = Rgb::new(0.1, 0.2, 0.3);

fn point_light_scene(integrator: IntegratorKind, strategy: LightSampling, max_depth: u32, light_y: f32) -> Scene {
    let mut scene = empty_scene(integrator, strategy, max_depth);
    let m = diffuse(&mut scene, ALBEDO);
    scene.geometry.add_mesh(floor(m, 0.0, 50.0, true));
    scene.lights.push(Light::Point { position: Vec3::new(0.0, light_y, 0.0), intensity: Rgb::splat(4.0) });
    scene.background = Background::Color(BACKGROUND);
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn point_light_on_a_lambertian_floor_is_exact_in_every_sample() {
    // From p = (1, 0, 0) the light is at d = (−1, 2, 0): d² = 5, cos θ = 2/√5, so the
    // irradiance is I cos θ / d² = 4 · (2/√5) / 5 and the reflected radiance ρ/π times it.
    // The one BSDF-sampled direction leaves the floor and sees the background: its weight
    // f cos θ / pdf = (ρ/π) cos θ / (cos θ/π) = ρ, with no environment light weight 1.
    let e = 4.0 * (2.0 / 5f32.sqrt()) / 5.0;
    let direct = ALBEDO * (e / PI);
    let with_background = direct + ALBEDO * BACKGROUND;
    for (y, side) in [(1.0f32, "above"), (-1.0, "below (two-sided)")] {
        let ray = ray_between(Vec3::new(1.0 + 1.2, 1.6 * y, 0.0), Vec3::new(1.0, 0.0, 0.0));
        for strategy in STRATEGIES {
            for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
                for max_depth in [2, 8] {
                    let scene = point_light_scene(integrator, strategy, max_depth, 2.0 * y);
                    assert_every_sample(&scene, &ray, 16, with_background, &format!("{integrator} {strategy} max_depth {max_depth} {side}"));
                }
                // One segment shows emitters only: the floor emits nothing.
                assert_every_sample(&point_light_scene(integrator, strategy, 1, 2.0 * y), &ray, 4, Rgb::ZERO, &format!("{integrator} max_depth 1 {side}"));
                // The light on the other side: only the background, through the BSDF sample.
                assert_every_sample(&point_light_scene(integrator, strategy, 8, -2.0 * y), &ray, 16, ALBEDO * BACKGROUND, &format!("{integrator} {strategy} light opposite {side}"));
            }
        }
        // Whitted: the direct term only (diffuse surfaces reflect no background), and it
        // needs two segments.
        let whitted = |max_depth, light_y| point_light_scene(IntegratorKind::Whitted, LightSampling::Mis, max_depth, light_y);
        assert_every_sample(&whitted(2, 2.0 * y), &ray, 1, direct, &format!("whitted {side}"));
        assert_every_sample(&whitted(1, 2.0 * y), &ray, 1, Rgb::ZERO, &format!("whitted max_depth 1 {side}"));
        assert_every_sample(&whitted(8, -2.0 * y), &ray, 1, Rgb::ZERO, &format!("whitted light opposite {side}"));
    }
}

#[test]
fn light_behind_the_geometric_surface_does_not_leak_through_shading_normals() {
    // A floor whose shading normals lean 45° towards +x: ns = (1, 1, 0)/√2, ng = +y. Seen from
    // (0.6, 0.8, 0), p = (1, 0, 0). A point light and a small sphere light just below the
    // floor on the +x side lie in front of ns (wi·ns > 0) but behind the real surface
    // (wi·ng < 0): they must give nothing. The background is black, and BSDF samples below
    // the floor are cut, so every sample is 0.
    let ns = Vec3::new(1.0, 1.0, 0.0).normalize();
    let p = Vec3::new(1.0, 0.0, 0.0);
    let ray = ray_between(p + 2.0 * Vec3::new(0.6, 0.8, 0.0), p);
    let scene_with = |integrator, strategy, light_dir: Vec3, sphere: bool| {
        let mut scene = empty_scene(integrator, strategy, 8);
        let m = diffuse(&mut scene, ALBEDO);
        let black = diffuse(&mut scene, Rgb::ZERO);
        let mut mesh = floor(m, 0.0, 50.0, true);
        mesh.normals = vec![ns; 4];
        scene.geometry.add_mesh(mesh);
        scene.lights.push(Light::Point { position: p + 3.0 * light_dir.normalize(), intensity: Rgb::splat(9.0) });
        if sphere {
            scene.geometry.add_sphere(Sphere { center: Vec3::new(4.0, -0.6, 0.0), radius: 0.2, to_world: Transform::IDENTITY, material: black, emission: Rgb::splat(5.0) });
        }
        scene.build_accel(&BuildOptions::default());
        scene
    };
    let below = Vec3::new(1.0, -0.2, 0.0);
    assert!(below.normalize().dot(ns) > 0.0 && (Vec3::new(4.0, -0.6, 0.0) - p).normalize().dot(ns) > 0.0);
    for strategy in STRATEGIES {
        for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
            assert_every_sample(&scene_with(integrator, strategy, below, true), &ray, 32, Rgb::ZERO, &format!("{integrator} {strategy}"));
        }
    }
    assert_every_sample(&scene_with(IntegratorKind::Whitted, LightSampling::Mis, below, false), &ray, 1, Rgb::ZERO, "whitted");
    // Mirrored above the floor the point light shines, with the cosine taken on the shading
    // normal: E = 9/3² · (wi·ns), L = ρ/π · E.
    let above = Vec3::new(1.0, 0.2, 0.0);
    let want = ALBEDO * (1.0 / PI * above.normalize().dot(ns));
    for integrator in [IntegratorKind::Direct, IntegratorKind::Path, IntegratorKind::Whitted] {
        assert_every_sample(&scene_with(integrator, LightSampling::Mis, above, false), &ray, 16, want, &format!("{integrator} light above"));
    }
}

#[test]
fn an_emitter_seen_directly_shows_its_radiance_from_the_front_only() {
    // A black one-sided emitter at y = 1 facing down, Le = (2, 3, 4). Every strategy counts a
    // camera ray's hit in full (nothing else could have found it); from behind, nothing.
    let le = Rgb::new(2.0, 3.0, 4.0);
    for integrator in [IntegratorKind::Direct, IntegratorKind::Path, IntegratorKind::Whitted] {
        for strategy in STRATEGIES {
            let mut scene = empty_scene(integrator, strategy, 8);
            let black = diffuse(&mut scene, Rgb::ZERO);
            scene.geometry.add_mesh(TriangleMesh { emission: le, ..floor(black, 1.0, 2.0, false) });
            scene.build_accel(&BuildOptions::default());
            let from_below = ray_between(Vec3::new(0.3, 0.0, 0.2), Vec3::new(0.5, 1.0, 0.1));
            assert_every_sample(&scene, &from_below, 8, le, &format!("{integrator} {strategy} front"));
            let from_above = ray_between(Vec3::new(0.3, 2.0, 0.2), Vec3::new(0.5, 1.0, 0.1));
            assert_every_sample(&scene, &from_above, 8, Rgb::ZERO, &format!("{integrator} {strategy} back"));
            // A black surface ends the path: under BSDF sampling (no shadow rays) the camera
            // ray is the only ray traced.
            if strategy == LightSampling::Bsdf && integrator != IntegratorKind::Whitted {
                assert_eq!(trace_counted(&scene, &from_below, 0).1.rays, 1, "{integrator}");
            }
        }
    }
}

/// A Lambertian floor (ρ = 0.5) under a large sphere light, radius r = 0.8 centred at height
/// d = 1 above p = 0 (its lowest point at 0.2), Le = 2: the irradiance from a sphere wholly
/// above the horizon is E = π Le (r/d)², so L = ρ Le (r/d)² = 0.64. BSDF samples hit it with
/// probability (r/d)² = 0.64, so both strategies carry weight under MIS.
#[test]
fn every_strategy_and_heuristic_converges_to_the_large_sphere_light() {
    let ray = ray_between(Vec3::new(2.0, 0.2, 0.0), Vec3::ZERO); // below the sphere all the way
    let want = 0.5 * 2.0 * 0.64;
    let mut configs: Vec<(IntegratorKind, LightSampling, MisHeuristic)> = STRATEGIES.iter().map(|&s| (IntegratorKind::Direct, s, MisHeuristic::Power)).collect();
    configs.push((IntegratorKind::Direct, LightSampling::Mis, MisHeuristic::Balance));
    configs.push((IntegratorKind::Path, LightSampling::Mis, MisHeuristic::Power));
    configs.push((IntegratorKind::Path, LightSampling::Uniform, MisHeuristic::Power));
    for (integrator, strategy, heuristic) in configs {
        let mut scene = empty_scene(integrator, strategy, 8);
        scene.settings.mis_heuristic = heuristic;
        let m = diffuse(&mut scene, Rgb::splat(0.5));
        let black = diffuse(&mut scene, Rgb::ZERO);
        scene.geometry.add_mesh(floor(m, 0.0, 50.0, true));
        scene.geometry.add_sphere(Sphere { center: Vec3::new(0.0, 1.0, 0.0), radius: 0.8, to_world: Transform::IDENTITY, material: black, emission: Rgb::splat(2.0) });
        scene.build_accel(&BuildOptions::default());
        assert_mean(&scene, &ray, 8192, want, &format!("{integrator} {strategy} {heuristic}"));
    }
}

#[test]
fn furnace_under_bsdf_sampling_counts_bounces_exactly() {
    // Inside a closed box emitting Le = 1 everywhere with albedo ρ = 0.5, under BSDF sampling
    // alone each bounce adds β·Le with β = ρ^k exactly (Lambert's weight f cos/pdf is ρ):
    // direct lighting sees 1 + ρ = 1.5, a path cut at three segments 1 + ρ + ρ² = 1.75.
    let ray = Ray::new(Vec3::ZERO, Vec3::new(0.3, 0.2, 1.0));
    let furnace = |integrator, strategy, max_depth| {
        let mut scene = empty_scene(integrator, strategy, max_depth);
        let m = diffuse(&mut scene, Rgb::splat(0.5));
        scene.geometry.add_mesh(inward_box(m, Rgb::ONE));
        scene.build_accel(&BuildOptions::default());
        scene
    };
    assert_every_sample(&furnace(IntegratorKind::Direct, LightSampling::Bsdf, 200), &ray, 32, Rgb::splat(1.5), "direct");
    assert_every_sample(&furnace(IntegratorKind::Path, LightSampling::Bsdf, 3), &ray, 32, Rgb::splat(1.75), "path, 3 segments");
    assert_every_sample(&furnace(IntegratorKind::Path, LightSampling::Bsdf, 1), &ray, 4, Rgb::ONE, "path, 1 segment");
    // With light sampling the same sums hold on average (MIS weights add up to one).
    assert_mean(&furnace(IntegratorKind::Direct, LightSampling::Mis, 200), &ray, 4096, 1.5, "direct, mis");
    assert_mean(&furnace(IntegratorKind::Path, LightSampling::Mis, 3), &ray, 4096, 1.75, "path, mis, 3 segments");
    assert_mean(&furnace(IntegratorKind::Direct, LightSampling::Uniform, 200), &ray, 4096, 1.5, "direct, uniform");
}

#[test]
fn russian_roulette_starts_after_three_bounces_and_keeps_the_furnace_unbiased() {
    // Same furnace, full paths, BSDF sampling only (so every ray traced is a path segment).
    // Segments 1-3 are always traced; after the third bounce β = ρ³ = 1/8 and the path goes
    // on with probability 1 − q = max β = 1/8, its weight divided by that back to β = 1; from
    // then on β = ρ = 1/2 before each roulette: on with probability 1/2, back to 1. Mean
    // segments 3 + (1/8)(1 + 1/2 + 1/4 + ...) = 3.25 (variance 0.6875); mean radiance
    // Le/(1 − ρ) = 2.
    let mut scene = empty_scene(IntegratorKind::Path, LightSampling::Bsdf, 1000);
    let m = diffuse(&mut scene, Rgb::splat(0.5));
    scene.geometry.add_mesh(inward_box(m, Rgb::ONE));
    scene.build_accel(&BuildOptions::default());
    let ray = Ray::new(Vec3::ZERO, Vec3::new(0.3, 0.2, 1.0));
    let n = 8192;
    let (mut rays, mut sum, mut sum2) = (0u64, 0.0f64, 0.0f64);
    for i in 0..n {
        let (l, c) = trace_counted(&scene, &ray, i);
        rays += c.rays;
        sum += l.y as f64;
        sum2 += (l.y as f64).powi(2);
    }
    let mean_rays = rays as f64 / n as f64;
    assert!((mean_rays - 3.25).abs() < 4.0 * (0.6875f64 / n as f64).sqrt(), "{mean_rays} segments per path (expected 3.25)");
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
    assert!((mean - 2.0).abs() < 4.0 * se, "{mean} ± {se} (expected 2)");
}

#[test]
fn a_closed_box_shuts_out_every_light_outside_it() {
    // A point light, a sphere light and a bright sky, all outside a closed grey box: inside,
    // every shadow ray is blocked and every path stays in the box. Every sample is 0.
    for strategy in STRATEGIES {
        for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
            let mut scene = empty_scene(integrator, strategy, 8);
            let m = diffuse(&mut scene, Rgb::splat(0.5));
            let black = diffuse(&mut scene, Rgb::ZERO);
            scene.geometry.add_mesh(inward_box(m, Rgb::ZERO));
            scene.geometry.add_sphere(Sphere { center: Vec3::new(0.0, 4.0, 0.0), radius: 0.5, to_world: Transform::IDENTITY, material: black, emission: Rgb::splat(10.0) });
            scene.lights.push(Light::Point { position: Vec3::new(0.5, 5.0, 0.0), intensity: Rgb::splat(50.0) });
            scene.environment = Some(constant_environment(3.0, Rgb::ONE));
            scene.build_accel(&BuildOptions::default());
            assert_every_sample(&scene, &Ray::new(Vec3::ZERO, Vec3::new(0.1, 1.0, 0.2)), 32, Rgb::ZERO, &format!("{integrator} {strategy}"));
        }
    }
}

#[test]
fn environment_seen_directly_and_reflected_by_a_lambertian_floor() {
    // A constant sky of radiance 2 scaled by (1, 0.75, 0.25). A camera ray that escapes sees it
    // in full under every strategy; the floor (ρ = 0.5) reflects ρ·L: exactly under BSDF
    // sampling (weight ρ, environment weight 1), on average otherwise (green: 0.5 · 1.5).
    let sky = Rgb::new(2.0, 1.5, 0.5);
    for strategy in STRATEGIES {
        for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
            let mut scene = empty_scene(integrator, strategy, 8);
            let m = diffuse(&mut scene, Rgb::splat(0.5));
            scene.geometry.add_mesh(floor(m, 0.0, 50.0, true));
            scene.environment = Some(constant_environment(2.0, Rgb::new(1.0, 0.75, 0.25)));
            scene.build_accel(&BuildOptions::default());
            assert_every_sample(&scene, &ray_between(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.3, 2.0, 0.1)), 8, sky, &format!("{integrator} {strategy} sky"));
            let down = ray_between(Vec3::new(0.4, 1.0, 0.2), Vec3::ZERO);
            if strategy == LightSampling::Bsdf {
                assert_every_sample(&scene, &down, 16, 0.5 * sky, &format!("{integrator} bsdf floor"));
            } else {
                assert_mean(&scene, &down, 4096, 0.75, &format!("{integrator} {strategy} floor"));
            }
        }
    }
}

/// Two parallel mirrors, reflectance r, the floor y = 0 and the ceiling y = 1, both over
/// x ∈ [−1, 1.2]. A ray from (−0.9, 0.5) going down at 45° meets the floor at x = −0.4, the
/// ceiling at 0.6, and would meet the floor again at 1.6, past its edge: it escapes to the
/// background after two reflections, on its third segment.
#[test]
fn mirrors_reflect_the_background_times_their_reflectance_per_bounce() {
    let r = Rgb::new(0.9, 0.5, 0.2);
    let ray = Ray::new(Vec3::new(-0.9, 0.5, 0.0), Vec3::new(1.0, -1.0, 0.0));
    for integrator in [IntegratorKind::Whitted, IntegratorKind::Direct, IntegratorKind::Path] {
        let scene_with = |max_depth, ceiling: bool| {
            let mut scene = empty_scene(integrator, LightSampling::Mis, max_depth);
            let m = scene.add_material("mirror", Material::Mirror { reflectance: TexColor::Constant(r) });
            scene.geometry.add_mesh(rect(m, 0.0, (-1.0, 1.2), (-1.0, 1.0), true));
            if ceiling {
                scene.geometry.add_mesh(rect(m, 1.0, (-1.0, 1.2), (-1.0, 1.0), false));
            }
            scene.background = Background::Color(BACKGROUND);
            scene.build_accel(&BuildOptions::default());
            scene
        };
        // One mirror: r·c, seen from above or (two-sided) from below.
        assert_every_sample(&scene_with(2, false), &ray, 4, r * BACKGROUND, &format!("{integrator}"));
        let from_below = Ray::new(Vec3::new(-0.9, -0.5, 0.0), Vec3::new(1.0, 1.0, 0.0));
        assert_every_sample(&scene_with(2, false), &from_below, 4, r * BACKGROUND, &format!("{integrator} from below"));
        // A mirror's light needs a second segment.
        assert_every_sample(&scene_with(1, false), &ray, 4, Rgb::ZERO, &format!("{integrator} max_depth 1"));
        // Two mirrors: three segments give r²·c, two give nothing.
        assert_every_sample(&scene_with(3, true), &ray, 4, r * r * BACKGROUND, &format!("{integrator} two mirrors"));
        assert_every_sample(&scene_with(2, true), &ray, 4, Rgb::ZERO, &format!("{integrator} two mirrors, max_depth 2"));
    }
}

/// Unpolarised Fresnel reflectance from the side of index `n1` into index `n2` at incidence
/// cosine `cos_i` (Hecht, Optics, §4.6.2), written out in f64.
fn fresnel(n1: f64, n2: f64, cos_i: f64) -> f64 {
    let sin_t = n1 / n2 * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The plane y = 0 bounds glass (n = 1.5) below it (its winding normal up: outside is +y);
/// a black emitter of radiance `le` lies at y = −1 facing up; the background above is c.
fn glass_scene(integrator: IntegratorKind, max_depth: u32, le: f32, flipped_normals: bool) -> Scene {
    glass_scene_of(integrator, max_depth, le, flipped_normals, 1.5)
}

fn glass_scene_of(integrator: IntegratorKind, max_depth: u32, le: f32, flipped_normals: bool, ior: f32) -> Scene {
    let mut scene = empty_scene(integrator, LightSampling::Mis, max_depth);
    let glass = scene.add_material("glass", Material::Dielectric { ior });
    let black = diffuse(&mut scene, Rgb::ZERO);
    let mut surface = floor(glass, 0.0, 50.0, true);
    if flipped_normals {
        // Shading normals against the winding: the mesh then orients ng like them (−y), so
        // the glass is above the plane.
        surface.normals = vec![-Vec3::Y; 4];
    }
    scene.geometry.add_mesh(surface);
    scene.geometry.add_mesh(TriangleMesh { emission: Rgb::splat(le), ..floor(black, -1.0, 50.0, true) });
    scene.background = Background::Color(BACKGROUND);
    scene.build_accel(&BuildOptions::default());
    scene
}

#[test]
fn glass_reflects_totally_beyond_the_critical_angle_and_splits_by_fresnel_below_it() {
    // From inside (y = −0.5) at 60° to the normal: sin θt = 1.5 sin 60° = 1.3 > 1, total
    // internal reflection, the ray goes down to the emitter: L = Le exactly, for every
    // integrator (specular bounces do not end direct lighting).
    let at = |deg: f32, y: f32| Ray::new(Vec3::new(0.0, y, 0.0), Vec3::new(deg.to_radians().sin(), -y.signum() * deg.to_radians().cos(), 0.0));
    for integrator in [IntegratorKind::Whitted, IntegratorKind::Direct, IntegratorKind::Path] {
        assert_every_sample(&glass_scene(integrator, 8, 3.0, false), &at(60.0, -0.5), 16, Rgb::splat(3.0), &format!("{integrator} total internal reflection"));
    }
    // At 30° from inside F = fresnel(1.5, 1, cos 30°): Whitted adds both branches,
    // F·Le + (1 − F)·c; the path tracer picks one with probability F and scales the
    // transmitted radiance by η² = 1.5² on leaving the glass (pbrt's radiance transport).
    let f = fresnel(1.5, 1.0, 30f64.to_radians().cos()) as f32;
    assert!(f > 0.05 && f < 0.3, "{f}");
    let whitted = f * Rgb::splat(3.0) + (1.0 - f) * BACKGROUND;
    assert_every_sample(&glass_scene(IntegratorKind::Whitted, 8, 3.0, false), &at(30.0, -0.5), 1, whitted, "whitted at 30° inside");
    assert_mean(&glass_scene(IntegratorKind::Path, 8, 3.0, false), &at(30.0, -0.5), 8192, f * 3.0 + (1.0 - f) * 2.25 * BACKGROUND.y, "path at 30° inside");
    // From outside at 45°: F = fresnel(1, 1.5, cos 45°), the transmitted ray reaches the
    // emitter (scaled by 1/1.5² entering the glass).
    let f = fresnel(1.0, 1.5, 45f64.to_radians().cos()) as f32;
    let whitted = f * BACKGROUND + (1.0 - f) * Rgb::splat(3.0);
    assert_every_sample(&glass_scene(IntegratorKind::Whitted, 8, 3.0, false), &at(45.0, 0.5), 1, whitted, "whitted at 45° outside");
    assert_mean(&glass_scene(IntegratorKind::Path, 8, 3.0, false), &at(45.0, 0.5), 8192, f * BACKGROUND.y + (1.0 - f) * 3.0 / 2.25, "path at 45° outside");
}

#[test]
fn glass_inside_and_outside_follow_the_geometric_normal() {
    // The same interface with its shading normals given against the winding: the mesh turns
    // ng to agree with ns (−y), so now the glass is above the plane and the emitter's side is
    // outside. From y = −0.5 at 60° the ray arrives from outside: F = fresnel(1, 1.5, cos 60°),
    // no total reflection.
    let ray = Ray::new(Vec3::new(0.0, -0.5, 0.0), Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0));
    let f = fresnel(1.0, 1.5, 0.5) as f32;
    let whitted = f * Rgb::splat(3.0) + (1.0 - f) * BACKGROUND;
    assert_every_sample(&glass_scene(IntegratorKind::Whitted, 8, 3.0, true), &ray, 1, whitted, "whitted");
    assert_mean(&glass_scene(IntegratorKind::Path, 8, 3.0, true), &ray, 8192, f * 3.0 + (1.0 - f) / 2.25 * BACKGROUND.y, "path");
}

#[test]
fn whitted_stops_refraction_at_the_depth_limit() {
    // Glass as above seen from outside at 45°, a grey floor (ρ = 0.5) at y = −1 lit by a point
    // light of intensity 1 at (0, −0.5, 0) under the glass. The transmitted ray reaches the
    // floor on segment 2, where a third segment is needed to light it: at max_depth 2 only the
    // reflected background counts, F·c; at 3 the floor adds (1 − F)·ρ/π·I cos/d².
    let f = fresnel(1.0, 1.5, 45f64.to_radians().cos());
    let sin_t = 45f64.to_radians().sin() / 1.5;
    let x = sin_t / (1.0 - sin_t * sin_t).sqrt(); // where the refracted ray meets y = −1
    let d2 = x * x + 0.25;
    let floor_l = 0.5 / std::f64::consts::PI * (0.5 / d2.sqrt()) / d2;
    let ray = Ray::new(Vec3::new(-0.5, 0.5, 0.0), Vec3::new(1.0, -1.0, 0.0));
    let scene_with = |max_depth| {
        let mut scene = empty_scene(IntegratorKind::Whitted, LightSampling::Mis, max_depth);
        let glass = scene.add_material("glass", Material::Dielectric { ior: 1.5 });
        let grey = diffuse(&mut scene, Rgb::splat(0.5));
        scene.geometry.add_mesh(floor(glass, 0.0, 50.0, true));
        scene.geometry.add_mesh(floor(grey, -1.0, 50.0, true));
        scene.lights.push(Light::Point { position: Vec3::new(0.0, -0.5, 0.0), intensity: Rgb::ONE });
        scene.background = Background::Color(BACKGROUND);
        scene.build_accel(&BuildOptions::default());
        scene
    };
    let fc = f as f32 * BACKGROUND;
    assert_every_sample(&scene_with(2), &ray, 1, fc, "max_depth 2");
    assert_every_sample(&scene_with(3), &ray, 1, fc + Rgb::splat(((1.0 - f) * floor_l) as f32), "max_depth 3");
    // From inside the glass at 30° the reflected ray is the one that reaches the floor: from
    // x = −1.5 tan 30° at y = −0.5 it meets the glass at x = −tan 30° and the floor right
    // under the light, d = 0.5, cos θ = 1, E = 1/0.25 = 4, L = ρ/π·4. The transmitted ray
    // sees the background: (1 − F)·c with F = fresnel(1.5, 1, cos 30°).
    let t30 = 30f32.to_radians().tan();
    let ray = Ray::new(Vec3::new(-1.5 * t30, -0.5, 0.0), Vec3::new(30f32.to_radians().sin(), 30f32.to_radians().cos(), 0.0));
    let f = fresnel(1.5, 1.0, 30f64.to_radians().cos()) as f32;
    let tc = (1.0 - f) * BACKGROUND;
    assert_every_sample(&scene_with(2), &ray, 1, tc, "from inside, max_depth 2");
    assert_every_sample(&scene_with(3), &ray, 1, tc + Rgb::splat(f * 0.5 / PI * 4.0), "from inside, max_depth 3");
}

#[test]
fn glass_of_index_below_one_transmits_away_from_the_normal() {
    // ior = 2/3: the outside is the denser side (a bubble). From outside at 30°,
    // sin θt = 1.5 sin 30° = 0.75: the refracted ray leaves at a grazier angle than it came,
    // and must still be followed as transmission. F = fresnel(1.5, 1, cos 30°); the path
    // tracer scales transmitted radiance by 1/η² = 1.5².
    let ray = Ray::new(Vec3::new(0.0, 0.5, 0.0), Vec3::new(30f32.to_radians().sin(), -30f32.to_radians().cos(), 0.0));
    let f = fresnel(1.5, 1.0, 30f64.to_radians().cos()) as f32;
    let whitted = f * BACKGROUND + (1.0 - f) * Rgb::splat(3.0);
    assert_every_sample(&glass_scene_of(IntegratorKind::Whitted, 8, 3.0, false, 1.0 / 1.5), &ray, 1, whitted, "whitted");
    assert_mean(&glass_scene_of(IntegratorKind::Path, 8, 3.0, false, 1.0 / 1.5), &ray, 8192, f * BACKGROUND.y + (1.0 - f) * 3.0 * 2.25, "path");
}

#[test]
fn whitted_phong_is_the_textbook_sum() {
    // Phong at p = 0 seen from wo = (−0.6, 0.8, 0), a point light of intensity 5 at (1, 2, 0):
    // wi = (1, 2, 0)/√5, E = 5/5 = 1, cos θ = 2/√5, the mirror of wi about n = +y is
    // (−1, 2, 0)/√5 and its cosine with wo (0.6 + 1.6)/√5. With an ambient light:
    // L = ka·Ia + kd·E·cos θ + ks·E·(r·wo)^p.
    let (ka, kd, ks, p) = (Rgb::new(0.2, 0.1, 0.0), Rgb::new(0.3, 0.2, 0.1), Rgb::new(0.5, 0.4, 0.6), 3.0f32);
    let ia = Rgb::splat(0.5);
    let mut scene = empty_scene(IntegratorKind::Whitted, LightSampling::Mis, 8);
    let m = scene.add_material("phong", Material::Phong { ka: ka.into(), kd: kd.into(), ks: ks.into(), exponent: p });
    scene.geometry.add_mesh(floor(m, 0.0, 50.0, true));
    scene.lights.push(Light::Point { position: Vec3::new(1.0, 2.0, 0.0), intensity: Rgb::splat(5.0) });
    scene.lights.push(Light::Ambient { intensity: ia });
    scene.build_accel(&BuildOptions::default());
    let cos = 2.0 / 5f32.sqrt();
    let spec = (2.2 / 5f32.sqrt()).powf(p);
    let want = ka * ia + kd * cos + ks * spec;
    assert_every_sample(&scene, &ray_between(Vec3::new(-0.6, 0.8, 0.0), Vec3::ZERO), 1, want, "phong");
}

#[test]
fn emission_adds_to_reflected_light() {
    // An emitting Lambertian floor (Le = 0.25 up, ρ = 0.5) under a point light of intensity 4
    // at height 2 above p = 0, seen from above: L = Le + ρ/π · 4/4. With one segment, Le alone.
    for integrator in [IntegratorKind::Whitted, IntegratorKind::Direct, IntegratorKind::Path] {
        let scene_with = |max_depth| {
            let mut scene = empty_scene(integrator, LightSampling::Mis, max_depth);
            let m = diffuse(&mut scene, Rgb::splat(0.5));
            scene.geometry.add_mesh(TriangleMesh { emission: Rgb::splat(0.25), ..floor(m, 0.0, 50.0, true) });
            scene.lights.push(Light::Point { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(4.0) });
            scene.build_accel(&BuildOptions::default());
            scene
        };
        let ray = ray_between(Vec3::new(0.3, 1.0, 0.4), Vec3::ZERO);
        assert_every_sample(&scene_with(8), &ray, 8, Rgb::splat(0.25 + 0.5 / PI), &format!("{integrator}"));
        assert_every_sample(&scene_with(1), &ray, 4, Rgb::splat(0.25), &format!("{integrator} max_depth 1"));
    }
}

#[test]
fn hair_is_shaded_with_the_fibre_along_dpdu() {
    // A Kajiya–Kay floor whose uvs make ∂p/∂u, the fibre tangent T, run along +x, or along
    // the diagonal (1, 0, 1)/√2 (u = x + z, v = z − x). Light from a point light of intensity
    // 4 at (0.6, 0.8, 0)·2 from p = 0 (E = 1, cos θi = 0.8), seen from wo = (−0.36, 0.8, 0.48).
    // f = (colour·kd·sin(T, wi) + ks·cos^p θ')/π with cos θ' = sin_i sin_o − (T·wi)(T·wo),
    // sin(T, w) = √(1 − (T·w)²); L = f·E·cos θi.
    let (color, kd, ks, p) = (Rgb::new(0.9, 0.6, 0.3), 0.7f32, 0.4f32, 5.0f32);
    let (wi, wo) = (Vec3::new(0.6, 0.8, 0.0), Vec3::new(-0.36, 0.8, 0.48));
    let s = std::f32::consts::FRAC_1_SQRT_2;
    // (T·wi, T·wo) worked out: (0.6, −0.36) along x; (0.6/√2, (−0.36 + 0.48)/√2) on the diagonal.
    for (uv, (ti, to)) in [(&(|v: Vec3| Vec2::new(v.x, v.z)) as &dyn Fn(Vec3) -> Vec2, (0.6f32, -0.36f32)), (&|v: Vec3| Vec2::new(v.x + v.z, v.z - v.x), (0.6 * s, 0.12 * s))] {
        let (sin_i, sin_o) = ((1.0 - ti * ti).sqrt(), (1.0 - to * to).sqrt());
        let cos_cone = sin_i * sin_o - ti * to;
        let want = (color * (kd * sin_i) + Rgb::splat(ks * cos_cone.powf(p))) / PI * 0.8;
        for integrator in [IntegratorKind::Whitted, IntegratorKind::Direct, IntegratorKind::Path] {
            let mut scene = empty_scene(integrator, LightSampling::Mis, 8);
            let m = scene.add_material("hair", Material::Hair { color: TexColor::Constant(color), kd, ks, exponent: p });
            let mut mesh = floor(m, 0.0, 50.0, true);
            mesh.uvs = mesh.positions.iter().map(|&v| uv(v)).collect();
            scene.geometry.add_mesh(mesh);
            scene.lights.push(Light::Point { position: 2.0 * wi, intensity: Rgb::splat(4.0) });
            scene.build_accel(&BuildOptions::default());
            assert_every_sample(&scene, &ray_between(wo, Vec3::ZERO), 8, want, &format!("{integrator}, T·wi = {ti}"));
        }
    }
}

#[test]
fn first_hit_passes_depth_normals_and_albedo() {
    // A floor at y = 0 (albedo (0.2, 0.4, 0.6)), a ray from (0, 3, 0) with a direction of
    // length 2 straight down: t = 1.5 in ray units, distance 3.
    let albedo = Rgb::new(0.2, 0.4, 0.6);
    let scene_for = |integrator| {
        let mut scene = empty_scene(integrator, LightSampling::Mis, 8);
        let m = diffuse(&mut scene, albedo);
        scene.geometry.add_mesh(floor(m, 0.0, 50.0, true));
        scene.build_accel(&BuildOptions::default());
        scene
    };
    let down = Ray::new(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, -2.0, 0.0));
    let up = Ray::new(Vec3::new(0.0, -3.0, 0.0), Vec3::new(0.0, 0.5, 0.0));
    let miss = Ray::new(Vec3::new(0.0, 3.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
    let depth = scene_for(IntegratorKind::Depth);
    let near = |a: Rgb, b: Rgb| (a - b).abs().max_element() < 1e-6;
    assert!(near(trace(&depth, &down, 0), Rgb::splat(3.0)) && near(trace(&depth, &up, 0), Rgb::splat(3.0)));
    assert_eq!(trace(&depth, &miss, 0), Rgb::ZERO);
    // Normals face the camera: 0.5·(n + 1), n = +y seen from above, −y from below; grey on a miss.
    let normals = scene_for(IntegratorKind::Normals);
    assert_eq!(trace(&normals, &down, 0), Rgb::new(0.5, 1.0, 0.5));
    assert_eq!(trace(&normals, &up, 0), Rgb::new(0.5, 0.0, 0.5));
    assert_eq!(trace(&normals, &miss, 0), Rgb::splat(0.5));
    // A tilted normal n = (0.6, 0.8, 0) on a plane seen from either side.
    let mut tilted = empty_scene(IntegratorKind::Normals, LightSampling::Mis, 8);
    let m = diffuse(&mut tilted, albedo);
    let mut mesh = floor(m, 0.0, 50.0, true);
    mesh.positions = mesh.positions.iter().map(|v| Vec3::new(0.8 * v.x, -0.6 * v.x, v.z)).collect();
    tilted.geometry.add_mesh(mesh);
    tilted.build_accel(&BuildOptions::default());
    let l = trace(&tilted, &Ray::new(Vec3::new(0.6, 0.8, 0.0), Vec3::new(-0.6, -0.8, 0.0)), 0);
    assert!(near(l, Rgb::new(0.8, 0.9, 0.5)), "{l}");
    let l = trace(&tilted, &Ray::new(Vec3::new(-0.6, -0.8, 0.0), Vec3::new(0.6, 0.8, 0.0)), 0);
    assert!(near(l, Rgb::new(0.2, 0.1, 0.5)), "{l}");
    let albedo_scene = scene_for(IntegratorKind::Albedo);
    assert_eq!(trace(&albedo_scene, &down, 0), albedo);
    assert_eq!(trace(&albedo_scene, &miss, 0), Rgb::ZERO);
}

#[test]
fn only_the_heatmaps_are_heatmaps() {
    let heatmaps: Vec<IntegratorKind> = IntegratorKind::ALL.iter().copied().filter(|k| k.is_heatmap()).collect();
    assert_eq!(heatmaps, [IntegratorKind::Heatmap, IntegratorKind::HeatmapTests]);
}
