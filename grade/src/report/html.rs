//! The HTML report: one self-contained page (images embedded as data URLs) with, per scene, the
//! reference, the student's render and the difference heat map side by side, the checks, and the
//! hint and handout of every checkpoint that lost points.

use std::fmt::Write;

use base64::Engine;
use image::RgbImage;

use crate::fingerprint::Closeness;
use crate::noisy::{tile_origin, NoisyVerdict};
use crate::outcome::{GradeReport, SceneResult, SceneStatus};
use crate::report::heatmap::heatmap;
use crate::report::reasons::{
    advice_line, checkpoints_text, kept_text, named_text, reason_lines, tile_problem_text,
};
use crate::report::tile_map::{tile_map, LEGEND};
use crate::rubric::TileTest;

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em;background:#fafafa;color:#222}\
table{border-collapse:collapse;margin:1em 0}td,th{padding:.3em .8em;border-bottom:1px solid #ddd;text-align:left}\
.pass{color:#176f2c;font-weight:bold}.fail{color:#b3261e;font-weight:bold}.wait{color:#666;font-weight:bold}\
.images{display:flex;gap:1em;flex-wrap:wrap}figure{margin:0}figcaption{max-width:256px}img{width:256px;image-rendering:pixelated;border:1px solid #ccc}\
td:last-child{max-width:60em;overflow-wrap:anywhere}.missing{width:256px;height:256px;background:#eee;display:flex;align-items:center;justify-content:center;color:#777}\
section{background:#fff;padding:1em 1.5em;margin:1.5em 0;border-radius:6px;box-shadow:0 1px 3px #0002}\
.hint{background:#fff6d5;padding:.5em 1em;border-left:4px solid #e0b400}";

/// The page for `report`.
pub fn page(report: &GradeReport) -> String {
    let mut h = String::new();
    let _ = write!(h, "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>raylab grade: {:.1} / {:.0}</title><style>{STYLE}</style></head><body>\n",
        report.score(), report.max_score());
    let _ = writeln!(
        h,
        "<h1>raylab: {:.1} / {:.0} points{}</h1>",
        report.score(),
        report.max_score(),
        escape(&crate::report::extra_text(report))
    );
    let _ = writeln!(h, "<table class=\"checkpoints\"><tr><th>#</th><th>checkpoint</th><th>tests</th><th>images</th><th>points</th><th>why points were lost</th></tr>");
    for c in &report.checkpoints {
        let (tests, images) = (c.tests_cell(), c.images_cell());
        let class = if c.reasons.is_empty() { "pass" } else { "fail" };
        let reasons: Vec<String> = reason_lines(c).iter().map(|r| escape(r)).collect();
        let hint = advice_line(c).map_or(String::new(), |a| format!("<p class=\"hint\">{}</p>", escape(&a)));
        let _ = writeln!(h, "<tr><td>{}</td><td>{}</td><td>{tests}</td><td>{images}</td><td class=\"{class}\">{:.1}/{:.0}</td><td>{}{hint}</td></tr>",
            c.checkpoint.id, escape(&c.checkpoint.title), c.score(), c.max_score(report.tests_ran), reasons.join("<br>"));
    }
    h.push_str("</table>\n");
    needed_list(&mut h, report);
    for s in &report.scenes {
        scene_section(&mut h, s, report);
    }
    h.push_str("</body></html>\n");
    h
}

/// The checkpoints not graded whose code the scenes run ([`GradeReport::needed`]).
fn needed_list(h: &mut String, report: &GradeReport) {
    if report.needed.is_empty() {
        return;
    }
    h.push_str("<p>Not graded here, but the scenes below run their code (no points from them):</p><ul>");
    for n in &report.needed {
        let (id, title, state) = (n.checkpoint.id, escape(&n.checkpoint.title), escape(&n.state()));
        let _ = write!(h, "<li>checkpoint {id} ({title}): {state}</li>");
    }
    h.push_str("</ul>\n");
}

fn scene_section(h: &mut String, s: &SceneResult, report: &GradeReport) {
    let (class, word) = match &s.status {
        SceneStatus::Passed => ("pass", "pass"),
        SceneStatus::Failed => ("fail", "FAIL"),
        SceneStatus::NotCounted(_) => ("wait", "not counted"),
    };
    let _ = writeln!(h, "<section class=\"scene\" id=\"scene-{0}\"><h2>{0} <span class=\"{class}\">{word}</span></h2><p>grades {1}{2}</p>",
        escape(&s.scene.name), checkpoints_text(&s.scene.grades), how_rendered(s));
    if s.scene.hidden {
        h.push_str("<p>A hidden scene: its checks are shown, never its images.</p>\n");
    } else {
        pictures(h, s);
    }
    match (&s.status, &s.error) {
        (SceneStatus::NotCounted(kept), _) => {
            let _ = writeln!(h, "<p class=\"wait\">{}</p>", escape(&kept_text(kept)));
        }
        (_, Some(e)) => {
            let _ = writeln!(h, "<p class=\"fail\">{}</p>", escape(&e.to_string()));
        }
        _ => {}
    }
    if let Some(n) = &s.named {
        let _ = writeln!(h, "<p class=\"fail\">{}</p>", escape(&named_text(&s.scene.name, n)));
    }
    if !s.checks.is_empty() {
        checks_table(h, s, class, word);
    }
    if let (Some(verdict), Some(test)) = (&s.tiles, &s.scene.tile_test) {
        tile_failures(h, verdict, test, s.reference.width());
    }
    for c in report
        .checkpoints
        .iter()
        .filter(|c| s.status == SceneStatus::Failed && s.scene.depends_on.contains(&c.checkpoint.id))
    {
        if let Some(advice) = advice_line(c) {
            let _ = writeln!(h, "<p class=\"hint\">Checkpoint {}: {}</p>", c.checkpoint.id, escape(&advice));
        }
    }
    h.push_str("</section>\n");
}

/// "; rendered in 0.4 s", and the stand-ins that drew the scene, if any.
fn how_rendered(s: &SceneResult) -> String {
    let rendered =
        if s.render.is_some() { format!("; rendered in {:.1} s", s.seconds) } else { String::new() };
    match s.stand_ins.as_slice() {
        [] => rendered,
        ids => format!(
            "{rendered}; {} not written yet, so drawn by {} stand-in (the same picture, no points for {})",
            checkpoints_text(ids),
            if ids.len() > 1 { "their" } else { "its" },
            if ids.len() > 1 { "them" } else { "it" }
        ),
    }
}

/// A public scene's pictures side by side: the reference, the render, where they differ (a heat
/// map, or a noisy scene's tile map) and the known mistake it looks like, if one is named.
fn pictures(h: &mut String, s: &SceneResult) {
    h.push_str("<div class=\"images\">");
    figure(h, "reference", Some(&s.reference));
    let mean = s.scene.tile_test.as_ref().map(|t| format!("yours: the mean of your {} renders", t.renders));
    let yours = match (&s.render, &s.status) {
        (None, SceneStatus::NotCounted(_)) => "yours: no image yet",
        (None, _) => "yours: the render failed (below)",
        (Some(_), _) => mean.as_deref().unwrap_or("yours"),
    };
    figure(h, yours, s.render.as_ref());
    match (&s.tiles, &s.scene.tile_test, &s.ssim) {
        (Some(verdict), Some(test), _) => {
            figure(h, LEGEND, Some(&tile_map(verdict, test.tile, &s.reference)))
        }
        (None, None, Some(ssim)) => figure(
            h,
            "difference (1 − SSIM over a faint copy of the reference: dim where the same, red to yellow where different)",
            Some(&heatmap(ssim, &s.reference)),
        ),
        _ => {}
    }
    if let Some(n) = &s.named {
        // The mistake's fingerprint, enlarged to the render's size, pixels kept square.
        let (w, h_) = s.reference.dimensions();
        let enlarged = image::imageops::resize(&n.picture, w, h_, image::imageops::FilterType::Nearest);
        let what = match n.closeness {
            Closeness::Ssim { .. } => "",
            Closeness::Tiles { .. } => " (its tile means)",
        };
        figure(h, &format!("looks like this known mistake{what}: {}", n.entry.description), Some(&enlarged));
    }
    h.push_str("</div>\n");
}

/// A scene's checks, each with its value and threshold; a failed check says `word` in `class`
/// (FAIL, or not counted).
fn checks_table(h: &mut String, s: &SceneResult, class: &str, word: &str) {
    h.push_str(
        "<table class=\"checks\"><tr><th>check</th><th>value</th><th>threshold</th><th>result</th></tr>",
    );
    for (check, m) in &s.checks {
        let (class, word) = if m.passed { ("pass", "pass") } else { (class, word) };
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{:.4}</td><td>{}</td><td class=\"{class}\">{word}</td></tr>",
            check.label(),
            m.value,
            escape(&check.threshold_text())
        );
    }
    h.push_str("</table>\n");
}

/// The first failing tiles of a tile test, where they are and why.
fn tile_failures(h: &mut String, verdict: &NoisyVerdict, test: &TileTest, width: u32) {
    const SHOWN: usize = 8;
    let _ = write!(
        h,
        "<p>{} renders, {} tiles of {2}×{2} pixels, each test at level {3:.1e} (a correct render fails somewhere with probability {4}); {5} tiles failed.</p>",
        test.renders,
        verdict.tiles.len(),
        test.tile,
        verdict.level,
        test.alpha,
        verdict.failures.len()
    );
    if !verdict.failures.is_empty() {
        h.push_str("<ul>");
        for f in verdict.failures.iter().take(SHOWN) {
            let (x, y) = tile_origin(f.tile, test.tile, width);
            let _ = write!(h, "<li>tile at pixel ({x}, {y}): {}</li>", escape(&tile_problem_text(f)));
        }
        if verdict.failures.len() > SHOWN {
            let _ = write!(h, "<li>and {} more</li>", verdict.failures.len() - SHOWN);
        }
        h.push_str("</ul>\n");
    }
}

fn figure(h: &mut String, caption: &str, image: Option<&RgbImage>) {
    let img = match image.and_then(|i| png_data_url(i).ok()) {
        Some(url) => format!("<img alt=\"{}\" src=\"{url}\">", escape(caption)),
        None => "<div class=\"missing\">no image</div>".to_string(),
    };
    let _ = write!(h, "<figure>{img}<figcaption>{}</figcaption></figure>", escape(caption));
}

fn png_data_url(image: &RgbImage) -> Result<String, image::ImageError> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png)?;
    Ok(format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes.into_inner())
    ))
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outcome::Phases;
    use crate::rubric::Rubric;
    use std::path::Path;

    /// A hidden scene is reported by name and checks, without an image; a public one with three.
    #[test]
    fn the_report_never_shows_a_hidden_scenes_images() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let rubric = Rubric::of_tree(&root).unwrap();
        let scene = |hidden: bool| {
            let scene = rubric.scenes.iter().find(|s| s.hidden == hidden).unwrap().clone();
            let image = RgbImage::new(16, 16);
            let ssim = crate::ssim::SsimMap::new(&image, &image).unwrap();
            SceneResult {
                scene,
                checks: Vec::new(),
                error: None,
                seconds: 0.1,
                render: Some(image.clone()),
                reference: image,
                ssim: Some(ssim),
                tiles: None,
                stand_ins: Vec::new(),
                status: SceneStatus::Passed,
                named: None,
            }
        };
        let report = |hidden: bool| GradeReport {
            scenes: vec![scene(hidden)],
            checkpoints: Vec::new(),
            tests_ran: false,
            needed: Vec::new(),
            seconds: 0.0,
            phases: Phases::default(),
        };
        let (public, hidden) = (page(&report(false)), page(&report(true)));
        assert_eq!(public.matches("<img").count(), 3);
        assert_eq!(hidden.matches("<img").count(), 0);
        assert!(hidden.contains(&escape(&report(true).scenes[0].scene.name)));
    }
}
