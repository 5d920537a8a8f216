//! Grading: scoring renders against reference images, per checkpoint.
//!
//! The grader only calls raylab's public rendering API; nothing in the renderer knows it exists.
//! [`rubric`] says what is graded, [`reference`](mod@reference) keeps the reference images,
//! [`features`] the masks made with them, [`ssim`] and [`metrics`] score a render. The modules
//! form layers (ARCHITECTURE.md, "Layers, checked"): each names only modules below it.

#![warn(missing_docs)]

pub mod features;
pub mod file_error;
pub mod fingerprint;
pub mod grading;
pub mod images;
#[cfg(feature = "instructor")]
pub mod instructor;
pub mod metrics;
pub mod noisy;
pub mod outcome;
pub mod plain;
pub mod reference;
pub mod regions;
pub mod report;
pub mod rubric;
pub mod run;
pub mod scene_failure;
pub mod ssim;
pub mod stats;
pub mod submission;
pub mod verdict;
pub mod watch;
