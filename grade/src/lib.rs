//! Grading: scoring renders against reference images, per checkpoint.
//!
//! The grader only calls raylab's public rendering API; nothing in the renderer knows it exists.
//! [`rubric`] says what is graded, [`reference`](mod@reference) keeps the reference images,
//! [`features`] the masks made with them, [`ssim`] and [`metrics`] score a render. The modules
//! form layers (ARCHITECTURE.md, "Layers, checked"): each names only modules below it.

#![warn(missing_docs)]

pub mod allow;
pub mod baseline;
pub mod batch;
pub mod cargo;
pub mod child;
pub mod features;
pub mod fingerprint;
pub mod grading;
pub mod heatmap;
pub mod html;
pub mod images;
#[cfg(feature = "instructor")]
pub mod instructor;
pub mod lexer;
pub mod markers;
pub mod metrics;
pub mod noisy;
pub mod outcome;
pub mod plain;
pub mod points;
pub mod probe;
pub mod reference;
pub mod report;
pub mod rubric;
pub mod sandbox;
pub mod scratch;
pub mod splice;
pub mod ssim;
pub mod stub;
pub mod submission;
pub mod tile_map;
pub mod unit_tests;
pub mod unpack;
pub mod watch;
