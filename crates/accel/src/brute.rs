//! The oracle: every primitive tested against every ray.

use raylab_core::Ray;

use crate::{Accel, AccelStats, Counters, Hit, Primitives, ValidationError};

#[derive(Debug, Default)]
pub struct Brute {
    len: usize,
    pub(crate) build_ms: f64,
}

impl Brute {
    pub fn build<P: Primitives + ?Sized>(prims: &P) -> Self {
        Self { len: prims.len(), build_ms: 0.0 }
    }
}

impl Accel for Brute {
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> Option<Hit> {
        c.rays += 1;
        let mut ray = *ray;
        let mut best = None;
        for i in 0..self.len as u32 {
            c.prim_tests += 1;
            if let Some(h) = prims.intersect(i, &ray) {
                ray.t_max = h.t;
                best = Some(Hit::new(i, h));
            }
        }
        best
    }

    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, c: &mut Counters) -> bool {
        c.rays += 1;
        (0..self.len as u32).any(|i| {
            c.prim_tests += 1;
            prims.intersect(i, ray).is_some()
        })
    }

    fn stats(&self) -> AccelStats {
        AccelStats { name: "none".into(), build_ms: self.build_ms, primitives: self.len, references: self.len, ..Default::default() }
    }

    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        if prims.len() != self.len {
            return Err(ValidationError::new("none", format!("built for {} primitives, given {}", self.len, prims.len())));
        }
        Ok(())
    }
}
