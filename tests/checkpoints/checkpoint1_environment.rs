//! Checkpoint 1: the environment works: every scene in `scenes/` loads, with its meshes.

mod checkpoint1 {
    use std::path::{Path, PathBuf};

    use raylab::scene::Scene;

    fn scene_files() -> Vec<PathBuf> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .expect("the scenes folder exists")
            .map(|e| e.expect("readable entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        files
    }

    #[test]
    fn every_scene_parses_validates_and_loads_its_meshes() {
        let files = scene_files();
        assert!(files.len() >= 4, "expected the four graded scenes, found {files:?}");
        for path in files {
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.triangles.is_empty(), "{}: no triangles", path.display());
            let shown = path.display();
            assert_eq!(
                scene.triangles.len(),
                scene.triangle_materials.len(),
                "{shown}: one material per triangle"
            );
            let known = scene.triangle_materials.iter().all(|&m| (m as usize) < scene.materials.len());
            assert!(known, "{shown}: a triangle names a material the scene does not have");
            let finite =
                scene.triangles.iter().all(|t| t.p0.is_finite() && t.p1.is_finite() && t.p2.is_finite());
            assert!(finite, "{shown}: a vertex is not finite");
        }
    }

    #[test]
    fn the_graded_scenes_are_there() {
        let names: Vec<String> =
            scene_files().iter().map(|p| p.file_stem().unwrap().to_string_lossy().into_owned()).collect();
        for name in ["cornell_direct", "cornell_refract", "intersection_test", "aliasing"] {
            assert!(names.iter().any(|n| n == name), "scenes/{name}.toml is missing");
        }
    }
}
