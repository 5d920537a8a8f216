//! The pinhole camera: which ray leaves through which point of the film.
//!
//! Film coordinates are in pixels: `x` from 0 at the left edge to `width` at the right, `y` from 0
//! at the top to `height` at the bottom, so pixel `(i, j)` covers `[i, i+1) × [j, j+1)` and its
//! centre is `(i + 0.5, j + 0.5)`. The vertical field of view spans the film's height; pixels are
//! square. With `h = tan(fov / 2)` and aspect `a = width / height`, the film point `(x, y)` looks
//! along
//!
//! ```text
//!   forward + (2x/width − 1) · a · h · right + (1 − 2y/height) · h · up
//! ```
//!
//! where `forward`, `right` and `up` are the camera's orthonormal basis.

use crate::math::{Ray, Vec2, Vec3};

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half_fov: f32,
    width: u32,
    height: u32,
}

impl Camera {
    /// A camera at `position` looking at `look_at`, with `up` roughly up (it need not be
    /// perpendicular to the view direction, but must not be parallel to it), a vertical field of
    /// view of `fov_degrees`, and a film of `width × height` pixels.
    pub fn new(position: Vec3, look_at: Vec3, up: Vec3, fov_degrees: f32, width: u32, height: u32) -> Self {
        let forward = (look_at - position).normalize();
        let right = forward.cross(up).normalize();
        Self {
            position,
            forward,
            right,
            up: right.cross(forward),
            tan_half_fov: (fov_degrees.to_radians() / 2.0).tan(),
            width,
            height,
        }
    }

    /// Film width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Film height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The same camera with a film of `width × height` pixels (the vertical field of view kept).
    pub fn with_resolution(&self, width: u32, height: u32) -> Self {
        Self { width, height, ..self.clone() }
    }

    /// The ray through the film point `film` (in pixels, see the module docs).
    pub fn ray(&self, film: Vec2) -> Ray {
        let aspect = self.width as f32 / self.height as f32;
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * aspect * self.tan_half_fov;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.tan_half_fov;
        Ray::new(self.position, self.forward + sx * self.right + sy * self.up)
    }
}

#[cfg(test)]
mod checkpoint1 {
    use super::*;

    #[track_caller]
    fn assert_dir(got: Vec3, want: Vec3) {
        assert!((got - want.normalize()).length() < 1e-6, "{got} vs {want}");
    }

    #[test]
    fn the_film_centre_looks_at_the_target() {
        let cam = Camera::new(Vec3::new(0.0, 1.0, 6.8), Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 19.5, 512, 512);
        let ray = cam.ray(Vec2::new(256.0, 256.0));
        assert_eq!(ray.origin, Vec3::new(0.0, 1.0, 6.8));
        assert_dir(ray.dir, -Vec3::Z);
    }

    #[test]
    fn the_corners_span_the_field_of_view() {
        // fov 90 degrees: tan(45°) = 1, so with a 2:1 film the corners are at (±2, ±1, -1).
        let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 90.0, 200, 100);
        assert_dir(cam.ray(Vec2::new(0.0, 0.0)).dir, Vec3::new(-2.0, 1.0, -1.0));
        assert_dir(cam.ray(Vec2::new(200.0, 0.0)).dir, Vec3::new(2.0, 1.0, -1.0));
        assert_dir(cam.ray(Vec2::new(0.0, 100.0)).dir, Vec3::new(-2.0, -1.0, -1.0));
        assert_dir(cam.ray(Vec2::new(200.0, 100.0)).dir, Vec3::new(2.0, -1.0, -1.0));
    }

    #[test]
    fn pixel_centres_are_half_a_pixel_in() {
        // Pixel (0, 0) of a 4x4 film with fov 90: its centre is at film (0.5, 0.5), i.e. at
        // screen (-0.75, 0.75) on the plane z = -1.
        let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 90.0, 4, 4);
        assert_dir(cam.ray(Vec2::new(0.5, 0.5)).dir, Vec3::new(-0.75, 0.75, -1.0));
    }

    #[test]
    fn up_need_not_be_perpendicular() {
        let cam = Camera::new(Vec3::ZERO, Vec3::new(0.0, -1.0, -1.0), Vec3::Y, 90.0, 10, 10);
        let top = cam.ray(Vec2::new(5.0, 0.0)).dir;
        assert!(top.y > cam.ray(Vec2::new(5.0, 10.0)).dir.y, "the top of the film looks higher");
        assert!(top.x.abs() < 1e-6);
    }
}
