//! The independent implementations of the regions (`grade/tests/similarity/independent/`, one
//! TOML file an author): the null each region's similarity is scored against, and the material
//! the engine is measured on. Their README says how they were written.

use std::path::Path;

use serde::Deserialize;

use crate::file_error::{read_toml, FileError, Problem};
use crate::instructor::similarity::Author;
use crate::plain::NotRead;

/// Where the independent implementations are, relative to the instructor's tree.
pub const INDEPENDENT_DIR: &str = "grade/tests/similarity/independent";

/// One author's file (its `persona` and each region's `checkpoint` are for the reader).
#[derive(Deserialize)]
struct AuthorFile {
    region: Vec<RegionEntry>,
}

/// One region of an author's.
#[derive(Deserialize)]
struct RegionEntry {
    file: String,
    function: String,
    body: String,
}

/// A region's name in the engine: `file::function`.
pub fn region_id(file: &str, function: &str) -> String {
    format!("{file}::{function}")
}

/// The halves of the independent authors (in file-name order): the first is the null every
/// comparison is scored against and the flag threshold is set with; the second is never used
/// but to measure the engine, on authors it has not seen. The deployed engine is the measured
/// one: a null of other pairs would change the scores' scale (a likelihood ratio is bounded by
/// the number of pairs it counts) and the threshold would no longer mean what was measured.
pub fn halves(authors: &[Author]) -> (&[Author], &[Author]) {
    authors.split_at(authors.len() / 2)
}

/// Every independent author under `root`, in file-name order, named by the file's stem.
pub fn independent(root: &Path) -> Result<Vec<Author>, FileError> {
    let dir = root.join(INDEPENDENT_DIR);
    let entries = std::fs::read_dir(&dir)
        .map_err(|_| FileError { file: dir.clone(), problem: Problem::Unreadable(NotRead::Missing) })?;
    let mut files: Vec<_> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|path| {
            let file: AuthorFile = read_toml(path)?;
            let name = path.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
            let regions = file
                .region
                .into_iter()
                .map(|r| (region_id(&r.file, &r.function), format!("{}\n", r.body)))
                .collect();
            Ok(Author { name, regions })
        })
        .collect()
}
