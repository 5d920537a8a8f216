//! Tracing a ray through the wide BVH: eight box tests at once, nearest child first.
//!
//! **Box test.** All eight children's boxes at once ([`super::boxes`]), with AVX2 where the CPU has
//! it (checked once per process by `std`), else two four-lane halves.
//!
//! **Order.** Children whose boxes the ray meets are pushed on the stack farthest first, each with
//! its entry distance `t_in`, so the nearest is visited next; an entry popped after a hit has
//! shrunk `t_max` below its `t_in` is skipped without a test (its box test would now fail: the
//! box was met on `[t_in, t_out]` and the range is now `[t_min, t_max]` with `t_max < t_in`).
//!
//! **Memory.** On x86-64 every child met is prefetched as it is pushed ([`WideBvh::prefetch`]).

use super::boxes::{BoxTest, Portable};
use super::{Child, Link, Packet, WideBvh, WideNode, WIDTH};
use crate::geometry::{BvhHit, TraversalStats};
use crate::math::Ray;

/// Entries the stack can hold: a node pushes at most `WIDTH − 1` more than it pops, and the tree
/// is no deeper than the binary tree's [`crate::geometry::bvh::MAX_DEPTH`].
const STACK: usize = (WIDTH - 1) * crate::geometry::bvh::MAX_DEPTH + 1;

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
        #[cfg(target_arch = "x86_64")]
        if self.use_avx2 {
            // SAFETY: `use_avx2` is set only where the CPU has AVX2 (`WideBvh::collapse`).
            return unsafe { self.traverse_avx2(ray, any_hit, stats) };
        }
        self.traverse_with::<Portable>(ray, any_hit, stats)
    }

    /// [`WideBvh::traverse`] compiled for AVX2, boxes tested by [`super::boxes::Avx2`].
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn traverse_avx2(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit> {
        self.traverse_with::<super::boxes::Avx2>(ray, any_hit, stats)
    }

    /// Asks the CPU to start loading the node or packet `link` names into its cache, so that it
    /// is there, or on its way, when the traversal comes to it: children met are pushed long
    /// before most of them are popped, and incoherent rays spend most of their time waiting for
    /// memory (prefetching every child met: +29% on raybench's incoherent rays, +25% on shadow
    /// rays, +9% on primary rays; docs/PERFORMANCE.md).
    #[inline(always)]
    fn prefetch(&self, link: Link) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            use std::mem::size_of;
            let (start, bytes) = match link.child() {
                Child::Node(n) => {
                    (self.nodes.as_ptr().wrapping_add(n as usize).cast::<i8>(), size_of::<WideNode>())
                }
                Child::Leaf { packet, .. } => {
                    (self.packets.as_ptr().wrapping_add(packet as usize).cast::<i8>(), size_of::<Packet>())
                }
                Child::Empty => return,
            };
            // One prefetch per 64 bytes from the start: a 176-byte packet, 16-byte aligned, spans
            // four lines half the time and then its last one is left to the hardware. Covering
            // it too (the exact line count, or packets aligned to a line) was no faster on
            // incoherent and shadow rays and 2-6% slower on primary ones (docs/PERFORMANCE.md).
            for offset in (0..bytes).step_by(64) {
                // SAFETY: prefetching never faults, whatever the address.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(offset)) };
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = link; // elsewhere the hardware's own prefetcher does what it can
    }

    /// The traversal, with the box tests of `B`.
    #[inline(always)]
    fn traverse_with<B: BoxTest>(
        &self,
        ray: &Ray,
        any_hit: bool,
        stats: &mut TraversalStats,
    ) -> Option<BvhHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut ray = *ray;
        let lanes = B::new(&ray);
        let mut closest = None;
        let mut stack = [(Link::EMPTY, 0.0f32); STACK];
        let mut len = 0;
        let mut next = Link::new(Child::Node(0));
        loop {
            match next.child() {
                // A leaf: its packet of triangles, each hit shrinking the ray.
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
                // A node: its children's boxes at once, those met pushed.
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
                        self.prefetch(entry.0);
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
    /// fewer than twice its box tests: a visit tests all of a node's boxes, up to eight, at once,
    /// so the visits fall several times over while the box tests barely rise.
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

    /// The portable box tests give the same answers as the AVX2 ones this CPU may trace with:
    /// brute force on the awkward meshes (rays in slab planes, NaN in the slab test), and the
    /// same hits as the dispatching traversal on random ones.
    #[test]
    fn the_portable_box_tests_agree_with_whatever_the_cpu_uses() {
        let mut rng = Rng::new(44, 0);
        let mut meshes = awkward_meshes();
        meshes.push(random_mesh(&mut rng, 1000));
        for triangles in &meshes {
            let wide = WideBvh::collapse(&Bvh::build(triangles, SplitMethod::Sah));
            let mut stats = TraversalStats::default();
            check_tracer_against_brute_force(triangles, 2_000, &mut rng, |ray, any_hit| {
                let portable = wide.traverse_with::<Portable>(ray, any_hit, &mut stats);
                assert_eq!(portable, wide.traverse(ray, any_hit, &mut stats), "{ray:?}");
                portable
            });
        }
    }

    #[test]
    fn a_tree_over_nothing_is_never_hit() {
        let wide = WideBvh::collapse(&Bvh::build(&[], SplitMethod::Sah));
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(wide.intersect(&ray, &mut TraversalStats::default()), None);
    }
}
