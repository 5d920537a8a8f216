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
//! **Conventions.** Same contract as [`super::split::object_median_split`]: reorder `prims` in
//! place, return a split with both halves non-empty. The partition is deterministic (it depends
//! only on the input order), so the tree is the same on every run.

use super::split::Split;
use super::PrimRef;
use crate::geometry::Aabb;

/// Slices of the centroid bounds per axis; 16 is the usual trade-off between build time and tree
/// quality (more bins barely lower the traversal cost).
pub const BINS: usize = 16;

/// Splits `prims` (at least two) at the binned plane of least SAH cost.
pub fn sah_split(prims: &mut [PrimRef]) -> Split {
    let centroid_bounds = prims.iter().fold(Aabb::EMPTY, |b, p| b.grow(p.centroid));
    let binnings = [0, 1, 2].map(|axis| Binning::new(&centroid_bounds, axis));
    // One pass over the triangles fills the bins of all three axes.
    let mut bins = [[Bin::EMPTY; BINS]; 3];
    for p in prims.iter() {
        for (axis_bins, binning) in bins.iter_mut().zip(&binnings) {
            let bin = &mut axis_bins[binning.of(p)];
            bin.count += 1;
            bin.bounds = bin.bounds.union(p.bounds);
        }
    }
    let best = (0..3)
        // Centroids that do not spread along an axis all share one bin: no plane there.
        .filter(|&axis| centroid_bounds.extent()[axis] > 0.0)
        .filter_map(|axis| best_plane(&bins[axis], prims.len()).map(|(bin, cost)| (axis, bin, cost)))
        .min_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
    let Some((axis, first_right_bin, _)) = best else {
        // Every centroid is the same point: no plane separates them, and any halving is as good.
        return Split { axis: 0, mid: prims.len() / 2 };
    };
    let mid = partition(prims, |p| binnings[axis].of(p) < first_right_bin);
    Split { axis, mid }
}

/// The triangles whose centroids fall in one slice: how many, and the box around them.
#[derive(Clone, Copy)]
struct Bin {
    count: u32,
    bounds: Aabb,
}

impl Bin {
    const EMPTY: Bin = Bin { count: 0, bounds: Aabb::EMPTY };
}

/// Maps a centroid coordinate on one axis to its bin.
struct Binning {
    axis: usize,
    min: f32,
    scale: f32,
}

impl Binning {
    fn new(centroid_bounds: &Aabb, axis: usize) -> Self {
        let extent = centroid_bounds.extent()[axis];
        Self { axis, min: centroid_bounds.min[axis], scale: BINS as f32 / extent }
    }

    fn of(&self, prim: &PrimRef) -> usize {
        // The largest centroid lands on BINS exactly: clamp it into the last bin. (A zero extent
        // gives 0 · ∞ = NaN, which `as` turns into bin 0.)
        (((prim.centroid[self.axis] - self.min) * self.scale) as usize).min(BINS - 1)
    }
}

/// The cheapest of the `BINS - 1` planes between bins, as (first bin of the second child, cost),
/// or `None` if every plane leaves one side empty. `n` is the number of triangles binned.
fn best_plane(bins: &[Bin; BINS], n: usize) -> Option<(usize, f32)> {
    // Sweep from the right: right_cost[i] is the cost of bins i.. as one child.
    let mut right_cost = [0f32; BINS];
    let mut acc = Bin::EMPTY;
    for i in (1..BINS).rev() {
        acc = Bin { count: acc.count + bins[i].count, bounds: acc.bounds.union(bins[i].bounds) };
        right_cost[i] = acc.count as f32 * acc.bounds.half_area();
    }
    // Sweep from the left, combining with the right sweep; skip planes with an empty side.
    let mut acc = Bin::EMPTY;
    let mut best: Option<(usize, f32)> = None;
    for i in 1..BINS {
        acc = Bin { count: acc.count + bins[i - 1].count, bounds: acc.bounds.union(bins[i - 1].bounds) };
        if acc.count == 0 || acc.count as usize == n {
            continue;
        }
        let cost = acc.count as f32 * acc.bounds.half_area() + right_cost[i];
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
    use crate::geometry::{Bvh, SplitMethod, Triangle};
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
