//! Per-object bounding boxes: the first step beyond brute force (the first seed report's
//! "ray–mesh tests"). Each object of [`Primitives::objects`] gets one box; a ray tests
//! every box and, for each box it hits, every primitive of that object.
//!
//! Cost is linear in the number of objects plus the size of every object hit, so it helps
//! a scene of many small objects and does nothing for one large mesh.

use std::ops::Range;

use raylab_core::{Aabb, Ray};

use crate::leaf::{any_hit, Closest};
use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

/// One box per object.
///
/// Invariants: `objects[k]` lies inside `0..primitives` and `boxes[k]` contains the bounds
/// of every primitive in `objects[k]`; empty objects are dropped at build.
#[derive(Debug, Default)]
pub struct ObjectBoxes {
    boxes: Vec<Aabb>,
    objects: Vec<Range<u32>>,
    primitives: usize,
    pub(crate) build_ms: f64,
}

impl ObjectBoxes {
    pub fn build<P: Primitives + ?Sized>(prims: &P) -> Self {
        let n = prims.len() as u32;
        // Clamp to the primitive count so that a wrong `objects()` cannot make the build
        // panic; `validate` then reports the primitives left out.
        let objects: Vec<Range<u32>> =
            prims.objects().into_iter().map(|r| r.start.min(n)..r.end.min(n)).filter(|r| !r.is_empty()).collect();
        let boxes = objects.iter().map(|r| r.clone().fold(Aabb::EMPTY, |b, i| b.union(prims.bounds(i)))).collect();
        Self { boxes, objects, primitives: prims.len(), build_ms: 0.0 }
    }

    /// Calls `leaf(ray, range, counters)` for each object whose box the ray hits within its
    /// current interval; `leaf` may shrink `ray.t_max` and returns `true` to stop.
    #[inline]
    fn walk(&self, ray: &mut Ray, c: &mut Counters, mut leaf: impl FnMut(&mut Ray, Range<u32>, &mut Counters) -> bool) {
        let inv = ray.inv_dir();
        for (b, r) in self.boxes.iter().zip(&self.objects) {
            c.object_tests += 1;
            if b.intersect(ray.origin, inv, ray.t_min, ray.t_max).is_some() {
                c.nodes_visited += 1;
                if leaf(ray, r.clone(), c) {
                    return;
                }
            }
        }
    }
}

impl Accel for ObjectBoxes {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        c.rays += 1;
        let mut ray = *ray;
        let mut closest = Closest::new(prims);
        self.walk(&mut ray, c, |ray, r, c| closest.test(ray, r, c));
        closest.best
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        c.rays += 1;
        let mut ray = *ray;
        let mut hit = false;
        self.walk(&mut ray, c, |ray, r, c| {
            hit = any_hit(prims, ray, r, c);
            hit
        });
        hit
    }

    fn stats(&self) -> AccelStats {
        let mut s = AccelStats {
            name: "aabb".into(),
            build_ms: self.build_ms,
            primitives: self.primitives,
            memory_bytes: self.boxes.len() * (std::mem::size_of::<Aabb>() + std::mem::size_of::<Range<u32>>()),
            ..Default::default()
        };
        let scene = self.boxes.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        let scene_area = scene.half_area().max(f32::MIN_POSITIVE) as f64;
        // Every box is tested by every ray (cost 1 each); a hit box costs its primitives.
        s.sah_cost = self.boxes.len() as f64;
        for (b, r) in self.boxes.iter().zip(&self.objects) {
            s.add_leaf(r.len());
            s.sah_cost += b.half_area() as f64 / scene_area * r.len() as f64;
        }
        s.max_depth = usize::from(!self.boxes.is_empty());
        s
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        let err = |m: String| Err(ValidationError::new("aabb", m));
        if prims.len() != self.primitives {
            return err(format!("built for {} primitives, given {}", self.primitives, prims.len()));
        }
        let mut seen = vec![false; prims.len()];
        for (k, (b, r)) in self.boxes.iter().zip(&self.objects).enumerate() {
            for p in r.clone() {
                if seen[p as usize] {
                    return err(format!("primitive {p} is in two objects"));
                }
                seen[p as usize] = true;
                if !b.contains_box(&prims.bounds(p)) {
                    return err(format!("primitive {p} sticks out of object box {k}"));
                }
            }
        }
        match seen.iter().position(|s| !s) {
            Some(p) => err(format!("primitive {p} is in no object")),
            None => Ok(()),
        }
    }
}
