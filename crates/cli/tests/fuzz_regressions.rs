//! Replays, on stable and in `cargo test`, every input the fuzz targets (fuzz/) were seeded
//! with (fuzz/corpus/TARGET/*) and every input that once crashed, hung or over-allocated
//! (fuzz/regressions/TARGET/*): each reader must return, Ok or Err, without a panic. The
//! harness here mirrors fuzz/fuzz_targets/*.rs and fuzz/src/lib.rs.

use std::path::{Path, PathBuf};

use raylab_loader::files::{Found, Resolver};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

fn scratch() -> PathBuf {
    let d = std::env::temp_dir().join(format!("raylab-fuzz-replay-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn file(name: &str, bytes: &[u8]) -> PathBuf {
    let p = scratch().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn scene_with_file(name: &str, bytes: &[u8], shape: &str) {
    let path = file(name, bytes);
    let src = format!("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[shapes]]\n{shape}\nfile = \"{name}\"\n");
    let _ = raylab_loader::parse_scene_str(&src, Path::new("fuzz.toml"), &Resolver::Disk { base: path.parent().unwrap().to_path_buf() });
}

/// Runs fuzz target `target`'s reader on `data`.
fn run(target: &str, data: &[u8]) {
    match target {
        "scene_toml" => {
            if let Ok(src) = std::str::from_utf8(data) {
                let _ = raylab_loader::parse_scene_str(src, Path::new("fuzz.toml"), &Resolver::Embedded);
            }
        }
        "obj_mtl" => {
            let (obj, mtl) = data.split_at(data.iter().position(|&b| b == 0).unwrap_or(data.len()));
            file("m.mtl", mtl.get(1..).unwrap_or(&[]));
            let _ = raylab_loader::obj::load_obj(&Found::Disk(file("m.obj", obj)), &raylab_core::Transform::IDENTITY);
        }
        "curves" => scene_with_file("c.curves", data, "type = \"curve\"\nmode = \"tube\"\nsegments = 2\nsides = 3"),
        "hair" => scene_with_file("c.hair", data, "type = \"curve\""),
        "patches_bpt" => scene_with_file("p.bpt", data, "type = \"bezier_patch\"\nsubdivisions = 2"),
        "patches_newell" => scene_with_file("p.txt", data, "type = \"bezier_patch\"\nmode = \"direct\""),
        "rayfile" => {
            let _ = raylab_lab::rayfile::read(&file("r.rays", data));
        }
        "film" => {
            let _ = raylab_render::film::Film::from_bytes(data);
        }
        image if image.starts_with("image_") => {
            let _ = raylab_loader::image_io::decode_image(Path::new(&format!("x.{}", &image[6..])), data, true);
        }
        other => panic!("fuzz input for an unknown target `{other}`"),
    }
}

#[test]
fn corpus_and_regression_inputs_load_without_panicking() {
    let mut replayed = 0;
    for kind in ["corpus", "regressions"] {
        let Ok(targets) = std::fs::read_dir(fuzz_dir().join(kind)) else { continue };
        for t in targets {
            let t = t.unwrap().path();
            let target = t.file_name().unwrap().to_string_lossy().into_owned();
            for input in std::fs::read_dir(&t).unwrap() {
                let input = input.unwrap().path();
                let data = std::fs::read(&input).unwrap();
                let r = std::panic::catch_unwind(|| run(&target, &data));
                assert!(r.is_ok(), "{} panicked", input.display());
                replayed += 1;
            }
        }
    }
    // Every target has seeds: a renamed folder must not silently skip them.
    assert!(replayed >= 12, "only {replayed} fuzz inputs replayed");
    std::fs::remove_dir_all(scratch()).unwrap();
}
