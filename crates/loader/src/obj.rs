//! Wavefront OBJ meshes (read by [`crate::obj_read`], streaming) and their MTL materials
//! (checked here, then read by `tobj`). Errors name the file and the line.

use std::io::Cursor;
use std::path::Path;

use raylab_core::{Rgb, Transform};
#[cfg(test)]
use raylab_core::{Vec2, Vec3};
use raylab_render::TriangleMesh;

use crate::error::{shorten, LoadError};
use crate::files::{not_found_message, Found};

pub use crate::obj_read::MtlMaterial;

/// The meshes of one OBJ file, in world space, with the MTL materials they refer to.
pub struct ObjData {
    /// Each mesh with the index of its material in `materials`, if any.
    pub meshes: Vec<(TriangleMesh, Option<usize>)>,
    pub materials: Vec<MtlMaterial>,
    /// Where relative texture names in the MTL are looked up.
    pub mtl_dir: Option<Found>,
    /// What was skipped, said once per file with counts (the caller prints them).
    pub warnings: Vec<String>,
}

pub fn load_obj(found: &Found, to_world: &Transform) -> Result<ObjData, LoadError> {
    let path = found.path();
    let siblings = found.sibling_resolver();
    let mut mtl_dir = None;
    let read = crate::obj_read::read_obj(&path, found.lines()?, to_world, |name| {
        let f = siblings.find(name).map_err(|tried| LoadError::file(&path, format!("mtllib: {}", not_found_message(name, &tried))))?;
        let bytes = f.read()?;
        check_mtl(&f.path(), &bytes)?;
        let (materials, _) = tobj::load_mtl_buf(&mut Cursor::new(bytes)).map_err(|e| LoadError::file(&f.path(), format!("cannot parse MTL: {e}")))?;
        mtl_dir = Some(f);
        Ok(materials)
    })?;
    Ok(ObjData { meshes: read.meshes, materials: read.materials, mtl_dir, warnings: read.short_faces.into_iter().collect() })
}

/// The MTL statements raylab uses, checked before tobj reads them (tobj takes `nan` and
/// negative colours as given, and panics on a colour of fewer than 3 numbers): colours of 3
/// finite numbers, not negative; scalars finite.
fn check_mtl(path: &Path, bytes: &[u8]) -> Result<(), LoadError> {
    let text = String::from_utf8_lossy(bytes);
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { continue };
        let colour = matches!(kw, "Ka" | "Kd" | "Ks" | "Ke" | "Tf");
        if !colour && !matches!(kw, "Ns" | "Ni" | "d" | "Tr") {
            continue;
        }
        let rest: Vec<&str> = words.collect();
        // Colours may be `spectral file` or `xyz x y z`, which raylab ignores as tobj does.
        if rest.first().is_some_and(|w| w.parse::<f32>().is_err() && !w.eq_ignore_ascii_case("nan") && !w.to_ascii_lowercase().contains("inf")) {
            continue;
        }
        let values: Vec<f32> = rest.iter().map_while(|w| w.parse::<f32>().ok()).collect();
        let err = |m: &str| Err(LoadError::new(path, Some(i + 1), kw, format!("{m}, found `{}`", shorten(&rest.join(" ")))));
        if values.iter().any(|v| !v.is_finite()) {
            return err("expected finite numbers");
        }
        // tobj panics on a colour of fewer than 3 numbers (found by the obj_mtl fuzz target).
        if matches!(kw, "Ka" | "Kd" | "Ks" | "Ke") && values.len() < 3 {
            return err("expected 3 numbers (r g b)");
        }
        if (colour || kw == "Ns") && values.iter().any(|&v| v < 0.0) {
            return err("must not be negative");
        }
    }
    Ok(())
}

/// The colour of an MTL entry, or `default`.
pub fn mtl_color(c: Option<[f32; 3]>, default: Rgb) -> Rgb {
    c.map(Rgb::from_array).unwrap_or(default)
}

/// A mesh as OBJ text: positions, UVs and normals each written once per distinct value (in
/// Rust's shortest round-trip notation, so reading the file back gives the same `f32`s) and
/// faces `f v/vt/vn`. Loading it (tobj, `single_index`) gives the same vertices in the same
/// order when no two vertices share all three values.
pub fn obj_text(mesh: &TriangleMesh) -> String {
    use std::collections::HashMap;
    use std::fmt::Write;
    fn index<const N: usize>(values: &mut Vec<[f32; N]>, ids: &mut HashMap<[u32; N], usize>, v: [f32; N]) -> usize {
        *ids.entry(v.map(f32::to_bits)).or_insert_with(|| {
            values.push(v);
            values.len()
        })
    }
    let (mut v, mut vt, mut vn) = (Vec::new(), Vec::new(), Vec::new());
    let (mut v_ids, mut vt_ids, mut vn_ids) = (HashMap::new(), HashMap::new(), HashMap::new());
    let corners: Vec<String> = (0..mesh.positions.len())
        .map(|i| {
            let p = index(&mut v, &mut v_ids, mesh.positions[i].to_array());
            let t = mesh.uvs.get(i).map(|t| index(&mut vt, &mut vt_ids, t.to_array()).to_string()).unwrap_or_default();
            match mesh.normals.get(i) {
                Some(n) => format!("{p}/{t}/{}", index(&mut vn, &mut vn_ids, n.to_array())),
                None if t.is_empty() => p.to_string(),
                None => format!("{p}/{t}"),
            }
        })
        .collect();
    let mut out = format!("# {}: {} triangles, written by raylab\n", mesh.name, mesh.len());
    for [x, y, z] in v {
        let _ = writeln!(out, "v {x} {y} {z}");
    }
    for [u, w] in vt {
        let _ = writeln!(out, "vt {u} {w}");
    }
    for [x, y, z] in vn {
        let _ = writeln!(out, "vn {x} {y} {z}");
    }
    for t in &mesh.indices {
        let _ = writeln!(out, "f {} {} {}", corners[t[0] as usize], corners[t[1] as usize], corners[t[2] as usize]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_obj_loads_back_identically() {
        let mesh = TriangleMesh {
            name: "two".into(),
            positions: vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 1e-7), Vec3::new(0.1, 0.2, 0.3), Vec3::new(0.0, 1.0, 1e-7), Vec3::new(-1.0, 0.5, 0.25)],
            normals: vec![Vec3::Z, Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::Y],
            uvs: vec![Vec2::new(0.0, 0.0), Vec2::new(1.0 / 3.0, 0.0), Vec2::new(0.0, 0.7), Vec2::new(0.5, 0.5), Vec2::new(0.25, 0.75), Vec2::new(0.9, 0.1)],
            indices: vec![[0, 1, 2], [3, 4, 5]],
            ..Default::default()
        };
        let text = obj_text(&mesh);
        // Shared positions and normals are written once.
        assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), 4);
        assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 3);
        let path = std::env::temp_dir().join(format!("raylab-obj-text-{}.obj", std::process::id()));
        std::fs::write(&path, &text).unwrap();
        let back = load_obj(&Found::Disk(path.clone()), &Transform::IDENTITY).unwrap();
        std::fs::remove_file(&path).unwrap();
        let (m, _) = &back.meshes[0];
        assert_eq!((&m.positions, &m.uvs, &m.indices), (&mesh.positions, &mesh.uvs, &mesh.indices));
        assert_eq!(&m.normals, &mesh.normals);
    }
}
