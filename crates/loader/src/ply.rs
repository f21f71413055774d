//! Stanford PLY meshes: ASCII and binary (little and big endian), triangles and polygons
//! (fanned), per-vertex normals (`nx ny nz`) and texture coordinates (`u v`, `s t`,
//! `texture_u texture_v` or `texture_s texture_t`). Elements other than `vertex` and `face`
//! are read past and ignored. A small reader of our own: it names the line (ASCII) or the
//! element and its index (binary) in every error, and refuses counts the file cannot hold.

use std::path::Path;

use raylab_core::{Transform, Vec2, Vec3};
use raylab_render::TriangleMesh;

use crate::error::LoadError;
use crate::files::Found;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
enum PropertyType {
    Scalar(Scalar),
    /// A count of type `.0`, then that many values of type `.1`.
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<(String, PropertyType)>,
}

/// Reads values one after another from the body, in the file's format.
struct Body<'a> {
    path: &'a Path,
    format: Format,
    bytes: &'a [u8],
    pos: usize,
    /// ASCII: the tokens of the current line, and the line number (1-based) in the file.
    tokens: Vec<&'a str>,
    next_token: usize,
    line: usize,
}

impl<'a> Body<'a> {
    fn err(&self, what: &str, msg: impl Into<String>) -> LoadError {
        match self.format {
            Format::Ascii => LoadError::new(self.path, Some(self.line), what, msg),
            _ => LoadError::new(self.path, None, what, format!("{} (at byte {})", msg.into(), self.pos)),
        }
    }

    /// ASCII: moves to the next non-empty line (one line holds one element).
    fn start_record(&mut self, what: &str) -> Result<(), LoadError> {
        if self.format != Format::Ascii {
            return Ok(());
        }
        if self.next_token < self.tokens.len() {
            return Err(self.err(what, format!("{} values left over on the line", self.tokens.len() - self.next_token)));
        }
        loop {
            if self.pos >= self.bytes.len() {
                return Err(self.err(what, "the file ends before this element"));
            }
            let end = self.bytes[self.pos..].iter().position(|&b| b == b'\n').map_or(self.bytes.len(), |k| self.pos + k);
            let text = std::str::from_utf8(&self.bytes[self.pos..end]).map_err(|_| self.err(what, "not ASCII text"))?;
            self.pos = (end + 1).min(self.bytes.len() + 1);
            self.line += 1;
            self.tokens = text.split_whitespace().collect();
            self.next_token = 0;
            if !self.tokens.is_empty() {
                return Ok(());
            }
        }
    }

    fn value(&mut self, t: Scalar, what: &str) -> Result<f64, LoadError> {
        if self.format == Format::Ascii {
            let Some(tok) = self.tokens.get(self.next_token) else {
                return Err(self.err(what, "too few values on the line"));
            };
            self.next_token += 1;
            return tok.parse::<f64>().map_err(|_| self.err(what, format!("`{tok}` is not a number")));
        }
        let n = t.size();
        if self.pos + n > self.bytes.len() {
            return Err(self.err(what, "the file ends early"));
        }
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&self.bytes[self.pos..self.pos + n]);
        if self.format == Format::BinaryBe {
            b[..n].reverse();
        }
        self.pos += n;
        Ok(match t {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }
}

/// The header: format and elements; returns where the body starts.
fn header(path: &Path, bytes: &[u8]) -> Result<(Format, Vec<Element>, usize, usize), LoadError> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(k) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(LoadError::file(path, "PLY header has no `end_header`"));
        };
        let line = std::str::from_utf8(&bytes[pos..pos + k]).map_err(|_| LoadError::new(path, Some(line_no + 1), "", "PLY header is not ASCII"))?.trim_end_matches('\r');
        pos += k + 1;
        line_no += 1;
        let err = |msg: String| LoadError::new(path, Some(line_no), "", msg);
        let words: Vec<&str> = line.split_whitespace().collect();
        if line_no == 1 {
            if line.trim() != "ply" {
                return Err(err("not a PLY file (the first line must be `ply`)".into()));
            }
            continue;
        }
        match words.first().copied() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                format = Some(match (words.get(1).copied(), words.get(2).copied()) {
                    (Some("ascii"), Some("1.0")) => Format::Ascii,
                    (Some("binary_little_endian"), Some("1.0")) => Format::BinaryLe,
                    (Some("binary_big_endian"), Some("1.0")) => Format::BinaryBe,
                    _ => return Err(err(format!("unknown format `{}` (valid: ascii 1.0, binary_little_endian 1.0, binary_big_endian 1.0)", words[1..].join(" ")))),
                });
            }
            Some("element") => {
                let (Some(name), Some(count)) = (words.get(1), words.get(2).and_then(|c| c.parse::<usize>().ok())) else {
                    return Err(err("expected `element NAME COUNT`".into()));
                };
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(err("`property` before any `element`".into()));
                };
                let ty = |name: &str| Scalar::parse(name).ok_or_else(|| err(format!("unknown property type `{name}`")));
                let prop = match words.get(1).copied() {
                    Some("list") if words.len() == 5 => (words[4].to_string(), PropertyType::List(ty(words[2])?, ty(words[3])?)),
                    Some(t) if words.len() == 3 && t != "list" => (words[2].to_string(), PropertyType::Scalar(ty(t)?)),
                    _ => return Err(err("expected `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME`".into())),
                };
                el.properties.push(prop);
            }
            Some("end_header") => break,
            Some(other) => return Err(err(format!("unknown header keyword `{other}`"))),
        }
    }
    let format = format.ok_or_else(|| LoadError::file(path, "PLY header has no `format` line"))?;
    Ok((format, elements, pos, line_no))
}

/// Reads a PLY mesh into world space.
pub fn load_ply(found: &Found, to_world: &Transform) -> Result<TriangleMesh, LoadError> {
    let path = found.path();
    let bytes = found.read()?;
    read_ply(&path, &bytes, to_world)
}

/// Parses PLY bytes; `path` names the file in messages.
pub fn read_ply(path: &Path, bytes: &[u8], to_world: &Transform) -> Result<TriangleMesh, LoadError> {
    let (format, elements, body_start, header_lines) = header(path, bytes)?;
    // A binary file cannot hold more elements than bytes: refuse absurd counts before allocating.
    let body_len = bytes.len() - body_start;
    for e in &elements {
        // ASCII: at least a digit and a separator per property.
        let min_size: usize = if format == Format::Ascii { 2 * e.properties.len().max(1) } else { e.properties.iter().map(|(_, t)| match t { PropertyType::Scalar(s) => s.size(), PropertyType::List(c, _) => c.size() }).sum::<usize>().max(1) };
        if e.count.saturating_mul(min_size) > body_len {
            return Err(LoadError::file(path, format!("element `{}` claims {} entries, more than the file's {body_len} bytes can hold", e.name, e.count)));
        }
    }
    // Counts the file can hold may still need more memory than the machine has: refused
    // before reserving (a vertex keeps at most a position, a normal and a UV: 32 bytes; a
    // face at least one triangle: 12).
    let count = |name: &str| elements.iter().find(|e| e.name == name).map_or(0, |e| e.count);
    let (nv, nf) = (count("vertex"), count("face"));
    let need = (nv as u64).checked_mul(32).and_then(|v| v.checked_add((nf as u64).checked_mul(12)?));
    raylab_render::memory_guard::check(&format!("its {nv} vertices and {nf} faces"), need).map_err(|e| LoadError::file(path, e))?;
    let mut body = Body { path, format, bytes, pos: body_start, tokens: Vec::new(), next_token: 0, line: header_lines };
    let mut positions = Vec::with_capacity(nv);
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::with_capacity(nf);
    let mut has_faces = false;
    for e in &elements {
        let find = |names: &[&str]| names.iter().find_map(|n| e.properties.iter().position(|(p, t)| p == n && matches!(t, PropertyType::Scalar(_))));
        let (xyz, nxyz, uv) = if e.name == "vertex" {
            let xyz = [find(&["x"]), find(&["y"]), find(&["z"])];
            if xyz.iter().any(Option::is_none) {
                return Err(LoadError::file(path, "element `vertex` needs properties x, y and z"));
            }
            let n = [find(&["nx"]), find(&["ny"]), find(&["nz"])];
            let uv = [find(&["u", "s", "texture_u", "texture_s"]), find(&["v", "t", "texture_v", "texture_t"])];
            (xyz.map(Option::unwrap), n.iter().all(Option::is_some).then(|| n.map(Option::unwrap)), uv.iter().all(Option::is_some).then(|| uv.map(Option::unwrap)))
        } else {
            ([0; 3], None, None)
        };
        let face_list = if e.name == "face" {
            has_faces = true;
            let k = e.properties.iter().position(|(p, t)| (p == "vertex_indices" || p == "vertex_index") && matches!(t, PropertyType::List(..)));
            Some(k.ok_or_else(|| LoadError::file(path, "element `face` needs a list property `vertex_indices`"))?)
        } else {
            None
        };
        let mut values = vec![0.0f64; e.properties.len()];
        let mut list: Vec<f64> = Vec::new();
        for i in 0..e.count {
            let what = format!("{}[{i}]", e.name);
            body.start_record(&what)?;
            for (k, (pname, ty)) in e.properties.iter().enumerate() {
                match ty {
                    PropertyType::Scalar(s) => values[k] = body.value(*s, &what)?,
                    PropertyType::List(ct, vt) => {
                        let n = body.value(*ct, &what)?;
                        if !(0.0..=1e6).contains(&n) || n.fract() != 0.0 {
                            return Err(body.err(&what, format!("bad list length {n} of `{pname}`")));
                        }
                        let is_face = face_list == Some(k);
                        if is_face {
                            list.clear();
                        }
                        for _ in 0..n as usize {
                            let v = body.value(*vt, &what)?;
                            if is_face {
                                list.push(v);
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                let p = Vec3::new(values[xyz[0]] as f32, values[xyz[1]] as f32, values[xyz[2]] as f32);
                if !p.is_finite() {
                    return Err(body.err(&what, "vertex position is not a finite number"));
                }
                positions.push(to_world.point(p));
                if let Some(n) = nxyz {
                    normals.push(Vec3::new(values[n[0]] as f32, values[n[1]] as f32, values[n[2]] as f32));
                }
                if let Some(t) = uv {
                    uvs.push(Vec2::new(values[t[0]] as f32, values[t[1]] as f32));
                }
            } else if face_list.is_some() {
                if list.len() < 3 {
                    return Err(body.err(&what, format!("a face needs at least 3 vertices, found {}", list.len())));
                }
                let nv = positions.len();
                let mut idx = Vec::with_capacity(list.len());
                for &v in &list {
                    if v < 0.0 || v.fract() != 0.0 || v as usize >= nv {
                        return Err(body.err(&what, format!("vertex index {v} out of range (the file has {nv} vertices)")));
                    }
                    idx.push(v as u32);
                }
                // Polygons are fanned around their first vertex, as pbrt and Blender do for convex ones.
                for k in 1..idx.len() - 1 {
                    indices.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
        }
    }
    if !has_faces {
        return Err(LoadError::file(path, "PLY file has no `face` element (point clouds are not meshes)"));
    }
    let normals = normals.iter().map(|&n| to_world.normal(n).try_normalize()).collect::<Option<Vec<Vec3>>>().unwrap_or_default();
    let name = path.file_stem().map_or("ply".into(), |s| s.to_string_lossy().into_owned());
    Ok(TriangleMesh { name, positions, normals, uvs, indices, ..Default::default() })
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD_ASCII: &str = "ply\nformat ascii 1.0\ncomment a unit square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";

    fn binary(big: bool) -> Vec<u8> {
        let mut b = format!("ply\nformat binary_{}_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n", if big { "big" } else { "little" }).into_bytes();
        for p in [[0.0f64, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]] {
            for c in p {
                b.extend(if big { c.to_be_bytes() } else { c.to_le_bytes() });
            }
            for c in [0.0f32, 0.0, 1.0] {
                b.extend(if big { c.to_be_bytes() } else { c.to_le_bytes() });
            }
        }
        b.push(3);
        for i in [0u32, 1, 2] {
            b.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
        }
        b
    }

    #[test]
    fn ascii_quad_is_fanned_into_two_triangles_with_uvs() {
        let m = read_ply(Path::new("q.ply"), QUAD_ASCII.as_bytes(), &Transform::IDENTITY).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(m.uvs[3], Vec2::new(0.0, 1.0));
        assert!(m.normals.is_empty());
    }

    #[test]
    fn binary_little_and_big_endian_read_the_same_triangle() {
        for big in [false, true] {
            let m = read_ply(Path::new("t.ply"), &binary(big), &Transform::IDENTITY).unwrap();
            assert_eq!(m.positions, vec![Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0)]);
            assert_eq!(m.normals, vec![Vec3::Z; 3]);
            assert_eq!(m.indices, vec![[0, 1, 2]]);
        }
    }

    #[test]
    fn errors_name_the_line_or_element() {
        let bad_index = QUAD_ASCII.replace("4 0 1 2 3", "3 0 1 7");
        assert_eq!(read_ply(Path::new("q.ply"), bad_index.as_bytes(), &Transform::IDENTITY).unwrap_err().to_string(), "q.ply:17: face[0]: vertex index 7 out of range (the file has 4 vertices)");
        let bad_number = QUAD_ASCII.replace("1 0 0 1 0", "1 x 0 1 0");
        assert_eq!(read_ply(Path::new("q.ply"), bad_number.as_bytes(), &Transform::IDENTITY).unwrap_err().to_string(), "q.ply:14: vertex[1]: `x` is not a number");
        let mut short = binary(false);
        short.truncate(short.len() - 2);
        assert_eq!(read_ply(Path::new("t.ply"), &short, &Transform::IDENTITY).unwrap_err().to_string(), format!("t.ply: face[0]: the file ends early (at byte {})", short.len() - 2));
        let huge = QUAD_ASCII.replace("element face 1", "element face 99999999999");
        assert_eq!(read_ply(Path::new("q.ply"), huge.as_bytes(), &Transform::IDENTITY).unwrap_err().to_string(), "q.ply: element `face` claims 99999999999 entries, more than the file's 50 bytes can hold");
        assert_eq!(read_ply(Path::new("x.ply"), b"PLY\n", &Transform::IDENTITY).unwrap_err().to_string(), "x.ply:1: not a PLY file (the first line must be `ply`)");
    }
}
