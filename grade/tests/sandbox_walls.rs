//! Each wall of the sandbox on its own (`grade/src/sandbox.rs`): a probe started through the
//! grader's launcher tries what the wall forbids. With every wall up it is refused; with only the
//! walls that forbid it left out (a switch test builds of the launcher alone accept) it succeeds,
//! so the refusal is that wall's doing and the probe really tries.
#![cfg(target_os = "linux")]

use std::path::{Path, PathBuf};

use raylab_grade::sandbox::probe::{allowed, Attempt};
use raylab_grade::sandbox::{Profile, Wall};

fn launcher() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_grader"))
}

/// A file outside every wall, and a path beside it to write.
fn outside() -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("raylab-walls-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let secret = dir.join("hidden-reference.png");
    std::fs::write(&secret, "secret").unwrap();
    // As the grader leaves the hidden references where it is root: readable by their owner only.
    std::fs::set_permissions(&secret, std::os::unix::fs::PermissionsExt::from_mode(0o600)).unwrap();
    (secret, dir.join("written.txt"))
}

/// The argument each attempt needs.
fn argument(attempt: Attempt, tcp: &str) -> String {
    let (secret, written) = outside();
    match attempt {
        Attempt::Tcp | Attempt::Udp => tcp.to_string(),
        Attempt::Signal | Attempt::Ptrace | Attempt::Setpgid => std::process::id().to_string(),
        Attempt::Read => secret.display().to_string(),
        Attempt::Write => written.display().to_string(),
        Attempt::Allocate => (8u64 << 30).to_string(),
        _ => String::new(),
    }
}

#[test]
fn every_wall_refuses_what_it_is_for_and_only_it() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let tcp = listener.local_addr().unwrap().to_string();
    let mut wrong = Vec::new();
    for attempt in Attempt::ALL {
        let arg = argument(attempt, &tcp);
        let walled = allowed(launcher(), attempt, &arg, &[]).unwrap();
        let open = allowed(launcher(), attempt, &arg, attempt.walls()).unwrap();
        let expected = (attempt.walls().is_empty(), true);
        if (walled, open) != expected {
            wrong.push(format!("{}: walled {walled}, without {:?} {open}", attempt.name(), attempt.walls()));
        }
        // Each wall alone that is meant for it refuses it too (the user wall exists for root only,
        // and where the probe's program is readable by all).
        let here = |w: &&Wall| **w != Wall::User || raylab_grade::sandbox::user::runs_as_user(launcher());
        for &wall in attempt.walls().iter().filter(here) {
            let others: Vec<Wall> = attempt.walls().iter().copied().filter(|&w| w != wall).collect();
            if allowed(launcher(), attempt, &arg, &others).unwrap() {
                wrong.push(format!("{}: {wall:?} alone does not refuse it", attempt.name()));
            }
        }
    }
    let (_, written) = outside();
    let _ = std::fs::remove_dir_all(written.parent().unwrap());
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// A build runs programs and starts processes (cargo runs rustc, rustc the linker), but reaches
/// no network, no other process and no file outside the tree, the toolchain and the system.
#[test]
fn a_build_runs_compilers_but_reaches_no_network_and_no_file_outside() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let tcp = listener.local_addr().unwrap().to_string();
    let build = |attempt: Attempt| {
        raylab_grade::sandbox::probe::allowed_in(
            launcher(),
            Profile::Build,
            attempt,
            &argument(attempt, &tcp),
            &[],
        )
        .unwrap()
    };
    let allowed: Vec<bool> = [Attempt::ExecShell, Attempt::Fork, Attempt::Thread].map(build).to_vec();
    assert_eq!(allowed, [true, true, true], "exec, fork, thread");
    let refused =
        [Attempt::Tcp, Attempt::Udp, Attempt::Ptrace, Attempt::Read, Attempt::Write, Attempt::Allocate];
    let leaks: Vec<&str> = refused.into_iter().filter(|&a| build(a)).map(Attempt::name).collect();
    let (_, written) = outside();
    let _ = std::fs::remove_dir_all(written.parent().unwrap());
    assert!(leaks.is_empty(), "a build was allowed to: {leaks:?}");
}

/// A grader killed in the middle of a build takes the build's processes with it: the launcher of
/// a build stays as their supervisor and kills its whole group when its parent dies. Here the
/// "grader" is a shell that starts a build whose program leaves a job behind, then kills itself.
#[test]
fn a_killed_grader_leaves_no_build_process_running() {
    use std::os::unix::process::CommandExt;
    let dir = std::env::temp_dir().join(format!("raylab-orphan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let marker = dir.join("written-after-the-grader-died");
    let build = format!("(sleep 2; touch {}) & wait", marker.display());
    let grader = format!(
        "{} __sandbox --build --write {} --memory 4294967296 --file-size 1073741824 --cpu 60 --parent $$ -- /bin/sh -c '{build}' & sleep 0.5; kill -9 $$",
        launcher().display(),
        dir.display()
    );
    let status =
        std::process::Command::new("/bin/sh").arg("-c").arg(grader).process_group(0).status().unwrap();
    assert!(!status.success(), "the shell killed itself");
    std::thread::sleep(std::time::Duration::from_secs(3));
    let written = marker.exists();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!written, "a process of the build outlived the grader");
}

/// Cargo reads the `.cargo/config.toml` of every folder above the tree it builds and stops on one
/// it cannot read: a scratch tree below the instructor's repository (the default work folder) must
/// still build inside the walls.
#[test]
fn a_build_below_a_cargo_config_reads_it() {
    let dir = std::env::temp_dir().join(format!("raylab-config-{}", std::process::id()));
    let tree = dir.join("work/tree");
    std::fs::create_dir_all(dir.join(".cargo")).unwrap();
    std::fs::create_dir_all(tree.join("src")).unwrap();
    std::fs::write(dir.join(".cargo/config.toml"), "[alias]\nx = \"build\"\n").unwrap();
    std::fs::write(tree.join("Cargo.toml"), "[package]\nname = \"t\"\nversion = \"0.1.0\"\n[workspace]\n")
        .unwrap();
    std::fs::write(tree.join("src/lib.rs"), "").unwrap();
    let target = dir.join("target");
    let mut cargo = std::process::Command::new(std::env::var_os("CARGO").unwrap_or("cargo".into()));
    cargo.current_dir(&tree).args(["locate-project"]).env("CARGO_TARGET_DIR", &target);
    let limit = std::time::Duration::from_secs(60);
    raylab_grade::sandbox::set_launcher(launcher().to_path_buf());
    let run = raylab_grade::child::run_build(cargo, limit, &tree, &target).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(run.success(), "{}", run.stderr);
}
