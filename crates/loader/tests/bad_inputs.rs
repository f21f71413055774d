//! Bad and edge inputs that were accepted, or refused with a wrong message (issue 12's
//! "Defects found when 276 bad and edge inputs were tried"): each is refused with the exact
//! message that names the file, the line and the field.

use std::path::{Path, PathBuf};

use raylab_loader::files::{read_capped, Resolver, MAX_DATA_BYTES};
use raylab_loader::mesh_scene::parse_mesh_scene;
use raylab_loader::{load_scene_str, parse_scene_str, Overrides};

const CAMERA: &str = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n";
const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// A fresh folder holding `files` (name, contents).
fn folder(name: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-bad-inputs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (f, bytes) in files {
        std::fs::write(dir.join(f), bytes).unwrap();
    }
    dir
}

/// The error of loading scene `src` (named `s.toml`) from `dir`.
fn error_in(dir: &Path, src: &str) -> String {
    match load_scene_str(src, Path::new("s.toml"), &Resolver::Disk { base: dir.to_path_buf() }, &Overrides::default()) {
        Ok(_) => panic!("loaded but should not:\n{src}"),
        Err(e) => e.to_string(),
    }
}

fn mesh_scene(file: &str) -> String {
    format!("{CAMERA}[[shapes]]\ntype = \"mesh\"\nfile = \"{file}\"\n")
}

#[test]
fn mtl_values_must_be_finite_and_colours_not_negative() {
    let obj = format!("mtllib m.mtl\n{TRIANGLE}usemtl a\nf 1 2 3\n");
    let dir = folder("mtl-nan", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nKe 1 1 1\nKd nan 0.5 0.5\n")]);
    assert_eq!(error_in(&dir, &mesh_scene("t.obj")), format!("{}:3: Kd: expected finite numbers, found `nan 0.5 0.5`", dir.join("m.mtl").display()));
    let dir = folder("mtl-neg", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nKs 0 -0.5 0\n")]);
    assert_eq!(error_in(&dir, &mesh_scene("t.obj")), format!("{}:2: Ks: must not be negative, found `0 -0.5 0`", dir.join("m.mtl").display()));
    let dir = folder("mtl-ns", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nNs inf\n")]);
    assert_eq!(error_in(&dir, &mesh_scene("t.obj")), format!("{}:2: Ns: expected finite numbers, found `inf`", dir.join("m.mtl").display()));
    // tobj panicked on these (found by the obj_mtl fuzz target).
    let dir = folder("mtl-short", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nKd 0.20\n")]);
    assert_eq!(error_in(&dir, &mesh_scene("t.obj")), format!("{}:2: Kd: expected 3 numbers (r g b), found `0.20`", dir.join("m.mtl").display()));
    let dir = folder("mtl-empty", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nKa\n")]);
    assert_eq!(error_in(&dir, &mesh_scene("t.obj")), format!("{}:2: Ka: expected 3 numbers (r g b), found ``", dir.join("m.mtl").display()));
    // A valid file still loads.
    let dir = folder("mtl-ok", &[("t.obj", obj.as_bytes()), ("m.mtl", b"newmtl a\nKd 0.5 0.5 0.5\nNs 10\n")]);
    load_scene_str(&mesh_scene("t.obj"), Path::new("s.toml"), &Resolver::Disk { base: dir }, &Overrides::default()).unwrap();
}

#[test]
fn a_negative_environment_map_is_refused() {
    // A 2×1 little-endian PFM (bottom row first) whose second pixel has a negative green.
    let mut pfm = b"PF\n2 1\n-1\n".to_vec();
    for v in [1.0f32, 1.0, 1.0, 0.5, -0.25, 0.5] {
        pfm.extend_from_slice(&v.to_le_bytes());
    }
    let dir = folder("env", &[("sky.pfm", &pfm)]);
    let src = format!("{CAMERA}[[lights]]\ntype = \"environment\"\nfile = \"sky.pfm\"\n");
    assert_eq!(error_in(&dir, &src), format!("s.toml:7: lights[0].file: {}: texel (1, 0) is [0.5, -0.25, 0.5]: an environment map's radiance must be finite and not negative", dir.join("sky.pfm").display()));
}

#[test]
fn meshes_without_triangles_and_scenes_as_meshes_are_refused() {
    let dir = folder("empty", &[("empty.obj", b""), ("points.obj", TRIANGLE.as_bytes()), ("other.toml", CAMERA.as_bytes())]);
    assert_eq!(error_in(&dir, &mesh_scene("empty.obj")), format!("{}: the mesh has no triangles", dir.join("empty.obj").display()));
    assert_eq!(error_in(&dir, &mesh_scene("points.obj")), format!("{}: the mesh has no triangles", dir.join("points.obj").display()));
    assert_eq!(error_in(&dir, &mesh_scene("other.toml")), "s.toml:7: shapes[0].file: unsupported mesh format `other.toml` (supported: .obj, .obj.gz, .ply, .ply.gz)");
}

#[test]
fn faces_of_fewer_than_three_vertices_are_counted_in_one_warning() {
    let obj = format!("{TRIANGLE}v 1 1 0\nf 1 2 3\nf 1 2\nf 2 3 4\nf 4");
    let dir = folder("short-faces", &[("t.obj", obj.as_bytes()), ("ok.obj", format!("{TRIANGLE}f 1 2 3\n").as_bytes())]);
    let desc = parse_scene_str(&mesh_scene("t.obj"), Path::new("s.toml"), &Resolver::Disk { base: dir.clone() }).unwrap();
    assert_eq!(desc.warnings, vec![format!("{}: skipped 2 faces with fewer than 3 vertices (the first on line 6); the last line has no end of line: is the file truncated?", dir.join("t.obj").display())]);
    assert_eq!(desc.geometry.triangle_count(), 2);
    let desc = parse_scene_str(&mesh_scene("ok.obj"), Path::new("s.toml"), &Resolver::Disk { base: dir.clone() }).unwrap();
    assert!(desc.warnings.is_empty(), "{:?}", desc.warnings);
    // A bare mesh says it too.
    assert_eq!(parse_mesh_scene(&dir.join("t.obj")).unwrap().warnings.len(), 1);
}

#[test]
fn a_curve_needs_a_thickness_as_a_sphere_does() {
    let curve = "[[shapes]]\ntype = \"curve\"\npoints = [[0, 0, 0], [1, 1, 0], [2, -1, 0], [3, 0, 0]]\n";
    let dir = folder("curves", &[("flat.curves", b"strand\n0 0 0 0\n1 1 0 0\n2 -1 0 0\n3 0 0 0\n"), ("tip.curves", b"strand\n0 0 0 0.1\n1 1 0 0.1\n2 -1 0 0.05\n3 0 0 0\n")]);
    assert_eq!(error_in(&dir, &format!("{CAMERA}{curve}radius = 0\n")), "s.toml:8: shapes[0].radius: must be positive, found 0");
    assert_eq!(error_in(&dir, &format!("{CAMERA}{curve}radius = [0, 0, 0, 0]\n")), "s.toml:8: shapes[0].radius: must not all be 0: the curve would have no thickness");
    assert_eq!(error_in(&dir, &format!("{CAMERA}[[shapes]]\ntype = \"curve\"\nfile = \"tip.curves\"\nradius = 0\n")), "s.toml:8: shapes[0].radius: must be positive, found 0");
    assert_eq!(error_in(&dir, &format!("{CAMERA}[[shapes]]\ntype = \"curve\"\nfile = \"flat.curves\"\n")), format!("{}:1: strand 0: every radius is 0: the curve would have no thickness", dir.join("flat.curves").display()));
    // A tapered tip (radius 0 at one end) is fine.
    parse_scene_str(&format!("{CAMERA}[[shapes]]\ntype = \"curve\"\nfile = \"tip.curves\"\n"), Path::new("s.toml"), &Resolver::Disk { base: dir.clone() }).unwrap();
    parse_scene_str(&format!("{CAMERA}{curve}radius = [0.1, 0.1, 0.1, 0]\n"), Path::new("s.toml"), &Resolver::Disk { base: dir }).unwrap();
}

#[test]
fn overflowing_scales_and_camera_distances_say_so() {
    let dir = folder("messages", &[]);
    let sphere = "[[shapes]]\ntype = \"sphere\"\nradius = 1\n";
    assert_eq!(error_in(&dir, &format!("{CAMERA}{sphere}transform = [{{ scale = 1e13 }}]\n")), "s.toml:8: shapes[0].transform[0].scale: scale [1e13, 1e13, 1e13] changes volumes by 1.0e39, beyond single precision (1e-30 to 3.4e38 in magnitude)");
    assert_eq!(error_in(&dir, &format!("{CAMERA}{sphere}transform = [{{ scale = [1, 0, 1] }}]\n")), "s.toml:8: shapes[0].transform[0].scale: scale must not be zero");
    assert_eq!(error_in(&dir, "[camera]\nfrom = [0, 0, 1e30]\nat = [0, 0, 0]\nvfov = 40\n"), "s.toml:3: camera.at: is 1.0e30 from camera.from, farther than single precision can aim a camera (1e18)");
    assert_eq!(error_in(&dir, "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 5]\nvfov = 40\n"), "s.toml:3: camera.at: must differ from camera.from");
}

#[test]
fn a_bare_mesh_without_extent_is_refused_by_name() {
    let dir = folder("coincide", &[("point.obj", b"v 2 2 2\nv 2 2 2\nv 2 2 2\nf 1 2 3\nf 3 2 1\n"), ("far.obj", b"v 1e6 1e6 1e6\nv 1000000.06 1e6 1e6\nv 1e6 1000000.06 1e6\nf 1 2 3\n")]);
    assert_eq!(parse_mesh_scene(&dir.join("point.obj")).unwrap_err().to_string(), format!("{}: every vertex of its triangles is the same point [2, 2, 2]: there is nothing to see or frame", dir.join("point.obj").display()));
    // A tiny mesh far from the origin gets a camera that does not coincide with its target.
    raylab_loader::load_mesh_scene(&dir.join("far.obj"), &Overrides::default()).unwrap();
}

#[test]
fn folders_and_devices_are_named_as_such() {
    let dir = folder("not-files", &[]);
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    assert_eq!(error_in(&dir, &mesh_scene("folder.obj")), format!("{}: is a folder, not a file", dir.join("folder.obj").display()));
    assert_eq!(parse_mesh_scene(&dir.join("folder.obj")).unwrap_err().to_string(), format!("{}: is a folder, not a file", dir.join("folder.obj").display()));
    #[cfg(unix)]
    {
        // /dev/zero is endless: read as a mesh it would exhaust memory.
        std::os::unix::fs::symlink("/dev/zero", dir.join("zero.obj")).unwrap();
        assert_eq!(error_in(&dir, &mesh_scene("zero.obj")), format!("{}: is a device, not a regular file", dir.join("zero.obj").display()));
        std::os::unix::fs::symlink("/dev/zero", dir.join("zero.toml")).unwrap();
        assert_eq!(raylab_loader::load_scene(&dir.join("zero.toml"), &Overrides::default()).unwrap_err().to_string(), format!("{}: is a device, not a regular file", dir.join("zero.toml").display()));
    }
}

#[test]
fn files_beyond_the_caps_are_refused_before_reading() {
    let dir = folder("caps", &[]);
    // A sparse file: its size is in the metadata, nothing is written or read.
    let big = dir.join("big.obj");
    std::fs::File::create(&big).unwrap().set_len(MAX_DATA_BYTES + 1).unwrap();
    assert_eq!(error_in(&dir, &mesh_scene("big.obj")), format!("{}: is 34359738369 bytes (32.0 GiB), more than the 32.0 GiB raylab reads from one such file", big.display()));
    let scene = dir.join("big.toml");
    std::fs::File::create(&scene).unwrap().set_len(raylab_loader::files::MAX_SCENE_BYTES + 1).unwrap();
    assert_eq!(raylab_loader::load_scene(&scene, &Overrides::default()).unwrap_err().to_string(), format!("{}: is 268435457 bytes (256.0 MiB), more than the 256.0 MiB raylab reads from one such file", scene.display()));
    // Under the cap, the bytes come back.
    std::fs::write(dir.join("small"), b"abc").unwrap();
    assert_eq!(read_capped(&dir.join("small"), 3).unwrap(), b"abc");
}

#[test]
fn long_names_from_the_file_are_shortened_in_messages() {
    let dir = folder("long", &[]);
    let key = "k".repeat(10_000_000);
    let e = error_in(&dir, &format!("{key} = 1\n{CAMERA}"));
    assert_eq!(e, format!("s.toml:1: {}... (10000000 bytes): unknown field (valid: camera, render, background, textures, materials, shapes, lights)", "k".repeat(60)));
    let e = error_in(&dir, &format!("{CAMERA}[[shapes]]\ntype = \"{}\"\n", "x".repeat(1000)));
    assert_eq!(e, format!("s.toml:6: shapes[0].type: unknown type `{}... (1000 bytes)` (valid: sphere, triangle, quad, mesh, curve, bezier_patch)", "x".repeat(60)));
}
