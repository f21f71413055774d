//! Which point of which triangle each texel of an atlas bakes, and the gutter fill.

use raylab_core::{Rgb, Vec2};
use raylab_render::TriangleMesh;

use super::COVERAGE_RADIUS;

/// The surface point a texel bakes: triangle `prim` at barycentrics `(b1, b2)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelSample {
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
}

/// How far inside its triangle, in barycentrics, a texel's point is pulled.
const INSET: f32 = 1e-4;

/// For each texel of a `size`² map (top row first), the closest point of the triangle whose
/// UV footprint lies within [`COVERAGE_RADIUS`] texels of the texel's centre, if any.
/// Texel `(x, row)` has its centre at `u = (x + ½) / size`, `v = 1 − (row + ½) / size`,
/// the lookup convention of image textures.
pub fn texel_samples(mesh: &TriangleMesh, size: u32) -> Vec<Option<TexelSample>> {
    let n = size as usize;
    let mut out = vec![None; n * n];
    for (prim, tri) in mesh.indices.iter().enumerate() {
        // Corners in texel units, v up.
        let [a, b, c] = tri.map(|i| mesh.uvs[i as usize] * size as f32);
        let lo = (a.min(b).min(c) - Vec2::splat(COVERAGE_RADIUS)).floor().max(Vec2::ZERO);
        let hi = (a.max(b).max(c) + Vec2::splat(COVERAGE_RADIUS)).ceil().min(Vec2::splat(size as f32 - 1.0));
        for y in lo.y as usize..=hi.y as usize {
            for x in lo.x as usize..=hi.x as usize {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let closest = closest_point(q, a, b, c);
                if closest.distance(q) <= COVERAGE_RADIUS {
                    // A hair inside: a point exactly on a boundary edge (a hole, a mesh border)
                    // can round outside the triangle when a bake ray crosses it.
                    let [_, b1, b2] = barycentrics(closest, a, b, c).map(|l| l.clamp(0.0, 1.0) * (1.0 - 3.0 * INSET) + INSET);
                    out[(n - 1 - y) * n + x] = Some(TexelSample { prim: prim as u32, b1, b2 });
                }
            }
        }
    }
    out
}

/// The point of triangle `abc` closest to `q`.
fn closest_point(q: Vec2, a: Vec2, b: Vec2, c: Vec2) -> Vec2 {
    let [l0, l1, l2] = barycentrics(q, a, b, c);
    if l0 >= 0.0 && l1 >= 0.0 && l2 >= 0.0 {
        return q;
    }
    let on_segment = |p: Vec2, s: Vec2| {
        let t = ((q - p).dot(s - p) / (s - p).length_squared()).clamp(0.0, 1.0);
        p + t * (s - p)
    };
    [on_segment(a, b), on_segment(b, c), on_segment(c, a)].into_iter().min_by(|x, y| x.distance_squared(q).total_cmp(&y.distance_squared(q))).unwrap()
}

fn barycentrics(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> [f32; 3] {
    let (e1, e2, d) = (b - a, c - a, p - a);
    let det = e1.perp_dot(e2);
    let b1 = d.perp_dot(e2) / det;
    let b2 = e1.perp_dot(d) / det;
    [1.0 - b1 - b2, b1, b2]
}

/// Fills uncovered texels from their covered 8-neighbours, `passes` rings outwards, so that
/// bilinear lookups and filtering at a chart's border never blend in the flat background.
pub fn dilate(texels: &mut [Rgb], covered: &[bool], size: u32, passes: usize) {
    let n = size as usize;
    let mut filled = covered.to_vec();
    for _ in 0..passes {
        let mut next = filled.clone();
        for y in 0..n {
            for x in 0..n {
                if filled[y * n + x] {
                    continue;
                }
                let (mut sum, mut count) = (Rgb::ZERO, 0);
                for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)] {
                    let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                    if (0..n as i64).contains(&xx) && (0..n as i64).contains(&yy) && filled[yy as usize * n + xx as usize] {
                        sum += texels[yy as usize * n + xx as usize];
                        count += 1;
                    }
                }
                if count > 0 {
                    texels[y * n + x] = sum / count as f32;
                    next[y * n + x] = true;
                }
            }
        }
        filled = next;
    }
}
