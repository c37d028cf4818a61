//! Embree 3 as the ray-query backend (feature `embree`; Debian's `libembree-dev`): the speed
//! reference that the default four-wide BVH is measured against (DESIGN.md section 2).
//!
//! The scene is one triangle geometry built with `RTC_SCENE_FLAG_ROBUST` (watertight triangle
//! tests, conservative boxes) and high build quality; Embree's `u`, `v` are the weights of the
//! second and third vertices, as tessera's `b1`, `b2`. Only the few C functions used are
//! declared here, from Embree 3.13's headers (`rtcore_*.h`). The wavefront's batches of bounce
//! and shadow rays go to Embree eight at a time, as packets (`rtcIntersect8`, `rtcOccluded8`):
//! 9% faster on scene A than one at a time.

#![allow(unsafe_code)]

use super::Hit;
use crate::geometry::Ray;
use glam::Vec3;
use std::ffi::c_void;

type RtcDevice = *mut c_void;
type RtcScene = *mut c_void;
type RtcGeometry = *mut c_void;

const RTC_GEOMETRY_TYPE_TRIANGLE: u32 = 0;
const RTC_BUFFER_TYPE_INDEX: u32 = 0;
const RTC_BUFFER_TYPE_VERTEX: u32 = 1;
const RTC_FORMAT_UINT3: u32 = 0x5003;
const RTC_FORMAT_FLOAT3: u32 = 0x9003;
const RTC_SCENE_FLAG_ROBUST: u32 = 1 << 2;
const RTC_BUILD_QUALITY_HIGH: u32 = 2;
const RTC_INVALID_GEOMETRY_ID: u32 = u32::MAX;
const RTC_ERROR_NONE: u32 = 0;

/// `struct RTCRay` (16-byte aligned).
#[repr(C, align(16))]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `struct RTCHit` (16-byte aligned, one instance level).
#[repr(C, align(16))]
struct RtcHit {
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    inst_id: [u32; 1],
}

/// `struct RTCRayHit`.
#[repr(C)]
struct RtcRayHit {
    ray: RtcRay,
    hit: RtcHit,
}

/// Rays in one packet query (`rtcIntersect8`, `rtcOccluded8`: AVX2's width).
pub(super) const PACKET: usize = 8;

/// `struct RTCRay8`: eight rays in structure-of-arrays form (32-byte aligned).
#[repr(C, align(32))]
struct RtcRay8 {
    org: [[f32; PACKET]; 3],
    tnear: [f32; PACKET],
    dir: [[f32; PACKET]; 3],
    time: [f32; PACKET],
    tfar: [f32; PACKET],
    mask: [u32; PACKET],
    id: [u32; PACKET],
    flags: [u32; PACKET],
}

/// `struct RTCHit8` (one instance level).
#[repr(C, align(32))]
struct RtcHit8 {
    ng: [[f32; PACKET]; 3],
    u: [f32; PACKET],
    v: [f32; PACKET],
    prim_id: [u32; PACKET],
    geom_id: [u32; PACKET],
    inst_id: [[u32; PACKET]; 1],
}

/// `struct RTCRayHit8`.
#[repr(C, align(32))]
struct RtcRayHit8 {
    ray: RtcRay8,
    hit: RtcHit8,
}

/// The `valid` mask of the packet calls: -1 for a lane that holds a ray, 0 for one that does
/// not (32-byte aligned).
#[repr(C, align(32))]
struct Valid8([i32; PACKET]);

/// `struct RTCIntersectContext` with one instance level and no minimum width.
#[repr(C)]
struct RtcIntersectContext {
    flags: u32,
    filter: Option<unsafe extern "C" fn(*const c_void)>,
    inst_id: [u32; 1],
}

impl RtcIntersectContext {
    /// `rtcInitIntersectContext` (an inline function of the header).
    fn new() -> Self {
        RtcIntersectContext { flags: 0, filter: None, inst_id: [RTC_INVALID_GEOMETRY_ID] }
    }
}

#[link(name = "embree3")]
unsafe extern "C" {
    fn rtcNewDevice(config: *const std::ffi::c_char) -> RtcDevice;
    fn rtcReleaseDevice(device: RtcDevice);
    fn rtcGetDeviceError(device: RtcDevice) -> u32;
    fn rtcNewScene(device: RtcDevice) -> RtcScene;
    fn rtcReleaseScene(scene: RtcScene);
    fn rtcSetSceneFlags(scene: RtcScene, flags: u32);
    fn rtcSetSceneBuildQuality(scene: RtcScene, quality: u32);
    fn rtcCommitScene(scene: RtcScene);
    fn rtcNewGeometry(device: RtcDevice, kind: u32) -> RtcGeometry;
    fn rtcSetNewGeometryBuffer(
        geometry: RtcGeometry,
        kind: u32,
        slot: u32,
        format: u32,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    fn rtcCommitGeometry(geometry: RtcGeometry);
    fn rtcAttachGeometry(scene: RtcScene, geometry: RtcGeometry) -> u32;
    fn rtcReleaseGeometry(geometry: RtcGeometry);
    fn rtcIntersect1(scene: RtcScene, context: *mut RtcIntersectContext, rayhit: *mut RtcRayHit);
    fn rtcOccluded1(scene: RtcScene, context: *mut RtcIntersectContext, ray: *mut RtcRay);
    fn rtcIntersect8(valid: *const Valid8, scene: RtcScene, context: *mut RtcIntersectContext, rayhit: *mut RtcRayHit8);
    fn rtcOccluded8(valid: *const Valid8, scene: RtcScene, context: *mut RtcIntersectContext, ray: *mut RtcRay8);
}

/// A committed Embree scene over a triangle soup.
pub(super) struct EmbreeScene {
    device: RtcDevice,
    scene: RtcScene,
}

// SAFETY: a committed Embree scene may be queried from any number of threads at once (Embree's
// documentation of rtcIntersect1 / rtcOccluded1); it is not modified after `build`.
unsafe impl Send for EmbreeScene {}
// SAFETY: as above; queries take `&self` and write only to their own ray structures.
unsafe impl Sync for EmbreeScene {}

impl EmbreeScene {
    /// Build over `triangles` (at least one), or say why Embree could not.
    pub(super) fn build(triangles: &[[Vec3; 3]]) -> Result<Self, String> {
        let n = triangles.len();
        // SAFETY: the buffers Embree returns hold `n` items of the stated strides, and are
        // filled before the geometry is committed; every handle is released once.
        unsafe {
            let device = rtcNewDevice(std::ptr::null());
            if device.is_null() {
                return Err("rtcNewDevice failed (is the CPU supported?)".into());
            }
            let scene = rtcNewScene(device);
            let embree = EmbreeScene { device, scene };
            rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
            rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
            let geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            let vertices = rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * n)
                .cast::<[f32; 3]>();
            let indices =
                rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n).cast::<[u32; 3]>();
            if vertices.is_null() || indices.is_null() {
                rtcReleaseGeometry(geometry);
                return Err(format!("Embree could not allocate {n} triangles"));
            }
            let vertices = std::slice::from_raw_parts_mut(vertices, 3 * n);
            let indices = std::slice::from_raw_parts_mut(indices, n);
            for (i, t) in triangles.iter().enumerate() {
                for (k, v) in t.iter().enumerate() {
                    vertices[3 * i + k] = v.to_array();
                }
                let first = 3 * i as u32;
                indices[i] = [first, first + 1, first + 2];
            }
            rtcCommitGeometry(geometry);
            rtcAttachGeometry(scene, geometry);
            rtcReleaseGeometry(geometry);
            rtcCommitScene(scene);
            match rtcGetDeviceError(device) {
                RTC_ERROR_NONE => Ok(embree),
                code => Err(format!("Embree error {code} building the scene")),
            }
        }
    }

    fn rtc_ray(ray: &Ray) -> RtcRay {
        RtcRay {
            org: ray.o.to_array(),
            tnear: 0.0,
            dir: ray.d.to_array(),
            time: 0.0,
            tfar: ray.t_max,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// The closest hit with `0 <= t <= ray.t_max` (Embree's interval is closed, tessera's open;
    /// offset ray origins keep the difference out of renders).
    pub(super) fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut context = RtcIntersectContext::new();
        let mut rayhit = RtcRayHit {
            ray: Self::rtc_ray(ray),
            hit: RtcHit {
                ng: [0.0; 3],
                u: 0.0,
                v: 0.0,
                prim_id: RTC_INVALID_GEOMETRY_ID,
                geom_id: RTC_INVALID_GEOMETRY_ID,
                inst_id: [RTC_INVALID_GEOMETRY_ID],
            },
        };
        // SAFETY: the scene is committed; context and rayhit are valid, aligned and exclusive.
        unsafe { rtcIntersect1(self.scene, &mut context, &mut rayhit) };
        let hit = &rayhit.hit;
        (hit.geom_id != RTC_INVALID_GEOMETRY_ID).then_some(Hit {
            t: rayhit.ray.tfar,
            primitive: hit.prim_id,
            b1: hit.u,
            b2: hit.v,
        })
    }

    /// Up to [`PACKET`] rays as one packet, and its `valid` mask.
    fn rtc_ray8(rays: &[Ray]) -> (RtcRay8, Valid8) {
        debug_assert!(rays.len() <= PACKET);
        let mut packet = RtcRay8 {
            org: [[0.0; PACKET]; 3],
            tnear: [0.0; PACKET],
            dir: [[0.0; PACKET]; 3],
            time: [0.0; PACKET],
            tfar: [0.0; PACKET],
            mask: [u32::MAX; PACKET],
            id: [0; PACKET],
            flags: [0; PACKET],
        };
        let mut valid = Valid8([0; PACKET]);
        for (lane, ray) in rays.iter().enumerate() {
            for axis in 0..3 {
                packet.org[axis][lane] = ray.o[axis];
                packet.dir[axis][lane] = ray.d[axis];
            }
            packet.tfar[lane] = ray.t_max;
            valid.0[lane] = -1;
        }
        (packet, valid)
    }

    /// [`EmbreeScene::intersect`] of up to [`PACKET`] rays, traced as one packet
    /// (`rtcIntersect8`), into `hits`.
    pub(super) fn intersect8(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        let (ray, valid) = Self::rtc_ray8(rays);
        let mut rayhit = RtcRayHit8 {
            ray,
            hit: RtcHit8 {
                ng: [[0.0; PACKET]; 3],
                u: [0.0; PACKET],
                v: [0.0; PACKET],
                prim_id: [RTC_INVALID_GEOMETRY_ID; PACKET],
                geom_id: [RTC_INVALID_GEOMETRY_ID; PACKET],
                inst_id: [[RTC_INVALID_GEOMETRY_ID; PACKET]],
            },
        };
        let mut context = RtcIntersectContext::new();
        // SAFETY: the scene is committed; valid, context and rayhit are valid, 32-byte aligned
        // and exclusive.
        unsafe { rtcIntersect8(&valid, self.scene, &mut context, &mut rayhit) };
        let hit = &rayhit.hit;
        for (lane, out) in hits.iter_mut().enumerate().take(rays.len()) {
            *out = (hit.geom_id[lane] != RTC_INVALID_GEOMETRY_ID).then_some(Hit {
                t: rayhit.ray.tfar[lane],
                primitive: hit.prim_id[lane],
                b1: hit.u[lane],
                b2: hit.v[lane],
            });
        }
    }

    /// [`EmbreeScene::occluded`] of up to [`PACKET`] rays, tested as one packet
    /// (`rtcOccluded8`), into `blocked`.
    pub(super) fn occluded8(&self, rays: &[Ray], blocked: &mut [bool]) {
        let (mut packet, valid) = Self::rtc_ray8(rays);
        let mut context = RtcIntersectContext::new();
        // SAFETY: as in `intersect8`.
        unsafe { rtcOccluded8(&valid, self.scene, &mut context, &mut packet) };
        for (lane, out) in blocked.iter_mut().enumerate().take(rays.len()) {
            *out = packet.tfar[lane] < 0.0;
        }
    }

    /// Whether anything lies on the ray with `0 <= t <= ray.t_max`.
    pub(super) fn occluded(&self, ray: &Ray) -> bool {
        let mut context = RtcIntersectContext::new();
        let mut r = Self::rtc_ray(ray);
        // SAFETY: as in `intersect`.
        unsafe { rtcOccluded1(self.scene, &mut context, &mut r) };
        // An occluded ray comes back with tfar = -inf.
        r.tfar < 0.0
    }
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: both handles are owned by this value and released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}
