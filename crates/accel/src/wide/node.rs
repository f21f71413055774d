//! The wide BVH's memory layout: `W`-wide nodes of child boxes in SoA form (one SIMD
//! register per bound), and leaves of precomputed triangles four at a time. How a node
//! stores its boxes is a [`Layout`]: f32 ([`WideNode`]) or quantised
//! ([`QuantNode`](super::quant::QuantNode)).

use raylab_core::{Aabb, Vec3};

use super::ray::RayBoxes;

/// A child slot's reference: an interior node's byte offset in units of [`NODE_UNIT`]
/// ([`node_ref`]), or [`LEAF`] with a range of [`TriBlock`]s, or [`EMPTY`].
///
/// Leaf layout: bit 31 set, bits 27..31 the block count minus one (1 to 16 blocks), bits
/// 0..27 the first block.
pub type ChildRef = u32;

/// The unit of an interior reference, in bytes: the walk finds a node at `base + (r << 5)`,
/// a shift where a node index needed a multiply by the node's size (three cycles more on the
/// chain from one node visit to the next: 1.5-4 % of a diffuse ray's time).
pub const NODE_UNIT: usize = 32;

/// The reference of node `index` of a layout of nodes `N` (a multiple of [`NODE_UNIT`] in
/// size: 224, 128 or 96 bytes).
#[inline]
pub const fn node_ref<N>(index: usize) -> ChildRef {
    let r = index * (std::mem::size_of::<N>() / NODE_UNIT);
    assert!(r < LEAF as usize, "wide BVH: more nodes than references can address");
    r as ChildRef
}

/// The index of the node that interior reference `r` points at, or `None` where `r` falls
/// inside a node rather than at its start (only a broken tree has such references).
#[inline]
pub const fn node_index<N>(r: ChildRef) -> Option<usize> {
    let stride = std::mem::size_of::<N>() / NODE_UNIT;
    if (r as usize).is_multiple_of(stride) {
        Some(r as usize / stride)
    } else {
        None
    }
}

pub const LEAF: u32 = 1 << 31;
pub const EMPTY: u32 = u32::MAX;
pub const MAX_LEAF_BLOCKS: usize = 16;
const BLOCK_BITS: u32 = 27;
pub const MAX_BLOCKS: usize = 1 << BLOCK_BITS;

#[inline]
pub fn leaf_ref(first_block: usize, blocks: usize) -> ChildRef {
    debug_assert!((1..=MAX_LEAF_BLOCKS).contains(&blocks) && first_block < MAX_BLOCKS);
    LEAF | ((blocks as u32 - 1) << BLOCK_BITS) | first_block as u32
}

#[inline]
pub fn is_leaf(r: ChildRef) -> bool {
    r & LEAF != 0
}

/// `(first block, block count)` of a leaf reference.
#[inline]
pub fn leaf_blocks(r: ChildRef) -> (usize, usize) {
    ((r & ((1 << BLOCK_BITS) - 1)) as usize, (((r >> BLOCK_BITS) & 0xF) + 1) as usize)
}

/// One node of `W` children: 224 bytes for `W = 8` (3.5 cache lines, Embree's BVH8 node
/// is 256), 128 for `W = 4`.
///
/// Invariants: an [`EMPTY`] slot has the empty box (`min = +∞`, `max = -∞`), which no
/// slab test can hit and which never produces NaN; every other slot's box contains its
/// subtree (its triangles, or with spatial splits the parts of them referenced there).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct WideNode<const W: usize> {
    /// `bounds[0..3]` = min x, y, z and `bounds[3..6]` = max x, y, z, one lane per child.
    pub bounds: [[f32; W]; 6], // 6·4W bytes
    pub child: [ChildRef; W],  //   4W     -> 28W (padded to 32 bytes)
}

const _: () = assert!(std::mem::size_of::<WideNode<8>>() == 224);
const _: () = assert!(std::mem::size_of::<WideNode<4>>() == 128);

impl<const W: usize> WideNode<W> {
    pub const EMPTY_NODE: Self = Self { bounds: [[f32::INFINITY; W], [f32::INFINITY; W], [f32::INFINITY; W], [f32::NEG_INFINITY; W], [f32::NEG_INFINITY; W], [f32::NEG_INFINITY; W]], child: [EMPTY; W] };

    pub fn set(&mut self, lane: usize, b: &Aabb, r: ChildRef) {
        for a in 0..3 {
            self.bounds[a][lane] = b.min[a];
            self.bounds[3 + a][lane] = b.max[a];
        }
        self.child[lane] = r;
    }

    pub fn child_bounds(&self, lane: usize) -> Aabb {
        let g = |k: usize| Vec3::new(self.bounds[k][lane], self.bounds[k + 1][lane], self.bounds[k + 2][lane]);
        Aabb { min: g(0), max: g(3) }
    }
}

/// How a `W`-wide node stores its child boxes and references. Traversal, statistics and
/// validation are written once against this; a layout only encodes, decodes and runs its
/// box test.
///
/// # Safety
/// The walk reads a node at any [`NODE_UNIT`] boundary a reference names, so the type must
/// be plain data (every bit pattern a valid value), a multiple of [`NODE_UNIT`] in size and
/// aligned to it.
pub unsafe trait Layout<const W: usize>: Copy + std::fmt::Debug + Send + Sync + 'static {
    /// Short name for statistics ("f32", "quantised").
    const NAME: &'static str;

    /// Decoding gives back exactly the encoded boxes: no parent's box needs widening to
    /// hold its children's decoded ones.
    const EXACT: bool;

    /// Lays out `node`. A decoded box contains the original one (it may only grow).
    fn encode(node: &WideNode<W>) -> Self;

    /// Calls `f` with the f32 node this one decodes to: the boxes the box test uses.
    #[inline(always)]
    fn with_decoded<R>(&self, f: impl FnOnce(&WideNode<W>) -> R) -> R {
        f(self.decoded(&mut std::mem::MaybeUninit::uninit()))
    }

    /// The f32 node this one decodes to: itself, or decoded into `scratch`. Without a
    /// closure, for walks whose SIMD code must inline into their caller's target features.
    fn decoded<'a>(&'a self, scratch: &'a mut std::mem::MaybeUninit<WideNode<W>>) -> &'a WideNode<W>;

    fn child(&self, lane: usize) -> ChildRef;

    /// Which children the ray enters within `[r.t_min, t_max]` (bit `l` for lane `l`), and
    /// their entry distances: the same answer as [`boxes_portable`](super::kernels::boxes_portable)
    /// on the decoded node, with SIMD or without.
    fn boxes<const SIMD: bool>(&self, r: &RayBoxes, t_max: f32, tnear: &mut [f32; W]) -> u32;
}

/// Up to four triangles, vertices in SoA form (`p[vertex][axis][lane]`), copied from the
/// mesh so that a leaf test needs no index or vertex loads: 160 bytes.
///
/// Lanes: `prim[l]` is the primitive index; [`TriBlock::OTHER`] marks a primitive that
/// is not a triangle (tested through `Primitives::intersect`; its vertices are zero, which
/// the block test relies on to never skip it) and
/// [`EMPTY`] an unused lane.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct TriBlock {
    pub p: [[[f32; 4]; 3]; 3], // 144 bytes
    pub prim: [u32; 4],        //  16 -> 160
}

const _: () = assert!(std::mem::size_of::<TriBlock>() == 160);

impl TriBlock {
    /// Flag of a lane whose primitive is not a triangle.
    pub const OTHER: u32 = 1 << 31;
    pub const EMPTY_BLOCK: Self = Self { p: [[[0.0; 4]; 3]; 3], prim: [EMPTY; 4] };

    pub fn set_triangle(&mut self, lane: usize, prim: u32, v: [Vec3; 3]) {
        for (k, p) in v.iter().enumerate() {
            for a in 0..3 {
                self.p[k][a][lane] = p[a];
            }
        }
        self.prim[lane] = prim;
    }

    pub fn vertex(&self, lane: usize, k: usize) -> Vec3 {
        Vec3::new(self.p[k][0][lane], self.p[k][1][lane], self.p[k][2][lane])
    }
}
