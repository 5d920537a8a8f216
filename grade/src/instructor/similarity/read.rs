//! The texts the engine compares: the instructor's tree's stubs and solution, and a submission's
//! regions, read with the hostile-submission file rules of [`submission_file`] (no links on the
//! way, plain files of bounded size, UTF-8, lexed before anything else).

use std::collections::BTreeMap;
use std::path::Path;

use crate::file_error::FileError;
use crate::instructor::similarity::test_set::region_id;
use crate::instructor::similarity::Author;
use crate::regions::baseline::regions_of;
use crate::regions::markers::Region;
use crate::regions::stub::{is_stub, stub_body};
use crate::submission::splice::submission_file;
use crate::submission::submission_root;

/// What the instructor's tree has for every region: the starter's stub and the solution.
pub struct TreeRegions {
    /// Each region's stub, as the starter has it.
    pub stubs: BTreeMap<String, String>,
    /// The solution, as an author named `solution`.
    pub solution: Author,
}

/// Reads every region of the instructor's tree at `root`.
pub fn tree_regions(root: &Path) -> Result<TreeRegions, FileError> {
    let mut stubs = BTreeMap::new();
    let mut solution = Author { name: "solution".to_string(), regions: BTreeMap::new() };
    for region in regions_of(root)? {
        let Ok((text, found)) = submission_file(root, &region.file) else { continue };
        let id = id_of(&region.file, &region.function);
        for f in found.iter().filter(|f| f.checkpoint == region.checkpoint && f.function == region.function) {
            stubs.insert(id.clone(), stub_body(&text, f.body.clone(), f.checkpoint));
            solution.regions.insert(id.clone(), text[f.body.clone()].to_string());
        }
    }
    Ok(TreeRegions { stubs, solution })
}

/// Which of `regions` (the instructor's tree's) a submission at `dir` wrote: not those still the
/// stub, nor those it lacks or whose file the rules refuse; named `name`.
pub fn student(name: &str, dir: &Path, regions: &[Region]) -> Author {
    let dir = submission_root(dir);
    let mut written = BTreeMap::new();
    for region in regions {
        let Ok((text, found)) = submission_file(&dir, &region.file) else { continue };
        let Some(f) =
            found.iter().find(|f| f.checkpoint == region.checkpoint && f.function == region.function)
        else {
            continue;
        };
        if !is_stub(&text, f.body.clone(), f.checkpoint) {
            written.insert(id_of(&region.file, &region.function), text[f.body.clone()].to_string());
        }
    }
    Author { name: name.to_string(), regions: written }
}

/// A region's id from its file (relative, `/`-separated) and function.
fn id_of(file: &Path, function: &str) -> String {
    let file: Vec<String> = file.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    region_id(&file.join("/"), function)
}
