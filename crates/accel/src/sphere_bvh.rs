//! A bottom-up hierarchy of bounding spheres, the second seed report's structure: leaves
//! are the primitives' bounding spheres, and the closest clusters are merged pairwise until
//! one sphere holds everything. "Closest" is the smallest merged sphere; instead of the
//! O(N²) search over all pairs, clusters look for their nearest neighbour within a window
//! along the Morton curve (PLOC, Meister & Bittner 2018), which keeps the build near
//! O(N log N) and parallel. Small subtrees are then collapsed into leaves by the SAH (with
//! sphere areas), and rays walk the tree front to back by ray–sphere tests.

use rayon::prelude::*;
use raylab_core::{Aabb, BoundingSphere, Ray, Vec3};

use crate::bvh::traverse::{any_in_tree, closest_in_tree, tree_stats, TreeNode};
use crate::bvh::{lbvh, ploc, SahCost};
use crate::{leaf_margin, Accel, AccelStats, BuildOptions, Counters, Hit, Primitives, ValidationError};

/// One node, 24 bytes: interior when `count == 0` (children at `left_first` and
/// `left_first + 1`), else a leaf of `indices[left_first .. left_first + count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct SphereNode {
    pub center: [f32; 3], // 12 bytes
    pub radius: f32,      //  4
    pub left_first: u32,  //  4
    pub count: u32,       //  4 -> 24
}

const _: () = assert!(std::mem::size_of::<SphereNode>() == 24);

impl SphereNode {
    #[inline]
    pub fn sphere(&self) -> BoundingSphere {
        BoundingSphere { center: Vec3::from_array(self.center), radius: self.radius }
    }

    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// A sphere hierarchy. Invariants: siblings adjacent, root at 0; every child's sphere lies
/// inside its parent's (up to rounding), every leaf's sphere holds its primitives' boxes,
/// and every primitive is in exactly one leaf.
#[derive(Debug)]
pub struct SphereBvh {
    nodes: Vec<SphereNode>,
    indices: Vec<u32>,
    primitives: usize,
    pub(crate) build_ms: f64,
}

/// Relative slack of the containment checks in `validate`: sphere unions are rounded.
const CONTAINMENT_TOLERANCE: f32 = 1e-5;

impl SphereBvh {
    pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Self {
        let n = prims.len();
        let bounds: Vec<Aabb> = (0..n as u32).into_par_iter().map(|i| prims.bounds(i)).collect();
        let margin = leaf_margin(&bounds.par_iter().copied().reduce(|| Aabb::EMPTY, Aabb::union));
        // Each leaf sphere is grown by the margin: a ray through a box corner lies on the
        // sphere's surface, where rounding in the ray–sphere test could otherwise miss it.
        let spheres: Vec<BoundingSphere> = bounds
            .par_iter()
            .map(|b| {
                let s = b.bounding_sphere();
                BoundingSphere { radius: s.radius + margin, ..s }
            })
            .collect();
        let centers: Vec<Vec3> = spheres.iter().map(|s| s.center).collect();
        let tree = ploc::cluster(&spheres, &centers, opts.ploc_radius);
        let (flat, indices) = lbvh::emit(tree, SahCost::from_options(opts), opts.max_leaf_size.max(1));
        let nodes = flat
            .into_iter()
            .map(|f| SphereNode { center: f.volume.center.to_array(), radius: f.volume.radius, left_first: f.left_first, count: f.count })
            .collect();
        Self { nodes, indices, primitives: n, build_ms: 0.0 }
    }

    /// Visits every node with its depth (root depth 1).
    fn visit(&self, mut f: impl FnMut(usize, usize)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![(0usize, 1usize)];
        while let Some((i, depth)) = stack.pop() {
            f(i, depth);
            let n = &self.nodes[i];
            if !n.is_leaf() && (n.left_first as usize) + 1 < self.nodes.len() {
                stack.push((n.left_first as usize, depth + 1));
                stack.push((n.left_first as usize + 1, depth + 1));
            }
        }
    }
}

/// `inner` lies inside `outer` up to [`CONTAINMENT_TOLERANCE`].
fn sphere_contains(outer: &BoundingSphere, inner: &BoundingSphere) -> bool {
    (inner.center - outer.center).length() + inner.radius <= outer.radius * (1.0 + CONTAINMENT_TOLERANCE)
}

impl TreeNode for SphereNode {
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
    #[inline]
    fn entry(&self, ray: &Ray, _inv_dir: Vec3) -> Option<f32> {
        self.sphere().intersect(ray).map(|(t, _)| t)
    }
}

impl Accel for SphereBvh {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        closest_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        any_in_tree(&self.nodes, &self.indices, prims, ray, c)
    }

    fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: "sphere-bvh".into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            memory_bytes: self.nodes.len() * std::mem::size_of::<SphereNode>() + self.indices.len() * 4,
            ..Default::default()
        };
        // Surface-area cost with sphere areas (∝ r²).
        tree_stats(&self.nodes, &mut s, |n| (n.radius as f64).powi(2));
        s
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new("sphere-bvh", m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        if self.nodes.is_empty() {
            return if prims.is_empty() { Ok(()) } else { err("no nodes for a non-empty scene".into()) };
        }
        let mut problem = None;
        let mut reached = vec![false; self.nodes.len()];
        let mut seen = vec![0u32; prims.len()];
        self.visit(|i, _| {
            if problem.is_some() {
                return;
            }
            if std::mem::replace(&mut reached[i], true) {
                problem = Some(format!("node {i} reached twice"));
                return;
            }
            let n = &self.nodes[i];
            let s = n.sphere();
            let (first, count) = (n.left_first as usize, n.count as usize);
            if n.is_leaf() {
                let Some(leaf) = self.indices.get(first..first + count) else {
                    problem = Some(format!("leaf {i} points past the index array"));
                    return;
                };
                for &p in leaf {
                    if p as usize >= prims.len() {
                        problem = Some(format!("leaf {i} holds primitive {p} of {}", prims.len()));
                        return;
                    }
                    let b = prims.bounds(p);
                    seen[p as usize] += 1;
                    let far = (b.centroid() - s.center).abs() + 0.5 * b.extent();
                    if far.length() > s.radius * (1.0 + CONTAINMENT_TOLERANCE) {
                        problem = Some(format!("primitive {p} sticks out of leaf {i}"));
                    }
                }
            } else if first + 1 >= self.nodes.len() || first <= i {
                problem = Some(format!("node {i} has children {first}, {} out of order or range", first + 1));
            } else if let Some(c) = [first, first + 1].into_iter().find(|&c| !sphere_contains(&s, &self.nodes[c].sphere())) {
                problem = Some(format!("child {c} sticks out of node {i}"));
            }
        });
        if let Some(m) = problem {
            return err(m);
        }
        if let Some(i) = reached.iter().position(|r| !r) {
            return err(format!("node {i} is unreachable"));
        }
        if let Some(p) = seen.iter().position(|&c| c != 1) {
            return err(format!("primitive {p} is in {} leaves, not one", seen[p]));
        }
        Ok(())
    }
}
