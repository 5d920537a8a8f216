//! One source per fact: a checkpoint's maths, conventions and pitfalls are written once, in the
//! header (`//!`) of the files holding its regions, which a student sees beside the code; its
//! handout (`checkpoints/NN-*.md`) keeps the goal, how to check, and the symptoms, and points to
//! the header. A test holds them together: every number and code span of a handout's text is
//! found in the headers.

#[cfg(test)]
mod tests {
    use raylab_grade::regions::stub::{region_bodies, rust_files};
    use raylab_grade::rubric::Rubric;

    use crate::repository;

    /// Sections about something other than the checkpoint's code (the harness's faster trees,
    /// how noisy images are graded: `docs/GRADING.md`), not held to its header.
    const OTHER_TOPICS: [&str; 2] = ["## Going further", "## How your images are graded"];

    /// The headers of the files holding checkpoint `n`'s regions, `//!` removed, white space
    /// collapsed.
    fn headers(n: u32) -> String {
        let files = rust_files(&repository().join("src")).unwrap();
        let held = files.iter().filter(|(_, text)| !region_bodies(text, n).is_empty());
        let lines = held.flat_map(|(_, text)| text.lines().filter_map(|l| l.strip_prefix("//!")));
        collapse(&lines.collect::<Vec<_>>().join(" "))
    }

    fn collapse(text: &str) -> String {
        text.split_whitespace().collect::<Vec<_>>().join(" ")
    }

    /// A code span that names where to look or what to run, not a fact: a path, a command, a
    /// flag, a scene.
    fn is_a_pointer(span: &str) -> bool {
        let path = span.contains('/')
            && (span.ends_with('/') || span.rsplit('.').next().is_some_and(|e| e.len() <= 4));
        let scene = repository().join("scenes").join(format!("{span}.toml")).is_file();
        path || scene || span.starts_with("cargo ") || span.starts_with("--") || span.ends_with(".rs")
    }

    /// The text of a handout that is held to the headers: without fenced blocks' fences, without
    /// the sections on other topics and instructor blocks.
    fn held_text(handout: &str) -> String {
        let mut held = String::new();
        let mut skipping = false;
        for line in handout.lines() {
            if line.starts_with("## ") {
                skipping = OTHER_TOPICS.iter().any(|t| line.starts_with(t));
            }
            if !skipping && !line.starts_with("```") {
                held += line;
                held.push('\n');
            }
        }
        held
    }

    /// Every code span and number of a handout's own text, each one missing from the headers.
    fn missing(handout: &str, headers: &str) -> Vec<String> {
        let text = held_text(handout);
        let mut missing = Vec::new();
        let parts: Vec<&str> = text.split('`').collect();
        for (i, part) in parts.iter().enumerate() {
            if i % 2 == 1 {
                if !is_a_pointer(part) && !headers.contains(&collapse(part)) {
                    missing.push(format!("`{part}`"));
                }
                continue;
            }
            let numbers =
                part.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == ',')).filter_map(|w| {
                    let w = w.trim_matches(|c| c == '.' || c == ',');
                    (!w.is_empty() && w.starts_with(|c: char| c.is_ascii_digit())).then_some(w)
                });
            missing.extend(numbers.filter(|n| !headers.contains(n)).map(str::to_string));
        }
        missing
    }

    #[test]
    fn every_number_and_code_span_of_a_handout_is_in_its_checkpoints_headers() {
        let mut problems = Vec::new();
        let rubric = Rubric::of_tree(repository()).unwrap();
        // Checkpoint 1 (the environment) has no region and so no header to hold its handout.
        for checkpoint in rubric.checkpoints.iter().filter(|c| !headers(c.id).is_empty()) {
            let n = checkpoint.id;
            let text = std::fs::read_to_string(repository().join(&checkpoint.handout)).unwrap();
            let name = checkpoint.handout.display().to_string();
            for fact in missing(&text, &headers(n)) {
                problems.push(format!("{name}: {fact} is not in the headers of checkpoint {n}'s files"));
            }
        }
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }

    /// The test would catch a fact written only in a handout.
    #[test]
    fn a_fact_only_in_a_handout_is_found() {
        let headers = collapse("the factor `1e-7 · |e1 × e2|`, checkpoint 2");
        assert_eq!(
            missing("uses `1e-7 · |e1 × e2|`, not `1e-8`; checkpoint 2 in 3 steps", &headers),
            ["`1e-8`", "3"]
        );
        assert!(
            missing("see `src/geometry/triangle.rs` and run `cargo test checkpoint2`", &headers).is_empty()
        );
        assert!(missing("## Going further\n`1e-9` and 42\n## Symptoms\n", &headers).is_empty());
    }
}
