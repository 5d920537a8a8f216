//! Grading a tree: run each checkpoint's unit tests and render each graded scene in child
//! processes, score the renders against the references, and combine both into points.
//!
//! Grading is a function of (the tree to build and test, its rubric, scenes and references):
//! everything is found under [`GradeOptions::root`], never the current directory.
//!
//! Who loses a failed scene's points, and what its row says, is [`points`]' concern.

mod error;
pub mod points;
mod scene;

pub use error::GradeError;

use scene::{grade_scene, Render};

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use indicatif::ProgressBar;

use crate::fingerprint::{Fingerprints, Naming};
use crate::grading::points::{explain_stub_stop, scene_status, score_checkpoint, Context, TestRuns};
use crate::outcome::{Blame, GradeReport, Needed, Phases, SceneResult, SceneStatus};
use crate::reference::{checked_manifest, Manifest};
use crate::regions::stub::stubbed_checkpoints;
use crate::rubric::{Checkpoint, GradedScene, Rubric};
use crate::run::cargo::{build_renderer, BUILD_TIME_LIMIT};
use crate::run::child::CHILD_ENV;
use crate::run::unit_tests::{build_tests, TestRun, TestsFailure};
use crate::scene_failure::SceneFailure;

/// A render may take this many times the reference's single-sample render time...
const TIME_LIMIT_FACTOR: f64 = 20.0;
/// ...but never less than this: a loaded machine must not fail a correct submission.
const TIME_LIMIT_FLOOR: Duration = Duration::from_secs(10);
/// One checkpoint's tests, once built.
const TEST_TIME_LIMIT: Duration = Duration::from_secs(120);

/// What to grade and how.
#[derive(Clone, Debug)]
pub struct GradeOptions {
    /// The repository: rubric, scenes, references, and the crate whose tests run.
    pub root: PathBuf,
    /// The tree whose renderer and tests are built and run, if not `root` (a submission spliced
    /// into a scratch copy of the instructor's tree, without the references).
    pub code: Option<PathBuf>,
    /// Cargo's target folder for the tree's builds (its own `target/` if `None`).
    pub target: Option<PathBuf>,
    /// Environment added for every render and test child (which checkpoints run a submission's
    /// code, see [`crate::submission::splice`]).
    pub env: Vec<(String, String)>,
    /// The checkpoints that are still the starter's stubs, if known (else read from the code).
    pub not_started: Option<Vec<u32>>,
    /// Only these checkpoints (all if `None`).
    pub checkpoints: Option<Vec<u32>>,
    /// Only these scenes, by name (all the checkpoints' scenes if `None`).
    pub scenes: Option<Vec<String>>,
    /// Run the unit tests (`cargo test`), or grade images only.
    pub run_tests: bool,
    /// Render with this seed instead of the rubric's (calibration tries several).
    pub seed: Option<u64>,
    /// Trace the tile-tested scenes' renders with the harness's wide BVH (`render --accel wide`,
    /// the same hits, three to four times faster). Only for trees whose checkpoints 2 to 4 are
    /// the reference solution's (calibration variants of later checkpoints): never for a
    /// submission, whose triangle test, boxes and traversal are judged in every render.
    pub wide_tile_renders: bool,
    /// Who loses a failed scene's points ([`crate::grading::points`]).
    pub blame: Blame,
}

impl GradeOptions {
    /// Everything in `root`: all checkpoints and scenes, tests included, the rubric's seeds.
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Self {
            root: root.into(),
            code: None,
            target: None,
            env: Vec::new(),
            not_started: None,
            checkpoints: None,
            scenes: None,
            run_tests: true,
            seed: None,
            wide_tile_renders: false,
            blame: Blame::Culprit,
        }
    }
}

/// The rubric of the instructor's tree at `root`, with every scene's reference checked
/// ([`checked_manifest`]): what a grade of someone else's code checks before it builds anything.
pub fn checked_rubric(root: &Path) -> Result<Rubric, GradeError> {
    let rubric = Rubric::of_tree(root)?;
    checked_manifest(root, &rubric, &rubric.scenes)?;
    Ok(rubric)
}

/// What a grade covers, decided before anything is built or run.
struct Plan {
    rubric: Rubric,
    /// The checkpoints graded.
    checkpoints: Vec<Checkpoint>,
    /// The scenes rendered.
    scenes: Vec<GradedScene>,
    manifest: Manifest,
    /// The checkpoints still the starter's stubs.
    stubbed: Vec<u32>,
    /// The checkpoints whose tests run: the graded ones, and every written one a scene runs (a
    /// stub's tests all fail: nothing to learn from running them).
    tested: Vec<Checkpoint>,
}

impl Plan {
    /// Whether a scene of the plan runs checkpoint `id`'s code.
    fn runs(&self, id: u32) -> bool {
        self.scenes.iter().any(|s| s.depends_on.contains(&id))
    }
}

/// The plan of a grade: the rubric, the selection of `options`, the references checked.
fn plan(options: &GradeOptions) -> Result<Plan, GradeError> {
    let root = &options.root;
    let rubric = Rubric::of_tree(root)?;
    let selected = |c: &&Checkpoint| options.checkpoints.as_ref().is_none_or(|ids| ids.contains(&c.id));
    let mut checkpoints: Vec<&Checkpoint> = rubric.checkpoints.iter().filter(selected).collect();
    let scenes = selected_scenes(&rubric, options, &checkpoints)?;
    // Scenes named alone grade the checkpoints they grade, not every checkpoint with no scene.
    if options.scenes.is_some() && options.checkpoints.is_none() {
        checkpoints.retain(|c| scenes.iter().any(|s| s.grades.contains(&c.id)));
    }
    let manifest = checked_manifest(root, &rubric, &scenes)?;
    let code = options.code.as_deref().unwrap_or(root);
    let stubbed = not_started(options, code, &rubric, &checkpoints)?;
    let runs = |id: u32| scenes.iter().any(|s| s.depends_on.contains(&id));
    let tested = (rubric.checkpoints.iter())
        .filter(|c| checkpoints.contains(c) || (runs(c.id) && !stubbed.contains(&c.id)))
        .cloned()
        .collect();
    let checkpoints = checkpoints.into_iter().cloned().collect();
    Ok(Plan { rubric, checkpoints, scenes, manifest, stubbed, tested })
}

/// Builds the tree's renderer and renders and scores every scene of `plan` with it.
fn render_scenes(
    options: &GradeOptions,
    plan: &Plan,
    progress: &ProgressBar,
    phases: &mut Phases,
) -> Result<Vec<SceneResult>, GradeError> {
    let code = options.code.as_deref().unwrap_or(&options.root);
    let renderer = if plan.scenes.is_empty() {
        Err(SceneFailure::NoRenderer(None)) // tests only: nothing to build, nothing said
    } else {
        progress.set_message("building the renderer");
        let built = Instant::now();
        let renderer = build_renderer(code, options.target.as_deref())
            .map_err(|e| SceneFailure::NoRenderer(Some(e.to_string())));
        phases.build += built.elapsed().as_secs_f64();
        renderer
    };
    progress.inc(1);
    let rendering = Instant::now();
    let mut results = Vec::new();
    for scene in &plan.scenes {
        progress.set_message(format!("rendering {}", scene.name));
        let entry = plan.manifest.fresh_entry(&options.root, scene)?;
        let limit =
            TIME_LIMIT_FLOOR.max(Duration::from_secs_f64(TIME_LIMIT_FACTOR * entry.graded_render_seconds));
        let (scene, stand_ins) = staged(scene.clone(), &plan.stubbed);
        let render = Render { limit, stand_ins: &stand_ins };
        results.push(grade_scene(options, renderer.as_deref(), scene, render, progress)?);
        progress.inc(1);
    }
    phases.renders = rendering.elapsed().as_secs_f64();
    Ok(results)
}

/// Grades the tree at `options.root`; `Err` only for bad input (a broken rubric, a missing or
/// stale reference), never for anything the graded code does.
pub fn grade(options: &GradeOptions, progress: &ProgressBar) -> Result<GradeReport, GradeError> {
    if std::env::var_os(CHILD_ENV).is_some() {
        return Err(GradeError::InsideChild);
    }
    let start = Instant::now();
    let plan = plan(options)?;
    let code = options.code.as_deref().unwrap_or(&options.root);
    let test_steps = if options.run_tests { plan.tested.len() + 1 } else { 0 };
    // Each grade counts its own steps from 0, also when a caller grades several times with one bar.
    progress.set_position(0);
    progress.set_length((test_steps + 1 + plan.scenes.len()) as u64);
    let mut phases = Phases::default();
    let tested: Vec<&Checkpoint> = plan.tested.iter().collect();
    let target = options.target.as_deref();
    let tests =
        options.run_tests.then(|| run_unit_tests(code, target, &options.env, &tested, progress, &mut phases));
    let mut scenes = render_scenes(options, &plan, progress, &mut phases)?;
    let context = Context { tests: tests.as_ref(), stubbed: &plan.stubbed, blame: options.blame };
    let graded: Vec<u32> = plan.checkpoints.iter().map(|c| c.id).collect();
    let fingerprints = Fingerprints::load(&options.root, &plan.manifest)?;
    for s in &mut scenes {
        explain_stub_stop(s, &context);
        s.status = scene_status(s, &graded, &context);
        s.named = name_mistake(s, &fingerprints, &graded, &context);
    }
    let needed = (plan.rubric.checkpoints.iter())
        .filter(|c| !plan.checkpoints.contains(c) && plan.runs(c.id))
        .map(|c| Needed {
            checkpoint: c.clone(),
            tests: tests.as_ref().and_then(|t| t.public.get(&c.id).cloned()),
            not_started: plan.stubbed.contains(&c.id),
        })
        .collect();
    Ok(GradeReport {
        checkpoints: plan.checkpoints.iter().map(|c| score_checkpoint(c, &scenes, &context)).collect(),
        scenes,
        tests_ran: options.run_tests,
        needed,
        seconds: start.elapsed().as_secs_f64(),
        phases,
    })
}

/// The known mistake a failed scene's render looks like, among those of the checkpoints whose code
/// it ran as the student wrote it: every written one it runs, or in an isolated grade the graded
/// ones ([`crate::fingerprint`]).
fn name_mistake(
    s: &SceneResult,
    fingerprints: &Fingerprints,
    graded: &[u32],
    context: &Context,
) -> Option<Naming> {
    if s.status != SceneStatus::Failed || s.scene.hidden {
        return None;
    }
    let students = |id: &u32| match context.blame {
        Blame::Culprit => !context.stubbed.contains(id),
        Blame::Isolated => graded.contains(id),
    };
    let checkpoints: Vec<u32> = s.scene.depends_on.iter().copied().filter(students).collect();
    let tiles = s.tile_signatures();
    fingerprints.name(&s.scene.name, s.evidence(&tiles)?, &checkpoints)
}

/// The checkpoints still the starter's stubs: given, or read from the code. In an isolated grade
/// only the graded ones count (every other region is the solution's, whatever the submission's).
fn not_started(
    options: &GradeOptions,
    code: &Path,
    rubric: &Rubric,
    checkpoints: &[&Checkpoint],
) -> Result<Vec<u32>, GradeError> {
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    let stubbed = match &options.not_started {
        Some(ids) => ids.clone(),
        None => stubbed_checkpoints(&code.join("src"), &ids)
            .map_err(|source| GradeError::Unreadable { path: code.join("src"), source })?,
    };
    let counts = |id: &u32| options.blame == Blame::Culprit || checkpoints.iter().any(|c| c.id == *id);
    Ok(stubbed.into_iter().filter(counts).collect())
}

/// `scene` as rendered in a tree whose `stubbed` checkpoints are not written yet: those it may
/// stand in for are drawn by their stand-ins (returned) and no longer among the checkpoints it
/// runs; any other stub still stops the render.
fn staged(mut scene: GradedScene, stubbed: &[u32]) -> (GradedScene, Vec<u32>) {
    let stand_ins: Vec<u32> = scene.stand_ins.iter().copied().filter(|c| stubbed.contains(c)).collect();
    scene.depends_on.retain(|c| !stand_ins.contains(c));
    (scene, stand_ins)
}

/// The scenes to render: those named, or those grading a selected checkpoint.
fn selected_scenes(
    rubric: &Rubric,
    options: &GradeOptions,
    checkpoints: &[&Checkpoint],
) -> Result<Vec<GradedScene>, GradeError> {
    if let Some(names) = &options.scenes {
        return names
            .iter()
            .map(|n| {
                let known = || rubric.scenes.iter().map(|s| s.name.clone()).collect();
                let scene = rubric.scenes.iter().find(|s| &s.name == n).cloned();
                scene.ok_or_else(|| GradeError::UnknownScene { name: n.clone(), known: known() })
            })
            .collect();
    }
    let wanted = |s: &&GradedScene| s.grades.iter().any(|g| checkpoints.iter().any(|c| c.id == *g));
    Ok(rubric.scenes.iter().filter(wanted).cloned().collect())
}

/// Builds the tests once, then runs each checkpoint's filter, and its hidden tests' filter.
fn run_unit_tests(
    code: &Path,
    target: Option<&Path>,
    env: &[(String, String)],
    checkpoints: &[&Checkpoint],
    progress: &ProgressBar,
    phases: &mut Phases,
) -> TestRuns {
    progress.set_message("compiling the tests");
    let start = Instant::now();
    let built = build_tests(code, target, BUILD_TIME_LIMIT);
    phases.build += start.elapsed().as_secs_f64();
    progress.inc(1);
    let start = Instant::now();
    let run = |filter: &str, first: &[String]| match &built {
        Ok(binaries) => binaries.run_filter(code, filter, first, env, TEST_TIME_LIMIT),
        Err(e) => TestRun { error: Some(TestsFailure::NoBuild(e.to_string())), ..TestRun::default() },
    };
    let mut runs = TestRuns::default();
    for c in checkpoints {
        progress.set_message(format!("testing checkpoint {}", c.id));
        runs.public.insert(c.id, run(&c.test_filter, &c.tests_first));
        if let Some(filter) = c.hidden.as_ref().and_then(|h| h.test_filter.as_deref()) {
            runs.hidden.insert(c.id, run(filter, &[]).hidden());
        }
        progress.inc(1);
    }
    phases.tests += start.elapsed().as_secs_f64();
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With no counted checkpoint (only extras graded) the total reads "0.0 / 0", not "-0.0 / -0":
    /// a float `sum` of nothing is negative zero.
    #[test]
    fn an_empty_total_is_a_plain_zero() {
        let report = GradeReport {
            checkpoints: Vec::new(),
            scenes: Vec::new(),
            tests_ran: false,
            needed: Vec::new(),
            seconds: 0.0,
            phases: Phases::default(),
        };
        assert_eq!(format!("{:.1} / {:.0}", report.score(), report.max_score()), "0.0 / 0");
    }
}
