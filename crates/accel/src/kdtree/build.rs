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
    use crate::PrimHit;
    use raylab_core::{Pcg32, Ray, Vec3};

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

    // ------------------------------------------------------------ worked by hand (issue 15)

    use crate::primitives::TestBoxes as Boxes;

    fn aabb(min: [f32; 3], max: [f32; 3]) -> Aabb {
        Aabb::new(Vec3::from_array(min), Vec3::from_array(max))
    }

    /// A box `[x0, x1] × [0, 1] × [0, 1]` (flat when `x0 == x1`).
    fn slab(x0: f32, x1: f32) -> Aabb {
        aabb([x0, 0.0, 0.0], [x1, 1.0, 1.0])
    }

    /// The sorted events of `boxes`, as `build` makes them.
    fn events_of(boxes: &[Aabb]) -> Vec<Event> {
        let mut ev = Vec::new();
        for (i, b) in boxes.iter().enumerate() {
            push_events(&mut ev, i as u32, b);
        }
        ev.sort_unstable_by(Event::order);
        ev
    }

    fn builder<'a>(prims: &'a Boxes, sah: SahCost, empty_bonus: f32, max_depth: usize) -> Builder<'a, Boxes> {
        Builder { prims, sah, empty_bonus, max_depth, nodes: Vec::new(), indices: Vec::new() }
    }

    const UNIT: SahCost = SahCost { traversal: 1.0, intersection: 1.0 };

    /// `kind` is `axis << 2 | type` with end 0, planar 1, start 2; a flat axis gives one
    /// planar event, any other a start and an end; `-0` is stored as `+0`.
    #[test]
    fn events_encode_axis_and_type() {
        let mut ev = Vec::new();
        push_events(&mut ev, 7, &Aabb { min: Vec3::new(-0.0, 2.0, 3.0), max: Vec3::new(1.0, 2.0, 5.0) });
        let got: Vec<(f32, u32, u8, usize, u8)> = ev.iter().map(|e| (e.pos, e.prim, e.kind, e.axis(), e.ty())).collect();
        assert_eq!(got, vec![(0.0, 7, 2, 0, START), (1.0, 7, 0, 0, END), (2.0, 7, 5, 1, PLANAR), (3.0, 7, 10, 2, START), (5.0, 7, 8, 2, END)]);
        assert_eq!(ev[0].pos.to_bits(), 0, "-0 kept as {}", ev[0].pos);
        // Axis 2's planar event: 8 | 1 = 9.
        let mut ev = Vec::new();
        push_events(&mut ev, 0, &aabb([0.0, 0.0, 4.0], [1.0, 1.0, 4.0]));
        assert_eq!((ev[4].kind, ev[4].axis(), ev[4].ty()), (9, 2, PLANAR));
        assert_eq!(ev.len(), 5);
        // A box ending at -0: its end at +0.
        let mut ev = Vec::new();
        push_events(&mut ev, 1, &Aabb { min: Vec3::splat(-1.0), max: Vec3::new(-0.0, 0.0, 0.0) });
        assert_eq!((ev[1].pos.to_bits(), ev[1].kind), (0, END), "-0 kept as {}", ev[1].pos);
    }

    /// Wald & Havran's counts for the plane at `pos` on `axis`, from their definition: a box
    /// with extent is below when it starts before the plane and above when it ends after it
    /// (a box across the plane is on both sides); a flat box is below, in or above the plane
    /// by its position.
    fn counts_by_definition(boxes: &[Aabb], axis: usize, pos: f32) -> [usize; 3] {
        let mut c = [0; 3];
        for b in boxes {
            let (lo, hi) = (b.min[axis], b.max[axis]);
            if lo == hi {
                c[if lo < pos { 0 } else if lo == pos { 1 } else { 2 }] += 1;
            } else {
                c[0] += usize::from(lo < pos);
                c[2] += usize::from(hi > pos);
            }
        }
        c
    }

    /// The cheapest plane by brute force: every face of every box strictly inside the voxel,
    /// counted by definition. `None` when no face lies inside.
    fn cheapest_by_brute_force(boxes: &[Aabb], voxel: &Aabb, bonus: f32) -> Option<f32> {
        let mut best: Option<f32> = None;
        for b in boxes {
            for axis in 0..3 {
                for pos in [b.min[axis], b.max[axis]] {
                    if pos > voxel.min[axis] && pos < voxel.max[axis] {
                        let (cost, _) = split_cost(&UNIT, bonus, voxel, axis, pos, counts_by_definition(boxes, axis, pos));
                        best = Some(best.map_or(cost, |c| c.min(cost)));
                    }
                }
            }
        }
        best
    }

    /// The sweep's best plane must cost what its counts by definition cost, and no face of
    /// any box may be cheaper. (Ties between equally cheap planes may go either way.)
    fn check_sweep(boxes: &[Aabb], voxel: &Aabb, bonus: f32) -> Option<Split> {
        let prims = Boxes(boxes.to_vec());
        let got = builder(&prims, UNIT, bonus, 20).find_split(voxel, &events_of(boxes), boxes.len());
        let want = cheapest_by_brute_force(boxes, voxel, bonus);
        match got {
            None => assert_eq!(want, None, "{boxes:?}"),
            Some(s) => {
                assert!(s.pos > voxel.min[s.axis] && s.pos < voxel.max[s.axis], "{s:?} outside {voxel:?}");
                assert!(boxes.iter().any(|b| b.min[s.axis] == s.pos || b.max[s.axis] == s.pos), "{s:?} is no face");
                let (cost, below) = split_cost(&UNIT, bonus, voxel, s.axis, s.pos, counts_by_definition(boxes, s.axis, s.pos));
                assert_eq!((s.cost, s.planar_below), (cost, below), "{s:?} in {boxes:?}");
                assert_eq!(Some(s.cost), want, "{s:?} in {boxes:?}");
            }
        }
        got
    }

    /// Voxel 4 × 1 × 1 (half area 4 + 1 + 4 = 9), KT = KI = 1; planes on the voxel's faces
    /// (every y and z plane here) are skipped.
    #[test]
    fn find_split_by_hand() {
        let voxel = slab(0.0, 4.0);
        // A box at x 0..1, two at 3..4. x = 1: 1 below (half area 1 + 1 + 1 = 3), 2 above
        // (3 + 1 + 3 = 7): 1 + (3 + 14)/9 = 26/9. x = 3: 1 below (7), 2 above (3):
        // 1 + (7 + 6)/9 = 22/9, the best, cheaper than the leaf (3).
        // (No primitive lies in the plane, so the side it would send them to is not asserted.)
        let s = check_sweep(&[slab(0.0, 1.0), slab(3.0, 4.0), slab(3.0, 4.0)], &voxel, 0.2).unwrap();
        assert_eq!((s.axis, s.pos), (0, 3.0));
        assert!((s.cost - 22.0 / 9.0).abs() < 1e-6, "{s:?}");
        // Two flat boxes at x = 1.5 between a box at 0..1 and two at 3..4. x = 1.5: 1 below
        // (half area 4), 2 in the plane, 2 above (6): in the plane going below
        // 1 + (4·3 + 6·2)/9 = 33/9, going above 1 + (4·1 + 6·4)/9 = 37/9: below, 33/9.
        // x = 1: 1 + (3·1 + 7·4)/9 = 40/9; x = 3: 1 + (7·3 + 3·2)/9 = 36/9.
        let s = check_sweep(&[slab(0.0, 1.0), slab(1.5, 1.5), slab(1.5, 1.5), slab(3.0, 4.0), slab(3.0, 4.0)], &voxel, 0.2).unwrap();
        assert_eq!((s.axis, s.pos, s.planar_below), (0, 1.5, true));
        assert!((s.cost - 33.0 / 9.0).abs() < 1e-6, "{s:?}");
        // Mirrored: two boxes at 0..1, the flat pair at 2.5, one box at 3..4. x = 2.5: below
        // (6/9) 2, above (4/9) 1: the pair going above 1 + (6·2 + 4·3)/9 = 33/9, below
        // 1 + (6·4 + 4·1)/9 = 37/9. x = 1: 1 + (3·2 + 7·3)/9 = 36/9; x = 3: 1 + (7·4 + 3)/9 = 40/9.
        let s = check_sweep(&[slab(0.0, 1.0), slab(0.0, 1.0), slab(2.5, 2.5), slab(2.5, 2.5), slab(3.0, 4.0)], &voxel, 0.2).unwrap();
        assert_eq!((s.axis, s.pos, s.planar_below), (0, 2.5, false));
        assert!((s.cost - 33.0 / 9.0).abs() < 1e-6, "{s:?}");
        // Along y and z: the voxel 1 × 4 × 4 (half area 4 + 16 + 4 = 24), a box filling
        // y 0..1 and one filling z 3..4. y = 1: below 1 × 1 × 4 (1 + 4 + 4 = 9) holds both,
        // above 1 × 3 × 4 (3 + 12 + 4 = 19) the second: 1 + (9·2 + 19)/24 = 61/24. z = 3:
        // below (19) the first, above (9) both: also 61/24, a tie (the first found, y, is
        // kept; not asserted).
        let voxel = aabb([0.0; 3], [1.0, 4.0, 4.0]);
        let s = check_sweep(&[aabb([0.0; 3], [1.0, 1.0, 4.0]), aabb([0.0, 0.0, 3.0], [1.0, 4.0, 4.0])], &voxel, 0.2).unwrap();
        assert!((s.cost - 61.0 / 24.0).abs() < 1e-6, "{s:?}");
        assert!(s.axis == 1 && s.pos == 1.0 || s.axis == 2 && s.pos == 3.0, "{s:?}");
        // Every face on the voxel's boundary: no plane at all.
        assert!(check_sweep(&[slab(0.0, 4.0)], &slab(0.0, 4.0), 0.2).is_none());
        assert!(builder(&Boxes(vec![]), UNIT, 0.2, 20).find_split(&voxel, &[], 0).is_none());
    }

    /// Random boxes on an integer lattice (so that faces coincide, boxes touch and many are
    /// flat), in their own bounds and in a larger voxel: the sweep agrees with brute force.
    #[test]
    fn find_split_agrees_with_brute_force() {
        let mut rng = Pcg32::new(15, 8);
        let mut planes = 0;
        for scene in 0..300 {
            let n = 1 + rng.below(7) as usize;
            let boxes: Vec<Aabb> = (0..n)
                .map(|_| {
                    let mut c = || {
                        let (a, b) = (rng.below(6) as f32, rng.below(6) as f32);
                        (a.min(b), a.max(b))
                    };
                    let (x, y, z) = (c(), c(), c());
                    aabb([x.0, y.0, z.0], [x.1, y.1, z.1])
                })
                .collect();
            let tight = boxes.iter().fold(Aabb::EMPTY, |v, b| v.union(*b));
            let voxel = if scene % 2 == 0 { tight } else { Aabb { min: tight.min - Vec3::new(1.0, 0.0, 2.0), max: tight.max + Vec3::new(0.0, 3.0, 0.0) } };
            if voxel.half_area() > 0.0 {
                planes += usize::from(check_sweep(&boxes, &voxel, if scene % 3 == 0 { 0.0 } else { 0.5 }).is_some());
            }
        }
        assert!(planes > 200, "only {planes} scenes had a plane");
    }

    /// Sorted by position then kind, as the sweep needs, and the same events (up to the
    /// order of equal ones) as `want`.
    fn assert_events(got: &[Event], want: Vec<Event>) {
        assert!(got.windows(2).all(|w| Event::order(&w[0], &w[1]).is_le()), "unsorted: {got:?}");
        let key = |e: &Event| (e.pos.to_bits(), e.kind, e.prim);
        let (mut g, mut w): (Vec<_>, Vec<_>) = (got.iter().map(key).collect(), want.iter().map(key).collect());
        g.sort();
        w.sort();
        assert_eq!(g, w);
    }

    /// Voxel [0, 4] × [0, 1]² cut at x = 2. Prims: 0 (x 0.5..1) and 1 (1.5..2, ending in the
    /// plane) below; 2 (2..3, starting in it) and 3 (3..3.5) above; flat at x = 1 (4), in the
    /// plane (5) and at x = 3 (6); 7 (x 1..3, y 0..0.5) across, clipped to x 1..2 below and
    /// 2..3 above. Prim 5 goes to the side the split says.
    #[test]
    fn partition_by_hand() {
        let across = aabb([1.0, 0.0, 0.0], [3.0, 0.5, 1.0]);
        let boxes = vec![slab(0.5, 1.0), slab(1.5, 2.0), slab(2.0, 3.0), slab(3.0, 3.5), slab(1.0, 1.0), slab(2.0, 2.0), slab(3.0, 3.0), across];
        let prims = Boxes(boxes.clone());
        let b = builder(&prims, UNIT, 0.2, 20);
        let (vb, va) = (slab(0.0, 2.0), slab(2.0, 4.0));
        let (below_part, above_part) = (aabb([1.0, 0.0, 0.0], [2.0, 0.5, 1.0]), aabb([2.0, 0.0, 0.0], [3.0, 0.5, 1.0]));
        for (planar_below, want_below, want_above) in [(true, vec![0, 1, 4, 5, 7], vec![2, 3, 6, 7]), (false, vec![0, 1, 4, 7], vec![2, 3, 5, 6, 7])] {
            let s = Split { axis: 0, pos: 2.0, cost: 0.0, planar_below };
            let ((eb, pb), (ea, pa)) = b.partition(events_of(&boxes), &[0, 1, 2, 3, 4, 5, 6, 7], &s, &vb, &va);
            assert_eq!((&pb, &pa), (&want_below, &want_above), "planar below: {planar_below}");
            // Each child's events are those of its primitives (local ids: positions in the
            // child's list), the prim across the plane with its clipped part.
            let child_events = |ids: &[u32], part: Aabb| {
                let mut ev = Vec::new();
                for (local, &g) in ids.iter().enumerate() {
                    push_events(&mut ev, local as u32, &if g == 7 { part } else { boxes[g as usize] });
                }
                ev
            };
            assert_events(&eb, child_events(&pb, below_part));
            assert_events(&ea, child_events(&pa, above_part));
        }
        // Global ids stay global: the same scene listed in reverse (local k is prim 7 − k).
        let s = Split { axis: 0, pos: 2.0, cost: 0.0, planar_below: true };
        let rev: Vec<Aabb> = boxes.iter().rev().copied().collect();
        let ((_, pb), (_, pa)) = b.partition(events_of(&rev), &[7, 6, 5, 4, 3, 2, 1, 0], &s, &vb, &va);
        assert_eq!((pb, pa), (vec![7, 5, 4, 1, 0], vec![7, 6, 3, 2]));
    }

    /// A part of a prim across the plane that is empty on one side gets no events there: a
    /// prim whose clipped bounds miss the voxel above.
    #[test]
    fn partition_drops_empty_clipped_parts() {
        /// Boxes whose clipping keeps only the part below x = 1.5 (a prim whose bounds are
        /// larger than what it holds, as a thin diagonal triangle's are).
        struct Shrunk(Boxes);
        impl Primitives for Shrunk {
            fn len(&self) -> usize {
                self.0.len()
            }
            fn bounds(&self, i: u32) -> Aabb {
                self.0.bounds(i)
            }
            fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
                self.0.intersect(i, ray)
            }
            fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
                self.0.bounds(i).intersection(*clip).intersection(slab(-10.0, 1.5))
            }
        }
        let prims = Shrunk(Boxes(vec![slab(1.0, 3.0), slab(3.0, 4.0)]));
        let b = Builder { prims: &prims, sah: UNIT, empty_bonus: 0.2, max_depth: 20, nodes: Vec::new(), indices: Vec::new() };
        let s = Split { axis: 0, pos: 2.0, cost: 0.0, planar_below: true };
        let ((eb, pb), (ea, pa)) = b.partition(events_of(&prims.0 .0), &[0, 1], &s, &slab(0.0, 2.0), &slab(2.0, 4.0));
        assert_eq!((pb, pa), (vec![0], vec![1]));
        assert_events(&eb, events_of(&[slab(1.0, 1.5)]));
        assert_events(&ea, events_of(&[slab(3.0, 4.0)]));
    }

    /// The whole build of the first scene of `find_split_by_hand`: a box at x 0..1 and two at
    /// x 3..4, y and z 0..1. The root voxel is the scene grown by the margin
    /// m = 4/2¹⁸ + 4 ulp(4) = 2⁻¹⁶ + 2⁻¹⁹ = 9·2⁻¹⁹. The root splits at x = 3 (cost about
    /// 22/9 against the leaf's 3; the planes on the scene's faces, now inside the voxel by m,
    /// cut off empty slabs of almost no area: 1 + 0.8·3 = 3.4). Below: one prim, a leaf
    /// (any split costs more than 1). Above: both at x 3..4, whose best cut is again an empty
    /// slab (1 + 0.8·2 = 2.6 > 2): a leaf.
    #[test]
    fn build_by_hand() {
        let prims = Boxes(vec![slab(0.0, 1.0), slab(3.0, 4.0), slab(3.0, 4.0)]);
        let t = build(&prims, &BuildOptions::default());
        let m = 9.0 * (2.0f32).powi(-19);
        assert_eq!(t.margin, m);
        assert_eq!(t.bounds, aabb([-m, -m, -m], [4.0 + m, 1.0 + m, 1.0 + m]));
        assert_eq!(t.nodes, vec![KdNode::interior(0, 3.0, 2), KdNode::leaf(0, 1), KdNode::leaf(1, 2)]);
        assert_eq!(t.indices, vec![0, 1, 2]);
        assert_eq!(t.primitives, 3);
        t.validate(&prims).unwrap();
        // No primitives: no nodes.
        let t = build(&Boxes(vec![]), &BuildOptions::default());
        assert_eq!((t.nodes.len(), t.indices.len(), t.primitives), (0, 0, 0));
    }

    /// A split exactly as costly as the leaf is not taken (Wald & Havran split only while
    /// cheaper). Voxel [0, 4] × [0, 1]² (half area 9), two prims at x 1.125..4: the one plane
    /// inside, x = 1.125, leaves the voxel below empty; above, 2.875 + 1 + 2.875 = 6.75,
    /// 3/4 of the voxel. KT = 1.25, KI = 1, empty bonus ½: 1.25 + ½·(¾·2) = 2, the leaf's
    /// cost. With KT = 1.125 the split (1.875) is taken.
    #[test]
    fn a_split_no_cheaper_than_the_leaf_is_not_taken() {
        let boxes = vec![slab(1.125, 4.0), slab(1.125, 4.0)];
        let prims = Boxes(boxes.clone());
        for (kt, want) in [(1.25, vec![KdNode::leaf(0, 2)]), (1.125, vec![KdNode::interior(0, 1.125, 2), KdNode::leaf(0, 0), KdNode::leaf(0, 2)])] {
            let mut b = builder(&prims, SahCost { traversal: kt, intersection: 1.0 }, 0.5, 20);
            b.node(slab(0.0, 4.0), events_of(&boxes), vec![0, 1], 1);
            assert_eq!(b.nodes, want, "KT = {kt}");
            assert_eq!(b.indices, vec![0, 1]);
        }
    }

    /// The depth limit holds on both sides: with splits made cheap (KT = 0.01) 64 small boxes
    /// would split far deeper (even one box in a voxel: cutting off empty space costs
    /// 0.01 + 0.8·(its area) < 1), so a limit of L levels is reached, and never passed on
    /// either side: the depth of each node is worked out from the node array itself.
    #[test]
    fn depth_limit_holds_below_and_above() {
        let mut rng = Pcg32::new(3, 15);
        let boxes: Vec<Aabb> = (0..64)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 8.0;
                Aabb::new(c, c + Vec3::splat(0.25))
            })
            .collect();
        let prims = Boxes(boxes.clone());
        let voxel = boxes.iter().fold(Aabb::EMPTY, |v, b| v.union(*b));
        for limit in [1, 2, 3, 5] {
            let mut b = builder(&prims, SahCost { traversal: 0.01, intersection: 1.0 }, 0.2, limit);
            b.node(voxel, events_of(&boxes), (0..64).collect(), 1);
            let t = KdTree { nodes: b.nodes, indices: b.indices, bounds: voxel, margin: 0.0, primitives: 64, build_ms: 0.0 };
            t.validate(&prims).unwrap();
            // Depth of each node: the below child is the next node, the above child `above()`.
            let mut depth = vec![0usize; t.nodes.len()];
            depth[0] = 1;
            let mut below_leaf_at_limit = false;
            for i in 0..t.nodes.len() {
                let n = t.nodes[i];
                if !n.is_leaf() {
                    depth[i + 1] = depth[i] + 1;
                    depth[n.above()] = depth[i] + 1;
                } else if i > 0 && !t.nodes[i - 1].is_leaf() && depth[i] == limit {
                    below_leaf_at_limit = true;
                }
            }
            assert_eq!(depth.iter().max(), Some(&limit), "limit {limit}");
            assert_eq!(t.stats().max_depth, limit);
            assert!(limit == 1 || below_leaf_at_limit, "limit {limit}: no below child at the limit");
        }
    }
}
