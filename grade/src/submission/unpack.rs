//! Submissions uploaded as zip archives, unpacked by a library (the `zip` crate), not by the
//! `unzip` program, with bounds a hostile archive cannot pass.
//!
//! An entry whose name is absolute or climbs out with `..` ([`zip::read::ZipFile::enclosed_name`]),
//! and any link, is refused; so are more than [`MAX_ENTRIES`] entries, and more bytes in all than
//! [`MAX_TOTAL_BYTES`] or [`MAX_RATIO`] times the archive's own size, counted as they are written
//! (a header's sizes are the archive's word, not a fact). A refused archive leaves nothing
//! behind, and its error names the entry.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use crate::plain::{kind, quote, FileKind};

/// No submission has more entries than this: the starter has a few hundred files.
pub const MAX_ENTRIES: usize = 20_000;
/// Nor unpacks to more than this: the starter is a few megabytes.
pub const MAX_TOTAL_BYTES: u64 = 256 << 20;
/// Source and meshes compress by 3 to 10 times; a zip bomb by a thousand or more. Archives under
/// [`RATIO_FLOOR`] bytes unpacked are not held to it.
pub const MAX_RATIO: u64 = 100;
/// See [`MAX_RATIO`].
pub const RATIO_FLOOR: u64 = 16 << 20;

/// An archive that was not unpacked: which, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot unpack: {why}", .archive.display())]
pub struct UnpackError {
    /// The archive.
    pub archive: PathBuf,
    /// Why.
    pub why: Refused,
}

/// Why an archive was not unpacked.
#[derive(Debug, thiserror::Error)]
pub enum Refused {
    /// It is a link, a folder or a device.
    #[error("not a plain file")]
    NotPlain,
    /// The system could not read it or write what it holds: the entry, if one.
    #[error("{}{source}", entry.as_ref().map(|e| format!("`{e}`: ")).unwrap_or_default())]
    Io {
        /// The entry's name, quoted for a report.
        entry: Option<String>,
        /// What the system said.
        source: std::io::Error,
    },
    /// The zip library could not read it, or one of its entries.
    #[error("not a zip archive ({0})")]
    NotZip(zip::result::ZipError),
    /// More entries than [`MAX_ENTRIES`].
    #[error("{0} entries, more than {MAX_ENTRIES}")]
    TooManyEntries(usize),
    /// An entry named by an absolute path or one that climbs out with `..`.
    #[error("`{0}`: an absolute path or one that leaves the archive's folder")]
    Escapes(String),
    /// An entry that is a link.
    #[error("`{0}`: a link; only files and folders are unpacked")]
    Link(String),
    /// More bytes unpacked than the budget for an archive of this size.
    #[error(
        "more than {} MiB unpacked from {} KiB (the limit: {MAX_RATIO} times the archive, at most {} MiB)",
        .budget >> 20,
        .size >> 10,
        MAX_TOTAL_BYTES >> 20
    )]
    Bomb {
        /// The bytes allowed.
        budget: u64,
        /// The archive's size.
        size: u64,
    },
}

/// Unpacks the zip at `archive` into `dest`, which must not exist yet; on any error `dest` is
/// removed and the error names the archive and the entry.
pub fn unpack_zip(archive: &Path, dest: &Path) -> Result<(), UnpackError> {
    let result = unpack(archive, dest);
    if result.is_err() {
        let _ = std::fs::remove_dir_all(dest);
    }
    result.map_err(|why| UnpackError { archive: archive.to_path_buf(), why })
}

/// A system error of `entry` (none: of the archive itself).
fn io(entry: Option<&str>) -> impl FnOnce(std::io::Error) -> Refused + '_ {
    move |source| Refused::Io { entry: entry.map(str::to_string), source }
}

fn unpack(archive: &Path, dest: &Path) -> Result<(), Refused> {
    if kind(archive) != Some(FileKind::File) {
        return Err(Refused::NotPlain);
    }
    let file = std::fs::File::open(archive).map_err(io(None))?;
    let size = file.metadata().map_err(io(None))?.len();
    let mut zip = zip::ZipArchive::new(file).map_err(Refused::NotZip)?;
    if zip.len() > MAX_ENTRIES {
        return Err(Refused::TooManyEntries(zip.len()));
    }
    let budget = MAX_TOTAL_BYTES.min(RATIO_FLOOR.max(size.saturating_mul(MAX_RATIO)));
    std::fs::create_dir(dest).map_err(io(None))?;
    let mut written = 0u64;
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).map_err(Refused::NotZip)?;
        let name = quote(entry.name());
        let Some(relative) = entry.enclosed_name() else { return Err(Refused::Escapes(name)) };
        if entry.is_symlink() {
            return Err(Refused::Link(name));
        }
        let io = || io(Some(&name));
        let path = dest.join(relative);
        if entry.is_dir() {
            std::fs::create_dir_all(&path).map_err(io())?;
            continue;
        }
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(io())?;
        }
        let mut out = std::fs::File::create_new(&path).map_err(io())?;
        let left = budget - written;
        written += std::io::copy(&mut (&mut entry).take(left + 1), &mut out).map_err(io())?;
        if written > budget {
            return Err(Refused::Bomb { budget, size });
        }
        out.flush().map_err(io())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use zip::write::SimpleFileOptions;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("raylab-unpack-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A zip of `files` (name, bytes), deflated, with `links` (name, target) as symbolic links.
    fn zip_of(path: &Path, files: &[(&str, &[u8])], links: &[(&str, &str)]) {
        let mut zip = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
        let options = SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        for (name, bytes) in files {
            zip.start_file(*name, options).unwrap();
            zip.write_all(bytes).unwrap();
        }
        for (name, target) in links {
            zip.add_symlink(*name, *target, options).unwrap();
        }
        zip.finish().unwrap();
    }

    #[test]
    fn grader_unpacks_a_plain_archive() {
        let dir = scratch("plain");
        zip_of(&dir.join("a.zip"), &[("raylab/src/lib.rs", b"pub mod a;"), ("raylab/README.md", b"")], &[]);
        unpack_zip(&dir.join("a.zip"), &dir.join("out")).unwrap();
        let text = std::fs::read_to_string(dir.join("out/raylab/src/lib.rs")).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(text, "pub mod a;");
    }

    /// Writes a hostile archive at the path it is given.
    type MakeArchive = fn(&Path);

    /// Each hostile archive is refused with the entry named, and leaves nothing behind.
    #[test]
    fn grader_refuses_links_escapes_bombs_and_non_archives() {
        let dir = scratch("hostile");
        let cases: [(&str, MakeArchive, &str); 5] = [
            ("escape", |p| zip_of(p, &[("../../outside.rs", b"x")], &[]), "leaves the archive"),
            ("absolute", |p| zip_of(p, &[("/etc/cron.d/x", b"x")], &[]), "an absolute path"),
            ("link", |p| zip_of(p, &[], &[("raylab/src/lib.rs", "/etc/passwd")]), "a link"),
            // 40 files of 6 MiB of zeros, 240 MiB in a quarter of a megabyte: each file is far
            // below any limit per file, their sum is not (the hostile archive had 40 of 60 MiB).
            (
                "bomb",
                |p| {
                    let zeros = vec![0u8; 6 << 20];
                    let names: Vec<String> = (0..40).map(|i| format!("f{i}")).collect();
                    let files: Vec<(&str, &[u8])> =
                        names.iter().map(|n| (n.as_str(), zeros.as_slice())).collect();
                    zip_of(p, &files, &[])
                },
                "unpacked from",
            ),
            ("garbage", |p| std::fs::write(p, b"PK\x03\x04 not really").unwrap(), "not a zip archive"),
        ];
        for (name, make, reason) in cases {
            let archive = dir.join(format!("{name}.zip"));
            make(&archive);
            let dest = dir.join(name);
            let error = unpack_zip(&archive, &dest).unwrap_err().to_string();
            assert!(error.contains(reason), "{name}: {error}");
            assert!(!dest.exists(), "{name}: left {}", dest.display());
        }
        let outside = dir.parent().unwrap().join("outside.rs").exists();
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(!outside);
    }
}
