//! The similarity page and CSV: the flagged pairs ranked, the clusters, and each flagged pair's
//! regions side by side with the lines their shared fingerprints cover marked.

use std::collections::BTreeSet;
use std::fmt::Write;

use std::path::Path;

use crate::file_error::FileError;
use crate::instructor::similarity::class::ClassSimilarity;
use crate::instructor::similarity::{Pair, Text, FLAG_SCORE};
use crate::report::html::escape;

/// The page, in `OUT`.
pub const PAGE: &str = "similarity.html";
/// The folder of `grader batch`'s output the page and the CSV go in: the instructor's alone. The
/// page shows students' code and the solution's side by side; nothing else in a batch's output
/// holds a line of either, so the class page and the students' folders can be shared.
pub const BATCH_FOLDER: &str = "similarity";
/// The CSV of every pair, in `OUT`.
pub const CSV: &str = "similarity.csv";

/// Writes [`PAGE`] and [`CSV`] into `out`, each whole or not at all.
pub fn write(class: &ClassSimilarity, out: &Path) -> Result<(), FileError> {
    std::fs::create_dir_all(out).map_err(|e| FileError::unwritable(out, &e))?;
    for (name, text) in [(PAGE, page(class)), (CSV, csv(class))] {
        let path = out.join(name);
        raylab_base::image_io::write_file_atomic(&path, text.as_bytes())
            .map_err(|e| FileError::unwritable(&path, &e))?;
    }
    Ok(())
}

/// Pairs shown under the threshold, for scale.
const UNFLAGGED_SHOWN: usize = 10;

/// Flagged pairs named in the class page's section.
const SECTION_PAIRS: usize = 10;

/// Flagged pairs listed in the table, and shown side by side: the page stays readable (and
/// small) even when a class is mostly copies; the CSV has every pair.
const FLAGGED_LISTED: usize = 300;
const FLAGGED_SHOWN: usize = 50;

/// What the page says before any pair: what a flag is and is not.
const CAVEAT: &str = "A flag marks two submissions whose solution regions are more alike than \
independent students' are, region by region, after undoing renamed bindings, literal spelling, layout, \
comments, <code>mut</code> and type annotations, reordered and unused <code>let</code>s. It is a reason to look and to talk with the students, \
not evidence: code written with the same assistant, tutorial or study group can look copied. \
Nothing here changes a grade or reaches a student.";

/// The class page's section (`grader batch`): how many pairs are flagged, the clusters, the first
/// flagged pairs (names and scores, no code), and a link to [`PAGE`] in [`BATCH_FOLDER`].
pub fn class_section(class: &ClassSimilarity) -> String {
    let names = &class.comparison.names;
    let flagged: Vec<&Pair> = class.flagged().collect();
    let mut out = format!(
        "<h2>Similar submissions</h2><p><b>{} of {} pairs flagged</b> (score above {FLAG_SCORE}), \
         {} clusters of three or more: <a href='{BATCH_FOLDER}/{PAGE}'>side by side</a> (the \
         instructor's: it shows code), every pair in <a href='{BATCH_FOLDER}/{CSV}'>{CSV}</a>. \
         {CAVEAT}</p><ul>",
        flagged.len(),
        class.comparison.pairs.len(),
        class.clusters.len()
    );
    for pair in flagged.iter().take(SECTION_PAIRS) {
        let _ = write!(
            out,
            "<li>{} and {}: {:.2}</li>",
            escape(&names[pair.a]),
            escape(&names[pair.b]),
            pair.score
        );
    }
    out + "</ul>\n"
}

/// The CSV: every pair, highest score first.
pub fn csv(class: &ClassSimilarity) -> String {
    let names = &class.comparison.names;
    let mut out = String::from("a,b,score,flagged,regions_alike,most_unusual_region,its_similarity\n");
    for pair in &class.comparison.pairs {
        let alike = pair.regions.iter().filter(|r| r.ratio > 1.0).count();
        let top = pair.regions.first();
        let _ = writeln!(
            out,
            "{},{},{:.2},{},{alike},{},{:.3}",
            quoted(&names[pair.a]),
            quoted(&names[pair.b]),
            pair.score,
            pair.score > FLAG_SCORE,
            quoted(top.map_or("", |r| r.region.as_str())),
            top.map_or(0.0, |r| r.similarity),
        );
    }
    out
}

/// A CSV field, quoted; one a spreadsheet would read as a formula (`=`, `+`, `-`, `@`) starts
/// with `'`.
fn quoted(field: &str) -> String {
    let guard = if field.starts_with(['=', '+', '-', '@']) { "'" } else { "" };
    format!("\"{guard}{}\"", field.replace('"', "\"\""))
}

/// The HTML page.
pub fn page(class: &ClassSimilarity) -> String {
    let flagged: Vec<&Pair> = class.flagged().collect();
    let mut out = String::from(HEAD) + &intro(class, flagged.len()) + &pairs_table(class, &flagged);
    for (rank, pair) in flagged.iter().take(FLAGGED_SHOWN).enumerate() {
        out += &pair_view(class, pair, rank);
    }
    out + "</body></html>"
}

/// The page's top: what a flag is, how many, what was not compared or read, the clusters.
fn intro(class: &ClassSimilarity, flagged: usize) -> String {
    let names = &class.comparison.names;
    let mut out = format!(
        "<h1>Similar submissions</h1><p class=caveat>{CAVEAT}</p><p>{} students; {} pairs compared, \
         each student with each other, with the solution{}; <b>{flagged} flagged</b> (score above \
         {FLAG_SCORE}). Measured on independent authors, about 3 pairs in 1,000 are flagged by \
         chance, more between students alike in style (docs/GRADING.md). A cluster joins students \
         through flagged pairs: its members need not be alike two by two.</p>",
        class.students,
        class.comparison.pairs.len(),
        if names.len() > class.students + 1 { " and with the earlier classes" } else { "" },
    );
    if !class.comparison.unjudged.is_empty() {
        let regions: Vec<String> = class.comparison.unjudged.iter().map(|r| function(r)).collect();
        let _ = write!(
            out,
            "<p>Not compared (no independent implementations to judge them by): {}.</p>",
            escape(&regions.join(", "))
        );
    }
    for (author, region) in &class.comparison.refused {
        let _ = write!(
            out,
            "<p class=unread>Not compared: {}'s {} (too long, too deep or not Rust tokens).</p>",
            escape(&names[*author]),
            escape(&function(region))
        );
    }
    for (student, why) in &class.unread {
        let _ = write!(out, "<p class=unread>Not read: {}: {}</p>", escape(student), escape(why));
    }
    if !class.clusters.is_empty() {
        out += "<h2>Clusters (three or more joined by flags)</h2><ul>";
        for cluster in &class.clusters {
            let members: Vec<String> = cluster.iter().map(|&i| escape(&names[i])).collect();
            let _ = write!(out, "<li>{}</li>", members.join(", "));
        }
        out += "</ul>";
    }
    out
}

/// The ranked pairs: the flagged ones (the first linked to their view), then a few below.
fn pairs_table(class: &ClassSimilarity, flagged: &[&Pair]) -> String {
    let names = &class.comparison.names;
    let mut out = String::from(
        "<h2>Pairs</h2><table><tr><th>#</th><th>submission</th><th>submission</th><th>score</th><th>regions alike</th></tr>",
    );
    let unflagged = class.comparison.pairs.iter().filter(|p| p.score <= FLAG_SCORE).take(UNFLAGGED_SHOWN);
    for (rank, pair) in flagged.iter().take(FLAGGED_LISTED).copied().chain(unflagged).enumerate() {
        let alike: Vec<String> =
            pair.regions.iter().filter(|r| r.ratio > 1.0).map(|r| function(&r.region)).collect();
        let link = match rank {
            _ if pair.score <= FLAG_SCORE => String::new(),
            r if r < FLAGGED_SHOWN => format!("<a href='#pair-{r}'>{}</a>", r + 1),
            r => format!("{}", r + 1),
        };
        let _ = write!(
            out,
            "<tr class={}><td>{link}</td><td>{}</td><td>{}</td><td>{:.2}</td><td>{}</td></tr>",
            if pair.score > FLAG_SCORE { "flag" } else { "quiet" },
            escape(&names[pair.a]),
            escape(&names[pair.b]),
            pair.score,
            escape(&alike.join(", ")),
        );
    }
    out += "</table>";
    if flagged.len() > FLAGGED_LISTED {
        let _ = write!(out, "<p>{} more flagged pairs are in the CSV.</p>", flagged.len() - FLAGGED_LISTED);
    }
    if flagged.len() > FLAGGED_SHOWN {
        let _ = write!(out, "<p>The first {FLAGGED_SHOWN} flagged pairs are shown side by side below.</p>");
    }
    out
}

/// One flagged pair: each region both wrote, most unusual first, side by side.
fn pair_view(class: &ClassSimilarity, pair: &Pair, rank: usize) -> String {
    let (names, texts) = (&class.comparison.names, &class.comparison.texts);
    let mut out = format!(
        "<section id='pair-{rank}'><h2>{}. {} and {} (score {:.2})</h2>",
        rank + 1,
        escape(&names[pair.a]),
        escape(&names[pair.b]),
        pair.score
    );
    for region in &pair.regions {
        let (a, b) = (&texts[pair.a][&region.region], &texts[pair.b][&region.region]);
        let _ = write!(
            out,
            "<h3>{} <small>similarity {:.2}, likelihood ratio {:.1} (copied over independent, in \
             the engine's model)</small></h3>\
             <div class=sides><pre>{}</pre><pre>{}</pre></div>",
            escape(&region.region),
            region.similarity,
            region.ratio,
            marked(a, b),
            marked(b, a)
        );
    }
    out + "</section>"
}

/// `text`'s body, numbered, the lines its fingerprints shared with `other` marked.
fn marked(text: &Text, other: &Text) -> String {
    let theirs: BTreeSet<u64> = other.prints.iter().map(|p| p.hash).collect();
    let lines: BTreeSet<usize> =
        text.prints.iter().filter(|p| theirs.contains(&p.hash)).flat_map(|p| p.lines.clone()).collect();
    let mut out = String::new();
    for (i, line) in text.body.lines().enumerate() {
        let n = i + 1;
        let line = escape(line);
        let _ = if lines.contains(&n) {
            writeln!(out, "<span class=n>{n:3}</span> <mark>{line}</mark>")
        } else {
            writeln!(out, "<span class=n>{n:3}</span> {line}")
        };
    }
    out
}

/// A region's function, for the table: `file::function` -> `function (file)`.
fn function(region: &str) -> String {
    match region.rsplit_once("::") {
        Some((file, function)) => format!("{function} ({})", file.rsplit('/').next().unwrap_or(file)),
        None => region.to_string(),
    }
}

const HEAD: &str = "<!doctype html><html><head><meta charset=utf-8><title>Similar submissions</title><style>
body{font:14px/1.4 system-ui,sans-serif;margin:24px;max-width:1400px}
.caveat{background:#fff8e1;border-left:4px solid #f0b400;padding:8px 12px}
table{border-collapse:collapse}td,th{padding:3px 10px;border-bottom:1px solid #ddd;text-align:left}
tr.quiet{color:#888}.unread{color:#a00}
.sides{display:grid;grid-template-columns:1fr 1fr;gap:12px}
pre{background:#f6f6f6;padding:8px;overflow-x:auto;font-size:12px;margin:0}
mark{background:#ffd54f}.n{color:#aaa}h3 small{font-weight:normal;color:#555}
</style></head><body>";
