//! The stub matrix: each checkpoint N stubbed alone, in a scratch tree, fails all of its own
//! tests, hidden ones included, and passes every test of the checkpoints before it.

use std::collections::BTreeSet;
use std::time::Duration;

use raylab_grade::instructor::variants::{make_scratch_tree, Variant};
use raylab_grade::regions::markers::checkpoints_in;
use raylab_grade::regions::stub::rust_files;
use raylab_grade::rubric::Rubric;
use raylab_grade::run::unit_tests::build_tests;

use crate::repository;

/// Builds each single-checkpoint stub in a scratch tree (one shared target folder) and runs the
/// test filters of that checkpoint and the ones before it.
pub fn stub_matrix() -> Result<(), String> {
    let work = repository().join("target/stub-matrix");
    // One target folder for every stub: cargo then reuses the dependencies built for earlier ones.
    let (tree, target) = (work.join("tree"), work.join("target"));
    let rubric = Rubric::of_tree(repository()).map_err(|e| e.to_string())?;
    // Each checkpoint's test filters: its public tests', and its hidden tests' if it has some.
    let filters = |m: u32| {
        let checkpoint = rubric.checkpoints.iter().find(|c| c.id == m);
        let hidden = checkpoint.and_then(|c| c.hidden.as_ref()).and_then(|h| h.test_filter.clone());
        checkpoint.map(|c| c.test_filter.clone()).into_iter().chain(hidden).collect::<Vec<_>>()
    };
    let mut problems = Vec::new();
    // Every checkpoint with regions in the renderer, as their markers say.
    let sources = rust_files(&repository().join("src")).map_err(|e| format!("src: {e}"))?;
    let with_regions: BTreeSet<u32> = sources.iter().flat_map(|(_, text)| checkpoints_in(text)).collect();
    for n in rubric.checkpoints.iter().map(|c| c.id).filter(|n| with_regions.contains(n)) {
        let variant = Variant {
            name: format!("stub_{n}"),
            checkpoint: n,
            correct: false,
            description: format!("checkpoint {n} stubbed alone"),
            fails: Vec::new(),
            seeds: Vec::new(),
            stub: true,
            second_of: None,
            patches: Vec::new(),
        };
        make_scratch_tree(repository(), &tree, &variant).map_err(|e| e.to_string())?;
        let binaries = build_tests(&tree, Some(&target), Duration::from_secs(900))
            .map_err(|e| format!("stub {n}: the tests do not build: {e}"))?;
        let mut row = format!("checkpoint {n} stubbed:");
        for (m, filter) in (1..=n).flat_map(|m| filters(m).into_iter().map(move |f| (m, f))) {
            let run = binaries.run_filter(&tree, &filter, &[], &[], Duration::from_secs(300));
            row += &format!("  {filter}: {}/{}", run.passed, run.passed + run.failed);
            let ok = if m < n {
                run.error.is_none() && run.failed == 0 && run.passed > 0
            } else {
                run.passed == 0 && run.failed > 0
            };
            if !ok {
                problems.push(format!(
                    "with checkpoint {n} stubbed, `{filter}`: {} passed, {} failed{}",
                    run.passed,
                    run.failed,
                    run.error.map(|e| format!(" ({e})")).unwrap_or_default()
                ));
            }
        }
        println!("{row}");
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems.join("\n"))
    }
}
