//! Checkpoint 4, part 1: splitting a node's triangles in two (the object-median split).
//!
//! **Task.** Write [`object_median_split`]: choose the axis along which the triangles' centroids
//! spread the most, order the triangles by centroid along it, and split them at the middle.
//!
//! **Maths.** The centroid bounds `B` are the box around all centroids; the axis is the one with
//! the largest extent `B.max − B.min`. The first half gets the `n / 2` triangles with the smallest
//! centroid coordinate on that axis, the second half the rest. Equal coordinates are ordered by the
//! triangles' input index, so the tree is the same on every run and every machine.
//!
//! **Conventions.** The split reorders `prims` in place and returns where the second half starts;
//! the harness ([`super::build_node`]) recurses into both halves and makes leaves of at most 4
//! triangles, stored flat, depth first: a node's first child is the next node, the second is at
//! its `second_child`. Both halves are non-empty whenever `n ≥ 2`: the median split always makes
//! progress, even when every centroid is the same point.
//!
//! **Pitfalls.**
//! - Splitting by the node's *bounds* instead of the *centroid* bounds picks bad axes for long
//!   triangles.
//! - Losing or repeating a triangle: the tree's `validate()` says which.
//! - `partial_cmp(..).unwrap()` panics on NaN; `f32::total_cmp` never does.
//! - A full sort works, but only the partition matters: `select_nth_unstable_by` finds it in O(n).
//!
//! **Check:** `cargo test checkpoint4`. Handout: `checkpoints/04-bvh.md`.

use super::PrimRef;

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use crate::geometry::Aabb;

/// A split: `prims[..mid]` go to the first child, `prims[mid..]` to the second.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split {
    /// The axis (0, 1, 2) the split was made along.
    pub axis: usize,
    /// Where the second child's triangles start.
    pub mid: usize,
}

/// Splits `prims` (at least two) at the median centroid along the widest centroid axis.
pub fn object_median_split(prims: &mut [PrimRef]) -> Split {
    // BEGIN SOLUTION checkpoint4
    let centroid_bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
    let axis = centroid_bounds.longest_axis();
    let mid = prims.len() / 2;
    // Partition so that prims[mid] is where a full sort by (centroid, index) would put it.
    prims.select_nth_unstable_by(mid, |a, b| {
        a.centroid[axis].total_cmp(&b.centroid[axis]).then(a.index.cmp(&b.index))
    });
    Split { axis, mid }
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint4 {
    use super::*;
    use crate::geometry::{Aabb, Bvh, SplitMethod};
    use crate::math::Vec3;
    use crate::test_fixtures::random_and_awkward_meshes;

    fn prims_at(centroids: &[Vec3]) -> Vec<PrimRef> {
        let prim =
            |(i, &c): (usize, &Vec3)| PrimRef { index: i as u32, bounds: Aabb::from_point(c), centroid: c };
        centroids.iter().enumerate().map(prim).collect()
    }

    fn indices(prims: &[PrimRef]) -> Vec<u32> {
        let mut ids: Vec<u32> = prims.iter().map(|p| p.index).collect();
        ids.sort_unstable();
        ids
    }

    #[test]
    fn the_split_halves_along_the_widest_centroid_axis() {
        // Centroids spread 10 along z, 1 along x: the split is along z, at the median z.
        let zs = [5.0, -3.0, 9.0, 0.0, 7.0, 1.0];
        let centroids: Vec<Vec3> =
            zs.iter().enumerate().map(|(i, &z)| Vec3::new(i as f32 * 0.2, 0.0, z)).collect();
        let mut prims = prims_at(&centroids);
        let split = object_median_split(&mut prims);
        assert_eq!(
            split,
            Split { axis: 2, mid: 3 },
            "centroids spread most along z (axis 2); 6 triangles split at 3"
        );
        assert_eq!(indices(&prims[..3]), vec![1, 3, 5], "the three smallest z");
        assert_eq!(indices(&prims[3..]), vec![0, 2, 4], "the three largest z");
    }

    #[test]
    fn the_axis_is_chosen_from_centroids_not_from_triangle_bounds() {
        // Long triangles along x, centroids spread along y: the split must be along y.
        let mut prims =
            prims_at(&[Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 2.0, 0.0)]);
        for p in &mut prims {
            p.bounds = Aabb::new(p.centroid - Vec3::X * 50.0, p.centroid + Vec3::X * 50.0);
        }
        let axis = object_median_split(&mut prims).axis;
        assert_eq!(
            axis, 1,
            "the triangles' bounds are widest along x, their centroids along y: split along y"
        );
    }

    #[test]
    fn equal_centroids_are_ordered_by_index() {
        let mut prims = prims_at(&[Vec3::ONE; 7]);
        prims.reverse();
        let split = object_median_split(&mut prims);
        assert_eq!(split.mid, 3, "7 equal centroids still split at n / 2 = 3: both halves non-empty");
        assert_eq!(
            indices(&prims[..3]),
            vec![0, 1, 2],
            "ties go by input index, so every build gives one tree"
        );
    }

    #[test]
    fn trees_over_random_and_awkward_meshes_are_valid() {
        for triangles in &random_and_awkward_meshes(5) {
            let bvh = Bvh::build(triangles, SplitMethod::ObjectMedian);
            bvh.validate().unwrap_or_else(|e| panic!("{} triangles: {e}", triangles.len()));
            if triangles.len() > 1 {
                // Halving leaves of at most 4: depth is ceil(log2(n / 4)) + 1.
                let expected = (triangles.len() as f64 / 4.0).log2().ceil().max(0.0) as usize + 1;
                assert_eq!(bvh.depth(), expected, "{} triangles", triangles.len());
            }
        }
    }
}
