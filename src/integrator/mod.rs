//! Integrators: the radiance arriving along a camera ray.
//!
//! The integrators of checkpoints 5, 6 and 8 follow a ray through glass to the first diffuse
//! surface with [`trace_to_diffuse`] (checkpoint 5); they differ only in how they shade that
//! surface. So the intersection-test integrator needs no lights, and checkpoint 5 never waits for
//! checkpoint 6. The path tracer (checkpoint 9) goes on from there: it bounces off diffuse
//! surfaces too, shading each with checkpoint 8's [`sample_direct`].

mod boxes;
mod boxes_crossed;
mod direct_lighting;
mod intersection_test;
mod monte_carlo_direct;
mod normals;
mod path_tracer;

pub use boxes::box_colour;
pub use boxes_crossed::boxes_crossed_colour;
pub use direct_lighting::{direct_from_point_light, DirectLightingIntegrator};
pub use intersection_test::{trace_to_diffuse, DiffuseHit, IntersectionTestIntegrator};
pub use monte_carlo_direct::{sample_direct, MonteCarloDirectIntegrator};
pub use normals::normal_colour;
pub use path_tracer::{russian_roulette, PathTracerIntegrator, ROULETTE_AFTER};

use crate::math::{Ray, Vec3};
use crate::rng::Rng;
use crate::scene::{IntegratorKind, RenderSettings, World};

/// The integrator a scene asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Checkpoint 5.
    IntersectionTest(IntersectionTestIntegrator),
    /// Checkpoint 6.
    DirectLighting(DirectLightingIntegrator),
    /// Checkpoint 8.
    MonteCarloDirect(MonteCarloDirectIntegrator),
    /// Checkpoint 9.
    PathTracer(PathTracerIntegrator),
    /// The first surface's normal as a colour: a scene of geometry alone (checkpoints 2 to 4), and
    /// `render`'s stand-in while checkpoint 5 is unwritten ([`crate::fallback`]).
    Normals,
    /// Each object's bounding box, coloured by the face the ray enters it through: the slab test
    /// (checkpoint 3) alone ([`box_colour`]).
    Boxes,
    /// How many of the BVH's boxes the ray crosses before its closest hit, as a heat map: the
    /// tree and traversal of checkpoint 4 ([`boxes_crossed_colour`]).
    BoxesCrossed,
}

impl Integrator {
    /// The integrator `settings` name, with their `max_depth`.
    pub fn from_settings(settings: &RenderSettings) -> Self {
        let max_depth = settings.max_depth;
        match settings.integrator {
            IntegratorKind::Normals => Self::Normals,
            IntegratorKind::Boxes => Self::Boxes,
            IntegratorKind::BoxesCrossed => Self::BoxesCrossed,
            IntegratorKind::IntersectionTest => {
                Self::IntersectionTest(IntersectionTestIntegrator { max_depth })
            }
            IntegratorKind::DirectLighting => Self::DirectLighting(DirectLightingIntegrator { max_depth }),
            IntegratorKind::MonteCarloDirect => {
                Self::MonteCarloDirect(MonteCarloDirectIntegrator { max_depth })
            }
            IntegratorKind::PathTracer => {
                Self::PathTracer(PathTracerIntegrator { max_depth, roulette_after: ROULETTE_AFTER })
            }
        }
    }

    /// Radiance arriving at the ray's origin from along `ray` (linear RGB); Monte Carlo
    /// integrators draw their random numbers from `rng`, the others none.
    pub fn li(&self, world: &World, ray: Ray, rng: &mut Rng) -> Vec3 {
        match self {
            Self::IntersectionTest(i) => i.li(world, ray),
            Self::DirectLighting(i) => i.li(world, ray),
            Self::MonteCarloDirect(i) => i.li(world, ray, rng),
            Self::PathTracer(i) => i.li(world, ray, rng),
            Self::Normals => normal_colour(world, ray),
            Self::Boxes => box_colour(world.scene(), ray),
            Self::BoxesCrossed => boxes_crossed_colour(world, ray),
        }
    }
}
