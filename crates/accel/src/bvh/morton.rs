//! Morton codes (Z-order): points quantised in their bounds and their coordinates' bits
//! interleaved, so that sorting by code walks space along a Z curve. LBVH reads its tree
//! off the sorted codes; PLOC and the sphere hierarchy start their clustering from that
//! order.

use rayon::prelude::*;
use raylab_core::{Aabb, Vec3};

/// Bits per axis of a Morton code: 3 × 10 = 30 bits fit a `u32`.
pub const MORTON_BITS: u32 = 10;

/// Spreads the low 10 bits of `v` to every third bit (bit k goes to bit 3k).
#[inline]
fn expand_bits(v: u32) -> u32 {
    let mut v = v & 0x3ff;
    v = (v | (v << 16)) & 0x0300_00ff;
    v = (v | (v << 8)) & 0x0300_f00f;
    v = (v | (v << 4)) & 0x030c_30c3;
    v = (v | (v << 2)) & 0x0924_9249;
    v
}

/// 30-bit Morton code of quantised coordinates (each below 1024): the bits of `x`, `y`, `z`
/// interleaved, `x` most significant in each triple (Karras 2012's convention).
#[inline]
pub fn morton3(x: u32, y: u32, z: u32) -> u32 {
    (expand_bits(x) << 2) | (expand_bits(y) << 1) | expand_bits(z)
}

/// Morton code of `p` quantised in `bounds`: `bounds.min` maps to 0, `bounds.max` to the
/// largest code; a flat axis maps to 0.
#[inline]
pub fn morton_code(p: Vec3, bounds: &Aabb) -> u32 {
    let cells = (1u32 << MORTON_BITS) as f32;
    let q = (bounds.offset(p) * cells).clamp(Vec3::ZERO, Vec3::splat(cells - 1.0));
    morton3(q.x as u32, q.y as u32, q.z as u32)
}

/// Indices of `points` sorted by their Morton codes in the points' bounds (ties by index,
/// so the order is deterministic), with the sorted codes. Parallel codes and sort.
pub(crate) fn morton_order(points: &[Vec3]) -> (Vec<u32>, Vec<u32>) {
    let bounds = points.par_iter().fold(|| Aabb::EMPTY, |b, &p| b.grow(p)).reduce(|| Aabb::EMPTY, Aabb::union);
    let mut keys: Vec<u64> =
        points.par_iter().enumerate().map(|(i, &p)| (morton_code(p, &bounds) as u64) << 32 | i as u64).collect();
    keys.par_sort_unstable();
    keys.into_par_iter().map(|k| (k as u32, (k >> 32) as u32)).unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_of_known_points() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert_eq!(morton_code(Vec3::ZERO, &b), 0);
        assert_eq!(morton_code(Vec3::ONE, &b), (1 << 30) - 1);
        // x = 0b11 -> bits 2 and 5; z = 0b101 -> bits 0 and 6: 4 + 32 + 1 + 64.
        assert_eq!(morton3(3, 0, 5), 101);
        assert_eq!(morton3(1, 0, 0), 4);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 1);
        // The top bit of x is the code's top bit: the first split halves space along x.
        assert_eq!(morton3(512, 0, 0), 1 << 29);
        // (0.5, 0.25, 0) quantises to (512, 256, 0).
        assert_eq!(morton_code(Vec3::new(0.5, 0.25, 0.0), &b), (1 << 29) | (1 << 25));
    }
}
