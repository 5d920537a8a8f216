//! A scene that lists `stand_ins` in the rubric is graded with those stand-ins while their
//! checkpoints are still stubs, against the one reference the solution made: so each stand-in
//! must draw that scene exactly as the solution's code does. Each such scene is rendered both
//! ways here, and the films must agree bit for bit.

// The renderer is linked by the instructor's grader only.
#![cfg(feature = "instructor")]

use std::path::Path;

use raylab::fallback::Fallbacks;
use raylab::scene::Scene;
use raylab_grade::rubric::Rubric;

#[test]
fn each_scene_draws_the_same_picture_with_the_stand_ins_it_lists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let rubric = Rubric::of_tree(&root).unwrap();
    let scenes: Vec<_> = rubric.scenes.iter().filter(|s| !s.stand_ins.is_empty()).collect();
    assert!(!scenes.is_empty(), "no scene lists stand-ins: this test checks nothing");
    for graded in scenes {
        let scene = Scene::load(&root.join(&graded.file)).unwrap();
        let settings = raylab::scene::RenderSettings { spp: graded.spp, seed: graded.seed, ..scene.settings };
        let render = |fallbacks: Fallbacks| {
            let (integrator, settings) = fallbacks.integrator(&settings);
            raylab::render::render_with(&fallbacks.world(&scene), &settings, integrator, &|_| {})
        };
        // Each stand-in alone, and all of them together.
        let mut sets: Vec<Vec<u32>> = graded.stand_ins.iter().map(|&c| vec![c]).collect();
        sets.push(graded.stand_ins.clone());
        let solution = render(Fallbacks::default());
        for set in sets {
            let stood_in =
                Fallbacks::standing_in(&set).unwrap_or_else(|c| panic!("checkpoint {c} has no stand-in"));
            assert!(render(stood_in) == solution, "{}: stand-ins {set:?} draw another picture", graded.name);
        }
    }
}
