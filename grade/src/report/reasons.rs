//! The words of a verdict ([`crate::verdict`]): why a checkpoint lost points, why a failed scene
//! costs one nothing, what to read. Text, HTML and Gradescope's JSON all say it in these words.

use crate::fingerprint::{tiles, Closeness, Naming};
use crate::noisy::{Channel, TileFailure, TileProblem};
use crate::outcome::CheckpointResult;
use crate::rubric::Checkpoint;
use crate::verdict::{Advice, FailedCheck, Kept, Loss, Part, Reason, Why};

/// A reason names this many failing tests; `cargo test checkpointN` shows them all.
const SHOWN_FAILURES: usize = 3;

/// Why the checkpoint of `result` lost points, one line each.
pub fn reason_lines(result: &CheckpointResult) -> Vec<String> {
    result.reasons.iter().map(reason_text).collect()
}

/// What the student of `result`'s checkpoint should read or do, if it is to blame.
pub fn advice_line(result: &CheckpointResult) -> Option<String> {
    result.advice.as_ref().map(|advice| advice_text(advice, &result.checkpoint))
}

/// One line for a failed tile: its channel, the test it failed, the values.
pub fn tile_problem_text(failure: &TileFailure) -> String {
    let channel = match failure.channel {
        Channel::Red => "red",
        Channel::Green => "green",
        Channel::Blue => "blue",
    };
    match failure.problem {
        TileProblem::NotFinite { mean } => format!("{channel} radiance is not finite ({mean})"),
        TileProblem::NoVariation { spread_ratio } => {
            format!("{channel} does not vary with the seed (spread {spread_ratio:.4}x the solution's)")
        }
        TileProblem::Mean { got, want, p } => {
            format!("{channel} mean {got:.4} vs {want:.4} expected (p = {p:.1e})")
        }
        TileProblem::Noise { spread_ratio, p } => {
            format!("{channel} noise {spread_ratio:.2}x the solution's (rank test, p = {p:.1e})")
        }
    }
}

/// One line of a report for `reason`.
pub fn reason_text(reason: &Reason) -> String {
    match reason {
        Reason::NotStarted => "not started: its code is still the starter's todo!()".to_string(),
        Reason::RegionRejected { own_tree: false } => {
            "a region was rejected (see below): graded with the starter's stub in its place".to_string()
        }
        Reason::RegionRejected { own_tree: true } => "a region was rejected (see below): graded here as written, but the instructor's grader runs the starter's stub in its place".to_string(),
        Reason::TestsWait { part, waiting, of, checkpoints } => format!(
            "{}unit tests: {waiting} of {of} wait for {}, not written yet (left out: they run its code)",
            label(*part),
            checkpoints_text(checkpoints)
        ),
        Reason::TestsDidNotRun { part, error } => format!("{}unit tests: {error}", label(*part)),
        Reason::TestsFailed { part, failed, of, names } => {
            let more = failed.saturating_sub(SHOWN_FAILURES);
            let more = if more > 0 { format!(" and {more} more") } else { String::new() };
            let shown = names[..names.len().min(SHOWN_FAILURES)].join(", ");
            format!("{}unit tests: {failed} of {of} failed: {shown}{more}", label(*part))
        }
        Reason::NoTests { part, filter } => {
            format!("{}unit tests: `cargo test {filter}` ran no test", label(*part))
        }
        Reason::SceneLost { part, scene, loss } => format!("{}scene {scene}: {}", label(*part), loss_text(loss)),
        Reason::LooksLike { scene, naming } => named_text(scene, naming),
    }
}

/// `""` or `"hidden "`: how a reason about the hidden checks begins.
fn label(part: Part) -> &'static str {
    match part {
        Part::Public => "",
        Part::Hidden => "hidden ",
    }
}

/// Who is to blame for a lost scene, and why it failed.
fn loss_text(loss: &Loss) -> String {
    match loss {
        Loss::Yours(why) => why_text(why),
        Loss::OthersFailWithYours { why, other, own } => format!(
            "{} (checkpoint {other}'s tests fail with your checkpoint {own}: only checkpoint {own} is your code in this grade)",
            why_text(why)
        ),
        Loss::UntilWritten(k) => format!("lost until checkpoint {k} is written: the scene runs its code"),
        Loss::EarlierWrong { earlier: k, why } => format!(
            "lost because checkpoint {k} is wrong (its unit tests fail); fix checkpoint {k} first ({})",
            why_text(why)
        ),
        Loss::NotWritten(id) => format!("checkpoint {id} is not written yet"),
        Loss::YourTestsFail { own, why } => format!("your checkpoint {own} tests fail; {}", why_text(why)),
    }
}

/// Why a failed scene costs a checkpoint nothing, for its row.
pub fn kept_text(kept: &Kept) -> String {
    match kept {
        Kept::Waiting { own, waiting } => format!(
            "not counted against checkpoint {own}: waiting for {}, not written yet (the scene runs {})",
            checkpoints_text(waiting),
            if waiting.len() > 1 { "their code" } else { "its code" }
        ),
        Kept::LaterWrong { own, later, why } => format!(
            "not counted against checkpoint {own}: checkpoint {later}'s tests fail, fix it first ({})",
            why_text(why)
        ),
    }
}

/// Why a scene failed: its error, or "ssim: got 0.9120, needs >= 0.9900, ..." for the checks
/// that failed.
fn why_text(why: &Why) -> String {
    match why {
        Why::Error(error) => error.to_string(),
        Why::Differs => "the image differs from the reference".to_string(),
        Why::Checks(checks) => checks.iter().map(failed_check_text).collect::<Vec<_>>().join(", "),
    }
}

fn failed_check_text(check: &FailedCheck) -> String {
    match check {
        FailedCheck::Metric { check, value } => {
            format!("{}: got {value:.4}, needs {}", check.label(), check.threshold_text())
        }
        FailedCheck::Tiles { failed, of, first: [x, y, right, bottom], first_failure } => format!(
            "tile test: {failed} of {of} tiles differ from the reference beyond their noise; the first, at pixels ({x}, {y}) to ({right}, {bottom}): {}",
            tile_problem_text(first_failure)
        ),
    }
}

/// What to read or do.
pub fn advice_text(advice: &Advice, checkpoint: &Checkpoint) -> String {
    match advice {
        Advice::NotStarted { handout } => format!("Not started yet: read {} first.", handout.display()),
        Advice::Hint => hint_text(checkpoint),
    }
}

/// The checkpoint's hint and where to read more: its handout's list of mistakes and symptoms.
pub fn hint_text(checkpoint: &Checkpoint) -> String {
    format!(
        "{} Read {}, section \"Symptoms of common mistakes\".",
        checkpoint.hint,
        checkpoint.handout.display()
    )
}

/// What a failed scene looks like, with the evidence and where to read about it: `scene room
/// looks like a known mistake of checkpoint 2: det < 0 treated as a miss (0.9993 to that
/// mistake's render, 0.1041 to the reference); read checkpoints/02-triangle.md, ...`.
pub fn named_text(scene: &str, named: &Naming) -> String {
    let e = &named.entry;
    let evidence = match named.closeness {
        Closeness::Ssim { to_mistake, to_reference } => {
            format!("{to_mistake:.4} to that mistake's render, {to_reference:.4} to the reference")
        }
        // At the floor (up to the rounding of exp(ln)), the renders are that mistake's own: the
        // same code and seeds.
        Closeness::Tiles { to_mistake, to_reference } if to_mistake <= tiles::MIN_DISTANCE * (1.0 + 1e-9) => format!(
            "the same tile means as that mistake's renders; RMS z over tiles {to_reference:.2} against the reference"
        ),
        Closeness::Tiles { to_mistake, to_reference } => format!(
            "RMS z over tiles: {to_mistake:.2} against that mistake's renders, {to_reference:.2} against the reference; two runs of the same code give about 1"
        ),
    };
    format!(
        "scene {scene} looks like a known mistake of checkpoint {}: {} ({evidence}); read {}, section \"Symptoms of common mistakes\"",
        e.checkpoint, e.description, e.handout
    )
}

/// "checkpoint 3", "checkpoints 3 and 4", "checkpoints 3, 4 and 5".
pub fn checkpoints_text(ids: &[u32]) -> String {
    let names: Vec<String> = ids.iter().map(u32::to_string).collect();
    match names.as_slice() {
        [one] => format!("checkpoint {one}"),
        [first @ .., last] => format!("checkpoints {} and {last}", first.join(", ")),
        [] => "no checkpoint".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A name by tile means gives both distances, or says the renders are the mistake's own.
    #[test]
    fn a_mistake_named_by_tile_means_says_how_far_in_rms_z() {
        let entry = crate::fingerprint::Entry {
            scene: "cornell_path".into(),
            mistake: "roulette".into(),
            checkpoint: 9,
            description: "survivors not divided by q".into(),
            handout: "checkpoints/09-path-tracing.md".into(),
            inputs_hash: String::new(),
            kind: crate::fingerprint::Kind::Tiles,
        };
        let named = |to_mistake| Naming {
            entry: entry.clone(),
            closeness: Closeness::Tiles { to_mistake, to_reference: 29.137 },
            picture: image::RgbImage::new(1, 1),
        };
        let near = named_text("cornell_path", &named(1.04));
        assert!(near.contains("(RMS z over tiles: 1.04 against that mistake's renders, 29.14 against the reference; two runs of the same code give about 1)"), "{near}");
        let same = named_text("cornell_path", &named((-(-tiles::MIN_DISTANCE.ln())).exp()));
        assert!(
            same.contains("(the same tile means as that mistake's renders; RMS z over tiles 29.14 against the reference)"),
            "{same}"
        );
    }

    /// Each test a tile fails is worded with its channel and its own values.
    #[test]
    fn a_failed_tile_says_its_channel_test_and_values() {
        let text = |problem| tile_problem_text(&TileFailure { tile: 3, channel: Channel::Green, problem });
        let cases = [
            (TileProblem::NotFinite { mean: f64::NAN }, "green radiance is not finite (NaN)"),
            (
                TileProblem::NoVariation { spread_ratio: 0.0 },
                "green does not vary with the seed (spread 0.0000x the solution's)",
            ),
            (
                TileProblem::Mean { got: 0.25, want: 0.5, p: 1e-9 },
                "green mean 0.2500 vs 0.5000 expected (p = 1.0e-9)",
            ),
            (
                TileProblem::Noise { spread_ratio: 2.0, p: 3e-7 },
                "green noise 2.00x the solution's (rank test, p = 3.0e-7)",
            ),
        ];
        for (problem, words) in cases {
            assert_eq!(text(problem), words);
        }
    }
}
