//! `grader`: grade the code as it stands against the reference images, per checkpoint.
//!
//! - `grader [--all | --checkpoint N | SCENE...] [--json FILE] [--out DIR] [--html DIR]` grades.
//! - `grader compare A.png B.png [--json] [--heatmap FILE]` compares two images.
//! - `grader update-references` re-renders the references (the instructor's command).
//!
//! Exit codes: 0 everything passed, 1 something failed, 2 bad usage or bad input (a missing or
//! stale reference, images of different sizes), with a one-line message.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod error;
#[cfg(feature = "instructor")]
mod instructor;

use clap::{Args, Parser, Subcommand};
use error::CliError;
use indicatif::ProgressBar;
use raylab_base::image_io::write_file_atomic;
use raylab_grade::file_error::FileError;
use raylab_grade::grading::{grade, GradeOptions};
use raylab_grade::images::{read_png, write_png};
use raylab_grade::metrics::{worst_tile_error, TILE};
use raylab_grade::report::progress::progress_bar;
use raylab_grade::ssim::SsimMap;
use raylab_grade::watch::Stage;
use raylab_grade::{report, report::heatmap::heatmap, report::html, run::probe, run::sandbox};

/// Grade raylab's checkpoints: unit tests and renders scored against reference images.
#[derive(Parser)]
#[command(version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Commands>,
    #[command(flatten)]
    grade: GradeArgs,
}

#[derive(Args)]
struct GradeArgs {
    /// Grade every checkpoint (the default when nothing else is named).
    #[arg(long)]
    all: bool,
    /// Grade only this checkpoint (its unit tests and the scenes that grade it).
    #[arg(long, value_name = "N", conflicts_with = "all")]
    checkpoint: Option<u32>,
    /// Grade only these graded scenes, by name or scene file.
    #[arg(value_name = "SCENE", conflicts_with_all = ["all", "checkpoint"])]
    scenes: Vec<String>,
    /// Write Gradescope's results.json here.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Keep each scene's render and difference heat map in this folder.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write an HTML report (index.html) into this folder.
    #[arg(long, value_name = "DIR")]
    html: Option<PathBuf>,
    /// Grade images only; do not run `cargo test`.
    #[arg(long)]
    skip_tests: bool,
    /// The repository to grade (rubric, scenes, references, tests).
    #[arg(long, default_value = ".")]
    root: PathBuf,
}

#[derive(Subcommand)]
enum Commands {
    /// Compare two images: SSIM (scikit-image's), worst tile, RMSE, and image-compare's MSSIM.
    Compare {
        /// First image (the reference).
        a: PathBuf,
        /// Second image.
        b: PathBuf,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Write the difference heat map here (PNG).
        #[arg(long, value_name = "FILE")]
        heatmap: Option<PathBuf>,
    },
    /// Grade a submission from the instructor's tree: only its solution regions are taken, each
    /// checkpoint judged on its own.
    Submission {
        /// The submission (a student's tree).
        dir: PathBuf,
        /// The instructor's repository: tests, rubric, scenes, references.
        #[arg(long, default_value = ".")]
        root: PathBuf,
        /// Where to build (reused between submissions; default: target/grader-submission in root).
        #[arg(long, value_name = "DIR")]
        work: Option<PathBuf>,
        /// Write Gradescope's results.json here.
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// Grade even where this machine cannot wall graded code in (see `grader sandbox`).
        #[arg(long)]
        no_sandbox: bool,
    },
    /// Re-run the current checkpoint's tests and scenes on every save, moving on when it passes.
    Watch {
        /// The checkpoint to start from.
        #[arg(long, default_value_t = 1)]
        from: u32,
        /// The repository (your tree).
        #[arg(long, default_value = ".")]
        root: PathBuf,
    },
    /// Grade many submissions (folders, or folders of folders) with one build folder: a report
    /// and results.json per student, grades.csv and a class page (index.html).
    Batch {
        /// Submissions, or folders holding one submission per subfolder.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// The instructor's repository.
        #[arg(long, default_value = ".")]
        root: PathBuf,
        /// Where to write the reports.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Grade even where this machine cannot wall graded code in (see `grader sandbox`).
        #[arg(long)]
        no_sandbox: bool,
    },
    /// The walls this machine puts around graded code, each measured by a probe that tries what
    /// it forbids; exits 1 when one is missing.
    Sandbox {
        /// Measure the walls (the only thing this command does).
        #[arg(long)]
        check: bool,
    },
    /// The instructor's commands (left out of the student starter's grader).
    #[cfg(feature = "instructor")]
    #[command(flatten)]
    Instructor(instructor::Command),
}

fn main() -> ExitCode {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    // The grader's executable is also the sandbox's launcher and its probe: both start here, in
    // a process with one thread, before anything else runs.
    #[cfg(target_os = "linux")]
    match args.get(1).and_then(|a| a.to_str()) {
        Some(sandbox::LAUNCH) => return sandbox::launcher::launch(&args[2..]),
        Some(probe::PROBE) => return ExitCode::from(probe::run(&args[2..]) as u8),
        _ => {}
    }
    if let Ok(me) = std::env::current_exe() {
        sandbox::set_launcher(me);
    }
    // Output piped into a reader that stops early (`| head`) ends the grader quietly, as it ends
    // other command-line tools, not in a panic. SAFETY: restores a default before any thread.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse_from(args);
    let result = match cli.command {
        Some(Commands::Compare { a, b, json, heatmap }) => compare(&a, &b, json, heatmap.as_deref()),
        Some(Commands::Submission { dir, root, work, json, no_sandbox }) => {
            walled(&root, no_sandbox).and_then(|()| submission(&root, &dir, work, json.as_deref()))
        }
        Some(Commands::Batch { dirs, root, out, no_sandbox }) => {
            walled(&root, no_sandbox).and_then(|()| batch(&root, &dirs, &out))
        }
        Some(Commands::Sandbox { .. }) => Ok(sandbox_check()),
        Some(Commands::Watch { from, root }) => watch(&root, from),
        #[cfg(feature = "instructor")]
        Some(Commands::Instructor(command)) => instructor::run(command),
        None => run_grade(cli.grade),
    };
    match result {
        Ok(code) => code,
        Err(message) => {
            eprintln!("grader: {message}");
            ExitCode::from(2)
        }
    }
}

/// `grader sandbox --check`: one line per wall; exit 1 if a required one is missing.
fn sandbox_check() -> ExitCode {
    let measured = probe::check();
    for wall in &measured {
        println!("{}", wall.line);
    }
    let missing = |required: bool| measured.iter().filter(|w| !w.holds && w.required == required).count();
    match (missing(true), missing(false)) {
        (0, 0) => println!("grader: every wall holds: graded code may run here"),
        (0, n) => {
            println!("grader: every required wall holds: graded code may run here ({n} more would be better)")
        }
        (n, _) => {
            println!("grader: {n} wall(s) missing (docs/THREAT_MODEL.md says what each one stops)");
            return ExitCode::from(1);
        }
    }
    ExitCode::SUCCESS
}

/// Grading someone else's code from the instructor's tree (`root` has no starter manifest) needs
/// the walls, unless `--no-sandbox` (which still raises every wall the machine has): they are
/// measured first; a missing required one stops the command, any other is a warning
/// ([`probe::Measured::required`]). Where the grader is root, the solution's source and the
/// hidden files are closed to every other user first. A student grading their own tree is never refused.
fn walled(root: &Path, no_sandbox: bool) -> Result<(), CliError> {
    if root.join(raylab_grade::regions::baseline::STARTER_MANIFEST).is_file() {
        return Ok(());
    }
    #[cfg(target_os = "linux")]
    sandbox::user::close_instructor_only(root).map_err(CliError::CannotClose)?;
    let missing: Vec<probe::Measured> = probe::check().into_iter().filter(|w| !w.holds).collect();
    for wall in &missing {
        eprintln!("grader: sandbox: {}", wall.line);
    }
    let required: Vec<&str> = missing.iter().filter(|w| w.required).map(|w| w.line.as_str()).collect();
    // The reports say only what changes what a grade can be trusted for; the rest is the log's.
    sandbox::note_missing(required.iter().map(|line| line.to_string()).collect());
    match (required.is_empty(), no_sandbox) {
        (true, _) => Ok(()),
        (false, true) => {
            eprintln!("grader: --no-sandbox: grading with the walls this machine has");
            Ok(())
        }
        (false, false) => Err(CliError::Unwalled(required.iter().map(|l| l.to_string()).collect())),
    }
}

fn run_grade(args: GradeArgs) -> Result<ExitCode, CliError> {
    let scenes = (!args.scenes.is_empty()).then(|| {
        args.scenes
            .iter()
            .map(|s| Path::new(s).file_stem().map_or(s.clone(), |n| n.to_string_lossy().into_owned()))
            .collect()
    });
    let options = GradeOptions {
        checkpoints: args.checkpoint.map(|c| vec![c]),
        scenes,
        run_tests: !args.skip_tests,
        ..GradeOptions::new(&args.root)
    };
    let progress = progress_bar(0);
    let graded = grade(&options, &progress);
    progress.finish_and_clear();
    let report = graded?;
    print!("{}", report::text(&report));
    if let Some(path) = &args.json {
        let text =
            serde_json::to_string_pretty(&report::gradescope_json(&report)).expect("JSON values print");
        write_file_atomic(path, text.as_bytes()).map_err(|e| FileError::unwritable(path, &e))?;
    }
    if let Some(dir) = &args.out {
        report::write_images(&report, dir)?;
    }
    if let Some(dir) = &args.html {
        std::fs::create_dir_all(dir).map_err(|e| FileError::unwritable(dir, &e))?;
        let path = dir.join("index.html");
        write_file_atomic(&path, html::page(&report).as_bytes())
            .map_err(|e| FileError::unwritable(&path, &e))?;
        eprintln!("grader: report in {}", path.display());
    }
    Ok(if report.all_passed() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn submission(
    root: &Path,
    dir: &Path,
    work: Option<PathBuf>,
    json: Option<&Path>,
) -> Result<ExitCode, CliError> {
    let work = work.unwrap_or_else(|| root.join("target/grader-submission"));
    let progress = progress_bar(0);
    let graded = raylab_grade::submission::grade_submission(root, dir, &work, &progress);
    progress.finish_and_clear();
    // Written whatever happened: a submission that cannot be graded gets 0 and why.
    if let Some(path) = json {
        let results = raylab_grade::submission::results_json(&graded);
        let text = serde_json::to_string_pretty(&results).expect("JSON values print");
        write_file_atomic(path, text.as_bytes()).map_err(|e| FileError::unwritable(path, &e))?;
    }
    let graded = graded?;
    print!("{}", raylab_grade::submission::text(&graded));
    Ok(if graded.isolated.all_passed() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn batch(root: &Path, dirs: &[PathBuf], out: &Path) -> Result<ExitCode, CliError> {
    let progress = progress_bar(0);
    let rows = raylab_grade::submission::batch::grade_all(root, dirs, out, &progress);
    progress.finish_and_clear();
    let rows = rows?;
    // The grades are written: a class that cannot be compared costs its similarity section only.
    #[cfg(feature = "instructor")]
    if let Err(e) = instructor::class_similarity(root, dirs, out, &rows) {
        eprintln!("grader: the similarity section was not written: {e}");
    }
    for row in rows {
        match row.graded {
            Ok(g) => println!("{}: {:.1} / {:.0}", row.student, g.isolated.score(), g.isolated.max_score()),
            Err(e) => println!("{}: not graded: {e}", row.student),
        }
    }
    println!(
        "grader: grades in {}, the class page {}, each student's report.txt and results.json in {}",
        out.join("grades.csv").display(),
        out.join("index.html").display(),
        out.join(raylab_grade::submission::batch::STUDENTS).join("<student>").display()
    );
    Ok(ExitCode::SUCCESS)
}

fn watch(root: &Path, from: u32) -> Result<ExitCode, CliError> {
    let rubric = raylab_grade::rubric::Rubric::of_tree(root)?;
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).filter(|&id| id >= from).collect();
    let check = |ids: &[u32], stage| {
        let scenes = (stage == Stage::Tests).then(Vec::new);
        let options = GradeOptions { checkpoints: Some(ids.to_vec()), scenes, ..GradeOptions::new(root) };
        grade(&options, &ProgressBar::hidden()).map(|report| report.checkpoints)
    };
    let mut changes = raylab_grade::watch::Polling::new(&root.join("src"));
    let stamped = !std::io::stdout().is_terminal();
    raylab_grade::watch::watch(&mut changes, check, &ids, stamped, &mut std::io::stdout())?;
    Ok(ExitCode::SUCCESS)
}

fn compare(a: &Path, b: &Path, json: bool, heatmap_path: Option<&Path>) -> Result<ExitCode, CliError> {
    let read = |path: &Path| read_png(path).map_err(|e| FileError::image(path, &e));
    let (ia, ib) = (read(a)?, read(b)?);
    let ssim = SsimMap::new(&ia, &ib).map_err(|mismatch| CliError::Incomparable {
        a: a.to_path_buf(),
        b: b.to_path_buf(),
        mismatch,
    })?;
    let rmse = {
        let sum: f64 =
            ia.as_raw().iter().zip(ib.as_raw()).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum();
        (sum / ia.as_raw().len() as f64).sqrt()
    };
    let simple =
        image_compare::rgb_similarity_structure(&image_compare::Algorithm::MSSIMSimple, &ia, &ib)?.score;
    if let Some(path) = heatmap_path {
        write_png(path, &heatmap(&ssim, &ia)).map_err(|e| FileError::image(path, &e))?;
    }
    if json {
        let value = serde_json::json!({"ssim": ssim.mean(), "worst_tile_error": worst_tile_error(&ia, &ib), "rmse_8bit": rmse, "image_compare_mssim_simple": simple});
        println!("{value}");
    } else {
        println!("ssim (scikit-image, Gaussian 11x11, sigma 1.5): {:.6}", ssim.mean());
        println!("worst {TILE}x{TILE} tile error (3x3 median):     {:.4}", worst_tile_error(&ia, &ib));
        println!("rmse of 8-bit values:                       {rmse:.4}");
        println!("image-compare MSSIMSimple (8x8 tiles; not Wang's SSIM): {simple:.6}");
    }
    Ok(ExitCode::SUCCESS)
}
