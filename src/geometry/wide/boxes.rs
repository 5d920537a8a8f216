//! A wide node's eight box tests for one ray: the slab test of checkpoint 3, lane by lane.
//!
//! Per axis the near and far plane distances `(plane − o) · inv_dir` (the near plane is `max` when
//! the ray travels toward decreasing coordinates), `t_in` raised and `t_out` lowered only by
//! comparisons that are false for NaN, as the scalar test does, so a lane's answer is the scalar
//! answer bit for bit. Two implementations of the same arithmetic: [`Portable`] (the `wide` crate:
//! two four-lane halves with SSE or NEON, scalar elsewhere) and, on x86-64 CPUs that have it,
//! [`Avx2`] (eight lanes in one instruction). `MAXPS`/`MINPS` and their AVX forms are defined as
//! exactly `a > b ? a : b` and `a < b ? a : b` (Intel SDM), the scalar test's NaN rule in one
//! instruction; NEON's max returns NaN, so elsewhere it is a compare and a blend.

use wide::{f32x8, CmpLe};
#[cfg(not(target_arch = "x86_64"))]
use wide::{CmpGt, CmpLt};

use super::{WideNode, WIDTH};
use crate::math::Ray;

/// A ray prepared for a node's box tests.
pub trait BoxTest {
    /// The ray spread over the lanes.
    fn new(ray: &Ray) -> Self;

    /// Which of `node`'s children's boxes the ray meets within `[t_min, t_max]` (bit `slot` of
    /// the mask), and where it enters each.
    fn boxes(&self, node: &WideNode, t_max: f32) -> (i32, [f32; WIDTH]);
}

/// The portable box tests (module docs).
pub struct Portable {
    origin: [f32x8; 3],
    inv_dir: [f32x8; 3],
    /// Per axis, whether the ray travels toward decreasing coordinates (`inv_dir < 0`).
    negative: [bool; 3],
    t_min: f32x8,
}

impl BoxTest for Portable {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        Self {
            origin: ray.origin.to_array().map(f32x8::splat),
            inv_dir: ray.inv_dir.to_array().map(f32x8::splat),
            negative: ray.inv_dir.to_array().map(|i| i < 0.0),
            t_min: f32x8::splat(ray.t_min),
        }
    }

    #[inline(always)]
    fn boxes(&self, node: &WideNode, t_max: f32) -> (i32, [f32; WIDTH]) {
        let mut t_in = self.t_min;
        let mut t_out = f32x8::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.negative[axis] {
                (node.max[axis], node.min[axis])
            } else {
                (node.min[axis], node.max[axis])
            };
            let near = (f32x8::from(near) - self.origin[axis]) * self.inv_dir[axis];
            let far = (f32x8::from(far) - self.origin[axis]) * self.inv_dir[axis];
            t_in = raise(near, t_in);
            t_out = lower(far, t_out);
        }
        (t_in.cmp_le(t_out).move_mask(), t_in.to_array())
    }
}

/// `if a > b { a } else { b }` lane by lane: a NaN `a` leaves `b`, as in the scalar slab test.
#[inline]
fn raise(a: f32x8, b: f32x8) -> f32x8 {
    #[cfg(target_arch = "x86_64")]
    return a.fast_max(b);
    #[cfg(not(target_arch = "x86_64"))]
    return a.cmp_gt(b).blend(a, b);
}

/// `if a < b { a } else { b }` lane by lane: a NaN `a` leaves `b`.
#[inline]
fn lower(a: f32x8, b: f32x8) -> f32x8 {
    #[cfg(target_arch = "x86_64")]
    return a.fast_min(b);
    #[cfg(not(target_arch = "x86_64"))]
    return a.cmp_lt(b).blend(a, b);
}

/// The AVX2 box tests (module docs). Only `WideBvh::traverse_avx2` makes one: a function compiled
/// for AVX2 and called only where the CPU has it (the module is private to `wide`).
#[cfg(target_arch = "x86_64")]
pub struct Avx2 {
    origin: [std::arch::x86_64::__m256; 3],
    inv_dir: [std::arch::x86_64::__m256; 3],
    negative: [bool; 3],
    t_min: std::arch::x86_64::__m256,
}

#[cfg(target_arch = "x86_64")]
impl BoxTest for Avx2 {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        use std::arch::x86_64::_mm256_set1_ps;
        // SAFETY: only called from `traverse_avx2`, which runs only on CPUs with AVX2.
        unsafe {
            Self {
                origin: ray.origin.to_array().map(|v| _mm256_set1_ps(v)),
                inv_dir: ray.inv_dir.to_array().map(|v| _mm256_set1_ps(v)),
                negative: ray.inv_dir.to_array().map(|i| i < 0.0),
                t_min: _mm256_set1_ps(ray.t_min),
            }
        }
    }

    #[inline(always)]
    fn boxes(&self, node: &WideNode, t_max: f32) -> (i32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        let mut entries = [0.0f32; WIDTH];
        // SAFETY: as for `new` (AVX2 is there); the loads and the store read and write whole
        // `[f32; 8]` arrays.
        unsafe {
            let mut t_in = self.t_min;
            let mut t_out = _mm256_set1_ps(t_max);
            for axis in 0..3 {
                let (near, far) = if self.negative[axis] {
                    (&node.max[axis], &node.min[axis])
                } else {
                    (&node.min[axis], &node.max[axis])
                };
                let near = _mm256_mul_ps(
                    _mm256_sub_ps(_mm256_loadu_ps(near.as_ptr()), self.origin[axis]),
                    self.inv_dir[axis],
                );
                let far = _mm256_mul_ps(
                    _mm256_sub_ps(_mm256_loadu_ps(far.as_ptr()), self.origin[axis]),
                    self.inv_dir[axis],
                );
                t_in = _mm256_max_ps(near, t_in);
                t_out = _mm256_min_ps(far, t_out);
            }
            _mm256_storeu_ps(entries.as_mut_ptr(), t_in);
            (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_in, t_out)), entries)
        }
    }
}
