//! Closest hits of a packet of up to [`PACKET`] rays (a 4×4 tile of camera rays) through
//! a wide BVH: the packet walks the tree together, each stack entry carrying the mask of
//! rays that entered the child, so a node is loaded once for all the rays that reach it
//! and the stack, the ordering and the loop run once per packet instead of once per ray.
//!
//! Each active ray tests a node's `W` child boxes with the single-ray kernel (AVX2 or
//! portable), and each candidate triangle with the same exact kernel, so the answers are
//! those of single-ray traversal bit for bit: hits are kept as the least `(t, prim)`
//! (see [`super::traverse::wins`]), which does not depend on the order of the tests, and
//! a ray's box tests are as conservative as when it travels alone.

use std::mem::MaybeUninit;

use raylab_core::intersect::ShearedRay;
use raylab_core::Ray;

use super::kernels::{RayBoxes, ROBUST_FAR};
use super::node::{is_leaf, ChildRef, TriBlock, EMPTY};
use super::traverse::{candidates, child_boxes, leaf_slice, wins, STACK};
use super::WideBvh;
use crate::{Hit, PrimHit, Primitives};

/// Rays per packet: a 4×4 tile, one bit each in a [`RayMask`].
pub const PACKET: usize = 16;

/// Bit `r` set: ray `r` of the packet is active.
type RayMask = u32;

#[derive(Clone, Copy)]
struct Entry {
    node: ChildRef,
    rays: RayMask,
    /// The least entry distance of those rays.
    t: f32,
}

/// Iterates over the set bits of a mask, lowest first.
#[inline(always)]
fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            b
        })
    })
}

/// Closest hits of `rays` (at most [`PACKET`]) into `out` (as long as `rays`).
#[inline(always)]
pub(super) fn closest<P: Primitives + ?Sized, const W: usize, const SIMD: bool>(bvh: &WideBvh<W>, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
    let n = rays.len();
    assert!(n <= PACKET && out.len() == n, "a packet holds at most {PACKET} rays and as many answers");
    out.fill(None);
    if bvh.root == EMPTY || n == 0 {
        return;
    }
    // Lanes past `n` repeat the last ray and are never active.
    let mut ray: [Ray; PACKET] = std::array::from_fn(|r| rays[r.min(n - 1)]);
    let rb: [RayBoxes; PACKET] = std::array::from_fn(|r| RayBoxes::new(&ray[r]));
    let sheared: [ShearedRay; PACKET] = std::array::from_fn(|r| ShearedRay::new(&ray[r]));
    // Each ray's far limit for box tests, widened as in single-ray traversal.
    let mut far: [f32; PACKET] = std::array::from_fn(|r| ray[r].t_max * ROBUST_FAR);
    let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let mut active: RayMask = (1 << n) - 1;
    'walk: loop {
        if is_leaf(cur) {
            for b in leaf_slice(bvh, cur) {
                for r in bits(active) {
                    let s = &sheared[r];
                    let mut m = candidates::<SIMD>(b, s);
                    while m != 0 {
                        let l = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let p = b.prim[l];
                        let prim = p & !TriBlock::OTHER;
                        let hit = if p & TriBlock::OTHER != 0 {
                            prims.intersect(prim, &ray[r])
                        } else {
                            s.triangle(ray[r].t_min, ray[r].t_max, b.vertex(l, 0), b.vertex(l, 1), b.vertex(l, 2)).map(|(t, u, v)| PrimHit { t, u, v })
                        };
                        if let Some(h) = hit {
                            if wins(h.t, prim, &out[r]) {
                                ray[r].t_max = h.t;
                                far[r] = h.t * ROBUST_FAR;
                                out[r] = Some(Hit::new(prim, h));
                            }
                        }
                    }
                }
            }
        } else {
            let node = &bvh.nodes[cur as usize];
            // Per child: the rays entering it and their least entry distance.
            let mut entered = [0 as RayMask; W];
            let mut nearest = [f32::INFINITY; W];
            let mut any = 0u32;
            for r in bits(active) {
                let mut tnear = [0.0f32; W];
                let m = child_boxes::<W, SIMD>(node, &rb[r], far[r], &mut tnear);
                any |= m;
                for l in bits(m) {
                    entered[l] |= 1 << r;
                    nearest[l] = nearest[l].min(tnear[l]);
                }
            }
            if any != 0 {
                if any & (any - 1) == 0 {
                    let l = any.trailing_zeros() as usize;
                    cur = node.child[l];
                    active = entered[l];
                    continue 'walk;
                }
                // Nearest child first, as in single-ray traversal (keys: distance bits
                // with the lane in the low bits).
                let lane_bits = W as u32 - 1;
                let mut keys = [0u32; W];
                let mut k = 0;
                for l in bits(any) {
                    let key = (nearest[l].to_bits() & !lane_bits) | l as u32;
                    let mut j = k;
                    while j > 0 && keys[j - 1] > key {
                        keys[j] = keys[j - 1];
                        j -= 1;
                    }
                    keys[j] = key;
                    k += 1;
                }
                for &key in keys[1..k].iter().rev() {
                    let l = (key & lane_bits) as usize;
                    stack[sp] = MaybeUninit::new(Entry { node: node.child[l], rays: entered[l], t: nearest[l] });
                    sp += 1;
                }
                let l = (keys[0] & lane_bits) as usize;
                cur = node.child[l];
                active = entered[l];
                continue 'walk;
            }
        }
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below `sp` were written by the pushes above.
            let e = unsafe { stack[sp].assume_init() };
            // Rays whose hit so far is nearer than every entry into the child drop out.
            let mut alive = 0;
            for r in bits(e.rays) {
                alive |= RayMask::from(e.t <= far[r]) << r;
            }
            if alive != 0 {
                cur = e.node;
                active = alive;
                continue 'walk;
            }
        }
        break;
    }
}
