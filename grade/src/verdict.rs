//! Why a checkpoint lost points, why a failed scene costs it nothing, and what its student should
//! do, as values. [`crate::grading::points`] computes them; [`crate::report`] words them (text,
//! HTML, Gradescope JSON) and is the only place that does.

use std::path::PathBuf;

use crate::fingerprint::Naming;
use crate::noisy::TileFailure;
use crate::rubric::Check;
use crate::run::unit_tests::TestsFailure;
use crate::scene_failure::SceneFailure;

/// Which of a checkpoint's checks a reason is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The public tests and scenes, which the student has.
    Public,
    /// The instructor's hidden ones.
    Hidden,
}

/// One reason a checkpoint lost points.
#[derive(Clone, Debug, PartialEq)]
pub enum Reason {
    /// Its regions are all still the starter's stub.
    NotStarted,
    /// A region was rejected by the allow list: graded with the starter's stub in its place, or,
    /// in the student's `own_tree`, as written here but with the stub by the instructor's grader.
    RegionRejected {
        /// Whether this is the student's own tree.
        own_tree: bool,
    },
    /// Some failed tests wait for checkpoints not written yet and are left out.
    TestsWait {
        /// Public or hidden tests.
        part: Part,
        /// How many wait.
        waiting: usize,
        /// How many tests ran.
        of: u32,
        /// The checkpoints they wait for.
        checkpoints: Vec<u32>,
    },
    /// The tests could not run: why (a compiler error, a time limit).
    TestsDidNotRun {
        /// Public or hidden tests.
        part: Part,
        /// What went wrong.
        error: TestsFailure,
    },
    /// Tests failed.
    TestsFailed {
        /// Public or hidden tests.
        part: Part,
        /// How many failed (those waiting left out).
        failed: usize,
        /// Of how many counted.
        of: usize,
        /// The names of the failed tests, in the order they ran.
        names: Vec<String>,
    },
    /// The checkpoint's test filter ran no test.
    NoTests {
        /// Public or hidden tests.
        part: Part,
        /// The `cargo test` filter.
        filter: String,
    },
    /// A scene it grades failed and costs it its points.
    SceneLost {
        /// Public or hidden scene.
        part: Part,
        /// The scene's name.
        scene: String,
        /// Who is to blame, and why the scene failed.
        loss: Loss,
    },
    /// The lost scene looks like a known mistake ([`crate::fingerprint`]).
    LooksLike {
        /// The scene's name.
        scene: String,
        /// The mistake and the evidence.
        naming: Naming,
    },
}

/// Why a failed scene costs a checkpoint its points (the blame rule of
/// [`crate::grading::points`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Loss {
    /// The checkpoint's own code is to blame.
    Yours(Why),
    /// Only checkpoint `own` is the student's code in this grade, though checkpoint `other`'s
    /// tests fail with it.
    OthersFailWithYours {
        /// Why the scene failed.
        why: Why,
        /// The checkpoint whose tests also fail.
        other: u32,
        /// The student's checkpoint.
        own: u32,
    },
    /// An earlier checkpoint the scene runs is not written yet.
    UntilWritten(u32),
    /// An earlier checkpoint the scene runs is wrong (its tests fail).
    EarlierWrong {
        /// That checkpoint.
        earlier: u32,
        /// Why the scene failed.
        why: Why,
    },
    /// The checkpoint itself is not written yet.
    NotWritten(u32),
    /// The checkpoint's own tests fail.
    YourTestsFail {
        /// The checkpoint.
        own: u32,
        /// Why the scene failed.
        why: Why,
    },
}

/// Why a failed scene costs a checkpoint it grades nothing.
#[derive(Clone, Debug, PartialEq)]
pub enum Kept {
    /// The scene waits for later checkpoints not written yet, whose code it runs.
    Waiting {
        /// The checkpoint that keeps its points.
        own: u32,
        /// The checkpoints it waits for.
        waiting: Vec<u32>,
    },
    /// A later checkpoint the scene runs is wrong: it is to be fixed first.
    LaterWrong {
        /// The checkpoint that keeps its points.
        own: u32,
        /// The later checkpoint whose tests fail.
        later: u32,
        /// Why the scene failed.
        why: Why,
    },
}

/// Why a scene failed, before anyone is blamed.
#[derive(Clone, Debug, PartialEq)]
pub enum Why {
    /// It could not be rendered or compared: what went wrong.
    Error(SceneFailure),
    /// A hidden scene's checks failed: nothing more is said.
    Differs,
    /// These checks failed.
    Checks(Vec<FailedCheck>),
}

/// A check a render failed.
#[derive(Clone, Debug, PartialEq)]
pub enum FailedCheck {
    /// A metric out of its bound.
    Metric {
        /// The check.
        check: Check,
        /// The value measured.
        value: f64,
    },
    /// A noisy scene's tile test.
    Tiles {
        /// Tiles that differ beyond their noise.
        failed: usize,
        /// Tiles tested.
        of: usize,
        /// The first failed tile's pixels: left, top, right, bottom (inclusive).
        first: [u32; 4],
        /// How the first failed tile differs.
        first_failure: TileFailure,
    },
}

/// What a checkpoint's student should read or do, when the checkpoint itself is to blame.
#[derive(Clone, Debug, PartialEq)]
pub enum Advice {
    /// Not started: read the handout first.
    NotStarted {
        /// The checkpoint's handout.
        handout: PathBuf,
    },
    /// The checkpoint's hint and its handout's section on common mistakes.
    Hint,
}
