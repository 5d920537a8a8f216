//! Points and boxes as four-lane vectors, for building trees fast (the harness's, not a task).
//!
//! `Vec3::min` and `max` are a compare and a select per coordinate (`if a < b { a } else { b }`);
//! a box held as two four-lane vectors (x, y, z, and a fourth lane whose value never matters)
//! grows by one SIMD `min` and one `max` for all three. On x86-64 the results are the same bits:
//! `MINPS`/`MAXPS` are defined as exactly that select, ties, signed zeros and NaN included (a
//! test checks it). Elsewhere (NEON, or the `wide` crate's scalar fallback) a zero bound may get
//! the other sign, which compares equal, so no slab test can tell; NaN coordinates, which a scene
//! never has (its loader rejects them), may give other boxes than there.

use wide::f32x4;

use crate::geometry::Aabb;
use crate::math::Vec3;

/// `p`'s coordinates in the first three of four lanes (the fourth is 0).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// On x86-64, growing and joining boxes as lanes gives the bits `Aabb` gives, signed zeros
    /// included (points on a grid of few values, so ties between +0 and −0 are frequent).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn boxes_as_lanes_are_the_aabb_bits() {
        let mut rng = Rng::new(15, 0);
        let mut coordinate = || [0.0, -0.0, 1.0, -1.0, 0.5][rng.next_u32() as usize % 5];
        let bits = |b: Aabb| [b.min, b.max].map(|c| c.to_array().map(f32::to_bits));
        for _ in 0..1_000 {
            let points: Vec<Vec3> =
                (0..6).map(|_| Vec3::new(coordinate(), coordinate(), coordinate())).collect();
            let (mut aabb, mut lanes_box) = (Aabb::EMPTY, Box4::EMPTY);
            for &p in &points {
                aabb = aabb.grow(p);
                lanes_box = lanes_box.grow(lanes(p));
            }
            assert_eq!(bits(lanes_box.aabb()), bits(aabb), "{points:?}");
            let other = Aabb::new(points[0], points[1]);
            assert_eq!(bits(lanes_box.union(Box4::of(&other)).aabb()), bits(aabb.union(other)), "{points:?}");
        }
    }
}
