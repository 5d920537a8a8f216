//! Grading a tree: run each checkpoint's unit tests and render each graded scene in child
//! processes, score the renders against the references, and combine both into points.
//!
//! Grading is a function of (the tree to build and test, its rubric, scenes and references):
//! everything is found under [`GradeOptions::root`], never the current directory.
//!
//! **Who loses a failed scene's points.** A scene carries the image points of every checkpoint it
//! `grades`, and runs the code of every checkpoint it `depends_on` (`cornell_refract` grades 6 but
//! runs 2 to 6). The unit tests of all of those run, whatever was selected, so `--checkpoint N`
//! gives checkpoint N the points `--all` gives it. When the scene fails, the *culprit* is the
//! lowest checkpoint it depends on whose own unit tests do not all pass. A graded checkpoint
//! before the culprit keeps the scene's points (its tests pass and the failure is explained
//! elsewhere); the culprit loses them with its hint; one after it loses them with "fix checkpoint
//! K first" and no hint of its own. If every unit test passes (or none ran), the failure cannot be
//! pinned on one checkpoint and every graded one loses the points, with its hint.
//!
//! **Isolated blame.** When checkpoint N alone runs a submission's code and every other region
//! is the solution's ([`Blame::Isolated`], `grader submission`'s grade), only N's code can have
//! made a scene fail: it costs N, whatever the other checkpoints' tests say, and the reason says
//! when their tests fail too ("checkpoint 5's tests fail with your checkpoint 2").

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use image::RgbImage;
use indicatif::ProgressBar;

use crate::cargo::{build_renderer, BUILD_TIME_LIMIT};
use crate::child::{run_limited, Limits, CHILD_ENV};
use crate::features::Masks;
use crate::images::read_png;
use crate::metrics::{Comparison, Measured};
use crate::noisy::{compare, graded_seed, tile_means, tile_origin, NoisyReference, NoisyVerdict};
use crate::reference::{load_reference, load_tile_reference, Manifest};
use crate::report::hint_text;
use crate::rubric::{Check, Checkpoint, GradedScene, Metric, Rubric, TileTest};
use crate::ssim::SsimMap;
use crate::stub::stubbed_checkpoints;
use crate::unit_tests::{build_tests, TestRun};
use raylab_base::film::Film;
use raylab_base::image_io::read_pfm;

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
    /// code, see [`crate::splice`]).
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
    /// Who loses a failed scene's points (module docs).
    pub blame: Blame,
}

/// Who can have made a failed scene fail (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blame {
    /// Every region runs the tree's own code: the lowest checkpoint whose tests fail.
    Culprit,
    /// Only the selected checkpoints' regions run a submission's code, the solution's everywhere
    /// else: the selected checkpoint.
    Isolated,
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

/// The outcome of one graded scene.
#[derive(Clone, Debug)]
pub struct SceneResult {
    /// The scene.
    pub scene: GradedScene,
    /// Each check with its value; empty if the render failed.
    pub checks: Vec<(Check, Measured)>,
    /// Why the scene scored 0 without checks (crash, time limit, size mismatch).
    pub error: Option<String>,
    /// Seconds the render took.
    pub seconds: f64,
    /// The student's render, if there is one.
    pub render: Option<RgbImage>,
    /// The reference image.
    pub reference: RgbImage,
    /// Per-pixel SSIM of render against reference, if both exist.
    pub ssim: Option<SsimMap>,
    /// The tile test's verdict, for a scene graded by one.
    pub tiles: Option<NoisyVerdict>,
}

impl SceneResult {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.error.is_none() && self.checks.iter().all(|(_, m)| m.passed)
    }
}

/// The outcome for one checkpoint.
#[derive(Clone, Debug)]
pub struct CheckpointResult {
    /// The checkpoint.
    pub checkpoint: Checkpoint,
    /// Its unit tests, if they ran.
    pub tests: Option<TestRun>,
    /// Its hidden unit tests, if it has some and they ran.
    pub hidden_tests: Option<TestRun>,
    /// Points from the unit tests, hidden ones included.
    pub test_score: f64,
    /// Points from the scenes, hidden ones included.
    pub image_score: f64,
    /// Why points were lost, one line each.
    pub reasons: Vec<String>,
    /// What to read or fix, when this checkpoint itself is to blame: its hint and handout, or
    /// "not started". `None` when it lost nothing or only lost points to another checkpoint.
    pub advice: Option<String>,
}

impl CheckpointResult {
    /// Points earned.
    pub fn score(&self) -> f64 {
        self.test_score + self.image_score
    }

    /// Points available, hidden ones included (test points only count when the tests ran).
    pub fn max_score(&self, tests_ran: bool) -> f64 {
        self.checkpoint.all_image_points() + if tests_ran { self.checkpoint.all_test_points() } else { 0.0 }
    }

    /// The unit tests passed, as a table cell: `9/10`, with the hidden ones beside:
    /// `9/10 + hidden 2/3`.
    pub fn tests_cell(&self) -> String {
        let cell = |t: &TestRun| match &t.error {
            None => format!("{}/{}", t.passed, t.passed + t.failed),
            Some(_) => "error".to_string(),
        };
        match (&self.tests, &self.hidden_tests) {
            (Some(t), Some(h)) => format!("{} + hidden {}", cell(t), cell(h)),
            (Some(t), None) => cell(t),
            (None, _) => "-".to_string(),
        }
    }

    /// The image points, as a table cell: `7.5/10`, or `-` if there are none.
    pub fn images_cell(&self) -> String {
        let max = self.checkpoint.all_image_points();
        if max > 0.0 {
            format!("{:.1}/{max:.0}", self.image_score)
        } else {
            "-".to_string()
        }
    }
}

/// A whole grading run.
#[derive(Clone, Debug)]
pub struct GradeReport {
    /// Per scene.
    pub scenes: Vec<SceneResult>,
    /// Per checkpoint.
    pub checkpoints: Vec<CheckpointResult>,
    /// Whether unit tests ran.
    pub tests_ran: bool,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// ...and of its phases.
    pub phases: Phases,
}

/// Wall-clock seconds of a grading run's phases.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Phases {
    /// Compiling the tests and the renderer.
    pub build: f64,
    /// Running the unit tests.
    pub tests: f64,
    /// Rendering and scoring the scenes.
    pub renders: f64,
}

impl std::ops::AddAssign for Phases {
    fn add_assign(&mut self, other: Phases) {
        self.build += other.build;
        self.tests += other.tests;
        self.renders += other.renders;
    }
}

impl GradeReport {
    /// Points earned, the extras' not included.
    pub fn score(&self) -> f64 {
        self.counted(false).map(CheckpointResult::score).sum()
    }

    /// Points available, the extras' not included.
    pub fn max_score(&self) -> f64 {
        self.counted(false).map(|c| c.max_score(self.tests_ran)).sum()
    }

    /// The extras' points earned and available, reported beside the total.
    pub fn extra_score(&self) -> (f64, f64) {
        self.counted(true).fold((0.0, 0.0), |(s, m), c| (s + c.score(), m + c.max_score(self.tests_ran)))
    }

    /// The checkpoints that are extras (`true`) or that count (`false`).
    fn counted(&self, extra: bool) -> impl Iterator<Item = &CheckpointResult> {
        self.checkpoints.iter().filter(move |c| c.checkpoint.extra == extra)
    }

    /// Whether every check and test passed, the extras' included.
    pub fn all_passed(&self) -> bool {
        self.checkpoints.iter().all(|c| (c.score() - c.max_score(self.tests_ran)).abs() < 1e-9)
    }
}

impl GradeReport {
    /// Every scene's check values and verdicts, for calibration: `{scene: {error, checks: {label:
    /// {value, passed}}}}`.
    pub fn values(&self) -> serde_json::Value {
        let scenes = self.scenes.iter().map(|s| {
            let checks = s
                .checks
                .iter()
                .map(|(c, m)| (c.label(), serde_json::json!({"value": m.value, "passed": m.passed})));
            let checks: serde_json::Map<String, serde_json::Value> = checks.collect();
            (
                s.scene.name.clone(),
                serde_json::json!({"error": s.error, "passed": s.passed(), "checks": checks}),
            )
        });
        serde_json::Value::Object(scenes.collect())
    }
}

/// Grades the tree at `options.root`; `Err` only for bad input (a broken rubric, a missing or
/// stale reference), never for anything the graded code does.
pub fn grade(options: &GradeOptions, progress: &ProgressBar) -> Result<GradeReport, String> {
    if std::env::var_os(CHILD_ENV).is_some() {
        return Err(format!("refusing to grade inside a grader child ({CHILD_ENV} is set)"));
    }
    let start = Instant::now();
    let root = &options.root;
    let rubric = Rubric::of_tree(root)?;
    let checkpoints: Vec<&Checkpoint> = rubric
        .checkpoints
        .iter()
        .filter(|c| options.checkpoints.as_ref().is_none_or(|ids| ids.contains(&c.id)))
        .collect();
    let scenes = selected_scenes(&rubric, options, &checkpoints)?;
    // The selected checkpoints' tests, and those of every checkpoint a selected scene runs.
    let tested: Vec<&Checkpoint> = rubric
        .checkpoints
        .iter()
        .filter(|c| checkpoints.contains(c) || scenes.iter().any(|s| s.depends_on.contains(&c.id)))
        .collect();
    let manifest = Manifest::load(root, &rubric)?;
    for scene in &scenes {
        manifest.fresh_entry(root, scene)?;
        load_reference(root, scene)?;
    }

    let code = options.code.as_deref().unwrap_or(root);
    let test_steps = if options.run_tests { tested.len() + 1 } else { 0 };
    // Each grade counts its own steps from 0, also when a caller grades several times with one bar.
    progress.set_position(0);
    progress.set_length((test_steps + 1 + scenes.len()) as u64);
    let target = options.target.as_deref();
    let mut phases = Phases::default();
    let tests =
        options.run_tests.then(|| run_unit_tests(code, target, &options.env, &tested, progress, &mut phases));
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    let stubbed = match &options.not_started {
        Some(ids) => ids.clone(),
        None => stubbed_checkpoints(&code.join("src"), &ids)
            .map_err(|e| format!("{}/src: {e}", code.display()))?,
    };
    progress.set_message("building the renderer");
    let built = Instant::now();
    let renderer = build_renderer(code, target).map_err(|e| format!("the renderer does not build: {e}"));
    phases.build += built.elapsed().as_secs_f64();
    progress.inc(1);
    let rendering = Instant::now();
    let mut scene_results = Vec::new();
    for scene in scenes {
        progress.set_message(format!("rendering {}", scene.name));
        let entry = manifest.fresh_entry(root, &scene)?;
        let limit =
            TIME_LIMIT_FLOOR.max(Duration::from_secs_f64(TIME_LIMIT_FACTOR * entry.graded_render_seconds));
        scene_results.push(grade_scene(options, renderer.as_deref(), scene, limit, progress)?);
        progress.inc(1);
    }
    phases.renders = rendering.elapsed().as_secs_f64();
    let checkpoint_results = checkpoints
        .iter()
        .map(|c| score_checkpoint(c, tests.as_ref(), &stubbed, &scene_results, options.blame))
        .collect();
    Ok(GradeReport {
        scenes: scene_results,
        checkpoints: checkpoint_results,
        tests_ran: options.run_tests,
        seconds: start.elapsed().as_secs_f64(),
        phases,
    })
}

/// The scenes to render: those named, or those grading a selected checkpoint.
fn selected_scenes(
    rubric: &Rubric,
    options: &GradeOptions,
    checkpoints: &[&Checkpoint],
) -> Result<Vec<GradedScene>, String> {
    if let Some(names) = &options.scenes {
        return names
            .iter()
            .map(|n| {
                let known = || rubric.scenes.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ");
                rubric
                    .scenes
                    .iter()
                    .find(|s| &s.name == n)
                    .cloned()
                    .ok_or_else(|| format!("{n}: not a graded scene (graded: {})", known()))
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
        Err(e) => TestRun { error: Some(format!("the tests do not compile: {e}")), ..TestRun::default() },
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

/// How the graded children render: the tree's renderer binary, the tree, the environment and
/// the time limit of one render.
struct Child<'a> {
    renderer: &'a Path,
    code: PathBuf,
    options: &'a GradeOptions,
    limit: Duration,
}

impl Child<'_> {
    /// Renders `scene` at its graded spp with `seed` in a child process: the PNG it writes, and
    /// the linear film if `pfm`; with the seconds it took.
    fn render(&self, scene: &GradedScene, seed: u64, pfm: bool) -> Result<(Rendered, f64), String> {
        let stem = std::env::temp_dir().join(format!("raylab-grader-{}-{}", std::process::id(), scene.name));
        let (png, film) = (stem.with_extension("png"), stem.with_extension("pfm"));
        let mut command = Command::new(self.renderer);
        command
            .current_dir(std::env::temp_dir())
            .env(CHILD_ENV, "1")
            .envs(self.options.env.iter().map(|(k, v)| (k, v)))
            .arg(self.code.join(&scene.file))
            .arg("--output")
            .arg(&png)
            .arg("--spp")
            .arg(scene.spp.to_string())
            .arg("--seed")
            .arg(seed.to_string())
            // Stand-ins are never graded: a stub fails the scene.
            .arg("--no-fallbacks");
        if pfm {
            command.arg("--pfm").arg(&film);
            if self.options.wide_tile_renders {
                command.arg("--accel").arg("wide");
            }
        }
        let run = run_limited(command, self.limit, Limits::GRADED)
            .map_err(|e| format!("cannot start {}: {e}", self.renderer.display()))?;
        let rendered = if !run.success() {
            // A hidden scene is reported by its fixed category only, never with its output.
            let failure = run.failure(self.limit);
            Err(if scene.hidden { failure.category.to_string() } else { failure.to_string() })
        } else if !png.exists() || (pfm && !film.exists()) {
            Err("the renderer exited without writing an image".to_string())
        } else {
            let image = read_png(&png).map_err(|e| match scene.hidden {
                true => "wrote an image that cannot be read".to_string(),
                false => e.to_string(),
            });
            let linear = if pfm { read_pfm(&film).map(Some).map_err(|e| e.to_string()) } else { Ok(None) };
            image.and_then(|image| Ok(Rendered { image, film: linear? }))
        };
        let _ = std::fs::remove_file(&png);
        let _ = std::fs::remove_file(&film);
        Ok((rendered?, run.seconds))
    }
}

/// What one graded render wrote.
struct Rendered {
    image: RgbImage,
    film: Option<Film>,
}

/// Renders one scene with the tree's `renderer` in child processes and scores it.
fn grade_scene(
    options: &GradeOptions,
    renderer: Result<&Path, &String>,
    scene: GradedScene,
    limit: Duration,
    progress: &ProgressBar,
) -> Result<SceneResult, String> {
    let (reference, masks) = load_reference(&options.root, &scene)?;
    let tiles = match &scene.tile_test {
        Some(test) => Some(load_tile_reference(&options.root, &scene, test)?),
        None => None,
    };
    // Absolute: the renderer runs in a scratch folder, not in the tree.
    let code = options.code.as_deref().unwrap_or(&options.root);
    let code = std::path::absolute(code).map_err(|e| format!("{}: {e}", code.display()))?;
    let mut result = SceneResult {
        scene: scene.clone(),
        checks: Vec::new(),
        error: None,
        seconds: 0.0,
        render: None,
        reference,
        ssim: None,
        tiles: None,
    };
    let renderer = match renderer {
        Ok(renderer) => renderer,
        Err(e) => {
            let hidden = "the renderer does not build".to_string();
            result.error = Some(if scene.hidden { hidden } else { e.clone() });
            return Ok(result);
        }
    };
    let child = Child { renderer, code, options, limit };
    let base = options.seed.unwrap_or(scene.seed);
    let scored = match (&scene.tile_test, &tiles) {
        (Some(test), Some(tiles)) => tile_test(&child, &mut result, test, tiles, base, progress),
        _ => child.render(&scene, base, false).and_then(|(rendered, seconds)| {
            result.seconds = seconds;
            score(&scene, rendered.image, &result.reference, &masks)
        }),
    };
    match scored {
        Ok((render, checks, ssim)) => {
            result.render = Some(render);
            result.checks = checks;
            result.ssim = Some(ssim);
        }
        Err(e) => result.error = Some(e),
    }
    Ok(result)
}

type Scored = (RgbImage, Vec<(Check, Measured)>, SsimMap);

fn score(
    scene: &GradedScene,
    render: RgbImage,
    reference: &RgbImage,
    masks: &Masks,
) -> Result<Scored, String> {
    let comparison = Comparison::new(&render, reference, masks)?;
    let checks = scene.checks.iter().map(|c| (c.clone(), comparison.measure(c))).collect();
    let ssim = comparison.ssim().clone();
    Ok((render, checks, ssim))
}

/// The tile test of a noisy scene ([`crate::noisy`]): `test.renders` renders with the seeds
/// [`graded_seed`] of `base`, their tile means against the reference's; the first render is the
/// one shown, with its SSIM against the reference image as a diagnostic.
fn tile_test(
    child: &Child,
    result: &mut SceneResult,
    test: &TileTest,
    tiles: &NoisyReference,
    base: u64,
    progress: &ProgressBar,
) -> Result<Scored, String> {
    let scene = &result.scene;
    let mut means = Vec::new();
    let mut shown = None;
    for k in 0..test.renders {
        progress.set_message(format!("rendering {} ({} of {})", scene.name, k + 1, test.renders));
        let (rendered, seconds) = child
            .render(scene, graded_seed(base, k), true)
            .map_err(|e| format!("render {} of {}: {e}", k + 1, test.renders))?;
        result.seconds += seconds;
        let film = rendered.film.expect("asked for the film");
        let (w, h) = result.reference.dimensions();
        if (film.width(), film.height()) != (w, h) {
            return Err(format!("the render is {}x{}, the reference {w}x{h}", film.width(), film.height()));
        }
        means.push(tile_means(&film, test.tile));
        shown.get_or_insert(rendered.image);
    }
    let verdict = compare(&means, tiles, test.alpha);
    let render = shown.ok_or("no render")?;
    let ssim = SsimMap::new(&render, &result.reference).map_err(|e| format!("{e} (render vs reference)"))?;
    let measured = [
        Measured { value: verdict.failures.len() as f64, passed: verdict.passed() },
        Measured { value: ssim.mean(), passed: true },
    ];
    let checks = scene.graded_checks().into_iter().zip(measured).collect();
    result.tiles = Some(verdict);
    Ok((render, checks, ssim))
}

/// A reason names this many failing tests; `cargo test checkpointN` shows them all.
const SHOWN_FAILURES: usize = 3;

/// Each tested checkpoint's unit-test runs, by id: its public tests, and its hidden ones if it
/// has any.
#[derive(Clone, Debug, Default)]
struct TestRuns {
    public: BTreeMap<u32, TestRun>,
    hidden: BTreeMap<u32, TestRun>,
}

/// The lowest checkpoint the scene runs whose own (public) tests do not all pass (module docs),
/// if the tests ran.
fn culprit(scene: &GradedScene, tests: Option<&TestRuns>) -> Option<u32> {
    let tests = &tests?.public;
    scene.depends_on.iter().copied().filter(|id| tests.get(id).is_none_or(|t| t.fraction() < 1.0)).min()
}

/// One part of a checkpoint's points: its public checks, or its hidden ones.
struct Part<'a> {
    /// `""` or `"hidden "`: how its reasons begin.
    label: &'static str,
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
    reasons: Vec<String>,
    blamed: bool,
}

/// Test points by the fraction passed; image points by the culprit rule (module docs); the
/// hidden checks, if any, scored the same way beside the public ones.
/// `stubbed`: the checkpoints whose regions are all still the starter's `todo!()`.
fn score_checkpoint(
    checkpoint: &Checkpoint,
    tests: Option<&TestRuns>,
    stubbed: &[u32],
    scenes: &[SceneResult],
    blame: Blame,
) -> CheckpointResult {
    let id = checkpoint.id;
    let graded = |hidden: bool| -> Vec<&SceneResult> {
        scenes.iter().filter(|s| s.scene.hidden == hidden && s.scene.grades.contains(&id)).collect()
    };
    let public = Part {
        label: "",
        test_points: checkpoint.test_points,
        image_points: checkpoint.image_points,
        filter: &checkpoint.test_filter,
        tests: tests.and_then(|t| t.public.get(&id)),
        scenes: graded(false),
    };
    let hidden = checkpoint.hidden.as_ref().map(|h| Part {
        label: "hidden ",
        test_points: h.test_points,
        image_points: h.image_points,
        filter: h.test_filter.as_deref().unwrap_or_default(),
        tests: tests.and_then(|t| t.hidden.get(&id)),
        scenes: graded(true),
    });
    let mut total = PartScore::default();
    if stubbed.contains(&id) && public.tests.is_some() {
        total.reasons.push("not started: its code is still the starter's todo!()".to_string());
    }
    for part in std::iter::once(&public).chain(hidden.as_ref()) {
        let score = score_part(id, part, tests, stubbed, blame);
        total.test_score += score.test_score;
        total.image_score += score.image_score;
        total.reasons.extend(score.reasons);
        total.blamed |= score.blamed;
    }
    let advice = if stubbed.contains(&id) {
        Some(format!("Not started yet: read {} first.", checkpoint.handout.display()))
    } else {
        total.blamed.then(|| hint_text(checkpoint))
    };
    CheckpointResult {
        checkpoint: checkpoint.clone(),
        tests: public.tests.cloned(),
        hidden_tests: hidden.and_then(|h| h.tests.cloned()),
        test_score: total.test_score,
        image_score: total.image_score,
        reasons: total.reasons,
        advice,
    }
}

fn score_part(id: u32, part: &Part, tests: Option<&TestRuns>, stubbed: &[u32], blame: Blame) -> PartScore {
    let not_started = |k: u32| stubbed.contains(&k);
    let label = part.label;
    let mut score = PartScore::default();
    if let Some(t) = part.tests {
        if not_started(id) {
            // Said once for the whole checkpoint.
        } else if let Some(e) = &t.error {
            score.reasons.push(format!("{label}unit tests: {e}"));
        } else if t.failed > 0 {
            // The test's own name reads as a sentence; its module path is the checkpoint's.
            let names: Vec<&str> = t.failures.iter().map(|f| f.rsplit("::").next().unwrap_or(f)).collect();
            let more = names.len().saturating_sub(SHOWN_FAILURES);
            let more = if more > 0 { format!(" and {more} more") } else { String::new() };
            score.reasons.push(format!(
                "{label}unit tests: {} of {} failed: {}{more}",
                t.failed,
                t.passed + t.failed,
                names[..names.len().min(SHOWN_FAILURES)].join(", ")
            ));
        } else if t.passed == 0 {
            score.reasons.push(format!("{label}unit tests: `cargo test {}` ran no test", part.filter));
        }
        score.blamed = t.fraction() < 1.0;
        score.test_score = part.test_points * t.fraction();
    }
    let mut kept = 0usize;
    for s in &part.scenes {
        if s.passed() {
            kept += 1;
            continue;
        }
        let why = match (&s.error, s.scene.hidden) {
            (Some(e), _) => e.clone(),
            (None, true) => "the image differs from the reference".to_string(),
            (None, false) => failed_checks(s),
        };
        let name = &s.scene.name;
        match (blame, culprit(&s.scene, tests)) {
            (Blame::Isolated, Some(k)) if k != id => {
                score.blamed = true;
                score.reasons.push(format!(
                    "{label}scene {name}: {why} (checkpoint {k}'s tests fail with your checkpoint {id}: only checkpoint {id} is your code in this grade)"
                ));
            }
            (Blame::Isolated, _) => {
                score.blamed = true;
                score.reasons.push(format!("{label}scene {name}: {why}"));
            }
            (_, Some(k)) if k > id => kept += 1,
            (_, Some(k)) if k < id && not_started(k) => score.reasons.push(format!(
                "{label}scene {name}: lost because checkpoint {k} is not started; write checkpoint {k} first"
            )),
            (_, Some(k)) if k < id => score.reasons.push(format!(
                "{label}scene {name}: lost because checkpoint {k} is wrong (its unit tests fail); fix checkpoint {k} first ({why})"
            )),
            _ => {
                score.blamed = true;
                score.reasons.push(format!("{label}scene {name}: {why}"));
            }
        }
    }
    if !part.scenes.is_empty() {
        score.image_score = part.image_points * kept as f64 / part.scenes.len() as f64;
    }
    score
}

/// "ssim: got 0.9120, needs >= 0.9900, ..." for the checks that failed.
fn failed_checks(s: &SceneResult) -> String {
    let failed: Vec<String> = s
        .checks
        .iter()
        .filter(|(_, m)| !m.passed)
        .map(|(c, m)| match (&s.tiles, c.metric) {
            (Some(v), Metric::TileTest) => {
                let tile = s.scene.tile_test.as_ref().map_or(1, |t| t.tile);
                let (x, y) = tile_origin(v.failures[0].tile, tile, s.reference.width());
                format!(
                    "tile test: {} of {} tiles differ from the reference beyond their noise; the first, at pixels ({x}, {y}) to ({}, {}): {}",
                    v.failures.len(),
                    v.tile_p.len(),
                    x + tile - 1,
                    y + tile - 1,
                    v.failures[0].reason
                )
            }
            _ => format!("{}: got {:.4}, needs {}", c.label(), m.value, c.threshold_text()),
        })
        .collect();
    failed.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

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
            error: Some("render differs".to_string()),
            seconds: 0.0,
            render: None,
            reference: RgbImage::new(1, 1),
            ssim: None,
            tiles: None,
        }
    }

    /// Every checkpoint's tests passing, but those `failing` (one of five fails).
    fn runs(failing: impl Fn(u32) -> bool) -> TestRuns {
        let run =
            |id| TestRun { passed: 5 - failing(id) as u32, failed: failing(id) as u32, ..TestRun::default() };
        TestRuns { public: (1..=9).map(|id| (id, run(id))).collect(), hidden: BTreeMap::new() }
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
            .map(|c| score_checkpoint(c, Some(tests), stubbed, scenes, Blame::Culprit))
            .collect()
    }

    /// A bug in checkpoint 2 fails every scene; each lost point names checkpoint 2, and only
    /// checkpoint 2 gets advice.
    #[test]
    fn grader_blames_every_failed_scene_on_the_lowest_checkpoint_whose_tests_fail() {
        let rubric = rubric();
        let tests = runs(|id| id == 2);
        let scenes: Vec<SceneResult> = rubric.scenes.iter().map(|s| failed_scene(&rubric, &s.name)).collect();
        for c in scored(&rubric, &tests, &[], &scenes) {
            let image_reasons: Vec<&String> = c.reasons.iter().filter(|r| r.starts_with("scene")).collect();
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
            assert!(c.advice.as_deref().is_some_and(|a| a.starts_with("Not started")), "{:?}", c.advice);
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
        tests.hidden.insert(6, TestRun { passed: 1, failed: 1, ..TestRun::default() });
        let passed = |name: &str| SceneResult { error: None, ..failed_scene(&rubric, name) };
        let scenes: Vec<SceneResult> = rubric
            .scenes
            .iter()
            .map(|s| if s.hidden { failed_scene(&rubric, &s.name) } else { passed(&s.name) })
            .collect();
        let result = score_checkpoint(six, Some(&tests), &[], &scenes, Blame::Culprit);
        assert_eq!(result.image_score, six.image_points);
        assert_eq!(result.test_score, six.test_points + hidden.test_points / 2.0);
        assert_eq!(result.max_score(true), six.all_test_points() + six.all_image_points());
        assert!(
            result.reasons.iter().any(|r| r.starts_with("hidden unit tests: 1 of 2 failed")),
            "{:?}",
            result.reasons
        );
        assert!(result.reasons.iter().any(|r| r.starts_with("hidden scene ")), "{:?}", result.reasons);
        assert_eq!(result.tests_cell(), "5/5 + hidden 1/2");
    }

    /// Checkpoint 2 graded alone, the solution everywhere else: its bug fails every scene and
    /// checkpoint 5's tests, and the scenes cost checkpoint 2 all the same, saying why; the
    /// culprit rule would have kept them (a later checkpoint's tests fail).
    #[test]
    fn grader_blames_the_only_checkpoint_of_the_student_in_an_isolated_grade() {
        let rubric = rubric();
        let two = rubric.checkpoints.iter().find(|c| c.id == 2).unwrap();
        let tests = runs(|id| id == 5);
        let scenes: Vec<SceneResult> = rubric.scenes.iter().map(|s| failed_scene(&rubric, &s.name)).collect();
        let culprit = score_checkpoint(two, Some(&tests), &[3, 4], &scenes, Blame::Culprit);
        let isolated = score_checkpoint(two, Some(&tests), &[3, 4], &scenes, Blame::Isolated);
        assert_eq!(culprit.image_score, two.image_points);
        assert_eq!(isolated.image_score, 0.0);
        assert!(isolated.advice.is_some());
        assert!(
            isolated.reasons.iter().any(|r| r.contains("checkpoint 5's tests fail with your checkpoint 2")),
            "{:?}",
            isolated.reasons
        );
        assert!(isolated.reasons.iter().all(|r| !r.contains("not started")), "{:?}", isolated.reasons);
    }
}
