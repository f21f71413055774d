//! The OBJ writer against text written out by hand from the format (Wavefront OBJ:
//! 1-based indices, `f v/vt/vn`, `f v//vn` without UVs), not only a round trip through tobj.

use raylab_core::{Vec2, Vec3};
use raylab_loader::obj::obj_text;
use raylab_render::TriangleMesh;

#[test]
fn quad_with_uvs_and_normals() {
    // Two triangles sharing an edge; corners 0 and 3, 2 and 4 share every value.
    let mesh = TriangleMesh {
        name: "quad".into(),
        positions: vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.5)],
        normals: vec![Vec3::Z; 6],
        uvs: vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 0.1)],
        indices: vec![[0, 1, 2], [3, 4, 5]],
        ..Default::default()
    };
    let expected = "# quad: 2 triangles, written by raylab\n\
                    v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0.5\n\
                    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 0.1\n\
                    vn 0 0 1\n\
                    f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
    assert_eq!(obj_text(&mesh), expected);
}

#[test]
fn positions_only_and_normals_without_uvs() {
    let tri = |normals: Vec<Vec3>| TriangleMesh {
        name: "t".into(),
        positions: vec![Vec3::new(-1.5, 2.0, 1e-7), Vec3::new(0.1, 0.2, 0.3), Vec3::new(3.0, -0.0, 0.0)],
        normals,
        indices: vec![[2, 1, 0]],
        ..Default::default()
    };
    // Shortest round-trip notation: 1e-7 stays `0.0000001`, −0 keeps its sign; the face keeps
    // the mesh's winding.
    assert_eq!(obj_text(&tri(vec![])), "# t: 1 triangles, written by raylab\nv -1.5 2 0.0000001\nv 0.1 0.2 0.3\nv 3 -0 0\nf 3 2 1\n");
    let n = vec![Vec3::X, Vec3::Y, Vec3::X];
    assert_eq!(obj_text(&tri(n)), "# t: 1 triangles, written by raylab\nv -1.5 2 0.0000001\nv 0.1 0.2 0.3\nv 3 -0 0\nvn 1 0 0\nvn 0 1 0\nf 3//1 2//2 1//1\n");
}
