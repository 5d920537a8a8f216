//! Why a grade could not be given at all: bad input (the rubric, a reference, a scene named that
//! the rubric does not grade, a tree whose sources cannot be read), as a value. Nothing the graded
//! code does is one: that is a failed test or scene, and costs points.

use std::path::PathBuf;

use crate::file_error::FileError;
use crate::rubric::RubricError;
use crate::run::child::CHILD_ENV;

/// Why a grade could not be given.
#[derive(Debug, thiserror::Error)]
pub enum GradeError {
    /// The grader was started inside one of its own children.
    #[error("refusing to grade inside a grader child ({CHILD_ENV} is set)")]
    InsideChild,
    /// The rubric cannot be read or breaks a rule.
    #[error(transparent)]
    Rubric(#[from] RubricError),
    /// A reference, a scene or a fingerprint file is missing, stale or malformed.
    #[error(transparent)]
    File(#[from] FileError),
    /// A scene named to be graded that the rubric does not grade.
    #[error("{name}: not a graded scene (graded: {})", known.join(", "))]
    UnknownScene {
        /// The name given.
        name: String,
        /// The scenes the rubric grades.
        known: Vec<String>,
    },
    /// A folder of the tree cannot be read.
    #[error("{}: {source}", path.display())]
    Unreadable {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}
