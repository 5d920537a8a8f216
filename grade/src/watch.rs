//! `grader watch`: the current checkpoint's tests and scenes again on every save, as rustlings
//! does, moving on to the next checkpoint when one passes, and the ones that passed again with it,
//! so a save that breaks an earlier checkpoint is named as the regression it is.
//!
//! Each round runs the current checkpoint's tests first and answers as soon as they ran, then
//! the tests of the checkpoints that passed before; the scenes are rendered only once every test
//! passes.
//!
//! The loop is written against two seams so it can be tested without files or builds: a
//! [`Changes`] source that blocks until something was saved, and a `check` function that grades
//! checkpoints, tests only or in full. The grader binary gives it [`Polling`] (modification times
//! of the tree's Rust sources, scanned every 100 ms: no platform watcher needed) and
//! [`grade`](crate::grading::grade).

use std::collections::{BTreeMap, BTreeSet};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use crate::outcome::CheckpointResult;
use crate::report::reasons::{advice_line, hint_text, reason_lines};

/// Something that waits for the next save.
pub trait Changes {
    /// Blocks until a source file changed; `false` when watching should stop.
    fn wait(&mut self) -> bool;
}

/// Watches the modification times of the Rust files below a folder.
pub struct Polling {
    dir: PathBuf,
    seen: BTreeMap<PathBuf, SystemTime>,
}

impl Polling {
    /// Watches the Rust files below `dir`, as they are now.
    pub fn new(dir: &Path) -> Self {
        let mut polling = Self { dir: dir.to_path_buf(), seen: BTreeMap::new() };
        polling.seen = polling.scan();
        polling
    }

    fn scan(&self) -> BTreeMap<PathBuf, SystemTime> {
        let mut times = BTreeMap::new();
        let mut stack = vec![self.dir.clone()];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
                let path = entry.path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    if let Ok(time) = entry.metadata().and_then(|m| m.modified()) {
                        times.insert(path, time);
                    }
                }
            }
        }
        times
    }
}

impl Changes for Polling {
    fn wait(&mut self) -> bool {
        loop {
            std::thread::sleep(Duration::from_millis(100));
            let now = self.scan();
            if now != self.seen {
                self.seen = now;
                return true;
            }
        }
    }
}

/// How much of a checkpoint a round grades.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Its unit tests only: the first answer after a save.
    Tests,
    /// Its tests and its scenes, once its tests pass.
    Full,
}

/// Watches the checkpoints `ids` in order: grades the current one with `check` (its tests,
/// then, when they pass, its scenes too), prints one
/// line when it passes and moves on, or prints what to look at first and waits for a save.
/// After every save, the checkpoints that passed are graded again with the current one, and one
/// that fails now is named as a regression and becomes the current one. With `stamped` (output
/// that is not a terminal) each round starts with the time. Returns when every checkpoint of `ids`
/// passes or `changes` stops.
pub fn watch<E: std::fmt::Display>(
    changes: &mut impl Changes,
    mut check: impl FnMut(&[u32], Stage) -> Result<Vec<CheckpointResult>, E>,
    ids: &[u32],
    stamped: bool,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let mut passed: BTreeSet<u32> = BTreeSet::new();
    let mut at = 0;
    let mut saved = false;
    let full = |r: &CheckpointResult| (r.score() - r.max_score(true)).abs() < 1e-9;
    while let Some(&current) = ids.get(at) {
        let again: Vec<u32> = if saved { passed.iter().copied().collect() } else { Vec::new() };
        let also = if again.is_empty() { String::new() } else { format!(" (and again {})", list(&again)) };
        let time = if stamped { stamp() } else { String::new() };
        writeln!(out, "{time}checking checkpoint {current}{also}...")?;
        out.flush()?;
        saved = false;
        let (results, answered) = round(&mut check, current, &again, out)?;
        let regressions: Vec<&CheckpointResult> =
            results.iter().filter(|r| passed.contains(&r.checkpoint.id) && !full(r)).collect();
        for r in &regressions {
            let id = r.checkpoint.id;
            writeln!(out, "checkpoint {id} passed before and fails now: {}", first_problem(r))?;
            passed.remove(&id);
            at = at.min(ids.iter().position(|&i| i == id).unwrap_or(at));
        }
        match results.iter().find(|r| r.checkpoint.id == current) {
            Some(result) if regressions.is_empty() && full(result) => {
                writeln!(
                    out,
                    "checkpoint {current} passes: {:.1}/{:.0}",
                    result.score(),
                    result.max_score(true)
                )?;
                passed.insert(current);
                at += 1;
                continue;
            }
            Some(result) if regressions.is_empty() && !answered => answer(out, result)?,
            _ => {}
        }
        writeln!(out, "waiting for a save...")?;
        out.flush()?;
        if !changes.wait() {
            return Ok(());
        }
        saved = true;
    }
    match ids.last() {
        Some(last) => writeln!(out, "every checkpoint up to {last} passes"),
        None => writeln!(out, "no checkpoint to watch"),
    }
}

/// One round of checks: the `current` checkpoint's tests first, answered as soon as they ran;
/// then the tests of those that passed before (`again`); the scenes only once every test passes.
/// The results, and whether the current checkpoint was answered already.
fn round<E: std::fmt::Display>(
    check: &mut impl FnMut(&[u32], Stage) -> Result<Vec<CheckpointResult>, E>,
    current: u32,
    again: &[u32],
    out: &mut impl Write,
) -> std::io::Result<(Vec<CheckpointResult>, bool)> {
    let tests_pass = |r: &CheckpointResult| (r.test_score - r.checkpoint.all_test_points()).abs() < 1e-9;
    let mut answered = false;
    let results = match check(&[current], Stage::Tests) {
        Ok(own) if own.iter().all(tests_pass) => {
            check(&again.iter().copied().chain([current]).collect::<Vec<_>>(), Stage::Full)
        }
        Ok(own) => {
            for r in &own {
                answer(out, r)?;
                answered = true;
            }
            out.flush()?;
            let earlier = if again.is_empty() { Ok(Vec::new()) } else { check(again, Stage::Tests) };
            earlier.map(|earlier| earlier.into_iter().chain(own).collect())
        }
        Err(e) => Err(e),
    };
    let results = results.unwrap_or_else(|e| {
        let _ = writeln!(out, "checkpoint {current}: cannot grade: {e}");
        Vec::new()
    });
    Ok((results, answered))
}

/// A checkpoint that lost points: its points, what to look at first, and what to read.
fn answer(out: &mut impl Write, result: &CheckpointResult) -> std::io::Result<()> {
    let id = result.checkpoint.id;
    writeln!(out, "checkpoint {id}: {:.1}/{:.0}", result.score(), result.max_score(true))?;
    writeln!(out, "  {}", first_problem(result))?;
    let advice = advice_line(result).unwrap_or_else(|| hint_text(&result.checkpoint));
    writeln!(out, "  {advice}")
}

/// "2, 3 and 4".
fn list(ids: &[u32]) -> String {
    let words: Vec<String> = ids.iter().map(u32::to_string).collect();
    match words.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => words.join(""),
    }
}

/// "[14:03:27] ": the time of day (UTC), for a log read later.
fn stamp() -> String {
    let seconds =
        SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).map_or(0, |d| d.as_secs()) % 86_400;
    format!("[{:02}:{:02}:{:02} UTC] ", seconds / 3600, seconds / 60 % 60, seconds % 60)
}

/// The first failing test with what it said, else the first reason points were lost.
fn first_problem(result: &CheckpointResult) -> String {
    if let Some((test, message)) = result.tests.as_ref().and_then(|t| t.first_failure.as_ref()) {
        let name = test.rsplit("::").next().unwrap_or(test);
        return format!("first failing test: {name}: {message}");
    }
    reason_lines(result).into_iter().next().unwrap_or_else(|| "points were lost".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rubric::Rubric;
    use crate::run::unit_tests::TestRun;

    /// Saves given by a list: `wait` takes the next, and stops when none is left.
    struct Saves(usize);

    impl Changes for Saves {
        fn wait(&mut self) -> bool {
            self.0 = self.0.saturating_sub(1);
            self.0 > 0
        }
    }

    fn result(id: u32, passed: u32, failed: u32) -> CheckpointResult {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let rubric = Rubric::load(&root.join(crate::rubric::RUBRIC), &root).unwrap();
        let checkpoint = rubric.checkpoints.iter().find(|c| c.id == id).unwrap().clone();
        let first_failure =
            (failed > 0).then(|| ("m::checkpoint2::the_back_face_is_hit_too".into(), "no hit".into()));
        let fraction = passed as f64 / (passed + failed) as f64;
        CheckpointResult {
            tests: Some(TestRun { passed, failed, first_failure, ..TestRun::default() }),
            hidden_tests: None,
            waiting: 0,
            test_score: checkpoint.test_points * fraction,
            image_score: checkpoint.image_points * fraction.floor(),
            reasons: Vec::new(),
            advice: None,
            checkpoint,
        }
    }

    #[test]
    fn grader_watch_waits_on_a_failing_checkpoint_and_moves_on_when_it_passes() {
        // Checkpoint 2 fails twice (two saves), then passes; checkpoint 3 passes at once.
        let mut runs = 0;
        let check = |ids: &[u32], stage| {
            runs += (stage == Stage::Tests) as u32;
            Ok::<_, String>(
                ids.iter()
                    .map(|&id| if id == 2 && runs <= 2 { result(2, 9, 1) } else { result(id, 10, 0) })
                    .collect(),
            )
        };
        let mut out = Vec::new();
        watch(&mut Saves(10), check, &[2, 3], false, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.matches("waiting for a save").count(), 2, "{text}");
        assert!(text.contains("first failing test: the_back_face_is_hit_too: no hit"), "{text}");
        assert!(text.contains("checkpoints/02-triangle.md"), "the handout: {text}");
        let passes: Vec<&str> = text.lines().filter(|l| l.contains("passes:")).collect();
        assert_eq!(passes.len(), 2, "{text}");
        assert!(text.ends_with("every checkpoint up to 3 passes\n"), "{text}");
        assert!(!text.contains('['), "no time stamps on a terminal: {text}");
    }

    /// Checkpoint 2 passes, checkpoint 3 fails; a save breaks checkpoint 2: it is graded again
    /// with 3, named as a regression, and is the current checkpoint until it passes again.
    #[test]
    fn grader_watch_names_a_regression_of_a_checkpoint_that_passed() {
        let (mut graded, mut full): (Vec<Vec<u32>>, Vec<Vec<u32>>) = (Vec::new(), Vec::new());
        let check =
            |ids: &[u32], stage| {
                match stage {
                    Stage::Tests => graded.push(ids.to_vec()),
                    Stage::Full => full.push(ids.to_vec()),
                }
                // The save before the third round breaks checkpoint 2; the next one mends it.
                let broken = graded.len() == 4;
                Ok::<_, String>(
                    ids.iter()
                        .map(|&id| {
                            if id == 3 || (id == 2 && broken) {
                                result(id, 9, 1)
                            } else {
                                result(id, 10, 0)
                            }
                        })
                        .collect(),
                )
            };
        let mut out = Vec::new();
        watch(&mut Saves(3), check, &[2, 3], true, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        // Each round: the current checkpoint's tests first (the answer), then those that passed.
        assert_eq!(graded, [vec![2], vec![3], vec![3], vec![2], vec![2], vec![3]], "{text}");
        // The scenes only in rounds whose tests all pass.
        assert_eq!(full, [vec![2], vec![2]], "{text}");
        let answer = text.find("checkpoint 3: 9.0/15").unwrap();
        assert!(answer < text.find("checkpoint 2 passed before").unwrap(), "the answer first: {text}");
        assert!(text.contains("checkpoint 2 passed before and fails now: first failing test"), "{text}");
        assert!(text.contains("checking checkpoint 3 (and again 2)..."), "{text}");
        let rounds: Vec<&str> = text.lines().filter(|l| l.contains("checking")).collect();
        assert!(rounds.iter().all(|l| l.starts_with('[') && l.contains(" UTC] ")), "{text}");
    }

    #[test]
    fn grader_watch_stops_when_the_saves_stop() {
        let mut out = Vec::new();
        watch(
            &mut Saves(1),
            |ids: &[u32], _| Ok::<_, String>(ids.iter().map(|&id| result(id, 0, 10)).collect()),
            &[2, 3, 4, 5, 6, 7],
            false,
            &mut out,
        )
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.matches("checkpoint 2: ").count(), 1, "{text}");
        assert!(!text.contains("every checkpoint"), "{text}");
    }

    /// A course that skips a checkpoint watches the ones it has, in order.
    #[test]
    fn grader_watch_goes_from_one_checkpoint_of_the_rubric_to_the_next() {
        let mut out = Vec::new();
        let check = |ids: &[u32], _| Ok::<_, String>(ids.iter().map(|&id| result(id, 10, 0)).collect());
        watch(&mut Saves(1), check, &[5, 8], false, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let passes: Vec<&str> = text.lines().filter(|l| l.contains(" passes")).collect();
        assert_eq!(
            passes,
            [
                "checkpoint 5 passes: 20.0/20",
                "checkpoint 8 passes: 20.0/20",
                "every checkpoint up to 8 passes"
            ],
            "{text}"
        );
    }

    #[test]
    fn grader_polling_sees_a_save() {
        let dir = std::env::temp_dir().join(format!("raylab-watch-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("src")).unwrap();
        let file = dir.join("src/a.rs");
        std::fs::write(&file, "fn a() {}").unwrap();
        let mut polling = Polling::new(&dir);
        let writer = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(1100));
            std::fs::write(&file, "fn a() { 1; }").unwrap();
        });
        assert!(polling.wait());
        writer.join().unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
