//! Uniform grid (Fujimoto et al. 1986; Amanatides & Woo 1987): the scene box is cut into
//! equal cells, each listing the primitives that overlap it, and a ray walks the cells it
//! pierces in order with a 3D digital differential analyser (3D-DDA).
//!
//! Resolution follows the usual density heuristic (Cleary & Wyvill 1988; Wald et al. 2006,
//! "Ray Tracing Animated Scenes using Coherent Grid Traversal"): about `λ·N` cells, cubic
//! in shape, so `res_axis = extent_axis · ∛(λN / V)`. Cells are stored compactly (CSR: one
//! offset per cell into one index array), as in Lagae & Dutré 2008, "Compact, Fast and
//! Robust Grids for Ray Tracing".

use rayon::prelude::*;
use raylab_core::{Aabb, Ray, Vec3};

use crate::leaf::{any_hit, Closest};
use crate::{robust_margin, Accel, AccelStats, BuildOptions, Counters, Hit, Primitives, ValidationError};

/// Upper bound on primitive references (cell entries): 128 MiB of indices. A scene whose
/// primitives would overlap more cells than this gets a coarser grid instead (large
/// primitives in a fine grid are the grid's known failure, "teapot in a stadium").
const MAX_REFERENCES: u64 = 1 << 25;

/// Slots of the per-ray mailbox. A primitive spanning several cells is tested once per ray
/// (Amanatides & Woo 1987); the mailbox is a small direct-mapped table of the last ids
/// tested, local to the ray (hashed mailboxing, Havran 2000), so traversal shares no
/// mutable state between threads. A collision only costs a repeated test.
const MAILBOX: usize = 32;

/// A uniform grid.
///
/// Invariants: `offsets.len() == cells + 1`, `offsets` is non-decreasing from 0 to
/// `indices.len()`; cell `(x, y, z)` is `x + res[0] * (y + res[1] * z)` and lists
/// `indices[offsets[c]..offsets[c + 1]]` in increasing order; every primitive whose bounds
/// overlap a cell grown by `margin` is listed in it unless `clipped_bounds` says it misses.
#[derive(Debug)]
pub struct Grid {
    bounds: Aabb,
    res: [u32; 3],
    cell_size: Vec3,
    inv_cell_size: Vec3,
    /// Cells are grown by this much at insertion so that rounding in the DDA never loses
    /// a primitive on a cell boundary (see [`robust_margin`]).
    margin: f32,
    density: f32,
    offsets: Vec<u32>,
    indices: Vec<u32>,
    primitives: usize,
    pub(crate) build_ms: f64,
}

/// Cells per axis for `n` primitives in `bounds` at density `λ` (cells per primitive):
/// `extent · ∛(λN/V)` rounded, at least 1, at most `max_res`. Axes too thin for one cell
/// get 1 and the others share the budget (a flat scene gets a 2D grid).
pub fn resolution(bounds: &Aabb, n: usize, density: f32, max_res: u32) -> [u32; 3] {
    let mut res = [1u32; 3];
    if n == 0 || bounds.is_empty() {
        return res;
    }
    let d = bounds.extent();
    let target = (density.max(0.0) as f64 * n as f64).max(1.0);
    let mut active = [d.x > 0.0, d.y > 0.0, d.z > 0.0];
    loop {
        let k = active.iter().filter(|&&a| a).count();
        if k == 0 {
            return res;
        }
        let measure: f64 = (0..3).filter(|&a| active[a]).map(|a| d[a] as f64).product();
        let per_unit = (target / measure).powf(1.0 / k as f64);
        let mut thin = false;
        for a in 0..3 {
            if !active[a] {
                continue;
            }
            let r = (d[a] as f64 * per_unit).round();
            if r < 1.0 {
                active[a] = false;
                thin = true;
            }
            res[a] = r.clamp(1.0, max_res.max(1) as f64) as u32;
        }
        if !thin {
            return res;
        }
        res = [1; 3];
    }
}

impl Grid {
    pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Self {
        let n = prims.len();
        let prim_bounds: Vec<Aabb> = (0..n as u32).into_par_iter().map(|i| prims.bounds(i)).collect();
        let scene = prim_bounds.par_iter().copied().reduce(|| Aabb::EMPTY, Aabb::union);
        let margin = robust_margin(&scene);
        // Grown by the margin so that no axis is flat and every cell has a finite inverse size.
        let bounds = if n == 0 { Aabb::new(Vec3::ZERO, Vec3::ONE) } else { Aabb::new(scene.min - margin, scene.max + margin) };
        let mut res = resolution(&bounds, n, opts.grid_density, opts.grid_max_resolution);
        let mut grid = loop {
            let g = Self::empty(bounds, res, margin, opts.grid_density, n);
            let estimate: u64 = prim_bounds.par_iter().map(|b| g.cell_range(b).map_or(0, |(lo, hi)| volume(lo, hi))).sum();
            if estimate <= MAX_REFERENCES || res == [1; 3] {
                break g;
            }
            res = res.map(|r| ((r as f32 * 0.8) as u32).max(1));
        };
        // Insertion in parallel: every primitive emits `cell << 32 | prim` keys for the cells
        // it overlaps; one parallel sort groups them by cell (and by primitive within a cell,
        // so the result does not depend on the thread count).
        let g = &grid;
        let mut keys: Vec<u64> = (0..n as u32)
            .into_par_iter()
            .flat_map_iter(|i| {
                let b = prim_bounds[i as usize];
                let (lo, hi) = g.cell_range(&b).unwrap_or(([1; 3], [0; 3]));
                let single = lo == hi;
                (lo[2]..=hi[2])
                    .flat_map(move |z| (lo[1]..=hi[1]).flat_map(move |y| (lo[0]..=hi[0]).map(move |x| [x, y, z])))
                    .filter(move |&cell| single || !prims.clipped_bounds(i, &g.cell_bounds(cell, g.margin)).is_empty())
                    .map(move |cell| (g.cell_index(cell) as u64) << 32 | i as u64)
            })
            .collect();
        keys.par_sort_unstable();
        let cells = grid.cell_count();
        let mut offsets = vec![0u32; cells + 1];
        for &k in &keys {
            offsets[(k >> 32) as usize + 1] += 1;
        }
        for c in 0..cells {
            offsets[c + 1] += offsets[c];
        }
        grid.indices = keys.into_par_iter().map(|k| k as u32).collect();
        grid.offsets = offsets;
        grid
    }

    fn empty(bounds: Aabb, res: [u32; 3], margin: f32, density: f32, primitives: usize) -> Self {
        let cell_size = bounds.extent() / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let cells = res.iter().map(|&r| r as usize).product::<usize>();
        Self {
            bounds,
            res,
            cell_size,
            inv_cell_size: Vec3::ONE / cell_size,
            margin,
            density,
            offsets: vec![0; cells + 1],
            indices: Vec::new(),
            primitives,
            build_ms: 0.0,
        }
    }

    pub fn resolution(&self) -> [u32; 3] {
        self.res
    }

    pub fn cell_count(&self) -> usize {
        self.offsets.len() - 1
    }

    #[inline]
    fn cell_index(&self, [x, y, z]: [u32; 3]) -> usize {
        x as usize + self.res[0] as usize * (y as usize + self.res[1] as usize * z as usize)
    }

    /// Cell coordinate of `x` on `axis`, clamped into the grid.
    #[inline]
    fn coord(&self, x: f32, axis: usize) -> u32 {
        let c = ((x - self.bounds.min[axis]) * self.inv_cell_size[axis]).floor();
        (c.max(0.0) as u32).min(self.res[axis] - 1)
    }

    /// First and last cell (inclusive) overlapped by `b` grown by the margin.
    fn cell_range(&self, b: &Aabb) -> Option<([u32; 3], [u32; 3])> {
        if b.is_empty() {
            return None;
        }
        let lo = [0, 1, 2].map(|a| self.coord(b.min[a] - self.margin, a));
        let hi = [0, 1, 2].map(|a| self.coord(b.max[a] + self.margin, a));
        Some((lo, hi))
    }

    /// Box of cell `c` grown by `grow` on every side.
    fn cell_bounds(&self, c: [u32; 3], grow: f32) -> Aabb {
        let lo = self.bounds.min + self.cell_size * Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
        Aabb { min: lo - grow, max: lo + self.cell_size + grow }
    }

    /// 3D-DDA (Amanatides & Woo 1987). Calls `prim(ray, i, counters)` for each primitive of
    /// each cell the ray pierces, nearest cell first, each primitive once; `prim` may shrink
    /// `ray.t_max` and returns `true` to stop. The walk ends early once `ray.t_max` lies
    /// within the current cell: a nearer hit would lie in a cell already visited, and since
    /// every primitive was tested against the whole remaining interval, it was found.
    #[inline]
    fn walk(&self, ray: &mut Ray, c: &mut Counters, mut prim: impl FnMut(&mut Ray, u32, &mut Counters) -> bool) {
        if self.indices.is_empty() {
            return;
        }
        let inv = ray.inv_dir();
        let Some((t0, _)) = self.bounds.intersect(ray.origin, inv, ray.t_min, ray.t_max) else { return };
        let entry = ray.at(t0);
        let mut cell = [0, 1, 2].map(|a| self.coord(entry[a], a) as i64);
        let step = [0, 1, 2].map(|a| if ray.dir[a] > 0.0 { 1i64 } else if ray.dir[a] < 0.0 { -1 } else { 0 });
        let mut mailbox = [u32::MAX; MAILBOX];
        loop {
            c.nodes_visited += 1;
            let idx = self.cell_index(cell.map(|x| x as u32));
            for &p in &self.indices[self.offsets[idx] as usize..self.offsets[idx + 1] as usize] {
                let slot = &mut mailbox[p as usize % MAILBOX];
                if *slot == p {
                    continue;
                }
                *slot = p;
                if prim(ray, p, c) {
                    return;
                }
            }
            // Distance to each axis's next cell boundary, computed from the plane itself
            // rather than accumulated, so rounding does not drift along long walks.
            let (mut axis, mut t_exit) = (0, f32::INFINITY);
            for a in 0..3 {
                if step[a] == 0 {
                    continue;
                }
                let k = if step[a] > 0 { cell[a] + 1 } else { cell[a] };
                let plane = self.bounds.min[a] + k as f32 * self.cell_size[a];
                let t = (plane - ray.origin[a]) * inv[a];
                if t < t_exit {
                    (axis, t_exit) = (a, t);
                }
            }
            if ray.t_max <= t_exit {
                return;
            }
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= self.res[axis] as i64 {
                return;
            }
        }
    }
}

fn volume(lo: [u32; 3], hi: [u32; 3]) -> u64 {
    (0..3).map(|a| (hi[a] - lo[a] + 1) as u64).product()
}

impl Accel for Grid {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        c.rays += 1;
        let mut ray = *ray;
        let mut closest = Closest::new(prims);
        self.walk(&mut ray, c, |ray, p, c| closest.test(ray, [p], c));
        closest.best
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        c.rays += 1;
        let mut ray = *ray;
        let mut hit = false;
        self.walk(&mut ray, c, |ray, p, c| {
            hit = any_hit(prims, ray, [p], c);
            hit
        });
        hit
    }

    fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: "grid".into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            max_depth: 1,
            memory_bytes: (self.offsets.len() + self.indices.len()) * 4,
            ..Default::default()
        };
        for w in self.offsets.windows(2) {
            let n = (w[1] - w[0]) as usize;
            s.add_leaf(n);
            s.interior_nodes += usize::from(n > 0);
        }
        let [x, y, z] = self.res;
        s.note("resolution", format!("{x}x{y}x{z}"));
        s.note("density", self.density);
        s.note("cells", self.cell_count());
        s.note("non-empty cells", s.interior_nodes);
        s
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new("grid", m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        let cells: usize = self.res.iter().map(|&r| r as usize).product();
        if self.offsets.len() != cells + 1 || self.offsets[0] != 0 || *self.offsets.last().unwrap() as usize != self.indices.len() {
            return err(format!("{} offsets for {cells} cells and {} references", self.offsets.len(), self.indices.len()));
        }
        let mut seen = vec![false; prims.len()];
        for z in 0..self.res[2] {
            for y in 0..self.res[1] {
                for x in 0..self.res[0] {
                    let c = self.cell_index([x, y, z]);
                    let (a, b) = (self.offsets[c] as usize, self.offsets[c + 1] as usize);
                    if a > b {
                        return err(format!("offsets decrease at cell {c}"));
                    }
                    let cell = self.cell_bounds([x, y, z], self.margin);
                    for &p in &self.indices[a..b] {
                        if p as usize >= prims.len() {
                            return err(format!("cell {c} holds primitive {p} of {}", prims.len()));
                        }
                        seen[p as usize] = true;
                        if prims.bounds(p).intersection(cell).is_empty() {
                            return err(format!("primitive {p} does not overlap cell {c}"));
                        }
                    }
                }
            }
        }
        match seen.iter().position(|s| !s) {
            Some(p) => err(format!("primitive {p} is in no cell")),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_of_known_box() {
        // 1000 primitives at λ = 4 in a 2x1x1 box: ∛(4000 / 2) = 12.6 cells per unit.
        let b = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        assert_eq!(resolution(&b, 1000, 4.0, 128), [25, 13, 13]);
        assert_eq!(resolution(&b, 1000, 4.0, 16), [16, 13, 13]);
        // A flat box gets a 2D grid: √(4000 / 2) = 44.7 cells per unit.
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 1.0));
        assert_eq!(resolution(&flat, 1000, 4.0, 128), [89, 1, 45]);
        // A sliver axis too thin for one cell drops out of the budget.
        let thin = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1e-6, 1.0));
        assert_eq!(resolution(&thin, 1000, 4.0, 128), [89, 1, 45]);
        assert_eq!(resolution(&b, 0, 4.0, 128), [1, 1, 1]);
        // Flat on the other axes too: √(4000 / 2) = 44.7 per unit.
        assert_eq!(resolution(&Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 0.0)), 1000, 4.0, 128), [89, 45, 1]);
        assert_eq!(resolution(&Aabb::new(Vec3::ZERO, Vec3::new(0.0, 2.0, 1.0)), 1000, 4.0, 128), [1, 89, 45]);
        // An axis worth exactly one cell stays in the budget: 100 × 100 × 0.6 at λN = 6000 is
        // ∛(6000 / 6000) = 1 per unit: 100, 100 and round(0.6) = 1. (Dropping it would give
        // √(6000 / 10⁴) = 0.77 per unit, 77 × 77.)
        assert_eq!(resolution(&Aabb::new(Vec3::ZERO, Vec3::new(100.0, 100.0, 0.6)), 1500, 4.0, 128), [100, 100, 1]);
        // No density: one cell per scene at least, ∛(1 / 2) = 0.79 per unit, 2 × 1 × 1.
        assert_eq!(resolution(&b, 1000, 0.0, 128), [2, 1, 1]);
    }

    use crate::primitives::TestBoxes as Boxes;

    /// Four boxes in [0, 4]³ at λ = 16: a 4 × 4 × 4 grid (cells of 1 + m/2, m = 9·2⁻¹⁹ the
    /// margin), cell (x, y, z) at x + 4y + 16z. Prim 0 [0, ½]³ in cell 0; prim 3 (x, y
    /// ¼..¾, z 3.25..3.75) in cell (0, 0, 3) = 48; prims 1 [3.5, 4]³ and 2 [3.25, 3.75]³ in
    /// cell 63.
    fn four() -> (Boxes, Grid) {
        let b = |lo: [f32; 3], hi: [f32; 3]| Aabb::new(Vec3::from_array(lo), Vec3::from_array(hi));
        let prims = Boxes(vec![b([0.0; 3], [0.5; 3]), b([3.5; 3], [4.0; 3]), b([3.25; 3], [3.75; 3]), b([0.25, 0.25, 3.25], [0.75, 0.75, 3.75])]);
        let g = Grid::build(&prims, &BuildOptions { grid_density: 16.0, ..BuildOptions::default() });
        (prims, g)
    }

    #[test]
    fn cells_listed_by_hand() {
        let (_, g) = four();
        assert_eq!(g.res, [4, 4, 4]);
        let mut offsets = vec![0];
        offsets.extend([1; 48]);
        offsets.extend([2; 15]);
        offsets.push(4);
        assert_eq!(g.offsets, offsets);
        assert_eq!(g.indices, vec![0, 3, 1, 2]);
    }

    #[test]
    fn validation_reports_each_broken_invariant() {
        let (prims, good) = four();
        good.validate(&prims).unwrap();
        let broken = |f: &dyn Fn(&mut Grid)| {
            let mut g = four().1;
            f(&mut g);
            g.validate(&prims).unwrap_err().message
        };
        assert_eq!(good.validate(&Boxes(prims.0[..3].to_vec())).unwrap_err().message, "built for 4 primitives, given 3");
        assert_eq!(broken(&|g| { g.offsets.pop(); }), "64 offsets for 64 cells and 4 references");
        assert_eq!(broken(&|g| g.offsets[0] = 1), "65 offsets for 64 cells and 4 references");
        assert_eq!(broken(&|g| g.indices.push(0)), "65 offsets for 64 cells and 5 references");
        assert_eq!(broken(&|g| g.offsets[63] = 0), "offsets decrease at cell 62");
        assert_eq!(broken(&|g| g.indices[0] = 9), "cell 0 holds primitive 9 of 4");
        assert_eq!(broken(&|g| g.indices[0] = 1), "primitive 1 does not overlap cell 0");
        assert_eq!(broken(&|g| g.indices[3] = 1), "primitive 2 is in no cell");
        let mut g = four().1;
        g.primitives = 3;
        assert_eq!(Accel::validate(&g, &prims).unwrap_err().accel, "grid");
    }

    /// The build time (set by `AnyAccel::build`) is passed on to the statistics.
    #[test]
    fn statistics_pass_the_build_time_on() {
        let mut g = four().1;
        g.build_ms = 1.25;
        assert_eq!(g.stats().build_ms, 1.25);
    }
}
