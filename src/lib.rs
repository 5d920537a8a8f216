//! raylab: a ray tracer built to be written by students, one checkpoint at a time, and graded.
//!
//! # The checkpoint map
//!
//! | checkpoint | task | where | tests |
//! |---|---|---|---|
//! | 1 | environment, nothing to write: scenes load, camera rays, PNG output | [`scene`], [`camera`], [`image_io`] | `cargo test checkpoint1` |
//! | 2 | ray-triangle intersection (Möller-Trumbore) | `src/geometry/triangle.rs`: [`geometry::intersect_triangle`] | `cargo test checkpoint2` |
//! | 3 | ray-box intersection (slab test) | `src/geometry/aabb.rs`: [`geometry::Aabb::intersect`] | `cargo test checkpoint3` |
//! | 4 | BVH: object-median split and traversal | `src/geometry/bvh/split.rs`, `src/geometry/bvh/traverse.rs` | `cargo test checkpoint4` |
//! | 5 | glass (Snell's law) and the intersection-test integrator | `src/material.rs`, `src/integrator/intersection_test.rs` | `cargo test checkpoint5` |
//! | 6 | direct lighting: Lambertian BRDF, point lights, shadows | `src/integrator/direct_lighting.rs` | `cargo test checkpoint6` |
//! | 7 | anti-aliasing: jittered samples per pixel | `src/sampling.rs`: [`sampling::estimate_pixel`] | `cargo test checkpoint7` |
//! | 8 (extra) | area lights, Monte Carlo direct lighting | `src/light/area.rs`, `src/light/choice.rs`, `src/integrator/monte_carlo_direct.rs` | `cargo test checkpoint8` |
//! | 9 (extra) | path tracing: cosine sampling, next-event estimation, Russian roulette | `src/hemisphere.rs`, `src/integrator/path_tracer.rs` | `cargo test checkpoint9` |
//!
//! Every task's code sits between `// BEGIN SOLUTION checkpointN` and `// END SOLUTION` (in the
//! student starter, a `todo!()`: the code written there, and only there, is graded). The conventions all checkpoints share (ray ranges,
//! `wo`/`wi`, normals, `eta`) are in [`math`]. [`stats`] holds the statistical tests that judge
//! Monte Carlo estimates (t and chi-square tails, Welch's test).
//!
//! # The pipeline
//!
//! `scene.toml` → [`scene::Scene::load`] → [`scene::World::new`] (builds the [`geometry::Bvh`]) →
//! [`render::render`] (camera rays, [`integrator::Integrator`], [`sampling`]) → [`film::Film`] →
//! [`image_io::write_film`] (sRGB PNG).

#![warn(missing_docs)]
// No `unsafe` in the renderer, solution regions included; the wide BVH's SIMD module alone
// allows it (src/geometry/mod.rs).
#![deny(unsafe_code)]

pub mod camera;
pub mod fallback;
pub mod geometry;
pub mod hemisphere;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod progress;
pub mod render;
pub mod sampling;
pub mod scene;

// Shared with the grader, from a crate without solution regions (base/).
pub use raylab_base::{film, image_io, rng, stats};

#[cfg(test)]
mod test_fixtures;
