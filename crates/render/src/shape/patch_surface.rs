//! Direct ray–patch intersection, the alternative to tracing a fine tessellation: Newton's
//! method on `P(u, v) − (o + t·d) = 0`, seeded where the ray meets a coarse tessellation
//! of the patch. Each patch is one primitive, bounded by its control points (a Bézier
//! patch lies in their convex hull), so every acceleration structure can index them.

use glam::DVec3;
use raylab_accel::{PrimHit, Primitives};
use raylab_core::{gamma, Aabb, Ray, Vec2, Vec3};

use super::{BezierPatch, SurfaceGeometry};
use crate::material::MaterialId;

/// Seed-grid triangles the ray misses by up to this much (in barycentrics) still seed a
/// solve: the coarse grid's chords cut inside convex parts of the surface, so rays near a
/// silhouette can hit the surface and miss the chords.
const SEED_SLACK: f64 = 0.5;
const NEWTON_STEPS: usize = 10;

/// Seed-grid quads per patch side used by scenes: with 4×4 a few grazing rays converge to
/// the farther of two roots; 8×8 found every root of the tessellation test.
pub const DEFAULT_SEED_GRID: u32 = 8;

/// Bicubic patches as primitives, intersected exactly (to `f64` Newton tolerance).
#[derive(Clone, Debug)]
pub struct PatchSurfaces {
    pub material: MaterialId,
    patches: Vec<BezierPatch>,
    seed_grid: usize,
    /// `(seed_grid + 1)²` points per patch, row by row in `v`.
    seeds: Vec<DVec3>,
    /// Per patch, per seed quad (row by row): the box any point a seed triangle of the quad
    /// can report lies in (its triangles grown by [`SEED_SLACK`]). A line missing it
    /// cannot seed a solve there, so most quads are skipped with one slab test.
    quad_reach: Vec<(DVec3, DVec3)>,
    /// The union of the reach boxes of each block of `BLOCK × BLOCK` quads.
    block_reach: Vec<(DVec3, DVec3)>,
}

/// Seed quads per side of a culling block.
const BLOCK: usize = 4;

impl PatchSurfaces {
    /// `seed_grid` quads per patch side seed the solves.
    pub fn new(patches: Vec<BezierPatch>, seed_grid: u32, material: MaterialId) -> Self {
        assert!(seed_grid > 0, "the seed grid needs at least one quad");
        let n = seed_grid as usize;
        let param = |k: usize| k as f64 / n as f64;
        let seeds: Vec<DVec3> = patches.iter().flat_map(|p| (0..=n).flat_map(move |i| (0..=n).map(move |j| p.point_f64(param(j), param(i))))).collect();
        let side = n + 1;
        let blocks = n.div_ceil(BLOCK);
        let (mut quad_reach, mut block_reach) = (Vec::new(), Vec::new());
        for grid in seeds.chunks(side * side) {
            let quads: Vec<(DVec3, DVec3)> = (0..n * n).map(|q| {
                let (row, col) = (q / n, q % n);
                let c = |di: usize, dj: usize| grid[(row + di) * side + col + dj];
                let mut reach = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for tri in [[c(0, 0), c(0, 1), c(1, 1)], [c(0, 0), c(1, 1), c(1, 0)]] {
                    // Barycentrics ≥ −s span the triangle scaled by 1 + 3s about its centroid.
                    let centroid = (tri[0] + tri[1] + tri[2]) / 3.0;
                    for v in tri {
                        let p = centroid + (1.0 + 3.0 * SEED_SLACK) * (v - centroid);
                        reach = (reach.0.min(p), reach.1.max(p));
                    }
                }
                reach
            }).collect();
            for b in 0..blocks * blocks {
                let (r0, c0) = ((b / blocks) * BLOCK, (b % blocks) * BLOCK);
                let union = (r0..(r0 + BLOCK).min(n)).flat_map(|r| (c0..(c0 + BLOCK).min(n)).map(move |c| r * n + c)).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |u, q| (u.0.min(quads[q].0), u.1.max(quads[q].1)));
                block_reach.push(union);
            }
            quad_reach.extend(quads);
        }
        Self { material, patches, seed_grid: n, seeds, quad_reach, block_reach }
    }

    pub fn len(&self) -> usize {
        self.patches.len()
    }

    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// Bytes held: control points and seed grids.
    pub fn memory_bytes(&self) -> usize {
        self.patches.len() * std::mem::size_of::<BezierPatch>()
            + self.seeds.len() * std::mem::size_of::<DVec3>()
            + (self.quad_reach.len() + self.block_reach.len()) * std::mem::size_of::<(DVec3, DVec3)>()
    }

    /// Surface data at `(u, v)` of patch `i`: the point and normal of the bicubic itself
    /// (exact normals, including at the poles; `ns = ng`).
    pub fn surface(&self, i: u32, u: f32, v: f32) -> SurfaceGeometry {
        let patch = &self.patches[i as usize];
        let p = patch.point(u, v);
        let (dpdu, dpdv) = patch.derivatives(u, v);
        let n = patch.normal(u, v);
        // Newton stops within 1e-9 of the patch size in f64; rounding (u, v) and the
        // evaluation to f32 adds a few ulps of the coordinates.
        let p_error = gamma(8) * p.abs() + Vec3::splat(1e-6 * patch.size() as f32);
        SurfaceGeometry { p, p_error, ng: n, ns: n, uv: Vec2::new(u, v), dpdu, dpdv }
    }

    pub fn patch(&self, i: u32) -> &BezierPatch {
        &self.patches[i as usize]
    }

    /// The closest hit `(t, u, v)` of the ray with patch `i`, `t` in `(t_min, t_max]`.
    pub fn intersect_patch(&self, i: u32, ray: &Ray) -> Option<(f32, f32, f32)> {
        let patch = &self.patches[i as usize];
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let n = self.seed_grid;
        let side = n + 1;
        let grid = &self.seeds[i as usize * side * side..][..side * side];
        let tolerance = 1e-9 * patch.size();
        let quad_reach = &self.quad_reach[i as usize * n * n..][..n * n];
        let blocks = n.div_ceil(BLOCK);
        let block_reach = &self.block_reach[i as usize * blocks * blocks..][..blocks * blocks];
        let inv_d = d.recip();
        let mut best: Option<(f32, f32, f32)> = None;
        for (b, reach) in block_reach.iter().enumerate() {
            if !line_meets_box(o, inv_d, reach) {
                continue;
            }
            let (r0, c0) = ((b / blocks) * BLOCK, (b % blocks) * BLOCK);
            for (row, col) in (r0..(r0 + BLOCK).min(n)).flat_map(|r| (c0..(c0 + BLOCK).min(n)).map(move |c| (r, c))) {
                if !line_meets_box(o, inv_d, &quad_reach[row * n + col]) {
                    continue;
                }
                let corner = |di: usize, dj: usize| (grid[(row + di) * side + col + dj], DVec3::new((col + dj) as f64, (row + di) as f64, 0.0) / n as f64);
                for [a, b, c] in [[corner(0, 0), corner(0, 1), corner(1, 1)], [corner(0, 0), corner(1, 1), corner(1, 0)]] {
                    let Some((t, b1, b2)) = plane_hit(o, d, [a.0, b.0, c.0]) else { continue };
                    let uv = (1.0 - b1 - b2) * a.1 + b1 * b.1 + b2 * c.1;
                    let Some((u, v, t)) = newton(patch, o, d, (uv.x.clamp(0.0, 1.0), uv.y.clamp(0.0, 1.0), t), tolerance) else { continue };
                    let t = t as f32;
                    if t > ray.t_min && t <= ray.t_max && best.is_none_or(|h| t < h.0) {
                        best = Some((t, u as f32, v as f32));
                    }
                }
            }
        }
        best
    }
}

/// Whether the whole line `o + t·d` (any `t`: a seed behind the origin may still converge
/// to a root in front) meets the box; `inv_d = 1/d` per component (±∞ for zero).
fn line_meets_box(o: DVec3, inv_d: DVec3, (lo, hi): &(DVec3, DVec3)) -> bool {
    let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..3 {
        if inv_d[k].is_infinite() {
            // Parallel to this slab: inside it or never.
            if o[k] < lo[k] || o[k] > hi[k] {
                return false;
            }
            continue;
        }
        let (t0, t1) = ((lo[k] - o[k]) * inv_d[k], (hi[k] - o[k]) * inv_d[k]);
        near = near.max(t0.min(t1));
        far = far.min(t0.max(t1));
    }
    near <= far
}

/// Where the ray meets the plane of `[a, b, c]`: `(t, b1, b2)`, if the barycentrics are
/// all at least `-SEED_SLACK`.
fn plane_hit(o: DVec3, d: DVec3, [a, b, c]: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let s = o - a;
    let q = s.cross(e1);
    let (b1, b2) = (s.dot(p) / det, d.dot(q) / det);
    (b1 >= -SEED_SLACK && b2 >= -SEED_SLACK && 1.0 - b1 - b2 >= -SEED_SLACK).then(|| (e2.dot(q) / det, b1, b2))
}

/// Solves `P(u, v) = o + t·d` from `start`; the root if it converges inside the patch.
fn newton(patch: &BezierPatch, o: DVec3, d: DVec3, start: (f64, f64, f64), tolerance: f64) -> Option<(f64, f64, f64)> {
    let (mut u, mut v, mut t) = start;
    for _ in 0..NEWTON_STEPS {
        let (p, pu, pv) = patch.point_and_derivatives_f64(u, v);
        let f = p - (o + t * d);
        if f.length() < tolerance {
            let inside = |x: f64| (-1e-9..=1.0 + 1e-9).contains(&x);
            return (inside(u) && inside(v)).then(|| (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0), t));
        }
        // The Jacobian's columns are ∂P/∂u, ∂P/∂v and −d; Cramer's rule for the step.
        let det = pu.dot(pv.cross(-d));
        if det.abs() <= 1e-12 * pu.length() * pv.length() * d.length() {
            return None;
        }
        u -= f.dot(pv.cross(-d)) / det;
        v -= pu.dot(f.cross(-d)) / det;
        t -= pu.dot(pv.cross(f)) / det;
        // Far outside the patch the bicubic's other roots lie; stop wandering there.
        if !(-1.0..=2.0).contains(&u) || !(-1.0..=2.0).contains(&v) {
            return None;
        }
    }
    None
}

impl Primitives for PatchSurfaces {
    fn len(&self) -> usize {
        self.patches.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(self.patches[i as usize].points)
    }

    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        self.intersect_patch(i, ray).map(|(t, u, v)| PrimHit { t, u, v })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Vec3;

    /// z = (B1 + B2)(u) (B1 + B2)(v) over (2u, 3v): a dome with z(0.5, 0.5) = 0.5625.
    fn dome() -> BezierPatch {
        let mut points = [Vec3::ZERO; 16];
        for row in 0..4 {
            for col in 0..4 {
                let inner = (1..3).contains(&row) && (1..3).contains(&col);
                points[4 * row + col] = Vec3::new(2.0 * col as f32 / 3.0, row as f32, if inner { 1.0 } else { 0.0 });
            }
        }
        BezierPatch { points }
    }

    #[test]
    fn ray_down_onto_the_dome_hits_its_height() {
        let s = PatchSurfaces::new(vec![dome()], 2, MaterialId::default());
        let (t, u, v) = s.intersect_patch(0, &Ray::new(Vec3::new(1.0, 1.5, 5.0), -Vec3::Z)).unwrap();
        assert!((t - (5.0 - 0.5625)).abs() < 1e-6 && (u - 0.5).abs() < 1e-6 && (v - 0.5).abs() < 1e-6, "{t} {u} {v}");
        // At (u, v) = (0.25, 0.5): z = (36/64)(0.75).
        let (t, u, _) = s.intersect_patch(0, &Ray::new(Vec3::new(0.5, 1.5, 5.0), -Vec3::Z)).unwrap();
        assert!((t - (5.0 - 0.421875)).abs() < 1e-6 && (u - 0.25).abs() < 1e-6, "{t} {u}");
    }

    #[test]
    fn closest_of_two_hits_and_the_ray_interval() {
        let s = PatchSurfaces::new(vec![dome()], 2, MaterialId::default());
        // Sideways through the dome at x = 1, z = 0.3: in at one flank, out at the other.
        let ray = Ray::new(Vec3::new(1.0, -1.0, 0.3), Vec3::Y);
        let (t_in, _, v_in) = s.intersect_patch(0, &ray).unwrap();
        let p = dome().point(0.5, v_in);
        assert!((p - ray.at(t_in)).length() < 1e-5 && v_in < 0.5, "{t_in} {v_in}");
        let (t_out, _, v_out) = s.intersect_patch(0, &Ray { t_min: t_in + 0.1, ..ray }).unwrap();
        assert!(t_out > t_in + 0.1 && v_out > 0.5, "{t_out} {v_out}");
        assert!(s.intersect_patch(0, &Ray { t_max: t_in * 0.9, ..ray }).is_none());
        // The same line the other way, from y = 4: the dome is symmetric about y = 1.5 (v = ½), so
        // the nearer hit is the mirror of the one above, t_in away again, and found after the
        // farther one in the seed grid's row order.
        let back = Ray::new(Vec3::new(1.0, 4.0, 0.3), -Vec3::Y);
        let (t_back, _, v_back) = s.intersect_patch(0, &back).unwrap();
        assert!((t_back - t_in).abs() < 1e-5 && (v_back - (1.0 - v_in)).abs() < 1e-5, "{t_back} {v_back} vs {t_in} {v_in}");
        // Beside the patch, and above it.
        assert!(s.intersect_patch(0, &Ray::new(Vec3::new(2.5, 1.5, 5.0), -Vec3::Z)).is_none());
        assert!(s.intersect_patch(0, &Ray::new(Vec3::new(-1.0, 1.5, 0.6), Vec3::X)).is_none());
    }

    /// The plane z = `z` as a patch with exact control points (col, row, z): P(u, v) = (3u, 3v, z),
    /// cubic Bernstein weights reproducing linear functions.
    fn square(z: f32) -> BezierPatch {
        BezierPatch { points: std::array::from_fn(|k| Vec3::new((k % 4) as f32, (k / 4) as f32, z)) }
    }

    fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
        (a - b).abs().max_element() < eps
    }

    #[test]
    fn counts_memory_bounds_and_surface_by_hand() {
        let mut moved = dome();
        for q in &mut moved.points {
            q.x += 5.0;
        }
        let s = PatchSurfaces::new(vec![dome(), moved], 2, MaterialId(4));
        assert_eq!((s.len(), Primitives::len(&s), s.is_empty(), s.material), (2, 2, false, MaterialId(4)));
        assert!(PatchSurfaces::new(Vec::new(), 2, MaterialId(0)).is_empty());
        assert_eq!(s.patch(1), &moved);
        // Per patch: 16 points of 12 bytes, (2 + 1)² seeds of 24, 4 quad and 1 block boxes of 48.
        assert_eq!(s.memory_bytes(), 2 * (16 * 12 + 9 * 24 + 5 * 48));
        // 5 quads a side make 2 × 2 blocks of up to 4 × 4: 36 seeds, 25 + 4 boxes.
        assert_eq!(PatchSurfaces::new(vec![dome()], 5, MaterialId(0)).memory_bytes(), 16 * 12 + 36 * 24 + 29 * 48);
        let b = s.bounds(1);
        assert_eq!((b.min, b.max), (Vec3::new(5.0, 0.0, 0.0), Vec3::new(7.0, 3.0, 1.0)));
        // At (0.25, 0.5) of the moved dome: p = (5.5, 1.5, (36/64)(0.75)), ∂p/∂u = (2, 0, (24/16)(0.75)),
        // ∂p/∂v = (0, 3, (36/64)(B1′ + B2′)(½) = 0); n ∝ (2, 0, 1.125) × (0, 3, 0) = (−3.375, 0, 6).
        // The error: γ₈|p| + 10⁻⁶ × the control net's size 3, γ₈ = 8(ε/2)/(1 − 8(ε/2)).
        let g = s.surface(1, 0.25, 0.5);
        let n = Vec3::new(-3.375, 0.0, 6.0).normalize();
        assert!(close(g.p, Vec3::new(5.5, 1.5, 0.421875), 1e-6) && close(g.dpdu, Vec3::new(2.0, 0.0, 1.125), 1e-6) && close(g.dpdv, Vec3::new(0.0, 3.0, 0.0), 1e-6), "{g:?}");
        assert!(close(g.ng, n, 1e-6) && close(g.ns, n, 1e-6) && g.uv == Vec2::new(0.25, 0.5), "{g:?}");
        let gamma8 = 8.0 * f64::from(f32::EPSILON) / 2.0 / (1.0 - 8.0 * f64::from(f32::EPSILON) / 2.0);
        let want = [5.5, 1.5, 0.421875].map(|c: f64| (gamma8 * c + 3e-6) as f32);
        assert!(close(g.p_error, Vec3::from(want), 1e-9), "{} vs {want:?}", g.p_error);
        // The trait's hit is intersect_patch's.
        let ray = Ray::new(Vec3::new(5.5, 1.5, 5.0), -Vec3::Z);
        let (t, u, v) = s.intersect_patch(1, &ray).unwrap();
        assert_eq!(Primitives::intersect(&s, 1, &ray), Some(PrimHit { t, u, v }));
        assert!((t - (5.0 - 0.421875)).abs() < 1e-6 && (u - 0.25).abs() < 1e-6 && (v - 0.5).abs() < 1e-6);
        assert!(Primitives::intersect(&s, 0, &ray).is_none());
    }

    #[test]
    fn hits_all_over_a_plane_patch_by_hand() {
        // P(u, v) = (3u, 3v, z): a ray from o along d meets it at t = (z − o.z)/d.z, u = x/3, v = y/3.
        // Seed grids of 1, 5 and 8 quads (culling blocks of 4 × 4: one, 2 × 2 with partial ones, 2 × 2),
        // three patches so that patch 2's seeds and boxes are found at their offsets, rays straight down
        // and slanted, to every cell of a 12 × 12 grid of points and to the corners.
        for grid in [1, 5, 8] {
            let s = PatchSurfaces::new(vec![square(0.0), square(-1.0), square(2.0)], grid, MaterialId(0));
            for (i, z) in [(0, 0.0f32), (1, -1.0), (2, 2.0)] {
                for k in 0..=12 {
                    for l in 0..=12 {
                        let (x, y) = (0.25 * k as f32, 0.25 * l as f32);
                        for d in [Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.5, -0.25, -2.0)] {
                            let o = Vec3::new(x, y, z) - 2.0 * d;
                            let hit = s.intersect_patch(i, &Ray::new(o, d));
                            let Some((t, u, v)) = hit else { panic!("grid {grid} patch {i} ({x}, {y}) along {d}: missed") };
                            assert!((t - 2.0).abs() < 1e-5 && (u - x / 3.0).abs() < 1e-5 && (v - y / 3.0).abs() < 1e-5, "grid {grid} patch {i} ({x}, {y}): {t} {u} {v}");
                        }
                    }
                }
                // Beside it, just off each edge, and pointing away from it.
                for (x, y) in [(-0.1, 1.5), (3.1, 1.5), (1.5, -0.1), (1.5, 3.1)] {
                    assert!(s.intersect_patch(i, &Ray::new(Vec3::new(x, y, z + 1.0), -Vec3::Z)).is_none(), "grid {grid} ({x}, {y})");
                }
                assert!(s.intersect_patch(i, &Ray::new(Vec3::new(1.5, 1.5, z + 1.0), Vec3::Z)).is_none());
            }
        }
    }

    #[test]
    fn newton_stops_relative_to_the_patch_size() {
        // square(0) scaled by 10⁵: P(u, v) = (3u, 3v, 0)·10⁵. Newton stops within 10⁻⁹ × the size
        // 3·10⁵ = 3·10⁻⁴; a fixed or inverse tolerance (10⁻⁹/size = 3·10⁻¹⁵) would sit below the f64
        // rounding of coordinates near 10⁵ (about 10⁻¹¹) and never be met.
        let mut big = square(0.0);
        for q in &mut big.points {
            *q *= 1e5;
        }
        let s = PatchSurfaces::new(vec![big], 2, MaterialId(0));
        let (t, u, v) = s.intersect_patch(0, &Ray::new(Vec3::new(1e5, 2e5, 4e5), -Vec3::Z)).expect("a hit");
        assert!((t - 4e5).abs() < 0.1 && (u - 1.0 / 3.0).abs() < 1e-6 && (v - 2.0 / 3.0).abs() < 1e-6, "{t} {u} {v}");
    }

    #[test]
    fn the_ray_interval_is_open_below_and_closed_above() {
        // Down onto z = 0 from z = 4: t = 4 exactly.
        let s = PatchSurfaces::new(vec![square(0.0)], 2, MaterialId(0));
        let ray = |t_min, t_max| Ray::segment(Vec3::new(1.0, 2.0, 4.0), -Vec3::Z, t_min, t_max);
        assert_eq!(s.intersect_patch(0, &ray(0.0, 4.0)), Some((4.0, 1.0 / 3.0, 2.0 / 3.0)));
        assert_eq!(s.intersect_patch(0, &ray(3.0, f32::INFINITY)).map(|h| h.0), Some(4.0));
        assert!(s.intersect_patch(0, &ray(4.0, 10.0)).is_none() && s.intersect_patch(0, &ray(0.0, 3.99)).is_none());
        // Two sheets, z = 0 and z = 2, each hit through its own seeds, from above and from below.
        let s = PatchSurfaces::new(vec![square(0.0), square(2.0)], 2, MaterialId(0));
        for (o, d, want) in [(4.0, -1.0, [4.0, 2.0]), (-1.0, 1.0, [1.0, 3.0])] {
            for i in 0..2 {
                let t = s.intersect_patch(i, &Ray::new(Vec3::new(1.5, 1.5, o), Vec3::new(0.0, 0.0, d))).unwrap().0;
                assert_eq!(t, want[i as usize]);
            }
        }
    }

    #[test]
    fn line_meets_box_by_hand() {
        // The box [0, 1] × [0, 2] × [0, 3]; a line o + t·d for any t.
        let b = (DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let meets = |o: [f64; 3], d: [f64; 3]| line_meets_box(DVec3::from(o), DVec3::from(d).recip(), &b);
        // Along x through the inside, and the same line from beyond the box, pointing away.
        assert!(meets([-1.0, 1.0, 1.0], [1.0, 0.0, 0.0]) && meets([2.0, 1.0, 1.0], [1.0, 0.0, 0.0]));
        // Parallel to x: inside the y and z slabs (on their faces too), or outside one.
        assert!(meets([-1.0, 0.0, 3.0], [1.0, 0.0, 0.0]) && meets([-1.0, 2.0, 0.0], [1.0, 0.0, 0.0]));
        assert!(!meets([-1.0, -0.1, 1.0], [1.0, 0.0, 0.0]) && !meets([-1.0, 2.1, 1.0], [1.0, 0.0, 0.0]) && !meets([-1.0, 1.0, 3.1], [1.0, 0.0, 0.0]));
        // Slanted in x and y at z = 1: from (0, 3) along (1, −1) the x slab is t ∈ [0, 1] and the
        // y slab t ∈ [1, 3]: they touch at t = 1, the corner (1, 2). From (0, 3.5): t ∈ [0, 1] and
        // [1.5, 3.5], apart. From (−1, −1) along (1, 1): [1, 2] and [1, 3], overlapping.
        assert!(meets([0.0, 3.0, 1.0], [1.0, -1.0, 0.0]) && !meets([0.0, 3.5, 1.0], [1.0, -1.0, 0.0]) && meets([-1.0, -1.0, 1.0], [1.0, 1.0, 0.0]));
        // Along (2, −1, 4) from (−2, 3, −4): x slab t ∈ [1, 1.5], y slab [1, 3], z slab [1, 1.75].
        assert!(meets([-2.0, 3.0, -4.0], [2.0, -1.0, 4.0]));
        // The z slab moved to t ∈ [1.6, 2.35] by starting at z = −6.4: apart from the x slab.
        assert!(!meets([-2.0, 3.0, -6.4], [2.0, -1.0, 4.0]));
    }

    #[test]
    fn plane_hit_by_hand() {
        // The triangle (1, 1, 1), (3, 1, 1), (1, 3, 1): e1 = (2, 0, 0), e2 = (0, 2, 0); a ray down from
        // z = 5 with |d| = 2 meets its plane at t = 2, with b1 = (x − 1)/2 and b2 = (y − 1)/2.
        let tri = [DVec3::new(1.0, 1.0, 1.0), DVec3::new(3.0, 1.0, 1.0), DVec3::new(1.0, 3.0, 1.0)];
        let hit = |x: f64, y: f64| plane_hit(DVec3::new(x, y, 5.0), DVec3::new(0.0, 0.0, -2.0), tri);
        assert_eq!(hit(1.5, 2.0), Some((2.0, 0.25, 0.5)));
        // Each barycentric may reach −½ (SEED_SLACK), not beyond.
        assert_eq!(hit(0.0, 2.0), Some((2.0, -0.5, 0.5)));
        assert_eq!(hit(2.0, 0.0), Some((2.0, 0.5, -0.5)));
        assert_eq!(hit(2.5, 2.5), Some((2.0, 0.75, 0.75)));
        assert_eq!([hit(-0.5, 2.0), hit(2.0, -0.5), hit(2.75, 2.75)], [None; 3]);
        // Upwards from below, t = −2 (the plane behind the origin still seeds), and parallel to it.
        assert_eq!(plane_hit(DVec3::new(1.5, 2.0, 5.0), DVec3::new(0.0, 0.0, 2.0), tri), Some((-2.0, 0.25, 0.5)));
        assert_eq!(plane_hit(DVec3::new(1.5, 2.0, 5.0), DVec3::new(1.0, 1.0, 0.0), tri), None);
    }

    #[test]
    fn newton_by_hand() {
        // On P(u, v) = (3u, 3v, 0) the system is linear: one step from anywhere reaches the root.
        // The ray from (−0.5, −0.5, 4) along (0.5, 1, −2) meets z = 0 at t = 2, (0.5, 1.5, 0):
        // u = 1/6, v = ½.
        let p = square(0.0);
        let (o, d) = (DVec3::new(-0.5, -0.5, 4.0), DVec3::new(0.5, 1.0, -2.0));
        let (u, v, t) = newton(&p, o, d, (0.9, 0.1, 0.3), 1e-9).unwrap();
        assert!((u - 1.0 / 6.0).abs() < 1e-12 && (v - 0.5).abs() < 1e-12 && (t - 2.0).abs() < 1e-12, "{u} {v} {t}");
        // Grazing, along (1, 0, −0.01) to (1.5, 1.5, 0) at t = 1.5: det = ∂P/∂u·(∂P/∂v × −d) = 3·(3·0.01)
        // = 0.09, small against |∂P/∂u||∂P/∂v||d| ≈ 9 but far from singular (bound 9·10⁻¹²).
        let (u, v, t) = newton(&p, DVec3::new(0.0, 1.5, 0.015), DVec3::new(1.0, 0.0, -0.01), (0.2, 0.7, 0.0), 1e-9).unwrap();
        assert!((u - 0.5).abs() < 1e-12 && (v - 0.5).abs() < 1e-12 && (t - 1.5).abs() < 1e-9, "{u} {v} {t}");
        // A root within 10⁻⁹ outside the patch is clamped onto its edge; farther out it is refused.
        let down = DVec3::new(0.0, 0.0, -1.0);
        assert_eq!(newton(&p, DVec3::new(-1.5e-9, 1.5, 1.0), down, (0.5, 0.5, 0.0), 1e-9), Some((0.0, 0.5, 1.0)));
        assert_eq!(newton(&p, DVec3::new(1.5, 3.0 + 1.5e-9, 1.0), down, (0.5, 0.5, 0.0), 1e-9), Some((0.5, 1.0, 1.0)));
        assert_eq!(newton(&p, DVec3::new(-6e-9, 1.5, 1.0), down, (0.5, 0.5, 0.0), 1e-9), None);
        assert_eq!(newton(&p, DVec3::new(1.5, 3.0 + 6e-9, 1.0), down, (0.5, 0.5, 0.0), 1e-9), None);
        // A root at u = 1.5 (x = 4.5): outside, though within the wandering range [−1, 2].
        assert_eq!(newton(&p, DVec3::new(4.5, 1.5, 1.0), down, (0.5, 0.5, 0.0), 1e-9), None);
        // Already at the root: no step. Parallel to the plane: a singular Jacobian, no root.
        assert_eq!(newton(&p, DVec3::new(1.5, 1.5, 1.0), down, (0.5, 0.5, 1.0), 1e-9), Some((0.5, 0.5, 1.0)));
        assert_eq!(newton(&p, DVec3::new(0.0, 1.5, 0.0), DVec3::X, (0.5, 0.5, 0.0), 1e-9), None);
        // The dome z = (B1 + B2)(u)(B1 + B2)(v) over (2u, v·3): from its top, straight down.
        let (u, v, t) = newton(&dome(), DVec3::new(1.0, 1.5, 5.0), down, (0.4, 0.6, 4.0), 1e-9).unwrap();
        // (Its control points' x, 2k/3 rounded to f32, put the top 10⁻⁸ off u = ½, where z is flat.)
        assert!((u - 0.5).abs() < 1e-7 && (v - 0.5).abs() < 1e-9 && (t - (5.0 - 0.5625)).abs() < 1e-9, "{u} {v} {t}");
    }
}
