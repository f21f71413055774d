//! `crease_angle` on smoothed meshes: range-checked, only with `smooth = true`, and 180°
//! is plain smoothing.

use std::path::Path;

use raylab_loader::files::Resolver;
use raylab_loader::{load_scene_str, Overrides};
use raylab_render::{Scene, TriangleMesh};
use raylab_testkit::shared_scenes;

fn teapot(keys: &str) -> Result<Scene, String> {
    let src = format!("[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n[[shapes]]\ntype = \"mesh\"\nfile = \"teapot_6320.obj\"\n{keys}");
    load_scene_str(&src, Path::new("s.toml"), &Resolver::Disk { base: shared_scenes() }, &Overrides::default()).map_err(|e| e.to_string())
}

fn mesh(keys: &str) -> TriangleMesh {
    teapot(keys).unwrap_or_else(|e| panic!("{e}")).geometry.meshes.remove(0)
}

#[test]
fn crease_angle_is_checked() {
    if !raylab_testkit::shared_files(&["teapot_6320.obj"]) {
        return;
    }
    assert_eq!(teapot("smooth = true\ncrease_angle = 200\n").err().unwrap(), "s.toml:9: shapes[0].crease_angle: must be between 0 and 180, found 200");
    assert_eq!(teapot("crease_angle = 30\n").err().unwrap(), "s.toml:8: shapes[0].crease_angle: needs `smooth = true`");
}

#[test]
fn crease_angle_180_is_plain_smoothing_and_smaller_angles_split_sharp_edges() {
    if !raylab_testkit::shared_files(&["teapot_6320.obj"]) {
        return;
    }
    let plain = mesh("smooth = true\n");
    let all = mesh("smooth = true\ncrease_angle = 180\n");
    assert_eq!((&plain.positions, &plain.normals, &plain.indices), (&all.positions, &all.normals, &all.indices));
    // 30° splits the vertices along the few sharper edges (3,644 vertices become 4,115)
    // and leaves the rest welded.
    let creased = mesh("smooth = true\ncrease_angle = 30\n");
    assert!(creased.positions.len() > plain.positions.len(), "{} vertices", creased.positions.len());
    assert!(creased.positions.len() < 2 * plain.positions.len(), "{} vertices", creased.positions.len());
    assert_eq!(creased.indices.len(), plain.indices.len());
}
