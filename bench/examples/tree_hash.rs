//! Prints a hash of the SAH and object-median trees over a mesh: every node (kind, links, the bits
//! of its box) and the leaf order. A change meant to make the build faster, not different, must
//! print the same hashes before and after (docs/PERFORMANCE.md):
//!
//! ```text
//! cargo run --release -p raylab-bench --example tree_hash -- target/ico1m.obj
//! ```

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::PathBuf;

use raylab::geometry::{Bvh, SplitMethod, Triangle, TriangleMesh};

fn main() -> Result<(), String> {
    let path = PathBuf::from(std::env::args().nth(1).ok_or("usage: tree_hash MESH.obj")?);
    let mesh = TriangleMesh::load_obj(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let triangles: Vec<Triangle> = mesh.triangles().collect();
    for method in [SplitMethod::Sah, SplitMethod::ObjectMedian] {
        let bvh = Bvh::build(&triangles, method);
        let mut hasher = DefaultHasher::new();
        for node in bvh.nodes() {
            format!("{:?}", node.view()).hash(&mut hasher);
            let bounds = node.bounds();
            for corner in [bounds.min, bounds.max] {
                corner.to_array().map(f32::to_bits).hash(&mut hasher);
            }
        }
        bvh.prim_ids().hash(&mut hasher);
        println!("{method:?}: {} nodes, hash {:016x}", bvh.nodes().len(), hasher.finish());
    }
    Ok(())
}
