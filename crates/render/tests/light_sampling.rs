//! χ² goodness of fit of every light-sampling strategy that has a density: the directions
//! a light's `sample` returns, binned over the sphere, against the counts its `pdf`
//! predicts (integrated over each bin), as the BSDF tests do for materials.

use raylab_accel::{BuildOptions, Counters};
use raylab_core::{Pcg32, Ray, Rgb, Transform, Vec2, Vec3};
use raylab_render::light::{EnvironmentLight, LightSampling};
use raylab_render::material::TexColor;
use raylab_render::texture::{Filter, ImageTexture, Wrap};
use raylab_render::{Camera, Material, RenderSettings, Scene, Sphere, TriangleMesh};
use std::f64::consts::PI;

const NZ: usize = 16;
const NP: usize = 32;
const SUB: usize = 24;
const N: usize = 400_000;

/// Bin of a unit direction: `z` in `NZ` slices of [-1, 1], azimuth in `NP`.
fn bin(w: Vec3) -> usize {
    let iz = (((w.z + 1.0) * 0.5 * NZ as f32) as usize).min(NZ - 1);
    let ip = ((w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU * NP as f32) as usize).min(NP - 1);
    iz * NP + ip
}

/// χ² and degrees of freedom of `N` draws of `sample` (None: no direction) against
/// `pdf` (solid-angle density).
fn chi_square(mut sample: impl FnMut(&mut Pcg32) -> Option<Vec3>, pdf: impl Fn(Vec3) -> f64) -> (f64, usize) {
    let mut observed = vec![0.0f64; NZ * NP + 1];
    let mut rng = Pcg32::new(17, 3);
    for _ in 0..N {
        observed[sample(&mut rng).map_or(NZ * NP, bin)] += 1.0;
    }
    let (dz, dphi) = (2.0 / NZ as f64, 2.0 * PI / NP as f64);
    let mut expected: Vec<f64> = (0..NZ * NP)
        .map(|cell| {
            let (iz, ip) = (cell / NP, cell % NP);
            let mut sum = 0.0;
            for (a, c) in (0..SUB * SUB).map(|k| (k / SUB, k % SUB)) {
                let z = -1.0 + (iz as f64 + (a as f64 + 0.5) / SUB as f64) * dz;
                let phi = (ip as f64 + (c as f64 + 0.5) / SUB as f64) * dphi;
                let r = (1.0 - z * z).max(0.0).sqrt();
                sum += pdf(Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32));
            }
            sum / (SUB * SUB) as f64 * dz * dphi * N as f64
        })
        .collect();
    let total: f64 = expected.iter().sum();
    expected.push((N as f64 - total).max(0.0));
    raylab_testkit::chi_square(&expected, &observed)
}

fn assert_fits(name: &str, (chi2, dof): (f64, usize)) {
    let limit = raylab_testkit::chi_square_limit(dof);
    assert!(dof >= 10, "{name}: only {dof} degrees of freedom");
    assert!(chi2 < limit, "{name}: χ² = {chi2:.1} with {dof} dof (limit {limit:.1})");
}

/// Emitters around the origin, seen from it: a square rect light above (facing down), a
/// sphere light to the side (if `sphere`), a tilted parallelogram below, with different
/// radiances so the power-proportional choice matters.
fn lights_scene(sphere: bool) -> Scene {
    let camera = Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings::default());
    let black = scene.add_material("light", Material::Diffuse { albedo: TexColor::Constant(Rgb::ZERO) });
    let rect = |corners: [Vec3; 4], le: f32| TriangleMesh { name: "rect".into(), positions: corners.to_vec(), indices: vec![[0, 1, 2], [0, 2, 3]], uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y], material: black, emission: Rgb::splat(le), ..Default::default() };
    // (v1 - v0) × (v2 - v0) = −z: facing the origin from z = 1.5.
    scene.geometry.add_mesh(rect([Vec3::new(-1.0, -1.0, 1.5), Vec3::new(-1.0, 1.0, 1.5), Vec3::new(1.0, 1.0, 1.5), Vec3::new(1.0, -1.0, 1.5)], 3.0));
    if sphere {
        scene.geometry.add_sphere(Sphere { center: Vec3::new(2.0, 0.0, 0.0), radius: 1.0, to_world: Transform::IDENTITY, material: black, emission: Rgb::splat(2.0) });
    }
    // A parallelogram (not a rectangle) below, facing up-ish towards the origin.
    scene.geometry.add_mesh(rect([Vec3::new(-2.0, -1.0, -1.0), Vec3::new(0.0, -1.5, -1.2), Vec3::new(0.5, 0.5, -1.6), Vec3::new(-1.5, 1.0, -1.4)], 1.0));
    scene.build_accel(&BuildOptions::default());
    scene
}

/// The density `strategy` gives direction `w` from the origin: that of the emitter the
/// direction meets first (these emitters do not overlap as seen from the origin).
fn light_pdf(scene: &Scene, strategy: LightSampling, w: Vec3) -> f64 {
    let mut c = Counters::default();
    match scene.intersect(&Ray::new(Vec3::ZERO, w), &mut c) {
        Some(hit) => scene.area_lights.pdf(&scene.geometry, strategy, hit.prim, Vec3::ZERO, hit.geom.p, hit.geom.ng) as f64,
        None => 0.0,
    }
}

#[test]
fn area_light_sampling_matches_its_density() {
    let scene = lights_scene(true);
    // Uniform area sampling returns points on the sphere's far side too, which shadow rays
    // then find hidden: as directions they double up on the near side, so the sphere is
    // left out of the uniform case (rects map points to directions one to one).
    let rects = lights_scene(false);
    for (name, s, strategy) in [("uniform, rects", &rects, LightSampling::Uniform), ("solid angle, rects and sphere", &scene, LightSampling::SolidAngle), ("mis light samples", &scene, LightSampling::Mis)] {
        let fit = chi_square(
            |rng| s.area_lights.sample(&s.geometry, &s.textures, Vec3::ZERO, &|_| 1.0, strategy, rng.next_f32(), rng.next_vec2()).map(|ls| ls.wi),
            |w| light_pdf(s, strategy, w),
        );
        assert_fits(name, fit);
    }
}

#[test]
fn environment_sampling_matches_its_density() {
    let (w, h) = (32, 16);
    let texels = (0..w * h).map(|i| if i == 4 * w + 20 || i == 11 * w + 3 { Rgb::splat(300.0) } else { Rgb::new(0.2, 0.4, 0.8) * (1.0 + (i % 7) as f32) }).collect();
    let env = EnvironmentLight::new(ImageTexture::new(w as u32, h as u32, texels, Wrap::Repeat, Filter::Bilinear).unwrap(), Rgb::ONE);
    assert_fits("environment", chi_square(|rng| env.sample(rng.next_vec2()).map(|s| s.wi), |w| env.pdf(w) as f64));
}
