//! Binary tree → `W`-wide tree, after Embree's BVH-N builders (Wald et al. 2008, "Getting
//! rid of packets"; Benthin et al. 2012): each wide node starts from a binary node's two
//! children and repeatedly opens the child of largest surface area — the one a ray is most
//! likely to enter, so the one whose node visit is worth saving by the SAH — until `W`
//! children are reached or none can be opened. Subtrees of at most [`LEAF_PRIMS`]
//! references become one leaf (one block of four triangles), so leaves are full SIMD
//! blocks instead of the binary builders' 1-2 triangles.

use raylab_core::Aabb;

use super::node::{leaf_ref, ChildRef, TriBlock, WideNode, MAX_BLOCKS, MAX_LEAF_BLOCKS};
use crate::bvh::{Bvh, BvhNode};
use crate::Primitives;

/// Subtrees with at most this many references become a single leaf: one [`TriBlock`].
pub const LEAF_PRIMS: usize = 4;

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
    /// References below each binary node.
    counts: Vec<usize>,
    nodes: Vec<WideNode<W>>,
    blocks: Vec<TriBlock>,
}

pub(super) fn collapse<P: Primitives + ?Sized, const W: usize>(bvh: &Bvh, prims: &P) -> Collapsed<W> {
    assert!(prims.len() < TriBlock::OTHER as usize, "wide BVH: more than 2^31 primitives");
    let bin = &bvh.nodes[..];
    if bin.is_empty() {
        return Collapsed { nodes: Vec::new(), blocks: Vec::new(), root: super::node::EMPTY, root_bounds: Aabb::EMPTY };
    }
    // Children always sit after their parent (checked by `Bvh::validate`), so a reverse
    // sweep sees children before parents.
    let mut counts = vec![0usize; bin.len()];
    for i in (0..bin.len()).rev() {
        let n = &bin[i];
        counts[i] = if n.is_leaf() { n.count as usize } else { counts[n.left_first as usize] + counts[n.left_first as usize + 1] };
    }
    let mut ctx = Ctx { bin, indices: &bvh.indices, prims, counts, nodes: Vec::with_capacity(bin.len() / W + 1), blocks: Vec::with_capacity(prims.len() / 2 + 1) };
    let root = ctx.child(0);
    assert!(ctx.blocks.len() <= MAX_BLOCKS, "wide BVH: too many triangle blocks");
    Collapsed { nodes: ctx.nodes, blocks: ctx.blocks, root, root_bounds: bin[0].bounds() }
}

impl<P: Primitives + ?Sized, const W: usize> Ctx<'_, P, W> {
    /// The reference for binary node `i`: a leaf if it is small enough, a wide node else.
    fn child(&mut self, i: usize) -> ChildRef {
        let n = &self.bin[i];
        if n.is_leaf() || self.counts[i] <= LEAF_PRIMS {
            let mut refs = Vec::with_capacity(self.counts[i]);
            self.gather(i, &mut refs);
            // Spatial splits may put one primitive in two leaves of a merged subtree.
            refs.sort_unstable();
            refs.dedup();
            return self.leaf(&refs, n.bounds());
        }
        let mut open: Vec<usize> = vec![n.left_first as usize, n.left_first as usize + 1];
        while open.len() < W {
            let best = open
                .iter()
                .enumerate()
                .filter(|&(_, &c)| !self.bin[c].is_leaf() && self.counts[c] > LEAF_PRIMS)
                .max_by(|a, b| self.bin[*a.1].bounds().half_area().total_cmp(&self.bin[*b.1].bounds().half_area()))
                .map(|(k, _)| k);
            let Some(k) = best else { break };
            let c = open.swap_remove(k);
            let l = self.bin[c].left_first as usize;
            open.extend([l, l + 1]);
        }
        let slot = self.nodes.len();
        self.nodes.push(WideNode::EMPTY_NODE);
        for (lane, &c) in open.iter().enumerate() {
            let r = self.child(c);
            let b = self.bin[c].bounds();
            self.nodes[slot].set(lane, &b, r);
        }
        slot as ChildRef
    }

    fn gather(&self, i: usize, out: &mut Vec<u32>) {
        let n = &self.bin[i];
        if n.is_leaf() {
            out.extend_from_slice(&self.indices[n.left_first as usize..(n.left_first + n.count) as usize]);
        } else {
            self.gather(n.left_first as usize, out);
            self.gather(n.left_first as usize + 1, out);
        }
    }

    /// A leaf over `refs` inside `bounds`; leaves too large for one reference (more than
    /// [`MAX_LEAF_BLOCKS`] blocks, from builders that cannot split equal centroids) become
    /// a wide node over chunks.
    fn leaf(&mut self, refs: &[u32], bounds: Aabb) -> ChildRef {
        let blocks = refs.len().div_ceil(4);
        if blocks <= MAX_LEAF_BLOCKS {
            let first = self.blocks.len();
            for chunk in refs.chunks(4) {
                let mut b = TriBlock::EMPTY_BLOCK;
                for (lane, &p) in chunk.iter().enumerate() {
                    match self.prims.triangle(p) {
                        Some(v) => b.set_triangle(lane, p, v),
                        None => b.prim[lane] = p | TriBlock::OTHER,
                    }
                }
                self.blocks.push(b);
            }
            return leaf_ref(first, blocks);
        }
        let per = refs.len().div_ceil(W);
        let slot = self.nodes.len();
        self.nodes.push(WideNode::EMPTY_NODE);
        for (lane, chunk) in refs.chunks(per).enumerate() {
            let cb = chunk.iter().fold(Aabb::EMPTY, |b, &p| b.union(self.prims.bounds(p))).intersection(bounds);
            let r = self.leaf(chunk, cb);
            self.nodes[slot].set(lane, &cb, r);
        }
        slot as ChildRef
    }
}
