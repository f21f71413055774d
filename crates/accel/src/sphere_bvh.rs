//! A bottom-up hierarchy of bounding spheres, the second seed report's structure: leaves
//! are the primitives' bounding spheres, and the closest clusters are merged pairwise until
//! one sphere holds everything. "Closest" is the smallest merged sphere; instead of the
//! O(N²) search over all pairs, clusters look for their nearest neighbour within a window
//! along the Morton curve (PLOC, Meister & Bittner 2018), which keeps the build near
//! O(N log N) and parallel. Small subtrees are then collapsed into leaves by the SAH (with
//! sphere areas), and rays walk the tree front to back by ray–sphere tests.

use rayon::prelude::*;
use raylab_core::{Aabb, BoundingSphere, Ray, Vec3};

use crate::tree::{any_in_tree, closest_in_tree, tree_stats, validate_tree, Containment, TreeNode};
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
            .into_par_iter()
            .map(|f| SphereNode { center: f.volume.center.to_array(), radius: f.volume.radius, left_first: f.left_first, count: f.count })
            .collect();
        Self { nodes, indices, primitives: n, build_ms: 0.0 }
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
        let leaf_holds = |i: usize, n: &SphereNode, p: u32| {
            let (b, s) = (prims.bounds(p), n.sphere());
            let far = (b.centroid() - s.center).abs() + 0.5 * b.extent();
            if far.length() > s.radius * (1.0 + CONTAINMENT_TOLERANCE) {
                return Err(format!("primitive {p} sticks out of leaf {i}"));
            }
            Ok(())
        };
        let child_inside = |n: &SphereNode, c: &SphereNode| sphere_contains(&n.sphere(), &c.sphere());
        validate_tree("sphere-bvh", &self.nodes, &self.indices, self.primitives, prims, Containment { child_inside, leaf_holds, each_once: true })
    }
}

#[cfg(test)]
mod tests {
    //! `validate` on trees built by hand (the fields are private, so these cannot be made
    //! outside), and the containment test against values worked out by hand. (Issue 15.)
    use super::*;
    use crate::PrimHit;

    /// Unit cubes at x = 10 + 3k as primitives.
    struct Cubes(usize);

    impl Primitives for Cubes {
        fn len(&self) -> usize {
            self.0
        }
        fn bounds(&self, i: u32) -> Aabb {
            let x = 10.0 + 3.0 * i as f32;
            Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
        }
        fn intersect(&self, _: u32, _: &Ray) -> Option<PrimHit> {
            None
        }
    }

    /// A node whose sphere (centre (13, 0.5, 0.5), radius 10) holds every cube used here.
    fn node(left_first: u32, count: u32) -> SphereNode {
        SphereNode { center: [13.0, 0.5, 0.5], radius: 10.0, left_first, count }
    }

    fn check(nodes: Vec<SphereNode>, indices: Vec<u32>, n: usize) -> Result<(), String> {
        SphereBvh { nodes, indices, primitives: n, build_ms: 0.0 }.validate(&Cubes(n)).map_err(|e| e.message)
    }

    /// Two unit cubes at x = 10 and 13, built: the scene's extent is 4, so leaves grow by
    /// 4·2⁻¹⁸ = 2⁻¹⁶ beyond the cubes' bounding spheres (centres (10.5, ½, ½) and
    /// (13.5, ½, ½), radius √3/2). The root is their union: centres 3 apart, equal radii, so
    /// its centre is the midpoint (12, ½, ½) and its radius 1.5 + r, grown by 4ε. The SAH
    /// splits (a leaf of two costs 2R² ≈ 11.2, the split R² + 2r² ≈ 7.1, with R ≈ 2.37 and
    /// r ≈ 0.87): the root over two leaves of one cube each.
    #[test]
    fn build_by_hand() {
        let b = SphereBvh::build(&Cubes(2), &BuildOptions::default());
        let r = 0.5 * 3f32.sqrt() + 2f32.powi(-16);
        let big = (1.5 + r) * (1.0 + 4.0 * f32::EPSILON);
        assert_eq!(b.nodes.len(), 3);
        assert_eq!((b.nodes[0].center, b.nodes[0].left_first, b.nodes[0].count), ([12.0, 0.5, 0.5], 1, 0));
        assert!((b.nodes[0].radius - big).abs() < 1e-6, "root radius {} vs {big}", b.nodes[0].radius);
        for (k, x) in [(1, 10.5), (2, 13.5)] {
            let n = b.nodes[k];
            assert_eq!((n.center, n.count), ([x, 0.5, 0.5], 1), "node {k}");
            assert!((n.radius - r).abs() < 1e-6, "node {k}: radius {} vs {r}", n.radius);
            let first = n.left_first as usize;
            assert_eq!(b.indices[first..first + 1], [k as u32 - 1], "node {k}");
        }
        assert_eq!(b.primitives, 2);
        b.validate(&Cubes(2)).unwrap();
        // One cube: a single leaf, grown by 2⁻¹⁸ (extent 1). No cube: no node.
        let one = SphereBvh::build(&Cubes(1), &BuildOptions::default());
        assert_eq!((one.nodes.len(), one.nodes[0].center, one.nodes[0].count, one.indices.clone()), (1, [10.5, 0.5, 0.5], 1, vec![0]));
        assert!((one.nodes[0].radius - (0.5 * 3f32.sqrt() + 2f32.powi(-18))).abs() < 1e-7);
        let none = SphereBvh::build(&Cubes(0), &BuildOptions::default());
        assert!(none.nodes.is_empty() && none.indices.is_empty());
    }

    #[test]
    fn sphere_containment_by_hand() {
        let outer = BoundingSphere { center: Vec3::new(5.0, 0.0, 0.0), radius: 2.0 };
        let at = |x: f32, radius: f32| BoundingSphere { center: Vec3::new(x, 0.0, 0.0), radius };
        // Touching from inside: distance 1 + radius 1 = 2, the outer radius.
        assert!(sphere_contains(&outer, &at(6.0, 1.0)));
        // Within the relative slack 10⁻⁵ (2 · 10⁻⁵ = 2e-5 here): 1 + 1.00001 ≤ 2.00002.
        assert!(sphere_contains(&outer, &at(6.0, 1.00001)));
        // Beyond it: 1 + 1.0001 > 2.00002; and entirely outside.
        assert!(!sphere_contains(&outer, &at(6.0, 1.0001)));
        assert!(!sphere_contains(&outer, &at(9.0, 0.5)));
        assert!(sphere_contains(&outer, &at(4.0, 0.5)));
    }

    #[test]
    fn validate_rejects_each_broken_tree() {
        // A good tree: root over leaves {0} and {1}.
        check(vec![node(1, 0), node(0, 1), node(1, 1)], vec![0, 1], 2).unwrap();
        // Children past the end (1 + 1 = 2 nodes) or not after their parent.
        assert_eq!(check(vec![node(1, 0), node(0, 2)], vec![0, 1], 2).unwrap_err(), "node 0 has children 1, 2 out of order or range");
        assert_eq!(check(vec![node(0, 0), node(0, 1), node(1, 1)], vec![0, 1], 2).unwrap_err(), "node 0 has children 0, 1 out of order or range");
        // A child sphere outside its parent's.
        let mut small = vec![node(1, 0), node(0, 1), node(1, 1)];
        small[0].radius = 1.0;
        assert_eq!(check(small, vec![0, 1], 2).unwrap_err(), "child 1 sticks out of node 0");
        let mut moved = vec![node(1, 0), node(0, 1), node(1, 1)];
        moved[2].center[0] = 14.0;
        assert_eq!(check(moved, vec![0, 1], 2).unwrap_err(), "child 2 sticks out of node 0");
        // Leaves pointing past the indices, or at a primitive that does not exist.
        assert_eq!(check(vec![node(1, 0), node(0, 1), node(1, 2)], vec![0, 1], 2).unwrap_err(), "leaf 2 points past the index array");
        assert_eq!(check(vec![node(1, 0), node(0, 1), node(1, 1)], vec![0, 5], 2).unwrap_err(), "leaf 2 holds primitive 5 of 2");
        // A primitive outside its leaf's sphere: cube 1 spans x 13..14, its corners lie √3/2 ≈
        // 0.866 from its centre: a sphere of radius 0.8 there misses them, one of 0.9 holds them.
        let mut tight = vec![node(1, 0), node(0, 1), node(1, 1)];
        tight[2] = SphereNode { center: [13.5, 0.5, 0.5], radius: 0.8, left_first: 1, count: 1 };
        assert_eq!(check(tight, vec![0, 1], 2).unwrap_err(), "primitive 1 sticks out of leaf 2");
        let mut fits = vec![node(1, 0), node(0, 1), node(1, 1)];
        fits[2] = SphereNode { center: [13.5, 0.5, 0.5], radius: 0.9, left_first: 1, count: 1 };
        check(fits, vec![0, 1], 2).unwrap();
        // Off centre, at x = 13.4: the farthest corners, at x = 14, lie (0.6, ½, ½) away,
        // √0.86 ≈ 0.9274: a radius of 0.9 misses them, 0.93 holds them.
        let leaf = |x: f32, radius: f32| vec![node(1, 0), node(0, 1), SphereNode { center: [x, 0.5, 0.5], radius, left_first: 1, count: 1 }];
        assert_eq!(check(leaf(13.4, 0.9), vec![0, 1], 2).unwrap_err(), "primitive 1 sticks out of leaf 2");
        check(leaf(13.4, 0.93), vec![0, 1], 2).unwrap();
        // The relative slack of 10⁻⁵ around the corners' distance √0.75 = 0.8660254 from the
        // centre: 0.866022 (less by 3.9·10⁻⁶ of it) passes, 0.86601 (1.7·10⁻⁵) does not.
        check(leaf(13.5, 0.866022), vec![0, 1], 2).unwrap();
        assert_eq!(check(leaf(13.5, 0.86601), vec![0, 1], 2).unwrap_err(), "primitive 1 sticks out of leaf 2");
        // Exactly at the slack: in f32, √0.75 rounds to 0x3F5DB3D7 and 1 + 10⁻⁵ to
        // 1.0000100136 (0x3F800054); the radius 0x3F5DB346 ≈ 0.86601675 times that rounds to
        // exactly 0x3F5DB3D7 (the product, exact in f64, is 0.8660254175, 2.9·10⁻⁸ from it and 3.0·10⁻⁸ from
        // the next float up), so the corners lie on the bound: inside. One ulp less
        // (0x3F5DB345) rounds below √0.75: outside.
        check(leaf(13.5, f32::from_bits(0x3F5D_B346)), vec![0, 1], 2).unwrap();
        assert_eq!(check(leaf(13.5, f32::from_bits(0x3F5D_B345)), vec![0, 1], 2).unwrap_err(), "primitive 1 sticks out of leaf 2");
        // Two interior nodes sharing children 3 and 4: node 4 is reached twice.
        let shared = vec![node(1, 0), node(3, 0), node(3, 0), node(0, 1), node(1, 1)];
        assert_eq!(check(shared, vec![0, 1], 2).unwrap_err(), "node 4 reached twice");
        // A node no one points to, and a primitive in two leaves or in none.
        assert_eq!(check(vec![node(1, 0), node(0, 1), node(1, 1), node(0, 1)], vec![0, 1], 2).unwrap_err(), "node 3 is unreachable");
        assert_eq!(check(vec![node(1, 0), node(0, 1), node(1, 2)], vec![0, 0, 1], 2).unwrap_err(), "primitive 0 is in 2 leaves, not one");
        assert_eq!(check(vec![node(1, 0), node(0, 1), node(1, 1)], vec![0, 0], 2).unwrap_err(), "primitive 1 is in no leaf");
        assert_eq!(check(vec![node(0, 1)], vec![0], 2).unwrap_err(), "primitive 1 is in no leaf");
        // Counts and emptiness.
        assert_eq!(check(vec![], vec![], 2).unwrap_err(), "no nodes for a non-empty scene");
        check(vec![], vec![], 0).unwrap();
        let built = SphereBvh { nodes: vec![node(0, 1)], indices: vec![0], primitives: 1, build_ms: 0.0 };
        assert_eq!(built.validate(&Cubes(2)).unwrap_err().message, "built for 1 primitives, given 2");
    }
}
