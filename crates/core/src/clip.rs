//! The part of a triangle inside a box, for spatial splits (kd-tree "perfect splits",
//! SBVH references, grid cells): Sutherland–Hodgman clipping of the triangle by the box's
//! six planes (Havran 2000, §4.5; Stich et al. 2009 clip the same way).

use glam::Vec3;

use crate::Aabb;

/// Bounds of the part of triangle `v` that lies inside `clip` (the empty box when none
/// does). Each plane may add one vertex, so the polygon has at most 3 + 6 = 9.
///
/// A new vertex lies on its plane exactly; its other coordinates carry a few roundings
/// relative to the edge's length, which the callers' margins absorb (see
/// `raylab_accel::robust_margin`). The result is intersected with `clip`, so it is never
/// larger than `bounds(v) ∩ clip`, the conservative answer.
pub fn triangle_bounds(v: [Vec3; 3], clip: &Aabb) -> Aabb {
    let whole = Aabb::from_points(v);
    // Planes the whole triangle lies inside cut nothing (clipping only shrinks it): the
    // usual case in a spatial split's bins, where only the bin's two planes cut.
    // (A triangle touching a plane from inside is not cut by it; treating it as cut would
    // give the same polygon.)
    let cuts = |axis: usize| (whole.min[axis] < clip.min[axis], whole.max[axis] > clip.max[axis]);
    if (0..3).all(|a| cuts(a) == (false, false)) {
        return whole.intersection(*clip);
    }
    // The polygon, in one of two buffers; each pass clips it into the other.
    let mut buf = [[Vec3::ZERO; 9]; 2];
    buf[0][..3].copy_from_slice(&v);
    let (mut cur, mut n) = (0, 3);
    for axis in 0..3 {
        let (below, above) = cuts(axis);
        for (plane, keep_below, cut) in [(clip.min[axis], false, below), (clip.max[axis], true, above)] {
            if !cut {
                continue;
            }
            let inside = |p: Vec3| if keep_below { p[axis] <= plane } else { p[axis] >= plane };
            let [b0, b1] = &mut buf;
            let (src, dst) = if cur == 0 { (&*b0, b1) } else { (&*b1, b0) };
            let mut m = 0;
            // Edges a → b, from the last vertex round to it.
            let (mut a, mut a_in) = (src[n - 1], inside(src[n - 1]));
            for &b in &src[..n] {
                let b_in = inside(b);
                if a_in != b_in {
                    let t = (plane - a[axis]) / (b[axis] - a[axis]);
                    let mut p = a + t * (b - a);
                    p[axis] = plane;
                    dst[m] = p;
                    m += 1;
                }
                if b_in {
                    dst[m] = b;
                    m += 1;
                }
                (a, a_in) = (b, b_in);
            }
            if m == 0 {
                return Aabb::EMPTY;
            }
            (cur, n) = (1 - cur, m);
        }
    }
    Aabb::from_points(buf[cur][..n].iter().copied()).intersection(*clip)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aabb(min: [f32; 3], max: [f32; 3]) -> Aabb {
        Aabb::new(Vec3::from_array(min), Vec3::from_array(max))
    }

    const TRI: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

    #[test]
    fn a_triangle_inside_keeps_its_bounds() {
        assert_eq!(triangle_bounds(TRI, &aabb([-1.0; 3], [2.0; 3])), aabb([0.0; 3], [1.0, 1.0, 0.0]));
    }

    #[test]
    fn a_slab_keeps_the_part_of_the_triangle_inside_it() {
        // x ≥ 1/2 cuts off the corner (1/2, 0), (1, 0), (1/2, 1/2): y reaches 1/2, not 1
        // (the triangle's box ∩ the slab would give y up to 1).
        assert_eq!(triangle_bounds(TRI, &aabb([0.5, -1.0, -1.0], [2.0, 2.0, 1.0])), aabb([0.5, 0.0, 0.0], [1.0, 0.5, 0.0]));
        // x ≤ 1/4 and y ≤ 1/4 both: the square [0, 1/4]² lies wholly below x + y = 1.
        assert_eq!(triangle_bounds(TRI, &aabb([-1.0; 3], [0.25, 0.25, 1.0])), aabb([0.0; 3], [0.25, 0.25, 0.0]));
        // x ∈ [1/4, 3/4], y ≥ 1/2: the edge x + y = 1 leaves x ≤ 1/2 there, so the part is
        // the triangle (1/4, 1/2), (1/2, 1/2), (1/4, 3/4).
        assert_eq!(triangle_bounds(TRI, &aabb([0.25, 0.5, -1.0], [0.75, 2.0, 1.0])), aabb([0.25, 0.5, 0.0], [0.5, 0.75, 0.0]));
    }

    #[test]
    fn a_box_inside_the_triangles_bounds_but_off_the_triangle_gets_nothing() {
        // The corner [0.75, 1]² of the triangle's box lies above x + y = 1.
        assert!(triangle_bounds(TRI, &aabb([0.75, 0.75, -1.0], [1.0, 1.0, 1.0])).is_empty());
        // A box beside the triangle's plane z = 0.
        assert!(triangle_bounds(TRI, &aabb([0.0, 0.0, 0.5], [1.0, 1.0, 1.0])).is_empty());
    }

    #[test]
    fn a_tilted_triangle_is_clipped_in_every_coordinate() {
        // (0,0,0), (2,0,2), (0,2,2) cut by z ≤ 1: the part is (0,0,0), (1,0,1), (0,1,1).
        let t = [Vec3::ZERO, Vec3::new(2.0, 0.0, 2.0), Vec3::new(0.0, 2.0, 2.0)];
        assert_eq!(triangle_bounds(t, &aabb([-5.0; 3], [5.0, 5.0, 1.0])), aabb([0.0; 3], [1.0, 1.0, 1.0]));
        // and by z ≥ 1: the quadrilateral (1,0,1), (2,0,2), (0,2,2), (0,1,1).
        assert_eq!(triangle_bounds(t, &aabb([-5.0, -5.0, 1.0], [5.0; 3])), aabb([0.0, 0.0, 1.0], [2.0, 2.0, 2.0]));
        // Cut on all three axes, x ≥ 1/2, y ≥ 1/2, z ≤ 3/2: with p = (2s, 2t, 2(s + t)) that
        // is s ≥ 1/4, t ≥ 1/4, s + t ≤ 3/4, the triangle (1/2, 1/2, 1), (1, 1/2, 3/2),
        // (1/2, 1, 3/2); the triangle's box cut by the clip box would reach x, y = 2, z = 0.
        assert_eq!(triangle_bounds(t, &aabb([0.5, 0.5, -5.0], [5.0, 5.0, 1.5])), aabb([0.5, 0.5, 1.0], [1.0, 1.0, 1.5]));
    }
}
