//! Scratch copies of a tree, for building what is graded (a submission spliced into the
//! instructor's tree, a catalogue variant) without touching the original.
//!
//! Files are written only when their bytes change, so cargo, which compares modification times,
//! rebuilds only what changed when the same scratch folder is used again.

use std::path::Path;

/// What a copy of the tree never takes: version control and build output.
pub const NOT_COPIED: [&str; 3] = [".git", "target", "out"];

/// Copies the tree `from` to `to`, leaving out the paths (relative to `from`) in `skip`.
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
    std::fs::create_dir_all(to.join(relative))?;
    for entry in std::fs::read_dir(from.join(relative))? {
        let entry = entry?;
        let path = relative.join(entry.file_name());
        if skip.iter().any(|s| Path::new(s) == path) {
            continue;
        }
        if entry.file_type()?.is_dir() {
            copy_below(from, to, &path, skip)?;
        } else {
            write_if_changed(&to.join(&path), &std::fs::read(entry.path())?)?;
        }
    }
    Ok(())
}
