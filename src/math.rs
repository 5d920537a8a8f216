//! Rays and the conventions every checkpoint shares.
//!
//! The checkpoint headers link here for what they share: read this once and the rest of raylab
//! follows it.
//!
//! # Conventions
//! - **Units and colour.** Positions in scene units, radiance in linear RGB (`Vec3`, f32). sRGB
//!   encoding happens once, when a film is written ([`crate::image_io`]).
//! - **Rays.** `r(t) = origin + t · dir` with `dir` of unit length. The valid part of a ray is the
//!   *open* interval `(t_min, t_max)`: a hit at exactly `t_min` or `t_max` does not count.
//! - **Directions at a surface.** `wo` and `wi` both point *away* from the surface point: `wo`
//!   toward where the ray came from (`wo = -ray.dir`), `wi` toward where light arrives from or
//!   the path continues.
//! - **Normals.** A triangle's geometric normal is `normalize((p1 - p0) × (p2 - p0))`. Closed meshes
//!   are wound counter-clockwise seen from outside, so that normal points *outward*.
//!   Shading flips it toward the viewer; glass uses its outward direction to tell entering from
//!   leaving.
//! - **Triangles are two-sided.** No back-face culling: a ray leaving a glass sphere must hit it.
//! - **Relative index of refraction.** `eta = eta_i / eta_t`, incident side over transmitted side.
//!   Entering glass of index 1.5 from air: `eta = 1 / 1.5`.
//! - **Secondary rays** start with [`spawn_ray`] or [`spawn_ray_to`], which move the origin off the
//!   surface along the geometric normal to the side the new ray leaves toward. No other code
//!   offsets rays or picks an epsilon of its own.

pub use glam::{Mat3, Mat4, UVec2, Vec2, Vec3};

/// A ray `origin + t · dir`, valid for `t` in the open interval `(t_min, t_max)`.
///
/// `inv_dir` is `1 / dir` per component, kept so the slab test (checkpoint 3) needs no division.
/// A zero component gives an infinite inverse with the sign of that zero, which the slab test
/// relies on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Component-wise `1 / dir`.
    pub inv_dir: Vec3,
    /// Hits must have `t > t_min`.
    pub t_min: f32,
    /// Hits must have `t < t_max`; closest-hit searches shrink it as they find hits.
    pub t_max: f32,
}

impl Ray {
    /// A ray from `origin` along `dir` (normalized here), valid for `t` in `(0, ∞)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::segment(origin, dir, f32::INFINITY)
    }

    /// A ray from `origin` along `dir` (normalized here), valid for `t` in `(0, t_max)`.
    pub fn segment(origin: Vec3, dir: Vec3, t_max: f32) -> Self {
        let dir = dir.normalize();
        debug_assert!(dir.is_finite(), "ray direction must be non-zero and finite");
        Self { origin, dir, inv_dir: dir.recip(), t_min: 0.0, t_max }
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// Mirror reflection of `wo` about the unit normal `n`: `2 (n · wo) n − wo`.
///
/// Both `wo` and the result point away from the surface, on the same side of it as each other.
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    debug_assert_unit(n, "reflect's normal");
    2.0 * n.dot(wo) * n - wo
}

/// Checks, in debug builds, that `v` has unit length, as the doc of the function that takes it
/// as `what` says: a caller's contract, checked where the function starts (outside any student
/// region, so a stub or a student's body keeps the check).
#[track_caller]
pub fn debug_assert_unit(v: Vec3, what: &str) {
    debug_assert!(v.is_normalized(), "{what} must have unit length, got {v} (length {})", v.length());
}

/// How far [`spawn_ray`] moves an origin off a surface, for a point `p`.
///
/// An f32 intersection point carries a rounding error of a few units in the last place of its
/// largest coordinate (about 6e-8 relative each). Moving `1e-4 · (1 + max |p_i|)` along the
/// normal clears that error by three orders of magnitude, while staying far below a pixel's
/// footprint in our scenes (about 5e-3 scene units at 512 px across a 2-unit Cornell box).
fn offset_distance(p: Vec3) -> f32 {
    const RELATIVE_OFFSET: f32 = 1e-4;
    RELATIVE_OFFSET * (1.0 + p.abs().max_element())
}

/// The point `p` moved off its surface (geometric normal `n`) to the side `dir` points to.
fn offset_origin(p: Vec3, n: Vec3, dir: Vec3) -> Vec3 {
    let offset = offset_distance(p) * n;
    if dir.dot(n) >= 0.0 {
        p + offset
    } else {
        p - offset
    }
}

/// A ray leaving the surface point `p` (geometric normal `n`, either orientation) along `dir`.
///
/// The origin is moved off the surface to the side `dir` leaves toward, so the new ray cannot
/// hit the surface it starts on ("acne"), however the normal is oriented.
pub fn spawn_ray(p: Vec3, n: Vec3, dir: Vec3) -> Ray {
    Ray::new(offset_origin(p, n, dir), dir)
}

/// A ray from the surface point `p` toward `target`, stopping just short of it.
///
/// Used for shadow rays: it reports geometry strictly between the surface and the target, not the
/// surface itself (offset as in [`spawn_ray`]) and not a surface the target sits on (the segment
/// ends one offset distance before the target).
pub fn spawn_ray_to(p: Vec3, n: Vec3, target: Vec3) -> Ray {
    let origin = offset_origin(p, n, target - p);
    let to_target = target - origin;
    let distance = to_target.length();
    Ray::segment(origin, to_target, distance - offset_distance(target))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spawned_rays_leave_on_the_side_they_point_to() {
        let p = Vec3::new(0.3, 1.0, -0.2);
        let n = Vec3::Y;
        let up = spawn_ray(p, n, Vec3::new(0.1, 1.0, 0.0));
        let down = spawn_ray(p, -n, Vec3::new(0.1, -1.0, 0.0));
        assert!(up.origin.y > p.y);
        assert!(down.origin.y < p.y);
    }

    #[test]
    fn a_ray_to_a_target_stops_short_of_it() {
        let p = Vec3::ZERO;
        let target = Vec3::new(0.0, 2.0, 0.0);
        let ray = spawn_ray_to(p, Vec3::Y, target);
        assert!(ray.at(ray.t_max).y < target.y);
        assert!(ray.at(ray.t_max).y > target.y - 1e-3);
    }

    #[test]
    fn reflection_keeps_the_tangent_and_flips_the_normal_part() {
        let wo = Vec3::new(1.0, 1.0, 0.0).normalize();
        let r = reflect(wo, Vec3::Y);
        assert!((r - Vec3::new(-wo.x, wo.y, 0.0)).length() < 1e-6);
    }
}
