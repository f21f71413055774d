use raylab_core::Aabb;

use crate::BuildOptions;

/// The surface area heuristic (Goldsmith & Salmon 1987; MacDonald & Booth 1990): the
/// expected cost of a split is the traversal cost plus each child's primitive count
/// weighted by the probability, proportional to its surface area, that a ray hitting the
/// parent hits the child.
#[derive(Clone, Copy, Debug)]
pub struct SahCost {
    pub traversal: f32,
    pub intersection: f32,
}

impl SahCost {
    pub fn from_options(o: &BuildOptions) -> Self {
        Self { traversal: o.traversal_cost, intersection: o.intersection_cost }
    }

    pub fn leaf(&self, count: usize) -> f32 {
        self.intersection * count as f32
    }

    /// Cost of splitting `parent` into `(left, n_left)` and `(right, n_right)`.
    pub fn split(&self, parent: &Aabb, left: &Aabb, n_left: usize, right: &Aabb, n_right: usize) -> f32 {
        self.split_areas(parent.half_area(), left.half_area(), n_left, right.half_area(), n_right)
    }

    /// [`SahCost::split`] from the boxes' half areas (a sweep keeps areas, not boxes).
    #[inline]
    pub fn split_areas(&self, parent: f32, left: f32, n_left: usize, right: f32, n_right: usize) -> f32 {
        if parent <= 0.0 {
            // A flat or point-like parent: every ray that hits it hits both children.
            return self.traversal + self.intersection * (n_left + n_right) as f32;
        }
        self.traversal + self.intersection * (left * n_left as f32 + right * n_right as f32) / parent
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Vec3;

    #[test]
    fn hand_computed_split_cost() {
        // Parent 2x1x1 (half area 2+1+2 = 5), children 1x1x1 (half area 3) with 3 and 1 prims.
        let parent = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        let left = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let right = Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0));
        let sah = SahCost { traversal: 1.0, intersection: 1.0 };
        assert!((sah.split(&parent, &left, 3, &right, 1) - (1.0 + (3.0 * 3.0 + 3.0 * 1.0) / 5.0)).abs() < 1e-6);
        assert_eq!(sah.leaf(4), 4.0);
    }
}
