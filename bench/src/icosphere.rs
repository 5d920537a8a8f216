//! The benchmark mesh: a bumpy geodesic sphere of any size, generated, never downloaded.
//!
//! Each face of an icosahedron is split into an `n × n` triangle grid (`20 n²` triangles, shared
//! vertices), projected onto the unit sphere, and displaced radially by
//!
//! ```text
//!   r(p) = 1 + 0.01 · (sin 12x + sin 12y + sin 12z)        (at most ±3 %)
//! ```
//!
//! so that the surface is not a perfect sphere (no engine gets to exploit that) while staying
//! closed and star-shaped around the origin.

use std::fmt::Write as _;
use std::path::Path;

use raylab::geometry::TriangleMesh;
use raylab::image_io::write_file_atomic;

/// The grid size `n` whose `20 n²` triangles come closest to `triangles` (at least 1):
/// 1,000,000 gives `n = 224`, 1,003,520 triangles.
pub fn grid_size_for(triangles: usize) -> u32 {
    ((triangles as f64 / 20.0).sqrt().round() as u32).max(1)
}

/// The bumpy geodesic sphere with a grid of `n × n` triangles per icosahedron face.
pub fn bumpy_icosphere(n: u32) -> TriangleMesh {
    let mut mesh = TriangleMesh::geodesic(n);
    for p in &mut mesh.positions {
        let bump = (12.0 * p.x).sin() + (12.0 * p.y).sin() + (12.0 * p.z).sin();
        *p *= 1.0 + 0.01 * bump;
    }
    mesh
}

/// Writes `mesh` as a Wavefront OBJ (`v` and `f` lines only), atomically.
pub fn write_obj(path: &Path, mesh: &TriangleMesh) -> std::io::Result<()> {
    let mut text = String::with_capacity(40 * (mesh.positions.len() + mesh.indices.len()));
    let _ = writeln!(text, "# raylab bumpy icosphere: {} triangles", mesh.indices.len());
    for p in &mesh.positions {
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    for [a, b, c] in &mesh.indices {
        let _ = writeln!(text, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    write_file_atomic(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_million_triangles_means_n_224() {
        assert_eq!(grid_size_for(1_000_000), 224);
        assert_eq!(20 * 224 * 224, 1_003_520);
        assert_eq!(grid_size_for(0), 1);
        assert_eq!(grid_size_for(80), 2);
    }

    #[test]
    fn the_bumps_stay_within_three_percent_and_the_mesh_round_trips_through_obj() {
        let mesh = bumpy_icosphere(6);
        assert_eq!(mesh.indices.len(), 20 * 36);
        let radii: Vec<f32> = mesh.positions.iter().map(|p| p.length()).collect();
        assert!(radii.iter().all(|r| (0.97..=1.03).contains(r)));
        assert!(radii.iter().any(|r| (r - 1.0).abs() > 0.005), "the sphere is bumpy");

        let dir = std::env::temp_dir().join(format!("raylab-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sphere.obj");
        write_obj(&path, &mesh).unwrap();
        let loaded = TriangleMesh::load_obj(&path).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        // Display of f32 round-trips exactly, so the triangles come back bit for bit.
        assert!(loaded.triangles().eq(mesh.triangles()));
    }
}
