//! Linear BVH (Lauterbach et al. 2009): primitives sorted along a Morton curve, the
//! hierarchy read off the sorted codes by Karras 2012, "Maximizing Parallelism in the
//! Construction of BVHs, Octrees, and k-d Trees", which finds each interior node's range
//! and split independently of the others, so all of them are built in parallel.
//!
//! Also the pieces the other bottom-up builders share: Morton order, a binary [`Tree`] over
//! any bounding [`Volume`], and [`emit`], which collapses small subtrees into leaves by the
//! SAH and flattens the tree depth-first with siblings adjacent.

use rayon::prelude::*;
use raylab_core::{Aabb, BoundingSphere, Vec3};

use super::{Bvh, BvhNode, SahCost, MAX_DEPTH};
use crate::{leaf_margin, BuildOptions, Primitives};

/// Bits per axis of a Morton code: 3 × 10 = 30 bits fit a `u32`.
pub const MORTON_BITS: u32 = 10;

/// Spreads the low 10 bits of `v` to every third bit (bit k goes to bit 3k).
#[inline]
fn expand_bits(v: u32) -> u32 {
    let mut v = v & 0x3ff;
    v = (v | (v << 16)) & 0x0300_00ff;
    v = (v | (v << 8)) & 0x0300_f00f;
    v = (v | (v << 4)) & 0x030c_30c3;
    v = (v | (v << 2)) & 0x0924_9249;
    v
}

/// 30-bit Morton code of quantised coordinates (each below 1024): the bits of `x`, `y`, `z`
/// interleaved, `x` most significant in each triple (Karras 2012's convention).
#[inline]
pub fn morton3(x: u32, y: u32, z: u32) -> u32 {
    (expand_bits(x) << 2) | (expand_bits(y) << 1) | expand_bits(z)
}

/// Morton code of `p` quantised in `bounds`: `bounds.min` maps to 0, `bounds.max` to the
/// largest code; a flat axis maps to 0.
#[inline]
pub fn morton_code(p: Vec3, bounds: &Aabb) -> u32 {
    let cells = (1u32 << MORTON_BITS) as f32;
    let q = (bounds.offset(p) * cells).clamp(Vec3::ZERO, Vec3::splat(cells - 1.0));
    morton3(q.x as u32, q.y as u32, q.z as u32)
}

/// Indices of `points` sorted by their Morton codes in the points' bounds (ties by index,
/// so the order is deterministic), with the sorted codes. Parallel codes and sort.
pub(crate) fn morton_order(points: &[Vec3]) -> (Vec<u32>, Vec<u32>) {
    let bounds = points.par_iter().fold(|| Aabb::EMPTY, |b, &p| b.grow(p)).reduce(|| Aabb::EMPTY, Aabb::union);
    let mut keys: Vec<u64> =
        points.par_iter().enumerate().map(|(i, &p)| (morton_code(p, &bounds) as u64) << 32 | i as u64).collect();
    keys.par_sort_unstable();
    keys.into_par_iter().map(|k| (k as u32, (k >> 32) as u32)).unzip()
}

/// A bounding volume a bottom-up builder can merge and price.
pub(crate) trait Volume: Copy + Send + Sync {
    fn union(self, o: Self) -> Self;
    /// Proportional to surface area: the SAH's hit probability, up to a constant factor.
    fn area(&self) -> f32;
}

impl Volume for Aabb {
    fn union(self, o: Self) -> Self {
        Aabb::union(self, o)
    }
    fn area(&self) -> f32 {
        self.half_area()
    }
}

impl Volume for BoundingSphere {
    fn union(self, o: Self) -> Self {
        BoundingSphere::union(self, o)
    }
    fn area(&self) -> f32 {
        self.radius * self.radius
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum TreeNode {
    Leaf { prim: u32 },
    Interior { children: [u32; 2] },
}

/// A binary tree built bottom-up or by Karras. Invariants: every primitive is in exactly one
/// leaf, `volumes[i]` bounds leaf `i`'s primitive (interior volumes are filled by [`emit`]),
/// and every node but `root` is the child of exactly one interior node.
pub(crate) struct Tree<V> {
    pub nodes: Vec<TreeNode>,
    pub volumes: Vec<V>,
    pub root: u32,
}

/// A node of a flattened tree: interior when `count == 0` (children at `left_first` and
/// `left_first + 1`), else a leaf of `indices[left_first .. left_first + count]`.
pub(crate) struct FlatNode<V> {
    pub volume: V,
    pub left_first: u32,
    pub count: u32,
}

/// Flattens `tree` depth-first with siblings adjacent (root at 0). Interior volumes are the
/// unions of their children. A subtree becomes one leaf when it holds at most `max_leaf`
/// primitives and the SAH says a leaf is no dearer than the subtree (the post-pass of
/// Karras & Aila 2013 §3, here without the treelet step), or when it lies deeper than
/// [`MAX_DEPTH`], which bounds the traversal stack even for chain-like trees.
pub(crate) fn emit<V: Volume>(mut tree: Tree<V>, sah: SahCost, max_leaf: usize) -> (Vec<FlatNode<V>>, Vec<u32>) {
    if tree.nodes.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let m = tree.nodes.len();
    // Pre-order with depths; reversed, it visits children before parents.
    let mut preorder = Vec::with_capacity(m);
    let mut depth = vec![0u32; m];
    let mut stack = vec![tree.root];
    while let Some(i) = stack.pop() {
        preorder.push(i);
        if let TreeNode::Interior { children } = tree.nodes[i as usize] {
            for c in children {
                depth[c as usize] = depth[i as usize] + 1;
                stack.push(c);
            }
        }
    }
    let mut count = vec![0u32; m];
    let mut cost = vec![0f32; m];
    let mut collapse = vec![false; m];
    for &i in preorder.iter().rev() {
        let i = i as usize;
        match tree.nodes[i] {
            TreeNode::Leaf { .. } => {
                count[i] = 1;
                cost[i] = sah.leaf(1) * tree.volumes[i].area();
                collapse[i] = true;
            }
            TreeNode::Interior { children: [l, r] } => {
                let (l, r) = (l as usize, r as usize);
                let v = tree.volumes[l].union(tree.volumes[r]);
                tree.volumes[i] = v;
                count[i] = count[l] + count[r];
                let split = sah.traversal * v.area() + cost[l] + cost[r];
                let leaf = sah.leaf(count[i] as usize) * v.area();
                collapse[i] = (count[i] as usize <= max_leaf && leaf <= split) || depth[i] as usize + 1 >= MAX_DEPTH;
                cost[i] = if collapse[i] { leaf } else { split };
            }
        }
    }
    let mut nodes = Vec::with_capacity(2 * m);
    let mut indices = Vec::with_capacity(count[tree.root as usize] as usize);
    nodes.push(FlatNode { volume: tree.volumes[tree.root as usize], left_first: 0, count: 0 });
    let mut stack = vec![(tree.root, 0usize)];
    while let Some((i, slot)) = stack.pop() {
        if collapse[i as usize] {
            nodes[slot].left_first = indices.len() as u32;
            nodes[slot].count = count[i as usize];
            let mut sub = vec![i];
            while let Some(k) = sub.pop() {
                match tree.nodes[k as usize] {
                    TreeNode::Leaf { prim } => indices.push(prim),
                    TreeNode::Interior { children: [l, r] } => sub.extend([r, l]),
                }
            }
        } else if let TreeNode::Interior { children } = tree.nodes[i as usize] {
            let left = nodes.len();
            nodes[slot].left_first = left as u32;
            for (k, &c) in children.iter().enumerate() {
                nodes.push(FlatNode { volume: tree.volumes[c as usize], left_first: 0, count: 0 });
                stack.push((c, left + k));
            }
        }
    }
    (nodes, indices)
}

/// Karras 2012 §3: interior node `i` of `n - 1` covers a range of sorted codes starting or
/// ending at `i`; the direction comes from which neighbour shares the longer prefix, the
/// other end and the split (where the common prefix grows) from two binary searches.
/// Returns each interior node's children as tree indices: leaf `k` is `k`, interior `j` is
/// `n + j`; the root is interior 0. Equal codes are told apart by their indices (§4).
fn karras(codes: &[u32]) -> Vec<[u32; 2]> {
    let n = codes.len() as i64;
    let delta = |i: i64, j: i64| -> i32 {
        if j < 0 || j >= n {
            return -1;
        }
        let (a, b) = (codes[i as usize], codes[j as usize]);
        if a == b { 32 + (i as u32 ^ j as u32).leading_zeros() as i32 } else { (a ^ b).leading_zeros() as i32 }
    };
    (0..n - 1)
        .into_par_iter()
        .map(|i| {
            let d = if delta(i, i + 1) > delta(i, i - 1) { 1 } else { -1 };
            let delta_min = delta(i, i - d);
            let mut l_max = 2;
            while delta(i, i + l_max * d) > delta_min {
                l_max *= 2;
            }
            let mut l = 0;
            let mut t = l_max / 2;
            while t >= 1 {
                if delta(i, i + (l + t) * d) > delta_min {
                    l += t;
                }
                t /= 2;
            }
            let j = i + l * d;
            let delta_node = delta(i, j);
            let (mut s, mut t) = (0, l);
            loop {
                t = (t + 1) / 2;
                if delta(i, i + (s + t) * d) > delta_node {
                    s += t;
                }
                if t == 1 {
                    break;
                }
            }
            let gamma = i + s * d + d.min(0);
            let left = if i.min(j) == gamma { gamma } else { n + gamma };
            let right = if i.max(j) == gamma + 1 { gamma + 1 } else { n + gamma + 1 };
            [left as u32, right as u32]
        })
        .collect()
}

/// Builds an LBVH: Morton order, Karras hierarchy, SAH collapse of small subtrees.
pub fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> Bvh {
    let n = prims.len();
    let bounds = grown_bounds(prims);
    let centroids: Vec<Vec3> = bounds.par_iter().map(Aabb::centroid).collect();
    let (order, codes) = morton_order(&centroids);
    let mut nodes: Vec<TreeNode> = order.iter().map(|&prim| TreeNode::Leaf { prim }).collect();
    nodes.extend(karras(&codes).into_iter().map(|children| TreeNode::Interior { children }));
    let mut volumes: Vec<Aabb> = order.iter().map(|&p| bounds[p as usize]).collect();
    volumes.resize(nodes.len(), Aabb::EMPTY);
    let root = if n > 1 { n as u32 } else { 0 };
    let tree = Tree { nodes, volumes, root };
    from_tree(tree, n, "lbvh", opts)
}

/// The primitives' boxes grown by [`leaf_margin`]. The shared BVH traversal prunes a box
/// whose entry distance exceeds the closest hit so far; for a primitive lying in its box's
/// face (coplanar triangles, axis-aligned quads) the two distances are equal in exact
/// arithmetic, and rounding could prune the box holding the truly closest hit. Grown
/// boxes are entered a margin earlier, so such ties always resolve towards visiting.
pub(crate) fn grown_bounds<P: Primitives + ?Sized>(prims: &P) -> Vec<Aabb> {
    let bounds: Vec<Aabb> = (0..prims.len() as u32).into_par_iter().map(|i| prims.bounds(i)).collect();
    let m = leaf_margin(&bounds.par_iter().copied().reduce(|| Aabb::EMPTY, Aabb::union));
    bounds.into_par_iter().map(|b| Aabb { min: b.min - m, max: b.max + m }).collect()
}

/// Flattens a box tree into a [`Bvh`] named `name`.
pub(crate) fn from_tree(tree: Tree<Aabb>, primitives: usize, name: &'static str, opts: &BuildOptions) -> Bvh {
    let (flat, indices) = emit(tree, SahCost::from_options(opts), opts.max_leaf_size.max(1));
    let nodes = flat
        .into_iter()
        .map(|f| if f.count > 0 { BvhNode::leaf(f.volume, f.left_first, f.count) } else { BvhNode::interior(f.volume, f.left_first) })
        .collect();
    Bvh::from_parts(nodes, indices, primitives, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_codes_of_known_points() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert_eq!(morton_code(Vec3::ZERO, &b), 0);
        assert_eq!(morton_code(Vec3::ONE, &b), (1 << 30) - 1);
        // x = 0b11 -> bits 2 and 5; z = 0b101 -> bits 0 and 6: 4 + 32 + 1 + 64.
        assert_eq!(morton3(3, 0, 5), 101);
        assert_eq!(morton3(1, 0, 0), 4);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 1);
        // The top bit of x is the code's top bit: the first split halves space along x.
        assert_eq!(morton3(512, 0, 0), 1 << 29);
        // (0.5, 0.25, 0) quantises to (512, 256, 0).
        assert_eq!(morton_code(Vec3::new(0.5, 0.25, 0.0), &b), (1 << 29) | (1 << 25));
    }

    #[test]
    fn karras_tree_of_four_codes() {
        // Codes 0b00, 0b01, 0b10, 0b11 (in the low bits): root splits between 1 and 2.
        let ch = karras(&[0, 1, 2, 3]);
        assert_eq!(ch[0], [4 + 1, 4 + 2]);
        assert_eq!(ch[1], [0, 1]);
        assert_eq!(ch[2], [2, 3]);
    }
}
