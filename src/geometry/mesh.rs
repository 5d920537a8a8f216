//! Triangle meshes: the built-in shapes, OBJ files, and placing them in the scene.
//!
//! All built-in shapes are closed or flat, centred on the origin, of half-size 1, and wound
//! counter-clockwise seen from outside, so their geometric normals point outward
//! ([`crate::math`]): `quad` is the square `[-1, 1]²` in the plane `y = 0` facing `+y`;
//! `cuboid` is the cube `[-1, 1]³`; `icosphere` is the unit sphere.

use std::collections::HashMap;
use std::path::Path;

use crate::geometry::Triangle;
use crate::math::{Mat4, Vec3};

/// Vertices and triangles indexing them (shared vertices: a closed mesh has no cracks).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Each triangle's three vertex indices, counter-clockwise seen from its front.
    pub indices: Vec<[u32; 3]>,
}

/// The placement `M = T · Rz · Ry · Rx · S`: scale, then rotate about the fixed X, then Y, then Z
/// axes (degrees), then translate.
pub fn transform_matrix(translate: Vec3, rotate_degrees: Vec3, scale: Vec3) -> Mat4 {
    let r = rotate_degrees * (std::f32::consts::PI / 180.0);
    Mat4::from_translation(translate)
        * Mat4::from_rotation_z(r.z)
        * Mat4::from_rotation_y(r.y)
        * Mat4::from_rotation_x(r.x)
        * Mat4::from_scale(scale)
}

impl TriangleMesh {
    /// The square `[-1, 1]²` in the plane `y = 0`, facing `+y`.
    pub fn quad() -> Self {
        Self {
            positions: vec![
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(-1.0, 0.0, 1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(1.0, 0.0, -1.0),
            ],
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// The cube `[-1, 1]³`, twelve triangles facing outward.
    pub fn cuboid() -> Self {
        // Corner i has x, y, z = ±1 from bits 0, 1, 2 of i.
        let positions = (0..8).map(|i| Vec3::new(sign(i & 1), sign(i & 2), sign(i & 4))).collect();
        // Each face as a cycle of four corners; `orient_outward` fixes the winding.
        let faces = [[0, 2, 6, 4], [1, 3, 7, 5], [0, 1, 5, 4], [2, 3, 7, 6], [0, 1, 3, 2], [4, 5, 7, 6]];
        let indices = faces.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
        let mut mesh = Self { positions, indices };
        mesh.orient_outward();
        mesh
    }

    /// The unit sphere: an icosahedron with each face split into `4^subdivisions` triangles, its
    /// vertices projected onto the sphere (20 · 4^subdivisions triangles).
    pub fn icosphere(subdivisions: u32) -> Self {
        Self::geodesic(1 << subdivisions)
    }

    /// The unit sphere: an icosahedron with each face split into an `n × n` triangle grid, its
    /// vertices projected onto the sphere (`20 n²` triangles).
    pub fn geodesic(n: u32) -> Self {
        let (corners, faces) = icosahedron();
        let mut welder = Welder::default();
        for [a, b, c] in faces {
            let (a, b, c) = (corners[a], corners[b], corners[c]);
            // Vertex (i, j) of the face grid is a + i/n (b − a) + j/n (c − a), with i + j ≤ n.
            let vertex = |welder: &mut Welder, i: u32, j: u32| {
                let p = a + (b - a) * (i as f32 / n as f32) + (c - a) * (j as f32 / n as f32);
                welder.index(p.normalize())
            };
            for i in 0..n {
                for j in 0..n - i {
                    let v00 = vertex(&mut welder, i, j);
                    let v10 = vertex(&mut welder, i + 1, j);
                    let v01 = vertex(&mut welder, i, j + 1);
                    welder.mesh.indices.push([v00, v10, v01]);
                    if i + j + 1 < n {
                        let v11 = vertex(&mut welder, i + 1, j + 1);
                        welder.mesh.indices.push([v10, v11, v01]);
                    }
                }
            }
        }
        let mut mesh = welder.mesh;
        mesh.orient_outward();
        mesh
    }

    /// Loads every object of an OBJ file into one mesh (polygons are triangulated).
    pub fn load_obj(path: &Path) -> Result<Self, tobj::LoadError> {
        let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
        let (models, _materials) = tobj::load_obj(path, &options)?;
        let mut mesh = Self::default();
        for model in models {
            let base = mesh.positions.len() as u32;
            let p = &model.mesh.positions;
            mesh.positions.extend(p.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
            let tris = model.mesh.indices.chunks_exact(3);
            mesh.indices.extend(tris.map(|t| [base + t[0], base + t[1], base + t[2]]));
        }
        Ok(mesh)
    }

    /// The mesh placed by `m`. Positions are transformed by `m`; a mirroring `m` (negative
    /// determinant) would turn the winding inside out, so its triangles are re-wound. Geometric
    /// normals computed from the new triangles then equal the inverse transpose of `m` applied to
    /// the old ones, normalized and still outward.
    pub fn transformed(mut self, m: &Mat4) -> Self {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if m.determinant() < 0.0 {
            for t in &mut self.indices {
                t.swap(1, 2);
            }
        }
        self
    }

    /// The triangles, in index order.
    pub fn triangles(&self) -> impl Iterator<Item = Triangle> + '_ {
        let p = &self.positions;
        self.indices.iter().map(|&[a, b, c]| Triangle::new(p[a as usize], p[b as usize], p[c as usize]))
    }

    /// Winds every triangle of a convex mesh around the origin so its normal points away from it.
    fn orient_outward(&mut self) {
        for t in &mut self.indices {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                t.swap(1, 2);
            }
        }
    }
}

fn sign(bit: usize) -> f32 {
    if bit == 0 {
        -1.0
    } else {
        1.0
    }
}

/// The icosahedron's 12 corners (cyclic permutations of (0, ±1, ±φ), normalized) and its 20 faces:
/// the triples of corners that are pairwise neighbours (edge length 2 before normalizing).
fn icosahedron() -> (Vec<Vec3>, Vec<[usize; 3]>) {
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    let mut corners = Vec::with_capacity(12);
    for (s1, s2) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
        corners.push(Vec3::new(0.0, s1, s2 * phi));
        corners.push(Vec3::new(s1, s2 * phi, 0.0));
        corners.push(Vec3::new(s2 * phi, 0.0, s1));
    }
    let neighbours = |a: usize, b: usize| (corners[a] - corners[b]).length() < 2.1;
    let mut faces = Vec::with_capacity(20);
    for a in 0..12 {
        for b in a + 1..12 {
            for c in b + 1..12 {
                if neighbours(a, b) && neighbours(b, c) && neighbours(a, c) {
                    faces.push([a, b, c]);
                }
            }
        }
    }
    debug_assert_eq!(faces.len(), 20);
    (corners.into_iter().map(Vec3::normalize).collect(), faces)
}

/// Builds a mesh whose vertices are shared: positions equal to within 2^-20 get one index.
#[derive(Default)]
struct Welder {
    mesh: TriangleMesh,
    seen: HashMap<[i32; 3], u32>,
}

impl Welder {
    fn index(&mut self, p: Vec3) -> u32 {
        let key = (p * (1 << 20) as f32).round().as_ivec3().to_array();
        let positions = &mut self.mesh.positions;
        *self.seen.entry(key).or_insert_with(|| {
            positions.push(p);
            positions.len() as u32 - 1
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed mesh wound outward has every edge used once in each direction, and encloses
    /// positive volume (the sum of signed tetrahedra from the origin).
    #[track_caller]
    fn assert_closed_and_outward(mesh: &TriangleMesh, volume: f32, tol: f32) {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for &[a, b, c] in &mesh.indices {
            for (u, v) in [(a, b), (b, c), (c, a)] {
                *edges.entry((u.min(v), u.max(v))).or_default() += if u < v { 1 } else { -1 };
            }
        }
        assert!(edges.values().all(|&n| n == 0), "open or inconsistently wound");
        let v: f32 = mesh.triangles().map(|t| t.p0.dot(t.p1.cross(t.p2)) / 6.0).sum();
        assert!((v - volume).abs() < tol, "volume {v}, expected {volume}");
    }

    #[test]
    fn the_cube_is_closed_outward_and_of_volume_8() {
        let cube = TriangleMesh::cuboid();
        assert_eq!(cube.indices.len(), 12);
        assert_closed_and_outward(&cube, 8.0, 1e-5);
    }

    #[test]
    fn the_icosphere_is_closed_outward_and_near_the_sphere_volume() {
        for (k, tris) in [(0, 20), (1, 80), (3, 1280)] {
            let sphere = TriangleMesh::icosphere(k);
            assert_eq!(sphere.indices.len(), tris);
            assert_eq!(sphere.positions.len(), tris / 2 + 2, "Euler: V = F/2 + 2 when shared");
        }
        // An inscribed polyhedron is a little smaller than the sphere (4.18879).
        assert_closed_and_outward(&TriangleMesh::icosphere(3), 4.155, 0.02);
    }

    #[test]
    fn a_mirroring_transform_keeps_normals_outward() {
        let m = transform_matrix(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(10.0, 20.0, 30.0),
            Vec3::new(-1.0, 0.5, 2.0),
        );
        let cube = TriangleMesh::cuboid();
        let placed = cube.clone().transformed(&m);
        let normal_matrix = m.inverse().transpose();
        for (before, after) in cube.triangles().zip(placed.triangles()) {
            let expected = normal_matrix.transform_vector3(before.normal()).normalize();
            assert!((after.normal() - expected).length() < 1e-5);
        }
        assert_closed_and_outward(
            &placed.transformed(&Mat4::from_translation(-Vec3::new(1.0, 2.0, 3.0))),
            8.0,
            1e-3,
        );
    }

    #[test]
    fn rotations_apply_x_then_y_then_z() {
        // Rx(90) takes +y to +z; then Rz(90) leaves +z alone. Ry(90) takes +z to +x.
        let m = transform_matrix(Vec3::ZERO, Vec3::new(90.0, 90.0, 0.0), Vec3::ONE);
        assert!((m.transform_vector3(Vec3::Y) - Vec3::X).length() < 1e-6);
    }
}
