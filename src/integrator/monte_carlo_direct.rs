//! Checkpoint 8, part 3: direct lighting from area lights (and point lights), estimated by
//! sampling the lights.
//!
//! **Task.** Write [`sample_direct`]: a one-sample estimate of the light a diffuse surface point
//! reflects toward `wo` directly from the scene's lights: choose a light with
//! [`choose_light`] (part 2), and for an area light a point on it with
//! [`AreaLight::sample`](crate::light::AreaLight::sample) (part 1); a point light is checkpoint
//! 6's [`direct_from_point_light`] divided by its probability.
//!
//! **Maths.** The light reflected toward `wo` from an area light is an integral over the light's
//! surface: with `y` a point on it, `wi = (y − x) / r`, `cos θ = n · wi` at the surface and
//! `cos θ_l = n_l · (−wi)` at the light,
//!
//! ```text
//!   L = ∫_A f · L_e · cos θ · cos θ_l / r² dA(y),      f = ρ / π,
//! ```
//!
//! where `cos θ_l / r²` converts the light's area to the solid angle it covers (`dω = cos θ_l
//! dA / r²`). Choosing the light with probability `P(light)` and `y` with density `pdf_A`, the
//! estimate of one sample is
//!
//! ```text
//!   L ≈ f · L_e · cos θ · cos θ_l / (r² · P(light) · pdf_A)
//! ```
//!
//! and zero if either cosine is not positive (the light is behind the surface, or shows the
//! surface its back) or something blocks the shadow ray from `x` to `y`. Averaged over many
//! samples (more spp), it converges to the exact direct light.
//!
//! The light and the point are raylab's choices: a light in proportion to its power (part 2), a
//! point uniformly over the light's area (part 1). Check by hand: a tiny light of area `A`
//! straight above `x` at height `h`, facing down, gives `L ≈ ρ/π · L_e · A / h²`.
//!
//! **Conventions.** Turn the surface normal toward `wo` first, as in checkpoint 6; a light shines
//! only from its front (`cos θ_l > 0`). Draw every random number from `rng`, in this order: one
//! for the light, three for the point. The integrator around this function adds what a surface
//! itself emits toward the camera (`SurfaceHit::emitted`), so lights are visible, through glass
//! too. The shadow ray is
//! [`spawn_ray_to`](crate::math::spawn_ray_to) the light point, which stops short of it, so the
//! light does not shadow itself.
//!
//! **Pitfalls** (each biases the image; `cargo test checkpoint8` compares the mean of 40,000
//! samples with Lambert's closed form for polygon lights, `E = (L_e / 2) Σ β_i (n · ĝ_i)` with
//! `β_i` the angle of edge `i` seen from `x` and `ĝ_i` the normal of the plane through `x` and
//! that edge, by a t-test):
//! - Dropping `cos θ_l / r²` (integrating over area as if it were solid angle).
//! - Dropping `cos θ_l` only: light from the light's edge-on parts is too strong.
//! - Forgetting `P(light)` or `pdf_A` (or using `1 / n` for a light chosen by power).
//!
//! **Check:** `cargo test checkpoint8`. Handout: `checkpoints/08-area-lights.md`.

use super::{trace_to_diffuse, DiffuseHit};
use crate::math::{Ray, Vec3};
use crate::rng::Rng;
use crate::scene::World;

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use {
    super::direct_from_point_light,
    crate::light::{choose_light, Light},
    crate::math::spawn_ray_to,
    std::f32::consts::PI,
};

/// Direct lighting from point and area lights by sampling one light per camera sample; the
/// camera (and a path through glass) sees emitting surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MonteCarloDirectIntegrator {
    /// Most glass surfaces a path passes.
    pub max_depth: u32,
}

impl MonteCarloDirectIntegrator {
    /// The radiance along `ray`: at the first diffuse surface (through glass), what it emits
    /// toward the ray plus a one-sample estimate of the direct light it reflects.
    pub fn li(&self, world: &World, ray: Ray, rng: &mut Rng) -> Vec3 {
        let Some(surface) = trace_to_diffuse(world, ray, self.max_depth) else {
            return Vec3::ZERO;
        };
        surface.hit.emitted(surface.wo) + sample_direct(world, &surface, rng)
    }
}

/// A one-sample estimate of the direct light `surface` reflects toward `surface.wo`.
pub fn sample_direct(world: &World, surface: &DiffuseHit, rng: &mut Rng) -> Vec3 {
    // BEGIN SOLUTION checkpoint8
    let scene = world.scene();
    let Some((index, p_light)) = choose_light(&scene.light_powers, rng.next_f32()) else {
        return Vec3::ZERO;
    };
    let light = match scene.light(index) {
        Light::Point(point) => return direct_from_point_light(world, surface, point) / p_light,
        Light::Area(area) => area,
    };
    let sample = light.sample([rng.next_f32(), rng.next_f32(), rng.next_f32()]);
    let p = surface.hit.p;
    let n = if surface.hit.normal.dot(surface.wo) < 0.0 { -surface.hit.normal } else { surface.hit.normal };
    let to_light = sample.point - p;
    let r2 = to_light.length_squared();
    let wi = to_light / r2.sqrt();
    let (cos_surface, cos_light) = (n.dot(wi), -sample.normal.dot(wi));
    if cos_surface <= 0.0 || cos_light <= 0.0 || world.occluded(&spawn_ray_to(p, n, sample.point)) {
        return Vec3::ZERO;
    }
    surface.albedo / PI * light.radiance * cos_surface * cos_light / (r2 * p_light * sample.pdf_area)
    // END SOLUTION
}

#[cfg(test)]
pub(crate) mod oracle {
    //! Lambert's closed form for the irradiance from a polygon of uniform radiance.

    use crate::math::Vec3;

    /// The irradiance at `x` (unit normal `n`) from a convex polygon `vertices` of radiance `l`
    /// lying wholly above `x`'s tangent plane and facing it: Lambert's formula
    /// `E = (l / 2) Σ_i β_i (n · ĝ_i)`, with `u_i` the unit vectors from `x` to the vertices,
    /// `β_i` the angle between `u_i` and `u_{i+1}`, and `ĝ_i` the unit normal of the plane
    /// through `x`, `u_i` and `u_{i+1}`. (The sign of the sum follows the winding; above the
    /// horizon every term has the same sign, so its magnitude is the irradiance.)
    pub fn polygon_irradiance(x: Vec3, n: Vec3, vertices: &[Vec3], l: f64) -> f64 {
        let u: Vec<glam::DVec3> = vertices.iter().map(|v| (*v - x).as_dvec3().normalize()).collect();
        let n = n.as_dvec3();
        let sum: f64 = (0..u.len())
            .map(|i| {
                let (a, b) = (u[i], u[(i + 1) % u.len()]);
                a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(a.cross(b).normalize())
            })
            .sum();
        l / 2.0 * sum.abs()
    }
}

#[cfg(test)]
mod checkpoint8 {
    use super::oracle::polygon_irradiance;
    use super::*;
    use crate::geometry::SplitMethod;
    use crate::scene::Scene;
    use crate::stats::Summary;
    use crate::test_fixtures::{assert_mean, scene_from_toml};

    const ALBEDO: f64 = 0.5;

    /// A floor of albedo 0.5 (y = 0, two-sided) and the `extra` TOML: lights and blockers.
    fn floor_scene(extra: &str) -> Scene {
        scene_from_toml(&format!(
            "[materials.floor]\nkind = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [materials.emitter]\nkind = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\nscale = [100, 1, 100]\n{extra}"
        ))
    }

    /// A square light of half-side `a` centred at `(cx, h, cz)`, facing down, radiance `l`.
    fn ceiling_light(cx: f32, h: f32, cz: f32, a: f32, l: f32) -> String {
        format!(
            "[[objects]]\nshape = \"quad\"\nmaterial = \"emitter\"\ntranslate = [{cx}, {h}, {cz}]\n\
             rotate = [180, 0, 0]\nscale = [{a}, 1, {a}]\nemission = [{l}, {l}, {l}]\n"
        )
    }

    fn square(cx: f32, h: f32, cz: f32, a: f32) -> [Vec3; 4] {
        [(-a, -a), (a, -a), (a, a), (-a, a)].map(|(dx, dz)| Vec3::new(cx + dx, h, cz + dz))
    }

    /// The floor point `x` as a diffuse hit, seen by a ray along the floor from the side (a ray
    /// from above would hit the light first).
    fn floor_hit<'a>(world: &World<'a>, x: Vec3) -> DiffuseHit<'a> {
        let from = x + Vec3::new(3.0, 0.2, 0.5);
        trace_to_diffuse(world, Ray::new(from, x - from), 0).expect("the floor")
    }

    /// `n` one-sample estimates at `x`, summarised (red channel: the scene is grey).
    fn estimates(scene: &Scene, x: Vec3, n: usize, seed: u64) -> Summary {
        let world = World::new(scene, SplitMethod::ObjectMedian);
        let surface = floor_hit(&world, x);
        let mut rng = Rng::new(seed, 0);
        Summary::of((0..n).map(|_| sample_direct(&world, &surface, &mut rng).x as f64))
    }

    /// One square light above the floor: the mean reflected radiance is ρ/π times Lambert's
    /// irradiance, at a point under the light and at one off to the side (where cos θ_l matters).
    #[test]
    fn the_mean_of_light_samples_is_lamberts_closed_form_for_a_square_light() {
        let scene = floor_scene(&ceiling_light(0.0, 1.0, 0.0, 0.5, 4.0));
        for (i, x) in [Vec3::new(0.1, 0.0, -0.2), Vec3::new(1.5, 0.0, 0.7)].into_iter().enumerate() {
            let e = polygon_irradiance(x, Vec3::Y, &square(0.0, 1.0, 0.0, 0.5), 4.0);
            assert_mean(&estimates(&scene, x, 40_000, 84 + i as u64), ALBEDO / std::f64::consts::PI * e);
        }
    }

    /// Two area lights of different size and radiance and a point light: the mean is the sum of
    /// the three closed forms, however the lights are chosen.
    #[test]
    fn the_mean_with_two_area_lights_and_a_point_light_is_the_sum_of_their_closed_forms() {
        let flux = 4.0 * std::f32::consts::PI * 0.8;
        let extra = format!(
            "{}{}[[lights]]\nposition = [0.3, 0.9, 0.4]\nflux = [{flux}, {flux}, {flux}]\n",
            ceiling_light(-0.6, 1.2, 0.0, 0.2, 20.0),
            ceiling_light(0.8, 0.8, -0.3, 0.6, 1.5)
        );
        let scene = floor_scene(&extra);
        let x = Vec3::new(0.1, 0.0, 0.1);
        let e = polygon_irradiance(x, Vec3::Y, &square(-0.6, 1.2, 0.0, 0.2), 20.0)
            + polygon_irradiance(x, Vec3::Y, &square(0.8, 0.8, -0.3, 0.6), 1.5);
        // The point light: I cos θ / r² with I = 0.8.
        let to_light = Vec3::new(0.3, 0.9, 0.4) - x;
        let point = 0.8 * (to_light.y / to_light.length()) as f64 / to_light.length_squared() as f64;
        assert_mean(&estimates(&scene, x, 40_000, 86), ALBEDO / std::f64::consts::PI * (e + point));
    }

    /// A blocker between the floor and the light: every sample is exactly zero. A light facing
    /// away from the floor gives nothing either.
    #[test]
    fn a_blocked_light_and_a_light_facing_away_give_nothing() {
        let blocker = "[[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\ntranslate = [0, 0.5, 0]\nscale = [2, 1, 2]\n";
        let scene = floor_scene(&format!("{}{blocker}", ceiling_light(0.0, 1.0, 0.0, 0.5, 4.0)));
        let blocked = estimates(&scene, Vec3::new(0.1, 0.0, 0.1), 2_000, 87);
        assert_eq!(
            (blocked.mean, blocked.variance),
            (0.0, 0.0),
            "a blocker hides the whole light: every sample 0"
        );
        let up = ceiling_light(0.0, 1.0, 0.0, 0.5, 4.0).replace("rotate = [180, 0, 0]", "rotate = [0, 0, 0]");
        let away = estimates(&floor_scene(&up), Vec3::new(0.1, 0.0, 0.1), 2_000, 88);
        assert_eq!(
            (away.mean, away.variance),
            (0.0, 0.0),
            "a light facing away (cos θ_l ≤ 0): every sample 0"
        );
    }
}

#[cfg(test)]
mod tests {
    use super::oracle::polygon_irradiance;
    use super::*;

    /// Lambert's formula against the closed form for a disc-like limit: a small square of area
    /// A at height h straight above gives E ≈ L A / h²; and a huge square gives π L.
    #[test]
    fn lamberts_polygon_formula_has_its_limits() {
        let x = Vec3::ZERO;
        let small =
            [(-0.01, -0.01), (0.01, -0.01), (0.01, 0.01), (-0.01, 0.01)].map(|(a, b)| Vec3::new(a, 2.0, b));
        let e = polygon_irradiance(x, Vec3::Y, &small, 3.0);
        assert!((e - 3.0 * 0.0004 / 4.0).abs() < 1e-6 * e.max(1e-9) * 100.0, "{e}");
        let huge = [(-1e4, -1e4), (1e4, -1e4), (1e4, 1e4), (-1e4, 1e4)].map(|(a, b)| Vec3::new(a, 1.0, b));
        let e = polygon_irradiance(x, Vec3::Y, &huge, 1.0);
        assert!((e - std::f64::consts::PI).abs() < 1e-3, "{e}");
    }

    /// An emitter's front shows its radiance, its back nothing.
    #[test]
    fn emitters_are_seen_from_the_front_only() {
        let scene = crate::test_fixtures::scene_from_toml(
            "[materials.emitter]\nkind = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"emitter\"\nemission = [1, 2, 3]\n",
        );
        let world = World::new(&scene, crate::geometry::SplitMethod::ObjectMedian);
        let seen =
            |from: Vec3, dir: Vec3| world.intersect(&Ray::new(from, dir)).expect("the quad").emitted(-dir);
        let front = seen(Vec3::new(0.1, 1.0, 0.2), -Vec3::Y);
        assert_eq!(front, Vec3::new(1.0, 2.0, 3.0), "seen from its front, the light shows L_e");
        assert_eq!(seen(Vec3::new(0.1, -1.0, 0.2), Vec3::Y), Vec3::ZERO, "seen from its back: nothing");
        assert_eq!(scene.area_lights.len(), 1, "one emitting quad, one area light");
        let power = vec![std::f32::consts::PI * 4.0 * 2.0];
        assert_eq!(scene.light_powers, power, "Φ = π · A · L_e, the mean of the channels (2) over area 4");
    }
}
