//! The instructor's own work on the instructor's own tree, compiled only with the `instructor`
//! feature (on in this repository, off in the student starter, whose grader compiles none of it):
//! the mistake catalogue as source patches ([`variants`]), the thresholds measured on it
//! ([`calibrate`]), the fingerprints a failed render is named by ([`fingerprint_make`]) and how well they name
//! ([`naming`]), the
//! references rendered with the linked renderer ([`render_references`]), the hostile submissions
//! the grader is tested against ([`fixture`]), the Gradescope package ([`package`]), and the
//! class's copied solutions ([`similarity`]).

pub mod calibrate;
pub mod error;
pub mod fingerprint_make;
pub mod fixture;
pub mod naming;
pub mod package;
pub mod render_references;
pub mod similarity;
pub mod variants;
