//! Checkpoint 2: ray-triangle intersection (Möller-Trumbore).
//!
//! **Task.** Write [`intersect_triangle`]: given a ray and a triangle's three vertices, return the
//! ray parameter `t` and the barycentric coordinates of the hit, or `None` for a miss.
//!
//! **Maths.** A point of the triangle is `p0 + b1·e1 + b2·e2` with `e1 = p1 − p0`, `e2 = p2 − p0`,
//! `b1 ≥ 0`, `b2 ≥ 0`, `b1 + b2 ≤ 1` (and `b0 = 1 − b1 − b2`). Setting it equal to
//! `o + t·d` gives a 3×3 linear system `[−d  e1  e2] (t, b1, b2)ᵀ = o − p0`. Cramer's rule with
//! the scalar triple product `a · (b × c)` solves it:
//!
//! ```text
//!   P = d × e2        det = e1 · P          (det = 0: the ray is parallel to the plane)
//!   T = o − p0        b1  = (T · P) / det
//!   Q = T × e1        b2  = (d · Q) / det    t = (e2 · Q) / det
//! ```
//!
//! **Conventions** ([`crate::math`]): the hit must have `t` in the ray's open range
//! `(t_min, t_max)`; triangles are two-sided, so `det` may have either sign; edges are inside
//! (`b = 0` is a hit), so in exact arithmetic a ray through an edge shared by two triangles hits
//! at least one (in floating point the two compute that edge differently and a ray may, rarely,
//! pass between them; a watertight test, Woop et al. 2013, rules that out).
//!
//! **Pitfalls.**
//! - Rejecting `det < 0` culls back faces: walls seen from inside and rays leaving glass vanish.
//! - "Parallel" must be judged relative to the triangle's size: `|det| = |d| |e1 × e2| |cos θ|`,
//!   with `θ` the angle between the ray and the triangle's normal, so a bare `|det| < 1e-8`
//!   rejects small triangles seen head-on and accepts huge ones seen edge-on. Compare `|det|`
//!   with `|e1 × e2|` instead (raylab counts `|det| <= 1e-7 · |e1 × e2|` as parallel: `|cos θ|`
//!   below 1e-7), with `<=`: a degenerate triangle (`e1 × e2 = 0`, so `det = 0`) then misses too
//!   (with `<`, `0 < 0` is false and the division by `det` gives a NaN hit). The length of
//!   `e1 × e2` costs a square root, so raylab returns early on `det == 0` (dividing is then safe)
//!   and makes this comparison last, for the few rays that pass every other test; comparing
//!   the squares of both sides avoids the root too.
//! - Test `b1` before computing `Q`, and `b1 + b2 ≤ 1`, not `b2 ≤ 1`.
//! - Accepting `t < t_min` shows what is behind the camera (and mirrored copies).
//! - Forgetting `t_max` lets a farther triangle replace a nearer one in every closest-hit search
//!   (the loop over all triangles `render` uses until checkpoints 3 and 4 are written, then the
//!   BVH): far surfaces cover near ones, in `room` already.
//!
//! **Check:** `cargo test checkpoint2`. Handout: `checkpoints/02-triangle.md`.

use crate::geometry::Aabb;
use crate::math::{Ray, Vec3};

/// A triangle by its three vertices; winding `p0 → p1 → p2` is counter-clockwise seen from the
/// side its normal points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// First vertex.
    pub p0: Vec3,
    /// Second vertex.
    pub p1: Vec3,
    /// Third vertex.
    pub p2: Vec3,
}

impl Triangle {
    /// The triangle with these vertices.
    pub fn new(p0: Vec3, p1: Vec3, p2: Vec3) -> Self {
        Self { p0, p1, p2 }
    }

    /// The smallest box containing the three vertices.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_point(self.p0).grow(self.p1).grow(self.p2)
    }

    /// The mean of the three vertices.
    pub fn centroid(&self) -> Vec3 {
        (self.p0 + self.p1 + self.p2) / 3.0
    }

    /// The unit geometric normal `normalize((p1 − p0) × (p2 − p0))`.
    pub fn normal(&self) -> Vec3 {
        (self.p1 - self.p0).cross(self.p2 - self.p0).normalize()
    }

    /// The area, `|(p1 − p0) × (p2 − p0)| / 2`.
    pub fn area(&self) -> f32 {
        0.5 * (self.p1 - self.p0).cross(self.p2 - self.p0).length()
    }

    /// The point with barycentric coordinates `(1 − b1 − b2, b1, b2)`.
    pub fn point(&self, b1: f32, b2: f32) -> Vec3 {
        (1.0 - b1 - b2) * self.p0 + b1 * self.p1 + b2 * self.p2
    }

    /// [`intersect_triangle`] on this triangle.
    pub fn intersect(&self, ray: &Ray) -> Option<TriangleHit> {
        intersect_triangle(ray, self.p0, self.p1, self.p2)
    }
}

/// Where a ray meets a triangle: the point is `ray.at(t)`, and also `(1 − b1 − b2)·p0 + b1·p1 + b2·p2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit, in the ray's open range `(t_min, t_max)`.
    pub t: f32,
    /// Barycentric weight of `p1`.
    pub b1: f32,
    /// Barycentric weight of `p2`.
    pub b2: f32,
}

/// Intersects `ray` with the triangle `(p0, p1, p2)` by Möller-Trumbore.
///
/// Returns the hit if the ray meets the triangle (edges included, either side) at a `t` strictly
/// inside `(ray.t_min, ray.t_max)`; `None` for a miss, a parallel ray or a degenerate triangle.
#[inline]
pub fn intersect_triangle(ray: &Ray, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
    // BEGIN SOLUTION checkpoint2
    // |det| below this fraction of |e1 × e2| counts as parallel: the ray meets the plane at less
    // than about 6e-6 degrees, where the hit point's error exceeds the triangle itself.
    const PARALLEL_COSINE: f32 = 1e-7;
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let t_vec = ray.origin - p0;
    let b1 = t_vec.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = t_vec.cross(e1);
    let b2 = ray.dir.dot(q) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    if !(t > ray.t_min && t < ray.t_max) {
        return None;
    }
    // |det| = |e1 × e2| |cos θ| for a unit direction: parallel (or degenerate, when the cross
    // product vanishes) is judged relative to the triangle's own size. Checked last because it
    // needs a square root, and most rays were rejected above without one; a near-parallel ray
    // only gives meaningless b1, b2, t, which this rejects whatever they are.
    if det.abs() <= PARALLEL_COSINE * e1.cross(e2).length() {
        return None;
    }
    Some(TriangleHit { t, b1, b2 })
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint2 {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::{random_triangle, random_unit_vector};

    fn unit_triangle() -> (Vec3, Vec3, Vec3) {
        (Vec3::ZERO, Vec3::X, Vec3::Y)
    }

    /// A ray from `z = 1` straight down onto the point `(x, y, 0)`.
    fn ray_down_at(x: f32, y: f32) -> Ray {
        Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z)
    }

    #[test]
    fn a_ray_through_the_middle_hits_with_its_barycentrics() {
        let (p0, p1, p2) = unit_triangle();
        let hit = intersect_triangle(&ray_down_at(0.25, 0.5), p0, p1, p2)
            .expect("a ray straight down onto (0.25, 0.5, 0) must hit the unit triangle");
        assert!(
            (hit.t - 1.0).abs() < 1e-6,
            "the hit is 1 unit below the origin: expected t = 1, got {}",
            hit.t
        );
        assert!(
            (hit.b1 - 0.25).abs() < 1e-6 && (hit.b2 - 0.5).abs() < 1e-6,
            "on the unit triangle (b1, b2) = (x, y): expected (0.25, 0.5), got ({}, {})",
            hit.b1,
            hit.b2
        );
    }

    #[test]
    fn the_back_face_is_hit_too() {
        let (p0, p1, p2) = unit_triangle();
        let from_below = Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z);
        let hit = intersect_triangle(&from_below, p0, p1, p2)
            .expect("a ray from below (det < 0) must hit: triangles are two-sided");
        assert!((hit.t - 1.0).abs() < 1e-6, "hit from below at distance 1: expected t = 1, got {}", hit.t);
    }

    #[test]
    fn points_just_inside_edges_and_vertices_hit_and_just_outside_miss() {
        let (p0, p1, p2) = unit_triangle();
        let d = 1e-4;
        let inside = [(d, d), (0.5, d), (d, 0.5), (0.5 - d, 0.5 - d), (1.0 - 3.0 * d, d)];
        let outside = [(-d, 0.5), (0.5, -d), (0.5 + d, 0.5 + d), (1.0 + d, 0.0), (-d, -d)];
        for (x, y) in inside {
            let got = intersect_triangle(&ray_down_at(x, y), p0, p1, p2);
            assert!(got.is_some(), "({x}, {y}) is just inside the triangle: expected a hit, got a miss");
        }
        for (x, y) in outside {
            let got = intersect_triangle(&ray_down_at(x, y), p0, p1, p2);
            assert!(
                got.is_none(),
                "({x}, {y}) is just outside (b1, b2 >= 0, b1 + b2 <= 1): expected a miss, got {got:?}"
            );
        }
    }

    #[test]
    fn a_triangle_behind_the_origin_is_not_hit() {
        let (p0, p1, p2) = unit_triangle();
        let away = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::Z);
        let got = intersect_triangle(&away, p0, p1, p2);
        assert!(
            got.is_none(),
            "the triangle is behind the ray (t = -1, not above t_min = 0): expected a miss, got {got:?}"
        );
    }

    #[test]
    fn hits_outside_the_open_t_window_are_rejected() {
        let (p0, p1, p2) = unit_triangle();
        let mut ray = ray_down_at(0.2, 0.2); // the hit is at t = 1
        ray.t_max = 0.999;
        assert!(intersect_triangle(&ray, p0, p1, p2).is_none(), "beyond t_max");
        ray.t_max = 1.001;
        assert!(intersect_triangle(&ray, p0, p1, p2).is_some(), "t = 1 inside (0, 1.001): expected a hit");
        ray.t_min = 1.001;
        ray.t_max = f32::INFINITY;
        assert!(intersect_triangle(&ray, p0, p1, p2).is_none(), "before t_min");
        // The hit is at t = 1 exactly (every value above is exact in f32): the window is open, so
        // a hit exactly at either end does not count.
        ray.t_min = 1.0;
        assert!(intersect_triangle(&ray, p0, p1, p2).is_none(), "exactly at t_min");
        ray.t_min = 0.0;
        ray.t_max = 1.0;
        assert!(intersect_triangle(&ray, p0, p1, p2).is_none(), "exactly at t_max");
    }

    #[test]
    fn points_exactly_on_edges_and_vertices_hit() {
        // On the unit triangle seen straight down, b1 = x and b2 = y, and Möller-Trumbore computes
        // them exactly in f32 here: these are b2 = 0, b1 = 0 and b1 + b2 = 1 (the three edges),
        // and the three vertices. Edges are inside, so all must hit.
        let (p0, p1, p2) = unit_triangle();
        for (x, y) in [(0.5, 0.0), (0.0, 0.5), (0.5, 0.5), (0.25, 0.75), (0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
            let hit = intersect_triangle(&ray_down_at(x, y), p0, p1, p2)
                .unwrap_or_else(|| panic!("({x}, {y}) is on the boundary: a hit"));
            assert!((hit.b1 - x).abs() < 1e-6 && (hit.b2 - y).abs() < 1e-6, "({x}, {y}): {hit:?}");
        }
    }

    /// A degenerate triangle has `e1 × e2 = 0`, so `det = 0`: a parallel test `|det| < k |e1 × e2|`
    /// lets it through (`0 < 0` is false) and the division by `det` gives NaN.
    #[track_caller]
    fn assert_degenerate_miss(what: &str, got: Option<TriangleHit>) {
        assert!(
            got.is_none(),
            "{what}: expected a miss, got {got:?}; det = 0 here: compare with `<=`, not `<`"
        );
    }

    #[test]
    fn parallel_rays_and_degenerate_triangles_miss() {
        let (p0, p1, p2) = unit_triangle();
        let in_plane = Ray::new(Vec3::new(-1.0, 0.2, 0.0), Vec3::X);
        let got = intersect_triangle(&in_plane, p0, p1, p2);
        assert!(got.is_none(), "a ray in the triangle's plane: expected a miss, got {got:?}");
        let sliver = (Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0));
        let down = ray_down_at(0.5, 0.0);
        assert_degenerate_miss("collinear vertices", intersect_triangle(&down, sliver.0, sliver.1, sliver.2));
        assert_degenerate_miss("three equal vertices", intersect_triangle(&down, p0, p0, p0));
    }

    #[test]
    fn the_parallel_test_scales_with_the_triangle() {
        // A tiny triangle seen head-on: |det| = 1e-12, far below any absolute epsilon.
        let s = 1e-6;
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, s, 0.0));
        let ray = Ray::new(Vec3::new(s / 4.0, s / 4.0, 1.0), -Vec3::Z);
        let got = intersect_triangle(&ray, p0, p1, p2);
        assert!(
            got.is_some(),
            "a 1e-6 triangle seen head-on must hit: judge \"parallel\" relative to |e1 × e2|, \
             not by a bare |det| threshold"
        );
    }

    #[test]
    fn aiming_at_given_barycentrics_gives_them_back() {
        let mut rng = Rng::new(2, 0);
        for _ in 0..2000 {
            let tri = random_triangle(&mut rng, 1.0);
            // Uniform in the triangle, kept 0.05 away from its edges.
            let (u, v) = (rng.next_f32(), rng.next_f32());
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let (b1, b2) = (0.05 + 0.85 * u, 0.05 + 0.85 * v);
            let target = tri.point(b1, b2);
            let origin = target + 2.0 * random_unit_vector(&mut rng);
            let ray = Ray::new(origin, target - origin);
            let cos = ray.dir.dot(tri.normal()).abs();
            let double_area = (tri.p1 - tri.p0).cross(tri.p2 - tri.p0).length();
            if cos < 0.05 || double_area < 0.05 {
                continue; // grazing or sliver: the input is ill-conditioned, not the code wrong
            }
            let hit = tri
                .intersect(&ray)
                .unwrap_or_else(|| panic!("a ray aimed at ({b1}, {b2}) inside {tri:?} missed"));
            // Error of a ratio of triple products with O(1) vectors: a few ε per product over |det|.
            let tol = 64.0 * f32::EPSILON * 9.0 / (cos * double_area);
            assert!((hit.b1 - b1).abs() < tol && (hit.b2 - b2).abs() < tol, "{hit:?} vs ({b1}, {b2})");
            let t = (target - origin).length();
            assert!((hit.t - t).abs() < tol * 3.0, "aimed from {t} away: expected t = {t}, got {}", hit.t);
        }
    }

    #[test]
    fn random_rays_agree_with_an_f64_oracle() {
        let mut rng = Rng::new(3, 0);
        let (mut agreed, mut hits) = (0, 0);
        for _ in 0..20_000 {
            let tri = random_triangle(&mut rng, 1.0);
            let origin = 3.0 * random_unit_vector(&mut rng);
            let towards = tri.centroid() + 0.8 * random_unit_vector(&mut rng);
            let ray = Ray::new(origin, towards - origin);
            let Some(oracle) = crate::test_fixtures::oracle_f64(&ray, &tri) else {
                continue; // within rounding of an edge, a window end, or parallel
            };
            let got = tri.intersect(&ray);
            assert_eq!(got.is_some(), oracle.is_some(), "{ray:?} {tri:?}: {got:?} vs {oracle:?}");
            if let (Some(g), Some((t, b1, b2, bound))) = (got, oracle) {
                hits += 1;
                assert!(
                    (g.t as f64 - t).abs() < bound * t.max(1.0),
                    "{ray:?} {tri:?}: t = {} vs exact {t}",
                    g.t
                );
                let (gb1, gb2) = (g.b1 as f64, g.b2 as f64);
                assert!(
                    (gb1 - b1).abs() < bound && (gb2 - b2).abs() < bound,
                    "{ray:?} {tri:?}: barycentrics ({gb1}, {gb2}) vs exact ({b1}, {b2})"
                );
            }
            agreed += 1;
        }
        assert!(agreed > 19_000, "too many undecidable cases: {agreed}");
        assert!(hits > 1_000, "the sample should contain many hits: {hits}");
    }
}
