//! A check's bounds, the hidden part's rules broken one at a time, and tests named first that
//! exist.

use super::*;

/// A check's threshold is a bound or the other, never both or neither: the rubric that
/// writes either is refused as it is read, with the check named.
#[test]
fn a_check_has_exactly_one_of_min_and_max() {
    let check =
        |bounds: &str| toml::from_str::<Check>(&format!("metric = \"ssim\"\n{bounds}\nwhy = \"x\"\n"));
    assert_eq!(check("min = 0.5").unwrap().threshold, Threshold::AtLeast(0.5));
    assert_eq!(check("max = 0.5").unwrap().threshold, Threshold::AtMost(0.5));
    for bounds in ["min = 0.5\nmax = 0.6", ""] {
        let error = check(bounds).unwrap_err().to_string();
        assert!(error.contains("a Ssim check needs exactly one of min or max"), "{error}");
    }
    assert!(check("min = 0.5\nmean = 1").is_err(), "unknown fields are still refused");
}

/// Each rule of the hidden rubric broken alone gives its own error.
#[test]
fn each_hidden_rule_broken_alone_gives_its_own_error() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let merged = |checkpoints: &str| {
        let hidden: HiddenRubric = toml::from_str(checkpoints).unwrap();
        Rubric::load(&root.join(RUBRIC), &root).unwrap().merge_hidden(hidden, &root)
    };
    let entry = |id: u32, points: f64, filter: &str| {
        format!("[[checkpoint]]\nid = {id}\ntest_points = {points}\ntest_filter = \"{filter}\"\n")
    };
    assert_eq!(merged(&entry(2, 1.0, "hidden2")), Ok(()));
    assert_eq!(merged(&entry(99, 1.0, "hidden99")), Err(RuleBroken::HiddenUnknownCheckpoint(99)));
    assert_eq!(merged(&entry(2, -1.0, "hidden2")), Err(RuleBroken::HiddenTestPoints(2)));
    assert_eq!(merged(&entry(2, 1.0, "")), Err(RuleBroken::HiddenTestPoints(2)));
    assert_eq!(
        merged(&entry(2, 1.0, "checkpoint2")),
        Err(RuleBroken::HiddenFilterTooWide { checkpoint: 2, filter: "checkpoint2".to_string() })
    );
    assert_eq!(merged(&entry(2, 1.0, "hidden2").repeat(2)), Err(RuleBroken::HiddenTwice(2)));
}

/// Every test a checkpoint runs first is a test of that checkpoint: a misspelt name would
/// silently run in libtest's order instead.
#[test]
fn grader_runs_first_only_tests_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let rubric = Rubric::load(&root.join(RUBRIC), &root).unwrap();
    let mut sources = crate::regions::stub::rust_files(&root.join("src")).unwrap();
    sources.extend(crate::regions::stub::rust_files(&root.join("tests/checkpoints")).unwrap());
    for checkpoint in &rubric.checkpoints {
        for name in &checkpoint.tests_first {
            let defined = sources.iter().any(|(_, text)| {
                text.contains(&format!("mod {}", checkpoint.test_filter))
                    && text.contains(&format!("fn {name}()"))
            });
            assert!(
                defined,
                "checkpoint {}: no test `{name}` in a `{}` module",
                checkpoint.id, checkpoint.test_filter
            );
        }
    }
    assert!(rubric.checkpoints.iter().any(|c| !c.tests_first.is_empty()));
}
