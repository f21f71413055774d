//! Wavefront OBJ meshes and their MTL materials, through `tobj`. Errors name the file and,
//! where `tobj` does not say, the line: on failure we scan the text for the first line
//! that explains it.

use std::io::Cursor;
use std::path::Path;

use raylab_core::{Rgb, Transform, Vec2, Vec3};
use raylab_render::TriangleMesh;

use crate::error::{shorten, text_from_bytes, LoadError};
use crate::files::{not_found_message, Found};

/// An MTL material, kept as read; the scene loader turns it into a raylab material.
pub type MtlMaterial = tobj::Material;

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
    let text = text_from_bytes(&path, found.read()?)?;
    let warnings = short_faces_warning(&path, &text).into_iter().collect();
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
    let siblings = found.sibling_resolver();
    // tobj takes an `Fn` material loader, so what it learns is kept in cells.
    let mtl_found = std::cell::RefCell::new(None);
    let mtl_error = std::cell::RefCell::new(None);
    let (models, materials) = tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &opts, |mtl: &Path| {
        let name = mtl.to_string_lossy();
        match siblings.find(&name) {
            Ok(f) => {
                let bytes = f.read().map_err(|e| {
                    *mtl_error.borrow_mut() = Some(e);
                    tobj::LoadError::OpenFileFailed
                })?;
                if let Err(e) = check_mtl(&f.path(), &bytes) {
                    *mtl_error.borrow_mut() = Some(e);
                    return Err(tobj::LoadError::OpenFileFailed);
                }
                *mtl_found.borrow_mut() = Some(f);
                tobj::load_mtl_buf(&mut Cursor::new(bytes))
            }
            Err(tried) => {
                *mtl_error.borrow_mut() = Some(LoadError::file(&path, format!("mtllib: {}", not_found_message(&name, &tried))));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    })
    .map_err(|e| locate_error(&path, &text, e))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let mtl_found = mtl_found.into_inner();
    let materials = materials.map_err(|e| LoadError::file(&mtl_found.as_ref().map_or(path.clone(), |f| f.path()), format!("cannot parse MTL: {e}")))?;
    // Positions are checked while the text is at hand to name the line; then the text is
    // freed, and each of tobj's meshes as soon as it is converted, so that the peak is not
    // the text, tobj's arrays and ours all at once.
    let mut first_vertex = 0;
    for model in &models {
        if let Some(k) = model.mesh.positions.iter().position(|x| !x.is_finite()) {
            let line = nth_statement_line(&text, "v", first_vertex + k / 3);
            return Err(LoadError::new(&path, line, "", "vertex position is not a finite number"));
        }
        first_vertex += model.mesh.positions.len() / 3;
    }
    drop(text);
    let normal_m = |n: Vec3| to_world.normal(n).try_normalize().unwrap_or(Vec3::Y);
    let mut meshes = Vec::new();
    for model in models {
        let m = model.mesh;
        let positions: Vec<Vec3> = m.positions.chunks_exact(3).map(|p| to_world.point(Vec3::new(p[0], p[1], p[2]))).collect();
        drop(m.positions);
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(LoadError::file(&path, "a vertex position overflows single precision once transformed"));
        }
        let normals: Vec<Vec3> = m.normals.chunks_exact(3).map(|n| normal_m(Vec3::new(n[0], n[1], n[2]))).collect();
        drop(m.normals);
        let uvs: Vec<Vec2> = m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])).collect();
        drop(m.texcoords);
        let normals = if normals.len() == positions.len() && normals.iter().all(|n| n.is_finite()) { normals } else { Vec::new() };
        let uvs = if uvs.len() == positions.len() && uvs.iter().all(|t| t.is_finite()) { uvs } else { Vec::new() };
        let indices = m.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        drop(m.indices);
        let mesh = TriangleMesh { name: model.name, positions, normals, uvs, indices, ..Default::default() };
        if !mesh.is_empty() {
            meshes.push((mesh, m.material_id));
        }
    }
    Ok(ObjData { meshes, materials, mtl_dir: mtl_found, warnings })
}

/// tobj drops faces of fewer than 3 vertices without a word; so does raylab, but it says
/// so, once, with the count, the first line, and whether the file looks truncated.
fn short_faces_warning(path: &Path, text: &str) -> Option<String> {
    let mut count = 0;
    let mut first = 0;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() == Some("f") && words.count() < 3 {
            count += 1;
            if count == 1 {
                first = i + 1;
            }
        }
    }
    if count == 0 {
        return None;
    }
    let truncated = if text.ends_with('\n') { "" } else { "; the last line has no end of line: is the file truncated?" };
    let faces = if count == 1 { "face" } else { "faces" };
    Some(format!("{}: skipped {count} {faces} with fewer than 3 vertices (the first on line {first}){truncated}", path.display()))
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

/// The line of the `k`-th (0-based) statement starting with `keyword`.
fn nth_statement_line(text: &str, keyword: &str, k: usize) -> Option<usize> {
    text.lines().enumerate().filter(|(_, l)| l.split_whitespace().next() == Some(keyword)).nth(k).map(|(i, _)| i + 1)
}

/// Turns a `tobj` error into one with a line number, by finding the first line to blame.
fn locate_error(path: &Path, text: &str, e: tobj::LoadError) -> LoadError {
    use tobj::LoadError as E;
    let keyword = match e {
        E::PositionParseError => "v",
        E::NormalParseError => "vn",
        E::TexcoordParseError => "vt",
        E::FaceParseError | E::InvalidPolygon | E::FaceVertexOutOfBounds | E::FaceTexCoordOutOfBounds | E::FaceNormalOutOfBounds => "f",
        _ => return LoadError::file(path, format!("cannot parse OBJ: {e}")),
    };
    let totals = [("v", count(text, "v")), ("vt", count(text, "vt")), ("vn", count(text, "vn"))];
    let mut so_far = [0usize; 3];
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let Some(kw) = words.next() else { continue };
        if let Some(k) = totals.iter().position(|(t, _)| *t == kw) {
            so_far[k] += 1;
        }
        if kw != keyword {
            continue;
        }
        let rest: Vec<&str> = words.collect();
        let line_no = Some(i + 1);
        if keyword == "f" {
            if rest.len() < 3 {
                return LoadError::new(path, line_no, "", format!("a face needs at least 3 vertices, found {}", rest.len()));
            }
            for corner in &rest {
                for (slot, idx) in corner.split('/').enumerate().take(3) {
                    if idx.is_empty() {
                        continue;
                    }
                    let Ok(v) = idx.parse::<i64>() else {
                        return LoadError::new(path, line_no, "", format!("bad face index `{}`", shorten(corner)));
                    };
                    let (name, total) = totals[slot];
                    let ok = if v > 0 { v as usize <= total } else { v < 0 && (-v) as usize <= so_far[slot] };
                    if !ok {
                        let what = ["vertex", "texture coordinate", "normal"][slot];
                        return LoadError::new(path, line_no, "", format!("face index {v} is out of range: the file has {total} {what} (`{name}`) entries"));
                    }
                }
            }
        } else if rest.iter().take(3).any(|w| w.parse::<f32>().is_err()) || rest.len() < 2 {
            return LoadError::new(path, line_no, "", format!("`{keyword}` expects numbers, found `{}`", shorten(&rest.join(" "))));
        }
    }
    LoadError::file(path, format!("cannot parse OBJ: {e}"))
}

fn count(text: &str, keyword: &str) -> usize {
    text.lines().filter(|l| l.split_whitespace().next() == Some(keyword)).count()
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
