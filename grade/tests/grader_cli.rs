//! The grader as instructors and students meet it (images only here: `--skip-tests`, so these
//! tests never run `cargo test` recursively). Named `grader_*`, outside every checkpoint filter.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    // The repository: this crate sits in its `grade/` folder.
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn grader(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grader"))
        .args(args)
        .env_remove("RAYLAB_GRADER_CHILD")
        .output()
        .expect("grader runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-grader-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A copy of what grading reads: rubric and handouts, scenes, references, and the crate root
/// whose public modules the rubric's `student_api` names.
fn copy_grading_inputs(to: &Path) {
    std::fs::create_dir_all(to.join("src")).unwrap();
    std::fs::copy(root().join("src/lib.rs"), to.join("src/lib.rs")).unwrap();
    for dir in ["checkpoints", "scenes", "scenes/meshes", "reference"] {
        std::fs::create_dir_all(to.join(dir)).unwrap();
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.is_file() {
                std::fs::copy(&path, to.join(dir).join(path.file_name().unwrap())).unwrap();
            }
        }
    }
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn grader_gives_the_solution_full_image_marks_and_writes_every_report() {
    let dir = scratch("full");
    let (json, html, out) = (dir.join("results.json"), dir.join("html"), dir.join("out"));
    let root = root();
    let result = grader(&[
        "--all",
        "--skip-tests",
        "--root",
        root.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(0), "{}", stderr(&result));
    let table = String::from_utf8_lossy(&result.stdout);
    // 40 public image points and 8 hidden ones.
    assert!(table.contains("total: 48.0 / 48 points"), "{table}");

    // Gradescope's field names, exactly.
    let results: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let mut top: Vec<&str> = results.as_object().unwrap().keys().map(String::as_str).collect();
    top.sort();
    assert_eq!(top, ["execution_time", "output", "score", "tests"]);
    for test in results["tests"].as_array().unwrap() {
        let mut keys: Vec<&str> = test.as_object().unwrap().keys().map(String::as_str).collect();
        keys.sort();
        assert_eq!(keys, ["max_score", "name", "number", "output", "score", "status", "visibility"]);
        assert_eq!(test["status"], "passed");
    }
    assert_eq!(results["score"], 48.0);

    // The HTML report: self-contained, three images per scene.
    let page = std::fs::read_to_string(html.join("index.html")).unwrap();
    assert!(page.starts_with("<!doctype html>") && page.trim_end().ends_with("</html>"));
    for scene in ["intersection_test", "cornell_direct", "cornell_refract", "aliasing"] {
        let start =
            page.find(&format!("id=\"scene-{scene}\"")).unwrap_or_else(|| panic!("no section for {scene}"));
        let section = &page[start..start + page[start..].find("</section>").unwrap()];
        assert_eq!(section.matches("<img ").count(), 3, "{scene}: reference, yours, difference");
        assert_eq!(section.matches("src=\"data:image/png;base64,").count(), 3, "{scene}: embedded");
        assert!(
            out.join(format!("{scene}.png")).is_file() && out.join(format!("{scene}.diff.png")).is_file()
        );
    }
    // A hidden scene: its checks, never its images.
    for scene in ["gem_gallery", "lamp_corner", "picket_fence"] {
        let start =
            page.find(&format!("id=\"scene-{scene}\"")).unwrap_or_else(|| panic!("no section for {scene}"));
        let section = &page[start..start + page[start..].find("</section>").unwrap()];
        assert_eq!(section.matches("<img ").count(), 0, "{scene} is hidden");
        assert!(section.contains("ssim"), "{scene}: its checks");
        assert!(
            !out.join(format!("{scene}.png")).exists() && !out.join(format!("{scene}.diff.png")).exists()
        );
    }
    assert!(!page.contains("src=\"http"), "nothing is fetched");
}

#[test]
fn grader_refuses_a_stale_reference() {
    let dir = scratch("stale");
    copy_grading_inputs(&dir);
    let scene = dir.join("scenes/cornell_direct.toml");
    let text = std::fs::read_to_string(&scene).unwrap().replace("flux = [40, 40, 40]", "flux = [41, 40, 40]");
    std::fs::write(&scene, text).unwrap();
    let out = grader(&["--checkpoint", "6", "--skip-tests", "--root", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("reference/cornell_direct.png is stale") && err.contains("update-references"),
        "{err}"
    );
}

#[test]
fn grader_reports_a_missing_reference_and_a_wrong_size_in_one_line() {
    let dir = scratch("missing");
    copy_grading_inputs(&dir);
    std::fs::remove_file(dir.join("reference/aliasing.png")).unwrap();
    let out = grader(&["aliasing", "--skip-tests", "--root", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("aliasing.png"), "{}", stderr(&out));

    // A reference of the wrong size is bad input too.
    image::RgbImage::new(64, 64).save(dir.join("reference/aliasing.png")).unwrap();
    let out = grader(&["aliasing", "--skip-tests", "--root", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("aliasing.png: the image is 64x64 but the scene renders 256x256"),
        "{}",
        stderr(&out)
    );
}

/// Bad input is the instructor's or the student's to fix, never the grader's crash: every
/// subcommand that reads a rubric refuses a broken one in one line naming the file, its line and
/// the field's problem, with exit code 2, before it builds or renders anything.
#[test]
fn grader_refuses_a_broken_rubric_in_one_line_from_every_subcommand() {
    let dir = scratch("broken-rubric");
    copy_grading_inputs(&dir);
    let rubric = dir.join("checkpoints/rubric.toml");
    let text = std::fs::read_to_string(&rubric).unwrap();
    let line = text.lines().position(|l| l.starts_with("test_points = ")).unwrap() + 1;
    let broken: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { "test_points = \"five\"".to_string() } else { l.to_string() })
        .collect();
    std::fs::write(&rubric, broken.join("\n")).unwrap();
    let (root, out) = (dir.to_str().unwrap(), dir.join("out"));
    let out = out.to_str().unwrap();
    let mut commands = vec![
        vec!["--skip-tests", "--root", root],
        vec!["watch", "--root", root],
        vec!["submission", root, "--root", root, "--no-sandbox", "--work", out],
        vec!["batch", root, "--root", root, "--out", out, "--no-sandbox"],
    ];
    if cfg!(feature = "instructor") {
        commands.extend([
            vec!["update-references", "--root", root],
            vec!["calibrate", "--check", "--root", root],
            vec!["fingerprints", "--root", root, "--table", out],
            vec!["package", "gradescope", "--root", root, "--out", out],
        ]);
    }
    let expected = format!("grader: {}:{line}: invalid type: string \"five\"", rubric.display());
    for args in commands {
        let output = grader(&args);
        let last = stderr(&output).lines().last().unwrap_or_default().to_string();
        assert_eq!(output.status.code(), Some(2), "{args:?}: {}", stderr(&output));
        assert!(last.starts_with(&expected), "{args:?}: {last}");
        assert!(!stderr(&output).contains("panicked"), "{args:?}: {}", stderr(&output));
    }
    assert!(!Path::new(out).exists(), "nothing was built or written");
}

/// The commands that read no rubric refuse their own bad input the same way: a missing image, an
/// unknown variant.
#[test]
fn grader_refuses_a_missing_image_and_an_unknown_variant_in_one_line() {
    let missing = root().join("reference/no_such_scene.png");
    let output = grader(&["compare", missing.to_str().unwrap(), missing.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(stderr(&output).lines().count(), 1, "{}", stderr(&output));
    assert!(stderr(&output).contains("no_such_scene.png"), "{}", stderr(&output));
    if cfg!(feature = "instructor") {
        let out = scratch("variant");
        let args = ["make-variant", "no_such_mistake", "--out", out.to_str().unwrap(), "--root", "."];
        let output =
            Command::new(env!("CARGO_BIN_EXE_grader")).args(args).current_dir(root()).output().unwrap();
        assert_eq!(output.status.code(), Some(2));
        assert!(
            stderr(&output).starts_with("grader: checkpoints/variants.toml: no variant `no_such_mistake`"),
            "{}",
            stderr(&output)
        );
    }
}

#[test]
fn grader_compare_prints_ssim_and_rejects_sizes_that_differ() {
    let reference = root().join("reference/cornell_direct.png");
    let out = grader(&["compare", reference.to_str().unwrap(), reference.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let values: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(values["ssim"], 1.0);
    let other = root().join("reference/aliasing.png");
    let out = grader(&["compare", reference.to_str().unwrap(), other.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("differ in size"), "{}", stderr(&out));
}

/// Output into a pipe whose reader is gone (`grader compare A B | head -1`) ends the grader
/// quietly, without a panic and its backtrace.
#[test]
fn grader_ends_quietly_when_its_reader_stops() {
    let reference = root().join("reference/cornell_direct.png");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_grader"))
        .args(["compare", reference.to_str().unwrap(), reference.to_str().unwrap()])
        .stdout(writer)
        .output()
        .unwrap();
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}

#[test]
fn grader_never_recurses_inside_its_own_children() {
    let out = Command::new(env!("CARGO_BIN_EXE_grader"))
        .args(["--all", "--root", root().to_str().unwrap()])
        .env("RAYLAB_GRADER_CHILD", "1")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("refusing"), "{}", stderr(&out));
}

#[test]
fn grader_rubric_as_loaded() {
    let rubric =
        raylab_grade::rubric::Rubric::load(&root().join("checkpoints/rubric.toml"), &root()).unwrap();
    assert_eq!(rubric.total_points(), 100.0);
    insta::assert_debug_snapshot!(rubric);
}

#[test]
fn grader_report_for_the_solution() {
    let out = grader(&["--all", "--skip-tests", "--root", root().to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    // Times vary from run to run; everything else is deterministic.
    let table = String::from_utf8_lossy(&out.stdout);
    let is_seconds = |w: &str| w.strip_suffix('s').is_some_and(|n| n.parse::<f64>().is_ok());
    let stable: Vec<String> = table
        .lines()
        .map(|line| {
            let words: Vec<&str> = line.split(' ').collect();
            let redacted: Vec<&str> = words
                .iter()
                .enumerate()
                .map(|(i, w)| {
                    let before_unit = words.get(i + 1) == Some(&"s") && w.parse::<f64>().is_ok();
                    if is_seconds(w) || before_unit {
                        "<time>"
                    } else {
                        w
                    }
                })
                .collect();
            // A time's width varies ("9.8s", "10.2s"): one space before it, whatever its padding.
            let line = redacted.join(" ");
            match line.find("<time>") {
                Some(i) => format!("{} {}", line[..i].trim_end(), line[i..].trim_end()),
                None => line.trim_end().to_string(),
            }
        })
        .collect();
    insta::assert_snapshot!(stable.join("\n"));
}

/// `grader watch` on the solution, from its last checkpoint: it passes at once, says so, and
/// ends (a smoke test of the real loop; the loop's logic is tested with synthetic saves).
#[test]
fn grader_watch_moves_past_a_passing_checkpoint_and_ends() {
    let root = root();
    let mut child = Command::new(env!("CARGO_BIN_EXE_grader"))
        .args(["watch", "--from", "9", "--root", root.to_str().unwrap()])
        .env_remove("RAYLAB_GRADER_CHILD")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("grader runs");
    // Generous: the first run may compile the tests and the renderer.
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(600);
    while child.try_wait().unwrap().is_none() {
        if std::time::Instant::now() > deadline {
            child.kill().unwrap();
            panic!("grader watch did not end");
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("checkpoint 9 passes: 20.0/20") && text.contains("every checkpoint up to 9 passes"),
        "{text}"
    );
}

/// A progress bar shared by several grades (as `grader submission` shares one) counts each grade's
/// steps from 0 to that grade's own total.
#[test]
fn grader_progress_counts_up_to_its_own_total_every_time() {
    let bar = indicatif::ProgressBar::hidden();
    for _ in 0..2 {
        let options = raylab_grade::grading::GradeOptions {
            checkpoints: Some(vec![2]),
            ..raylab_grade::grading::GradeOptions::new(root())
        };
        raylab_grade::grading::grade(&options, &bar).unwrap();
        assert_eq!(Some(bar.position()), bar.length());
    }
}

/// `grader batch` counts students: one step each, up to the class's size, also for submissions
/// that cannot be graded.
#[test]
fn grader_batch_progress_counts_up_to_the_class_size() {
    let class = scratch("progress-class");
    // Archives that are not zips: each costs its row, and the bar a step, in no time.
    for student in ["alice", "bob"] {
        std::fs::write(class.join(format!("{student}.zip")), "not a zip").unwrap();
    }
    let out = scratch("progress-out");
    let bar = indicatif::ProgressBar::hidden();
    let rows = raylab_grade::submission::batch::grade_all(&root(), std::slice::from_ref(&class), &out, &bar)
        .unwrap();
    std::fs::remove_dir_all(&class).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!((bar.position(), bar.length()), (2, Some(2)));
}

/// A student's tree: the solution's region files with each region's body replaced by `author`'s.
#[cfg(feature = "instructor")]
fn student_tree(dir: &Path, author: &raylab_grade::instructor::similarity::Author) {
    use raylab_grade::regions::markers::find_regions;
    for (id, body) in &author.regions {
        let (file, function) = id.rsplit_once("::").unwrap();
        let path = dir.join(file);
        let text =
            std::fs::read_to_string(if path.exists() { path.clone() } else { root().join(file) }).unwrap();
        let found = find_regions(&text).unwrap().into_iter().find(|f| f.function == function).unwrap();
        // The END marker stays alone on its line.
        let newline = if body.ends_with('\n') { "" } else { "\n" };
        let edited = format!("{}{body}{newline}{}", &text[..found.body.start], &text[found.body.end..]);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, edited).unwrap();
    }
}

/// A class of four unseen authors, a disguised copy of the third, the solution disguised but for
/// one region, a copy of an earlier class's student, and a hostile tree; and that earlier class.
#[cfg(feature = "instructor")]
fn similarity_class(unseen: &[raylab_grade::instructor::similarity::Author]) -> (PathBuf, PathBuf) {
    use raylab_grade::instructor::similarity::disguise::{disguise, Disguise};
    let class = scratch("similarity-class");
    for author in &unseen[..4] {
        student_tree(&class.join(format!("student-{}", author.name)), author);
    }
    // A copy of the third under every disguise at once.
    let mut copy = unseen[2].clone();
    for (i, body) in copy.regions.values_mut().enumerate() {
        *body = disguise(body, &Disguise::ALL, i as u64);
    }
    student_tree(&class.join("copier"), &copy);
    // The published solution in disguise, one region its own (a catalogue variant differs from
    // the solution in one region too).
    let tree = raylab_grade::instructor::similarity::read::tree_regions(&root()).unwrap();
    let mut solution = unseen[0].clone();
    for (i, (id, body)) in solution.regions.iter_mut().enumerate().skip(1) {
        *body = disguise(&tree.solution.regions[id], &Disguise::ALL, i as u64);
    }
    student_tree(&class.join("from-the-solution"), &solution);
    // A student of an earlier class, whose code the first copied.
    let earlier = scratch("similarity-earlier");
    student_tree(&earlier.join("senior"), &unseen[4]);
    student_tree(&earlier.join("other-senior"), &unseen[5]);
    let mut first = unseen[4].clone();
    first
        .regions
        .values_mut()
        .for_each(|body| *body = disguise(body, &[Disguise::Rename, Disguise::Layout], 1));
    student_tree(&class.join("junior"), &first);
    hostile_tree(&class.join("hostile"), &unseen[3]);
    (class, earlier)
}

/// `author`'s tree at `hostile` with a region file that is a link out, one of bytes that are not
/// UTF-8, one that does not parse, a region nested 4,000 deep and one of 900 KB.
#[cfg(feature = "instructor")]
fn hostile_tree(hostile: &Path, author: &raylab_grade::instructor::similarity::Author) {
    student_tree(hostile, author);
    std::fs::remove_file(hostile.join("src/geometry/triangle.rs")).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", hostile.join("src/geometry/triangle.rs")).unwrap();
    std::fs::write(hostile.join("src/sampling.rs"), [0xff, 0xfe, b'{']).unwrap();
    // A region nested four thousand deep, and one of 900 KB: refused unread, never parsed.
    let mut huge = raylab_grade::instructor::similarity::Author::default();
    let deep = format!("{}{}\n", "(".repeat(4000), ")".repeat(4000));
    huge.regions.insert("src/geometry/aabb.rs::intersect".into(), deep);
    let long = format!("let x = 1;\n{}x\n", "let y = x + 1;\n".repeat(60_000));
    huge.regions.insert("src/geometry/bvh/traverse.rs::traverse".into(), long);
    student_tree(hostile, &huge);
    let material = std::fs::read_to_string(hostile.join("src/material.rs")).unwrap();
    std::fs::write(hostile.join("src/material.rs"), material.replace("let ", "let = ;;{ ")).unwrap();
}

#[test]
#[cfg(feature = "instructor")]
fn grader_similarity_flags_a_disguised_copy_and_reads_hostile_trees_without_harm() {
    use raylab_grade::instructor::similarity::test_set::{halves, independent};
    let authors = independent(&root()).unwrap();
    let (_, unseen) = halves(&authors);
    let (class, earlier) = similarity_class(unseen);
    let out = scratch("similarity-out");
    let output = grader(&[
        "similarity",
        class.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--against",
        earlier.to_str().unwrap(),
        "--root",
        root().to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(0), "{stdout}{}", stderr(&output));
    let copied = format!("flagged: copier and student-{}", unseen[2].name);
    let copied_other_way = format!("flagged: student-{} and copier", unseen[2].name);
    assert!(stdout.contains(&copied) || stdout.contains(&copied_other_way), "{stdout}");
    assert!(stdout.contains("flagged: from-the-solution and solution"), "{stdout}");
    assert!(stdout.contains("flagged: junior and earlier: senior"), "{stdout}");
    let page = std::fs::read_to_string(out.join("similarity.html")).unwrap();
    assert!(page.contains("<mark>") && page.contains("not evidence"), "the pair is shown side by side");
    let csv = std::fs::read_to_string(out.join("similarity.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + 28 + 8 + 16,
        "28 pairs of eight students, 8 with the solution, 16 with the seniors:\n{csv}"
    );
    assert!(!page.contains("root:x:0:0"), "a linked file is never read");
    assert!(page.contains("Not compared: hostile's intersect"), "the deep region is listed");
    assert!(page.contains("Not compared: hostile's traverse"), "the long region is listed");
    // Bad input: one line, exit 2.
    let similarity = |class: &str, out: &Path| {
        grader(&["similarity", class, "--out", out.to_str().unwrap(), "--root", root().to_str().unwrap()])
    };
    let missing = similarity("/no/such/class", &out);
    assert_eq!(missing.status.code(), Some(2), "{}", stderr(&missing));
    let lines = stderr(&missing);
    assert_eq!(
        lines.lines().filter(|l| l.starts_with("grader:") && l.contains("no/such/class")).count(),
        1,
        "{lines}"
    );
    let unwritable = similarity(class.to_str().unwrap(), &out.join("similarity.csv"));
    assert_eq!(unwritable.status.code(), Some(2), "{}", stderr(&unwritable));
}

#[test]
#[cfg(feature = "instructor")]
fn grader_batch_writes_the_similarity_section_beside_the_grades() {
    let class = scratch("batch-section-class");
    for student in ["alice", "bob"] {
        std::fs::write(class.join(format!("{student}.zip")), "not a zip").unwrap();
    }
    let out = scratch("batch-section-out");
    let paths =
        [class.to_str().unwrap(), out.to_str().unwrap(), root().to_str().unwrap()].map(str::to_string);
    let output = grader(&["batch", &paths[0], "--out", &paths[1], "--root", &paths[2], "--no-sandbox"]);
    assert_eq!(output.status.code(), Some(0), "{}", stderr(&output));
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        index.contains("<h2>Similar submissions</h2>") && index.contains("href='similarity/similarity.html'"),
        "{index}"
    );
    assert!(out.join("similarity/similarity.csv").exists() && out.join("grades.csv").exists());
    // Nothing of it in a student's files.
    for student in ["alice", "bob"] {
        let report = std::fs::read_to_string(out.join("students").join(student).join("report.txt")).unwrap();
        assert!(!report.contains("imilar"), "{report}");
    }
}
