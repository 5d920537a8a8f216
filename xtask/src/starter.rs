//! The student starter: this repository's tracked files without the instructor's, every solution
//! region replaced by its stub (`todo!("checkpoint N: ...")`, see `raylab_grade::regions::stub`), and a
//! check that no line of any solution survives.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use raylab_grade::instructor::package::tracked_files;
use raylab_grade::instructor::variants::stub_tree;
use raylab_grade::regions::baseline::write_starter_manifest;
use raylab_grade::regions::markers::find_regions;
use raylab_grade::regions::stub::rust_files;

use crate::repository;

/// Left out of the starter: instructor-only material (this generator, the benchmarks, the
/// mistake catalogue and what it measured, and the instructor's CI, which runs them). Paths are
/// relative to the repository; a folder leaves out everything below it.
const INSTRUCTOR_ONLY: [&str; 14] = [
    "xtask",
    "bench",
    ".ci",
    "checkpoints/variants.toml",
    "docs/CALIBRATION.md",
    "docs/TILE_TEST_CALIBRATION.md",
    "docs/ZOO.md",
    "docs/PERFORMANCE.md",
    "docs/INSTRUCTORS.md",
    "docs/THREAT_MODEL.md",
    "grade/tests",
    "tools",
    // The hidden checks: scenes, references, rubric and tests graded only by the instructor.
    "hidden",
    "tests/hidden",
];

/// The workspace section of the starter's `Cargo.toml`: the renderer, what it shares with the
/// grader, and the grader, in a workspace of its own, so the starter builds wherever it is
/// unpacked.
const STARTER_WORKSPACE: &str =
    "# The root package is the renderer, what you read and edit; `grade/` is the grader that gives
# you feedback (`cargo grader`); `base/` is what both use (film, image files, random numbers,
# statistics, the scene format), none of it yours to edit, so your edits never rebuild the
# grader. `cargo test` at the root builds and tests the renderer alone.
[workspace]
members = [\"base\", \"grade\"]
";

/// Writes the starter into `out`, replacing what is there.
pub fn starter(out: &Path) -> Result<(), String> {
    let root = repository();
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    for file in starter_files(root)? {
        let to = out.join(&file);
        std::fs::create_dir_all(to.parent().unwrap_or(out)).map_err(|e| format!("{}: {e}", to.display()))?;
        std::fs::copy(root.join(&file), &to).map_err(|e| format!("{}: {e}", file.display()))?;
    }
    let edit = |file: &str, change: &dyn Fn(&str) -> Result<String, String>| {
        let path = out.join(file);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        std::fs::write(&path, change(&text)?).map_err(|e| format!("{}: {e}", path.display()))
    };
    edit("Cargo.toml", &|text| {
        let package = text.split("\n# Crates by audience.").next().unwrap_or(text).trim_end();
        let shared = text.find("[workspace.package]").map_or("", |i| &text[i..]);
        Ok(format!("{package}\n\n{STARTER_WORKSPACE}\n{shared}"))
    })?;
    edit(".cargo/config.toml", &|text| {
        Ok(text.lines().filter(|l| !l.starts_with("xtask")).map(|l| format!("{l}\n")).collect())
    })?;
    for document in documents(out)? {
        edit(&document, &student_text)?;
    }
    // The starter's grader has no instructor commands: the catalogue they need is not there.
    edit("grade/Cargo.toml", &|text| {
        let on = "default = [\"instructor\"]";
        text.contains(on)
            .then(|| text.replace(on, "default = []"))
            .ok_or_else(|| format!("grade/Cargo.toml: no `{on}`"))
    })?;
    let rubric = raylab_grade::rubric::Rubric::load(&out.join(raylab_grade::rubric::RUBRIC), out)
        .map_err(|e| e.to_string())?;
    let workflow = out.join(".github/workflows/classroom.yml");
    std::fs::create_dir_all(workflow.parent().unwrap_or(out))
        .map_err(|e| format!("{}: {e}", workflow.display()))?;
    std::fs::write(&workflow, crate::classroom::workflow(&rubric))
        .map_err(|e| format!("{}: {e}", workflow.display()))?;
    // The rubric's checkpoints: a region of any other would survive, and is refused just below.
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    stub_tree(&out.join("src"), &ids).map_err(|e| format!("stubbing {}: {e}", out.display()))?;
    let survivors = surviving_solution_lines(&root.join("src"), &out.join("src"))?;
    if !survivors.is_empty() {
        return Err(format!("solution lines survive in the starter: {survivors:?}"));
    }
    // Last: what `grader submission .` compares a student's tree with.
    write_starter_manifest(out).map_err(|e| e.to_string())
}

/// The documents a student reads, relative to the starter: the README, the handouts, `docs/`.
fn documents(out: &Path) -> Result<Vec<String>, String> {
    let mut found = vec!["README.md".to_string()];
    for folder in ["checkpoints", "docs"] {
        let entries = std::fs::read_dir(out.join(folder)).map_err(|e| format!("{folder}: {e}"))?;
        let mut names: Vec<String> = entries
            .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
            .filter(|n| n.ends_with(".md"))
            .map(|n| format!("{folder}/{n}"))
            .collect();
        names.sort();
        found.extend(names);
    }
    Ok(found)
}

/// The files the starter takes: those under version control (`git ls-files`, so nothing the
/// working folder happens to hold, such as renders or reports, reaches students), without the
/// instructor-only ones.
fn starter_files(root: &Path) -> Result<Vec<PathBuf>, String> {
    let instructor_only = |file: &Path| INSTRUCTOR_ONLY.iter().any(|p| file.starts_with(p));
    Ok(tracked_files(root).map_err(|e| e.to_string())?.into_iter().filter(|f| !instructor_only(f)).collect())
}

/// A document (README, docs) as students see it: blocks between `<!-- BEGIN INSTRUCTOR -->` and
/// `<!-- END INSTRUCTOR -->` removed, and the text of `<!-- STUDENT ... -->` comments shown.
fn student_text(text: &str) -> Result<String, String> {
    const BEGIN: &str = "<!-- BEGIN INSTRUCTOR -->\n";
    const END: &str = "<!-- END INSTRUCTOR -->\n";
    const STUDENT: &str = "<!-- STUDENT\n";
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find(BEGIN) {
        let end = rest[start..].find(END).ok_or("README.md: an instructor block is not closed")? + start;
        out.push_str(&rest[..start]);
        rest = &rest[end + END.len()..];
    }
    out.push_str(rest);
    let mut shown = String::new();
    let mut rest = out.as_str();
    while let Some(start) = rest.find(STUDENT) {
        let end = rest[start..].find("-->\n").ok_or("README.md: a student comment is not closed")? + start;
        shown.push_str(&rest[..start]);
        shown.push_str(&rest[start + STUDENT.len()..end]);
        rest = &rest[end + "-->\n".len()..];
    }
    shown.push_str(rest);
    Ok(shown)
}

/// Lines of solution regions (of at least 12 characters, not also found outside the regions)
/// that still occur anywhere in the starter's sources.
fn surviving_solution_lines(solution: &Path, starter: &Path) -> Result<Vec<String>, String> {
    let (mut inside, mut outside) = (BTreeSet::new(), BTreeSet::new());
    for text in rust_texts(solution)? {
        let regions: Vec<_> = find_regions(&text).unwrap_or_default().into_iter().map(|f| f.body).collect();
        let mut offset = 0;
        for line in text.split_inclusive('\n') {
            let set = if regions.iter().any(|r| r.contains(&offset)) { &mut inside } else { &mut outside };
            set.insert(line.trim().to_string());
            offset += line.len();
        }
    }
    let distinctive: BTreeSet<String> =
        inside.difference(&outside).filter(|l| l.len() >= 12).cloned().collect();
    let mut found = BTreeSet::new();
    for text in rust_texts(starter)? {
        found.extend(text.lines().map(str::trim).filter(|l| distinctive.contains(*l)).map(str::to_string));
    }
    Ok(found.into_iter().collect())
}

fn rust_texts(dir: &Path) -> Result<Vec<String>, String> {
    let files = rust_files(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(files.into_iter().map(|(_, text)| text).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path as the documents name one: in backquotes or a Markdown link, starting with a folder
    /// or file of the repository, without wildcards or placeholders.
    fn named_paths(text: &str) -> Vec<String> {
        let roots = [
            "src/",
            "tests/",
            "checkpoints/",
            "docs/",
            "grade/",
            "scenes/",
            "reference/",
            "tools/",
            ".cargo/",
        ];
        let files = ["ARCHITECTURE.md", "Cargo.toml", "rust-toolchain.toml", "README.md"];
        let quoted = text.split('`').skip(1).step_by(2);
        let linked = text.split("](").skip(1).filter_map(|t| t.split(')').next());
        quoted
            .chain(linked)
            .map(|t| t.trim_end_matches(['.', ',']))
            .filter(|t| t.chars().all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c)))
            .filter(|t| roots.iter().any(|r| t.starts_with(r)) || files.contains(t))
            .map(str::to_string)
            .collect()
    }

    /// The starter tells the truth: every path its documents name exists in it, and every
    /// command they give works there (its cargo aliases exist, no instructor command is named).
    #[test]
    fn every_path_and_command_the_starters_documents_name_exists_in_it() {
        let out = std::env::temp_dir().join(format!("raylab-starter-docs-{}", std::process::id()));
        starter(&out).unwrap();
        let aliases = std::fs::read_to_string(out.join(".cargo/config.toml")).unwrap();
        let mut problems = Vec::new();
        for document in documents(&out).unwrap() {
            let text = std::fs::read_to_string(out.join(&document)).unwrap();
            for path in named_paths(&text) {
                if !out.join(&path).exists() {
                    problems.push(format!("{document} names {path}, which the starter does not ship"));
                }
            }
            for command in [
                "cargo xtask",
                "cargo bench",
                "raybench",
                "grader calibrate",
                "make-variant",
                "update-references",
                "grader similarity",
            ] {
                if text.contains(command) {
                    problems
                        .push(format!("{document} gives `{command}`, which does not work in the starter"));
                }
            }
            if text.contains("cargo grader") && !aliases.contains("grader = ") {
                problems.push(format!(
                    "{document} gives `cargo grader`, but .cargo/config.toml has no such alias"
                ));
            }
        }
        std::fs::remove_dir_all(&out).unwrap();
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }

    /// `grader submission .` in a student's tree reads it against the starter's manifest: the
    /// pristine starter has every region a stub and nothing ignored; a student's edits are listed
    /// (a region taken, a rejected line at its own line number, a new file, a change outside the
    /// regions, a deleted file), and the instructor's tree has no manifest.
    #[test]
    fn a_students_tree_is_read_against_the_starters_manifest() {
        use raylab_grade::regions::allow::StudentApi;
        use raylab_grade::regions::baseline::{starter_manifest, Baseline};
        use raylab_grade::submission::splice::{read_submission, Taken};
        let out = std::env::temp_dir().join(format!("raylab-starter-manifest-{}", std::process::id()));
        starter(&out).unwrap();
        assert_eq!(starter_manifest(repository()).unwrap(), None);
        let manifest = starter_manifest(&out).unwrap().expect("the starter has a manifest");
        let api = StudentApi::of(&raylab_grade::rubric::Rubric::of_tree(&out).unwrap());
        let read = || read_submission(&Baseline::Starter(&manifest), &out, &api).unwrap();
        let pristine = read();
        assert!(pristine.ignored.is_empty(), "{:?}", pristine.ignored);
        assert!(pristine.regions.iter().all(|(_, t)| *t == Taken::NotStarted), "{:?}", pristine.regions);
        assert_eq!(pristine.regions.len(), manifest.regions.len());

        let edit = |file: &str, from: &str, to: &str| {
            let text = std::fs::read_to_string(out.join(file)).unwrap();
            assert!(text.contains(from), "{file}: {from}");
            std::fs::write(out.join(file), text.replacen(from, to, 1)).unwrap();
        };
        std::fs::copy(repository().join("src/geometry/triangle.rs"), out.join("src/geometry/triangle.rs"))
            .unwrap();
        let aabb = std::fs::read_to_string(out.join("src/geometry/aabb.rs")).unwrap();
        let stub_line = aabb.lines().position(|l| l.contains("todo!(\"checkpoint 3")).unwrap() + 1;
        edit(
            "src/geometry/aabb.rs",
            "        todo!(\"checkpoint 3",
            "        let _ = std::fs::read(\"x\");\n        todo!(\"checkpoint 3",
        );
        edit("src/camera.rs", "\n", "\n// a comment outside every region\n");
        std::fs::write(out.join("notes.txt"), "mine").unwrap();
        std::fs::remove_file(out.join("scenes/intersection_test.toml")).unwrap();
        let edited = read();
        std::fs::remove_dir_all(&out).unwrap();
        let taken = |function: &str| &edited.regions.iter().find(|(r, _)| r.function == function).unwrap().1;
        assert!(matches!(taken("intersect_triangle"), Taken::Code(_)));
        let Taken::Rejected { line, .. } = taken("intersect") else { panic!("{:?}", taken("intersect")) };
        assert_eq!(*line, stub_line, "the rejected line of src/geometry/aabb.rs");
        assert_eq!(
            edited.ignored,
            [
                "notes.txt: a new file: ignored",
                "scenes/intersection_test.toml: deleted: ignored (the instructor's is used)",
                "src/camera.rs: changed outside your regions: ignored",
            ]
        );
    }

    /// The names of the hidden checks: the hidden scenes, and every hidden test function.
    fn hidden_names() -> Vec<String> {
        let rubric = raylab_grade::rubric::Rubric::of_tree(repository()).unwrap();
        let mut names: Vec<String> =
            rubric.scenes.iter().filter(|s| s.hidden).map(|s| s.name.clone()).collect();
        for entry in std::fs::read_dir(repository().join("tests/hidden")).unwrap() {
            let text = std::fs::read_to_string(entry.unwrap().path()).unwrap();
            let tests = text.split("#[test]\nfn ").skip(1).filter_map(|t| t.split('(').next());
            names.extend(tests.map(str::to_string));
        }
        names
    }

    /// The starter has no hidden check: no hidden folder, and no file naming a hidden scene or test.
    #[test]
    fn the_starter_ships_no_hidden_scene_reference_rubric_or_test() {
        let names = hidden_names();
        assert!(names.len() >= 3 + 6, "the hidden checks were not found: {names:?}");
        let out = std::env::temp_dir().join(format!("raylab-starter-hidden-{}", std::process::id()));
        starter(&out).unwrap();
        let mut problems = Vec::new();
        for folder in ["hidden", "tests/hidden"] {
            if out.join(folder).exists() {
                problems.push(format!("the starter ships {folder}/"));
            }
        }
        for file in files_below(&out) {
            let text = std::fs::read(out.join(&file)).map(|b| String::from_utf8_lossy(&b).into_owned());
            for name in names.iter().filter(|n| text.as_ref().is_ok_and(|t| t.contains(n.as_str()))) {
                problems.push(format!("{} names the hidden check {name}", file.display()));
            }
        }
        std::fs::remove_dir_all(&out).unwrap();
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }

    /// Every file below `root`, relative to it.
    fn files_below(root: &Path) -> Vec<PathBuf> {
        let mut found = Vec::new();
        let mut folders = vec![PathBuf::new()];
        while let Some(folder) = folders.pop() {
            for entry in std::fs::read_dir(root.join(&folder)).unwrap() {
                let entry = entry.unwrap();
                let path = folder.join(entry.file_name());
                if entry.file_type().unwrap().is_dir() {
                    folders.push(path);
                } else {
                    found.push(path);
                }
            }
        }
        found
    }

    #[test]
    fn the_student_text_drops_instructor_blocks_and_shows_student_notes() {
        let text =
            "a\n<!-- BEGIN INSTRUCTOR -->\nsecret\n<!-- END INSTRUCTOR -->\n<!-- STUDENT\nhello\n-->\nb\n";
        assert_eq!(student_text(text).unwrap(), "a\nhello\nb\n");
        assert!(student_text("<!-- BEGIN INSTRUCTOR -->\nopen").is_err());
        let readme = std::fs::read_to_string(repository().join("README.md")).unwrap();
        let student = student_text(&readme).unwrap();
        assert!(!student.contains("reference solution") && !student.contains("cargo xtask"), "{student}");
        assert!(student.contains("Your tasks are the `todo!("));
    }
}
