//! One row per checkpoint: the rubric (`checkpoints/rubric.toml`) says which checkpoints there
//! are, which are extras and how their tests are run; the markers in `src/` say which files hold
//! each one's regions. The checkpoint tables a student reads first (the README's and the crate
//! docs' in `src/lib.rs`) are written by hand for their words, and held to both by a test.

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, BTreeSet};

    use raylab_grade::regions::markers::find_regions;
    use raylab_grade::regions::stub::rust_files;
    use raylab_grade::rubric::Rubric;

    use crate::repository;

    /// Each checkpoint's region files, `src/...`, as their markers say.
    fn region_files() -> BTreeMap<u32, BTreeSet<String>> {
        let mut files: BTreeMap<u32, BTreeSet<String>> = BTreeMap::new();
        for (path, text) in rust_files(&repository().join("src")).unwrap() {
            let name =
                format!("src/{}", path.strip_prefix(repository().join("src")).unwrap_or(&path).display());
            for found in find_regions(&text).unwrap() {
                files.entry(found.checkpoint).or_default().insert(name.clone());
            }
        }
        files
    }

    /// What a table row says: its first cell (`8 (extra)`), every `src/*.rs` path in it, and the
    /// `cargo test ...` command in it.
    struct Row {
        first: String,
        files: BTreeSet<String>,
        command: Option<String>,
    }

    /// The rows of the checkpoint table in `text`, whose lines start with `prefix` (`|`): the
    /// table whose header's first cell is `#` or `checkpoint`, up to its last line.
    fn rows(text: &str, prefix: &str) -> Vec<Row> {
        let cells = |line: &str| line.split('|').map(|c| c.trim().to_string()).collect::<Vec<_>>();
        let lines: Vec<&str> = text.lines().collect();
        let Some(header) = lines.iter().position(|l| {
            l.strip_prefix(prefix).is_some_and(|rest| ["#", "checkpoint"].contains(&cells(rest)[0].as_str()))
        }) else {
            return Vec::new();
        };
        lines[header + 2..]
            .iter()
            .map_while(|l| l.strip_prefix(prefix))
            .map(|rest| {
                let c = cells(rest);
                let spans: Vec<&str> = c.iter().flat_map(|cell| cell.split('`').skip(1).step_by(2)).collect();
                let files = spans.iter().filter(|s| s.starts_with("src/") && s.ends_with(".rs"));
                Row {
                    first: c[0].clone(),
                    files: files.map(|s| s.to_string()).collect(),
                    command: spans.iter().find(|s| s.starts_with("cargo test ")).map(|s| s.to_string()),
                }
            })
            .collect()
    }

    /// Where the table `name` disagrees with the rubric and the markers.
    fn problems(
        name: &str,
        rows: &[Row],
        rubric: &Rubric,
        files: &BTreeMap<u32, BTreeSet<String>>,
    ) -> Vec<String> {
        let mut problems = Vec::new();
        let wanted: Vec<String> = rubric
            .checkpoints
            .iter()
            .map(|c| if c.extra { format!("{} (extra)", c.id) } else { c.id.to_string() })
            .collect();
        let firsts: Vec<String> = rows.iter().map(|r| r.first.clone()).collect();
        if firsts != wanted {
            problems.push(format!("{name}: rows {firsts:?}, the rubric has {wanted:?}"));
        }
        for (row, checkpoint) in rows.iter().zip(&rubric.checkpoints) {
            let id = checkpoint.id;
            let command = format!("cargo test {}", checkpoint.test_filter);
            if row.command.as_deref() != Some(command.as_str()) {
                problems
                    .push(format!("{name}: checkpoint {id} says {:?}, the rubric `{command}`", row.command));
            }
            let held = files.get(&id).cloned().unwrap_or_default();
            if row.files != held {
                problems.push(format!(
                    "{name}: checkpoint {id} lists {:?}, its regions are in {held:?}",
                    row.files
                ));
            }
        }
        problems
    }

    fn tables() -> [(&'static str, String, &'static str); 2] {
        let read = |file: &str| std::fs::read_to_string(repository().join(file)).unwrap();
        [("README.md", read("README.md"), "|"), ("src/lib.rs", read("src/lib.rs"), "//! |")]
    }

    #[test]
    fn the_checkpoint_tables_follow_the_rubric_and_the_markers() {
        let (rubric, files) = (Rubric::of_tree(repository()).unwrap(), region_files());
        let mut found = Vec::new();
        for (name, text, prefix) in tables() {
            let rows = rows(&text, prefix);
            assert!(rows.len() >= 9, "{name}: no checkpoint table found");
            found.extend(problems(name, &rows, &rubric, &files));
        }
        assert!(found.is_empty(), "{}", found.join("\n"));
    }

    /// The test would see a table that lost a file, a row, or an extra's mark.
    #[test]
    fn a_table_that_drifts_from_the_rubric_is_caught() {
        let (rubric, files) = (Rubric::of_tree(repository()).unwrap(), region_files());
        let [(name, readme, prefix), _] = tables();
        let drifts = [
            readme.replacen(", `src/geometry/bvh/traverse.rs`", "", 1),
            readme.replacen("| 8 (extra) |", "| 8 |", 1),
            readme.replacen("`cargo test checkpoint7`", "`cargo test checkpoint_7`", 1),
            readme.lines().filter(|l| !l.starts_with("| 6 |")).collect::<Vec<_>>().join("\n"),
        ];
        for drifted in drifts {
            assert_ne!(drifted, readme, "the drift must change the README");
            assert!(!problems(name, &rows(&drifted, prefix), &rubric, &files).is_empty());
        }
    }
}
