//! Bicubic Bézier patch files, for `bezier_patch` shapes:
//! - Newell's teapot format (`.txt`): the patch count; per patch a line of 16
//!   comma-separated 1-based indices into the points (4 rows of 4); the point count; per
//!   point a line `x,y,z`.
//! - Eric Haines' SPD format (`.bpt`): the patch count; per patch a line with its degrees
//!   in u and v (only `3 3`, bicubic, is accepted) and 16 lines `x y z`.
//!
//! Errors name the file, the line and the patch or point.

use std::path::Path;

use raylab_core::{Transform, Vec3};
use raylab_render::shape::bezier_patch::tessellate;
use raylab_render::shape::BezierPatch;
use raylab_render::TriangleMesh;

use crate::error::{shorten, text_from_bytes, LoadError};
use crate::files::Found;

/// The patches of `found`, tessellated with `subdivisions` per patch side, in world space.
pub fn load_patch_mesh(found: &Found, subdivisions: u32, to_world: &Transform) -> Result<TriangleMesh, LoadError> {
    let mut mesh = tessellate(&load_patches(found)?, subdivisions);
    for p in &mut mesh.positions {
        *p = to_world.point(*p);
    }
    for n in &mut mesh.normals {
        *n = to_world.normal(*n).try_normalize().unwrap_or(Vec3::Y);
    }
    // A mirroring transform reverses the winding; keep it following the normals.
    if to_world.swaps_handedness() {
        for tri in &mut mesh.indices {
            tri.swap(1, 2);
        }
    }
    Ok(mesh)
}

/// The patches of `found` with their control points in world space (a Bézier patch
/// transforms with its control points), for direct intersection.
pub fn load_patches_world(found: &Found, to_world: &Transform) -> Result<Vec<BezierPatch>, LoadError> {
    let mut patches = load_patches(found)?;
    for patch in &mut patches {
        patch.points = patch.points.map(|p| to_world.point(p));
    }
    Ok(patches)
}

/// The patches of a `.txt` (Newell) or `.bpt` (SPD) file, gzipped or not.
pub fn load_patches(found: &Found) -> Result<Vec<BezierPatch>, LoadError> {
    let path = found.path();
    let name = path.to_string_lossy();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    let parse = if name.ends_with(".bpt") {
        parse_bpt
    } else if name.ends_with(".txt") {
        parse_newell
    } else {
        return Err(LoadError::file(&path, "unknown patch format: expected `.txt` (Newell's indexed patches) or `.bpt` (SPD)"));
    };
    parse(&path, &text_from_bytes(&path, found.read()?)?)
}

/// The non-blank lines of a file with their 1-based numbers.
struct Lines<'a> {
    path: &'a Path,
    lines: Box<dyn Iterator<Item = (usize, &'a str)> + 'a>,
}

impl<'a> Lines<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        Self { path, lines: Box::new(text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).filter(|(_, l)| !l.is_empty())) }
    }

    /// The next line, which `field` must be on.
    fn next(&mut self, field: &str) -> Result<(usize, &'a str), LoadError> {
        self.lines.next().ok_or_else(|| LoadError::new(self.path, None, field, "missing: the file ends early"))
    }

    fn count(&mut self, field: &str) -> Result<usize, LoadError> {
        let (line, text) = self.next(field)?;
        match text.parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(LoadError::new(self.path, Some(line), field, format!("expected a whole number of at least 1, found `{}`", shorten(text)))),
        }
    }

    fn end(&mut self, after: &str) -> Result<(), LoadError> {
        match self.lines.next() {
            Some((line, _)) => Err(LoadError::new(self.path, Some(line), "", format!("unexpected line after the {after}"))),
            None => Ok(()),
        }
    }
}

/// A point from 3 numbers separated by `sep` (`','`, or `' '` for any whitespace).
fn point(path: &Path, (line, text): (usize, &str), sep: char, field: &str) -> Result<Vec3, LoadError> {
    let words: Vec<&str> = if sep == ' ' { text.split_whitespace().collect() } else { text.split(sep).map(str::trim).collect() };
    let err = |msg: String| LoadError::new(path, Some(line), field, msg);
    if words.len() != 3 {
        let form = if sep == ' ' { "`x y z`" } else { "`x,y,z`" };
        return Err(err(format!("expected 3 numbers {form}, found {}", words.len())));
    }
    let mut p = [0.0; 3];
    for (c, w) in p.iter_mut().zip(&words) {
        *c = w.parse::<f32>().ok().filter(|x| x.is_finite()).ok_or_else(|| err(format!("`{}` is not a finite number", shorten(w))))?;
    }
    Ok(Vec3::from_array(p))
}

fn parse_newell(path: &Path, text: &str) -> Result<Vec<BezierPatch>, LoadError> {
    let mut lines = Lines::new(path, text);
    let patch_count = lines.count("patch count")?;
    // No capacity from the header: a corrupt count must end in an error, not an allocation.
    let mut patches = Vec::new();
    for k in 1..=patch_count {
        let field = format!("patch {k}");
        let (line, text) = lines.next(&field)?;
        let words: Vec<&str> = text.split(',').map(str::trim).collect();
        if words.len() != 16 {
            return Err(LoadError::new(path, Some(line), field, format!("expected 16 comma-separated indices, found {}", words.len())));
        }
        let indices = words.iter().map(|w| w.parse::<usize>().map_err(|_| LoadError::new(path, Some(line), &field, format!("`{}` is not an index", shorten(w))))).collect::<Result<Vec<_>, _>>()?;
        patches.push((line, field, indices));
    }
    let point_count = lines.count("point count")?;
    let points = (1..=point_count).map(|k| {
        let field = format!("point {k}");
        point(path, lines.next(&field)?, ',', &field)
    }).collect::<Result<Vec<_>, _>>()?;
    lines.end("last point")?;
    patches.into_iter().map(|(line, field, indices)| {
        let mut patch = BezierPatch { points: [Vec3::ZERO; 16] };
        for (p, &i) in patch.points.iter_mut().zip(&indices) {
            if !(1..=point_count).contains(&i) {
                return Err(LoadError::new(path, Some(line), &field, format!("index {i} is out of range: the file has {point_count} points, numbered from 1")));
            }
            *p = points[i - 1];
        }
        Ok(patch)
    }).collect()
}

fn parse_bpt(path: &Path, text: &str) -> Result<Vec<BezierPatch>, LoadError> {
    let mut lines = Lines::new(path, text);
    let patch_count = lines.count("patch count")?;
    // No capacity from the header: a corrupt count must end in an error, not an allocation.
    let mut patches = Vec::new();
    for k in 1..=patch_count {
        let field = format!("patch {k}");
        let (line, text) = lines.next(&field)?;
        let degrees: Vec<&str> = text.split_whitespace().collect();
        if degrees != ["3", "3"] {
            let msg = match degrees.iter().map(|d| d.parse::<u32>()).collect::<Result<Vec<_>, _>>() {
                Ok(d) if d.len() == 2 => format!("degree {}×{} is not supported: only bicubic patches (`3 3`)", d[0], d[1]),
                _ => format!("expected the degrees in u and v (`3 3`), found `{}`", shorten(text)),
            };
            return Err(LoadError::new(path, Some(line), field, msg));
        }
        let mut patch = BezierPatch { points: [Vec3::ZERO; 16] };
        for (j, p) in patch.points.iter_mut().enumerate() {
            let field = format!("patch {k} point {}", j + 1);
            *p = point(path, lines.next(&field)?, ' ', &field)?;
        }
        patches.push(patch);
    }
    lines.end("last patch")?;
    Ok(patches)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn newell_err(text: &str) -> String {
        parse_newell(Path::new("t.txt"), text).unwrap_err().to_string()
    }

    fn bpt_err(text: &str) -> String {
        parse_bpt(Path::new("t.bpt"), text).unwrap_err().to_string()
    }

    const INDICES: &str = "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16";

    /// One patch over 16 points: point k is (k, 0, 0).
    fn newell(indices: &str) -> String {
        let points: String = (1..=16).map(|k| format!("{k},0,0\n")).collect();
        format!("1\n{indices}\n16\n{points}")
    }

    fn bpt(degrees: &str) -> String {
        let points: String = (1..=16).map(|k| format!("{k} 0 0\n")).collect();
        format!("1\n{degrees}\n{points}\n")
    }

    #[test]
    fn both_formats_read_the_same_patch() {
        let a = parse_newell(Path::new("t.txt"), &newell(INDICES)).unwrap();
        let b = parse_bpt(Path::new("t.bpt"), &bpt("3 3")).unwrap();
        assert_eq!(a, b);
        assert_eq!(a[0].points[15], Vec3::new(16.0, 0.0, 0.0));
        let reversed: Vec<String> = (1..=16).rev().map(|k| k.to_string()).collect();
        let c = parse_newell(Path::new("t.txt"), &newell(&reversed.join(","))).unwrap();
        assert_eq!(c[0].points[0], Vec3::new(16.0, 0.0, 0.0));
    }

    #[test]
    fn newell_errors_name_line_and_field() {
        assert_eq!(newell_err("x\n"), "t.txt:1: patch count: expected a whole number of at least 1, found `x`");
        assert_eq!(newell_err(&newell("1,2,3")), "t.txt:2: patch 1: expected 16 comma-separated indices, found 3");
        assert_eq!(newell_err(&newell(&INDICES.replace("16", "17"))), "t.txt:2: patch 1: index 17 is out of range: the file has 16 points, numbered from 1");
        assert_eq!(newell_err(&newell(&INDICES.replacen("1,", "0,", 1))), "t.txt:2: patch 1: index 0 is out of range: the file has 16 points, numbered from 1");
        assert_eq!(newell_err(&newell(&INDICES.replace("7", "seven"))), "t.txt:2: patch 1: `seven` is not an index");
        assert_eq!(newell_err(&newell(INDICES).replace("5,0,0", "5,zero,0")), "t.txt:8: point 5: `zero` is not a finite number");
        assert_eq!(newell_err(&newell(INDICES).replace("5,0,0", "5,0")), "t.txt:8: point 5: expected 3 numbers `x,y,z`, found 2");
        assert_eq!(newell_err(&newell(INDICES).replace("\n16\n", "\n17\n")), "t.txt: point 17: missing: the file ends early");
        assert_eq!(newell_err(&newell(INDICES).replace("\n16\n", "\n15\n")), "t.txt:19: unexpected line after the last point");
        assert_eq!(newell_err(&newell(INDICES).replacen("1\n", "2\n", 1)), "t.txt:3: patch 2: expected 16 comma-separated indices, found 1");
        // A corrupt count is an error, not an allocation of that many patches.
        assert_eq!(newell_err(&newell(INDICES).replacen("1\n", "99999999999999\n", 1)), "t.txt:3: patch 2: expected 16 comma-separated indices, found 1");
    }

    #[test]
    fn bpt_errors_name_line_and_field() {
        assert_eq!(bpt_err(&bpt("3 2")), "t.bpt:2: patch 1: degree 3×2 is not supported: only bicubic patches (`3 3`)");
        assert_eq!(bpt_err(&bpt("three")), "t.bpt:2: patch 1: expected the degrees in u and v (`3 3`), found `three`");
        assert_eq!(bpt_err(&bpt("3 3").replace("4 0 0", "4 0 nan")), "t.bpt:6: patch 1 point 4: `nan` is not a finite number");
        assert_eq!(bpt_err(&bpt("3 3").replace("4 0 0", "4 0")), "t.bpt:6: patch 1 point 4: expected 3 numbers `x y z`, found 2");
        assert_eq!(bpt_err(&bpt("3 3").replacen("1\n", "2\n", 1)), "t.bpt: patch 2: missing: the file ends early");
        assert_eq!(bpt_err(&format!("{}3 3\n", bpt("3 3"))), "t.bpt:20: unexpected line after the last patch");
    }

    #[test]
    fn unknown_extension_and_missing_file() {
        let found = Found::Disk("patches.obj".into());
        assert_eq!(load_patches(&found).unwrap_err().to_string(), "patches.obj: unknown patch format: expected `.txt` (Newell's indexed patches) or `.bpt` (SPD)");
        let found = Found::Disk("/no/such/teapot.bpt".into());
        let msg = load_patches(&found).unwrap_err().to_string();
        assert!(msg.starts_with("/no/such/teapot.bpt: cannot read: "), "{msg}");
    }
}
