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

/// Traversals of kd-trees written by hand (the builder decides the planes, so these need the
/// private node layout), with every answer and count worked out in the comments.
#[cfg(test)]
mod tests {
    use raylab_core::{Aabb, Ray, Vec3};

    use super::super::{KdNode, KdTree};
    use crate::{Accel, Counters, PrimHit, Primitives};

    /// Triangles through the watertight kernel, as the renderer's meshes.
    struct Tris(Vec<[Vec3; 3]>);

    impl Primitives for Tris {
        fn len(&self) -> usize {
            self.0.len()
        }
        fn bounds(&self, i: u32) -> Aabb {
            Aabb::from_points(self.0[i as usize])
        }
        fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
            let [a, b, c] = self.0[i as usize];
            raylab_core::intersect::triangle(ray, a, b, c).map(|(t, u, v)| PrimHit { t, u, v })
        }
    }

    /// The point with coordinate `c` on axis `a`, and `u`, `v` on the next two axes.
    fn at(a: usize, c: f32, u: f32, v: f32) -> Vec3 {
        let mut p = [0.0; 3];
        p[a] = c;
        p[(a + 1) % 3] = u;
        p[(a + 2) % 3] = v;
        Vec3::from_array(p)
    }

    /// Halves of the square `[−16, 16]²` in the plane at `c`, legs of 32 (determinant 2¹⁰ in
    /// the watertight test, so distances come out exact): `(u + 16) + (v + 16) ≤ 32` ...
    fn near_half(a: usize, c: f32) -> [Vec3; 3] {
        [at(a, c, -16.0, -16.0), at(a, c, 16.0, -16.0), at(a, c, -16.0, 16.0)]
    }

    /// ... and `≥ 32`.
    fn far_half(a: usize, c: f32) -> [Vec3; 3] {
        [at(a, c, 16.0, 16.0), at(a, c, -16.0, 16.0), at(a, c, 16.0, -16.0)]
    }

    /// Scene K on axis `a`, margin ¼, root voxel c ∈ [0, 4] × [−16, 16]²:
    ///
    /// ```text
    /// node 0: split c = 2, above = node 4
    ///   node 1: split c = 1, above = node 3
    ///     node 2: leaf [1, 4]   c ∈ [0, 1]
    ///     node 3: leaf [0, 4]   c ∈ [1, 2]
    ///   node 4: leaf [3, 2]     c ∈ [2, 4]
    /// ```
    ///
    /// Prims: 0 near half at c = 1.5, 1 near half at c = 0.875 (within the margin of the
    /// plane c = 1), 2 near half at c = 3, 3 far half at c = 2.5, 4 a triangle across the
    /// axis `a + 1` (in the plane u = 8) spanning c ∈ [0.75, 1.25], in both leaves it touches.
    fn scene_k(a: usize) -> (Tris, KdTree) {
        let (u, v) = ((a + 1) % 3, (a + 2) % 3);
        // Prim 4: in the plane u = 8, vertices (c, v) = (0.75, −16), (1.25, −16), (0.75, 16):
        // area ½·½·32 = 8, determinant 16 for rays along u.
        let mut p4 = [Vec3::ZERO; 3];
        for (k, (c, w)) in [(0.75, -16.0), (1.25, -16.0), (0.75, 16.0)].into_iter().enumerate() {
            let mut p = [0.0; 3];
            (p[a], p[u], p[v]) = (c, 8.0, w);
            p4[k] = Vec3::from_array(p);
        }
        let prims = Tris(vec![near_half(a, 1.5), near_half(a, 0.875), near_half(a, 3.0), far_half(a, 2.5), p4]);
        let nodes = vec![KdNode::interior(a, 2.0, 4), KdNode::interior(a, 1.0, 3), KdNode::leaf(0, 2), KdNode::leaf(2, 2), KdNode::leaf(4, 2)];
        let bounds = Aabb::new(at(a, 0.0, -16.0, -16.0).min(at(a, 4.0, 16.0, 16.0)), at(a, 0.0, -16.0, -16.0).max(at(a, 4.0, 16.0, 16.0)));
        let tree = KdTree { nodes, indices: vec![1, 4, 0, 4, 3, 2], bounds, margin: 0.25, primitives: 5, build_ms: 0.0 };
        tree.validate(&prims).unwrap();
        (prims, tree)
    }

    fn ray_along(axis: usize, sign: f32, origin: Vec3, t_min: f32, t_max: f32) -> Ray {
        let mut d = [0.0; 3];
        d[axis] = sign;
        Ray::segment(origin, Vec3::from_array(d), t_min, t_max)
    }

    type Answer = (Option<(u32, f32)>, u64, u64);

    fn closest(tree: &KdTree, prims: &Tris, ray: &Ray) -> Answer {
        let mut c = Counters::default();
        let h = tree.intersect(prims, ray, &mut c);
        assert_eq!(c.rays, 1);
        (h.map(|h| (h.prim, h.t)), c.nodes_visited, c.prim_tests)
    }

    fn any(tree: &KdTree, prims: &Tris, ray: &Ray) -> (bool, u64, u64) {
        let mut c = Counters::default();
        let h = tree.occluded(prims, ray, &mut c);
        assert_eq!(c.rays, 1);
        (h, c.nodes_visited, c.prim_tests)
    }

    /// Each ray of scene K with its closest and any-hit answers. The walk cuts the ray's
    /// interval [t0, t1] at each plane (t_p), widened by the slack ¼ (margin / |dir|): the
    /// child on the origin's side gets [t0, min(t1, t_p + ¼)], the other is stacked with
    /// [max(t0, t_p − ¼), t1]; a stacked child is entered only if its start is not beyond
    /// the hit so far.
    fn scene_k_rays(a: usize) -> Vec<(Ray, Answer, (bool, u64, u64))> {
        let (u, inf) = ((a + 1) % 3, f32::INFINITY);
        vec![
            // +a from c = −1 at (−4, −2): root interval [1, 5]; node 0 (t_p = 3) stacks node 4
            // from 2.75; node 1 (t_p = 2) stacks node 3 from 1.75; node 2: prim 1 at t = 1.875
            // (prim 4 is parallel); node 3 (1.75 ≤ 1.875) is tested, nothing nearer; node 4
            // (2.75) dropped. Any hit stops at prim 1.
            (ray_along(a, 1.0, at(a, -1.0, -4.0, -2.0), 0.0, inf), (Some((1, 1.875)), 4, 4), (true, 3, 1)),
            // −a from c = 5: above first: node 4 (prim 3 missed, prim 2 at t = 2); node 1,
            // stacked from 2.75, dropped.
            (ray_along(a, -1.0, at(a, 5.0, -4.0, -2.0), 0.0, inf), (Some((2, 2.0)), 2, 2), (true, 2, 2)),
            // +a from c = 1.25: node 0 stacks node 4 from ½; at node 1 the plane is behind
            // (t_p = −¼): node 3 only, prim 0 at t = ¼.
            (ray_along(a, 1.0, at(a, 1.25, -4.0, -2.0), 0.0, inf), (Some((0, 0.25)), 3, 2), (true, 3, 1)),
            // +a from c = 2 exactly on the root plane: above only (t_p = 0): prim 2 at t = 1.
            (ray_along(a, 1.0, at(a, 2.0, -4.0, -2.0), 0.0, inf), (Some((2, 1.0)), 2, 2), (true, 2, 2)),
            // −a from c = 2: below only; node 1 (t_p = 1) enters node 3 first: prim 0 at ½;
            // node 2, stacked from ¾, dropped.
            (ray_along(a, -1.0, at(a, 2.0, -4.0, -2.0), 0.0, inf), (Some((0, 0.5)), 3, 2), (true, 3, 1)),
            // Along +u from u = −20 at c = 1.125, v = −14 (parallel to the planes): below the
            // root plane, above node 1's: node 3 only; prim 4 at u = 8, t = 28.
            (ray_along(u, 1.0, at(a, 1.125, -20.0, -14.0), 0.0, inf), (Some((4, 28.0)), 3, 2), (true, 3, 2)),
            // The same at c = 1, in node 1's plane: both children, node 2 first (prim 4 at 28),
            // then node 3 (stacked with the whole interval, from t = 4) ties it.
            (ray_along(u, 1.0, at(a, 1.0, -20.0, -14.0), 0.0, inf), (Some((4, 28.0)), 4, 4), (true, 3, 2)),
            // At c = 0.8125: node 2 only.
            (ray_along(u, 1.0, at(a, 0.8125, -20.0, -14.0), 0.0, inf), (Some((4, 28.0)), 3, 2), (true, 3, 2)),
            // +a from −1 at (10, 12), through the far halves: every leaf, prim 3 at t = 3.5.
            (ray_along(a, 1.0, at(a, -1.0, 10.0, 12.0), 0.0, inf), (Some((3, 3.5)), 5, 6), (true, 5, 5)),
            // The same ending at t = 2.9 (c = 1.9): the root plane (t_p = 3) lies within the
            // slack of the end, so node 4 is still stacked (from 2.75 ≤ 2.9) and tested.
            (ray_along(a, 1.0, at(a, -1.0, 10.0, 12.0), 0.0, 2.9), (None, 5, 6), (false, 5, 6)),
            // Starting at t = 2.5 (c = 1.5): node 1's plane (t_p = 2) lies before the
            // interval [2.5, 3.25] by more than the slack: node 3 only, then node 4.
            (ray_along(a, 1.0, at(a, -1.0, 10.0, 12.0), 2.5, inf), (Some((3, 3.5)), 4, 4), (true, 4, 3)),
            // −a from c = 5 starting at t = 2.25 (c = 2.75, past prim 2): above first; node 4
            // holds no hit, node 1 (stacked from 2.75) is popped and takes its above child
            // (node 3) first: prim 0 at c = 1.5, t = 3.5; node 2 (from 3.75) dropped.
            (ray_along(a, -1.0, at(a, 5.0, -4.0, -2.0), 2.25, inf), (Some((0, 3.5)), 4, 4), (true, 4, 3)),
            // +a at half speed from c = −1: distances double (t_p = 6 and 4) and so does the
            // slack (½): prim 1 at t = 3.75; node 3 stacked from 3.5 is tested, node 4 (5.5)
            // dropped.
            (Ray::new(at(a, -1.0, -4.0, -2.0), 0.5 * ray_along(a, 1.0, Vec3::ZERO, 0.0, inf).dir), (Some((1, 3.75)), 4, 4), (true, 3, 1)),
            // From c = −1, u = 14 along (a, u) = (1, 1): the ray leaves the root voxel through
            // u = 16 at t = 2 (c = 1), before the root plane (t_p = 3, beyond 2 + ¼): node 1
            // only, where both children are walked (t_p = 2): prims 1 and 0 are missed
            // (their planes are reached at u = 15.875 and 16.5, outside their halves).
            (Ray::new(at(a, -1.0, 14.0, 0.0), at(a, 1.0, 1.0, 0.0)), (None, 4, 4), (false, 4, 4)),
            // +a from c = −1 starting at t = 1.8 (c = 0.8), just before node 1's plane
            // (t_p = 2): the plane is not before the interval, so node 2 (prim 1 at 1.875)
            // is walked, then node 3 (from 1.8).
            (ray_along(a, 1.0, at(a, -1.0, -4.0, -2.0), 1.8, inf), (Some((1, 1.875)), 4, 4), (true, 3, 1)),
            // Leaving the root voxel: nothing visited.
            (ray_along(a, -1.0, at(a, -1.0, -4.0, -2.0), 0.0, inf), (None, 0, 0), (false, 0, 0)),
        ]
    }

    #[test]
    fn kdtree_walks_front_to_back_on_every_axis_and_direction() {
        for a in 0..3 {
            let (prims, tree) = scene_k(a);
            for (k, (ray, want, want_any)) in scene_k_rays(a).into_iter().enumerate() {
                assert_eq!(closest(&tree, &prims, &ray), want, "axis {a} ray {k}");
                assert_eq!(any(&tree, &prims, &ray), want_any, "axis {a} ray {k}: any");
            }
        }
    }

    /// Two planes across different axes crossed within the slack of each other: the root
    /// splits c = 2 (above: node 4), node 1 splits u = 0 (above: node 3); margin ¼, root
    /// voxel c ∈ [0, 4], u ∈ [−4, 4]. Node 3 (c < 2, u > 0) lists prim 0, a near half at
    /// c = 2.125, within the margin of its voxel. The ray from (c, u) = (−1, −3.25) along
    /// (1, 1) crosses c = 2 at t = 3 and u = 0 at t = 3.25: node 1's interval ends at
    /// 3 + ¼, so its plane (3.25, within the slack of that end) stacks node 3 from 3.0;
    /// node 2 (empty), node 3 (prim 0 at t = 3.125), node 4 (stacked from 2.75, empty).
    #[test]
    fn kdtree_interval_ends_are_widened_by_the_slack() {
        for a in 0..3 {
            let (u, v) = ((a + 1) % 3, (a + 2) % 3);
            let prims = Tris(vec![[at(a, 2.125, -1.0, -17.0), at(a, 2.125, 31.0, -17.0), at(a, 2.125, -1.0, 15.0)]]);
            let nodes = vec![KdNode::interior(a, 2.0, 4), KdNode::interior(u, 0.0, 3), KdNode::leaf(0, 0), KdNode::leaf(0, 1), KdNode::leaf(1, 0)];
            let mut lo = [0.0; 3];
            let mut hi = [0.0; 3];
            (lo[a], lo[u], lo[v], hi[a], hi[u], hi[v]) = (0.0, -4.0, -16.0, 4.0, 4.0, 16.0);
            let tree = KdTree { nodes, indices: vec![0], bounds: Aabb::new(Vec3::from_array(lo), Vec3::from_array(hi)), margin: 0.25, primitives: 1, build_ms: 0.0 };
            let ray = Ray::new(at(a, -1.0, -3.25, -10.0), at(a, 1.0, 1.0, 0.0));
            assert_eq!(closest(&tree, &prims, &ray), (Some((0, 3.125)), 5, 1), "axis {a}");
        }
    }

    /// A chain of 62 planes (the builder's `MAX_DEPTH`), each stacking its above child (an
    /// empty leaf) before the next: the stack holds `MAX_DEPTH + 2` entries. Node k (0..62)
    /// splits at c = 62 − k, its below child is node k + 1 and its above child the leaf
    /// 63 + k; node 62 is the last below leaf. A ray along +a from c = ½ crosses every plane
    /// and, finding nothing, visits every node: 62 + 63.
    #[test]
    fn kdtree_stack_holds_the_deepest_chain() {
        let mut nodes: Vec<KdNode> = (0..62u32).map(|k| KdNode::interior(0, (62 - k) as f32, 63 + k)).collect();
        nodes.extend((0..63).map(|_| KdNode::leaf(0, 0)));
        let prims = Tris(vec![near_half(0, 100.0)]);
        let tree = KdTree { nodes, indices: vec![], bounds: Aabb::new(Vec3::new(0.0, -16.0, -16.0), Vec3::new(63.0, 16.0, 16.0)), margin: 0.0, primitives: 1, build_ms: 0.0 };
        let ray = ray_along(0, 1.0, Vec3::new(0.5, -4.0, -2.0), 0.0, f32::INFINITY);
        assert_eq!(closest(&tree, &prims, &ray), (None, 125, 0));
    }

    /// Statistics of scene K by hand. Half areas of the voxels (extent c × 32 × 32):
    /// root 4·32 + 32·32 + 32·4 = 1280; c-extent 2: 1152 (nodes 1, 4); extent 1: 1088
    /// (nodes 2, 3). SAH = (1280 + 1152 + 2·1088 + 2·1088 + 2·1152) / 1280 = 7.1.
    #[test]
    fn kdtree_statistics_by_hand() {
        let (prims, tree) = scene_k(1);
        let s = Accel::stats(&tree);
        assert_eq!(s.name, "kdtree");
        assert_eq!((s.primitives, s.interior_nodes, s.leaves, s.references, s.max_depth), (5, 2, 3, 6, 3));
        assert_eq!(s.leaf_histogram[..3], [0, 0, 3]);
        assert!((s.sah_cost - 9088.0 / 1280.0).abs() < 1e-12, "{}", s.sah_cost);
        assert_eq!(s.memory_bytes, 5 * 8 + 6 * 4);
        assert_eq!(s.notes, vec![("empty leaves".to_string(), "0".to_string())]);
        assert!(Accel::validate(&tree, &prims).is_ok());
        // An empty leaf is counted as one.
        let mut t = scene_k(1).1;
        t.nodes[3] = KdNode::leaf(2, 0);
        t.indices = vec![1, 4, 3, 2];
        t.nodes[4] = KdNode::leaf(2, 2);
        let s = t.stats();
        assert_eq!(s.notes[0].1, "1");
        assert_eq!((s.leaves, s.references), (3, 4));
        assert!((s.sah_cost - (1280.0 + 1152.0 + 2.0 * 1088.0 + 2.0 * 1152.0) / 1280.0).abs() < 1e-12);
        // The build time is passed on; depth counts along above children too: root (depth
        // 1) split at c = 2 with its above child node 2 (depth 2) split at c = 3, whose
        // children (nodes 3 and 4) are at depth 3. Voxels: root c ∈ [0, 4] (1280), node 1
        // c ∈ [0, 2] (1152), node 2 c ∈ [2, 4] (1152), nodes 3, 4 extent 1 (1088).
        let mut t = scene_k(1).1;
        t.build_ms = 1.25;
        t.nodes = vec![KdNode::interior(1, 2.0, 2), KdNode::leaf(0, 2), KdNode::interior(1, 3.0, 4), KdNode::leaf(2, 0), KdNode::leaf(2, 2)];
        t.indices = vec![1, 0, 3, 2];
        let s = t.stats();
        assert_eq!((s.build_ms, s.interior_nodes, s.leaves, s.max_depth, s.references), (1.25, 2, 3, 3, 4));
        assert!((s.sah_cost - (1280.0 + 1152.0 + 2.0 * 1152.0 + 0.0 * 1088.0 + 2.0 * 1088.0) / 1280.0).abs() < 1e-12, "{}", s.sah_cost);
        let empty = KdTree { nodes: vec![], indices: vec![], bounds: Aabb::EMPTY, margin: 0.0, primitives: 0, build_ms: 0.0 };
        let s = empty.stats();
        assert_eq!((s.interior_nodes, s.leaves, s.max_depth), (0, 0, 0));
        assert_eq!(empty.intersect(&Tris(vec![]), &ray_along(0, 1.0, Vec3::ZERO, 0.0, 1.0), &mut Counters::default()), None);
    }

    /// The node encoding: axis in the low two bits (3 = leaf), the above child or the count
    /// in the rest, the split or the first index in `data`.
    #[test]
    fn kdtree_node_fields() {
        let n = KdNode::interior(2, 1.5, 77);
        assert!(!n.is_leaf());
        assert_eq!((n.axis(), n.split(), n.above()), (2, 1.5, 77));
        assert_eq!((n.flags, n.data), (2 | 77 << 2, 1.5f32.to_bits()));
        let l = KdNode::leaf(9, 5);
        assert!(l.is_leaf());
        assert_eq!((l.first(), l.count()), (9, 5));
        assert_eq!((l.flags, l.data), (3 | 5 << 2, 9));
        assert!(!KdNode::interior(0, 0.0, 1).is_leaf() && !KdNode::interior(1, 0.0, 1).is_leaf());
    }

    /// Validation on hand-broken copies of scene K, each with its message.
    #[test]
    fn kdtree_validation_finds_each_broken_invariant() {
        let (prims, good) = scene_k(0);
        let broken = |f: &dyn Fn(&mut KdTree)| {
            let mut t = scene_k(0).1;
            f(&mut t);
            t.validate(&prims).unwrap_err().message
        };
        assert!(good.validate(&prims).is_ok());
        assert_eq!(good.validate(&Tris(prims.0[..4].to_vec())).unwrap_err().message, "built for 5 primitives, given 4");
        assert_eq!(broken(&|t| t.nodes.clear()), "no nodes for a non-empty scene");
        let empty = KdTree { nodes: vec![], indices: vec![], bounds: Aabb::EMPTY, margin: 0.0, primitives: 0, build_ms: 0.0 };
        assert!(empty.validate(&Tris(vec![])).is_ok());
        assert_eq!(broken(&|t| t.nodes[4] = KdNode::leaf(5, 2)), "leaf 4 points past the index array");
        assert_eq!(broken(&|t| t.indices[5] = 9), "leaf 4 holds primitive 9 of 5");
        // Prim 1 (c = 0.875) listed in node 4's voxel c ∈ [2, 4].
        assert_eq!(broken(&|t| t.indices[4] = 1), "primitive 1 does not touch the voxel of leaf 4");
        assert_eq!(broken(&|t| t.nodes[0] = KdNode::interior(0, 2.0, 1)), "node 0 has its above child at 1");
        assert_eq!(broken(&|t| t.nodes[0] = KdNode::interior(0, 2.0, 5)), "node 0 has its above child at 5");
        assert_eq!(broken(&|t| t.nodes[1] = KdNode::interior(0, 2.5, 3)), "split 2.5 of node 1 lies outside its voxel on axis 0");
        assert_eq!(broken(&|t| t.nodes[1] = KdNode::interior(0, -0.5, 3)), "split -0.5 of node 1 lies outside its voxel on axis 0");
        assert_eq!(broken(&|t| t.nodes[1] = KdNode::interior(0, f32::NAN, 3)), "split NaN of node 1 lies outside its voxel on axis 0");
        // Splits on the voxel's faces are allowed: node 1 at c = 0 or c = 2 (its voxel's
        // faces), with an empty leaf on the flat side and prims 0, 4, 1 on the other.
        for (split, flat_below) in [(0.0, true), (2.0, false)] {
            let mut t = scene_k(0).1;
            t.nodes[1] = KdNode::interior(0, split, 3);
            (t.nodes[2], t.nodes[3]) = if flat_below { (KdNode::leaf(0, 0), KdNode::leaf(0, 3)) } else { (KdNode::leaf(0, 3), KdNode::leaf(0, 0)) };
            t.nodes[4] = KdNode::leaf(3, 2);
            t.indices = vec![0, 4, 1, 3, 2];
            t.validate(&prims).unwrap_or_else(|e| panic!("split at {split}: {e}"));
        }
        assert_eq!(broken(&|t| t.indices.push(0)), "leaves reference 6 of 7 indices");
        // Node 1's above child is node 4 too (emptied, so that it fits either voxel).
        assert_eq!(
            broken(&|t| {
                t.nodes[1] = KdNode::interior(0, 1.0, 4);
                t.nodes[4] = KdNode::leaf(0, 0);
            }),
            "node 4 reached twice"
        );
        // Node 5 hangs off nothing.
        assert_eq!(broken(&|t| t.nodes.push(KdNode::leaf(0, 0))), "node 5 is unreachable");
        assert_eq!(
            broken(&|t| {
                t.indices[1] = 1;
                t.indices[3] = 0;
            }),
            "primitive 4 is in no leaf"
        );
        assert_eq!(Accel::validate(&broken_tree(), &prims).unwrap_err().accel, "kdtree");
    }

    fn broken_tree() -> KdTree {
        let mut t = scene_k(0).1;
        t.primitives = 4;
        t
    }
}
