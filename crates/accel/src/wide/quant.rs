//! The quantised 8-wide node (`bvh8q`), in the spirit of Ylitie et al.'s compressed wide
//! BVH (CWBVH, 2017): each child box is stored as 8-bit offsets on a per-node grid whose
//! cell sizes are powers of two, so a node is 96 bytes instead of 224 and a box test reads
//! two cache lines instead of four.
//!
//! Decoding is `origin + q · 2^e` in f32: `q · 2^e` is exact (an 8-bit integer times a
//! power of two), and the one rounded addition is monotonic in `q`, so the encoder checks
//! each bound with the very operations the traversal runs and moves it one step outward
//! until the decoded box contains the original. The traversal then runs the f32 slab test
//! on decoded boxes, with the same robustness argument (pbrt-v4's widened far distance):
//! boxes only grow, so no hit is lost, and the portable and AVX2 kernels decode to the same
//! bits.

use super::ray::RayBoxes;
use super::node::{ChildRef, Layout, WideNode, EMPTY};

/// Eight children's boxes quantised on the node's grid: 96 bytes.
///
/// Invariants: lane `l` is in use exactly when bit `l` of `occupied` is set; an unused lane
/// has `child = EMPTY` and the inverted box `q_min = 255`, `q_max = 0`; `exp[a]` is a
/// biased f32 exponent in `1..=254` (a normal scale).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct QuantNode {
    /// The grid's corner: the least corner of the union of the children's boxes.
    pub origin: [f32; 3], // 12
    /// Per axis the biased exponent of the grid step `2^(exp - 127)`: its f32 bits are `exp << 23`.
    pub exp: [u8; 3], //  3
    pub occupied: u8, //  1
    /// Rows as [`WideNode::bounds`]: `q[0..3]` min x, y, z and `q[3..6]` max, one lane per child.
    pub q: [[u8; 8]; 6], // 48
    pub child: [ChildRef; 8], // 32 -> 96
}

const _: () = assert!(std::mem::size_of::<QuantNode>() == 96);

impl QuantNode {
    /// The grid step of axis `a`.
    #[inline(always)]
    pub fn step(&self, a: usize) -> f32 {
        f32::from_bits((self.exp[a] as u32) << 23)
    }

    /// Bound `q` of axis `a` decoded, with the traversal's operations.
    #[inline(always)]
    fn decode(&self, a: usize, q: u8) -> f32 {
        self.origin[a] + q as f32 * self.step(a)
    }
}

/// Finite stand-ins for infinite bounds: a hit point has finite coordinates, so a box
/// clamped to `±f32::MAX` still contains every point a ray can hit in the original.
fn finite(x: f32) -> f32 {
    x.clamp(f32::MIN, f32::MAX)
}

// SAFETY: f32, u8 and u32 fields only, 96 bytes, `align(32)`.
unsafe impl Layout<8> for QuantNode {
    const NAME: &'static str = "quantised";
    const EXACT: bool = false;

    fn encode(n: &WideNode<8>) -> Self {
        let mut out = QuantNode { origin: [0.0; 3], exp: [127; 3], occupied: 0, q: [[255; 8], [255; 8], [255; 8], [0; 8], [0; 8], [0; 8]], child: [EMPTY; 8] };
        let lanes: Vec<usize> = (0..8).filter(|&l| n.child[l] != EMPTY).collect();
        for &l in &lanes {
            out.occupied |= 1 << l;
            out.child[l] = n.child[l];
        }
        if lanes.is_empty() {
            return out;
        }
        for a in 0..3 {
            let lo = lanes.iter().map(|&l| finite(n.bounds[a][l])).fold(f32::MAX, f32::min);
            let hi = lanes.iter().map(|&l| finite(n.bounds[3 + a][l])).fold(f32::MIN, f32::max);
            out.origin[a] = lo;
            // The least step whose 255 cells reach `hi` (in f64 the extent cannot overflow),
            // then checked with the f32 decoding itself.
            let cells = ((hi as f64 - lo as f64) / 255.0).max(f64::MIN_POSITIVE);
            let mut e = (cells.log2().ceil() as i32).clamp(-126, 127);
            out.exp[a] = (e + 127) as u8;
            while out.decode(a, 255) < hi && e < 127 {
                e += 1;
                out.exp[a] = (e + 127) as u8;
            }
            let step = out.step(a) as f64;
            for &l in &lanes {
                let (b_lo, b_hi) = (finite(n.bounds[a][l]), finite(n.bounds[3 + a][l]));
                let mut q_lo = ((b_lo as f64 - lo as f64) / step).floor().clamp(0.0, 255.0) as u8;
                while q_lo > 0 && out.decode(a, q_lo) > b_lo {
                    q_lo -= 1;
                }
                let mut q_hi = ((b_hi as f64 - lo as f64) / step).ceil().clamp(0.0, 255.0) as u8;
                while q_hi < 255 && out.decode(a, q_hi) < b_hi {
                    q_hi += 1;
                }
                out.q[a][l] = q_lo;
                out.q[3 + a][l] = q_hi;
            }
        }
        out
    }

    #[inline(always)]
    fn decoded<'a>(&'a self, scratch: &'a mut std::mem::MaybeUninit<WideNode<8>>) -> &'a WideNode<8> {
        let n = scratch.write(WideNode::<8>::EMPTY_NODE);
        for l in (0..8).filter(|l| self.occupied & (1 << l) != 0) {
            for row in 0..6 {
                n.bounds[row][l] = self.decode(row % 3, self.q[row][l]);
            }
            n.child[l] = self.child[l];
        }
        n
    }

    #[inline(always)]
    fn child(&self, lane: usize) -> ChildRef {
        self.child[lane]
    }

    #[inline(always)]
    fn boxes<const SIMD: bool>(&self, r: &RayBoxes, t_max: f32, tnear: &mut [f32; 8]) -> u32 {
        #[cfg(target_arch = "x86_64")]
        if SIMD {
            // SAFETY: SIMD = true with W = 8 is only instantiated inside functions with AVX2
            // enabled (`closest_avx2`, ...) that `Kernel::available` selects after detecting it.
            return unsafe { boxes_avx2(self, r, t_max, tnear) };
        }
        boxes_portable(self, r, t_max, tnear)
    }
}

/// The slab test of [`kernels::boxes_portable`](super::kernels::boxes_portable) on the
/// decoded boxes of the occupied lanes.
#[inline(always)]
#[allow(clippy::needless_range_loop)] // lanes index the bound rows and `tnear` alike
pub fn boxes_portable(n: &QuantNode, r: &RayBoxes, t_max: f32, tnear: &mut [f32; 8]) -> u32 {
    let mut mask = 0;
    for lane in 0..8 {
        let (mut t0, mut t1) = (r.t_min, t_max);
        for a in 0..3 {
            let near = (n.decode(a, n.q[r.near[a]][lane]) - r.origin[a]) * r.inv[a];
            let far = (n.decode(a, n.q[r.far[a]][lane]) - r.origin[a]) * r.inv_far[a];
            t0 = if near > t0 { near } else { t0 };
            t1 = if far < t1 { far } else { t1 };
        }
        tnear[lane] = t0;
        mask |= u32::from(t0 <= t1) << lane;
    }
    mask & n.occupied as u32
}

/// [`boxes_portable`] with AVX2: each row's eight bytes widened to f32 and decoded in one
/// register, then the slab test of [`slabs_avx2`](super::kernels::slabs_avx2).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn boxes_avx2(n: &QuantNode, r: &RayBoxes, t_max: f32, tnear: &mut [f32; 8]) -> u32 {
    use std::arch::x86_64::*;
    let mut t0 = _mm256_set1_ps(r.t_min);
    let mut t1 = _mm256_set1_ps(t_max);
    for a in 0..3 {
        let base = _mm256_set1_ps(n.origin[a]);
        let step = _mm256_set1_ps(n.step(a));
        // SAFETY: each row is 8 bytes.
        let row = |k: usize| unsafe { _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(n.q[k].as_ptr().cast()))) };
        let lo = _mm256_add_ps(base, _mm256_mul_ps(row(r.near[a]), step));
        let hi = _mm256_add_ps(base, _mm256_mul_ps(row(r.far[a]), step));
        let o = _mm256_set1_ps(r.origin[a]);
        let near = _mm256_mul_ps(_mm256_sub_ps(lo, o), _mm256_set1_ps(r.inv[a]));
        let far = _mm256_mul_ps(_mm256_sub_ps(hi, o), _mm256_set1_ps(r.inv_far[a]));
        t0 = _mm256_max_ps(near, t0);
        t1 = _mm256_min_ps(far, t1);
    }
    // SAFETY: `tnear` holds 8 f32.
    unsafe { _mm256_storeu_ps(tnear.as_mut_ptr(), t0) };
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32 & n.occupied as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::{Aabb, Pcg32, Vec3};

    fn node_of(boxes: &[Aabb]) -> WideNode<8> {
        let mut n = WideNode::<8>::EMPTY_NODE;
        for (l, b) in boxes.iter().enumerate() {
            n.set(l, b, l as u32);
        }
        n
    }

    fn decoded(q: &QuantNode, l: usize) -> Aabb {
        q.with_decoded(|n| n.child_bounds(l))
    }

    #[test]
    fn a_node_is_96_bytes() {
        assert_eq!(std::mem::size_of::<QuantNode>(), 96);
    }

    /// Boxes on a grid of step 1/4 from 0 to 255/4 decode exactly: no bound moves.
    #[test]
    fn boxes_on_the_grid_decode_exactly() {
        let boxes = [Aabb::new(Vec3::ZERO, Vec3::splat(63.75)), Aabb::new(Vec3::new(0.25, 1.0, 2.5), Vec3::new(0.5, 1.25, 40.0))];
        let q = QuantNode::encode(&node_of(&boxes));
        // Extent 63.75 = 255 steps of 2^-2: the exponent is -2, biased 125.
        assert_eq!(q.exp, [125; 3]);
        assert_eq!(q.q[0][1], 1); // 0.25 / 0.25
        assert_eq!(q.q[5][1], 160); // 40 / 0.25
        for (l, b) in boxes.iter().enumerate() {
            assert_eq!(decoded(&q, l), *b);
        }
        assert_eq!(q.occupied, 0b11);
    }

    /// The step is the least power of two whose 255 cells cover the node's extent, measured
    /// from the node's least corner (here 100, not 0): extent 63.75 = 255 · 2^-2.
    #[test]
    fn the_step_covers_the_extent_from_the_least_corner() {
        let boxes = [Aabb::new(Vec3::splat(100.0), Vec3::splat(163.75)), Aabb::new(Vec3::splat(100.5), Vec3::splat(101.0))];
        let q = QuantNode::encode(&node_of(&boxes));
        assert_eq!(q.exp, [125; 3]);
        assert_eq!(q.origin, [100.0; 3]);
        assert_eq!((q.q[0][1], q.q[3][1]), (2, 4)); // 0.5 / 0.25 and 1.0 / 0.25
        for (l, b) in boxes.iter().enumerate() {
            assert_eq!(decoded(&q, l), *b);
        }
    }

    /// Where the f64 estimates round, the f32 checks repair them. With a corner at -2^24
    /// and a step of 2^17, `2^24 ∓ 10^-30` rounds to 2^24 in f64, so the estimates for a box
    /// [-10^-30, 10^-30] are cell 128 on both sides, which decodes to 0: outside the box on
    /// both sides; the checks move them to 127 and 129. And with a corner at -255 and a
    /// maximum of 10^-30, the extent rounds to 255 (a step of 1, whose last cell decodes to
    /// 0 < 10^-30): the check doubles the step.
    #[test]
    fn rounding_in_the_estimates_is_repaired() {
        let c = 2f32.powi(24);
        let tiny = Aabb::new(Vec3::splat(-1e-30), Vec3::splat(1e-30));
        let q = QuantNode::encode(&node_of(&[Aabb::new(Vec3::splat(-c), Vec3::splat(127.0 * 2f32.powi(17))), tiny]));
        assert_eq!(q.exp, [17 + 127; 3]);
        assert_eq!((q.q[0][1], q.q[3][1]), (127, 129));
        assert!(decoded(&q, 1).contains_box(&tiny));
        let wide = Aabb::new(Vec3::splat(-255.0), Vec3::ZERO);
        let up = Aabb::new(Vec3::ZERO, Vec3::splat(1e-30));
        let q = QuantNode::encode(&node_of(&[wide, up]));
        assert_eq!(q.exp, [1 + 127; 3]);
        assert!(decoded(&q, 0).contains_box(&wide) && decoded(&q, 1).contains_box(&up));
        assert_eq!(q.q[3][1], 128); // -255 + 128 · 2 = 1, the first cell end at or above 10^-30
    }

    /// Random boxes, at scales from 1e-30 to 1e30 and far from the origin: every decoded
    /// box contains its original and is at most one grid step larger on each side.
    #[test]
    fn decoded_boxes_contain_the_originals_and_are_tight() {
        let mut rng = Pcg32::new(7, 0);
        for case in 0..4000 {
            let scale = 10f32.powi((case % 61) - 30);
            let offset = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * scale * [0.0, 1.0, 1e3, 1e6][case as usize % 4];
            let k = 1 + case as usize % 8;
            let boxes: Vec<Aabb> = (0..k)
                .map(|_| {
                    let p = offset + Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
                    // Some boxes flat on an axis, as axis-aligned triangles give.
                    let size = Vec3::new(rng.next_f32(), rng.next_f32(), if rng.next_f32() < 0.2 { 0.0 } else { rng.next_f32() }) * scale * 0.3;
                    Aabb::new(p, p + size)
                })
                .collect();
            let q = QuantNode::encode(&node_of(&boxes));
            for (l, b) in boxes.iter().enumerate() {
                let d = decoded(&q, l);
                assert!(d.contains_box(b), "case {case}: {d:?} does not contain {b:?}");
                for a in 0..3 {
                    // One step of slack from the grid, one from the rounding of the origin's addition.
                    let slack = 2.0 * q.step(a) + 2.0 * f32::EPSILON * q.origin[a].abs().max(b.max[a].abs());
                    assert!(b.min[a] - d.min[a] <= slack && d.max[a] - b.max[a] <= slack, "case {case} axis {a}: {d:?} too loose around {b:?}");
                }
            }
            assert_eq!(q.occupied as u32, (1u32 << k) - 1);
        }
    }

    /// Boxes spanning most of the f32 range (an extent that overflows f32) and infinite
    /// bounds still decode to boxes containing every finite point of the originals.
    #[test]
    fn huge_and_infinite_boxes_stay_conservative() {
        let boxes = [Aabb::new(Vec3::splat(-3e38), Vec3::splat(3e38)), Aabb::new(Vec3::new(f32::NEG_INFINITY, 0.0, 0.0), Vec3::new(1.0, f32::INFINITY, 1.0)), Aabb::new(Vec3::splat(1.0), Vec3::splat(1.0))];
        let q = QuantNode::encode(&node_of(&boxes));
        for (l, b) in boxes.iter().enumerate() {
            let d = decoded(&q, l);
            for a in 0..3 {
                assert!(d.min[a] <= b.min[a].max(f32::MIN) && d.max[a] >= b.max[a].min(f32::MAX), "lane {l} axis {a}: {d:?} around {b:?}");
            }
        }
    }

    /// Unused lanes are never entered, whatever the ray: a ray through the whole node hits
    /// only the two occupied lanes.
    #[test]
    fn unused_lanes_are_never_hit() {
        let boxes = [Aabb::new(Vec3::ZERO, Vec3::ONE), Aabb::new(Vec3::splat(2.0), Vec3::splat(3.0))];
        let q = QuantNode::encode(&node_of(&boxes));
        let ray = raylab_core::Ray::new(Vec3::splat(-1.0), Vec3::ONE);
        let mut tnear = [0.0; 8];
        assert_eq!(boxes_portable(&q, &RayBoxes::new(&ray), f32::INFINITY, &mut tnear), 0b11);
        // The first box is entered at t = 1 (the corner 0), the second at t = 3.
        assert_eq!(&tnear[..2], &[1.0, 3.0]);
        // Decoded (for packets, statistics, validation), unused lanes are the f32 layout's
        // empty slots: an inverted infinite box that no slab test enters.
        q.with_decoded(|n| {
            for l in 2..8 {
                assert_eq!(n.child[l], EMPTY);
                assert!((0..3).all(|r| n.bounds[r][l] == f32::INFINITY && n.bounds[3 + r][l] == f32::NEG_INFINITY), "lane {l}");
            }
        });
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            let mut t2 = [0.0; 8];
            // SAFETY: AVX2 detected.
            assert_eq!(unsafe { boxes_avx2(&q, &RayBoxes::new(&ray), f32::INFINITY, &mut t2) }, 0b11);
            assert_eq!(t2[..2], tnear[..2]);
        }
    }
}
