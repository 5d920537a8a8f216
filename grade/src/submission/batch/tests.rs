//! A class as uploaded: one submission or a folder of them, zipped or not, never two students
//! merged, and a row kept for each submission that could not be graded.

use super::*;

/// `folder` zipped into `into` by the zip crate, its entries named from `folder`'s parent.
fn zip(folder: &Path, into: &Path) {
    use std::io::Write;
    let mut zip = zip::ZipWriter::new(std::fs::File::create(into).unwrap());
    let base = folder.parent().unwrap();
    let mut stack = vec![folder.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let name = dir.strip_prefix(base).unwrap().to_string_lossy().into_owned();
        zip.add_directory(name, zip::write::SimpleFileOptions::default()).unwrap();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let name = path.strip_prefix(base).unwrap().to_string_lossy().into_owned();
                zip.start_file(name, zip::write::SimpleFileOptions::default()).unwrap();
                zip.write_all(&std::fs::read(&path).unwrap()).unwrap();
            }
        }
    }
    zip.finish().unwrap();
}

fn folders(entries: &[Entry]) -> Vec<(String, Result<PathBuf, String>)> {
    entries.iter().map(|e| (e.student.clone(), e.dir.as_ref().cloned().map_err(|e| e.to_string()))).collect()
}

/// Folders, folders of folders, zips of either, and zips inside a folder (a student's upload),
/// with the tree at the top or one folder down.
#[test]
fn grader_finds_one_submission_or_a_folder_of_them_zipped_or_not() {
    let dir = std::env::temp_dir().join(format!("raylab-batch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let unpacked = dir.join("unpacked");
    for student in ["bob", "alice", "carol/raylab-main"] {
        std::fs::create_dir_all(dir.join("class").join(student).join("src")).unwrap();
    }
    let class = submissions(&[dir.join("class")], &unpacked).unwrap();
    let want = ["alice", "bob", "carol"].map(|s| (s.to_string(), Ok(dir.join("class").join(s))));
    assert_eq!(folders(&class), want, "one per subfolder, sorted");
    let bob = submissions(&[dir.join("class/bob")], &unpacked).unwrap();
    assert_eq!(folders(&bob), [("bob".to_string(), Ok(dir.join("class/bob")))]);
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    assert!(submissions(&[dir.join("empty")], &unpacked).is_err());

    // The same class as one zip, and carol's upload as a zip inside the folder.
    zip(&dir.join("class"), &dir.join("download.zip"));
    let zipped = submissions(&[dir.join("download.zip")], &unpacked).unwrap();
    let want =
        ["alice", "bob", "carol"].map(|s| (s.to_string(), Ok(unpacked.join("download-0/class").join(s))));
    assert_eq!(folders(&zipped), want);
    zip(&dir.join("class/carol/raylab-main"), &dir.join("class/carol.zip"));
    std::fs::remove_dir_all(dir.join("class/carol")).unwrap();
    let mixed = submissions(&[dir.join("class")], &unpacked).unwrap();
    assert_eq!(folders(&mixed)[2], ("carol".to_string(), Ok(unpacked.join("students/carol"))));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// One student's folder beside zips is a class, not alice's tree; a zip that does not unpack
/// is its student's row with the reason; a zip named like the grader's own files is a student
/// like any other; names that would climb out, hide or collide get folders of their own.
#[test]
fn grader_never_merges_students_nor_stops_at_a_broken_zip() {
    let dir = std::env::temp_dir().join(format!("raylab-batch-broken-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("class/alice/src")).unwrap();
    std::fs::create_dir_all(dir.join("bob/src")).unwrap();
    zip(&dir.join("bob"), &dir.join("class/grades.csv.zip"));
    std::fs::write(dir.join("class/mallory.zip"), b"PK\x03\x04 not a zip").unwrap();
    for copy in ["alice.zip", "..zip", "a b\nc.zip", ".hidden.zip"] {
        std::fs::copy(dir.join("class/grades.csv.zip"), dir.join("class").join(copy)).unwrap();
    }
    let unpacked = dir.join("unpacked");
    let class = submissions(&[dir.join("class")], &unpacked).unwrap();
    let names: Vec<&str> = class.iter().map(|e| e.student.as_str()).collect();
    let unpacked_ok: Vec<bool> =
        class.iter().map(|e| e.dir.as_ref().is_ok_and(|d| d.join("bob/src").is_dir())).collect();
    std::fs::remove_dir_all(&dir).unwrap();
    // Sorted by file name: "..zip", ".hidden.zip", "a b\nc.zip", "alice", "alice.zip", ...
    assert_eq!(names, ["submission", "_.hidden", "a_b_c", "alice", "alice-2", "grades.csv", "mallory"]);
    assert_eq!(unpacked_ok, [true, true, true, false, true, true, false], "{class:?}");
    assert!(
        class[6].dir.as_ref().is_err_and(|e| e.to_string().contains("mallory.zip: cannot unpack")),
        "{:?}",
        class[6]
    );
}

#[test]
fn grader_keeps_a_row_for_a_submission_it_could_not_grade() {
    let rows = vec![Row {
        student: "mallory \"m\"".to_string(),
        graded: Err(SubmissionError::NotAFolder(PathBuf::from("m"))),
    }];
    let table = csv(&rows);
    assert!(table.lines().nth(1).unwrap().starts_with("\"mallory \"\"m\"\"\","), "{table}");
    assert!(table.contains("not graded: m: not a folder"), "{table}");
    assert!(class_page(&rows, "").contains("1 submissions, 0 graded"));
}
