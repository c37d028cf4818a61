//! Bad input gets a clear error naming the file and the problem, never a panic, and never
//! replaces a good output image.

mod common;

use common::{load, scene_dir};
use std::process::Command;

const CAMERA: &str = "[camera]\nfov = 40\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n";

/// Load `scene.toml` (with `files`) and return the error message, which must mention every
/// string of `needles`.
fn error_of(toml: &str, files: &[(&str, &[u8])], needles: &[&str]) -> String {
    let dir = scene_dir(toml, files);
    let msg = match load(dir.path()) {
        Ok(_) => panic!("expected an error for:\n{toml}"),
        Err(e) => e.to_string(),
    };
    for n in needles {
        assert!(msg.contains(n), "error {msg:?} does not mention {n:?}");
    }
    msg
}

fn obj_scene(file: &str) -> String {
    format!("{CAMERA}[[shapes]]\ntype = \"obj\"\nfilename = \"{file}\"\n")
}

#[test]
fn malformed_toml_reports_file_and_line() {
    let msg = error_of("[camera]\nfov = 40\neye = [0, 0\n", &[], &["scene.toml:3"]);
    assert!(msg.contains("scene.toml:"), "{msg}");
    error_of(&format!("{CAMERA}[render]\nwidht = 5\n"), &[], &["scene.toml:6", "unknown field `widht`"]);
    error_of(
        &format!("{CAMERA}[materials.a]\ntype = \"plastik\"\n"),
        &[],
        &["scene.toml:6", "unknown variant `plastik`"],
    );
    error_of("[render]\nspp = 4\n", &[], &["scene.toml", "missing field `camera`"]);
}

#[test]
fn missing_files_are_named() {
    error_of(&obj_scene("nowhere.obj"), &[], &["nowhere.obj", "shapes[0]"]);
    error_of(
        &format!(
            "{CAMERA}[textures.t]\ntype = \"image\"\nfilename = \"gone.png\"\n[materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n"
        ),
        &[],
        &["gone.png", "textures.t"],
    );
    error_of(
        &format!("{CAMERA}[environment]\ntype = \"envmap\"\nfilename = \"sky.exr\"\n"),
        &[],
        &["sky.exr", "environment"],
    );
    let missing_scene = tessera::scene::load_scene(std::path::Path::new("/no/such/scene.toml"), &Default::default());
    assert!(missing_scene.err().unwrap().to_string().contains("/no/such/scene.toml"));
}

#[test]
fn malformed_obj_is_an_error() {
    error_of(
        &obj_scene("bad.obj"),
        &[("bad.obj", b"v 0 0 0\nv 1 0 0\nv zero 1 0\nf 1 2 3\n")],
        &["bad.obj", "malformed OBJ"],
    );
    error_of(&obj_scene("oob.obj"), &[("oob.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")], &["oob.obj"]);
    error_of(
        &obj_scene("nan.obj"),
        &[("nan.obj", b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n")],
        &["shapes[0]", "non-finite position"],
    );
    error_of(&obj_scene("empty.obj"), &[("empty.obj", b"# nothing\n")], &["shapes[0]", "no triangles"]);
    error_of(
        &obj_scene("flat.obj"),
        &[("flat.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")],
        &["all 1 triangles have zero area"],
    );
}

#[test]
fn zero_area_triangles_are_dropped_with_a_warning() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 2\n";
    let dir = scene_dir(&obj_scene("some.obj"), &[("some.obj", obj)]);
    let scene = load(dir.path()).expect("a mesh with some good triangles loads");
    assert_eq!(scene.geometry.triangles.len(), 1);
    assert!(
        scene.warnings.iter().any(|w| w.contains("dropped 2 zero-area triangles") && w.contains("some.obj")),
        "{:?}",
        scene.warnings
    );
}

#[test]
fn malformed_gltf_is_an_error() {
    let scene = format!("{CAMERA}[[shapes]]\ntype = \"gltf\"\nfilename = \"m.gltf\"\n");
    error_of(&scene, &[("m.gltf", b"{ this is not json")], &["m.gltf", "malformed glTF"]);
    error_of(&scene, &[("m.gltf", b"\x00\x01garbage")], &["m.gltf"]);
    // Valid JSON whose buffer is missing.
    let json = br#"{"asset": {"version": "2.0"}, "buffers": [{"uri": "none.bin", "byteLength": 12}]}"#;
    error_of(&scene, &[("m.gltf", json)], &["m.gltf"]);
    // A scene without meshes.
    error_of(
        &scene,
        &[("m.gltf", br#"{"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]}"#)],
        &["no triangle meshes"],
    );
}

#[test]
fn malformed_images_are_errors() {
    let scene = format!(
        "{CAMERA}[textures.t]\ntype = \"image\"\nfilename = \"t.png\"\n[materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n"
    );
    error_of(&scene, &[("t.png", b"\x89PNG\r\n\x1a\nthis is cut short")], &["t.png", "cannot decode"]);
    let exr = format!("{CAMERA}[environment]\ntype = \"envmap\"\nfilename = \"sky.exr\"\n");
    error_of(&exr, &[("sky.exr", b"v/1\x01 not an exr")], &["sky.exr"]);
}

#[test]
fn absurd_parameters_are_rejected() {
    error_of(&format!("{CAMERA}[render]\nwidth = 0\n"), &[], &["render.width/height", "0x512"]);
    error_of(&format!("{CAMERA}[render]\nwidth = 100000\nheight = 100000\n"), &[], &["100000x100000"]);
    error_of(&format!("{CAMERA}[render]\nspp = 0\n"), &[], &["render.spp"]);
    error_of(&format!("{CAMERA}[render]\nspp = 4000000000\n"), &[], &["render.spp"]);
    error_of(&format!("{CAMERA}[render]\nmax_depth = 0\n"), &[], &["render.max_depth"]);
    error_of("[camera]\nfov = 0\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n", &[], &["camera.fov"]);
    error_of("[camera]\nfov = 40\neye = [0, 0, 3]\ntarget = [0, 0, 3]\n", &[], &["camera"]);
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"conductor\"\nalpha = -1\n"),
        &[],
        &["materials.m.alpha_u", "-1"],
    );
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"dielectric\"\nint_ior = 1\next_ior = 1\n"),
        &[],
        &["must differ"],
    );
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"dielectric\"\nint_ior = \"unobtainium\"\n"),
        &[],
        &["unknown IOR name"],
    );
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\nemission = -1\n"), &[], &["emission", "outside [0, 1e15]"]);
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\ntransform = [{{ scale = 0 }}]\n"), &[], &["singular"]);
}

#[test]
fn unknown_names_list_the_known_ones() {
    error_of(
        &format!("{CAMERA}[materials.metal]\ntype = \"diffuse\"\n[[shapes]]\ntype = \"cube\"\nmaterial = \"metl\"\n"),
        &[],
        &["unknown material 'metl'", "metal"],
    );
    error_of(
        &format!(
            "{CAMERA}[textures.checker]\ntype = \"image\"\nfilename = \"c.png\"\n[materials.m]\ntype = \"diffuse\"\nreflectance = \"chekcer\"\n"
        ),
        &[],
        &["materials.m.reflectance", "unknown texture 'chekcer'", "checker"],
    );
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"conductor\"\nmaterial = \"Unobtainium\"\n"),
        &[],
        &["unknown conductor"],
    );
}

fn tessera() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tessera"))
}

#[test]
fn cli_reports_errors_and_keeps_existing_output() {
    let dir = scene_dir(&format!("{CAMERA}[render]\nspp = 0\n"), &[]);
    let out = dir.path().join("good.exr");
    std::fs::write(&out, b"a good image").unwrap();
    let result = tessera().arg("render").arg(dir.path().join("scene.toml")).arg("-o").arg(&out).output().unwrap();
    assert_eq!(result.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.starts_with("error: ") && stderr.contains("render.spp"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(std::fs::read(&out).unwrap(), b"a good image");

    // A bad crop and a bad output extension are errors too.
    let ok = scene_dir(&format!("{CAMERA}[render]\nwidth = 8\nheight = 8\nspp = 1\n"), &[]);
    let bad_crop = tessera()
        .arg("render")
        .arg(ok.path().join("scene.toml"))
        .args(["--crop", "0,0,9,4", "-o"])
        .arg(ok.path().join("a.exr"))
        .output()
        .unwrap();
    assert_eq!(bad_crop.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad_crop.stderr).contains("--crop"));
    let bad_ext = tessera()
        .arg("render")
        .arg(ok.path().join("scene.toml"))
        .arg("-o")
        .arg(ok.path().join("a.jpg"))
        .output()
        .unwrap();
    assert_eq!(bad_ext.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad_ext.stderr).contains(".exr"));
}

#[test]
fn cli_renders_crop_and_aovs() {
    let dir = scene_dir(
        &format!("{CAMERA}[render]\nwidth = 16\nheight = 12\nspp = 2\n[[shapes]]\ntype = \"rectangle\"\n"),
        &[],
    );
    let out = dir.path().join("crop.exr");
    let status = tessera()
        .arg("render")
        .arg(dir.path().join("scene.toml"))
        .args(["--crop", "2,3,10,7", "--aov", "albedo,uv", "--threads", "1", "-q", "-o"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let img = tessera::image::read_bitmap(&out, tessera::image::ColorSpace::Linear).unwrap();
    assert_eq!((img.width, img.height), (8, 4));
}

#[test]
fn bad_tiling_and_blending_textures_are_named() {
    let png = {
        let mut bytes = Vec::new();
        image::GrayImage::from_pixel(4, 4, image::Luma([90]))
            .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
            .unwrap();
        bytes
    };
    let three_channel_exr = {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.exr");
        let plane = vec![1.0f32; 4];
        tessera::image::write_exr(
            &p,
            2,
            2,
            vec![("R".into(), plane.clone()), ("G".into(), plane.clone()), ("B".into(), plane)],
        )
        .unwrap();
        std::fs::read(&p).unwrap()
    };
    let nan_exr = {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("n.exr");
        let plane = vec![1.0f32, f32::NAN, 1.0, 1.0];
        let channels = ["R", "G", "B", "A"].iter().map(|c| (c.to_string(), plane.clone())).collect();
        tessera::image::write_exr(&p, 2, 2, channels).unwrap();
        std::fs::read(&p).unwrap()
    };
    // A cut map whose cell channel holds 2.5, not a cell number.
    let fractional_cell_exr = {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.exr");
        let planes = [vec![2.5f32, 0.0, 0.0, 0.0], vec![0.5; 4], vec![0.5; 4], vec![1.0; 4]];
        let channels = ["R", "G", "B", "A"].iter().zip(planes).map(|(c, p)| (c.to_string(), p)).collect();
        tessera::image::write_exr(&p, 2, 2, channels).unwrap();
        std::fs::read(&p).unwrap()
    };
    let files: &[(&str, &[u8])] =
        &[("e.png", &png), ("f.exr", &three_channel_exr), ("n.exr", &nan_exr), ("c.exr", &fractional_cell_exr)];
    let with = |tb: &str, extra: &str| {
        format!(
            "{CAMERA}[textures.e]\ntype = \"image\"\nfilename = \"e.png\"\n{extra}\
             [textures.tb]\ntype = \"tiling_blending\"\n{tb}\n\
             [materials.m]\ntype = \"diffuse\"\nreflectance = \"tb\"\n[[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n"
        )
    };
    error_of(&with("exemplar = \"nope\"", ""), files, &["textures.tb.exemplar", "unknown texture 'nope'"]);
    error_of(&with("exemplar = \"tb\"", ""), files, &["textures.tb", "refers to itself"]);
    error_of(&with("exemplar = \"e\"\ntile_size = 0", ""), files, &["textures.tb.tile_size"]);
    error_of(&with("exemplar = \"e\"\nblend = \"mix_max\"", ""), files, &["textures.tb", "priority"]);
    error_of(&with("exemplar = \"e\"\nexponent = 3", ""), files, &["textures.tb.exponent", "sharpened"]);
    error_of(&with("exemplar = \"e\"\nblend = \"sharpened\"\nexponent = -1", ""), files, &["textures.tb.exponent"]);
    error_of(&with("exemplar = \"e\"\nblend = \"mix_max\"\npriority = \"e\"\nlambda = nan", ""), files, &["lambda"]);
    error_of(
        &with("exemplar = \"e\"\nlayer_of = \"e\"", ""),
        files,
        &["textures.tb.layer_of", "not a tiling_blending"],
    );
    error_of(
        &with(
            "exemplar = \"e\"\nlayer_of = \"a\"\nseed = 3",
            "[textures.a]\ntype = \"tiling_blending\"\nexemplar = \"e\"\n",
        ),
        files,
        &["textures.tb", "seed", "layer_of"],
    );
    error_of(
        &with("exemplar = \"e\"\ndeformation = [{ type = \"map\", filename = \"f.exr\" }]", ""),
        files,
        &["f.exr", "4 channels", "textures.tb.deformation[0]"],
    );
    error_of(
        &with("exemplar = \"e\"\ndeformation = [{ type = \"map\", filename = \"n.exr\" }]", ""),
        files,
        &["n.exr", "NaN", "textures.tb.deformation[0]"],
    );
    error_of(&with("exemplar = \"e\"\ncuts = \"f.exr\"", ""), files, &["f.exr", "4 channels", "textures.tb.cuts"]);
    error_of(&with("exemplar = \"e\"\ncuts = \"n.exr\"", ""), files, &["n.exr", "NaN", "textures.tb.cuts"]);
    error_of(&with("exemplar = \"e\"\ncuts = \"c.exr\"", ""), files, &["c.exr", "2.5", "textures.tb.cuts"]);
    error_of(
        &with("exemplar = \"e\"\ndeformation = [{ type = \"map\", filename = \"none.exr\" }]", ""),
        files,
        &["none.exr", "textures.tb.deformation[0]"],
    );
    error_of(
        &with("exemplar = \"e\"\ndeformation = [{ type = \"scale\", scale = 0 }]", ""),
        files,
        &["deformation[0]", "non-zero"],
    );
    error_of(&with("exemplar = \"e\"\ndeformation = [{ type = \"twist\" }]", ""), files, &["unknown variant `twist`"]);
    error_of(
        &with(
            "exemplar = \"inner\"\nblend = \"histogram_preserving\"",
            "[textures.inner]\ntype = \"tiling_blending\"\nexemplar = \"e\"\n",
        ),
        files,
        &["textures.tb", "image exemplar"],
    );
}

#[test]
fn cli_bake_names_unknown_textures_and_writes_images() {
    let dir = scene_dir(
        &format!(
            "{CAMERA}[textures.e]\ntype = \"image\"\nfilename = \"e.png\"\n\
             [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"e\"\n"
        ),
        &[("e.png", &{
            let mut bytes = Vec::new();
            image::RgbImage::from_fn(8, 8, |x, y| image::Rgb([(x * 30) as u8, (y * 30) as u8, 100]))
                .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
                .unwrap();
            bytes
        })],
    );
    let scene = dir.path().join("scene.toml");
    let missing = tessera()
        .arg("bake")
        .arg(&scene)
        .args(["--texture", "nope", "-o"])
        .arg(dir.path().join("a.exr"))
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("unknown texture 'nope'"));
    let out = dir.path().join("tb.exr");
    let ok =
        tessera().arg("bake").arg(&scene).args(["--texture", "tb", "--res", "16", "-o"]).arg(&out).output().unwrap();
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let image = tessera::image::read_bitmap(&out, tessera::image::ColorSpace::Linear).unwrap();
    assert_eq!((image.width, image.height, image.channels), (16, 16, 4));
}
