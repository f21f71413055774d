//! Every generator's description, written by the TOML writer and read back by the TOML
//! front end, is the same description (the same camera, settings, materials, spheres,
//! triangles, curves and lights, value for value) and renders the same image.

use std::path::PathBuf;

use raylab_core::{Rgb, Vec3};
use raylab_loader::description::SceneDescription;
use raylab_loader::toml_write::write_toml;
use raylab_loader::Overrides;
use raylab_procedural::{generate, Size, NAMES};
use raylab_render::settings::SETTINGS;

/// A folder of this process for one test's scene `name`: tests run in parallel and must not
/// share (or delete) each other's files.
fn scratch(test: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab_gen_round_trip_{}_{test}_{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `desc` into a fresh folder and reads it back through the TOML front end.
fn round_trip(test: &str, name: &str, desc: &SceneDescription) -> SceneDescription {
    let dir = scratch(test, name);
    let written = write_toml(desc, name, &format!("{name}, round trip")).unwrap_or_else(|e| panic!("{name}: {e}"));
    for f in &written.side_files {
        std::fs::write(dir.join(&f.name), &f.contents).unwrap();
    }
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, &written.toml).unwrap();
    let back = raylab_loader::parse_any(&path, false).unwrap_or_else(|e| panic!("{name}: {e}\n{}", written.toml));
    std::fs::remove_dir_all(&dir).ok();
    back
}

/// Every mesh triangle as its material, corner positions (bits) and corner normals, sorted:
/// the OBJ writer shares equal vertices, so the arrays differ in order while the surfaces
/// are the same.
type Corners = (u32, [[u32; 3]; 3], [Vec3; 3]);

fn triangles(desc: &SceneDescription) -> Vec<Corners> {
    let mut out: Vec<Corners> = desc
        .geometry
        .meshes
        .iter()
        .flat_map(|m| {
            m.indices.iter().map(move |t| {
                let p = t.map(|k| m.positions[k as usize].to_array().map(f32::to_bits));
                let n = t.map(|k| m.normals.get(k as usize).copied().unwrap_or(Vec3::ZERO));
                (m.material.0, p, n)
            })
        })
        .collect();
    out.sort_by_key(|a| (a.0, a.1));
    out
}

fn assert_same_triangles(name: &str, a: &[Corners], b: &[Corners]) {
    assert_eq!(a.len(), b.len(), "{name}");
    for (x, y) in a.iter().zip(b) {
        assert_eq!((x.0, x.1), (y.0, y.1), "{name}");
        // Unit normals written as text and renormalised on reading: equal to a few ulps.
        for k in 0..3 {
            assert!((x.2[k] - y.2[k]).abs().max_element() <= 1e-6, "{name}: normal {} vs {}", x.2[k], y.2[k]);
        }
    }
}

fn size_of(name: &str) -> Size {
    Size { size: if name == "mount" { 3 } else { 2 }, strands: 30, segments: 3 }
}

#[test]
fn every_generator_reads_back_as_the_description_it_wrote() {
    for &name in NAMES {
        let g = generate(name, size_of(name)).unwrap();
        let (a, b) = (&g.scene, &round_trip("every", name, &g.scene));
        let (ca, cb) = (&a.camera, &b.camera);
        assert_eq!((ca.from, ca.at, ca.up, ca.vfov, ca.aperture, ca.focus_distance), (cb.from, cb.at, cb.up, cb.vfov, cb.aperture, cb.focus_distance), "{name}");
        for s in SETTINGS {
            assert_eq!(a.settings.get(s.key), b.settings.get(s.key), "{name}: setting {}", s.key);
        }
        assert_eq!((&a.materials, &a.material_names), (&b.materials, &b.material_names), "{name}");
        assert_eq!(a.background, b.background, "{name}");
        assert_eq!(a.lights, b.lights, "{name}");
        let spheres = |d: &SceneDescription| d.geometry.spheres.iter().map(|s| (s.center, s.radius, s.material, s.emission, s.to_world)).collect::<Vec<_>>();
        assert_eq!(spheres(a), spheres(b), "{name}");
        assert_same_triangles(name, &triangles(a), &triangles(b));
        let curves = |d: &SceneDescription| d.geometry.curves.iter().map(|c| (c.material, c.segments.clone())).collect::<Vec<_>>();
        assert_eq!(curves(a), curves(b), "{name}");
        assert!(a.triangle_count() + a.geometry.spheres.len() + a.geometry.curves.len() > 2, "{name}: nothing generated");
    }
}

#[test]
fn a_written_scene_renders_the_image_of_its_description() {
    let o = Overrides { width: Some(48), height: Some(36), spp: Some(1), ..Default::default() };
    for name in ["tetra", "hair"] {
        let g = generate(name, size_of(name)).unwrap();
        let back = round_trip("render", name, &g.scene);
        let render = |d: SceneDescription| raylab_render::render(&raylab_loader::build_scene(d, &o).unwrap(), &|_| {}).pixels;
        let (want, got) = (render(g.scene), render(back));
        let worst = want.iter().zip(&got).map(|(p, q)| (*p - *q).abs().max_element()).fold(0.0f32, f32::max);
        // Same surfaces, same samples: the same image up to the last bit of shading.
        assert!(worst < 1e-5, "{name}: worst pixel difference {worst}");
        assert!(want.iter().any(|p| *p != Rgb::new(0.08, 0.1, 0.15)), "{name}: the image shows only the background");
    }
}

/// What a description holds but a scene file cannot say without more files is an error
/// naming it, never dropped.
#[test]
fn what_the_writer_cannot_write_is_an_error() {
    let mut g = generate("balls", Size { size: 1, strands: 0, segments: 0 }).unwrap();
    g.scene.lights.push(raylab_render::Light::Spot { position: Vec3::ZERO, direction: Vec3::Y, intensity: Rgb::ONE, cos_inner: 0.9, cos_outer: 0.8 });
    assert_eq!(write_toml(&g.scene, "s", "").unwrap_err(), "spot lights have no scene-file spelling (they come from glTF)");
    let mut g = generate("balls", Size { size: 1, strands: 0, segments: 0 }).unwrap();
    g.scene.geometry.meshes[0].emission = Rgb::ONE;
    assert_eq!(write_toml(&g.scene, "s", "").unwrap_err(), "mesh `quad` emits light: area lights are not written");
}
