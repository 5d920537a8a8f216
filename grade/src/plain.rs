//! A submission's files, read as plain files only and with bounds.
//!
//! A student controls their tree: a region file may be a symbolic link into the instructor's
//! tree, to `/dev/zero` or to `/dev/stdin`, a FIFO, or a gigabyte of text. So every path of a
//! submission is examined without following links ([`walk`]), and a file is opened with
//! `O_NOFOLLOW | O_NONBLOCK` and checked to be a regular file on the open handle before one byte is
//! read ([`read_plain`]): a link, a device, a FIFO or a socket is never read, and no read goes past
//! its limit. What a child, a compiler or a file name says is quoted in a report only through
//! [`quote()`]: one line, bounded.

use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// No file of a submission is read past this many bytes: the largest file of the starter is far
/// below it (a region file is a few kilobytes; a scene's mesh under 100 KiB).
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// What a path is, without following links.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A regular file.
    File,
    /// A folder.
    Dir,
    /// Anything else: never opened. Its name for a report ("a symbolic link").
    Other(&'static str),
}

/// Why a file was not read.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotRead {
    /// Nothing at that path.
    Missing,
    /// Not a regular file: what it is.
    NotPlain(&'static str),
    /// Longer than the limit.
    TooLarge(u64),
    /// Its text is not UTF-8: the first byte that is not.
    NotUtf8(usize),
    /// Any other error, as the system words it.
    Io(String),
}

impl std::fmt::Display for NotRead {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotRead::Missing => write!(f, "missing"),
            NotRead::NotPlain(what) => write!(f, "{what}, not a plain file: never read"),
            NotRead::TooLarge(limit) => write!(f, "larger than {} KiB: not read", limit / 1024),
            NotRead::NotUtf8(byte) => write!(f, "not UTF-8 at byte {byte}"),
            NotRead::Io(e) => write!(f, "{e}"),
        }
    }
}

/// What `path` is, without following a link; `None` if nothing is there.
pub fn kind(path: &Path) -> Option<FileKind> {
    let file_type = std::fs::symlink_metadata(path).ok()?.file_type();
    Some(if file_type.is_file() {
        FileKind::File
    } else if file_type.is_dir() {
        FileKind::Dir
    } else {
        FileKind::Other(describe(&file_type))
    })
}

fn describe(file_type: &std::fs::FileType) -> &'static str {
    if file_type.is_symlink() {
        "a symbolic link"
    } else if file_type.is_fifo() {
        "a FIFO"
    } else if file_type.is_socket() {
        "a socket"
    } else if file_type.is_block_device() || file_type.is_char_device() {
        "a device"
    } else {
        "not a file"
    }
}

/// The bytes of the regular file at `path`, at most `limit` of them; its last component is never
/// followed if it is a link (the folders above it must come from [`walk`] or be the grader's).
pub fn read_plain(path: &Path, limit: u64) -> Result<Vec<u8>, NotRead> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(|e| match e.raw_os_error() {
            Some(libc::ELOOP) => NotRead::NotPlain("a symbolic link"),
            _ if e.kind() == std::io::ErrorKind::NotFound => NotRead::Missing,
            _ => NotRead::Io(e.to_string()),
        })?;
    let file_type = file.metadata().map_err(|e| NotRead::Io(e.to_string()))?.file_type();
    if !file_type.is_file() {
        return Err(NotRead::NotPlain(describe(&file_type)));
    }
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| NotRead::Io(e.to_string()))?;
    if bytes.len() as u64 > limit {
        return Err(NotRead::TooLarge(limit));
    }
    Ok(bytes)
}

/// A plain file's text. Line endings `\r\n` are read as `\n` (line numbers stay the same).
pub fn read_text(path: &Path, limit: u64) -> Result<String, NotRead> {
    let bytes = read_plain(path, limit)?;
    let text = String::from_utf8(bytes).map_err(|e| NotRead::NotUtf8(e.utf8_error().valid_up_to()))?;
    Ok(if text.contains("\r\n") { text.replace("\r\n", "\n") } else { text })
}

/// Every path below `dir`, relative to it, with what it is, in a stable order; links are listed,
/// never followed, and `skip` names (relative paths) are left out with everything below them.
pub fn walk(dir: &Path, skip: &[&str]) -> std::io::Result<Vec<(PathBuf, FileKind)>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(relative) = stack.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(dir.join(&relative))?.collect::<Result<_, _>>()?;
        entries.sort_by_key(|e| std::cmp::Reverse(e.file_name()));
        for entry in entries {
            let path = relative.join(entry.file_name());
            if skip.iter().any(|s| path == Path::new(s)) {
                continue;
            }
            let kind = kind(&entry.path()).unwrap_or(FileKind::Other("gone"));
            if kind == FileKind::Dir {
                stack.push(path.clone());
            }
            out.push((path, kind));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

/// Whether `path` is a folder, not a link to one.
pub fn is_plain_dir(path: &Path) -> bool {
    kind(path) == Some(FileKind::Dir)
}

/// The longest quote of a child's text in a report.
pub const MAX_QUOTE_CHARS: usize = 200;

/// Text a child or a compiler wrote, made fit for a report: one line, control characters
/// (terminal escapes, carriage returns, tabs) replaced by spaces and runs of white space folded,
/// at most [`MAX_QUOTE_CHARS`] characters (cut with "...").
pub fn quote(text: &str) -> String {
    let cleaned: String = text.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    let words: Vec<&str> = cleaned.split_whitespace().collect();
    let line = words.join(" ");
    match line.char_indices().nth(MAX_QUOTE_CHARS) {
        Some((cut, _)) => format!("{}...", &line[..cut]),
        None => line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("raylab-plain-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn grader_reads_no_link_device_or_fifo() {
        let dir = scratch("links");
        std::fs::write(dir.join("real.rs"), "fn a() {}").unwrap();
        std::os::unix::fs::symlink(dir.join("real.rs"), dir.join("link.rs")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", dir.join("zero.rs")).unwrap();
        std::os::unix::fs::symlink("/dev/stdin", dir.join("stdin.rs")).unwrap();
        let fifo = std::ffi::CString::new(dir.join("fifo.rs").into_os_string().into_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
        let read = |name: &str| read_plain(&dir.join(name), MAX_FILE_BYTES);
        let results = ["real.rs", "link.rs", "zero.rs", "stdin.rs", "fifo.rs", "none.rs"].map(read);
        let listed = walk(&dir, &[]).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(results[0], Ok(b"fn a() {}".to_vec()));
        for r in &results[1..4] {
            assert_eq!(*r, Err(NotRead::NotPlain("a symbolic link")));
        }
        assert_eq!(results[4], Err(NotRead::NotPlain("a FIFO")));
        assert_eq!(results[5], Err(NotRead::Missing));
        let kinds: Vec<_> = listed.iter().map(|(p, k)| (p.to_str().unwrap(), *k)).collect();
        assert_eq!(
            kinds,
            [
                ("fifo.rs", FileKind::Other("a FIFO")),
                ("link.rs", FileKind::Other("a symbolic link")),
                ("real.rs", FileKind::File),
                ("stdin.rs", FileKind::Other("a symbolic link")),
                ("zero.rs", FileKind::Other("a symbolic link")),
            ]
        );
    }

    #[test]
    fn grader_reads_no_file_past_its_limit_and_names_the_first_bad_byte() {
        let dir = scratch("limits");
        std::fs::write(dir.join("big"), vec![b'a'; 2000]).unwrap();
        std::fs::write(dir.join("latin1.rs"), b"fn a() {}\n// caf\xe9\n").unwrap();
        std::fs::write(dir.join("crlf.rs"), "fn a() {\r\n}\r\n").unwrap();
        let big = (read_plain(&dir.join("big"), 1999), read_plain(&dir.join("big"), 2000).map(|b| b.len()));
        let texts = ["latin1.rs", "crlf.rs"].map(|n| read_text(&dir.join(n), MAX_FILE_BYTES));
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(big, (Err(NotRead::TooLarge(1999)), Ok(2000)));
        assert_eq!(texts, [Err(NotRead::NotUtf8(16)), Ok("fn a() {\n}\n".to_string())]);
    }

    #[test]
    fn grader_walks_into_no_linked_folder() {
        let dir = scratch("walk");
        std::fs::create_dir_all(dir.join("tree/src")).unwrap();
        std::fs::write(dir.join("tree/src/a.rs"), "").unwrap();
        std::fs::create_dir_all(dir.join("elsewhere")).unwrap();
        std::fs::write(dir.join("elsewhere/secret.rs"), "").unwrap();
        std::os::unix::fs::symlink(dir.join("elsewhere"), dir.join("tree/linked")).unwrap();
        let listed = walk(&dir.join("tree"), &[]).unwrap();
        let plain = (is_plain_dir(&dir.join("tree/src")), is_plain_dir(&dir.join("tree/linked")));
        std::fs::remove_dir_all(&dir).unwrap();
        let names: Vec<_> = listed.iter().map(|(p, _)| p.to_str().unwrap()).collect();
        assert_eq!(names, ["linked", "src", "src/a.rs"]);
        assert_eq!(plain, (true, false));
    }
}
