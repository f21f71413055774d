//! Front-to-back traversal with an explicit stack: both children's boxes are tested and the
//! nearer one is entered first, so that the closest hit shrinks `t_max` early.

use raylab_core::Ray;

use super::{Bvh, MAX_DEPTH};
use crate::leaf::{any_hit, Closest};
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

impl Accel for Bvh {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        c.rays += 1;
        let mut ray = *ray;
        let mut closest = Closest::new(prims);
        self.walk(&mut ray, c, |ray, first, count, c| closest.test(ray, self.indices[first..first + count].iter().copied(), c));
        closest.best
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        c.rays += 1;
        let mut ray = *ray;
        let mut hit = false;
        self.walk(&mut ray, c, |ray, first, count, c| {
            hit = any_hit(prims, ray, self.indices[first..first + count].iter().copied(), c);
            hit
        });
        hit
    }

    fn stats(&self) -> AccelStats {
        Bvh::stats(self)
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        Bvh::validate(self, prims)
    }
}

impl Bvh {
    /// Visits the leaves a ray may hit, nearest box first. `leaf(ray, first, count, counters)`
    /// may shrink `ray.t_max`; returning `true` stops the walk.
    #[inline]
    fn walk(&self, ray: &mut Ray, c: &mut Counters, mut leaf: impl FnMut(&mut Ray, usize, usize, &mut Counters) -> bool) {
        let Some(root) = self.nodes.first() else { return };
        let inv = ray.inv_dir();
        if root.bounds().intersect(ray.origin, inv, ray.t_min, ray.t_max).is_none() {
            return;
        }
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            c.nodes_visited += 1;
            let n = &self.nodes[node];
            if n.is_leaf() {
                if leaf(ray, n.left_first as usize, n.count as usize, c) {
                    return;
                }
            } else {
                let l = n.left_first as usize;
                let dl = self.nodes[l].bounds().intersect(ray.origin, inv, ray.t_min, ray.t_max);
                let dr = self.nodes[l + 1].bounds().intersect(ray.origin, inv, ray.t_min, ray.t_max);
                match (dl, dr) {
                    (Some((tl, _)), Some((tr, _))) => {
                        let (near, far) = if tl <= tr { (l, l + 1) } else { (l + 1, l) };
                        stack[sp] = far as u32;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = l + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop until a node that may still hold something nearer than the current hit.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                node = stack[sp] as usize;
                if self.nodes[node].bounds().intersect(ray.origin, inv, ray.t_min, ray.t_max).is_some() {
                    break;
                }
            }
        }
    }
}
