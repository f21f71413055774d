//! The BVH's side of the shared binary-tree walk (`tree.rs`): how a ray enters a box.

use raylab_core::{Ray, Vec3};

use super::{Bvh, BvhNode};
use crate::tree::{any_in_tree, closest_in_tree, TreeNode};
use crate::wide::ray::ROBUST_FAR;
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

impl Accel for Bvh {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        closest_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        any_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn stats(&self) -> AccelStats {
        Bvh::stats(self)
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        Bvh::validate(self, prims)
    }
}

impl TreeNode for BvhNode {
    #[inline]
    fn is_leaf(&self) -> bool {
        self.count > 0
    }
    #[inline]
    fn left_first(&self) -> usize {
        self.left_first as usize
    }
    #[inline]
    fn count(&self) -> usize {
        self.count as usize
    }
    /// Against `t_max` widened by `1 + 2γ₃`, as the wide traversal does: the triangles
    /// around a vertex hit at distances an ulp apart, and the box of the nearer one may
    /// round its entry above the farther hit; pruning it returned a hit an ulp behind the
    /// oracle's (issue 12).
    #[inline]
    fn entry(&self, ray: &Ray, inv_dir: Vec3) -> Option<f32> {
        self.bounds().intersect(ray.origin, inv_dir, ray.t_min, ray.t_max * ROBUST_FAR).map(|(t, _)| t)
    }
}
