//! SBVH, the spatial-split BVH (Stich, Friedrich & Dietrich 2009, "Spatial Splits in
//! Bounding Volume Hierarchies"). A node may be split like a kd-tree, by a plane that cuts
//! primitives: a primitive straddling the plane is referenced from both children, each
//! reference bounded by the primitive's part on its side (`Primitives::clipped_bounds`).
//! Leaf boxes shrink around long, thin or diagonal triangles at the price of duplicate
//! references.
//!
//! Each node compares the best binned object split (Wald 2007) with the best binned
//! spatial split; spatial splits are only tried where the object split's children overlap
//! by more than `α` times the root's area, which keeps duplication to where it pays.
//! Straddling references may be "unsplit" (§4.3): sent whole to one child when that costs
//! less than duplicating them.

use glam::Vec3A;
use raylab_core::Aabb;

use super::prim_ref::{truncate, Box3, PrimRef, MAX_PRIMS};
use super::{Bvh, BvhNode, SahCost, MAX_DEPTH};
use crate::{leaf_margin, BuildOptions, Primitives};

/// Duplicate references allowed, as a fraction of the primitive count. Stich et al. bound
/// duplication by `α` alone; a budget (as in Embree's spatial-split builder) also bounds
/// memory on adversarial input. It is shared between children in proportion to their sizes,
/// so the tree does not depend on the order nodes are built in.
const SPLIT_BUDGET: f32 = 1.0;

/// Nodes with at least this many references build their two subtrees in parallel.
const PARALLEL_THRESHOLD: usize = 4096;

enum Split {
    /// Refs whose centroid falls in a bin (of `bins`) below `plane` go left.
    Object { axis: usize, plane: usize, lo: f32, scale: f32, bins: usize },
    /// A plane at `pos`; `left`, `right`, `n_left`, `n_right` are the children estimated by
    /// the bins, used to decide unsplitting.
    Spatial { axis: usize, pos: f32, left: Box3, right: Box3, n_left: usize, n_right: usize },
}

struct Builder<'a, P: ?Sized> {
    prims: &'a P,
    sah: SahCost,
    max_leaf: usize,
    bins: usize,
    /// `α` times the root's half area: below this overlap no spatial split is tried.
    min_overlap: f32,
    /// Leaf boxes are grown by this much (see [`super::lbvh::grown_bounds`]).
    margin: f32,
    nodes: Vec<BvhNode>,
    indices: Vec<u32>,
}

pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Bvh {
    let n = prims.len();
    assert!(n < MAX_PRIMS, "SBVH: more than 2^30 primitives");
    // A reference is bounded by the part of its primitive inside the node holding it.
    let refs: Vec<PrimRef> = (0..n as u32)
        .map(|i| {
            let b = prims.bounds(i);
            PrimRef::new(b.min.into(), b.max.into(), i)
        })
        .collect();
    let root = refs.iter().fold(Box3::EMPTY, |b, r| b.union(r.bounds())).aabb();
    let mut b = Builder {
        prims,
        sah: SahCost::from_options(opts),
        max_leaf: opts.max_leaf_size.max(1),
        bins: opts.bins.clamp(2, 256),
        min_overlap: opts.spatial_split_alpha * root.half_area(),
        margin: leaf_margin(&root),
        nodes: Vec::new(),
        indices: Vec::new(),
    };
    if n > 0 {
        b.nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
        let mut scratch = Scratch::new(b.bins);
        b.node(0, refs, 1, (SPLIT_BUDGET * n as f32) as usize, &mut scratch);
    }
    Bvh::from_parts(b.nodes, b.indices, n, "sbvh").with_spatial_splits()
}

impl<P: Primitives + ?Sized> Builder<'_, P> {
    /// Builds the subtree over `refs` into `nodes[slot]`, allowing `budget` more duplicate
    /// references below; returns the box written.
    fn node(&mut self, slot: usize, refs: Vec<PrimRef>, depth: usize, budget: usize, scratch: &mut Scratch) -> Aabb {
        let (mut bounds, mut centroids) = (Box3::EMPTY, Box3::EMPTY);
        for r in &refs {
            bounds.grow(r.min(), r.max);
            let c = r.centroid();
            centroids.grow(c, c);
        }
        let n = refs.len();
        let split = if n <= 1 || depth >= MAX_DEPTH { None } else { self.split(&refs, &bounds, &centroids, budget, scratch) };
        let children = match split {
            Some(s) => self.apply(refs, s, budget),
            None => Err(refs),
        };
        let (left, right) = match children {
            Ok(c) => c,
            // No plane separates the references (all centroids coincide, or a spatial split
            // left one side empty): halve by index while the leaf would be too large.
            Err(mut refs) if n > self.max_leaf && depth < MAX_DEPTH => {
                let right = refs.split_off(n / 2);
                (refs, right)
            }
            Err(refs) => {
                let b = bounds.aabb();
                let leaf = Aabb { min: b.min - self.margin, max: b.max + self.margin };
                self.nodes[slot] = BvhNode::leaf(leaf, self.indices.len() as u32, n as u32);
                self.indices.extend(refs.iter().map(|r| r.id()));
                return leaf;
            }
        };
        let dups = (left.len() + right.len()).saturating_sub(n);
        let rest = budget.saturating_sub(dups);
        let left_budget = rest * left.len() / (left.len() + right.len());
        let l = self.nodes.len();
        self.nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
        self.nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
        let right_budget = rest - left_budget;
        let (bl, br) = if n >= PARALLEL_THRESHOLD {
            // The right subtree goes to a builder of its own on another thread, then is
            // appended after the left one: the layout of the serial build, on any thread count.
            let mut sub = self.fork();
            let (bl, br) = rayon::join(|| self.node(l, left, depth + 1, left_budget, scratch), || sub.node(0, right, depth + 1, right_budget, &mut Scratch::new(sub.bins)));
            self.append(l + 1, sub);
            (bl, br)
        } else {
            (self.node(l, left, depth + 1, left_budget, scratch), self.node(l + 1, right, depth + 1, right_budget, scratch))
        };
        let b = bl.union(br);
        self.nodes[slot] = BvhNode::interior(b, l as u32);
        b
    }

    /// An empty builder with the same settings, its root at slot 0.
    fn fork(&self) -> Self {
        let (sah, max_leaf, bins, min_overlap, margin) = (self.sah, self.max_leaf, self.bins, self.min_overlap, self.margin);
        Builder { prims: self.prims, sah, max_leaf, bins, min_overlap, margin, nodes: vec![BvhNode::interior(Aabb::EMPTY, 0)], indices: Vec::new() }
    }

    /// Appends the tree of a forked builder: its root goes to `slot`, its other nodes and
    /// its indices after ours, their references shifted accordingly.
    fn append(&mut self, slot: usize, sub: Self) {
        let (node_base, index_base) = (self.nodes.len() as u32 - 1, self.indices.len() as u32);
        let shift = |mut n: BvhNode| {
            n.left_first += if n.is_leaf() { index_base } else { node_base };
            n
        };
        self.nodes[slot] = shift(sub.nodes[0]);
        self.nodes.extend(sub.nodes[1..].iter().map(|&n| shift(n)));
        self.indices.extend(sub.indices);
    }

    /// The cheaper of the best object and spatial splits, or `None` when a leaf is cheaper
    /// and allowed. `centroids` bounds the references' centroids.
    fn split(&self, refs: &[PrimRef], bounds: &Box3, centroids: &Box3, budget: usize, scratch: &mut Scratch) -> Option<Split> {
        let object = self.object_split(refs, bounds, centroids, scratch);
        let overlap = object.as_ref().map_or(f32::INFINITY, |(_, _, l, r)| l.intersection(*r).half_area());
        let spatial = (budget > 0 && overlap > self.min_overlap).then(|| self.spatial_split(refs, bounds, scratch)).flatten();
        let best = match (object, spatial) {
            (Some((co, o, _, _)), Some((cs, s))) => Some(if cs < co { (cs, s) } else { (co, o) }),
            (Some((co, o, _, _)), None) => Some((co, o)),
            (None, s) => s,
        };
        let (cost, split) = best?;
        (cost < self.sah.leaf(refs.len()) || refs.len() > self.max_leaf).then_some(split)
    }

    /// Binned SAH over reference centroids (Wald 2007), the three axes binned in one pass:
    /// cost, split, and the two children's boxes (for the overlap test). Small nodes get
    /// fewer bins (4 + n/20, at most `bins`), as in Embree and the binned builder: most
    /// nodes are small, and there clearing and sweeping bins cost more than binning.
    fn object_split(&self, refs: &[PrimRef], bounds: &Box3, centroids: &Box3, s: &mut Scratch) -> Option<(f32, Split, Box3, Box3)> {
        let nb = self.bins.min(4 + refs.len() / 20);
        let (lo, hi) = (centroids.min, centroids.max);
        let scale = [0, 1, 2].map(|a| if hi[a] > lo[a] { nb as f32 / (hi[a] - lo[a]) } else { 0.0 });
        s.clear(nb);
        let (lo, scale_v, top) = (fourth_lane_zero(lo.to_array()), fourth_lane_zero(scale), Vec3A::splat((nb - 1) as f32));
        for r in refs {
            let bin = bins3(r.centroid(), lo, scale_v, top);
            for axis in 0..3 {
                if scale[axis] > 0.0 {
                    let b = axis * nb + bin[axis] as usize;
                    s.bounds[b].grow(r.min(), r.max);
                    s.enter[b] += 1;
                }
            }
        }
        let (cost, axis, p) = self.best_plane(bounds, s, nb, scale.map(|sc| sc > 0.0), false)?;
        let (left, right) = s.sides(axis, nb, p);
        Some((cost, Split::Object { axis, plane: p, lo: lo[axis], scale: scale[axis], bins: nb }, left, right))
    }

    /// Binned spatial split (Stich et al. 2009, §4.2): bins are equal slabs of the node's
    /// box; each reference is chopped into the bins it spans, counted as entering its first
    /// bin and leaving its last, so a plane's left side counts entries and its right exits.
    /// The three axes are binned in one pass over the references.
    fn spatial_split(&self, refs: &[PrimRef], bounds: &Box3, s: &mut Scratch) -> Option<(f32, Split)> {
        let nb = self.bins;
        let (lo, hi) = (bounds.min, bounds.max);
        let axes = [0, 1, 2].map(|a| hi[a] > lo[a]);
        let width = [0, 1, 2].map(|a| (hi[a] - lo[a]) / nb as f32);
        let scale = [0, 1, 2].map(|a| if axes[a] { nb as f32 / (hi[a] - lo[a]) } else { 0.0 });
        let plane = |a: usize, k: usize| if k == nb { hi[a] } else { lo[a] + k as f32 * width[a] };
        s.clear(nb);
        // Bin `k` of `axis` as bounds to clamp a box to: its planes on `axis`, infinite elsewhere.
        for axis in (0..3).filter(|&a| axes[a]) {
            for k in 0..nb {
                let (mut below, mut above) = (Vec3A::NEG_INFINITY, Vec3A::INFINITY);
                below[axis] = plane(axis, k);
                above[axis] = plane(axis, k + 1);
                s.slabs[axis * nb + k] = (below, above);
            }
        }
        let (lo, scale_v, top) = (fourth_lane_zero(lo.to_array()), fourth_lane_zero(scale), Vec3A::splat((nb - 1) as f32));
        for r in refs {
            // The bins of the box's two corners.
            let (first, last) = (bins3(r.min(), lo, scale_v, top), bins3(r.max, lo, scale_v, top));
            for axis in (0..3).filter(|&a| axes[a]) {
                let (f, l) = (axis * nb + first[axis] as usize, axis * nb + last[axis].max(first[axis]) as usize);
                s.enter[f] += 1;
                s.exit[l] += 1;
                for (bin, &(below, above)) in s.bounds[f..=l].iter_mut().zip(&s.slabs[f..=l]) {
                    // The reference's box cut by the bin, not the primitive clipped to it:
                    // exact clipping in every bin a reference spans made the build 2.5x
                    // slower for a tree 1 % better (docs/performance.md, fifth round);
                    // `apply` clips the references it splits exactly.
                    let slab = Box3 { min: r.min().max(below), max: r.max.min(above) };
                    if !slab.is_empty() {
                        bin.grow(slab.min, slab.max);
                    }
                }
            }
        }
        let (cost, axis, p) = self.best_plane(bounds, s, nb, axes, true)?;
        let (left, right) = s.sides(axis, nb, p);
        let bins = axis * nb..(axis + 1) * nb;
        let (n_left, n_right) = (s.enter[bins.start..bins.start + p].iter().sum::<u32>() as usize, s.exit[bins.start + p..bins.end].iter().sum::<u32>() as usize);
        Some((cost, Split::Spatial { axis, pos: plane(axis, p), left, right, n_left, n_right }))
    }

    /// The cheapest `(cost, axis, plane)` over the binned `axes`: a plane's left side is
    /// counted by `enter`, its right side by `exit` for a spatial split (references leaving
    /// a bin) and by `enter` for an object split (references in a bin). The first of equal
    /// costs wins, axis by axis.
    fn best_plane(&self, bounds: &Box3, s: &mut Scratch, nb: usize, axes: [bool; 3], spatial: bool) -> Option<(f32, usize, usize)> {
        let mut best: Option<(f32, usize, usize)> = None;
        for axis in (0..3).filter(|&a| axes[a]) {
            let bins = axis * nb..(axis + 1) * nb;
            let right = if spatial { &s.exit[bins.clone()] } else { &s.enter[bins.clone()] };
            if let Some((cost, p)) = self.sweep(bounds, &s.bounds[bins.clone()], &s.enter[bins], right, &mut s.suffix) {
                if best.is_none_or(|b| cost < b.0) {
                    best = Some((cost, axis, p));
                }
            }
        }
        best
    }

    /// The cheapest plane `p` (1..bins) between `bins[..p]`, counted by `left_count`, and
    /// `bins[p..]`, counted by `right_count`, with both sides non-empty: a suffix pass, then
    /// a prefix pass evaluating the SAH; the first of equal costs wins. `suffix` is scratch.
    fn sweep(&self, parent: &Box3, bins: &[Box3], left_count: &[u32], right_count: &[u32], suffix: &mut [(f32, u32)]) -> Option<(f32, usize)> {
        let nb = bins.len();
        let (mut right, mut nr) = (Box3::EMPTY, 0u32);
        for k in (1..nb).rev() {
            right = right.union(bins[k]);
            nr += right_count[k];
            suffix[k] = (right.half_area(), nr);
        }
        let pa = parent.half_area();
        let (mut left, mut nl) = (Box3::EMPTY, 0u32);
        let mut best: Option<(f32, usize)> = None;
        for p in 1..nb {
            left = left.union(bins[p - 1]);
            nl += left_count[p - 1];
            let (right_area, nr) = suffix[p];
            if nl == 0 || nr == 0 {
                continue;
            }
            let cost = self.sah.split_areas(pa, left.half_area(), nl as usize, right_area, nr as usize);
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, p));
            }
        }
        best
    }

    /// The part of primitive `prim` inside `clip`, or `None` when there is none.
    fn clip(&self, prim: u32, clip: &Box3) -> Option<Box3> {
        if clip.is_empty() {
            return None;
        }
        let clip = clip.aabb();
        let b = self.prims.clipped_bounds(prim, &clip).intersection(clip);
        (!b.is_empty()).then(|| Box3::from_aabb(&b))
    }

    /// Distributes `refs` between the children; gives `refs` back when one side would be
    /// empty. An object split keeps the left side in `refs`' buffer.
    fn apply(&self, mut refs: Vec<PrimRef>, split: Split, budget: usize) -> Result<(Vec<PrimRef>, Vec<PrimRef>), Vec<PrimRef>> {
        let (left, right) = match split {
            Split::Object { axis, plane, lo, scale, bins } => {
                let right: Vec<PrimRef> = refs.extract_if(.., |r| bin_of(r.centroid()[axis], lo, scale, bins) >= plane).collect();
                (refs, right)
            }
            Split::Spatial { axis, pos, left: lb, right: rb, n_left, n_right } => {
                let (mut left, mut right) = (Vec::with_capacity(n_left), Vec::with_capacity(n_right));
                let mut dups = 0;
                for r in refs.iter() {
                    if r.max[axis] <= pos {
                        left.push(*r);
                        continue;
                    }
                    if r.min()[axis] >= pos {
                        right.push(*r);
                        continue;
                    }
                    let (mut below, mut above) = (r.bounds(), r.bounds());
                    below.max[axis] = pos;
                    above.min[axis] = pos;
                    let half = |b: Box3| PrimRef::new(b.min, b.max, r.id());
                    match (self.clip(r.id(), &below), self.clip(r.id(), &above)) {
                        (Some(b), Some(a)) => {
                            // Reference unsplitting (§4.3): keep the whole reference on one
                            // side when that is cheaper than both halves, and always once
                            // the duplication budget is spent.
                            let (nl, nr) = (n_left as f32, n_right as f32);
                            let split = lb.half_area() * nl + rb.half_area() * nr;
                            let only_left = lb.union(r.bounds()).half_area() * nl + rb.half_area() * (nr - 1.0);
                            let only_right = lb.half_area() * (nl - 1.0) + rb.union(r.bounds()).half_area() * nr;
                            if dups < budget && split < only_left.min(only_right) {
                                dups += 1;
                                left.push(half(b));
                                right.push(half(a));
                            } else if only_left <= only_right {
                                left.push(*r);
                            } else {
                                right.push(*r);
                            }
                        }
                        (Some(b), None) => left.push(half(b)),
                        (None, Some(a)) => right.push(half(a)),
                        (None, None) => left.push(*r),
                    }
                }
                (left, right)
            }
        };
        match (left.is_empty(), right.is_empty()) {
            (false, false) => Ok((left, right)),
            (true, _) => Err(right),
            (false, true) => Err(left),
        }
    }
}

/// Bins of the three axes and the sweep's suffix sums, reused by every node a builder
/// splits: no allocation per node.
struct Scratch {
    bounds: Vec<Box3>,
    /// Object splits: references per bin. Spatial splits: references entering a bin.
    enter: Vec<u32>,
    /// Spatial splits: references leaving a bin.
    exit: Vec<u32>,
    suffix: Vec<(f32, u32)>,
    /// Spatial splits: each bin's planes (see `spatial_split`).
    slabs: Vec<(Vec3A, Vec3A)>,
}

impl Scratch {
    fn new(bins: usize) -> Self {
        Self { bounds: vec![Box3::EMPTY; 3 * bins], enter: vec![0; 3 * bins], exit: vec![0; 3 * bins], suffix: vec![(0.0, 0); bins], slabs: vec![(Vec3A::ZERO, Vec3A::ZERO); 3 * bins] }
    }

    /// Empties the first `nb` bins of each axis.
    fn clear(&mut self, nb: usize) {
        self.bounds[..3 * nb].fill(Box3::EMPTY);
        self.enter[..3 * nb].fill(0);
        self.exit[..3 * nb].fill(0);
    }

    /// The boxes left and right of plane `p` among the `nb` bins of `axis`.
    fn sides(&self, axis: usize, nb: usize, p: usize) -> (Box3, Box3) {
        let bins = &self.bounds[axis * nb..(axis + 1) * nb];
        let union = |b: &[Box3]| b.iter().fold(Box3::EMPTY, |a, &x| a.union(x));
        (union(&bins[..p]), union(&bins[p..]))
    }
}

/// `[x, y, z]` with a zero fourth lane: a PrimRef's fourth lane holds its index as a
/// tiny float, and the difference of two such, scaled, would be a denormal (a microcode
/// assist per operation: this made binning 1.5x slower). Times zero it stays zero.
fn fourth_lane_zero(v: [f32; 3]) -> Vec3A {
    Vec3A::from_vec4(glam::Vec4::new(v[0], v[1], v[2], 0.0))
}

/// [`bin_of`] on the three axes at once: `lo` and `scale` from [`fourth_lane_zero`], `top`
/// the last bin. A NaN (an infinite scale times a zero offset) becomes 0 at `max`.
#[inline]
fn bins3(x: Vec3A, lo: Vec3A, scale: Vec3A, top: Vec3A) -> [u32; 3] {
    truncate(((x - lo) * scale).max(Vec3A::ZERO).min(top))
}

#[inline]
fn bin_of(x: f32, lo: f32, scale: f32, nb: usize) -> usize {
    (((x - lo) * scale).max(0.0) as usize).min(nb - 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The vector binning of the splits gives `bin_of`'s bins on each axis, at the edges
    /// too: below the origin, on the last plane, beyond it, infinite and NaN offsets (an
    /// infinite scale times a zero offset), with a PrimRef's index in the fourth lane.
    #[test]
    fn vector_binning_matches_bin_of() {
        let nb = 16;
        let top = Vec3A::splat((nb - 1) as f32);
        let lo = [-1.0f32, 0.0, 2.5];
        let scales = [[16.0 / 3.0, 0.5, 1e-3], [f32::INFINITY, 16.0, 0.0]];
        let xs = [-1.0f32, -1.5, 0.0, 1e-30, 0.1875, 2.0, 2.999, 3.0, 1e9, f32::INFINITY, f32::NEG_INFINITY, 2.5, 5.5];
        for scale in scales {
            let (lo_v, scale_v) = (fourth_lane_zero(lo), fourth_lane_zero(scale));
            for &x in &xs {
                for &id in &[0u32, 7, 123_456] {
                    let r = PrimRef::new(Vec3A::splat(x), Vec3A::splat(x), id);
                    let bins = bins3(r.min(), lo_v, scale_v, top);
                    for a in 0..3 {
                        assert_eq!(bins[a] as usize, bin_of(x, lo[a], scale[a], nb), "x {x}, axis {a}, scale {}", scale[a]);
                    }
                }
            }
        }
    }
}
