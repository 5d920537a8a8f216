//! Instructor tasks.
//!
//! `cargo xtask starter --out DIR` writes the student starter from the reference solution;
//! `cargo xtask stub-matrix` proves, for each checkpoint N stubbed alone, that every checkpoint-N
//! test fails and every test of the checkpoints before N passes; `cargo xtask zoo` runs the mistake
//! catalogue and writes which check catches each mistake; `cargo xtask stage-points` checks that a
//! mistake costs the same points in a student's own tree as in `grader submission`;
//! `cargo xtask gradescope-dry-run` runs the Gradescope autograder's life cycle on a scratch root; `cargo xtask first-build` and
//! `cargo xtask student-loop` time a student's first build and their edit-and-grade loop.
//!
//! The starter is the whole repository with every solution region replaced by its stub
//! (`todo!("checkpoint N: ...")`, see `raylab_grade::regions::stub`), and without what only instructors
//! need: this generator, the mistake catalogue (`checkpoints/variants.toml`) and its calibration
//! table. It then checks that no line of any solution survives in the starter.

mod catalogue;
mod classroom;
mod course;
mod course_with;
mod first_build;
mod gradescope;
mod handouts;
mod layers;
mod similarity_export;
mod stage_points;
mod starter;
mod stub_matrix;
mod student_loop;
mod tables;
mod zoo;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(about = "raylab's instructor tasks")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write the student starter repository into DIR (replaced if it exists).
    Starter {
        /// Where to write it.
        #[arg(long)]
        out: PathBuf,
    },
    /// A course that skips checkpoint ID, made from this tree with no change to the grader:
    /// its solution grades in full without ID, and its starter stubs every other region.
    CourseWithout {
        /// The checkpoint the course skips.
        id: u32,
    },
    /// A course that adds checkpoint 10 (mirror reflection), made from this tree with no change
    /// to the grader: graded in full, its catalogue mistake costs it alone, its starter stubs it.
    CourseWithExtra,
    /// For each checkpoint N from 2 to 7 stubbed alone: N's tests all fail, earlier ones pass.
    StubMatrix,
    /// Each crate's modules, folder by folder, bottom layer first; fails on a cycle between
    /// sibling modules (ARCHITECTURE.md lists the grader's layers in this order).
    Layers,
    /// Run the mistake catalogue: which unit test or scene catches each variant (docs/ZOO.md).
    Zoo,
    /// Grade each catalogue mistake of checkpoint N in a starter written up to N, by the
    /// student's grader and by `grader submission`: N's points must agree (docs/GRADING.md).
    StagePoints {
        /// Only these mistakes (default: every one).
        mistakes: Vec<String>,
    },
    /// Write the similarity engine's measured classes as files, for its peers to be run on the
    /// same pairs (tools/similarity-peers/).
    SimilarityExport {
        /// Where to write them.
        #[arg(long)]
        out: PathBuf,
        /// How many classes (of 60 students).
        #[arg(long, default_value_t = 3)]
        classes: usize,
    },
    /// Time a student's first `cargo test checkpoint2` in a fresh starter with a cold target
    /// folder, and the edit-to-result time after one edit (docs/PERFORMANCE.md).
    FirstBuild,
    /// Time a student's loop in a fresh starter: a save in checkpoint N's region to the exit of
    /// `cargo grader --checkpoint N`, for N = 2 to 7 (docs/PERFORMANCE.md).
    StudentLoop {
        /// Saves timed per checkpoint (the median is printed).
        #[arg(long, default_value_t = 5)]
        runs: usize,
    },
    /// Package the tree for Gradescope, unpack it in a scratch root, run setup.sh, and
    /// run_autograder on the solution, the starter and two hostile submissions.
    GradescopeDryRun {
        /// Run setup.sh and run_autograder as in Gradescope's container
        /// (tools/gradescope-emulation.sh), on the solution and the worst hostile submission.
        #[arg(long)]
        emulate: bool,
    },
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Starter { out } => {
            starter::starter(&out).map(|()| println!("wrote the student starter to {}", out.display()))
        }
        Command::StubMatrix => stub_matrix::stub_matrix(),
        Command::CourseWithout { id } => course::without(id),
        Command::CourseWithExtra => course_with::with_extra(),
        Command::Layers => layers::layers(),
        Command::Zoo => zoo::zoo(),
        Command::StagePoints { mistakes } => stage_points::stage_points(&mistakes),
        Command::SimilarityExport { out, classes } => similarity_export::similarity_export(&out, classes),
        Command::FirstBuild => first_build::first_build(),
        Command::StudentLoop { runs } => student_loop::student_loop(runs),
        Command::GradescopeDryRun { emulate } => gradescope::gradescope_dry_run(emulate),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("xtask: {message}");
            ExitCode::from(1)
        }
    }
}

/// The repository this xtask belongs to.
fn repository() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lives inside the repository")
}
