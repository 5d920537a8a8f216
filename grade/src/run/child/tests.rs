//! Children under attack: crashes, endless loops, grandchildren that outlive them, floods of
//! output, memory and file limits; each survived and reported in one line.

use super::*;
use crate::plain::MAX_QUOTE_CHARS;

fn sh(script: &str) -> Command {
    let mut c = Command::new("sh");
    c.arg("-c").arg(script);
    c
}

/// A marker file that a background job of the child would create after a second.
fn marker_after_a_second(name: &str) -> (PathBuf, String) {
    let marker = std::env::temp_dir().join(format!("raylab-{name}-{}", std::process::id()));
    let job = format!("(sleep 1; touch {}) &", marker.display());
    (marker, job)
}

#[test]
fn grader_kills_what_a_child_leaves_running() {
    let (marker, job) = marker_after_a_second("orphan");
    let run = run_with_limit(sh(&format!("{job} exit 0")), Duration::from_secs(10)).unwrap();
    assert!(run.success());
    std::thread::sleep(Duration::from_millis(1500));
    assert!(!marker.exists(), "the background job outlived its parent");
}

#[test]
fn grader_stops_a_child_and_its_group_at_the_time_limit() {
    let (marker, job) = marker_after_a_second("timeout");
    let limit = Duration::from_millis(300);
    let run = run_with_limit(sh(&format!("{job} sleep 30")), limit).unwrap();
    assert!(run.status.is_none() && run.failure(limit).category == Category::OutOfTime);
    std::thread::sleep(Duration::from_millis(1500));
    assert!(!marker.exists(), "the background job outlived the time limit");
}

#[test]
fn grader_limits_the_size_of_files_a_graded_child_writes() {
    let limits = Some(Limits { file_size: 1 << 20, ..Limits::GRADED.unwrap() });
    let path = std::env::temp_dir().join(format!("raylab-big-{}", std::process::id()));
    let script = format!("head -c 4000000 /dev/zero > {}", path.display());
    let run = run_limited(sh(&script), Duration::from_secs(10), limits).unwrap();
    let size = std::fs::metadata(&path).map_or(0, |m| m.len());
    let _ = std::fs::remove_file(&path);
    assert!(!run.success() && size <= 1 << 20, "wrote {size} bytes");
}

/// 300 files of 1 MiB, each under the per-file limit, pass a 64 MiB budget: the child is
/// stopped near it, with the reason a report gives. It pauses 10 ms a file, so the whole
/// takes at least 3 s and the watch looks a dozen times before it could end.
#[test]
fn grader_bounds_what_a_graded_child_writes_in_all() {
    let own = OwnFolder::new().unwrap();
    let limits = Limits { written: Budget { bytes: 64 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
    let script = format!(
        "for i in $(seq 300); do head -c 1048576 /dev/zero > {}/$i; sleep 0.01; done",
        own.path().display()
    );
    let limit = Duration::from_secs(60);
    let walls = Walls {
        profile: Profile::Run,
        read: Vec::new(),
        write: vec![own.path().to_path_buf()],
        limits,
        cpu_seconds: 60,
        user: None,
    };
    let run = run_walled(sh(&script), limit, walls).unwrap();
    let written = std::fs::read_dir(own.path()).unwrap().count();
    assert!(run.wrote_too_much && !run.success(), "{run:?}");
    assert!((64..300).contains(&written), "{written} files of 1 MiB left");
    assert_eq!(
        run.failure(limit).to_string(),
        "wrote too much output: its files passed 64 MiB or 1000 entries in all"
    );
}

/// Files opened and unlinked hold disk that no walk of the folder sees (until the child ends,
/// so this one holds seven of 10 MiB open): the bytes the child wrote count anyway.
#[test]
fn grader_counts_what_a_graded_child_writes_into_unlinked_files() {
    let own = OwnFolder::new().unwrap();
    let limits = Limits { written: Budget { bytes: 64 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
    let script = format!(
        "cd {}; for i in 3 4 5 6 7 8 9; do eval \"exec $i>f\"; rm f; head -c 10485760 /dev/zero >&$i; done; sleep 30",
        own.path().display()
    );
    let walls = Walls {
        profile: Profile::Run,
        read: Vec::new(),
        write: vec![own.path().to_path_buf()],
        limits,
        cpu_seconds: 60,
        user: None,
    };
    let run = run_walled(sh(&script), Duration::from_secs(60), walls).unwrap();
    assert!(run.wrote_too_much && run.seconds < 30.0, "{run:?}");
    assert!(std::fs::read_dir(own.path()).unwrap().next().is_none(), "the files were unlinked");
}

/// A child that ends before the first look is measured once more: what it left behind counts,
/// what it wrote and removed again does not.
#[test]
fn grader_measures_what_a_quick_child_left_behind() {
    let own = OwnFolder::new().unwrap();
    let file = own.path().join("big");
    std::fs::write(&file, vec![1u8; 2 << 20]).unwrap();
    let limits = Limits { written: Budget { bytes: 1 << 20, entries: 1_000 }, ..Limits::GRADED.unwrap() };
    let run = |script: String| {
        let walls = Walls {
            profile: Profile::Run,
            read: Vec::new(),
            write: vec![own.path().to_path_buf()],
            limits,
            cpu_seconds: 60,
            user: None,
        };
        run_walled(sh(&script), Duration::from_secs(60), walls).unwrap()
    };
    let copy = format!("cp {0} {0}.copy", file.display());
    let removed = run(format!("{copy}; rm {}.copy", file.display()));
    assert!(removed.success(), "{removed:?}");
    let left = run(copy);
    assert!(left.wrote_too_much && !left.success() && left.seconds < 0.25, "{left:?}");
}

/// What a child writes reaches a report on one clean line of at most 200 characters, and
/// each way of failing has its fixed word.
#[test]
fn grader_quotes_a_child_on_one_short_clean_line() {
    let text = format!("\x1b[31mred\x1b[0m\r\nsecond\tline {}", "é".repeat(500));
    let quoted = quote(&text);
    assert!(quoted.starts_with("[31mred [0m second line éé"), "{quoted}");
    assert!(!quoted.chars().any(char::is_control));
    assert_eq!(quoted.chars().count(), MAX_QUOTE_CHARS + 3);
    let limit = Duration::from_secs(10);
    let failure = |script: &str| run_with_limit(sh(script), limit).unwrap().failure(limit);
    let panicked = failure(&format!("echo 'x\n{PANIC_PREFIX}boom\x1b[2J' >&2; exit 101"));
    assert_eq!(panicked, Failure { category: Category::Panicked, detail: Some("boom [2J".to_string()) });
    assert_eq!(failure("echo last words >&2; exit 3").to_string(), "failed: exit status: 3: last words");
    assert_eq!(failure("kill -ABRT $$").to_string(), "crashed: aborted");
    let mut head = Command::new("head");
    head.args(["-c", "3000000", "/dev/zero"]);
    let too_much =
        run_limited(head, limit, Some(Limits { file_size: 1 << 20, ..Limits::GRADED.unwrap() })).unwrap();
    assert_eq!(too_much.failure(limit).category, Category::TooMuchOutput);
}
