//! O(N log N) SAH construction (Wald & Havran 2006, §4): the events of all three axes are
//! sorted once; each node finds its best plane by one sweep over its sorted events, and
//! hands its children event lists that are still sorted (the events of primitives on one
//! side are filtered in order; only those of straddling primitives are regenerated from
//! the clipped bounds, sorted and merged).

use raylab_core::Aabb;

use super::{split_voxel, KdNode, KdTree};
use crate::bvh::SahCost;
use crate::{robust_margin, BuildOptions, Primitives};

/// The traversal stack holds at most one entry per level.
pub(super) const MAX_DEPTH: usize = 62;

const END: u8 = 0;
const PLANAR: u8 = 1;
const START: u8 = 2;

/// A primitive's box starting, ending or lying flat at `pos` on one axis. `prim` is the
/// primitive's index in its node's list, not the global id.
#[derive(Clone, Copy, Debug)]
struct Event {
    pos: f32,
    prim: u32,
    /// `axis << 2 | type`: events at one position group by axis, then end < planar < start,
    /// the order the sweep needs.
    kind: u8,
}

impl Event {
    fn axis(&self) -> usize {
        (self.kind >> 2) as usize
    }

    fn ty(&self) -> u8 {
        self.kind & 3
    }

    fn order(a: &Event, b: &Event) -> std::cmp::Ordering {
        a.pos.total_cmp(&b.pos).then(a.kind.cmp(&b.kind))
    }
}

/// Appends the events of box `b` of local primitive `prim`. `+ 0.0` turns `-0` into `+0`,
/// so that sorting (total order) and classification (`<=`) agree on equal positions.
fn push_events(out: &mut Vec<Event>, prim: u32, b: &Aabb) {
    for axis in 0..3 {
        let (lo, hi) = (b.min[axis] + 0.0, b.max[axis] + 0.0);
        let k = (axis as u8) << 2;
        if lo == hi {
            out.push(Event { pos: lo, prim, kind: k | PLANAR });
        } else {
            out.push(Event { pos: lo, prim, kind: k | START });
            out.push(Event { pos: hi, prim, kind: k | END });
        }
    }
}

fn merge(a: Vec<Event>, b: Vec<Event>) -> Vec<Event> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if Event::order(&b[j], &a[i]).is_lt() {
            out.push(b[j]);
            j += 1;
        } else {
            out.push(a[i]);
            i += 1;
        }
    }
    out.extend_from_slice(&a[i..]);
    out.extend_from_slice(&b[j..]);
    out
}

/// A candidate plane: where, its cost, and on which side primitives lying in it go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Split {
    pub axis: usize,
    pub pos: f32,
    pub cost: f32,
    pub planar_below: bool,
}

/// SAH cost of cutting `voxel` at `pos` with `[below, planar, above]` primitives: wholly
/// below, lying in the plane and wholly above (Wald & Havran 2006, §3): planar primitives
/// go to the cheaper side. The intersection part is reduced by `empty_bonus` when a side
/// is empty, which favours cutting off empty space (MacDonald & Booth 1990; pbrt).
pub(super) fn split_cost(sah: &SahCost, empty_bonus: f32, voxel: &Aabb, axis: usize, pos: f32, counts: [usize; 3]) -> (f32, bool) {
    let [n_below, n_planar, n_above] = counts;
    let (below, above) = split_voxel(voxel, axis, pos);
    let area = voxel.half_area();
    let (pb, pa) = (below.half_area() / area, above.half_area() / area);
    let cost = |nb: usize, na: usize| {
        let bonus = if nb == 0 || na == 0 { empty_bonus } else { 0.0 };
        sah.traversal + sah.intersection * (1.0 - bonus) * (pb * nb as f32 + pa * na as f32)
    };
    let (cb, ca) = (cost(n_below + n_planar, n_above), cost(n_below, n_above + n_planar));
    if cb <= ca { (cb, true) } else { (ca, false) }
}

/// A child's sorted events and primitives (global ids).
type Child = (Vec<Event>, Vec<u32>);

struct Builder<'a, P: ?Sized> {
    prims: &'a P,
    sah: SahCost,
    empty_bonus: f32,
    max_depth: usize,
    nodes: Vec<KdNode>,
    indices: Vec<u32>,
}

pub(super) fn build<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions) -> KdTree {
    let n = prims.len();
    let mut events = Vec::with_capacity(6 * n);
    let mut scene = Aabb::EMPTY;
    for i in 0..n as u32 {
        let b = prims.bounds(i);
        scene = scene.union(b);
        push_events(&mut events, i, &b);
    }
    events.sort_unstable_by(Event::order);
    let margin = robust_margin(&scene);
    let bounds = Aabb { min: scene.min - margin, max: scene.max + margin };
    let mut b = Builder {
        prims,
        sah: SahCost::from_options(opts),
        empty_bonus: opts.empty_bonus.clamp(0.0, 1.0),
        // pbrt's depth limit, 8 + 1.3 log2 N, within the traversal stack.
        max_depth: ((8.0 + 1.3 * (n.max(1) as f32).log2()).round() as usize).min(MAX_DEPTH),
        nodes: Vec::new(),
        indices: Vec::new(),
    };
    if n > 0 {
        b.node(bounds, events, (0..n as u32).collect(), 1);
    }
    KdTree { nodes: b.nodes, indices: b.indices, bounds, margin, primitives: n, build_ms: 0.0 }
}

impl<P: Primitives + ?Sized> Builder<'_, P> {
    /// Builds the subtree of `voxel` over `prims` (global ids; `events` refer to positions in
    /// `prims`), appending it depth first.
    fn node(&mut self, voxel: Aabb, events: Vec<Event>, prims: Vec<u32>, depth: usize) {
        let n = prims.len();
        // Wald & Havran's termination: split only while the best plane is cheaper than a leaf.
        let split = (depth < self.max_depth && n > 0 && voxel.half_area() > 0.0)
            .then(|| self.find_split(&voxel, &events, n))
            .flatten()
            .filter(|s| s.cost < self.sah.leaf(n));
        let Some(s) = split else {
            self.nodes.push(KdNode::leaf(self.indices.len() as u32, n as u32));
            self.indices.extend(prims);
            return;
        };
        let at = self.nodes.len();
        self.nodes.push(KdNode::leaf(0, 0));
        let (vb, va) = split_voxel(&voxel, s.axis, s.pos);
        let ((eb, pb), (ea, pa)) = self.partition(events, &prims, &s, &vb, &va);
        drop(prims);
        self.node(vb, eb, pb, depth + 1);
        self.nodes[at] = KdNode::interior(s.axis, s.pos, self.nodes.len() as u32);
        self.node(va, ea, pa, depth + 1);
    }

    /// One sweep over the sorted events (Wald & Havran 2006, Alg. 4), keeping per axis the
    /// counts of primitives wholly below, in and above the current plane. Planes on the
    /// voxel's boundary are skipped: they would make an empty child of zero volume.
    fn find_split(&self, voxel: &Aabb, events: &[Event], n: usize) -> Option<Split> {
        let (mut nb, mut np, mut na) = ([0usize; 3], [0usize; 3], [n; 3]);
        let mut best: Option<Split> = None;
        let mut i = 0;
        while i < events.len() {
            let (pos, axis) = (events[i].pos, events[i].axis());
            let mut count = [0usize; 3];
            for ty in [END, PLANAR, START] {
                while i < events.len() && events[i].pos == pos && events[i].axis() == axis && events[i].ty() == ty {
                    count[ty as usize] += 1;
                    i += 1;
                }
            }
            let (ends, planar, starts) = (count[END as usize], count[PLANAR as usize], count[START as usize]);
            np[axis] = planar;
            na[axis] -= planar + ends;
            if pos > voxel.min[axis] && pos < voxel.max[axis] {
                let (cost, planar_below) = split_cost(&self.sah, self.empty_bonus, voxel, axis, pos, [nb[axis], np[axis], na[axis]]);
                if best.is_none_or(|b| cost < b.cost) {
                    best = Some(Split { axis, pos, cost, planar_below });
                }
            }
            nb[axis] += starts + planar;
            np[axis] = 0;
        }
        best
    }

    /// Splits a node's primitives and events between its children (Wald & Havran 2006,
    /// §4.3). Primitives wholly on one side keep their events, still sorted; primitives
    /// straddling the plane are clipped to each child's voxel (perfect splits) and get new
    /// events there, or none where the clipped part is empty.
    fn partition(&self, events: Vec<Event>, prims: &[u32], s: &Split, vb: &Aabb, va: &Aabb) -> (Child, Child) {
        const BOTH: u8 = 0;
        const BELOW: u8 = 1;
        const ABOVE: u8 = 2;
        let mut side = vec![BOTH; prims.len()];
        for e in events.iter().filter(|e| e.axis() == s.axis) {
            let k = e.prim as usize;
            match e.ty() {
                END if e.pos <= s.pos => side[k] = BELOW,
                START if e.pos >= s.pos => side[k] = ABOVE,
                PLANAR => side[k] = if e.pos < s.pos || (e.pos == s.pos && s.planar_below) { BELOW } else { ABOVE },
                _ => {}
            }
        }
        let clip = |g: u32, v: &Aabb| {
            let b = self.prims.clipped_bounds(g, v).intersection(*v);
            (!b.is_empty()).then_some(b)
        };
        let mut straddling = Vec::new();
        let (mut id_below, mut id_above) = (vec![u32::MAX; prims.len()], vec![u32::MAX; prims.len()]);
        let (mut pb, mut pa) = (Vec::new(), Vec::new());
        for (k, &g) in prims.iter().enumerate() {
            let (in_below, in_above) = match side[k] {
                BELOW => (true, false),
                ABOVE => (false, true),
                _ => {
                    let (b, a) = (clip(g, vb), clip(g, va));
                    straddling.push((k, b, a));
                    (b.is_some(), a.is_some())
                }
            };
            if in_below {
                id_below[k] = pb.len() as u32;
                pb.push(g);
            }
            if in_above {
                id_above[k] = pa.len() as u32;
                pa.push(g);
            }
        }
        let (mut eb, mut ea) = (Vec::new(), Vec::new());
        for e in events {
            match side[e.prim as usize] {
                BELOW => eb.push(Event { prim: id_below[e.prim as usize], ..e }),
                ABOVE => ea.push(Event { prim: id_above[e.prim as usize], ..e }),
                _ => {}
            }
        }
        let (mut nb, mut na) = (Vec::new(), Vec::new());
        for (k, b, a) in straddling {
            if let Some(b) = b {
                push_events(&mut nb, id_below[k], &b);
            }
            if let Some(a) = a {
                push_events(&mut na, id_above[k], &a);
            }
        }
        nb.sort_unstable_by(Event::order);
        na.sort_unstable_by(Event::order);
        ((merge(eb, nb), pb), (merge(ea, na), pa))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Vec3;

    #[test]
    fn hand_computed_split_cost() {
        // Voxel 2x1x1 (half area 5) cut at x = 0.5: below 0.5x1x1 (half area 2), above
        // 1.5x1x1 (half area 4). With 2 primitives below, 3 above, 1 in the plane, KT = KI = 1:
        // planar below: 1 + (2/5)·3 + (4/5)·3 = 4.6; planar above: 1 + (2/5)·2 + (4/5)·4 = 5.0.
        let v = Aabb::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        let sah = SahCost { traversal: 1.0, intersection: 1.0 };
        let (cost, below) = split_cost(&sah, 0.2, &v, 0, 0.5, [2, 1, 3]);
        assert!((cost - 4.6).abs() < 1e-5, "{cost}");
        assert!(below);
        // Cutting off empty space: 4 primitives above, none below, bonus 0.2:
        // 1 + 0.8·(4/5)·4 = 3.56, cheaper than the leaf's 4.
        let (cost, _) = split_cost(&sah, 0.2, &v, 0, 0.5, [0, 0, 4]);
        assert!((cost - 3.56).abs() < 1e-5, "{cost}");
    }

    #[test]
    fn merge_keeps_event_order() {
        let e = |pos: f32, kind: u8| Event { pos, prim: 0, kind };
        let m = merge(vec![e(0.0, START), e(2.0, END)], vec![e(0.0, END), e(1.0, PLANAR), e(2.0, 4 | START)]);
        let got: Vec<(f32, u8)> = m.iter().map(|e| (e.pos, e.kind)).collect();
        assert_eq!(got, vec![(0.0, END), (0.0, START), (1.0, PLANAR), (2.0, END), (2.0, 4 | START)]);
    }
}
