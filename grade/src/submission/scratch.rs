//! Scratch copies of a tree, for building what is graded (a submission spliced into the
//! instructor's tree, a catalogue variant) without touching the original.
//!
//! Files are written only when their bytes change, so cargo, which compares modification times,
//! rebuilds only what changed when the same scratch folder is used again.

use std::path::Path;

/// What a copy of the tree never takes: version control and build output.
pub const NOT_COPIED: [&str; 3] = [".git", "target", "out"];

/// Makes `to` a copy of the tree `from`, leaving out the paths (relative to `from`) in `skip`:
/// what `to` holds from an earlier copy and `from` no longer has (a file renamed since) is removed,
/// but never a path in `skip` (a scratch tree's own `target`).
pub fn copy_tree(from: &Path, to: &Path, skip: &[&str]) -> std::io::Result<()> {
    copy_below(from, to, Path::new(""), skip)
}

/// Writes `bytes` to `path` unless it already holds them, so that cargo, which compares
/// modification times, rebuilds only what changed.
pub fn write_if_changed(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(());
    }
    std::fs::write(path, bytes)
}

fn copy_below(from: &Path, to: &Path, relative: &Path, skip: &[&str]) -> std::io::Result<()> {
    let skipped = |path: &Path| skip.iter().any(|s| Path::new(s) == path);
    std::fs::create_dir_all(to.join(relative))?;
    for entry in std::fs::read_dir(from.join(relative))? {
        let entry = entry?;
        let path = relative.join(entry.file_name());
        if skipped(&path) {
            continue;
        }
        let is_dir = entry.file_type()?.is_dir();
        let old = std::fs::symlink_metadata(to.join(&path));
        if old.is_ok_and(|old| old.is_dir() != is_dir) {
            remove(&to.join(&path))?;
        }
        if is_dir {
            copy_below(from, to, &path, skip)?;
        } else {
            write_if_changed(&to.join(&path), &std::fs::read(entry.path())?)?;
        }
    }
    for entry in std::fs::read_dir(to.join(relative))? {
        let path = relative.join(entry?.file_name());
        if !skipped(&path) && std::fs::symlink_metadata(from.join(&path)).is_err() {
            remove(&to.join(&path))?;
        }
    }
    Ok(())
}

/// Removes a file, a link or a whole folder.
fn remove(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path)?.is_dir() {
        true => std::fs::remove_dir_all(path),
        false => std::fs::remove_file(path),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(path: &Path, text: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }

    /// A scratch folder used again ends as a fresh copy would: what the tree renamed or removed
    /// since is gone (a stale `noisy.rs` beside a new `noisy/mod.rs` stops the build), a folder
    /// that became a file is replaced, a skipped folder is kept, an unchanged file is not
    /// rewritten.
    #[test]
    fn a_copy_over_an_old_copy_keeps_nothing_stale_but_what_it_skips() {
        let dir = std::env::temp_dir().join(format!("raylab-scratch-{}", std::process::id()));
        let (from, to) = (dir.join("from"), dir.join("to"));
        let _ = std::fs::remove_dir_all(&dir);
        write(&from.join("src/noisy.rs"), "old");
        write(&from.join("src/lib.rs"), "same");
        write(&from.join("notes"), "a folder later");
        copy_tree(&from, &to, &["target"]).unwrap();
        write(&to.join("target/debug/keep"), "built");
        let unchanged = std::fs::metadata(to.join("src/lib.rs")).unwrap().modified().unwrap();

        std::fs::remove_file(from.join("src/noisy.rs")).unwrap();
        write(&from.join("src/noisy/mod.rs"), "new");
        std::fs::remove_file(from.join("notes")).unwrap();
        write(&from.join("notes/one.md"), "now a folder");
        copy_tree(&from, &to, &["target"]).unwrap();

        assert!(!to.join("src/noisy.rs").exists(), "the renamed file is gone");
        assert_eq!(std::fs::read_to_string(to.join("src/noisy/mod.rs")).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(to.join("notes/one.md")).unwrap(), "now a folder");
        assert_eq!(std::fs::read_to_string(to.join("target/debug/keep")).unwrap(), "built");
        let after = std::fs::metadata(to.join("src/lib.rs")).unwrap().modified().unwrap();
        assert_eq!(unchanged, after, "an unchanged file keeps its time, so cargo does not rebuild");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
