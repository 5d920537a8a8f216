//! Points: a checkpoint's test points by the fraction of its unit tests that pass, its image
//! points by who is to blame for each failed scene, and what each scene's row says about it.
//!
//! **Who loses a failed scene's points.** A scene carries the image points of every checkpoint it
//! `grades`, and runs the code of every checkpoint it `depends_on` (`cornell_refract` grades 6 but
//! runs 2 to 6). When the scene fails, the *culprit* is the lowest checkpoint it depends on that
//! is not written yet or whose own unit tests do not all pass. A graded checkpoint before the
//! culprit keeps the scene's points (its tests pass and the failure is explained elsewhere): the
//! scene is *not counted* against it, and its row never says FAIL for it. The culprit loses them
//! with its hint; one after it loses them with "fix checkpoint K first" and no hint of its own.
//! If no checkpoint is to blame that way, every graded one loses the points, with its hint.
//!
//! **Stand-ins.** A scene whose picture a checkpoint's stand-in draws exactly (`stand_ins` in the
//! rubric) is rendered with it while that checkpoint is not written, and no longer runs its code:
//! it is graded for the others, and never gives the stood-in checkpoint points.
//!
//! **Waiting for another checkpoint.** In a student's own tree, a test of checkpoint N that stops
//! in the `todo!()` of checkpoint K, a checkpoint whose regions are all still the starter's stubs,
//! says nothing about N: it is listed as waiting for K and left out of N's fraction (a test's
//! panic message is trusted this far only because K's source is known to be the stub).
//!
//! **Isolated blame.** When checkpoint N alone runs a submission's code and every other region
//! is the solution's ([`Blame::Isolated`], `grader submission`'s grade), only N's code can have
//! made a scene fail: it costs N, whatever the other checkpoints' tests say, and the reason says
//! when their tests fail too ("checkpoint 5's tests fail with your checkpoint 2"). Nothing waits:
//! the other checkpoints are the solution's.

use std::collections::BTreeMap;

use crate::noisy::tile_origin;
use crate::outcome::{Blame, CheckpointResult, SceneResult, SceneStatus};
use crate::rubric::{Checkpoint, GradedScene, Metric};
use crate::run::unit_tests::TestRun;
use crate::scene_failure::SceneFailure;
use crate::verdict::{Advice, FailedCheck, Kept, Loss, Part, Reason, Why};

/// Each tested checkpoint's unit-test runs, by id: its public tests, and its hidden ones if it
/// has any.
#[derive(Clone, Debug, Default)]
pub struct TestRuns {
    /// The public tests' runs.
    pub public: BTreeMap<u32, TestRun>,
    /// The hidden tests' runs.
    pub hidden: BTreeMap<u32, TestRun>,
}

/// What the grader knows of a tree besides its test runs: which checkpoints are still the
/// starter's stubs (only those graded, in an isolated grade) and who can be blamed.
#[derive(Clone, Copy, Debug)]
pub struct Context<'a> {
    /// The unit tests, if they ran.
    pub tests: Option<&'a TestRuns>,
    /// The checkpoints whose regions are all still the starter's `todo!()`.
    pub stubbed: &'a [u32],
    /// Who can have made a failed scene fail.
    pub blame: Blame,
}

impl Context<'_> {
    fn not_started(&self, id: u32) -> bool {
        self.stubbed.contains(&id)
    }

    /// The lowest checkpoint the scene runs that is not started or whose own (public) tests do
    /// not all pass, if there is one (module docs). None without tests (`--skip-tests`): nothing
    /// then shows the graded checkpoints right, so a failed scene costs each of them.
    fn culprit(&self, scene: &GradedScene) -> Option<u32> {
        let tests = self.tests?;
        let failing = |id: &u32| {
            self.not_started(*id) || tests.public.get(id).is_none_or(|t| self.fraction(t, *id) < 1.0)
        };
        scene.depends_on.iter().copied().filter(failing).min()
    }

    /// The checkpoint not written yet whose stub stopped the scene's render, if that is why it
    /// failed (never in an isolated grade, where the others are the solution's).
    pub fn stopped_at(&self, s: &SceneResult) -> Option<u32> {
        let k = s.error.as_ref()?.stub_panic()?;
        (self.blame == Blame::Culprit && self.not_started(k)).then_some(k)
    }

    /// The fraction of `run`'s tests (checkpoint `id`'s) that pass, those waiting for another
    /// checkpoint left out; when all of them wait, nothing is lost yet: 1. A run that went wrong
    /// or ran nothing scores 0.
    fn fraction(&self, run: &TestRun, id: u32) -> f64 {
        let waiting = self.waiting(run, id).len() as u32;
        match (&run.error, run.passed + run.failed - waiting) {
            (None, 0) if waiting > 0 => 1.0,
            (None, counted) if counted > 0 => run.passed as f64 / counted as f64,
            _ => 0.0,
        }
    }

    /// The failed tests of `run` that wait for another checkpoint not written yet (module docs).
    fn waiting<'r>(&self, run: &'r TestRun, id: u32) -> Vec<&'r (String, u32)> {
        let waits = |&&(_, k): &&(String, u32)| k != id && self.not_started(k);
        match self.blame {
            Blame::Culprit if !self.not_started(id) => run.stub_panics.iter().filter(waits).collect(),
            _ => Vec::new(),
        }
    }
}

/// What a failed scene means for one checkpoint it grades.
enum Judged {
    /// The checkpoint keeps the scene's points; why the scene failed all the same.
    Kept(Kept),
    /// The checkpoint loses them: why, and whether its own code is to blame (its hint is shown).
    Lost { loss: Loss, blamed: bool },
}

/// Judges a failed scene for checkpoint `id` (module docs).
fn judge(s: &SceneResult, id: u32, context: &Context) -> Judged {
    let why = match (&s.error, s.scene.hidden) {
        (Some(e), _) => Why::Error(e.clone()),
        (None, true) => Why::Differs,
        (None, false) => Why::Checks(failed_checks(s)),
    };
    let lost = |loss, blamed| Judged::Lost { loss, blamed };
    let not_started = |k| context.not_started(k);
    match (context.blame, context.culprit(&s.scene)) {
        (Blame::Isolated, Some(k)) if k != id => {
            lost(Loss::OthersFailWithYours { why, other: k, own: id }, true)
        }
        (Blame::Isolated, _) => lost(Loss::Yours(why), true),
        (_, Some(k)) if k > id && not_started(k) => {
            let waiting = s.scene.depends_on.iter().copied().filter(|&d| d > id && not_started(d)).collect();
            Judged::Kept(Kept::Waiting { own: id, waiting })
        }
        (_, Some(k)) if k > id => Judged::Kept(Kept::LaterWrong { own: id, later: k, why }),
        (_, Some(k)) if k < id && not_started(k) => lost(Loss::UntilWritten(k), false),
        (_, Some(k)) if k < id => lost(Loss::EarlierWrong { earlier: k, why }, false),
        (_, Some(_)) if not_started(id) => lost(Loss::NotWritten(id), true),
        (_, Some(_)) => lost(Loss::YourTestsFail { own: id, why }, true),
        (_, None) => lost(Loss::Yours(why), true),
    }
}

/// Words a student can read for a render that stopped in the stub of a checkpoint not written
/// yet, in place of the stub's panic.
pub fn explain_stub_stop(s: &mut SceneResult, context: &Context) {
    if let Some(k) = context.stopped_at(s) {
        s.error = Some(SceneFailure::NotWritten(k));
    }
}

/// What a scene's row says, given the checkpoints graded (module docs): FAIL only when it cost
/// one of them points.
pub fn scene_status(s: &SceneResult, graded: &[u32], context: &Context) -> SceneStatus {
    if s.passed() {
        return SceneStatus::Passed;
    }
    let mut kept = None;
    for &id in s.scene.grades.iter().filter(|id| graded.contains(id)) {
        match judge(s, id, context) {
            Judged::Lost { .. } => return SceneStatus::Failed,
            Judged::Kept(note) => kept = kept.or(Some(note)),
        }
    }
    kept.map_or(SceneStatus::Failed, SceneStatus::NotCounted)
}

/// One part of a checkpoint's points: its public checks, or its hidden ones.
struct Checks<'a> {
    part: Part,
    test_points: f64,
    image_points: f64,
    filter: &'a str,
    tests: Option<&'a TestRun>,
    scenes: Vec<&'a SceneResult>,
}

/// A part's points, why points were lost, and whether the checkpoint itself is to blame.
#[derive(Default)]
struct PartScore {
    test_score: f64,
    image_score: f64,
    reasons: Vec<Reason>,
    blamed: bool,
}

/// Test points by the fraction passed, the waiting tests left out; image points by the culprit
/// rule (module docs); the hidden checks, if any, scored the same way beside the public ones.
pub fn score_checkpoint(
    checkpoint: &Checkpoint,
    scenes: &[SceneResult],
    context: &Context,
) -> CheckpointResult {
    let id = checkpoint.id;
    let graded = |hidden: bool| -> Vec<&SceneResult> {
        scenes.iter().filter(|s| s.scene.hidden == hidden && s.scene.grades.contains(&id)).collect()
    };
    let runs =
        |hidden: bool| context.tests.and_then(|t| if hidden { t.hidden.get(&id) } else { t.public.get(&id) });
    let public = Checks {
        part: Part::Public,
        test_points: checkpoint.test_points,
        image_points: checkpoint.image_points,
        filter: &checkpoint.test_filter,
        tests: runs(false),
        scenes: graded(false),
    };
    let hidden = checkpoint.hidden.as_ref().map(|h| Checks {
        part: Part::Hidden,
        test_points: h.test_points,
        image_points: h.image_points,
        filter: h.test_filter.as_deref().unwrap_or_default(),
        tests: runs(true),
        scenes: graded(true),
    });
    let mut total = PartScore::default();
    if context.not_started(id) {
        total.reasons.push(Reason::NotStarted);
    }
    for part in std::iter::once(&public).chain(hidden.as_ref()) {
        let score = score_part(id, part, context);
        total.test_score += score.test_score;
        total.image_score += score.image_score;
        total.reasons.extend(score.reasons);
        total.blamed |= score.blamed;
    }
    let advice = if context.not_started(id) {
        Some(Advice::NotStarted { handout: checkpoint.handout.clone() })
    } else {
        total.blamed.then_some(Advice::Hint)
    };
    CheckpointResult {
        checkpoint: checkpoint.clone(),
        waiting: public.tests.map_or(0, |t| context.waiting(t, id).len()),
        tests: public.tests.cloned(),
        hidden_tests: hidden.and_then(|h| h.tests.cloned()),
        test_score: total.test_score,
        image_score: total.image_score,
        reasons: total.reasons,
        advice,
    }
}

fn score_part(id: u32, part: &Checks, context: &Context) -> PartScore {
    let mut score = PartScore::default();
    if let Some(t) = part.tests {
        let (reasons, fraction) = test_reasons(id, part, t, context);
        score.reasons = reasons;
        score.blamed = fraction < 1.0;
        score.test_score = part.test_points * fraction;
    }
    let mut kept = 0usize;
    for s in &part.scenes {
        // A checkpoint not written earns nothing, though a stand-in may have drawn the scene.
        if s.passed() && !context.not_started(id) {
            kept += 1;
            continue;
        }
        match judge(s, id, context) {
            Judged::Kept(_) => kept += 1,
            Judged::Lost { loss, blamed } => {
                // A checkpoint not started says so once, not once a scene.
                if !context.not_started(id) {
                    let scene = s.scene.name.clone();
                    score.reasons.push(Reason::SceneLost { part: part.part, scene: scene.clone(), loss });
                    score.reasons.extend(s.named.clone().map(|naming| Reason::LooksLike { scene, naming }));
                }
                score.blamed |= blamed;
            }
        }
    }
    if !part.scenes.is_empty() {
        score.image_score = part.image_points * kept as f64 / part.scenes.len() as f64;
    }
    score
}

/// Why a part's tests lost points, and the fraction of them that counts as passed (the tests
/// waiting for another checkpoint left out).
fn test_reasons(id: u32, checks: &Checks, t: &TestRun, context: &Context) -> (Vec<Reason>, f64) {
    let part = checks.part;
    let waiting = context.waiting(t, id);
    let mut reasons = Vec::new();
    if !waiting.is_empty() {
        let mut checkpoints: Vec<u32> = waiting.iter().map(|(_, k)| *k).collect();
        checkpoints.sort_unstable();
        checkpoints.dedup();
        reasons.push(Reason::TestsWait {
            part,
            waiting: waiting.len(),
            of: t.passed + t.failed,
            checkpoints,
        });
    }
    // The test's own name reads as a sentence; its module path is the checkpoint's.
    let names: Vec<String> = t
        .failures
        .iter()
        .filter(|f| !waiting.iter().any(|(w, _)| w == *f))
        .map(|f| f.rsplit("::").next().unwrap_or(f).to_string())
        .collect();
    if context.not_started(id) {
        // Said once for the whole checkpoint.
    } else if let Some(error) = &t.error {
        reasons.push(Reason::TestsDidNotRun { part, error: error.clone() });
    } else if t.failed as usize > waiting.len() {
        let failed = t.failed as usize - waiting.len();
        reasons.push(Reason::TestsFailed { part, failed, of: t.passed as usize + failed, names });
    } else if t.passed == 0 && waiting.is_empty() {
        reasons.push(Reason::NoTests { part, filter: checks.filter.to_string() });
    }
    (reasons, context.fraction(t, id))
}

/// The checks of a scene that failed.
fn failed_checks(s: &SceneResult) -> Vec<FailedCheck> {
    s.checks
        .iter()
        .filter(|(_, m)| !m.passed)
        .map(|(c, m)| match (&s.tiles, c.metric) {
            (Some(v), Metric::TileTest) => {
                let tile = s.scene.tile_test.as_ref().map_or(1, |t| t.tile);
                let (x, y) = tile_origin(v.failures[0].tile, tile, s.reference.width());
                FailedCheck::Tiles {
                    failed: v.failures.len(),
                    of: v.tiles.len(),
                    first: [x, y, x + tile - 1, y + tile - 1],
                    first_failure: v.failures[0],
                }
            }
            _ => FailedCheck::Metric { check: c.clone(), value: m.value },
        })
        .collect()
}

#[cfg(test)]
mod tests;
