//! Closest hits of a packet traced ray-major, as Embree's `rtcIntersect16` and
//! `rtcIntersect8`: ray `r` lives in lane `r` of every register, and a node's child box (or
//! a leaf's triangle) is broadcast and tested against all the packet's rays at once. The
//! child-major path (`packet.rs`) runs each ray's 8-wide box test in turn instead, and
//! transposes the answers into per-child ray masks.
//!
//! One walk, generic over the register width ([`Vector`]): sixteen rays per 512-bit
//! register with AVX-512 (`avx512.rs`), eight per 256-bit register with AVX2 (`avx2.rs`;
//! CPUs without AVX-512 trace a 16-ray camera tile as two packets of 4×2 rays, as Embree
//! runs `rtcIntersect16` there). Each width brings its instructions and its own ways of
//! loading the rays and of reducing lanes; everything else is written once here.
//!
//! Each lane does the single-ray kernels' IEEE operations in the same order (the slab test
//! of [`slabs_avx2`](super::kernels::slabs_avx2), the watertight test of
//! [`triangles_sse`](super::kernels::triangles_sse)), and hits are kept as the least
//! `(t, prim)` as in [`wins`](super::traverse::wins), so every ray gets exactly its
//! single-ray answer. A stack entry carries each ray's entry distance into the child
//! (infinity for rays that did not enter it), so a pop drops exactly the rays whose hit so
//! far lies nearer, ray by ray.
//!
//! A node is first tested against the packet's frustum (one 8-wide test bounding all the
//! rays' slab distances, as Embree's coherent traversal does), and only the children it
//! keeps are tested ray by ray in the lanes; they are visited in the order of the
//! frustum's entry distances. Pushed children are prefetched.
//!
//! It needs the packet's rays to share their direction signs (the box rows they read) and
//! their shear axes (the triangle coordinates they read): camera tiles nearly always do.
//! [`closest`] declines other packets, and the caller takes the child-major path.

/// The methods of [`Vector`] that are one intrinsic each, for register type `$f`: the
/// broadcast, then `name = intrinsic` pairs of two operands.
macro_rules! one_intrinsic_each {
    ($f:ty, $splat:ident, $($name:ident = $op:ident),*) => {
        #[inline(always)]
        fn splat(self, x: f32) -> $f {
            // SAFETY: the token proves the CPU runs it.
            unsafe { $splat(x) }
        }
        $(
            #[inline(always)]
            fn $name(self, a: $f, b: $f) -> $f {
                // SAFETY: as above.
                unsafe { $op(a, b) }
            }
        )*
    };
}

pub(super) mod avx2;
pub(super) mod avx512;
#[cfg(test)]
mod tests;

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::{gamma, Ray};

use super::ray::{BlockRay, ROBUST_FAR};
use super::node::{is_leaf, Layout, TriBlock, WideNode, EMPTY};
use super::traverse::prefetch;
use super::traverse::{block_closest, exact_lane, insert_sorted, leaf_slice, occupied, wins, STACK};
use super::WideBvh;
use crate::{Counters, Hit, Primitives};

/// One register width's lanes and operations. A value of an implementing type is a token:
/// it exists only where the CPU runs its instructions, so the methods are safe to call.
/// Lane masks are the bits of a `u32`, lane `r` in bit `r`.
///
/// # Safety
/// A token may only be made on a CPU with the width's features, AVX2 among them (the
/// frustum test runs AVX2 for both widths).
pub(super) unsafe trait Vector: Copy {
    /// Rays per packet, one per lane.
    const RAYS: usize;
    /// The bits of every lane.
    const ALL: u32;
    /// A register of `RAYS` f32.
    type F: Copy;
    /// `RAYS` f32 in memory, aligned for the register's loads and stores.
    type Lanes: Copy + AsRef<[f32]> + AsMut<[f32]>;

    fn splat(self, x: f32) -> Self::F;
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    /// `_mm*_min_ps`: `b` when either is NaN.
    fn min(self, a: Self::F, b: Self::F) -> Self::F;
    /// `_mm*_max_ps`: `b` when either is NaN.
    fn max(self, a: Self::F, b: Self::F) -> Self::F;
    fn abs(self, a: Self::F) -> Self::F;
    /// The lanes where comparison `P` (a `_CMP_*` predicate) holds.
    fn cmp<const P: i32>(self, a: Self::F, b: Self::F) -> u32;
    /// Ordered comparisons (false where either is NaN), and the unordered test.
    #[inline(always)]
    fn lt(self, a: Self::F, b: Self::F) -> u32 {
        self.cmp::<_CMP_LT_OQ>(a, b)
    }
    #[inline(always)]
    fn le(self, a: Self::F, b: Self::F) -> u32 {
        self.cmp::<_CMP_LE_OQ>(a, b)
    }
    #[inline(always)]
    fn gt(self, a: Self::F, b: Self::F) -> u32 {
        self.cmp::<_CMP_GT_OQ>(a, b)
    }
    #[inline(always)]
    fn eq(self, a: Self::F, b: Self::F) -> u32 {
        self.cmp::<_CMP_EQ_OQ>(a, b)
    }
    #[inline(always)]
    fn unord(self, a: Self::F, b: Self::F) -> u32 {
        self.cmp::<_CMP_UNORD_Q>(a, b)
    }
    /// `b` in the lanes of `m`, `a` elsewhere.
    fn blend(self, m: u32, a: Self::F, b: Self::F) -> Self::F;
    /// The lanes where the sign bits of `a`, `b` and `c` are not all the same.
    fn signs_differ(self, a: Self::F, b: Self::F, c: Self::F) -> u32;
    /// The lanes where `a`'s bits are below `b`'s as unsigned integers.
    fn below_u32(self, a: Self::F, b: Self::F) -> u32;
    fn least_of(self, v: Self::F) -> f32;
    fn most_of(self, v: Self::F) -> f32;
    fn store(self, v: Self::F) -> Self::Lanes;
    fn load(self, l: &Self::Lanes) -> Self::F;
    /// Fields `0..8` of `rays` (1 to `RAYS`; lanes past their count repeat the last ray),
    /// one register each: field `f` of ray `r` in lane `r` of the `f`-th.
    fn load_rays(self, rays: &[Ray]) -> [Self::F; RAY_F32];
    /// The least and greatest lane of each of `origin` and `inv`, and the least of `t_min`
    /// (all finite).
    fn extremes(self, origin: [Self::F; 3], inv: [Self::F; 3], t_min: Self::F) -> Extremes;
}

/// `N` f32 aligned as register type `A`: a width's [`Vector::Lanes`].
#[derive(Clone, Copy)]
#[repr(C)]
pub(super) struct Lanes<A, const N: usize> {
    _align: [A; 0],
    lanes: [f32; N],
}

impl<A, const N: usize> Lanes<A, N> {
    pub(super) fn new(lanes: [f32; N]) -> Self {
        Lanes { _align: [], lanes }
    }

    pub(super) fn as_mut_ptr(&mut self) -> *mut f32 {
        self.lanes.as_mut_ptr()
    }

    pub(super) fn as_ptr(&self) -> *const f32 {
        self.lanes.as_ptr()
    }
}

impl<A, const N: usize> AsRef<[f32]> for Lanes<A, N> {
    fn as_ref(&self) -> &[f32] {
        &self.lanes
    }
}

impl<A, const N: usize> AsMut<[f32]> for Lanes<A, N> {
    fn as_mut(&mut self) -> &mut [f32] {
        &mut self.lanes
    }
}

/// Floats per [`Ray`]: a ray loads as one 32-byte row.
pub(super) const RAY_F32: usize = 8;
const _: () = assert!(std::mem::size_of::<Ray>() == 4 * RAY_F32);

/// What [`Vector::extremes`] finds.
pub(super) struct Extremes {
    pub(super) origin: [[f32; 2]; 3],
    pub(super) inv: [[f32; 2]; 3],
    pub(super) t_min: f32,
}

/// The packet's per-ray constants, one lane per ray, and what its rays share.
struct Packet<V: Vector> {
    origin: [V::F; 3],
    inv: [V::F; 3],
    inv_far: [V::F; 3],
    t_min: V::F,
    /// Shear `d[kx]/d[kz]`, `d[ky]/d[kz]` and scale `1/d[kz]`.
    shear: [V::F; 3],
    /// `RayBoxes::near` and `far` of every ray.
    near_rows: [usize; 3],
    far_rows: [usize; 3],
    /// `(kx, ky, kz)` of every ray's `ShearedRay`.
    axes: (usize, usize, usize),
    /// `origin` and `shear` stored lane by lane (6 rows).
    each: [V::Lanes; 6],
    /// The packet's frustum, when its constants are finite.
    frustum: Option<Frustum>,
}

/// What bounds every ray's slab distances, so that one 8-wide test culls the children no
/// ray of the packet enters (Embree's coherent traversal does the same). IEEE operations
/// are monotone, so the slab arithmetic on the extreme origin and inverse of each axis
/// bounds each ray's entry distance from below and exit distance from above; with finite
/// constants no NaN arises.
pub(super) struct Frustum {
    /// Per axis, the origin giving the least near-plane difference `bound - origin` for
    /// rays along `+axis` (the greatest origin) and the greatest for rays along `-axis`.
    pub(super) near_origin: [f32; 3],
    /// The other extreme, for the far planes.
    pub(super) far_origin: [f32; 3],
    /// Per axis, the least and greatest inverse direction, and the same of `inv_far`.
    pub(super) inv: [[f32; 2]; 3],
    pub(super) inv_far: [[f32; 2]; 3],
    /// The least `t_min`.
    pub(super) t_min: f32,
}

impl<V: Vector> Packet<V> {
    /// Ray `r`'s `ShearedRay`.
    fn sheared(&self, r: usize) -> ShearedRay {
        let e = |k: usize| self.each[k].as_ref()[r];
        let (kx, ky, kz) = self.axes;
        ShearedRay { origin: raylab_core::Vec3::new(e(0), e(1), e(2)), kx, ky, kz, sx: e(3), sy: e(4), sz: e(5) }
    }

    /// The constants of `rays` (1 to `V::RAYS`; lanes past their count repeat the last
    /// ray), computed as `RayBoxes::new` and `ShearedRay::new` do ray by ray, and their
    /// `t_max`; `None` unless they share box rows and shear axes.
    ///
    /// No closure here or in the walk touches a register: a closure does not inherit the
    /// target features that the width's entry enables, and one left out of line would call
    /// each intrinsic.
    #[inline(always)]
    fn new(v: V, rays: &[Ray]) -> Option<(Packet<V>, V::F)> {
        let f = v.load_rays(rays);
        const ORIGIN: usize = std::mem::offset_of!(Ray, origin) / 4;
        const DIR: usize = std::mem::offset_of!(Ray, dir) / 4;
        let origin = [f[ORIGIN], f[ORIGIN + 1], f[ORIGIN + 2]];
        let dir = [f[DIR], f[DIR + 1], f[DIR + 2]];
        let (t_min, t_max) = (f[std::mem::offset_of!(Ray, t_min) / 4], f[std::mem::offset_of!(Ray, t_max) / 4]);
        let zero = v.splat(0.0);
        let one = v.splat(1.0);
        // `RayBoxes::new` lane by lane: the near rows must agree.
        let inv = [v.div(one, v.add(dir[0], zero)), v.div(one, v.add(dir[1], zero)), v.div(one, v.add(dir[2], zero))];
        let negative = [v.lt(inv[0], zero), v.lt(inv[1], zero), v.lt(inv[2], zero)];
        if negative.iter().any(|&m| m != 0 && m != V::ALL) {
            return None;
        }
        let near_rows = [0, 1, 2].map(|a| if negative[a] != 0 { 3 + a } else { a });
        let far_rows = [0, 1, 2].map(|a| if negative[a] != 0 { a } else { 3 + a });
        // `ShearedRay::new` lane by lane: the axes must agree.
        let ad = [v.abs(dir[0]), v.abs(dir[1]), v.abs(dir[2])];
        let (x0, z0, yz) = (v.gt(ad[0], ad[1]), v.gt(ad[0], ad[2]), v.gt(ad[1], ad[2]));
        let (along_x, along_y) = (x0 & z0, !x0 & yz);
        let kz = if along_x == V::ALL {
            0
        } else if along_y == V::ALL {
            1
        } else if along_x == 0 && along_y == 0 {
            2
        } else {
            return None;
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        match v.lt(dir[kz], zero) {
            0 => {}
            m if m == V::ALL => std::mem::swap(&mut kx, &mut ky),
            _ => return None,
        }
        // `1/d[kz]` is `inv[kz]` (`1/(d + 0)`) unless `d[kz]` is `-0`: a zero direction,
        // left to the child-major path.
        if v.eq(dir[kz], zero) != 0 {
            return None;
        }
        let shear = [v.div(dir[kx], dir[kz]), v.div(dir[ky], dir[kz]), inv[kz]];
        let robust_far = v.splat(ROBUST_FAR);
        let inv_far = [v.mul(inv[0], robust_far), v.mul(inv[1], robust_far), v.mul(inv[2], robust_far)];
        // The same constants ray by ray, for leaves that one ray reaches.
        let each = [v.store(origin[0]), v.store(origin[1]), v.store(origin[2]), v.store(shear[0]), v.store(shear[1]), v.store(shear[2])];
        let inf = v.splat(f32::INFINITY);
        let mut finite = true;
        for x in [origin[0], origin[1], origin[2], inv[0], inv[1], inv[2], inv_far[0], inv_far[1], inv_far[2], t_min] {
            finite &= v.lt(v.abs(x), inf) == V::ALL;
        }
        let frustum = if finite {
            let e = v.extremes(origin, inv, t_min);
            let along = |a: usize, pos: usize| if negative[a] == 0 { e.origin[a][pos] } else { e.origin[a][1 - pos] };
            Some(Frustum {
                near_origin: [0, 1, 2].map(|a| along(a, 1)),
                far_origin: [0, 1, 2].map(|a| along(a, 0)),
                inv: e.inv,
                // Rounding is monotone: the extremes of `inv · ROBUST_FAR` are those of `inv`
                // times it, as each lane computes it.
                inv_far: e.inv.map(|[l, h]| [l * ROBUST_FAR, h * ROBUST_FAR]),
                t_min: e.t_min,
            })
        } else {
            None
        };
        Some((Packet { origin, inv, inv_far, t_min, shear, near_rows, far_rows, axes: (kx, ky, kz), each, frustum }, t_max))
    }
}

/// What each ray has found so far: its `t_max` (the best hit's distance once it has one),
/// the best primitive (its bits; `u32::MAX` for none) and its barycentrics.
struct Best<V: Vector> {
    t: V::F,
    prim: V::F,
    u: V::F,
    v: V::F,
}

/// [`Best`] stored lane by lane.
struct BestLanes<V: Vector> {
    t: V::Lanes,
    prim: V::Lanes,
    u: V::Lanes,
    v: V::Lanes,
}

impl<V: Vector> Best<V> {
    #[inline(always)]
    fn store(&self, v: V) -> BestLanes<V> {
        BestLanes { t: v.store(self.t), prim: v.store(self.prim), u: v.store(self.u), v: v.store(self.v) }
    }

    #[inline(always)]
    fn load(v: V, l: &BestLanes<V>) -> Best<V> {
        Best { t: v.load(&l.t), prim: v.load(&l.prim), u: v.load(&l.u), v: v.load(&l.v) }
    }
}

impl<V: Vector> BestLanes<V> {
    /// Ray `r`'s hit so far.
    fn hit(&self, r: usize) -> Option<Hit> {
        let prim = self.prim.as_ref()[r].to_bits();
        (prim != u32::MAX).then(|| Hit { t: self.t.as_ref()[r], prim, u: self.u.as_ref()[r], v: self.v.as_ref()[r] })
    }
}

/// Closest hits of `rays` (1 to `V::RAYS`) into `out` (as long as `rays`); `false`, with
/// `out` and `c` untouched, for a packet whose rays do not share their box rows and shear
/// axes. Counting (`COUNT`) charges as the child-major path does: each node once per
/// active ray, each block's occupied lanes once per ray tested against it. Inlined into
/// each width's entry (`avx512::closest`, `avx2::closest`), which enables its features.
#[inline(always)]
fn closest<V: Vector, P: Primitives + ?Sized, const W: usize, N: Layout<W>, const COUNT: bool>(v: V, bvh: &WideBvh<W, N>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) -> bool {
    let n = rays.len();
    debug_assert!(W == 8 && (1..=V::RAYS).contains(&n) && out.len() == n);
    let Some((p, t_max)) = Packet::new(v, rays) else { return false };
    out.fill(None);
    if COUNT {
        c.rays += n as u64;
    }
    if bvh.root == EMPTY {
        return true;
    }
    let (near_rows, far_rows, (kx, ky, kz)) = (p.near_rows, p.far_rows, p.axes);
    let zero = v.splat(0.0);
    let inf = v.splat(f32::INFINITY);
    let mut best = Best { t: t_max, prim: v.splat(f32::from_bits(u32::MAX)), u: zero, v: zero };
    let mut far = v.mul(best.t, v.splat(ROBUST_FAR));
    // Every ray's `far`, for the frustum.
    let mut far_max = v.most_of(far);
    let mut stack_node = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut stack_t = [const { MaybeUninit::<V::Lanes>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    // Each ray's entry distance into `cur`: infinity for rays not in it.
    let all = if n == V::RAYS { V::ALL } else { (1 << n) - 1 };
    let mut cur_t = v.blend(all, inf, p.t_min);
    'walk: loop {
        // Rays still in this subtree: entered it, and their hit so far is not nearer.
        let active = v.le(cur_t, far) & all;
        if active != 0 {
            if COUNT {
                c.nodes_visited += u64::from(active.count_ones());
            }
            if is_leaf(cur) {
                let blocks = leaf_slice(bvh, cur);
                if COUNT {
                    c.prim_tests += blocks.iter().map(occupied).sum::<u64>() * u64::from(active.count_ones());
                }
                if active.count_ones() <= FEW_IN_LEAF {
                    few_in_leaf(v, blocks, prims, rays, &p, active, &mut best);
                } else {
                    for b in blocks {
                        block(v, b, prims, rays, &p, (kx, ky, kz), active, &mut best);
                    }
                }
                far = v.mul(best.t, v.splat(ROBUST_FAR));
                far_max = v.most_of(far);
            } else {
                // Children any ray entered, the nearest first; the others wait on the
                // stack with each ray's entry distance.
                let lane_bits = W as u32 - 1;
                let mut entry = [const { MaybeUninit::<V::Lanes>::uninit() }; 8];
                let mut keys = [0u32; 8];
                let mut k = 0;
                let mut scratch = MaybeUninit::uninit();
                let node = bvh.node(cur).decoded(&mut scratch);
                // SAFETY: `W == 8` (the caller's check), so the types are the same.
                let node8 = unsafe { &*(node as *const WideNode<W>).cast::<WideNode<8>>() };
                // Children are ordered by the frustum's entry distance (a packet of copies of
                // one ray walks as that ray does alone), else by their rays' least entry
                // distance.
                let mut order = [0.0f32; 8];
                let mut candidates = match &p.frustum {
                    Some(f) => {
                        // SAFETY: every `Vector` token implies AVX2; `order` holds 8 f32.
                        unsafe {
                            let (m, t0) = frustum_slabs(node8, f, near_rows, far_rows, far_max);
                            _mm256_storeu_ps(order.as_mut_ptr(), t0);
                            m
                        }
                    }
                    None => 0xFF,
                };
                while candidates != 0 {
                    let l = candidates.trailing_zeros() as usize;
                    candidates &= candidates - 1;
                    if node8.child[l] == EMPTY {
                        continue;
                    }
                    let (hit, t0) = slabs(v, node8, l, &p, near_rows, far_rows, far, active);
                    if hit == 0 {
                        continue;
                    }
                    let t0 = v.blend(hit, inf, t0);
                    entry[l] = MaybeUninit::new(v.store(t0));
                    let least = if p.frustum.is_some() { order[l] } else { v.least_of(t0) };
                    insert_sorted(&mut keys, &mut k, (least.to_bits() & !lane_bits) | l as u32);
                }
                if k > 0 {
                    let node = bvh.node(cur);
                    for &key in keys[1..k].iter().rev() {
                        let l = (key & lane_bits) as usize;
                        prefetch(bvh, node.child(l));
                        stack_node[sp] = MaybeUninit::new(node.child(l));
                        stack_t[sp] = entry[l];
                        sp += 1;
                    }
                    let l = (keys[0] & lane_bits) as usize;
                    cur = node.child(l);
                    // SAFETY: the entries of entered lanes were stored above.
                    cur_t = v.load(unsafe { entry[l].assume_init_ref() });
                    continue 'walk;
                }
            }
        }
        if sp == 0 {
            break;
        }
        sp -= 1;
        // SAFETY: entries below `sp` were written by the pushes above.
        (cur, cur_t) = unsafe { (stack_node[sp].assume_init(), v.load(stack_t[sp].assume_init_ref())) };
    }
    let lanes = best.store(v);
    for (r, o) in out.iter_mut().enumerate() {
        *o = lanes.hit(r);
    }
    true
}

/// Leaves that this many rays or fewer reach are tested ray by ray (each ray's four-wide
/// triangle test): a packet's lanes for one ray cost more. Nodes are always tested in the
/// packet's lanes: after the frustum test that is cheaper than ray by ray even for two rays.
pub(super) const FEW_IN_LEAF: u32 = 1;

/// The blocks of a leaf against the `active` rays one at a time, with the single-ray
/// block test, from and into their best hits so far.
#[inline(always)]
fn few_in_leaf<V: Vector, P: Primitives + ?Sized>(v: V, blocks: &[TriBlock], prims: &P, rays: &[Ray], p: &Packet<V>, active: u32, best: &mut Best<V>) {
    let mut lanes = best.store(v);
    let mut m = active;
    while m != 0 {
        let r = m.trailing_zeros() as usize;
        m &= m - 1;
        let mut hit = lanes.hit(r);
        let mut ray = Ray { t_max: lanes.t.as_ref()[r], ..rays[r] };
        let s = p.sheared(r);
        for b in blocks {
            block_closest::<P, true>(b, prims, &s, &BlockRay::new(&s), &mut ray, &mut hit);
        }
        if let Some(h) = hit {
            lanes.t.as_mut()[r] = h.t;
            lanes.prim.as_mut()[r] = f32::from_bits(h.prim);
            lanes.u.as_mut()[r] = h.u;
            lanes.v.as_mut()[r] = h.v;
        }
    }
    *best = Best::load(v, &lanes);
}

/// Child `l` of `node` against the `active` rays: the rays entering it (within each ray's
/// `far` limit) and their entry distances, as [`slabs_avx2`](super::kernels::slabs_avx2)
/// computes them for each ray.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn slabs<V: Vector>(v: V, node: &WideNode<8>, l: usize, p: &Packet<V>, near_rows: [usize; 3], far_rows: [usize; 3], far: V::F, active: u32) -> (u32, V::F) {
    let mut t0 = p.t_min;
    let mut t1 = far;
    for a in 0..3 {
        let lo = v.splat(node.bounds[near_rows[a]][l]);
        let hi = v.splat(node.bounds[far_rows[a]][l]);
        let near = v.mul(v.sub(lo, p.origin[a]), p.inv[a]);
        let far = v.mul(v.sub(hi, p.origin[a]), p.inv_far[a]);
        // As in the single-ray kernel: `max(a, b)` returns `b` when either is NaN.
        t0 = v.max(near, t0);
        t1 = v.min(far, t1);
    }
    (v.le(t0, t1) & active, t0)
}

/// The children of `node` that some ray of the packet may enter (a superset of those any
/// ray's [`slabs`] enters, since `far` bounds every ray's limit) and a lower bound of their
/// rays' entry distances. AVX2 alone, for both widths.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn frustum_slabs(node: &WideNode<8>, f: &Frustum, near_rows: [usize; 3], far_rows: [usize; 3], far: f32) -> (u32, __m256) {
    let mut t0 = _mm256_set1_ps(f.t_min);
    let mut t1 = _mm256_set1_ps(far);
    let set = _mm256_set1_ps;
    for a in 0..3 {
        // SAFETY: a row holds 8 f32.
        let (lo, hi) = unsafe { (_mm256_loadu_ps(node.bounds[near_rows[a]].as_ptr()), _mm256_loadu_ps(node.bounds[far_rows[a]].as_ptr())) };
        let (dn, df) = (_mm256_sub_ps(lo, set(f.near_origin[a])), _mm256_sub_ps(hi, set(f.far_origin[a])));
        let near = _mm256_min_ps(_mm256_mul_ps(dn, set(f.inv[a][0])), _mm256_mul_ps(dn, set(f.inv[a][1])));
        let far = _mm256_max_ps(_mm256_mul_ps(df, set(f.inv_far[a][0])), _mm256_mul_ps(df, set(f.inv_far[a][1])));
        t0 = _mm256_max_ps(near, t0);
        t1 = _mm256_min_ps(far, t1);
    }
    (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32, t0)
}

/// The triangles of block `b` against the `active` rays, updating each ray's best hit; a
/// lane the SIMD arithmetic cannot decide, or that is not a triangle, goes through the
/// exact scalar kernel ray by ray, as in single-ray traversal.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn block<V: Vector, P: Primitives + ?Sized>(v: V, b: &TriBlock, prims: &P, rays: &[Ray], p: &Packet<V>, axes: (usize, usize, usize), active: u32, best: &mut Best<V>) {
    for j in 0..4 {
        let prim = b.prim[j];
        if prim == EMPTY {
            continue;
        }
        let zero = v.splat(0.0);
        let (hit, exact, t, u, w) = if prim & TriBlock::OTHER != 0 { (0, active, zero, zero, zero) } else { triangle(v, b, j, p, axes, active, best.t) };
        if hit != 0 {
            keep(v, best, hit, t, u, w, prim);
        }
        let mut m = exact;
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            let so_far = best.store(v);
            let ray = Ray { t_max: so_far.t.as_ref()[r], ..rays[r] };
            let id = prim & !TriBlock::OTHER;
            let so_far = so_far.hit(r);
            if let Some(x) = exact_lane(b, j, prims, &ShearedRay::new(&ray), &ray).filter(|x| x.t <= ray.t_max && wins(x.t, id, &so_far)) {
                keep(v, best, 1 << r, v.splat(x.t), v.splat(x.u), v.splat(x.v), id);
            }
        }
    }
}

/// Makes `(t, prim)` the best hit of the rays in `hit` where it wins: nearer, or as near
/// and a lower primitive ([`wins`](super::traverse::wins)).
#[inline(always)]
fn keep<V: Vector>(v: V, best: &mut Best<V>, hit: u32, t: V::F, u: V::F, w: V::F, prim: u32) {
    let id = v.splat(f32::from_bits(prim));
    let nearer = v.lt(t, best.t);
    let tie = v.eq(t, best.t) & v.below_u32(id, best.prim);
    let win = hit & (nearer | tie);
    best.t = v.blend(win, best.t, t);
    best.u = v.blend(win, best.u, u);
    best.v = v.blend(win, best.v, w);
    best.prim = v.blend(win, best.prim, id);
}

/// Triangle `j` of block `b` against the `active` rays: [`triangles_sse`]'s operations
/// for one triangle and a packet of rays. Returns the rays hitting it within
/// `(t_min, t_max]` with `t` and barycentrics, and the rays left to the exact scalar
/// kernel.
///
/// [`triangles_sse`]: super::kernels::triangles_sse
#[inline(always)]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn triangle<V: Vector>(v: V, b: &TriBlock, j: usize, p: &Packet<V>, (kx, ky, kz): (usize, usize, usize), active: u32, t_max: V::F) -> (u32, u32, V::F, V::F, V::F) {
    let [_, _, sz] = p.shear;
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (project(v, b, 0, j, p, (kx, ky, kz)), project(v, b, 1, j, p, (kx, ky, kz)), project(v, b, 2, j, p, (kx, ky, kz)));
    let u = v.sub(v.mul(cx, by), v.mul(cy, bx));
    let e = v.sub(v.mul(ax, cy), v.mul(ay, cx));
    let w = v.sub(v.mul(bx, ay), v.mul(by, ax));
    let zero = v.splat(0.0);
    let mixed = v.signs_differ(u, e, w);
    // Most rays reaching a leaf miss most of its triangles, and the edge functions say
    // so: all three non-zero and not NaN (their product's magnitude above zero, as in
    // `triangles_sse`) with mixed signs.
    let nonzero = v.gt(v.abs(v.mul(v.mul(u, e), w)), zero);
    if active & !(nonzero & mixed) == 0 {
        return (0, 0, zero, zero, zero);
    }
    let undecided_edges = v.eq(u, zero) | v.eq(e, zero) | v.eq(w, zero) | v.unord(u, e) | v.unord(w, w);
    // Where the edge functions are decided, mixed signs are "outside".
    let outside = mixed;
    let det = v.add(v.add(u, e), w);
    let (az, bz, cz) = (v.mul(sz, az), v.mul(sz, bz), v.mul(sz, cz));
    let t_scaled = v.add(v.add(v.mul(u, az), v.mul(e, bz)), v.mul(w, cz));
    let inv_det = v.div(v.splat(1.0), det);
    let t = v.mul(t_scaled, inv_det);
    let (max_zt, max_xt, max_yt, max_e) = (max3(v, az, bz, cz), max3(v, ax, bx, cx), max3(v, ay, by, cy), max3(v, u, e, w));
    let (g2, g3, g5) = (v.splat(gamma(2)), v.splat(gamma(3)), v.splat(gamma(5)));
    let delta_z = v.mul(g3, max_zt);
    let delta_x = v.mul(g5, v.add(max_xt, max_zt));
    let delta_y = v.mul(g5, v.add(max_yt, max_zt));
    let delta_e = v.mul(v.splat(2.0), v.add(v.add(v.mul(v.mul(g2, max_xt), max_yt), v.mul(delta_y, max_xt)), v.mul(delta_x, max_yt)));
    let delta_t = v.mul(v.mul(v.splat(3.0), v.add(v.add(v.mul(v.mul(g3, max_e), max_zt), v.mul(delta_e, max_zt)), v.mul(delta_z, max_e))), v.abs(inv_det));
    let inf = v.splat(f32::INFINITY);
    let finite = v.lt(v.abs(t), inf) & v.lt(v.abs(delta_t), inf);
    let ahead = v.gt(t, delta_t);
    let behind = v.lt(t, v.sub(zero, delta_t));
    let rejected = !undecided_edges & (outside | v.eq(det, zero));
    let decided_t = finite & (ahead | behind);
    let in_range = v.gt(t, p.t_min) & v.le(t, t_max);
    let hit = active & !(undecided_edges | rejected) & finite & ahead & in_range;
    let exact = active & (undecided_edges | !(rejected | decided_t));
    (hit, exact, t, v.mul(e, inv_det), v.mul(w, inv_det))
}

/// Vertex `q` of triangle `j` in each ray's sheared frame: `x`, `y` and the unscaled `z`.
#[inline(always)]
fn project<V: Vector>(v: V, b: &TriBlock, q: usize, j: usize, p: &Packet<V>, (kx, ky, kz): (usize, usize, usize)) -> (V::F, V::F, V::F) {
    let [sx, sy, _] = p.shear;
    let az = v.sub(v.splat(b.p[q][kz][j]), p.origin[kz]);
    let x = v.sub(v.sub(v.splat(b.p[q][kx][j]), p.origin[kx]), v.mul(sx, az));
    let y = v.sub(v.sub(v.splat(b.p[q][ky][j]), p.origin[ky]), v.mul(sy, az));
    (x, y, az)
}

/// The greatest magnitude of `a`, `b` and `c`, lane by lane.
#[inline(always)]
fn max3<V: Vector>(v: V, a: V::F, b: V::F, c: V::F) -> V::F {
    v.max(v.max(v.abs(a), v.abs(b)), v.abs(c))
}
