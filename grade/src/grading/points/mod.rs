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
mod tests {
    use super::*;

    use crate::fingerprint::Naming;
    use crate::outcome::SceneStatus;
    use crate::report::reasons::{advice_line, kept_text, reason_lines};
    use crate::rubric::Rubric;
    use crate::run::child::{Category, Failure};
    use image::RgbImage;
    use std::path::{Path, PathBuf};

    fn root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    /// The public rubric, without the hidden checks.
    fn rubric() -> Rubric {
        Rubric::load(&root().join(crate::rubric::RUBRIC), &root()).unwrap()
    }

    fn failed_scene(rubric: &Rubric, name: &str) -> SceneResult {
        SceneResult {
            scene: rubric.scenes.iter().find(|s| s.name == name).unwrap().clone(),
            checks: Vec::new(),
            error: Some(SceneFailure::NoImage),
            seconds: 0.0,
            render: None,
            reference: RgbImage::new(1, 1),
            ssim: None,
            tiles: None,
            stand_ins: Vec::new(),
            status: SceneStatus::Failed,
            named: None,
        }
    }

    /// A failed scene named as a known mistake says so under the checkpoint that loses its
    /// points, right after the scene's own reason, with the evidence and the handout.
    #[test]
    fn a_named_mistake_follows_the_lost_scene() {
        let rubric = rubric();
        let entry = crate::fingerprint::Entry {
            scene: "room".into(),
            mistake: "triangle_rejects_back_faces".into(),
            checkpoint: 2,
            description: "back faces culled".into(),
            handout: "checkpoints/02-triangle.md".into(),
            inputs_hash: String::new(),
        };
        let named = Naming { entry, to_mistake: 0.99, to_reference: 0.1, thumbnail: RgbImage::new(1, 1) };
        let scene = SceneResult { named: Some(named), ..failed_scene(&rubric, "room") };
        let tests = runs(|id| id == 2);
        let two = score_checkpoint(&rubric.checkpoints[1], &[scene], &culprit(&tests, &[]));
        let at = reason_lines(&two)
            .iter()
            .position(|r| r.starts_with("scene room: "))
            .expect("the scene's reason");
        assert_eq!(
            reason_lines(&two).get(at + 1).map(String::as_str),
            Some("scene room looks like a known mistake of checkpoint 2: back faces culled (0.9900 to that mistake's render, 0.1000 to the reference); read checkpoints/02-triangle.md, section \"Symptoms of common mistakes\"")
        );
    }

    /// A failed result for each scene that runs checkpoint `id`'s code.
    fn failed_scenes_running(rubric: &Rubric, id: u32) -> Vec<SceneResult> {
        let runs_it = rubric.scenes.iter().filter(|s| s.depends_on.contains(&id));
        runs_it.map(|s| failed_scene(rubric, &s.name)).collect()
    }

    /// Every checkpoint's tests passing, but those `failing` (one of five fails).
    fn runs(failing: impl Fn(u32) -> bool) -> TestRuns {
        let run = |id| match failing(id) {
            true => TestRun { passed: 4, failed: 1, failures: vec![format!("t{id}")], ..TestRun::default() },
            false => TestRun { passed: 5, ..TestRun::default() },
        };
        TestRuns { public: (1..=9).map(|id| (id, run(id))).collect(), hidden: BTreeMap::new() }
    }

    fn culprit<'a>(tests: &'a TestRuns, stubbed: &'a [u32]) -> Context<'a> {
        Context { tests: Some(tests), stubbed, blame: Blame::Culprit }
    }

    fn scored(
        rubric: &Rubric,
        tests: &TestRuns,
        stubbed: &[u32],
        scenes: &[SceneResult],
    ) -> Vec<CheckpointResult> {
        rubric
            .checkpoints
            .iter()
            .map(|c| {
                score_checkpoint(c, scenes, &Context { tests: Some(tests), stubbed, blame: Blame::Culprit })
            })
            .collect()
    }

    /// A bug in checkpoint 2 fails every scene that runs it; each lost point names checkpoint 2,
    /// and only checkpoint 2 gets advice.
    #[test]
    fn grader_blames_every_failed_scene_on_the_lowest_checkpoint_whose_tests_fail() {
        let rubric = rubric();
        let tests = runs(|id| id == 2);
        let scenes = failed_scenes_running(&rubric, 2);
        for c in scored(&rubric, &tests, &[], &scenes) {
            let lines = reason_lines(&c);
            let image_reasons: Vec<&String> = lines.iter().filter(|r| r.starts_with("scene")).collect();
            if c.checkpoint.id == 2 {
                assert!(c.advice.is_some() && !image_reasons.is_empty());
            } else {
                assert!(c.advice.is_none(), "checkpoint {}: {:?}", c.checkpoint.id, c.advice);
                assert!(
                    image_reasons.iter().all(|r| r.contains("fix checkpoint 2 first")),
                    "{image_reasons:?}"
                );
            }
        }
    }

    /// Checkpoint 2 written, 3 to 9 still the starter's: checkpoint 2 keeps its image points,
    /// and the later ones are "not started", with their handout.
    #[test]
    fn grader_gives_a_correct_checkpoint_its_points_when_later_ones_are_not_started() {
        let rubric = rubric();
        let tests = runs(|id| id > 2);
        let scenes: Vec<SceneResult> = rubric.scenes.iter().map(|s| failed_scene(&rubric, &s.name)).collect();
        let results = scored(&rubric, &tests, &[3, 4, 5, 6, 7, 8, 9], &scenes);
        assert_eq!(results[1].score(), results[1].max_score(true));
        for c in &results[2..] {
            assert!(advice_line(c).is_some_and(|a| a.starts_with("Not started")), "{:?}", c.advice);
        }
    }

    /// A hidden scene that fails costs the hidden image points only, with a reason naming it as
    /// hidden; the hidden tests' points come beside the public ones.
    #[test]
    fn grader_scores_hidden_checks_beside_the_public_ones() {
        let rubric = Rubric::of_tree(&root()).unwrap();
        let six = rubric.checkpoints.iter().find(|c| c.id == 6).unwrap();
        let hidden = six.hidden.clone().expect("checkpoint 6 has hidden checks");
        let mut tests = runs(|_| false);
        tests
            .hidden
            .insert(6, TestRun { passed: 1, failed: 1, failures: vec!["h".into()], ..TestRun::default() });
        let passed = |name: &str| SceneResult { error: None, ..failed_scene(&rubric, name) };
        let scenes: Vec<SceneResult> = rubric
            .scenes
            .iter()
            .map(|s| if s.hidden { failed_scene(&rubric, &s.name) } else { passed(&s.name) })
            .collect();
        let result = score_checkpoint(six, &scenes, &culprit(&tests, &[]));
        assert_eq!(result.image_score, six.image_points);
        assert_eq!(result.test_score, six.test_points + hidden.test_points / 2.0);
        assert_eq!(result.max_score(true), six.all_test_points() + six.all_image_points());
        assert!(
            reason_lines(&result).iter().any(|r| r.starts_with("hidden unit tests: 1 of 2 failed")),
            "{:?}",
            result.reasons
        );
        assert!(reason_lines(&result).iter().any(|r| r.starts_with("hidden scene ")), "{:?}", result.reasons);
        assert_eq!(result.tests_cell(), "5/5 + hidden 1/2");
    }

    /// Checkpoint 2 graded alone, the solution everywhere else: its bug fails every scene and
    /// checkpoint 5's tests, and the scenes cost checkpoint 2 all the same, saying why; the
    /// culprit rule would have kept those that run checkpoint 5 (a later checkpoint's tests fail).
    #[test]
    fn grader_blames_the_only_checkpoint_of_the_student_in_an_isolated_grade() {
        let rubric = rubric();
        let two = rubric.checkpoints.iter().find(|c| c.id == 2).unwrap();
        let tests = runs(|id| id == 5);
        let scenes = failed_scenes_running(&rubric, 5);
        let isolated_context = Context { tests: Some(&tests), stubbed: &[], blame: Blame::Isolated };
        let isolated = score_checkpoint(two, &scenes, &isolated_context);
        let culprit = score_checkpoint(two, &scenes, &culprit(&tests, &[]));
        assert_eq!(culprit.image_score, two.image_points);
        assert_eq!(isolated.image_score, 0.0);
        assert!(isolated.advice.is_some());
        assert!(
            reason_lines(&isolated)
                .iter()
                .any(|r| r.contains("checkpoint 5's tests fail with your checkpoint 2")),
            "{:?}",
            isolated.reasons
        );
        assert!(reason_lines(&isolated).iter().all(|r| !r.contains("not started")), "{:?}", isolated.reasons);
    }

    /// A scene that stops in checkpoint `k`'s stub, as the render child reports it, explained.
    fn stopped_in_the_stub_of(rubric: &Rubric, name: &str, k: u32, context: &Context) -> SceneResult {
        let detail = format!("not yet implemented: checkpoint {k}: write `object_median_split`: Splits");
        let panic = Failure { category: Category::Panicked, detail: Some(detail) };
        let mut scene =
            SceneResult { error: Some(SceneFailure::Failed(panic)), ..failed_scene(rubric, name) };
        explain_stub_stop(&mut scene, context);
        scene
    }

    /// Checkpoint 2 alone written and graded: the scenes that stop in checkpoint 4's stub cost it
    /// nothing and their rows are "not counted", never FAIL, saying what they wait for.
    #[test]
    fn grader_does_not_count_a_scene_that_waits_for_a_later_checkpoint() {
        let rubric = rubric();
        let tests = runs(|id| id > 2);
        let stubbed = [3, 4, 5, 6, 7, 8, 9];
        let context = culprit(&tests, &stubbed);
        let scene = stopped_in_the_stub_of(&rubric, "intersection_test", 4, &context);
        let status = scene_status(&scene, &[2], &context);
        let SceneStatus::NotCounted(kept) = &status else { panic!("{status:?}") };
        let note = kept_text(kept);
        assert!(note.contains("waiting for checkpoints 3, 4 and 5, not written yet"), "{note}");
        assert_eq!(status.word(), "-");
        let two = score_checkpoint(&rubric.checkpoints[1], std::slice::from_ref(&scene), &context);
        assert_eq!(two.score(), two.max_score(true), "{:?}", two.reasons);
        // Graded with checkpoint 5 (--all), the same scene costs checkpoint 5: FAIL.
        assert_eq!(scene_status(&scene, &[2, 5], &context), SceneStatus::Failed);
    }

    /// A scene that passed with stand-ins gives the checkpoints stood in for nothing, and the
    /// written ones their points.
    #[test]
    fn a_scene_drawn_by_stand_ins_gives_a_checkpoint_not_written_nothing() {
        let rubric = rubric();
        let tests = runs(|id| id > 2);
        let stubbed = [3, 4, 5, 6, 7, 8, 9];
        let context = culprit(&tests, &stubbed);
        let passed = SceneResult { error: None, ..failed_scene(&rubric, "intersection_test") };
        let [two, three] =
            [1, 2].map(|i| score_checkpoint(&rubric.checkpoints[i], std::slice::from_ref(&passed), &context));
        assert_eq!((two.image_score, three.image_score), (two.checkpoint.image_points, 0.0));
    }

    /// Checkpoint 2 written with a bug (its tests fail), 3 to 9 stubs: the scene costs checkpoint
    /// 2 its points with a reason naming checkpoint 2 and the one it could not run, never the
    /// panic of another checkpoint's stub.
    #[test]
    fn grader_names_the_checkpoint_to_blame_not_the_stub_that_stopped_the_scene() {
        let rubric = rubric();
        let tests = runs(|id| id >= 2);
        let stubbed = [3, 4, 5, 6, 7, 8, 9];
        let context = culprit(&tests, &stubbed);
        let scene = stopped_in_the_stub_of(&rubric, "intersection_test", 4, &context);
        assert_eq!(scene_status(&scene, &[2], &context), SceneStatus::Failed);
        let two = score_checkpoint(&rubric.checkpoints[1], &[scene], &context);
        assert_eq!(two.image_score, 0.0);
        let lines = reason_lines(&two);
        let reason = lines.iter().find(|r| r.starts_with("scene ")).expect("a scene reason");
        assert_eq!(
            reason,
            "scene intersection_test: your checkpoint 2 tests fail; the scene could not run: checkpoint 4 is not written yet"
        );
        assert!(two.advice.is_some());
        // A stub's words panicked by a checkpoint that is written are its own error.
        let written = stopped_in_the_stub_of(&rubric, "intersection_test", 2, &context);
        assert!(written.error.unwrap().to_string().starts_with("panicked: not yet implemented"));
    }

    /// Checkpoint 5's tests, three of which stop in checkpoint 4's stub: with checkpoint 4 not
    /// written they wait, left out of the fraction and without checkpoint 5's hint; with
    /// checkpoint 4 written (the same words panicked by code) or in an isolated grade, they fail.
    #[test]
    fn grader_leaves_out_tests_waiting_for_a_checkpoint_not_written_yet() {
        let rubric = rubric();
        let five = rubric.checkpoints.iter().find(|c| c.id == 5).unwrap();
        let names: Vec<String> = (0..4).map(|i| format!("checkpoint5::t{i}")).collect();
        let run = TestRun {
            passed: 6,
            failed: 4,
            failures: names.clone(),
            stub_panics: names[..3].iter().map(|n| (n.clone(), 4)).collect(),
            ..TestRun::default()
        };
        let mut tests = runs(|_| false);
        tests.public.insert(5, run);
        let graded = |tests: &TestRuns, stubbed: &[u32], blame| {
            score_checkpoint(five, &[], &Context { tests: Some(tests), stubbed, blame })
        };
        let waiting = graded(&tests, &[4], Blame::Culprit);
        assert_eq!(waiting.test_score, five.test_points * 6.0 / 7.0);
        assert_eq!(waiting.waiting, 3);
        assert_eq!(waiting.tests_cell(), "6/7 + 3 wait");
        assert!(
            reason_lines(&waiting).iter().any(|r| r.contains("3 of 10 wait for checkpoint 4")),
            "{:?}",
            waiting.reasons
        );
        assert!(
            reason_lines(&waiting).iter().any(|r| r.contains("1 of 7 failed: t3")),
            "{:?}",
            waiting.reasons
        );
        for failing in [graded(&tests, &[], Blame::Culprit), graded(&tests, &[4], Blame::Isolated)] {
            assert_eq!(failing.test_score, five.test_points * 0.6);
            assert_eq!((failing.waiting, failing.tests_cell().as_str()), (0, "6/10"));
        }
        // Every failure waits, none is the checkpoint's own: nothing lost yet, and no hint.
        tests.public.get_mut(&5).unwrap().stub_panics.push((names[3].clone(), 4));
        let all_wait = graded(&tests, &[4], Blame::Culprit);
        assert_eq!(all_wait.test_score, five.test_points);
        assert!(all_wait.advice.is_none(), "{:?}", all_wait.advice);
    }

    /// Images only (`--skip-tests`): nothing shows checkpoint 2 right, so a scene that could not
    /// run costs it, even with the later checkpoints not written.
    #[test]
    fn grader_without_tests_counts_every_failed_scene() {
        let rubric = rubric();
        let context = Context { tests: None, stubbed: &[3, 4, 5, 6, 7, 8, 9], blame: Blame::Culprit };
        let scene = stopped_in_the_stub_of(&rubric, "intersection_test", 4, &context);
        assert_eq!(scene_status(&scene, &[2], &context), SceneStatus::Failed);
        let two = score_checkpoint(&rubric.checkpoints[1], std::slice::from_ref(&scene), &context);
        assert_eq!(two.image_score, 0.0);
    }
}
