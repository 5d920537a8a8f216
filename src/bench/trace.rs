//! Tracing a workload through a BVH on a given number of threads, and what it measured.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::geometry::{Bvh, TraversalStats};
use crate::math::Ray;

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
pub fn trace(bvh: &Bvh, rays: &[Ray], any_hit: bool) -> TraceReport {
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
    use crate::bench::{bumpy_icosphere, Workload};
    use crate::geometry::SplitMethod;

    #[test]
    fn every_incoherent_ray_hits_the_closed_sphere_and_sah_tests_fewer_boxes() {
        // The bumpy sphere encloses the ball of radius 0.97, so every ray aimed at a point
        // inside that ball must cross it; at most 1 - 0.97^3 = 8.7 % of targets uniform in the
        // unit ball lie outside it. Any-hit, closest-hit and both trees must agree on the count.
        let triangles: Vec<_> = bumpy_icosphere(8).triangles().collect();
        let rays = &Workload::Incoherent.rays()[..20_000];
        let median = Bvh::build(&triangles, SplitMethod::ObjectMedian);
        let sah = Bvh::build(&triangles, SplitMethod::Sah);
        let closest = trace(&median, rays, false);
        assert_eq!(trace(&median, rays, true).hits, closest.hits);
        assert_eq!(trace(&sah, rays, false).hits, closest.hits);
        assert!(closest.hits > rays.len() * 9 / 10, "{closest:?}");
        assert!(trace(&sah, rays, false).stats.box_tests < closest.stats.box_tests);
    }
}
