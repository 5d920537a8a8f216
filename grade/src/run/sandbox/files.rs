//! The file wall of a graded process (Landlock): it may read and execute the system's programs
//! and libraries, its own program and the paths the caller names; read its own `/proc/self`
//! (the C library reads its stack's bounds there) and the cgroup limits (how many threads to
//! start); write only its own folder. Everything else, the instructor's tree, the hidden
//! references and tests, the solution's source beside the submission's, other students' folders,
//! `/proc` of other processes, is neither readable nor writable. Where the kernel has Landlock's
//! scopes (ABI 6), signals and abstract UNIX sockets are kept inside the sandbox too.
//!
//! A build reads the system, the toolchain (`CARGO_HOME`, `RUSTUP_HOME`) and the scratch tree, and
//! writes its target folder and its own: not the instructor's tree, its references or other
//! students' folders, wherever an `include_bytes!` points.
//!
//! Best effort, as the `landlock` crate defines it: a kernel without Landlock leaves this wall
//! out (`grader sandbox --check` says so); a kernel with an older ABI enforces what it knows.

use std::ffi::OsString;
use std::path::PathBuf;

use landlock::{
    path_beneath_rules, Access, AccessFs, AccessNet, Ruleset, RulesetAttr, RulesetCreatedAttr, RulesetStatus,
    Scope, ABI,
};

use super::{Profile, Walls};

/// The newest Landlock ABI this wall is written for.
const TARGET: ABI = ABI::V6;

/// System folders every program needs to start: the dynamic loader, the C library and its
/// configuration.
const SYSTEM: [&str; 6] = ["/usr", "/lib", "/lib64", "/etc/ld.so.cache", "/dev/null", "/dev/urandom"];

/// The process's own view of itself and its limits.
const SELF_VIEW: [&str; 2] = ["/proc/self", "/sys/fs/cgroup"];

/// What a build reads besides the tree: the system (compilers, linker, headers, the C library)
/// and its processes' views of themselves.
const BUILD_SYSTEM: [&str; 7] = ["/usr", "/lib", "/lib64", "/etc", "/proc", "/sys", "/dev"];

/// Restricts the calling thread (and what it executes) to `walls`, with `program` executable.
pub fn restrict(walls: &Walls, program: &OsString) -> Result<RulesetStatus, landlock::RulesetError> {
    let mut read: Vec<PathBuf> = match walls.profile {
        Profile::Run => SYSTEM.iter().chain(&SELF_VIEW).map(PathBuf::from).collect(),
        Profile::Build => BUILD_SYSTEM.iter().map(PathBuf::from).chain(toolchain()).collect(),
    };
    read.extend(walls.read.iter().cloned());
    if walls.profile == Profile::Build {
        read.extend(cargo_configs(&walls.read));
    }
    read.push(PathBuf::from(program));
    let mut write = walls.write.clone();
    if walls.profile == Profile::Build {
        // Compilers write their probes' output there.
        write.push(PathBuf::from("/dev/null"));
    }
    let (read, write) = (read.into_iter().filter(|p| p.exists()), write.into_iter().filter(|p| p.exists()));
    let status = Ruleset::default()
        .handle_access(AccessFs::from_all(TARGET))
        .and_then(|r| r.handle_access(AccessNet::from_all(TARGET)))
        .and_then(|r| r.scope(Scope::from_all(TARGET)))
        .and_then(|r| r.create())
        .and_then(|r| r.add_rules(path_beneath_rules(read, AccessFs::from_read(TARGET))))
        .and_then(|r| r.add_rules(path_beneath_rules(write, AccessFs::from_all(TARGET))))
        .and_then(|r| r.restrict_self())?;
    Ok(status.ruleset)
}

/// The `.cargo` folders of `paths` and their ancestors, and the vendored sources their
/// configuration names: cargo reads every such `.cargo/config.toml` and stops with "permission
/// denied" on one it cannot (a scratch tree below the instructor's repository, the default
/// `target/grader-submission`), and the Gradescope autograder's crates are vendored beside the
/// instructor's tree (`[source.vendored] directory = ...`).
fn cargo_configs(paths: &[PathBuf]) -> Vec<PathBuf> {
    let folders: Vec<PathBuf> = paths.iter().flat_map(|p| p.ancestors().map(|a| a.to_path_buf())).collect();
    let mut found = Vec::new();
    for folder in folders {
        let cargo = folder.join(".cargo");
        for config in ["config.toml", "config"].map(|name| cargo.join(name)) {
            found.extend(vendored(&config).into_iter().map(|dir| folder.join(dir)));
        }
        found.push(cargo);
    }
    found
}

/// The `directory` of every `[source.NAME]` of a cargo configuration file, as written (a
/// relative one is relative to the folder holding `.cargo/`).
fn vendored(config: &std::path::Path) -> Vec<PathBuf> {
    let Ok(text) = std::fs::read_to_string(config) else { return Vec::new() };
    let Ok(table) = text.parse::<toml::Table>() else { return Vec::new() };
    let sources = table.get("source").and_then(|s| s.as_table()).into_iter().flat_map(|s| s.values());
    sources.filter_map(|s| s.get("directory")?.as_str().map(PathBuf::from)).collect()
}

/// Where cargo and rustup keep the toolchain and the crates' sources: `CARGO_HOME` and
/// `RUSTUP_HOME`, by default `~/.cargo` and `~/.rustup`.
pub(super) fn toolchain() -> Vec<PathBuf> {
    let home = std::env::var_os("HOME").map(PathBuf::from).unwrap_or_default();
    let or =
        |var: &str, default: &str| std::env::var_os(var).map(PathBuf::from).unwrap_or(home.join(default));
    vec![or("CARGO_HOME", ".cargo"), or("RUSTUP_HOME", ".rustup")]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A build reads the `.cargo` folders above its tree and the vendored sources they name.
    #[test]
    fn a_build_reads_cargo_configs_above_it_and_their_vendored_sources() {
        let dir = std::env::temp_dir().join(format!("raylab-vendored-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("repo/.cargo")).unwrap();
        let config =
            "[source.crates-io]\nreplace-with = \"v\"\n[source.v]\ndirectory = \"/autograder/vendor\"\n";
        std::fs::write(dir.join("repo/.cargo/config.toml"), config).unwrap();
        let reads = cargo_configs(&[dir.join("repo/work/tree")]);
        let _ = std::fs::remove_dir_all(&dir);
        assert!(reads.contains(&PathBuf::from("/autograder/vendor")), "{reads:?}");
        assert!(
            reads.contains(&dir.join("repo/.cargo")) && reads.contains(&dir.join("repo/work/tree/.cargo"))
        );
    }
}
