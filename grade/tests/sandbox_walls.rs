//! Each wall of the sandbox on its own (`grade/src/sandbox/`): a probe started through the
//! grader's launcher tries what the wall forbids. With every wall up it is refused; with only the
//! walls that forbid it left out (a switch test builds of the launcher alone accept) it succeeds,
//! so the refusal is that wall's doing and the probe really tries.
#![cfg(target_os = "linux")]

use std::path::{Path, PathBuf};

use raylab_grade::run::probe::{allowed, Attempt};
use raylab_grade::run::sandbox::{Profile, Wall};

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
    let wrong: Vec<String> =
        Attempt::ALL.into_iter().flat_map(|a| held_by(a, &argument(a, &tcp), a.walls())).collect();
    let (_, written) = outside();
    let _ = std::fs::remove_dir_all(written.parent().unwrap());
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// What is wrong with the claim that `walls` refuse `attempt` with `arg`: allowed with every wall
/// up, refused with exactly those left out, or allowed with one of them alone (the user wall
/// exists for root only, and where the probe's program is readable by all).
fn held_by(attempt: Attempt, arg: &str, walls: &[Wall]) -> Vec<String> {
    let mut wrong = Vec::new();
    let walled = allowed(launcher(), attempt, arg, &[]).unwrap();
    let open = allowed(launcher(), attempt, arg, walls).unwrap();
    if (walled, open) != (walls.is_empty(), true) {
        wrong.push(format!("{} {arg}: walled {walled}, without {walls:?} {open}", attempt.name()));
    }
    let here = |w: &&Wall| **w != Wall::User || raylab_grade::run::sandbox::user::runs_as_user(launcher());
    for &wall in walls.iter().filter(here) {
        let others: Vec<Wall> = walls.iter().copied().filter(|&w| w != wall).collect();
        if allowed(launcher(), attempt, arg, &others).unwrap() {
            wrong.push(format!("{} {arg}: {wall:?} alone does not refuse it", attempt.name()));
        }
    }
    wrong
}

/// What graded code reads and writes, each with the walls that stop it: the user wall stops only
/// what is not open to all (the hidden references, once the grader has closed them; the grader's
/// environment); the solution's source in a scratch tree and the grader's command line are
/// Landlock's alone (docs/THREAT_MODEL.md).
#[test]
fn each_file_a_submission_wants_is_refused_by_its_walls() {
    let dir = std::env::temp_dir().join(format!("raylab-reads-{}", std::process::id()));
    let (source, build) = (dir.join("tree/src/geometry/triangle.rs"), dir.join("target/debug"));
    std::fs::create_dir_all(source.parent().unwrap()).unwrap();
    std::fs::create_dir_all(&build).unwrap();
    std::fs::write(&source, "// BEGIN SOLUTION").unwrap();
    let me = std::process::id();
    let (landlock, both) = (&[Wall::Landlock][..], &[Wall::Landlock, Wall::User][..]);
    // A hidden reference, as the grader leaves it where it is root: readable by its owner only.
    let secret = dir.join("hidden-reference.png");
    std::fs::write(&secret, "secret").unwrap();
    std::fs::set_permissions(&secret, std::os::unix::fs::PermissionsExt::from_mode(0o600)).unwrap();
    let cases = [
        (Attempt::Read, secret.display().to_string(), both),
        (Attempt::Read, source.display().to_string(), landlock),
        (Attempt::Read, format!("/proc/{me}/cmdline"), landlock),
        (Attempt::Read, format!("/proc/{me}/environ"), both),
        (Attempt::Write, build.join("render").display().to_string(), both),
    ];
    let wrong: Vec<String> = cases.iter().flat_map(|(a, arg, walls)| held_by(*a, arg, walls)).collect();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// A build runs programs and starts processes (cargo runs rustc, rustc the linker), but reaches
/// no network, no other process and no file outside the tree, the toolchain and the system.
#[test]
fn a_build_runs_compilers_but_reaches_no_network_and_no_file_outside() {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let tcp = listener.local_addr().unwrap().to_string();
    let build = |attempt: Attempt| {
        raylab_grade::run::probe::allowed_in(
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
    raylab_grade::run::sandbox::set_launcher(launcher().to_path_buf());
    let run = raylab_grade::run::child::run_build(cargo, limit, &tree, &target).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(run.success(), "{}", run.stderr);
}
