//! `tessera render --set KEY=VALUE` (src/scene/set.rs): a render with values set on the command
//! line equals, bit for bit, the render of a file that says the same; bad keys are errors that
//! name the key, and nothing is rendered.

mod common;

use std::process::Command;

const SCENE: &str = "[render]\nwidth = 24\nheight = 18\nspp = 4\nseed = 7\n\
     [camera]\nfov = 40\neye = [0, 1, 4]\ntarget = [0, 0, 0]\n\
     [environment]\ntype = \"constant\"\nradiance = 0.5\n\
     [materials.m]\ntype = \"diffuse\"\nreflectance = [0.7, 0.4, 0.2]\n\
     [[shapes]]\ntype = \"uv_sphere\"\nmaterial = \"m\"\n";

#[test]
fn set_values_render_as_the_file_would_say_them() {
    let dir = common::scene_dir(SCENE, &[]);
    let edited = SCENE
        .replace("width = 24", "width = 16")
        .replace("fov = 40", "fov = 55.5")
        .replace("reflectance = [0.7, 0.4, 0.2]", "reflectance = [0.1, 0.9, 0.3]");
    std::fs::write(dir.path().join("edited.toml"), edited).unwrap();
    let render = |scene: &str, out: &str, set: &[&str]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tessera"));
        cmd.arg("render").arg(dir.path().join(scene)).args(["-q", "-o"]).arg(dir.path().join(out));
        set.iter().for_each(|s| {
            cmd.args(["--set", s]);
        });
        let run = cmd.output().unwrap();
        (run.status.code(), String::from_utf8_lossy(&run.stderr).into_owned(), dir.path().join(out))
    };
    let (code, err, by_set) = render(
        "scene.toml",
        "set.exr",
        &["render.width=16", "camera.fov = 55.5", "materials.m.reflectance=[0.1, 0.9, 0.3]"],
    );
    assert_eq!(code, Some(0), "{err}");
    let (code, err, by_file) = render("edited.toml", "file.exr", &[]);
    assert_eq!(code, Some(0), "{err}");
    let (a, b) = (std::fs::read(&by_set).unwrap(), std::fs::read(&by_file).unwrap());
    assert_eq!(a, b, "the same scene, set or written, renders the same bytes");
    let image = tessera::image::read_exr_image(&by_set).unwrap();
    assert_eq!((image.width, image.height), (16, 18));
    for (set, needle) in [
        ("render.widht=3", "unknown field `widht`"),
        ("shapes[4].type=\"obj\"", "--set shapes[4].type"),
        ("camera.fov=inf", "camera.fov"),
    ] {
        let (code, err, out) = render("scene.toml", "bad.exr", &[set]);
        assert_eq!(code, Some(1), "{set}");
        assert!(err.contains(needle), "{set}: {err}");
        assert!(!out.exists(), "{set}");
    }
}
