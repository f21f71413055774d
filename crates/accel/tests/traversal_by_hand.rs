//! Traversals on trees written by hand, with every answer and every count worked out in the
//! comments: which primitive a ray hits and at what distance, how many nodes it visits and
//! how many primitives it tests, for the binary BVH (`bvh/traverse.rs`) and the wide BVHs
//! (`wide/traverse.rs`, `wide/packet.rs`, `wide/kernels.rs`) with every kernel this CPU runs.
//!
//! The scenes are squares' halves lying in planes across one axis `a` (coordinate `c`), the
//! rays run along that axis, both ways, for each of the three axes. A right triangle with
//! legs of 32 has a determinant of 32·32 = 2¹⁰ in the watertight test, so its distances
//! come out exact: a plane at `c` is hit at `t = |c − o|` from a ray starting at `o`.

use raylab_accel::bvh::{Bvh, BvhNode};
use raylab_accel::wide::node::{is_leaf, leaf_ref, node_index, node_ref, Layout, TriBlock, WideNode, EMPTY};
use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters, Hit, Kernel, Primitives, QuantNode, WideBvh, PACKET};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit::{Prim, Soup};

/// The point with coordinate `c` on axis `a`, and `u`, `v` on the next two axes.
fn at(a: usize, c: f32, u: f32, v: f32) -> Vec3 {
    let mut p = [0.0; 3];
    p[a] = c;
    p[(a + 1) % 3] = u;
    p[(a + 2) % 3] = v;
    Vec3::from_array(p)
}

/// Lower-left half of the square `[u0, u0 + 32] × [v0, v0 + 32]` in the plane at `c`:
/// the points with `(u − u0) + (v − v0) ≤ 32`.
fn near_half(a: usize, c: f32, u0: f32, v0: f32) -> [Vec3; 3] {
    [at(a, c, u0, v0), at(a, c, u0 + 32.0, v0), at(a, c, u0, v0 + 32.0)]
}

/// The other half of the same square: `(u − u0) + (v − v0) ≥ 32`. Its box is the whole
/// square, so a ray through the first half enters the box and misses the triangle.
fn far_half(a: usize, c: f32, u0: f32, v0: f32) -> [Vec3; 3] {
    [at(a, c, u0 + 32.0, v0 + 32.0), at(a, c, u0, v0 + 32.0), at(a, c, u0 + 32.0, v0)]
}

/// A ray along axis `a` (`sign` ±1) from coordinate `o`, at `(u, v)`.
fn axis_ray(a: usize, sign: f32, o: f32, u: f32, v: f32, t_max: f32) -> Ray {
    let mut d = [0.0; 3];
    d[a] = sign;
    Ray::segment(at(a, o, u, v), Vec3::from_array(d), 0.0, t_max)
}

/// Bounds of primitive `p` (`Soup::bounds` is the whole soup's).
fn pb(soup: &Soup, p: u32) -> Aabb {
    Primitives::bounds(soup, p)
}

fn union(soup: &Soup, prims: &[u32]) -> Aabb {
    prims.iter().fold(Aabb::EMPTY, |b, &p| b.union(pb(soup, p)))
}

/// What a traversal answered and counted: `(prim, t)` of the hit, nodes visited, primitives
/// tested.
type Answer = (Option<(u32, f32)>, u64, u64);

fn closest<A: Accel>(accel: &A, soup: &Soup, ray: &Ray) -> Answer {
    let mut c = Counters::default();
    let h = accel.intersect(soup, ray, &mut c);
    assert_eq!(c.rays, 1, "one ray counted");
    assert_eq!(c.object_tests, 0);
    (h.map(|h| (h.prim, h.t)), c.nodes_visited, c.prim_tests)
}

fn any<A: Accel>(accel: &A, soup: &Soup, ray: &Ray) -> (bool, u64, u64) {
    let mut c = Counters::default();
    let h = accel.occluded(soup, ray, &mut c);
    assert_eq!(c.rays, 1, "one ray counted");
    (h, c.nodes_visited, c.prim_tests)
}

// ---------------------------------------------------------------------------------------
// Binary BVH
// ---------------------------------------------------------------------------------------

/// Scene B on axis `a`: planes at c = 3 (prim 0), 1 (prim 1) and 5 (prim 2) over the square
/// `[−16, 16]²`, and prim 3 at c = 2 over `[20, 52] × [−16, 16]`. The tree:
///
/// ```text
/// node 0: interior, children 1, 2          box c ∈ [1, 5], u ∈ [−16, 52]
///   node 1: interior, children 3, 4        box c ∈ [2, 5], u ∈ [−16, 52]
///     node 3: leaf, indices[1..2] = [3]    box c = 2, u ∈ [20, 52]
///     node 4: leaf, indices[2..4] = [2, 0] box c ∈ [3, 5], u ∈ [−16, 16]
///   node 2: leaf, indices[0..1] = [1]      box c = 1, u ∈ [−16, 16]
/// ```
fn scene_b(a: usize) -> (Soup, Bvh) {
    let soup = Soup::triangles([near_half(a, 3.0, -16.0, -16.0), near_half(a, 1.0, -16.0, -16.0), near_half(a, 5.0, -16.0, -16.0), near_half(a, 2.0, 20.0, -16.0)]);
    let nodes = vec![
        BvhNode::interior(union(&soup, &[0, 1, 2, 3]), 1),
        BvhNode::interior(union(&soup, &[0, 2, 3]), 3),
        BvhNode::leaf(union(&soup, &[1]), 0, 1),
        BvhNode::leaf(union(&soup, &[3]), 1, 1),
        BvhNode::leaf(union(&soup, &[0, 2]), 2, 2),
    ];
    let bvh = Bvh::from_parts(nodes, vec![1, 3, 2, 0], 4, "by hand");
    bvh.validate(&soup).unwrap();
    (soup, bvh)
}

#[test]
fn binary_bvh_visits_the_nearer_child_first_on_every_axis_and_direction() {
    for a in 0..3 {
        let (soup, bvh) = scene_b(a);
        // +a from c = 0 at (−4, −2): the root's children are entered at t = 2 (node 1) and
        // t = 1 (node 2). Node 2 first: prim 1 at t = 1; node 1 (entry 2 > 1·(1 + 2γ₃)) is
        // then pruned. Root and node 2 visited, one test. Node 1 first would cost 5 visits.
        let up = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        assert_eq!(closest(&bvh, &soup, &up), (Some((1, 1.0)), 2, 1), "axis {a} +");
        // −a from c = 6: node 1 entered at t = 1 (c = 5), node 2 at t = 5. Node 1 first:
        // its child node 3 (u ∈ [20, 52]) is missed, node 4 entered at t = 1; its leaf tests
        // prim 2 (c = 5, t = 1) then prim 0 (c = 3, t = 3, beyond the hit): both tested.
        // Node 2, popped with entry 5, is pruned. Visits: root, node 1, node 4.
        let down = axis_ray(a, -1.0, 6.0, -4.0, -2.0, f32::INFINITY);
        assert_eq!(closest(&bvh, &soup, &down), (Some((2, 1.0)), 3, 2), "axis {a} −");
        // Any hit stops at the leaf's first hit: prim 2 tested, prim 0 not.
        assert_eq!(any(&bvh, &soup, &down), (true, 3, 1), "axis {a} − any");
        assert_eq!(any(&bvh, &soup, &up), (true, 2, 1), "axis {a} + any");
        // At (24, −8) only prim 3's side is entered: root, node 1 (node 2 missed), node 3
        // (node 4 missed): prim 3 at c = 2, t = 2.
        let side = axis_ray(a, 1.0, 0.0, 24.0, -8.0, f32::INFINITY);
        assert_eq!(closest(&bvh, &soup, &side), (Some((3, 2.0)), 3, 1), "axis {a} side");
        assert_eq!(any(&bvh, &soup, &side), (true, 3, 1), "axis {a} side any");
        // At (18, 0), between the squares: the root and node 1 are entered, no child of
        // node 1 is: two visits, no test, no hit.
        let gap = axis_ray(a, 1.0, 0.0, 18.0, 0.0, f32::INFINITY);
        assert_eq!(closest(&bvh, &soup, &gap), (None, 2, 0), "axis {a} gap");
        assert_eq!(any(&bvh, &soup, &gap), (false, 2, 0), "axis {a} gap any");
        // A segment ending before the root box (c = 1 at t = 1 > 0.5): nothing visited.
        let short = axis_ray(a, 1.0, 0.0, -4.0, -2.0, 0.5);
        assert_eq!(closest(&bvh, &soup, &short), (None, 0, 0), "axis {a} short");
        assert_eq!(any(&bvh, &soup, &short), (false, 0, 0), "axis {a} short any");
        // A segment ending exactly on prim 1 (t_max = 1): the interval (t_min, t_max] is
        // closed above, so the hit is found, and the root box's entry at exactly t_max too.
        let exact = axis_ray(a, 1.0, 0.0, -4.0, -2.0, 1.0);
        assert_eq!(closest(&bvh, &soup, &exact), (Some((1, 1.0)), 2, 1), "axis {a} t_max on the plane");
        // Rays leaving the scene miss the root box: no visit at all.
        let away = axis_ray(a, -1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        assert_eq!(closest(&bvh, &soup, &away), (None, 0, 0), "axis {a} away");
        // The same answers through `AnyAccel`.
        let wrapped = AnyAccel::Bvh(scene_b(a).1);
        assert_eq!(closest(&wrapped, &soup, &down), (Some((2, 1.0)), 3, 2));
        assert_eq!(wrapped.intersect_fast(&soup, &down).map(|h| (h.prim, h.t)), Some((2, 1.0)));
        assert!(wrapped.occluded_fast(&soup, &down) && !wrapped.occluded_fast(&soup, &gap));
    }
}

/// The binary BVH's hit carries the triangle's barycentrics: prim 1's vertices are
/// `(−16, −16)`, `(16, −16)`, `(−16, 16)` in `(u, v)`, so the point `(−4, −2)` is
/// `p0 + (12/32)(p1 − p0) + (14/32)(p2 − p0)`: weights 6/32, 12/32, 14/32 of p0, p1, p2.
#[test]
fn binary_bvh_hit_reports_the_barycentrics() {
    let (soup, bvh) = scene_b(2);
    let h = bvh.intersect(&soup, &axis_ray(2, 1.0, 0.0, -4.0, -2.0, f32::INFINITY), &mut Counters::default()).unwrap();
    let (b0, b1, b2) = (6.0 / 32.0, 12.0 / 32.0, 14.0 / 32.0);
    // `u`, `v` are two of the three weights; which two is the kernel's convention, but
    // they are two of these, and the third is 1 − u − v.
    let w = [h.u, h.v, 1.0 - h.u - h.v];
    let mut sorted = w;
    sorted.sort_by(f32::total_cmp);
    assert_eq!(sorted, [b0, b1, b2], "weights {w:?}");
}

/// Statistics of scene B's tree by hand. Half areas (the SAH drops the factor 2):
/// root c ∈ [1, 5] × u ∈ [−16, 52] × v ∈ [−16, 16]: 4·68 + 68·32 + 32·4 = 2576;
/// node 1 c ∈ [2, 5]: 3·68 + 68·32 + 32·3 = 2476; nodes 2 and 3 (flat squares): 32·32 =
/// 1024; node 4 c ∈ [3, 5]: 2·32 + 32·32 + 32·2 = 1152. SAH cost = interior areas + leaf
/// areas × counts, over the root's: (2576 + 2476 + 1024 + 1024 + 2·1152) / 2576.
#[test]
fn binary_bvh_statistics_by_hand() {
    let (soup, bvh) = scene_b(0);
    let s = Accel::stats(&bvh);
    assert_eq!(s.name, "by hand");
    assert_eq!((s.primitives, s.interior_nodes, s.leaves, s.references, s.max_depth), (4, 2, 3, 4, 3));
    assert_eq!(s.leaf_histogram[..3], [0, 2, 1]);
    let want = (2576.0 + 2476.0 + 1024.0 + 1024.0 + 2.0 * 1152.0) / 2576.0;
    assert!((s.sah_cost - want).abs() < 1e-12, "SAH {} vs {want}", s.sah_cost);
    // Five 32-byte nodes and four 4-byte indices.
    assert_eq!(s.memory_bytes, 5 * 32 + 4 * 4);
    assert!(Accel::validate(&bvh, &soup).is_ok());
    // The same boxes with the interior node on the right: its leaves are at depth 3 too.
    let nodes = vec![
        BvhNode::interior(union(&soup, &[0, 1, 2, 3]), 1),
        BvhNode::leaf(union(&soup, &[1]), 0, 1),
        BvhNode::interior(union(&soup, &[0, 2, 3]), 3),
        BvhNode::leaf(union(&soup, &[3]), 1, 1),
        BvhNode::leaf(union(&soup, &[0, 2]), 2, 2),
    ];
    let right = Bvh::from_parts(nodes, vec![1, 3, 2, 0], 4, "by hand");
    right.validate(&soup).unwrap();
    let s = right.stats();
    assert_eq!((s.interior_nodes, s.leaves, s.references, s.max_depth), (2, 3, 4, 3));
    assert!((s.sah_cost - want).abs() < 1e-12, "SAH {} vs {want}", s.sah_cost);
    // A tree for three primitives given four: the trait's validation reports it.
    let three = Soup::triangles(soup.prims[..3].iter().map(|p| match p {
        Prim::Triangle(v) => *v,
        Prim::Sphere { .. } => unreachable!(),
    }));
    assert!(Accel::validate(&bvh, &three).is_err());
}

/// Sibling boxes entered at the same distance are taken left first (`tl <= tr`): two
/// halves of one square at c = 1 in two leaves, in either order; the ray hits prim 0 only.
#[test]
fn binary_bvh_ties_go_left_first() {
    for a in 0..3 {
        // Prim 0 at c = 1 (hit), prim 1 at c = 1 over the same square but the other half
        // (box entered at the same t = 1, triangle missed).
        let soup = Soup::triangles([near_half(a, 1.0, -16.0, -16.0), far_half(a, 1.0, -16.0, -16.0)]);
        let b = |p: u32| pb(&soup, p);
        for (left, right) in [(0u32, 1u32), (1, 0)] {
            let nodes = vec![BvhNode::interior(union(&soup, &[0, 1]), 1), BvhNode::leaf(b(left), 0, 1), BvhNode::leaf(b(right), 1, 1)];
            let bvh = Bvh::from_parts(nodes, vec![left, right], 2, "ties");
            let ray = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
            // Left first: if the left leaf holds the hit, the right one (entry 1 ≤ 1·(1 + 2γ₃))
            // is still visited and tested: both boxes are entered at the hit's distance.
            assert_eq!(closest(&bvh, &soup, &ray), (Some((0, 1.0)), 3, 2), "axis {a}, left {left}");
            // Any hit: stops at the hit; with the miss on the left, both leaves are visited.
            assert_eq!(any(&bvh, &soup, &ray), (true, if left == 0 { 2 } else { 3 }, if left == 0 { 1 } else { 2 }), "axis {a}, left {left}");
        }
    }
}

/// A chain 66 levels deep (deeper than the builders make: validation accepts it) in which
/// the ray enters both children of every interior node: the 65 right siblings are stacked
/// before the first is popped. The stack holds `MAX_DEPTH + 1` = 65 entries.
///
/// Node `2k + 1` is the interior node at depth `k + 2` (its left child `2k + 3`), node
/// `2k + 2` the leaf of prim k; the deepest node's two leaves hold prims 64 and 65. The 66
/// prims are copies of one flat square at c = 10, so every entry is t = 10 and ties take the
/// left child (the chain) first. All 66 leaves are visited and tested (each hit is at t = 10
/// = t_max, within the closed interval, and replaces the last): 65 interior + 66 leaf
/// visits, and the hit kept is the last leaf popped's, node 2's prim 0.
#[test]
fn binary_bvh_stack_holds_a_chain_66_deep() {
    let soup = Soup::triangles([near_half(1, 10.0, -16.0, -16.0); 66]);
    let b = pb(&soup, 0);
    let mut nodes = vec![BvhNode::interior(b, 1)];
    for k in 0..64u32 {
        nodes.push(BvhNode::interior(b, 2 * k + 3));
        nodes.push(BvhNode::leaf(b, k, 1));
    }
    nodes.push(BvhNode::leaf(b, 64, 1));
    nodes.push(BvhNode::leaf(b, 65, 1));
    assert_eq!(nodes.len(), 131);
    let bvh = Bvh::from_parts(nodes, (0..66).collect(), 66, "chain");
    bvh.validate(&soup).unwrap();
    assert_eq!(bvh.stats().max_depth, 66);
    let ray = axis_ray(1, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
    assert_eq!(closest(&bvh, &soup, &ray), (Some((0, 10.0)), 131, 66));
}

// ---------------------------------------------------------------------------------------
// Wide BVHs
// ---------------------------------------------------------------------------------------

/// The kernels this CPU can run: always the portable one; SIMD (AVX2 for 8 lanes, SSE2 for
/// 4) and AVX-512 where detected. Each test runs with each, and checks that the one asked
/// for is the one used.
fn kernels(w: usize) -> Vec<Kernel> {
    let mut k = vec![Kernel::Portable];
    #[cfg(target_arch = "x86_64")]
    {
        use std::is_x86_feature_detected as has;
        if w == 4 || has!("avx2") {
            k.push(Kernel::Simd);
        }
        if has!("avx512f") && has!("avx512vl") && has!("avx2") && has!("bmi1") && has!("bmi2") {
            k.push(Kernel::Avx512);
        }
    }
    let _ = w;
    k
}

/// A wide BVH over `soup` whose nodes, blocks and root are replaced by the ones given.
fn wide_by_hand<const W: usize>(soup: &Soup, nodes: Vec<WideNode<W>>, blocks: Vec<TriBlock>, root: u32, kernel: Kernel) -> WideBvh<W> {
    let n = soup.len() as u32;
    let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, n)], (0..n).collect(), n as usize, "one leaf");
    let mut w = WideBvh::<W>::from_binary(&bin, soup, "by hand").with_kernel(kernel);
    assert_eq!(w.kernel(), kernel, "this CPU runs {kernel:?}");
    w.nodes = nodes;
    w.blocks = blocks;
    w.root = root;
    w
}

/// The same tree with quantised nodes.
fn quant_by_hand(soup: &Soup, nodes: &[WideNode<8>], blocks: Vec<TriBlock>, root: u32, kernel: Kernel) -> WideBvh<8, QuantNode> {
    let n = soup.len() as u32;
    let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, n)], (0..n).collect(), n as usize, "one leaf");
    let mut w = WideBvh::<8, QuantNode>::from_binary(&bin, soup, "by hand").with_kernel(kernel);
    assert_eq!(w.kernel(), kernel);
    // Interior references count in units of 32 bytes: node k of 224 bytes is node k of 96.
    let requant = |r: u32| if r == EMPTY || is_leaf(r) { r } else { node_ref::<QuantNode>(node_index::<WideNode<8>>(r).expect("at a node's start")) };
    w.nodes = nodes.iter().map(|n| WideNode { child: n.child.map(requant), ..*n }).map(|n| <QuantNode as Layout<8>>::encode(&n)).collect();
    w.blocks = blocks;
    w.root = root;
    w
}

/// A block holding `prims` in its first lanes (the rest empty).
fn block(soup: &Soup, prims: &[u32]) -> TriBlock {
    let mut b = TriBlock::EMPTY_BLOCK;
    for (l, &p) in prims.iter().enumerate() {
        match soup.triangle(p) {
            Some(v) => b.set_triangle(l, p, v),
            None => b.prim[l] = p | TriBlock::OTHER,
        }
    }
    b
}

/// Scene W on axis `a`: one wide root whose lanes are leaves of one block of one primitive.
///
/// | lane | prim | plane | square          | the ray at (−4, −2) | at (24, −8)   |
/// |------|------|-------|-----------------|---------------------|---------------|
/// | 0    | 0    | c = 2 | [−16, 16]²      | hits                | misses box    |
/// | 1    | 1    | c = 4 | [−16, 16]²      | hits                | misses box    |
/// | 2    | 2    | c = 1 | [−16, 16]²      | hits                | misses box    |
/// | 3    | 3    | c = 3 | [−16, 16]²      | hits                | misses box    |
/// | 4    | 4    | c = 2 | [20, 52]×[−16, 16] | misses box       | hits          |
/// | 5    | 5    | c = ½ | [−16, 16]², far half | box only        | misses box    |
/// | 6    | 6    | c = 3 | [20, 52]×[−16, 16] | misses box       | hits          |
/// | 7    | —    | empty |                 |                     |               |
///
/// For 4-wide trees lanes 4–7 are left out (prims 4–6 then sit in no leaf).
fn scene_w(a: usize) -> Soup {
    Soup::triangles([
        near_half(a, 2.0, -16.0, -16.0),
        near_half(a, 4.0, -16.0, -16.0),
        near_half(a, 1.0, -16.0, -16.0),
        near_half(a, 3.0, -16.0, -16.0),
        near_half(a, 2.0, 20.0, -16.0),
        far_half(a, 0.5, -16.0, -16.0),
        near_half(a, 3.0, 20.0, -16.0),
    ])
}

fn scene_w_tree<const W: usize>(soup: &Soup, kernel: Kernel) -> WideBvh<W> {
    let mut root = WideNode::<W>::EMPTY_NODE;
    let lanes = W.min(7);
    for l in 0..lanes {
        root.set(l, &pb(soup, l as u32), leaf_ref(l, 1));
    }
    let blocks = (0..lanes as u32).map(|p| block(soup, &[p])).collect();
    wide_by_hand(soup, vec![root], blocks, 0, kernel)
}

/// Hand answers for scene W (8 wide), each ray `(ray, closest answer, any-hit answer)`.
///
/// The root is visited first, then children nearest first (entry distances are the planes'
/// distances); after a hit at t, a stacked child entered beyond t·(1 + 2γ₃) is dropped.
/// Any hit enters the lowest hit lane and stacks the others, popping the highest first.
fn scene_w_rays(a: usize) -> Vec<(Ray, Answer, (bool, u64, u64))> {
    let inf = f32::INFINITY;
    vec![
        // +a from c = 0: entries lane 5: ½ (missed triangle), 2: 1, 0: 2, 3: 3, 1: 4.
        // Lane 5, then lane 2 hits at t = 1, the rest dropped: 3 visits, 2 tests.
        // Any hit: lane 0 first (lowest hit lane): hits at t = 2.
        (axis_ray(a, 1.0, 0.0, -4.0, -2.0, inf), (Some((2, 1.0)), 3, 2), (true, 2, 1)),
        // −a from c = 5: entries lane 1: 1, 3: 2, 0: 3, 2: 4, 5: 4½. Lane 1 hits at t = 1.
        (axis_ray(a, -1.0, 5.0, -4.0, -2.0, inf), (Some((1, 1.0)), 2, 1), (true, 2, 1)),
        // +a, t_max = 1.5: lanes 5 (½) and 2 (1) only, the two-child case: 3 visits.
        // Any hit: lane 2 first (the lower of 2 and 5).
        (axis_ray(a, 1.0, 0.0, -4.0, -2.0, 1.5), (Some((2, 1.0)), 3, 2), (true, 2, 1)),
        // +a, t_max = 0.75: lane 5 only, the one-child case: its triangle is missed.
        (axis_ray(a, 1.0, 0.0, -4.0, -2.0, 0.75), (None, 2, 1), (false, 2, 1)),
        // +a, t_max = 0.25: no lane: the root alone.
        (axis_ray(a, 1.0, 0.0, -4.0, -2.0, 0.25), (None, 1, 0), (false, 1, 0)),
        // +a at (24, −8): lanes 4 (t = 2) and 6 (t = 3): lane 4 hits, lane 6 dropped.
        (axis_ray(a, 1.0, 0.0, 24.0, -8.0, inf), (Some((4, 2.0)), 2, 1), (true, 2, 1)),
        // −a from c = 5 at (24, −8): lane 6 at t = 2 (the higher lane is the nearer one).
        // Any hit: lane 4 first (t = 3).
        (axis_ray(a, -1.0, 5.0, 24.0, -8.0, inf), (Some((6, 2.0)), 2, 1), (true, 2, 1)),
        // Between the squares: the root only.
        (axis_ray(a, 1.0, 0.0, 18.0, 0.0, inf), (None, 1, 0), (false, 1, 0)),
        // Away from the scene.
        (axis_ray(a, -1.0, 0.0, -4.0, -2.0, inf), (None, 1, 0), (false, 1, 0)),
        // +a from c = 1.5 (between planes): lane 2 and lane 5 behind; lanes 0 (t = ½),
        // 3 (1½), 1 (2½): lane 0 hits at ½.
        (axis_ray(a, 1.0, 1.5, -4.0, -2.0, inf), (Some((0, 0.5)), 2, 1), (true, 2, 1)),
        // +a at (10, 12), where (u + 16) + (v + 16) = 54 > 32: the near halves are missed,
        // lane 5's far half is hit at t = ½ (entered first: 2 visits). Any hit enters lane 0
        // (missed), then pops the highest stacked lane, 5: a hit, 3 visits and 2 tests.
        (axis_ray(a, 1.0, 0.0, 10.0, 12.0, inf), (Some((5, 0.5)), 2, 1), (true, 3, 2)),
        // +a ending exactly on lane 2's plane (t_max = 1): its box is entered at t_max,
        // within the closed interval: as the first ray (lane 5, then lane 2 at t = 1).
        (axis_ray(a, 1.0, 0.0, -4.0, -2.0, 1.0), (Some((2, 1.0)), 3, 2), (true, 2, 1)),
    ]
}

#[test]
fn wide_bvh8_visits_children_nearest_first_with_every_kernel() {
    for a in 0..3 {
        let soup = scene_w(a);
        for kernel in kernels(8) {
            let w = scene_w_tree::<8>(&soup, kernel);
            for (k, (ray, want, want_any)) in scene_w_rays(a).into_iter().enumerate() {
                assert_eq!(closest(&w, &soup, &ray), want, "axis {a} {kernel:?} ray {k}");
                assert_eq!(w.intersect_fast(&soup, &ray).map(|h| (h.prim, h.t)), want.0, "axis {a} {kernel:?} ray {k}: fast");
                assert_eq!(any(&w, &soup, &ray), want_any, "axis {a} {kernel:?} ray {k}: any");
                assert_eq!(w.occluded_fast(&soup, &ray), want_any.0, "axis {a} {kernel:?} ray {k}: fast any");
            }
        }
    }
}

/// The same tree 4 wide (lanes 0–3: planes at 2, 4, 1, 3): SSE2 and portable kernels.
#[test]
fn wide_bvh4_visits_children_nearest_first_with_every_kernel() {
    let inf = f32::INFINITY;
    for a in 0..3 {
        let soup = scene_w(a);
        for kernel in kernels(4) {
            let w = scene_w_tree::<4>(&soup, kernel);
            // +a: lanes 2 (1), 0 (2), 3 (3), 1 (4): lane 2 hits at 1, the rest dropped.
            let up = axis_ray(a, 1.0, 0.0, -4.0, -2.0, inf);
            assert_eq!(closest(&w, &soup, &up), (Some((2, 1.0)), 2, 1), "axis {a} {kernel:?}");
            assert_eq!(any(&w, &soup, &up), (true, 2, 1), "axis {a} {kernel:?} any");
            // −a from 5: lane 1 (c = 4) at 1.
            let down = axis_ray(a, -1.0, 5.0, -4.0, -2.0, inf);
            assert_eq!(closest(&w, &soup, &down), (Some((1, 1.0)), 2, 1), "axis {a} {kernel:?}");
            // From c = 2.5 both ways: +a lanes 3 (½), 1 (1½): two children; −a lanes 0 (½),
            // 2 (1½).
            let mid_up = axis_ray(a, 1.0, 2.5, -4.0, -2.0, inf);
            assert_eq!(closest(&w, &soup, &mid_up), (Some((3, 0.5)), 2, 1), "axis {a} {kernel:?}");
            let mid_down = axis_ray(a, -1.0, 2.5, -4.0, -2.0, inf);
            assert_eq!(closest(&w, &soup, &mid_down), (Some((0, 0.5)), 2, 1), "axis {a} {kernel:?}");
            // Outside the squares: the root only.
            let gap = axis_ray(a, 1.0, 0.0, 18.0, 0.0, inf);
            assert_eq!(closest(&w, &soup, &gap), (None, 1, 0), "axis {a} {kernel:?}");
            assert_eq!(any(&w, &soup, &gap), (false, 1, 0), "axis {a} {kernel:?}");
        }
    }
}

/// The quantised layout rounds boxes outward (flat boxes get a thickness of up to one grid
/// step), so entry distances move; the answers do not.
#[test]
fn quantised_bvh8_gives_the_hand_answers() {
    for a in 0..3 {
        let soup = scene_w(a);
        for kernel in kernels(8) {
            let f = scene_w_tree::<8>(&soup, kernel);
            let q = quant_by_hand(&soup, &f.nodes, f.blocks.clone(), 0, kernel);
            for (k, (ray, want, want_any)) in scene_w_rays(a).into_iter().enumerate() {
                assert_eq!(q.intersect(&soup, &ray, &mut Counters::default()).map(|h| (h.prim, h.t)), want.0, "axis {a} {kernel:?} ray {k}");
                assert_eq!(q.occluded(&soup, &ray, &mut Counters::default()), want_any.0, "axis {a} {kernel:?} ray {k}: any");
                let mut out = [None];
                q.intersect_packet(&soup, &[ray], &mut out);
                assert_eq!(out[0].map(|h| (h.prim, h.t)), want.0, "axis {a} {kernel:?} ray {k}: packet");
            }
        }
    }
}

/// Packets of scene W's rays, in several orders and lengths (inactive lanes past the end):
/// each answer is the hand answer of its ray.
#[test]
fn packets_give_each_ray_its_hand_answer() {
    for a in 0..3 {
        let soup = scene_w(a);
        let cases = scene_w_rays(a);
        // 10 rays, then reversed, then 16 (some twice), then one.
        let mut orders: Vec<Vec<usize>> = vec![(0..10).collect(), (0..10).rev().collect(), (0..16).map(|k| (k * 7) % 10).collect(), vec![1], vec![3, 4, 7, 8]];
        orders.push((0..16).map(|k| [0, 1, 5, 6][k % 4]).collect());
        for kernel in kernels(8) {
            let w = scene_w_tree::<8>(&soup, kernel);
            for order in &orders {
                let rays: Vec<Ray> = order.iter().map(|&k| cases[k].0).collect();
                let mut out = vec![Some(Hit { t: -1.0, prim: 99, u: 0.0, v: 0.0 }); rays.len()];
                w.intersect_packet(&soup, &rays, &mut out);
                for (i, &k) in order.iter().enumerate() {
                    assert_eq!(out[i].map(|h| (h.prim, h.t)), cases[k].1 .0, "axis {a} {kernel:?} order {order:?} slot {i} (ray {k})");
                }
            }
        }
        for kernel in kernels(4) {
            let w = scene_w_tree::<4>(&soup, kernel);
            // 4-wide: rays 1 (lane 1 at 1), 7 (gap), 8 (away) have the same answers; ray 0
            // hits lane 2 at 1 (lane 5 is not in the tree).
            let rays = [cases[0].0, cases[1].0, cases[7].0, cases[8].0, cases[9].0];
            let mut out = vec![None; rays.len()];
            w.intersect_packet(&soup, &rays, &mut out);
            let got: Vec<_> = out.iter().map(|h| h.map(|h| (h.prim, h.t))).collect();
            assert_eq!(got, vec![Some((2, 1.0)), Some((1, 1.0)), None, None, Some((0, 0.5))], "axis {a} {kernel:?}");
        }
    }
}

/// Ties: two triangles at the same distance (prims 1 and 0, duplicates of one triangle).
/// The wide traversal returns the least `(t, prim)` whatever the order of the tests: prim 0,
/// within one block (in either lane order) and across leaves (in either lane order), for
/// single rays and packets. Across leaves both boxes are entered at the hit's distance, so
/// the second is still visited (its entry t = 1 is not beyond 1·(1 + 2γ₃)).
#[test]
fn wide_ties_go_to_the_lower_primitive() {
    for a in 0..3 {
        let t = near_half(a, 1.0, -16.0, -16.0);
        // Prim 2: nearer (c = ½) but only in some trees below, to check that a nearer
        // hit with a higher index still wins.
        let soup = Soup::triangles([t, t, near_half(a, 0.5, -16.0, -16.0)]);
        let ray = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        for kernel in kernels(8) {
            for lanes in [[0u32, 1], [1, 0]] {
                // One block holding both.
                let mut root = WideNode::<8>::EMPTY_NODE;
                root.set(0, &union(&soup, &[0, 1]), leaf_ref(0, 1));
                let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &lanes)], 0, kernel);
                assert_eq!(closest(&w, &soup, &ray), (Some((0, 1.0)), 2, 2), "axis {a} {kernel:?} block {lanes:?}");
                let mut out = [None];
                w.intersect_packet(&soup, &[ray], &mut out);
                assert_eq!(out[0].map(|h| (h.prim, h.t)), Some((0, 1.0)), "axis {a} {kernel:?} block {lanes:?}: packet");
                // Two leaves, one each.
                let mut root = WideNode::<8>::EMPTY_NODE;
                root.set(0, &pb(&soup, lanes[0]), leaf_ref(0, 1));
                root.set(1, &pb(&soup, lanes[1]), leaf_ref(1, 1));
                let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[lanes[0]]), block(&soup, &[lanes[1]])], 0, kernel);
                assert_eq!(closest(&w, &soup, &ray), (Some((0, 1.0)), 3, 2), "axis {a} {kernel:?} leaves {lanes:?}");
                w.intersect_packet(&soup, &[ray, ray], &mut [None, None]);
                let mut out = [None, None];
                w.intersect_packet(&soup, &[ray, ray], &mut out);
                assert_eq!(out.map(|h| h.map(|h| (h.prim, h.t))), [Some((0, 1.0)); 2], "axis {a} {kernel:?} leaves {lanes:?}: packet");
                // A nearer triangle with a higher index wins over both (block [2, lanes...]).
                let mut root = WideNode::<8>::EMPTY_NODE;
                root.set(0, &union(&soup, &[0, 1, 2]), leaf_ref(0, 1));
                let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[lanes[0], 2, lanes[1]])], 0, kernel);
                assert_eq!(closest(&w, &soup, &ray), (Some((2, 0.5)), 2, 3), "axis {a} {kernel:?} nearer {lanes:?}");
                let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[2, lanes[0], lanes[1]])], 0, kernel);
                assert_eq!(closest(&w, &soup, &ray), (Some((2, 0.5)), 2, 3), "axis {a} {kernel:?} nearer first {lanes:?}");
            }
        }
    }
}

/// Ties across levels: the root holds a leaf with prim 1 (c = 1) in lane 0 and an interior
/// node in lane 1 whose only child is a leaf with prim 0, the same triangle. Both root lanes
/// are entered at t = 1; lane 0 first (equal keys: the lower lane), hit at t = 1; the node in
/// lane 1 is popped (entry 1 ≤ 1·(1 + 2γ₃)), its child's box test keeps the child (entry 1,
/// exit 1·(1 + 2γ₃) against t_max·(1 + 2γ₃)), and prim 0 wins the tie. Visits: root, leaf,
/// node, leaf: 4; tests 2.
#[test]
fn wide_ties_across_levels() {
    for a in 0..3 {
        let t = near_half(a, 1.0, -16.0, -16.0);
        let soup = Soup::triangles([t, t]);
        let ray = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        for kernel in kernels(8) {
            let mut root = WideNode::<8>::EMPTY_NODE;
            root.set(0, &pb(&soup, 1), leaf_ref(0, 1));
            root.set(1, &pb(&soup, 0), node_ref::<WideNode<8>>(1));
            let mut inner = WideNode::<8>::EMPTY_NODE;
            inner.set(0, &pb(&soup, 0), leaf_ref(1, 1));
            let w = wide_by_hand(&soup, vec![root, inner], vec![block(&soup, &[1]), block(&soup, &[0])], 0, kernel);
            w.validate(&soup).unwrap();
            assert_eq!(closest(&w, &soup, &ray), (Some((0, 1.0)), 4, 2), "axis {a} {kernel:?}");
            let mut out = [None];
            w.intersect_packet(&soup, &[ray], &mut out);
            assert_eq!(out[0].map(|h| (h.prim, h.t)), Some((0, 1.0)), "axis {a} {kernel:?}: packet");
            // Any hit: lane 0 first, hit: root and one leaf.
            assert_eq!(any(&w, &soup, &ray), (true, 2, 1), "axis {a} {kernel:?}: any");
        }
    }
}

/// A ray starting on a box's face, leaving it backwards: lane 0's box c ∈ [2, 3] (prim 0 at
/// c = 2.5), lane 1's c ∈ [1, 2] (prim 1 at c = 1.5); from c = 3 along −a. Lane 0's entry
/// is `(3 − 3)·(−1) = −0`, which the slab test's `max` with `t_min = +0` turns into +0 (as
/// the SIMD `max` returns its second operand on equal zeros): lane 0 sorts first (its key is
/// 0, where −0's sign bit would sort it last), hits at t = ½ and lane 1 (entry 1) is dropped:
/// 2 visits, 1 test.
#[test]
fn wide_ray_starting_on_a_box_face() {
    for a in 0..3 {
        let soup = Soup::triangles([near_half(a, 2.5, -16.0, -16.0), near_half(a, 1.5, -16.0, -16.0)]);
        let slab = |lo: f32, hi: f32| Aabb::new(at(a, lo, -16.0, -16.0).min(at(a, hi, 16.0, 16.0)), at(a, lo, -16.0, -16.0).max(at(a, hi, 16.0, 16.0)));
        let ray = axis_ray(a, -1.0, 3.0, -4.0, -2.0, f32::INFINITY);
        for kernel in kernels(8) {
            let mut root = WideNode::<8>::EMPTY_NODE;
            root.set(0, &slab(2.0, 3.0), leaf_ref(0, 1));
            root.set(1, &slab(1.0, 2.0), leaf_ref(1, 1));
            let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[0]), block(&soup, &[1])], 0, kernel);
            assert_eq!(closest(&w, &soup, &ray), (Some((0, 0.5)), 2, 1), "axis {a} {kernel:?}");
        }
        for kernel in kernels(4) {
            let mut root = WideNode::<4>::EMPTY_NODE;
            root.set(0, &slab(2.0, 3.0), leaf_ref(0, 1));
            root.set(1, &slab(1.0, 2.0), leaf_ref(1, 1));
            let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[0]), block(&soup, &[1])], 0, kernel);
            assert_eq!(closest(&w, &soup, &ray), (Some((0, 0.5)), 2, 1), "axis {a} {kernel:?} 4 wide");
        }
    }
}

/// Boxes tested after a hit are tested against it: the root's lane 0 is a leaf with prim 0
/// at c = 1, lane 1 an interior node (box c ∈ [1, 1.5]) whose only child is a leaf with
/// prim 1 at c = 1.5. From c = 0 along +a: lane 0 (entry 1, the lower lane of two equal
/// keys) hits at t = 1; the node (entry 1 ≤ 1·(1 + 2γ₃)) is visited, but its child, entered
/// at 1.5, is not: root, leaf, node: 3 visits, 1 test.
#[test]
fn wide_boxes_after_a_hit_are_tested_against_it() {
    for a in 0..3 {
        let soup = Soup::triangles([near_half(a, 1.0, -16.0, -16.0), near_half(a, 1.5, -16.0, -16.0)]);
        let ray = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        for kernel in kernels(8) {
            let mut root = WideNode::<8>::EMPTY_NODE;
            root.set(0, &pb(&soup, 0), leaf_ref(0, 1));
            root.set(1, &pb(&soup, 1).union(pb(&soup, 0)), node_ref::<WideNode<8>>(1));
            let mut inner = WideNode::<8>::EMPTY_NODE;
            inner.set(0, &pb(&soup, 1), leaf_ref(1, 1));
            let w = wide_by_hand(&soup, vec![root, inner], vec![block(&soup, &[0]), block(&soup, &[1])], 0, kernel);
            w.validate(&soup).unwrap();
            assert_eq!(closest(&w, &soup, &ray), (Some((0, 1.0)), 3, 1), "axis {a} {kernel:?}");
            let mut out = [None];
            w.intersect_packet(&soup, &[ray], &mut out);
            assert_eq!(out[0].map(|h| (h.prim, h.t)), Some((0, 1.0)), "axis {a} {kernel:?}: packet");
        }
    }
}

/// A leaf of two blocks starting at block 1 (block 0 belongs to another leaf), blocks
/// partly filled: closest hit tests every occupied lane of both blocks; any hit stops after
/// the first block that holds a hit. Spheres (not triangles) go through their own test.
///
/// Prims: 0 at c = 3 (hit), 1 at c = 2 (far half: missed), 2 at c = 5 (hit), 3 at c = 1
/// (hit), 4 a sphere of radius 1 at c = 8 on the ray (hit at t = 7 from c = 0), 5 at c = 6.
/// Leaf A (lane 0, blocks 1–2): block 1 = [1, 0, 2], block 2 = [4, 3]; leaf B (lane 1, block
/// 0) = [5].
#[test]
fn wide_leaves_of_several_blocks_and_spheres() {
    for a in 0..3 {
        let mut soup = Soup::triangles([near_half(a, 3.0, -16.0, -16.0), far_half(a, 2.0, -16.0, -16.0), near_half(a, 5.0, -16.0, -16.0), near_half(a, 1.0, -16.0, -16.0)]);
        soup.prims.push(Prim::Sphere { center: at(a, 8.0, -4.0, -2.0), radius: 1.0 });
        soup.prims.push(Prim::Triangle(near_half(a, 6.0, -16.0, -16.0)));
        for kernel in kernels(8) {
            let mut root = WideNode::<8>::EMPTY_NODE;
            root.set(0, &union(&soup, &[0, 1, 2, 3, 4]), leaf_ref(1, 2));
            root.set(1, &pb(&soup, 5), leaf_ref(0, 1));
            let blocks = vec![block(&soup, &[5]), block(&soup, &[1, 0, 2]), block(&soup, &[4, 3])];
            assert_eq!(blocks[2].prim[0], 4 | TriBlock::OTHER, "the sphere is flagged");
            let w = wide_by_hand(&soup, vec![root], blocks, 0, kernel);
            w.validate(&soup).unwrap();
            // +a from 0: leaf A entered at t = 1, leaf B at 6. A: five lanes tested, the
            // nearest is prim 3 at t = 1; B dropped. Root + A: 2 visits, 5 tests.
            let up = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
            assert_eq!(closest(&w, &soup, &up), (Some((3, 1.0)), 2, 5), "axis {a} {kernel:?}");
            // Any hit: block 1 holds hits (prims 0, 2): three lanes counted, block 2 not.
            assert_eq!(any(&w, &soup, &up), (true, 2, 3), "axis {a} {kernel:?}: any");
            // −a from c = 9.5: leaf A (box up to c = 9, the sphere) at ½, leaf B (c = 6) at
            // 3½. In A the sphere is nearest: entered at c = 9, t = ½. B dropped.
            let down = axis_ray(a, -1.0, 9.5, -4.0, -2.0, f32::INFINITY);
            let h = w.intersect(&soup, &down, &mut Counters::default()).unwrap();
            assert_eq!(h.prim, 4, "axis {a} {kernel:?}: the sphere");
            assert!((h.t - 0.5).abs() < 1e-6, "axis {a} {kernel:?}: sphere at {}", h.t);
            // A segment of length 4 from c = 9.5 (down to c = 5.5): the sphere (t = ½) and
            // prim 5 (c = 6, t = 3½) are within it, prims 0, 2, 3 (t = 6½, 4½, 8½) are not.
            // Any hit enters leaf A first (lane 0): block 1 holds no hit (three tests), block
            // 2's sphere is hit (two more). Closest: the sphere; leaf B dropped.
            let seg = axis_ray(a, -1.0, 9.5, -4.0, -2.0, 4.0);
            assert_eq!(any(&w, &soup, &seg), (true, 2, 5), "axis {a} {kernel:?}: any, segment");
            let h = w.intersect(&soup, &seg, &mut Counters::default()).unwrap();
            assert_eq!(h.prim, 4, "axis {a} {kernel:?}: segment");
            let mut out = [None, None];
            w.intersect_packet(&soup, &[up, seg], &mut out);
            assert_eq!(out[0].map(|h| (h.prim, h.t)), Some((3, 1.0)), "axis {a} {kernel:?}: packet");
            assert_eq!(out[1].map(|h| h.prim), Some(4), "axis {a} {kernel:?}: packet");
        }
    }
}

/// An empty wide BVH: no node, no hit, one ray counted.
#[test]
fn empty_wide_bvh_counts_the_ray_only() {
    let soup = Soup::default();
    for kind in [AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Q] {
        for kernel in kernels(8) {
            let w = AnyAccel::build(kind, &soup, &BuildOptions::default()).with_kernel(kernel);
            let ray = Ray::new(Vec3::ZERO, Vec3::X);
            assert_eq!(closest(&w, &soup, &ray), (None, 0, 0));
            assert_eq!(any(&w, &soup, &ray), (false, 0, 0));
        }
    }
}

/// The kernel is chosen at run time: `Simd` by default where the CPU runs it, `Avx512` for
/// the packets of 8-wide nodes where the CPU runs it and otherwise only when asked for,
/// `Portable` always available; a forced kernel is that of packets too.
#[test]
fn kernels_are_chosen_by_what_the_cpu_runs() {
    let soup = raylab_testkit::cube();
    for (kind, w) in [(AccelKind::Bvh8, 8), (AccelKind::Bvh4, 4), (AccelKind::Bvh8Q, 8)] {
        let ks = kernels(w);
        let accel = AnyAccel::build(kind, &soup, &BuildOptions::default());
        let simd = ks.contains(&Kernel::Simd);
        assert_eq!(accel.kernel(), Some(if simd { Kernel::Simd } else { Kernel::Portable }), "{kind}");
        let ray_major = w == 8 && ks.contains(&Kernel::Avx512);
        assert_eq!(accel.packet_kernel(), if ray_major { Some(Kernel::Avx512) } else { accel.kernel() }, "{kind}");
        let portable = accel.with_kernel(Kernel::Portable);
        assert_eq!((portable.kernel(), portable.packet_kernel()), (Some(Kernel::Portable), Some(Kernel::Portable)));
        let accel = AnyAccel::build(kind, &soup, &BuildOptions::default()).with_kernel(Kernel::Avx512);
        let best = *ks.last().unwrap();
        assert_eq!(accel.kernel(), Some(best), "{kind}: Avx512 where it runs, else the next best");
        assert_eq!(accel.stats().notes.iter().find(|(k, _)| k == "kernel").map(|(_, v)| v.clone()), Some(format!("{best:?}")));
    }
    assert_eq!(AnyAccel::build(AccelKind::Bvh, &soup, &BuildOptions::default()).with_kernel(Kernel::Simd).kernel(), None);
}

/// `PACKET` is a 4×4 tile.
#[test]
fn a_packet_is_sixteen_rays() {
    assert_eq!(PACKET, 16);
}

/// Structures without a packet traversal answer packets ray by ray: scene B's rays through
/// the binary BVH in one packet get their hand answers.
#[test]
fn binary_bvh_answers_packets_ray_by_ray() {
    let (soup, bvh) = scene_b(1);
    let accel = AnyAccel::Bvh(bvh);
    let inf = f32::INFINITY;
    let rays = [axis_ray(1, 1.0, 0.0, -4.0, -2.0, inf), axis_ray(1, -1.0, 6.0, -4.0, -2.0, inf), axis_ray(1, 1.0, 0.0, 18.0, 0.0, inf), axis_ray(1, 1.0, 0.0, 24.0, -8.0, inf)];
    let mut out = [Some(Hit { t: -1.0, prim: 99, u: 0.0, v: 0.0 }); 4];
    accel.intersect_packet(&soup, &rays, &mut out);
    assert_eq!(out.map(|h| h.map(|h| (h.prim, h.t))), [Some((1, 1.0)), Some((2, 1.0)), None, Some((3, 2.0))]);
}

/// Per-thread counters add field by field.
#[test]
fn counters_merge_field_by_field() {
    let mut a = Counters { rays: 1, nodes_visited: 20, prim_tests: 300, object_tests: 4000 };
    let b = Counters { rays: 5, nodes_visited: 60, prim_tests: 700, object_tests: 8000 };
    a.merge(&b);
    assert_eq!(a, Counters { rays: 6, nodes_visited: 80, prim_tests: 1000, object_tests: 12000 });
    a += b;
    assert_eq!(a, Counters { rays: 11, nodes_visited: 140, prim_tests: 1700, object_tests: 20000 });
}

/// The statistics report, written out by hand: leaves of 1, 2, 3 and 20 primitives fill
/// buckets 1, 2, 3 and the open last bucket 16+; 26 references over 4 leaves is 6.50 per
/// leaf; 2048 bytes are 2.0 KiB.
#[test]
fn statistics_report_by_hand() {
    use raylab_accel::AccelStats;
    let mut s = AccelStats { name: "hand".into(), build_ms: 1.5, primitives: 10, interior_nodes: 3, max_depth: 5, sah_cost: 2.25, memory_bytes: 2048, ..Default::default() };
    for n in [1, 2, 3, 20] {
        s.add_leaf(n);
    }
    assert_eq!((s.leaves, s.references), (4, 26));
    let mut h = vec![0usize; 17];
    (h[1], h[2], h[3], h[16]) = (1, 1, 1, 1);
    assert_eq!(s.leaf_histogram, h);
    s.note("width", 8);
    s.note("fill", "75%");
    assert_eq!(s.notes, vec![("width".to_string(), "8".to_string()), ("fill".to_string(), "75%".to_string())]);
    let zeros = " 4:0 5:0 6:0 7:0 8:0 9:0 10:0 11:0 12:0 13:0 14:0 15:0";
    assert_eq!(
        s.to_string(),
        format!("hand: 10 primitives, built in 1.50 ms\n  interior nodes 3, leaves 4, max depth 5\n  references 26 (6.50 per leaf), SAH cost 2.25\n  memory 2.0 KiB\n  width 8, fill 75%\n  leaf sizes: 0:0 1:1 2:1 3:1{zeros} 16+:1")
    );
    // The histogram is printed up to its last non-empty bucket.
    let mut small = AccelStats { name: "small".into(), ..Default::default() };
    small.add_leaf(0);
    small.add_leaf(2);
    small.add_leaf(2);
    assert_eq!(small.leaf_histogram.len(), 17);
    assert_eq!(small.to_string(), "small: 0 primitives, built in 0.00 ms\n  interior nodes 0, leaves 3, max depth 0\n  references 4 (1.33 per leaf), SAH cost 0.00\n  memory 0.0 KiB\n  leaf sizes: 0:1 1:0 2:2");
    // No leaves: no average (not 0/0), no histogram.
    let none = AccelStats { name: "none".into(), memory_bytes: 512, ..Default::default() };
    assert_eq!(none.to_string(), "none: 0 primitives, built in 0.00 ms\n  interior nodes 0, leaves 0, max depth 0\n  references 0 (0.00 per leaf), SAH cost 0.00\n  memory 0.5 KiB");
}

/// The portable kernel's triangle filter (`triangle_candidates`) and the SSE2 block test
/// (`triangles_sse`) on one block, worked by hand. Lane 0: the triangle A = (0, 0),
/// B = (4, 0), C = (0, 4) in the plane z = 0; lane 1: the same wound the other way; lane 2:
/// a primitive that is not a triangle (always a candidate, always left to its own test);
/// lane 3: empty (never). Rays along −z from z = 1 (t = 1 at z = 0) through points inside
/// the triangle (kept), across each edge and beyond each vertex (one or two edge functions
/// negative, the others positive, none zero: rejected, whatever the winding), and on an
/// edge or its extension (an edge function exactly zero: kept for the exact kernel).
#[test]
fn triangle_filter_and_block_test_by_hand() {
    use raylab_accel::wide::kernels::triangle_candidates;
    use raylab_core::intersect::ShearedRay;
    let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let (a, b, c) = (p(0.0, 0.0), p(4.0, 0.0), p(0.0, 4.0));
    let mut blk = TriBlock::EMPTY_BLOCK;
    blk.set_triangle(0, 0, [a, b, c]);
    blk.set_triangle(1, 1, [a, c, b]);
    blk.prim[2] = 2 | TriBlock::OTHER;
    // (point, kept by the filter, hit)
    let cases = [
        ((1.0, 1.0), true, true),    // inside
        ((3.0, 0.5), true, true),    // inside, near the hypotenuse
        ((1.0, -1.0), false, false), // across AB (y < 0)
        ((-1.0, 1.0), false, false), // across AC (x < 0)
        ((3.0, 3.0), false, false),  // across BC (x + y > 4)
        ((-1.0, -1.0), false, false), // beyond A
        ((6.0, -1.0), false, false), // beyond B (y < 0 and x + y > 4)
        ((-1.0, 6.0), false, false), // beyond C
        ((1.0, 0.0), true, true),    // on AB: a zero edge function
        ((6.0, 0.0), true, false),   // on AB's extension past B: zero, so kept; a miss
        ((0.0, 0.0), true, true),    // on the vertex A: two zero edge functions
    ];
    for ((x, y), kept, hit) in cases {
        let ray = Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
        let s = ShearedRay::new(&ray);
        let want = if kept { 0b111 } else { 0b100 };
        assert_eq!(triangle_candidates(&blk, &s), want, "filter at ({x}, {y})");
        for l in 0..2 {
            assert_eq!(s.triangle(0.0, f32::INFINITY, blk.vertex(l, 0), blk.vertex(l, 1), blk.vertex(l, 2)).map(|h| h.0), hit.then_some(1.0), "lane {l} at ({x}, {y})");
        }
        #[cfg(target_arch = "x86_64")]
        {
            use raylab_accel::wide::kernels::triangles_sse;
            let h = triangles_sse(&blk, &s, 0.0, f32::INFINITY);
            // A zero edge function leaves the lane to the exact kernel; the non-triangle
            // lane always goes there; the empty lane never.
            let on_edge = x == 0.0 || y == 0.0;
            let want_exact = if on_edge { 0b111 } else { 0b100 };
            assert_eq!((h.hit, h.exact), (if hit && !on_edge { 0b11 } else { 0 }, want_exact), "SSE at ({x}, {y})");
            if hit && !on_edge {
                assert_eq!((h.t[0], h.t[1]), (1.0, 1.0));
                // Barycentrics of (x, y): weights x/4 of B and y/4 of C, as two of u, v, 1 − u − v.
                let mut w = [h.u[0], h.v[0], 1.0 - h.u[0] - h.v[0]];
                w.sort_by(f32::total_cmp);
                let mut want = [x / 4.0, y / 4.0, 1.0 - x / 4.0 - y / 4.0];
                want.sort_by(f32::total_cmp);
                assert_eq!(w, want, "barycentrics at ({x}, {y})");
            }
        }
    }
    // Oblique rays from z = 4 along (½, ¼, −1) reach z = 0 at t = 4, 2 and 1 further in x
    // and y: the filter must test the sheared point, not the origin's (x, y) or a wrongly
    // sheared one. Hits 1 or ½ inside an edge are kept; a miss is rejected.
    let d = Vec3::new(0.5, 0.25, -1.0);
    for ((x, y), kept) in [((1.0, 1.0), true), ((3.0, 0.5), true), ((0.5, 3.0), true), ((-1.0, -1.0), false), ((3.0, 3.0), false)] {
        let ray = Ray::new(Vec3::new(x - 2.0, y - 1.0, 4.0), d);
        let s = ShearedRay::new(&ray);
        assert_eq!(triangle_candidates(&blk, &s), if kept { 0b111 } else { 0b100 }, "oblique filter at ({x}, {y})");
        #[cfg(target_arch = "x86_64")]
        {
            let h = raylab_accel::wide::kernels::triangles_sse(&blk, &s, 0.0, f32::INFINITY);
            assert_eq!((h.hit, h.exact), (if kept { 0b11 } else { 0 }, 0b100), "oblique SSE at ({x}, {y})");
            if kept {
                assert_eq!((h.t[0], h.t[1]), (4.0, 4.0));
            }
            // Beyond t_max, or not beyond t_min: decided, not hit.
            let h = raylab_accel::wide::kernels::triangles_sse(&blk, &s, 0.0, 3.5);
            assert_eq!((h.hit, h.exact), (0, 0b100));
            let h = raylab_accel::wide::kernels::triangles_sse(&blk, &s, 4.0, 8.0);
            assert_eq!((h.hit, h.exact), (0, 0b100));
        }
    }
}

/// A soup that counts calls to `Primitives::intersect`. With `hide_triangles`, `triangle`
/// answers `None` (the default), so the wide BVHs call `intersect` (the same watertight
/// test) for every lane, and the calls count every triangle test.
struct Counting<'a> {
    soup: &'a Soup,
    calls: std::sync::atomic::AtomicUsize,
    hide_triangles: bool,
}

impl Primitives for Counting<'_> {
    fn len(&self) -> usize {
        self.soup.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        pb(self.soup, i)
    }
    fn intersect(&self, i: u32, ray: &Ray) -> Option<raylab_accel::PrimHit> {
        self.calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        self.soup.intersect(i, ray)
    }
    fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
        if self.hide_triangles { None } else { self.soup.triangle(i) }
    }
}

/// Wide BVHs test the triangles copied into their blocks themselves: `Primitives::intersect`
/// is called only for lanes that are not triangles (the sphere of the several-blocks scene,
/// once per ray that reaches its block), with every kernel, single rays and packets.
#[test]
fn wide_bvh_calls_intersect_only_for_non_triangles() {
    let a = 0;
    let mut soup = Soup::triangles([near_half(a, 3.0, -16.0, -16.0), far_half(a, 2.0, -16.0, -16.0), near_half(a, 5.0, -16.0, -16.0), near_half(a, 1.0, -16.0, -16.0)]);
    soup.prims.push(Prim::Sphere { center: at(a, 8.0, -4.0, -2.0), radius: 1.0 });
    let counting = Counting { soup: &soup, calls: 0.into(), hide_triangles: false };
    let calls = || counting.calls.swap(0, std::sync::atomic::Ordering::Relaxed);
    for kernel in kernels(8) {
        let mut root = WideNode::<8>::EMPTY_NODE;
        root.set(0, &union(&soup, &[0, 1, 2]), leaf_ref(0, 1));
        root.set(1, &pb(&soup, 4).union(pb(&soup, 3)), leaf_ref(1, 1));
        let n = soup.len() as u32;
        let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, n)], (0..n).collect(), n as usize, "one leaf");
        let mut w = WideBvh::<8>::from_binary(&bin, &counting, "by hand").with_kernel(kernel);
        (w.nodes, w.blocks, w.root) = (vec![root], vec![block(&soup, &[1, 0, 2]), block(&soup, &[4, 3])], 0);
        // +a at (−4, −2) from c = 0: leaf 0 (c ∈ [2, 5], entry 2) and leaf 1 (c ∈ [1, 9],
        // entry 1): leaf 1 first, prim 3 at t = 1 and the sphere (entered at c = 7) tested
        // by its own test: one call; leaf 0 dropped.
        let up = axis_ray(a, 1.0, 0.0, -4.0, -2.0, f32::INFINITY);
        assert_eq!(w.intersect(&counting, &up, &mut Counters::default()).map(|h| (h.prim, h.t)), Some((3, 1.0)), "{kernel:?}");
        assert_eq!(calls(), 1, "{kernel:?}: the sphere only");
        // At (−4, 10): (u + 16) + (v + 16) = 38 > 32, so the near halves are missed and the
        // far half (prim 1, c = 2) is hit at t = 2. Closest hit: leaf 1 (entry 1) first, its
        // sphere lane is tested by a call (missed: v ∈ [−3, −1]), then leaf 0: one call. Any
        // hit: leaf 0 first (the lower lane), prim 1 hit, no call. The packet of two rays:
        // one call per ray in leaf 1.
        let side = axis_ray(a, 1.0, 0.0, -4.0, 10.0, f32::INFINITY);
        assert_eq!(w.intersect(&counting, &side, &mut Counters::default()).map(|h| (h.prim, h.t)), Some((1, 2.0)), "{kernel:?}");
        assert!(w.occluded(&counting, &side, &mut Counters::default()));
        let mut out = [None, None];
        w.intersect_packet(&counting, &[side, side], &mut out);
        assert_eq!(out.map(|h| h.map(|h| h.prim)), [Some(1); 2]);
        assert_eq!(calls(), 1 + 2, "{kernel:?}: the sphere lane, three times");
    }
}

/// Two levels: the root's lane 0 is a leaf (block 0: prim 0, c = 1), lane 1 the interior
/// node 1 (box of prim 1), whose lane 0 is a leaf (block 1: prim 1, c = 2).
fn two_levels(soup: &Soup) -> WideBvh<8> {
    let mut root = WideNode::<8>::EMPTY_NODE;
    root.set(0, &pb(soup, 0), leaf_ref(0, 1));
    root.set(1, &pb(soup, 1), node_ref::<WideNode<8>>(1));
    let mut inner = WideNode::<8>::EMPTY_NODE;
    inner.set(0, &pb(soup, 1), leaf_ref(1, 1));
    wide_by_hand(soup, vec![root, inner], vec![block(soup, &[0]), block(soup, &[1])], 0, Kernel::Portable)
}

/// Statistics of scene W's 8-wide tree by hand. Its root box is the scene's: c ∈ [½, 4],
/// u ∈ [−16, 52], v ∈ [−16, 16], half area 3.5·68 + 68·32 + 32·3.5 = 2526; seven leaves of
/// one block, each a flat 32 × 32 square (half area 1024): SAH = 1 + 7·1024/2526. One
/// 224-byte node and seven 160-byte blocks: 1344 bytes, 192 per triangle; 7 of 28 lanes
/// used. The two-level tree: depth 3, SAH = 1 + (1024 + 1024 + 1024)/(half area of the
/// scene box c ∈ [1, 2] × 32 × 32: 32 + 1024 + 32).
#[test]
fn wide_statistics_by_hand() {
    let soup = scene_w(0);
    let w = scene_w_tree::<8>(&soup, Kernel::Portable);
    let s = w.stats();
    assert_eq!(s.name, "by hand");
    assert_eq!((s.primitives, s.interior_nodes, s.leaves, s.references, s.max_depth), (7, 1, 7, 7, 2));
    assert_eq!(s.leaf_histogram[..2], [0, 7]);
    let want = 1.0 + 7.0 * 1024.0 / 2526.0;
    assert!((s.sah_cost - want).abs() < 1e-9, "{} vs {want}", s.sah_cost);
    assert_eq!(s.memory_bytes, 224 + 7 * 160);
    let note = |k: &str| s.notes.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
    assert_eq!((note("width"), note("boxes"), note("kernel"), note("block fill"), note("bytes/triangle")), (Some("8"), Some("f32"), Some("Portable"), Some("25%"), Some("192.0")));
    let t = two_levels(&Soup::triangles([near_half(0, 1.0, -16.0, -16.0), near_half(0, 2.0, -16.0, -16.0)]));
    let s = t.stats();
    assert_eq!((s.interior_nodes, s.leaves, s.references, s.max_depth), (2, 2, 2, 3));
    assert!((s.sah_cost - (1.0 + 3.0 * 1024.0 / 1088.0)).abs() < 1e-9, "{}", s.sah_cost);
    assert_eq!(t.root_bounds(), Aabb::new(Vec3::new(1.0, -16.0, -16.0), Vec3::new(2.0, 16.0, 16.0)));
    // A leaf of two blocks is charged two in the SAH, and a quantised node is 96 bytes.
    let q = quant_by_hand(&soup, &w.nodes, w.blocks.clone(), 0, Kernel::Portable);
    let qs = q.stats();
    assert_eq!((qs.memory_bytes, qs.notes.iter().find(|(n, _)| n == "boxes").map(|(_, v)| v.as_str())), (96 + 7 * 160, Some("quantised")));
}

/// `validate` on hand-broken copies of the two-level tree, each with its message. Before the
/// fix to `WideBvh::walk` a node listing itself made validation loop for ever, and a
/// reference past the nodes made it panic (index out of bounds).
#[test]
fn wide_validation_finds_each_broken_invariant() {
    let soup = Soup::triangles([near_half(0, 1.0, -16.0, -16.0), near_half(0, 2.0, -16.0, -16.0)]);
    let good = two_levels(&soup);
    good.validate(&soup).unwrap();
    let broken = |f: &dyn Fn(&mut WideBvh<8>)| {
        let mut t = two_levels(&soup);
        f(&mut t);
        t.validate(&soup).unwrap_err().message
    };
    let one = Soup::triangles([near_half(0, 1.0, -16.0, -16.0)]);
    assert_eq!(good.validate(&one).unwrap_err().message, "built for 2 primitives, given 1");
    assert_eq!(broken(&|t| t.root = u32::MAX), "no root for a non-empty scene");
    assert_eq!(broken(&|t| t.nodes[0].child[0] = leaf_ref(5, 1)), "leaf 0x80000005 points past the blocks");
    assert_eq!(broken(&|t| t.blocks[0].prim[0] = 7), "block 0 holds primitive 7 of 2");
    assert_eq!(broken(&|t| t.blocks[0].p[1][1][0] = 3.0), "block 0 lane 0: triangle data of primitive 0 differs from the mesh");
    // A lane flagged "not a triangle" must hold zero vertices (the block test skips a
    // block only by its triangles' edge functions).
    assert_eq!(broken(&|t| t.blocks[0].prim[0] |= 1 << 31), "block 0 lane 0: primitive 0 is not a triangle, yet has vertices");
    assert_eq!(broken(&|t| t.nodes[0].bounds[4][0] = 0.0), "primitive 0 sticks out of its leaf box");
    assert_eq!(broken(&|t| t.nodes[1].child[0] = node_ref::<WideNode<8>>(1)), "node 1 out of range or reached twice");
    assert_eq!(broken(&|t| t.nodes[0].child[1] = node_ref::<WideNode<8>>(5)), "node 5 out of range or reached twice");
    assert_eq!(broken(&|t| t.nodes[0].child[1] = 1), "reference 1 falls inside a node");
    assert_eq!(broken(&|t| (t.nodes[1].bounds[0][3], t.nodes[1].bounds[3][3]) = (0.0, 1.0)), "node 1 lane 3: an empty slot with a non-empty box");
    assert_eq!(broken(&|t| t.nodes[1].bounds[5][0] = 20.0), "node 1 lane 0 sticks out of its parent");
    assert_eq!(broken(&|t| t.nodes.push(WideNode::EMPTY_NODE)), "node 2 is unreachable");
    assert_eq!(broken(&|t| t.blocks[1].prim[0] = u32::MAX), "primitive 1 is in no leaf");
    // An empty tree for an empty scene is valid.
    let empty = Soup::default();
    assert!(AnyAccel::build(AccelKind::Bvh8, &empty, &BuildOptions::default()).validate(&empty).is_ok());
}

/// Packets prune by each ray's far limit, `t_max·(1 + 2γ₃)`, kept up to date with its hits:
/// seen through the calls to `Primitives::intersect` that a sphere behind them costs. Leaf A
/// (lane 0): prim 0, the far half of the square at c = 1 (hit at (u, v) = (10, 12), where
/// (u + 16) + (v + 16) = 54 ≥ 32); leaf B (lane 1): prim 1, a sphere of radius ½ at c = 2,
/// (u, v) = (10, 12), its box entered at c = 1.5. Rays along +a at (10, 12).
#[test]
fn packets_prune_by_each_rays_far_limit() {
    let a = 0;
    let mut soup = Soup::triangles([far_half(a, 1.0, -16.0, -16.0)]);
    soup.prims.push(Prim::Sphere { center: at(a, 2.0, 10.0, 12.0), radius: 0.5 });
    let counting = Counting { soup: &soup, calls: 0.into(), hide_triangles: false };
    let calls = || counting.calls.swap(0, std::sync::atomic::Ordering::Relaxed);
    for kernel in kernels(8) {
        let mut root = WideNode::<8>::EMPTY_NODE;
        root.set(0, &pb(&soup, 0), leaf_ref(0, 1));
        root.set(1, &pb(&soup, 1), leaf_ref(1, 1));
        let n = soup.len() as u32;
        let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, n)], (0..n).collect(), n as usize, "one leaf");
        let mut w = WideBvh::<8>::from_binary(&bin, &counting, "by hand").with_kernel(kernel);
        (w.nodes, w.blocks, w.root) = (vec![root], vec![block(&soup, &[0]), block(&soup, &[1])], 0);
        // Ending at t = 0.9: neither box is entered (1 and 1.5 > 0.9·(1 + 2γ₃)): no call.
        let short = axis_ray(a, 1.0, 0.0, 10.0, 12.0, 0.9);
        // Unbounded: prim 0 at t = 1, after which leaf B (entry 1.5 > 1·(1 + 2γ₃)) is
        // dropped: no call.
        let hit = axis_ray(a, 1.0, 0.0, 10.0, 12.0, f32::INFINITY);
        // From c = 1.25, past the triangle: leaf B only, the sphere at t = 0.25: one call.
        let past = axis_ray(a, 1.0, 1.25, 10.0, 12.0, f32::INFINITY);
        let mut out = [None; 3];
        w.intersect_packet(&counting, &[short, hit, past], &mut out);
        assert_eq!(out.map(|h| h.map(|h| h.prim)), [None, Some(0), Some(1)], "{kernel:?}");
        assert_eq!(out[1].unwrap().t, 1.0);
        assert!((out[2].unwrap().t - 0.25).abs() < 1e-6);
        // The packet enters leaf B first (its least entry, 0.25, is the ray past the
        // triangle's) with both unbounded rays, before `hit` has found prim 0: two calls.
        assert_eq!(calls(), 2, "{kernel:?}: leaf B first, for two rays");
        // Without `past`, leaf A (entry 1) comes first: `hit` finds prim 0, and leaf B is
        // then dropped for it; `short` entered neither: no call.
        w.intersect_packet(&counting, &[short, hit], &mut out[..2]);
        assert_eq!(calls(), 0, "{kernel:?}");
    }
}

/// Packets take children nearest first by their least entry, whatever their lanes: lane 0
/// holds a sphere at c = 3.5 (box entered at 3), lane 1 the sphere at c = 2 (1.5), lane 2
/// the far half at c = 1 (1). The ray at (10, 12) (with the spheres on it) meets the far
/// half first, at t = 1, and both spheres are then dropped: no call, with three children
/// (the sort) and, ending at t = 2.5, two (lane 0 not entered). Any other order tests a
/// sphere first.
#[test]
fn packets_take_children_nearest_first() {
    let a = 0;
    let mut soup = Soup::triangles([far_half(a, 1.0, -16.0, -16.0)]);
    soup.prims.push(Prim::Sphere { center: at(a, 2.0, 10.0, 12.0), radius: 0.5 });
    soup.prims.push(Prim::Sphere { center: at(a, 3.5, 10.0, 12.0), radius: 0.5 });
    let counting = Counting { soup: &soup, calls: 0.into(), hide_triangles: false };
    let calls = || counting.calls.swap(0, std::sync::atomic::Ordering::Relaxed);
    for kernel in kernels(8) {
        let mut root = WideNode::<8>::EMPTY_NODE;
        root.set(0, &pb(&soup, 2), leaf_ref(2, 1));
        root.set(1, &pb(&soup, 1), leaf_ref(1, 1));
        root.set(2, &pb(&soup, 0), leaf_ref(0, 1));
        let n = soup.len() as u32;
        let bin = Bvh::from_parts(vec![BvhNode::leaf(soup.bounds(), 0, n)], (0..n).collect(), n as usize, "one leaf");
        let mut w = WideBvh::<8>::from_binary(&bin, &counting, "by hand").with_kernel(kernel);
        (w.nodes, w.blocks, w.root) = (vec![root], vec![block(&soup, &[0]), block(&soup, &[1]), block(&soup, &[2])], 0);
        for t_max in [f32::INFINITY, 2.5] {
            let ray = axis_ray(a, 1.0, 0.0, 10.0, 12.0, t_max);
            let mut out = [None; 2];
            w.intersect_packet(&counting, &[ray, ray], &mut out);
            assert_eq!(out.map(|h| h.map(|h| (h.prim, h.t))), [Some((0, 1.0)); 2], "{kernel:?} t_max {t_max}");
            assert_eq!(calls(), 0, "{kernel:?} t_max {t_max}: the far half first");
        }
    }
}

/// Statistics of the several-blocks scene (axis x): its box (the scene's) is c ∈ [1, 9] ×
/// 32 × 32, half area 8·32 + 32·32 + 32·8 = 1536; leaf A has the same box, 5 primitives in
/// 2 blocks (charged 2), leaf B a flat square (1024) of 1 in 1 block: SAH = 1 + 2 +
/// 1024/1536; one node and three blocks, 224 + 3·160 bytes. Built through `AnyAccel`, a
/// wide BVH reports its build time; SBVH-based ones accept leaves their primitives stick
/// out of.
#[test]
fn wide_statistics_of_leaves_of_several_blocks() {
    let a = 0;
    let mut soup = Soup::triangles([near_half(a, 3.0, -16.0, -16.0), far_half(a, 2.0, -16.0, -16.0), near_half(a, 5.0, -16.0, -16.0), near_half(a, 1.0, -16.0, -16.0)]);
    soup.prims.push(Prim::Sphere { center: at(a, 8.0, -4.0, -2.0), radius: 1.0 });
    soup.prims.push(Prim::Triangle(near_half(a, 6.0, -16.0, -16.0)));
    let mut root = WideNode::<8>::EMPTY_NODE;
    root.set(0, &union(&soup, &[0, 1, 2, 3, 4]), leaf_ref(1, 2));
    root.set(1, &pb(&soup, 5), leaf_ref(0, 1));
    let w = wide_by_hand(&soup, vec![root], vec![block(&soup, &[5]), block(&soup, &[1, 0, 2]), block(&soup, &[4, 3])], 0, Kernel::Portable);
    let s = w.stats();
    assert_eq!((s.interior_nodes, s.leaves, s.references, s.max_depth, s.memory_bytes), (1, 2, 6, 2, 224 + 3 * 160));
    assert_eq!(s.leaf_histogram[..6], [0, 1, 0, 0, 0, 1]);
    assert!((s.sah_cost - (3.0 + 1024.0 / 1536.0)).abs() < 1e-9, "{}", s.sah_cost);
    // A leaf reference past the blocks (blocks 1..4 of 3: 1 + 3 > 3, where 1·3 is not) is
    // reported, not followed.
    let mut t = w;
    t.nodes[0].child[1] = leaf_ref(1, 3);
    assert_eq!(t.validate(&soup).unwrap_err().message, "leaf 0x90000001 points past the blocks");
    let cube = raylab_testkit::cube();
    for kind in [AccelKind::Bvh8, AccelKind::Bvh8Sbvh, AccelKind::Bvh8Q, AccelKind::Bvh4] {
        let accel = AnyAccel::build(kind, &cube, &BuildOptions::default());
        accel.validate(&cube).unwrap_or_else(|e| panic!("{kind}: {e}"));
        let s = accel.stats();
        assert!(s.build_ms > 0.0, "{kind}: the build time is reported");
        assert_eq!((s.name.as_str(), s.primitives, s.references), (kind.name(), 12, 12));
    }
}

/// Scene W's one-node tree (`scene_w_tree`) with blocks flagging their primitive as not a
/// triangle.
fn scene_w_hidden<const W: usize>(soup: &Soup, kernel: Kernel) -> WideBvh<W> {
    let mut w = scene_w_tree::<W>(soup, kernel);
    for (p, b) in w.blocks.iter_mut().enumerate() {
        *b = TriBlock::EMPTY_BLOCK;
        b.prim[0] = p as u32 | TriBlock::OTHER;
    }
    w
}

/// Through `AnyAccel`, the wide BVHs trace a packet together, which is not its rays one by
/// one: the packet takes children in the order of their least entry over its rays, so a ray
/// may be charged (and test) a child that it alone would have dropped. Scene W on axis 0,
/// rays at (−4, −2): `r1` along +a from c = 0 (alone: the root, lane 5 at ½ whose far half it
/// misses, lane 2 at 1 hit; 3 visits, 2 tests), `r2` along −a from c = 5 (alone: the root,
/// lane 1 at 1 hit; 2 visits, 1 test). Together, 8 wide, the least entries are lane 5: ½
/// (r1's), lanes 1 and 2: 1 (r2's, r1's), lanes 0 and 3: 2. Both rays visit the root, lane 5
/// (both miss), then lanes 1 and 2 in either order, each entered at 1, within both rays'
/// limits all along (r1 hits lane 1 at t = 4 and lane 2 at 1, r2 lane 1 at 1 and lane 2 at
/// 4 or not at all); lanes 0 and 3 (entry 2) are then beyond both: 8 visits and 6 tests,
/// against 5 and 3 ray by ray. 4 wide (lanes 0–3: no lane 5): the root and lanes 1 and 2 for
/// both, 6 visits and 4 tests, against 2 + 2 and 1 + 1. The quantised boxes move the
/// entries by less than a grid step (3.5/255 along the axis), which changes none of this.
/// With the triangles hidden, each test is a call.
#[test]
fn any_accel_traces_wide_packets_together() {
    let soup = scene_w(0);
    let hidden = Counting { soup: &soup, calls: 0.into(), hide_triangles: true };
    let calls = || hidden.calls.swap(0, std::sync::atomic::Ordering::Relaxed);
    let inf = f32::INFINITY;
    let rays = [axis_ray(0, 1.0, 0.0, -4.0, -2.0, inf), axis_ray(0, -1.0, 5.0, -4.0, -2.0, inf)];
    for kernel in kernels(8) {
        let w8 = scene_w_hidden::<8>(&soup, kernel);
        let q = quant_by_hand(&soup, &w8.nodes, w8.blocks.clone(), 0, kernel);
        let w4 = scene_w_hidden::<4>(&soup, kernel);
        for (accel, visits, tests) in [(AnyAccel::Bvh8(w8), 8, 6), (AnyAccel::Bvh8Q(q), 8, 6), (AnyAccel::Bvh4(w4), 6, 4)] {
            assert!(accel.has_packets());
            let mut out = [None; 2];
            accel.intersect_packet(&hidden, &rays, &mut out);
            assert_eq!(out.map(|h| h.map(|h| (h.prim, h.t))), [Some((2, 1.0)), Some((1, 1.0))], "{kernel:?}");
            assert_eq!(calls(), tests as usize, "{kernel:?}: {visits} visits");
            let mut out = [None; 2];
            let mut c = Counters::default();
            accel.intersect_packet_counted(&hidden, &rays, &mut out, &mut c);
            assert_eq!(out.map(|h| h.map(|h| (h.prim, h.t))), [Some((2, 1.0)), Some((1, 1.0))], "{kernel:?}");
            assert_eq!(c, Counters { rays: 2, nodes_visited: visits, prim_tests: tests, object_tests: 0 }, "{kernel:?}");
            assert_eq!(calls(), tests as usize, "{kernel:?}: counted");
            // Ray by ray: 3 + 2 visits and 2 + 1 tests 8 wide, 2 + 2 and 1 + 1 4 wide.
            let mut single = Counters::default();
            for (r, want) in rays.iter().zip([(2, 1.0), (1, 1.0)]) {
                assert_eq!(accel.intersect(&hidden, r, &mut single).map(|h| (h.prim, h.t)), Some(want));
            }
            let alone = if visits == 8 { (5, 3) } else { (4, 2) };
            assert_eq!((single.nodes_visited, single.prim_tests), alone, "{kernel:?}: ray by ray");
            calls();
        }
    }
}
