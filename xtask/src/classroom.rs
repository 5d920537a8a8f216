//! The GitHub Classroom workflow the starter ships (`.github/workflows/classroom.yml`), written
//! from the rubric so its points never drift from it.
//!
//! On every push it runs each checkpoint's unit tests as one Classroom test worth the rubric's
//! test points (`classroom-resources/autograding-command-grader`, reported by
//! `autograding-grading-reporter`), then the student-side grader: its table goes to the run's
//! summary and its HTML report is kept as an artifact. This is feedback: the student's repository
//! decides what the workflow runs, so marks come from the instructor's `grader submission`
//! (docs/INSTRUCTORS.md).

use std::fmt::Write;

use raylab_grade::rubric::Rubric;

/// The workflow up to the checkpoints' steps: checkout, and the tests built once.
const HEADER: &str =
    "# Written by `cargo xtask starter` from checkpoints/rubric.toml: feedback on every push.
# The points here are the unit tests' share; your instructor grades the submission itself.
name: Autograding
\"on\":
  - push
  - workflow_dispatch
permissions:
  checks: write
  actions: read
  contents: read
jobs:
  autograding:
    runs-on: ubuntu-latest
    if: github.actor != 'github-classroom[bot]'
    steps:
      - uses: actions/checkout@v4
      - name: Build the tests once
        run: cargo test --no-run --quiet
";

/// The workflow file, for the public rubric.
pub fn workflow(rubric: &Rubric) -> String {
    let mut yaml = String::from(HEADER);
    let mut runners = Vec::new();
    for c in rubric.checkpoints.iter().filter(|c| c.test_points > 0.0) {
        let id = format!("checkpoint-{}", c.id);
        let _ = write!(
            yaml,
            "      - name: \"Checkpoint {n}: {title}\"
        id: {id}
        uses: classroom-resources/autograding-command-grader@v1
        with:
          test-name: \"Checkpoint {n}: {title}\"
          command: cargo test --quiet {filter}
          timeout: 10
          max-score: {points}
",
            n = c.id,
            title = c.title,
            filter = c.test_filter,
            points = c.test_points,
        );
        runners.push(id);
    }
    yaml += "      - name: Report the unit tests to Classroom\n";
    yaml += "        uses: classroom-resources/autograding-grading-reporter@v1\n        env:\n";
    for id in &runners {
        let _ =
            writeln!(yaml, "          {}_RESULTS: \"${{{{steps.{id}.outputs.result}}}}\"", id.to_uppercase());
    }
    let _ = write!(
        yaml,
        "        with:
          runners: {}
      - name: The grader (images and all), as feedback
        if: always()
        run: |
          echo '```' >> \"$GITHUB_STEP_SUMMARY\"
          cargo grader --all --html grader-report >> \"$GITHUB_STEP_SUMMARY\" || true
          echo '```' >> \"$GITHUB_STEP_SUMMARY\"
      - name: Keep the grader's report
        if: always()
        uses: actions/upload-artifact@v4
        with:
          name: grader-report
          path: grader-report/
",
        runners.join(",")
    );
    yaml
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repository;

    /// One Classroom test per checkpoint with tests, worth its test points, each reported, and
    /// the points add up to the rubric's test points.
    #[test]
    fn the_classroom_workflow_has_every_checkpoints_tests_at_the_rubrics_points() {
        let root = repository();
        let rubric = Rubric::load(&root.join(raylab_grade::rubric::RUBRIC), root).unwrap();
        let yaml = workflow(&rubric);
        let mut total = 0.0;
        for c in &rubric.checkpoints {
            assert!(yaml.contains(&format!("command: cargo test --quiet {}\n", c.test_filter)), "{}", c.id);
            assert!(yaml.contains(&format!("CHECKPOINT-{}_RESULTS", c.id)), "{}", c.id);
            total += c.test_points;
        }
        let scores: f64 = yaml
            .lines()
            .filter_map(|l| l.trim().strip_prefix("max-score: "))
            .map(|p| p.parse::<f64>().unwrap())
            .sum();
        assert_eq!(scores, total);
        assert!(!yaml.contains('\t'), "YAML has no tabs");
    }
}
