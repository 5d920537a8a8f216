//! `cargo xtask similarity-export --out DIR`: the similarity engine's measured classes as files,
//! for its peers (Dolos, copydetect) to be run on the same pairs (`tools/similarity-peers/`).
//!
//! For each of the first `--classes` synthetic classes of the test set's second half (the classes
//! docs/GRADING.md's table is measured on), one file per student in two forms: `regions/`, the
//! student's region bodies only, each wrapped in a function of its own (the text raylab compares);
//! `whole/`, every file with a region, the student's bodies in place (what a tool without
//! raylab's regions is given). Beside them `labels.csv`: each pair's regions shared, whether
//! one copied the other, and raylab's score. `template-regions/starter.rs` and
//! `template-whole/starter.rs` are the same two forms of the starter's stubs, the peers'
//! boilerplate (each alone in its folder: copydetect takes boilerplate by folder).

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use raylab_grade::instructor::similarity::compare;
use raylab_grade::instructor::similarity::measure::Synthetic;
use raylab_grade::instructor::similarity::read::tree_regions;
use raylab_grade::instructor::similarity::test_set::{halves, independent};
use raylab_grade::regions::markers::find_regions;

use crate::repository;

/// The seed the second half's classes are measured with (`grade/tests/similarity.rs`).
const REPORTED_SEED: u64 = 2;

/// Writes `classes` classes into `out`.
pub fn similarity_export(out: &Path, classes: usize) -> Result<(), String> {
    let root = repository();
    let tree = tree_regions(root).map_err(|e| e.to_string())?;
    let authors = independent(root).map_err(|e| e.to_string())?;
    let (null, unseen) = halves(&authors);
    write(&out.join("template-regions/starter.rs"), &regions_form(&tree.stubs, &tree.stubs))?;
    write(&out.join("template-whole/starter.rs"), &whole_form(root, &tree.stubs)?)?;
    for class in 0..classes {
        let dir = out.join(format!("class-{class:02}"));
        let synthetic = Synthetic::draw(unseen, &tree.stubs, class, REPORTED_SEED);
        let mut labels = String::from("a,b,shared,copied,raylab\n");
        for pair in compare(&synthetic.students, &[], null, &tree.stubs).pairs {
            let label = synthetic.label(pair.a, pair.b, pair.score);
            let _ = writeln!(
                labels,
                "{},{},{},{},{}",
                label.a,
                label.b,
                label.shared,
                label.copy.is_some(),
                label.score
            );
        }
        write(&dir.join("labels.csv"), &labels)?;
        for (i, student) in synthetic.students.iter().enumerate() {
            write(
                &dir.join(format!("regions/student-{i:02}.rs")),
                &regions_form(&student.regions, &tree.stubs),
            )?;
            write(&dir.join(format!("whole/student-{i:02}.rs")), &whole_form(root, &student.regions)?)?;
        }
    }
    println!(
        "{}: {classes} classes of {} students",
        out.display(),
        raylab_grade::instructor::similarity::measure::CLASS_SIZE
    );
    Ok(())
}

/// Each region of `stubs`' list, `regions`' body (the stub's if it has none), in a function.
fn regions_form(regions: &BTreeMap<String, String>, stubs: &BTreeMap<String, String>) -> String {
    let mut out = String::new();
    for (k, (id, stub)) in stubs.iter().enumerate() {
        let _ = write!(out, "// {id}\nfn region_{k}() {{\n{}}}\n\n", regions.get(id).unwrap_or(stub));
    }
    out
}

/// Every file of the tree with a region, `regions`' bodies in place, one after the other.
fn whole_form(root: &Path, regions: &BTreeMap<String, String>) -> Result<String, String> {
    let mut files: BTreeMap<&str, Vec<(&str, &String)>> = BTreeMap::new();
    for (id, body) in regions {
        let (file, function) = id.rsplit_once("::").ok_or(format!("no file in {id}"))?;
        files.entry(file).or_default().push((function, body));
    }
    let mut out = String::new();
    for (file, bodies) in files {
        let mut text = std::fs::read_to_string(root.join(file)).map_err(|e| format!("{file}: {e}"))?;
        // From the last region back, so earlier ranges stay valid.
        let mut found = find_regions(&text).map_err(|e| format!("{file}: {e}"))?;
        found.sort_by_key(|f| std::cmp::Reverse(f.body.start));
        for f in found {
            if let Some((_, body)) = bodies.iter().find(|(function, _)| *function == f.function) {
                text.replace_range(f.body.clone(), body);
            }
        }
        let _ = write!(out, "// {file}\n{text}\n");
    }
    Ok(out)
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    let parent = path.parent().expect("a file in a folder");
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}
