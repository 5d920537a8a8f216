//! A scene with its BVH: the two queries integrators ask, closest hit and occlusion.
//!
//! Rays go through checkpoint 4's binary BVH (the student's traversal, boxes and triangle test)
//! unless the world was made with [`World::wide`]: the harness's wide BVH, for renders in which no
//! student code is judged or shown (ARCHITECTURE.md, "Which tracer").

use super::Scene;
use crate::geometry::{any_triangle, closest_triangle, Bvh, SplitMethod, TraversalStats, WideBvh};
use crate::material::Material;
use crate::math::{Ray, Vec3};

/// A scene ready for tracing: the scene and a BVH over its triangles.
pub struct World<'a> {
    scene: &'a Scene,
    tracer: Tracer,
}

/// How rays find triangles.
enum Tracer {
    /// Through the BVH (checkpoints 2 to 4).
    Bvh(Bvh),
    /// Through the harness's wide BVH, collapsed from the SAH tree.
    Wide(WideBvh),
    /// By testing every triangle: `render`'s stand-in while checkpoint 3 or 4 is unwritten
    /// ([`crate::fallback`]).
    EveryTriangle,
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
    /// The radiance the object emits from its front side (zero unless it is an area light).
    pub emission: Vec3,
}

impl SurfaceHit<'_> {
    /// The radiance leaving the surface toward `wo` by emission: the object's emission seen from
    /// its front (the side the normal points to), nothing from behind.
    pub fn emitted(&self, wo: Vec3) -> Vec3 {
        if self.normal.dot(wo) > 0.0 {
            self.emission
        } else {
            Vec3::ZERO
        }
    }
}

impl<'a> World<'a> {
    /// Builds the BVH over the scene's triangles with `method`.
    pub fn new(scene: &'a Scene, method: SplitMethod) -> Self {
        Self { scene, tracer: Tracer::Bvh(Bvh::build(&scene.triangles, method)) }
    }

    /// With the harness's wide BVH (collapsed from a SAH tree): the fastest tracer, for renders
    /// that judge no student code, such as the reference solution's references.
    pub fn wide(scene: &'a Scene) -> Self {
        let wide = WideBvh::collapse(&Bvh::build(&scene.triangles, SplitMethod::Sah));
        Self { scene, tracer: Tracer::Wide(wide) }
    }

    /// Without a BVH: every ray tests every triangle (`render`'s stand-in for checkpoints 3, 4).
    pub fn tracing_every_triangle(scene: &'a Scene) -> Self {
        Self { scene, tracer: Tracer::EveryTriangle }
    }

    /// The scene.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// The closest surface `ray` meets in its range.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceHit<'a>> {
        let hit = match &self.tracer {
            Tracer::Bvh(bvh) => bvh.intersect(ray, &mut TraversalStats::default()),
            Tracer::Wide(wide) => wide.intersect(ray, &mut TraversalStats::default()),
            Tracer::EveryTriangle => closest_triangle(&self.scene.triangles, ray),
        }?;
        let triangle = &self.scene.triangles[hit.prim as usize];
        let material = self.scene.triangle_materials[hit.prim as usize];
        let object = self.scene.triangle_objects[hit.prim as usize];
        Some(SurfaceHit {
            t: hit.hit.t,
            p: triangle.point(hit.hit.b1, hit.hit.b2),
            normal: triangle.normal(),
            material: &self.scene.materials[material as usize],
            object,
            emission: self.scene.object_emission[object as usize],
        })
    }

    /// Checkpoint 4's binary tree, if rays are traced through it.
    pub fn bvh(&self) -> Option<&Bvh> {
        match &self.tracer {
            Tracer::Bvh(bvh) => Some(bvh),
            Tracer::Wide(_) | Tracer::EveryTriangle => None,
        }
    }

    /// Whether anything blocks `ray` in its range.
    pub fn occluded(&self, ray: &Ray) -> bool {
        match &self.tracer {
            Tracer::Bvh(bvh) => bvh.occluded(ray, &mut TraversalStats::default()),
            Tracer::Wide(wide) => wide.occluded(ray, &mut TraversalStats::default()),
            Tracer::EveryTriangle => any_triangle(&self.scene.triangles, ray),
        }
    }
}
