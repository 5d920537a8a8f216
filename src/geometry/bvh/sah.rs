//! The binned surface area heuristic (SAH) split: the harness's faster tree, not a student task.
//!
//! **Idea.** A ray that meets a node's box `B` meets a child's box `C` with probability about
//! `area(C) / area(B)` (for rays of uniformly random direction). The expected cost of splitting
//! `n` triangles into `(L, R)` is therefore, up to constants shared by every candidate,
//!
//! ```text
//!   cost(L, R) = |L| · area(bounds(L)) + |R| · area(bounds(R))
//! ```
//!
//! and the best split minimises it. Trying every position on every axis costs O(n log n) per node;
//! *binning* tries only the planes between [`BINS`] equal slices of the centroid bounds on each
//! axis, which costs O(n) per node and finds trees almost as good (Wald, "On fast Construction of
//! SAH-based Bounding Volume Hierarchies", 2007).
//!
//! **Speed.** Points and boxes are four-lane vectors ([`super::lanes`]): the three bins of a
//! centroid come from one subtraction, multiplication and truncation, and a bin's box grows by one
//! SIMD `min` and `max`. The 1M-triangle build took 0.63 s with `Vec3` and
//! [`crate::geometry::Aabb`], and takes 0.49 s with lanes here and for the node boxes in
//! [`super::build_node`]; the tree is the same (docs/PERFORMANCE.md).
//!
//! **Conventions.** Same contract as [`super::split::object_median_split`]: reorder `prims` in
//! place, return a split with both halves non-empty. The partition is deterministic (it depends
//! only on the input order), so the tree is the same on every run.

use wide::{f32x4, i32x4};

use super::lanes::{lanes, Box4};
use super::split::Split;
use super::PrimRef;

/// Slices of the centroid bounds per axis; 16 is the usual trade-off between build time and tree
/// quality (more bins barely lower the traversal cost).
pub const BINS: usize = 16;

/// Splits `prims` (at least two) at the binned plane of least SAH cost.
pub fn sah_split(prims: &mut [PrimRef]) -> Split {
    let centroids = prims.iter().fold(Box4::EMPTY, |b, p| b.grow(lanes(p.centroid)));
    let binning = Binning::new(centroids);
    // One pass over the triangles fills the bins of all three axes.
    let mut bins = [[Bin::EMPTY; BINS]; 3];
    for p in prims.iter() {
        let bounds = Box4::of(&p.bounds);
        for (axis_bins, bin) in bins.iter_mut().zip(binning.of(p)) {
            let bin = &mut axis_bins[bin];
            bin.count += 1;
            bin.bounds = bin.bounds.union(bounds);
        }
    }
    let extent = (centroids.max - centroids.min).to_array();
    let best = (0..3)
        // Centroids that do not spread along an axis all share one bin: no plane there.
        .filter(|&axis| extent[axis] > 0.0)
        .filter_map(|axis| best_plane(&bins[axis], prims.len()).map(|(bin, cost)| (axis, bin, cost)))
        .min_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
    let Some((axis, first_right_bin, _)) = best else {
        // Every centroid is the same point: no plane separates them, and any halving is as good.
        return Split { axis: 0, mid: prims.len() / 2 };
    };
    let mid = partition(prims, |p| binning.of(p)[axis] < first_right_bin);
    Split { axis, mid }
}

/// The triangles whose centroids fall in one slice: how many, and the box around them.
#[derive(Clone, Copy)]
struct Bin {
    count: u32,
    bounds: Box4,
}

impl Bin {
    const EMPTY: Bin = Bin { count: 0, bounds: Box4::EMPTY };

    /// The bins' triangles together.
    fn merge(self, other: Bin) -> Bin {
        Bin { count: self.count + other.count, bounds: self.bounds.union(other.bounds) }
    }
}

/// Maps a centroid to its bin on each axis, all three at once.
struct Binning {
    /// The lower corner of the centroids' bounds.
    min: f32x4,
    /// Bins per unit length, per axis: `BINS / extent`.
    scale: f32x4,
}

impl Binning {
    /// The binning of centroids bounded by `centroids`.
    fn new(centroids: Box4) -> Self {
        Self { min: centroids.min, scale: f32x4::splat(BINS as f32) / (centroids.max - centroids.min) }
    }

    /// The bin of `prim`'s centroid along x, y and z: `⌊(c − min) · scale⌋`, the largest centroid
    /// (which lands on `BINS` exactly) clamped into the last bin. A zero extent gives 0 · ∞ =
    /// NaN, which the truncation turns into bin 0, and a denormal one ∞, which it saturates, as
    /// Rust's `as` does: `trunc_int` must stay the saturating truncation (`fast_trunc_int` turns
    /// both into `i32::MIN`). The fourth lane is computed and ignored.
    #[inline]
    fn of(&self, prim: &PrimRef) -> [usize; 3] {
        let bins = ((lanes(prim.centroid) - self.min) * self.scale)
            .trunc_int()
            .max(i32x4::ZERO)
            .min(i32x4::splat(BINS as i32 - 1))
            .to_array();
        [0, 1, 2].map(|axis| bins[axis] as usize)
    }
}

/// The cheapest of the `BINS - 1` planes between bins, as (first bin of the second child, cost),
/// or `None` if every plane leaves one side empty. `n` is the number of triangles binned.
fn best_plane(bins: &[Bin; BINS], n: usize) -> Option<(usize, f32)> {
    // Sweep from the right: right_cost[i] is the cost of bins i.. as one child.
    let mut right_cost = [0f32; BINS];
    let mut acc = Bin::EMPTY;
    for i in (1..BINS).rev() {
        acc = acc.merge(bins[i]);
        right_cost[i] = acc.count as f32 * acc.bounds.aabb().half_area();
    }
    // Sweep from the left, combining with the right sweep; skip planes with an empty side.
    let mut acc = Bin::EMPTY;
    let mut best: Option<(usize, f32)> = None;
    for i in 1..BINS {
        acc = acc.merge(bins[i - 1]);
        if acc.count == 0 || acc.count as usize == n {
            continue;
        }
        let cost = acc.count as f32 * acc.bounds.aabb().half_area() + right_cost[i];
        if best.is_none_or(|(_, c)| cost < c) {
            best = Some((i, cost));
        }
    }
    best
}

/// Moves the elements for which `left` holds to the front, and returns how many there are.
fn partition(prims: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut mid = 0;
    for i in 0..prims.len() {
        if left(&prims[i]) {
            prims.swap(i, mid);
            mid += 1;
        }
    }
    mid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Aabb, Bvh, SplitMethod, Triangle};
    use crate::math::Vec3;
    use crate::rng::Rng;
    use crate::test_fixtures::{
        awkward_meshes, check_against_brute_force, random_and_awkward_meshes, random_mesh,
    };

    fn prim(index: u32, min: Vec3, max: Vec3) -> PrimRef {
        let bounds = Aabb::new(min, max);
        PrimRef { index, bounds, centroid: (bounds.min + bounds.max) / 2.0 }
    }

    #[test]
    fn two_separate_clusters_are_split_between_them_not_at_the_median() {
        // Six small boxes near x = 0 and two near x = 10: the median would cut the left cluster
        // (4 | 4); SAH separates the clusters (6 | 2), whose boxes are far smaller.
        let mut prims: Vec<PrimRef> = (0..6)
            .map(|i| prim(i, Vec3::new(i as f32 * 0.1, 0.0, 0.0), Vec3::new(i as f32 * 0.1 + 0.1, 0.1, 0.1)))
            .chain(
                (6..8)
                    .map(|i| prim(i, Vec3::new(10.0 + i as f32 * 0.1, 0.0, 0.0), Vec3::new(10.2, 0.1, 0.1))),
            )
            .collect();
        let split = sah_split(&mut prims);
        assert_eq!(split, Split { axis: 0, mid: 6 });
        let mut left: Vec<u32> = prims[..6].iter().map(|p| p.index).collect();
        left.sort_unstable();
        assert_eq!(left, vec![0, 1, 2, 3, 4, 5]);
    }

    /// All three bins at once are what the scalar formula `⌊(c − min) · scale⌋`, clamped to the
    /// bins, gives on each axis, NaN (a zero extent), ±∞ (a denormal one) and centroids outside
    /// the bounds included.
    #[test]
    fn bins_are_the_scalar_formulas_on_every_axis() {
        let mut rng = Rng::new(14, 0);
        for _ in 0..10_000 {
            // Per axis the lower bound and the extent of the centroids.
            let mut axis = || match rng.next_u32() % 4 {
                0 => (rng.next_f32() - 0.5, 0.0),
                1 => (0.0, f32::from_bits(1 + rng.next_u32() % 8)), // denormal: BINS / extent = ∞
                _ => (rng.next_f32() - 0.5, rng.next_f32() * 10.0),
            };
            let [x, y, z] = [axis(), axis(), axis()];
            let (lower, extent) = (Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1));
            // Mostly inside the bounds, some a little outside (below: a negative bin, or −∞).
            let t = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 1.4 - 0.2;
            let centroid = lower + extent * t;
            let binning = Binning::new(Box4 { min: lanes(lower), max: lanes(lower + extent) });
            let p = PrimRef { index: 0, bounds: Aabb::from_point(centroid), centroid };
            let scalar = [0, 1, 2].map(|axis| {
                let scale = BINS as f32 / ((lower + extent)[axis] - lower[axis]);
                (((centroid[axis] - lower[axis]) * scale) as usize).min(BINS - 1)
            });
            assert_eq!(binning.of(&p), scalar, "{lower} {extent} {centroid}");
        }
    }

    #[test]
    fn identical_centroids_still_split_in_two() {
        let mut prims: Vec<PrimRef> = (0..9).map(|i| prim(i, Vec3::ZERO, Vec3::ONE)).collect();
        assert_eq!(sah_split(&mut prims).mid, 4);
    }

    #[test]
    fn sah_trees_over_random_and_awkward_meshes_are_valid() {
        for triangles in &random_and_awkward_meshes(11) {
            let bvh = Bvh::build(triangles, SplitMethod::Sah);
            bvh.validate().unwrap_or_else(|e| panic!("{} triangles: {e}", triangles.len()));
        }
    }

    #[test]
    fn sah_trees_find_the_same_closest_hits_as_brute_force() {
        let mut rng = Rng::new(12, 0);
        let mut meshes: Vec<Vec<Triangle>> = [1, 5, 100, 1000].map(|n| random_mesh(&mut rng, n)).into();
        meshes.extend(awkward_meshes());
        for triangles in &meshes {
            check_against_brute_force(triangles, SplitMethod::Sah, 2_000, &mut rng);
        }
    }
}
