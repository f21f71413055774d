//! Front-to-back traversal over the ray's `t` interval (pbrt-v3 `KdTreeAccel::Intersect`):
//! at each interior node the interval is cut at the plane, the child on the origin's side
//! is entered first and the other is stacked with the rest of the interval; the walk stops
//! as soon as the closest hit lies before the next stacked interval.
//!
//! Every plane distance is widened by the tree's margin, converted to `t` on the split axis
//! (`margin / |dir[axis]|`): a rounded plane distance then never sends a ray to one child
//! only when a primitive of the other could hold a hit as close (coplanar primitives, edges
//! in a plane, grazing rays), and primitives are always tested on the whole remaining ray,
//! so widening costs a few visits, never a result.

use raylab_core::Ray;

use super::build::MAX_DEPTH;
use super::KdTree;
use crate::leaf::{any_hit, Closest};
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

impl KdTree {
    /// Calls `leaf(ray, primitives, counters)` for the leaves the ray may hit, nearest first;
    /// `leaf` may shrink `ray.t_max` and returns `true` to stop.
    #[inline]
    fn walk(&self, ray: &mut Ray, c: &mut Counters, mut leaf: impl FnMut(&mut Ray, &[u32], &mut Counters) -> bool) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = ray.inv_dir();
        let Some((mut t_min, mut t_max)) = self.bounds.intersect(ray.origin, inv, ray.t_min, ray.t_max) else { return };
        let mut stack = [(0u32, 0f32, 0f32); MAX_DEPTH + 2];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            c.nodes_visited += 1;
            let n = &self.nodes[node];
            if !n.is_leaf() {
                let (axis, split) = (n.axis(), n.split());
                let (o, d) = (ray.origin[axis], ray.dir[axis]);
                let below_first = o < split || (o == split && d <= 0.0);
                let (first, second) = if below_first { (node + 1, n.above()) } else { (n.above(), node + 1) };
                if d == 0.0 {
                    // Parallel to the plane: one side, or both when the ray lies in it.
                    if o == split {
                        stack[sp] = (second as u32, t_min, t_max);
                        sp += 1;
                    }
                    node = first;
                    continue;
                }
                let t_plane = (split - o) * inv[axis];
                let slack = self.margin * inv[axis].abs();
                if t_plane <= 0.0 || t_plane > t_max + slack {
                    node = first;
                } else if t_plane < t_min - slack {
                    node = second;
                } else {
                    stack[sp] = (second as u32, t_min.max(t_plane - slack), t_max);
                    sp += 1;
                    node = first;
                    t_max = t_max.min(t_plane + slack);
                }
                continue;
            }
            if leaf(ray, &self.indices[n.first()..n.first() + n.count()], c) {
                return;
            }
            // Pop the next interval that may still hold a hit nearer than the closest so far.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (next, lo, hi) = stack[sp];
                if lo <= ray.t_max {
                    (node, t_min, t_max) = (next as usize, lo, hi);
                    break;
                }
            }
        }
    }
}

impl Accel for KdTree {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        c.rays += 1;
        let mut ray = *ray;
        let mut closest = Closest::new(prims);
        self.walk(&mut ray, c, |ray, leaf, c| closest.test(ray, leaf.iter().copied(), c));
        closest.best
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        c.rays += 1;
        let mut ray = *ray;
        let mut hit = false;
        self.walk(&mut ray, c, |ray, leaf, c| {
            hit = any_hit(prims, ray, leaf.iter().copied(), c);
            hit
        });
        hit
    }

    fn stats(&self) -> AccelStats {
        KdTree::stats(self)
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        KdTree::validate(self, prims)
    }
}
