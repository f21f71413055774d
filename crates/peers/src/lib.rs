//! Other engines' acceleration structures, traced on exactly the rays raylab traces.
//!
//! A lab that compares structures is believed only if its best one is measured against
//! what engines ship (issue 11). Each peer is built from raylab's triangle list (in
//! raylab's primitive order, so primitive ids agree) and answers the same two questions as
//! raylab's structures, closest hit and any hit, one ray at a time; Embree also answers
//! 16-ray packets through `rtcIntersect16`. The peers are optional: `--features obvhs`,
//! `bvh` (together `peers`) and `embree`; without them this crate builds only raylab's own
//! side (the harness, the agreement check and the tables), and asking for a peer is an
//! error that says how to build it (`scripts/peers.sh`).

pub mod agree;
pub mod cpu_time;
pub mod harness;
mod raylab_peer;
pub mod table;

#[cfg(feature = "bvh")]
mod bvh_peer;
#[cfg(feature = "embree")]
mod embree;
#[cfg(feature = "obvhs")]
mod obvhs_peer;

pub use raylab_peer::RaylabPeer;

use raylab_core::{Ray, Vec3};

/// A closest hit as every structure reports it: the distance and the primitive's index in
/// raylab's primitive order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeerHit {
    pub t: f32,
    pub prim: u32,
}

/// Rays per packet of [`Peer::intersect16`].
pub const PACKET: usize = 16;

/// An acceleration structure that is not one of raylab's own (or raylab's, wrapped the same
/// way so that every structure is timed through the same calls).
pub trait Peer: Send + Sync {
    /// The name printed in tables and JSON.
    fn name(&self) -> String;
    /// Wall-clock build time, including what the engine needs before it can trace
    /// (copying the triangles into its own buffers).
    fn build_ms(&self) -> f64;
    /// Bytes held while tracing: the structure and the triangle data it reads.
    fn memory_bytes(&self) -> usize;
    fn intersect(&self, ray: &Ray) -> Option<PeerHit>;
    fn occluded(&self, ray: &Ray) -> bool;
    /// Up to [`PACKET`] rays at once (`out` as long as `rays`). Peers without a packet
    /// kernel trace them one by one; [`Peer::has_packets`] says which.
    fn intersect16(&self, rays: &[Ray], out: &mut [Option<PeerHit>]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.intersect(r);
        }
    }
    fn has_packets(&self) -> bool {
        false
    }
}

/// The peers `--peers` can name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PeerKind {
    /// Embree 3, build quality HIGH (spatial splits): the bar.
    Embree,
    /// Embree 3, build quality MEDIUM: binned SAH without spatial splits, the tree HIGH
    /// robust builds too (only the leaves and kernels differ), so the two side by side give
    /// the price of the guarantees in Embree.
    EmbreeMedium,
    /// Embree 3, build quality HIGH with the scene flag `RTC_SCENE_FLAG_ROBUST`: box tests
    /// that rounding cannot make miss and watertight triangle tests, the guarantees of
    /// raylab's kernels.
    EmbreeRobust,
    /// obvhs's compressed wide BVH (Ylitie et al. 2017), `medium_build` preset.
    ObvhsCwbvh,
    /// obvhs's binary BVH, `medium_build` preset.
    ObvhsBvh2,
    /// The `bvh` crate (svenstaro/bvh), binned SAH, one triangle per leaf.
    BvhCrate,
}

impl PeerKind {
    pub fn name(self) -> &'static str {
        match self {
            PeerKind::Embree => "embree",
            PeerKind::EmbreeMedium => "embree-medium",
            PeerKind::EmbreeRobust => "embree-robust",
            PeerKind::ObvhsCwbvh => "obvhs-cwbvh",
            PeerKind::ObvhsBvh2 => "obvhs-bvh2",
            PeerKind::BvhCrate => "bvh-crate",
        }
    }

    /// The feature of the `raylab` command that builds this peer (`peers` turns on this
    /// crate's `obvhs` and `bvh`).
    pub fn feature(self) -> &'static str {
        match self {
            PeerKind::Embree | PeerKind::EmbreeMedium | PeerKind::EmbreeRobust => "embree",
            PeerKind::ObvhsCwbvh | PeerKind::ObvhsBvh2 | PeerKind::BvhCrate => "peers",
        }
    }

    /// Whether this build of raylab has the peer.
    pub fn available(self) -> bool {
        match self {
            PeerKind::Embree | PeerKind::EmbreeMedium | PeerKind::EmbreeRobust => cfg!(feature = "embree"),
            PeerKind::ObvhsCwbvh | PeerKind::ObvhsBvh2 => cfg!(feature = "obvhs"),
            PeerKind::BvhCrate => cfg!(feature = "bvh"),
        }
    }
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PeerError {
    #[error("--peers: unknown peer `{0}` (expected embree, obvhs, bvh, or one of embree-medium, embree-robust, obvhs-cwbvh, obvhs-bvh2, bvh-crate)")]
    Unknown(String),
    #[error("--peers: `{peer}` is not in this build of raylab; build it with `cargo build --release -p raylab --features {feature}` (scripts/peers.sh installs libembree-dev and runs the whole comparison)")]
    NotBuilt { peer: &'static str, feature: &'static str },
    #[error("embree: {0}")]
    Embree(String),
    #[error("peers trace triangle meshes only: primitive {0} is not a triangle")]
    NotATriangle(u32),
}

/// Parses a comma-separated `--peers` list: `embree` stands for HIGH, MEDIUM and HIGH
/// robust, `obvhs`
/// for CWBVH and BVH2, `bvh` for the `bvh` crate. Every named peer must be in this build.
pub fn parse_list(list: &str) -> Result<Vec<PeerKind>, PeerError> {
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let kinds: &[PeerKind] = match name {
            "embree" => &[PeerKind::Embree, PeerKind::EmbreeMedium, PeerKind::EmbreeRobust],
            "obvhs" => &[PeerKind::ObvhsCwbvh, PeerKind::ObvhsBvh2],
            "bvh" | "bvh-crate" => &[PeerKind::BvhCrate],
            "embree-medium" => &[PeerKind::EmbreeMedium],
            "embree-robust" => &[PeerKind::EmbreeRobust],
            "obvhs-cwbvh" => &[PeerKind::ObvhsCwbvh],
            "obvhs-bvh2" => &[PeerKind::ObvhsBvh2],
            _ => return Err(PeerError::Unknown(name.to_string())),
        };
        for &k in kinds {
            if !k.available() {
                return Err(PeerError::NotBuilt { peer: k.name(), feature: k.feature() });
            }
            if !out.contains(&k) {
                out.push(k);
            }
        }
    }
    if out.is_empty() {
        return Err(PeerError::Unknown(list.to_string()));
    }
    Ok(out)
}

/// Builds `kind` over `tris` (raylab's primitive order) with `threads` build threads
/// (Embree's device; the Rust peers build in the calling rayon pool).
pub fn build(kind: PeerKind, tris: &[[Vec3; 3]], threads: usize) -> Result<Box<dyn Peer>, PeerError> {
    let _ = (tris, threads);
    match kind {
        #[cfg(feature = "embree")]
        PeerKind::Embree => Ok(Box::new(embree::EmbreePeer::build(tris, threads, embree::Quality::High)?)),
        #[cfg(feature = "embree")]
        PeerKind::EmbreeMedium => Ok(Box::new(embree::EmbreePeer::build(tris, threads, embree::Quality::Medium)?)),
        #[cfg(feature = "embree")]
        PeerKind::EmbreeRobust => Ok(Box::new(embree::EmbreePeer::build(tris, threads, embree::Quality::HighRobust)?)),
        #[cfg(feature = "obvhs")]
        PeerKind::ObvhsCwbvh => Ok(Box::new(obvhs_peer::ObvhsPeer::build_cwbvh(tris))),
        #[cfg(feature = "obvhs")]
        PeerKind::ObvhsBvh2 => Ok(Box::new(obvhs_peer::ObvhsPeer::build_bvh2(tris))),
        #[cfg(feature = "bvh")]
        PeerKind::BvhCrate => Ok(Box::new(bvh_peer::BvhCratePeer::build(tris))),
        #[allow(unreachable_patterns)]
        k => Err(PeerError::NotBuilt { peer: k.name(), feature: k.feature() }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_expand_and_missing_features_say_how_to_build() {
        assert_eq!(parse_list("nope"), Err(PeerError::Unknown("nope".into())));
        let all = [PeerKind::Embree, PeerKind::EmbreeMedium, PeerKind::EmbreeRobust, PeerKind::ObvhsCwbvh, PeerKind::ObvhsBvh2, PeerKind::BvhCrate];
        if all.iter().all(|k| k.available()) {
            assert_eq!(parse_list("embree,obvhs,bvh").unwrap(), all.to_vec());
            assert_eq!(parse_list("obvhs-cwbvh, obvhs").unwrap(), vec![PeerKind::ObvhsCwbvh, PeerKind::ObvhsBvh2]);
        }
        if !PeerKind::BvhCrate.available() {
            assert_eq!(parse_list("bvh").unwrap_err().to_string(), "--peers: `bvh-crate` is not in this build of raylab; build it with `cargo build --release -p raylab --features peers` (scripts/peers.sh installs libembree-dev and runs the whole comparison)");
        }
        if !PeerKind::Embree.available() {
            let e = parse_list("embree").unwrap_err();
            assert_eq!(e, PeerError::NotBuilt { peer: "embree", feature: "embree" });
            assert!(e.to_string().contains("--features embree") && e.to_string().contains("scripts/peers.sh"), "{e}");
        }
    }
}
