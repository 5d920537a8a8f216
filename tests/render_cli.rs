//! The `render` command as a user meets it: good runs write a PNG, bad input gives one clear
//! line and exit code 2, and a failed run never replaces a good image.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raylab-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn render(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_render")).args(args).output().expect("render runs")
}

/// A valid small scene, with `replace` applied to break it.
fn scene_text(replace: (&str, &str)) -> String {
    let text = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\nwidth = 16\nheight = 12\n\n\
        [integrator]\nkind = \"intersection_test\"\nspp = 1\n\n\
        [materials.white]\nkind = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\n\
        [[objects]]\nshape = \"sphere\"\nmaterial = \"white\"\nscale = [1, 1, 1]\n";
    assert!(text.contains(replace.0), "the scene has no {:?}", replace.0);
    text.replacen(replace.0, replace.1, 1)
}

fn stderr_of(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn render_cli_writes_a_png_of_the_scene_size() {
    let dir = scratch("ok");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, scene_text(("", ""))).unwrap();
    let png = dir.join("out.png");
    let out = render(&[scene.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let image = raylab::image_io::read_png(&png).unwrap();
    assert_eq!((image.width, image.height), (16, 12));
    assert!(image.data.chunks_exact(3).any(|p| p[0] > 100), "the sphere is visible");
}

/// `--pfm` keeps the linear values: encoded to sRGB, they give the PNG's bytes exactly.
#[test]
fn render_cli_writes_the_linear_film_beside_the_png_when_asked() {
    let dir = scratch("pfm");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, scene_text(("", ""))).unwrap();
    let (png, pfm) = (dir.join("out.png"), dir.join("out.pfm"));
    let out = render(&[scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--pfm", pfm.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr_of(&out));
    let film = raylab::image_io::read_pfm(&pfm).unwrap();
    assert_eq!(raylab::image_io::film_to_rgb8(&film), raylab::image_io::read_png(&png).unwrap());
    let wrong = render(&[scene.to_str().unwrap(), "-o", png.to_str().unwrap(), "--pfm", "out.exr"]);
    assert_eq!(wrong.status.code(), Some(2));
    assert!(stderr_of(&wrong).contains("out.exr: --pfm must name a .pfm file"), "{}", stderr_of(&wrong));
}

/// `--accel wide` traces with the harness's wide BVH: the same closest hits as checkpoint 4's
/// tree, so the same film, bit for bit, on a scene where no ray meets an edge two objects share
/// (there either object is the closest hit, and the trees may pick differently).
#[test]
fn render_cli_traces_with_the_wide_bvh_when_asked() {
    let dir = scratch("wide");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, scene_text(("", ""))).unwrap();
    let film = |accel: &str| {
        let (png, pfm) = (dir.join(format!("{accel}.png")), dir.join(format!("{accel}.pfm")));
        let out = render(&[
            scene.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "--pfm",
            pfm.to_str().unwrap(),
            "--accel",
            accel,
        ]);
        assert!(out.status.success(), "{}", stderr_of(&out));
        raylab::image_io::read_pfm(&pfm).unwrap()
    };
    assert_eq!(film("wide"), film("bvh"));
    let wrong = render(&[scene.to_str().unwrap(), "-o", "x.png", "--accel", "embree"]);
    assert_eq!(wrong.status.code(), Some(2), "{}", stderr_of(&wrong));
}

/// Each broken scene: (what is replaced, by what, the line the error must name, a word of it).
const BROKEN: &[(&str, &str, usize, &str)] = &[
    ("fov = 40", "fov = 40 40", 5, "camera"),
    ("fov = 40", "fov = nan", 5, "camera.fov"),
    ("width = 16", "width = 0", 6, "camera.width"),
    ("height = 12", "height = -3", 7, "camera.height"),
    ("width = 16", "width = 100000", 6, "camera.width"),
    ("spp = 1", "spp = 0", 11, "integrator.spp"),
    ("position = [0, 0, 5]", "position = [0, inf, 5]", 2, "camera.position"),
    ("material = \"white\"", "material = \"chrome\"", 19, "objects[0].material"),
    ("scale = [1, 1, 1]", "scale = [1, 0, 1]", 20, "objects[0].scale"),
    ("shape = \"sphere\"", "shape = \"obj\"\nfile = \"missing.obj\"", 19, "objects[0].file"),
    ("shape = \"sphere\"", "shape = \"cone\"", 18, "objects[0].shape"),
    ("kind = \"intersection_test\"", "kind = \"photon_mapper\"", 10, "integrator.kind"),
    ("fov = 40", "fov = 40\nzoom = 2", 6, "camera"),
    ("albedo = [0.8, 0.8, 0.8]", "albedo = [0.8, 1.8, 0.8]", 15, "materials.white.albedo"),
    ("albedo = [0.8, 0.8, 0.8]", "ior = 1.5", 15, "materials.white.ior"),
    ("kind = \"diffuse\"", "kind = \"glass\"", 15, "materials.white.albedo"),
    ("albedo = [0.8, 0.8, 0.8]", "", 14, "materials.white.kind"),
    ("look_at = [0, 0, 0]", "look_at = [0, 0, 5]", 3, "camera.look_at"),
    ("fov = 40", "", 1, "camera"),
    ("fov = 40", "fov = 40\northographic_height = 2", 6, "camera.orthographic_height"),
    ("fov = 40", "orthographic_height = 0", 5, "camera.orthographic_height"),
];

#[test]
fn render_cli_reports_bad_scenes_in_one_line_with_file_line_and_field() {
    let dir = scratch("bad");
    let png = dir.join("out.png");
    for &(from, to, line, field) in BROKEN {
        let scene = dir.join("broken.toml");
        std::fs::write(&scene, scene_text((from, to))).unwrap();
        let out = render(&[scene.to_str().unwrap(), "-o", png.to_str().unwrap()]);
        let err = stderr_of(&out);
        assert_eq!(out.status.code(), Some(2), "{to}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{to}: one line, got {err}");
        assert!(!err.contains("panicked"), "{to}: {err}");
        let location = format!("broken.toml:{line}:");
        assert!(
            err.contains(&location) && err.contains(field),
            "{to}: expected {location} and {field}, got {err}"
        );
        assert!(!png.exists(), "{to}: no image for a broken scene");
    }
}

#[test]
fn render_cli_reports_a_missing_scene_file_and_bad_arguments() {
    let out = render(&["no/such/scene.toml", "-o", "x.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr_of(&out).contains("no/such/scene.toml"), "{}", stderr_of(&out));
    let out = render(&["scene.toml", "-o", "x.png", "--spp", "0"]);
    assert_eq!(out.status.code(), Some(2), "clap rejects spp 0");
    let out = render(&["scene.toml", "-o", "x.jpg"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr_of(&out).contains("x.jpg"));
}

#[test]
fn render_cli_never_leaves_a_broken_image_over_a_good_one() {
    let dir = scratch("atomic");
    let png = dir.join("keep.png");
    std::fs::write(&png, b"a good image").unwrap();
    let scene = dir.join("broken.toml");
    std::fs::write(&scene, scene_text(("fov = 40", "fov = nan"))).unwrap();
    let out = render(&[scene.to_str().unwrap(), "-o", png.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(&png).unwrap(), b"a good image");
    // An output folder that does not exist: named in the error, exit 2.
    std::fs::write(&scene, scene_text(("", ""))).unwrap();
    let missing = dir.join("no-such-folder/out.png");
    let out = render(&[scene.to_str().unwrap(), "-o", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr_of(&out).contains("out.png"), "{}", stderr_of(&out));
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 2, "only keep.png and broken.toml remain: {leftovers:?}");
    let _ = Path::new(&dir);
}
