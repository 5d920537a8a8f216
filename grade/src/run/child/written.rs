//! How much a child may leave behind in the folders it may write, over all its files.
//!
//! `RLIMIT_FSIZE` bounds one file; nothing in the kernel that a process without privileges can set
//! bounds the sum (a tmpfs of fixed size needs a mount, which Gradescope's container refuses). So
//! the grader measures: while the child runs it walks the child's writable folders four times a
//! second and kills the child's group as soon as they hold more than [`Budget`] beyond what they
//! held when it started. What can slip past is what the child writes between two looks: at most
//! a quarter of a second at the disk's speed, on top of the budget. A child quicker than one look
//! is measured once more when it ends: what it left behind counts all the same.
//!
//! A file that is open and unlinked (or made with `O_TMPFILE`) holds disk no walk can see. So the
//! grader also reads the child's own count of bytes written (`wchar` in `/proc/PID/io`, every
//! thread and reaped child included) and holds it to the same budget: a render writes one image,
//! a unit test next to nothing. Such a file gives its disk back when the last process holding it
//! ends, so it only matters while the child runs.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::run::sandbox::Budget;

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
    budget: Budget,
    process: Option<u32>,
    last: Instant,
}

impl Watch {
    /// Starts watching `folders`, allowing `budget` more than they hold now.
    pub fn start(folders: &[PathBuf], budget: Budget) -> Watch {
        let now = usage(folders, None);
        let allowed = Usage { bytes: now.bytes + budget.bytes, entries: now.entries + budget.entries };
        Watch { folders: folders.to_vec(), allowed, budget, process: None, last: Instant::now() }
    }

    /// Also holds the bytes process `pid` has written, wherever, to the budget.
    pub fn follow(&mut self, pid: u32) {
        self.process = Some(pid);
    }

    /// Whether the folders hold more than allowed, or the process wrote more than the budget;
    /// measured at most every `EVERY`.
    pub fn exceeded(&mut self) -> bool {
        if self.last.elapsed() < EVERY {
            return false;
        }
        self.last = Instant::now();
        let wrote = self.process.and_then(bytes_written).unwrap_or(0);
        wrote > self.budget.bytes || self.left_too_much()
    }

    /// Whether the folders hold more than allowed now: for the last look, once the child ended.
    pub fn left_too_much(&self) -> bool {
        let now = usage(&self.folders, Some(self.allowed));
        now.bytes > self.allowed.bytes || now.entries > self.allowed.entries
    }
}

/// The bytes process `pid` has passed to `write` and its kin (`wchar`), if the system tells.
fn bytes_written(pid: u32) -> Option<u64> {
    let io = std::fs::read_to_string(format!("/proc/{pid}/io")).ok()?;
    io.lines().find_map(|l| l.strip_prefix("wchar:")).and_then(|n| n.trim().parse().ok())
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
            // A folder of a million entries is not walked to its end.
            if stop.is_some_and(|s| total.bytes > s.bytes || total.entries > s.entries) {
                return total;
            }
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

    /// Only what is added counts; many files under the per-file limit add up.
    #[test]
    fn the_budget_counts_what_is_added_over_all_files() {
        let own = crate::run::child::OwnFolder::new().unwrap();
        let dir = own.path().to_path_buf();
        std::fs::write(dir.join("before.bin"), vec![1u8; 1 << 20]).unwrap();
        let mut watch = Watch::start(std::slice::from_ref(&dir), Budget { bytes: 1 << 20, entries: 100 });
        watch.last -= EVERY;
        assert!(!watch.exceeded(), "what was there before is not counted");
        for i in 0..3 {
            std::fs::write(dir.join(format!("{i}.bin")), vec![1u8; 512 << 10]).unwrap();
        }
        watch.last -= EVERY;
        assert!(watch.exceeded(), "1.5 MiB in three files passes a 1 MiB budget");
    }

    /// Empty files cost no bytes but an inode each.
    #[test]
    fn the_budget_counts_entries() {
        let own = crate::run::child::OwnFolder::new().unwrap();
        let dir = own.path().to_path_buf();
        let mut watch = Watch::start(std::slice::from_ref(&dir), Budget { bytes: 1 << 20, entries: 10 });
        std::fs::create_dir(dir.join("sub")).unwrap();
        for i in 0..10 {
            std::fs::write(dir.join("sub").join(i.to_string()), "").unwrap();
        }
        watch.last -= EVERY;
        assert!(watch.exceeded(), "11 entries pass a budget of 10");
    }
}
