//! What holds the mistake catalogue (`checkpoints/variants.toml`) and the rubric together: checked
//! in a second, long before `cargo xtask zoo` or `grader calibrate` build anything. The catalogue's
//! `fails` are the scenes a variant must fail; `grader calibrate --check` (in CI) renders them.

#[cfg(test)]
mod tests {
    use raylab_grade::instructor::variants::{check_patches, Change, Patch, Variant, VariantFile};
    use raylab_grade::rubric::{GradedScene, Rubric};

    use crate::repository;

    fn catalogue() -> Vec<Variant> {
        VariantFile::load(&repository().join("checkpoints/variants.toml")).unwrap().variants
    }

    /// The catalogue patches the solution's text: an edit to a solution region can silently
    /// break one. Checked here in a second, long before `zoo` or `grader calibrate` build it.
    #[test]
    fn every_catalogue_patch_applies_to_the_current_solution() {
        let variants = catalogue();
        check_patches(repository(), &variants).unwrap_or_else(|e| panic!("{e}"));
    }

    /// A mistake written a second way (`second_of`) measures the naming of the first one
    /// (`grader fingerprints`): it repeats a catalogue mistake that fails a scene, in the same
    /// checkpoint, with the same `fails`, in other words than the first's patches; and every
    /// mistake a fingerprint names has one.
    #[test]
    fn every_second_way_repeats_a_named_mistake_in_other_words() {
        let variants = catalogue();
        let named: Vec<&Variant> = variants
            .iter()
            .filter(|v| !v.correct && !v.stub && v.second_of.is_none() && !v.fails.is_empty())
            .collect();
        // What the mistake writes, not where.
        let written = |p: &Patch| match &p.change {
            Change::Replace { replace, .. } => replace.clone(),
            Change::Body { body, .. } => body.clone(),
        };
        let texts = |v: &Variant| -> Vec<String> { v.patches.iter().map(written).collect() };
        for second in variants.iter().filter(|v| v.second_of.is_some()) {
            let first = named.iter().find(|f| Some(&f.name) == second.second_of.as_ref());
            let first = first.unwrap_or_else(|| {
                panic!("{}: second_of names no catalogue mistake that fails a scene", second.name)
            });
            assert_eq!(
                (second.checkpoint, &second.fails, second.correct),
                (first.checkpoint, &first.fails, false),
                "{}",
                second.name
            );
            assert_ne!(texts(second), texts(first), "{}: the same patch as {}", second.name, first.name);
        }
        for first in named {
            assert!(
                variants.iter().any(|v| v.second_of.as_ref() == Some(&first.name)),
                "{}: no second way (`second_of`) to measure its naming",
                first.name
            );
        }
    }

    /// A scene gives checkpoint N image points only if it runs N's code: the catalogue's stub of
    /// N (its regions replaced by the starter's `todo!()`) must list every scene that grades N,
    /// and `grader calibrate --check` (in CI) then shows each of those scenes fails or refuses
    /// with the stub. A stand-in would draw the scene without N's code, so no scene may grade a
    /// checkpoint it stands in for.
    #[test]
    fn every_scene_fails_with_each_checkpoint_it_grades_stubbed() {
        let variants = catalogue();
        let rubric = Rubric::of_tree(repository()).unwrap();
        let mut missing = Vec::new();
        for scene in &rubric.scenes {
            for &n in &scene.grades {
                let stub = variants.iter().find(|v| v.stub && v.checkpoint == n);
                if scene.stand_ins.contains(&n) || stub.is_none_or(|v| !v.fails.contains(&scene.name)) {
                    missing
                        .push(format!("scene {} grades checkpoint {n}: stub_{n} must fail it", scene.name));
                }
            }
        }
        assert!(missing.is_empty(), "{}", missing.join("\n"));
    }

    /// The first checkpoint `scene` needs that is neither written at checkpoint `n`'s stage (2 to
    /// `n` written, the rest the starter's stubs) nor drawn by a stand-in the scene lists: the
    /// scene cannot be graded in a student's tree before it is written.
    fn waits_for(scene: &GradedScene, n: u32) -> Option<u32> {
        scene.depends_on.iter().copied().find(|&d| d > n && !scene.stand_ins.contains(&d))
    }

    /// A mistake costs its checkpoint N the same image points in the student's own tree at N's
    /// stage as in `grader submission`: there, a scene that cannot run yet is lost to N (its
    /// tests fail, so N is the culprit), so every such scene grading N must be one the mistake
    /// fails in a submission too, which listing it in the mistake's `fails` makes calibration
    /// check. Scenes that do run at the stage are compared by `cargo xtask stage-points`
    /// (docs/GRADING.md). Hidden scenes are not in a student's tree and are left out.
    #[test]
    fn a_mistake_fails_every_scene_of_its_checkpoint_that_waits_for_a_later_one() {
        let rubric = Rubric::of_tree(repository()).unwrap();
        let mut problems = Vec::new();
        for mistake in catalogue().iter().filter(|v| !v.correct && !v.stub) {
            let n = mistake.checkpoint;
            for scene in rubric.scenes.iter().filter(|s| !s.hidden && s.grades.contains(&n)) {
                if let Some(k) = waits_for(scene, n).filter(|_| !mistake.fails.contains(&scene.name)) {
                    problems.push(format!(
                        "{}: scene {} grades checkpoint {n} but waits for checkpoint {k} in a student's tree; list it in the mistake's fails, or grade {n} elsewhere",
                        mistake.name, scene.name
                    ));
                }
            }
        }
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }
}
