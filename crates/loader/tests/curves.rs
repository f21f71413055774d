//! Curve shapes and the hair material in scene files: inline points, text curve files and
//! `.hair` files, each mode; errors asserted by their exact message.

use std::path::{Path, PathBuf};

use raylab_core::{Vec3, Vec4};
use raylab_loader::files::Resolver;
use raylab_loader::{load_scene_str, Overrides};
use raylab_render::{Material, Scene};

const CAMERA: &str = "[camera]\nfrom = [0, 0, 5]\nat = [0, 0, 0]\nvfov = 40\n";

/// A fresh folder for files the tests write.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-curves-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn load_in(dir: &Path, src: &str) -> Result<Scene, String> {
    load_scene_str(src, Path::new("c.toml"), &Resolver::Disk { base: dir.to_path_buf() }, &Overrides::default()).map_err(|e| e.to_string())
}

fn load(src: &str) -> Result<Scene, String> {
    load_in(&std::env::temp_dir(), src)
}

fn shape(keys: &str) -> String {
    format!("{CAMERA}[[shapes]]\ntype = \"curve\"\n{keys}")
}

#[test]
fn inline_points_in_each_basis_and_mode() {
    let points = "points = [[0, 0, 0], [1, 1, 0], [2, -1, 0], [3, 0, 0]]\n";
    let s = load(&shape(&format!("{points}radius = 0.1\n"))).unwrap();
    assert_eq!((s.geometry.curves.len(), s.geometry.curves[0].len()), (1, 1));
    assert_eq!(s.geometry.curves[0].segments[0].control_points()[3], Vec4::new(3.0, 0.0, 0.0, 0.1));
    // Per-point radii, a B-spline, and a transform (radii scale with it).
    let s = load(&shape(&format!("{points}radius = [0.1, 0.2, 0.3, 0.4]\nbasis = \"bspline\"\ntransform = [{{ scale = 2 }}]\n"))).unwrap();
    let first = s.geometry.curves[0].segments[0].control_points()[0];
    // (p0 + 4p1 + p2)/6 = (1, 0.5, 0), radius (0.1 + 0.8 + 0.3)/6 = 0.2, all doubled.
    assert!((first - Vec4::new(2.0, 1.0, 0.0, 0.4)).abs().max_element() < 1e-6, "{first}");
    // A tube: 2 segments' worth of rings (3 per segment + 1) of 5 sides, two caps.
    let s = load(&shape(&format!("{points}radius = 0.1\ndegree = 1\nmode = \"tube\"\nsegments = 3\nsides = 5\n"))).unwrap();
    assert!(s.geometry.curves.is_empty());
    assert_eq!(s.geometry.triangle_count(), 2 * 5 * 9 + 2 * 5);
}

#[test]
fn curve_files_in_text() {
    let dir = scratch("text");
    std::fs::write(dir.join("s.curves"), "# two strands\nstrand\n0 0 0 0.05\n1 0 0\n\nstrand  # the second\n0 1 0\n1 1 0 0.02\n").unwrap();
    let s = load_in(&dir, &shape("file = \"s.curves\"\ndegree = 1\nradius = 0.03\n")).unwrap();
    assert_eq!(s.geometry.curves.len(), 2);
    assert_eq!(s.geometry.curves[0].segments[0].control_points(), &[Vec4::new(0.0, 0.0, 0.0, 0.05), Vec4::new(1.0, 0.0, 0.0, 0.03)]);
    assert_eq!(s.geometry.curves[1].segments[0].control_points(), &[Vec4::new(0.0, 1.0, 0.0, 0.03), Vec4::new(1.0, 1.0, 0.0, 0.02)]);

    let err = |text: &str, keys: &str| {
        std::fs::write(dir.join("bad.curves"), text).unwrap();
        load_in(&dir, &shape(&format!("file = \"bad.curves\"\n{keys}"))).unwrap_err()
    };
    let bad = dir.join("bad.curves").display().to_string();
    assert_eq!(err("strand\n0 0 x\n", ""), format!("{bad}:2: expected `strand` or a point `x y z [radius]`, found `0 0 x`"));
    assert_eq!(err("0 0 0\n", ""), format!("{bad}:1: a point before the first `strand` line"));
    assert_eq!(err("strand\n0 0\n", ""), format!("{bad}:2: a point needs 3 coordinates and an optional radius, found 2 numbers"));
    assert_eq!(err("strand\n0 0 0 -1\n", ""), format!("{bad}:2: the radius must not be negative, found -1"));
    assert_eq!(err("# nothing\n", ""), "c.toml:7: shapes[0].file: ".to_string() + &bad + ": no strands");
    assert_eq!(err("strand\n0 0 0\nstrand\n0 0 0\n1 0 0\n2 0 0\n", ""), format!("{bad}:1: strand 0: a Bézier curve of degree 3 needs 3·k + 1 points, found 1"));
}

/// Writes a `.hair` file: header, then the segments, points and thickness arrays when given.
fn write_hair(path: &Path, strands: &[Vec<Vec3>], segments: bool, thickness: Option<&[f32]>, default: (u32, f32)) {
    let points: usize = strands.iter().map(Vec::len).sum();
    let flags = 2 | if segments { 1 } else { 0 } | if thickness.is_some() { 4 } else { 0 };
    let mut b = b"HAIR".to_vec();
    for v in [strands.len() as u32, points as u32, flags, default.0] {
        b.extend(v.to_le_bytes());
    }
    for v in [default.1, 1.0, 0.5, 0.4, 0.3] {
        b.extend(v.to_le_bytes());
    }
    b.resize(128, 0);
    if segments {
        for s in strands {
            b.extend(((s.len() - 1) as u16).to_le_bytes());
        }
    }
    for p in strands.iter().flatten() {
        for c in p.to_array() {
            b.extend(c.to_le_bytes());
        }
    }
    for t in thickness.into_iter().flatten() {
        b.extend(t.to_le_bytes());
    }
    std::fs::write(path, b).unwrap();
}

#[test]
fn hair_files_round_trip() {
    let dir = scratch("hair");
    let strands = vec![
        vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.5, 2.0, 0.0), Vec3::new(1.0, 2.5, 0.5)],
        vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.2)],
    ];
    let thickness = [0.2, 0.18, 0.16, 0.14, 0.1, 0.05];
    write_hair(&dir.join("a.hair"), &strands, true, Some(&thickness), (0, 0.0));
    let s = load_in(&dir, &shape("file = \"a.hair\"\ndegree = 1\n")).unwrap();
    let read: Vec<Vec<Vec4>> = s.geometry.curves.iter().map(|c| {
        let mut pts = vec![c.segments[0].control_points()[0]];
        pts.extend(c.segments.iter().map(|b| b.control_points()[1]));
        pts
    }).collect();
    let want: Vec<Vec<Vec4>> = vec![
        strands[0].iter().zip(&thickness[..4]).map(|(p, t)| p.extend(t / 2.0)).collect(),
        strands[1].iter().zip(&thickness[4..]).map(|(p, t)| p.extend(t / 2.0)).collect(),
    ];
    assert_eq!(read, want);
    // Without the optional arrays: the header's segment count and thickness.
    let same = vec![strands[0].clone(), strands[0].clone()];
    write_hair(&dir.join("b.hair"), &same, false, None, (3, 0.08));
    let s = load_in(&dir, &shape("file = \"b.hair\"\n")).unwrap();
    assert_eq!(s.geometry.curves.len(), 2);
    assert_eq!(s.geometry.curves[1].segments[0].control_points()[2], Vec4::new(0.5, 2.0, 0.0, 0.04));

    let path = |name: &str| dir.join(name).display().to_string();
    std::fs::write(dir.join("c.hair"), b"HAIR").unwrap();
    assert_eq!(load_in(&dir, &shape("file = \"c.hair\"\n")).unwrap_err(), format!("{}: too short for a .hair header: 4 bytes of 128", path("c.hair")));
    std::fs::write(dir.join("d.hair"), [b'X'; 128]).unwrap();
    assert_eq!(load_in(&dir, &shape("file = \"d.hair\"\n")).unwrap_err(), format!("{}: not a .hair file (it does not start with \"HAIR\")", path("d.hair")));
    write_hair(&dir.join("e.hair"), &same, false, None, (2, 0.08));
    assert_eq!(load_in(&dir, &shape("file = \"e.hair\"\n")).unwrap_err(), format!("{}: the strands' segment counts make 6 points, the header says 8", path("e.hair")));
    // Counts that the file cannot hold are errors before anything is allocated for them.
    let mut huge = std::fs::read(dir.join("b.hair")).unwrap();
    huge[4..8].copy_from_slice(&4_000_000_000u32.to_le_bytes());
    std::fs::write(dir.join("g.hair"), huge).unwrap();
    assert_eq!(load_in(&dir, &shape("file = \"g.hair\"\n")).unwrap_err(), format!("{}: the header announces 4000000000 strands but only 8 points", path("g.hair")));
    let mut truncated = std::fs::read(dir.join("a.hair")).unwrap();
    truncated.truncate(140);
    std::fs::write(dir.join("f.hair"), truncated).unwrap();
    assert_eq!(load_in(&dir, &shape("file = \"f.hair\"\ndegree = 1\n")).unwrap_err(), format!("{}: truncated: the header announces 228 bytes, the file has 140", path("f.hair")));
    assert_eq!(load_in(&dir, &shape("file = \"a.hair\"\nradius = 1\n")).unwrap_err(), "c.toml:8: shapes[0].radius: not used with .hair files, which give every point's thickness");
}

#[test]
fn scene_errors_name_line_and_field() {
    let points = "points = [[0, 0, 0], [1, 1, 0], [2, -1, 0], [3, 0, 0]]\n";
    assert_eq!(load(&shape(points)).unwrap_err(), "c.toml:5: shapes[0].radius: missing (required with `points`)");
    assert_eq!(load(&shape("radius = 1\n")).unwrap_err(), "c.toml:5: shapes[0].points: missing (give `points` or `file`)");
    assert_eq!(load(&shape(&format!("{points}radius = [1, 2]\n"))).unwrap_err(), "c.toml:8: shapes[0].radius: expected 4 radii (one per point), found 2");
    assert_eq!(load(&shape(&format!("{points}radius = [1, 2, -3, 4]\n"))).unwrap_err(), "c.toml:8: shapes[0].radius[2]: must not be negative, found -3");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nbasis = \"nurbs\"\n"))).unwrap_err(), "c.toml:9: shapes[0].basis: unknown basis `nurbs` (valid: bezier, bspline, catmull-rom)");
    assert_eq!(load(&shape(&format!("{points}radius = 1\ndegree = 4\n"))).unwrap_err(), "c.toml:9: shapes[0].degree: must be between 1 and 3, found 4");
    assert_eq!(load(&shape(&format!("{points}radius = 1\ndegree = 2\n"))).unwrap_err(), "c.toml:7: shapes[0].points: a Bézier curve of degree 2 needs 2·k + 1 points, found 4");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nbasis = \"catmull-rom\"\ndegree = 2\n"))).unwrap_err(), "c.toml:7: shapes[0].points: Catmull–Rom splines are cubic: degree must be 3, found 2");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nmode = \"ribbon\"\n"))).unwrap_err(), "c.toml:9: shapes[0].mode: unknown mode `ribbon` (valid: tube, direct)");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nsides = 6\n"))).unwrap_err(), "c.toml:9: shapes[0].sides: only used with mode = \"tube\"");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nmode = \"tube\"\nsides = 2\n"))).unwrap_err(), "c.toml:10: shapes[0].sides: must be between 3 and 256, found 2");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nsmooth = true\n"))).unwrap_err(), "c.toml:9: shapes[0].smooth: not a field of `curve` shapes (valid: type, material, transform, points, radius, basis, degree, file, mode, segments, sides)");
    assert_eq!(load(&shape(&format!("{points}radius = 1\nfile = \"missing.curves\"\n"))).unwrap_err().split(" (looked").next().unwrap(), "c.toml:9: shapes[0].file: cannot find `missing.curves`");
}

#[test]
fn hair_material() {
    let s = load(&format!("{CAMERA}[[materials]]\nname = \"h\"\ntype = \"hair\"\ncolor = [0.3, 0.2, 0.1]\nkd = 0.5\nks = 0.25\nexponent = 60\n")).unwrap();
    let Material::Hair { kd, ks, exponent, .. } = s.materials[1] else { panic!("{:?}", s.materials[1]) };
    assert_eq!((kd, ks, exponent), (0.5, 0.25, 60.0));
    assert_eq!(
        load(&format!("{CAMERA}[[materials]]\nname = \"h\"\ntype = \"hair\"\nks = 2\n")).unwrap_err(),
        "c.toml:8: materials[0].ks: must be between 0 and 1, found 2"
    );
    assert_eq!(
        load(&format!("{CAMERA}[[materials]]\nname = \"h\"\ntype = \"hair\"\nalbedo = 1\n")).unwrap_err(),
        "c.toml:8: materials[0].albedo: not a field of `hair` materials (valid: name, type, normal_map, normal_space, bump_map, bump_scale, color, kd, ks, exponent)"
    );
}
