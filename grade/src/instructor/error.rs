//! Why an instructor's command stopped, as a value: the catalogue, a hostile fixture, a program
//! it runs (git, cargo, zip), or the instructor's inputs it grades with. The grader's `main`
//! reports it in one line (a catalogue's every broken patch on a line of its own) with exit
//! code 2.

use std::path::PathBuf;

use crate::file_error::FileError;
use crate::grading::GradeError;
use crate::rubric::RubricError;

/// Why an instructor's command stopped.
#[derive(Debug, thiserror::Error)]
pub enum InstructorError {
    /// A file cannot be read, parsed or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// The rubric cannot be read or breaks a rule.
    #[error(transparent)]
    Rubric(#[from] RubricError),
    /// A grade of the tree (or of a variant's) stopped on bad input.
    #[error(transparent)]
    Grade(#[from] GradeError),
    /// A scene the references are rendered from does not load.
    #[error(transparent)]
    Scene(#[from] raylab::scene::SceneError),
    /// Patches of the catalogue that do not apply, each with its variant.
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"))]
    Catalogue(Vec<Unpatched>),
    /// A hostile fixture that cannot be made.
    #[error("fixture {name}: {problem}")]
    Fixture {
        /// The fixture's folder name.
        name: String,
        /// What is wrong.
        problem: FixtureProblem,
    },
    /// A program the command runs could not start.
    #[error("cannot run {program}: {source}")]
    CannotRun {
        /// The program.
        program: String,
        /// What the system said.
        source: std::io::Error,
    },
    /// A program the command runs failed.
    #[error("{program} failed: {last_line}")]
    Failed {
        /// The program.
        program: String,
        /// The last line of its error output.
        last_line: String,
    },
    /// A tile-tested scene whose rubric asks for no reference renders.
    #[error("scene {0}: tile_test needs reference renders")]
    NoTileRenders(String),
    /// A catalogue mistake to fingerprint whose checkpoint or scene reference is missing.
    #[error("{variant}: no checkpoint {checkpoint} or no reference of {scene}")]
    NoFingerprintBase {
        /// The variant.
        variant: String,
        /// Its checkpoint.
        checkpoint: u32,
        /// The scene.
        scene: String,
    },
}

/// A catalogue patch that does not apply.
#[derive(Debug, thiserror::Error)]
#[error("variant {variant}: {problem}")]
pub struct Unpatched {
    /// The variant.
    pub variant: String,
    /// Why its patch does not apply.
    pub problem: PatchProblem,
}

/// Why a patch does not apply.
#[derive(Debug, thiserror::Error)]
pub enum PatchProblem {
    /// Its file cannot be read or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// Its `find` text occurs other than once.
    #[error("{}: {find:?} occurs {count} times, not once", .file.display())]
    NotOnce {
        /// The file.
        file: PathBuf,
        /// The text.
        find: String,
        /// How often it occurs.
        count: usize,
    },
    /// Its `find` text is outside the checkpoint's regions.
    #[error("{}: {find:?} is not inside a checkpoint {checkpoint} solution region", .file.display())]
    OutsideRegion {
        /// The file.
        file: PathBuf,
        /// The text.
        find: String,
        /// The variant's checkpoint.
        checkpoint: u32,
    },
    /// Its region number is past the file's regions of the checkpoint.
    #[error("{}: no region {region} of checkpoint {checkpoint}", .file.display())]
    NoRegion {
        /// The file.
        file: PathBuf,
        /// The region's number in the file, from 0.
        region: usize,
        /// The variant's checkpoint.
        checkpoint: u32,
    },
}

/// Why a hostile fixture cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum FixtureProblem {
    /// A file of it, or of the copy it edits, cannot be read or written.
    #[error(transparent)]
    File(#[from] FileError),
    /// A region edit names a function with no region in its file.
    #[error("no region of {function} in {}", .file.display())]
    NoRegion {
        /// The file.
        file: PathBuf,
        /// The function.
        function: String,
    },
    /// A `{FILE:FUNCTION+N}` place in `expected.toml` that is not one.
    #[error("expected.toml: `{{{0}}}`: not FILE:FUNCTION+N with a region there")]
    BadPlace(String),
}
