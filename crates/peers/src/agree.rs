//! Whether a peer gave raylab's answers, ray by ray.
//!
//! Peers intersect triangles with their own kernels (Embree and obvhs: Möller–Trumbore
//! variants; raylab: the watertight test of Woop et al. 2013), so the same hit comes back at
//! distances that differ in the last bits, and a ray through a shared edge or vertex may be
//! caught by raylab's watertight test and slip through the other's (or hit the neighbour).
//! The tolerance, documented in docs/performance.md:
//! - a ray agrees when both miss, or both hit at distances within [`REL_T_TOLERANCE`]
//!   (relative; a different primitive at the same distance is the other side of a shared
//!   edge and agrees); for any-hit rays, when both say the same;
//! - at most [`DISAGREEING_PER_RAY`] of the rays (1 in 2,000, rounded up) may disagree;
//!   beyond that the benchmark fails loudly, printing the first disagreement. The most seen
//!   (docs/performance.md) is 1.5 in 10,000: obvhs's CWBVH on the 871k dragon's shadow
//!   rays, which leave the surface and cross its edges; a traversal bug breaks far more.

use crate::PeerHit;

/// Relative difference of two distances to the same surface that still counts as the same
/// hit (about 800 ulps: Möller–Trumbore's error grows as rays graze a triangle).
pub const REL_T_TOLERANCE: f32 = 1e-4;

/// Fraction of rays allowed to disagree (rays through shared edges and vertices).
pub const DISAGREEING_PER_RAY: f64 = 5e-4;

/// One structure's answers against the reference's, for one ray set.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Agreement {
    pub rays: usize,
    pub hits: u64,
    pub t_sum: f64,
    pub reference_hits: u64,
    pub reference_t_sum: f64,
    /// Rays whose answers differ beyond the tolerance.
    pub disagreeing: usize,
    /// The first of them, described for the error message.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first: Option<String>,
}

impl Agreement {
    /// Disagreeing rays allowed for this many rays.
    pub fn allowed(&self) -> usize {
        (self.rays as f64 * DISAGREEING_PER_RAY).ceil() as usize
    }

    pub fn ok(&self) -> bool {
        self.disagreeing <= self.allowed()
    }

    /// Relative difference of the distance sums.
    pub fn t_sum_rel_diff(&self) -> f64 {
        (self.t_sum - self.reference_t_sum).abs() / self.reference_t_sum.abs().max(f64::MIN_POSITIVE)
    }
}

fn same_distance(a: f32, b: f32) -> bool {
    (a - b).abs() <= REL_T_TOLERANCE * a.abs().max(b.abs())
}

/// Compares closest-hit answers, ray by ray (`got[i]` answers the ray of `reference[i]`).
pub fn closest(reference: &[Option<PeerHit>], got: &[Option<PeerHit>]) -> Agreement {
    assert_eq!(reference.len(), got.len(), "answers for different ray sets");
    let mut a = Agreement { rays: got.len(), ..Default::default() };
    for (i, (w, g)) in reference.iter().zip(got).enumerate() {
        if let Some(w) = w {
            a.reference_hits += 1;
            a.reference_t_sum += w.t as f64;
        }
        if let Some(g) = g {
            a.hits += 1;
            a.t_sum += g.t as f64;
        }
        let agrees = match (w, g) {
            (None, None) => true,
            (Some(w), Some(g)) => same_distance(w.t, g.t),
            _ => false,
        };
        if !agrees {
            a.disagreeing += 1;
            if a.first.is_none() {
                a.first = Some(format!("ray {i}: {g:?}, reference {w:?}"));
            }
        }
    }
    a
}

/// Compares any-hit answers, ray by ray.
pub fn any(reference: &[bool], got: &[bool]) -> Agreement {
    assert_eq!(reference.len(), got.len(), "answers for different ray sets");
    let mut a = Agreement { rays: got.len(), ..Default::default() };
    for (i, (&w, &g)) in reference.iter().zip(got).enumerate() {
        a.reference_hits += u64::from(w);
        a.hits += u64::from(g);
        if w != g {
            a.disagreeing += 1;
            if a.first.is_none() {
                a.first = Some(format!("ray {i}: occluded {g}, reference {w}"));
            }
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(t: f32, prim: u32) -> Option<PeerHit> {
        Some(PeerHit { t, prim })
    }

    #[test]
    fn near_distances_and_shared_edges_agree_others_are_counted() {
        // 4,000 rays: 2 may disagree (1 in 2,000).
        let mut reference = vec![None; 4_000];
        let mut got = vec![None; 4_000];
        reference[0] = hit(2.0, 7);
        got[0] = hit(2.0 * (1.0 + 5e-5), 7); // within 1e-4 relative
        reference[1] = hit(3.0, 8);
        got[1] = hit(3.0, 9); // the neighbour across a shared edge, same distance
        let a = closest(&reference, &got);
        assert_eq!((a.disagreeing, a.allowed(), a.hits, a.reference_hits), (0, 2, 2, 2));
        assert_eq!(a.reference_t_sum, 5.0);
        assert!(a.ok());

        reference[2] = hit(1.0, 1); // missed by the peer
        got[3] = hit(4.0, 2); // invented by the peer
        reference[4] = hit(1.0, 3);
        got[4] = hit(1.001, 3); // 1e-3 relative: a different surface
        let a = closest(&reference, &got);
        assert_eq!(a.disagreeing, 3);
        assert!(!a.ok());
        assert_eq!(a.first.as_deref(), Some("ray 2: None, reference Some(PeerHit { t: 1.0, prim: 1 })"));
    }

    #[test]
    fn any_hit_answers_must_match() {
        let reference = [true, false, true, false];
        let a = any(&reference, &[true, false, false, true]);
        assert_eq!((a.rays, a.hits, a.reference_hits, a.disagreeing, a.allowed()), (4, 2, 2, 2, 1));
        assert!(!a.ok());
        assert_eq!(a.first.as_deref(), Some("ray 2: occluded false, reference true"));
        assert!(any(&reference, &reference).ok());
    }
}
