//! The three fixed ray workloads, defined so that any engine can trace exactly the same rays.
//!
//! - **primary**: a pinhole at `(0, 0, 3.2)` looking at the origin, up `+y`, 40° vertical field
//!   of view, 1024 × 1024 pixels, one ray through each pixel centre, row-major from the top-left
//!   ([`raylab::camera::Camera`] with its film convention).
//! - **incoherent**: 2^20 rays; ray `k` takes its origin uniformly on the sphere of radius 3 and
//!   aims at a point uniform in the unit ball, both drawn from PCG32 ([`raylab::rng::Rng`]) seeded
//!   with [`INCOHERENT_SEED`] on stream `k`. Closest hit in `(0, ∞)`.
//! - **shadow**: the incoherent rays as any-hit queries.

use std::f32::consts::TAU;
use std::fmt;

use raylab::camera::Camera;
use raylab::math::{Ray, Vec2, Vec3};
use raylab::rng::Rng;

/// Seed of the incoherent rays.
pub const INCOHERENT_SEED: u64 = 2026;

/// Side of the primary workload's square film, in pixels.
pub const PRIMARY_RESOLUTION: u32 = 1024;

/// Number of incoherent (and shadow) rays.
pub const INCOHERENT_RAYS: usize = 1 << 20;

/// Which rays to trace, and as which query.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Workload {
    /// Camera rays through pixel centres: coherent, closest hit.
    Primary,
    /// Rays between random points: incoherent, closest hit.
    Incoherent,
    /// The incoherent rays as any-hit (shadow) queries.
    Shadow,
}

impl Workload {
    /// Every workload, in the order reports list them.
    pub const ALL: [Workload; 3] = [Workload::Primary, Workload::Incoherent, Workload::Shadow];

    /// The workload's rays.
    pub fn rays(self) -> Vec<Ray> {
        match self {
            Workload::Primary => primary_rays(),
            Workload::Incoherent | Workload::Shadow => incoherent_rays(),
        }
    }

    /// Whether the rays are any-hit queries.
    pub fn any_hit(self) -> bool {
        self == Workload::Shadow
    }
}

impl fmt::Display for Workload {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Workload::Primary => "primary",
            Workload::Incoherent => "incoherent",
            Workload::Shadow => "shadow",
        })
    }
}

fn primary_rays() -> Vec<Ray> {
    let n = PRIMARY_RESOLUTION;
    let camera = Camera::new(Vec3::new(0.0, 0.0, 3.2), Vec3::ZERO, Vec3::Y, 40.0, n, n);
    let pixel = |k: u32| Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
    (0..n * n).map(|k| camera.ray(pixel(k))).collect()
}

fn incoherent_rays() -> Vec<Ray> {
    (0..INCOHERENT_RAYS as u64)
        .map(|k| {
            let mut rng = Rng::new(INCOHERENT_SEED, k);
            let origin = 3.0 * uniform_on_sphere(&mut rng);
            let target = uniform_in_ball(&mut rng);
            Ray::new(origin, target - origin)
        })
        .collect()
}

/// Uniform on the unit sphere: `z` uniform in `[-1, 1]` (Archimedes), azimuth uniform.
fn uniform_on_sphere(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let phi = TAU * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform in the unit ball, by rejection from the cube `[-1, 1]³`.
fn uniform_in_ball(rng: &mut Rng) -> Vec3 {
    loop {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
        if p.length_squared() <= 1.0 {
            return p;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primary_rays_start_at_the_camera_and_the_middle_one_looks_at_the_origin() {
        let rays = primary_rays();
        assert_eq!(rays.len(), 1 << 20);
        assert!(rays.iter().all(|r| r.origin == Vec3::new(0.0, 0.0, 3.2)));
        // Pixel (512, 512) has its centre half a pixel right of and below the film centre.
        let middle = rays[512 * 1024 + 512].dir;
        let half_pixel = (20f32.to_radians().tan()) / 1024.0;
        assert!((middle - Vec3::new(half_pixel, -half_pixel, -1.0).normalize()).length() < 1e-6);
        // The top-left ray leans left and up by the half field of view (less half a pixel).
        let top_left = rays[0].dir;
        assert!(top_left.x < 0.0 && top_left.y > 0.0);
        assert!((top_left.y / -top_left.z - (20f32.to_radians().tan() - half_pixel)).abs() < 1e-5);
    }

    #[test]
    fn incoherent_rays_start_on_the_radius_3_sphere_and_pass_through_the_unit_ball() {
        let rays = incoherent_rays();
        assert_eq!(rays.len(), INCOHERENT_RAYS);
        for ray in rays.iter().step_by(97) {
            assert!((ray.origin.length() - 3.0).abs() < 1e-5, "{ray:?}");
            // The closest approach to the origin is at most 1: the target is in the unit ball.
            let closest = ray.origin - ray.origin.dot(ray.dir) * ray.dir;
            assert!(closest.length() <= 1.0 + 1e-5, "{ray:?}");
        }
        // Uniform origins: the mean is near 0 (standard error 3 / sqrt(3 · 2^20) per axis).
        let mean = rays.iter().map(|r| r.origin).sum::<Vec3>() / rays.len() as f32;
        assert!(mean.abs().max_element() < 5.0 * 3.0 / (3.0 * rays.len() as f32).sqrt(), "{mean}");
    }
}
