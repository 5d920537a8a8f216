//! Why a submission, or a class, was not graded, as a value: its folder, its archive, the
//! instructor's inputs, or the grader itself. `grader submission` reports it in one line with exit
//! code 2; `grader batch` gives it as that student's row and goes on.

use std::path::PathBuf;

use crate::file_error::FileError;
use crate::grading::GradeError;
use crate::rubric::RubricError;
use crate::submission::unpack::UnpackError;

/// Why a submission, or a class, was not graded.
#[derive(Debug, thiserror::Error)]
pub enum SubmissionError {
    /// The path given is not a folder.
    #[error("{}: not a folder", .0.display())]
    NotAFolder(PathBuf),
    /// Its archive was refused.
    #[error(transparent)]
    Unpack(#[from] UnpackError),
    /// A file of the submission, the instructor's tree or the scratch tree cannot be read or
    /// written.
    #[error(transparent)]
    File(#[from] FileError),
    /// The rubric cannot be read or breaks a rule.
    #[error(transparent)]
    Rubric(#[from] RubricError),
    /// The instructor's inputs stop the grade.
    #[error(transparent)]
    Grade(#[from] GradeError),
    /// The grader itself panicked on this submission (a bug of ours): its message.
    #[error("the grader failed on this submission: {}", .0.as_deref().unwrap_or("no message"))]
    Panicked(Option<String>),
    /// No submission in the folders given.
    #[error("no submissions found")]
    NoSubmissions,
}
