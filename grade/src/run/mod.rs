//! Running the graded tree's code, and surviving it: every build, render and unit test is a
//! child process ([`child`]) with a time limit, resource limits and, where the machine gives
//! them, the sandbox's walls ([`sandbox`], measured by [`probe`]); [`cargo`] builds the tree's
//! `render` and [`build_error`] says why a build failed, [`unit_tests`] runs each checkpoint's tests one
//! process per test.

pub mod build_error;
pub mod cargo;
pub mod child;
pub mod probe;
pub mod sandbox;
pub mod unit_tests;
