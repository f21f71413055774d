//! Top-down builders. Subtrees are built in parallel (`rayon::join`) into a temporary
//! tree, which is then flattened depth-first with siblings adjacent, in parallel too. Below
//! [`PARALLEL_THRESHOLD`] primitives a subtree is built on one thread straight into flat
//! nodes in that layout (siblings allocated side by side, as tinybvh does), which the
//! flattening only moves: no boxed node and no second walk for most of the tree.
//!
//! Primitives travel as [`PrimRef`]s, box and index together (Embree's layout), which the
//! splits partition (stably, in parallel at the top of the tree): binning and partitioning stream through memory instead of
//! following an index into separate box and centroid arrays, and a partition hands each
//! side its box and its centroids' box, so no node reads its primitives again to bound them.
//!
//! A partition writes each side to its place in a second array as long as the first, whose
//! parts the children then use as their input, the first array's as their output (ping-pong):
//! one read and one write per primitive and level, with no copy back. A leaf whose
//! primitives end up in the second array copies them home.

use glam::Vec3A;
use rayon::prelude::*;
use raylab_core::Aabb;

use super::prim_ref::{truncate, Box3, PrimRef, MAX_PRIMS};
use super::{BvhNode, SahCost, SplitMethod, MAX_DEPTH};
use crate::{BuildOptions, Primitives};

/// Subtrees smaller than this are built on the current thread.
const PARALLEL_THRESHOLD: usize = 4096;

/// Nodes with at least this many primitives are bounded and binned in parallel (the top
/// levels of the tree, where `rayon::join` over subtrees has not yet spread the work).
const PARALLEL_BINNING: usize = 1 << 15;
const BIN_CHUNK: usize = 1 << 13;

/// Threads from which large nodes partition in parallel (see [`partition`]).
const PARALLEL_PARTITION_THREADS: usize = 4;

/// The tree above [`PARALLEL_THRESHOLD`], built by parallel tasks, whose subtrees below it
/// arrive already flat.
enum BuildNode {
    Leaf { bounds: Aabb, first: u32, count: u32 },
    /// `descendants`: the flat nodes below it, which [`flatten`] lays out.
    Interior { bounds: Aabb, children: Box<[BuildNode; 2]>, descendants: usize },
    /// A subtree built on one thread straight into flat nodes in [`flatten`]'s layout:
    /// its root first, node references counted from it.
    Flat(Vec<BvhNode>),
}

impl BuildNode {
    fn descendants(&self) -> usize {
        match self {
            BuildNode::Leaf { .. } => 0,
            BuildNode::Interior { descendants, .. } => *descendants,
            BuildNode::Flat(nodes) => nodes.len() - 1,
        }
    }
}

/// What a node needs to know of its primitives: their box and their centroids' box.
#[derive(Clone, Copy)]
struct Extent {
    geom: Box3,
    cent: Box3,
}

impl Extent {
    const EMPTY: Extent = Extent { geom: Box3::EMPTY, cent: Box3::EMPTY };

    #[inline]
    fn add(&mut self, r: &PrimRef) {
        self.geom.grow(r.min(), r.max);
        let c = r.centroid();
        self.cent.grow(c, c);
    }

    fn merge(self, o: Extent) -> Extent {
        Extent { geom: self.geom.union(o.geom), cent: self.cent.union(o.cent) }
    }

    /// Bounds `refs`, in parallel for large slices (unions are exact: the same boxes
    /// whatever the split of the work).
    fn of(refs: &[PrimRef]) -> Extent {
        let serial = |part: &[PrimRef]| {
            let mut e = Extent::EMPTY;
            part.iter().for_each(|r| e.add(r));
            e
        };
        if refs.len() < PARALLEL_BINNING {
            return serial(refs);
        }
        refs.par_chunks(BIN_CHUNK).map(serial).reduce(|| Extent::EMPTY, Extent::merge)
    }
}

/// The part of a leaf's cost that grows with its triangles when the SAH counts in blocks.
/// Counting blocks alone, a leaf of one large triangle and three small ones costs what the
/// large one alone costs, so it is never split; rays that reach the large triangle then
/// test the small ones' block too, and renders of scenes with large walls or floors next
/// to small triangles got 1.1-1.25x slower (docs/performance.md, "Ninth round"). Splitting
/// off the large triangle costs one traversal step and saves `c(4) - c(1)`, three times
/// this share: just above a third, splitting wins.
const PER_TRIANGLE: f32 = 0.35;

struct Ctx {
    method: SplitMethod,
    sah: SahCost,
    max_leaf: usize,
    bins: usize,
    /// [`BuildOptions::leaf_block`] (rounded up to a power of two) and its log: the sweep
    /// counts blocks with a shift instead of an integer division per plane.
    block: usize,
    block_log: u32,
    /// [`PER_TRIANGLE`] when counting in blocks, else 0.
    per_triangle: f32,
}

impl Ctx {
    fn new(method: SplitMethod, opts: &BuildOptions) -> Self {
        let block = opts.leaf_block.max(1).next_power_of_two();
        let per_triangle = if block > 1 { PER_TRIANGLE } else { 0.0 };
        Ctx { method, sah: SahCost::from_options(opts), max_leaf: opts.max_leaf_size.max(1), bins: opts.bins.clamp(2, 256), block, block_log: block.trailing_zeros(), per_triangle }
    }

    /// The tests a side of `n` primitives costs: `n`, or in blocks, one per block plus
    /// [`PER_TRIANGLE`] per triangle.
    #[inline]
    fn blocks(&self, n: usize) -> f32 {
        // Through `u32` (counts stay below 2³⁰): converting a `usize` to a float costs a
        // branch on its top bit without AVX-512.
        ((n + self.block - 1) >> self.block_log) as u32 as f32 + self.per_triangle * n as u32 as f32
    }
}

/// Nodes counted in blocks of at most this many primitives are split by trying every cut
/// ([`Ctx::split_tiny`]).
const TINY: usize = 4;

/// A split: the size of the left part (now in front) and the extents of both parts.
type Split = (usize, Extent, Extent);

pub(super) fn build<P: Primitives + ?Sized>(prims: &P, method: SplitMethod, opts: &BuildOptions) -> (Vec<BvhNode>, Vec<u32>) {
    let n = prims.len();
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    assert!(n < MAX_PRIMS, "BVH: more than 2^30 primitives");
    let mut refs: Vec<PrimRef> = (0..n as u32)
        .into_par_iter()
        .map(|i| {
            let b = prims.bounds(i);
            PrimRef::new(b.min.into(), b.max.into(), i)
        })
        .collect();
    let ctx = Ctx::new(method, opts);
    let extent = Extent::of(&refs);
    // The partitions' second array, allocated (and its pages touched, in parallel) once
    // rather than grown and faulted in at every large node.
    let mut spare: Vec<PrimRef> = if n >= PARALLEL_THRESHOLD { refs.par_iter().copied().collect() } else { refs.clone() };
    let root = ctx.build(Halves { refs: &mut refs, spare: &mut spare, home: true }, extent, 0, 1, &mut Scratch::new(ctx.bins));
    let mut nodes: Vec<BvhNode> = (0..1 + root.descendants()).into_par_iter().map(|_| BvhNode::interior(Aabb::EMPTY, 0)).collect();
    let (top, below) = nodes.split_at_mut(1);
    top[0] = flatten(root, 1, below);
    (nodes, refs.par_iter().map(PrimRef::id).collect())
}

/// Lays out `node`'s subtree depth-first with siblings adjacent in `below` (whose first
/// element is flat node `base`): its two children first, then the left child's
/// descendants, then the right's. Returns `node` as a flat node. Subtrees are laid out in
/// parallel (each writes its own part of `below`), in the serial order.
fn flatten(node: BuildNode, base: usize, below: &mut [BvhNode]) -> BvhNode {
    match node {
        BuildNode::Leaf { bounds, first, count } => BvhNode::leaf(bounds, first, count),
        BuildNode::Flat(nodes) => {
            // Node k ≥ 1 of the subtree lands at `base + k - 1`.
            let moved = |n: &BvhNode| if n.is_leaf() { *n } else { BvhNode { left_first: n.left_first + base as u32 - 1, ..*n } };
            for (to, n) in below.iter_mut().zip(&nodes[1..]) {
                *to = moved(n);
            }
            moved(&nodes[0])
        }
        BuildNode::Interior { bounds, children, descendants } => {
            let [l, r] = *children;
            let (pair, rest) = below.split_at_mut(2);
            let (l_below, r_below) = rest.split_at_mut(l.descendants());
            let (l_base, r_base) = (base + 2, base + 2 + l.descendants());
            (pair[0], pair[1]) = if descendants >= PARALLEL_THRESHOLD {
                rayon::join(|| flatten(l, l_base, l_below), || flatten(r, r_base, r_below))
            } else {
                (flatten(l, l_base, l_below), flatten(r, r_base, r_below))
            };
            BvhNode::interior(bounds, base as u32)
        }
    }
}

/// Per-thread working memory of the binned SAH, allocated once per subtree built on a
/// thread of its own rather than once per node.
struct Scratch {
    bins: Bins,
    /// Per plane, the right side's primitives and its area times their test count.
    right_count: Vec<usize>,
    right_cost: Vec<f32>,
}

impl Scratch {
    fn new(nb: usize) -> Self {
        Self { bins: Bins::new(nb), right_count: vec![0; nb], right_cost: vec![0.0; nb] }
    }
}

/// A subtree's primitives (`refs`) and the same range of the other array (`spare`, as
/// long): `home` when `refs` lies in the output array, which the leaves must fill.
struct Halves<'a> {
    refs: &'a mut [PrimRef],
    spare: &'a mut [PrimRef],
    home: bool,
}

impl<'a> Halves<'a> {
    /// A leaf: its primitives, copied into the output array when they lie in the other.
    fn settle(self) {
        if !self.home {
            self.spare.copy_from_slice(self.refs);
        }
    }

    /// The two children's halves after a split of `mid` on the left that `moved` the
    /// primitives into `spare` (or left them in `refs`).
    fn children(self, mid: usize, moved: bool) -> (Halves<'a>, Halves<'a>) {
        let (from, to, home) = if moved { (self.spare, self.refs, !self.home) } else { (self.refs, self.spare, self.home) };
        let ((lf, rf), (lt, rt)) = (from.split_at_mut(mid), to.split_at_mut(mid));
        (Halves { refs: lf, spare: lt, home }, Halves { refs: rf, spare: rt, home })
    }
}

impl Ctx {
    /// Builds the subtree over `h.refs` (bounded by `extent`), whose first element sits at
    /// `offset` in the final primitive order.
    fn build(&self, mut h: Halves, extent: Extent, offset: usize, depth: usize, scratch: &mut Scratch) -> BuildNode {
        let n = h.refs.len();
        if n < PARALLEL_THRESHOLD {
            let mut nodes = Vec::with_capacity(n);
            nodes.push(BvhNode::interior(Aabb::EMPTY, 0));
            self.build_flat(h, extent, offset, depth, scratch, &mut nodes, 0);
            return BuildNode::Flat(nodes);
        }
        let bounds = extent.geom.aabb();
        let split = if n <= 1 || depth >= MAX_DEPTH { None } else { self.split(&mut h, &extent, scratch) };
        let Some(((mid, le, re), moved)) = split else {
            h.settle();
            return BuildNode::Leaf { bounds, first: offset as u32, count: n as u32 };
        };
        let (l, r) = h.children(mid, moved);
        let (left, right) = rayon::join(|| self.build(l, le, offset, depth + 1, scratch), || self.build(r, re, offset + mid, depth + 1, &mut Scratch::new(self.bins)));
        let descendants = 2 + left.descendants() + right.descendants();
        BuildNode::Interior { bounds, children: Box::new([left, right]), descendants }
    }

    /// [`Ctx::build`] on this thread, writing node `at` of `nodes` and appending its
    /// subtree as [`flatten`] lays it out: the two children side by side, then the left
    /// child's subtree, then the right's (tinybvh's order of allocation).
    #[allow(clippy::too_many_arguments)]
    fn build_flat(&self, mut h: Halves, extent: Extent, offset: usize, depth: usize, scratch: &mut Scratch, nodes: &mut Vec<BvhNode>, at: usize) {
        let (bounds, n) = (extent.geom.aabb(), h.refs.len());
        let split = if n <= 1 || depth >= MAX_DEPTH { None } else { self.split(&mut h, &extent, scratch) };
        let Some(((mid, le, re), moved)) = split else {
            h.settle();
            nodes[at] = BvhNode::leaf(bounds, offset as u32, n as u32);
            return;
        };
        let pair = nodes.len();
        nodes.extend([BvhNode::interior(Aabb::EMPTY, 0); 2]);
        nodes[at] = BvhNode::interior(bounds, pair as u32);
        let (l, r) = h.children(mid, moved);
        self.build_flat(l, le, offset, depth + 1, scratch, nodes, pair);
        self.build_flat(r, re, offset + mid, depth + 1, scratch, nodes, pair + 1);
    }

    /// Splits `h.refs`, or `None` for a leaf; the flag says whether the primitives moved
    /// to `h.spare` (a partition) or were reordered in place.
    fn split(&self, h: &mut Halves, extent: &Extent, scratch: &mut Scratch) -> Option<(Split, bool)> {
        let refs = &mut *h.refs;
        let cb = extent.cent.aabb();
        let axis = cb.max_axis();
        if cb.max[axis] - cb.min[axis] <= 0.0 {
            // All centroids coincide: no plane separates them. Split by index only when the
            // leaf would be too large, so leaves stay bounded.
            return (refs.len() > self.max_leaf).then(|| (halves(refs, refs.len() / 2), false));
        }
        match self.method {
            SplitMethod::BinnedSah if refs.len() <= TINY.min(self.block) => self.split_tiny(refs, extent).map(|s| (s, false)),
            SplitMethod::BinnedSah => self.split_sah(h, extent, scratch).map(|s| (s, true)),
            SplitMethod::Median => (refs.len() > self.max_leaf).then(|| (split_median(refs, axis), false)),
            SplitMethod::Midpoint => {
                if refs.len() <= self.max_leaf {
                    return None;
                }
                let mid = 0.5 * (cb.min[axis] + cb.max[axis]);
                let left = |r: &PrimRef| r.centroid()[axis] < mid;
                let m = refs.iter().filter(|r| left(r)).count();
                if m == 0 || m == refs.len() {
                    return Some((split_median(refs, axis), false));
                }
                Some((partition(refs, h.spare, m, left), true))
            }
        }
    }

    /// The binned SAH's choice for a node of at most [`TINY`] primitives, made by trying
    /// every way to cut them in two (at most seven) instead of binning: half the nodes are
    /// this small when counting in blocks, and there clearing, filling and sweeping bins
    /// cost more than the exact answer. Reorders `refs` in place, the left side first.
    fn split_tiny(&self, refs: &mut [PrimRef], extent: &Extent) -> Option<Split> {
        let n = refs.len();
        debug_assert!((2..=TINY).contains(&n));
        let pa = extent.geom.half_area();
        let flat = pa <= 0.0;
        let weight = |b: &Box3| if flat { 1.0 } else { b.half_area() };
        // The union of every subset of the primitives, by its mask: each from the subset
        // without its lowest member, with no branch on the masks' bits.
        let mut union = [Box3::EMPTY; 1 << TINY];
        for mask in 1..1usize << n {
            let low = mask.trailing_zeros() as usize;
            union[mask] = union[mask & (mask - 1)].union(refs[low].bounds());
        }
        let all = (1usize << n) - 1;
        // The last primitive always on the right: each cut once.
        let (mut best_x, mut best_mask) = (f32::INFINITY, 0);
        for mask in 1..1usize << (n - 1) {
            let nl = mask.count_ones() as usize;
            let x = weight(&union[mask]) * self.blocks(nl) + weight(&union[all ^ mask]) * self.blocks(n - nl);
            if x < best_x {
                (best_x, best_mask) = (x, mask);
            }
        }
        let best_cost = self.sah.traversal + self.sah.intersection * if flat { best_x } else { best_x / pa };
        if best_cost >= self.sah.intersection * self.blocks(n) && n <= self.max_leaf {
            return None;
        }
        let mut copy = [refs[0]; TINY];
        copy[..n].copy_from_slice(refs);
        let left = |i: &usize| best_mask >> i & 1 != 0;
        for (to, i) in refs.iter_mut().zip((0..n).filter(left).chain((0..n).filter(|i| !left(i)))) {
            *to = copy[i];
        }
        Some(halves(refs, best_mask.count_ones() as usize))
    }

    /// Binned SAH over all three axes (Wald 2007, "On fast Construction of SAH-based
    /// Bounding Volume Hierarchies"): centroids fall into `bins` equal bins per axis; the
    /// `bins - 1` planes between bins are evaluated by a prefix/suffix sweep.
    fn split_sah(&self, h: &mut Halves, extent: &Extent, scratch: &mut Scratch) -> Option<Split> {
        let refs = &*h.refs;
        // Fewer bins for small nodes, as Embree does (4 + n/20, at most `bins`): most nodes
        // are small, and there clearing and sweeping the bins cost more than binning.
        let nb = self.bins.min(4 + refs.len() / 20);
        let cb = &extent.cent;
        let scale = Vec3A::select((cb.max - cb.min).cmpgt(Vec3A::ZERO), Vec3A::splat(nb as f32) / (cb.max - cb.min), Vec3A::ZERO);
        let bins = &mut scratch.bins;
        bins.clear(nb);
        if refs.len() < PARALLEL_BINNING {
            bins.add(refs, nb, cb.min, scale);
        } else {
            let parts = refs.par_chunks(BIN_CHUNK).map(|part| {
                let mut b = Bins::new(nb);
                b.add(part, nb, cb.min, scale);
                b
            });
            *bins = parts.reduce(|| Bins::new(nb), Bins::merge);
        }
        let (right_count, right_cost) = (&mut scratch.right_count, &mut scratch.right_cost);
        // Planes are compared by their children's area-weighted test counts, `x`; the
        // parent's area and the constants enter once, for the best. A flat parent (zero
        // area): every ray that hits it hits both children, so they weigh 1 each.
        let pa = extent.geom.half_area();
        let flat = pa <= 0.0;
        let weight = |b: &Box3| if flat { 1.0 } else { b.half_area() };
        // The cheapest plane so far: (x, axis, plane, primitives on its left); `axis == 3`
        // while there is none.
        let (mut best_x, mut best_axis, mut best_plane, mut best_left) = (f32::INFINITY, 3, 0, 0);
        for axis in 0..3 {
            if scale[axis] == 0.0 {
                continue;
            }
            let (bin_bounds, bin_count) = (&bins.bounds[axis * nb..(axis + 1) * nb], &bins.count[axis * nb..(axis + 1) * nb]);
            let (mut acc, mut cnt) = (Box3::EMPTY, 0);
            for p in (1..nb).rev() {
                acc = acc.union(bin_bounds[p]);
                cnt += bin_count[p];
                right_count[p] = cnt;
                right_cost[p] = weight(&acc) * self.blocks(cnt);
            }
            let (mut acc, mut cnt) = (Box3::EMPTY, 0);
            for p in 1..nb {
                acc = acc.union(bin_bounds[p - 1]);
                cnt += bin_count[p - 1];
                if cnt == 0 || right_count[p] == 0 {
                    continue;
                }
                let x = weight(&acc) * self.blocks(cnt) + right_cost[p];
                if best_axis == 3 || x < best_x {
                    (best_x, best_axis, best_plane, best_left) = (x, axis, p, cnt);
                }
            }
        }
        let best_cost = self.sah.traversal + self.sah.intersection * if flat { best_x } else { best_x / pa };
        let (axis, plane) = (best_axis, best_plane);
        if axis == 3 || (best_cost >= self.sah.intersection * self.blocks(refs.len()) && refs.len() <= self.max_leaf) {
            return None;
        }
        // Bin `⌊clamp((c - lo) · s, 0, nb - 1)⌋ < plane` as one comparison: the plane is a
        // whole number at most `nb - 1`, and a NaN falls in bin 0, on the left. It is the
        // binning's arithmetic, so exactly the `best_left` primitives binned left go left.
        let (lo, s, plane_f) = (cb.min[axis], scale[axis], plane as f32);
        #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x >= p)`, not `x < p`: a NaN goes left.
        let split = partition(refs, h.spare, best_left, |r| !((r.centroid()[axis] - lo) * s >= plane_f));
        debug_assert!(split.0 > 0 && split.0 < refs.len());
        Some(split)
    }
}

/// Splits at the object median along `axis` (ties in any order).
fn split_median(refs: &mut [PrimRef], axis: usize) -> Split {
    let mid = refs.len() / 2;
    refs.select_nth_unstable_by(mid, |a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
    halves(refs, mid)
}

/// Splits at `mid` as the primitives lie.
fn halves(refs: &[PrimRef], mid: usize) -> Split {
    (mid, Extent::of(&refs[..mid]), Extent::of(&refs[mid..]))
}

/// Bins of the three axes, `nb` per axis (axis-major, in the first `3 nb` entries): the union of the boxes whose
/// centroid falls in each bin, and their count.
///
/// Binning keeps [`SETS`] sets of bins, primitive `i` going to set `i mod SETS` (two sets
/// below [`FOUR_SETS`] primitives), and folds the others into the first at the end of
/// [`Bins::add`]. Consecutive primitives of a mesh often fall in the same bin, and each
/// update of a bin then waits for the previous one's store to reach its load (store
/// forwarding plus the `min`/`max`): with several sets, that many such chains run side by
/// side.
struct Bins {
    bounds: Vec<Box3>,
    count: Vec<usize>,
    /// Where each further set starts: `3 nb` of the largest `nb` the bins were made for.
    stride: usize,
}

/// Sets of bins (see [`Bins`]).
const SETS: usize = 4;

/// Nodes from this many primitives bin into all [`SETS`] sets; smaller ones into two, whose
/// fold costs less.
const FOUR_SETS: usize = 128;

/// Where a centroid falls: bin `⌊clamp((c - lo) · scale, 0, nb - 1)⌋` on each axis.
struct Binning {
    lo: Vec3A,
    scale: Vec3A,
    top: Vec3A,
    nb: usize,
}

impl Binning {
    /// Bins `refs` into the first `S` sets, primitive `i` into set `i mod S`; returns `S`.
    #[inline(always)]
    fn add_in_sets<const S: usize>(&self, refs: &[PrimRef], bounds: &mut [&mut [Box3]; SETS], count: &mut [&mut [usize]; SETS]) -> usize {
        let mut groups = refs.chunks_exact(S);
        for group in &mut groups {
            for s in 0..S {
                self.bin(&group[s], bounds[s], count[s]);
            }
        }
        for (s, r) in groups.remainder().iter().enumerate() {
            self.bin(r, bounds[s], count[s]);
        }
        S
    }

    #[inline(always)]
    fn bin(&self, r: &PrimRef, bounds: &mut [Box3], count: &mut [usize]) {
        // In [0, nb - 1]: a NaN became 0 at `max`.
        let bin = truncate(((r.centroid() - self.lo) * self.scale).max(Vec3A::ZERO).min(self.top));
        for (axis, b) in bin.into_iter().enumerate() {
            let k = axis * self.nb + b as usize;
            bounds[k].grow(r.min(), r.max);
            count[k] += 1;
        }
    }
}

impl Bins {
    fn new(nb: usize) -> Self {
        Self { bounds: vec![Box3::EMPTY; SETS * 3 * nb], count: vec![0; SETS * 3 * nb], stride: 3 * nb }
    }

    /// Empties the first `nb` bins of each axis (the other sets are empty between calls).
    fn clear(&mut self, nb: usize) {
        self.bounds[..3 * nb].fill(Box3::EMPTY);
        self.count[..3 * nb].fill(0);
    }

    /// Bins `refs` along the three axes of the centroid box starting at `lo` with `scale`
    /// bins per unit (0 on axes of zero extent, whose bins are then never read). Unions and
    /// counts are exact, so splitting the work over threads or sets gives the same bins,
    /// hence the same tree, whatever the thread count.
    #[inline]
    fn add(&mut self, refs: &[PrimRef], nb: usize, lo: Vec3A, scale: Vec3A) {
        let at = Binning { lo, scale, top: Vec3A::splat((nb - 1) as f32), nb };
        let stride = self.stride;
        let mut bounds: [&mut [Box3]; SETS] = Default::default();
        let mut count: [&mut [usize]; SETS] = Default::default();
        for ((b, c), (set_b, set_c)) in bounds.iter_mut().zip(&mut count).zip(self.bounds.chunks_exact_mut(stride).zip(self.count.chunks_exact_mut(stride))) {
            (*b, *c) = (&mut set_b[..3 * nb], &mut set_c[..3 * nb]);
        }
        let sets = if refs.len() >= FOUR_SETS { at.add_in_sets::<SETS>(refs, &mut bounds, &mut count) } else { at.add_in_sets::<2>(refs, &mut bounds, &mut count) };
        let [first, rest @ ..] = &mut bounds;
        let [first_count, rest_count @ ..] = &mut count;
        for (more, more_count) in rest[..sets - 1].iter_mut().zip(&mut rest_count[..sets - 1]) {
            for k in 0..3 * nb {
                first[k] = first[k].union(std::mem::replace(&mut more[k], Box3::EMPTY));
                first_count[k] += std::mem::take(&mut more_count[k]);
            }
        }
    }

    /// Adds `o`'s bins to these (first sets only: the others are empty between calls).
    fn merge(mut self, o: Bins) -> Bins {
        for (a, b) in self.bounds[..self.stride].iter_mut().zip(&o.bounds[..o.stride]) {
            *a = a.union(*b);
        }
        for (a, b) in self.count[..self.stride].iter_mut().zip(&o.count[..o.stride]) {
            *a += b;
        }
        self
    }
}

/// Writes the `m` primitives of `src` for which `left` holds to the front of `dst` and the
/// others behind them, both sides in their input order (a stable partition); returns `m`
/// and both sides' extents. Nodes of [`PARALLEL_BINNING`] primitives or more (the top of
/// the tree, where few subtrees run side by side) partition in parallel when there are
/// [`PARALLEL_PARTITION_THREADS`] threads: the parallel partition makes two passes over
/// memory to the serial one's one, and pays off only then. Both give the same order, so
/// the tree does not depend on it.
///
/// # Panics
/// When `left` holds for other than `m` primitives (the caller counted them).
fn partition(src: &[PrimRef], dst: &mut [PrimRef], m: usize, left: impl Fn(&PrimRef) -> bool + Sync) -> Split {
    debug_assert_eq!(src.len(), dst.len());
    if src.len() >= PARALLEL_BINNING && rayon::current_num_threads() >= PARALLEL_PARTITION_THREADS {
        partition_parallel(src, dst, m, left)
    } else {
        partition_serial(src, dst, m, left)
    }
}

/// One sweep, each primitive read once and written once.
fn partition_serial(src: &[PrimRef], dst: &mut [PrimRef], m: usize, left: impl Fn(&PrimRef) -> bool) -> Split {
    let (lefts, rights) = dst.split_at_mut(m);
    let (le, re, written) = scatter(src, lefts, rights, &left);
    assert_eq!(written, m, "partition: the left side's count");
    (m, le, re)
}

/// A stable partition in chunks of [`BIN_CHUNK`]: each chunk counts its left side, prefix
/// sums of the counts give each chunk its place on either side, and the chunks then write
/// their primitives there side by side, bounding both sides. Both sides keep the input
/// order, so the result does not depend on the thread count.
fn partition_parallel(src: &[PrimRef], dst: &mut [PrimRef], m: usize, left: impl Fn(&PrimRef) -> bool + Sync) -> Split {
    let counts: Vec<usize> = src.par_chunks(BIN_CHUNK).map(|chunk| chunk.iter().filter(|r| left(r)).count()).collect();
    assert_eq!(counts.iter().sum::<usize>(), m, "partition: the left side's count");
    let (mut lefts, mut rights) = dst.split_at_mut(m);
    let mut places = Vec::with_capacity(counts.len());
    for (chunk, &cm) in src.chunks(BIN_CHUNK).zip(&counts) {
        let (l, l_rest) = std::mem::take(&mut lefts).split_at_mut(cm);
        let (r, r_rest) = std::mem::take(&mut rights).split_at_mut(chunk.len() - cm);
        places.push((l, r));
        (lefts, rights) = (l_rest, r_rest);
    }
    let (le, re) = src
        .par_chunks(BIN_CHUNK)
        .zip(places)
        .map(|(chunk, (l, r))| {
            let (le, re, _) = scatter(chunk, l, r, &left);
            (le, re)
        })
        .reduce(|| (Extent::EMPTY, Extent::EMPTY), |(a, b), (c, d)| (a.merge(c), b.merge(d)));
    (m, le, re)
}

/// Writes the primitives of `src` for which `left` holds to the front of `lefts` and the
/// others to the front of `rights`, each side in input order; returns both sides' extents
/// and the count written left. Panics when a side does not fit its slice.
#[inline(always)]
fn scatter(src: &[PrimRef], lefts: &mut [PrimRef], rights: &mut [PrimRef], left: &impl Fn(&PrimRef) -> bool) -> (Extent, Extent, usize) {
    let (mut le, mut re) = (Extent::EMPTY, Extent::EMPTY);
    let (mut i, mut j) = (0, 0);
    for r in src {
        if left(r) {
            le.add(r);
            lefts[i] = *r;
            i += 1;
        } else {
            re.add(r);
            rights[j] = *r;
            j += 1;
        }
    }
    (le, re, i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extents_equal(a: &Extent, b: &Extent) -> bool {
        let eq = |x: &Box3, y: &Box3| x.min == y.min && x.max == y.max;
        eq(&a.geom, &b.geom) && eq(&a.cent, &b.cent)
    }

    /// Binning in several sets gives the bins of one set, primitive by primitive, also over
    /// calls that reuse the bins (the other sets must be folded and emptied each time), for
    /// counts that no set count divides, in two sets and in four.
    #[test]
    fn several_sets_bin_as_one() {
        let mut rng = raylab_core::Pcg32::new(7, 1);
        let mut next = move || rng.next_f32();
        let nb = 9;
        let (lo, scale) = (Vec3A::ZERO, Vec3A::splat(nb as f32 / 10.0));
        let mut bins = Bins::new(16);
        for n in [1, 2, 7, 127, 1000, 1001, 1003] {
            let refs: Vec<PrimRef> = (0..n as u32)
                .map(|id| {
                    let min = Vec3A::new(next(), next(), next()) * 9.0;
                    PrimRef::new(min, min + Vec3A::new(next(), next(), next()), id)
                })
                .collect();
            bins.clear(nb);
            bins.add(&refs, nb, lo, scale);
            let (mut want_bounds, mut want_count) = (vec![Box3::EMPTY; 3 * nb], vec![0; 3 * nb]);
            for r in &refs {
                for (axis, b) in truncate(((r.centroid() - lo) * scale).max(Vec3A::ZERO).min(Vec3A::splat((nb - 1) as f32))).into_iter().enumerate() {
                    want_bounds[axis * nb + b as usize].grow(r.min(), r.max);
                    want_count[axis * nb + b as usize] += 1;
                }
            }
            assert_eq!(&bins.count[..3 * nb], &want_count[..], "{n} primitives");
            assert!(bins.bounds[..3 * nb].iter().zip(&want_bounds).all(|(a, b)| a.min == b.min && a.max == b.max), "{n} primitives");
        }
    }

    /// Both partitions are the stable one: lefts then rights, each in input order, with the
    /// extents of exactly those primitives, across chunk boundaries and at the edges
    /// (nothing on one side).
    #[test]
    fn partitions_are_stable_and_bound_both_sides() {
        let mut rng = raylab_core::Pcg32::new(99, 0);
        let mut next = move || rng.next_f32();
        let n = 3 * BIN_CHUNK + 5;
        let input: Vec<PrimRef> = (0..n as u32)
            .map(|id| {
                let min = Vec3A::new(next(), next(), next()) * 100.0;
                PrimRef::new(min, min + Vec3A::new(next(), next(), next()), id)
            })
            .collect();
        for cut in [-1.0, 30.0, 50.0, 101.0] {
            let left = |r: &PrimRef| r.centroid().x < cut;
            let count = input.iter().filter(|r| left(r)).count();
            let mut refs = input.clone();
            let (m, le, re) = partition_parallel(&input, &mut refs, count, left);
            let mut serial = input.clone();
            let (ms, les, res) = partition_serial(&input, &mut serial, count, left);
            assert!(serial.iter().map(PrimRef::id).eq(refs.iter().map(PrimRef::id)) && ms == m, "cut {cut}: the serial partition's order");
            assert!(extents_equal(&les, &le) && extents_equal(&res, &re));
            let want: Vec<u32> = input.iter().filter(|r| left(r)).chain(input.iter().filter(|r| !left(r))).map(PrimRef::id).collect();
            assert_eq!(refs.iter().map(PrimRef::id).collect::<Vec<_>>(), want, "cut {cut}");
            assert_eq!(m, input.iter().filter(|r| left(r)).count());
            let bound = |part: &[PrimRef]| part.iter().fold(Extent::EMPTY, |mut e, r| {
                e.add(r);
                e
            });
            assert!(extents_equal(&le, &bound(&refs[..m])) && extents_equal(&re, &bound(&refs[m..])), "cut {cut}");
        }
    }
}
