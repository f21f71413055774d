//! The primitive loop every structure runs in its leaves (cells, objects): closest hit,
//! shrinking the ray as hits are found, or any hit, stopping at the first. Structures
//! differ only in which candidates they hand over.

use raylab_core::Ray;

use crate::{Counters, Hit, Primitives};

/// Closest-hit state carried through a walk.
pub(crate) struct Closest<'a, P: ?Sized> {
    prims: &'a P,
    pub best: Option<Hit>,
}

impl<'a, P: Primitives + ?Sized> Closest<'a, P> {
    pub fn new(prims: &'a P) -> Self {
        Self { prims, best: None }
    }

    /// Tests `candidates`, keeping the nearest hit and moving `ray.t_max` to it. Returns
    /// `false`: a closest-hit walk never stops early.
    #[inline]
    pub fn test(&mut self, ray: &mut Ray, candidates: impl IntoIterator<Item = u32>, c: &mut Counters) -> bool {
        for p in candidates {
            c.prim_tests += 1;
            if let Some(h) = self.prims.intersect(p, ray) {
                ray.t_max = h.t;
                self.best = Some(Hit::new(p, h));
            }
        }
        false
    }
}

/// Whether any of `candidates` is hit; stops at the first.
#[inline]
pub(crate) fn any_hit<P: Primitives + ?Sized>(prims: &P, ray: &Ray, candidates: impl IntoIterator<Item = u32>, c: &mut Counters) -> bool {
    candidates.into_iter().any(|p| {
        c.prim_tests += 1;
        prims.intersect(p, ray).is_some()
    })
}
