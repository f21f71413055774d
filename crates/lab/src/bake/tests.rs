use raylab_accel::BuildOptions;
use raylab_core::{Vec2, Vec3};
use raylab_render::shading::{decode_normal, NormalSpace, ShadingPerturbation};
use raylab_render::texture::{Filter, ImageTexture, Wrap};
use raylab_render::{Camera, Light, Material, RenderSettings, Scene, Texture, TriangleMesh};

use super::raster::texel_samples;
use super::*;

/// A latitude-longitude sphere of radius 1 without its polar caps (no degenerate
/// triangles), wound outwards, with smooth (angle-weighted) normals and no UVs.
fn smooth_sphere(rings: u32, segments: u32) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * (r + 1) as f32 / (rings + 2) as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            mesh.positions.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
        }
    }
    for r in 0..rings {
        for s in 0..segments {
            let i = |r: u32, s: u32| r * segments + s % segments;
            let (a, b, c, d) = (i(r, s), i(r, s + 1), i(r + 1, s), i(r + 1, s + 1));
            mesh.indices.extend([[a, d, b], [a, c, d]]);
        }
    }
    mesh.compute_smooth_normals(180.0);
    mesh
}

fn low_with_atlas(mesh: &TriangleMesh, size: u32) -> TriangleMesh {
    let mut low = with_atlas_uvs(mesh, size).unwrap();
    low.compute_tangents();
    low
}

#[test]
fn atlas_triangles_never_share_a_texel() {
    let mesh = smooth_sphere(6, 8);
    let low = low_with_atlas(&mesh, 256);
    assert!(low.uvs.iter().all(|uv| uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all()));
    let mut claimed = vec![0usize; low.len()];
    for s in texel_samples(&low, 256).into_iter().flatten() {
        claimed[s.prim as usize] += 1;
    }
    // Every triangle is the same shape in the atlas: an overlap would steal texels from one.
    let (min, max) = (*claimed.iter().min().unwrap(), *claimed.iter().max().unwrap());
    assert!(min > 50 && max - min <= max / 10, "texels per triangle from {min} to {max}");
}

#[test]
fn baking_a_mesh_onto_itself_gives_flat_normals() {
    let mesh = smooth_sphere(12, 16);
    let low = low_with_atlas(&mesh, 512);
    let map = bake_normal_map(&low, &mesh, 512, 0.05);
    assert_eq!(map.hits, map.covered, "every covered texel finds the surface");
    let worst = map.texels.iter().map(|&c| decode_normal(c).angle_between(Vec3::Z)).fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "largest deviation {worst} rad");
    // Bake against a shrunken copy: the normals still agree (it is the same shape), but
    // misses beyond max_distance stay flat and are counted.
    let mut far = mesh.clone();
    far.positions.iter_mut().for_each(|p| *p *= 0.5);
    assert_eq!(bake_normal_map(&low, &far, 512, 0.05).hits, 0);
}

/// The same sphere rendered with `map` (or none) as seen by the `normals` AOV.
fn render_normals(low: &TriangleMesh, map: Option<Texture>) -> Vec<Rgb> {
    let camera = Camera::new(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 1.0, 0.0, None).unwrap();
    let settings = RenderSettings { width: 48, height: 48, spp: 1, integrator: "normals".parse().unwrap(), ..Default::default() };
    let mut scene = Scene::new(camera, settings);
    let m = scene.add_material("m", Material::default_diffuse());
    if let Some(t) = map {
        let t = scene.add_texture("map", t);
        scene.material_perturbations[m.0 as usize] = Some(ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Tangent });
    }
    scene.geometry.add_mesh(TriangleMesh { material: m, tangents: Vec::new(), ..low.clone() });
    scene.lights.push(Light::Ambient { intensity: Rgb::ONE });
    scene.build_accel(&BuildOptions::default());
    raylab_render::render(&scene, &|_| {}).pixels
}

#[test]
fn rendering_with_a_self_baked_map_is_unchanged() {
    let mesh = smooth_sphere(12, 16);
    let low = low_with_atlas(&mesh, 512);
    let map = bake_normal_map(&low, &mesh, 512, 0.05);
    // Stored as 8-bit like the PNG the bake command writes.
    let texels = map.texels.iter().map(|c| (*c * 255.0).round() / 255.0).collect();
    let texture = Texture::Image(ImageTexture::new(512, 512, texels, Wrap::Clamp, Filter::Bilinear).unwrap());
    let plain = render_normals(&low, None);
    let mapped = render_normals(&low, Some(texture));
    let diff = |a: &[Rgb], b: &[Rgb]| a.iter().zip(b).map(|(x, y)| (*x - *y).abs().max_element()).fold(0.0f32, f32::max);
    // 8-bit storage tilts a flat normal by at most ~0.004 rad.
    assert!(diff(&plain, &mapped) < 0.01, "max difference {}", diff(&plain, &mapped));
    let tilted = render_normals(&low, Some(Texture::Constant(raylab_render::shading::encode_normal(Vec3::new(0.3, 0.0, 0.954)))));
    assert!(diff(&plain, &tilted) > 0.1, "a wrong map must show");
}

#[test]
fn a_baked_tilt_decodes_to_the_high_normal_in_the_renderer() {
    // Low: the unit square facing +z (two triangles). High: the plane z = 0.1·x, larger.
    let square = |z: fn(f32) -> f32, lo: f32, hi: f32| {
        let mut m = TriangleMesh {
            positions: [(lo, lo), (hi, lo), (hi, hi), (lo, hi)].map(|(x, y)| Vec3::new(x, y, z(x))).to_vec(),
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        m.compute_smooth_normals(180.0);
        m
    };
    let low = low_with_atlas(&square(|_| 0.0, 0.0, 1.0), 64);
    let high = square(|x| 0.1 * x, -1.0, 2.0);
    let map = bake_normal_map(&low, &high, 64, 0.3);
    assert_eq!(map.hits, map.covered);
    let camera = Camera::new(Vec3::new(0.5, 0.5, 3.0), Vec3::new(0.5, 0.5, 0.0), Vec3::Y, 40.0, 1.0, 0.0, None).unwrap();
    let mut scene = Scene::new(camera, RenderSettings::default());
    let t = scene.add_texture("map", Texture::Image(ImageTexture::new(64, 64, map.texels, Wrap::Clamp, Filter::Bilinear).unwrap()));
    let m = scene.add_material("m", Material::default_diffuse());
    scene.material_perturbations[m.0 as usize] = Some(ShadingPerturbation::NormalMap { texture: t, space: NormalSpace::Tangent });
    scene.geometry.add_mesh(TriangleMesh { material: m, tangents: Vec::new(), ..low });
    scene.build_accel(&BuildOptions::default());
    let expected = Vec3::new(-0.1, 0.0, 1.0).normalize();
    let mut rng = raylab_core::Pcg32::new(5, 6);
    for _ in 0..500 {
        let at = Vec3::new(rng.next_f32(), rng.next_f32(), 0.0);
        let hit = scene.intersect(&Ray::new(at + Vec3::Z, -Vec3::Z), &mut raylab_accel::Counters::default()).unwrap();
        assert!(hit.geom.ns.angle_between(expected) < 1e-3, "at {at}: {} instead of {expected}", hit.geom.ns);
    }
}
