//! A wide BVH leaf: up to four triangles stored lane by lane, intersected with one ray at once.
//!
//! **Layout.** Each coordinate of the first vertex and of the two edges `e1 = p1 − p0`,
//! `e2 = p2 − p0` is a four-lane vector (structure of arrays), so one SIMD instruction does the
//! same step of Möller-Trumbore for all four triangles. Unused lanes hold a degenerate triangle
//! (all zero), whose determinant is 0: it never hits.
//!
//! **Exactness.** The kernel evaluates the same expressions, in the same order, as the reference
//! solution of checkpoint 2 (`intersect_triangle`): cross and dot products with glam's operand
//! order, `1 / det` then products, the same rejections (NaN fails every comparison, as there), and
//! the same grazing test `|det| ≤ 1e-7 · |e1 × e2|`. IEEE arithmetic is the same in a lane as in a
//! scalar register and Rust never fuses a multiply with an add on its own, so every lane returns
//! the bit-identical `t`, `b1`, `b2`; the wide tree's tests check exactly that against the binary
//! tree. Among lanes that hit, the smallest `t` wins, ties to the lowest lane: the triangle the
//! binary tree's leaf loop would keep.

use wide::{f32x4, CmpEq, CmpGe, CmpGt, CmpLe, CmpLt, CmpNe};

use crate::geometry::{Triangle, TriangleHit};
use crate::math::Ray;

/// Lanes per packet: triangles per leaf.
pub const LANES: usize = 4;

/// `|det|` at most this fraction of `|e1 × e2|` counts as a ray grazing the triangle's plane:
/// checkpoint 2's tolerance, so that both kernels reject the same rays.
const GRAZING: f32 = 1e-7;

/// Up to [`LANES`] triangles, lane by lane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct Packet {
    p0: [f32x4; 3],
    e1: [f32x4; 3],
    e2: [f32x4; 3],
    /// `GRAZING · |e1 × e2|` per lane.
    grazing: f32x4,
    /// The input index of each lane's triangle (unused lanes: `u32::MAX`).
    prims: [u32; LANES],
}

impl Packet {
    /// A packet of `triangles` (1 to [`LANES`]), each with its input index.
    pub fn new(triangles: impl IntoIterator<Item = (u32, Triangle)>) -> Self {
        let mut lanes = [[[0.0f32; LANES]; 3]; 3];
        let mut grazing = [0.0f32; LANES];
        let mut prims = [u32::MAX; LANES];
        let mut count = 0;
        for (lane, (prim, t)) in triangles.into_iter().enumerate() {
            assert!(lane < LANES, "a packet holds at most {LANES} triangles");
            count += 1;
            let (e1, e2) = (t.p1 - t.p0, t.p2 - t.p0);
            for axis in 0..3 {
                lanes[0][axis][lane] = t.p0[axis];
                lanes[1][axis][lane] = e1[axis];
                lanes[2][axis][lane] = e2[axis];
            }
            grazing[lane] = GRAZING * e1.cross(e2).length();
            prims[lane] = prim;
        }
        assert!(count > 0, "a packet holds at least one triangle");
        let [p0, e1, e2] = lanes.map(|vectors| vectors.map(f32x4::from));
        Self { p0, e1, e2, grazing: f32x4::from(grazing), prims }
    }

    /// The input indices of the packet's triangles, lane by lane.
    pub fn prims(&self) -> impl Iterator<Item = u32> + '_ {
        self.prims.iter().copied().take_while(|&p| p != u32::MAX)
    }

    /// The closest hit of `ray` in its open range `(t_min, t_max)` among the packet's triangles,
    /// as (input index, hit), or `None`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(u32, TriangleHit)> {
        let d = ray.dir.to_array().map(f32x4::splat);
        let [e1, e2] = [&self.e1, &self.e2];
        // p = d × e2, det = e1 · p
        let p = cross(&d, e2);
        let det = dot(e1, &p);
        let mut hit = det.cmp_ne(f32x4::ZERO);
        let inv_det = f32x4::ONE / det;
        let o = ray.origin.to_array().map(f32x4::splat);
        let t_vec = [o[0] - self.p0[0], o[1] - self.p0[1], o[2] - self.p0[2]];
        let b1 = dot(&t_vec, &p) * inv_det;
        hit &= b1.cmp_ge(f32x4::ZERO) & b1.cmp_le(f32x4::ONE);
        let q = cross(&t_vec, e1);
        let b2 = dot(&d, &q) * inv_det;
        hit &= !(b2.cmp_lt(f32x4::ZERO) | (b1 + b2).cmp_gt(f32x4::ONE));
        let t = dot(e2, &q) * inv_det;
        hit &= t.cmp_gt(f32x4::splat(ray.t_min)) & t.cmp_lt(f32x4::splat(ray.t_max));
        hit &= det.abs().cmp_gt(self.grazing);
        let mask = hit.move_mask();
        if mask == 0 {
            return None;
        }
        // The nearest lane that hits, without branching: the lanes that miss at infinity, the
        // least `t`, the first lane holding it. (A hit's `t` passed `t > t_min`: never NaN.)
        let t_hits = hit.blend(t, f32x4::splat(f32::INFINITY)).to_array();
        let nearest = t_hits.into_iter().fold(f32::INFINITY, f32::min);
        let lane =
            (f32x4::from(t_hits).cmp_eq(f32x4::splat(nearest)).move_mask() & mask).trailing_zeros() as usize;
        let (b1, b2) = (b1.to_array(), b2.to_array());
        Some((self.prims[lane], TriangleHit { t: t_hits[lane], b1: b1[lane], b2: b2[lane] }))
    }
}

/// `a × b` lane by lane, with glam's operand order (`Vec3::cross`).
#[inline]
fn cross(a: &[f32x4; 3], b: &[f32x4; 3]) -> [f32x4; 3] {
    [a[1] * b[2] - b[1] * a[2], a[2] * b[0] - b[2] * a[0], a[0] * b[1] - b[0] * a[1]]
}

/// `a · b` lane by lane, summed left to right as glam does (`Vec3::dot`).
#[inline]
fn dot(a: &[f32x4; 3], b: &[f32x4; 3]) -> f32x4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::intersect_triangle;
    use crate::math::Vec3;
    use crate::rng::Rng;
    use crate::test_fixtures::{random_triangle, random_unit_vector};

    /// Every lane returns what checkpoint 2's solution returns for its triangle, bit for bit,
    /// on random rays near random triangles (about half of them hit).
    #[test]
    fn each_lane_agrees_bit_for_bit_with_intersect_triangle() {
        let mut rng = Rng::new(41, 0);
        let mut hits = 0;
        for _ in 0..20_000 {
            let triangle = random_triangle(&mut rng, 1.0);
            let packet = Packet::new([(7, triangle)]);
            let target = triangle.point(rng.next_f32() * 1.2 - 0.1, rng.next_f32() * 1.2 - 0.1);
            let origin = target + random_unit_vector(&mut rng) * 2.0;
            let ray = Ray::new(origin, target - origin);
            let want = intersect_triangle(&ray, triangle.p0, triangle.p1, triangle.p2);
            assert_eq!(packet.intersect(&ray), want.map(|hit| (7, hit)), "{triangle:?} {ray:?}");
            hits += want.is_some() as u32;
        }
        assert!((5_000..15_000).contains(&hits), "{hits} hits: the rays should test both outcomes");
    }

    /// Of several triangles hit, the closest wins; of two at the same distance, the first.
    #[test]
    fn the_closest_lane_wins_and_ties_go_to_the_first() {
        let at =
            |z: f32| Triangle::new(Vec3::new(-1.0, -1.0, z), Vec3::new(1.0, -1.0, z), Vec3::new(0.0, 1.0, z));
        let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z);
        let packet = Packet::new([(0, at(1.0)), (1, at(3.0)), (2, at(-2.0)), (3, at(3.0))]);
        let (prim, hit) = packet.intersect(&ray).expect("hit");
        assert_eq!((prim, hit.t), (1, 2.0));
        assert_eq!(packet.prims().collect::<Vec<_>>(), [0, 1, 2, 3]);
        // The unused lanes of a short packet never hit, even a ray through the origin.
        let short = Packet::new([(9, at(-3.0))]);
        assert_eq!(short.prims().count(), 1);
        assert_eq!(short.intersect(&Ray::new(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z)).map(|h| h.0), Some(9));
        assert_eq!(Packet::new([(9, at(7.0))]).intersect(&ray), None);
    }
}
