//! The tree view: how many of the BVH's boxes each camera ray crosses before its closest hit, as
//! a heat map. Scenes of `kind = "boxes_crossed"` show checkpoint 4 in a picture before checkpoint
//! 5 exists, and show what the image of the surfaces cannot: the shape of the tree the split built,
//! and whether the traversal's hit is the closest.
//!
//! **What it counts.** The nodes whose boxes the ray meets between `t_min` and its closest hit
//! (or `t_max` where it hits nothing), tested by checkpoint 3's slab test. That is the least work
//! any traversal of this tree can do for the ray, so every correct traversal, whatever order it
//! visits children in, draws the same picture; a tree split along the wrong axis, or a hit that
//! is not the closest, draws another. (Work beyond it, such as opening the far child first, shows
//! in the traversal's own counts, [`crate::geometry::TraversalStats`], not here.)
//!
//! **Why a scan.** Every node's box contains its children's, and the slab test is monotone in the
//! box's bounds, so a ray meets a node's box only if it meets its parent's: scanning all nodes
//! counts what a walk from the root would.
//!
//! **The scale.** `n` boxes are coloured `heat(n / FULL_SCALE)` on a black, purple, red, orange,
//! yellow ramp (the display colours of the perceptually even "inferno" map), clamped at
//! [`FULL_SCALE`] boxes: pale yellow.
//!
//! Without the binary tree (`render`'s stand-in while checkpoint 3 or 4 is unwritten, or
//! `--accel wide`) no box is counted: the picture is black.

use crate::geometry::{Bvh, TraversalStats};
use crate::image_io::srgb_to_linear;
use crate::math::{Ray, Vec3};
use crate::scene::World;

/// The boxes drawn pale yellow, the top of the scale.
pub const FULL_SCALE: f32 = 64.0;

/// Display (sRGB-encoded) colours at equal steps of the scale, from 0 tests to [`FULL_SCALE`].
const RAMP: [[f32; 3]; 5] =
    [[0.0, 0.0, 0.02], [0.34, 0.06, 0.43], [0.87, 0.27, 0.23], [0.99, 0.65, 0.04], [0.99, 1.0, 0.64]];

/// The heat colour (linear RGB) of the boxes `ray` crosses before its closest hit.
pub fn boxes_crossed_colour(world: &World, ray: Ray) -> Vec3 {
    heat(world.bvh().map_or(0, |bvh| boxes_crossed(bvh, ray)) as f32 / FULL_SCALE)
}

/// How many of the tree's boxes `ray` meets up to its closest hit (in its whole range where it
/// hits nothing). Up to a hair beyond the hit (a relative 1e-4), so that the boxes whose face
/// holds the surface hit, such as its own leaf's on a flat wall, count whatever the rounding of
/// `t`.
fn boxes_crossed(bvh: &Bvh, mut ray: Ray) -> usize {
    if let Some(hit) = bvh.intersect(&ray, &mut TraversalStats::default()) {
        ray.t_max = hit.hit.t * (1.0 + 1e-4);
    }
    bvh.nodes().iter().filter(|node| node.bounds().intersect(&ray).is_some()).count()
}

/// The ramp's colour at `x` in `[0, 1]` (clamped), interpolated in display values and decoded to
/// linear, so that the written image shows the ramp's own colours.
fn heat(x: f32) -> Vec3 {
    let position = x.clamp(0.0, 1.0) * (RAMP.len() - 1) as f32;
    let step = (position as usize).min(RAMP.len() - 2);
    let f = position - step as f32;
    let display = Vec3::from(RAMP[step]).lerp(Vec3::from(RAMP[step + 1]), f);
    display.to_array().map(srgb_to_linear).into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::SplitMethod;
    use crate::image_io::linear_to_srgb;
    use crate::test_fixtures::stack_of_planes;

    /// Down a stack of planes split by the object median, a ray that hits the first plane
    /// crosses exactly the boxes on the root-to-leaf path of that plane (the others lie beyond
    /// it), from either end; a ray inside every box that misses every triangle crosses them all;
    /// a ray beside the stack, none.
    #[test]
    fn a_hit_crosses_the_boxes_on_its_path_and_a_miss_inside_the_boxes_crosses_all() {
        let bvh = Bvh::build(&stack_of_planes(256), SplitMethod::ObjectMedian);
        let depth = bvh.depth();
        assert_eq!(depth, 7, "64 leaves of 4 planes: a path of 7 nodes");
        assert_eq!(boxes_crossed(&bvh, Ray::new(Vec3::new(0.1, 0.3, -1.0), Vec3::Z)), depth);
        assert_eq!(boxes_crossed(&bvh, Ray::new(Vec3::new(0.1, 0.3, 3.0), -Vec3::Z)), depth);
        let beside_the_apex = Ray::new(Vec3::new(0.9, 0.9, -1.0), Vec3::Z);
        assert_eq!(boxes_crossed(&bvh, beside_the_apex), bvh.nodes().len());
        assert_eq!(boxes_crossed(&bvh, Ray::new(Vec3::new(3.0, 0.0, -1.0), Vec3::Z)), 0);
    }

    /// The ends of the scale are the ramp's ends, values beyond it are clamped, and more tests
    /// are never darker.
    #[test]
    fn the_ramp_runs_from_near_black_to_pale_yellow_and_brightens_with_the_count() {
        let display = |x: f32| heat(x).to_array().map(linear_to_srgb);
        for (got, want) in display(0.0).iter().zip(RAMP[0]) {
            assert!((got - want).abs() < 1e-3, "{got} {want}");
        }
        for (got, want) in display(1.0).iter().zip(RAMP[4]) {
            assert!((got - want).abs() < 1e-3, "{got} {want}");
        }
        assert_eq!(heat(3.0), heat(1.0));
        let luminance = |x: f32| heat(x).dot(Vec3::new(0.2126, 0.7152, 0.0722));
        for i in 0..100 {
            let (a, b) = (i as f32 / 100.0, (i + 1) as f32 / 100.0);
            assert!(luminance(a) <= luminance(b), "darker at {b} than at {a}");
        }
    }
}
