//! Fixtures for tests and benchmarks: seeded random geometry and rays, and a primitive
//! soup (triangles and spheres) that implements [`Primitives`] with the same kernels the
//! renderer uses.

use std::ops::Range;
use std::path::PathBuf;

use raylab_accel::{PrimHit, Primitives};
use raylab_core::{intersect, Aabb, Pcg32, Ray, Vec3};

/// One primitive of a [`Soup`].
#[derive(Clone, Copy, Debug)]
pub enum Prim {
    Triangle([Vec3; 3]),
    Sphere { center: Vec3, radius: f32 },
}

/// A list of primitives, optionally grouped into objects (consecutive ranges).
#[derive(Clone, Debug, Default)]
pub struct Soup {
    pub prims: Vec<Prim>,
    pub objects: Vec<Range<u32>>,
}

impl Soup {
    pub fn new(prims: Vec<Prim>) -> Self {
        let n = prims.len() as u32;
        // One object holding every primitive.
        #[allow(clippy::single_range_in_vec_init)]
        let objects = if n > 0 { vec![0..n] } else { vec![] };
        Self { prims, objects }
    }

    pub fn triangles(tris: impl IntoIterator<Item = [Vec3; 3]>) -> Self {
        Self::new(tris.into_iter().map(Prim::Triangle).collect())
    }

    /// Appends another soup as a new object.
    pub fn push_object(&mut self, other: Soup) {
        let start = self.prims.len() as u32;
        self.prims.extend(other.prims);
        let end = self.prims.len() as u32;
        if end > start {
            self.objects.push(start..end);
        }
    }

    pub fn bounds(&self) -> Aabb {
        raylab_accel::primitives::total_bounds(self)
    }
}

impl Primitives for Soup {
    fn len(&self) -> usize {
        self.prims.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        match self.prims[i as usize] {
            Prim::Triangle(v) => Aabb::from_points(v),
            Prim::Sphere { center, radius } => Aabb::new(center - Vec3::splat(radius), center + Vec3::splat(radius)),
        }
    }

    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        match self.prims[i as usize] {
            Prim::Triangle([a, b, c]) => intersect::triangle(ray, a, b, c).map(|(t, u, v)| PrimHit { t, u, v }),
            Prim::Sphere { center, radius } => intersect::sphere(ray, center, radius).map(|t| PrimHit { t, u: 0.0, v: 0.0 }),
        }
    }

    fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
        match self.prims[i as usize] {
            Prim::Triangle(v) => Some(v),
            Prim::Sphere { .. } => None,
        }
    }

    fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
        match self.prims[i as usize] {
            Prim::Triangle(v) => raylab_core::clip::triangle_bounds(v, clip),
            Prim::Sphere { .. } => Primitives::bounds(self, i).intersection(*clip),
        }
    }

    fn objects(&self) -> Vec<Range<u32>> {
        self.objects.clone()
    }
}

pub fn random_point(rng: &mut Pcg32, b: &Aabb) -> Vec3 {
    b.min + (b.max - b.min) * Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32())
}

pub fn random_dir(rng: &mut Pcg32) -> Vec3 {
    raylab_core::sampling::uniform_sphere(rng.next_vec2())
}

/// `n` random triangles with vertices in `b`, each of size about `size` (a "soup").
pub fn random_triangles(rng: &mut Pcg32, n: usize, b: &Aabb, size: f32) -> Soup {
    Soup::triangles((0..n).map(|_| {
        let c = random_point(rng, b);
        [c + size * random_dir(rng), c + size * random_dir(rng), c + size * random_dir(rng)]
    }))
}

pub fn random_spheres(rng: &mut Pcg32, n: usize, b: &Aabb, max_radius: f32) -> Soup {
    Soup::new((0..n).map(|_| Prim::Sphere { center: random_point(rng, b), radius: max_radius * (0.05 + 0.95 * rng.next_f32()) }).collect())
}

/// Rays from random points of `from` towards random points of `to`, plus some with random
/// directions; a quarter are axis-parallel.
pub fn random_rays(rng: &mut Pcg32, n: usize, from: &Aabb, to: &Aabb) -> Vec<Ray> {
    (0..n)
        .map(|k| {
            let o = random_point(rng, from);
            let d = match k % 4 {
                0 => random_dir(rng),
                1 => {
                    let axis = rng.below(3) as usize;
                    let mut d = Vec3::ZERO;
                    d[axis] = if rng.next_f32() < 0.5 { -1.0 } else { 1.0 };
                    d
                }
                _ => (random_point(rng, to) - o).try_normalize().unwrap_or(Vec3::X),
            };
            Ray::new(o, d)
        })
        .collect()
}

/// A closed unit cube made of 12 triangles, centred at the origin (the seeds' cube).
pub fn cube() -> Soup {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) - Vec3::splat(0.5);
    let c = [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.), v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)];
    let faces = [[0, 1, 2, 3], [5, 4, 7, 6], [4, 0, 3, 7], [1, 5, 6, 2], [3, 2, 6, 7], [4, 5, 1, 0]];
    Soup::triangles(faces.iter().flat_map(|f| [[c[f[0]], c[f[1]], c[f[2]]], [c[f[0]], c[f[2]], c[f[3]]]]))
}

/// The folder of shared scenes: `$RAYLAB_SHARED` when set (pointing it at a missing folder
/// shows which tests need the shared data), else `../shared/scenes` beside the repository.
pub fn shared_scenes() -> PathBuf {
    match std::env::var_os("RAYLAB_SHARED") {
        Some(dir) => PathBuf::from(dir),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes"),
    }
}

/// `name` in [`shared_scenes`], or `None` after saying on stderr which file is missing and
/// where it was looked for: the caller returns early, so a checkout without the shared data
/// skips the test instead of failing it (`let Some(path) = shared_file("x") else { return };`).
pub fn shared_file(name: &str) -> Option<PathBuf> {
    let path = shared_scenes().join(name);
    if path.is_file() {
        return Some(path);
    }
    eprintln!("skipped: needs the shared scene file `{name}`, not found at {} (set RAYLAB_SHARED to the shared `scenes` folder)", path.display());
    None
}

/// Whether every file in `names` is in [`shared_scenes`] (each missing one is reported as by
/// [`shared_file`]).
pub fn shared_files(names: &[&str]) -> bool {
    // Not `all`: it would stop at the first missing file and report only that one.
    #[allow(clippy::unnecessary_fold)]
    let all = names.iter().map(|n| shared_file(n).is_some()).fold(true, |a, b| a && b);
    all
}

/// A file of the repository's `assets/` folder (always present, unlike the shared data).
pub fn asset(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets").join(name)
}

/// Reads the vertices and triangular faces of a plain OBJ file (tests only; the real
/// loader lives in `raylab-loader`).
pub fn read_obj_triangles(path: &std::path::Path) -> Soup {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut v = Vec::new();
    let mut tris = Vec::new();
    for line in text.lines() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let p: Vec<f32> = it.take(3).map(|s| s.parse().unwrap()).collect();
                v.push(Vec3::new(p[0], p[1], p[2]));
            }
            Some("f") => {
                let idx: Vec<usize> = it.map(|s| s.split('/').next().unwrap().parse::<usize>().unwrap() - 1).collect();
                for k in 1..idx.len() - 1 {
                    tris.push([v[idx[0]], v[idx[k]], v[idx[k + 1]]]);
                }
            }
            _ => {}
        }
    }
    Soup::triangles(tris)
}

/// Pearson's χ² of `observed` counts against `expected` ones (same cells), cells expecting
/// fewer than 5 pooled into one: `(χ², degrees of freedom)`.
pub fn chi_square(expected: &[f64], observed: &[f64]) -> (f64, usize) {
    let mut cells: Vec<(f64, f64)> = expected.iter().copied().zip(observed.iter().copied()).collect();
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut chi2, mut dof, mut pool) = (0.0, 0usize, (0.0, 0.0));
    for (e, o) in cells {
        if e < 5.0 {
            pool = (pool.0 + e, pool.1 + o);
            continue;
        }
        chi2 += (o - e) * (o - e) / e;
        dof += 1;
    }
    if pool.0 > 0.0 {
        chi2 += (pool.1 - pool.0) * (pool.1 - pool.0) / pool.0;
        dof += 1;
    }
    (chi2, dof.saturating_sub(1))
}

/// The χ² a fit must stay under: the mean `dof` plus five standard deviations `√(2 dof)`
/// (p ≈ 1e-5 of a false alarm).
pub fn chi_square_limit(dof: usize) -> f64 {
    dof as f64 + 5.0 * (2.0 * dof as f64).sqrt()
}

/// How far (in units in the last place of the oracle's distance) a structure's closest hit
/// may lie behind the oracle's. Box and plane tests round too: where coplanar triangles
/// overlap (fans, duplicated faces) their distances along one ray differ by an ulp or two,
/// and a box entry rounded up by an ulp may prune the nearer one after the farther one was
/// found. pbrt-v4 bounds that rounding by 2γ₃ ≈ 3.6e-7 relative (3 ulps); 4 ulps cover it.
pub const ORACLE_ULPS: u32 = 4;

/// What "agrees with the oracle" means for a closest-hit query (documented in
/// docs/testing.md): both miss, or both hit and
/// 1. the reported hit is genuine: its primitive, intersected alone, gives exactly its `t`;
/// 2. it is not nearer than the true closest hit (nothing is invented in front of it);
/// 3. it is at most [`ORACLE_ULPS`] ulps behind the oracle's `t`: only a tie, or a near tie
///    between overlapping coplanar primitives, may resolve differently.
///
/// A different primitive at the same (or near-tied) distance is therefore accepted; any
/// real bug (a missed nearer surface, a wrong `t`, a hit that does not exist) is not.
pub fn agrees_with_oracle<P: Primitives + ?Sized>(prims: &P, ray: &Ray, want: Option<raylab_accel::Hit>, got: Option<raylab_accel::Hit>) -> Result<(), String> {
    match (want, got) {
        (None, None) => Ok(()),
        (Some(w), Some(g)) => {
            if g.t == w.t && g.prim == w.prim {
                return Ok(());
            }
            let again = prims.intersect(g.prim, ray).map(|h| h.t);
            if again != Some(g.t) {
                return Err(format!("prim {} reported at t = {} but intersects at {again:?}", g.prim, g.t));
            }
            if g.t < w.t {
                return Err(format!("t = {} (prim {}) is nearer than the oracle's closest {} (prim {})", g.t, g.prim, w.t, w.prim));
            }
            let ulps = g.t.to_bits() - w.t.to_bits();
            if ulps > ORACLE_ULPS {
                return Err(format!("t = {} (prim {}) is {ulps} ulps behind the oracle's {} (prim {})", g.t, g.prim, w.t, w.prim));
            }
            Ok(())
        }
        (w, g) => Err(format!("{g:?} vs oracle {w:?}")),
    }
}

/// A binary BVH as nested primitive sets, independent of the node layout: a leaf is its
/// primitives in brackets (sorted), or the bare index for one; an interior node
/// `(left right)`. Tests compare the trees builders make with trees worked out by hand.
pub fn bvh_shape(b: &raylab_accel::Bvh) -> String {
    fn walk(b: &raylab_accel::Bvh, i: usize) -> String {
        let n = &b.nodes[i];
        if n.is_leaf() {
            let mut p: Vec<u32> = b.indices[n.left_first as usize..(n.left_first + n.count) as usize].to_vec();
            p.sort();
            let s: Vec<String> = p.iter().map(u32::to_string).collect();
            return if s.len() == 1 { s[0].clone() } else { format!("[{}]", s.join(" ")) };
        }
        let l = n.left_first as usize;
        format!("({} {})", walk(b, l), walk(b, l + 1))
    }
    if b.nodes.is_empty() { String::new() } else { walk(b, 0) }
}

/// Axis-aligned boxes as primitives: a hit is the entry into the box; clipping is the default
/// `bounds ∩ clip`. Builder tests place them by hand.
pub struct Boxes(pub Vec<Aabb>);

impl Primitives for Boxes {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        self.0[i as usize]
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        let (t0, _) = self.0[i as usize].intersect_ray(ray)?;
        (t0 > ray.t_min && t0 <= ray.t_max).then_some(PrimHit { t: t0, u: 0.0, v: 0.0 })
    }
}
