//! The few declarations of Embree 3's C API (`/usr/include/embree3`, 3.13) that the peer
//! uses, written out by hand rather than generated: the layouts below follow
//! `rtcore_ray.h` and `rtcore_common.h` with `RTC_MAX_INSTANCE_LEVEL_COUNT = 1` and
//! `RTC_MIN_WIDTH = 0`, as Debian builds it (asserted at compile time).

#![allow(non_camel_case_types, dead_code)]

use std::ffi::{c_char, c_void};

pub type RTCDevice = *mut c_void;
pub type RTCScene = *mut c_void;
pub type RTCGeometry = *mut c_void;

pub const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;
pub const RTC_GEOMETRY_TYPE_TRIANGLE: i32 = 0;
pub const RTC_BUFFER_TYPE_INDEX: i32 = 0;
pub const RTC_BUFFER_TYPE_VERTEX: i32 = 1;
pub const RTC_FORMAT_UINT3: i32 = 0x5003;
pub const RTC_FORMAT_FLOAT3: i32 = 0x9003;
pub const RTC_BUILD_QUALITY_MEDIUM: i32 = 1;
pub const RTC_BUILD_QUALITY_HIGH: i32 = 2;
pub const RTC_SCENE_FLAG_ROBUST: i32 = 1 << 2;
pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: u32 = 0;
pub const RTC_INTERSECT_CONTEXT_FLAG_COHERENT: u32 = 1;
pub const RTC_ERROR_NONE: i32 = 0;

/// `struct RTCRay`: 16-byte aligned, 48 bytes.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    pub tfar: f32,
    pub mask: u32,
    pub id: u32,
    pub flags: u32,
}

/// `struct RTCHit`: 16-byte aligned, 32 bytes.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCHit {
    pub ng_x: f32,
    pub ng_y: f32,
    pub ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub prim_id: u32,
    pub geom_id: u32,
    pub inst_id: [u32; 1],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// `struct RTCRay16`: structure of arrays, 64-byte aligned.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct RTCRay16 {
    pub org_x: [f32; 16],
    pub org_y: [f32; 16],
    pub org_z: [f32; 16],
    pub tnear: [f32; 16],
    pub dir_x: [f32; 16],
    pub dir_y: [f32; 16],
    pub dir_z: [f32; 16],
    pub time: [f32; 16],
    pub tfar: [f32; 16],
    pub mask: [u32; 16],
    pub id: [u32; 16],
    pub flags: [u32; 16],
}

#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct RTCHit16 {
    pub ng_x: [f32; 16],
    pub ng_y: [f32; 16],
    pub ng_z: [f32; 16],
    pub u: [f32; 16],
    pub v: [f32; 16],
    pub prim_id: [u32; 16],
    pub geom_id: [u32; 16],
    pub inst_id: [[u32; 16]; 1],
}

#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCRayHit16 {
    pub ray: RTCRay16,
    pub hit: RTCHit16,
}

/// The valid mask of a 16-ray packet (-1 valid, 0 not), aligned like the packet.
#[repr(C, align(64))]
pub struct Valid16(pub [i32; 16]);

/// `struct RTCIntersectContext` (what `rtcInitIntersectContext`, an inline function of the
/// header, fills in: the flags, no filter, no instance).
#[repr(C)]
pub struct RTCIntersectContext {
    pub flags: u32,
    pub filter: *const c_void,
    pub inst_id: [u32; 1],
}

impl RTCIntersectContext {
    pub fn new(flags: u32) -> Self {
        Self { flags, filter: std::ptr::null(), inst_id: [RTC_INVALID_GEOMETRY_ID] }
    }
}

const _: () = {
    assert!(std::mem::size_of::<RTCRay>() == 48 && std::mem::align_of::<RTCRay>() == 16);
    assert!(std::mem::size_of::<RTCHit>() == 32);
    assert!(std::mem::size_of::<RTCRayHit>() == 80);
    assert!(std::mem::size_of::<RTCRay16>() == 12 * 64 && std::mem::align_of::<RTCRayHit16>() == 64);
    assert!(std::mem::size_of::<RTCHit16>() == 8 * 64);
    assert!(std::mem::size_of::<RTCIntersectContext>() == 24);
};

/// `bool (*RTCMemoryMonitorFunction)(void* ptr, ssize_t bytes, bool post)`.
pub type RTCMemoryMonitorFunction = extern "C" fn(user: *mut c_void, bytes: isize, post: bool) -> bool;

extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    pub fn rtcReleaseDevice(device: RTCDevice);
    pub fn rtcGetDeviceError(device: RTCDevice) -> i32;
    pub fn rtcSetDeviceMemoryMonitorFunction(device: RTCDevice, f: Option<RTCMemoryMonitorFunction>, user: *mut c_void);
    pub fn rtcNewScene(device: RTCDevice) -> RTCScene;
    pub fn rtcReleaseScene(scene: RTCScene);
    pub fn rtcSetSceneBuildQuality(scene: RTCScene, quality: i32);
    pub fn rtcSetSceneFlags(scene: RTCScene, flags: i32);
    pub fn rtcCommitScene(scene: RTCScene);
    pub fn rtcNewGeometry(device: RTCDevice, kind: i32) -> RTCGeometry;
    pub fn rtcReleaseGeometry(geometry: RTCGeometry);
    pub fn rtcSetGeometryBuildQuality(geometry: RTCGeometry, quality: i32);
    pub fn rtcSetNewGeometryBuffer(geometry: RTCGeometry, kind: i32, slot: u32, format: i32, byte_stride: usize, count: usize) -> *mut c_void;
    pub fn rtcCommitGeometry(geometry: RTCGeometry);
    pub fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> u32;
    pub fn rtcIntersect1(scene: RTCScene, context: *mut RTCIntersectContext, rayhit: *mut RTCRayHit);
    pub fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
    pub fn rtcIntersect16(valid: *const i32, scene: RTCScene, context: *mut RTCIntersectContext, rayhit: *mut RTCRayHit16);
}
