//! Wide BVHs: a layout converted from any binary BVH (tinybvh's `ConvertFrom`, obvhs's
//! `bvh2` → `cwbvh`), not a builder of its own. Nodes hold `W` = 4 or 8 child boxes in SoA
//! form, tested at once with SIMD; leaves hold blocks of four triangles copied from the
//! mesh (Embree's `Triangle4`), tested without index indirection.
//!
//! - `node.rs`: the memory layout and its byte budget, and the [`Layout`] of a node's boxes;
//! - `quant.rs`: the quantised 8-wide node (`bvh8q`, 96 bytes instead of 224);
//! - `collapse.rs`: binary → wide, by a cost-driven programme (Ylitie et al. 2017);
//! - `ray.rs`: the per-ray constants of the kernels, computed once per ray;
//! - `kernels.rs`: box and triangle kernels, SIMD and portable with identical answers, and
//!   the f32 node's [`Layout`];
//! - `traverse.rs`: closest and any hit, counting or not;
//! - `packet.rs`: closest hits of 16-ray packets (4×4 tiles of camera rays), child-major;
//! - `ray_major/`: the same ray-major, one ray per lane, in one walk generic over the
//!   register width: sixteen rays with AVX-512 (Embree's `rtcIntersect16`), eight with
//!   AVX2 (`rtcIntersect8`, a 16-ray tile as two packets of eight).

mod collapse;
pub mod kernels;
pub mod node;
mod packet;
pub mod quant;
pub mod ray;
#[cfg(target_arch = "x86_64")]
mod ray_major;
mod traverse;

use rayon::prelude::*;
use raylab_core::{Aabb, Ray, Vec3};

use crate::bvh::Bvh;
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};
use node::{is_leaf, leaf_blocks, node_index, ChildRef, Layout, TriBlock, WideNode, EMPTY, NODE_UNIT};

pub use collapse::LEAF_PRIMS;
pub use packet::PACKET;

/// Which kernels a traversal runs. All give bit-identical answers (the tests compare them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// Plain Rust, on any CPU.
    Portable,
    /// `std::arch`: AVX2 (with BMI1 and BMI2) for 8-wide nodes, SSE2 for 4-wide (x86-64
    /// only). Packets of 8-wide nodes go ray-major in halves of eight rays
    /// (`wide/ray_major/avx2.rs`), those whose rays do not share box rows and shear axes
    /// child-major (`wide/packet.rs`).
    Simd,
    /// The same intrinsics with the whole traversal compiled for AVX-512F/VL: 32 vector
    /// registers instead of 16 and mask registers for the compares. Same IEEE operations
    /// in the same order, so the same answers. Packets of 8-wide nodes whose rays share box
    /// rows and shear axes go ray-major, sixteen rays in the lanes of a 512-bit register
    /// (`wide/ray_major/avx512.rs`). The default for such packets where the CPU runs it: see
    /// [`Kernel::detect_packets`].
    Avx512,
}

impl Kernel {
    /// The default kernel of single rays for width `w` on this CPU (runtime detection: the
    /// binary stays portable, no `target-cpu` needed): [`Kernel::Simd`] where it runs. Not
    /// [`Kernel::Avx512`]: for single rays it measured no faster (docs/performance.md).
    pub fn detect(w: usize) -> Kernel {
        Kernel::Simd.available(w)
    }

    /// The default kernel of packets: [`Kernel::Avx512`] for 8-wide nodes where the CPU
    /// runs it (sixteen rays per register: docs/performance.md, eleventh round), else that
    /// of single rays (with AVX2, eight rays per register: nineteenth round).
    pub fn detect_packets(w: usize) -> Kernel {
        if w == 8 { Kernel::Avx512.available(w) } else { Kernel::detect(w) }
    }

    /// `self` if this CPU runs it for width `w`, else the next best that it runs.
    pub fn available(self, w: usize) -> Kernel {
        #[cfg(target_arch = "x86_64")]
        {
            use std::is_x86_feature_detected as has;
            if self == Kernel::Avx512 && has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2") {
                return Kernel::Avx512;
            }
            // The 8-wide walks use BMI's `tzcnt` and `blsr` on hit masks too: every CPU with
            // AVX2 has them, but they are separate features.
            if self != Kernel::Portable && (w == 4 || (w == 8 && has!("avx2") && has!("bmi1") && has!("bmi2"))) {
                return Kernel::Simd;
            }
        }
        let _ = w;
        Kernel::Portable
    }
}

/// A `W`-wide BVH whose nodes store their boxes as layout `N` (f32 by default).
///
/// Invariants: `root` is [`EMPTY`] exactly when there are no primitives; every interior
/// reference indexes `nodes`, every leaf reference a range of `blocks`; every primitive is
/// in some block lane.
#[derive(Debug)]
pub struct WideBvh<const W: usize, N: Layout<W> = WideNode<W>> {
    pub nodes: Vec<N>,
    pub blocks: Vec<TriBlock>,
    pub root: ChildRef,
    root_bounds: Aabb,
    pub name: &'static str,
    pub(crate) build_ms: f64,
    primitives: usize,
    spatial_splits: bool,
    /// The kernels of single rays and of packets.
    kernel: Kernel,
    packet_kernel: Kernel,
    /// Whether single rays prefetch the children they enter and push ([`Prefetch`]).
    prefetch_children: bool,
}

/// Whether single rays prefetch each child they enter or push (all the cache lines of its
/// node, or of its leaf's first block), as Embree's walk does: a pushed child is then in
/// the cache when it is popped, and an entered node's child references (its last line)
/// arrive with its planes. It pays where the structure is far larger than the caches and
/// gains nothing, or loses a per cent or two, where it is not (docs/performance.md,
/// twenty-fourth round), so by default it is on from [`PREFETCH_BYTES`] of
/// structure. Answers and counted work never change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prefetch {
    /// On for structures of at least [`PREFETCH_BYTES`].
    Auto,
    On,
    Off,
}

/// The structure size from which [`Prefetch::Auto`] prefetches. On a 2-core Intel Xeon
/// with 2 MiB of L2 per core, prefetching made the 871k dragon's 51 MiB `bvh8` 7-11 %
/// faster on primary, diffuse and shadow rays, and left the 202k dragon's 11.6 MiB one
/// and the 69k bunny's 3.8 MiB one as they were (within ±2 %).
pub const PREFETCH_BYTES: usize = 32 << 20;

impl<const W: usize, N: Layout<W>> WideBvh<W, N> {
    /// Converts a binary BVH built over `prims`.
    pub fn from_binary<P: Primitives + ?Sized>(bvh: &Bvh, prims: &P, name: &'static str) -> Self {
        const { assert!(W == 4 || W == 8, "wide BVHs are 4 or 8 wide") };
        let c = collapse::collapse::<P, W, N>(bvh, prims);
        let nodes: Vec<N> = encode(c.nodes, c.root);
        // The root's decoded boxes may round past the scene's bounds: the root box holds them.
        let root_bounds = if c.root == EMPTY || is_leaf(c.root) { c.root_bounds } else { nodes[index::<W, N>(c.root)].with_decoded(|n| (0..W).filter(|&l| n.child[l] != EMPTY).fold(c.root_bounds, |b, l| b.union(n.child_bounds(l)))) };
        let w = Self { nodes, blocks: c.blocks, root: c.root, root_bounds, name, build_ms: 0.0, primitives: prims.len(), spatial_splits: bvh.spatial_splits, kernel: Kernel::detect(W), packet_kernel: Kernel::detect_packets(W), prefetch_children: false };
        w.with_prefetch(Prefetch::Auto)
    }

    /// Sets whether single rays prefetch the children they enter and push.
    pub fn with_prefetch(mut self, p: Prefetch) -> Self {
        self.prefetch_children = match p {
            Prefetch::Auto => self.bytes() >= PREFETCH_BYTES,
            Prefetch::On => true,
            Prefetch::Off => false,
        };
        self
    }

    /// Whether single rays prefetch the children they enter and push ([`Prefetch`]).
    pub fn prefetches_children(&self) -> bool {
        self.prefetch_children
    }

    /// The node interior reference `r` points at: at `r` [`NODE_UNIT`]s from the first,
    /// found with a shift (see [`NODE_UNIT`]).
    #[inline(always)]
    pub(super) fn node(&self, r: ChildRef) -> &N {
        const { assert!(std::mem::size_of::<N>().is_multiple_of(NODE_UNIT) && std::mem::align_of::<N>() >= NODE_UNIT, "a layout's nodes fill and align to whole reference units") };
        let at = r as usize * NODE_UNIT;
        assert!(at + std::mem::size_of::<N>() <= std::mem::size_of_val(&self.nodes[..]), "wide BVH: node reference {r} past the nodes");
        // SAFETY: within the nodes (checked), at a multiple of `NODE_UNIT` from their start,
        // which `Layout` types are aligned to; a reference that falls inside a node (only a
        // broken tree has one) reads plain data, which `Layout` types are.
        unsafe { &*self.nodes.as_ptr().cast::<u8>().add(at).cast::<N>() }
    }

    /// Bytes of nodes and blocks.
    fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<N>() + self.blocks.len() * std::mem::size_of::<TriBlock>()
    }

    /// Forces a kernel, for single rays and packets (tests compare them). Asking for one
    /// this CPU lacks gives the next best it has ([`Kernel::available`]).
    pub fn with_kernel(mut self, k: Kernel) -> Self {
        self.kernel = k.available(W);
        self.packet_kernel = self.kernel;
        self
    }

    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    pub fn packet_kernel(&self) -> Kernel {
        self.packet_kernel
    }

    pub fn root_bounds(&self) -> Aabb {
        self.root_bounds
    }

    /// Closest hit without counting: the fast path (`raylab trace`).
    #[inline]
    pub fn intersect_fast<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray) -> Option<Hit> {
        self.closest_dispatch::<P, false>(prims, ray, &mut Counters::default())
    }

    /// Any hit without counting.
    #[inline]
    pub fn occluded_fast<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray) -> bool {
        self.any_dispatch::<P, false>(prims, ray, &mut Counters::default())
    }

    /// Closest hits of a packet of at most [`PACKET`] rays, traversed together: `out[i]`
    /// is exactly what [`WideBvh::intersect_fast`] returns for `rays[i]`.
    ///
    /// # Panics
    /// If `rays` holds more than [`PACKET`] rays or `out` is not as long as `rays`.
    pub fn intersect_packet<P: Primitives + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.packet_dispatch::<P, false>(prims, rays, out, &mut Counters::default())
    }

    /// [`WideBvh::intersect_packet`], counting (the renderer's camera rays).
    pub fn intersect_packet_counted<P: Primitives + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
        self.packet_dispatch::<P, true>(prims, rays, out, c)
    }

    #[inline]
    fn packet_dispatch<P: Primitives + ?Sized, const COUNT: bool>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
        #[cfg(target_arch = "x86_64")]
        if W == 8 && self.packet_kernel == Kernel::Avx512 && !rays.is_empty() && rays.len() <= PACKET && out.len() == rays.len() && ray_major_available() {
            // SAFETY: the features were detected (`Kernel::Avx512` is only chosen after
            // detecting them, and `ray_major_available` checks them again).
            if unsafe { ray_major::avx512::closest::<P, W, N, COUNT>(self, prims, rays, out, c) } {
                return;
            }
        }
        #[cfg(target_arch = "x86_64")]
        match self.packet_kernel {
            // SAFETY: `Kernel::Avx512` is only chosen after detecting its features.
            Kernel::Avx512 => return unsafe { packet_avx512::<P, W, N, COUNT>(self, prims, rays, out, c) },
            Kernel::Simd if W == 8 && !rays.is_empty() && rays.len() <= PACKET && out.len() == rays.len() => {
                // Ray-major in packets of eight (4×2 rays of a camera tile), as Embree on
                // AVX2; a part whose rays do not share box rows and shear axes goes
                // child-major.
                for (rays, out) in rays.chunks(ray_major::avx2::RAYS).zip(out.chunks_mut(ray_major::avx2::RAYS)) {
                    // SAFETY: `Kernel::Simd` with W = 8 is only chosen after detecting AVX2.
                    if !unsafe { ray_major::avx2::closest::<P, W, N, COUNT>(self, prims, rays, out, c) } {
                        // SAFETY: as above.
                        unsafe { packet_avx2::<P, W, N, COUNT>(self, prims, rays, out, c) };
                    }
                }
                return;
            }
            // SAFETY: `Kernel::Simd` with W = 8 is only chosen after detecting AVX2.
            Kernel::Simd if W == 8 => return unsafe { packet_avx2::<P, W, N, COUNT>(self, prims, rays, out, c) },
            Kernel::Simd => return packet::closest::<P, W, N, true, COUNT>(self, prims, rays, out, c),
            Kernel::Portable => {}
        }
        packet::closest::<P, W, N, false, COUNT>(self, prims, rays, out, c)
    }

    #[inline]
    fn closest_dispatch<P: Primitives + ?Sized, const COUNT: bool>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        if self.prefetch_children {
            self.closest_kernel::<P, COUNT, true>(prims, ray, c)
        } else {
            self.closest_kernel::<P, COUNT, false>(prims, ray, c)
        }
    }

    #[inline(always)]
    fn closest_kernel<P: Primitives + ?Sized, const COUNT: bool, const PF: bool>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        match self.kernel {
            // SAFETY: `Kernel::Avx512` is only chosen after detecting its features.
            Kernel::Avx512 => return unsafe { closest_avx512::<P, W, N, COUNT, PF>(self, prims, ray, c) },
            // SAFETY: `Kernel::Simd` with W = 8 is only chosen after detecting AVX2.
            Kernel::Simd if W == 8 => return unsafe { closest_avx2::<P, W, N, COUNT, PF>(self, prims, ray, c) },
            Kernel::Simd => return traverse::closest::<P, W, N, true, COUNT, PF>(self, prims, ray, c),
            Kernel::Portable => {}
        }
        traverse::closest::<P, W, N, false, COUNT, PF>(self, prims, ray, c)
    }

    #[inline]
    fn any_dispatch<P: Primitives + ?Sized, const COUNT: bool>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        if self.prefetch_children {
            self.any_kernel::<P, COUNT, true>(prims, ray, c)
        } else {
            self.any_kernel::<P, COUNT, false>(prims, ray, c)
        }
    }

    #[inline(always)]
    fn any_kernel<P: Primitives + ?Sized, const COUNT: bool, const PF: bool>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        #[cfg(target_arch = "x86_64")]
        match self.kernel {
            // SAFETY: `Kernel::Avx512` is only chosen after detecting its features.
            Kernel::Avx512 => return unsafe { any_avx512::<P, W, N, COUNT, PF>(self, prims, ray, c) },
            // SAFETY: `Kernel::Simd` with W = 8 is only chosen after detecting AVX2.
            Kernel::Simd if W == 8 => return unsafe { any_avx2::<P, W, N, COUNT, PF>(self, prims, ray, c) },
            Kernel::Simd => return traverse::any::<P, W, N, true, COUNT, PF>(self, prims, ray, c),
            Kernel::Portable => {}
        }
        traverse::any::<P, W, N, false, COUNT, PF>(self, prims, ray, c)
    }

    /// Calls `f(reference, bounds, depth)` for every child reference, depth first. A node
    /// is entered once, and only if it exists: on a broken tree (a cycle, a reference past
    /// the nodes) `f` still sees the reference, which validation reports, and the walk ends.
    fn walk(&self, mut f: impl FnMut(ChildRef, &Aabb, usize)) {
        if self.root == EMPTY {
            return;
        }
        let mut entered = vec![false; self.nodes.len()];
        let mut stack = vec![(self.root, self.root_bounds, 1usize)];
        while let Some((r, b, depth)) = stack.pop() {
            f(r, &b, depth);
            let i = node_index::<N>(r).filter(|_| !is_leaf(r));
            if let Some(i) = i.filter(|&i| entered.get(i).is_some_and(|e| !e)) {
                entered[i] = true;
                self.nodes[i].with_decoded(|n| {
                    for lane in 0..W {
                        if n.child[lane] != EMPTY {
                            stack.push((n.child[lane], n.child_bounds(lane), depth + 1));
                        }
                    }
                });
            }
        }
    }

    fn leaf_prims(&self, r: ChildRef) -> impl Iterator<Item = u32> + '_ {
        let (first, n) = leaf_blocks(r);
        self.blocks[first..first + n].iter().flat_map(|b| b.prim).filter(|&p| p != EMPTY).map(|p| p & !TriBlock::OTHER)
    }
}

/// Lays out `nodes` as `N`, children before parents, each interior lane's box widened to
/// the union of its child's decoded boxes: a layout that rounds boxes outward (quantised)
/// then still nests every box in its parent's, which validation checks. For an exact
/// layout (f32 boxes) the union is the lane's own box: the nodes convert one by one, in
/// parallel, and the f32 layout takes the vector as it is (a copy of tens of MiB, and as
/// many fresh pages, was a few per cent of a build).
fn encode<const W: usize, N: Layout<W>>(nodes: Vec<WideNode<W>>, root: ChildRef) -> Vec<N> {
    let nodes = match (Box::new(nodes) as Box<dyn std::any::Any>).downcast::<Vec<N>>() {
        Ok(same) => return *same,
        Err(other) => *other.downcast::<Vec<WideNode<W>>>().expect("the vector boxed above"),
    };
    if N::EXACT {
        return nodes.par_iter().map(N::encode).collect();
    }
    let mut preorder = Vec::with_capacity(nodes.len());
    let mut stack = vec![root];
    while let Some(r) = stack.pop() {
        if r != EMPTY && !is_leaf(r) {
            preorder.push(index::<W, N>(r));
            stack.extend(nodes[index::<W, N>(r)].child);
        }
    }
    let mut out: Vec<Option<N>> = vec![None; nodes.len()];
    for &i in preorder.iter().rev() {
        let mut n = nodes[i];
        for lane in 0..W {
            let r = n.child[lane];
            if r != EMPTY && !is_leaf(r) {
                let widened = out[index::<W, N>(r)].expect("children come first").with_decoded(|c| (0..W).filter(|&l| c.child[l] != EMPTY).fold(n.child_bounds(lane), |b, l| b.union(c.child_bounds(l))));
                n.set(lane, &widened, r);
            }
        }
        out[i] = Some(N::encode(&n));
    }
    // Nodes no traversal reaches (validation reports them) keep their own boxes.
    out.into_iter().zip(&nodes).map(|(e, n)| e.unwrap_or_else(|| N::encode(n))).collect()
}

/// The index of the node a reference from the collapse points at (always at a node's start).
fn index<const W: usize, N: Layout<W>>(r: ChildRef) -> usize {
    node_index::<N>(r).expect("the collapse references nodes at their start")
}

/// Whether this CPU runs the 16-ray ray-major packet path (`ray_major/avx512.rs`): AVX-512F and VL.
#[cfg(target_arch = "x86_64")]
fn ray_major_available() -> bool {
    use std::is_x86_feature_detected as has;
    has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2")
}

/// The AVX2 instantiations: the whole traversal is compiled with AVX2 so that the box
/// kernel inlines into it, and single rays with BMI (mask loops in `tzcnt` and `blsr`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2")]
unsafe fn closest_avx2<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    traverse::closest::<P, W, N, true, COUNT, PF>(bvh, prims, ray, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn packet_avx2<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
    packet::closest::<P, W, N, true, COUNT>(bvh, prims, rays, out, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2")]
unsafe fn any_avx2<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    traverse::any::<P, W, N, true, COUNT, PF>(bvh, prims, ray, c)
}

/// The AVX-512 instantiations: the same code as the AVX2 ones (the AVX2 and SSE2
/// intrinsics inline into them), given 32 vector registers, mask registers and BMI.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
unsafe fn closest_avx512<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
    traverse::closest::<P, W, N, true, COUNT, PF>(bvh, prims, ray, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
unsafe fn packet_avx512<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
    packet::closest::<P, W, N, true, COUNT>(bvh, prims, rays, out, c)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,bmi1,bmi2")]
unsafe fn any_avx512<P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool, const PF: bool>(bvh: &WideBvh<W, N>, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
    traverse::any::<P, W, N, true, COUNT, PF>(bvh, prims, ray, c)
}

impl<const W: usize, N: Layout<W>> Accel for WideBvh<W, N> {
    #[inline]
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        self.closest_dispatch::<P, true>(prims, ray, c)
    }

    #[inline]
    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        self.any_dispatch::<P, true>(prims, ray, c)
    }

    fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: self.name.into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            memory_bytes: self.bytes(),
            ..Default::default()
        };
        let root_area = (self.root_bounds.half_area() as f64).max(f64::MIN_POSITIVE);
        let mut cost = 0.0;
        self.walk(|r, b, depth| {
            s.max_depth = s.max_depth.max(depth);
            let rel = b.half_area() as f64 / root_area;
            if is_leaf(r) {
                let n = self.leaf_prims(r).count();
                s.add_leaf(n);
                // A block of four is tested as one SIMD step plus its candidates: charge
                // blocks, the unit the kernel works in.
                cost += rel * leaf_blocks(r).1 as f64;
            } else {
                s.interior_nodes += 1;
                cost += rel;
            }
        });
        s.sah_cost = cost;
        let blocks_used = self.blocks.iter().map(|b| b.prim.iter().filter(|&&p| p != EMPTY).count()).sum::<usize>();
        s.note("width", W);
        s.note("boxes", N::NAME);
        s.note("kernel", format!("{:?}", self.kernel));
        s.note("packet kernel", format!("{:?}", self.packet_kernel));
        s.note("prefetch", if self.prefetch_children { "entered and pushed children" } else { "off" });
        s.note("block fill", format!("{:.0}%", 100.0 * blocks_used as f64 / (4 * self.blocks.len()).max(1) as f64));
        s.note("bytes/triangle", format!("{:.1}", s.memory_bytes as f64 / self.primitives.max(1) as f64));
        s
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new(self.name, m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        if self.root == EMPTY {
            return if prims.is_empty() { Ok(()) } else { err("no root for a non-empty scene".into()) };
        }
        let mut seen = vec![false; prims.len()];
        let mut reached = vec![false; self.nodes.len()];
        let mut problem = None;
        self.walk(|r, b, _| {
            if problem.is_some() {
                return;
            }
            if is_leaf(r) {
                let (first, n) = leaf_blocks(r);
                if first + n > self.blocks.len() {
                    problem = Some(format!("leaf {r:#x} points past the blocks"));
                    return;
                }
                for (k, blk) in self.blocks[first..first + n].iter().enumerate() {
                    for lane in 0..4 {
                        let p = blk.prim[lane];
                        if p == EMPTY {
                            continue;
                        }
                        let i = p & !TriBlock::OTHER;
                        if i as usize >= prims.len() {
                            problem = Some(format!("block {} holds primitive {i} of {}", first + k, prims.len()));
                            return;
                        }
                        seen[i as usize] = true;
                        let copy = [0, 1, 2].map(|v| blk.vertex(lane, v));
                        if p & TriBlock::OTHER != 0 && copy != [Vec3::ZERO; 3] {
                            problem = Some(format!("block {} lane {lane}: primitive {i} is not a triangle, yet has vertices", first + k));
                            return;
                        }
                        if (p & TriBlock::OTHER == 0).then_some(copy) != prims.triangle(i) {
                            problem = Some(format!("block {} lane {lane}: triangle data of primitive {i} differs from the mesh", first + k));
                            return;
                        }
                        let pb = prims.bounds(i);
                        let inside = if self.spatial_splits { !pb.intersection(*b).is_empty() } else { b.contains_box(&pb) };
                        if !inside {
                            problem = Some(format!("primitive {i} {} leaf box", if self.spatial_splits { "does not touch its" } else { "sticks out of its" }));
                            return;
                        }
                    }
                }
            } else {
                let Some(i) = node_index::<N>(r) else {
                    problem = Some(format!("reference {r} falls inside a node"));
                    return;
                };
                if i >= self.nodes.len() || reached[i] {
                    problem = Some(format!("node {i} out of range or reached twice"));
                    return;
                }
                reached[i] = true;
                let n = self.nodes[i].with_decoded(|n| *n);
                for lane in 0..W {
                    let cb = n.child_bounds(lane);
                    if n.child[lane] == EMPTY {
                        if cb.min.cmplt(cb.max).any() {
                            problem = Some(format!("node {i} lane {lane}: an empty slot with a non-empty box"));
                            return;
                        }
                    } else if !b.contains_box(&cb) {
                        problem = Some(format!("node {i} lane {lane} sticks out of its parent"));
                        return;
                    }
                }
            }
        });
        if let Some(m) = problem {
            return err(m);
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return err(format!("node {i} is unreachable"));
        }
        if let Some(p) = seen.iter().position(|s| !s) {
            return err(format!("primitive {p} is in no leaf"));
        }
        Ok(())
    }
}
