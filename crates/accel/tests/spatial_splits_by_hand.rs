//! The SBVH builder (Stich et al. 2009) on scenes small enough to work out by hand: which of
//! the object and spatial splits it takes, where a straddling reference is cut and what each
//! half is bounded by, when a reference is kept whole ("unsplitting", §4.3), the `α` overlap
//! threshold and the duplication budget. Every expected tree, box and cost is derived in the
//! comments from the SAH written out: cost = T + I·Σ(half area · count) / parent half area.
//! The scenes lie in the plane z = 0, so a box's half area is its x extent times its y
//! extent. (Issue 15: mutation testing found that no test checked which tree SBVH makes.)

use raylab_accel::bvh::{sbvh, Bvh};
use raylab_accel::{BuildOptions, PrimHit, Primitives};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit::{bvh_shape as shape, Boxes};

/// Line segments, clipped exactly (Liang–Barsky): the part of a diagonal segment inside a
/// slab has a smaller box than the segment's box cut by the slab.
struct Segments(Vec<[Vec3; 2]>);

impl Primitives for Segments {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn bounds(&self, i: u32) -> Aabb {
        Aabb::from_points(self.0[i as usize])
    }
    fn intersect(&self, _: u32, _: &Ray) -> Option<PrimHit> {
        None
    }
    fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
        let [p, q] = self.0[i as usize];
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        for a in 0..3 {
            let d = q[a] - p[a];
            if d == 0.0 {
                if p[a] < clip.min[a] || p[a] > clip.max[a] {
                    return Aabb::EMPTY;
                }
                continue;
            }
            let (ta, tb) = ((clip.min[a] - p[a]) / d, (clip.max[a] - p[a]) / d);
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        }
        if t0 > t1 {
            return Aabb::EMPTY;
        }
        Aabb::from_points([p + t0 * (q - p), p + t1 * (q - p)])
    }
}

/// A box in the plane z = 0.
fn rect(x0: f32, x1: f32, y0: f32, y1: f32) -> Aabb {
    Aabb::new(Vec3::new(x0, y0, 0.0), Vec3::new(x1, y1, 0.0))
}

fn opts(traversal: f32, intersection: f32, max_leaf: usize, bins: usize, alpha: f32) -> BuildOptions {
    BuildOptions { traversal_cost: traversal, intersection_cost: intersection, max_leaf_size: max_leaf, bins, spatial_split_alpha: alpha, ..BuildOptions::default() }
}

/// The leaves' boxes in depth-first order, left before right.
fn leaf_boxes(b: &Bvh) -> Vec<Aabb> {
    fn walk(b: &Bvh, i: usize, out: &mut Vec<Aabb>) {
        let n = &b.nodes[i];
        if n.is_leaf() {
            out.push(n.bounds());
        } else {
            walk(b, n.left_first as usize, out);
            walk(b, n.left_first as usize + 1, out);
        }
    }
    let mut out = Vec::new();
    walk(b, 0, &mut out);
    out
}

/// The primitives under node `i`, sorted, without repeats.
fn prims_under(b: &Bvh, i: usize) -> Vec<u32> {
    let n = &b.nodes[i];
    let mut p = if n.is_leaf() {
        b.indices[n.left_first as usize..(n.left_first + n.count) as usize].to_vec()
    } else {
        let mut p = prims_under(b, n.left_first as usize);
        p.extend(prims_under(b, n.left_first as usize + 1));
        p
    };
    p.sort();
    p.dedup();
    p
}

/// The root's two children: each one's box and primitives.
fn root_children(b: &Bvh) -> [(Aabb, Vec<u32>); 2] {
    let l = b.nodes[0].left_first as usize;
    assert!(!b.nodes[0].is_leaf(), "the root is a leaf");
    [(b.nodes[l].bounds(), prims_under(b, l)), (b.nodes[l + 1].bounds(), prims_under(b, l + 1))]
}

fn assert_box(got: Aabb, want: Aabb, what: &str) {
    let close = (got.min - want.min).abs().max_element() < 1e-6 && (got.max - want.max).abs().max_element() < 1e-6;
    assert!(close, "{what}: got {got:?}, want {want:?}");
}

/// Leaf boxes are grown by the scene's largest extent / 2¹⁸ on every side.
fn grown(b: Aabb, scene_extent: f32) -> Aabb {
    let m = scene_extent / 262_144.0;
    Aabb { min: b.min - Vec3::splat(m), max: b.max + Vec3::splat(m) }
}

/// Scene A: two unit squares at either end of a 4 x 1 strip and a box covering the strip.
/// x runs from 8 to 12 (not from 0, so that a bin's offset from the box's corner matters).
fn scene_a() -> Boxes {
    Boxes(vec![rect(8.0, 9.0, 0.0, 1.0), rect(11.0, 12.0, 0.0, 1.0), rect(8.0, 12.0, 0.0, 1.0)])
}

#[test]
fn a_long_box_is_cut_in_two_by_a_spatial_split() {
    // Scene A, T = 1, I = 2, root half area 4 · 1 = 4, leaf cost 2 · 3 = 6.
    // Object split (centroids 8.5, 11.5, 10; with 2 bins over [8.5, 11.5] the long box's
    // centroid 10 falls in bin 1): {0} | {1, 2} = 1 + 2·(1·1 + 4·2)/4 = 5.5.
    // Spatial split at x = 10: bin 0 holds square 0 and the long box's part [8, 10], bin 1
    // the rest; 2 references enter bin 0 and 2 leave bin 1: 1 + 2·(2·2 + 2·2)/4 = 5.
    // Along y (plane 0.5, all three boxes cut): 1 + 2·(2·3 + 2·3)/4 = 7. The spatial split
    // at x = 10 is the cheapest and beats the leaf (5 < 6).
    // Unsplitting the long box: both halves cost 2·2 + 2·2 = 8, the whole box on the left
    // 4·2 + 2·1 = 10, on the right 2·1 + 4·2 = 10: it is cut.
    // Each child {square, half box} over a 2 x 1 box: object split 1 + 2·(1·1 + 2·1)/2 = 4,
    // not below its leaf cost 2·2 = 4 (spatial: 1 + 2·(1·2 + 1·2)/2 = 5): two leaves.
    for bins in [2, 4] {
        // With 4 bins (planes 9, 10, 11) the long box enters bin 0 and leaves bin 3; square
        // 0 touches the plane x = 9 and so leaves bin 1. At x = 9: 1 + 2·(1·2 + 3·3)/4 = 6.5;
        // at x = 10: 5; at x = 11: 1 + 2·(3·2 + 1·2)/4 = 5, a tie kept on the first plane.
        for max_leaf in [2, 8] {
            let b = sbvh::build(&scene_a(), &opts(1.0, 2.0, max_leaf, bins, 1e-5));
            assert_eq!(shape(&b), "([0 2] [1 2])", "bins {bins}, max leaf {max_leaf}");
            let leaves = leaf_boxes(&b);
            // The leaves bound the long box's halves, grown by 4 / 2¹⁸ = 2⁻¹⁶ (exact in f32).
            let m = 1.0 / 65_536.0;
            assert_eq!(leaves[0], Aabb::new(Vec3::new(8.0 - m, -m, -m), Vec3::new(10.0 + m, 1.0 + m, m)), "bins {bins}");
            assert_eq!(leaves[1], Aabb::new(Vec3::new(10.0 - m, -m, -m), Vec3::new(12.0 + m, 1.0 + m, m)), "bins {bins}");
            assert_eq!(b.nodes[0].bounds(), Aabb::new(Vec3::new(8.0 - m, -m, -m), Vec3::new(12.0 + m, 1.0 + m, m)));
            assert_eq!(b.stats().references, 4);
            b.validate(&scene_a()).unwrap();
        }
    }
    // With a leaf size of 1 the children split too (by their object split, cost 4): the
    // long box's halves get leaves of their own.
    let b = sbvh::build(&scene_a(), &opts(1.0, 2.0, 1, 2, 1e-5));
    assert_eq!(shape(&b), "((0 2) (2 1))");
    let m = 1.0 / 65_536.0;
    let want = [rect(8.0, 9.0, 0.0, 1.0), rect(8.0, 10.0, 0.0, 1.0), rect(10.0, 12.0, 0.0, 1.0), rect(11.0, 12.0, 0.0, 1.0)];
    for (got, want) in leaf_boxes(&b).into_iter().zip(want) {
        assert_eq!(got, Aabb { min: want.min - Vec3::splat(m), max: want.max + Vec3::splat(m) });
    }
}

#[test]
fn a_split_that_ties_with_the_leaf_makes_a_leaf() {
    // Scene A's children: the object split costs exactly the leaf's 4 (above), and a split
    // must be strictly cheaper. With I = 1.5 the root still splits (1 + 1.5·2 = 4 < 4.5,
    // object 1 + 1.5·9/4 = 4.375) and the children stay leaves (3.25 > 3); with T = 1,
    // I = 1 the spatial split ties with the leaf at the root (1 + 2 = 3): one leaf.
    assert_eq!(shape(&sbvh::build(&scene_a(), &opts(1.0, 1.5, 8, 2, 1e-5))), "([0 2] [1 2])");
    assert_eq!(shape(&sbvh::build(&scene_a(), &opts(1.0, 1.0, 8, 2, 1e-5))), "[0 1 2]");
    // ... unless the leaf would be too large (3 > 2): then the cheapest split is taken.
    assert_eq!(shape(&sbvh::build(&scene_a(), &opts(1.0, 1.0, 2, 2, 1e-5))), "([0 2] [1 2])");
}

#[test]
fn spatial_splits_are_tried_only_above_the_overlap_threshold() {
    // Scene A's object split {0} | {1, 2} has children overlapping in [8, 9] x [0, 1]: half
    // area 1, a quarter of the root's 4. Spatial splits are tried when that exceeds α · 4.
    let spatial = "([0 2] [1 2])";
    // Without them the object split (5.5 < 6) is taken; in its right child {1, 2} over
    // [8, 12] (centroids 11.5, 10) the object split 1 + 2·(4·1 + 1·1)/4 = 3.5 beats the leaf 4.
    let object = "(0 (2 1))";
    for (alpha, want) in [(0.2, spatial), (0.249, spatial), (0.25, object), (0.3, object)] {
        assert_eq!(shape(&sbvh::build(&scene_a(), &opts(1.0, 2.0, 8, 2, alpha))), want, "alpha {alpha}");
    }
}

#[test]
fn straddling_references_are_kept_whole_when_that_is_cheaper() {
    // Scene A plus two short boxes across x = 10: 3 over [9.8, 10.1], 4 over [9.9, 10.2].
    // T = 1, I = 2, root half area 4, leaf 10. Object split (2 bins over the centroids
    // [8.5, 11.5]; 3's centroid 9.95 falls in bin 0, 4's 10.05 in bin 1): {0, 3} | {1, 2, 4}
    // = 1 + 2·(2.1·2 + 4·3)/4 = 9.1. Spatial at x = 10: four references enter bin 0
    // ([8, 10]) and four leave bin 1: 1 + 2·(2·4 + 2·4)/4 = 9, the cheapest.
    // Unsplitting uses these estimates (left 2 x 1 with 4, right 2 x 1 with 4): both
    // halves cost 2·4 + 2·4 = 16. Long box: whole on the left 4·4 + 2·3 = 22, right 22: cut.
    // Box 3: left 2.1·4 + 2·3 = 14.4, right 2·3 + 2.2·4 = 14.8: whole, on the left.
    // Box 4: left 2.2·4 + 6 = 14.8, right 6 + 2.1·4 = 14.4: whole, on the right.
    let mut prims = scene_a();
    prims.0.push(rect(9.8, 10.1, 0.0, 1.0));
    prims.0.push(rect(9.9, 10.2, 0.0, 1.0));
    let b = sbvh::build(&prims, &opts(1.0, 2.0, 8, 2, 1e-5));
    let [(lb, lp), (rb, rp)] = root_children(&b);
    assert_eq!(lp, [0, 2, 3]);
    assert_eq!(rp, [1, 2, 4]);
    // The children's boxes show what was kept whole: 3 reaches 10.1 on the left, 4 starts
    // at 9.9 on the right, the long box is cut at 10.
    assert_box(lb, grown(rect(8.0, 10.1, 0.0, 1.0), 4.0), "left child");
    assert_box(rb, grown(rect(9.9, 12.0, 0.0, 1.0), 4.0), "right child");
    // (The children split further, by spatial splits of their own: only the root's
    // decision is worked out here.)
    b.validate(&prims).unwrap();
}

#[test]
fn diagonal_segments_are_bounded_by_their_clipped_parts() {
    // An X of two segments over [0, 4] x [0, 4] (half area 16): (0,0)-(4,4) and (0,4)-(4,0).
    // Their centroids coincide, so there is no object split; with a leaf size of 1 the
    // spatial split is taken. x = 2 and y = 2 tie (each side 2 x 4 with both references:
    // 1 + (8·2 + 8·2)/16 = 3); x comes first. Cutting costs 8·2 + 8·2 = 32 against 40 for
    // either whole: both are cut. Clipped exactly, segment 0's part left of x = 2 lies in
    // [0, 2] x [0, 2] and segment 1's in [0, 2] x [2, 4] (not the 2 x 4 of box ∩ slab), so
    // each child then splits by y into one leaf per part.
    let s = Segments(vec![[Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 4.0, 0.0)], [Vec3::new(0.0, 4.0, 0.0), Vec3::new(4.0, 0.0, 0.0)]]);
    let b = sbvh::build(&s, &opts(1.0, 1.0, 1, 2, 1e-5));
    assert_eq!(shape(&b), "((0 1) (1 0))");
    let want = [rect(0.0, 2.0, 0.0, 2.0), rect(0.0, 2.0, 2.0, 4.0), rect(2.0, 4.0, 0.0, 2.0), rect(2.0, 4.0, 2.0, 4.0)];
    for (got, want) in leaf_boxes(&b).into_iter().zip(want) {
        assert_box(got, grown(want, 4.0), "leaf");
    }
    b.validate(&s).unwrap();
}

#[test]
fn sah_split_of_a_parent_without_area() {
    use raylab_accel::bvh::SahCost;
    // A parent on a line (2 x 0 x 0: half area 2·0 + 0·0 + 0·2 = 0): every ray that hits it
    // hits both children, so the split costs T + I·(n_left + n_right) = 0.5 + 2·(2 + 3) =
    // 10.5 whatever the children. (A unit square is not such a parent: its half area is 1.)
    let sah = SahCost { traversal: 0.5, intersection: 2.0 };
    let line = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0));
    let half = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(line.half_area(), 0.0);
    assert_eq!(sah.split(&line, &half, 2, &half, 3), 10.5);
    assert_eq!(sah.split(&line, &line, 4, &half, 0), 8.5);
    // A point: 0.5 + 2·1.
    let point = Aabb::new(Vec3::ONE, Vec3::ONE);
    assert_eq!(sah.split(&point, &point, 1, &point, 0), 2.5);
}

#[test]
fn the_duplication_budget_is_shared_by_counts_and_spent_in_order() {
    // Unit squares 0 at x 0..1 and 1 at x 7..8, and two long boxes 2 and 3 over 0..8 (y 0..1
    // throughout); leaf size 1, so every node of two or more splits, the cheaper way.
    // Costs below are X in T + I·X, X = Σ(half area · count) / parent half area.
    // Root (8 x 1, budget 4 = one duplicate per primitive): object split {0} | {1, 2, 3}
    // X = (1·1 + 8·3)/8 = 3.125; spatial at x = 4 (3 references enter [0, 4], 3 leave
    // [4, 8]) X = (4·3 + 4·3)/8 = 3: both long boxes are cut (halves 4·3 + 4·3 = 24 against
    // 8·3 + 4·2 = 32 for either whole). 2 duplicates leave 2, shared by counts 3 and 3:
    // 2·3/6 = 1 to the left child, 2 − 1 = 1 to the right.
    // Left child {0, 2 [0, 4], 3 [0, 4]}: object {0} | {2, 3} X = (1·1 + 4·2)/4 = 2.25 beats
    // spatial at x = 2 (X = (2·3 + 2·2)/4 = 2.5); budget 1 split 1·1/3 = 0 and 1.
    // {2, 3} over [0, 4] with budget 1: no object split (same centroids); spatial at x = 2
    // (x and y tie at X = 2, x first): box 2 is cut, the budget is then spent and box 3 is
    // kept whole, on the left (a tie: 4·2 + 2·1 = 2·1 + 4·2). Children {2 [0, 2], 3} (no
    // budget: object split by centroids 1 < 2) and {2 [2, 4]}.
    // Right child {1, 2 [4, 8], 3 [4, 8]}: object {2, 3} | {1} (X = 2.25); budget 1 split
    // 1·2/3 = 0 and 1: {2, 3} over [4, 8] has no budget, no object split: halved by index.
    let prims = Boxes(vec![rect(0.0, 1.0, 0.0, 1.0), rect(7.0, 8.0, 0.0, 1.0), rect(0.0, 8.0, 0.0, 1.0), rect(0.0, 8.0, 0.0, 1.0)]);
    let b = sbvh::build(&prims, &opts(1.0, 1.0, 1, 2, 1e-5));
    assert_eq!(shape(&b), "((0 ((2 3) 2)) ((2 3) 1))");
    assert_eq!(b.stats().references, 7);
    let want = [rect(0.0, 1.0, 0.0, 1.0), rect(0.0, 2.0, 0.0, 1.0), rect(0.0, 4.0, 0.0, 1.0), rect(2.0, 4.0, 0.0, 1.0), rect(4.0, 8.0, 0.0, 1.0), rect(4.0, 8.0, 0.0, 1.0), rect(7.0, 8.0, 0.0, 1.0)];
    for (got, want) in leaf_boxes(&b).into_iter().zip(want) {
        assert_box(got, grown(want, 8.0), "leaf");
    }
    b.validate(&prims).unwrap();
}

/// Point boxes (zero extent on every axis) at the given x.
fn points(xs: impl IntoIterator<Item = f32>) -> Boxes {
    Boxes(xs.into_iter().map(|x| Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x, 0.0, 0.0))).collect())
}

#[test]
fn coincident_references_are_halved_by_index() {
    // Five points at the same place: no object split (one centroid), no spatial split (no
    // axis has extent), so a node larger than the leaf size (2) is halved by position:
    // {0, 1} | {2, 3, 4}, then {2} | {3, 4}.
    let b = sbvh::build(&points([5.0; 5]), &opts(1.0, 1.0, 2, 2, 1e-5));
    assert_eq!(shape(&b), "([0 1] (2 [3 4]))");
    assert_eq!(shape(&sbvh::build(&points([5.0; 5]), &opts(1.0, 1.0, 5, 2, 1e-5))), "[0 1 2 3 4]");
}

#[test]
fn sbvh_chains_are_cut_at_depth_64() {
    // Points at x = 3^k, k = 0..=70, leaf size 1, 2 bins. The scene is a line (half area 0),
    // so every split costs T + I·n, never below a leaf: nodes split only because they are
    // too large, along x at the one plane, the middle of the centroids' range; every point
    // but the largest lies below it (3^(k-1) < 3^k / 2). No spatial split is tried (the
    // children's overlap has no area, not above α times the root's 0). So each level peels
    // off the largest point: the node at depth d holds 72 - d points, until the node at
    // depth 64 becomes a leaf of 8: 63 interior nodes and 64 leaves. Mirrored (x = -3^k),
    // the chain runs down the right children.
    for sign in [1.0f32, -1.0] {
        let prims = points((0..=70).map(|k| sign * 3f32.powi(k)));
        let b = sbvh::build(&prims, &opts(1.0, 1.0, 1, 2, 1e-5));
        let s = b.stats();
        assert_eq!((s.max_depth, s.interior_nodes, s.leaves, s.references), (64, 63, 64, 71), "sign {sign}");
        assert_eq!((s.leaf_histogram[1], s.leaf_histogram[8]), (63, 1), "sign {sign}");
        b.validate(&prims).unwrap();
    }
}

#[test]
fn sbvh_chains_built_in_parallel_are_cut_at_depth_64_too() {
    // As above, with 4100 more points at the chain's low end, so that every node of the
    // chain holds at least 4096 references and builds its children through `rayon::join`.
    // Mirrored (x = -3^k, extras at -0.5), the chain runs down the right children instead.
    for sign in [1.0f32, -1.0] {
        let xs: Vec<f32> = (0..=70).map(|k| sign * 3f32.powi(k)).chain(std::iter::repeat_n(sign * 0.5, 4100)).collect();
        let prims = points(xs);
        let b = sbvh::build(&prims, &opts(1.0, 1.0, 1, 2, 1e-5));
        let s = b.stats();
        // Depth 64 holds 8 chain points and the 4100 extras: one leaf of 4108.
        assert_eq!((s.max_depth, s.interior_nodes, s.leaves, s.references), (64, 63, 64, 4171), "sign {sign}");
        assert_eq!((s.leaf_histogram[1], *s.leaf_histogram.last().unwrap()), (63, 1), "sign {sign}");
        b.validate(&prims).unwrap();
    }
}

#[test]
fn an_object_split_that_ties_with_the_spatial_one_is_kept() {
    // Scene A with square 0 shrunk to the segment x = 8, y 0..1 (no area). T = 1, I = 2;
    // α = -1 so that spatial splits are tried although the object split's children overlap
    // only in that segment (no area). Object split {0} | {1, 2}: X = (0·1 + 4·2)/4 = 2;
    // spatial at x = 10 (bins [8, 10] and [10, 12], two references each): X = (2·2 + 2·2)/4
    // = 2, a tie, which keeps the object split (a spatial split only when strictly cheaper).
    // Then {1, 2}: object (2 1) at X = (4·1 + 1·1)/4 = 1.25 against spatial (2·1 + 2·2)/4 =
    // 1.5 and the leaf's 2: cost 3.5 < 4.
    let prims = Boxes(vec![rect(8.0, 8.0, 0.0, 1.0), rect(11.0, 12.0, 0.0, 1.0), rect(8.0, 12.0, 0.0, 1.0)]);
    let b = sbvh::build(&prims, &opts(1.0, 2.0, 8, 2, -1.0));
    assert_eq!(shape(&b), "(0 (2 1))");
    assert_eq!(b.stats().references, 3);
}

#[test]
fn object_planes_that_tie_keep_the_first() {
    // Unit squares at x 0..1, 2..3 and 4..5; 4 bins over the centroids [0.5, 4.5] (width 1)
    // put them in bins 0, 2 and 3. Σ(half area · count): plane 1 {0} | {1, 2} = 1·1 + 3·2 = 7,
    // plane 2 the same sets, plane 3 {0, 1} | {2} = 3·2 + 1·1 = 7: a tie, kept on plane 1.
    // T = I = 1: 1 + 7/5 = 2.4 beats the leaf's 3; the children's boxes do not overlap, so no
    // spatial split is tried. Then {1, 2}: 1 + (1 + 1)/3 < 2.
    let prims = Boxes(vec![rect(0.0, 1.0, 0.0, 1.0), rect(2.0, 3.0, 0.0, 1.0), rect(4.0, 5.0, 0.0, 1.0)]);
    assert_eq!(shape(&sbvh::build(&prims, &opts(1.0, 1.0, 8, 4, 1e-5))), "(0 (1 2))");
}

#[test]
fn a_spatial_split_that_sends_everything_one_way_is_dropped() {
    // Two copies of the box [0, 8] x [0, 1] x [0, 1] (half area 8 + 1 + 8 = 17), leaf size 1,
    // 16 bins. No object split (same centroids). Spatial planes along x all cost the same,
    // Σ = 2·(2a + 1) + 2·(2(8 - a) + 1) = 36 at x = a (along y or z: 50), so the first,
    // x = 0.5, is taken. Unsplitting each copy: cut, 2·2 + 16·2 = 36 ([0, 0.5] has half area
    // 0.5 + 1 + 0.5 = 2, [0.5, 8] 16); whole on the left 17·2 + 16·1 = 50; whole on the
    // right 2·1 + 17·2 = 36, a tie with cutting, which keeps the copy whole: both go right,
    // the left side is empty, so the split is dropped and the node halved by index: two
    // leaves bounding the whole boxes.
    let prims = Boxes(vec![Aabb::new(Vec3::ZERO, Vec3::new(8.0, 1.0, 1.0)); 2]);
    let b = sbvh::build(&prims, &opts(1.0, 1.0, 1, 16, 1e-5));
    assert_eq!(shape(&b), "(0 1)");
    let s = b.stats();
    assert_eq!((s.leaves, s.references, s.max_depth), (2, 2, 2));
    // Grown by 8 / 2¹⁸ = 2⁻¹⁵.
    let m = 1.0 / 32_768.0;
    let whole = Aabb::new(Vec3::splat(-m), Vec3::new(8.0 + m, 1.0 + m, 1.0 + m));
    assert_eq!(leaf_boxes(&b), [whole, whole]);
    b.validate(&prims).unwrap();
}
