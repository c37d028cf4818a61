//! Bad input gets a clear error naming the file and the problem, never a panic, and never
//! replaces a good output image.

mod common;

use common::{load, scene_dir};
use std::process::Command;
use tessera::image::Aov;

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

/// `image` encoded as PNG.
fn png(image: impl Into<image::DynamicImage>) -> Vec<u8> {
    let mut bytes = Vec::new();
    image.into().write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
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
    // `tessera deform` reads meshes through load_surface: the same checks, no panic in deform/.
    let dir = scene_dir("", &[("oob.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 1/1 2/1 7/1\n")]);
    let msg = tessera::scene::load_surface(&dir.path().join("oob.obj")).map(|_| ()).unwrap_err().to_string();
    assert!(msg.contains("oob.obj"), "{msg}");
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
fn malformed_ply_is_an_error_naming_the_file() {
    let scene = |file: &str| format!("{CAMERA}[[shapes]]\ntype = \"ply\"\nfilename = \"{file}\"\n");
    error_of(&scene("bad.ply"), &[("bad.ply", b"ply\nformat ascii 1.0\nend_header\n")], &["bad.ply", "no triangles"]);
    let truncated = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nend_header\n\x00\x00";
    error_of(&scene("cut.ply"), &[("cut.ply", truncated)], &["cut.ply", "ends before"]);
    error_of(&scene("text.ply"), &[("text.ply", b"solid cube\nendsolid\n")], &["text.ply", "end_header"]);
}

#[test]
fn malformed_serialized_is_an_error_naming_the_file() {
    use std::io::Write;
    let scene = |file: &str, index: u32| {
        format!("{CAMERA}[[shapes]]\ntype = \"serialized\"\nfilename = \"{file}\"\nshape_index = {index}\n")
    };
    let zlib = |body: &[u8]| {
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(body).unwrap();
        z.finish().unwrap()
    };
    let header = |version: u16| [0x041Cu16.to_le_bytes(), version.to_le_bytes()].concat();
    // A header claiming 30 million triangles over a stream of a few bytes: an error, and no
    // allocation for them.
    let mut claims = 0x1000u32.to_le_bytes().to_vec();
    claims.extend(b"big\0");
    claims.extend(3u64.to_le_bytes());
    claims.extend(30_000_000u64.to_le_bytes());
    let lying = [header(4), zlib(&claims)].concat();
    error_of(&scene("lying.serialized", 0), &[("lying.serialized", &lying)], &["lying.serialized", "truncated"]);
    error_of(&scene("text.serialized", 0), &[("text.serialized", b"solid cube\n")], &["text.serialized", "magic"]);
    let v5 = [header(5), zlib(&claims)].concat();
    error_of(&scene("v5.serialized", 0), &[("v5.serialized", &v5)], &["v5.serialized", "version 5"]);
    let mut one = lying.clone();
    one.extend(0u64.to_le_bytes());
    one.extend(1u32.to_le_bytes());
    error_of(
        &scene("one.serialized", 3),
        &[("one.serialized", &one)],
        &["one.serialized", "shape_index 3", "1 meshes"],
    );
    let garbage = [header(4), vec![0x78, 0x9c, 1, 2, 3]].concat();
    error_of(&scene("bad.serialized", 0), &[("bad.serialized", &garbage)], &["bad.serialized", "corrupt"]);
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
    error_of(
        &format!("{CAMERA}[render]\nfilter = {{ type = \"gaussian\", stddev = -1 }}\n"),
        &[],
        &["render.filter", "stddev"],
    );
    error_of(
        &format!("{CAMERA}[render]\nfilter = {{ type = \"tent\", radius = 1e9 }}\n"),
        &[],
        &["render.filter", "radius"],
    );
    error_of(&format!("{CAMERA}[render]\nfilter = {{ type = \"mitchell\" }}\n"), &[], &["mitchell"]);
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
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\nemission = -1\n"),
        &[],
        &["emission", "outside [0, 1e15]"],
    );
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\ntransform = [{{ scale = 0 }}]\n"), &[], &["singular"]);
    // Spheres: a radius that is not positive, an ellipsoid, keys of other shapes.
    for radius in ["0", "-1", "1e30"] {
        error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nradius = {radius}\n"), &[], &["shapes[0]", "radius"]);
    }
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\ntransform = [{{ scale = [1, 2, 1] }}]\n"),
        &[],
        &["shapes[0]", "ellipsoid"],
    );
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"sphere\"\nsegments = 8\n"), &[], &["uv_sphere only"]);
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"cube\"\nradius = 2\n"), &[], &["sphere only"]);
}

#[test]
fn bad_lights_and_cameras_name_the_parameter() {
    let light = |body: &str| format!("{CAMERA}[[lights]]\n{body}\n");
    error_of(&light("type = \"point\"\nposition = [0, 1, 0]\nintensity = -2"), &[], &["lights[0]", "intensity"]);
    error_of(&light("type = \"point\"\nposition = [0, 1, 0]"), &[], &["intensity"]);
    error_of(&light("type = \"lamp\"\nposition = [0, 1, 0]"), &[], &["unknown variant `lamp`"]);
    let spot = "type = \"spot\"\nposition = [0, 1, 0]\nintensity = 1";
    error_of(&light(spot), &[], &["lights[0]", "exactly one of direction and target"]);
    error_of(&light(&format!("{spot}\ntarget = [0, 1, 0]")), &[], &["lights[0]", "no length"]);
    error_of(
        &light(&format!("{spot}\ndirection = [0, -1, 0]\ncutoff_angle = 20\nbeam_width = 30")),
        &[],
        &["lights[0]", "beam width 30"],
    );
    error_of(&light("type = \"directional\"\ndirection = [0, 0, 0]\nirradiance = 1"), &[], &["lights[0]", "no length"]);
    error_of(
        &light("type = \"sun\"\ndirection = [0, -1, 0]\nirradiance = 1\nangular_diameter = 0"),
        &[],
        &["lights[0]", "needs a disc"],
    );
    error_of(
        &light("type = \"sun\"\ndirection = [0, -1, 0]\nirradiance = 1e14\nangular_diameter = 0.001"),
        &[],
        &["lights[0]", "radiance"],
    );
    let camera = |keys: &str| format!("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n{keys}\n");
    error_of(&camera("projection = \"orthographic\""), &[], &["camera.extent is required"]);
    error_of(&camera("projection = \"orthographic\"\nextent = -1"), &[], &["camera.extent"]);
    error_of(&camera("projection = \"orthographic\"\nfov = 30"), &[], &["camera.fov applies to a perspective"]);
    error_of(&camera("fov = 30\nextent = 2"), &[], &["camera.extent applies to an orthographic"]);
    error_of(&camera("fov = 30\naperture_radius = 0.1"), &[], &["aperture_radius and focus_distance"]);
    error_of(&camera("fov = 30\naperture_radius = 0.1\nfocus_distance = 0"), &[], &["camera.focus_distance"]);
    error_of(
        &camera("projection = \"orthographic\"\nextent = 2\naperture_radius = 0.1\nfocus_distance = 1"),
        &[],
        &["thin lens needs a perspective camera"],
    );
    error_of(&camera("fov = 30\nnear_clip = -1"), &[], &["camera.near_clip"]);
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"cube\"\nlights = false\n"),
        &[],
        &["lights and light_scale apply to gltf shapes only"],
    );
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
    let png = png(image::GrayImage::from_pixel(4, 4, image::Luma([90])));
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
    // An identity F map, for cuts files.
    let identity_exr = {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("i.exr");
        let planes = [vec![1.0f32; 4], vec![0.0; 4], vec![0.0; 4], vec![1.0; 4]];
        let channels = ["R", "G", "B", "A"].iter().zip(planes).map(|(c, p)| (c.to_string(), p)).collect();
        tessera::image::write_exr(&p, 2, 2, channels).unwrap();
        std::fs::read(&p).unwrap()
    };
    let point = |s: &str| format!("[0.5, 0.1, 0.5, 0.9, {s}, 0, 0]");
    let cuts =
        |a: &str, b: &str| format!("{{\"curves\": [{{\"scale\": 1, \"points\": [{}, {}]}}]}}", point(a), point(b));
    let (decreasing, overflowing) = (cuts("1", "0"), cuts("0", "1e39"));
    let files: &[(&str, &[u8])] = &[
        ("e.png", &png),
        ("f.exr", &three_channel_exr),
        ("n.exr", &nan_exr),
        ("i.exr", &identity_exr),
        ("dec.json", decreasing.as_bytes()),
        ("big.json", overflowing.as_bytes()),
        ("bad.json", b"{\"curves\": 3}"),
    ];
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
    error_of(&with("exemplar = \"e\"\ncuts = \"dec.json\"", ""), files, &["textures.tb.cuts", "map factor"]);
    // Chart maps: one channel of whole numbers, the F map's size; field_at needs a field.
    let charted = |charts: &str| {
        with(
            &format!(
                "exemplar = \"e\"\nfield_at = \"tile_centre\"\n\
                 deformation = [{{ type = \"map\", filename = \"i.exr\", charts = \"{charts}\" }}]"
            ),
            "",
        )
    };
    error_of(&charted("f.exr"), files, &["f.exr", "one channel", "textures.tb.deformation[0].charts"]);
    error_of(&charted("e.png"), files, &["e.png", "the F map's size, 2x2"]);
    error_of(
        &with("exemplar = \"e\"\nfield_at = \"tile_centre\"", ""),
        files,
        &["textures.tb.field_at", "no deformation"],
    );
    error_of(&with("exemplar = \"e\"\nfield_at = \"corner\"", ""), files, &["unknown variant `corner`", "tile_centre"]);
    let mapped = |cuts: &str| {
        with(
            &format!("exemplar = \"e\"\ndeformation = [{{ type = \"map\", filename = \"i.exr\" }}]\ncuts = \"{cuts}\""),
            "",
        )
    };
    error_of(&mapped("dec.json"), files, &["dec.json", "decreases", "textures.tb.cuts"]);
    error_of(&mapped("big.json"), files, &["big.json", "not finite", "textures.tb.cuts"]);
    error_of(&mapped("bad.json"), files, &["bad.json", "not a cuts file", "textures.tb.cuts"]);
    error_of(&mapped("none.json"), files, &["none.json", "textures.tb.cuts"]);
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

/// A scene folder with an 8 x 8 image texture `e` and a tiling-and-blending texture `tb` of it.
fn image_and_tiling_blending_scene() -> tempfile::TempDir {
    scene_dir(
        &format!(
            "{CAMERA}[textures.e]\ntype = \"image\"\nfilename = \"e.png\"\n\
             [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"e\"\n"
        ),
        &[("e.png", &png(image::RgbImage::from_fn(8, 8, |x, y| image::Rgb([(x * 30) as u8, (y * 30) as u8, 100]))))],
    )
}

#[test]
fn cli_bake_names_unknown_textures_and_writes_images() {
    let dir = image_and_tiling_blending_scene();
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

#[test]
fn gpu_commands_name_what_is_wrong() {
    let dir = image_and_tiling_blending_scene();
    let scene = dir.path().join("scene.toml");
    let stderr_of = |args: &[&str]| {
        let out = tessera().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let scene = scene.to_str().unwrap();
    // Not a tiling-and-blending texture, with or without the `gpu` feature.
    assert!(stderr_of(&["gpu-check", scene, "--texture", "e"]).contains("not a tiling_blending texture"));
    assert!(stderr_of(&["gpu-check", scene, "--texture", "tb", "--tolerance", "NaN"]).contains("--tolerance"));
    assert!(stderr_of(&["gpu-check", scene, "--texture", "nope"]).contains("unknown texture 'nope'"));
    assert!(stderr_of(&["gpu-view", scene, "--texture", "e"]).contains("not a tiling_blending texture"));
    assert!(stderr_of(&["gpu-view", scene, "--texture", "tb", "--tolerance=-1"]).contains("--tolerance"));
    let msg = stderr_of(&["gpu-view", scene, "--texture", "tb", "-o", "view.txt"]);
    assert!(msg.contains("view.txt"), "{msg}");
    // Sizes clap refuses (exit status 2), saying why.
    for (res, why) in
        [("0x10", "outside"), ("640", "WIDTHxHEIGHT"), ("99999x99999", "outside"), ("8000x8000", "more than")]
    {
        let out = tessera().args(["gpu-view", scene, "--texture", "tb", "--res", res]).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{res}");
        let msg = String::from_utf8_lossy(&out.stderr);
        assert!(msg.contains(why), "{res}: {msg}");
    }
    // The shader export writes atomically: a folder that does not exist is an error naming it.
    let missing = dir.path().join("no/such/folder/t.glsl");
    let msg = stderr_of(&["shader", "export", "--lang", "glsl", "-o", missing.to_str().unwrap()]);
    assert!(msg.contains("no/such/folder"), "{msg}");
    assert!(!missing.exists());
}

/// A small glTF document (`common::small_gltf`) edited by `edit`, as a GLB.
fn edited_glb(edit: impl Fn(String) -> String) -> Vec<u8> {
    let (json, bin) = common::small_gltf();
    common::glb(&edit(json), &bin)
}

#[test]
fn gltf_documents_the_gltf_crate_would_panic_on_are_errors() {
    let scene = format!("{CAMERA}[[shapes]]\ntype = \"gltf\"\nfilename = \"m.glb\"\n");
    let fails = |glb: Vec<u8>, needles: &[&str]| {
        let msg = error_of(&scene, &[("m.glb", &glb)], needles);
        // `tessera deform` reads the same file through load_surface: the same error, no panic.
        let dir = scene_dir("", &[("m.glb", &glb)]);
        let surface = tessera::scene::load_surface(&dir.path().join("m.glb")).map(|_| ()).unwrap_err().to_string();
        assert!(needles.iter().all(|n| surface.contains(n)), "{surface} lacks {needles:?}");
        msg
    };
    let swap = |from: &'static str, to: &'static str| {
        move |json: String| {
            assert!(json.contains(from), "{from}");
            json.replacen(from, to, 1)
        }
    };
    // The unedited document loads.
    let dir = scene_dir(&scene, &[("m.glb", &edited_glb(|j| j))]);
    load(dir.path()).expect("the small glTF loads");
    // (text replaced, its replacement, what the error must say besides the file's name)
    let cases: &[(&str, &str, &[&str])] = &[
        ("\"POSITION\": 0", "\"POSITION\": 99", &["POSITION is accessor 99"]),
        ("\"NORMAL\": 1", "\"NORMAL\": 99", &["malformed glTF"]),
        (
            "\"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\"",
            "\"componentType\": 5121, \"count\": 4, \"type\": \"VEC3\", \"min\"",
            &["accessor 0", "allows"],
        ),
        ("\"componentType\": 5123, \"count\": 6", "\"componentType\": 5126, \"count\": 6", &["indices", "allows"]),
        ("\"count\": 4, \"type\": \"VEC2\"", "\"count\": 0, \"type\": \"VEC2\"", &["TexCoords(0)", "0 values"]),
        ("\"count\": 6, \"type\": \"SCALAR\"", "\"count\": 600, \"type\": \"SCALAR\"", &["reaches past the end"]),
        (
            "\"byteOffset\": 0, \"byteLength\": 48",
            "\"byteOffset\": 0, \"byteLength\": 48, \"byteStride\": 4",
            &["byteStride 4"],
        ),
        (
            "\"byteOffset\": 48, \"byteLength\": 48",
            "\"byteOffset\": 48, \"byteLength\": 4800",
            &["past the end of buffer 0"],
        ),
        ("{\"mesh\": 0,", "{\"children\": [0], \"mesh\": 0,", &["cycle"]),
        ("{\"camera\": 0,", "{\"children\": [1], \"camera\": 0,", &["child of both"]),
        (
            "\"count\": 4, \"type\": \"VEC2\"}",
            "\"count\": 4, \"type\": \"VEC2\", \"sparse\": {\"count\": 1, \"indices\": {\"bufferView\": 4, \"componentType\": 5123}, \"values\": {\"bufferView\": 2}}}",
            &["sparse"],
        ),
    ];
    for (from, to, needles) in cases {
        fails(edited_glb(swap(from, to)), &[&["m.glb"], *needles].concat());
    }
    // Images: without bufferView or uri; with a bufferView past the buffer. Without a mimeType
    // the format is read from the data, which works.
    let msg = error_of(
        &scene,
        &[("m.glb", &edited_glb(swap("{\"bufferView\": 5, \"mimeType\": \"image/png\"}", "{}")))],
        &["m.glb", "image 0"],
    );
    assert!(msg.contains("uri") || msg.contains("malformed"), "{msg}");
    let no_mime = edited_glb(swap(", \"mimeType\": \"image/png\"", ""));
    load(scene_dir(&scene, &[("m.glb", &no_mime)]).path()).expect("the PNG is recognised by its content");
    let scene_gltf = format!("{CAMERA}[[shapes]]\ntype = \"gltf\"\nfilename = \"m.gltf\"\n");
    let (json, _) = common::small_gltf();
    let external = json.replace("BUFFER_URI", ", \"uri\": \"/dev/zero\"");
    error_of(&scene_gltf, &[("m.gltf", external.as_bytes())], &["/dev/zero", "not a regular file"]);
    let remote = json.replace("BUFFER_URI", ", \"uri\": \"https://example.com/b.bin\"");
    error_of(&scene_gltf, &[("m.gltf", remote.as_bytes())], &["m.gltf", "relative file path"]);
    // Factors outside glTF's ranges.
    error_of(
        &scene,
        &[("m.glb", &edited_glb(swap("\"metallicFactor\": 0.2", "\"metallicFactor\": -5")))],
        &["m.glb", "[0, 1]"],
    );
}

/// An OpenEXR file of 2 x 2 pixels whose header claims a data window of `side` x `side`.
fn exr_claiming(side: i32) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.exr");
    let channels = ["R", "G", "B"].iter().map(|c| (c.to_string(), vec![0.5f32; 4])).collect();
    tessera::image::write_exr(&p, 2, 2, channels).unwrap();
    let mut bytes = std::fs::read(&p).unwrap();
    let key = b"dataWindow\0box2i\0";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&(side - 1).to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&(side - 1).to_le_bytes());
    bytes
}

#[test]
fn sizes_from_files_and_flags_are_limited_before_allocation() {
    let texture = |file: &str| {
        format!(
            "{CAMERA}[textures.t]\ntype = \"image\"\nfilename = \"{file}\"\n[materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n"
        )
    };
    error_of(&texture("big.exr"), &[("big.exr", &exr_claiming(100_000))], &["big.exr", "100000", "limit"]);
    // /dev/zero is read for ever and /dev/urandom has no end: only regular files are read.
    error_of(&texture("/dev/urandom"), &[], &["/dev/urandom", "not a regular file"]);
    error_of(&obj_scene("/dev/zero"), &[], &["/dev/zero", "not a regular file"]);
    let zero_scene = tessera::scene::load_scene(std::path::Path::new("/dev/zero"), &Default::default());
    assert!(zero_scene.err().unwrap().to_string().contains("not a regular file"));
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"uv_sphere\"\nsegments = 65536\nrings = 65536\n"),
        &[],
        &["shapes[0]", "uv_sphere", "8192"],
    );
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"uv_sphere\"\nsegments = 8192\nrings = 8192\n"),
        &[],
        &["shapes[0]", "134217728", "limit"],
    );
    // Tiling and blending nested four deep: each level triples the cost of every lookup.
    let png = png(image::GrayImage::from_pixel(4, 4, image::Luma([90])));
    let chain = |depth: usize| {
        let mut toml = format!("{CAMERA}[textures.t0]\ntype = \"image\"\nfilename = \"e.png\"\n");
        for i in 1..=depth {
            toml += &format!("[textures.t{i}]\ntype = \"tiling_blending\"\nexemplar = \"t{}\"\n", i - 1);
        }
        toml + &format!("[materials.m]\ntype = \"diffuse\"\nreflectance = \"t{depth}\"\n")
    };
    load(scene_dir(&chain(3), &[("e.png", &png)]).path()).expect("three levels are allowed");
    error_of(&chain(4), &[("e.png", &png)], &["nest 4 deep", "t4 -> t3 -> t2 -> t1"]);
    // Flags: clap refuses them before anything runs.
    let dir = scene_dir(&format!("{CAMERA}[render]\nwidth = 4\nheight = 4\nspp = 1\n"), &[]);
    for (args, needle) in [
        (vec!["render", "scene.toml", "--threads", "1000000"], "thread count"),
        (vec!["deform", "m.obj", "--res", "16384", "-o", "out"], "16384"),
        (vec!["bake", "scene.toml", "--texture", "t", "--res", "16384", "-o", "b.exr"], "16384"),
    ] {
        let out = tessera().current_dir(dir.path()).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(needle) && !stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

#[test]
fn non_finite_values_never_reach_an_output() {
    // TOML has nan and inf, and 1e300 is infinite as an f32: each is named by its key.
    error_of("[camera]\nfov = nan\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n", &[], &["camera.fov", "NaN"]);
    error_of(
        &format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\ntransform = [{{ translate = [0, 1e300, 0] }}]\n"),
        &[],
        &["shapes[0].transform[0].translate[1]"],
    );
    // Physically impossible parameters.
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"diffuse\"\nreflectance = -5\n"),
        &[],
        &["materials.m.reflectance", "[0, 1]"],
    );
    for ior in ["1e-30", "1e32", "0.5"] {
        error_of(
            &format!("{CAMERA}[materials.m]\ntype = \"dielectric\"\nint_ior = {ior}\n"),
            &[],
            &["materials.m.int_ior", "index of refraction"],
        );
    }
    error_of(
        &format!("{CAMERA}[materials.m]\ntype = \"conductor\"\neta = [1, 1, 1]\nk = [-1, 0, 0]\n"),
        &[],
        &["materials.m", "conductor"],
    );
    error_of(&format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\nemission = 1e30\n"), &[], &["emission", "1e15"]);
    // A scale field of 2^1000 at u = 1, and a bright emitter: the bake, the AOVs and the
    // variance stay finite.
    let exemplar = png(image::RgbImage::from_fn(8, 8, |x, y| image::Rgb([(x * 30) as u8, (y * 30) as u8, 100])));
    let toml = format!(
        "{CAMERA}[render]\nwidth = 12\nheight = 12\nspp = 4\n[textures.e]\ntype = \"image\"\nfilename = \"e.png\"\nfilter = \"ewa\"\n\
         [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"e\"\ndeformation = [{{ type = \"scale\", scale = 1, gradient = [1000, 0] }}]\n\
         [materials.m]\ntype = \"diffuse\"\nreflectance = \"tb\"\n[[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n\
         [[shapes]]\ntype = \"rectangle\"\nemission = 1e14\ntransform = [{{ translate = [0, 0, 4] }}]\n\
         [environment]\ntype = \"constant\"\nradiance = 1e14\n"
    );
    let (_dir, scene) = common::scene(&toml, &[("e.png", &exemplar)]);
    let aovs = [Aov::Albedo, Aov::Normal, Aov::Uv, Aov::Footprint];
    let film = tessera::integrator::render(&scene, None, &aovs, &|_, _| {});
    for (name, image) in [("radiance", film.radiance()), ("variance", film.variance())]
        .into_iter()
        .chain(aovs.iter().map(|a| ("an AOV", film.aov(*a).unwrap())))
    {
        assert_eq!(image.non_finite_count(), 0, "{name}");
    }
    let texture = &scene.textures[scene.textures.len() - 1];
    let baked = tessera::texture::bake(texture, 32, tessera::texture::BakeFootprint::Texel);
    assert_eq!(baked.non_finite_count(), 0);
}

#[test]
fn diff_never_passes_a_non_finite_image_or_criterion() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, value: f32| {
        let p = dir.path().join(name);
        let channels = ["R", "G", "B"].iter().map(|c| (c.to_string(), vec![value; 16])).collect();
        tessera::image::write_exr(&p, 4, 4, channels).unwrap();
        p
    };
    let (nan, black, variance) = (write("nan.exr", f32::NAN), write("black.exr", 0.0), write("var.exr", 0.01));
    let diff = |args: &[&str]| tessera().current_dir(dir.path()).arg("diff").args(args).output().unwrap();
    let out = diff(&["nan.exr", "black.exr", "--max-relmse", "1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("FAIL: 48 values of the test image are NaN"));
    let out = diff(&["nan.exr", "black.exr", "--variance", "var.exr", "--spp", "4"]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    let out = diff(&["black.exr", "nan.exr", "--max-relmse", "1"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not usable as a reference"));
    for args in [["--max-relmse", "nan"], ["--max-flip", "-1"], ["--spp", "0"]] {
        let mut all = vec!["black.exr", "black.exr", "--variance", "var.exr", "--spp", "4"];
        all.extend(args);
        let out = diff(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    }
    assert!(diff(&["black.exr", "black.exr", "--max-relmse", "0"]).status.success());
    let _ = (nan, black, variance);
}

/// A 4 x 4 grid of squares with UVs: `overlap` gives the first column the UVs of the third,
/// so that one UV column holds two islands and the first none.
fn grid_obj(overlap: bool) -> String {
    let mut obj = String::new();
    for j in 0..=4 {
        for i in 0..=4 {
            obj += &format!("v {} {} 0\nvt {} {}\n", i as f32 / 4.0, j as f32 / 4.0, i as f32 / 4.0, j as f32 / 4.0);
        }
    }
    for j in 0..4 {
        for i in 0..4 {
            let a = j * 5 + i + 1;
            let (b, c, d) = (a + 1, a + 6, a + 5);
            if overlap && i == 0 {
                // Same positions, UVs of the square two to the right: stacked on another island.
                obj += &format!(
                    "f {a}/{} {b}/{} {c}/{}\nf {a}/{} {c}/{} {d}/{}\n",
                    a + 2,
                    b + 2,
                    c + 2,
                    a + 2,
                    c + 2,
                    d + 2
                );
            } else {
                obj += &format!("f {a}/{a} {b}/{b} {c}/{c}\nf {a}/{a} {c}/{c} {d}/{d}\n");
            }
        }
    }
    obj
}

#[test]
fn failed_runs_leave_output_folders_as_they_were() {
    let dir =
        scene_dir("", &[("m.obj", grid_obj(false).as_bytes()), ("flat.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")]);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("f_map.exr"), b"the good map").unwrap();
    // A folder where a file must go: deform fails, and no file of the set is replaced.
    std::fs::create_dir(out.join("orientation.png")).unwrap();
    let run = tessera().current_dir(dir.path()).args(["deform", "m.obj", "--res", "16", "-o", "out"]).output().unwrap();
    assert_eq!(run.status.code(), Some(1), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(String::from_utf8_lossy(&run.stderr).contains("orientation.png"));
    assert_eq!(std::fs::read(out.join("f_map.exr")).unwrap(), b"the good map");
    // No staging folder is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
    // A mesh without UVs fails before anything is written, and makes no folder.
    let run = tessera().current_dir(dir.path()).args(["deform", "flat.obj", "-o", "new"]).output().unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(!dir.path().join("new").exists());
    // With the obstacle gone, all six files are written.
    std::fs::remove_dir(out.join("orientation.png")).unwrap();
    let run = tessera().current_dir(dir.path()).args(["deform", "m.obj", "--res", "16", "-o", "out"]).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_ne!(std::fs::read(out.join("f_map.exr")).unwrap(), b"the good map");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 6);
}

#[test]
fn lost_data_and_empty_scenes_are_reported() {
    // UVs on some faces only: an error, not UVs silently dropped.
    error_of(
        &obj_scene("p.obj"),
        &[("p.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\nf 2 4 3\n")],
        &["p.obj", "some faces have texture coordinates"],
    );
    let (_d, scene) = common::scene(CAMERA, &[]);
    assert!(scene.warnings.iter().any(|w| w.contains("no shapes")), "{:?}", scene.warnings);
    assert!(scene.warnings.iter().any(|w| w.contains("no light")), "{:?}", scene.warnings);
    let (_d, lit) = common::scene(&format!("{CAMERA}[[shapes]]\ntype = \"rectangle\"\nemission = 1\n"), &[]);
    assert!(lit.warnings.is_empty(), "{:?}", lit.warnings);
    // Overlapping UV islands: deform warns with the fraction.
    let dir = scene_dir("", &[("stacked.obj", grid_obj(true).as_bytes()), ("plain.obj", grid_obj(false).as_bytes())]);
    let run = |mesh: &str| {
        let folder = format!("maps-of-{mesh}");
        let out =
            tessera().current_dir(dir.path()).args(["deform", mesh, "--res", "32", "-o", &folder]).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let stacked = run("stacked.obj");
    assert!(stacked.contains("33.33% of the UV area is covered by more than one triangle"), "{stacked}");
    assert!(!run("plain.obj").contains("overlapping"));
}

/// `tessera tiles`: a triangle in a quad-only mesh, a non-manifold edge and a 3 x 3 image are
/// errors naming the file and the problem; a good output file stays as it was; a scene whose
/// `quad_tiles` image has the wrong size is an error naming the texture.
#[test]
fn bad_tile_inputs_are_named_and_keep_existing_output() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name);
    let quads = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 3 3 3\nv 4 4 4\n";
    std::fs::write(path("triangle.obj"), format!("{quads}f 1 2 3 4\nf 2 5 6\n")).unwrap();
    std::fs::write(path("fan.obj"), format!("{quads}f 1 2 3 4\nf 2 5 6 3\nf 3 7 8 2\n")).unwrap();
    std::fs::write(path("tiny.png"), png(image::RgbImage::new(3, 3))).unwrap();
    std::fs::write(path("good.obj"), b"a good mesh").unwrap();
    std::fs::write(path("good.png"), b"a good image").unwrap();
    let run = |args: &[&std::ffi::OsStr]| {
        let out = tessera().args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(stderr.starts_with("error: ") && !stderr.contains("panicked"), "{stderr}");
        stderr
    };
    let os = |s: &str| std::ffi::OsString::from(s);
    let map =
        |mesh: &str| run(&[&os("tiles"), &os("map"), path(mesh).as_os_str(), &os("-o"), path("good.obj").as_os_str()]);
    let msg = map("triangle.obj");
    assert!(msg.contains("triangle.obj") && msg.contains("face 2 (line 10) has 3 corners"), "{msg}");
    let msg = map("fan.obj");
    assert!(msg.contains("fan.obj") && msg.contains("non-manifold") && msg.contains("vertices 2 and 3"), "{msg}");
    let msg = run(&[&os("tiles"), &os("synth"), path("tiny.png").as_os_str(), &os("-o"), path("good.png").as_os_str()]);
    assert!(msg.contains("tiny.png") && msg.contains("too small"), "{msg}");
    let msg = run(&[
        &os("tiles"),
        &os("synth"),
        path("tiny.png").as_os_str(),
        &os("--tile-res"),
        &os("100"),
        &os("-o"),
        path("good.png").as_os_str(),
    ]);
    assert!(msg.contains("--tile-res") && msg.contains("multiple of 16"), "{msg}");
    assert_eq!(std::fs::read(path("good.obj")).unwrap(), b"a good mesh");
    assert_eq!(std::fs::read(path("good.png")).unwrap(), b"a good image");

    let toml = format!(
        "{CAMERA}[textures.t]\ntype = \"quad_tiles\"\nfilename = \"tiles.png\"\n[materials.m]\ntype = \"diffuse\"\n\
         reflectance = \"t\"\n[[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n"
    );
    error_of(
        &toml,
        &[("tiles.png", &png(image::RgbImage::new(100, 100)))],
        &["textures.t", "tiles.png", "not a tile image"],
    );
}
