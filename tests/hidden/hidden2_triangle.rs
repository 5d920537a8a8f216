//! Checkpoint 2, hidden: Möller-Trumbore on random triangles, aimed at chosen barycentrics, and
//! far from the origin.

use crate::oracle::{direction, point_in_cube};
use raylab::geometry::intersect_triangle;
use raylab::math::{Ray, Vec3};
use raylab::rng::Rng;

/// A ray aimed at the point of barycentrics `(b1, b2)` comes back with those barycentrics and the
/// distance to the point, from either side. Skinny triangles and grazing rays are skipped: there
/// the answer is ill-conditioned and f32 cannot give 1e-3.
#[test]
fn random_rays_aimed_at_chosen_barycentrics_return_them_and_the_distance() {
    let mut rng = Rng::new(21, 0);
    let mut tried = 0;
    while tried < 500 {
        let (p0, p1, p2) =
            (point_in_cube(&mut rng, 10.0), point_in_cube(&mut rng, 10.0), point_in_cube(&mut rng, 10.0));
        let normal = (p1 - p0).cross(p2 - p0);
        let longest = (p1 - p0).length().max((p2 - p0).length()).max((p2 - p1).length());
        // Area over the longest edge squared: 0.1 keeps every angle above a few degrees.
        if normal.length() < 0.2 * longest * longest {
            continue;
        }
        let (u, v) = (rng.next_f32(), rng.next_f32());
        let (b1, b2) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        let target = p0 + b1 * (p1 - p0) + b2 * (p2 - p0);
        let dir = direction(&mut rng);
        if dir.dot(normal.normalize()).abs() < 0.2 {
            continue;
        }
        let distance = 1.0 + 20.0 * rng.next_f32();
        let ray = Ray::new(target - distance * dir, dir);
        let hit = intersect_triangle(&ray, p0, p1, p2)
            .unwrap_or_else(|| panic!("no hit at ({b1}, {b2}) of {p0} {p1} {p2} from {ray:?}"));
        assert!((hit.t - distance).abs() <= 1e-4 * distance, "t {} vs {distance}", hit.t);
        assert!(
            (hit.b1 - b1).abs() < 1e-3 && (hit.b2 - b2).abs() < 1e-3,
            "({}, {}) vs ({b1}, {b2})",
            hit.b1,
            hit.b2
        );
        tried += 1;
    }
}

/// A triangle 3000 units away, far from the origin: t is right to f32's precision there.
#[test]
fn a_triangle_far_from_the_origin_is_hit_at_the_right_distance() {
    let centre = Vec3::new(1000.0, 2000.0, -3000.0);
    let (p0, p1, p2) = (
        centre + Vec3::new(-1.0, -1.0, 0.0),
        centre + Vec3::new(1.0, -1.0, 0.0),
        centre + Vec3::new(0.0, 1.0, 0.0),
    );
    let ray = Ray::new(Vec3::new(1000.25, 2000.125, 0.0), -Vec3::Z);
    let hit = intersect_triangle(&ray, p0, p1, p2).expect("hit");
    // f32 carries about 7 digits: 3000 · 2⁻²³ · a few operations.
    assert!((hit.t - 3000.0).abs() < 3000.0 * 1e-6, "t = {}", hit.t);
    let missed = Ray::new(Vec3::new(1001.25, 2000.125, 0.0), -Vec3::Z);
    assert_eq!(intersect_triangle(&missed, p0, p1, p2), None);
}

/// A ray whose range stops short of the triangle, or starts past it, does not hit it.
#[test]
fn a_hit_outside_the_rays_range_on_either_end_is_no_hit() {
    let (p0, p1, p2) = (Vec3::new(0.0, 0.0, -2.0), Vec3::new(2.0, 0.0, -2.0), Vec3::new(0.0, 2.0, -2.0));
    let origin = Vec3::new(0.5, 0.5, 0.0);
    assert!(intersect_triangle(&Ray::segment(origin, -Vec3::Z, 2.5), p0, p1, p2).is_some());
    assert_eq!(intersect_triangle(&Ray::segment(origin, -Vec3::Z, 1.9), p0, p1, p2), None);
    let late = Ray { t_min: 2.1, ..Ray::new(origin, -Vec3::Z) };
    assert_eq!(intersect_triangle(&late, p0, p1, p2), None);
}
