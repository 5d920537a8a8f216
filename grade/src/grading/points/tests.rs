//! Who loses a scene's points and what each row says, on made-up results: culprits, stubs,
//! waiting tests, stand-ins, isolated grades, hidden scenes.

use super::*;

use crate::fingerprint::{Closeness, Naming};
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
        kind: crate::fingerprint::Kind::Thumbnail,
    };
    let closeness = Closeness::Ssim { to_mistake: 0.99, to_reference: 0.1 };
    let named = Naming { entry, closeness, picture: RgbImage::new(1, 1) };
    let scene = SceneResult { named: Some(named), ..failed_scene(&rubric, "room") };
    let tests = runs(|id| id == 2);
    let two = score_checkpoint(&rubric.checkpoints[1], &[scene], &culprit(&tests, &[]));
    let at =
        reason_lines(&two).iter().position(|r| r.starts_with("scene room: ")).expect("the scene's reason");
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
        .map(|c| score_checkpoint(c, scenes, &Context { tests: Some(tests), stubbed, blame: Blame::Culprit }))
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
            assert!(image_reasons.iter().all(|r| r.contains("fix checkpoint 2 first")), "{image_reasons:?}");
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
    let mut scene = SceneResult { error: Some(SceneFailure::Failed(panic)), ..failed_scene(rubric, name) };
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
    assert!(reason_lines(&waiting).iter().any(|r| r.contains("1 of 7 failed: t3")), "{:?}", waiting.reasons);
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
