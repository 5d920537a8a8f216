//! Grading: scoring renders against reference images, per checkpoint.
//!
//! The grader only calls raylab's public rendering API; nothing in the renderer knows it exists.

pub mod ssim;
