//! Splicing on whole trees: every region of the solution found in it, regions of several
//! checkpoints in one file, a rejected region built as the starter's stub.

use super::*;

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

#[test]
fn grader_finds_every_region_of_the_solution_in_the_solution() {
    let root = repository();
    let api = StudentApi::of(&crate::rubric::Rubric::of_tree(&root).unwrap());
    let submission = read_submission(&Baseline::Tree(&root), &root, &api).unwrap();
    assert!(submission.regions.len() >= 11, "{:?}", submission.regions);
    assert!(submission.regions.iter().all(|(_, t)| matches!(t, Taken::Code(_))), "{:?}", submission.notes());
    assert!(submission.not_started().is_empty() && submission.rejected().is_empty());
}

/// An instructor's tree `ours` and a submission `theirs` under `dir`, each with one file of two
/// regions (checkpoints 2 and 3).
fn two_trees(dir: &Path) -> (PathBuf, PathBuf) {
    let _ = std::fs::remove_dir_all(dir);
    let (ours, theirs) = (dir.join("ours"), dir.join("theirs"));
    // Markers are assembled so that the starter generator does not stub this fixture itself.
    let file = |a: &str, b: &str| {
        format!(
            "fn a() -> u32 {{\n    // BEGIN{} SOLUTION checkpoint2\n    {a}\n    // END SOLUTION\n}}\n\
             fn b() -> u32 {{\n    // BEGIN{} SOLUTION checkpoint3\n    {b}\n    // END SOLUTION\n}}\n",
            "", ""
        )
    };
    for (tree, text) in [(&ours, file("1 + 1", "2 + 2")), (&theirs, file("10 * 10", "20 * 20"))] {
        std::fs::create_dir_all(tree.join("src")).unwrap();
        std::fs::write(tree.join("src/a.rs"), text).unwrap();
        std::fs::write(tree.join("src/lib.rs"), "mod a;\n").unwrap();
    }
    (ours, theirs)
}

/// A file with regions of two checkpoints: each gets its own two bodies, in place.
#[test]
fn grader_splices_regions_of_several_checkpoints_in_one_file() {
    let dir = std::env::temp_dir().join(format!("raylab-splice-{}", std::process::id()));
    let (ours, theirs) = two_trees(&dir);
    let dest = dir.join("dest");
    // References, public and hidden, stay out of the scratch tree; hidden scenes go in.
    for dir in ["reference", "hidden/reference", "hidden/scenes"] {
        std::fs::create_dir_all(ours.join(dir)).unwrap();
        std::fs::write(ours.join(dir).join("x.png"), "image").unwrap();
    }
    let submission = read_submission(&Baseline::Tree(&ours), &theirs, &StudentApi::default()).unwrap();
    write_spliced_tree(&ours, &submission, &dest).unwrap();
    let spliced = std::fs::read_to_string(dest.join("src/a.rs")).unwrap();
    let copied =
        ["reference", "hidden/reference", "hidden/scenes"].map(|d| dest.join(d).join("x.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(copied, [false, false, true]);
    for (n, student, solution) in [(2, "10 * 10", "1 + 1"), (3, "20 * 20", "2 + 2")] {
        let want =
            format!("if crate::graded::student({n}) {{\n    {student}\n}} else {{\n    {solution}\n}}\n");
        assert!(spliced.contains(&want), "{spliced}");
    }
}

/// A rejected region's code never reaches the build: the tree is, byte for byte, the one
/// where that region is still the starter's stub, so it scores what the stub scores.
#[test]
fn grader_builds_a_rejected_region_as_the_starters_stub() {
    let dir = std::env::temp_dir().join(format!("raylab-splice-rejected-{}", std::process::id()));
    let (ours, theirs) = two_trees(&dir);
    let spliced = |taken: Taken| {
        let mut submission =
            read_submission(&Baseline::Tree(&ours), &theirs, &StudentApi::default()).unwrap();
        submission.regions.iter_mut().find(|(r, _)| r.checkpoint == 2).unwrap().1 = taken;
        let dest = dir.join("dest");
        write_spliced_tree(&ours, &submission, &dest).unwrap();
        std::fs::read_to_string(dest.join("src/a.rs")).unwrap()
    };
    let rejected = spliced(Taken::Rejected { line: 3, reason: Refusal::Unsafe });
    let stub = spliced(Taken::NotStarted);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(rejected, stub);
    assert!(!rejected.contains("10 * 10") && rejected.contains("20 * 20"), "{rejected}");
    assert!(rejected.contains("todo!("), "{rejected}");
}
