//! The rules a rubric follows, each broken rule its own error with its own message
//! ([`Rubric::validate`]): a rubric an instructor edits by hand is told exactly what is wrong,
//! and a grader never runs on a rubric that could give points no scene or test can earn.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use super::{Metric, Rubric};

/// One rule of the rubric broken: what, and where (the checkpoint or scene).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RuleBroken {
    /// Checkpoint ids are positive and increase down the rubric; a course may skip one (a
    /// checkpoint it gives as code).
    #[error("checkpoint ids must be positive and increasing, got {0:?}")]
    CheckpointIds(Vec<u32>),
    /// A checkpoint's handout must exist.
    #[error("checkpoint {checkpoint}: handout {} does not exist", .handout.display())]
    MissingHandout {
        /// The checkpoint.
        checkpoint: u32,
        /// Its handout, relative to the tree.
        handout: PathBuf,
    },
    /// A checkpoint's student API names modules of the renderer: those `src/lib.rs` declares
    /// (`pub mod`) or re-exports (`pub use`).
    #[error("checkpoint {checkpoint}: student_api names `{module}`, which src/lib.rs does not make public")]
    UnknownModule {
        /// The checkpoint.
        checkpoint: u32,
        /// The module it names.
        module: String,
    },
    /// Points are never negative.
    #[error("checkpoint {0}: points must not be negative")]
    NegativePoints(u32),
    /// Every checkpoint has a hint for a student who fails it.
    #[error("checkpoint {0}: the hint must not be empty")]
    EmptyHint(u32),
    /// Scene names are unique (a reference is named after its scene).
    #[error("scene {0} appears twice")]
    SceneTwice(String),
    /// A scene's file must exist.
    #[error("scene {scene}: {} does not exist", .file.display())]
    MissingScene {
        /// The scene.
        scene: String,
        /// Its file, relative to the tree.
        file: PathBuf,
    },
    /// A render takes at least one sample per pixel.
    #[error("scene {0}: spp must be at least 1")]
    ZeroSpp(String),
    /// The reference is rendered with at least the samples of the graded render.
    #[error("scene {0}: reference_spp must be at least spp")]
    ReferenceSpp(String),
    /// A scene grades at least one checkpoint.
    #[error("scene {0}: grades no checkpoint")]
    GradesNothing(String),
    /// A scene is judged by checks or by a tile test: exactly one of the two.
    #[error("scene {0}: needs either checks or a tile_test (exactly one)")]
    ChecksOrTileTest(String),
    /// A tile test needs 2 to 65536 renders of each kind.
    #[error("scene {0}: tile_test needs 2 to 65536 renders of each kind")]
    TileRenders(String),
    /// A tile is at least one pixel.
    #[error("scene {0}: tile_test needs a tile of at least 1 pixel")]
    TileSize(String),
    /// The family-wise error rate is a probability strictly between 0 and 1.
    #[error("scene {0}: tile_test needs 0 < alpha < 1")]
    Alpha(String),
    /// A tile-tested scene's seed leaves room for the graded seeds (`noisy::graded_seed`).
    #[error("scene {0}: a tile-tested scene needs a seed below 2^24")]
    Seed(String),
    /// A scene names only checkpoints of the rubric.
    #[error("scene {scene}: names unknown checkpoint {checkpoint}")]
    UnknownCheckpoint {
        /// The scene.
        scene: String,
        /// The checkpoint it names.
        checkpoint: u32,
    },
    /// A scene depends on every checkpoint it grades or stands in for.
    #[error("scene {scene}: grades or stands in for checkpoint {checkpoint} but does not depend on it")]
    NotDependedOn {
        /// The scene.
        scene: String,
        /// The checkpoint missing from its `depends_on`.
        checkpoint: u32,
    },
    /// A check has a mask exactly when its metric is a mask metric.
    #[error("scene {scene}: a {metric:?} check needs a mask exactly when its metric is a mask metric")]
    Mask {
        /// The scene.
        scene: String,
        /// The check's metric.
        metric: Metric,
    },
    /// A tile test is written as `[scene.tile_test]`, never as a check.
    #[error("scene {0}: a tile test is a [scene.tile_test], not a check")]
    TileTestAsCheck(String),
    /// The hidden rubric adds checks to checkpoints of the public one only.
    #[error("checkpoint {0} is not in {RUBRIC}", RUBRIC = super::RUBRIC)]
    HiddenUnknownCheckpoint(u32),
    /// A checkpoint has one entry in the hidden rubric at most.
    #[error("checkpoint {0} appears twice")]
    HiddenTwice(u32),
    /// Hidden points are never negative, and a hidden test filter is given exactly when there
    /// are hidden test points.
    #[error("checkpoint {0}: points must not be negative, and a test_filter given exactly for test points")]
    HiddenTestPoints(u32),
    /// A hidden test filter matches hidden tests only (`hidden3_...`), never public ones.
    #[error("checkpoint {checkpoint}: test_filter {filter:?} would also match public tests; name hidden tests `hidden{checkpoint}_...`")]
    HiddenFilterTooWide {
        /// The checkpoint.
        checkpoint: u32,
        /// Its hidden test filter.
        filter: String,
    },
    /// A checkpoint has image points exactly when some scene grades it (public and hidden apart).
    #[error("checkpoint {checkpoint}: {}image points and {}scenes grading it go together", hidden_word(*.hidden), hidden_word(*.hidden))]
    PointsWithoutScenes {
        /// The checkpoint.
        checkpoint: u32,
        /// Whether it is about the hidden checks.
        hidden: bool,
    },
}

fn hidden_word(hidden: bool) -> &'static str {
    if hidden {
        "hidden "
    } else {
        ""
    }
}

/// The names of the `pub mod` and `pub use` lines of `lib` (a crate root): its public modules
/// and what it re-exports.
fn public_modules(lib: &str) -> BTreeSet<&str> {
    let lines = lib.lines().filter_map(|l| l.strip_prefix("pub mod ").or_else(|| l.strip_prefix("pub use ")));
    lines
        .flat_map(|l| l.split(|c: char| !(c.is_alphanumeric() || c == '_')))
        .filter(|w| !w.is_empty())
        .collect()
}

/// The first rule `rubric` breaks in the tree at `root`, checkpoints first, then scene by scene.
pub(super) fn check(rubric: &Rubric, root: &Path) -> Result<(), RuleBroken> {
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    if ids.first() == Some(&0) || ids.windows(2).any(|w| w[0] >= w[1]) {
        return Err(RuleBroken::CheckpointIds(ids));
    }
    let lib = std::fs::read_to_string(root.join("src/lib.rs")).unwrap_or_default();
    let public = public_modules(&lib);
    for c in &rubric.checkpoints {
        if !root.join(&c.handout).is_file() {
            return Err(RuleBroken::MissingHandout { checkpoint: c.id, handout: c.handout.clone() });
        }
        if let Some(module) = c.student_api.iter().flatten().find(|m| !public.contains(m.as_str())) {
            return Err(RuleBroken::UnknownModule { checkpoint: c.id, module: module.clone() });
        }
        if c.test_points < 0.0 || c.image_points < 0.0 {
            return Err(RuleBroken::NegativePoints(c.id));
        }
        if c.hint.trim().is_empty() {
            return Err(RuleBroken::EmptyHint(c.id));
        }
    }
    let mut names = BTreeSet::new();
    for s in &rubric.scenes {
        if !names.insert(&s.name) {
            return Err(RuleBroken::SceneTwice(s.name.clone()));
        }
        check_scene(s, &ids, root)?;
    }
    let graded: BTreeSet<(u32, bool)> =
        rubric.scenes.iter().flat_map(|s| s.grades.iter().map(move |&g| (g, s.hidden))).collect();
    for c in &rubric.checkpoints {
        let hidden_points = c.hidden.as_ref().map_or(0.0, |h| h.image_points);
        for (points, hidden) in [(c.image_points, false), (hidden_points, true)] {
            if (points > 0.0) != graded.contains(&(c.id, hidden)) {
                return Err(RuleBroken::PointsWithoutScenes { checkpoint: c.id, hidden });
            }
        }
    }
    Ok(())
}

/// The rules of one scene, given the rubric's checkpoint ids.
fn check_scene(s: &super::GradedScene, ids: &[u32], root: &Path) -> Result<(), RuleBroken> {
    let scene = || s.name.clone();
    if !root.join(&s.file).is_file() {
        return Err(RuleBroken::MissingScene { scene: scene(), file: s.file.clone() });
    }
    if s.spp == 0 {
        return Err(RuleBroken::ZeroSpp(scene()));
    }
    if s.reference_spp < s.spp {
        return Err(RuleBroken::ReferenceSpp(scene()));
    }
    if s.grades.is_empty() {
        return Err(RuleBroken::GradesNothing(scene()));
    }
    if s.checks.is_empty() == s.tile_test.is_none() {
        return Err(RuleBroken::ChecksOrTileTest(scene()));
    }
    if let Some(t) = &s.tile_test {
        let renders = [t.renders, t.reference_renders, t.solution_renders];
        if renders.iter().any(|&r| !(2..=1 << 16).contains(&r)) {
            return Err(RuleBroken::TileRenders(scene()));
        }
        if t.tile == 0 {
            return Err(RuleBroken::TileSize(scene()));
        }
        if !(t.alpha > 0.0 && t.alpha < 1.0) {
            return Err(RuleBroken::Alpha(scene()));
        }
        if s.seed >= 1 << 24 {
            return Err(RuleBroken::Seed(scene()));
        }
    }
    if let Some(&g) = s.grades.iter().chain(&s.depends_on).find(|g| !ids.contains(g)) {
        return Err(RuleBroken::UnknownCheckpoint { scene: scene(), checkpoint: g });
    }
    if let Some(&g) = s.grades.iter().chain(&s.stand_ins).find(|g| !s.depends_on.contains(g)) {
        return Err(RuleBroken::NotDependedOn { scene: scene(), checkpoint: g });
    }
    for check in &s.checks {
        let metric = check.metric;
        if metric == Metric::TileTest {
            return Err(RuleBroken::TileTestAsCheck(scene()));
        }
        if metric.needs_mask() != check.mask.is_some() {
            return Err(RuleBroken::Mask { scene: scene(), metric });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::GradedScene;
    use super::*;

    fn root() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
    }

    /// The instructor's rubric (hidden checks merged in) with one change: the rule it breaks.
    fn broken(change: impl FnOnce(&mut Rubric)) -> Option<RuleBroken> {
        let mut rubric = Rubric::of_tree(&root()).expect("the tree's rubric is valid");
        change(&mut rubric);
        rubric.validate(&root()).err()
    }

    /// The first scene judged by checks, and the first judged by a tile test.
    fn checked(r: &mut Rubric) -> &mut GradedScene {
        r.scenes.iter_mut().find(|s| !s.checks.is_empty() && !s.hidden).expect("a scene with checks")
    }

    fn tiled(r: &mut Rubric) -> &mut GradedScene {
        r.scenes.iter_mut().find(|s| s.tile_test.is_some()).expect("a tile-tested scene")
    }

    fn tile_test(r: &mut Rubric) -> &mut crate::rubric::TileTest {
        tiled(r).tile_test.as_mut().unwrap()
    }

    type Change = Box<dyn FnOnce(&mut Rubric)>;
    type Case = (Change, fn(&RuleBroken) -> bool);

    /// One change of the instructor's rubric per rule of [`Rubric::validate`], and the error it
    /// must give (the hidden part's rules are tested in `rubric::tests`, where it is merged).
    fn each_rule_broken() -> Vec<Case> {
        vec![
            (Box::new(|r| r.checkpoints.swap(0, 1)), |e| matches!(e, RuleBroken::CheckpointIds(_))),
            (Box::new(|r| r.checkpoints[0].handout = "checkpoints/none.md".into()), |e| {
                matches!(e, RuleBroken::MissingHandout { checkpoint: 1, .. })
            }),
            (Box::new(|r| r.checkpoints[1].student_api = Some(vec!["geometery".into()])), |e| {
                matches!(e, RuleBroken::UnknownModule { checkpoint: 2, .. })
            }),
            (Box::new(|r| r.checkpoints[1].test_points = -1.0), |e| *e == RuleBroken::NegativePoints(2)),
            (Box::new(|r| r.checkpoints[1].hint = " ".into()), |e| *e == RuleBroken::EmptyHint(2)),
            (Box::new(|r| r.scenes.push(r.scenes[0].clone())), |e| matches!(e, RuleBroken::SceneTwice(_))),
            (Box::new(|r| checked(r).file = "scenes/none.toml".into()), |e| {
                matches!(e, RuleBroken::MissingScene { .. })
            }),
            (Box::new(|r| checked(r).spp = 0), |e| matches!(e, RuleBroken::ZeroSpp(_))),
            (Box::new(|r| (checked(r).spp, checked(r).reference_spp) = (2, 1)), |e| {
                matches!(e, RuleBroken::ReferenceSpp(_))
            }),
            (Box::new(|r| checked(r).grades.clear()), |e| matches!(e, RuleBroken::GradesNothing(_))),
            (Box::new(|r| checked(r).checks.clear()), |e| matches!(e, RuleBroken::ChecksOrTileTest(_))),
            (Box::new(|r| tile_test(r).solution_renders = 1), |e| matches!(e, RuleBroken::TileRenders(_))),
            (Box::new(|r| tile_test(r).tile = 0), |e| matches!(e, RuleBroken::TileSize(_))),
            (Box::new(|r| tile_test(r).alpha = 1.0), |e| matches!(e, RuleBroken::Alpha(_))),
            (Box::new(|r| tiled(r).seed = 1 << 24), |e| matches!(e, RuleBroken::Seed(_))),
            (Box::new(|r| checked(r).depends_on.push(99)), |e| {
                matches!(e, RuleBroken::UnknownCheckpoint { checkpoint: 99, .. })
            }),
            (
                Box::new(|r| {
                    let s = checked(r);
                    let graded = s.grades[0];
                    s.depends_on.retain(|&d| d != graded);
                }),
                |e| matches!(e, RuleBroken::NotDependedOn { .. }),
            ),
            (
                Box::new(|r| {
                    let masked = r.scenes.iter_mut().flat_map(|s| &mut s.checks).find(|c| c.mask.is_some());
                    masked.expect("a masked check").mask = None;
                }),
                |e| matches!(e, RuleBroken::Mask { .. }),
            ),
            (Box::new(|r| checked(r).checks[0].metric = Metric::TileTest), |e| {
                matches!(e, RuleBroken::TileTestAsCheck(_))
            }),
            (Box::new(|r| r.scenes.retain(|s| s.hidden || !s.grades.contains(&2))), |e| {
                *e == RuleBroken::PointsWithoutScenes { checkpoint: 2, hidden: false }
            }),
            (Box::new(|r| r.scenes.retain(|s| !s.hidden)), |e| {
                matches!(e, RuleBroken::PointsWithoutScenes { hidden: true, .. })
            }),
        ]
    }

    /// Each rule, broken alone in the instructor's rubric, gives its own error, and no two rules
    /// share a message.
    #[test]
    fn each_rule_broken_alone_gives_its_own_error() {
        let cases = each_rule_broken();
        let mut variants = Vec::new();
        let cases_run = cases.len();
        for (i, (change, expected)) in cases.into_iter().enumerate() {
            let error = broken(change).unwrap_or_else(|| panic!("case {i}: no rule broken"));
            assert!(expected(&error), "case {i}: got {error:?}");
            variants.push(std::mem::discriminant(&error));
        }
        let distinct = variants.iter().enumerate().filter(|(i, v)| !variants[..*i].contains(v)).count();
        // The last two cases break the same rule (image points without scenes), public and hidden.
        assert_eq!(distinct, cases_run - 1, "each other case is its own rule");
        assert_eq!(broken(|_| {}), None, "the instructor's rubric itself breaks no rule");
    }

    /// A course may skip a checkpoint (ids 1 to 6, then 8): ids only have to be positive and to
    /// increase.
    #[test]
    fn checkpoint_ids_may_skip_one_but_never_repeat_go_back_or_start_at_zero() {
        let ids_broken =
            |change: fn(&mut Rubric)| matches!(broken(change), Some(RuleBroken::CheckpointIds(_)));
        assert!(!ids_broken(|r| r.checkpoints.iter_mut().skip(6).for_each(|c| c.id += 1)));
        assert!(ids_broken(|r| r.checkpoints[0].id = 0));
        assert!(ids_broken(|r| r.checkpoints[2].id = 2));
        assert!(ids_broken(|r| r.checkpoints.swap(3, 4)));
    }
}
