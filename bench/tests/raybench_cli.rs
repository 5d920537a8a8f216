//! The `raybench` command: it writes the benchmark mesh, traces it, and turns bad input into one
//! line and exit code 2. (Its speed is a benchmark, never a test: only counts are checked here.)

use std::path::PathBuf;
use std::process::{Command, Output};

fn raybench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raybench")).args(args).output().expect("raybench runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-raybench-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn raybench_generates_the_icosphere_and_traces_every_workload() {
    let dir = scratch("ok");
    let mesh = dir.join("ico.obj");
    let out = raybench(&["--generate", "icosphere", "--triangles", "500", "-o", mesh.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // 500 / 20 = 25 = 5²: n = 5, 500 triangles exactly.
    assert!(String::from_utf8_lossy(&out.stdout).contains("n = 5, 500 triangles"));

    let out = raybench(&[mesh.to_str().unwrap(), "--repeat", "1", "--threads", "2"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("500 triangles"), "{stdout}");
    for workload in ["primary", "incoherent", "shadow"] {
        let row = stdout.lines().find(|l| l.starts_with(workload)).unwrap_or_else(|| panic!("{stdout}"));
        assert!(row.contains("1048576"), "2^20 rays: {row}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn raybench_bad_input_is_one_line_and_exit_2() {
    let dir = scratch("bad");
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, "# no faces\n").unwrap();
    let missing = dir.join("missing.obj");
    for (args, names) in [
        (vec![missing.to_str().unwrap()], "missing.obj"),
        (vec![empty.to_str().unwrap()], "no triangles"),
        (vec!["--generate", "icosphere", "--triangles", "80", "-o", "/nonexistent-dir/x.obj"], "x.obj"),
    ] {
        let out = raybench(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(names) && !stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
