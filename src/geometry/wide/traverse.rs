//! Tracing a ray through the wide BVH: eight box tests at once, nearest child first.
//!
//! **Box test.** The slab test of checkpoint 3, lane by lane over a node's eight children: per axis
//! the near and far plane distances `(plane − o) · inv_dir` (the near plane is `max` when the ray
//! travels toward decreasing coordinates), `t_in` raised and `t_out` lowered only by comparisons
//! that are false for NaN, as the scalar test does, so a lane's answer is the scalar answer.
//!
//! **Order.** Children whose boxes the ray meets are pushed on the stack farthest first, each with
//! its entry distance `t_in`, so the nearest is visited next; an entry popped after a hit has
//! shrunk `t_max` below its `t_in` is skipped without a test (its box test would now fail: the
//! box was met on `[t_in, t_out]` and the range is now `[t_min, t_max]` with `t_max < t_in`).

use wide::{f32x8, CmpLe};
#[cfg(not(target_arch = "x86_64"))]
use wide::{CmpGt, CmpLt};

use super::{Child, Link, WideBvh, WideNode, WIDTH};
use crate::geometry::{BvhHit, TraversalStats};
use crate::math::Ray;

/// Entries the stack can hold: a node pushes at most `LANES − 1` more than it pops, and the tree
/// is no deeper than the binary tree's [`crate::geometry::bvh::MAX_DEPTH`].
const STACK: usize = (WIDTH - 1) * crate::geometry::bvh::MAX_DEPTH + 1;

/// A ray spread over the lanes, ready for box tests.
struct RayLanes {
    origin: [f32x8; 3],
    inv_dir: [f32x8; 3],
    /// Per axis, whether the ray travels toward decreasing coordinates (`inv_dir < 0`).
    negative: [bool; 3],
    t_min: f32x8,
}

impl RayLanes {
    fn new(ray: &Ray) -> Self {
        Self {
            origin: ray.origin.to_array().map(f32x8::splat),
            inv_dir: ray.inv_dir.to_array().map(f32x8::splat),
            negative: ray.inv_dir.to_array().map(|i| i < 0.0),
            t_min: f32x8::splat(ray.t_min),
        }
    }

    /// Which of `node`'s children's boxes the ray meets within `[t_min, t_max]` (bit `slot` of
    /// the mask), and where it enters each.
    #[inline]
    fn boxes(&self, node: &WideNode, t_max: f32) -> (i32, [f32; WIDTH]) {
        let mut t_in = self.t_min;
        let mut t_out = f32x8::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.negative[axis] {
                (node.max[axis], node.min[axis])
            } else {
                (node.min[axis], node.max[axis])
            };
            let near = (f32x8::from(near) - self.origin[axis]) * self.inv_dir[axis];
            let far = (f32x8::from(far) - self.origin[axis]) * self.inv_dir[axis];
            t_in = raise(near, t_in);
            t_out = lower(far, t_out);
        }
        (t_in.cmp_le(t_out).move_mask(), t_in.to_array())
    }
}

/// `if a > b { a } else { b }` lane by lane: a NaN `a` leaves `b`, as in the scalar slab test.
#[inline]
fn raise(a: f32x8, b: f32x8) -> f32x8 {
    // MAXPS is defined as exactly this (Intel SDM: `src1 > src2 ? src1 : src2`), in one
    // instruction; elsewhere (NEON's max returns NaN) compare and blend.
    #[cfg(target_arch = "x86_64")]
    return a.fast_max(b);
    #[cfg(not(target_arch = "x86_64"))]
    return a.cmp_gt(b).blend(a, b);
}

/// `if a < b { a } else { b }` lane by lane: a NaN `a` leaves `b` (MINPS, as [`raise`]).
#[inline]
fn lower(a: f32x8, b: f32x8) -> f32x8 {
    #[cfg(target_arch = "x86_64")]
    return a.fast_min(b);
    #[cfg(not(target_arch = "x86_64"))]
    return a.cmp_lt(b).blend(a, b);
}

impl WideBvh {
    /// The closest hit of `ray` in its range, or `None`.
    pub fn intersect(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<BvhHit> {
        self.traverse(ray, false, stats)
    }

    /// Whether anything blocks `ray` in its range.
    pub fn occluded(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        self.traverse(ray, true, stats).is_some()
    }

    /// The closest hit of `ray`, or with `any_hit` the first hit found, as
    /// [`crate::geometry::Bvh::traverse`] answers; counts box and triangle tests in `stats`.
    pub fn traverse(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut ray = *ray;
        let lanes = RayLanes::new(&ray);
        let mut closest = None;
        let mut stack = [(Link::EMPTY, 0.0f32); STACK];
        let mut len = 0;
        let mut next = Link::new(Child::Node(0));
        loop {
            match next.child() {
                Child::Leaf { packet, triangles } => {
                    stats.triangle_tests += triangles as u64;
                    if let Some((prim, hit)) = self.packets[packet as usize].intersect(&ray) {
                        ray.t_max = hit.t;
                        closest = Some(BvhHit { prim, hit });
                        if any_hit {
                            return closest;
                        }
                    }
                }
                Child::Node(n) => {
                    let node = &self.nodes[n as usize];
                    stats.box_tests += node.used as u64;
                    let (mask, t_ins) = lanes.boxes(node, ray.t_max);
                    // The children met go on the stack sorted by entry distance, farthest
                    // first; the last, the nearest, is taken off again and visited next. (Shadow
                    // rays too: unsorted, they tested 8% more boxes on raybench's shadow rays.)
                    let base = len;
                    // Empty slots are never met: the mask holds children only.
                    let mut bits = mask as u32;
                    while bits != 0 {
                        let slot = bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        let entry = (node.links[slot], t_ins[slot]);
                        let mut i = len;
                        while i > base && stack[i - 1].1 < entry.1 {
                            stack[i] = stack[i - 1];
                            i -= 1;
                        }
                        stack[i] = entry;
                        len += 1;
                    }
                    if len > base {
                        len -= 1;
                        next = stack[len].0;
                        continue;
                    }
                }
                Child::Empty => unreachable!("empty slots have the empty box, which no ray meets"),
            }
            // Pop the nearest waiting child the ray can still meet before its closest hit.
            loop {
                if len == 0 {
                    return closest;
                }
                len -= 1;
                let (link, t_in) = stack[len];
                if t_in <= ray.t_max {
                    next = link;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Bvh, SplitMethod, Triangle};
    use crate::math::Vec3;
    use crate::rng::Rng;
    use crate::test_fixtures::{awkward_meshes, check_tracer_against_brute_force, random_mesh};

    /// Closest hits equal testing every triangle, on random and awkward meshes (axis-aligned and
    /// coplanar triangles, rays in slab planes), collapsed from both binary trees.
    #[test]
    fn closest_hits_equal_brute_force() {
        let mut rng = Rng::new(42, 0);
        let mut meshes: Vec<Vec<Triangle>> =
            [1, 2, 5, 17, 100, 1000].map(|n| random_mesh(&mut rng, n)).into();
        meshes.extend(awkward_meshes());
        for triangles in &meshes {
            for method in [SplitMethod::ObjectMedian, SplitMethod::Sah] {
                let wide = WideBvh::collapse(&Bvh::build(triangles, method));
                let mut stats = TraversalStats::default();
                check_tracer_against_brute_force(triangles, 2_000, &mut rng, |ray, any_hit| {
                    wide.traverse(ray, any_hit, &mut stats)
                });
            }
        }
    }

    /// The same hit, bit for bit, as the binary tree it was collapsed from, ray by ray, with
    /// fewer node visits: four boxes per visit instead of one (the counts are box tests, so they
    /// barely fall; the visits halve).
    #[test]
    fn hits_equal_the_binary_trees() {
        let mut rng = Rng::new(43, 0);
        let triangles = random_mesh(&mut rng, 5_000);
        let bvh = Bvh::build(&triangles, SplitMethod::Sah);
        let wide = WideBvh::collapse(&bvh);
        let (mut binary_stats, mut wide_stats) = (TraversalStats::default(), TraversalStats::default());
        for _ in 0..5_000 {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0 - 1.5;
            let ray = Ray::new(origin, crate::test_fixtures::random_unit_vector(&mut rng));
            let (a, b) = (bvh.intersect(&ray, &mut binary_stats), wide.intersect(&ray, &mut wide_stats));
            assert_eq!(a.map(|h| h.hit), b.map(|h| h.hit), "{ray:?}");
            assert_eq!(bvh.occluded(&ray, &mut binary_stats), wide.occluded(&ray, &mut wide_stats));
        }
        assert!(wide_stats.box_tests < 2 * binary_stats.box_tests, "{wide_stats:?} vs {binary_stats:?}");
    }

    #[test]
    fn a_tree_over_nothing_is_never_hit() {
        let wide = WideBvh::collapse(&Bvh::build(&[], SplitMethod::Sah));
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(wide.intersect(&ray, &mut TraversalStats::default()), None);
    }
}
