//! Checkpoint 5, part 2: the `IntersectionTestIntegrator`: follow rays through glass, then show
//! what they hit.
//!
//! **Task.** Write [`trace_to_diffuse`]: follow a ray through perfectly refracting surfaces
//! (using [`refract_or_reflect`](crate::material::refract_or_reflect) from part 1) until it reaches a diffuse surface; and
//! [`IntersectionTestIntegrator::li`]: shade that surface without any light, as
//! `albedo · |n · wo|`, the cosine between the ray and the normal, black if nothing diffuse is reached.
//!
//! **Algorithm.** Repeat: find the closest hit; if it is diffuse, done; if it is glass, continue
//! from the hit point in the refracted (or totally reflected) direction with
//! [`spawn_ray`](crate::math::spawn_ray). Each glass surface met counts one bounce; a path that would need more than
//! `max_depth` bounces is black. A miss is black.
//!
//! **Conventions** ([`crate::math`]): `wo = −ray.dir`; the hit's normal is the outward geometric
//! normal, which `refract_or_reflect` needs as it is (do not flip it toward the ray first).
//!
//! **Pitfalls.**
//! - Spawning the next ray at the hit point itself: it hits the same surface again at `t ≈ 0`
//!   (black speckles, worst on tilted glass far from the origin: the test
//!   `a_tilted_glass_slab_far_from_the_origin_lets_rays_through` shows it).
//!   [`spawn_ray`](crate::math::spawn_ray) moves the origin to the side the new direction leaves toward.
//! - Computing the refracted direction but continuing along the old one.
//! - An endless loop: count bounces.
//!
//! **Check:** `cargo test checkpoint5`, and render `scenes/intersection_test.toml`.
//! Handout: `checkpoints/05-refraction.md`.

use crate::math::{Ray, Vec3};
use crate::scene::{SurfaceHit, World};

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use {
    crate::material::{refract_or_reflect, Material},
    crate::math::spawn_ray,
};

/// The diffuse surface a path reaches, and the direction back along the path.
#[derive(Clone, Copy, Debug)]
pub struct DiffuseHit<'a> {
    /// The hit.
    pub hit: SurfaceHit<'a>,
    /// Unit direction from the hit point back along the arriving ray.
    pub wo: Vec3,
    /// The surface's albedo.
    pub albedo: Vec3,
}

/// Follows `ray` through at most `max_depth` glass surfaces to the first diffuse surface it
/// meets; `None` if it escapes or needs more bounces.
pub fn trace_to_diffuse<'a>(world: &World<'a>, ray: Ray, max_depth: u32) -> Option<DiffuseHit<'a>> {
    // BEGIN SOLUTION checkpoint5
    let mut ray = ray;
    for _bounce in 0..=max_depth {
        let hit = world.intersect(&ray)?;
        let wo = -ray.dir;
        match *hit.material {
            Material::Diffuse { albedo } => return Some(DiffuseHit { hit, wo, albedo }),
            Material::PerfectRefraction { ior } => {
                let wi = refract_or_reflect(wo, hit.normal, ior);
                ray = spawn_ray(hit.p, hit.normal, wi);
            }
        }
    }
    None
    // END SOLUTION
}

/// Shades the first diffuse surface by albedo and viewing angle: no lights needed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IntersectionTestIntegrator {
    /// Most glass surfaces a path passes.
    pub max_depth: u32,
}

impl IntersectionTestIntegrator {
    /// `albedo · |n · wo|` at the first diffuse surface along `ray`, black if there is none.
    pub fn li(&self, world: &World, ray: Ray) -> Vec3 {
        // BEGIN SOLUTION checkpoint5
        match trace_to_diffuse(world, ray, self.max_depth) {
            Some(d) => d.albedo * d.hit.normal.dot(d.wo).abs(),
            None => Vec3::ZERO,
        }
        // END SOLUTION
    }
}

#[cfg(test)]
mod checkpoint5 {
    use super::*;
    use crate::geometry::SplitMethod;
    use crate::scene::Scene;
    use crate::test_fixtures::scene_from_toml;

    /// A diffuse floor at y = −1 (albedo 0.5) under a glass slab of thickness 1 (y in ±0.5).
    fn slab_scene(ior: f32) -> Scene {
        scene_from_toml(&format!(
            r#"
            [materials.floor]
            kind = "diffuse"
            albedo = [0.5, 0.5, 0.5]
            [materials.glass]
            kind = "glass"
            ior = {ior}
            [[objects]]
            shape = "quad"
            material = "floor"
            translate = [0, -1, 0]
            scale = [50, 1, 50]
            [[objects]]
            shape = "box"
            material = "glass"
            scale = [20, 0.5, 20]
            "#
        ))
    }

    fn integrator(max_depth: u32) -> IntersectionTestIntegrator {
        IntersectionTestIntegrator { max_depth }
    }

    #[test]
    fn a_ray_that_hits_nothing_is_black() {
        let scene = slab_scene(1.5);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let got = integrator(8).li(&world, Ray::new(Vec3::new(0.0, 3.0, 0.0), Vec3::Y));
        assert_eq!(got, Vec3::ZERO, "a ray up into the empty sky hits nothing: black");
    }

    #[test]
    fn a_diffuse_surface_shows_albedo_times_the_viewing_cosine_from_either_side() {
        let scene = slab_scene(1.5);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        // From just above the floor (below the slab), looking down at 60 degrees from the normal.
        let dir = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
        let li = integrator(0).li(&world, Ray::new(Vec3::new(0.0, -0.8, 0.0), dir));
        assert!((li - Vec3::splat(0.5 * 0.5)).abs().max_element() < 1e-5, "{li}");
        // From below the floor, looking up at it: the back is shaded the same way.
        let li = integrator(0).li(&world, Ray::new(Vec3::new(0.0, -2.0, 0.0), Vec3::Y));
        assert!((li - Vec3::splat(0.5)).abs().max_element() < 1e-5, "{li}");
    }

    #[test]
    fn a_glass_slab_shifts_a_ray_but_does_not_bend_it() {
        let scene = slab_scene(1.5);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let dir = Vec3::new(1.0, -1.0, 0.0).normalize();
        let d =
            trace_to_diffuse(&world, Ray::new(Vec3::new(0.0, 1.5, 0.0), dir), 8).expect("reaches the floor");
        assert!((d.wo + dir).length() < 1e-5, "leaves parallel to how it entered: {}", -d.wo);
        // Above the slab the ray drops 1 (x += 1); inside, 1 at sin θt = sin 45° / 1.5
        // (x += tan θt); below, 0.5 (x += 0.5).
        let sin_t = 45f32.to_radians().sin() / 1.5;
        let expected_x = 1.5 + sin_t / (1.0 - sin_t * sin_t).sqrt();
        // Each glass surface starts the next ray δ = 1e-4 (1 + max |p|) ≈ 3e-4 off the surface
        // (math::spawn_ray), shifting the landing point by δ (1 + tan θ) at most: 2 surfaces.
        assert!((d.hit.p - Vec3::new(expected_x, -1.0, 0.0)).length() < 2.0 * 3e-4 * 2.0, "{}", d.hit.p);
    }

    /// Parallel faces: a ray through a glass slab leaves in the direction it came, shifted
    /// sideways, and lands on the floor behind it, however the slab is turned and wherever it
    /// is. Far from the origin and tilted, hit points do not round onto the faces' planes, so a
    /// ray restarted from the exact hit point meets its own face again.
    #[test]
    fn a_tilted_glass_slab_far_from_the_origin_lets_rays_through() {
        let (centre, degrees) = (Vec3::splat(1000.0), Vec3::new(25.0, 0.0, 15.0));
        let m = crate::geometry::transform_matrix(centre, degrees, Vec3::ONE);
        let n = m.transform_vector3(Vec3::Y).normalize();
        let side = m.transform_vector3(Vec3::X).normalize();
        let objects = format!(
            "[materials.floor]\nkind = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [materials.glass]\nkind = \"glass\"\nior = 1.5\n\
             [[objects]]\nshape = \"box\"\nmaterial = \"glass\"\ntranslate = [1000, 1000, 1000]\n\
             rotate = [25, 0, 15]\nscale = [20, 0.5, 20]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\ntranslate = [{}, {}, {}]\n\
             rotate = [25, 0, 15]\nscale = [50, 1, 50]\n",
            centre.x - 3.0 * n.x,
            centre.y - 3.0 * n.y,
            centre.z - 3.0 * n.z
        );
        let scene = scene_from_toml(&objects);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        // 30° from the normal; inside the slab (thickness 1) sin θt = sin 30° / 1.5.
        let (sin_i, sin_t) = (0.5f32, 0.5f32 / 1.5);
        let (tan_i, tan_t) = (sin_i / (1.0 - sin_i * sin_i).sqrt(), sin_t / (1.0 - sin_t * sin_t).sqrt());
        let dir = (-n * (1.0 - sin_i * sin_i).sqrt() + side * sin_i).normalize();
        for i in 0..50 {
            let start =
                centre + 2.0 * n + (i as f32 * 0.37 - 9.0) * side + (i as f32 * 0.23 - 5.0) * n.cross(side);
            let d = trace_to_diffuse(&world, Ray::new(start, dir), 8)
                .unwrap_or_else(|| panic!("ray {i} is lost"));
            assert!((d.wo + dir).length() < 1e-4, "ray {i} leaves parallel to how it entered: {}", -d.wo);
            // It drops 1.5 to the slab, 1 through it, 2.5 to the floor (3 below the centre), going
            // sideways tan θi per unit of depth, but tan θt in the glass.
            let want = start - 5.0 * n + (4.0 * tan_i + tan_t) * side;
            // Each glass surface restarts the ray δ = 1e-4 (1 + max |p|) ≈ 0.1 off the surface
            // (math::spawn_ray), moving the landing point by δ (1 + tan θ) ≤ 0.16 at most: two
            // surfaces, 0.32; rounding at 1000 (6e-5 an ulp) is far below that.
            assert!((d.hit.p - want).length() < 0.35, "ray {i} lands at {}, not {want}", d.hit.p);
        }
    }

    #[test]
    fn a_slab_of_index_one_changes_nothing() {
        let scene = slab_scene(1.0);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let dir = Vec3::new(0.3, -1.0, 0.2).normalize();
        let d = trace_to_diffuse(&world, Ray::new(Vec3::new(0.0, 1.5, 0.0), dir), 8).unwrap();
        let straight = Ray::new(Vec3::new(0.0, 1.5, 0.0), dir).at(2.5 / -dir.y);
        assert!((d.wo + dir).length() < 1e-5, "index 1 bends nothing: {}", -d.wo);
        // Each glass surface restarts the ray δ ≤ 3e-4 off the surface along the normal
        // (math::spawn_ray), which moves the landing point sideways by δ tan θ ≤ 0.4 δ here.
        assert!((d.hit.p - straight).length() < 2.0 * 3e-4 * 0.4, "{} vs {straight}", d.hit.p);
    }

    #[test]
    fn paths_needing_more_bounces_than_max_depth_are_black() {
        let scene = slab_scene(1.5);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let down = Ray::new(Vec3::new(0.2, 1.5, 0.1), -Vec3::Y);
        assert_eq!(integrator(1).li(&world, down), Vec3::ZERO, "two glass surfaces need depth 2");
        let got = integrator(2).li(&world, down);
        assert!(
            (got - Vec3::splat(0.5)).abs().max_element() < 1e-5,
            "depth 2 crosses both glass faces to the floor, seen head-on: albedo 0.5 · |n · wo| = 0.5, got {got}"
        );
    }

    #[test]
    fn total_internal_reflection_keeps_a_steep_ray_inside_the_slab() {
        // Started inside the slab at 60 degrees (beyond the critical 41.8), the ray reflects
        // between the faces until depth runs out; never reaching the floor.
        let scene = slab_scene(1.5);
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let dir = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
        let inside = Ray::new(Vec3::new(0.0, 0.0, 0.0), dir);
        let got = trace_to_diffuse(&world, inside, 6);
        assert!(
            got.is_none(),
            "60° inside glass is beyond the critical 41.8°: it reflects until depth runs out, got {got:?}"
        );
        // At 30 degrees it leaves through the bottom face and reaches the floor.
        let dir = Vec3::new(30f32.to_radians().sin(), -30f32.to_radians().cos(), 0.0);
        let got = trace_to_diffuse(&world, Ray::new(Vec3::ZERO, dir), 6);
        assert!(got.is_some(), "30° inside glass leaves through the bottom face and reaches the floor");
    }
}
