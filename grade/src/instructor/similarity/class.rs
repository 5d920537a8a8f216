//! `grader similarity DIR... --out OUT`: a class's submissions compared, the flagged pairs and
//! clusters found, for a person to look at ([`super::page`] writes them). Nothing of it reaches a
//! grade, a `results.json` or a student's report.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::instructor::similarity::read::{student, tree_regions};
use crate::instructor::similarity::test_set::{halves, independent};
use crate::instructor::similarity::{compare, Author, Comparison, FLAG_SCORE};
use crate::regions::baseline::regions_of;
use crate::submission::batch::submissions;
use crate::submission::SubmissionError;

/// A class compared.
pub struct ClassSimilarity {
    /// The comparison: the students, then the solution, then the earlier classes' students.
    pub comparison: Comparison,
    /// How many of the authors are this class's students.
    pub students: usize,
    /// The submissions that could not be read, with why.
    pub unread: Vec<(String, String)>,
    /// Groups of three or more students joined by flagged pairs, each sorted.
    pub clusters: Vec<Vec<usize>>,
}

impl ClassSimilarity {
    /// The flagged pairs, highest score first.
    pub fn flagged(&self) -> impl Iterator<Item = &crate::instructor::similarity::Pair> {
        self.comparison.pairs.iter().filter(|p| p.score > FLAG_SCORE)
    }
}

/// Compares the submissions under `dirs` (read as `grader batch` finds them, zips unpacked into
/// `work`, removed after) with each other, with the solution and with those under `against`,
/// using the instructor's tree at `root`.
pub fn similarity(
    root: &Path,
    dirs: &[PathBuf],
    against: &[PathBuf],
    work: &Path,
) -> Result<ClassSimilarity, SubmissionError> {
    let regions = regions_of(root)?;
    let tree = tree_regions(root)?;
    let mut unread = Vec::new();
    let mut read = |dirs: &[PathBuf], folder: &str, prefix: &str| -> Result<Vec<Author>, SubmissionError> {
        let entries = submissions(dirs, &work.join(folder))?;
        Ok(entries
            .into_iter()
            .filter_map(|entry| match entry.dir {
                Ok(dir) => Some(student(&format!("{prefix}{}", entry.student), &dir, &regions)),
                Err(why) => {
                    unread.push((format!("{prefix}{}", entry.student), why.to_string()));
                    None
                }
            })
            .collect())
    };
    let students = read(dirs, "unpacked", "")?;
    let mut others = vec![tree.solution];
    if !against.is_empty() {
        others.extend(read(against, "earlier", "earlier: ")?);
    }
    let _ = std::fs::remove_dir_all(work);
    let independent = independent(root)?;
    let comparison = compare(&students, &others, halves(&independent).0, &tree.stubs);
    let clusters = clusters(&comparison, students.len());
    Ok(ClassSimilarity { comparison, students: students.len(), unread, clusters })
}

/// The groups of three or more of the first `students` authors that flagged pairs join.
fn clusters(comparison: &Comparison, students: usize) -> Vec<Vec<usize>> {
    let mut group: Vec<usize> = (0..students).collect();
    fn find(group: &mut [usize], i: usize) -> usize {
        let mut root = i;
        while group[root] != root {
            root = group[root];
        }
        group[i] = root;
        root
    }
    for pair in comparison.pairs.iter().filter(|p| p.score > FLAG_SCORE && p.b < students) {
        let (a, b) = (find(&mut group, pair.a), find(&mut group, pair.b));
        group[a.max(b)] = a.min(b);
    }
    let mut members: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..students {
        let root = find(&mut group, i);
        members.entry(root).or_default().push(i);
    }
    members.into_values().filter(|m| m.len() >= 3).collect()
}
