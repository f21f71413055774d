//! Acceleration structures behind one trait.
//!
//! A structure sees only what [`Primitives`] tells it (count, bounds, a leaf intersection
//! callback), never shapes, materials or files. Every structure answers the same two
//! questions (pbrt's `Intersect` / `IntersectP`): [`Accel::intersect`] for the closest hit
//! and [`Accel::occluded`] for any hit (shadow rays), counts its work in per-thread
//! [`Counters`], reports [`AccelStats`] and can [`Accel::validate`] itself.
//!
//! The runtime choice is [`AnyAccel`], a closed enum matched per call: no `dyn` in the hot loop.

pub mod aabb;
pub mod brute;
pub mod bvh;
pub mod counters;
pub mod grid;
pub mod kdtree;
mod leaf;
mod par;
pub mod primitives;
pub mod sphere_bvh;
pub mod stats;
mod tree;
pub mod wide;

use std::fmt;
use std::str::FromStr;
use std::time::Instant;

use raylab_core::{Aabb, Ray};

pub use aabb::ObjectBoxes;
pub use brute::Brute;
pub use bvh::{Bvh, SplitMethod};
pub use counters::Counters;
pub use grid::Grid;
pub use kdtree::KdTree;
pub use primitives::{Hit, PrimHit, Primitives};
pub use sphere_bvh::SphereBvh;
pub use stats::AccelStats;
pub use wide::quant::QuantNode;
pub use wide::{Kernel, Prefetch, WideBvh, PACKET};

/// What every acceleration structure offers.
pub trait Accel: Send + Sync {
    /// Closest hit with `t` in `(ray.t_min, ray.t_max]`.
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, counters: &mut Counters) -> Option<Hit>;
    /// Whether anything is hit in `(ray.t_min, ray.t_max]`; may stop at the first hit found.
    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, counters: &mut Counters) -> bool;
    /// Statistics of the built structure (build time is filled in by [`AnyAccel::build`]).
    fn stats(&self) -> AccelStats;
    /// Checks the structure's invariants: every primitive reachable, children inside parents,
    /// counts consistent.
    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError>;
}

/// A broken invariant found by [`Accel::validate`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{accel}: {message}")]
pub struct ValidationError {
    pub accel: &'static str,
    pub message: String,
}

impl ValidationError {
    pub fn new(accel: &'static str, message: impl Into<String>) -> Self {
        Self { accel, message: message.into() }
    }
}

/// The structures a user can choose by name (`--accel NAME`, `[render] accel`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccelKind {
    /// Every primitive tested: the oracle.
    None,
    /// BVH, binned SAH (Wald 2007).
    Bvh,
    /// BVH split at the object median of the longest axis.
    BvhMedian,
    /// BVH split at the spatial midpoint of the longest axis.
    BvhMidpoint,
    /// One bounding box per object (the first seed report's ray–mesh tests).
    Aabb,
    /// Uniform grid walked by 3D-DDA (Amanatides & Woo 1987).
    Grid,
    /// Linear BVH: Morton order, Karras 2012 hierarchy.
    Lbvh,
    /// BVH by parallel locally-ordered clustering (Meister & Bittner 2018).
    LbvhPloc,
    /// SAH kd-tree with perfect splits, built in O(N log N) (Wald & Havran 2006).
    KdTree,
    /// Bottom-up hierarchy of bounding spheres (the second seed report's BVH).
    SphereBvh,
    /// BVH with spatial splits (Stich et al. 2009).
    Sbvh,
    /// Binned SAH BVH collapsed to 8-wide SIMD nodes with 4-triangle leaf blocks.
    Bvh8,
    /// Binned SAH BVH collapsed to 4-wide SIMD nodes with 4-triangle leaf blocks.
    Bvh4,
    /// SBVH collapsed to 8-wide nodes.
    Bvh8Sbvh,
    /// `bvh8` with quantised child boxes (8 bits per bound on a per-node grid, after
    /// Ylitie et al.'s CWBVH): 96-byte nodes instead of 224.
    Bvh8Q,
}

impl AccelKind {
    pub const ALL: &'static [AccelKind] =
        &[AccelKind::None, AccelKind::Bvh, AccelKind::BvhMedian, AccelKind::BvhMidpoint, AccelKind::Aabb, AccelKind::Grid, AccelKind::Lbvh, AccelKind::LbvhPloc, AccelKind::KdTree, AccelKind::SphereBvh, AccelKind::Sbvh, AccelKind::Bvh8, AccelKind::Bvh4, AccelKind::Bvh8Sbvh, AccelKind::Bvh8Q];

    pub fn name(self) -> &'static str {
        match self {
            AccelKind::None => "none",
            AccelKind::Bvh => "bvh",
            AccelKind::BvhMedian => "bvh-median",
            AccelKind::BvhMidpoint => "bvh-midpoint",
            AccelKind::Aabb => "aabb",
            AccelKind::Grid => "grid",
            AccelKind::Lbvh => "lbvh",
            AccelKind::LbvhPloc => "lbvh-ploc",
            AccelKind::KdTree => "kdtree",
            AccelKind::SphereBvh => "sphere-bvh",
            AccelKind::Sbvh => "sbvh",
            AccelKind::Bvh8 => "bvh8",
            AccelKind::Bvh4 => "bvh4",
            AccelKind::Bvh8Sbvh => "bvh8-sbvh",
            AccelKind::Bvh8Q => "bvh8q",
        }
    }

    pub fn names() -> String {
        Self::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
    }
}

impl fmt::Display for AccelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown structure name; the message lists the valid ones.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unknown acceleration structure `{0}` (valid: {names})", names = AccelKind::names())]
pub struct UnknownAccel(pub String);

impl FromStr for AccelKind {
    type Err = UnknownAccel;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| UnknownAccel(s.to_string()))
    }
}

raylab_core::value_enum_from_names!(AccelKind);

/// Embree's build quality knob: which builder makes the binary tree that `bvh`, `bvh4` and
/// `bvh8` are laid out from (other names keep their own builder).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildQuality {
    /// LBVH (Morton codes, Karras 2012), as Embree's low quality: the fastest build
    /// (2-5x faster than binned SAH here), a worse tree.
    Low,
    /// Binned SAH (Wald 2007): the default.
    #[default]
    Medium,
    /// SBVH with spatial splits (Stich et al. 2009): the slowest build, the best tree.
    High,
}

raylab_core::named_enum!(BuildQuality, "build quality", {
    Low => "low",
    Medium => "medium",
    High => "high",
});

/// Build parameters shared by the builders; each reads the fields it needs.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// Cost of one traversal step relative to one primitive test (SAH).
    pub traversal_cost: f32,
    /// Cost of one primitive test.
    pub intersection_cost: f32,
    /// Leaves never hold more primitives than this unless they cannot be split.
    pub max_leaf_size: usize,
    /// Bins per axis of binned builders; `bvh`'s binned SAH gives nodes of `n` primitives
    /// `min(bins, 4 + n/20)` (Embree's rule: small nodes need fewer).
    pub bins: usize,
    /// Grid cells per primitive, `λ` (the grid has about `λ·N` cells). pbrt-v1's `3∛N`
    /// cells on the longest axis amounts to `λ = 27` on a cube; a handful is usual
    /// (Wald et al. 2006; Ize et al. 2007, "Grid Creation Strategies").
    pub grid_density: f32,
    /// Grid cells per axis at most, so that a huge scene cannot exhaust memory.
    pub grid_max_resolution: u32,
    /// PLOC's search radius along the Morton curve (Meister & Bittner 2018 find 8-16 a
    /// good trade between build time and tree quality).
    pub ploc_radius: usize,
    /// Fraction of the intersection cost a kd-tree split saves when one child is empty,
    /// which favours cutting off empty space (Wald & Havran 2006 use 0.2, pbrt 0.5).
    pub empty_bonus: f32,
    /// SBVH: spatial splits are tried only where the object split's children overlap by
    /// more than this fraction of the root's area (Stich et al. 2009 suggest 10⁻⁵).
    pub spatial_split_alpha: f32,
    /// Builder of the binary tree under `bvh`, `bvh4` and `bvh8`.
    pub quality: BuildQuality,
    /// The binned SAH counts a side's primitives in blocks of this many (Embree's
    /// `logBlockSize`): a leaf costs one test per block, plus a share per triangle that
    /// keeps a large triangle out of a block of small ones. 1 for binary BVHs; the wide
    /// layouts build with 4, the triangles their leaves test at once, which ends the
    /// binary tree at the leaves they will hold. A power of two (others count as the next
    /// one up).
    pub leaf_block: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self { traversal_cost: 1.0, intersection_cost: 1.0, max_leaf_size: 8, bins: 16, grid_density: 4.0, grid_max_resolution: 128, ploc_radius: 16, empty_bonus: 0.2, spatial_split_alpha: 1e-5, quality: BuildQuality::Medium, leaf_block: 1 }
    }
}

/// Distance by which grids and kd-trees grow cells (or split planes) when they decide
/// which side of a boundary a primitive or a ray is on, and BVHs of boxes or spheres grow
/// their leaves. Rounding moves a point by two kinds of error, bounded separately:
/// - arithmetic on distances within the scene (plane distances, `t` along a ray, clipping
///   parameters) errs relative to the scene's size: 2⁻¹⁸ of its extent, some thirty ulps;
/// - each operation that lands on an absolute coordinate (a ray point `o + t·d`, a cell
///   boundary `min + k·size`) rounds by half an ulp of that coordinate; four such roundings
///   per decision at most, so four ulps of the largest coordinate.
///
/// A primitive within the margin of a boundary is kept on both sides, so no hit is lost or
/// taken from the wrong cell. The margin used to be 2⁻¹⁸ of the largest *coordinate*: a
/// scene of size 20 shifted to 1e6 then grew every cell by 3.8, and the grid, kd-tree and
/// the BVHs built on grown leaves did hundreds of times the work (issue 12). Rays whose
/// origin lies far outside the scene (beyond ~10⁴ scene sizes) are not covered by this bound.
pub(crate) fn robust_margin(scene: &Aabb) -> f32 {
    if scene.is_empty() {
        return f32::MIN_POSITIVE;
    }
    let largest_coordinate = scene.min.abs().max(scene.max.abs()).max_element();
    leaf_margin(scene) + 4.0 * (largest_coordinate.next_up() - largest_coordinate)
}

/// The part of [`robust_margin`] that BVHs of boxes and spheres need for their leaves: their
/// traversal only computes distances from the ray origin (`(bound - origin) / dir`, the
/// offset to a sphere's centre), whose rounding is relative to those distances, never to the
/// absolute coordinates, so 2⁻¹⁸ of the scene's extent covers it.
pub(crate) fn leaf_margin(scene: &Aabb) -> f32 {
    if scene.is_empty() {
        return f32::MIN_POSITIVE;
    }
    (scene.extent().max_element() * (1.0 / 262_144.0)).max(f32::MIN_POSITIVE)
}

/// The binary BVH a wide layout is converted from: [`binary_at_quality`], with the binned
/// SAH counting in the leaves' blocks of four ([`BuildOptions::leaf_block`]) and binary
/// leaves of at most four when every primitive is a triangle. Other primitives are tested
/// one call each, whatever block they share, so there a leaf's cost stays one per
/// primitive.
pub fn binary_for_wide<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions, name: &'static str) -> Bvh {
    if !all_triangles(prims) {
        return binary_at_quality(prims, opts, name);
    }
    binary_at_quality(prims, &BuildOptions { leaf_block: 4, max_leaf_size: opts.max_leaf_size.min(4), ..opts.clone() }, name)
}

fn all_triangles<P: Primitives + ?Sized>(prims: &P) -> bool {
    use rayon::prelude::*;
    (0..prims.len() as u32).into_par_iter().with_min_len(4096).all(|i| prims.is_triangle(i))
}

/// The binary BVH of `opts.quality`, named `name` (the user's choice, whatever the builder).
fn binary_at_quality<P: Primitives + ?Sized>(prims: &P, opts: &BuildOptions, name: &'static str) -> Bvh {
    let mut bvh = match opts.quality {
        BuildQuality::Low => bvh::lbvh::build(prims, opts),
        BuildQuality::Medium => Bvh::build(prims, SplitMethod::BinnedSah, opts),
        BuildQuality::High => bvh::sbvh::build(prims, opts),
    };
    bvh.name = name;
    bvh
}

/// A built structure of any kind.
#[derive(Debug)]
pub enum AnyAccel {
    None(Brute),
    Bvh(Bvh),
    Aabb(ObjectBoxes),
    Grid(Grid),
    KdTree(KdTree),
    SphereBvh(SphereBvh),
    Bvh8(WideBvh<8>),
    Bvh4(WideBvh<4>),
    Bvh8Q(WideBvh<8, QuantNode>),
}

macro_rules! dispatch {
    ($self:expr, $a:ident => $e:expr) => {
        match $self {
            AnyAccel::None($a) => $e,
            AnyAccel::Bvh($a) => $e,
            AnyAccel::Aabb($a) => $e,
            AnyAccel::Grid($a) => $e,
            AnyAccel::KdTree($a) => $e,
            AnyAccel::SphereBvh($a) => $e,
            AnyAccel::Bvh8($a) => $e,
            AnyAccel::Bvh4($a) => $e,
            AnyAccel::Bvh8Q($a) => $e,
        }
    };
}

impl AnyAccel {
    /// Builds the structure `kind` over `prims` and records the build time in its stats.
    pub fn build<P: Primitives + ?Sized>(kind: AccelKind, prims: &P, opts: &BuildOptions) -> Self {
        let start = Instant::now();
        let mut accel = match kind {
            AccelKind::None => AnyAccel::None(Brute::build(prims)),
            AccelKind::Bvh => AnyAccel::Bvh(binary_at_quality(prims, opts, "bvh")),
            AccelKind::BvhMedian => AnyAccel::Bvh(Bvh::build(prims, SplitMethod::Median, opts)),
            AccelKind::BvhMidpoint => AnyAccel::Bvh(Bvh::build(prims, SplitMethod::Midpoint, opts)),
            AccelKind::Aabb => AnyAccel::Aabb(ObjectBoxes::build(prims)),
            AccelKind::Grid => AnyAccel::Grid(Grid::build(prims, opts)),
            AccelKind::Lbvh => AnyAccel::Bvh(bvh::lbvh::build(prims, opts)),
            AccelKind::LbvhPloc => AnyAccel::Bvh(bvh::ploc::build(prims, opts)),
            AccelKind::KdTree => AnyAccel::KdTree(KdTree::build(prims, opts)),
            AccelKind::SphereBvh => AnyAccel::SphereBvh(SphereBvh::build(prims, opts)),
            AccelKind::Sbvh => AnyAccel::Bvh(bvh::sbvh::build(prims, opts)),
            AccelKind::Bvh8 => AnyAccel::Bvh8(WideBvh::from_binary(&binary_for_wide(prims, opts, "bvh"), prims, "bvh8")),
            AccelKind::Bvh4 => AnyAccel::Bvh4(WideBvh::from_binary(&binary_for_wide(prims, opts, "bvh"), prims, "bvh4")),
            AccelKind::Bvh8Sbvh => AnyAccel::Bvh8(WideBvh::from_binary(&bvh::sbvh::build(prims, opts), prims, "bvh8-sbvh")),
            AccelKind::Bvh8Q => AnyAccel::Bvh8Q(WideBvh::from_binary(&binary_for_wide(prims, opts, "bvh"), prims, "bvh8q")),
        };
        let ms = start.elapsed().as_secs_f64() * 1e3;
        dispatch!(&mut accel, a => a.build_ms = ms);
        accel
    }

    /// [`Accel::intersect`] without counters: wide BVHs run their non-counting build (the
    /// counters compiled out), other structures count into a scratch value.
    #[inline]
    pub fn intersect_fast<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray) -> Option<Hit> {
        match self {
            AnyAccel::Bvh8(a) => a.intersect_fast(prims, ray),
            AnyAccel::Bvh4(a) => a.intersect_fast(prims, ray),
            AnyAccel::Bvh8Q(a) => a.intersect_fast(prims, ray),
            a => a.intersect(prims, ray, &mut Counters::default()),
        }
    }

    /// [`Accel::occluded`] without counters (see [`AnyAccel::intersect_fast`]).
    #[inline]
    pub fn occluded_fast<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray) -> bool {
        match self {
            AnyAccel::Bvh8(a) => a.occluded_fast(prims, ray),
            AnyAccel::Bvh4(a) => a.occluded_fast(prims, ray),
            AnyAccel::Bvh8Q(a) => a.occluded_fast(prims, ray),
            a => a.occluded(prims, ray, &mut Counters::default()),
        }
    }

    /// Closest hits of a packet of at most [`PACKET`] rays (a 4×4 tile of camera rays):
    /// wide BVHs traverse the rays together, other structures one by one. `out[i]` is
    /// exactly [`AnyAccel::intersect_fast`] of `rays[i]`.
    ///
    /// # Panics
    /// If `rays` holds more than [`PACKET`] rays or `out` is not as long as `rays`.
    pub fn intersect_packet<P: Primitives + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert!(rays.len() <= PACKET && out.len() == rays.len(), "a packet holds at most {PACKET} rays and as many answers");
        match self {
            AnyAccel::Bvh8(a) => a.intersect_packet(prims, rays, out),
            AnyAccel::Bvh4(a) => a.intersect_packet(prims, rays, out),
            AnyAccel::Bvh8Q(a) => a.intersect_packet(prims, rays, out),
            a => {
                for (o, r) in out.iter_mut().zip(rays) {
                    *o = a.intersect_fast(prims, r);
                }
            }
        }
    }

    /// [`AnyAccel::intersect_packet`], counting as [`Accel::intersect`] does: wide BVHs
    /// charge each ray the nodes and triangle lanes it was active in (see `wide::packet`),
    /// other structures trace the rays one by one. The answers are the same.
    ///
    /// # Panics
    /// As [`AnyAccel::intersect_packet`].
    pub fn intersect_packet_counted<P: Primitives + ?Sized>(&self, prims: &P, rays: &[Ray], out: &mut [Option<Hit>], c: &mut Counters) {
        assert!(rays.len() <= PACKET && out.len() == rays.len(), "a packet holds at most {PACKET} rays and as many answers");
        match self {
            AnyAccel::Bvh8(a) => a.intersect_packet_counted(prims, rays, out, c),
            AnyAccel::Bvh4(a) => a.intersect_packet_counted(prims, rays, out, c),
            AnyAccel::Bvh8Q(a) => a.intersect_packet_counted(prims, rays, out, c),
            a => {
                for (o, r) in out.iter_mut().zip(rays) {
                    *o = a.intersect(prims, r, c);
                }
            }
        }
    }

    /// Whether [`AnyAccel::intersect_packet`] traverses rays together (wide BVHs) rather
    /// than one by one.
    pub fn has_packets(&self) -> bool {
        matches!(self, AnyAccel::Bvh8(_) | AnyAccel::Bvh4(_) | AnyAccel::Bvh8Q(_))
    }

    /// The kernel of a wide BVH; `None` for other structures.
    pub fn kernel(&self) -> Option<Kernel> {
        match self {
            AnyAccel::Bvh8(a) => Some(a.kernel()),
            AnyAccel::Bvh4(a) => Some(a.kernel()),
            AnyAccel::Bvh8Q(a) => Some(a.kernel()),
            _ => None,
        }
    }

    /// The packet kernel of a wide BVH; `None` for other structures.
    pub fn packet_kernel(&self) -> Option<Kernel> {
        match self {
            AnyAccel::Bvh8(a) => Some(a.packet_kernel()),
            AnyAccel::Bvh4(a) => Some(a.packet_kernel()),
            AnyAccel::Bvh8Q(a) => Some(a.packet_kernel()),
            _ => None,
        }
    }

    /// Forces the kernel of a wide BVH (no effect on other structures): tests compare the
    /// SIMD and portable kernels.
    pub fn with_kernel(self, k: Kernel) -> Self {
        match self {
            AnyAccel::Bvh8(a) => AnyAccel::Bvh8(a.with_kernel(k)),
            AnyAccel::Bvh4(a) => AnyAccel::Bvh4(a.with_kernel(k)),
            AnyAccel::Bvh8Q(a) => AnyAccel::Bvh8Q(a.with_kernel(k)),
            a => a,
        }
    }

    /// Sets whether the single rays of a wide BVH prefetch the children they enter and
    /// push (no effect on other structures).
    pub fn with_prefetch(self, p: Prefetch) -> Self {
        match self {
            AnyAccel::Bvh8(a) => AnyAccel::Bvh8(a.with_prefetch(p)),
            AnyAccel::Bvh4(a) => AnyAccel::Bvh4(a.with_prefetch(p)),
            AnyAccel::Bvh8Q(a) => AnyAccel::Bvh8Q(a.with_prefetch(p)),
            a => a,
        }
    }

    /// Whether single rays prefetch the children they enter and push; `None` for
    /// structures other than wide BVHs.
    pub fn prefetches_children(&self) -> Option<bool> {
        match self {
            AnyAccel::Bvh8(a) => Some(a.prefetches_children()),
            AnyAccel::Bvh4(a) => Some(a.prefetches_children()),
            AnyAccel::Bvh8Q(a) => Some(a.prefetches_children()),
            _ => None,
        }
    }
}

impl Accel for AnyAccel {
    #[inline]
    fn intersect<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, counters: &mut Counters) -> Option<Hit> {
        dispatch!(self, a => a.intersect(prims, ray, counters))
    }
    #[inline]
    fn occluded<P: Primitives + ?Sized>(&self, prims: &P, ray: &Ray, counters: &mut Counters) -> bool {
        dispatch!(self, a => a.occluded(prims, ray, counters))
    }
    fn stats(&self) -> AccelStats {
        dispatch!(self, a => a.stats())
    }
    fn validate<P: Primitives + ?Sized>(&self, prims: &P) -> Result<(), ValidationError> {
        dispatch!(self, a => a.validate(prims))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_lists_valid() {
        for k in AccelKind::ALL {
            assert_eq!(k.name().parse::<AccelKind>().unwrap(), *k);
        }
        let e = "octree".parse::<AccelKind>().unwrap_err();
        assert_eq!(e.to_string(), format!("unknown acceleration structure `octree` (valid: {})", AccelKind::names()));
    }

    /// The names, written out: the list the error message and `--help` show, and `Display`.
    #[test]
    fn names_by_hand() {
        let all = "none, bvh, bvh-median, bvh-midpoint, aabb, grid, lbvh, lbvh-ploc, kdtree, sphere-bvh, sbvh, bvh8, bvh4, bvh8-sbvh, bvh8q";
        assert_eq!(AccelKind::names(), all);
        let shown: Vec<String> = AccelKind::ALL.iter().map(|k| k.to_string()).collect();
        assert_eq!(shown.join(", "), all);
        assert_eq!(format!("[{}]", AccelKind::Bvh8Q), "[bvh8q]");
        assert_eq!("sphere-bvh".parse::<AccelKind>(), Ok(AccelKind::SphereBvh));
        assert_eq!("Bvh".parse::<AccelKind>(), Err(UnknownAccel("Bvh".into())));
    }

    /// The margins by hand (issue 12), on scenes whose values are exact in `f32`:
    /// - `[-1, 3]³`: extent 4, so the leaf margin is 4·2⁻¹⁸ = 2⁻¹⁶; the largest coordinate
    ///   3 lies in [2, 4), where an ulp is 2¹⁻²³ = 2⁻²², four of them 2⁻²⁰;
    /// - the same shape of size 20 shifted to 10⁶ (`[10⁶, 10⁶ + 20]`): leaf margin
    ///   20·2⁻¹⁸ = 5·2⁻¹⁶; 10⁶ + 20 lies in [2¹⁹, 2²⁰), an ulp of 2¹⁹⁻²³ = 1/16, four 1/4;
    /// - a point (extent 0): the leaf margin is the least normal number, not 0;
    /// - the empty scene: the least normal number for both.
    #[test]
    fn margins_by_hand() {
        let cube = Aabb::new(raylab_core::Vec3::splat(-1.0), raylab_core::Vec3::splat(3.0));
        assert_eq!(leaf_margin(&cube), 2f32.powi(-16));
        assert_eq!(robust_margin(&cube), 2f32.powi(-16) + 2f32.powi(-20));
        let far = Aabb::new(raylab_core::Vec3::new(1e6, 1e6, 1e6 + 5.0), raylab_core::Vec3::new(1e6 + 20.0, 1e6 + 10.0, 1e6 + 10.0));
        assert_eq!(leaf_margin(&far), 5.0 * 2f32.powi(-16));
        assert_eq!(robust_margin(&far), 5.0 * 2f32.powi(-16) + 0.25);
        // A negative coordinate counts by its magnitude: [-(10⁶ + 20), -10⁶] as above.
        let negative = Aabb::new(-far.max, -far.min);
        assert_eq!(robust_margin(&negative), 5.0 * 2f32.powi(-16) + 0.25);
        let point = Aabb::new(raylab_core::Vec3::splat(1.0), raylab_core::Vec3::splat(1.0));
        assert_eq!(leaf_margin(&point), f32::MIN_POSITIVE);
        // 1 lies in [1, 2): an ulp of 2⁻²³, four of them 2⁻²¹ (the least normal number
        // added to it is lost in rounding).
        assert_eq!(robust_margin(&point), 2f32.powi(-21));
        assert_eq!(leaf_margin(&Aabb::EMPTY), f32::MIN_POSITIVE);
        assert_eq!(robust_margin(&Aabb::EMPTY), f32::MIN_POSITIVE);
    }
}
