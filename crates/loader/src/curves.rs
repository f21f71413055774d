//! Curve shapes (`type = "curve"`): control points inline or from a file — raylab's text
//! format or Cem Yuksel's binary `.hair` — turned into Bézier segments, then into a
//! tessellated tube or directly intersected curves. Formats in `docs/scene-format.md`.

use raylab_core::{Transform, Vec3, Vec4};
use raylab_render::shape::curve::{tessellate, to_bezier_segments, Basis, Bezier, CurveMode};
use raylab_render::shape::Curve;
use raylab_render::MaterialId;

use crate::description::SceneDescription;

use crate::error::{shorten, text_from_bytes, LoadError};
use crate::files::Found;
use crate::toml_read::{in_range, positive, Table, Val};

/// The keys of a curve shape besides `type`, `material` and `transform`.
pub const KEYS: &[&str] = &["points", "radius", "basis", "degree", "file", "mode", "segments", "sides"];

/// Radius of points a text file gives without one, when the scene gives no `radius`.
const DEFAULT_RADIUS: f32 = 0.01;

/// One strand's control points (`w` the radius) and where an error about it points.
struct Strand {
    points: Vec<Vec4>,
    /// The line of its `strand` keyword in a text file.
    line: Option<usize>,
}

/// Reads the curve shape `t` (its `file`, if any, already found) into `scene`.
pub fn add_curves(scene: &mut SceneDescription, t: &Table, file: Option<(Val, Found)>, material: MaterialId, to_world: &Transform) -> Result<(), LoadError> {
    let basis = t.opt("basis", |v| v.str()?.parse::<Basis>().map_err(|e| v.err(e)))?.unwrap_or(Basis::Bezier);
    let degree = t.opt("degree", |v| in_range(v, v.integer()?, 1, 3))?.unwrap_or(3) as usize;
    let mode = mode(t)?;
    let radius_v = t.get("radius");
    let segments_of = |strand: &[Vec4]| to_bezier_segments(basis, degree, strand);
    let mut strands: Vec<Vec<Bezier>> = Vec::new();
    match (t.get("points"), file) {
        (Some(_), Some((fv, _))) => return Err(fv.err("give either `points` or `file`, not both")),
        (None, None) => return Err(t.doc.err(&t.span, &t.field("points"), "missing (give `points` or `file`)")),
        (Some(pv), None) => {
            let points = pv.points()?;
            let rv = radius_v.ok_or_else(|| t.doc.err(&t.span, &t.field("radius"), "missing (required with `points`)"))?;
            let radii = radii(&rv, points.len())?;
            let cp: Vec<Vec4> = points.iter().zip(radii).map(|(p, r)| p.extend(r)).collect();
            strands.push(segments_of(&cp).map_err(|e| pv.err(e))?);
        }
        (None, Some((fv, found))) => {
            let path = found.path();
            let is_hair = path.to_string_lossy().trim_end_matches(".gz").ends_with(".hair");
            let default_radius = match &radius_v {
                Some(v) if is_hair => return Err(v.err("not used with .hair files, which give every point's thickness")),
                Some(v) => positive(v, v.f32()?)?,
                None => DEFAULT_RADIUS,
            };
            let bytes = found.read()?;
            let read = if is_hair { read_hair(&path, &bytes)? } else { read_text(&path, text_from_bytes(&path, bytes)?, default_radius)? };
            if read.is_empty() {
                return Err(fv.err(format!("{}: no strands", path.display())));
            }
            for (k, s) in read.iter().enumerate() {
                // As a sphere of radius 0: a curve with no thickness anywhere is invisible.
                if s.points.iter().all(|p| p.w == 0.0) {
                    return Err(LoadError::new(&path, s.line, "", format!("strand {k}: every radius is 0: the curve would have no thickness")));
                }
                strands.push(segments_of(&s.points).map_err(|e| LoadError::new(&path, s.line, "", format!("strand {k}: {e}")))?);
            }
        }
    }
    for strand in strands {
        let strand: Vec<Bezier> = strand.iter().map(|b| b.transformed(to_world)).collect();
        match mode {
            CurveMode::Direct => scene.geometry.add_curve(Curve::new(strand, material)),
            CurveMode::Tube { segments, sides } => scene.geometry.add_mesh(tessellate(&strand, segments, sides, material)),
        }
    }
    Ok(())
}

fn mode(t: &Table) -> Result<CurveMode, LoadError> {
    let name = t.opt("mode", |v| v.str().map(str::to_string))?.unwrap_or_else(|| "direct".into());
    match name.as_str() {
        "tube" => {
            let segments = t.opt("segments", |v| in_range(v, v.integer()?, 1, 1024))?.unwrap_or(8) as u32;
            let sides = t.opt("sides", |v| in_range(v, v.integer()?, 3, 256))?.unwrap_or(8) as u32;
            Ok(CurveMode::Tube { segments, sides })
        }
        "direct" => {
            for k in ["segments", "sides"] {
                if let Some(v) = t.get(k) {
                    return Err(v.err("only used with mode = \"tube\""));
                }
            }
            Ok(CurveMode::Direct)
        }
        other => Err(t.get("mode").unwrap().err(format!("unknown mode `{other}` (valid: tube, direct)"))),
    }
}

fn non_negative(v: &Val, r: f32) -> Result<f32, LoadError> {
    if r >= 0.0 { Ok(r) } else { Err(v.err(format!("must not be negative, found {r}"))) }
}

/// `radius`: one positive number for every point, or one per point (0 allowed, at a
/// tapered tip, but not everywhere).
fn radii(v: &Val, n: usize) -> Result<Vec<f32>, LoadError> {
    if let Ok(r) = v.f32() {
        return Ok(vec![positive(v, r)?; n]);
    }
    let a = v.array().map_err(|_| v.err("expected a number or an array of one number per point"))?;
    if a.len() != n {
        return Err(v.err(format!("expected {n} radii (one per point), found {}", a.len())));
    }
    let radii = a.iter().enumerate().map(|(k, e)| {
        let ev = Val { doc: v.doc, field: format!("{}[{k}]", v.field), value: e };
        non_negative(&ev, ev.f32()?)
    }).collect::<Result<Vec<f32>, _>>()?;
    if radii.iter().all(|&r| r == 0.0) {
        return Err(v.err("must not all be 0: the curve would have no thickness"));
    }
    Ok(radii)
}

/// The text format: `strand` starts a strand, then one control point per line,
/// `x y z` or `x y z radius`; `#` starts a comment.
fn read_text(path: &std::path::Path, text: String, default_radius: f32) -> Result<Vec<Strand>, LoadError> {
    let mut strands: Vec<Strand> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if line == "strand" {
            strands.push(Strand { points: Vec::new(), line: Some(line_no) });
            continue;
        }
        let err = |msg: String| LoadError::new(path, Some(line_no), "", msg);
        let numbers: Vec<f32> = line.split_whitespace().map(|w| w.parse::<f32>().ok().filter(|x| x.is_finite())).collect::<Option<_>>().ok_or_else(|| err(format!("expected `strand` or a point `x y z [radius]`, found `{}`", shorten(line))))?;
        let radius = match numbers.len() {
            3 => default_radius,
            4 if numbers[3] >= 0.0 => numbers[3],
            4 => return Err(err(format!("the radius must not be negative, found {}", numbers[3]))),
            n => return Err(err(format!("a point needs 3 coordinates and an optional radius, found {n} numbers"))),
        };
        let strand = strands.last_mut().ok_or_else(|| err("a point before the first `strand` line".into()))?;
        strand.points.push(Vec3::new(numbers[0], numbers[1], numbers[2]).extend(radius));
    }
    Ok(strands)
}

/// Cem Yuksel's `.hair` format (cemyuksel.com/research/hairmodels): a 128-byte header —
/// "HAIR", strand count, point count, array flags, default segment count, thickness,
/// transparency and colour, 88 bytes of text — then the arrays the flags name, in order:
/// segments per strand (u16), points (3 × f32), thickness, transparency (f32), colour
/// (3 × f32), all little-endian. A strand of `s` segments has `s + 1` points; the
/// thickness is a diameter.
fn read_hair(path: &std::path::Path, bytes: &[u8]) -> Result<Vec<Strand>, LoadError> {
    let err = |msg: String| LoadError::file(path, msg);
    if bytes.len() < 128 {
        return Err(err(format!("too short for a .hair header: {} bytes of 128", bytes.len())));
    }
    if &bytes[..4] != b"HAIR" {
        return Err(err("not a .hair file (it does not start with \"HAIR\")".into()));
    }
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
    let (strands, points, flags, default_segments, default_thickness) = (u32_at(4) as usize, u32_at(8) as usize, u32_at(12), u32_at(16) as usize, f32_at(20));
    let (has_segments, has_points, has_thickness, has_transparency, has_color) = (flags & 1 != 0, flags & 2 != 0, flags & 4 != 0, flags & 8 != 0, flags & 16 != 0);
    if !has_points {
        return Err(err("the file has no points array (flag bit 1)".into()));
    }
    // Every strand has a point, and the points are bounded by the file's size below: so is
    // anything sized by the strand count.
    if strands > points {
        return Err(err(format!("the header announces {strands} strands but only {points} points")));
    }
    let size = 128 + [(has_segments, 2 * strands), (has_points, 12 * points), (has_thickness, 4 * points), (has_transparency, 4 * points), (has_color, 12 * points)].iter().filter(|(on, _)| *on).map(|(_, n)| n).sum::<usize>();
    if bytes.len() < size {
        return Err(err(format!("truncated: the header announces {size} bytes, the file has {}", bytes.len())));
    }
    let mut offset = 128;
    let segment_counts: Vec<usize> = if has_segments {
        let counts = (0..strands).map(|k| u16::from_le_bytes([bytes[offset + 2 * k], bytes[offset + 2 * k + 1]]) as usize).collect();
        offset += 2 * strands;
        counts
    } else {
        vec![default_segments; strands]
    };
    let total: usize = segment_counts.iter().map(|s| s + 1).sum();
    if total != points {
        return Err(err(format!("the strands' segment counts make {total} points, the header says {points}")));
    }
    let positions = offset;
    offset += 12 * points;
    let thickness = |i: usize| if has_thickness { f32_at(offset + 4 * i) } else { default_thickness };
    let mut out = Vec::with_capacity(strands);
    let mut i = 0;
    for count in segment_counts {
        let cp = (i..i + count + 1).map(|j| {
            let p = Vec3::new(f32_at(positions + 12 * j), f32_at(positions + 12 * j + 4), f32_at(positions + 12 * j + 8));
            p.extend(0.5 * thickness(j).max(0.0))
        }).collect();
        out.push(Strand { points: cp, line: None });
        i += count + 1;
    }
    if out.iter().flat_map(|s| &s.points).any(|p| !p.is_finite()) {
        return Err(err("a point or thickness is not a finite number".into()));
    }
    Ok(out)
}
