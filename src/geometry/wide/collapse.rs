//! Which binary nodes become wide nodes: the collapse plan, chosen by the surface area heuristic.
//!
//! **The question.** Collapsing keeps the binary tree's boxes and leaves and drops interior
//! nodes: a wide node stands for a binary node `n` and takes as its children up to eight nodes
//! below it that together cover `n`'s subtree (a *cut* of the subtree). Which cut? Opening the
//! child of largest area first, greedily, fills the nodes near the root but leaves many nearly
//! empty ones at the bottom of an unbalanced (SAH) tree: on a 1M-triangle mesh, 109,177 wide
//! nodes over 323,352 leaves, four children per node on average where eight fit. The plan below
//! makes 62,890 (six children on average), and primary and incoherent rays through it run 8%
//! faster (docs/PERFORMANCE.md).
//!
//! **The cost.** As for the binary SAH: a ray that meets a box of half area `A` inside the root's
//! `A_root` does so with probability `A / A_root`, so the expected cost of tracing a random ray
//! is, up to that constant, `Σ A(wide node) · c_node + Σ A(leaf) · c_leaf` over the wide tree.
//! Every cut keeps every binary leaf, so the second sum is the same whatever is chosen: the best
//! collapse is the one whose wide nodes have the least total area, and `c_node` drops out too.
//! Let `C(n, i)` be the least total area of the wide nodes covering `n`'s subtree when it may
//! take at most `i` slots of its wide parent (a forest of at most `i` roots):
//!
//! ```text
//! C(leaf, i)   = 0
//! C(n, 1)      = A(n) + D(n, 8)               n interior: it becomes a wide node
//! C(n, i)      = min(C(n, i − 1), D(n, i))    i ≥ 2: or its two children share the i slots
//! D(n, i)      = min over 1 ≤ k < i of C(first child, k) + C(second child, i − k)
//! ```
//!
//! Children are computed before parents (they come later in the depth-first array), so one pass
//! from the last node to the first fills the table; the collapse then reads each wide node's cut
//! off the choices. This is the dynamic programme of Ylitie, Karras and Laine (2017, "Efficient
//! incoherent ray traversal on GPUs through compressed wide BVHs"), without their leaf merging:
//! checkpoint 4's builder already stops at four triangles, all a packet holds, so no subtree
//! above a leaf would fit one.

use super::WIDTH;
use crate::geometry::bvh::NodeView;
use crate::geometry::Bvh;

/// The collapse plan of a binary tree: for every binary node and slot budget, how to spend it.
pub struct Plan {
    /// `split[n][i - 1]`: with `i` slots for `n`'s subtree, the slots its first child takes
    /// (the second takes the rest), or 0 when `i - 1` slots do as well (for `i = 1`: `n` takes
    /// the slot itself, as a leaf or as a wide node).
    split: Vec<[u8; WIDTH]>,
    /// For an interior `n` made a wide node: how many of its eight slots its first child takes.
    opened: Vec<u8>,
}

impl Plan {
    /// The least-cost plan for `bvh` (module docs).
    pub fn new(bvh: &Bvh) -> Self {
        let nodes = bvh.nodes();
        let mut cost = vec![[0.0f32; WIDTH]; nodes.len()];
        let mut split = vec![[0u8; WIDTH]; nodes.len()];
        let mut opened = vec![0u8; nodes.len()];
        for n in (0..nodes.len()).rev() {
            let NodeView::Interior { second_child, .. } = nodes[n].view() else {
                continue;
            };
            let (first, second) = (&cost[n + 1], &cost[second_child as usize]);
            // D(n, i) and its best k, for i = 2 ..= WIDTH. (Should every cost be infinite, areas
            // overflowing on an enormous mesh, the first child takes one slot: still a cut.)
            let mut shared = [(f32::INFINITY, 1u8); WIDTH];
            for (i, best) in shared.iter_mut().enumerate().skip(1) {
                for k in 1..=i {
                    let c = first[k - 1] + second[i - k];
                    if c < best.0 {
                        *best = (c, k as u8);
                    }
                }
            }
            cost[n][0] = nodes[n].bounds().half_area() + shared[WIDTH - 1].0;
            opened[n] = shared[WIDTH - 1].1;
            for i in 1..WIDTH {
                cost[n][i] = cost[n][i - 1];
                if shared[i].0 < cost[n][i] {
                    (cost[n][i], split[n][i]) = shared[i];
                }
            }
        }
        Self { split, opened }
    }

    /// The binary nodes that become the children of the wide node standing for binary node `n`,
    /// in depth-first order: `n` itself if it is a leaf (a tree of one leaf), else the best cut
    /// of its subtree into at most eight slots.
    pub fn children(&self, bvh: &Bvh, n: usize) -> Vec<usize> {
        let mut cut = Vec::with_capacity(WIDTH);
        match bvh.nodes()[n].view() {
            NodeView::Leaf { .. } => cut.push(n),
            NodeView::Interior { second_child, .. } => {
                let k = usize::from(self.opened[n]);
                self.cut(bvh, n + 1, k, &mut cut);
                self.cut(bvh, second_child as usize, WIDTH - k, &mut cut);
            }
        }
        cut
    }

    /// Appends the roots covering `n`'s subtree with at most `slots` of them.
    fn cut(&self, bvh: &Bvh, n: usize, slots: usize, out: &mut Vec<usize>) {
        // The largest budget up to `slots` that shares is the one the cost was reached with.
        let Some((budget, k)) =
            (1..=slots).rev().map(|i| (i, usize::from(self.split[n][i - 1]))).find(|&(_, k)| k != 0)
        else {
            out.push(n);
            return;
        };
        let NodeView::Interior { second_child, .. } = bvh.nodes()[n].view() else {
            unreachable!("only interior nodes share slots with their children")
        };
        self.cut(bvh, n + 1, k, out);
        self.cut(bvh, second_child as usize, budget - k, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::wide::{Child, WideBvh};
    use crate::geometry::SplitMethod;
    use crate::rng::Rng;
    use crate::test_fixtures::random_mesh;

    /// The children of `n`: both, or none for a leaf.
    fn children(bvh: &Bvh, n: usize) -> Option<[usize; 2]> {
        match bvh.nodes()[n].view() {
            NodeView::Interior { second_child, .. } => Some([n + 1, second_child as usize]),
            NodeView::Leaf { .. } => None,
        }
    }

    /// Every cut of `n`'s subtree below `n` itself: each a list of binary nodes covering it.
    fn cuts_below(bvh: &Bvh, n: usize) -> Vec<Vec<usize>> {
        let Some([first, second]) = children(bvh, n) else { return vec![] };
        let with = |m: usize| {
            let mut cuts = cuts_below(bvh, m);
            cuts.push(vec![m]);
            cuts
        };
        let (a, b) = (with(first), with(second));
        a.iter().flat_map(|x| b.iter().map(move |y| [x.clone(), y.clone()].concat())).collect()
    }

    /// The least total area of wide nodes for `n`'s subtree with `n` a wide node, by trying
    /// every cut of at most eight slots.
    fn brute_force(bvh: &Bvh, n: usize) -> f32 {
        let best = cuts_below(bvh, n)
            .into_iter()
            .filter(|cut| cut.len() <= WIDTH)
            .map(|cut| {
                cut.iter().filter(|&&m| children(bvh, m).is_some()).map(|&m| brute_force(bvh, m)).sum()
            })
            .fold(f32::INFINITY, f32::min);
        bvh.nodes()[n].bounds().half_area() + best
    }

    /// The total area of the wide tree's nodes: the root's box and every interior child's.
    fn total_area(bvh: &Bvh, wide: &WideBvh) -> f32 {
        let inner = wide.nodes().iter().flat_map(|node| {
            (0..WIDTH)
                .filter(|&s| matches!(node.child(s), Child::Node(_)))
                .map(|s| node.bounds(s).half_area())
        });
        bvh.nodes()[0].bounds().half_area() + inner.sum::<f32>()
    }

    /// The collapse reaches the least total node area of all collapses, found by enumerating
    /// every cut of small random trees (9 to 56 triangles, up to about 20 leaves).
    #[test]
    fn the_collapse_has_the_least_node_area() {
        let mut rng = Rng::new(45, 0);
        let mut checked = 0;
        for n in [9, 17, 24, 33, 40, 48, 56] {
            for method in [SplitMethod::ObjectMedian, SplitMethod::Sah] {
                let bvh = Bvh::build(&random_mesh(&mut rng, n), method);
                let (want, got) = (brute_force(&bvh, 0), total_area(&bvh, &WideBvh::collapse(&bvh)));
                assert!((got - want).abs() <= 1e-5 * want, "{n} triangles, {method:?}: {got} > {want}");
                checked += (bvh.nodes().len() > 2 * WIDTH) as u32;
            }
        }
        assert!(checked >= 6, "the trees should be large enough to need more than one wide node");
    }

    /// A mesh so large that its boxes' areas overflow to infinity still collapses into a valid
    /// tree (every cut then costs the same).
    #[test]
    fn overflowing_areas_still_give_a_valid_tree() {
        let mut rng = Rng::new(46, 0);
        let huge: Vec<_> = random_mesh(&mut rng, 200)
            .into_iter()
            .map(|t| crate::geometry::Triangle::new(t.p0 * 1e30, t.p1 * 1e30, t.p2 * 1e30))
            .collect();
        let bvh = Bvh::build(&huge, SplitMethod::Sah);
        assert!(bvh.nodes()[0].bounds().half_area().is_infinite(), "the test needs overflowing areas");
        WideBvh::collapse(&bvh).validate(&bvh).unwrap();
    }
}
