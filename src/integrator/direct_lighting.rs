//! Checkpoint 6: direct lighting from point lights, with shadows.
//!
//! **Task.** Write [`direct_from_point_light`]: the radiance a diffuse surface point reflects
//! toward the viewer from one point light, zero if the light is hidden; and
//! [`DirectLightingIntegrator::li`], which sums it over all lights at the surface found by
//! [`trace_to_diffuse`](super::trace_to_diffuse) (checkpoint 5).
//!
//! **Maths.** A point light of intensity `I` ([`PointLight::intensity`], `= Φ / 4π`) at distance
//! `r`, in direction `wi`, gives the surface an irradiance `E = I · cos θ / r²` with
//! `cos θ = n · wi`. A Lambertian surface of albedo `ρ` has the BRDF `ρ / π` in every direction,
//! so the radiance it sends toward the viewer is
//!
//! ```text
//!   L = ρ / π · I · cos θ / r²        (zero if cos θ ≤ 0 or something blocks the light)
//! ```
//!
//! Check: albedo 0.5 under `I = 1` at distance 1, head on: `L = 0.5 / π ≈ 0.159`.
//!
//! **Conventions** ([`crate::math`]): surfaces are two-sided, so first turn the geometric normal
//! toward the viewer (`wo`); a light on the other side of the surface then has `cos θ ≤ 0`.
//! The shadow ray is [`spawn_ray_to`](crate::math::spawn_ray_to) the light: it starts off the surface and stops short of
//! the light. Glass blocks shadow rays: a point light seen through glass cannot be found by a
//! straight shadow ray, so its light is lost (as in any Whitted-style renderer).
//!
//! **Pitfalls.**
//! - Using the flux as the intensity (a factor 4π too bright).
//! - Forgetting `1/π`: the surface reflects more than it receives.
//! - Forgetting `1/r²` (no falloff, a flat look) or `cos θ` (grazing walls as bright as facing
//!   ones).
//! - A shadow ray from the exact hit point hits its own surface: black speckles ("acne").
//! - A shadow ray that does not stop at the light sees the ceiling behind it: everything dark.
//!
//! **Check:** `cargo test checkpoint6`, and render `scenes/cornell_direct.toml`.
//! Handout: `checkpoints/06-direct-lighting.md`.

use super::DiffuseHit;
use crate::light::PointLight;
use crate::math::{Ray, Vec3};
use crate::scene::World;

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use {super::trace_to_diffuse, crate::math::spawn_ray_to, std::f32::consts::PI};

/// Lambertian shading from point lights with shadow rays, through glass by checkpoint 5's path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectLightingIntegrator {
    /// Most glass surfaces a path passes.
    pub max_depth: u32,
}

impl DirectLightingIntegrator {
    /// The radiance along `ray`: direct light from every point light at the first diffuse
    /// surface, black if there is none.
    pub fn li(&self, world: &World, ray: Ray) -> Vec3 {
        // BEGIN SOLUTION checkpoint6
        let Some(surface) = trace_to_diffuse(world, ray, self.max_depth) else {
            return Vec3::ZERO;
        };
        let lights = world.scene().lights.iter();
        lights.map(|light| direct_from_point_light(world, &surface, light)).sum()
        // END SOLUTION
    }
}

/// Radiance the diffuse `surface` reflects toward `surface.wo` from `light`.
pub fn direct_from_point_light(world: &World, surface: &DiffuseHit, light: &PointLight) -> Vec3 {
    // BEGIN SOLUTION checkpoint6
    let p = surface.hit.p;
    let n = if surface.hit.normal.dot(surface.wo) < 0.0 { -surface.hit.normal } else { surface.hit.normal };
    let to_light = light.position - p;
    let r2 = to_light.length_squared();
    let cos_theta = n.dot(to_light) / r2.sqrt();
    if cos_theta <= 0.0 || world.occluded(&spawn_ray_to(p, n, light.position)) {
        return Vec3::ZERO;
    }
    let irradiance = light.intensity() * cos_theta / r2;
    surface.albedo / PI * irradiance
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint6 {
    use std::f32::consts::PI;

    use super::*;
    use crate::geometry::SplitMethod;
    use crate::scene::Scene;
    use crate::test_fixtures::scene_from_toml;

    /// Flux giving intensity `i`: Φ = 4π i.
    fn flux(i: f32) -> f32 {
        4.0 * PI * i
    }

    /// A floor of albedo 0.5 in the plane y = 0, plus `extra` TOML (lights, blockers).
    fn floor_scene(extra: &str) -> Scene {
        scene_from_toml(&format!(
            "[materials.floor]\nkind = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [materials.glass]\nkind = \"glass\"\nior = 1.5\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\nscale = [100, 1, 100]\n{extra}"
        ))
    }

    fn light_at(x: f32, y: f32, z: f32, intensity: f32) -> String {
        let f = flux(intensity);
        format!("[[lights]]\nposition = [{x}, {y}, {z}]\nflux = [{f}, {f}, {f}]\n")
    }

    fn li_looking_at(scene: &Scene, target: Vec3, from: Vec3) -> Vec3 {
        let world = World::new(scene, SplitMethod::ObjectMedian);
        DirectLightingIntegrator { max_depth: 8 }.li(&world, Ray::new(from, target - from))
    }

    /// Relative agreement to 1e-4: f32 rounding in a handful of operations is below 1e-6; the
    /// hit point's offset along the normal is 1e-4 of scene scale, and moves r² by less.
    #[track_caller]
    fn assert_close(got: Vec3, want: f32) {
        assert!((got - Vec3::splat(want)).abs().max_element() <= 1e-4 * want.max(1e-3), "{got} vs {want}");
    }

    #[test]
    fn a_floor_under_a_point_light_matches_the_closed_form() {
        // I = 1 at height 1: at horizontal distance x, r² = 1 + x², cos θ = 1 / r,
        // so L = 0.5 / π · 1 / r³.
        let scene = floor_scene(&light_at(0.0, 1.0, 0.0, 1.0));
        for x in [0.0f32, 0.5, 1.0, 2.0, 5.0] {
            let r = (1.0 + x * x).sqrt();
            let li = li_looking_at(&scene, Vec3::new(x, 0.0, 0.0), Vec3::new(x - 1.0, 3.0, 1.0));
            assert_close(li, 0.5 / PI / (r * r * r));
        }
    }

    #[test]
    fn the_viewing_direction_does_not_change_lambertian_radiance() {
        let scene = floor_scene(&light_at(0.3, 2.0, 0.0, 3.0));
        let target = Vec3::new(0.5, 0.0, -0.5);
        let a = li_looking_at(&scene, target, Vec3::new(0.5, 4.0, -0.5));
        let b = li_looking_at(&scene, target, Vec3::new(5.0, 0.5, 3.0));
        assert!(
            (a - b).abs().max_element() < 1e-5 * a.x,
            "a Lambertian point looks the same from everywhere: {a} vs {b}"
        );
    }

    #[test]
    fn two_lights_add() {
        let (l1, l2) = (light_at(1.0, 1.0, 0.0, 2.0), light_at(-1.0, 2.0, 1.0, 0.5));
        let target = Vec3::new(0.2, 0.0, 0.3);
        let eye = Vec3::new(0.0, 3.0, 3.0);
        let both = li_looking_at(&floor_scene(&format!("{l1}{l2}")), target, eye);
        let sum =
            li_looking_at(&floor_scene(&l1), target, eye) + li_looking_at(&floor_scene(&l2), target, eye);
        assert!(
            (both - sum).abs().max_element() < 1e-6,
            "two lights: expected the sum of each alone, {sum}, got {both}"
        );
        assert!(both.x > 0.0, "both lights see the point: expected light, got {both}");
    }

    #[test]
    fn points_in_shadow_are_black() {
        // A small square blocker at height 0.5 over the origin; the light at height 1.
        let blocker = "[[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\ntranslate = [0, 0.5, 0]\nscale = [0.2, 1, 0.2]\n";
        let scene = floor_scene(&format!("{}{blocker}", light_at(0.0, 1.0, 0.0, 1.0)));
        let shadowed = li_looking_at(&scene, Vec3::new(0.1, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.0));
        assert_eq!(
            shadowed,
            Vec3::ZERO,
            "the blocker hides the light from this point: the shadow ray must find it"
        );
        let lit = li_looking_at(&scene, Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.0));
        assert!(lit.x > 0.0, "this point sees the light past the blocker: expected light, got {lit}");
    }

    #[test]
    fn glass_blocks_shadow_rays() {
        let glass = "[[objects]]\nshape = \"sphere\"\nmaterial = \"glass\"\ntranslate = [0, 0.5, 0]\nscale = [0.2, 0.2, 0.2]\n";
        let scene = floor_scene(&format!("{}{glass}", light_at(0.0, 1.0, 0.0, 1.0)));
        let got = li_looking_at(&scene, Vec3::new(0.05, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.0));
        assert_eq!(got, Vec3::ZERO, "a glass ball between the point and the light blocks the shadow ray");
    }

    #[test]
    fn a_light_behind_the_surface_gives_nothing() {
        let scene = floor_scene(&light_at(0.0, -1.0, 0.0, 1.0));
        let got = li_looking_at(&scene, Vec3::new(0.3, 0.0, 0.0), Vec3::new(0.0, 2.0, 1.0));
        assert_eq!(got, Vec3::ZERO, "seen from above, a light below the floor has cos θ ≤ 0: nothing");
        // Seen from below, the same light lights the underside: the normal faces the viewer.
        let below = li_looking_at(&scene, Vec3::ZERO, Vec3::new(0.0, -3.0, 0.5));
        assert_close(below, 0.5 / PI);
    }

    #[test]
    fn a_tilted_floor_far_from_the_origin_has_no_acne() {
        // Every point of a lit floor 1000 units away, tilted so that no hit point falls exactly
        // on its plane, must be lit: a shadow ray hitting its own surface leaves black speckles.
        // (An axis-aligned floor would hide the mistake: its hit points round onto the plane.)
        let (centre, degrees, scale) =
            (Vec3::splat(1000.0), Vec3::new(25.0, 0.0, 15.0), Vec3::new(20.0, 1.0, 20.0));
        let m = crate::geometry::transform_matrix(centre, degrees, scale);
        let (along_x, along_z) = (m.transform_vector3(Vec3::X), m.transform_vector3(Vec3::Z));
        let n = along_z.cross(along_x).normalize(); // the quad faces +y: z × x = y
        let light = centre + 2.0 * n;
        let floor = "[[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\ntranslate = [1000, 1000, 1000]\n\
                     rotate = [25, 0, 15]\nscale = [20, 1, 20]\n";
        let scene = floor_scene(&format!("{}{floor}", light_at(light.x, light.y, light.z, 4.0)));
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        for i in 0..400 {
            let (u, v) = ((i % 20) as f32 * 0.0193 - 0.19, (i / 20) as f32 * 0.0187 - 0.18);
            let target = centre + u * along_x + v * along_z;
            let from = target + 5.0 * n + 0.3 * along_x.normalize();
            let li = DirectLightingIntegrator { max_depth: 8 }.li(&world, Ray::new(from, target - from));
            let to_light = light - target;
            let r2 = to_light.length_squared();
            let want = 0.5 / PI * 4.0 * n.dot(to_light) / r2.sqrt() / r2;
            // 1e-3: the hit point is known to about one ulp of 1000 (6e-5), which moves r² by
            // well under 1e-4 of itself at r ≥ 2; a speck of acne is black, off by 100 %.
            assert!((li.x - want).abs() < 1e-3 * want, "point {target}: {li} vs {want}");
        }
    }

    #[test]
    fn a_closed_box_lets_no_light_out() {
        let closed_box = "[[objects]]\nshape = \"box\"\nmaterial = \"floor\"\ntranslate = [0, 1, 0]\nscale = [0.5, 0.5, 0.5]\n";
        let scene = floor_scene(&format!("{}{closed_box}", light_at(0.0, 1.0, 0.0, 1.0)));
        for target in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.5, 0.0), Vec3::new(0.5, 1.2, 0.1)] {
            let li = li_looking_at(&scene, target, target + Vec3::new(2.0, 3.0, 1.5));
            assert_eq!(li, Vec3::ZERO, "at {target}");
        }
    }

    #[test]
    fn a_floor_seen_through_a_glass_slab_is_lit_where_the_ray_lands() {
        // Glass slab y in [1, 2]; the light under it at height 0.5; the eye above the slab.
        // The refracted path lands at the floor point the slab shift predicts, lit in closed form.
        let slab = "[[objects]]\nshape = \"box\"\nmaterial = \"glass\"\ntranslate = [0, 1.5, 0]\nscale = [20, 0.5, 20]\n";
        let scene = floor_scene(&format!("{}{slab}", light_at(0.0, 0.5, 0.0, 1.0)));
        let dir = Vec3::new(1.0, -1.0, 0.0).normalize();
        let eye = Vec3::new(-3.0, 3.0, 0.0);
        let sin_t = 45f32.to_radians().sin() / 1.5;
        let x = -3.0 + 1.0 + sin_t / (1.0 - sin_t * sin_t).sqrt() + 1.0;
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let li = DirectLightingIntegrator { max_depth: 8 }.li(&world, Ray::new(eye, dir));
        let r2 = x * x + 0.25;
        let want = 0.5 / PI * (0.5 / r2.sqrt()) / r2;
        // The two glass surfaces' ray offsets move the landing point by up to 1.2e-3 (see
        // checkpoint 5's slab test); L ∝ 1/r³ changes by 3 |x| dx / r² ≈ 3 dx relative here.
        assert!((li.x - want).abs() < 3.0 * 1.2e-3 * want, "{li} vs {want}");
    }
}
