//! Points and boxes as four-lane vectors, for building trees fast (the harness's, not a task).
//!
//! A `Vec3` coordinate by coordinate costs a NaN-aware compare and blend per `f32::min`; a box
//! held as two four-lane vectors (x, y, z and an unused lane) grows by one SIMD `min` and one
//! `max`. The boxes are the same: `min` and `max` are exact, and where they may differ from
//! [`Aabb::union`], in the sign of a zero bound, no ray can tell (`(±0 − o) · d⁻¹` is the same
//! for every origin `o` and direction `d`).

use wide::f32x4;

use crate::geometry::Aabb;
use crate::math::Vec3;

/// `p`'s coordinates in the first three of four lanes.
#[inline]
pub fn lanes(p: Vec3) -> f32x4 {
    f32x4::new([p.x, p.y, p.z, 0.0])
}

/// The first three lanes of `v` as a point.
fn point(v: f32x4) -> Vec3 {
    let [x, y, z, _] = v.to_array();
    Vec3::new(x, y, z)
}

/// An axis-aligned box as two four-lane corners.
#[derive(Clone, Copy)]
pub struct Box4 {
    /// The lower corner.
    pub min: f32x4,
    /// The upper corner.
    pub max: f32x4,
}

impl Box4 {
    /// The empty box, the identity of [`Box4::union`].
    pub const EMPTY: Box4 =
        Box4 { min: f32x4::new([f32::INFINITY; 4]), max: f32x4::new([f32::NEG_INFINITY; 4]) };

    /// `bounds` as lanes.
    #[inline]
    pub fn of(bounds: &Aabb) -> Self {
        Self { min: lanes(bounds.min), max: lanes(bounds.max) }
    }

    /// The box around both.
    #[inline]
    pub fn union(self, other: Box4) -> Self {
        Self { min: self.min.fast_min(other.min), max: self.max.fast_max(other.max) }
    }

    /// This box grown to contain the point `p` (as lanes).
    #[inline]
    pub fn grow(self, p: f32x4) -> Self {
        Self { min: self.min.fast_min(p), max: self.max.fast_max(p) }
    }

    /// This box as an [`Aabb`].
    pub fn aabb(self) -> Aabb {
        Aabb { min: point(self.min), max: point(self.max) }
    }
}
