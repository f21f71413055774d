//! Binary tree → `W`-wide tree by a cost-driven collapse (after Ylitie, Karras & Laine 2017,
//! "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", §4.1): a
//! dynamic programme over the binary tree chooses, for every subtree, whether it becomes a
//! leaf (one or more blocks of four triangles), one wide node, or is spread over several of
//! its parent's `W` slots, so as to minimise the SAH cost the statistics report: each wide
//! node charged its surface area, each leaf its area times its blocks (the units the
//! traversal tests), relative to the root. Embree's greedy rule (open the child of largest
//! area until `W` children) is one of the trees it considers, so the cost never rises.
//! Subtrees of at most [`LEAF_PRIMS`] references may become leaves (two blocks); binary
//! leaves always do. The plan also sizes what every subtree emits, so the output is
//! allocated once and subtrees are emitted in parallel straight into their parts of it.

use rayon::prelude::*;
use raylab_core::Aabb;

use super::node::{leaf_ref, node_ref, ChildRef, TriBlock, WideNode, EMPTY, MAX_BLOCKS, MAX_LEAF_BLOCKS, NODE_UNIT};
use crate::bvh::{Bvh, BvhNode};
use crate::par::DisjointSlice;
use crate::Primitives;

/// Subtrees of at most this many references may become a single leaf (two [`TriBlock`]s).
pub const LEAF_PRIMS: usize = 8;

/// Wide nodes over at least this many references emit their children's subtrees as
/// parallel tasks, each into its own part of the output (sized by the plan): the serial
/// emission's layout, whatever the thread count.
const FORK_REFS: usize = 16 * 1024;

/// The plan's bottom-up pass forks at binary nodes above this depth.
const FORK_DEPTH: usize = 12;

pub(super) struct Collapsed<const W: usize> {
    pub nodes: Vec<WideNode<W>>,
    pub blocks: Vec<TriBlock>,
    pub root: ChildRef,
    pub root_bounds: Aabb,
}

struct Ctx<'a, P: ?Sized, const W: usize> {
    bin: &'a [BvhNode],
    indices: &'a [u32],
    prims: &'a P,
    /// The dynamic programme's choices per binary node (see [`plan`]).
    plan: Vec<Plan<W>>,
    fork_refs: usize,
    /// A node's size in the final layout, in [`NODE_UNIT`]s: interior references are
    /// offsets ([`node_ref`]).
    stride: usize,
}

/// What a subtree emits: wide nodes and triangle blocks. The plan knows it before anything
/// is emitted, so the output is allocated once and every subtree writes its own part of it.
#[derive(Clone, Copy, Default, Debug, PartialEq)]
struct Size {
    nodes: u32,
    blocks: u32,
}

impl std::ops::Add for Size {
    type Output = Size;
    fn add(self, o: Size) -> Size {
        Size { nodes: self.nodes + o.nodes, blocks: self.blocks + o.blocks }
    }
}

/// What a leaf of `refs` references emits (see [`Ctx::leaf`]): its blocks, or a wide node
/// over chunks when they are too many for one reference.
fn leaf_size<const W: usize>(refs: usize) -> Size {
    let blocks = refs.div_ceil(4);
    if blocks <= MAX_LEAF_BLOCKS {
        return Size { nodes: 0, blocks: blocks as u32 };
    }
    let per = refs.div_ceil(W);
    let (full, rest) = (refs / per, refs % per);
    let mut size = Size { nodes: 1, blocks: 0 };
    for _ in 0..full {
        size = size + leaf_size::<W>(per);
    }
    if rest > 0 {
        size = size + leaf_size::<W>(rest);
    }
    size
}

/// The part of the output one subtree writes: its nodes and blocks, and where they start in
/// the whole output (references are absolute).
struct Part<'o, const W: usize> {
    nodes: &'o mut [WideNode<W>],
    blocks: &'o mut [TriBlock],
    node_base: usize,
    block_base: usize,
}

impl<'o, const W: usize> Part<'o, W> {
    /// Splits off the first `size` of this part for a subtree; `self` keeps the rest.
    fn take(&mut self, size: Size) -> Part<'o, W> {
        let (nodes, rest_n) = std::mem::take(&mut self.nodes).split_at_mut(size.nodes as usize);
        let (blocks, rest_b) = std::mem::take(&mut self.blocks).split_at_mut(size.blocks as usize);
        let head = Part { nodes, blocks, node_base: self.node_base, block_base: self.block_base };
        (self.nodes, self.blocks) = (rest_n, rest_b);
        self.node_base += size.nodes as usize;
        self.block_base += size.blocks as usize;
        head
    }
}

/// The wide tree of `bvh`, its interior references pointing into a layout of nodes `N`
/// (which encodes the returned f32 nodes one for one).
pub(super) fn collapse<P: Primitives + ?Sized, const W: usize, N>(bvh: &Bvh, prims: &P) -> Collapsed<W> {
    collapse_forking::<P, W, N>(bvh, prims, FORK_REFS)
}

/// [`collapse`], emitting the children of wide nodes over `fork_refs` references or more
/// as parallel tasks (tests compare forking everywhere with never).
fn collapse_forking<P: Primitives + ?Sized, const W: usize, N>(bvh: &Bvh, prims: &P, fork_refs: usize) -> Collapsed<W> {
    assert!(prims.len() < TriBlock::OTHER as usize, "wide BVH: more than 2^31 primitives");
    let bin = &bvh.nodes[..];
    if bin.is_empty() {
        return Collapsed { nodes: Vec::new(), blocks: Vec::new(), root: EMPTY, root_bounds: Aabb::EMPTY };
    }
    // Spatial splits may put one primitive in two leaves of a merged subtree, which then
    // holds it once: the plan counts such leaves' distinct references.
    let distinct = bvh.spatial_splits.then_some(&bvh.indices[..]);
    let plan = plan::<W>(bin, distinct);
    let size = plan[0].size;
    assert!(size.blocks as usize <= MAX_BLOCKS, "wide BVH: too many triangle blocks");
    // Every node's reference stays below the leaf flag.
    node_ref::<N>(size.nodes as usize);
    let ctx = Ctx { bin, indices: &bvh.indices, prims, plan, fork_refs, stride: std::mem::size_of::<N>() / NODE_UNIT };
    // Filled in parallel: tens of MiB written (and their pages faulted in) by one thread
    // were a third of the collapse's time at 16 threads.
    let mut nodes: Vec<WideNode<W>> = (0..size.nodes as usize).into_par_iter().map(|_| WideNode::EMPTY_NODE).collect();
    let mut blocks: Vec<TriBlock> = (0..size.blocks as usize).into_par_iter().map(|_| TriBlock::EMPTY_BLOCK).collect();
    let root = ctx.child(0, Part { nodes: &mut nodes, blocks: &mut blocks, node_base: 0, block_base: 0 }, &mut Vec::new());
    Collapsed { nodes, blocks, root, root_bounds: bin[0].bounds() }
}

/// What the dynamic programme chose for one binary node.
#[derive(Clone, Copy)]
struct Plan<const W: usize> {
    /// Whole, as one slot of its parent: a leaf (else a wide node).
    leaf: bool,
    /// `split[j - 1]`, for at most `j` slots: 0 to keep the subtree whole in one slot, else
    /// `k`, the slots its left child spreads over (the right child takes `j - k`). For
    /// `j = W` and an interior node, `wide[..]` below is what its own wide node holds.
    split: [u8; W],
    /// When whole and not a leaf: the left child's share of the wide node's `W` slots.
    wide: u8,
    /// The subtree's cost, whole (the root's is the tree's SAH cost, times the root's area).
    /// Only the tests read it back, to check the programme's sums by hand; other builds
    /// leave it out (24 bytes per binary node instead of 28).
    #[cfg(test)]
    cost: f32,
    /// References below the node.
    refs: u32,
    /// What the subtree emits, whole.
    size: Size,
}

#[cfg(not(test))]
const _: () = assert!(std::mem::size_of::<Plan<8>>() == 24);

/// The dynamic programme, children before parents. `cost[j - 1]` is the least cost of a
/// subtree spread over at most `j` slots of its parent; a wide node costs its area, a leaf
/// its area times its blocks. Subtrees near the root are planned in parallel. `distinct`:
/// the leaves' references when they may repeat (spatial splits), to size leaves by the
/// primitives they hold once.
fn plan<const W: usize>(bin: &[BvhNode], distinct: Option<&[u32]>) -> Vec<Plan<W>> {
    let mut plan: Vec<Plan<W>> = (0..bin.len()).into_par_iter().map(|_| Plan { leaf: true, split: [0; W], wide: 0, #[cfg(test)] cost: 0.0, refs: 0, size: Size::default() }).collect();
    if !bin.is_empty() {
        plan_subtree(bin, distinct, 0, 0, &DisjointSlice::new(&mut plan));
    }
    plan
}

/// The distinct references of subtree `i` (see [`plan`]), or `refs` when they cannot repeat.
fn distinct_refs(bin: &[BvhNode], distinct: Option<&[u32]>, i: usize, refs: usize) -> usize {
    let Some(indices) = distinct else { return refs };
    let mut all = Vec::with_capacity(refs);
    gather(bin, indices, i, &mut all);
    all.sort_unstable();
    all.dedup();
    all.len()
}

/// The references of subtree `i`, leaf by leaf.
fn gather(bin: &[BvhNode], indices: &[u32], i: usize, out: &mut Vec<u32>) {
    let n = &bin[i];
    if n.is_leaf() {
        out.extend_from_slice(&indices[n.left_first as usize..(n.left_first + n.count) as usize]);
    } else {
        gather(bin, indices, n.left_first as usize, out);
        gather(bin, indices, n.left_first as usize + 1, out);
    }
}

/// Plans binary node `i` at `depth` and its subtree; returns its references, `cost`, and
/// `size[j - 1]`, what it emits over at most `j` slots (the sum over the nodes in them).
fn plan_subtree<const W: usize>(bin: &[BvhNode], distinct: Option<&[u32]>, i: usize, depth: usize, plan: &DisjointSlice<Plan<W>>) -> (usize, [f32; W], [Size; W]) {
    let n = &bin[i];
    let area = n.bounds().half_area().max(0.0);
    if n.is_leaf() {
        let refs = n.count as usize;
        let as_leaf = area * refs.div_ceil(4) as f32;
        let size = leaf_size::<W>(distinct_refs(bin, distinct, i, refs));
        // SAFETY: each node is planned once, by the one task that holds its subtree.
        unsafe { plan.write(i, Plan { leaf: true, split: [0; W], wide: 0, #[cfg(test)] cost: as_leaf, refs: refs as u32, size }) };
        return (refs, [as_leaf; W], [size; W]);
    }
    let (l, r) = (n.left_first as usize, n.left_first as usize + 1);
    let ((refs_l, cost_l, size_l), (refs_r, cost_r, size_r)) = if depth < FORK_DEPTH {
        rayon::join(|| plan_subtree(bin, distinct, l, depth + 1, plan), || plan_subtree(bin, distinct, r, depth + 1, plan))
    } else {
        (plan_subtree(bin, distinct, l, depth + 1, plan), plan_subtree(bin, distinct, r, depth + 1, plan))
    };
    let refs = refs_l + refs_r;
    let as_leaf = area * refs.div_ceil(4) as f32;
    // spread[j - 1]: both children over at most j slots (j ≥ 2), and the left's share.
    // Selections, not branches: which share wins is as good as random, and mispredicting
    // it was a quarter of the build's mispredictions.
    let mut spread = [(f32::INFINITY, 0u8); W];
    for j in 2..=W {
        let (mut best, mut share) = (f32::INFINITY, 0u8);
        for k in 1..j {
            let c = cost_l[k - 1] + cost_r[j - k - 1];
            share = if c < best { k as u8 } else { share };
            best = if c < best { c } else { best };
        }
        spread[j - 1] = (best, share);
    }
    let as_node = area + spread[W - 1].0;
    let leaf = refs <= LEAF_PRIMS && as_leaf <= as_node;
    let whole = if leaf { as_leaf } else { as_node };
    let wide = spread[W - 1].1 as usize;
    let size = if leaf { leaf_size::<W>(distinct_refs(bin, distinct, i, refs)) } else { Size { nodes: 1, blocks: 0 } + size_l[wide - 1] + size_r[W - wide - 1] };
    let mut p = Plan { leaf, split: [0; W], wide: wide as u8, #[cfg(test)] cost: whole, refs: refs as u32, size };
    let mut cost = [whole; W];
    let mut sizes = [size; W];
    for j in 2..=W {
        let (c, k) = spread[j - 1];
        if c < whole {
            cost[j - 1] = c;
            p.split[j - 1] = k;
            sizes[j - 1] = size_l[k as usize - 1] + size_r[j - k as usize - 1];
        }
    }
    // SAFETY: as for the leaves above.
    unsafe { plan.write(i, p) };
    (refs, cost, sizes)
}

impl<P: Primitives + ?Sized, const W: usize> Ctx<'_, P, W> {
    /// Emits binary node `i`, whole (a leaf or a wide node, as planned), into `out`, which
    /// is exactly its planned size; returns its reference. The layout is depth first: a
    /// wide node, then its lanes' subtrees in lane order, blocks in the same order.
    /// `refs`: working memory for the leaves' references, reused from leaf to leaf (an
    /// allocation per leaf was a tenth of the collapse).
    fn child(&self, i: usize, mut out: Part<'_, W>, refs: &mut Vec<u32>) -> ChildRef {
        let n = &self.bin[i];
        if n.is_leaf() || self.plan[i].leaf {
            refs.clear();
            gather(self.bin, self.indices, i, refs);
            // Spatial splits may put one primitive in two leaves of a merged subtree.
            refs.sort_unstable();
            refs.dedup();
            return self.leaf(refs, n.bounds(), out);
        }
        let l = n.left_first as usize;
        let k = self.plan[i].wide as usize;
        let (mut open, mut len) = ([0; W], 0);
        self.slots(l, k, &mut open, &mut len);
        self.slots(l + 1, W - k, &mut open, &mut len);
        let open = &open[..len];
        let node = out.take(Size { nodes: 1, blocks: 0 });
        if self.plan[i].refs as usize >= self.fork_refs {
            let lanes: Vec<(usize, Part<'_, W>)> = open.iter().map(|&c| (c, out.take(self.plan[c].size))).collect();
            assert!(out.nodes.is_empty() && out.blocks.is_empty(), "the plan sized the subtree");
            let refs: Vec<ChildRef> = lanes.into_par_iter().map(|(c, part)| self.child(c, part, &mut Vec::new())).collect();
            for (lane, (&c, r)) in open.iter().zip(refs).enumerate() {
                node.nodes[0].set(lane, &self.bin[c].bounds(), r);
            }
        } else {
            for (lane, &c) in open.iter().enumerate() {
                let r = self.child(c, out.take(self.plan[c].size), refs);
                node.nodes[0].set(lane, &self.bin[c].bounds(), r);
            }
            assert!(out.nodes.is_empty() && out.blocks.is_empty(), "the plan sized the subtree");
        }
        (node.node_base * self.stride) as ChildRef
    }

    /// The binary nodes that subtree `i` puts in at most `j` slots of its parent, appended
    /// to the first `len` of `out`.
    fn slots(&self, i: usize, j: usize, out: &mut [usize; W], len: &mut usize) {
        match self.plan[i].split[j - 1] {
            0 => {
                out[*len] = i;
                *len += 1;
            }
            k => {
                let l = self.bin[i].left_first as usize;
                self.slots(l, k as usize, out, len);
                self.slots(l + 1, j - k as usize, out, len);
            }
        }
    }

    /// A leaf over `refs` inside `bounds`, into `out` (its [`leaf_size`]); leaves too large
    /// for one reference (more than [`MAX_LEAF_BLOCKS`] blocks, from builders that cannot
    /// split equal centroids) become a wide node over chunks.
    fn leaf(&self, refs: &[u32], bounds: Aabb, mut out: Part<'_, W>) -> ChildRef {
        let blocks = refs.len().div_ceil(4);
        if blocks <= MAX_LEAF_BLOCKS {
            assert!(out.nodes.is_empty() && out.blocks.len() == blocks, "the plan sized the leaf");
            // Vertices come straight from the primitives: a copy of every triangle gathered
            // beforehand (40 bytes each, on fresh pages) cost more than the loads it saved.
            for (b, chunk) in out.blocks.iter_mut().zip(refs.chunks(4)) {
                for (lane, &p) in chunk.iter().enumerate() {
                    match self.prims.triangle(p) {
                        Some(v) => b.set_triangle(lane, p, v),
                        None => b.prim[lane] = p | TriBlock::OTHER,
                    }
                }
            }
            return leaf_ref(out.block_base, blocks);
        }
        let per = refs.len().div_ceil(W);
        let node = out.take(Size { nodes: 1, blocks: 0 });
        for (lane, chunk) in refs.chunks(per).enumerate() {
            let cb = chunk.iter().fold(Aabb::EMPTY, |b, &p| b.union(self.prims.bounds(p))).intersection(bounds);
            let r = self.leaf(chunk, cb, out.take(leaf_size::<W>(chunk.len())));
            node.nodes[0].set(lane, &cb, r);
        }
        (node.node_base * self.stride) as ChildRef
    }
}

#[cfg(test)]
mod tests {
    use raylab_core::{Aabb, Vec3};

    use super::*;

    fn aabb(x: f32, y: f32, z: f32) -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::new(x, y, z))
    }

    /// Forking the emission changes who writes what, never the result: a tree collapsed
    /// with every wide node forking, or some, is the same bytes as one never forking.
    #[test]
    fn forking_emits_the_serial_layout() {
        let mut rng = raylab_core::Pcg32::new(12345, 0);
        let mut next = move || rng.next_f32();
        let boxes: Vec<Aabb> = (0..3000)
            .map(|_| {
                let p = Vec3::new(next(), next(), next()) * 10.0;
                Aabb::new(p, p + Vec3::new(next(), next(), next()) * 0.3)
            })
            .collect();
        let prims = crate::primitives::TestBoxes(boxes);
        let bvh = Bvh::build(&prims, crate::bvh::SplitMethod::BinnedSah, &crate::BuildOptions::default());
        let serial = collapse_forking::<_, 8, WideNode<8>>(&bvh, &prims, usize::MAX);
        assert!(serial.nodes.len() > 50, "a tree deep enough to fork at several levels");
        for fork_refs in [1, 64, 1000] {
            let forked = collapse_forking::<_, 8, WideNode<8>>(&bvh, &prims, fork_refs);
            assert_eq!(forked.root, serial.root);
            assert!(forked.nodes == serial.nodes, "nodes differ when forking at {fork_refs} references");
            assert!(forked.blocks == serial.blocks, "blocks differ when forking at {fork_refs} references");
        }
    }

    /// A leaf's size by hand: 64 references fill 16 blocks, one reference; 65 are chunked 9
    /// per lane (seven chunks of 9, three blocks each, and one of 2) under one wide node;
    /// 200 over 4 lanes are four chunks of 50, 13 blocks each.
    #[test]
    fn leaf_sizes_by_hand() {
        assert_eq!(leaf_size::<8>(64), Size { nodes: 0, blocks: 16 });
        assert_eq!(leaf_size::<8>(65), Size { nodes: 1, blocks: 7 * 3 + 1 });
        assert_eq!(leaf_size::<4>(200), Size { nodes: 1, blocks: 4 * 13 });
        assert_eq!(leaf_size::<4>(0), Size { nodes: 0, blocks: 0 });
    }

    /// The plan's sizes are what is emitted, with leaves too large for one reference (300
    /// equal boxes: no plane separates their centroids, the builder makes leaves of 8 and
    /// the collapse merges none) and with repeated references (the same primitives in two
    /// leaves, as spatial splits make them).
    #[test]
    fn the_plan_sizes_what_is_emitted() {
        let same = crate::primitives::TestBoxes(vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 300]);
        let bin = vec![BvhNode::leaf(aabb(1.0, 1.0, 1.0), 0, 300)];
        let bvh = Bvh::from_parts(bin, (0..300).collect(), 300, "one big leaf");
        let c = collapse_forking::<_, 8, WideNode<8>>(&bvh, &same, 1);
        // Chunks of 38: seven of ten blocks and one of 34 references, nine blocks.
        assert_eq!(leaf_size::<8>(300), Size { nodes: 1, blocks: 7 * 10 + 9 });
        assert_eq!((c.nodes.len(), c.blocks.len()), (1, 79));
        // Leaves {0..4} and {2..6}, both whole in one leaf of six distinct primitives.
        let bin = vec![BvhNode::interior(aabb(1.0, 1.0, 1.0), 1), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 0, 4), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 4, 4)];
        let bvh = Bvh::from_parts(bin, vec![0, 1, 2, 3, 2, 3, 4, 5], 6, "repeats").with_spatial_splits();
        let c = collapse_forking::<_, 8, WideNode<8>>(&bvh, &crate::primitives::TestBoxes(vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 6]), 1);
        assert_eq!((c.root, c.nodes.len(), c.blocks.len()), (leaf_ref(0, 2), 0, 2));
        assert_eq!(c.blocks[1].prim.map(|p| p & !TriBlock::OTHER), [4, 5, EMPTY & !TriBlock::OTHER, EMPTY & !TriBlock::OTHER]);
    }

    /// Two leaves of three filling their parent's box: as one leaf of two blocks the parent
    /// costs 3 · 2 = 6 (half area 3 of the unit cube, two blocks); as a wide node over two
    /// one-block leaves 3 + 3 + 3 = 9. The greedy rule (leaves of at most four) took the node.
    #[test]
    fn six_triangles_in_one_box_make_one_leaf() {
        let bin = [BvhNode::interior(aabb(1.0, 1.0, 1.0), 1), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 0, 3), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 3, 3)];
        let whole = plan::<8>(&bin, None);
        assert!(whole[0].leaf);
        assert_eq!(whole[0].cost, 6.0);
        // Small children, half area 0.25 each (0.5 × 0.5 × 0): as a node 3 + 0.25 + 0.25 = 3.5 < 6.
        let bin = [BvhNode::interior(aabb(1.0, 1.0, 1.0), 1), BvhNode::leaf(aabb(0.5, 0.5, 0.0), 0, 3), BvhNode::leaf(aabb(0.5, 0.5, 0.0), 3, 3)];
        assert!(!plan::<8>(&bin, None)[0].leaf);
    }

    /// Root R (half area 3) over A (interior, half area 2, over two leaves of eight, half area
    /// 1 and two blocks each, so 2 each) and B (a leaf of four, half area 1: cost 1), 4 wide.
    /// A kept whole costs 2 + 2 + 2 = 6 in one slot; spread over two slots 4. R's node: A in
    /// one slot 6 + 1, in two slots 4 + 1 = 5 (three slots gain nothing): A's leaves go up
    /// into R's node, and R costs 3 + 5 = 8.
    #[test]
    fn a_child_is_spread_over_its_parents_slots_when_cheaper() {
        let bin = [
            BvhNode::interior(aabb(1.0, 1.0, 1.0), 1),
            BvhNode::interior(aabb(1.0, 1.0, 0.5), 3),
            BvhNode::leaf(aabb(0.5, 0.5, 0.75), 0, 4),
            BvhNode::leaf(aabb(0.5, 0.5, 0.75), 4, 8),
            BvhNode::leaf(aabb(0.5, 0.5, 0.75), 12, 8),
        ];
        for (i, want) in [3.0, 2.0, 1.0, 1.0, 1.0].into_iter().enumerate() {
            assert_eq!(bin[i].bounds().half_area(), want, "node {i}");
        }
        let plan = plan::<4>(&bin, None);
        assert_eq!((plan[0].cost, plan[1].cost, plan[2].cost), (8.0, 6.0, 1.0));
        assert!(!plan[0].leaf && !plan[1].leaf, "20 and 16 references are too many for a leaf");
        assert_eq!(plan[0].wide, 2, "A takes two of R's four slots");
        assert_eq!(plan[1].split[1], 1, "A over two slots: one for each of its leaves");
        assert_eq!(plan[1].split[0], 0, "A in one slot stays whole");
        assert_eq!(plan[1].wide, 1);
    }

    /// What the plans of the two trees above emit. Six references in one box: the root is
    /// one leaf of two blocks (primitives 0..4 and 4, 5), no wide node. R over A (two leaves
    /// of eight) and B (a leaf of four), 4 wide: one node whose lanes are A's leaves, then B,
    /// then an empty slot, each lane with its binary node's box; blocks in lane order. The
    /// same bytes whether the root's children are emitted as tasks (`fork_refs` 1) or not.
    #[test]
    fn planned_trees_emit_by_hand() {
        let boxes = |n: usize| crate::primitives::TestBoxes((0..n).map(|i| Aabb::new(Vec3::splat(i as f32 * 0.01), Vec3::splat(0.5))).collect());
        let other = |ps: [u32; 4]| ps.map(|p| if p == EMPTY { EMPTY } else { p | TriBlock::OTHER });
        let bin = vec![BvhNode::interior(aabb(1.0, 1.0, 1.0), 1), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 0, 3), BvhNode::leaf(aabb(1.0, 1.0, 1.0), 3, 3)];
        let bvh = Bvh::from_parts(bin, (0..6).collect(), 6, "six");
        for fork_refs in [1, usize::MAX] {
            let c = collapse_forking::<_, 8, WideNode<8>>(&bvh, &boxes(6), fork_refs);
            assert_eq!((c.root, c.nodes.len()), (leaf_ref(0, 2), 0), "one leaf, forking at {fork_refs}");
            assert_eq!(c.blocks.iter().map(|b| b.prim).collect::<Vec<_>>(), [other([0, 1, 2, 3]), other([4, 5, EMPTY, EMPTY])]);
        }
        let (a0, a1, b) = (aabb(0.5, 0.5, 0.75), Aabb::new(Vec3::new(0.5, 0.0, 0.0), Vec3::new(1.0, 0.5, 0.75)), aabb(1.0, 1.0, 0.25));
        let bin = vec![
            BvhNode::interior(aabb(1.0, 1.0, 1.0), 1),
            BvhNode::interior(aabb(1.0, 1.0, 0.75), 3),
            BvhNode::leaf(b, 0, 4),
            BvhNode::leaf(a0, 4, 8),
            BvhNode::leaf(a1, 12, 8),
        ];
        let bvh = Bvh::from_parts(bin, (0..20).collect(), 20, "r-a-b");
        for fork_refs in [1, usize::MAX] {
            let c = collapse_forking::<_, 4, WideNode<4>>(&bvh, &boxes(20), fork_refs);
            assert_eq!((c.root, c.nodes.len(), c.blocks.len()), (0, 1, 5), "forking at {fork_refs}");
            let n = &c.nodes[0];
            assert_eq!(n.child, [leaf_ref(0, 2), leaf_ref(2, 2), leaf_ref(4, 1), EMPTY], "forking at {fork_refs}");
            assert_eq!((n.child_bounds(0), n.child_bounds(1), n.child_bounds(2)), (a0, a1, b));
            let prims: Vec<[u32; 4]> = c.blocks.iter().map(|b| b.prim).collect();
            assert_eq!(prims, [other([4, 5, 6, 7]), other([8, 9, 10, 11]), other([12, 13, 14, 15]), other([16, 17, 18, 19]), other([0, 1, 2, 3])]);
        }
    }

    /// Slots are counted on both sides. R (half area 3, 4 wide) over A (a leaf of four, half
    /// area 1: cost 1) and B (half area 2) over C1 and C2 (half area 1.5 each), each over two
    /// leaves of eight (half area 1, two blocks: 2 each). C whole: 1.5 + 2 + 2 = 5.5; spread
    /// over two slots: 4. B over three slots: one C whole, the other spread, 5.5 + 4 = 9.5;
    /// over four: 8; whole: 2 + 8 = 10 (two slots gain nothing: 5.5 + 5.5 > 10). R: A in one
    /// slot and B over three, 1 + 9.5 = 10.5, against B over two (1 + 10) or one (1 + 10):
    /// R costs 3 + 10.5 = 13.5. (Giving B a fourth slot, beyond R's four, would read 12.)
    #[test]
    fn slots_add_up_to_the_width() {
        let (leaf, c) = (aabb(0.5, 0.5, 0.75), aabb(1.0, 1.0, 0.25));
        let bin = [
            BvhNode::interior(aabb(1.0, 1.0, 1.0), 1),
            BvhNode::leaf(leaf, 0, 4),
            BvhNode::interior(aabb(1.0, 1.0, 0.5), 3),
            BvhNode::interior(c, 5),
            BvhNode::interior(c, 7),
            BvhNode::leaf(leaf, 4, 8),
            BvhNode::leaf(leaf, 12, 8),
            BvhNode::leaf(leaf, 20, 8),
            BvhNode::leaf(leaf, 28, 8),
        ];
        assert_eq!(c.half_area(), 1.5);
        let plan = plan::<4>(&bin, None);
        assert_eq!(plan.iter().map(|p| p.cost).collect::<Vec<_>>(), [13.5, 1.0, 10.0, 5.5, 5.5, 2.0, 2.0, 2.0, 2.0]);
        assert_eq!(plan[0].wide, 1, "A takes one of R's slots, B three");
        assert_eq!(plan[2].split[2], 1, "B over three slots: C1 whole, C2 over two");
        assert_eq!(plan[2].split[1], 0, "B over two slots stays whole");
        assert_eq!(plan[4].split[1], 1);
    }
}
