//! Control of a render from the command line: `--set KEY=VALUE` (src/scene/set.rs) renders as
//! the file would say it, bit for bit, and bad keys are errors that name the key, with nothing
//! rendered; `--time-limit` writes the whole samples per pixel that fit; Ctrl-C writes the image
//! of the passes done and exits 130 (src/integrator/progressive.rs; that passes add up to the
//! uninterrupted image bit for bit is tests/determinism.rs).

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

/// The scene with a budget that no test waits for.
fn endless() -> tempfile::TempDir {
    common::scene_dir(&SCENE.replace("spp = 4", "spp = 1000000"), &[])
}

#[test]
fn a_time_limit_writes_the_samples_that_fit() {
    let dir = endless();
    let out = dir.path().join("limited.exr");
    let run = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("render")
        .arg(dir.path().join("scene.toml"))
        .args(["--time-limit", "0.5", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("time limit: ") && stderr.contains(" of 1000000 spp rendered"), "{stderr}");
    assert!(tessera::image::read_exr_image(&out).is_ok());
    for bad in ["0", "-1", "nan", "soon"] {
        let run = Command::new(env!("CARGO_BIN_EXE_tessera"))
            .arg("render")
            .arg(dir.path().join("scene.toml"))
            .args(["--time-limit", bad])
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(2), "--time-limit {bad}");
    }
}

#[test]
fn ctrl_c_writes_the_image_so_far_and_exits_130() {
    let dir = endless();
    let out = dir.path().join("interrupted.exr");
    let child = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("render")
        .arg(dir.path().join("scene.toml"))
        .arg("-o")
        .arg(&out)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    // The shell's own `kill` (no procps needed).
    let kill = Command::new("sh").args(["-c", &format!("kill -INT {}", child.id())]).status().unwrap();
    assert!(kill.success());
    let run = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted: ") && stderr.contains(" of 1000000 spp rendered"), "{stderr}");
    let image = tessera::image::read_exr_image(&out).unwrap();
    assert_eq!((image.width, image.height), (24, 18));
}

#[test]
fn a_resumed_render_equals_an_uninterrupted_one_bit_for_bit() {
    let dir = endless();
    let scene = dir.path().join("scene.toml");
    let run = |args: &[&str]| {
        let run = Command::new(env!("CARGO_BIN_EXE_tessera")).arg("render").arg(&scene).args(args).output().unwrap();
        (run.status.code(), String::from_utf8_lossy(&run.stderr).into_owned())
    };
    let (out, state) = (dir.path().join("r.exr"), dir.path().join("r.exr.state"));
    let out_arg = out.to_str().unwrap();
    let (code, err) = run(&["--time-limit", "0.3", "--aov", "albedo", "-o", out_arg]);
    assert_eq!(code, Some(0), "{err}");
    assert!(state.exists(), "an unfinished render leaves its state");
    let done: u32 = err.split("time limit: ").nth(1).and_then(|t| t.split(' ').next()).unwrap().parse().unwrap();
    // Resumed to a few more samples than were done, against the same count rendered at once.
    let spp = (done + 5).to_string();
    for (args, needle) in [
        (vec!["--resume", "--spp", &spp, "--aov", "albedo", "--seed", "9", "-o", out_arg], "another scene"),
        (vec!["--resume", "--spp", &spp, "-o", out_arg], "another crop, resolution or AOVs"),
        (vec!["--resume", "--spp", &spp, "--aov", "albedo", "-o", "elsewhere.exr"], "no unfinished render"),
    ] {
        let (code, err) = run(&args);
        assert_eq!(code, Some(1), "{args:?}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    let (code, err) = run(&["--resume", "--spp", &spp, "--aov", "albedo", "-o", out_arg]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains(&format!("resuming {out_arg} from {done} of {spp} spp")), "{err}");
    assert!(!state.exists(), "a finished render removes its state");
    let whole = dir.path().join("whole.exr");
    let (code, err) = run(&["--spp", &spp, "--aov", "albedo", "-q", "-o", whole.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&whole).unwrap());
}

#[test]
fn png_output_is_exposed_and_tone_mapped_and_exr_stays_linear() {
    let dir = common::scene_dir(SCENE, &[]);
    let render = |out: &str, args: &[&str]| {
        let run = Command::new(env!("CARGO_BIN_EXE_tessera"))
            .arg("render")
            .arg(dir.path().join("scene.toml"))
            .args(args)
            .args(["-q", "-o"])
            .arg(dir.path().join(out))
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        dir.path().join(out)
    };
    let exr = render("linear.exr", &["--exposure", "1.5", "--tonemap", "aces"]);
    let plain = render("plain.exr", &[]);
    assert_eq!(std::fs::read(&exr).unwrap(), std::fs::read(&plain).unwrap(), "EXR output is never tone-mapped");
    let linear = tessera::image::read_exr_channels(&exr, &["R", "G", "B"]).unwrap();
    for (args, tone) in [
        (vec!["--exposure", "1.5", "--tonemap", "aces"], tessera::image::ToneMap::Aces),
        (vec!["--exposure", "-2"], tessera::image::ToneMap::Clamp),
    ] {
        let gain = args[1].parse::<f32>().unwrap().exp2();
        let png = image::open(render("shown.png", &args)).unwrap().to_rgb8();
        for (shown, v) in png.as_raw().iter().zip(&linear.data) {
            let expected = tessera::color::linear_to_srgb(tone.map(v * gain)) * 255.0;
            assert!((*shown as f32 - expected).abs() <= 0.51, "{args:?}: {shown} for {expected}");
        }
    }
}

/// PFM and Radiance HDR outputs hold the linear radiance: the PFM bit for bit (read back here
/// by hand: header, then little-endian rows from the bottom up), the HDR within its RGBE
/// precision (8-bit mantissas under the exponent of the pixel's largest channel: one step is at
/// most 1/128 of that channel).
#[test]
fn pfm_and_hdr_outputs_hold_the_linear_radiance() {
    let dir = common::scene_dir(SCENE, &[]);
    for out in ["a.exr", "a.pfm", "a.hdr"] {
        let run = Command::new(env!("CARGO_BIN_EXE_tessera"))
            .arg("render")
            .arg(dir.path().join("scene.toml"))
            .args(["-q", "-o"])
            .arg(dir.path().join(out))
            .output()
            .unwrap();
        assert!(run.status.success(), "{out}: {}", String::from_utf8_lossy(&run.stderr));
    }
    let exr = tessera::image::read_bitmap_raw(&dir.path().join("a.exr"), tessera::image::ColorSpace::Linear).unwrap();
    let pfm = std::fs::read(dir.path().join("a.pfm")).unwrap();
    let header = b"PF\n24 18\n-1.0\n";
    assert_eq!(&pfm[..header.len()], header);
    let values: Vec<f32> =
        pfm[header.len()..].chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
    let (w, h) = (24, 18);
    assert_eq!(values.len(), w * h * 3);
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let from_pfm = values[((h - 1 - y) * w + x) * 3 + c];
                assert_eq!(from_pfm.to_bits(), exr.data[(y * w + x) * exr.channels + c].to_bits(), "({x}, {y}) {c}");
            }
        }
    }
    let hdr = tessera::image::read_bitmap_raw(&dir.path().join("a.hdr"), tessera::image::ColorSpace::Linear).unwrap();
    assert_eq!((hdr.width, hdr.height), (w, h));
    for i in 0..w * h {
        let largest = (0..3).map(|c| exr.data[i * exr.channels + c]).fold(0.0, f32::max);
        for c in 0..3 {
            let (a, b) = (hdr.data[i * hdr.channels + c], exr.data[i * exr.channels + c]);
            assert!((a - b).abs() <= largest / 128.0, "pixel {i} channel {c}: {a} vs {b}");
        }
    }
}
