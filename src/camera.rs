//! The camera: which ray leaves through which point of the film.
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
//! where `forward`, `right` and `up` are the camera's orthonormal basis. An orthographic camera
//! (the [`Projection`]) sends every ray along `forward`, from the point
//!
//! ```text
//!   position + (2x/width − 1) · a · H/2 · right + (1 − 2y/height) · H/2 · up
//! ```
//!
//! of the plane through the eye, where `H` is the film's height in world units. Seen straight
//! along an axis, its rays have exact zero direction components (signed as the scene's `look_at −
//! position` gives them: `-0.0` stays `-0.0`), and with `H` and the film a power of two, pixel
//! centres fall exactly on the planes of boxes placed on them: the slab test's hardest cases.

use crate::math::{Ray, Vec2, Vec3};

/// How the film maps to rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Every ray leaves the eye; the vertical field of view in degrees, in (0, 180).
    Pinhole {
        /// Vertical field of view in degrees.
        fov_degrees: f32,
    },
    /// Parallel rays along the view direction, leaving the film plane through the eye.
    Orthographic {
        /// The film's height in world units.
        height: f32,
    },
}

/// A camera: a pinhole or an orthographic one.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    position: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// Half the film's height: `tan(fov / 2)` at unit distance (pinhole) or in world units.
    half_height: f32,
    orthographic: bool,
    width: u32,
    height: u32,
}

impl Camera {
    /// A pinhole camera at `position` looking at `look_at`, with `up` roughly up (it need not be
    /// perpendicular to the view direction, but must not be parallel to it), a vertical field of
    /// view of `fov_degrees`, and a film of `width × height` pixels.
    pub fn new(position: Vec3, look_at: Vec3, up: Vec3, fov_degrees: f32, width: u32, height: u32) -> Self {
        Self::with_projection(position, look_at, up, Projection::Pinhole { fov_degrees }, width, height)
    }

    /// A camera placed as in [`Camera::new`], with either projection.
    pub fn with_projection(
        position: Vec3,
        look_at: Vec3,
        up: Vec3,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Self {
        let forward = (look_at - position).normalize();
        let right = forward.cross(up).normalize();
        let (half_height, orthographic) = match projection {
            Projection::Pinhole { fov_degrees } => ((fov_degrees.to_radians() / 2.0).tan(), false),
            Projection::Orthographic { height } => (height / 2.0, true),
        };
        Self { position, forward, right, up: right.cross(forward), half_height, orthographic, width, height }
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
        let sx = (2.0 * film.x / self.width as f32 - 1.0) * aspect * self.half_height;
        let sy = (1.0 - 2.0 * film.y / self.height as f32) * self.half_height;
        if self.orthographic {
            Ray::new(self.position + sx * self.right + sy * self.up, self.forward)
        } else {
            Ray::new(self.position, self.forward + sx * self.right + sy * self.up)
        }
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
    fn orthographic_rays_are_parallel_and_start_on_the_film_plane() {
        // Film 4 units tall, 8 x 8 pixels: pixel (0, 0)'s centre is at (-1.75, 1.75) on the plane
        // z = 4, and with a power-of-two film the arithmetic is exact.
        let film = Projection::Orthographic { height: 4.0 };
        let cam = Camera::with_projection(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, film, 8, 8);
        let corner = cam.ray(Vec2::new(0.5, 0.5));
        assert_eq!(corner.origin, Vec3::new(-1.75, 1.75, 4.0));
        assert_eq!(corner.dir, -Vec3::Z);
        assert_eq!(cam.ray(Vec2::new(7.5, 4.5)).origin, Vec3::new(1.75, -0.25, 4.0));
    }

    #[test]
    fn an_axis_view_keeps_the_sign_of_its_zero_components() {
        let film = Projection::Orthographic { height: 2.0 };
        let cam =
            Camera::with_projection(Vec3::new(0.0, 0.0, 4.0), Vec3::new(-0.0, 0.0, 0.0), Vec3::Y, film, 4, 4);
        let dir = cam.ray(Vec2::new(1.5, 2.5)).dir;
        assert_eq!((dir.x.to_bits(), dir.y.to_bits()), ((-0.0f32).to_bits(), 0.0f32.to_bits()));
        assert_eq!(cam.ray(Vec2::new(1.5, 2.5)).inv_dir.x, f32::NEG_INFINITY);
    }

    #[test]
    fn up_need_not_be_perpendicular() {
        let cam = Camera::new(Vec3::ZERO, Vec3::new(0.0, -1.0, -1.0), Vec3::Y, 90.0, 10, 10);
        let top = cam.ray(Vec2::new(5.0, 0.0)).dir;
        assert!(top.y > cam.ray(Vec2::new(5.0, 10.0)).dir.y, "the top of the film looks higher");
        assert!(top.x.abs() < 1e-6);
    }
}
