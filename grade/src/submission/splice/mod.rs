//! A submission graded from the instructor's tree: only the text of its solution regions is
//! taken, spliced into a scratch copy of the instructor's pristine tree, and graded there with the
//! instructor's tests, rubric, scenes and references.
//!
//! **Matching.** Each region of the instructor's tree is found in the submission by its file, its
//! checkpoint and the function whose body it is. A region whose markers were moved, renamed or
//! deleted, or whose file is gone, is "not found" and counts as not done; a region still the
//! starter's stub is "not started"; a region that fails the allow list ([`crate::regions::allow`]) is
//! "rejected" with its file and line. In all three cases the starter's stub stands in its place.
//! Everything else in the submission (tests, rubric, references, manifests, build scripts, new
//! files, other functions) is ignored and listed.
//!
//! **Both versions in one build.** Every region of the scratch tree holds the submission's body
//! and the solution's, chosen at run time per checkpoint:
//! `if crate::graded::student(N) { submission } else { solution }`, where `student` reads the
//! environment variable [`STUDENT_ENV`] (`"2,3"`) once. One build then grades each checkpoint on
//! its own (its own regions from the submission, the solution everywhere else) and the whole
//! submission (every region from it). Region code cannot reach the solution's body: it sits
//! inline in the same function, and the allow list rejects every path through `graded`.

use std::path::{Path, PathBuf};

use std::collections::BTreeMap;

use crate::file_error::FileError;
use crate::plain::{kind, read_text, FileKind, NotRead, MAX_FILE_BYTES};
use crate::reference::REFERENCE_DIRS;
use crate::regions::allow::{check_region, Refusal, StudentApi};
use crate::regions::baseline::{ignored_files, Baseline};
use crate::regions::lexer::{line_at, LexError};
use crate::regions::markers::{checkpoints_in, find_regions, Found, Region};
use crate::regions::stub::{is_stub, region_bodies, region_function, stub_regions};
use crate::run::build_error::CompileError;
use crate::submission::scratch::{copy_tree, write_if_changed};

/// The renderer's crate root, which the scratch tree extends with the `graded` module.
const LIB: &str = "src/lib.rs";

/// The environment variable naming the checkpoints whose regions run the submission's code.
pub const STUDENT_ENV: &str = "RAYLAB_GRADED_STUDENT";

/// Test builds of the grader only: a region holding the token this variable names is taken
/// without the allow list, so the hostile suite can show what the sandbox stops when the checker
/// has a hole ([`crate::instructor::fixture::UNCHECKED`]). Release builds have no such door.
pub const UNCHECKED_ENV: &str = "RAYLAB_UNCHECKED_TOKEN";

/// Whether `body` is taken without the allow list (see [`UNCHECKED_ENV`]).
fn unchecked(body: &str) -> bool {
    cfg!(debug_assertions) && std::env::var(UNCHECKED_ENV).is_ok_and(|t| t.len() >= 16 && body.contains(&t))
}

/// What the submission has for a region.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Taken {
    /// Its own code, which passed the allow list.
    Code(String),
    /// Still the starter's stub.
    NotStarted,
    /// No region for this function in this file: why.
    NotFound(Unfound),
    /// Code that failed the allow list: the first thing refused, at its line in the file.
    Rejected {
        /// The line in the file, from 1.
        line: usize,
        /// What was refused.
        reason: Refusal,
    },
    /// Code that does not compile, replaced by the stub so the rest can be graded.
    DoesNotCompile(NotCompiling),
}

/// Why a submission has no region for a function.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Unfound {
    /// A folder on the way to the file is something else (a link): its path, and what it is.
    NotPlain(PathBuf, &'static str),
    /// The file is not there.
    Missing(PathBuf),
    /// The file is there but was not read (too large, not UTF-8, not a plain file).
    NotRead(PathBuf, NotRead),
    /// The file does not lex as Rust (a string or comment that never ends) at this line.
    NotRust(PathBuf, usize, LexError),
    /// The file has no region of this checkpoint in this function.
    NoRegion(u32, String),
}

impl std::fmt::Display for Unfound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unfound::NotPlain(path, what) => {
                write!(f, "{} is {what}: only plain files and folders are read", path.display())
            }
            Unfound::Missing(file) => write!(f, "{} is missing", file.display()),
            Unfound::NotRead(file, why) => write!(f, "{}: {why}", file.display()),
            Unfound::NotRust(file, line, e) => {
                write!(f, "{}:{line}: {e}: the file cannot be read as Rust", file.display())
            }
            Unfound::NoRegion(checkpoint, function) => write!(
                f,
                "no `// BEGIN SOLUTION checkpoint{checkpoint}` region in `{function}`: were its markers moved, renamed or deleted?"
            ),
        }
    }
}

/// Why a region's own code was replaced by its stub.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotCompiling {
    /// The compiler's first error is in this region.
    Here(CompileError),
    /// With the submission's code the tree does not build, by an error in a file that is not the
    /// student's (a hidden test, the instructor's code), of which only its heading (`error[E0308]`)
    /// may be said.
    Elsewhere {
        /// `error[E0308]`, or `error`.
        heading: String,
    },
}

impl std::fmt::Display for NotCompiling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotCompiling::Here(error) => write!(f, "{error}"),
            NotCompiling::Elsewhere { heading } => write!(
                f,
                "with your code the tree does not build: {heading} in a file that is not yours, which is not shown"
            ),
        }
    }
}

/// The regions taken from a submission, and what was ignored.
#[derive(Clone, Debug)]
pub struct Submission {
    /// Every region of the instructor's tree, with what the submission has for it.
    pub regions: Vec<(Region, Taken)>,
    /// Files of the submission that differ from the starter outside the regions: ignored.
    pub ignored: Vec<String>,
}

impl Submission {
    /// Checkpoints with regions none of which holds code of the submission's own.
    pub fn not_started(&self) -> Vec<u32> {
        let mut ids: Vec<u32> = self.regions.iter().map(|(r, _)| r.checkpoint).collect();
        ids.sort();
        ids.dedup();
        ids.retain(|&id| self.regions.iter().all(|(r, t)| r.checkpoint != id || *t == Taken::NotStarted));
        ids
    }

    /// Checkpoints with a rejected region: they score 0.
    pub fn rejected(&self) -> Vec<u32> {
        let mut ids: Vec<u32> = self
            .regions
            .iter()
            .filter(|(_, t)| matches!(t, Taken::Rejected { .. }))
            .map(|(r, _)| r.checkpoint)
            .collect();
        ids.sort();
        ids.dedup();
        ids
    }

    /// One line per region that is not the submission's own code, for the report.
    pub fn notes(&self) -> Vec<String> {
        let noted = |(_, t): &&(Region, Taken)| !matches!(t, Taken::Code(_) | Taken::NotStarted);
        self.regions.iter().filter(noted).map(|(r, t)| r.line(t)).collect()
    }
}

impl Region {
    /// One line of a report: the region, and what the submission has for it.
    pub fn line(&self, taken: &Taken) -> String {
        let what = format!("{} `{}` (checkpoint {})", self.file.display(), self.function, self.checkpoint);
        match taken {
            Taken::Code(_) => format!("{what}: your code, taken"),
            Taken::NotStarted => format!("{what}: still the starter's stub"),
            Taken::NotFound(why) => format!("{what}: not found, counts as not done: {why}"),
            Taken::Rejected { line, reason } => {
                format!("{what}: rejected, graded as not written: {}:{line}: {reason}", self.file.display())
            }
            Taken::DoesNotCompile(why) => format!("{what}: does not compile, graded as not done: {why}"),
        }
    }
}

impl Submission {
    /// Takes every region of the submission's own code as not compiling, for a build error
    /// (`heading`, as `error[E0308]`) in a file that is not the student's: a hidden test or the
    /// instructor's code, which a report must not quote. `false` if there was none.
    pub fn stub_every_region(&mut self, heading: &str) -> bool {
        let mut any = false;
        for (_, taken) in &mut self.regions {
            if matches!(taken, Taken::Code(_)) {
                *taken = Taken::DoesNotCompile(NotCompiling::Elsewhere { heading: heading.to_string() });
                any = true;
            }
        }
        any
    }

    /// The region of the submission's own code whose body in the spliced tree `tree` holds line
    /// `line` of `file`, if any.
    pub fn code_region_at(&mut self, tree: &Path, file: &Path, line: usize) -> Option<&mut Taken> {
        let text = std::fs::read_to_string(tree.join(file)).ok()?;
        let line_of = |byte: usize| text[..byte].lines().count() + 1;
        let Found { checkpoint, function, .. } = find_regions(&text)
            .ok()?
            .into_iter()
            .find(|f| (line_of(f.body.start)..line_of(f.body.end)).contains(&line))?;
        let (_, taken) = self
            .regions
            .iter_mut()
            .find(|(r, _)| r.file == file && r.checkpoint == checkpoint && r.function == function)?;
        matches!(taken, Taken::Code(_)).then_some(taken)
    }
}

pub use crate::regions::baseline::HIDDEN_DIRS;

/// A submission's region file: its text and regions, or why it gives none (missing, not a plain
/// file, too large, not UTF-8, does not lex).
pub fn submission_file(submission: &Path, file: &Path) -> Result<(String, Vec<Found>), Unfound> {
    let mut folder = submission.to_path_buf();
    for component in file.parent().into_iter().flat_map(Path::components) {
        folder.push(component);
        match kind(&folder) {
            Some(FileKind::Dir) => {}
            Some(FileKind::Other(what)) => {
                let name = folder.strip_prefix(submission).unwrap_or(&folder).to_path_buf();
                return Err(Unfound::NotPlain(name, what));
            }
            _ => return Err(Unfound::Missing(file.to_path_buf())),
        }
    }
    let text = read_text(&submission.join(file), MAX_FILE_BYTES).map_err(|why| match why {
        NotRead::Missing => Unfound::Missing(file.to_path_buf()),
        _ => Unfound::NotRead(file.to_path_buf(), why),
    })?;
    let found =
        find_regions(&text).map_err(|e| Unfound::NotRust(file.to_path_buf(), line_at(&text, e.byte), e))?;
    Ok((text, found))
}

/// Reads what the submission at `submission` has for every region of the baseline (the
/// instructor's tree, or the starter's manifest in a student's own tree).
pub fn read_submission(
    baseline: &Baseline,
    submission: &Path,
    api: &StudentApi,
) -> Result<Submission, FileError> {
    let wanted = baseline.regions()?;
    let mut files: BTreeMap<&Path, Result<(String, Vec<Found>), Unfound>> = BTreeMap::new();
    for region in &wanted {
        files.entry(&region.file).or_insert_with(|| submission_file(submission, &region.file));
    }
    let regions = wanted
        .iter()
        .map(|region| {
            let taken = match &files[region.file.as_path()] {
                Err(why) => Taken::NotFound(why.clone()),
                Ok((text, found)) => take(region, text, found, api),
            };
            (region.clone(), taken)
        })
        .collect();
    Ok(Submission { regions, ignored: ignored_files(baseline, submission)? })
}

/// What the submission's file, `text` with its regions `found`, has for `region`.
fn take(region: &Region, text: &str, found: &[Found], api: &StudentApi) -> Taken {
    let Some(f) = found.iter().find(|f| f.checkpoint == region.checkpoint && f.function == region.function)
    else {
        return Taken::NotFound(Unfound::NoRegion(region.checkpoint, region.function.clone()));
    };
    if is_stub(text, f.body.clone(), region.checkpoint) {
        return Taken::NotStarted;
    }
    let body = &text[f.body.clone()];
    if unchecked(body) {
        return Taken::Code(body.to_string());
    }
    match check_region(body, region.checkpoint, &api.modules(region.checkpoint)) {
        Ok(()) => Taken::Code(body.to_string()),
        Err(rejection) => Taken::Rejected {
            line: line_at(text, f.body.start) - 1 + rejection.line,
            reason: rejection.reason,
        },
    }
}

/// Writes the scratch tree: the instructor's tree without its references, hidden ones included
/// (graded code never runs beside them), and without build output; every region holding the
/// submission's body (or the stub) and the solution's, and the `graded` switch between them. Files that already hold the right
/// text are left alone, so the next submission rebuilds only what differs.
pub fn write_spliced_tree(instructor: &Path, submission: &Submission, dest: &Path) -> Result<(), FileError> {
    let mut files: Vec<&PathBuf> = submission.regions.iter().map(|(r, _)| &r.file).collect();
    files.dedup();
    // Written below: copying them first would touch them and make cargo rebuild every time.
    let written: Vec<String> =
        files.iter().map(|f| f.to_string_lossy().into_owned()).chain([LIB.to_string()]).collect();
    let skip: Vec<&str> = [".git", "target", "out"]
        .into_iter()
        .chain(REFERENCE_DIRS)
        .chain(written.iter().map(String::as_str))
        .collect();
    if dest.is_dir() {
        remove_stale(instructor, dest, Path::new("")).map_err(|e| FileError::unwritable(dest, &e))?;
    }
    copy_tree(instructor, dest, &skip).map_err(|e| FileError::unwritable(dest, &e))?;
    for file in files {
        let path = dest.join(file);
        let text =
            std::fs::read_to_string(instructor.join(file)).map_err(|e| FileError::unreadable(file, &e))?;
        // Every region's new body, for all checkpoints, applied from the end of the file so that
        // the ranges of the original text stay valid.
        let mut bodies: Vec<(std::ops::Range<usize>, String)> = Vec::new();
        for checkpoint in checkpoints_in(&text) {
            let stubbed = stub_regions(&text, checkpoint);
            let stubs = region_bodies(&stubbed, checkpoint);
            for (range, stub) in region_bodies(&text, checkpoint).into_iter().zip(stubs) {
                let function = region_function(&text, range.start);
                let taken = submission
                    .regions
                    .iter()
                    .find(|(r, _)| r.file == *file && r.checkpoint == checkpoint && r.function == function);
                let student = match taken {
                    Some((_, Taken::Code(body))) => body.as_str(),
                    _ => &stubbed[stub],
                };
                bodies.push((range.clone(), both(checkpoint, student, &text[range])));
            }
        }
        bodies.sort_by_key(|(range, _)| std::cmp::Reverse(range.start));
        let mut out = text.clone();
        for (range, body) in bodies {
            out.replace_range(range, &body);
        }
        write_if_changed(&path, out.as_bytes()).map_err(|e| FileError::unwritable(&path, &e))?;
    }
    let lib = instructor.join(LIB);
    let text = std::fs::read_to_string(&lib).map_err(|e| FileError::unreadable(&lib, &e))?;
    let text = format!("{text}\n#[doc(hidden)]\npub mod graded;\n");
    let write = |path: PathBuf, text: &str| {
        write_if_changed(&path, text.as_bytes()).map_err(|e| FileError::unwritable(&path, &e))
    };
    write(dest.join(LIB), &text)?;
    write(dest.join("src/graded.rs"), GRADED_MODULE)
}

/// Removes the files of an earlier scratch tree that the instructor's tree no longer has (its
/// build output and the `graded` module aside).
fn remove_stale(instructor: &Path, dest: &Path, relative: &Path) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dest.join(relative))? {
        let entry = entry?;
        let path = relative.join(entry.file_name());
        if path == Path::new("target") || path == Path::new("src/graded.rs") {
            continue;
        }
        if entry.file_type()?.is_dir() {
            remove_stale(instructor, dest, &path)?;
        } else if !instructor.join(&path).is_file() {
            std::fs::remove_file(entry.path())?;
        }
    }
    Ok(())
}

/// A region body holding both versions.
fn both(checkpoint: u32, student: &str, solution: &str) -> String {
    format!("if crate::graded::student({checkpoint}) {{\n{student}}} else {{\n{solution}}}\n")
}

/// The switch between the submission's code and the solution's, in the scratch tree only.
const GRADED_MODULE: &str = r#"//! Written by the grader into its scratch copy of the tree: which checkpoints run the
//! submission's region code (the environment variable RAYLAB_GRADED_STUDENT, "2,3"); the others
//! run the solution's.

use std::sync::OnceLock;

/// Whether checkpoint `n`'s regions run the submission's code.
pub fn student(n: u32) -> bool {
    static CHOSEN: OnceLock<u64> = OnceLock::new();
    let chosen = CHOSEN.get_or_init(|| {
        let list = std::env::var("RAYLAB_GRADED_STUDENT").unwrap_or_default();
        list.split(',').filter_map(|s| s.trim().parse::<u32>().ok()).filter(|&c| c < 64).fold(0, |m, c| m | 1 << c)
    });
    n < 64 && chosen & (1 << n) != 0
}
"#;

#[cfg(test)]
mod tests;
