//! The benchmark peer: the same mesh and rays through Intel Embree 3 (`--features peer-embree`).
//!
//! Embree is used as a library would be in a renderer: one triangle geometry, the default build
//! quality, single-ray queries `rtcIntersect1` / `rtcOccluded1` (no packets or streams, which is
//! what raylab traces too). The device is created with `threads=N`, so its build uses the same
//! number of threads as raylab's measurement; queries run on rayon's threads, like raylab's.

use std::ffi::CString;
use std::time::{Duration, Instant};

use embree::sys::{
    rtcAttachGeometry, rtcCommitGeometry, rtcCommitScene, rtcGetDeviceError, rtcIntersect1, rtcNewDevice,
    rtcNewGeometry, rtcNewScene, rtcOccluded1, rtcReleaseDevice, rtcReleaseGeometry, rtcReleaseScene,
    rtcSetNewGeometryBuffer, RTCDevice, RTCGeometry, RTCScene,
};
use embree::{BufferType, Error, Format, GeometryType, IntersectContext, RayHit};
use rayon::prelude::*;

use raylab::geometry::TriangleMesh;
use raylab::math::Ray;

/// A committed Embree scene over one triangle mesh.
pub struct EmbreeScene {
    device: RTCDevice,
    scene: RTCScene,
    /// Wall time of `rtcCommitScene` (the BVH build).
    pub build_time: Duration,
}

// Embree scenes are safe to query from many threads once committed (Embree's API docs), and
// this type allows nothing else.
unsafe impl Send for EmbreeScene {}
unsafe impl Sync for EmbreeScene {}

impl EmbreeScene {
    /// Builds Embree's BVH over `mesh` with `threads` build threads.
    pub fn new(mesh: &TriangleMesh, threads: usize) -> Result<Self, String> {
        let config = CString::new(format!("threads={threads}")).expect("no NUL in the config");
        // SAFETY: plain Embree 3 API calls in the documented order; every buffer is written
        // within the item count it was created with, and the handles are released in `Drop`.
        unsafe {
            let device = rtcNewDevice(config.as_ptr());
            if device.is_null() {
                return Err("Embree: rtcNewDevice failed".into());
            }
            let geometry = rtcNewGeometry(device, GeometryType::TRIANGLE);
            let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
            let filled = fill_buffer(geometry, BufferType::VERTEX, Format::FLOAT3, &positions)
                .and_then(|()| fill_buffer(geometry, BufferType::INDEX, Format::UINT3, &mesh.indices));
            if let Err(e) = filled {
                rtcReleaseGeometry(geometry);
                rtcReleaseDevice(device);
                return Err(e);
            }
            rtcCommitGeometry(geometry);
            let scene = rtcNewScene(device);
            rtcAttachGeometry(scene, geometry);
            rtcReleaseGeometry(geometry);
            let start = Instant::now();
            rtcCommitScene(scene);
            let build_time = start.elapsed();
            let error = rtcGetDeviceError(device);
            let scene = Self { device, scene, build_time };
            if error != Error::NONE {
                return Err(format!("Embree: error {error:?} while building"));
            }
            Ok(scene)
        }
    }

    /// Traces `rays` (closest hit, or any hit) in the current rayon pool; returns the number of
    /// hits and the wall time.
    pub fn trace(&self, rays: &[Ray], any_hit: bool) -> (usize, Duration) {
        let start = Instant::now();
        let hits =
            rays.par_chunks(4096).map(|chunk| chunk.iter().filter(|r| self.hit(r, any_hit)).count()).sum();
        (hits, start.elapsed())
    }

    fn hit(&self, ray: &Ray, any_hit: bool) -> bool {
        let mut context = IntersectContext::incoherent();
        let mut query = embree::Ray {
            org_x: ray.origin.x,
            org_y: ray.origin.y,
            org_z: ray.origin.z,
            dir_x: ray.dir.x,
            dir_y: ray.dir.y,
            dir_z: ray.dir.z,
            tnear: ray.t_min,
            tfar: ray.t_max,
            time: 0.0,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        };
        // SAFETY: the scene is committed; the context and ray are valid for the call.
        unsafe {
            if any_hit {
                rtcOccluded1(self.scene, &mut context, &mut query);
                // Embree marks an occluded ray by setting tfar to -inf.
                query.tfar < 0.0
            } else {
                let mut rayhit = RayHit::new(query);
                rtcIntersect1(self.scene, &mut context, &mut rayhit);
                rayhit.hit.hit()
            }
        }
    }
}

/// Gives `geometry` a new buffer of `items` (three 4-byte values each) and copies them in.
///
/// # Safety
/// `geometry` must be a live Embree geometry handle.
unsafe fn fill_buffer<T: Copy>(
    geometry: RTCGeometry,
    kind: BufferType,
    format: Format,
    items: &[T],
) -> Result<(), String> {
    debug_assert_eq!(std::mem::size_of::<T>(), 12);
    let buffer = rtcSetNewGeometryBuffer(geometry, kind, 0, format, 12, items.len()) as *mut T;
    if buffer.is_null() {
        return Err(format!("Embree: could not allocate a {kind:?} buffer"));
    }
    std::ptr::copy_nonoverlapping(items.as_ptr(), buffer, items.len());
    Ok(())
}

impl Drop for EmbreeScene {
    fn drop(&mut self) {
        // SAFETY: the handles were created in `new` and are released once.
        unsafe {
            rtcReleaseScene(self.scene);
            rtcReleaseDevice(self.device);
        }
    }
}
