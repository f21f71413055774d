//! Linear BVH (Lauterbach et al. 2009): primitives sorted along a Morton curve, the
//! hierarchy read off the sorted codes by Karras 2012, "Maximizing Parallelism in the
//! Construction of BVHs, Octrees, and k-d Trees", which finds each interior node's range
//! and split independently of the others, so all of them are built in parallel.
//!
//! Also the pieces the other bottom-up builders share: a binary [`Tree`] over
//! any bounding [`Volume`], and [`emit`], which collapses small subtrees into leaves by the
//! SAH and flattens the tree depth-first with siblings adjacent.

use rayon::prelude::*;
use raylab_core::{Aabb, BoundingSphere, Vec3};

use super::morton::morton_order;
use super::{Bvh, BvhNode, SahCost, MAX_DEPTH};
use crate::par::DisjointSlice;
use crate::{leaf_margin, BuildOptions, Primitives};

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
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FlatNode<V> {
    pub volume: V,
    pub left_first: u32,
    pub count: u32,
}

/// Tree nodes closer to the root than this are handled by tasks forked with `rayon::join`
/// (up to 2^12 of them), deeper subtrees by one task each, iteratively: trees from PLOC can
/// be chains thousands of nodes deep.
const FORK_DEPTH: u32 = 12;

/// [`emit`]'s second pass forks only for subtrees of at least this many primitives.
const FORK_PRIMITIVES: u32 = 1024;

/// What [`emit`]'s bottom-up pass finds for a tree node: its primitives, its SAH cost (as
/// a leaf if collapsed, else split) and its descendants in the flat tree, `descendants`,
/// 0 when the node becomes a leaf (collapsed), else 2 plus those of its two children.
#[derive(Clone, Copy, Default)]
struct Summary {
    count: u32,
    cost: f32,
    descendants: u32,
}

/// Flattens `tree` depth-first with siblings adjacent (root at 0). Interior volumes are the
/// unions of their children. A subtree becomes one leaf when it holds at most `max_leaf`
/// primitives and the SAH says a leaf is no dearer than the subtree (the post-pass of
/// Karras & Aila 2013 §3, here without the treelet step), or when it lies deeper than
/// [`MAX_DEPTH`], which bounds the traversal stack even for chain-like trees.
///
/// Layout: the children of an interior flat node whose descendants start at slot `p` lie at
/// `p` and `p + 1`, the left child's descendants follow from `p + 2`, then the right's; the
/// left subtree's primitives come before the right's in `indices`. So every subtree's
/// descendants and primitives are contiguous ranges whose sizes the bottom-up pass knows,
/// and both passes run in parallel (the result does not depend on the thread count).
pub(crate) fn emit<V: Volume>(mut tree: Tree<V>, sah: SahCost, max_leaf: usize) -> (Vec<FlatNode<V>>, Vec<u32>) {
    if tree.nodes.is_empty() {
        return (Vec::new(), Vec::new());
    }
    debug_assert!(is_tree(&tree), "emit: not a tree (a node with several parents, or a root with one)");
    let root = tree.root;
    let mut summaries: Vec<Summary> = (0..tree.nodes.len()).into_par_iter().map(|_| Summary::default()).collect();
    let pass = BottomUp { nodes: &tree.nodes, volumes: DisjointSlice::new(&mut tree.volumes), summaries: DisjointSlice::new(&mut summaries), sah, max_leaf };
    pass.subtree(root, 0);
    let top = summaries[root as usize];
    let first = flat_node(&tree.volumes, &summaries, root, 1, 0);
    let mut nodes: Vec<FlatNode<V>> = (0..1 + top.descendants as usize).into_par_iter().map(|_| first).collect();
    let mut indices = vec![0u32; top.count as usize];
    let pass = Flatten { nodes: &tree.nodes, volumes: &tree.volumes, summaries: &summaries };
    let job = Job { node: root, depth: 0, base: 1, descendants: &mut nodes[1..], first: 0, indices: &mut indices };
    pass.child(job);
    (nodes, indices)
}

/// Whether every node but the root is the child of at most one interior node, and the root
/// the child of none: the part of the [`Tree`] invariant that makes the subtrees of two
/// siblings disjoint, which [`emit`]'s bottom-up pass relies on for safety.
fn is_tree<V>(tree: &Tree<V>) -> bool {
    let mut parents = vec![0u8; tree.nodes.len()];
    for n in &tree.nodes {
        if let TreeNode::Interior { children } = n {
            for c in children {
                parents[*c as usize] = parents[*c as usize].saturating_add(1);
            }
        }
    }
    // Nodes nobody reaches (no parent, not the root) are harmless: the passes never see them.
    parents.iter().enumerate().all(|(i, &p)| if i == tree.root as usize { p == 0 } else { p <= 1 })
}

/// The flat node of tree node `i`: a leaf of the primitives from `first` if collapsed, else
/// interior with children at `base`.
fn flat_node<V: Volume>(volumes: &[V], summaries: &[Summary], i: u32, base: usize, first: usize) -> FlatNode<V> {
    let s = summaries[i as usize];
    let volume = volumes[i as usize];
    if s.descendants == 0 { FlatNode { volume, left_first: first as u32, count: s.count } } else { FlatNode { volume, left_first: base as u32, count: 0 } }
}

/// [`emit`]'s bottom-up pass: interior volumes and every node's [`Summary`], written by
/// node id. A task owns the tree nodes of its subtree: the [`Tree`] invariant (each node but
/// the root is the child of one interior node) makes two siblings' subtrees disjoint.
struct BottomUp<'a, V> {
    nodes: &'a [TreeNode],
    volumes: DisjointSlice<'a, V>,
    summaries: DisjointSlice<'a, Summary>,
    sah: SahCost,
    max_leaf: usize,
}

impl<V: Volume> BottomUp<'_, V> {
    /// Summarises the subtree of `i`, at `depth`: forked in two near the root, iteratively
    /// (children before parents) below [`FORK_DEPTH`].
    fn subtree(&self, i: u32, depth: u32) {
        match self.nodes[i as usize] {
            TreeNode::Interior { children: [l, r] } if depth < FORK_DEPTH => {
                rayon::join(|| self.subtree(l, depth + 1), || self.subtree(r, depth + 1));
                // SAFETY: this task owns node `i`; the children's subtrees, disjoint from each
                // other and owned by the two tasks just joined, are done.
                unsafe { self.interior(i, depth, l, r) }
            }
            _ => self.serial(i, depth),
        }
    }

    fn serial(&self, i: u32, depth: u32) {
        let mut stack = vec![(i, depth, false)];
        while let Some((i, depth, expanded)) = stack.pop() {
            match self.nodes[i as usize] {
                // SAFETY (both): this task owns the subtree of `i` and visits each of its nodes
                // once, a parent after its children (pushed above it on the stack).
                TreeNode::Leaf { .. } => unsafe { self.leaf(i) },
                TreeNode::Interior { children: [l, r] } if expanded => unsafe { self.interior(i, depth, l, r) },
                TreeNode::Interior { children: [l, r] } => stack.extend([(i, depth, true), (r, depth + 1, false), (l, depth + 1, false)]),
            }
        }
    }

    /// # Safety
    /// The calling task owns node `i`.
    unsafe fn leaf(&self, i: u32) {
        let i = i as usize;
        // SAFETY: the caller owns `i`.
        unsafe {
            let cost = self.sah.leaf(1) * self.volumes.get(i).area();
            self.summaries.write(i, Summary { count: 1, cost, descendants: 0 });
        }
    }

    /// # Safety
    /// The calling task owns node `i`, whose children `l` and `r` are summarised.
    unsafe fn interior(&self, i: u32, depth: u32, l: u32, r: u32) {
        let (i, l, r) = (i as usize, l as usize, r as usize);
        // SAFETY: the caller owns `i`, and the children's entries are written and no longer
        // touched by any task.
        unsafe {
            let v = self.volumes.get(l).union(self.volumes.get(r));
            self.volumes.write(i, v);
            let (a, b) = (self.summaries.get(l), self.summaries.get(r));
            let count = a.count + b.count;
            let split = self.sah.traversal * v.area() + a.cost + b.cost;
            let leaf = self.sah.leaf(count as usize) * v.area();
            let collapse = (count as usize <= self.max_leaf && leaf <= split) || depth as usize + 1 >= MAX_DEPTH;
            let s = if collapse { Summary { count, cost: leaf, descendants: 0 } } else { Summary { count, cost: split, descendants: 2 + a.descendants + b.descendants } };
            self.summaries.write(i, s);
        }
    }
}

/// A subtree to flatten: interior `node` at `depth`, not collapsed, already stored by its
/// parent; its descendants go in `descendants`, which starts at slot `base`, and its
/// primitives in `indices`, which starts at index `first`.
struct Job<'a, V> {
    node: u32,
    depth: u32,
    base: usize,
    descendants: &'a mut [FlatNode<V>],
    first: usize,
    indices: &'a mut [u32],
}

/// [`emit`]'s second pass: each task fills the ranges of its subtree.
struct Flatten<'a, V> {
    nodes: &'a [TreeNode],
    volumes: &'a [V],
    summaries: &'a [Summary],
}

impl<V: Volume> Flatten<'_, V> {
    /// Forks in two while the subtree is near the root and large, else runs `serial`.
    fn run(&self, job: Job<'_, V>) {
        let s = self.summaries[job.node as usize];
        if job.depth < FORK_DEPTH && s.count >= FORK_PRIMITIVES {
            let [l, r] = self.children(job);
            rayon::join(|| self.child(l), || self.child(r));
        } else {
            self.serial(job);
        }
    }

    /// Flattens the subtree of `job`, whose node may be collapsed.
    fn child(&self, job: Job<'_, V>) {
        if self.summaries[job.node as usize].descendants == 0 {
            self.gather(job.node, job.indices);
        } else {
            self.run(job);
        }
    }

    fn serial(&self, job: Job<'_, V>) {
        let mut stack = vec![job];
        while let Some(job) = stack.pop() {
            let [l, r] = self.children(job);
            for c in [r, l] {
                if self.summaries[c.node as usize].descendants == 0 {
                    self.gather(c.node, c.indices);
                } else {
                    stack.push(c);
                }
            }
        }
    }

    /// Stores the two children of `job` at the start of its descendants and splits its
    /// ranges between them: left child's descendants, then the right's; likewise primitives.
    fn children<'j>(&self, job: Job<'j, V>) -> [Job<'j, V>; 2] {
        let TreeNode::Interior { children: [l, r] } = self.nodes[job.node as usize] else { unreachable!("a tree leaf is always collapsed") };
        let (sl, sr) = (self.summaries[l as usize], self.summaries[r as usize]);
        let (pair, rest) = job.descendants.split_at_mut(2);
        let (dl, dr) = rest.split_at_mut(sl.descendants as usize);
        let (il, ir) = job.indices.split_at_mut(sl.count as usize);
        let (bl, br) = (job.base + 2, job.base + 2 + sl.descendants as usize);
        let (fl, fr) = (job.first, job.first + sl.count as usize);
        pair[0] = flat_node(self.volumes, self.summaries, l, bl, fl);
        pair[1] = flat_node(self.volumes, self.summaries, r, br, fr);
        let depth = job.depth + 1;
        debug_assert_eq!(dr.len(), sr.descendants as usize);
        [Job { node: l, depth, base: bl, descendants: dl, first: fl, indices: il }, Job { node: r, depth, base: br, descendants: dr, first: fr, indices: ir }]
    }

    /// Writes the primitives of the collapsed subtree of `i` into `out`, left to right.
    fn gather(&self, i: u32, out: &mut [u32]) {
        let mut k = 0;
        let mut stack = vec![i];
        while let Some(j) = stack.pop() {
            match self.nodes[j as usize] {
                TreeNode::Leaf { prim } => {
                    out[k] = prim;
                    k += 1;
                }
                TreeNode::Interior { children: [l, r] } => stack.extend([r, l]),
            }
        }
        debug_assert_eq!(k, out.len());
    }
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
        .into_par_iter()
        .map(|f| if f.count > 0 { BvhNode::leaf(f.volume, f.left_first, f.count) } else { BvhNode::interior(f.volume, f.left_first) })
        .collect();
    Bvh::from_parts(nodes, indices, primitives, name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Unit boxes at x = 0, 2, 4, ... as leaves `0..n` (primitive `p` in leaf `p`), and the
    /// interior nodes `n..` given by their children.
    fn hand_tree(n: usize, interiors: &[[u32; 2]], root: u32) -> Tree<Aabb> {
        let mut nodes: Vec<TreeNode> = (0..n as u32).map(|prim| TreeNode::Leaf { prim }).collect();
        nodes.extend(interiors.iter().map(|&children| TreeNode::Interior { children }));
        let mut volumes: Vec<Aabb> = (0..n).map(|p| Aabb::new(Vec3::new(2.0 * p as f32, 0.0, 0.0), Vec3::new(2.0 * p as f32 + 1.0, 1.0, 1.0))).collect();
        volumes.resize(nodes.len(), Aabb::EMPTY);
        Tree { nodes, volumes, root }
    }

    fn boxes(a: u32, b: u32) -> Aabb {
        Aabb::new(Vec3::new(2.0 * a as f32, 0.0, 0.0), Vec3::new(2.0 * b as f32 + 1.0, 1.0, 1.0))
    }

    /// Root = (A, B), A = (p0, C), C = (p1, p2), B = (p3, p4), listed as nodes 5.. in the
    /// order C, A, B, root. With `max_leaf` 1 nothing collapses: the root's children at 1
    /// and 2, then A's descendants (its children at 3, 4, then C's at 5, 6), then B's at 7, 8;
    /// the left subtree's primitives before the right's.
    #[test]
    fn emit_layout_by_hand() {
        let tree = hand_tree(5, &[[1, 2], [0, 5], [3, 4], [6, 7]], 8);
        let sah = SahCost { traversal: 1.0, intersection: 1.0 };
        let (nodes, indices) = emit(tree, sah, 1);
        let shape: Vec<(u32, u32)> = nodes.iter().map(|f| (f.left_first, f.count)).collect();
        assert_eq!(shape, [(1, 0), (3, 0), (7, 0), (0, 1), (5, 0), (1, 1), (2, 1), (3, 1), (4, 1)]);
        assert_eq!(indices, [0, 1, 2, 3, 4]);
        let volumes: Vec<Aabb> = nodes.iter().map(|f| f.volume).collect();
        assert_eq!(volumes, [boxes(0, 4), boxes(0, 2), boxes(3, 4), boxes(0, 0), boxes(1, 2), boxes(1, 1), boxes(2, 2), boxes(3, 3), boxes(4, 4)]);
        // Traversal dearer than any leaf of two: C and B collapse (2 primitives), A (3) and
        // the root cannot. A's children at 3, 4 (B, a leaf, has no descendants).
        let tree = hand_tree(5, &[[1, 2], [0, 5], [3, 4], [6, 7]], 8);
        let (nodes, indices) = emit(tree, SahCost { traversal: 100.0, intersection: 1.0 }, 2);
        let shape: Vec<(u32, u32)> = nodes.iter().map(|f| (f.left_first, f.count)).collect();
        assert_eq!(shape, [(1, 0), (3, 0), (3, 2), (0, 1), (1, 2)]);
        assert_eq!(indices, [0, 1, 2, 3, 4]);
        // A lone leaf is the root.
        let (nodes, indices) = emit(hand_tree(1, &[], 0), sah, 1);
        assert_eq!(nodes, [FlatNode { volume: boxes(0, 0), left_first: 0, count: 1 }]);
        assert_eq!(indices, [0]);
    }

    /// A chain of 200 leaves (each interior node is (leaf, next interior)) is cut at
    /// `MAX_DEPTH - 1` into one leaf, whatever the SAH; built the same on 1 and 3 threads.
    #[test]
    fn emit_collapses_deep_chains_alike_on_any_thread_count() {
        let n = 200u32;
        // Interior n + k = (leaf k, interior n + k + 1); the last one (n + n - 2) ends in leaf n - 1.
        let interiors: Vec<[u32; 2]> = (0..n - 1).map(|k| [k, if k + 2 == n { n - 1 } else { n + k + 1 }]).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| emit(hand_tree(n as usize, &interiors, n), SahCost { traversal: 1.0, intersection: 1.0 }, 1))
        };
        let (nodes, indices) = run(1);
        assert_eq!(indices, (0..n).collect::<Vec<_>>());
        // Depth d holds leaf d - 1 and the chain's next node: the node at depth 63 collapses.
        assert_eq!(nodes.len(), 1 + 2 * (MAX_DEPTH - 1));
        let last = nodes.last().unwrap();
        assert_eq!((last.left_first, last.count), (MAX_DEPTH as u32 - 1, n - (MAX_DEPTH as u32 - 1)));
        assert_eq!(run(3), (nodes, indices));
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
