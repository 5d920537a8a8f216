//! Checkpoint 3: ray-box intersection (the slab test).
//!
//! **Task.** Write [`Aabb::intersect`]: the part of the ray's range from `t_min` to `t_max` that
//! lies inside the box, as `Some((t_in, t_out))` with both ends counted, or `None` if the ray
//! misses the box in that range.
//!
//! **Maths.** The box is the intersection of three slabs `min_i ≤ x_i ≤ max_i`. Along axis `i` the
//! ray is inside its slab for `t` between `(min_i − o_i) / d_i` and `(max_i − o_i) / d_i` (swap
//! them when `inv_dir_i < 0`, which holds for `d_i = −0.0` too, where `d_i < 0` does not). The
//! ray is in the box where it is in all three slabs at once:
//!
//! ```text
//!   t_in  = max(t_min, near_x, near_y, near_z)
//!   t_out = min(t_max, far_x,  far_y,  far_z)       hit  ⇔  t_in ≤ t_out
//! ```
//!
//! Multiply by `ray.inv_dir` instead of dividing by `ray.dir`: it is cheaper, and it gives the
//! right infinities for zero components.
//!
//! **Conventions.** The result is a *closed* interval `[t_in, t_out]`, unlike a ray's hits, whose
//! range is open ([`crate::math`]): a flat box (`min_i == max_i`, such as the bounds of a Cornell
//! wall) has `t_in == t_out` and is hit, and a ray starting inside a box gets `t_in == t_min`. A box
//! only tells the BVH where to look; the triangle test inside it applies the open range.
//!
//! **Pitfalls.**
//! - Negative directions: the near plane is `max_i`, not `min_i`. Decide the swap from the sign of
//!   `inv_dir` (`−0.0` gives `−∞`), not by `d_i < 0` (false for `−0.0`: the test
//!   `negative_directions_swap_near_and_far` tries it).
//! - Zero direction components: `inv_dir = ±∞`, and `(min_i − o_i) · ∞` is `±∞`, which is right
//!   (the slab is either everything or nothing). But if `o_i` lies exactly on a slab plane,
//!   `0 · ∞ = NaN`. Merging it into the interval ignores it: any comparison with NaN is false, so
//!   `if near > t_in { t_in = near }` keeps `t_in`, and so do `t_in.max(near)` and
//!   `t_out.min(far)` (f32's `max` and `min` return the other operand). That is the right
//!   answer: a ray lying in the plane of a closed slab is inside it for all `t`. Picking near and
//!   far themselves with `t0.min(t1)` and `t0.max(t1)` is not: with one of them NaN, both give
//!   the other, near and far become the same infinity, and the ray misses a slab it lies in.
//! - Start from the ray's own `t_min` and `t_max` (not from `−∞`), or boxes behind the origin
//!   count as hits.
//! - `t_in < t_out` instead of `≤` misses flat boxes: the walls of a Cornell box.
//!
//! **Check:** `cargo test checkpoint3`. Handout: `checkpoints/03-aabb.md`.

use crate::math::{Ray, Vec3};

/// An axis-aligned box `{x : min ≤ x ≤ max}`. [`Aabb::EMPTY`] has `min > max` and contains nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: Vec3,
    /// The corner with the largest coordinates.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// The box spanned by two corners, in any order.
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Self { min: a.min(b), max: a.max(b) }
    }

    /// The box holding exactly one point.
    pub fn from_point(p: Vec3) -> Self {
        Self { min: p, max: p }
    }

    /// This box enlarged to contain `p`.
    pub fn grow(self, p: Vec3) -> Self {
        Self { min: self.min.min(p), max: self.max.max(p) }
    }

    /// The smallest box containing both.
    pub fn union(self, other: Aabb) -> Self {
        Self { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// `max − min` (negative for the empty box).
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Half the surface area, `xy + yz + zx` of the extent (0 for the empty box): what the SAH
    /// split compares, since only ratios of areas matter there.
    pub fn half_area(&self) -> f32 {
        let e = self.extent().max(Vec3::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// The axis (0, 1, 2 for x, y, z) along which the box is longest; ties go to the lower axis.
    pub fn longest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Whether `other` lies inside this box (boundaries included).
    pub fn contains(&self, other: &Aabb) -> bool {
        self.min.cmple(other.min).all() && other.max.cmple(self.max).all()
    }

    /// The overlap `(t_in, t_out)` of the box with the ray's range `[t_min, t_max]`, a closed
    /// interval (`t_in == t_out` when the ray touches the box or crosses a flat one), or `None`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<(f32, f32)> {
        // BEGIN SOLUTION checkpoint3
        let mut t_in = ray.t_min;
        let mut t_out = ray.t_max;
        for axis in 0..3 {
            let inv = ray.inv_dir[axis];
            let t_lo = (self.min[axis] - ray.origin[axis]) * inv;
            let t_hi = (self.max[axis] - ray.origin[axis]) * inv;
            // A negative direction (including −0.0, whose inverse is −∞) meets max first.
            let (near, far) = if inv < 0.0 { (t_hi, t_lo) } else { (t_lo, t_hi) };
            // Any comparison with NaN is false, so a NaN keeps t_in and t_out as they are. NaN
            // comes from 0 · ∞, a ray lying in this slab's boundary plane, which this closed slab
            // does not restrict. (`t_in.max(near)` ignores NaN too, at the price of a few more
            // instructions per call: this test runs dozens of times per ray.)
            if near > t_in {
                t_in = near;
            }
            if far < t_out {
                t_out = far;
            }
        }
        (t_in <= t_out).then_some((t_in, t_out))
        // END SOLUTION
    }
}

#[cfg(test)]
mod checkpoint3 {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::random_unit_vector;

    fn unit_box() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::ONE)
    }

    #[track_caller]
    fn assert_interval(got: Option<(f32, f32)>, t_in: f32, t_out: f32) {
        let (a, b) = got.unwrap_or_else(|| panic!("expected the overlap [{t_in}, {t_out}], got a miss"));
        let close = (a - t_in).abs() < 1e-6 && (b - t_out).abs() < 1e-6;
        assert!(close, "expected the overlap [{t_in}, {t_out}], got [{a}, {b}]");
    }

    /// The ray must miss the box.
    #[track_caller]
    fn assert_miss(got: Option<(f32, f32)>, why: &str) {
        assert!(got.is_none(), "{why}: expected a miss, got {got:?}");
    }

    #[test]
    fn a_ray_through_the_box_enters_and_leaves_where_expected() {
        let ray = Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X);
        assert_interval(unit_box().intersect(&ray), 1.0, 2.0);
    }

    #[test]
    fn negative_directions_swap_near_and_far() {
        let ray = Ray::new(Vec3::new(3.0, 0.5, 0.5), -Vec3::X);
        assert_interval(unit_box().intersect(&ray), 2.0, 3.0);
        let diagonal = Ray::new(Vec3::splat(2.0), -Vec3::ONE);
        let s3 = 3f32.sqrt();
        assert_interval(unit_box().intersect(&diagonal), s3, 2.0 * s3);
    }

    #[test]
    fn an_origin_inside_the_box_starts_the_interval_at_t_min() {
        let ray = Ray::new(Vec3::splat(0.5), Vec3::Y);
        assert_interval(unit_box().intersect(&ray), 0.0, 0.5);
    }

    #[test]
    fn a_box_behind_the_origin_is_missed() {
        let ray = Ray::new(Vec3::new(2.0, 0.5, 0.5), Vec3::X);
        assert_miss(unit_box().intersect(&ray), "the box lies at t < 0, before t_min");
    }

    #[test]
    fn a_box_beyond_t_max_is_missed() {
        let ray = Ray::segment(Vec3::new(-2.0, 0.5, 0.5), Vec3::X, 1.5);
        assert_miss(unit_box().intersect(&ray), "the box starts at t = 2, after t_max = 1.5");
        let longer = Ray::segment(Vec3::new(-2.0, 0.5, 0.5), Vec3::X, 2.5);
        assert_interval(unit_box().intersect(&longer), 2.0, 2.5);
    }

    #[test]
    fn touching_an_edge_or_crossing_a_flat_box_is_a_hit() {
        // Along the edge y = 1, z = 1 of the unit box.
        let grazing = Ray::new(Vec3::new(-1.0, 1.0, 1.0), Vec3::X);
        assert_interval(unit_box().intersect(&grazing), 1.0, 2.0);
        // Through the corner (1, 1, 1) only.
        let corner = Ray::new(Vec3::new(2.0, 0.0, 1.0), Vec3::new(-1.0, 1.0, 0.0));
        let s2 = 2f32.sqrt();
        assert_interval(unit_box().intersect(&corner), s2, s2);
        // A flat wall, like a Cornell box's floor.
        let floor = Aabb::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        let down = Ray::new(Vec3::new(0.3, 2.0, 0.2), -Vec3::Y);
        assert_interval(floor.intersect(&down), 2.0, 2.0);
    }

    #[test]
    fn zero_direction_components_inside_the_slab_hit_and_outside_miss() {
        let along_x = |y: f32, z: f32| Ray::new(Vec3::new(-1.0, y, z), Vec3::X);
        assert_interval(unit_box().intersect(&along_x(0.5, 0.5)), 1.0, 2.0);
        assert_miss(unit_box().intersect(&along_x(1.5, 0.5)), "d_y = 0 and y = 1.5 is outside the y slab");
        assert_miss(unit_box().intersect(&along_x(0.5, -0.5)), "d_z = 0 and z = -0.5 is outside the z slab");
    }

    #[test]
    fn an_origin_on_a_slab_plane_with_zero_direction_gives_no_nan() {
        for (y, z) in [(0.0, 0.5), (1.0, 0.5), (0.0, 0.0), (1.0, 1.0)] {
            for dir in [Vec3::X, Vec3::new(1.0, -0.0, 0.0), Vec3::new(1.0, 0.0, -0.0)] {
                let ray = Ray::new(Vec3::new(-1.0, y, z), dir);
                assert_interval(unit_box().intersect(&ray), 1.0, 2.0);
            }
        }
        let outside_plane_parallel = Ray::new(Vec3::new(-1.0, 1.0 + 1e-6, 0.5), Vec3::X);
        assert_miss(
            unit_box().intersect(&outside_plane_parallel),
            "parallel to the face y = 1, just above it",
        );
    }

    /// The overlap in f64, from the definition: each slab handled as its own case.
    fn oracle(b: &Aabb, ray: &Ray) -> Option<(f64, f64)> {
        let (mut t_in, mut t_out) = (ray.t_min as f64, ray.t_max as f64);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis] as f64, ray.dir[axis] as f64);
            let (lo, hi) = (b.min[axis] as f64, b.max[axis] as f64);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((lo - o) / d, (hi - o) / d);
            t_in = t_in.max(t0.min(t1));
            t_out = t_out.min(t0.max(t1));
        }
        (t_in <= t_out).then_some((t_in, t_out))
    }

    #[test]
    fn random_rays_agree_with_an_f64_oracle() {
        let mut rng = Rng::new(4, 0);
        let mut hits = 0;
        for i in 0..20_000 {
            let corner =
                |rng: &mut Rng| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0;
            let b = Aabb::new(corner(&mut rng), corner(&mut rng));
            let dir = random_unit_vector(&mut rng);
            // Aim near the box's centre so that about half the rays hit.
            let origin = 3.0 * random_unit_vector(&mut rng);
            let aim = (b.min + b.max) / 2.0 + 0.6 * random_unit_vector(&mut rng) - origin;
            let mut dir = if i % 2 == 0 { dir } else { aim };
            if i % 4 == 0 {
                dir[i / 4 % 3] = 0.0; // exercise zero components too
            }
            let ray = Ray::new(origin, dir);
            let (got, want) = (b.intersect(&ray), oracle(&b, &ray));
            // Each t is one subtraction and one product of O(1) values: within a few ε of the
            // exact value relative to its size. Cases closer than that to a miss are undecidable.
            let tol = |t: f64| 8.0 * f32::EPSILON as f64 * (4.0 + t.abs());
            match (got, want) {
                (Some((a, b)), Some((c, d))) => {
                    hits += 1;
                    let close = (a as f64 - c).abs() < tol(c) && (b as f64 - d).abs() < tol(d);
                    assert!(close, "{ray:?}: got [{a}, {b}], the exact overlap is [{c}, {d}]");
                }
                (None, Some((c, d))) => {
                    assert!(d - c < 2.0 * tol(d), "{ray:?}: missed the overlap [{c}, {d}]")
                }
                (Some((a, b)), None) => {
                    assert!(
                        b - a < 2.0 * tol(b as f64) as f32,
                        "{ray:?}: [{a}, {b}], but the ray misses the box"
                    )
                }
                (None, None) => {}
            }
        }
        assert!(hits > 2_000, "the sample should contain many hits: {hits}");
    }
}
