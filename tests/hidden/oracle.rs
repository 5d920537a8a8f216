//! Helpers shared by the hidden tests: random inputs and a brute-force closest hit.

use raylab::geometry::{Triangle, TriangleHit};
use raylab::math::{Ray, Vec3};
use raylab::rng::Rng;

/// A point uniform in the cube `[-r, r]³`.
pub fn point_in_cube(rng: &mut Rng, r: f32) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (2.0 * r) - Vec3::splat(r)
}

/// A unit direction, uniform on the sphere (rejection from the cube).
pub fn direction(rng: &mut Rng) -> Vec3 {
    loop {
        let v = point_in_cube(rng, 1.0);
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// The closest hit of `ray` among `triangles`, testing every one: the BVH's oracle.
pub fn closest_hit(triangles: &[Triangle], ray: &Ray) -> Option<(u32, TriangleHit)> {
    let mut best: Option<(u32, TriangleHit)> = None;
    for (i, t) in triangles.iter().enumerate() {
        if let Some(hit) = t.intersect(ray) {
            if best.is_none_or(|(_, b)| hit.t < b.t) {
                best = Some((i as u32, hit));
            }
        }
    }
    best
}
