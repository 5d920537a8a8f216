//! A bounding volume hierarchy over triangles: its layout, its construction, and its checks.
//!
//! The tree is stored flat, depth first: a node's first child is the next node in the array, its
//! second child is found by index. Leaves point into [`Bvh::triangles`], which construction
//! reorders so that each leaf's triangles are contiguous. Checkpoint 4 has two parts: the split
//! (`split.rs`, where the student writes the object-median split) and the traversal
//! (`traverse.rs`). This file holds the plumbing around them: the recursion, leaves, and
//! [`Bvh::validate`], which the tests use to check any tree, however it was split.

mod lanes;
mod sah;
mod split;
mod traverse;

use split::{object_median_split, Split};
pub use traverse::{BvhHit, TraversalStats};

use rayon::prelude::*;

use crate::geometry::{Aabb, Triangle};
use crate::math::Vec3;
use lanes::Box4;

/// How a node's triangles are divided between its two children.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SplitMethod {
    /// Half the triangles on each side, along the widest centroid axis (the student's split).
    #[default]
    ObjectMedian,
    /// The binned surface area heuristic (`sah.rs`): the harness's faster tree, for
    /// benchmarks and large meshes.
    Sah,
}

impl SplitMethod {
    /// Reorders `prims` (at least two) and says where to split them.
    pub fn split(self, prims: &mut [PrimRef]) -> Split {
        match self {
            SplitMethod::ObjectMedian => object_median_split(prims),
            SplitMethod::Sah => sah::sah_split(prims),
        }
    }
}

/// Most triangles a leaf holds.
pub const MAX_LEAF_TRIANGLES: usize = 4;

/// Deepest tree traversal supports (its stack is fixed-size). An object-median tree over n
/// triangles is about log2(n / 4) + 1 deep: 64 levels would hold far more triangles than memory.
pub const MAX_DEPTH: usize = 64;

/// One node of the flattened tree. Read it through [`Node::view`].
///
/// Packed into 32 bytes and aligned to 32, so a node never straddles a cache line and a parent
/// often shares its line with its first child: traversal spends much of its time waiting for
/// nodes to arrive from memory.
#[derive(Clone, Copy, PartialEq)]
#[repr(C, align(32))]
pub struct Node {
    bounds: Aabb,
    /// A leaf's first triangle, or an interior node's second child.
    index: u32,
    /// A leaf's triangle count, or [`INTERIOR`] plus the split axis.
    meta: u32,
}

const _: () = assert!(std::mem::size_of::<Node>() == 32);

/// The bit of [`Node::meta`] that marks an interior node.
const INTERIOR: u32 = 1 << 31;

/// What a node is: a leaf with its triangles, or an interior node with two children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NodeView {
    /// Triangles `first .. first + count` of [`Bvh::triangles`].
    Leaf {
        /// Index of the leaf's first triangle.
        first: u32,
        /// Number of triangles, 1 to [`MAX_LEAF_TRIANGLES`].
        count: u32,
    },
    /// The first child is the next node in the array; the second is at `second_child`.
    Interior {
        /// The axis (0, 1, 2) along which the children were split.
        axis: u8,
        /// Index of the second child.
        second_child: u32,
    },
}

impl Node {
    /// A leaf over `count` triangles starting at `first`.
    pub fn leaf(bounds: Aabb, first: u32, count: u32) -> Self {
        debug_assert!(count < INTERIOR, "a leaf's count must leave the top bit free");
        Self { bounds, index: first, meta: count }
    }

    /// An interior node split along `axis` whose second child is at index `second_child`.
    pub fn interior(bounds: Aabb, axis: u8, second_child: u32) -> Self {
        Self { bounds, index: second_child, meta: INTERIOR | axis as u32 }
    }

    /// This node as it reads when its subtree is moved `offset` places further down the array.
    fn moved_by(self, offset: u32) -> Self {
        match self.view() {
            NodeView::Leaf { .. } => self,
            NodeView::Interior { .. } => Self { index: self.index + offset, ..self },
        }
    }

    /// The box around everything below this node.
    pub fn bounds(&self) -> &Aabb {
        &self.bounds
    }

    /// Leaf or interior, with their indices.
    pub fn view(&self) -> NodeView {
        if self.meta & INTERIOR == 0 {
            NodeView::Leaf { first: self.index, count: self.meta }
        } else {
            NodeView::Interior { axis: (self.meta & !INTERIOR) as u8, second_child: self.index }
        }
    }
}

impl std::fmt::Debug for Node {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Node").field("bounds", &self.bounds).field("kind", &self.view()).finish()
    }
}

/// A triangle being sorted into the tree: its index in the input, its box and its centroid.
#[derive(Clone, Copy, Debug)]
pub struct PrimRef {
    /// Index of the triangle in the array given to [`Bvh::build`].
    pub index: u32,
    /// The triangle's bounds.
    pub bounds: Aabb,
    /// The triangle's centroid.
    pub centroid: Vec3,
}

/// A BVH over a set of triangles.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<Triangle>,
    /// `prim_ids[i]` is the input index of `triangles[i]`.
    prim_ids: Vec<u32>,
}

impl Bvh {
    /// Builds a tree over `triangles`, splitting nodes with `method`.
    pub fn build(triangles: &[Triangle], method: SplitMethod) -> Self {
        let mut prims: Vec<PrimRef> = triangles
            .par_iter()
            .with_min_len(PARALLEL_BUILD_MIN)
            .enumerate()
            .map(|(i, t)| PrimRef { index: i as u32, bounds: t.bounds(), centroid: t.centroid() })
            .collect();
        let mut nodes = Vec::with_capacity(2 * prims.len());
        if !prims.is_empty() {
            build_node(&mut prims, 0, method, &mut nodes);
        }
        Self {
            nodes,
            triangles: prims
                .par_iter()
                .with_min_len(PARALLEL_BUILD_MIN)
                .map(|p| triangles[p.index as usize])
                .collect(),
            prim_ids: prims.iter().map(|p| p.index).collect(),
        }
    }

    /// The flattened nodes, root first (empty for a tree over no triangles).
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The triangles in leaf order.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The input index of each triangle of [`Bvh::triangles`]: `triangles()[i]` is the
    /// `prim_ids()[i]`-th triangle given to [`Bvh::build`].
    pub fn prim_ids(&self) -> &[u32] {
        &self.prim_ids
    }

    /// The length of the longest root-to-leaf path, counted in nodes (0 for an empty tree).
    pub fn depth(&self) -> usize {
        fn depth_below(nodes: &[Node], i: usize) -> usize {
            match nodes[i].view() {
                NodeView::Leaf { .. } => 1,
                NodeView::Interior { second_child, .. } => {
                    1 + depth_below(nodes, i + 1).max(depth_below(nodes, second_child as usize))
                }
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            depth_below(&self.nodes, 0)
        }
    }

    /// Checks every structural invariant; the error names the first node that breaks one.
    ///
    /// Invariants: depth-first layout (children after their parent, the first child next); leaves
    /// hold 1 to [`MAX_LEAF_TRIANGLES`] triangles; every triangle is in exactly one leaf; every
    /// node's box contains its children's boxes and its triangles; depth at most [`MAX_DEPTH`].
    pub fn validate(&self) -> Result<(), String> {
        let mut seen = vec![false; self.triangles.len()];
        if !self.nodes.is_empty() {
            self.validate_node(0, 1, &mut seen)?;
        }
        if let Some(i) = seen.iter().position(|s| !s) {
            return Err(format!("triangle {} is in no leaf", self.prim_ids[i]));
        }
        let mut ids = self.prim_ids.clone();
        ids.sort_unstable();
        if ids.iter().enumerate().any(|(i, &id)| id != i as u32) {
            return Err("the leaf order is not a permutation of the input triangles".into());
        }
        Ok(())
    }

    fn validate_node(&self, i: usize, depth: usize, seen: &mut [bool]) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!("node {i} is deeper than {MAX_DEPTH}"));
        }
        let node = &self.nodes[i];
        match node.view() {
            NodeView::Leaf { first, count } => {
                let range = first as usize..first as usize + count as usize;
                if count == 0 || count as usize > MAX_LEAF_TRIANGLES || range.end > seen.len() {
                    return Err(format!("leaf {i} has a bad range {range:?}"));
                }
                for t in range {
                    if std::mem::replace(&mut seen[t], true) {
                        return Err(format!("triangle {} is in two leaves", self.prim_ids[t]));
                    }
                    if !node.bounds.contains(&self.triangles[t].bounds()) {
                        return Err(format!("leaf {i} does not contain triangle {}", self.prim_ids[t]));
                    }
                }
            }
            NodeView::Interior { second_child, .. } => {
                let second = second_child as usize;
                if second <= i + 1 || second >= self.nodes.len() {
                    return Err(format!("node {i} has second child {second}: not depth first"));
                }
                for child in [i + 1, second] {
                    if !node.bounds.contains(&self.nodes[child].bounds) {
                        return Err(format!("node {i} does not contain its child {child}"));
                    }
                    self.validate_node(child, depth + 1, seen)?;
                }
            }
        }
        Ok(())
    }
}

/// Nodes over at least this many triangles build their two children in parallel, and the passes
/// over every triangle (their boxes, the final gather) go to threads in pieces at least this
/// long: large enough that handing work to another thread costs nothing next to the work itself.
const PARALLEL_BUILD_MIN: usize = 1 << 14;

/// Appends the subtree over `prims` (which start at position `first` of the leaf order) to
/// `nodes` in depth-first order, and returns the index of its root.
///
/// The tree is the same whatever the number of threads: splits depend only on the triangles, and
/// a second child built on another thread is appended exactly where the sequential build puts it.
fn build_node(prims: &mut [PrimRef], first: usize, method: SplitMethod, nodes: &mut Vec<Node>) -> u32 {
    let bounds = prims.iter().fold(Box4::EMPTY, |b, p| b.union(Box4::of(&p.bounds))).aabb();
    let index = nodes.len();
    if prims.len() <= MAX_LEAF_TRIANGLES {
        nodes.push(Node::leaf(bounds, first as u32, prims.len() as u32));
        return index as u32;
    }
    let parallel = prims.len() >= PARALLEL_BUILD_MIN;
    let split = method.split(prims);
    debug_assert!(
        0 < split.mid && split.mid < prims.len(),
        "a split must leave triangles on both sides, got {} of {}",
        split.mid,
        prims.len()
    );
    // A placeholder, completed once the second child's index is known.
    nodes.push(Node::leaf(bounds, 0, 0));
    let (left, right) = prims.split_at_mut(split.mid);
    let right_first = first + split.mid;
    let second_child = if parallel {
        // The second child goes into a vector of its own, its links counted from 0, and is moved
        // behind the first child once both are done.
        let ((), right_nodes) = rayon::join(
            || {
                build_node(left, first, method, nodes);
            },
            || {
                let mut right_nodes = Vec::with_capacity(2 * right.len() / MAX_LEAF_TRIANGLES);
                build_node(right, right_first, method, &mut right_nodes);
                right_nodes
            },
        );
        let offset = nodes.len() as u32;
        nodes.extend(right_nodes.into_iter().map(|node| node.moved_by(offset)));
        offset
    } else {
        build_node(left, first, method, nodes);
        build_node(right, right_first, method, nodes)
    };
    nodes[index] = Node::interior(bounds, split.axis as u8, second_child);
    index as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::test_fixtures::random_mesh;

    #[test]
    fn the_tree_is_the_same_for_any_number_of_build_threads() {
        let triangles = random_mesh(&mut Rng::new(13, 0), 3 * PARALLEL_BUILD_MIN);
        for method in [SplitMethod::ObjectMedian, SplitMethod::Sah] {
            let build = |threads| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| Bvh::build(&triangles, method))
            };
            let (one, four) = (build(1), build(4));
            four.validate().unwrap();
            assert_eq!(one.nodes, four.nodes, "{method:?}");
            assert_eq!(one.prim_ids, four.prim_ids, "{method:?}");
        }
    }
}
