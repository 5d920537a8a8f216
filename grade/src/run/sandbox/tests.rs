//! The launcher's arguments: what `wrap` writes it reads back, and anything else it refuses.

use super::*;

/// The launcher reads back exactly what `wrap` wrote.
#[test]
fn the_launchers_arguments_round_trip() {
    let walls = Walls {
        profile: Profile::Build,
        read: vec![PathBuf::from("/scenes"), PathBuf::from("/bin/x")],
        write: vec![PathBuf::from("own")],
        limits: Limits::GRADED.unwrap(),
        cpu_seconds: 40,
        user: Some(61_001),
    };
    let mut command = Command::new("/bin/render");
    command.args(["scene.toml", "--spp", "4"]).env("A", "1").current_dir("/work");
    let wrapped = wrap(Path::new("/grader"), &command, &walls, &[]);
    let args: Vec<OsString> = wrapped.get_args().map(OsString::from).collect();
    assert_eq!(args[0], LAUNCH);
    let launch = parse_launch(&args[1..]).unwrap();
    assert_eq!(launch.walls.read, walls.read);
    // A relative folder is made absolute: the launcher starts in the child's working folder.
    assert_eq!(launch.walls.write, [std::env::current_dir().unwrap().join("own")]);
    assert_eq!(launch.walls.profile, Profile::Build);
    assert_eq!(launch.walls.limits.memory, walls.limits.memory);
    assert_eq!(launch.walls.limits.file_size, walls.limits.file_size);
    assert_eq!(launch.walls.cpu_seconds, 40);
    assert_eq!(launch.walls.user, Some(61_001));
    assert_eq!(launch.parent, std::process::id());
    assert_eq!(launch.program, ["/bin/render", "scene.toml", "--spp", "4"].map(OsString::from));
    assert_eq!(wrapped.get_current_dir(), Some(Path::new("/work")));
    let envs: Vec<_> = wrapped.get_envs().collect();
    assert!(envs.contains(&(std::ffi::OsStr::new("TMPDIR"), Some(std::ffi::OsStr::new("own")))));
    assert!(envs.contains(&(std::ffi::OsStr::new("A"), Some(std::ffi::OsStr::new("1")))));
    // A run gets nothing of the grader's environment but PATH.
    let run = wrap(Path::new("/grader"), &command, &Walls { profile: Profile::Run, ..walls }, &[]);
    let names: Vec<_> = run.get_envs().map(|(k, _)| k.to_str().unwrap().to_string()).collect();
    assert!(names.iter().all(|k| ["TMPDIR", "A", "PATH"].contains(&k.as_str())), "{names:?}");
}

#[test]
fn the_launcher_refuses_what_it_does_not_know() {
    let args = |a: &[&str]| a.iter().map(OsString::from).collect::<Vec<_>>();
    let refused = |a: &[&str]| parse_launch(&args(a)).unwrap_err();
    assert_eq!(refused(&["--write", "/o", "--bogus", "--", "x"]), ArgumentError::Unknown("--bogus".into()));
    assert_eq!(refused(&["--write", "/o", "--"]), ArgumentError::NoProgram);
    let doors = ArgumentError::UnknownWall("doors".into());
    assert_eq!(refused(&["--without", "doors", "--write", "/o", "--", "x"]), doors);
    assert_eq!(refused(&["--cpu", "many", "--write", "/o", "--", "x"]), ArgumentError::NotANumber("--cpu"));
    assert_eq!(refused(&["--write"]), ArgumentError::NoValue("--write"));
}
