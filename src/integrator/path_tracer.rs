//! Checkpoint 9, parts 2 and 3: path tracing, light that bounces any number of times (colour
//! bleeding), with next-event estimation and Russian roulette.
//!
//! **Task.** Write [`PathTracerIntegrator::li`], the path loop, and [`russian_roulette`].
//!
//! **Maths.** The radiance leaving a diffuse point is what it emits plus what it reflects,
//! `L(x, ωo) = L_e(x, ωo) + ∫ f · L(y, −ωi) · cos θ dωi` (the rendering equation), where `y` is
//! the first surface seen from `x` along `ωi`. A path estimates it by following one direction per
//! bounce and carrying a *throughput* `β`, the product of the weights so far. At each diffuse
//! vertex:
//!
//! 1. **Next-event estimation**: add `β · sample_direct(...)` (checkpoint 8), the light arriving
//!    straight from the lights.
//! 2. **Continue**: pick `ωi` with [`cosine_hemisphere`] (part 1); its weight is `f cos θ / p =
//!    (ρ / π) cos θ / (cos θ / π) = ρ`, so `β ← β · ρ`.
//! 3. **Russian roulette** (from the [`ROULETTE_AFTER`]-th surface on): continue with
//!    probability `q`, else stop; a path that continues divides `β` by `q`. The expected value
//!    is unchanged (`q · β/q + (1 − q) · 0 = β`), and paths stop after a few bounces.
//!
//! Glass (checkpoint 5's [`refract_or_reflect`]) turns the path without a weight.
//!
//! **Which emission counts.** Where the path hits an emitting surface, add `β · L_e` only if the
//! previous vertex was the camera or glass. After a diffuse vertex, next-event estimation has
//! already counted the light reached this way; counting it again would count it twice. (Light
//! seen through glass can only be reached by this rule: a shadow ray stops at glass.)
//!
//! **Conventions.** `max_depth` is the most surfaces a path hits, glass included. Draw every
//! random number from `rng`, in this order at each diffuse vertex: those of `sample_direct`, two
//! for the direction, one for the roulette. The survival probability is
//! `q = min(max(β.r, β.g, β.b), 0.95)` after the bounce's weight. Turn the normal toward `ωo`
//! before sampling around it, and spawn the next ray with [`spawn_ray`].
//!
//! Check by hand: the *white furnace*, a closed sphere of albedo ρ that emits `L_e` everywhere
//! inside. Every point sees `L_e` plus what it reflects, so `L = L_e + ρ L = L_e / (1 − ρ)`; with
//! a depth cap of `d` surfaces and no roulette, `L = L_e (1 + ρ + … + ρ^d)`. `cargo test
//! checkpoint9` checks both by a t-test on 20,000 paths (the roulette also set to `u32::MAX`:
//! never), and a floor under a light against Lambert's formula (checkpoint 8), where counting
//! emission twice would double the answer.
//!
//! **Pitfalls** (each biases the image):
//! - Adding `L_e` at every hit: the light is counted twice after each diffuse bounce.
//! - Never adding `L_e` after glass: lights seen through glass are black.
//! - Forgetting to divide by `q`: the image darkens with every bounce roulette decides.
//!
//! **Check:** `cargo test checkpoint9`. Handout: `checkpoints/09-path-tracing.md`.

use crate::math::{Ray, Vec3};
use crate::rng::Rng;
use crate::scene::World;

// Used by the solution regions below; the starter's stubs do not use them yet.
#[allow(unused_imports)]
use {
    super::{sample_direct, DiffuseHit},
    crate::hemisphere::cosine_hemisphere,
    crate::material::{refract_or_reflect, Material},
    crate::math::spawn_ray,
};

/// Russian roulette decides from this surface of a path on (the first is the camera ray's).
pub const ROULETTE_AFTER: u32 = 3;

/// Global illumination by path tracing with next-event estimation (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathTracerIntegrator {
    /// Most surfaces a path hits, glass included.
    pub max_depth: u32,
    /// Russian roulette decides from this surface on ([`ROULETTE_AFTER`]; `u32::MAX`: never).
    pub roulette_after: u32,
}

impl PathTracerIntegrator {
    /// The radiance arriving along `ray`, estimated by one path.
    pub fn li(&self, world: &World, ray: Ray, rng: &mut Rng) -> Vec3 {
        // BEGIN SOLUTION checkpoint9
        let mut radiance = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        let mut ray = ray;
        // The camera, or glass, sees emission; after a diffuse vertex next-event estimation has
        // counted it.
        let mut count_emission = true;
        for depth in 1..=self.max_depth {
            let Some(hit) = world.intersect(&ray) else { break };
            let wo = -ray.dir;
            if count_emission {
                radiance += throughput * hit.emitted(wo);
            }
            match *hit.material {
                Material::PerfectRefraction { ior } => {
                    ray = spawn_ray(hit.p, hit.normal, refract_or_reflect(wo, hit.normal, ior));
                    count_emission = true;
                }
                Material::Diffuse { albedo } => {
                    radiance += throughput * sample_direct(world, &DiffuseHit { hit, wo, albedo }, rng);
                    let n = if hit.normal.dot(wo) < 0.0 { -hit.normal } else { hit.normal };
                    let wi = cosine_hemisphere(n, [rng.next_f32(), rng.next_f32()]);
                    throughput *= albedo;
                    ray = spawn_ray(hit.p, n, wi);
                    count_emission = false;
                    if depth >= self.roulette_after {
                        match russian_roulette(throughput, rng) {
                            Some(weighted) => throughput = weighted,
                            None => break,
                        }
                    }
                }
            }
        }
        radiance
        // END SOLUTION
    }
}

/// Russian roulette: `None` (stop the path) with probability `1 − q`, else the throughput
/// divided by `q`, for `q = min(max channel of throughput, 0.95)`; one random number.
pub fn russian_roulette(throughput: Vec3, rng: &mut Rng) -> Option<Vec3> {
    // BEGIN SOLUTION checkpoint9
    let q = throughput.max_element().min(0.95);
    (rng.next_f32() < q).then(|| throughput / q)
    // END SOLUTION
}

#[cfg(test)]
mod checkpoint9 {
    use super::*;
    use crate::geometry::SplitMethod;
    use crate::integrator::monte_carlo_direct::oracle::polygon_irradiance;
    use crate::integrator::trace_to_diffuse;
    use crate::scene::Scene;
    use crate::stats::{welch, Summary};
    use crate::test_fixtures::{assert_mean, scene_from_toml, scene_from_toml_at};

    const NO_ROULETTE: u32 = u32::MAX;

    fn path_tracer(max_depth: u32, roulette_after: u32) -> PathTracerIntegrator {
        PathTracerIntegrator { max_depth, roulette_after }
    }

    /// The white furnace: a closed sphere (an icosphere of radius 1, 320 triangles) whose inside
    /// has albedo `rho` and emits `le`. Any closed enclosure gives irradiance `π L_e` everywhere
    /// inside, so the series below is exact for it; a sphere also keeps next-event estimation's
    /// variance finite (`cos θ cos θ_l / r²` is nearly constant on a sphere, where in a box it
    /// grows without bound near the edges and the sample mean converges badly).
    fn furnace(rho: f32, le: f32) -> Scene {
        // An OBJ wound inward, so the emitting front faces the inside.
        let mut obj = String::new();
        for (i, t) in crate::geometry::TriangleMesh::icosphere(2).triangles().enumerate() {
            for p in [t.p0, t.p2, t.p1] {
                obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
            }
            obj += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
        }
        let dir = std::env::temp_dir().join(format!("raylab-furnace-{}-{rho}-{le}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("inside_out.obj"), obj).unwrap();
        let scene = scene_from_toml_at(
            &format!(
                "[materials.wall]\nkind = \"diffuse\"\nalbedo = [{rho}, {rho}, {rho}]\n\
                 [[objects]]\nshape = \"obj\"\nfile = \"inside_out.obj\"\nmaterial = \"wall\"\n\
                 emission = [{le}, {le}, {le}]\n"
            ),
            &dir.join("furnace.toml"),
        );
        let _ = std::fs::remove_dir_all(&dir);
        scene
    }

    /// `n` paths from inside the furnace, in directions spread over the sphere (red channel).
    fn furnace_paths(integrator: PathTracerIntegrator, scene: &Scene, n: usize, seed: u64) -> Summary {
        let world = World::new(scene, SplitMethod::ObjectMedian);
        let mut rng = Rng::new(seed, 0);
        let origin = Vec3::new(0.1, -0.2, 0.3);
        Summary::of((0..n).map(|i| {
            let dir = crate::test_fixtures::random_unit_vector(&mut Rng::new(seed, i as u64 + 1));
            integrator.li(&world, Ray::new(origin, dir), &mut rng).x as f64
        }))
    }

    /// With a depth cap of `d` surfaces and no roulette, a path sees `L_e` at the first surface
    /// and next-event estimation adds `ρ^k L_e` at the k-th: the mean is `L_e Σ_{k=0..d} ρ^k`.
    /// Counting emission after a diffuse bounce as well would add the same terms again.
    #[test]
    fn the_white_furnace_with_a_depth_cap_gives_the_truncated_series() {
        let (rho, le): (f64, f64) = (0.5, 1.0);
        let scene = furnace(rho as f32, le as f32);
        for (depth, seed) in [(1, 901), (3, 902)] {
            let want: f64 = (0..=depth).map(|k| le * rho.powi(k as i32)).sum();
            assert_mean(&furnace_paths(path_tracer(depth, NO_ROULETTE), &scene, 20_000, seed), want);
        }
    }

    /// With Russian roulette and no practical depth cap, the furnace's radiance is the whole
    /// series: `L_e / (1 − ρ)`.
    #[test]
    fn with_russian_roulette_the_white_furnace_converges_to_le_over_one_minus_rho() {
        let (rho, le): (f64, f64) = (0.6, 2.0);
        let scene = furnace(rho as f32, le as f32);
        let paths = furnace_paths(path_tracer(100_000, ROULETTE_AFTER), &scene, 20_000, 903);
        assert_mean(&paths, le / (1.0 - rho));
    }

    /// Roulette changes how long paths are, not their mean: with and without it, at the same
    /// depth cap, the furnace's means agree by Welch's t-test (p > 1e-3).
    #[test]
    fn russian_roulette_keeps_the_mean() {
        let scene = furnace(0.7, 1.0);
        let with = furnace_paths(path_tracer(8, ROULETTE_AFTER), &scene, 20_000, 904);
        let without = furnace_paths(path_tracer(8, NO_ROULETTE), &scene, 20_000, 905);
        let w = welch(&with, &without);
        assert!(w.p > 1e-3, "with roulette {:.4}, without {:.4}: p = {:.1e}", with.mean, without.mean, w.p);
    }

    /// The roulette itself: a throughput of (0.3, 0.2, 0.1) survives 30% of the time, divided by
    /// 0.3, so its mean is the throughput (binomial: 100,000 draws give a standard error of 0.0015
    /// on the rate; 5 of them is the tolerance).
    #[test]
    fn roulette_survives_with_probability_q_and_divides_by_it() {
        let mut rng = Rng::new(906, 0);
        let beta = Vec3::new(0.3, 0.2, 0.1);
        let n = 100_000;
        let survivors: Vec<Vec3> = (0..n).filter_map(|_| russian_roulette(beta, &mut rng)).collect();
        let rate = survivors.len() as f64 / n as f64;
        assert!((rate - 0.3).abs() < 5.0 * (0.3f64 * 0.7 / n as f64).sqrt(), "survival rate {rate}");
        let divided = survivors.iter().all(|s| (*s - beta / 0.3).abs().max_element() < 1e-6);
        assert!(divided, "a survivor's throughput is divided by q = 0.3: expected {}", beta / 0.3);
        // A bright throughput is capped at 0.95: some paths still stop.
        let stopped = (0..1000).filter(|_| russian_roulette(Vec3::splat(2.0), &mut rng).is_none()).count();
        assert!((20..=80).contains(&stopped), "{stopped} of 1000 stopped at q = 0.95");
    }

    /// A camera looking at a light through a glass slab sees the light's radiance: emission
    /// counts after a glass bounce (and perfect refraction carries radiance unweighted).
    #[test]
    fn a_light_seen_through_glass_is_counted() {
        let scene = scene_from_toml(
            "[materials.glass]\nkind = \"glass\"\nior = 1.5\n\
             [materials.emitter]\nkind = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[objects]]\nshape = \"box\"\nmaterial = \"glass\"\nscale = [5, 0.2, 5]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"emitter\"\ntranslate = [0, 3, 0]\n\
             rotate = [180, 0, 0]\nscale = [5, 1, 5]\nemission = [3, 2, 1]\n",
        );
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let ray = Ray::new(Vec3::new(0.2, -2.0, 0.1), Vec3::new(0.1, 1.0, -0.2).normalize());
        let li = path_tracer(8, ROULETTE_AFTER).li(&world, ray, &mut Rng::new(907, 0));
        assert!((li - Vec3::new(3.0, 2.0, 1.0)).abs().max_element() < 1e-4, "{li}");
    }

    /// A diffuse surface is two-sided: a floor seen from its back (its normal turned down)
    /// reflects what it reflects seen from its front, bounced light included. Under a square
    /// light and a ceiling (which only the floor lights), a few percent of the floor's light has
    /// bounced off the ceiling; a path that keeps sampling around the unturned normal sends
    /// those bounces into the floor and loses them (3% darker here, t ≈ 11 with these 20,000
    /// paths a side). Welch's test, p > 1e-3.
    #[test]
    fn a_surface_seen_from_its_back_bounces_light_as_from_its_front() {
        let floor_facing = |rotate: i32| {
            scene_from_toml(&format!(
                "[materials.white]\nkind = \"diffuse\"\nalbedo = [0.6, 0.6, 0.6]\n\
                 [materials.emitter]\nkind = \"diffuse\"\nalbedo = [0, 0, 0]\n\
                 [[objects]]\nshape = \"quad\"\nmaterial = \"white\"\nrotate = [{rotate}, 0, 0]\nscale = [100, 1, 100]\n\
                 [[objects]]\nshape = \"quad\"\nmaterial = \"white\"\ntranslate = [0, 1.5, 0]\n\
                 rotate = [180, 0, 0]\nscale = [100, 1, 100]\n\
                 [[objects]]\nshape = \"quad\"\nmaterial = \"emitter\"\ntranslate = [0, 1, 0]\n\
                 rotate = [180, 0, 0]\nscale = [0.5, 1, 0.5]\nemission = [4, 4, 4]\n"
            ))
        };
        let ray = Ray::new(Vec3::new(2.0, 0.5, 1.0), Vec3::new(-1.7, -0.5, -1.1).normalize());
        let means: Vec<Summary> = [0, 180]
            .into_iter()
            .enumerate()
            .map(|(i, rotate)| {
                let scene = floor_facing(rotate);
                let world = World::new(&scene, SplitMethod::ObjectMedian);
                let mut rng = Rng::new(909 + i as u64, 0);
                let tracer = path_tracer(64, ROULETTE_AFTER);
                Summary::of((0..20_000).map(|_| tracer.li(&world, ray, &mut rng).x as f64))
            })
            .collect();
        let w = welch(&means[0], &means[1]);
        assert!(w.p > 1e-3, "front {:.4}, back {:.4}: p = {:.1e}", means[0].mean, means[1].mean, w.p);
    }

    /// A floor under a square light (whose own albedo is 0): paths that bounce off the floor
    /// either escape or reach the light, which next-event estimation has counted, so the mean is
    /// the direct light alone, `ρ/π` times Lambert's irradiance. Adding the light's emission
    /// where the bounced path hits it would double it.
    #[test]
    fn emission_after_a_diffuse_bounce_is_left_to_next_event_estimation() {
        let scene = scene_from_toml(
            "[materials.floor]\nkind = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [materials.emitter]\nkind = \"diffuse\"\nalbedo = [0, 0, 0]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"floor\"\nscale = [100, 1, 100]\n\
             [[objects]]\nshape = \"quad\"\nmaterial = \"emitter\"\ntranslate = [0, 1, 0]\n\
             rotate = [180, 0, 0]\nscale = [0.5, 1, 0.5]\nemission = [4, 4, 4]\n",
        );
        let world = World::new(&scene, SplitMethod::ObjectMedian);
        let x = Vec3::new(0.3, 0.0, -0.1);
        let from = x + Vec3::new(3.0, 0.2, 0.5);
        let ray = Ray::new(from, (x - from).normalize());
        let got = trace_to_diffuse(&world, ray, 0).map(|d| d.hit.p);
        assert!(
            got.is_some_and(|p| (p - x).length() < 1e-4),
            "aimed at {x}: expected that point, got {got:?}"
        );
        let mut rng = Rng::new(908, 0);
        let paths = Summary::of(
            (0..40_000).map(|_| path_tracer(8, ROULETTE_AFTER).li(&world, ray, &mut rng).x as f64),
        );
        let square = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)].map(|(a, b)| Vec3::new(a, 1.0, b));
        let e = polygon_irradiance(x, Vec3::Y, &square, 4.0);
        assert_mean(&paths, 0.5 / std::f64::consts::PI * e);
    }
}
