//! Why a `grader` command stopped on bad input or a machine it cannot trust, as a value: `main`
//! prints it on one line (`grader: ...`) and exits with code 2, the one place that does.

use std::path::PathBuf;

use raylab_grade::file_error::FileError;
use raylab_grade::grading::GradeError;
#[cfg(feature = "instructor")]
use raylab_grade::instructor::error::InstructorError;
use raylab_grade::rubric::RubricError;
use raylab_grade::ssim::SizeMismatch;
use raylab_grade::submission::SubmissionError;

/// Why a command stopped.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A file given or read cannot be read, parsed or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// The rubric cannot be read or breaks a rule.
    #[error(transparent)]
    Rubric(#[from] RubricError),
    /// The grade stopped on bad input.
    #[error(transparent)]
    Grade(#[from] GradeError),
    /// A submission or a class was not graded.
    #[error(transparent)]
    Submission(#[from] SubmissionError),
    /// An instructor's command stopped.
    #[cfg(feature = "instructor")]
    #[error(transparent)]
    Instructor(#[from] InstructorError),
    /// Graded code of someone else would run without walls this machine lacks: each, in a line.
    #[error(
        "this machine cannot wall graded code in ({}); see `grader sandbox --check`, or grade anyway with --no-sandbox",
        .0.join("; ")
    )]
    Unwalled(Vec<String>),
    /// The instructor's hidden files could not be closed to the graded user.
    #[error("cannot close the instructor's files: {0}")]
    CannotClose(std::io::Error),
    /// Two images of different sizes given to `compare`.
    #[error("{} and {}: {mismatch}", .a.display(), .b.display())]
    Incomparable {
        /// The first image.
        a: PathBuf,
        /// The second.
        b: PathBuf,
        /// Their sizes.
        mismatch: SizeMismatch,
    },
    /// The image-compare crate refused the pair.
    #[error("image-compare: {0}")]
    ImageCompare(#[from] image_compare::CompareError),
    /// The standard output could not be written.
    #[error("cannot write: {0}")]
    Output(#[from] std::io::Error),
    /// A catalogue variant named that the catalogue does not have.
    #[cfg(feature = "instructor")]
    #[error("checkpoints/variants.toml: no variant `{name}` (known: {})", .known.join(", "))]
    UnknownVariant {
        /// The name given.
        name: String,
        /// The catalogue's names.
        known: Vec<String>,
    },
}
