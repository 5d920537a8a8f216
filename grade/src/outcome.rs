//! What grading finds: per scene, per checkpoint and for the whole run, as values.
//!
//! [`crate::grading`] fills them in, [`crate::grading::points`] scores them, [`crate::report`] and
//! [`crate::report::html`] word them.

use image::RgbImage;

use crate::fingerprint::{Evidence, Naming, TileSignature};
use crate::metrics::Measured;
use crate::noisy::NoisyVerdict;
use crate::rubric::{Check, Checkpoint, GradedScene};
use crate::run::unit_tests::TestRun;
use crate::scene_failure::SceneFailure;
use crate::ssim::SsimMap;
use crate::verdict::{Advice, Kept, Reason};

/// Who can have made a failed scene fail ([`crate::grading::points`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blame {
    /// Every region runs the tree's own code: the lowest checkpoint whose tests fail.
    Culprit,
    /// Only the selected checkpoints' regions run a submission's code, the solution's everywhere
    /// else: the selected checkpoint.
    Isolated,
}

/// The outcome of one graded scene.
#[derive(Clone, Debug)]
pub struct SceneResult {
    /// The scene.
    pub scene: GradedScene,
    /// Each check with its value; empty if the render failed.
    pub checks: Vec<(Check, Measured)>,
    /// Why the scene scored 0 without checks (crash, time limit, size mismatch).
    pub error: Option<SceneFailure>,
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
    /// The checkpoints not written yet whose stand-ins drew it (see `GradedScene::stand_ins`).
    pub stand_ins: Vec<u32>,
    /// What its row says, once the checkpoints are scored.
    pub status: SceneStatus,
    /// The known mistake a failed render looks like, if one is clearly named
    /// ([`crate::fingerprint`]).
    pub named: Option<Naming>,
}

/// What a scene's row says ([`crate::grading::points::scene_status`]).
#[derive(Clone, Debug, PartialEq)]
pub enum SceneStatus {
    /// Every check passed.
    Passed,
    /// It cost a graded checkpoint points.
    Failed,
    /// It failed, but costs the graded checkpoints nothing: why (a later checkpoint is not
    /// written yet, or is wrong).
    NotCounted(Kept),
}

impl SceneStatus {
    /// The word of its row: `pass`, `FAIL`, or `-` (not counted).
    pub fn word(&self) -> &'static str {
        match self {
            SceneStatus::Passed => "pass",
            SceneStatus::Failed => "FAIL",
            SceneStatus::NotCounted(_) => "-",
        }
    }
}

impl SceneResult {
    /// For a tile-tested scene, the tile means of its renders and the reference's expected ones,
    /// as signatures ([`crate::fingerprint::tiles`]).
    pub fn tile_signatures(&self) -> Option<(TileSignature, TileSignature)> {
        let (verdict, test) = self.tiles.as_ref().zip(self.scene.tile_test.as_ref())?;
        let across = self.reference.width().div_ceil(test.tile);
        Some((TileSignature::of(&verdict.yours, across), TileSignature::of(&verdict.expected, across)))
    }

    /// What naming a mistake compares this failed scene by: the tile signatures `tiles` of a
    /// tile-tested scene, else its render's picture; `None` without a render.
    pub fn evidence<'a>(&'a self, tiles: &'a Option<(TileSignature, TileSignature)>) -> Option<Evidence<'a>> {
        Some(match tiles {
            Some((mine, expected)) => Evidence::Tiles { mine, expected },
            None => Evidence::Picture { render: self.render.as_ref()?, reference: &self.reference },
        })
    }

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
    /// How many of its (public) tests wait for a checkpoint not written yet, left out of its
    /// fraction ([`crate::grading::points`]).
    pub waiting: usize,
    /// Points from the unit tests, hidden ones included.
    pub test_score: f64,
    /// Points from the scenes, hidden ones included.
    pub image_score: f64,
    /// Why points were lost, one line each.
    pub reasons: Vec<Reason>,
    /// What to read or fix, when this checkpoint itself is to blame: its hint and handout, or
    /// "not started". `None` when it lost nothing or only lost points to another checkpoint.
    pub advice: Option<Advice>,
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

    /// The unit tests passed, as a table cell: `9/10`, with those waiting for another
    /// checkpoint (`7/8 + 2 wait`) and the hidden ones beside: `9/10 + hidden 2/3`.
    pub fn tests_cell(&self) -> String {
        let cell = |t: &TestRun, waiting: usize| match (&t.error, waiting) {
            (None, 0) => format!("{}/{}", t.passed, t.passed + t.failed),
            (None, w) => format!("{}/{} + {w} wait", t.passed, t.passed as usize + t.failed as usize - w),
            (Some(_), _) => "error".to_string(),
        };
        match (&self.tests, &self.hidden_tests) {
            (Some(t), Some(h)) => format!("{} + hidden {}", cell(t, self.waiting), cell(h, 0)),
            (Some(t), None) => cell(t, self.waiting),
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
    /// The checkpoints not graded here whose code a graded scene runs: their tests ran (or were
    /// skipped, not written yet) only to say who is to blame; they change no points.
    pub needed: Vec<Needed>,
    /// Wall-clock seconds of the whole run.
    pub seconds: f64,
    /// ...and of its phases.
    pub phases: Phases,
}

/// A checkpoint not graded whose code a graded scene runs ([`GradeReport::needed`]).
#[derive(Clone, Debug)]
pub struct Needed {
    /// The checkpoint.
    pub checkpoint: Checkpoint,
    /// Its unit tests, if they ran (not when it is not written yet).
    pub tests: Option<TestRun>,
    /// Whether its regions are all still the starter's stubs.
    pub not_started: bool,
}

impl Needed {
    /// Its state in words: not written yet, or what its tests say.
    pub fn state(&self) -> String {
        match (&self.tests, self.not_started) {
            (_, true) => "not written yet".to_string(),
            (Some(t), false) if t.error.is_none() && t.failed == 0 => {
                format!("tests {}/{} pass", t.passed, t.passed)
            }
            (Some(t), false) if t.error.is_none() => format!(
                "tests {}/{} pass: `cargo test {}` says which fail",
                t.passed,
                t.passed + t.failed,
                self.checkpoint.test_filter
            ),
            (Some(_), false) => "its tests could not run".to_string(),
            (None, false) => "tests not run".to_string(),
        }
    }
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
        // Folded from +0: an empty `sum` of floats is -0, which prints as "-0".
        self.counted(false).fold(0.0, |s, c| s + c.score())
    }

    /// Points available, the extras' not included.
    pub fn max_score(&self) -> f64 {
        self.counted(false).fold(0.0, |m, c| m + c.max_score(self.tests_ran))
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
                serde_json::json!({"error": s.error.as_ref().map(|e| e.to_string()), "passed": s.passed(), "checks": checks}),
            )
        });
        serde_json::Value::Object(scenes.collect())
    }
}
