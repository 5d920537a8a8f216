//! Tracing a workload through a BVH on a given number of threads, and what it measured.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use raylab::geometry::{Bvh, BvhHit, TraversalStats, WideBvh};
use raylab::math::Ray;

/// A tree rays can be traced through: the binary BVH of checkpoint 4, or the harness's wide one.
pub trait Tracer: Sync {
    /// The closest hit, or with `any_hit` the first found, counting work in `stats`.
    fn traverse(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit>;
}

impl Tracer for Bvh {
    fn traverse(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit> {
        Bvh::traverse(self, ray, any_hit, stats)
    }
}

impl Tracer for WideBvh {
    fn traverse(&self, ray: &Ray, any_hit: bool, stats: &mut TraversalStats) -> Option<BvhHit> {
        WideBvh::traverse(self, ray, any_hit, stats)
    }
}

/// Rays per parallel task: large enough that scheduling costs nothing, small enough to balance.
const CHUNK: usize = 4096;

/// What one pass over a workload did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceReport {
    /// Rays traced.
    pub rays: usize,
    /// Rays that hit something.
    pub hits: usize,
    /// Box and triangle tests, summed over all rays.
    pub stats: TraversalStats,
    /// Wall time of the pass.
    pub time: Duration,
}

impl TraceReport {
    /// Millions of rays per second.
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64() / 1e6
    }

    /// Mean ray-box tests per ray.
    pub fn box_tests_per_ray(&self) -> f64 {
        self.stats.box_tests as f64 / self.rays as f64
    }

    /// Mean ray-triangle tests per ray.
    pub fn triangle_tests_per_ray(&self) -> f64 {
        self.stats.triangle_tests as f64 / self.rays as f64
    }
}

/// Traces every ray (closest hit, or any hit) in the current rayon pool; counts are the same
/// whatever the number of threads.
pub fn trace(bvh: &impl Tracer, rays: &[Ray], any_hit: bool) -> TraceReport {
    let start = Instant::now();
    let (hits, stats) = rays
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut stats = TraversalStats::default();
            let hits = chunk.iter().filter(|ray| bvh.traverse(ray, any_hit, &mut stats).is_some()).count();
            (hits, stats)
        })
        .reduce(|| (0, TraversalStats::default()), |a, b| (a.0 + b.0, add(a.1, b.1)));
    TraceReport { rays: rays.len(), hits, stats, time: start.elapsed() }
}

fn add(a: TraversalStats, b: TraversalStats) -> TraversalStats {
    TraversalStats {
        box_tests: a.box_tests + b.box_tests,
        triangle_tests: a.triangle_tests + b.triangle_tests,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{bumpy_icosphere, Workload};
    use raylab::geometry::SplitMethod;

    #[test]
    fn the_trees_agree_on_every_workload_and_sah_tests_fewer_boxes() {
        let triangles: Vec<_> = bumpy_icosphere(16).triangles().collect();
        let median = Bvh::build(&triangles, SplitMethod::ObjectMedian);
        let sah = Bvh::build(&triangles, SplitMethod::Sah);
        for workload in Workload::ALL {
            // Every 53rd ray: a sample spread over the whole film or sphere.
            let rays: Vec<_> = workload.rays().into_iter().step_by(53).collect();
            let (m, s) = (trace(&median, &rays, workload.any_hit()), trace(&sah, &rays, workload.any_hit()));
            assert_eq!(m.hits, s.hits, "{workload}");
            assert!(s.stats.box_tests < m.stats.box_tests, "{workload}: sah {s:?}, median {m:?}");
        }
        // The bumpy sphere encloses the ball of radius 0.97, so every ray aimed at a point inside
        // that ball must cross it; at most 1 - 0.97^3 = 8.7 % of targets uniform in the unit ball
        // lie outside it.
        let rays: Vec<_> = Workload::Incoherent.rays().into_iter().step_by(53).collect();
        let closest = trace(&median, &rays, false);
        assert!(closest.hits as f64 > 0.913 * rays.len() as f64, "{closest:?}");
        assert_eq!(trace(&median, &rays, true).hits, closest.hits, "any-hit agrees with closest-hit");
    }

    /// The wide tree, collapsed from either binary tree, finds the same hit as that tree for
    /// every ray of every workload, bit for bit (closest hit: t and barycentrics; shadow rays:
    /// whether blocked), and visits fewer nodes: each visit tests four boxes.
    #[test]
    fn the_wide_trees_find_the_same_hits_as_the_binary_trees() {
        let triangles: Vec<_> = bumpy_icosphere(16).triangles().collect();
        for method in [SplitMethod::ObjectMedian, SplitMethod::Sah] {
            let binary = Bvh::build(&triangles, method);
            let wide = WideBvh::collapse(&binary);
            for workload in Workload::ALL {
                let rays: Vec<_> = workload.rays().into_iter().step_by(53).collect();
                let any_hit = workload.any_hit();
                let mut stats = TraversalStats::default();
                for ray in &rays {
                    let (a, b) =
                        (binary.traverse(ray, any_hit, &mut stats), wide.traverse(ray, any_hit, &mut stats));
                    if any_hit {
                        assert_eq!(a.is_some(), b.is_some(), "{workload} {method:?}: {ray:?}");
                    } else {
                        assert_eq!(a.map(|h| h.hit), b.map(|h| h.hit), "{workload} {method:?}: {ray:?}");
                    }
                }
                let (b, w) = (trace(&binary, &rays, any_hit), trace(&wide, &rays, any_hit));
                let visits = |r: &TraceReport| r.stats.box_tests;
                assert!(visits(&w) < 2 * visits(&b), "{workload} {method:?}: wide {w:?}, binary {b:?}");
            }
        }
    }
}
