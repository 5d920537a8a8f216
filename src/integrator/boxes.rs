//! The boxes view: each object's bounding box, found by the slab test of checkpoint 3 alone (no
//! BVH, no triangle), coloured by the face the ray enters it through as the normals view colours
//! surfaces, `(n + 1) / 2` for the face's outward normal `n`. Scenes of `kind = "boxes"` show
//! checkpoint 3 in a picture before checkpoint 4 exists: a box behind the camera in front of the
//! others (`t_min` ignored), boxes missing where rays point backwards along an axis (near and far
//! not swapped), flat boxes gone (an open interval).

use crate::geometry::Aabb;
use crate::math::{Ray, Vec3};
use crate::scene::Scene;

/// The colour of the box `ray` enters first in its range; black where it enters none.
pub fn box_colour(scene: &Scene, ray: Ray) -> Vec3 {
    let entered = scene.object_boxes.iter().filter_map(|b| b.intersect(&ray).map(|(t_in, _)| (t_in, b)));
    entered
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(Vec3::ZERO, |(t_in, b)| (entry_normal(b, ray.at(t_in), ray.dir) + 1.0) * 0.5)
}

/// The outward normal of the face of `b` that a ray along `dir` enters through at `p`: the face
/// plane nearest to `p` (in units of the box's extent along each axis, so a flat box's own plane
/// wins), facing against `dir`.
fn entry_normal(b: &Aabb, p: Vec3, dir: Vec3) -> Vec3 {
    let extent = b.extent().max(Vec3::splat(1e-6));
    let distance =
        |axis: usize| (p[axis] - b.min[axis]).abs().min((p[axis] - b.max[axis]).abs()) / extent[axis];
    let axis = (0..3).min_by(|&i, &j| distance(i).total_cmp(&distance(j))).unwrap_or(0);
    let mut n = Vec3::ZERO;
    n[axis] = if dir[axis] > 0.0 { -1.0 } else { 1.0 };
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point on each face of a box gives that face's outward normal, facing the ray; on a flat
    /// box, its own plane, from either side.
    #[test]
    fn the_entry_face_is_the_nearest_face_facing_the_ray() {
        let b = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 4.0));
        let down = Vec3::new(0.3, -1.0, -0.2);
        assert_eq!(entry_normal(&b, Vec3::new(1.0, 0.5, 4.0), -Vec3::Z), Vec3::Z);
        assert_eq!(entry_normal(&b, Vec3::new(0.0, 0.9, 3.9), Vec3::X), -Vec3::X);
        assert_eq!(entry_normal(&b, Vec3::new(1.9, 1.0, 2.0), down), Vec3::Y);
        let flat = Aabb::new(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        assert_eq!(entry_normal(&flat, Vec3::new(0.99, 0.0, 0.0), down), Vec3::Y);
        assert_eq!(entry_normal(&flat, Vec3::new(0.99, 0.0, 0.0), -down), -Vec3::Y);
    }
}
