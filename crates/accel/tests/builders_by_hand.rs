//! The BVH builders on tiny hand-made scenes, against trees, costs and codes worked out by
//! hand in the comments: Morton codes against the bit interleaving written out, the binned
//! SAH's choice of plane and its leaf-or-split decision against the cost formula, the
//! median and midpoint splits, the LBVH's radix tree (Karras 2012) and its SAH collapse,
//! PLOC's mutual nearest neighbours, and `Bvh::validate` on broken trees built by hand.
//! (Issue 15: these were found missing by mutation testing; the oracle and quality tests
//! check that trees work and are good, not which tree a builder makes.)

use raylab_accel::bvh::{self, lbvh, morton, Bvh, BvhNode, SplitMethod};
use raylab_accel::{Accel, BuildOptions, Counters};
use raylab_core::{Aabb, Ray, Vec3};
use raylab_testkit::{bvh_shape as shape, Boxes, Prim, Soup};

fn aabb(min: [f32; 3], max: [f32; 3]) -> Aabb {
    Aabb::new(Vec3::from_array(min), Vec3::from_array(max))
}

/// A box of half size `h` centred at `(x, 0, 0)`.
fn cube_at(x: f32, h: f32) -> Aabb {
    aabb([x - h, -h, -h], [x + h, h, h])
}

fn opts(traversal: f32, intersection: f32, max_leaf: usize, bins: usize) -> BuildOptions {
    BuildOptions { traversal_cost: traversal, intersection_cost: intersection, max_leaf_size: max_leaf, bins, ..BuildOptions::default() }
}

// ---------------------------------------------------------------- Morton codes

/// Morton code written out bit by bit: bit k of x goes to bit 3k + 2, of y to 3k + 1, of z
/// to 3k (x most significant in each triple).
fn interleave(x: u32, y: u32, z: u32) -> u32 {
    let mut code = 0;
    for k in 0..10 {
        code |= ((x >> k) & 1) << (3 * k + 2) | ((y >> k) & 1) << (3 * k + 1) | ((z >> k) & 1) << (3 * k);
    }
    code
}

#[test]
fn morton3_interleaves_the_bits_as_written_out() {
    // Every bit of one axis: 0b100 repeated ten times = 0x24924924, and shifted.
    assert_eq!(morton::morton3(1023, 0, 0), 0x2492_4924);
    assert_eq!(morton::morton3(0, 1023, 0), 0x1249_2492);
    assert_eq!(morton::morton3(0, 0, 1023), 0x0924_9249);
    assert_eq!(morton::morton3(1023, 1023, 1023), (1 << 30) - 1);
    // Single bits of each axis at each position, and mixed patterns in every bit.
    for k in 0..10 {
        assert_eq!(morton::morton3(1 << k, 0, 0), 1 << (3 * k + 2), "x bit {k}");
        assert_eq!(morton::morton3(0, 1 << k, 0), 1 << (3 * k + 1), "y bit {k}");
        assert_eq!(morton::morton3(0, 0, 1 << k), 1 << (3 * k), "z bit {k}");
    }
    for (x, y, z) in [(0x2aa, 0x155, 0x3c3), (0x155, 0x2aa, 0x0f0), (1, 2, 3), (1000, 517, 99), (0x3ff, 0, 0x155)] {
        assert_eq!(morton::morton3(x, y, z), interleave(x, y, z), "({x}, {y}, {z})");
    }
    // (x, y, z) = (5, 3, 6): x 101 -> bits 2, 8; y 011 -> bits 1, 4; z 110 -> bits 3, 6.
    assert_eq!(morton::morton3(5, 3, 6), 4 + 256 + 2 + 16 + 8 + 64);
}

#[test]
fn morton_code_quantises_each_axis_in_its_own_extent() {
    // Extents 2, 4 and 8 (not 1, where `*` and `/` agree). (0.5, 3, 1) sits at 1/4, 3/4 and
    // 1/8 of them: 1024 cells give cells 256, 768 and 128.
    let b = aabb([0.0, 0.0, 0.0], [2.0, 4.0, 8.0]);
    assert_eq!(morton::morton_code(Vec3::new(0.5, 3.0, 1.0), &b), interleave(256, 768, 128));
    // Offset bounds: the minimum maps to cell 0, the maximum to cell 1023 (clamped from 1024).
    let b = aabb([-3.0, 10.0, 5.0], [1.0, 12.0, 6.0]);
    assert_eq!(morton::morton_code(Vec3::new(-3.0, 10.0, 5.0), &b), 0);
    assert_eq!(morton::morton_code(Vec3::new(1.0, 12.0, 6.0), &b), (1 << 30) - 1);
    // Half way on x, a quarter on y, the top cell on z: cells 512, 256, 1023.
    assert_eq!(morton::morton_code(Vec3::new(-1.0, 10.5, 6.0), &b), interleave(512, 256, 1023));
    // Outside the bounds clamps to the end cells.
    assert_eq!(morton::morton_code(Vec3::new(-100.0, 100.0, 5.5), &b), interleave(0, 1023, 512));
    // A flat axis maps to 0.
    let flat = aabb([0.0, 0.0, 0.0], [4.0, 0.0, 4.0]);
    assert_eq!(morton::morton_code(Vec3::new(1.0, 0.0, 3.0), &flat), interleave(256, 0, 768));
}

// ---------------------------------------------------------------- LBVH

/// Boxes centred on the x axis where 1024 Morton cells span x in [0, 1024], so a centre at
/// `k + 0.5` has x cell k (y and z are flat, cell 0), and the codes are `interleave(k, 0, 0)`.
/// The primitives are listed out of order, with a duplicate cell.
fn radix_scene() -> Boxes {
    // prim: 0 at the top (cell 1023, clamped from 1024), 1 in cell 2, 2 at 0 (cell 0), 3 in
    // cell 3, 4 in cell 1, 5 in cell 2 again.
    Boxes([1024.0, 2.5, 0.0, 3.5, 1.5, 2.5].iter().map(|&x| cube_at(x, 0.25)).collect())
}

#[test]
fn lbvh_is_the_radix_tree_of_the_morton_codes() {
    // Sorted by (code, index): 2 (cell 0), 4 (1), 1 (2), 5 (2), 3 (3), 0 (1023). The radix
    // tree splits where the highest differing bit changes: x bit 9 separates cell 1023 from
    // the rest; x bit 1 splits {0, 1} from {2, 2, 3}; bit 0 splits {2, 2} from {3}; equal
    // codes 1 and 5 are split by their position (Karras §4). One primitive per leaf
    // (max_leaf_size 1: the SAH collapse may only merge up to one primitive).
    let s = radix_scene();
    let b = lbvh::build(&s, &opts(1.0, 1.0, 1, 16));
    b.validate(&s).unwrap();
    assert_eq!(shape(&b), "(((2 4) ((1 5) 3)) 0)");
    assert_eq!(b.nodes.len(), 11);
}

#[test]
fn lbvh_of_a_single_primitive_is_one_leaf() {
    let s = Boxes(vec![cube_at(3.0, 1.0)]);
    let b = lbvh::build(&s, &BuildOptions::default());
    assert_eq!(shape(&b), "0");
    assert_eq!(b.nodes.len(), 1);
    // The leaf is the box grown by 2⁻¹⁸ of its extent, 2: 2⁻¹⁷ on each side.
    let m = 2.0f32.powi(-17);
    assert_eq!(b.root_bounds(), aabb([2.0 - m, -1.0 - m, -1.0 - m], [4.0 + m, 1.0 + m, 1.0 + m]));
}

/// Two unit cubes along x with a gap `g` between them.
fn pair(g: f32) -> Boxes {
    Boxes(vec![aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), aabb([1.0 + g, 0.0, 0.0], [2.0 + g, 1.0, 1.0])])
}

#[test]
fn lbvh_collapses_a_pair_by_the_sah_as_worked_out() {
    // The post-pass (Karras & Aila 2013 §3) prices a leaf of both cubes against the split,
    // with areas unnormalised: a unit cube has half area 3, the pair's box (2 + g) by 1 by 1
    // has 2(2 + g) + 1 = 5 + 2g. leaf = I·2·(5 + 2g); split = T·(5 + 2g) + I·3 + I·3.
    // Collapse when leaf <= split (and 2 <= max_leaf). The margin of 2⁻¹⁸ of the extent
    // moves these by ~10⁻⁵, far from every tie below.
    let cases = [
        // (gap, T, I, max_leaf, collapsed?)
        (1.0, 1.0, 1.0, 8, false), // leaf 14 > split 7 + 6 = 13
        (0.0, 1.0, 1.0, 8, true),  // leaf 10 <= split 5 + 6 = 11
        (0.0, 1.0, 1.0, 1, false), // two primitives do not fit a leaf of one
        (1.0, 2.0, 1.0, 8, true),  // leaf 14 <= split 14 + 6 = 20
        (0.4, 1.0, 1.0, 8, true),  // 5.8: leaf 11.6 <= split 11.8
        (0.6, 1.0, 1.0, 8, false), // 6.2: leaf 12.4 > split 12.2
        (2.0, 1.0, 3.0, 8, false), // 9: leaf 54 > split 9 + 18 = 27
        (1.0, 6.0, 0.5, 8, true),  // 7: leaf 7 <= split 42 + 3 = 45
    ];
    for (g, t, i, max_leaf, collapsed) in cases {
        let s = pair(g);
        let b = lbvh::build(&s, &opts(t, i, max_leaf, 16));
        b.validate(&s).unwrap();
        let want = if collapsed { "[0 1]" } else { "(0 1)" };
        assert_eq!(shape(&b), want, "gap {g}, T {t}, I {i}, max leaf {max_leaf}");
        assert_eq!(b.nodes.len(), if collapsed { 1 } else { 3 });
    }
}

#[test]
fn lbvh_collapse_sums_the_subtrees_costs() {
    // Three cubes: 0 and 1 identical at the origin, 2 at x = 10 (gap 9). Sorted: 0, 1 (tie by
    // index), 2. {0, 1}: box area 3, leaf 2·3 = 6 <= split 3 + 3 + 3 = 9: collapsed, cost 6.
    // Root: box 11 by 1 by 1, area 23; leaf 3·23 = 69 > split 23 + 6 + 3 = 32. With T = 3:
    // {0, 1} still collapses (6 <= 15); root: 69 <= 69 + 6 + 3: one leaf of all three.
    let s = Boxes(vec![aabb([0.0; 3], [1.0; 3]), aabb([0.0; 3], [1.0; 3]), aabb([10.0, 0.0, 0.0], [11.0, 1.0, 1.0])]);
    let b = lbvh::build(&s, &opts(1.0, 1.0, 8, 16));
    assert_eq!(shape(&b), "([0 1] 2)");
    let b = lbvh::build(&s, &opts(3.0, 1.0, 8, 16));
    assert_eq!(shape(&b), "[0 1 2]");
    // T = 2: root leaf 69 > split 46 + 9 = 55.
    let b = lbvh::build(&s, &opts(2.0, 1.0, 8, 16));
    assert_eq!(shape(&b), "([0 1] 2)");
}

// ---------------------------------------------------------------- PLOC

#[test]
fn ploc_merges_mutual_nearest_neighbours() {
    // Cubes of half size 0.25 centred at x = 0, 1, 5, 6, 20, listed out of order. The
    // distance of two clusters is the half area of their union: for boxes from x0 to x1 it is
    // (x1 − x0)·0.5·2 + 0.25. Round 1: 0–1 and 5–6 are mutual nearest (union lengths 1.5);
    // 20's nearest is 6 (14.5), not mutual: it waits. Round 2: {0, 1}–{5, 6} (6.5) against
    // {5, 6}–20 (15.5): the first pair merges. Round 3: the rest.
    let xs = [5.0, 20.0, 0.0, 6.0, 1.0];
    let s = Boxes(xs.iter().map(|&x| cube_at(x, 0.25)).collect());
    let b = bvh::ploc::build(&s, &opts(1.0, 1.0, 1, 16));
    b.validate(&s).unwrap();
    // prims: 0 at x 5, 1 at 20, 2 at 0, 3 at 6, 4 at 1. Children in Morton (x) order.
    assert_eq!(shape(&b), "(((2 4) (0 3)) 1)");
}

#[test]
fn ploc_searches_only_within_its_radius() {
    // Small cubes at x = 0 and 2 with a large one (half size 5) at x = 1 between them on the
    // Morton curve. With radius 1 the cube at 0 sees only the large one: they merge (the large
    // one's two candidates tie at its own box's area, and the lower pair wins), then the cube
    // at 2 joins. With radius 2 the two small cubes see each other (union 2.5 x 0.5 x 0.5) and
    // merge first.
    let s = Boxes(vec![cube_at(0.0, 0.25), cube_at(1.0, 5.0), cube_at(2.0, 0.25)]);
    let radius = |r: usize| BuildOptions { ploc_radius: r, ..opts(1.0, 1.0, 1, 16) };
    assert_eq!(shape(&bvh::ploc::build(&s, &radius(1))), "((0 1) 2)");
    assert_eq!(shape(&bvh::ploc::build(&s, &radius(2))), "((0 2) 1)");
    assert_eq!(shape(&bvh::ploc::build(&s, &radius(16))), "((0 2) 1)");
}

// ---------------------------------------------------------------- binned SAH

#[test]
fn binned_sah_picks_the_cheapest_plane_of_all_axes() {
    // A, B, D unit cubes at x = 0, 1, 3; C = [2, 3] x [0, 4] x [0, 1] (tall). With 4 bins the
    // centroids x 0.5, 1.5, 2.5, 3.5 fall in bins 0, 1, 2, 3 and y 0.5, 0.5, 2, 0.5 in bins 0,
    // 0, 3, 0. Σ half area × count per candidate:
    //   x {A}|{BCD}:  3·1 + (3·4 + 4·1 + 1·3)·3 = 3 + 57 = 60
    //   x {AB}|{CD}:  (2 + 1 + 2)·2 + (2·4 + 4 + 2)·2 = 10 + 28 = 38
    //   x {ABC}|{D}:  19·3 + 3 = 60
    //   y {ABD}|{C}:  (4 + 1 + 4)·3 + (1·4 + 4 + 1)·1 = 27 + 9 = 36   <- cheapest
    // although x is the longest axis of the centroids' box.
    let s = Boxes(vec![
        aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
        aabb([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]),
        aabb([2.0, 0.0, 0.0], [3.0, 4.0, 1.0]),
        aabb([3.0, 0.0, 0.0], [4.0, 1.0, 1.0]),
    ]);
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 1, 4));
    b.validate(&s).unwrap();
    // {A, B, D}: x centroids 0.5, 1.5, 3.5 in bins 0, 1, 3 (width 0.75): {A}|{BD} costs
    // 3 + (3 + 1 + 3)·2 = 17, {AB}|{D} 5·2 + 3 = 13: the latter.
    assert_eq!(shape(&b), "(((0 1) 3) 2)");
    // The nodes' boxes: root 4 x 4 x 1, children {A, B, D} 4 x 1 x 1 and C.
    assert_eq!(b.nodes[0].bounds(), aabb([0.0; 3], [4.0, 4.0, 1.0]));
    let l = b.nodes[0].left_first as usize;
    assert_eq!(b.nodes[l].bounds(), aabb([0.0; 3], [4.0, 1.0, 1.0]));
    assert_eq!(b.nodes[l + 1].bounds(), aabb([2.0, 0.0, 0.0], [3.0, 4.0, 1.0]));
    // Stats of this tree by hand: 3 interior nodes, 4 leaves of one, depth 4 (root 1).
    let st = b.stats();
    assert_eq!((st.interior_nodes, st.leaves, st.max_depth, st.references), (3, 4, 4, 4));
    assert_eq!(st.memory_bytes, 7 * 32 + 4 * 4);
    assert_eq!((st.name.as_str(), st.primitives), ("bvh", 4));
    assert_eq!(b.root_bounds(), aabb([0.0; 3], [4.0, 4.0, 1.0]));
    // Built through `AnyAccel`, the build time reaches the stats.
    let any = raylab_accel::AnyAccel::build(raylab_accel::AccelKind::BvhMedian, &s, &BuildOptions::default());
    assert!(any.stats().build_ms > 0.0);
    assert_eq!(any.stats().name, "bvh-median");
}

#[test]
fn binned_sah_weighs_left_and_right_by_their_counts() {
    // Unit cubes A, B, C at x = 0, 1, 2 and two 1 x 1 x 3 slabs D = [6,7]x[0,1]x[0,3] and
    // E = [7,8]x[0,1]x[0,3]; 2 bins per axis. x centroids 0.5, 1.5, 2.5 fall in bin 0 (width
    // 3.5), 6.5 and 7.5 in bin 1; z centroids 0.5 and 1.5 likewise: {A,B,C}|{D,E} either way,
    // 7·3 + (2 + 3 + 6)·2 = 43 against the root's half area 8 + 3 + 24 = 35.
    let s = Boxes(vec![
        aabb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
        aabb([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]),
        aabb([2.0, 0.0, 0.0], [3.0, 1.0, 1.0]),
        aabb([6.0, 0.0, 0.0], [7.0, 1.0, 3.0]),
        aabb([7.0, 0.0, 0.0], [8.0, 1.0, 3.0]),
    ]);
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 8, 2));
    b.validate(&s).unwrap();
    // Root: cost 1 + 43/35 = 2.23 < leaf 5: split.
    // {A,B,C} (3 x 1 x 1, area 7): best plane {A}|{BC} at x 1.5 (bins of width 1): cost
    // 1 + (3 + 5·2)/7 = 2.86 < 3: split; {B,C}: 1 + 6/5 = 2.2 > 2: leaf.
    // {D,E} (2 x 1 x 3, area 2 + 3 + 6 = 11): 1 + (7 + 7)/11 = 2.27 > 2: leaf.
    assert_eq!(shape(&b), "((0 [1 2]) [3 4])");
}

#[test]
fn binned_sah_bins_small_nodes_coarser() {
    // Twenty cubes of half size 1/4 at x = 0, 1, ..., 19. A node of n primitives is binned
    // into min(bins, 4 + n/20) bins (Embree's rule), so the root gets 5 bins of width 19/5:
    // x 0-3, 4-7, 8-11, 12-15, 16-19. A left part of 4k cubes spans 4k - 1/2 in x, half area
    // 4k - 1/4, so Σ half area × count is 15 + 252 = 267, 62 + 141 = 203, 203 and 267 for
    // k = 1..4: the tie goes to the first plane, 8 cubes on the left (x up to 7.25).
    // With 16 bins the even split 10 | 10 (195) would be reachable and chosen; with 4 (or
    // 3) bins, 10 | 10 (or 7 | 13).
    let s = Boxes((0..20).map(|i| cube_at(i as f32, 0.25)).collect());
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 1, 16));
    b.validate(&s).unwrap();
    let l = b.nodes[0].left_first as usize;
    assert_eq!(b.nodes[l].bounds(), aabb([-0.25; 3], [7.25, 0.25, 0.25]));
    assert_eq!(b.nodes[l + 1].bounds(), aabb([7.75, -0.25, -0.25], [19.25, 0.25, 0.25]));
}

#[test]
fn binned_sah_leaf_or_split_decision_follows_the_cost_formula() {
    // Two unit cubes with gap g (see `pair`): the only split, {A}|{B}, costs
    // T + I·(3 + 3)/(5 + 2g) against a leaf of I·2; a split happens when it is cheaper, or
    // always when 2 > max_leaf.
    let cases = [
        // (gap, T, I, max_leaf, split?)
        (1.0, 1.0, 1.0, 8, true),  // 1 + 6/7 = 1.857 < 2
        (0.0, 1.0, 1.0, 8, false), // 1 + 6/5 = 2.2 >= 2
        (0.5, 1.0, 1.0, 8, false), // 1 + 6/6 = 2 >= 2: a tie stays a leaf
        (0.0, 1.0, 1.0, 1, true),  // a leaf of two is not allowed
        (4.0, 3.0, 2.0, 8, true),  // 3 + 12/13 = 3.92 < 4
        (3.0, 3.0, 2.0, 8, false), // 3 + 12/11 = 4.09 >= 4
        (0.0, 0.5, 3.0, 8, true),  // 0.5 + 18/5 = 4.1 < 6
    ];
    for (g, t, i, max_leaf, split) in cases {
        let s = pair(g);
        let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(t, i, max_leaf, 16));
        b.validate(&s).unwrap();
        assert_eq!(shape(&b), if split { "(0 1)" } else { "[0 1]" }, "gap {g}, T {t}, I {i}, max leaf {max_leaf}");
    }
}

#[test]
fn binned_sah_counts_in_blocks_for_the_wide_layouts() {
    // With `leaf_block` 4 a side of n costs c(n) = ⌈n/4⌉ + 0.35·n (one test per block and a
    // share per triangle): c(1) = 1.35, c(2) = 1.7, c(3) = 2.05, c(4) = 2.4, c(8) = 4.8.
    // Two rows of four unit cubes, at x = 0..4 and x = 20..24: the root (24 × 1 × 1, half
    // area 49) splits into its rows (half area 9 each) for 1 + 2·9·2.4/49 = 1.88 < 4.8. A row
    // stays one leaf, 2.4, against 1 + 2·5·1.7/9 = 2.89 for halves of two (half area 5) and
    // 1 + (3·1.35 + 7·2.05)/9 = 3.04 for one and three. Counting primitives the rows split
    // (1 + 2·5·2/9 = 3.22 < 4) into pairs that stay leaves (1 + (3 + 3)/5 = 2.2 ≥ 2).
    let rows = Boxes((0..4).map(|i| cube_at(i as f32 + 0.5, 0.5)).chain((0..4).map(|i| cube_at(20.0 + i as f32 + 0.5, 0.5))).collect());
    let blocks = BuildOptions { leaf_block: 4, ..opts(1.0, 1.0, 8, 16) };
    let b = Bvh::build(&rows, SplitMethod::BinnedSah, &blocks);
    b.validate(&rows).unwrap();
    assert_eq!(shape(&b), "([0 1 2 3] [4 5 6 7])");
    assert_eq!(shape(&Bvh::build(&rows, SplitMethod::BinnedSah, &opts(1.0, 1.0, 8, 16))), "(([0 1] [2 3]) ([4 5] [6 7]))");
    // A leaf larger than `max_leaf_size` still splits, whatever the blocks say.
    assert_eq!(shape(&Bvh::build(&rows, SplitMethod::BinnedSah, &BuildOptions { leaf_block: 4, ..opts(1.0, 1.0, 2, 16) })), "(([0 1] [2 3]) ([4 5] [6 7]))");
}

/// The shape of the binned SAH's tree over `boxes`, counting in blocks of four.
fn in_blocks(boxes: Vec<Aabb>) -> String {
    let s = Boxes(boxes);
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &BuildOptions { leaf_block: 4, ..opts(1.0, 1.0, 8, 16) });
    b.validate(&s).unwrap();
    shape(&b)
}

#[test]
fn binned_sah_in_blocks_splits_a_large_primitive_from_small_ones() {
    // A cube of side 10 at the origin (half area 300) and three cubes of side 0.1 at x = 4,
    // 4.2, 4.4 inside it (together 0.5 × 0.1 × 0.1, half area 0.11). Splitting the large one
    // off costs 1 + (300·c(1) + 0.11·c(3))/300 = 2.351 against a leaf of all four, c(4) =
    // 2.4: a split. Counting blocks alone (c(n) = ⌈n/4⌉) it would be 2.0004 against 1, a
    // leaf whose one block every ray reaching the large cube would test; the per-triangle
    // share must exceed a third for the split to win (c(4) - c(1) > the traversal cost).
    // The three small ones stay a leaf: 2.05 against 1 + (0.03·1.35 + 0.07·1.7)/0.11 = 2.45.
    assert_eq!(in_blocks(vec![cube_at(0.0, 5.0), cube_at(4.0, 0.05), cube_at(4.2, 0.05), cube_at(4.4, 0.05)]), "(0 [1 2 3])");
}

#[test]
fn binned_sah_in_blocks_tries_every_cut_of_four() {
    // The large cube of the test above (half area 300), now centred at x = 1 between small
    // ones at x = 0.8, 1.2 and 1.4 (their union 0.7 × 0.1 × 0.1, half area 0.15). No plane
    // isolates it: the plane cuts cost 1 + (0.03·c(1) + 300·c(3))/300 = 3.05, 1 + (300·c(2)
    // + 0.07·c(2))/300 = 2.70 and 3.05 again, all above a leaf's c(4) = 2.4, so bins would
    // make a leaf. Of every cut, {1} | {0, 2, 3} costs 1 + (300·1.35 + 0.15·2.05)/300 =
    // 2.351: a split. The small ones stay a leaf (2.05 against 2.06 and 2.52 for their
    // cuts).
    assert_eq!(in_blocks(vec![cube_at(0.8, 0.05), cube_at(1.0, 5.0), cube_at(1.2, 0.05), cube_at(1.4, 0.05)]), "(1 [0 2 3])");
}

#[test]
fn wide_layouts_count_in_blocks_only_when_every_primitive_is_a_triangle() {
    // The rows of `binned_sah_counts_in_blocks_for_the_wide_layouts` as triangles, each
    // spanning its unit cube: in blocks, one leaf per row. With the last one a sphere of
    // the same bounds, which a leaf tests with a call of its own whatever block it shares,
    // the binary tree under the wide layouts counts primitives: pairs.
    let tri = |x: f32| Prim::Triangle([Vec3::new(x, -0.5, -0.5), Vec3::new(x + 1.0, 0.5, -0.5), Vec3::new(x + 1.0, 0.5, 0.5)]);
    let xs = [0.0, 1.0, 2.0, 3.0, 20.0, 21.0, 22.0, 23.0];
    let triangles = Soup::new(xs.iter().map(|&x| tri(x)).collect());
    let opts = BuildOptions::default();
    assert_eq!(shape(&raylab_accel::binary_for_wide(&triangles, &opts, "bvh")), "([0 1 2 3] [4 5 6 7])");
    let mut mixed: Vec<Prim> = xs[..7].iter().map(|&x| tri(x)).collect();
    mixed.push(Prim::Sphere { center: Vec3::new(23.5, 0.0, 0.0), radius: 0.5 });
    let mixed = Soup::new(mixed);
    let b = raylab_accel::binary_for_wide(&mixed, &opts, "bvh");
    b.validate(&mixed).unwrap();
    assert_eq!(shape(&b), "(([0 1] [2 3]) ([4 5] [6 7]))");
}

#[test]
fn binned_sah_bins_by_centroid_position() {
    // Eight unit cubes at x = 0, 1, 2, 3, 10, 11, 12, 13 with 2 bins: centroids 0.5 .. 13.5,
    // bin width 6.5: the first four in bin 0. Cost 1 + (4·(4 + 1 + 4)·2)/(14 + 1 + 14) =
    // 1 + 72/29 = 3.48 < 8: split in the middle; each half (area 9) splits {0,1}|{2,3} at 2
    // bins of width 1.5: 1 + (5·2 + 5·2)/9 = 3.22 < 4; pairs (area 5) cost 1 + 6/5 = 2.2 >= 2: leaves.
    // The same along y and along z (each axis has its own bins and counts).
    for axis in 0..3 {
        let s = Boxes(
            [0.0, 1.0, 2.0, 3.0, 10.0, 11.0, 12.0, 13.0]
                .iter()
                .map(|&x| {
                    let (mut min, mut max) = ([0.0f32; 3], [1.0f32; 3]);
                    (min[axis], max[axis]) = (x, x + 1.0);
                    aabb(min, max)
                })
                .collect(),
        );
        let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 8, 2));
        b.validate(&s).unwrap();
        assert_eq!(shape(&b), "(([0 1] [2 3]) ([4 5] [6 7]))", "along axis {axis}");
    }
}

#[test]
fn median_and_midpoint_split_where_they_say() {
    // Point-like boxes with centroids x = 0, 1, 2, 10 (listed out of order) and max leaf 1.
    // Median: two and two at every level. Midpoint: the middle of the centroids' extent, 5,
    // separates 10; then 1 separates 0 from {1, 2} (x < 1 goes left); then 1.5.
    let s = Boxes([2.0, 10.0, 0.0, 1.0].iter().map(|&x| cube_at(x, 0.1)).collect());
    let median = Bvh::build(&s, SplitMethod::Median, &opts(1.0, 1.0, 1, 16));
    median.validate(&s).unwrap();
    assert_eq!(shape(&median), "((2 3) (0 1))");
    let midpoint = Bvh::build(&s, SplitMethod::Midpoint, &opts(1.0, 1.0, 1, 16));
    midpoint.validate(&s).unwrap();
    assert_eq!(shape(&midpoint), "((2 (3 0)) 1)");
    // Five: the median puts 5/2 = 2 on the left.
    let s = Boxes([4.0, 3.0, 2.0, 1.0, 0.0].iter().map(|&x| cube_at(x, 0.1)).collect());
    let median = Bvh::build(&s, SplitMethod::Median, &opts(1.0, 1.0, 2, 16));
    assert_eq!(shape(&median), "([3 4] (2 [0 1]))");
    // With max leaf 8 neither splits five primitives.
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::Median, &opts(1.0, 1.0, 8, 16))), "[0 1 2 3 4]");
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::Midpoint, &opts(1.0, 1.0, 8, 16))), "[0 1 2 3 4]");
}

#[test]
fn midpoint_falls_back_to_the_median_when_the_middle_separates_nothing() {
    // Two point boxes one ulp apart: the middle rounds onto the lower one, so `x < mid` puts
    // nothing on the left; the median then splits one and one.
    let a = 1.0f32;
    let b = a.next_up();
    let s = Boxes(vec![aabb([b, 0.0, 0.0], [b, 0.0, 0.0]), aabb([a, 0.0, 0.0], [a, 0.0, 0.0])]);
    let t = Bvh::build(&s, SplitMethod::Midpoint, &opts(1.0, 1.0, 1, 16));
    t.validate(&s).unwrap();
    assert_eq!(shape(&t), "(1 0)");
}

#[test]
fn coincident_centroids_are_halved_by_index_down_to_the_leaf_size() {
    // Five nested boxes with the same centre (at x = 3, not 0, where the centroids' extent
    // `max − min` and `max + min` would agree): no plane separates them, so nodes larger than
    // the leaf size (2) are halved by index: 5 -> 2 + 3, 3 -> 1 + 2.
    let s = Boxes((1..=5).map(|k| cube_at(3.0, k as f32)).collect());
    for method in [SplitMethod::BinnedSah, SplitMethod::Median, SplitMethod::Midpoint] {
        let b = Bvh::build(&s, method, &opts(1.0, 1.0, 2, 16));
        b.validate(&s).unwrap();
        assert_eq!(shape(&b), "([0 1] (2 [3 4]))", "{method:?}");
        // Within the leaf size they stay together.
        let b = Bvh::build(&s, method, &opts(1.0, 1.0, 5, 16));
        assert_eq!(shape(&b), "[0 1 2 3 4]", "{method:?}");
    }
}

#[test]
fn binned_sah_breaks_ties_towards_the_first_plane() {
    // Unit cubes at x = 0, 2, 4: 4 bins of width 1 over the centroids 0.5 .. 4.5 hold them in
    // bins 0, 2, 3. {A}|{BC} (planes 1 and 2) and {AB}|{C} (plane 3) cost the same by
    // symmetry, 3·1 + (3 + 1 + 3)·2 = 17, and the first plane is kept.
    let s = Boxes([0.0, 2.0, 4.0].iter().map(|&x| aabb([x, 0.0, 0.0], [x + 1.0, 1.0, 1.0])).collect());
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 1, 4));
    assert_eq!(shape(&b), "(0 (1 2))");
}

#[test]
fn binned_sah_on_a_line_prices_every_split_as_the_whole_node() {
    // Point boxes on the x axis: every box is flat, half area 0, so the split costs
    // T + I·n (a ray that hits the node hits both children) against a leaf of I·n: never
    // cheaper, so three stay in one leaf unless the leaf size forces a split.
    let s = Boxes([0.0, 1.0, 2.0].iter().map(|&x| aabb([x, 0.0, 0.0], [x, 0.0, 0.0])).collect());
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 8, 16))), "[0 1 2]");
    // T = 1, I = 3: 1 + 9 >= 9, still a leaf; T = 0.5, I = 1: 0.5 + 3 >= 3.
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 3.0, 8, 16))), "[0 1 2]");
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::BinnedSah, &opts(0.5, 1.0, 8, 16))), "[0 1 2]");
    // Forced: bins of width 0.5 put 0, 1, 2 in bins 0, 2, 3; the first plane separates 0.
    assert_eq!(shape(&Bvh::build(&s, SplitMethod::BinnedSah, &opts(1.0, 1.0, 1, 4))), "(0 (1 2))");
}

#[test]
fn trees_are_cut_at_depth_64() {
    // Point boxes at x = 3^k, k = 1 .. 79, and `extra` more at x = 1: the midpoint of
    // [1, 3^m], about 1.5·3^(m−1), separates only the farthest (with 2^k it would round onto
    // 2^(m−1) once 1 + 2^m rounds to 2^m), so the midpoint tree is a chain; a node at depth d
    // (root 1) holds extra + 81 − d primitives. At depth 64 it becomes a leaf of extra + 17:
    // 63 interior nodes, 63 leaves of one (the peeled points at depths 2 .. 64) and that leaf.
    // Mirrored (x = −3^k) the chain runs down the right children instead of the left; with
    // 4100 extra points the nodes of the chain hold over 4096 primitives, so their children
    // are built in parallel (`rayon::join`), which has its own depth and offset arithmetic.
    for sign in [1.0f32, -1.0] {
        for extra in [1usize, 4100] {
            let point = |x: f32| aabb([sign * x, 0.0, 0.0], [sign * x, 0.0, 0.0]);
            let s = Boxes((1..80).map(|k| point(3.0f32.powi(k))).chain((0..extra).map(|_| point(1.0))).collect());
            let b = Bvh::build(&s, SplitMethod::Midpoint, &opts(1.0, 1.0, 1, 16));
            b.validate(&s).unwrap_or_else(|e| panic!("sign {sign}, extra {extra}: {e}"));
            let st = b.stats();
            assert_eq!((st.max_depth, st.interior_nodes, st.leaves, st.references), (64, 63, 64, 79 + extra), "sign {sign}, extra {extra}");
            assert_eq!(st.leaf_histogram[1], 63);
            assert_eq!(st.leaf_histogram[16], 1, "the leaf of {} goes to the last bucket, 16+", extra + 16);
        }
    }
}

#[test]
fn large_nodes_are_binned_in_parallel_with_the_same_counts() {
    // 40 000 primitives (above the 2^15 at which a node's binning is split into chunks
    // and merged): two clusters of 20 000 tiny cubes, in [0, 1]³ and [100, 101] x [0, 1]²,
    // interleaved in index order. Any split but the gap between them costs more; the root's
    // children hold 20 000 each, each inside its cluster.
    let mut rng = raylab_core::Pcg32::new(15, 1);
    let s = Boxes((0..40_000).map(|i| { let x = if i % 2 == 0 { 0.0 } else { 100.0 }; let c = Vec3::new(x + rng.next_f32(), rng.next_f32(), rng.next_f32()); Aabb::new(c - 0.001, c + 0.001) }).collect());
    let b = Bvh::build(&s, SplitMethod::BinnedSah, &BuildOptions::default());
    let l = b.nodes[0].left_first as usize;
    assert!(!b.nodes[0].is_leaf());
    let count = |i: usize| -> u32 {
        let mut stack = vec![i];
        let mut n = 0;
        while let Some(k) = stack.pop() {
            let node = &b.nodes[k];
            if node.is_leaf() { n += node.count } else { stack.extend([node.left_first as usize, node.left_first as usize + 1]) }
        }
        n
    };
    assert_eq!((count(l), count(l + 1)), (20_000, 20_000));
    assert!(b.nodes[l].bounds().max.x < 1.01 && b.nodes[l + 1].bounds().min.x > 99.99);
}

#[test]
fn builders_of_nothing_and_of_one() {
    let none = Boxes(vec![]);
    for b in [Bvh::build(&none, SplitMethod::BinnedSah, &BuildOptions::default()), lbvh::build(&none, &BuildOptions::default()), bvh::ploc::build(&none, &BuildOptions::default()), bvh::sbvh::build(&none, &BuildOptions::default())] {
        assert!(b.nodes.is_empty() && b.indices.is_empty(), "{}", b.name);
        b.validate(&none).unwrap();
        assert_eq!(b.intersect(&none, &Ray::new(Vec3::ZERO, Vec3::X), &mut Counters::default()), None);
    }
    let one = Boxes(vec![aabb([1.0, 2.0, 3.0], [2.0, 3.0, 4.0])]);
    let b = Bvh::build(&one, SplitMethod::BinnedSah, &BuildOptions::default());
    assert_eq!((b.nodes.len(), b.indices.as_slice()), (1, &[0u32][..]));
    assert_eq!(b.nodes[0], BvhNode::leaf(aabb([1.0, 2.0, 3.0], [2.0, 3.0, 4.0]), 0, 1));
    assert_eq!(b.name, "bvh");
    assert_eq!(Bvh::build(&one, SplitMethod::Median, &BuildOptions::default()).name, "bvh-median");
    assert_eq!(Bvh::build(&one, SplitMethod::Midpoint, &BuildOptions::default()).name, "bvh-midpoint");
}

// ---------------------------------------------------------------- validate

fn leaf(min: [f32; 3], max: [f32; 3], first: u32, count: u32) -> BvhNode {
    BvhNode::leaf(aabb(min, max), first, count)
}

fn interior(min: [f32; 3], max: [f32; 3], left: u32) -> BvhNode {
    BvhNode::interior(aabb(min, max), left)
}

/// Expects `validate` to fail with a message containing `what`.
fn rejects(b: &Bvh, prims: &Boxes, what: &str) {
    match b.validate(prims) {
        Ok(()) => panic!("accepted a tree with {what}"),
        Err(e) => assert!(e.message.contains(what), "{what}: got `{}`", e.message),
    }
}

#[test]
fn validate_accepts_a_good_tree_and_rejects_each_broken_invariant() {
    // Two unit cubes at x 0 and 2 under a root 3 x 1 x 1.
    let prims = Boxes(vec![aabb([0.0; 3], [1.0; 3]), aabb([2.0, 0.0, 0.0], [3.0, 1.0, 1.0])]);
    let root = interior([0.0; 3], [3.0, 1.0, 1.0], 1);
    let l0 = leaf([0.0; 3], [1.0; 3], 0, 1);
    let l1 = leaf([2.0, 0.0, 0.0], [3.0, 1.0, 1.0], 1, 1);
    let good = Bvh::from_parts(vec![root, l0, l1], vec![0, 1], 2, "t");
    good.validate(&prims).unwrap();
    // One leaf of both is fine too, and so is a tree over no primitives.
    Bvh::from_parts(vec![leaf([0.0; 3], [3.0, 1.0, 1.0], 0, 2)], vec![1, 0], 2, "t").validate(&prims).unwrap();
    Bvh::from_parts(vec![], vec![], 0, "t").validate(&Boxes(vec![])).unwrap();

    rejects(&Bvh::from_parts(vec![root, l0, l1], vec![0, 1], 3, "t"), &prims, "built for 3 primitives, given 2");
    rejects(&Bvh::from_parts(vec![], vec![], 2, "t"), &prims, "no nodes for a non-empty scene");
    // A leaf of two starting at index 1 of two indices: 1 + 2 > 2.
    rejects(&Bvh::from_parts(vec![root, l0, leaf([2.0, 0.0, 0.0], [3.0, 1.0, 1.0], 1, 2)], vec![0, 1], 2, "t"), &prims, "points past the index array");
    // Exactly at the end (1 + 1 = 2) is fine: that is `good`. Index 2 of 2 primitives:
    rejects(&Bvh::from_parts(vec![root, l0, l1], vec![0, 2], 2, "t"), &prims, "holds primitive 2 of 2");
    rejects(&Bvh::from_parts(vec![root, l0, l1], vec![1, 0], 2, "t"), &prims, "sticks out of leaf");
    // Primitive 1 in both leaves, 0 in none.
    let both = Bvh::from_parts(vec![root, leaf([0.0; 3], [3.0, 1.0, 1.0], 1, 1), l1], vec![0, 1], 2, "t");
    rejects(&both, &prims, "primitive 0 is in no leaf");
    // Primitive 1 in two leaves and 0 in one: only spatial splits duplicate references.
    let dup = Bvh::from_parts(vec![root, leaf([0.0; 3], [3.0, 1.0, 1.0], 0, 2), l1], vec![0, 1, 1], 2, "t");
    rejects(&dup, &prims, "primitive 1 is in 2 leaves, not one");
    dup.with_spatial_splits().validate(&prims).unwrap();
    // Children out of range (left 2: its sibling would be node 3), pointing back at the root
    // (left 0 <= 0), or sticking out.
    rejects(&Bvh::from_parts(vec![interior([0.0; 3], [3.0, 1.0, 1.0], 2), l0, l1], vec![0, 1], 2, "t"), &prims, "out of order or range");
    rejects(&Bvh::from_parts(vec![interior([0.0; 3], [3.0, 1.0, 1.0], 0), l0, l1], vec![0, 1], 2, "t"), &prims, "out of order or range");
    rejects(&Bvh::from_parts(vec![interior([0.0; 3], [2.5, 1.0, 1.0], 1), l0, l1], vec![0, 1], 2, "t"), &prims, "child 2 sticks out of node 0");
    // A node reached twice: nodes 1 and 2 both have children 3 and 4.
    let twice = Bvh::from_parts(
        vec![root, interior([0.0; 3], [3.0, 1.0, 1.0], 3), interior([0.0; 3], [3.0, 1.0, 1.0], 3), l0, l1],
        vec![0, 1],
        2,
        "t",
    );
    rejects(&twice, &prims, "reached twice");
    // An unreachable node after the tree.
    rejects(&Bvh::from_parts(vec![root, l0, l1, l1], vec![0, 1], 2, "t"), &prims, "node 3 is unreachable");
    // With spatial splits a primitive may stick out of its leaf but must touch it.
    let clipped = Bvh::from_parts(vec![root, leaf([0.0; 3], [0.5, 1.0, 1.0], 0, 1), l1], vec![0, 1], 2, "t");
    rejects(&clipped, &prims, "sticks out of leaf 1");
    clipped.with_spatial_splits().validate(&prims).unwrap();
    let apart = Bvh::from_parts(vec![root, leaf([0.0; 3], [1.0; 3], 0, 1), leaf([0.0; 3], [1.0; 3], 1, 1)], vec![0, 1], 2, "t");
    rejects(&apart.with_spatial_splits(), &prims, "primitive 1 does not touch leaf 2");
}

#[test]
fn sah_cost_formula_by_hand() {
    use raylab_accel::bvh::SahCost;
    let sah = SahCost { traversal: 0.5, intersection: 2.0 };
    // Parent 2 x 1 x 1 (half area 5), children unit cubes (3) with 3 and 1 primitives:
    // 0.5 + 2·(3·3 + 3·1)/5 = 0.5 + 4.8 = 5.3.
    let parent = aabb([0.0; 3], [2.0, 1.0, 1.0]);
    let (l, r) = (aabb([0.0; 3], [1.0; 3]), aabb([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]));
    assert!((sah.split(&parent, &l, 3, &r, 1) - 5.3).abs() < 1e-5);
    // Left 1 x 1 x 1 with 2, right 2 x 1 x 1 (5) with 4 inside a 2 x 2 x 1 parent (4 + 2 + 2 = 8):
    // 0.5 + 2·(3·2 + 5·4)/8 = 0.5 + 6.5 = 7.
    assert!((sah.split(&aabb([0.0; 3], [2.0, 2.0, 1.0]), &l, 2, &parent, 4) - 7.0).abs() < 1e-5);
    // A flat parent (a unit square, half area 0): every ray that hits it hits both children,
    // 0.5 + 2·(2 + 3) = 10.5.
    let flat = aabb([0.0; 3], [1.0, 1.0, 0.0]);
    assert_eq!(sah.split(&flat, &flat, 2, &flat, 3), 10.5);
    assert_eq!(sah.leaf(5), 10.0);
}

#[test]
fn ploc_pairs_up_identical_boxes_in_one_round() {
    // 4096 identical boxes: every distance ties, so the tie-break decides. Pairing positions
    // (0, 1), (2, 3), ... each round halves the clusters: a complete binary tree of depth 12,
    // which the SAH collapse cuts into leaves of 8 (a subtree of k identical boxes of area A
    // costs k·A as a leaf against A + k·A split; 16 exceed the leaf size): 512 leaves, 511
    // interior nodes, depth 10 with the root at 1. (Ties by position alone paired only the
    // lowest two each round: 4095 rounds, a chain cut at depth 64 into a leaf of 4033.)
    let s = Boxes(vec![aabb([0.0; 3], [1.0; 3]); 4096]);
    let b = bvh::ploc::build(&s, &BuildOptions::default());
    b.validate(&s).unwrap();
    let st = b.stats();
    assert_eq!((st.max_depth, st.interior_nodes, st.leaves, st.references), (10, 511, 512, 4096));
    assert_eq!(st.leaf_histogram[8], 512);
}

#[test]
fn ploc_chain_of_nested_boxes_is_cut_at_depth_64() {
    // 100 nested cubes [0, 1 + k]³: the union of two is the larger, so a cluster's nearest is
    // the next larger cube (ties between lower ones go to the nearest on the curve), and only
    // the lowest pair is mutual: each round the cluster of cubes 0 .. k takes cube k + 1, a
    // chain. The SAH collapse keeps it (a leaf of k + 1 cubes costs (k + 1)·A_k against a split
    // of 2·A_k plus the smaller cluster's cost: only cubes 0 and 1 collapse), so the cut at
    // depth 64 makes it: interior nodes at depths 1 .. 63 (root 1), each with a cube as right
    // child, and at depth 64 the cluster of the 37 smallest as one leaf.
    let s = Boxes((0..100).map(|k| aabb([0.0; 3], [1.0 + k as f32; 3])).collect());
    let b = bvh::ploc::build(&s, &BuildOptions::default());
    b.validate(&s).unwrap();
    let st = b.stats();
    assert_eq!((st.max_depth, st.interior_nodes, st.leaves, st.references), (64, 63, 64, 100));
    assert_eq!(st.leaf_histogram[1], 63);
    assert_eq!(st.leaf_histogram[16], 1, "the leaf of 37");
    // The root's right child is the largest cube.
    let l = b.nodes[0].left_first as usize;
    assert_eq!(b.indices[b.nodes[l + 1].left_first as usize], 99);
}

#[test]
fn lbvh_radix_tree_of_runs_and_of_spread_codes() {
    // Equal codes are ordered by position, and the tree over a run is the radix tree of the
    // positions' bits (Karras §4). A cube at x = 0 (code 0, position 0) and six identical
    // cubes at x = 10 (the top code, positions 1 .. 6 = 001 .. 110): the codes split 0 from the
    // run; positions 1 .. 3 and 4 .. 6 differ in bit 2; then {1}|{2, 3} (bit 1) and
    // {4, 5}|{6} (bit 1). Prims 0 .. 5 are the run in index order, prim 6 the lone cube.
    let mut cubes = vec![cube_at(10.0, 0.5); 6];
    cubes.push(cube_at(0.0, 0.5));
    let s = Boxes(cubes);
    let b = lbvh::build(&s, &opts(1.0, 1.0, 1, 16));
    b.validate(&s).unwrap();
    assert_eq!(shape(&b), "(6 ((0 (1 2)) ((3 4) 5)))");
    // Eight cubes at x = 128·k (k = 0 .. 7, listed in reverse): 1024 cells over [0, 896]
    // put them in cells 146.3·k rounded down, 0, 146, 292, 438, 585, 731, 877, 1023 (1024
    // clamped): x bit 9 (512) splits k < 4 from k >= 4, bit 8 (256) each half again, a
    // balanced tree.
    let s = Boxes((0..8).rev().map(|k| cube_at(128.0 * k as f32, 0.1)).collect());
    let b = lbvh::build(&s, &opts(1.0, 1.0, 1, 16));
    b.validate(&s).unwrap();
    // prim p is k = 7 − p.
    assert_eq!(shape(&b), "(((7 6) (5 4)) ((3 2) (1 0)))");
}
