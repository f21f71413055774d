//! Items of the first hour (issue 13, "Fix") not covered elsewhere: the help names every
//! structure itself, and `bake` finds the README's meshes on the shared scene path.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn raylab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raylab")).args(args).current_dir(dir).output().expect("raylab runs")
}

/// A folder inside the repository, so that the shared scene folder beside it is an ancestor's.
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("first-hour-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn render_help_lists_every_structure_and_points_nowhere_else() {
    let o = raylab(&["render", "--help"], Path::new("."));
    let help = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success());
    let names = "none, bvh, bvh-median, bvh-midpoint, aabb, grid, lbvh, lbvh-ploc, kdtree, sphere-bvh, sbvh, bvh8, bvh4, bvh8-sbvh, bvh8q";
    assert_eq!(names, raylab_accel::AccelKind::names());
    assert!(help.contains(names), "{help}");
    assert!(!help.contains("inspect --help"), "{help}");
}

/// The README's `raylab bake --high dragon_vrip.obj.gz ...` names meshes without a folder:
/// they are found on the shared scene path (here the bunny, which is faster to bake).
#[test]
fn bake_finds_bare_mesh_names_on_the_shared_scene_path() {
    let dir = scratch("bake");
    let o = raylab(&["bake", "--high", "bunny_4968.obj", "--low", "bunny_4968.obj", "-o", "normal.png", "--size", "1024"], &dir);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("normal.png").is_file());
    std::fs::remove_dir_all(&dir).ok();
}
