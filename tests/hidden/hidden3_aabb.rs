//! Checkpoint 3, hidden: the slab test against an independent oracle (the ray clipped by the six
//! face planes, one at a time), and rays inside the plane of a face.

use crate::oracle::{direction, point_in_cube};
use raylab::geometry::Aabb;
use raylab::math::{Ray, Vec3};
use raylab::rng::Rng;

/// Where `ray` is inside `aabb`, by clipping its range against each face's half-space in turn
/// (Cyrus-Beck): no slabs, no inverse directions.
fn clipped(aabb: &Aabb, ray: &Ray) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (ray.t_min, ray.t_max);
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        for (plane, inside_below) in [(aabb.min[axis], false), (aabb.max[axis], true)] {
            // Inside means o + t d <= plane (max face) or >= plane (min face).
            let side = if inside_below { plane - o } else { o - plane };
            let rate = if inside_below { d } else { -d };
            if rate == 0.0 {
                if side < 0.0 {
                    return None;
                }
            } else if rate > 0.0 {
                t1 = t1.min(side / rate);
            } else {
                t0 = t0.max(side / rate);
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Random boxes and random rays, half of them aimed at a point of the box, some starting inside:
/// the same interval as clipping, to f32 rounding, whenever the ray does not merely graze the box.
#[test]
fn random_rays_overlap_random_boxes_where_face_clipping_says() {
    let mut rng = Rng::new(31, 0);
    let (mut hits, mut misses) = (0, 0);
    for _ in 0..20_000 {
        let aabb = Aabb::new(point_in_cube(&mut rng, 3.0), point_in_cube(&mut rng, 3.0));
        let origin = point_in_cube(&mut rng, 4.0);
        let dir = if rng.next_f32() < 0.5 {
            let inside = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            aabb.min + inside * (aabb.max - aabb.min) - origin
        } else {
            direction(&mut rng)
        };
        let ray = Ray::segment(origin, dir, 1.0 + 8.0 * rng.next_f32());
        let want = clipped(&aabb, &ray);
        let got = aabb.intersect(&ray);
        match (want, got) {
            (Some((a0, a1)), Some((b0, b1))) => {
                hits += 1;
                assert!(
                    (a0 - b0).abs() < 1e-4 && (a1 - b1).abs() < 1e-4,
                    "{aabb:?} {ray:?}: {got:?} vs {want:?}"
                );
            }
            (None, None) => misses += 1,
            // A grazing ray, within rounding of the box: either answer is right.
            (Some((a0, a1)), None) | (None, Some((a0, a1))) if a1 - a0 < 1e-4 => {}
            _ => panic!("{aabb:?} {ray:?}: {got:?}, clipping says {want:?}"),
        }
    }
    assert!(hits > 2_000 && misses > 2_000, "{hits} hits, {misses} misses: the test must see both");
}

/// Rays parallel to a pair of faces, with a direction component of +0 or -0: between the faces or
/// on one (the box is closed) they overlap it, outside they do not.
#[test]
fn rays_in_the_plane_of_a_face_follow_the_face_with_either_signed_zero() {
    let aabb = Aabb::new(Vec3::ZERO, Vec3::ONE);
    for zero in [0.0f32, -0.0] {
        for (y, overlaps) in [(0.5, true), (1.0, true), (0.0, true), (1.5, false), (-0.5, false)] {
            let mut ray = Ray::new(Vec3::new(-1.0, y, 0.5), Vec3::new(1.0, zero, 0.0));
            ray.inv_dir = ray.dir.recip();
            let got = aabb.intersect(&ray);
            assert_eq!(got.is_some(), overlaps, "y = {y}, dir.y = {zero:?}: {got:?}");
            if let Some((t_in, t_out)) = got {
                assert!((t_in - 1.0).abs() < 1e-6 && (t_out - 2.0).abs() < 1e-6, "{got:?}");
            }
        }
    }
}
