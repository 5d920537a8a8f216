//! Checkpoint 4, part 2: finding what a ray hits with the BVH.
//!
//! **Task.** Write [`Bvh::traverse`]: visit the nodes whose boxes the ray meets, test the
//! triangles of the leaves reached, and return the closest hit, or, for a shadow ray
//! (`any_hit`), the first hit found.
//!
//! **Algorithm.** Depth first with an explicit stack (no recursion): start at the root; at a
//! node whose box the ray meets, a leaf tests its triangles, an interior node continues with its
//! *near* child and pushes the far one. Near is the first child when the ray travels toward
//! increasing coordinates on the node's split axis (`dir[axis] ≥ 0`), else the second (only
//! speed depends on this order, so a `−0.0` component may go either way, unlike checkpoint 3's
//! swap). Every hit shrinks `t_max` to its `t`, so boxes beyond the closest hit so far are
//! skipped: `ray` is borrowed, so work on a copy (`let mut ray = *ray;`).
//!
//! **Conventions.** Count every box test and triangle test in `stats`; tests use the counts to
//! check the traversal prunes. Use [`crate::geometry::intersect_triangle`] and
//! [`crate::geometry::Aabb::intersect`] from checkpoints 2 and 3. The tree stores its triangles
//! reordered (`self.triangles[i]`); a hit's `prim` is the triangle's index in the array given to
//! [`Bvh::build`], `self.prim_ids[i]`, not `i`.
//!
//! **Pitfalls.**
//! - Returning the first hit found as the closest: leaves are not visited in order of distance.
//! - Not shrinking `t_max`: every box along the ray is opened, and unless you compare each
//!   hit's `t` with the closest so far, the last hit found wins instead of the closest.
//! - Far child first: also right but slow. The counts in `stats` show both.
//! - An empty tree has no root: nothing to hit.
//!
//! **Check:** `cargo test checkpoint4`. Handout: `checkpoints/04-bvh.md`.

use super::Bvh;
use crate::geometry::TriangleHit;
use crate::math::Ray;

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use {
    super::{NodeView, MAX_DEPTH},
    crate::geometry::intersect_triangle,
};

/// The closest (or any) hit of a ray in a BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhHit {
    /// Input index of the triangle hit (its index in the array given to [`Bvh::build`]).
    pub prim: u32,
    /// Where the ray met it.
    pub hit: TriangleHit,
}

/// Work done by traversals, summed over the calls it is passed to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Ray-box tests made.
    pub box_tests: u64,
    /// Ray-triangle tests made.
    pub triangle_tests: u64,
}

impl Bvh {
    /// The closest hit of `ray` in its range, or `None`.
    pub fn intersect(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<BvhHit> {
        self.traverse(ray, false, stats)
    }

    /// Whether anything blocks `ray` in its range (for shadow rays: stops at the first hit).
    pub fn occluded(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        self.traverse(ray, true, stats).is_some()
    }

    /// The closest hit of `ray`, or with `any_hit` the first hit found; counts work in `stats`.
    pub fn traverse(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit> {
        // BEGIN SOLUTION checkpoint4
        if self.nodes.is_empty() {
            return None;
        }
        let mut ray = *ray;
        // Looked up by the node's axis below: an array index, where `ray.dir[axis]` would branch.
        let dir_is_negative = ray.dir.to_array().map(|d| d < 0.0);
        let mut closest = None;
        let mut stack = [0u32; MAX_DEPTH];
        let mut stack_len = 0;
        let mut node = 0usize;
        loop {
            stats.box_tests += 1;
            if self.nodes[node].bounds().intersect(&ray).is_some() {
                match self.nodes[node].view() {
                    NodeView::Leaf { first, count } => {
                        for i in first as usize..(first + count) as usize {
                            stats.triangle_tests += 1;
                            let t = &self.triangles[i];
                            if let Some(hit) = intersect_triangle(&ray, t.p0, t.p1, t.p2) {
                                ray.t_max = hit.t;
                                closest = Some(BvhHit { prim: self.prim_ids[i], hit });
                                if any_hit {
                                    return closest;
                                }
                            }
                        }
                    }
                    NodeView::Interior { axis, second_child } => {
                        let (first_child, second_child) = (node + 1, second_child as usize);
                        let (near, far) = if dir_is_negative[axis as usize] {
                            (second_child, first_child)
                        } else {
                            (first_child, second_child)
                        };
                        stack[stack_len] = far as u32;
                        stack_len += 1;
                        node = near;
                        continue;
                    }
                }
            }
            if stack_len == 0 {
                return closest;
            }
            stack_len -= 1;
            node = stack[stack_len] as usize;
        }
        // END SOLUTION
    }
}

#[cfg(test)]
mod checkpoint4 {
    use super::*;
    use crate::geometry::{SplitMethod, Triangle};
    use crate::math::Vec3;
    use crate::rng::Rng;
    use crate::test_fixtures::{awkward_meshes, check_against_brute_force, random_mesh, stack_of_planes};

    #[test]
    fn closest_hits_equal_brute_force_on_random_meshes() {
        let mut rng = Rng::new(6, 0);
        for n in [1, 2, 5, 17, 100, 1000] {
            let triangles = random_mesh(&mut rng, n);
            check_against_brute_force(&triangles, SplitMethod::ObjectMedian, 2_000, &mut rng);
        }
    }

    #[test]
    fn closest_hits_equal_brute_force_on_awkward_meshes() {
        let mut rng = Rng::new(7, 0);
        for triangles in awkward_meshes() {
            check_against_brute_force(&triangles, SplitMethod::ObjectMedian, 2_000, &mut rng);
        }
    }

    #[test]
    fn a_tree_over_nothing_is_never_hit() {
        let bvh = Bvh::build(&[], SplitMethod::ObjectMedian);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let mut stats = TraversalStats::default();
        assert_eq!(bvh.intersect(&ray, &mut stats), None, "an empty tree has no root: nothing to hit");
        assert!(!bvh.occluded(&ray, &mut stats), "an empty tree occludes nothing");
    }

    #[test]
    fn hits_beyond_t_max_are_ignored() {
        let quad = [
            Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0)),
            Triangle::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)),
        ];
        let bvh = Bvh::build(&quad, SplitMethod::ObjectMedian);
        let mut stats = TraversalStats::default();
        let short = Ray::segment(Vec3::new(0.1, 0.2, 2.0), -Vec3::Z, 1.5);
        assert_eq!(bvh.intersect(&short, &mut stats), None, "the quad is at t = 2, beyond t_max = 1.5");
        assert!(
            !bvh.occluded(&short, &mut stats),
            "a shadow ray stops at its t_max = 1.5: the quad at t = 2 does not block it"
        );
    }

    #[test]
    fn a_stack_of_planes_is_pruned_by_the_closest_hit() {
        // 256 parallel triangles along z; a ray down the axis crosses them all. Near-first
        // traversal with a shrinking t_max opens one root-to-leaf path (one box test per level),
        // then rejects each pushed far child with one more box test, and tests one leaf.
        let bvh = Bvh::build(&stack_of_planes(256), SplitMethod::ObjectMedian);
        let depth = bvh.depth() as u64;
        for (z0, dir, nearest_z) in [(-1.0, Vec3::Z, 0.0), (3.0, -Vec3::Z, 1.275)] {
            let ray = Ray::new(Vec3::new(0.1, 0.3, z0), dir);
            let mut stats = TraversalStats::default();
            let hit = bvh.intersect(&ray, &mut stats).expect("a ray down the stack's axis hits it");
            let z = ray.at(hit.hit.t).z;
            assert!(
                (z - nearest_z).abs() < 1e-5,
                "the closest plane is at z = {nearest_z}, got the one at z = {z}"
            );
            assert!(stats.box_tests < 2 * depth, "{stats:?} for depth {depth}");
            assert!((1..=4).contains(&stats.triangle_tests), "one leaf of 1 to 4 triangles: {stats:?}");
        }
    }
}
