//! The similarity engine measured on the independent implementations (`tests/similarity/`):
//! every disguise undone on every region, and the threshold set on one half of the authors,
//! the table reported on classes drawn from the other.
#![cfg(feature = "instructor")]

use std::fmt::Write;
use std::path::Path;

use raylab_grade::instructor::similarity::disguise::{disguise, Disguise};
use raylab_grade::instructor::similarity::measure::{
    average_precision, measure, rows, threshold, Copied, Labelled,
};
use raylab_grade::instructor::similarity::normalise::normalise;
use raylab_grade::instructor::similarity::read::tree_regions;
use raylab_grade::instructor::similarity::test_set::{halves, independent};
use raylab_grade::instructor::similarity::{compare, FLAG_SCORE};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap()
}

/// Synthetic classes per half: 20 classes of 60 are 35,400 pairs a half.
const CLASSES: usize = 20;

#[test]
fn similarity_normalising_undoes_every_disguise_of_every_independent_region() {
    let text = |body: &str| normalise(body).into_iter().map(|t| t.text).collect::<Vec<_>>();
    let mut failures = Vec::new();
    // How many regions each disguise (alone) changed: a disguise that changes nothing tests nothing.
    let mut changed = [0; Disguise::ALL.len()];
    let authors = independent(root()).unwrap();
    assert!(authors.len() >= 12, "the test set has {} authors", authors.len());
    for author in authors {
        assert_eq!(author.regions.len(), 11, "{}: every region of checkpoints 2 to 7", author.name);
        for (region, body) in &author.regions {
            let original = text(body);
            assert!(
                syn::parse_str::<syn::Block>(&format!("{{\n{body}\n}}")).is_ok(),
                "{} {region}",
                author.name
            );
            let alone = Disguise::ALL.map(|d| vec![d]);
            for disguises in alone.iter().map(Vec::as_slice).chain(Disguise::COMBINATIONS) {
                let disguised = disguise(body, disguises, 11);
                if let ([one], true) = (disguises, &disguised != body) {
                    changed[Disguise::ALL.iter().position(|d| d == one).unwrap()] += 1;
                }
                if text(&disguised) != original {
                    failures.push(format!("{} {region} {disguises:?}", author.name));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{} not undone:\n{}", failures.len(), failures.join("\n"));
    eprintln!("regions each disguise changed: {changed:?} ({:?})", Disguise::ALL.map(Disguise::name));
    assert!(changed.iter().all(|&n| n > 0), "{changed:?}");
}

#[test]
fn similarity_threshold_set_on_one_half_and_reported_on_the_other() {
    let tree = tree_regions(root()).unwrap();
    let authors = independent(root()).unwrap();
    let (train, report) = halves(&authors);
    // The threshold: set on classes of the first half, scored against the first half's null.
    let set_on = threshold(&measure(train, train, &tree.stubs, CLASSES, 1));
    assert!(
        (FLAG_SCORE - (set_on * 100.0).ceil() / 100.0).abs() < 1e-9,
        "FLAG_SCORE is {FLAG_SCORE}, the first half sets {set_on:.4}: measure again and update it and docs/GRADING.md"
    );
    // Reported: classes of the second half, the same null (authors the engine never saw).
    let pairs: Vec<Labelled> = measure(report, train, &tree.stubs, CLASSES, 2);
    let mut table = table(&pairs);
    // Whole authors: each of the second half against the others and the solution, every region
    // by one hand (a mosaic student's regions are by different authors, so a mosaic pair never
    // has two authors alike in style across all their regions: whole pairs do).
    let whole = compare(report, std::slice::from_ref(&tree.solution), train, &tree.stubs);
    let flagged = |b: &dyn Fn(usize) -> bool| {
        let pairs: Vec<_> = whole.pairs.iter().filter(|p| b(p.b)).collect();
        (pairs.iter().filter(|p| p.score > FLAG_SCORE).count(), pairs.len())
    };
    let ((authors_flagged, author_pairs), (solution_flagged, solution_pairs)) =
        (flagged(&|b| b < report.len()), flagged(&|b| b == report.len()));
    let _ = writeln!(
        table,
        "Whole authors of the second half: {authors_flagged} of {author_pairs} pairs flagged; \
         with the solution: {solution_flagged} of {solution_pairs}."
    );
    let _ = std::fs::create_dir_all(root().join("target"));
    let _ = std::fs::write(root().join("target/SIMILARITY.md"), &table);
    eprintln!("{table}");
    // A whole copy is flagged, whatever the disguise.
    let whole: Vec<&Labelled> =
        pairs.iter().filter(|p| p.copy.is_some_and(|(n, _)| n == Copied::All)).collect();
    assert!(!whole.is_empty() && whole.iter().all(|p| p.score > FLAG_SCORE), "{whole:?}");
    // The table docs/GRADING.md shows is this one.
    let docs = std::fs::read_to_string(root().join("docs/GRADING.md")).unwrap();
    assert!(
        docs.contains(&table),
        "docs/GRADING.md does not hold the measured table (target/SIMILARITY.md):\n{table}"
    );
}

/// The markdown table of `pairs` at [`FLAG_SCORE`].
fn table(pairs: &[Labelled]) -> String {
    let mut out = String::from("| pairs | count | flagged | share |\n|---|---:|---:|---:|\n");
    for row in rows(pairs, FLAG_SCORE) {
        let share = if row.pairs == 0 { 0.0 } else { row.flagged as f64 / row.pairs as f64 };
        let _ = writeln!(out, "| {} | {} | {} | {:.4} |", row.label, row.pairs, row.flagged, share);
    }
    let _ = writeln!(
        out,
        "\nAverage precision (sharing 2 or more regions a positive): {:.3}\n",
        average_precision(pairs)
    );
    out
}
