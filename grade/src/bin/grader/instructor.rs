//! The instructor's commands: re-rendering the references, calibrating the thresholds against
//! the mistake catalogue, writing one variant of it. Built with the `instructor` feature (on by
//! default here; the student starter's grader leaves it off, since the catalogue is not there).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Subcommand;
use raylab_base::image_io::write_file_atomic;
use raylab_grade::file_error::FileError;
use raylab_grade::grading::checked_rubric;
use raylab_grade::instructor::calibrate::Sweep;
use raylab_grade::instructor::render_references::update_references;
use raylab_grade::instructor::variants::{make_scratch_tree, VariantFile};
use raylab_grade::rubric::Rubric;

use crate::error::CliError;

use raylab_grade::report::progress::progress_bar;

/// The instructor's subcommands.
#[derive(Subcommand)]
pub enum Command {
    /// Re-render every reference image, mask and the manifest (run on the reference solution).
    UpdateReferences {
        /// The repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
    /// Grade every variant of checkpoints/variants.toml and write the calibration table.
    Calibrate {
        /// The repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
        /// Where to write the table (Markdown) [default: docs/CALIBRATION.md, with --sweep
        /// docs/TILE_TEST_CALIBRATION.md].
        #[arg(long)]
        table: Option<PathBuf>,
        /// Exit 1 unless every correct variant passes and every mistake fails its scenes.
        #[arg(long)]
        check: bool,
        /// Measure the tile test's false-fail rate and power instead: the noisy scenes only, with
        /// seeds 1 to N.
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..1 << 24))]
        sweep: Option<u64>,
        /// With --sweep: seeds 1 to M for the mistakes and for the correct variants of
        /// checkpoints no noisy scene grades [default: N].
        #[arg(long, value_name = "M", requires = "sweep", value_parser = clap::value_parser!(u64).range(1..1 << 24))]
        other_seeds: Option<u64>,
    },
    /// Render the mistake catalogue into reference/fingerprints/ (a thumbnail per mistake and
    /// scene, so a failed render can be named) and measure the naming on renders held out.
    Fingerprints {
        /// The repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
        /// Where to write the naming table (Markdown).
        #[arg(long, default_value = "target/NAMING.md")]
        table: PathBuf,
    },
    /// Package the tree for a grading platform: `gradescope` writes Gradescope's autograder zip
    /// (setup.sh, run_autograder, this tree with its hidden checks, the crates vendored).
    Package {
        /// The platform (only `gradescope` so far).
        #[arg(value_parser = ["gradescope"])]
        platform: String,
        /// The zip to write.
        #[arg(long, value_name = "FILE", default_value = "autograder.zip")]
        out: PathBuf,
        /// The repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
    /// Write a copy of the tree with one variant of checkpoints/variants.toml applied.
    MakeVariant {
        /// The variant's name.
        name: String,
        /// Where to write the copy (replaced if it exists).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// The repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
    /// Find copied solutions across a class: every pair of submissions compared over their
    /// solution regions, flagged pairs written to OUT/similarity.html and OUT/similarity.csv for a
    /// person to look at (never a grade).
    Similarity {
        /// Submissions, or folders holding one submission per subfolder (as `grader batch`).
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Where to write the page and the CSV.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Earlier classes' submissions to compare each student with (not with each other).
        #[arg(long, value_name = "DIR", num_args = 1..)]
        against: Vec<PathBuf>,
        /// The instructor's repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
}

/// Runs one of the instructor's commands.
pub fn run(command: Command) -> Result<ExitCode, CliError> {
    match command {
        Command::UpdateReferences { root } => update(&root),
        Command::Calibrate { root, table, check, sweep, other_seeds } => {
            let sweep = sweep.map(|seeds| Sweep { seeds, other_seeds: other_seeds.unwrap_or(seeds) });
            calibrate(&root, table.as_deref(), check, sweep)
        }
        Command::MakeVariant { name, out, root } => make_variant(&root, &name, &out),
        Command::Fingerprints { root, table } => fingerprints(&root, &table),
        Command::Package { platform: _, out, root } => package(&root, &out),
        Command::Similarity { dirs, out, against, root } => similarity(&root, &dirs, &against, &out),
    }
}

/// `grader batch`'s similarity section: the class compared, its page and CSV in OUT/similarity/,
/// and a section in the class page.
pub fn class_similarity(
    root: &Path,
    dirs: &[PathBuf],
    out: &Path,
    rows: &[raylab_grade::submission::batch::Row],
) -> Result<(), CliError> {
    use raylab_grade::instructor::similarity::{class::similarity, page};
    eprintln!("grader: comparing the class's solution regions (copied solutions)");
    let class = similarity(root, dirs, &[], &out.join(".work").join("similarity"))?;
    page::write(&class, &out.join(page::BATCH_FOLDER))?;
    let index = out.join("index.html");
    let html = raylab_grade::submission::batch::class_page(rows, &page::class_section(&class));
    write_file_atomic(&index, html.as_bytes()).map_err(|e| FileError::unwritable(&index, &e))?;
    Ok(())
}

fn similarity(root: &Path, dirs: &[PathBuf], against: &[PathBuf], out: &Path) -> Result<ExitCode, CliError> {
    use raylab_grade::instructor::similarity::class::similarity;
    use raylab_grade::instructor::similarity::page::{write, CSV, PAGE};
    eprintln!("grader: reading and comparing the submissions' solution regions");
    let class = similarity(root, dirs, against, &out.join(".work"))?;
    write(&class, out)?;
    let names = &class.comparison.names;
    for pair in class.flagged() {
        println!("flagged: {} and {} (score {:.2})", names[pair.a], names[pair.b], pair.score);
    }
    for (student, why) in &class.unread {
        println!("not read: {student}: {why}");
    }
    println!(
        "grader: {} students, {} flagged pairs, {} clusters; the page is {}, every pair in {}",
        class.students,
        class.flagged().count(),
        class.clusters.len(),
        out.join(PAGE).display(),
        out.join(CSV).display()
    );
    Ok(ExitCode::SUCCESS)
}

fn package(root: &Path, out: &Path) -> Result<ExitCode, CliError> {
    checked_rubric(root)?; // a broken rubric or reference is found here, not on Gradescope
    eprintln!("grader: packaging {} for Gradescope (cargo vendor may take a minute)", root.display());
    raylab_grade::instructor::package::gradescope(root, &root.join("target/package/gradescope"), out)?;
    let size = std::fs::metadata(out).map_err(|e| FileError::unreadable(out, &e))?.len();
    println!("{}: Gradescope autograder, {:.1} MB", out.display(), size as f64 / 1e6);
    Ok(ExitCode::SUCCESS)
}

fn update(root: &Path) -> Result<ExitCode, CliError> {
    let rubric = Rubric::of_tree(root)?;
    let progress = progress_bar(rubric.scenes.len() as u64);
    let manifest = update_references(root, &rubric, &progress);
    progress.finish_and_clear();
    for (entry, scene) in manifest?.references.iter().zip(&rubric.scenes) {
        let image = raylab_grade::reference::image_path(Path::new(""), scene);
        println!("{}: {} spp in {:.2} s", image.display(), entry.spp, entry.render_seconds);
    }
    Ok(ExitCode::SUCCESS)
}

fn calibrate(
    root: &Path,
    table: Option<&Path>,
    check: bool,
    sweep: Option<Sweep>,
) -> Result<ExitCode, CliError> {
    let rubric = checked_rubric(root)?;
    let progress = progress_bar(0);
    let runs = raylab_grade::instructor::calibrate::run_all(root, sweep, &progress);
    progress.finish_and_clear();
    let runs = runs?;
    let (text, header, default_table) = match sweep {
        None => (
            raylab_grade::instructor::calibrate::markdown(&runs, &rubric),
            "# Calibration\n\nWritten by `cargo run --release --bin grader -- calibrate`: every variant of \
            `checkpoints/variants.toml` graded against the references. ✗ marks a failed check.\n\n"
                .to_string(),
            "docs/CALIBRATION.md",
        ),
        Some(Sweep { seeds, other_seeds }) => (
            raylab_grade::instructor::calibrate::sweep_markdown(&runs, &rubric),
            format!(
                "# Calibration of the tile test\n\nWritten by `cargo run --release --bin grader -- calibrate \
                --sweep {seeds} --other-seeds {other_seeds}`: the noisy scenes graded with seeds 1 to {seeds} for \
                the solution and the correct variants of checkpoints 8 and 9, 1 to {other_seeds} for the other \
                correct variants and for every mistake that must fail a noisy scene; rates with 95% \
                Clopper-Pearson intervals.\n\n"
            ),
            "docs/TILE_TEST_CALIBRATION.md",
        ),
    };
    let table = table.unwrap_or(Path::new(default_table));
    if let Some(dir) = table.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| FileError::unwritable(dir, &e))?;
    }
    write_file_atomic(table, format!("{header}{text}").as_bytes())
        .map_err(|e| FileError::unwritable(table, &e))?;
    println!("{text}");
    let problems = raylab_grade::instructor::calibrate::verdicts(&runs, &rubric);
    for p in &problems {
        println!("calibration: {p}");
    }
    Ok(if check && !problems.is_empty() { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

fn fingerprints(root: &Path, table: &Path) -> Result<ExitCode, CliError> {
    let progress = progress_bar(0);
    let made = raylab_grade::instructor::fingerprint_make::make(root, &progress);
    progress.finish_and_clear();
    let made = made?;
    write_file_atomic(table, made.table.as_bytes()).map_err(|e| FileError::unwritable(table, &e))?;
    println!("{}", made.table);
    println!(
        "{}: {} fingerprints, margin {:.4}; the table is in {}",
        raylab_grade::fingerprint::DIR,
        made.count,
        made.rule.margin,
        table.display()
    );
    Ok(ExitCode::SUCCESS)
}

fn make_variant(root: &Path, name: &str, out: &Path) -> Result<ExitCode, CliError> {
    let variants = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    let variant = variants.iter().find(|v| v.name == name).ok_or_else(|| CliError::UnknownVariant {
        name: name.to_string(),
        known: variants.iter().map(|v| v.name.clone()).collect(),
    })?;
    make_scratch_tree(root, out, variant)?;
    println!("{}: {} ({})", out.display(), variant.name, variant.description);
    Ok(ExitCode::SUCCESS)
}
