//! How much a child may leave behind in the folders it may write, over all its files.
//!
//! `RLIMIT_FSIZE` bounds one file; nothing in the kernel that a process without privileges can set
//! bounds the sum (a tmpfs of fixed size needs a mount, which Gradescope's container refuses). So
//! the grader measures: while the child runs it walks the child's writable folders four times a
//! second and kills the child's group as soon as they hold more than [`Budget`] beyond what they
//! held when it started. What can slip past is what the child writes between two looks: at most
//! a quarter of a second at the disk's speed, on top of the budget.

use std::path::PathBuf;
use std::time::{Duration, Instant};

/// What a child may add to its writable folders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Bytes of disk, counted as the blocks each file holds (a sparse file costs what it stores).
    pub bytes: u64,
    /// Files, folders and links: each costs an inode, which can run out before the bytes do.
    pub entries: u64,
}

/// Bytes and entries under some folders.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Usage {
    bytes: u64,
    entries: u64,
}

/// How often the folders are measured.
const EVERY: Duration = Duration::from_millis(250);

/// Watches a child's writable folders against its budget.
#[derive(Debug)]
pub struct Watch {
    folders: Vec<PathBuf>,
    allowed: Usage,
    last: Instant,
}

impl Watch {
    /// Starts watching `folders`, allowing `budget` more than they hold now.
    pub fn start(folders: &[PathBuf], budget: Budget) -> Watch {
        let now = usage(folders, None);
        let allowed = Usage { bytes: now.bytes + budget.bytes, entries: now.entries + budget.entries };
        Watch { folders: folders.to_vec(), allowed, last: Instant::now() }
    }

    /// Whether the folders hold more than allowed; measured at most every [`EVERY`].
    pub fn exceeded(&mut self) -> bool {
        if self.last.elapsed() < EVERY {
            return false;
        }
        self.last = Instant::now();
        let now = usage(&self.folders, Some(self.allowed));
        now.bytes > self.allowed.bytes || now.entries > self.allowed.entries
    }
}

/// What `folders` hold, symbolic links not followed; the walk stops once it passes `stop`.
fn usage(folders: &[PathBuf], stop: Option<Usage>) -> Usage {
    let mut total = Usage::default();
    let mut pending: Vec<PathBuf> = folders.to_vec();
    while let Some(dir) = pending.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let Ok(meta) = entry.metadata() else { continue };
            total.entries += 1;
            total.bytes += disk_bytes(&meta);
            if meta.is_dir() {
                pending.push(entry.path());
            }
        }
        if stop.is_some_and(|s| total.bytes > s.bytes || total.entries > s.entries) {
            break;
        }
    }
    total
}

/// The disk a file holds.
#[cfg(unix)]
fn disk_bytes(meta: &std::fs::Metadata) -> u64 {
    std::os::unix::fs::MetadataExt::blocks(meta) * 512
}

/// The disk a file holds.
#[cfg(not(unix))]
fn disk_bytes(meta: &std::fs::Metadata) -> u64 {
    meta.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("raylab-written-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Only what is added counts; many files under the per-file limit add up.
    #[test]
    fn the_budget_counts_what_is_added_over_all_files() {
        let dir = folder("bytes");
        std::fs::write(dir.join("before.bin"), vec![1u8; 1 << 20]).unwrap();
        let mut watch = Watch::start(std::slice::from_ref(&dir), Budget { bytes: 1 << 20, entries: 100 });
        watch.last -= EVERY;
        assert!(!watch.exceeded(), "what was there before is not counted");
        for i in 0..3 {
            std::fs::write(dir.join(format!("{i}.bin")), vec![1u8; 512 << 10]).unwrap();
        }
        watch.last -= EVERY;
        assert!(watch.exceeded(), "1.5 MiB in three files passes a 1 MiB budget");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Empty files cost no bytes but an inode each.
    #[test]
    fn the_budget_counts_entries() {
        let dir = folder("entries");
        let mut watch = Watch::start(std::slice::from_ref(&dir), Budget { bytes: 1 << 20, entries: 10 });
        std::fs::create_dir(dir.join("sub")).unwrap();
        for i in 0..10 {
            std::fs::write(dir.join("sub").join(i.to_string()), "").unwrap();
        }
        watch.last -= EVERY;
        assert!(watch.exceeded(), "11 entries pass a budget of 10");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
