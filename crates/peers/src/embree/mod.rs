//! Intel Embree 3 (Debian's `libembree-dev`) through the hand-written FFI of [`ffi`]: one
//! device per structure configured with `threads=N` (and what `RAYLAB_EMBREE_CONFIG` adds), one triangle-mesh geometry with an
//! indexed vertex buffer (shared vertices merged, as an application hands Embree a mesh),
//! the scene built at quality HIGH (spatial splits) or MEDIUM, and at HIGH with the scene
//! flag `RTC_SCENE_FLAG_ROBUST` (box tests that rounding cannot make miss and watertight
//! triangle tests: the guarantees raylab's kernels give, at their price). Rays are traced with
//! `rtcIntersect1` / `rtcOccluded1` from raylab's rayon workers, and primary packets with
//! `rtcIntersect16`. Memory is what Embree's memory monitor reports as held after the
//! build: its BVH, its triangle leaves and the buffers it keeps.

mod ffi;

use std::collections::HashMap;
use std::ffi::{c_void, CString};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::time::Instant;

use raylab_core::{Ray, Vec3};

use crate::{Peer, PeerError, PeerHit, PACKET};
use ffi::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quality {
    High,
    Medium,
    /// HIGH with `RTC_SCENE_FLAG_ROBUST`.
    HighRobust,
}

pub struct EmbreePeer {
    device: RTCDevice,
    scene: RTCScene,
    quality: Quality,
    build_ms: f64,
    /// Bytes Embree holds, counted by its memory monitor (boxed: Embree keeps the pointer).
    bytes: Box<AtomicIsize>,
}

// SAFETY: a committed Embree scene may be traced from any number of threads at once (the
// rtcIntersect*/rtcOccluded* calls are documented thread-safe); nothing mutates it after
// the build, and the device and scene are released only on drop.
unsafe impl Send for EmbreePeer {}
unsafe impl Sync for EmbreePeer {}

extern "C" fn monitor(user: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user` is the `AtomicIsize` boxed in the peer, which outlives the device.
    unsafe { &*(user as *const AtomicIsize) }.fetch_add(bytes, Ordering::Relaxed);
    true
}

fn check(device: RTCDevice, what: &str) -> Result<(), PeerError> {
    // SAFETY: `device` is a live device.
    match unsafe { rtcGetDeviceError(device) } {
        RTC_ERROR_NONE => Ok(()),
        e => Err(PeerError::Embree(format!("{what} failed with RTCError {e}"))),
    }
}

/// An indexed mesh from a triangle soup: vertices merged by their exact bits.
fn indexed(tris: &[[Vec3; 3]]) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(tris.len());
    let mut vertices = Vec::with_capacity(tris.len());
    let indices = tris
        .iter()
        .map(|t| {
            t.map(|p| {
                *ids.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
                    vertices.push(p.to_array());
                    vertices.len() as u32 - 1
                })
            })
        })
        .collect();
    (vertices, indices)
}

impl EmbreePeer {
    /// Builds the scene; the build time counts copying the mesh into Embree's buffers and
    /// the commit (merging the soup's vertices is raylab's side and is not counted).
    pub fn build(tris: &[[Vec3; 3]], threads: usize, quality: Quality) -> Result<Self, PeerError> {
        let (vertices, indices) = indexed(tris);
        // `RAYLAB_EMBREE_CONFIG` adds to the device's configuration: `verbose=2` prints
        // Embree's own statistics of each build (SAH cost, nodes, fill) and its kernels.
        let extra = std::env::var("RAYLAB_EMBREE_CONFIG").map(|c| format!(",{c}")).unwrap_or_default();
        let config = CString::new(format!("threads={threads}{extra}")).map_err(|_| PeerError::Embree("RAYLAB_EMBREE_CONFIG holds a NUL byte".into()))?;
        // SAFETY: plain calls of Embree's C API on the objects created here, in the
        // documented order; buffers are written within the sizes Embree allocated.
        unsafe {
            let device = rtcNewDevice(config.as_ptr());
            if device.is_null() {
                return Err(PeerError::Embree("rtcNewDevice returned no device".into()));
            }
            let bytes = Box::new(AtomicIsize::new(0));
            rtcSetDeviceMemoryMonitorFunction(device, Some(monitor), &*bytes as *const AtomicIsize as *mut c_void);
            let mut peer = Self { device, scene: std::ptr::null_mut(), quality, build_ms: 0.0, bytes };
            let q = match quality {
                Quality::High | Quality::HighRobust => RTC_BUILD_QUALITY_HIGH,
                Quality::Medium => RTC_BUILD_QUALITY_MEDIUM,
            };
            let start = Instant::now();
            peer.scene = rtcNewScene(device);
            rtcSetSceneBuildQuality(peer.scene, q);
            if quality == Quality::HighRobust {
                rtcSetSceneFlags(peer.scene, RTC_SCENE_FLAG_ROBUST);
            }
            let geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(geometry, q);
            let v = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, vertices.len()) as *mut [f32; 3];
            let i = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, indices.len()) as *mut [u32; 3];
            check(device, "rtcSetNewGeometryBuffer")?;
            std::ptr::copy_nonoverlapping(vertices.as_ptr(), v, vertices.len());
            std::ptr::copy_nonoverlapping(indices.as_ptr(), i, indices.len());
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(peer.scene, geometry);
            rtcReleaseGeometry(geometry);
            rtcCommitScene(peer.scene);
            peer.build_ms = start.elapsed().as_secs_f64() * 1e3;
            check(device, "rtcCommitScene")?;
            Ok(peer)
        }
    }
}

impl Drop for EmbreePeer {
    fn drop(&mut self) {
        // SAFETY: released once, the scene before its device.
        unsafe {
            if !self.scene.is_null() {
                rtcReleaseScene(self.scene);
            }
            rtcReleaseDevice(self.device);
        }
    }
}

fn rtc_ray(r: &Ray) -> RTCRay {
    RTCRay { org_x: r.origin.x, org_y: r.origin.y, org_z: r.origin.z, tnear: r.t_min, dir_x: r.dir.x, dir_y: r.dir.y, dir_z: r.dir.z, time: 0.0, tfar: r.t_max, mask: u32::MAX, id: 0, flags: 0 }
}

impl Peer for EmbreePeer {
    fn name(&self) -> String {
        match self.quality {
            Quality::High => "embree high".into(),
            Quality::Medium => "embree medium".into(),
            Quality::HighRobust => "embree high robust".into(),
        }
    }
    fn build_ms(&self) -> f64 {
        self.build_ms
    }
    fn memory_bytes(&self) -> usize {
        self.bytes.load(Ordering::Relaxed).max(0) as usize
    }
    fn intersect(&self, ray: &Ray) -> Option<PeerHit> {
        let mut rh = RTCRayHit { ray: rtc_ray(ray), hit: RTCHit { geom_id: RTC_INVALID_GEOMETRY_ID, inst_id: [RTC_INVALID_GEOMETRY_ID], ..Default::default() } };
        let mut ctx = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
        // SAFETY: a committed scene; `ctx` and `rh` are properly aligned and initialised.
        unsafe { rtcIntersect1(self.scene, &mut ctx, &mut rh) };
        (rh.hit.geom_id != RTC_INVALID_GEOMETRY_ID).then_some(PeerHit { t: rh.ray.tfar, prim: rh.hit.prim_id })
    }
    fn occluded(&self, ray: &Ray) -> bool {
        let mut r = rtc_ray(ray);
        let mut ctx = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
        // SAFETY: as for `intersect`; Embree sets `tfar` to -∞ on a hit.
        unsafe { rtcOccluded1(self.scene, &mut ctx, &mut r) };
        r.tfar == f32::NEG_INFINITY
    }
    fn intersect16(&self, rays: &[Ray], out: &mut [Option<PeerHit>]) {
        assert!(rays.len() <= PACKET && out.len() == rays.len());
        let mut valid = Valid16([0; 16]);
        // SAFETY: all-zero bits are valid for these plain arrays of numbers.
        let mut p: RTCRayHit16 = unsafe { std::mem::zeroed() };
        for (k, r) in rays.iter().enumerate() {
            valid.0[k] = -1;
            (p.ray.org_x[k], p.ray.org_y[k], p.ray.org_z[k]) = (r.origin.x, r.origin.y, r.origin.z);
            (p.ray.dir_x[k], p.ray.dir_y[k], p.ray.dir_z[k]) = (r.dir.x, r.dir.y, r.dir.z);
            (p.ray.tnear[k], p.ray.tfar[k], p.ray.mask[k]) = (r.t_min, r.t_max, u32::MAX);
            p.hit.geom_id[k] = RTC_INVALID_GEOMETRY_ID;
            p.hit.inst_id[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        let mut ctx = RTCIntersectContext::new(RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
        // SAFETY: `valid` and `p` are 64-byte aligned as rtcIntersect16 requires.
        unsafe { rtcIntersect16(valid.0.as_ptr(), self.scene, &mut ctx, &mut p) };
        for (k, o) in out.iter_mut().enumerate() {
            *o = (p.hit.geom_id[k] != RTC_INVALID_GEOMETRY_ID).then_some(PeerHit { t: p.ray.tfar[k], prim: p.hit.prim_id[k] });
        }
    }
    fn has_packets(&self) -> bool {
        true
    }
}
