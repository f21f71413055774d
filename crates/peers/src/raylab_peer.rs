//! raylab's own structures behind the [`Peer`] trait, so that they are timed through
//! exactly the same calls and loops as the peers.

use raylab_accel::{Accel, AnyAccel, AccelKind, Primitives};
use raylab_core::Ray;

use crate::{Peer, PeerHit};

pub struct RaylabPeer<'a, P: Primitives + Sync + ?Sized> {
    pub kind: AccelKind,
    pub accel: AnyAccel,
    pub prims: &'a P,
    /// Bytes of the triangle data the structure reads while tracing but does not count
    /// itself (the mesh, for structures that index into it; 0 for those that copy it).
    pub mesh_bytes: usize,
}

impl<P: Primitives + Sync + ?Sized> Peer for RaylabPeer<'_, P> {
    fn name(&self) -> String {
        format!("raylab {}", self.kind.name())
    }
    fn build_ms(&self) -> f64 {
        self.accel.stats().build_ms
    }
    fn memory_bytes(&self) -> usize {
        self.accel.stats().memory_bytes + self.mesh_bytes
    }
    fn intersect(&self, ray: &Ray) -> Option<PeerHit> {
        self.accel.intersect_fast(self.prims, ray).map(|h| PeerHit { t: h.t, prim: h.prim })
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.accel.occluded_fast(self.prims, ray)
    }
    fn intersect16(&self, rays: &[Ray], out: &mut [Option<PeerHit>]) {
        let mut hits = [None; raylab_accel::PACKET];
        self.accel.intersect_packet(self.prims, rays, &mut hits[..rays.len()]);
        for (o, h) in out.iter_mut().zip(&hits) {
            *o = h.map(|h| PeerHit { t: h.t, prim: h.prim });
        }
    }
    /// The wide BVHs trace packets together; the other structures one ray at a time.
    fn has_packets(&self) -> bool {
        matches!(self.kind, AccelKind::Bvh8 | AccelKind::Bvh4 | AccelKind::Bvh8Sbvh | AccelKind::Bvh8Q)
    }
}
