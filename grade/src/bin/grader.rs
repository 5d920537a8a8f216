//! `grader`: grade the code as it stands against the reference images, per checkpoint.
//!
//! - `grader [--all | --checkpoint N | SCENE...] [--json FILE] [--out DIR] [--html DIR]` grades.
//! - `grader compare A.png B.png [--json] [--heatmap FILE]` compares two images.
//! - `grader update-references` re-renders the references (the instructor's command).
//!
//! Exit codes: 0 everything passed, 1 something failed, 2 bad usage or bad input (a missing or
//! stale reference, images of different sizes), with a one-line message.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use raylab::image_io::write_file_atomic;
use raylab_grade::grading::{grade, GradeOptions};
use raylab_grade::images::{read_png, write_png};
use raylab_grade::metrics::{worst_tile_error, TILE};
use raylab_grade::reference::update_references;
use raylab_grade::rubric::Rubric;
use raylab_grade::ssim::SsimMap;
use raylab_grade::variants::{make_scratch_tree, VariantFile};
use raylab_grade::{heatmap::heatmap, html, report};

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
    },
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
        /// Where to write the table (Markdown).
        #[arg(long, default_value = "docs/CALIBRATION.md")]
        table: PathBuf,
        /// Exit 1 unless every correct variant passes and every mistake fails its scenes.
        #[arg(long)]
        check: bool,
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Commands::Compare { a, b, json, heatmap }) => compare(&a, &b, json, heatmap.as_deref()),
        Some(Commands::Submission { dir, root, work, json }) => {
            submission(&root, &dir, work, json.as_deref())
        }
        Some(Commands::UpdateReferences { root }) => update(&root),
        Some(Commands::Calibrate { root, table, check }) => calibrate(&root, &table, check),
        Some(Commands::MakeVariant { name, out, root }) => make_variant(&root, &name, &out),
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

fn progress_bar(length: u64) -> ProgressBar {
    let style =
        ProgressStyle::with_template("{spinner} [{bar:30}] {pos}/{len} {msg}").expect("a valid template");
    ProgressBar::new(length).with_style(style.progress_chars("=> "))
}

fn run_grade(args: GradeArgs) -> Result<ExitCode, String> {
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
            serde_json::to_string_pretty(&report::gradescope_json(&report)).map_err(|e| e.to_string())?;
        write_file_atomic(path, text.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(dir) = &args.out {
        report::write_images(&report, dir)?;
    }
    if let Some(dir) = &args.html {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let path = dir.join("index.html");
        write_file_atomic(&path, html::page(&report).as_bytes())
            .map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("grader: report in {}", path.display());
    }
    Ok(if report.all_passed() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn submission(
    root: &Path,
    dir: &Path,
    work: Option<PathBuf>,
    json: Option<&Path>,
) -> Result<ExitCode, String> {
    let work = work.unwrap_or_else(|| root.join("target/grader-submission"));
    let progress = progress_bar(0);
    let graded = raylab_grade::submission::grade_submission(root, dir, &work, &progress);
    progress.finish_and_clear();
    let graded = graded?;
    let text = raylab_grade::submission::text(&graded);
    print!("{text}");
    if let Some(path) = json {
        let mut results = report::gradescope_json(&graded.isolated);
        results["output"] = serde_json::Value::String(text);
        let results = serde_json::to_string_pretty(&results).map_err(|e| e.to_string())?;
        write_file_atomic(path, results.as_bytes()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(if graded.isolated.all_passed() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn compare(a: &Path, b: &Path, json: bool, heatmap_path: Option<&Path>) -> Result<ExitCode, String> {
    let (ia, ib) = (read_png(a).map_err(|e| e.to_string())?, read_png(b).map_err(|e| e.to_string())?);
    let ssim = SsimMap::new(&ia, &ib).map_err(|e| format!("{} and {}: {e}", a.display(), b.display()))?;
    let rmse = {
        let sum: f64 =
            ia.as_raw().iter().zip(ib.as_raw()).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum();
        (sum / ia.as_raw().len() as f64).sqrt()
    };
    let simple = image_compare::rgb_similarity_structure(&image_compare::Algorithm::MSSIMSimple, &ia, &ib)
        .map_err(|e| format!("image-compare: {e}"))?
        .score;
    if let Some(path) = heatmap_path {
        write_png(path, &heatmap(&ssim, &ia)).map_err(|e| e.to_string())?;
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

fn update(root: &Path) -> Result<ExitCode, String> {
    let rubric = Rubric::load(&root.join("checkpoints/rubric.toml"), root)?;
    let progress = progress_bar(rubric.scenes.len() as u64);
    let manifest = update_references(root, &rubric, &progress);
    progress.finish_and_clear();
    for entry in manifest?.references {
        println!("reference/{}.png: {} spp in {:.2} s", entry.name, entry.spp, entry.render_seconds);
    }
    Ok(ExitCode::SUCCESS)
}

fn calibrate(root: &Path, table: &Path, check: bool) -> Result<ExitCode, String> {
    let rubric = Rubric::load(&root.join("checkpoints/rubric.toml"), root)?;
    let progress = progress_bar(0);
    let runs = raylab_grade::calibrate::run_all(root, &progress);
    progress.finish_and_clear();
    let runs = runs?;
    let text = raylab_grade::calibrate::markdown(&runs, &rubric);
    let header =
        "# Calibration\n\nWritten by `cargo run --release --bin grader -- calibrate`: every variant of \
        `checkpoints/variants.toml` graded against the references. ✗ marks a failed check.\n\n";
    if let Some(dir) = table.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    write_file_atomic(table, format!("{header}{text}").as_bytes())
        .map_err(|e| format!("{}: {e}", table.display()))?;
    println!("{text}");
    let problems = raylab_grade::calibrate::verdicts(&runs);
    for p in &problems {
        println!("calibration: {p}");
    }
    Ok(if check && !problems.is_empty() { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

fn make_variant(root: &Path, name: &str, out: &Path) -> Result<ExitCode, String> {
    let variants = VariantFile::load(&root.join("checkpoints/variants.toml"))?.variants;
    let variant = variants.iter().find(|v| v.name == name).ok_or_else(|| {
        let names: Vec<&str> = variants.iter().map(|v| v.name.as_str()).collect();
        format!("{name}: no such variant (known: {})", names.join(", "))
    })?;
    make_scratch_tree(root, out, variant)?;
    println!("{}: {} ({})", out.display(), variant.name, variant.description);
    Ok(ExitCode::SUCCESS)
}
