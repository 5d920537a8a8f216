//! Reports of a grading run: the text table, Gradescope's `results.json`, and the pictures; the
//! one self-contained HTML page ([`html`]) with its difference heat maps ([`heatmap`](mod@heatmap)) and a
//! noisy scene's signed tile map ([`tile_map`](mod@tile_map)).

pub mod heatmap;
pub mod html;
pub mod progress;
pub mod reasons;
pub mod tile_map;

use std::fmt::Write;
use std::path::Path;

use image::RgbImage;
use serde_json::json;

use crate::file_error::FileError;
use crate::images::write_png;
use crate::outcome::{GradeReport, SceneResult, SceneStatus};
use crate::report::heatmap::heatmap;
use crate::report::reasons::{advice_line, kept_text, reason_lines};
use crate::report::tile_map::tile_map;

/// The table a person reads: per scene, every check; then per checkpoint, the points and why
/// points were lost, with the handout to read.
pub fn text(report: &GradeReport) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<18} {:<8} {:<22} {:>8} {:>10}  {:<6} {:>6}",
        "scene", "grades", "check", "value", "threshold", "result", "time"
    );
    for s in &report.scenes {
        scene_rows(&mut out, s);
    }
    let _ = writeln!(out);
    let width = report.checkpoints.iter().map(|c| c.tests_cell().len()).max().unwrap_or(0).max(9);
    let _ =
        writeln!(out, "{:<3} {:<44} {:>width$} {:>9} {:>11}", "#", "checkpoint", "tests", "images", "points");
    for c in &report.checkpoints {
        let (tests, images) = (c.tests_cell(), c.images_cell());
        let points = format!("{:.1}/{:.0}", c.score(), c.max_score(report.tests_ran));
        let _ = writeln!(
            out,
            "{:<3} {:<44} {tests:>width$} {images:>9} {points:>11}",
            c.checkpoint.id, c.checkpoint.title
        );
        for reason in reason_lines(c) {
            let _ = writeln!(out, "      - {reason}");
        }
        if let Some(advice) = advice_line(c) {
            let _ = writeln!(out, "      hint: {advice}");
        }
    }
    needed_text(&mut out, report);
    let _ = writeln!(
        out,
        "\ntotal: {:.1} / {:.0} points{} in {:.1} s{}",
        report.score(),
        report.max_score(),
        extra_text(report),
        report.seconds,
        if report.tests_ran { "" } else { " (images only: unit tests not run)" }
    );
    out
}

/// A scene's rows of the table: a failed render, or one row per check; and why a failed scene
/// is not counted.
fn scene_rows(out: &mut String, s: &SceneResult) {
    let grades = s.scene.grades.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
    let time = format!("{:.1}s", s.seconds);
    let word = s.status.word();
    if let Some(e) = &s.error {
        let _ = writeln!(
            out,
            "{:<18} {:<8} {:<22} {:>8} {:>10}  {:<6} {:>6}",
            s.scene.name, grades, "render", "-", "-", word, time
        );
        if s.status == SceneStatus::Failed {
            let _ = writeln!(out, "{:<18} {e}", "");
        }
    }
    for (i, (check, m)) in s.checks.iter().enumerate() {
        let (name, grades, time) =
            if i == 0 { (s.scene.name.as_str(), grades.as_str(), time.as_str()) } else { ("", "", "") };
        let result = if m.passed { "pass" } else { word };
        let _ = writeln!(
            out,
            "{name:<18} {grades:<8} {:<22} {:>8.4} {:>10}  {result:<6} {time:>6}",
            check.label(),
            m.value,
            check.threshold_text()
        );
    }
    if let SceneStatus::NotCounted(kept) = &s.status {
        let _ = writeln!(out, "{:<18} {}", "", kept_text(kept));
    }
}

/// The checkpoints not graded whose code the scenes run, and what their tests say: they change
/// no points here.
fn needed_text(out: &mut String, report: &GradeReport) {
    if report.needed.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "\nnot graded here, but the scenes above run their code (no points, exit code unchanged):"
    );
    for n in &report.needed {
        let state = n.state();
        let _ = writeln!(out, "{:<3} {:<44} {state}", n.checkpoint.id, n.checkpoint.title);
    }
}

/// `" (+ 7.5 / 10 extra, not counted)"`, or nothing without extras.
pub fn extra_text(report: &GradeReport) -> String {
    let (score, max) = report.extra_score();
    if max > 0.0 {
        format!(" (+ {score:.1} / {max:.0} extra, not counted)")
    } else {
        String::new()
    }
}

/// Gradescope's `results.json`: `score`, `execution_time`, `output`, and one test entry per
/// checkpoint part (unit tests, images) with `name`, `number`, `score`, `max_score`, `status`,
/// `output`, `visibility`.
pub fn gradescope_json(report: &GradeReport) -> serde_json::Value {
    let mut tests = Vec::new();
    for c in &report.checkpoints {
        let id = c.checkpoint.id;
        let output = match (advice_line(c), reason_lines(c)) {
            (_, reasons) if reasons.is_empty() => "All checks passed.".to_string(),
            (Some(advice), reasons) => format!("{}\nHint: {advice}", reasons.join("\n")),
            (None, reasons) => reasons.join("\n"),
        };
        let mut part = |number: &str, name: String, score: f64, max: f64| {
            let status = if (score - max).abs() < 1e-9 { "passed" } else { "failed" };
            tests.push(json!({
                "name": name, "number": number, "score": round2(score), "max_score": max,
                "status": status, "output": output, "visibility": "visible",
            }));
        };
        let hidden = c.checkpoint.hidden.as_ref();
        let extra = if c.checkpoint.extra { " (extra, not counted)" } else { "" };
        let with_hidden =
            |points: f64| if points > 0.0 { format!(" ({points} of them hidden)") } else { String::new() };
        if report.tests_ran && c.checkpoint.all_test_points() > 0.0 {
            let hidden = with_hidden(hidden.map_or(0.0, |h| h.test_points));
            part(
                &format!("{id}.1"),
                format!("Checkpoint {id}: {}: unit tests{hidden}{extra}", c.checkpoint.title),
                c.test_score,
                c.checkpoint.all_test_points(),
            );
        }
        if c.checkpoint.all_image_points() > 0.0 {
            let hidden = with_hidden(hidden.map_or(0.0, |h| h.image_points));
            part(
                &format!("{id}.2"),
                format!("Checkpoint {id}: {}: images{hidden}{extra}", c.checkpoint.title),
                c.image_score,
                c.checkpoint.all_image_points(),
            );
        }
    }
    json!({
        "score": round2(report.score()),
        "execution_time": report.seconds.round() as u64,
        "output": text(report),
        "tests": tests,
    })
}

fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// Writes each public scene's render into `dir` as `<scene>.png` (a noisy scene's: the mean of
/// its renders), with its difference heat map as `<scene>.diff.png`, or a noisy scene's tile map
/// as `<scene>.tiles.png` (a hidden scene's images are never shown).
pub fn write_images(report: &GradeReport, dir: &Path) -> Result<(), FileError> {
    std::fs::create_dir_all(dir).map_err(|e| FileError::unwritable(dir, &e))?;
    let png = |name: String, image: &RgbImage| {
        let path = dir.join(name);
        write_png(&path, image).map_err(|e| FileError::image(&path, &e))
    };
    for s in report.scenes.iter().filter(|s| !s.scene.hidden) {
        if let Some(render) = &s.render {
            png(format!("{}.png", s.scene.name), render)?;
        }
        if let (Some(ssim), None) = (&s.ssim, &s.tiles) {
            png(format!("{}.diff.png", s.scene.name), &heatmap(ssim, &s.reference))?;
        }
        if let (Some(verdict), Some(test)) = (&s.tiles, &s.scene.tile_test) {
            png(format!("{}.tiles.png", s.scene.name), &tile_map(verdict, test.tile, &s.reference))?;
        }
    }
    Ok(())
}
