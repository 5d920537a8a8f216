//! The rubric: what each checkpoint is worth and what grades it, loaded from
//! `checkpoints/rubric.toml` into typed structs and checked.
//!
//! A checkpoint earns `test_points` in proportion to its unit tests passing (`cargo test
//! <test_filter>`), and `image_points` in proportion to the graded scenes naming it that pass every
//! check. A scene is rendered with the code as it stands and compared with its reference image;
//! see [`Check`] for the metrics.
//!
//! **Hidden checks.** The instructor's tree may add `hidden/rubric.toml`: more tests and scenes
//! per checkpoint, worth points of their own, that the student starter does not ship (`cargo
//! xtask starter` leaves out `hidden/` and `tests/hidden/`). [`Rubric::of_tree`] merges them in:
//! a hidden scene is graded like a public one, against `hidden/reference/`, and reports show it by
//! name and result but never its images.

use std::path::{Path, PathBuf};

use serde::Deserialize;

mod rules;

use crate::file_error::{read_toml, FileError};

pub use rules::RuleBroken;

/// The whole rubric.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rubric {
    /// The checkpoints, in order.
    #[serde(rename = "checkpoint")]
    pub checkpoints: Vec<Checkpoint>,
    /// The graded scenes.
    #[serde(rename = "scene")]
    pub scenes: Vec<GradedScene>,
}

/// One checkpoint.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Checkpoint {
    /// 1, 2, 3, ... in order.
    pub id: u32,
    /// Short title.
    pub title: String,
    /// Points for the unit tests.
    pub test_points: f64,
    /// Points for the graded scenes.
    #[serde(default)]
    pub image_points: f64,
    /// The `cargo test` filter that runs exactly this checkpoint's tests.
    pub test_filter: String,
    /// One sentence pointing a student who fails in the right direction.
    pub hint: String,
    /// The handout, relative to the repository root.
    pub handout: PathBuf,
    /// Tests (by function name) that run first, in this order: those whose failure names a common
    /// mistake most plainly. The first of them that fails is the one a student is shown first.
    #[serde(default)]
    pub tests_first: Vec<String>,
    /// An extra (the global-illumination checkpoints): graded and reported like the others, but
    /// its points are not in the total. Set it to `false` to count them.
    #[serde(default)]
    pub extra: bool,
    /// The modules of the renderer (`crate::...`) its regions may name: the student API its
    /// handout works with. Every module of the student API if not given (the extras).
    #[serde(default)]
    pub student_api: Option<Vec<String>>,
    /// The instructor's hidden checks of this checkpoint, if any (from `hidden/rubric.toml`).
    #[serde(skip)]
    pub hidden: Option<HiddenChecks>,
}

impl Checkpoint {
    /// Points for unit tests, hidden ones included.
    pub fn all_test_points(&self) -> f64 {
        self.test_points + self.hidden.as_ref().map_or(0.0, |h| h.test_points)
    }

    /// Points for scenes, hidden ones included.
    pub fn all_image_points(&self) -> f64 {
        self.image_points + self.hidden.as_ref().map_or(0.0, |h| h.image_points)
    }
}

/// A checkpoint's hidden checks: tests and scenes the student never sees, worth points of their
/// own beside the public ones.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HiddenChecks {
    /// The checkpoint.
    pub id: u32,
    /// Points for the hidden unit tests.
    #[serde(default)]
    pub test_points: f64,
    /// Points for the hidden scenes grading this checkpoint.
    #[serde(default)]
    pub image_points: f64,
    /// The `cargo test` filter of the hidden tests: it must not match a public test name (so not
    /// `checkpointN`).
    pub test_filter: Option<String>,
}

/// `hidden/rubric.toml`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
struct HiddenRubric {
    #[serde(rename = "checkpoint", default)]
    checkpoints: Vec<HiddenChecks>,
    #[serde(rename = "scene", default)]
    scenes: Vec<GradedScene>,
}

/// Where a tree keeps its rubric...
pub const RUBRIC: &str = "checkpoints/rubric.toml";
/// ...and the instructor's hidden checks.
pub const HIDDEN_RUBRIC: &str = "hidden/rubric.toml";

/// A scene the grader renders and compares.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GradedScene {
    /// Short name: the reference is `reference/<name>.png`.
    pub name: String,
    /// The scene file, relative to the repository root.
    pub file: PathBuf,
    /// Samples per pixel for the student's render.
    pub spp: u32,
    /// Samples per pixel for the reference (more for a converged one).
    pub reference_spp: u32,
    /// Seed of both renders.
    #[serde(default)]
    pub seed: u64,
    /// The checkpoints whose image points this scene carries.
    pub grades: Vec<u32>,
    /// Every checkpoint whose code rendering the scene runs (a superset of `grades`): a failure
    /// is blamed on the lowest of them whose unit tests fail.
    pub depends_on: Vec<u32>,
    /// Checkpoints among `depends_on` whose stand-ins (`raylab::fallback`) draw this scene's
    /// picture exactly as their code does: while one is still the starter's stub, the scene is
    /// rendered with its stand-in (`render --stand-ins`) and graded all the same, costing or
    /// giving that checkpoint nothing. A test renders each such scene both ways.
    #[serde(default)]
    pub stand_ins: Vec<u32>,
    /// What must hold for the scene to pass: image checks against the reference...
    #[serde(rename = "check", default)]
    pub checks: Vec<Check>,
    /// ...or, for a Monte Carlo scene, the per-tile statistical test of several renders.
    pub tile_test: Option<TileTest>,
    /// Whether it comes from `hidden/rubric.toml`: its reference lives in `hidden/reference/`,
    /// and no report shows its images.
    #[serde(skip)]
    pub hidden: bool,
}

impl GradedScene {
    /// The checks grading reports for this scene: the rubric's, or a tile test's verdict with
    /// SSIM beside it as a diagnostic.
    pub fn graded_checks(&self) -> Vec<Check> {
        match &self.tile_test {
            Some(test) => vec![Check::tile_test(test), Check::diagnostic(Metric::Ssim)],
            None => self.checks.clone(),
        }
    }
}

/// How a noisy (Monte Carlo) scene is graded: the per-tile statistical test of
/// [`crate::noisy`], whose seeds [`crate::noisy::graded_seed`] fixes in advance.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TileTest {
    /// Renders of the graded code (`K`), each at the scene's `spp`.
    pub renders: u32,
    /// Side of the square tiles, in pixels.
    pub tile: u32,
    /// The probability that a correct submission fails the scene (the family-wise error rate).
    pub alpha: f64,
    /// Renders of the reference solution at `reference_spp` whose tile means give the expected
    /// value (`R`); their average is the reference image.
    pub reference_renders: u32,
    /// Renders of the reference solution at `spp`: how noisy a correct render is.
    pub solution_renders: u32,
    /// Why these numbers: the calibration they come from.
    pub why: String,
}

/// One requirement on a render, compared with the reference.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(try_from = "CheckFile")]
pub struct Check {
    /// Which number.
    pub metric: Metric,
    /// For mask metrics: which mask.
    pub mask: Option<Mask>,
    /// What the number must be to pass.
    pub threshold: Threshold,
    /// Why this threshold: the calibration it comes from.
    pub why: String,
}

/// What a check's number must be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Threshold {
    /// At least this (similarities: `min = ...` in the rubric).
    AtLeast(f64),
    /// At most this (errors: `max = ...`).
    AtMost(f64),
    /// Shown, deciding nothing (never in a rubric: the SSIM beside a tile test).
    Diagnostic,
}

/// A check as the rubric writes it: exactly one of `min` and `max`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckFile {
    metric: Metric,
    mask: Option<Mask>,
    min: Option<f64>,
    max: Option<f64>,
    why: String,
}

/// A check written with both bounds or neither: the metric it names.
#[derive(Debug, thiserror::Error)]
#[error("a {0:?} check needs exactly one of min or max")]
pub struct NotOneBound(pub Metric);

impl TryFrom<CheckFile> for Check {
    type Error = NotOneBound;

    fn try_from(c: CheckFile) -> Result<Check, NotOneBound> {
        let threshold = match (c.min, c.max) {
            (Some(min), None) => Threshold::AtLeast(min),
            (None, Some(max)) => Threshold::AtMost(max),
            _ => return Err(NotOneBound(c.metric)),
        };
        Ok(Check { metric: c.metric, mask: c.mask, threshold, why: c.why })
    }
}

/// The numbers a check can ask for.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Mean SSIM of the whole image (scikit-image's, see [`crate::ssim`]).
    Ssim,
    /// The largest mean error of any 32 × 32 tile (see [`crate::metrics::worst_tile_error`]): a
    /// local error that a whole-image mean hides.
    WorstTileError,
    /// Mean SSIM inside a mask.
    MaskSsim,
    /// Root mean square error of linear radiance inside a mask (8-bit sRGB decoded).
    MaskRmse,
    /// The number of tiles failing a scene's [`TileTest`]; made by the grader from
    /// `[scene.tile_test]`, never written as a `[[scene.check]]`.
    TileTest,
}

/// Pixel sets derived from a feature render made with the reference solution.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum Mask {
    /// Pixels whose camera ray first meets glass.
    Glass,
    /// Pixels whose diffuse surface is hidden from at least one light.
    Shadow,
    /// Pixels where the object seen changes within the pixel's neighbourhood.
    Edge,
}

impl Check {
    /// The metric's name, with its mask: `ssim`, `mask_ssim(glass)`.
    pub fn label(&self) -> String {
        let name = match self.metric {
            Metric::Ssim => "ssim",
            Metric::WorstTileError => "worst_tile_error",
            Metric::MaskSsim => "mask_ssim",
            Metric::MaskRmse => "mask_rmse",
            Metric::TileTest => "tile_test",
        };
        match self.mask {
            Some(mask) => format!("{name}({})", format!("{mask:?}").to_lowercase()),
            None => name.to_string(),
        }
    }

    /// The check of a tile-tested scene: no tile may fail.
    pub fn tile_test(test: &TileTest) -> Check {
        Check {
            metric: Metric::TileTest,
            mask: None,
            threshold: Threshold::AtMost(0.0),
            why: test.why.clone(),
        }
    }

    /// A number shown beside the checks that decides nothing (SSIM of a noisy render).
    pub fn diagnostic(metric: Metric) -> Check {
        let why = "a diagnostic: two correct noisy renders differ, so it decides nothing".to_string();
        Check { metric, mask: None, threshold: Threshold::Diagnostic, why }
    }

    /// The threshold as text: `>= 0.990` or `<= 0.020`.
    pub fn threshold_text(&self) -> String {
        match self.threshold {
            Threshold::AtLeast(min) => format!(">= {min:.4}"),
            Threshold::AtMost(max) => format!("<= {max:.4}"),
            Threshold::Diagnostic => "diagnostic".to_string(),
        }
    }
}

impl Metric {
    /// Whether the metric needs a mask.
    pub fn needs_mask(self) -> bool {
        matches!(self, Metric::MaskSsim | Metric::MaskRmse)
    }
}

/// Why a rubric file cannot be used: it cannot be read or parsed, or it breaks a rule.
#[derive(Debug, thiserror::Error)]
pub enum RubricError {
    /// The file cannot be read or parsed.
    #[error(transparent)]
    File(#[from] FileError),
    /// The file parses but breaks a rule.
    #[error("{}: {rule}", file.display())]
    Broken {
        /// The rubric file.
        file: PathBuf,
        /// The rule broken.
        rule: RuleBroken,
    },
}

impl Rubric {
    /// The rubric of the tree at `root`: `checkpoints/rubric.toml`, with the hidden checks of
    /// `hidden/rubric.toml` merged in if the tree has them (the instructor's does, a starter not).
    pub fn of_tree(root: &Path) -> Result<Rubric, RubricError> {
        let mut rubric = Rubric::load(&root.join(RUBRIC), root)?;
        let file = root.join(HIDDEN_RUBRIC);
        if file.exists() {
            let hidden: HiddenRubric = read_toml(&file)?;
            rubric.merge_hidden(hidden, root).map_err(|rule| RubricError::Broken { file, rule })?;
        }
        Ok(rubric)
    }

    /// Loads and checks `path`.
    pub fn load(path: &Path, root: &Path) -> Result<Rubric, RubricError> {
        let rubric: Rubric = read_toml(path)?;
        rubric.validate(root).map_err(|rule| RubricError::Broken { file: path.to_path_buf(), rule })?;
        Ok(rubric)
    }

    fn merge_hidden(&mut self, hidden: HiddenRubric, root: &Path) -> Result<(), RuleBroken> {
        for h in hidden.checkpoints {
            let id = h.id;
            let checkpoint = self
                .checkpoints
                .iter_mut()
                .find(|c| c.id == id)
                .ok_or(RuleBroken::HiddenUnknownCheckpoint(id))?;
            let filter = h.test_filter.as_deref().unwrap_or_default();
            if h.test_points < 0.0 || h.image_points < 0.0 || (h.test_points > 0.0) == filter.is_empty() {
                return Err(RuleBroken::HiddenTestPoints(id));
            }
            if filter.contains("checkpoint") {
                return Err(RuleBroken::HiddenFilterTooWide { checkpoint: id, filter: filter.to_string() });
            }
            if checkpoint.hidden.replace(h).is_some() {
                return Err(RuleBroken::HiddenTwice(id));
            }
        }
        for mut scene in hidden.scenes {
            scene.hidden = true;
            self.scenes.push(scene);
        }
        self.validate(root)
    }

    /// The checks `rustlings dev check` would make: ids in order, files exist, every scene
    /// grades known checkpoints, every check is well-formed, every image point has a scene. The
    /// first rule broken, as a [`RuleBroken`] (each variant is one rule).
    pub fn validate(&self, root: &Path) -> Result<(), RuleBroken> {
        rules::check(self, root)
    }

    /// Total points counted, hidden ones included, the extras' not.
    pub fn total_points(&self) -> f64 {
        self.checkpoints.iter().filter(|c| !c.extra).map(|c| c.all_test_points() + c.all_image_points()).sum()
    }
}

#[cfg(test)]
mod tests;
