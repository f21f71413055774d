//! Top-down builders. Subtrees are built in parallel (`rayon::join`) into a temporary
//! tree, which is then flattened depth-first with siblings adjacent.

use rayon::prelude::*;
use raylab_core::{Aabb, Vec3};

use super::{BvhNode, SahCost, SplitMethod, MAX_DEPTH};
use crate::{BuildOptions, Primitives};

/// Subtrees smaller than this are built on the current thread.
const PARALLEL_THRESHOLD: usize = 4096;

enum BuildNode {
    Leaf { bounds: Aabb, first: u32, count: u32 },
    Interior { bounds: Aabb, children: Box<[BuildNode; 2]> },
}

struct Ctx<'a> {
    bounds: &'a [Aabb],
    centroids: &'a [Vec3],
    method: SplitMethod,
    sah: SahCost,
    max_leaf: usize,
    bins: usize,
}

pub(super) fn build<P: Primitives + ?Sized>(prims: &P, method: SplitMethod, opts: &BuildOptions) -> (Vec<BvhNode>, Vec<u32>) {
    let n = prims.len();
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let bounds: Vec<Aabb> = (0..n as u32).into_par_iter().map(|i| prims.bounds(i)).collect();
    let centroids: Vec<Vec3> = bounds.par_iter().map(|b| b.centroid()).collect();
    let mut indices: Vec<u32> = (0..n as u32).collect();
    let ctx = Ctx { bounds: &bounds, centroids: &centroids, method, sah: SahCost::from_options(opts), max_leaf: opts.max_leaf_size.max(1), bins: opts.bins.clamp(2, 256) };
    let root = ctx.build(&mut indices, 0, 1);
    let mut nodes = Vec::with_capacity(2 * n);
    nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
    flatten(root, 0, &mut nodes);
    (nodes, indices)
}

fn flatten(node: BuildNode, slot: usize, nodes: &mut Vec<BvhNode>) {
    match node {
        BuildNode::Leaf { bounds, first, count } => nodes[slot] = BvhNode::leaf(bounds, first, count),
        BuildNode::Interior { bounds, children } => {
            let left = nodes.len();
            nodes[slot] = BvhNode::interior(bounds, left as u32);
            nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
            nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
            let [l, r] = *children;
            flatten(l, left, nodes);
            flatten(r, left + 1, nodes);
        }
    }
}

impl Ctx<'_> {
    /// Builds the subtree over `idx`, whose first element sits at `offset` in the index array.
    fn build(&self, idx: &mut [u32], offset: usize, depth: usize) -> BuildNode {
        let bounds = self.union_of(idx, |i| self.bounds[i as usize]);
        let leaf = BuildNode::Leaf { bounds, first: offset as u32, count: idx.len() as u32 };
        if idx.len() <= 1 || depth >= MAX_DEPTH {
            return leaf;
        }
        let Some(mid) = self.split(idx, &bounds) else { return leaf };
        let (l, r) = idx.split_at_mut(mid);
        let (left, right) = if l.len() + r.len() >= PARALLEL_THRESHOLD {
            rayon::join(|| self.build(l, offset, depth + 1), || self.build(r, offset + mid, depth + 1))
        } else {
            (self.build(l, offset, depth + 1), self.build(r, offset + mid, depth + 1))
        };
        BuildNode::Interior { bounds, children: Box::new([left, right]) }
    }

    /// Partitions `idx` and returns the size of the left part, or `None` for a leaf.
    fn split(&self, idx: &mut [u32], bounds: &Aabb) -> Option<usize> {
        let cb = self.union_of(idx, |i| Aabb::new(self.centroids[i as usize], self.centroids[i as usize]));
        let axis = cb.max_axis();
        let extent = cb.max[axis] - cb.min[axis];
        if extent <= 0.0 {
            // All centroids coincide: no plane separates them. Split by index only when the
            // leaf would be too large, so leaves stay bounded.
            return (idx.len() > self.max_leaf).then_some(idx.len() / 2);
        }
        match self.method {
            SplitMethod::BinnedSah => self.split_sah(idx, bounds, &cb),
            SplitMethod::Median => (idx.len() > self.max_leaf).then(|| self.split_median(idx, axis)),
            SplitMethod::Midpoint => {
                if idx.len() <= self.max_leaf {
                    return None;
                }
                let mid = 0.5 * (cb.min[axis] + cb.max[axis]);
                let m = partition(idx, |i| self.centroids[i as usize][axis] < mid);
                Some(if m == 0 || m == idx.len() { self.split_median(idx, axis) } else { m })
            }
        }
    }

    fn split_median(&self, idx: &mut [u32], axis: usize) -> usize {
        let mid = idx.len() / 2;
        idx.select_nth_unstable_by(mid, |&a, &b| self.centroids[a as usize][axis].total_cmp(&self.centroids[b as usize][axis]));
        mid
    }

    /// Binned SAH over all three axes (Wald 2007, "On fast Construction of SAH-based
    /// Bounding Volume Hierarchies"): centroids fall into `bins` equal bins per axis; the
    /// `bins - 1` planes between bins are evaluated by a prefix/suffix sweep.
    fn split_sah(&self, idx: &mut [u32], bounds: &Aabb, cb: &Aabb) -> Option<usize> {
        let nb = self.bins;
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, plane)
        let mut right_area = vec![0.0f32; nb];
        let mut right_count = vec![0usize; nb];
        let bins = self.bin(idx, cb);
        for axis in 0..3 {
            let (lo, hi) = (cb.min[axis], cb.max[axis]);
            if hi <= lo {
                continue;
            }
            let (bin_bounds, bin_count) = (&bins.bounds[axis * nb..(axis + 1) * nb], &bins.count[axis * nb..(axis + 1) * nb]);
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            for p in (1..nb).rev() {
                acc = acc.union(bin_bounds[p]);
                cnt += bin_count[p];
                right_area[p] = acc.half_area();
                right_count[p] = cnt;
            }
            let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
            let pa = bounds.half_area();
            for p in 1..nb {
                acc = acc.union(bin_bounds[p - 1]);
                cnt += bin_count[p - 1];
                if cnt == 0 || right_count[p] == 0 {
                    continue;
                }
                let cost = if pa > 0.0 {
                    self.sah.traversal + self.sah.intersection * (acc.half_area() * cnt as f32 + right_area[p] * right_count[p] as f32) / pa
                } else {
                    self.sah.traversal + self.sah.intersection * idx.len() as f32
                };
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, p));
                }
            }
        }
        let (cost, axis, plane) = best?;
        if cost >= self.sah.leaf(idx.len()) && idx.len() <= self.max_leaf {
            return None;
        }
        let (lo, hi) = (cb.min[axis], cb.max[axis]);
        let scale = nb as f32 / (hi - lo);
        let m = partition(idx, |i| bin_of(self.centroids[i as usize][axis], lo, scale, nb) < plane);
        debug_assert!(m > 0 && m < idx.len());
        Some(m)
    }
}

/// Bins of the three axes, `nb` per axis (axis-major): the union of the boxes whose
/// centroid falls in each bin, and their count.
struct Bins {
    bounds: Vec<Aabb>,
    count: Vec<usize>,
}

impl Bins {
    fn new(nb: usize) -> Self {
        Self { bounds: vec![Aabb::EMPTY; 3 * nb], count: vec![0; 3 * nb] }
    }

    fn merge(mut self, o: Bins) -> Bins {
        for (a, b) in self.bounds.iter_mut().zip(o.bounds) {
            *a = a.union(b);
        }
        for (a, b) in self.count.iter_mut().zip(o.count) {
            *a += b;
        }
        self
    }
}

/// Nodes with at least this many primitives are binned in parallel (the top levels of the
/// tree, where `rayon::join` over subtrees has not yet spread the work).
const PARALLEL_BINNING: usize = 1 << 15;
const BIN_CHUNK: usize = 1 << 13;

impl Ctx<'_> {
    /// The union of `f(i)` over `idx`, in parallel for large nodes (unions are exact: the
    /// same box whatever the split of the work).
    fn union_of(&self, idx: &[u32], f: impl Fn(u32) -> Aabb + Sync) -> Aabb {
        if idx.len() < PARALLEL_BINNING {
            return idx.iter().fold(Aabb::EMPTY, |b, &i| b.union(f(i)));
        }
        idx.par_chunks(BIN_CHUNK).map(|part| part.iter().fold(Aabb::EMPTY, |b, &i| b.union(f(i)))).reduce(|| Aabb::EMPTY, Aabb::union)
    }

    /// Bins `idx` along the three axes of the centroid box `cb` (axes of zero extent get
    /// empty bins). Unions and counts are exact, so splitting the work over threads gives
    /// the same bins, hence the same tree, whatever the thread count.
    fn bin(&self, idx: &[u32], cb: &Aabb) -> Bins {
        let nb = self.bins;
        let scale: [f32; 3] = std::array::from_fn(|a| if cb.max[a] > cb.min[a] { nb as f32 / (cb.max[a] - cb.min[a]) } else { 0.0 });
        let bin_part = |part: &[u32]| {
            let mut bins = Bins::new(nb);
            for &i in part {
                let c = self.centroids[i as usize];
                let b = self.bounds[i as usize];
                for axis in 0..3 {
                    if scale[axis] > 0.0 {
                        let k = axis * nb + bin_of(c[axis], cb.min[axis], scale[axis], nb);
                        bins.bounds[k] = bins.bounds[k].union(b);
                        bins.count[k] += 1;
                    }
                }
            }
            bins
        };
        if idx.len() < PARALLEL_BINNING {
            return bin_part(idx);
        }
        idx.par_chunks(BIN_CHUNK).map(bin_part).reduce(|| Bins::new(nb), Bins::merge)
    }
}

#[inline]
fn bin_of(c: f32, lo: f32, scale: f32, nb: usize) -> usize {
    (((c - lo) * scale) as usize).min(nb - 1)
}

/// In-place partition; returns the number of elements for which `pred` holds (now in front).
fn partition(idx: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut m = 0;
    for k in 0..idx.len() {
        if pred(idx[k]) {
            idx.swap(k, m);
            m += 1;
        }
    }
    m
}
