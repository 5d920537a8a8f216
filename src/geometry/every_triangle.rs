//! Tracing without a tree: every triangle tested for every ray, with checkpoint 2 alone.
//!
//! `render`'s stand-in while checkpoint 3 or 4 is unwritten ([`crate::fallback`]), and the brute
//! force the BVH's tests compare with: slow (O(n) per ray) but needing nothing but the triangle
//! test.

use super::{intersect_triangle, BvhHit, Triangle};
use crate::math::Ray;

/// The closest triangle `ray` meets in its range, testing every one (checkpoint 2 only).
pub fn closest_triangle(triangles: &[Triangle], ray: &Ray) -> Option<BvhHit> {
    let mut ray = *ray;
    let mut closest = None;
    for (prim, t) in triangles.iter().enumerate() {
        if let Some(hit) = intersect_triangle(&ray, t.p0, t.p1, t.p2) {
            ray.t_max = hit.t;
            closest = Some(BvhHit { prim: prim as u32, hit });
        }
    }
    closest
}

/// Whether any triangle blocks `ray` in its range, testing every one (checkpoint 2 only).
pub fn any_triangle(triangles: &[Triangle], ray: &Ray) -> bool {
    triangles.iter().any(|t| intersect_triangle(ray, t.p0, t.p1, t.p2).is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::{random_mesh, random_unit_vector};

    /// The stand-in tracer finds the nearest of all the hits each triangle gives alone on the
    /// full ray, and any-hit agrees with it.
    #[test]
    fn testing_every_triangle_finds_the_nearest_hit() {
        let mut rng = Rng::new(5, 0);
        let triangles = random_mesh(&mut rng, 200);
        for _ in 0..500 {
            let origin = 2.0 * random_unit_vector(&mut rng);
            let ray = Ray::new(origin, 0.3 * random_unit_vector(&mut rng) - origin);
            let nearest = triangles
                .iter()
                .filter_map(|t| intersect_triangle(&ray, t.p0, t.p1, t.p2))
                .map(|h| h.t)
                .reduce(f32::min);
            assert_eq!(closest_triangle(&triangles, &ray).map(|h| h.hit.t), nearest, "{ray:?}");
            assert_eq!(any_triangle(&triangles, &ray), nearest.is_some());
        }
    }
}
