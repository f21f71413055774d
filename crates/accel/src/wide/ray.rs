//! The per-ray constants of the kernels, computed once per ray before a walk: the slab
//! test's ([`RayBoxes`]) and the triangle test's ([`BlockRay`], from the watertight test's
//! [`ShearedRay`]).

use raylab_core::intersect::ShearedRay;
use raylab_core::{gamma, Ray};

/// Far distances are scaled by `1 + 2γ₃` so that rounding never misses a box (pbrt-v4
/// §6.8.2), as `Aabb::intersect` does.
pub const ROBUST_FAR: f32 = 1.0 + 2.0 * gamma(3);

/// Per-ray constants of the slab test.
///
/// The slab distances are computed as `(bound - origin) * inv_dir`, exactly as
/// `Aabb::intersect` does, not as `bound * inv_dir - origin * inv_dir` with the product
/// precomputed: that form (one FMA per slab in Embree) cancels catastrophically near the
/// origin, where rays leaving a surface need the box test most, and with a zero direction
/// component it computes `∞ - ∞`. One subtraction more per slab keeps pbrt's error bound.
/// The far distances' widening by [`ROBUST_FAR`] is folded into their inverse
/// (`inv_far`): the product `(bound - origin) · (inv · R)` carries the same four roundings
/// as `((bound - origin) · inv) · R`, so the same bound, for one multiplication less.
///
/// The eight (or four) boxes' entry and exit distances are reduced over the three axes in
/// integer order ([`boxes_portable`](super::kernels::boxes_portable)): on a chain that every node visit waits for, a
/// vector integer `max` takes one cycle where a float `max` takes four.
#[derive(Clone, Copy, Debug)]
pub struct RayBoxes {
    pub origin: [f32; 3],
    pub inv: [f32; 3],
    /// `inv · ROBUST_FAR`.
    pub inv_far: [f32; 3],
    /// Row of [`WideNode::bounds`](super::node::WideNode::bounds) giving the near (entry) plane of each axis: the min row
    /// when the direction is positive, the max row when it is negative. This sorts the
    /// slab distances once per ray instead of once per box.
    pub near: [usize; 3],
    pub far: [usize; 3],
    /// `t_min`, with `-0` made `+0`.
    pub t_min: f32,
    /// Whether the slab distances are reduced in integer order ([`boxes_portable`](super::kernels::boxes_portable)): the
    /// ray starts at `t_min >= 0` and no distance can be NaN (a finite inverse direction;
    /// a valid ray's origin is finite). Rays along an axis or reaching behind their origin
    /// take the float test.
    pub by_bits: bool,
}

impl RayBoxes {
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let inv = ray.inv_dir().to_array();
        // Written without branches: a ray's direction signs are as good as random.
        let neg = inv.map(|i| usize::from(i < 0.0));
        let near = [0, 1, 2].map(|a| a + 3 * neg[a]);
        let far = [0, 1, 2].map(|a| a + 3 - 3 * neg[a]);
        // `-0 + 0 = +0`; every other value is unchanged.
        let t_min = ray.t_min + 0.0;
        let by_bits = (t_min >= 0.0) & inv[0].is_finite() & inv[1].is_finite() & inv[2].is_finite();
        Self { origin: ray.origin.to_array(), inv, inv_far: inv.map(|i| i * ROBUST_FAR), near, far, t_min, by_bits }
    }
}

/// A [`ShearedRay`]'s constants in the order the block test reads them, picked once per
/// ray: the origin's components along the shear axes `kx`, `ky`, `kz`, the shear, and the
/// axes. (Picking `origin[kx]` per block took about a fifth of a missed block's
/// instructions: a run-time index into a `Vec3` is a chain of branches.)
#[derive(Clone, Copy, Debug)]
pub struct BlockRay {
    pub origin: [f32; 3],
    pub shear: [f32; 3],
    pub axes: [usize; 3],
}

impl BlockRay {
    #[inline(always)]
    pub fn new(s: &ShearedRay) -> Self {
        let o: &[f32; 3] = s.origin.as_ref();
        Self { origin: [o[s.kx], o[s.ky], o[s.kz]], shear: [s.sx, s.sy, s.sz], axes: [s.kx, s.ky, s.kz] }
    }
}
