//! The OBJ text to meshes in one pass, a line at a time: the text is never held whole, and
//! each object (`o`, `g` or a change of `usemtl`, as tobj splits them) becomes a
//! [`TriangleMesh`] as soon as it ends. It keeps tobj's meaning (polygons fanned from their
//! first corner, a vertex per distinct `v/vt/vn` within an object in order of first use,
//! relative indices, `v x y z w`), at a fraction of tobj's peak memory: tobj keeps every face
//! as a 104-byte enum and the text besides; here a face is its 12-byte triangle.

use std::collections::HashMap;
use std::path::Path;

use raylab_core::{Transform, Vec2, Vec3};
use raylab_render::TriangleMesh;

use crate::error::{shorten, text_from_bytes, LoadError};
use crate::files::Lines;

/// An MTL material, kept as read; the scene loader turns it into a raylab material.
pub type MtlMaterial = tobj::Material;

/// An index slot of a face corner that is not given (`1//3`).
const MISSING: u32 = u32::MAX;
const SLOTS: [(&str, &str); 3] = [("v", "vertex"), ("vt", "texture coordinate"), ("vn", "normal")];

/// What an OBJ file gave: meshes with their material's index, the materials of its MTL
/// files, and the short faces skipped.
pub struct ObjMeshes {
    pub meshes: Vec<(TriangleMesh, Option<usize>)>,
    pub materials: Vec<MtlMaterial>,
    pub short_faces: Option<String>,
}

/// Reads `lines`; `mtllib` loads an MTL file by the name the OBJ gives.
pub fn read_obj(path: &Path, mut lines: Lines, to_world: &Transform, mut mtllib: impl FnMut(&str) -> Result<Vec<MtlMaterial>, LoadError>) -> Result<ObjMeshes, LoadError> {
    let mut r = Reader { path, to_world, line: 0, pos: Vec::new(), tex: Vec::new(), norm: Vec::new(), object: Object::new("unnamed_object".into(), None), meshes: Vec::new() };
    let mut materials: Vec<MtlMaterial> = Vec::new();
    let mut by_name: HashMap<String, usize> = HashMap::new();
    let (mut short, mut first_short, mut ends_with_newline) = (0usize, 0usize, true);
    let (mut buf, mut corners) = (Vec::new(), Vec::new());
    while lines.next_into(&mut buf)? {
        r.line += 1;
        ends_with_newline = buf.last() == Some(&b'\n');
        while buf.last().is_some_and(|&b| b == b'\n' || b == b'\r') {
            buf.pop();
        }
        let text = text_from_bytes(path, std::mem::take(&mut buf)).map_err(|e| LoadError { line: Some(r.line), ..e })?;
        let mut words = text.split_whitespace();
        match words.next() {
            Some("v") => r.vertex(&text, words)?,
            Some("vt") => r.tex.push(r.floats::<2>("vt", &text, words)?),
            Some("vn") => r.norm.push(r.floats::<3>("vn", &text, words)?),
            Some("f") => {
                corners.clear();
                for w in words {
                    corners.push(r.corner(w)?);
                }
                // tobj drops faces of fewer than 3 vertices without a word: raylab says so, once.
                match corners.len() {
                    0 => return Err(r.err("a face needs at least 3 vertices, found 0")),
                    1 | 2 => {
                        short += 1;
                        if short == 1 {
                            first_short = r.line;
                        }
                    }
                    _ => r.face(&corners),
                }
                r.object.has_faces = true;
            }
            Some("o" | "g") => {
                r.end_object()?;
                // As tobj: the rest of the line after its first character.
                let name = text[text.chars().next().map_or(0, char::len_utf8)..].trim();
                r.object.name = if name.is_empty() { "unnamed_object".into() } else { name.to_string() };
            }
            Some("mtllib") => {
                let name = text.split_once(' ').unwrap_or_default().1.trim();
                let offset = materials.len();
                let loaded = mtllib(name)?;
                by_name.extend(loaded.iter().enumerate().map(|(i, m)| (m.name.clone(), offset + i)));
                materials.extend(loaded);
            }
            Some("usemtl") => {
                let name = text.split_once(' ').unwrap_or_default().1.trim();
                if name.is_empty() {
                    return Err(r.err("`usemtl` needs a material name"));
                }
                let id = by_name.get(name).copied();
                if id != r.object.material {
                    r.end_object()?;
                    r.object.material = id;
                }
            }
            // Comments, lines (`l`), points (`p`), smoothing groups and the rest: nothing to draw.
            _ => {}
        }
        buf = text.into_bytes();
    }
    r.end_object()?;
    let short_faces = (short > 0).then(|| {
        let truncated = if ends_with_newline { "" } else { "; the last line has no end of line: is the file truncated?" };
        let faces = if short == 1 { "face" } else { "faces" };
        format!("{}: skipped {short} {faces} with fewer than 3 vertices (the first on line {first_short}){truncated}", path.display())
    });
    Ok(ObjMeshes { meshes: r.meshes, materials, short_faces })
}

struct Reader<'a> {
    path: &'a Path,
    to_world: &'a Transform,
    line: usize,
    pos: Vec<[f32; 3]>,
    tex: Vec<[f32; 2]>,
    norm: Vec<[f32; 3]>,
    object: Object,
    meshes: Vec<(TriangleMesh, Option<usize>)>,
}

/// The object being read: its distinct corners and its triangles over them.
struct Object {
    name: String,
    material: Option<usize>,
    has_faces: bool,
    corners: Vec<[u32; 3]>,
    ids: HashMap<[u32; 3], u32, ahash::RandomState>,
    triangles: Vec<[u32; 3]>,
    /// Indices past the entries read so far (allowed: the object may define them later),
    /// each larger than the ones before in its slot: (line, slot, index as written, 0-based).
    forward: Vec<(usize, usize, i64, u32)>,
}

impl Object {
    fn new(name: String, material: Option<usize>) -> Self {
        Self { name, material, has_faces: false, corners: Vec::new(), ids: HashMap::default(), triangles: Vec::new(), forward: Vec::new() }
    }
}

impl Reader<'_> {
    fn err(&self, message: impl Into<String>) -> LoadError {
        LoadError::new(self.path, Some(self.line), "", message)
    }

    fn floats<const N: usize>(&self, keyword: &str, text: &str, mut words: std::str::SplitWhitespace) -> Result<[f32; N], LoadError> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = words.next().and_then(|w| w.parse().ok()).ok_or_else(|| self.expects_numbers(keyword, text))?;
        }
        Ok(out)
    }

    fn expects_numbers(&self, keyword: &str, text: &str) -> LoadError {
        let rest = text.trim_start()[keyword.len()..].split_whitespace().collect::<Vec<_>>().join(" ");
        self.err(format!("`{keyword}` expects numbers, found `{}`", shorten(&rest)))
    }

    /// `v x y z`, `v x y z w` (divided by w, as tobj does) or `v x y z r g b` (the colour ignored).
    fn vertex(&mut self, text: &str, mut words: std::str::SplitWhitespace) -> Result<(), LoadError> {
        let mut p = self.floats::<3>("v", text, words.clone())?;
        let extra: Vec<&str> = words.by_ref().skip(3).collect();
        match extra.len() {
            0 | 3 => {}
            1 => {
                let w: f32 = extra[0].parse().map_err(|_| self.expects_numbers("v", text))?;
                if w == 0.0 {
                    return Err(self.err("`v` has a w of 0"));
                }
                p = p.map(|x| x / w);
            }
            n => return Err(self.err(format!("`v` expects 3 numbers, 4 (x y z w) or 6 (x y z r g b), found {}", n + 3))),
        }
        if !p.iter().all(|x| x.is_finite()) {
            return Err(self.err("vertex position is not a finite number"));
        }
        self.pos.push(p);
        Ok(())
    }

    /// A face corner `v`, `v/vt`, `v//vn` or `v/vt/vn` as 0-based indices, relative ones
    /// resolved against the entries read so far.
    fn corner(&mut self, word: &str) -> Result<[u32; 3], LoadError> {
        let bad = |r: &Self| r.err(format!("bad face index `{}`", shorten(word)));
        let mut out = [MISSING; 3];
        for (slot, part) in word.split('/').enumerate() {
            if slot > 2 || (slot == 0 && part.is_empty()) {
                return Err(bad(self));
            }
            if part.is_empty() {
                continue;
            }
            let written: i64 = part.parse().map_err(|_| bad(self))?;
            let so_far = [self.pos.len(), self.tex.len(), self.norm.len()][slot] as i64;
            let index = if written > 0 { written - 1 } else { so_far + written };
            if written == 0 || index < 0 {
                return Err(self.out_of_range(self.line, slot, written, so_far as usize));
            }
            let index = index.min(MISSING as i64 - 1) as u32;
            if index as i64 >= so_far && self.object.forward.iter().rev().find(|f| f.1 == slot).is_none_or(|f| index > f.3) {
                self.object.forward.push((self.line, slot, written, index));
            }
            out[slot] = index;
        }
        Ok(out)
    }

    fn out_of_range(&self, line: usize, slot: usize, written: i64, total: usize) -> LoadError {
        let (name, what) = SLOTS[slot];
        LoadError::new(self.path, Some(line), "", format!("face index {written} is out of range: the file has {total} {what} (`{name}`) entries"))
    }

    /// A polygon, fanned around its first corner.
    fn face(&mut self, corners: &[[u32; 3]]) {
        let o = &mut self.object;
        let mut id = |c: [u32; 3]| {
            *o.ids.entry(c).or_insert_with(|| {
                o.corners.push(c);
                o.corners.len() as u32 - 1
            })
        };
        let (first, mut prev) = (id(corners[0]), id(corners[1]));
        for &c in &corners[2..] {
            let next = id(c);
            o.triangles.push([first, prev, next]);
            prev = next;
        }
    }

    /// Turns the object read so far into a mesh and starts the next with its material.
    fn end_object(&mut self) -> Result<(), LoadError> {
        if !self.object.has_faces {
            return Ok(());
        }
        let next = Object::new(self.object.name.clone(), self.object.material);
        let Object { name, material, corners, ids, triangles, forward, .. } = std::mem::replace(&mut self.object, next);
        drop(ids);
        // As tobj, texture coordinates and normals are looked up only when the file has some.
        let totals = [self.pos.len(), self.tex.len(), self.norm.len()];
        if let Some(&(line, slot, written, _)) = forward.iter().find(|f| (f.1 == 0 || totals[f.1] > 0) && f.3 as usize >= totals[f.1]) {
            return Err(self.out_of_range(line, slot, written, totals[slot]));
        }
        let positions: Vec<Vec3> = corners.iter().map(|c| self.to_world.point(Vec3::from_array(self.pos[c[0] as usize]))).collect();
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(LoadError::file(self.path, "a vertex position overflows single precision once transformed"));
        }
        let normal = |n: [f32; 3]| self.to_world.normal(Vec3::from_array(n)).try_normalize().unwrap_or(Vec3::Y);
        let normals: Vec<Vec3> = if !self.norm.is_empty() && corners.iter().all(|c| c[2] != MISSING) { corners.iter().map(|c| normal(self.norm[c[2] as usize])).collect() } else { Vec::new() };
        let uvs: Vec<Vec2> = if !self.tex.is_empty() && corners.iter().all(|c| c[1] != MISSING) { corners.iter().map(|c| Vec2::from_array(self.tex[c[1] as usize])).collect() } else { Vec::new() };
        drop(corners);
        let normals = if normals.iter().all(|n| n.is_finite()) { normals } else { Vec::new() };
        let uvs = if uvs.iter().all(|t| t.is_finite()) { uvs } else { Vec::new() };
        let mut indices = triangles;
        indices.shrink_to_fit();
        let mesh = TriangleMesh { name, positions, normals, uvs, indices, ..Default::default() };
        if !mesh.is_empty() {
            self.meshes.push((mesh, material));
        }
        Ok(())
    }
}
