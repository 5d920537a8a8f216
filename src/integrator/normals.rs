//! The normals view: each surface coloured by its geometric normal, `(n + 1) / 2`, so a surface
//! facing +x is pink-red, +y green, +z blue. Scenes of geometry alone (checkpoints 2 to 4) are
//! drawn so, and it is `render`'s stand-in while checkpoint 5 is unwritten ([`crate::fallback`]).

use crate::math::{Ray, Vec3};
use crate::scene::World;

/// The first surface's normal, turned toward the viewer, as a colour: `(n + 1) / 2`; black where
/// the ray meets nothing.
pub fn normal_colour(world: &World, ray: Ray) -> Vec3 {
    world.intersect(&ray).map_or(Vec3::ZERO, |hit| {
        let n = if hit.normal.dot(ray.dir) > 0.0 { -hit.normal } else { hit.normal };
        (n + 1.0) * 0.5
    })
}
