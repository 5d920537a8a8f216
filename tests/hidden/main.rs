//! The instructor's hidden tests: checks of checkpoints 2 to 7 that the student starter does not
//! ship (`cargo xtask starter` leaves out `tests/hidden/` and `hidden/`), graded for the points
//! `hidden/rubric.toml` gives them. Each module is `hiddenN_...`, so `cargo test hiddenN` runs one
//! checkpoint's and `cargo test checkpointN` (the student's command) none of them.
//!
//! They test the same contracts as the public tests, with other oracles and other inputs: a
//! student who passes the public tests by the handout's maths passes these too; one who fitted
//! the code to the public tests' inputs does not.

mod hidden2_triangle;
mod hidden3_aabb;
mod hidden4_bvh;
mod hidden5_refraction;
mod hidden6_direct_lighting;
mod hidden7_antialiasing;
mod oracle;
