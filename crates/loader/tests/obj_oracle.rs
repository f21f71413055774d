//! raylab's streaming OBJ reader against tobj (which it replaced, and which still reads the
//! MTL files): the same meshes, vertex for vertex, for the shared OBJ files and for
//! hand-written ones with groups, materials, quads, polygons, relative and forward indices.

use std::path::{Path, PathBuf};

use raylab_core::{Transform, Vec2, Vec3};
use raylab_loader::files::Found;
use raylab_loader::obj::load_obj;

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes")
}

fn assert_same_as_tobj(path: &Path) {
    let ours = load_obj(&Found::Disk(path.to_path_buf()), &Transform::IDENTITY).unwrap();
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    let (models, materials) = tobj::load_obj(path, &opts).unwrap();
    let models: Vec<_> = models.into_iter().filter(|m| !m.mesh.indices.is_empty()).collect();
    assert_eq!(ours.meshes.len(), models.len(), "{}", path.display());
    assert_eq!(ours.materials.len(), materials.map_or(0, |m| m.len()));
    for ((mesh, material), model) in ours.meshes.iter().zip(&models) {
        let m = &model.mesh;
        assert_eq!((&mesh.name, *material), (&model.name, m.material_id), "{}", path.display());
        let positions: Vec<Vec3> = m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        assert_eq!(mesh.positions, positions, "{}", path.display());
        let indices: Vec<[u32; 3]> = m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        assert_eq!(mesh.indices, indices, "{}", path.display());
        let normals: Vec<Vec3> = m.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2]).try_normalize().unwrap_or(Vec3::Y)).collect();
        assert_eq!(mesh.normals, if normals.len() == positions.len() { normals } else { Vec::new() }, "{}", path.display());
        let uvs: Vec<Vec2> = m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])).collect();
        assert_eq!(mesh.uvs, if uvs.len() == positions.len() { uvs } else { Vec::new() }, "{}", path.display());
    }
}

#[test]
fn shared_obj_files_read_as_tobj_reads_them() {
    for name in ["CornellBox-Original.obj", "cornell_box.obj", "bunny_4968.obj", "spot_triangulated.obj", "teapot_6320.obj", "dragon_vrip_res4.obj"] {
        assert_same_as_tobj(&scenes().join(name));
    }
}

#[test]
fn groups_materials_polygons_and_relative_indices_read_as_tobj_reads_them() {
    let dir = std::env::temp_dir().join(format!("raylab-obj-oracle-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n").unwrap();
    let obj = "mtllib m.mtl\n# a comment\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 0 2\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 2\n\
               o first\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/1/1\nf -5/1/1 -3/3/1 -1/2/1\nusemtl blue\nf 1 2 3 4 5\nusemtl blue\n\
               g second\nf 4 7 6\nv 2 2 2\nv 3 3 3\nf 1 2\nf 1//1 2//1 3//1\ng empty\ng third\nusemtl nothing\nf 2 3 1\n";
    std::fs::write(dir.join("t.obj"), obj).unwrap();
    assert_same_as_tobj(&dir.join("t.obj"));
    let ours = load_obj(&Found::Disk(dir.join("t.obj")), &Transform::IDENTITY).unwrap();
    // Hand-checked: the quad and the pentagon fanned, `v 0.5 2 0 2` divided by w, the forward
    // indices 6 and 7 of `second` defined after its face.
    let counts: Vec<(&str, usize, usize, Option<usize>)> = ours.meshes.iter().map(|(m, k)| (m.name.as_str(), m.indices.len(), m.positions.len(), *k)).collect();
    assert_eq!(counts, vec![("first", 3, 5, Some(0)), ("first", 3, 5, Some(1)), ("second", 2, 6, Some(1)), ("third", 1, 3, None)]);
    assert_eq!(ours.meshes[1].0.positions[4], Vec3::new(0.25, 1.0, 0.0));
    assert_eq!(ours.warnings, vec![format!("{}: skipped 1 face with fewer than 3 vertices (the first on line 23)", dir.join("t.obj").display())]);
    std::fs::remove_dir_all(&dir).unwrap();
}
