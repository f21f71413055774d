//! Malformed input gives an error naming the file, the line and the field — asserted by
//! its exact message, as pbrt's parser tests do.

use std::path::{Path, PathBuf};

use raylab_loader::{load_scene, load_scene_str, Overrides};
use raylab_loader::files::Resolver;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// Loads `src` as `bad.toml` from the fixtures folder and returns the error message.
fn error_of(src: &str) -> String {
    let base = fixtures();
    match load_scene_str(src, Path::new("bad.toml"), &Resolver::Disk { base }, &Overrides::default()) {
        Ok(_) => panic!("scene loaded but should not:\n{src}"),
        Err(e) => e.to_string(),
    }
}

const CAMERA: &str = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n";

#[test]
fn wrong_value_type_names_line_and_field() {
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = \"origin\"\nvfov = 40\n"), "bad.toml:3: camera.at: expected an array of 3 numbers, found a string");
    assert_eq!(error_of("[camera]\nfrom = [0, 0]\nat = [0, 0, 0]\nvfov = 40\n"), "bad.toml:2: camera.from: expected an array of 3 numbers, found an array of 2 elements");
    assert_eq!(error_of("[camera]\nfrom = [0, \"x\", 5]\nat = [0, 0, 0]\nvfov = 40\n"), "bad.toml:2: camera.from: expected an array of 3 numbers, found a string at index 1");
}

#[test]
fn unknown_keys_and_types_list_the_valid_ones() {
    assert_eq!(
        error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nfov = 40\n"),
        "bad.toml:4: camera.fov: unknown field (valid: from, at, up, vfov, width, height, aperture, focus_distance)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[[shapes]]\ntype = \"cylinder\"\n")),
        "bad.toml:6: shapes[0].type: unknown type `cylinder` (valid: sphere, triangle, quad, mesh, bezier_patch)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\nvertices = [[0, 0, 0]]\n")),
        "bad.toml:8: shapes[0].vertices: not a field of `sphere` shapes (valid: type, material, transform, center, radius)"
    );
    assert_eq!(
        error_of(&format!("{CAMERA}[render]\naccel = \"octree\"\n")),
        format!("bad.toml:6: render.accel: unknown acceleration structure `octree` (valid: {})", raylab_accel::AccelKind::names())
    );
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[lens]\n"), "bad.toml:5: lens: unknown field (valid: camera, render, background, textures, materials, shapes, lights)");
}

#[test]
fn out_of_range_values() {
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = -1\n")), "bad.toml:7: shapes[0].radius: must be positive, found -1");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 180\n"), "bad.toml:4: camera.vfov: must be in (0, 180) degrees, found 180");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\nwidth = 0\n"), "bad.toml:5: camera.width: must be between 1 and 16384, found 0");
    assert_eq!(error_of(&format!("{CAMERA}[render]\nspp = 10\n")), "bad.toml:6: render.spp: the jittered sampler needs a square number of samples (1, 4, 9, 16, ...), found 10");
    assert_eq!(error_of("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 5]\nvfov = 40\n"), "bad.toml:3: camera.at: must differ from camera.from");
    assert_eq!(error_of(&format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [1, -1, 1]\n")), "bad.toml:8: lights[0].intensity: colour components must not be negative, found [1, -1, 1]");
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = nan\n")), "bad.toml:7: shapes[0].radius: expected a finite number");
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\ntransform = [{{ scale = 0 }}]\n")), "bad.toml:8: shapes[0].transform[0].scale: scale must not be zero");
}

#[test]
fn references_to_undefined_names() {
    assert_eq!(error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = 1\nmaterial = \"gold\"\n")), "bad.toml:8: shapes[0].material: unknown material `gold` (defined: none)");
    assert_eq!(error_of(&format!("{CAMERA}[[materials]]\nname = \"m\"\ntype = \"diffuse\"\nalbedo = \"earth\"\n")), "bad.toml:8: materials[0].albedo: unknown texture `earth` (defined: none)");
    assert_eq!(error_of("vfov = 1\n"), "bad.toml:1: vfov: unknown field (valid: camera, render, background, textures, materials, shapes, lights)");
    assert_eq!(error_of("[render]\nspp = 4\n"), "bad.toml:1: camera: missing (required)");
}

#[test]
fn missing_files_name_every_path_tried() {
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"no_such_mesh.obj\"\n"));
    let direct = fixtures().join("no_such_mesh.obj");
    assert!(msg.starts_with(&format!("bad.toml:7: shapes[0].file: cannot find `no_such_mesh.obj` (looked in {}", direct.display())), "{msg}");
    let msg = error_of(&format!("{CAMERA}[[textures]]\nname = \"t\"\ntype = \"image\"\nfile = \"no_such_texture.png\"\n"));
    assert!(msg.starts_with("bad.toml:8: textures[0].file: cannot find `no_such_texture.png` (looked in "), "{msg}");
}

#[test]
fn malformed_obj_names_its_line() {
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"bad_index.obj\"\n"));
    assert_eq!(msg, format!("{}:6: face index 4 is out of range: the file has 3 vertex (`v`) entries", fixtures().join("bad_index.obj").display()));
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"bad_number.obj\"\n"));
    assert_eq!(msg, format!("{}:3: `v` expects numbers, found `1.0 zero 0.0`", fixtures().join("bad_number.obj").display()));
    let msg = error_of(&format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"not_utf8.obj\"\n"));
    assert_eq!(msg, format!("{}:2: not valid UTF-8 (byte 0xff)", fixtures().join("not_utf8.obj").display()));
}

#[test]
fn non_utf8_and_syntax_errors_in_the_scene() {
    let path = fixtures().join("not_utf8.toml");
    let e = load_scene(&path, &Overrides::default()).unwrap_err().to_string();
    assert_eq!(e, format!("{}:3: not valid UTF-8 (byte 0xfe)", path.display()));
    let e = error_of("[camera\nfrom = 1\n");
    assert!(e.starts_with("bad.toml:1: TOML syntax error: "), "{e}");
    let missing = fixtures().join("nope.toml");
    let e = load_scene(&missing, &Overrides::default()).unwrap_err().to_string();
    assert!(e.starts_with(&format!("{}: cannot read: ", missing.display())), "{e}");
}

#[test]
fn example_scenes_and_default_scene_parse() {
    let scenes = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    let files = std::fs::read_dir(&scenes).unwrap().chain(std::fs::read_dir(scenes.join("lab")).unwrap());
    for entry in files {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "toml") {
            let scene = load_scene(&p, &Overrides::default()).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.geometry.meshes.is_empty() || !scene.geometry.spheres.is_empty(), "{}", p.display());
            n += 1;
        }
    }
    assert!(n >= 15, "only {n} example scenes");
    let d = raylab_loader::default_scene(&Overrides::default()).unwrap();
    assert_eq!(d.geometry.triangle_count(), 4968 + 2);
    assert_eq!(d.geometry.spheres.len(), 2);
}
