//! Checkpoint 4, hidden: closest hits and shadow queries of BVHs over meshes the public tests do
//! not build (a fan of triangles sharing one centroid, a long thin strip), against brute force.

use crate::oracle::{closest_hit, direction, point_in_cube};
use raylab::geometry::{Bvh, SplitMethod, TraversalStats, Triangle};
use raylab::math::{Ray, Vec3};
use raylab::rng::Rng;

/// Closest hits, and `occluded` on segments, equal brute force on random rays, half of them aimed
/// at a random triangle.
fn agrees_with_brute_force(triangles: &[Triangle], seed: u64) {
    let bvh = Bvh::build(triangles, SplitMethod::ObjectMedian);
    bvh.validate().expect("a valid tree");
    let mut rng = Rng::new(seed, 0);
    let mut stats = TraversalStats::default();
    let mut hits = 0;
    for _ in 0..3_000 {
        let origin = point_in_cube(&mut rng, 4.0);
        let dir = if rng.next_f32() < 0.5 {
            let t = triangles[(rng.next_u32() as usize) % triangles.len()];
            t.point(0.3, 0.3) - origin
        } else {
            direction(&mut rng)
        };
        let ray = Ray::new(origin, dir);
        let want = closest_hit(triangles, &ray);
        let got = bvh.intersect(&ray, &mut stats);
        assert_eq!(got.map(|h| h.hit.t), want.map(|(_, h)| h.t), "{ray:?}");
        hits += want.is_some() as u32;
        let segment = Ray { t_max: 3.0 * rng.next_f32(), ..ray };
        assert_eq!(
            bvh.occluded(&segment, &mut stats),
            closest_hit(triangles, &segment).is_some(),
            "{segment:?}"
        );
    }
    assert!(hits > 1_000, "only {hits} hits: the test must see hits");
}

/// 64 triangles rotated about one point: every centroid is the same, so no split separates them.
#[test]
fn a_fan_of_triangles_with_one_shared_centroid_is_traversed_right() {
    let triangles: Vec<Triangle> = (0..64)
        .map(|i| {
            let a = i as f32 * 0.37;
            let (u, v) = (Vec3::new(a.cos(), a.sin(), 0.3 * a.sin()), Vec3::new(-a.sin(), a.cos(), 0.5));
            // Vertices c + u, c - u/2 + v, c - u/2 - v: centroid c.
            Triangle::new(u * 2.0, v * 2.0 - u, -v * 2.0 - u)
        })
        .collect();
    for t in &triangles {
        assert!(t.centroid().length() < 1e-5);
    }
    agrees_with_brute_force(&triangles, 41);
}

/// A strip of 500 triangles along x, 100 units long and 1 wide: the widest axis is x at every level.
#[test]
fn a_long_thin_strip_is_traversed_right() {
    let triangles: Vec<Triangle> = (0..500)
        .map(|i| {
            let x = -50.0 + i as f32 * 0.2;
            Triangle::new(
                Vec3::new(x, -0.5, 0.0),
                Vec3::new(x + 0.2, -0.5, 0.1),
                Vec3::new(x + 0.1, 0.5, -0.1),
            )
        })
        .collect();
    agrees_with_brute_force(&triangles, 42);
}
