//! A scene with its BVH: the two queries integrators ask, closest hit and occlusion.

use super::Scene;
use crate::geometry::{Bvh, SplitMethod, TraversalStats};
use crate::material::Material;
use crate::math::{Ray, Vec3};

/// A scene ready for tracing: the scene and a BVH over its triangles.
pub struct World<'a> {
    scene: &'a Scene,
    bvh: Bvh,
}

/// Where a ray meets the scene, and what is there.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit<'a> {
    /// The ray parameter.
    pub t: f32,
    /// The point, interpolated from the triangle's vertices (more accurate than `o + t·d`).
    pub p: Vec3,
    /// The triangle's unit geometric normal, outward for closed meshes (not flipped to the ray).
    pub normal: Vec3,
    /// The surface's material.
    pub material: &'a Material,
    /// Index of the scene object hit (its `[[objects]]` entry).
    pub object: u32,
}

impl<'a> World<'a> {
    /// Builds the BVH over the scene's triangles with `method`.
    pub fn new(scene: &'a Scene, method: SplitMethod) -> Self {
        Self { scene, bvh: Bvh::build(&scene.triangles, method) }
    }

    /// The scene.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// The BVH.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// The closest surface `ray` meets in its range.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit<'a>> {
        let hit = self.bvh.intersect(ray, &mut TraversalStats::default())?;
        let triangle = &self.scene.triangles[hit.prim as usize];
        let material = self.scene.triangle_materials[hit.prim as usize];
        Some(SurfaceHit {
            t: hit.hit.t,
            p: triangle.point(hit.hit.b1, hit.hit.b2),
            normal: triangle.normal(),
            material: &self.scene.materials[material as usize],
            object: self.scene.triangle_objects[hit.prim as usize],
        })
    }

    /// Whether anything blocks `ray` in its range.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.occluded(ray, &mut TraversalStats::default())
    }
}
