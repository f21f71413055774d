//! The first hour of a user who brings their own scene: PLY and pbrt-v4 files open as TOML
//! does, unknown formats and certain-black renders are said plainly, and the options that
//! used to trip people up (`--spp 5`, `gen -o x.obj`) do what they say.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../loader/tests/data").canonicalize().unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-byo-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn ply_and_pbrt_render_like_toml() {
    let dir = scratch("render");
    for file in ["bunny_binary.ply", "bunny.pbrt"] {
        let path = data().join(file);
        let o = raylab(&["render", path.to_str().unwrap(), "--width", "32", "--height", "24", "--spp", "1", "-o", "out.png"], &dir);
        assert!(o.status.success(), "{file}: {}", stderr(&o));
        assert!(dir.join("out.png").exists());
        std::fs::remove_file(dir.join("out.png")).unwrap();
    }
    let o = raylab(&["inspect", data().join("bunny.pbrt").to_str().unwrap()], &dir);
    assert!(String::from_utf8_lossy(&o.stdout).contains("4970 triangles"), "{}", String::from_utf8_lossy(&o.stdout));
}

#[test]
fn unknown_formats_are_rejected_by_extension() {
    let dir = scratch("ext");
    std::fs::write(dir.join("model.fbx"), "binary").unwrap();
    let o = raylab(&["render", "model.fbx"], &dir);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stderr(&o).trim_end(), "raylab: error: model.fbx: unsupported file type (supported: .toml, .pbrt, .gltf, .glb, .obj, .obj.gz, .ply, .ply.gz)");
}

#[test]
fn lenient_pbrt_warns_and_skips() {
    let dir = scratch("lenient");
    std::fs::write(dir.join("s.pbrt"), "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"spot\" \"rgb I\" [ 1 1 1 ]\nLightSource \"point\" \"point3 from\" [ 0 0 4 ]\nShape \"sphere\"\n").unwrap();
    let strict = raylab(&["render", "s.pbrt", "--width", "8", "--height", "8", "--spp", "1", "-q"], &dir);
    assert_eq!(strict.status.code(), Some(1));
    assert!(stderr(&strict).contains("s.pbrt:4: LightSource: light \"spot\" is not supported (supported: point, distant, infinite)"), "{}", stderr(&strict));
    let lenient = raylab(&["render", "s.pbrt", "--width", "8", "--height", "8", "--spp", "1", "-q", "--lenient"], &dir);
    assert!(lenient.status.success(), "{}", stderr(&lenient));
    assert!(stderr(&lenient).contains("warning: s.pbrt:4: LightSource: light \"spot\" is not supported"), "{}", stderr(&lenient));
}

#[test]
fn certain_black_renders_and_rounded_spp_are_said_once() {
    let dir = scratch("black");
    std::fs::write(dir.join("dark.toml"), "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[shapes]]\ntype = \"sphere\"\nradius = 1\n").unwrap();
    let o = raylab(&["render", "dark.toml", "--width", "8", "--height", "8", "--spp", "5", "-q"], &dir);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.matches("warning: the scene has no lights and a black background: the `whitted` integrator will render a black image").count(), 1, "{err}");
    assert_eq!(err.matches("note: the jittered sampler stratifies 3×3: 5 samples per pixel rounded up to 9").count(), 1, "{err}");
    // Lit only by an emitter, `whitted` sees the emitter and nothing it lights.
    std::fs::write(dir.join("area.toml"), "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[lights]]\ntype = \"sphere\"\ncenter = [0, 2, 0]\nradius = 0.5\nradiance = 5\n").unwrap();
    let o = raylab(&["render", "area.toml", "--width", "8", "--height", "8", "--spp", "1", "-q"], &dir);
    assert!(stderr(&o).contains("warning: the scene is lit only by area lights (emitters), which `whitted` does not sample"), "{}", stderr(&o));
    let o = raylab(&["render", "area.toml", "--width", "8", "--height", "8", "--spp", "1", "-q", "--integrator", "path"], &dir);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn gen_refuses_an_output_that_would_be_overwritten() {
    let dir = scratch("gen");
    let o = raylab(&["gen", "tetra", "--size", "2", "-o", "t.obj"], &dir);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stderr(&o).trim_end(), "raylab: error: --output: the scene file must end in .toml (its mesh or curves are written beside it), found t.obj");
}

/// `cd scenes && raylab inspect bunny.toml`: the mesh is found on the shared scene path even
/// though the scene is named without a folder.
#[test]
fn a_scene_named_from_its_own_folder_finds_shared_meshes() {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").canonicalize().unwrap();
    let o = raylab(&["inspect", "bunny.toml"], &scenes);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4970 triangles"), "{}", String::from_utf8_lossy(&o.stdout));
}
