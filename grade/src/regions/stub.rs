//! Solution regions, and the stubs that replace them in the student starter.
//!
//! Student code sits between `// BEGIN SOLUTION checkpointN` and `// END SOLUTION`, each region
//! the whole body of one function. The stub keeps the markers, silences the parameters the
//! body no longer uses, and panics with `todo!("checkpoint N: <the function's first doc
//! sentence>")`, so that the starter builds without warnings and says what to write.

use crate::regions::markers::find_regions;

/// The byte ranges of the bodies of `checkpoint`'s solution regions in `text` (see
/// [`crate::regions::markers`]); none if the text does not lex.
pub fn region_bodies(text: &str, checkpoint: u32) -> Vec<std::ops::Range<usize>> {
    let found = find_regions(text).unwrap_or_default();
    found.into_iter().filter(|f| f.checkpoint == checkpoint).map(|f| f.body).collect()
}

/// The stub's first line: what the markers around it are for.
const KEEP_MARKERS: &str =
    "// Write your code here, between the markers, which must stay: the grader takes only what is between them.";
/// Before the line that silences the parameters.
const SILENCE: &str = "// This `let _` only keeps the compiler quiet about unused parameters: delete it.";

/// `text` with the body of every `checkpoint` region replaced by its stub.
pub fn stub_regions(text: &str, checkpoint: u32) -> String {
    let mut out = text.to_string();
    for r in region_bodies(text, checkpoint).into_iter().rev() {
        let stub = stub_body(text, r.clone(), checkpoint);
        out.replace_range(r, &stub);
    }
    out
}

/// The starter's stub for the region of `checkpoint` whose body is `body` in `text`.
pub fn stub_body(text: &str, body: std::ops::Range<usize>, checkpoint: u32) -> String {
    let line_start = text[..body.start.saturating_sub(1)].rfind('\n').map_or(0, |i| i + 1);
    let indent: String = text[line_start..].chars().take_while(|c| c.is_whitespace()).collect();
    let (name, params, summary) = enclosing_fn(&text[..line_start]);
    let mut stub = format!("{indent}{KEEP_MARKERS}\n");
    let silence = |stub: &mut String, what: &str| {
        *stub += &format!("{indent}{SILENCE}\n{indent}let _ = {what};\n");
    };
    match params.len() {
        0 => {}
        1 => silence(&mut stub, &params[0]),
        _ => silence(&mut stub, &format!("({})", params.join(", "))),
    }
    let message = if summary.is_empty() {
        format!("checkpoint {checkpoint}: write `{name}`")
    } else {
        format!("checkpoint {checkpoint}: write `{name}`: {summary}")
    }
    .replace('\\', "\\\\")
    .replace('"', "\\\"");
    stub + &format!("{indent}todo!(\"{}\")\n", message.replace('{', "{{").replace('}', "}}"))
}

/// The checkpoint whose stub panicked, if `message` (a test's or a render's panic) holds the
/// panic of a stub [`stub_body`] wrote: `not yet implemented: checkpoint K: write `...`.
/// It says where a run stopped, not who wrote what: any code can panic with these words, so a
/// caller trusts it only for a checkpoint whose regions are all stubs.
pub fn stub_panic(message: &str) -> Option<u32> {
    const PANIC: &str = "not yet implemented: checkpoint ";
    message.match_indices(PANIC).find_map(|(i, _)| {
        let rest = &message[i + PANIC.len()..];
        let digits = rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len());
        rest[digits..].starts_with(": write `").then(|| rest[..digits].parse().ok()).flatten()
    })
}

/// Whether the body of the region of `checkpoint` at `body` in `text` is still the starter's
/// stub: the very text [`stub_body`] writes for it, up to white space at the ends of lines and
/// blank lines (an editor's reformatting). Any other text, a single character of code included,
/// is the student's.
pub fn is_stub(text: &str, body: std::ops::Range<usize>, checkpoint: u32) -> bool {
    let lines =
        |s: &str| s.lines().map(str::trim).filter(|l| !l.is_empty()).map(str::to_string).collect::<Vec<_>>();
    lines(&text[body.clone()]) == lines(&stub_body(text, body, checkpoint))
}

/// The checkpoints among `ids` whose every solution region in the Rust files below `dir` is still
/// the starter's stub (a checkpoint with no region at all is not among them).
pub fn stubbed_checkpoints(dir: &std::path::Path, ids: &[u32]) -> std::io::Result<Vec<u32>> {
    let texts: Vec<String> = rust_files(dir)?.into_iter().map(|(_, text)| text).collect();
    let stubbed = |&id: &u32| {
        let regions: Vec<(&String, std::ops::Range<usize>)> =
            texts.iter().flat_map(|t| region_bodies(t, id).into_iter().map(move |r| (t, r))).collect();
        !regions.is_empty() && regions.into_iter().all(|(t, r)| is_stub(t, r, id))
    };
    Ok(ids.iter().copied().filter(stubbed).collect())
}

/// Every Rust file below `dir`, with its text, in a stable order.
pub fn rust_files(dir: &std::path::Path) -> std::io::Result<Vec<(std::path::PathBuf, String)>> {
    let mut files = Vec::new();
    let mut entries: Vec<_> = std::fs::read_dir(dir)?.collect::<Result<_, _>>()?;
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let path = entry.path();
        if path.is_dir() {
            files.extend(rust_files(&path)?);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let text = std::fs::read_to_string(&path)?;
            files.push((path, text));
        }
    }
    Ok(files)
}

/// The name of the function whose body the region starting at byte `start` of `text` is.
pub fn region_function(text: &str, start: usize) -> String {
    let found = find_regions(text).unwrap_or_default();
    found.into_iter().find(|f| f.body.start == start).map(|f| f.function).unwrap_or_default()
}

/// For the last `fn` in `before`: its name, its parameters as borrows to silence (`&x`, `&mut y`
/// for a `mut y` binding; `self` and `_`-names skipped) and the first sentence of its doc comment.
fn enclosing_fn(before: &str) -> (String, Vec<String>, String) {
    let lines: Vec<&str> = before.lines().collect();
    let is_fn = |l: &str| {
        let t = l.trim_start();
        let t = t.strip_prefix("pub(crate) ").or_else(|| t.strip_prefix("pub ")).unwrap_or(t);
        t.starts_with("fn ")
    };
    let Some(fn_line) = lines.iter().rposition(|l| is_fn(l)) else {
        return (String::new(), Vec::new(), String::new());
    };
    let signature = lines[fn_line..].join("\n");
    let after_fn = &signature[signature.find("fn ").map_or(0, |i| i + 3)..];
    let name = after_fn.split(['(', '<']).next().unwrap_or("").trim().to_string();
    let params = signature.find('(').map_or(Vec::new(), |open| split_params(&signature[open + 1..]));
    let docs: Vec<&str> = lines[..fn_line]
        .iter()
        .rev()
        .take_while(|l| l.trim_start().starts_with("///") || l.trim_start().starts_with("#["))
        .filter_map(|l| l.trim_start().strip_prefix("///"))
        .collect();
    let doc = docs.iter().rev().map(|l| l.trim()).collect::<Vec<_>>().join(" ");
    let summary = doc.split(". ").next().unwrap_or("").trim_end_matches('.').to_string();
    (name, params, summary)
}

/// The parameter bindings of a parameter list starting just after its `(`.
fn split_params(list: &str) -> Vec<String> {
    let (mut depth, mut current, mut params, mut prev) = (0i32, String::new(), Vec::new(), ' ');
    for c in list.chars() {
        let arrow = prev == '-' && c == '>'; // `->` in `impl Fn(A) -> B` is no bracket
        prev = c;
        match c {
            _ if arrow => {}
            '(' | '<' | '[' | '{' => depth += 1,
            ')' | '>' | ']' | '}' if depth == 0 && c == ')' => {
                params.push(std::mem::take(&mut current));
                break;
            }
            ')' | '>' | ']' | '}' => depth -= 1,
            ',' if depth == 0 => {
                params.push(std::mem::take(&mut current));
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    params
        .iter()
        .filter_map(|p| {
            let binding = p.split(':').next()?.trim();
            let (mutable, name) = match binding.strip_prefix("mut ") {
                Some(name) => (true, name.trim()),
                None => (false, binding),
            };
            let skip = name.is_empty() || name.contains("self") || name.starts_with('_');
            (!skip).then(|| if mutable { format!("&mut {name}") } else { format!("&{name}") })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Markers are assembled so that the starter generator does not stub this fixture itself.
    const SOLUTION: &str = concat!(
        "/// Estimates the pixel. More words here.\n",
        "pub fn estimate(pixel: UVec2, spp: u32, _rng: &mut Rng, mut radiance: impl FnMut(Vec2) -> Vec3) -> Vec3 {\n",
        "    // BEGIN", " SOLUTION checkpoint7\n",
        "    radiance(pixel.as_vec2()) * spp as f32\n",
        "    // END SOLUTION\n",
        "}\n"
    );

    #[test]
    fn grader_stubs_say_what_to_write_and_silence_unused_parameters() {
        let stub = stub_regions(SOLUTION, 7);
        let expected = format!(
            " SOLUTION checkpoint7\n    {KEEP_MARKERS}\n    {SILENCE}\n    let _ = (&pixel, &spp, &mut radiance);\n{}",
            "    todo!(\"checkpoint 7: write `estimate`: Estimates the pixel\")\n    // END SOLUTION\n"
        );
        assert!(stub.contains(&expected), "{stub}");
        assert!(!stub.contains("radiance(pixel"));
        assert_eq!(stub_regions(SOLUTION, 6), SOLUTION, "other checkpoints untouched");
    }

    /// The stub's panic, as libtest and the renderer print it, names its checkpoint; other
    /// panics and a near miss of the words do not.
    #[test]
    fn grader_reads_the_checkpoint_of_a_stubs_panic() {
        let stub = stub_regions(SOLUTION, 7);
        let message = stub.split("todo!(\"").nth(1).and_then(|m| m.split("\")").next()).unwrap();
        let printed = format!("thread 'main' panicked at src/x.rs:3:5:\nnot yet implemented: {message}");
        assert_eq!(stub_panic(&printed), Some(7));
        assert_eq!(stub_panic("panicked: not yet implemented: checkpoint 12: write `f`"), Some(12));
        for other in [
            "not yet implemented",
            "not yet implemented: checkpoint 4",
            "not yet implemented: checkpoint x: write `f`",
            "not yet implemented: checkpoint 4: wrote `f`",
            "assertion failed: checkpoint 4: write `f`",
        ] {
            assert_eq!(stub_panic(other), None, "{other}");
        }
    }

    #[test]
    fn grader_tells_a_stub_from_a_started_region() {
        let stub = stub_regions(SOLUTION, 7);
        let stubbed = |text: &str, n| region_bodies(text, 7).into_iter().all(|r| is_stub(text, r, n));
        assert!(stubbed(&stub, 7), "{stub}");
        assert!(!stubbed(SOLUTION, 7));
        assert!(stubbed(&stub.replace("    todo!(", "\n      todo!("), 7), "re-indented");
        assert!(stubbed(&stub.replace('\n', "\r\n"), 7), "CRLF");
        // Started: a line of the student's own, before or on the lines of the stub.
        for started in [
            stub.replace("    todo!(", "    let n = spp * 2;\n    todo!("),
            stub.replace("let _ = (", "let _ = { std::process::exit(0) };\n    let _ = ("),
            stub.replace("let _ = (&pixel", "let _ = (&pixel.x"),
            stub.replace(KEEP_MARKERS, "// my own words"),
        ] {
            assert!(!stubbed(&started, 7), "{started}");
        }
        assert!(!stubbed(&stub, 6), "another checkpoint's todo");
    }
}
