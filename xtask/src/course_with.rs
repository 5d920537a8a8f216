//! A course that adds a checkpoint, made and graded with no change to the grader or to this
//! crate: `cargo xtask course-with-extra` copies the tree and adds checkpoint 10, "Mirror
//! reflection", as docs/INSTRUCTORS.md ("Add or change a checkpoint") tells an instructor to:
//!
//! - code: markers around the body of `reflect` (src/math.rs), and its tests in a
//!   `mod checkpoint10` beside it;
//! - data: its handout, its rubric row, a scene that grades it (the intersection-test Cornell
//!   box, whose glass reflects light that cannot leave it), 10 in the `depends_on` of every scene
//!   with glass, one mistake in the catalogue, and the new scene's reference.
//!
//! Then it checks what a course needs of the new checkpoint: the solution grades in full with a
//! row for 10; the catalogue mistake, graded as a submission, costs checkpoint 10 its test and
//! image points and every other checkpoint nothing (each judged on its own); the starter stubs
//! checkpoint 10 with the others. The new scene shares `intersection_test`'s file and thresholds:
//! the same picture, calibrated there (docs/CALIBRATION.md).

use std::path::Path;
use std::time::Instant;

use raylab_grade::grading::{grade, GradeOptions};
use raylab_grade::instructor::render_references::{render_reference, write_manifests};
use raylab_grade::instructor::variants::{check_patches, make_scratch_tree, VariantFile};
use raylab_grade::reference::Manifest;
use raylab_grade::report::progress::progress_bar;
use raylab_grade::rubric::{Rubric, RUBRIC};
use raylab_grade::submission::grade_submission;

use crate::course::{copy_tracked, starter_keeps_only};
use crate::repository;

/// The new checkpoint's id: above every id of the rubric, and the first with two digits.
const ID: u32 = 10;

/// The body of `reflect` in src/math.rs, and where the new tests go.
const REGION_FILE: &str = "src/math.rs";
const BODY: &str = "    2.0 * n.dot(wo) * n - wo\n}\n";

const TESTS: &str = r#"
#[cfg(test)]
mod checkpoint10 {
    use super::*;

    #[test]
    fn reflect_keeps_the_tangent_part_and_flips_the_normal_part() {
        let r = reflect(Vec3::new(0.6, 0.8, 0.0), Vec3::Y);
        assert!((r - Vec3::new(-0.6, 0.8, 0.0)).length() < 1e-6, "{r}");
    }

    #[test]
    fn reflect_at_normal_incidence_returns_the_same_direction() {
        assert!((reflect(Vec3::Z, Vec3::Z) - Vec3::Z).length() < 1e-6);
    }
}
"#;

const HANDOUT: &str = "# Checkpoint 10: mirror reflection\n\n\
    Write `reflect` in `src/math.rs`: the mirror direction of `wo` about the unit normal `n`,\n\
    `2 (n . wo) n - wo`. Glass reflects totally what it cannot refract (checkpoint 5).\n\n\
    Check: `cargo test checkpoint10`; the scene `mirror` in `cargo grader`.\n\n\
    ## Symptoms of common mistakes\n\n\
    - Dark or wrong rims inside the glass: `-wo` or `wo - 2 (n . wo) n` sends the ray the wrong way.\n";

const ROW: &str = r#"
id = 10
title = "Mirror reflection"
test_points = 5
image_points = 5
test_filter = "checkpoint10"
hint = "Keep the tangent part of wo and flip its normal part: 2 (n . wo) n - wo."
handout = "checkpoints/10-mirror.md"
"#;

const SCENE: &str = r#"
name = "mirror"
file = "scenes/intersection_test.toml"
spp = 1
reference_spp = 1
grades = [10]
depends_on = [2, 3, 4, 5, 10]

[[check]]
metric = "worst_tile_error"
max = 3.0
why = "as intersection_test (the same picture): correct <= 0.044, mistakes >= 73.2"
"#;

const MISTAKE: &str = r#"
name = "reflect_back"
checkpoint = 10
correct = false
description = "returns -wo: light goes back the way it came"
fails = ["mirror"]

[[patch]]
file = "src/math.rs"
region = 0
body = "    -wo\n"
"#;

/// Makes the course with checkpoint 10 in `target/course-with/` and checks it.
pub fn with_extra() -> Result<(), String> {
    let started = Instant::now();
    let work = repository().join("target/course-with");
    let course = work.join("course");
    copy_tracked(repository(), &course)?;
    add_checkpoint(&course)?;
    println!("course with checkpoint {ID}: added; rendering its scene's reference");
    let rubric = Rubric::of_tree(&course).map_err(|e| e.to_string())?;
    add_reference(&course, &rubric)?;
    let variants =
        VariantFile::load(&course.join("checkpoints/variants.toml")).map_err(|e| e.to_string())?.variants;
    check_patches(&course, &variants).map_err(|e| e.to_string())?;
    println!("course with checkpoint {ID}: grading its solution");
    let progress = progress_bar(0);
    let options = GradeOptions { target: Some(work.join("target")), ..GradeOptions::new(&course) };
    let graded = grade(&options, &progress).map_err(|e| e.to_string());
    progress.finish_and_clear();
    let report = graded?;
    print!("{}", raylab_grade::report::text(&report));
    let ids: Vec<u32> = rubric.checkpoints.iter().map(|c| c.id).collect();
    let graded: Vec<u32> = report.checkpoints.iter().map(|c| c.checkpoint.id).collect();
    if graded != ids || !graded.contains(&ID) || !report.all_passed() {
        return Err(format!("the course with {ID} graded {graded:?}, not all in full (wanted {ids:?})"));
    }
    println!("course with checkpoint {ID}: grading its catalogue mistake as a submission");
    let mistake = variants.iter().find(|v| v.checkpoint == ID).ok_or("no mistake of checkpoint 10")?;
    let submission = work.join("submission");
    make_scratch_tree(&course, &submission, mistake).map_err(|e| e.to_string())?;
    mistake_costs_only_its_checkpoint(&course, &submission, &work)?;
    starter_keeps_only(&course, &ids, &[], &work.join("starter-src"))?;
    println!(
        "course with checkpoint {ID}: graded, its mistake named by its points alone, stubbed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The code and data of checkpoint 10, added to the copy at `course` (module docs).
fn add_checkpoint(course: &Path) -> Result<(), String> {
    let io = |path: &Path, e: std::io::Error| format!("{}: {e}", path.display());
    let file = course.join(REGION_FILE);
    let text = std::fs::read_to_string(&file).map_err(|e| io(&file, e))?;
    let marked =
        format!("    // BEGIN SOLUTION checkpoint{ID}\n{}    // END SOLUTION\n}}\n", &BODY[..BODY.len() - 2]);
    if text.matches(BODY).count() != 1 {
        return Err(format!("{REGION_FILE}: the body of `reflect` is not there once"));
    }
    std::fs::write(&file, text.replace(BODY, &marked) + TESTS).map_err(|e| io(&file, e))?;
    let handout = course.join("checkpoints/10-mirror.md");
    std::fs::write(&handout, HANDOUT).map_err(|e| io(&handout, e))?;
    let rubric = course.join(RUBRIC);
    edit_toml(&rubric, |table| {
        push(table, "checkpoint", ROW);
        for scene in array(table, "scene").iter_mut().filter_map(toml::Value::as_table_mut) {
            if let Some(toml::Value::Array(ids)) = scene.get_mut("depends_on") {
                if ids.iter().any(|v| v.as_integer() == Some(5)) {
                    ids.push(toml::Value::Integer(ID.into()));
                }
            }
        }
        push(table, "scene", SCENE);
    })?;
    edit_toml(&course.join("checkpoints/variants.toml"), |table| push(table, "variant", MISTAKE))
}

/// The reference of the new scene, rendered by the solution and added to the manifest.
fn add_reference(course: &Path, rubric: &Rubric) -> Result<(), String> {
    let scene = rubric.scenes.iter().find(|s| s.grades == [ID]).ok_or("no scene grades checkpoint 10")?;
    let mut manifest = Manifest::load(course, rubric).map_err(|e| e.to_string())?;
    manifest.references.push(render_reference(course, scene).map_err(|e| e.to_string())?);
    write_manifests(course, rubric, &manifest).map_err(|e| e.to_string())
}

/// Grades the `submission` (the course's solution with the mistake) with the `course` as the
/// instructor's tree: checkpoint 10 loses test and image points, every other keeps all of its.
fn mistake_costs_only_its_checkpoint(course: &Path, submission: &Path, work: &Path) -> Result<(), String> {
    let progress = progress_bar(0);
    let graded = grade_submission(course, submission, work, &progress).map_err(|e| e.to_string());
    progress.finish_and_clear();
    let report = graded?;
    print!("{}", raylab_grade::report::text(&report.isolated));
    let tests_ran = report.isolated.tests_ran;
    for c in &report.isolated.checkpoints {
        let (id, full) = (c.checkpoint.id, c.score() == c.max_score(tests_ran));
        let wrong = if id == ID {
            full || c.test_score >= c.checkpoint.test_points || c.image_score >= c.checkpoint.image_points
        } else {
            !full
        };
        if wrong {
            return Err(format!(
                "checkpoint {id} scored {:.1}/{:.1} with checkpoint {ID}'s mistake",
                c.score(),
                c.max_score(tests_ran)
            ));
        }
    }
    Ok(())
}

/// Reads the TOML file at `path`, changes it with `edit` and writes it back.
fn edit_toml(path: &Path, edit: impl FnOnce(&mut toml::Table)) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let text = std::fs::read_to_string(path).map_err(|e| fail(&e))?;
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| fail(&e))?;
    edit(&mut table);
    let text = toml::to_string(&table).map_err(|e| fail(&e))?;
    std::fs::write(path, text).map_err(|e| fail(&e))
}

/// The array of tables `key` of `table`.
fn array<'t>(table: &'t mut toml::Table, key: &str) -> &'t mut Vec<toml::Value> {
    let value = table.entry(key).or_insert_with(|| toml::Value::Array(Vec::new()));
    value.as_array_mut().expect("an array of tables")
}

/// Appends the table written as `entry` to the array of tables `key`.
fn push(table: &mut toml::Table, key: &str, entry: &str) {
    let entry: toml::Table = toml::from_str(entry).expect("the entries above are TOML");
    array(table, key).push(toml::Value::Table(entry));
}
