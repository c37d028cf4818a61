//! `tessera import-mitsuba`: Mitsuba 3 XML in, a tessera scene out. The golden scenes' exports
//! must come back as the same scenes (the same image from the same random numbers), and a scene
//! written by hand in Mitsuba's own idioms must translate, with what was not translated listed.

mod common;

use tessera::image::compare::image_metrics;
use tessera::scene::{SceneOverrides, export_mitsuba, import_mitsuba, load_scene};

/// Render `scene` at a small size and sample count, the same for both sides of a comparison.
fn render_small(path: &std::path::Path) -> tessera::image::Bitmap {
    let overrides = SceneOverrides { width: Some(48), height: Some(48), spp: Some(8), ..Default::default() };
    let scene = load_scene(path, &overrides).unwrap_or_else(|e| panic!("{e}"));
    common::render_film(&scene).radiance()
}

/// Every golden scene, exported to Mitsuba XML and imported back, renders as its original. The
/// two renders draw the same random numbers, so anything but float rounding (the export's near
/// clip of 1 mm, a texture offset computed back) shows: a relMSE of a few 1e-2, as two
/// independent renders at 8 spp would give, fails by three orders of magnitude.
#[test]
fn golden_scenes_round_trip_through_mitsuba_xml() {
    let golden = common::repo().join("scenes/golden");
    let mut names: Vec<_> = std::fs::read_dir(&golden)
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().to_str()?.strip_suffix(".toml").map(str::to_string))
        .collect();
    names.sort();
    assert!(names.len() >= 9, "{names:?}");
    for name in names {
        let original = golden.join(format!("{name}.toml"));
        let scene = load_scene(&original, &SceneOverrides::default()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let export = dir.path().join("mitsuba");
        export_mitsuba(&scene, &export, 64).unwrap();
        let import = import_mitsuba(&export.join("scene.xml"), &export).unwrap_or_else(|e| panic!("{name}: {e}"));
        // What the export writes is all translatable but its reconstruction filter (a box) and
        // its near clip, which are exact too.
        assert!(import.untranslated.is_empty(), "{name}: {:?}", import.untranslated);
        let imported = export.join("imported.toml");
        std::fs::write(&imported, import.to_toml(&export.join("scene.xml"))).unwrap();
        let (a, b) = (render_small(&original), render_small(&imported));
        let metrics = image_metrics(&b, &a).unwrap();
        println!("{name:<18} relMSE {:.2e}", metrics.relmse);
        assert!(metrics.relmse < 1e-5, "{name}: the imported scene renders differently, relMSE {:.3e}", metrics.relmse);
    }
}

/// A scene in Mitsuba's own idioms: `$` defaults (also in a `type`), a `<ref>`-erenced texture
/// and BSDF, a checkerboard, a `twosided` wrapper, a sensor whose field of view spans x by
/// default and whose near clip is Mitsuba's default, a spot light placed by `lookat`, an exact
/// sphere, a PLY mesh, and things
/// tessera does not have (a `principled` BSDF, a sphere scaled unevenly), each listed; a
/// serialized file's second mesh; Mitsuba's default Gaussian pixel filter.
#[test]
fn a_hand_written_mitsuba_scene_translates_with_its_gaps_listed() {
    let xml = r#"<scene version="3.0.0">
        <default name="spp" value="32"/>
        <default name="res" value="64"/>
        <default name="integrator" value="path"/>
        <integrator type="$integrator"><integer name="max_depth" value="6"/></integrator>
        <sensor type="perspective">
            <float name="fov" value="45"/>
            <transform name="to_world"><lookat origin="0, 2, 6" target="0, 0, 0" up="0, 1, 0"/></transform>
            <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
            <film type="hdrfilm"><integer name="width" value="$res"/><integer name="height" value="48"/></film>
        </sensor>
        <texture type="bitmap" id="checks"><string name="filename" value="checker.png"/></texture>
        <bsdf type="twosided" id="floor"><bsdf type="diffuse"><ref name="reflectance" id="checks"/></bsdf></bsdf>
        <bsdf type="diffuse" id="board"><texture type="checkerboard" name="reflectance"><rgb name="color1" value="0.1"/>
            <transform name="to_uv"><scale x="4" y="2"/></transform></texture></bsdf>
        <bsdf type="roughconductor" id="gold"><string name="material" value="Al"/><float name="alpha" value="0.2"/></bsdf>
        <shape type="rectangle"><transform name="to_world"><scale value="5"/><rotate x="1" angle="-90"/></transform><ref id="floor"/></shape>
        <shape type="sphere"><point name="center" x="0" y="1" z="0"/><float name="radius" value="0.8"/><ref id="gold"/></shape>
        <shape type="sphere"><transform name="to_world"><scale x="0.2" y="0.4" z="0.2"/><translate x="2"/></transform></shape>
        <shape type="ply"><string name="filename" value="quad.ply"/></shape>
        <shape type="serialized"><string name="filename" value="quads.serialized"/><integer name="shape_index" value="1"/></shape>
        <shape type="cube"><bsdf type="principled"/></shape>
        <shape type="rectangle"><ref id="board"/><transform name="to_world"><translate z="-3"/></transform></shape>
        <emitter type="spot">
            <transform name="to_world"><lookat origin="2, 4, 2" target="0, 0, 0"/></transform>
            <rgb name="intensity" value="40, 35, 30"/><float name="cutoff_angle" value="25"/>
        </emitter>
        <emitter type="constant"><rgb name="radiance" value="0.1"/></emitter>
    </scene>"#;
    let files: [(&str, &[u8]); 4] = [
        ("scene.xml", xml.as_bytes()),
        ("checker.png", &checker_png()),
        ("quad.ply", QUAD_PLY.as_bytes()),
        ("quads.serialized", &quads_serialized()),
    ];
    let dir = common::scene_dir("", &files);
    let import = import_mitsuba(&dir.path().join("scene.xml"), dir.path()).unwrap();
    let gaps = import.untranslated.join("\n");
    for expected in ["principled", "ellipsoid", "Beckmann"] {
        assert!(gaps.contains(expected), "{expected} should be listed:\n{gaps}");
    }
    // Defaults apply in every attribute: `type="$integrator"` is the path tracer; the film's
    // filter is Mitsuba's default Gaussian.
    assert!(!gaps.contains("integrator") && !gaps.contains("filter"), "{gaps}");
    let path = dir.path().join("imported.toml");
    std::fs::write(&path, import.to_toml(&dir.path().join("scene.xml"))).unwrap();
    let scene = load_scene(&path, &SceneOverrides::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((scene.settings.width, scene.settings.height, scene.settings.spp), (64, 48, 32));
    assert_eq!(scene.settings.max_depth, Some(6));
    assert_eq!(scene.settings.pixel_filter, tessera::image::PixelFilter::Gaussian { stddev: 0.5 });
    // Mitsuba's default near clip, and its field of view along x.
    let model = scene.camera.model();
    assert_eq!(model.near_clip, 0.01);
    assert_eq!(
        model.projection,
        tessera::camera::Projection::Perspective { fov: 45.0, axis: tessera::camera::FovAxis::X }
    );
    // The camera still looks at the origin from (0, 2, 6), right on the image towards +x.
    let (ray, _) = scene.camera.generate_ray(glam::Vec2::new(32.0, 24.0), glam::Vec2::ZERO);
    let expected = (-glam::Vec3::new(0.0, 2.0, 6.0)).normalize();
    assert!(ray.d.distance(expected) < 1e-5, "{}", ray.d);
    let (right, _) = scene.camera.generate_ray(glam::Vec2::new(63.0, 24.0), glam::Vec2::ZERO);
    assert!(right.d.x > 0.1);
    // The spot points from (2, 4, 2) at the origin; the floor is two-sided and textured.
    let spot = &scene.lights.points[0];
    assert!(spot.spot.unwrap().axis().distance(-glam::Vec3::new(2.0, 4.0, 2.0).normalize()) < 1e-5);
    assert!(scene.materials.iter().any(|m| m.name == "materials.floor" && m.two_sided));
    assert_eq!(scene.geometry.shapes.len(), 7, "rectangle, 2 spheres, PLY, serialized, cube, rectangle");
    // The checkerboard: Mitsuba's default color0, the given color1, its to_uv as for bitmaps.
    let board = scene.textures.iter().find_map(|t| match t {
        tessera::texture::Texture::Checkerboard(b) => Some(*b),
        _ => None,
    });
    let board = board.expect("a checkerboard texture");
    assert_eq!((board.color0.x, board.color1.x, board.scale), (0.4, 0.1, glam::Vec2::new(4.0, 2.0)));
    assert_eq!(board.offset, glam::Vec2::new(0.0, -1.0));
    // The serialized file's second mesh: the quad moved by x + 3, double precision.
    let g = &scene.geometry;
    let i = g.shapes.iter().position(|s| s.name.contains("quads.serialized")).unwrap();
    let vertices = &g.positions[g.shapes[i].first_vertex as usize..g.shapes[i + 1].first_vertex as usize];
    assert_eq!(vertices.iter().map(|p| p.x).fold(f32::MIN, f32::max), 4.0);
    assert!(!g.shapes[i].has_normals && g.shapes[i].has_uvs);
    // The sphere is exact; the unevenly scaled one a mesh.
    let [sphere] = &scene.geometry.spheres[..] else { panic!("one exact sphere") };
    assert_eq!((sphere.center(), sphere.radius()), (glam::Vec3::Y, 0.8));
}

fn checker_png() -> Vec<u8> {
    let image =
        image::RgbImage::from_fn(
            8,
            8,
            |x, y| if (x + y) % 2 == 0 { image::Rgb([200; 3]) } else { image::Rgb([40; 3]) },
        );
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

#[test]
fn malformed_mitsuba_files_are_errors_naming_the_file() {
    for (xml, needle) in [
        ("<scene><shape", "malformed XML"),
        ("<notascene/>", "not <scene>"),
        ("<scene version=\"3.0.0\"/>", "no <sensor>"),
        ("<scene><sensor type=\"perspective\"><float name=\"fov\" value=\"wide\"/></sensor></scene>", "fov = 'wide'"),
        ("<scene><sensor type=\"fisheye\"/></scene>", "sensor type 'fisheye'"),
        ("<scene><shape type=\"cube\"><ref id=\"nothing\"/></shape></scene>", "<ref id=\"nothing\">"),
        (
            "<scene><shape type=\"cube\"><transform name=\"to_world\"><matrix value=\"1 2 3\"/></transform></shape></scene>",
            "16 (or 9) numbers",
        ),
    ] {
        let dir = common::scene_dir("", &[("bad.xml", xml.as_bytes())]);
        let err = import_mitsuba(&dir.path().join("bad.xml"), dir.path()).unwrap_err().to_string();
        assert!(err.contains("bad.xml") && err.contains(needle), "{xml}: {err}");
    }
}

/// The command writes the scene only once it loads: a translation whose files are missing is an
/// error naming them, and leaves a previous scene file as it was.
#[test]
fn the_command_writes_only_a_scene_that_loads() {
    let xml = r#"<scene version="3.0.0">
        <sensor type="orthographic"><transform name="to_world"><scale x="2" y="2"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>
        <shape type="obj"><string name="filename" value="missing.obj"/></shape>
        <emitter type="point"><point name="position" value="0, 2, 0"/><rgb name="intensity" value="5"/></emitter>
    </scene>"#;
    let dir = common::scene_dir("# a scene that was here before\n", &[("scene.xml", xml.as_bytes())]);
    let out = dir.path().join("scene.toml");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["import-mitsuba", "scene.xml", "-o", "scene.toml"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && stderr.contains("missing.obj"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "# a scene that was here before\n");
    // Without the missing mesh it is written, and the orthographic film's scale is its extent.
    std::fs::write(dir.path().join("scene.xml"), xml.replace("missing.obj", "cube.obj")).unwrap();
    std::fs::write(dir.path().join("cube.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["import-mitsuba", "scene.xml", "-o", "scene.toml"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let scene = load_scene(&out, &SceneOverrides::default()).unwrap();
    assert_eq!(
        scene.camera.model().projection,
        tessera::camera::Projection::Orthographic { extent: 4.0, axis: tessera::camera::FovAxis::X }
    );
    assert_eq!(scene.lights.points.len(), 1);
}

/// A quad whose texture coordinates follow x and y.
const QUAD_PLY: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
    property float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\n\
    end_header\n-1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n4 0 1 2 3\n";

/// A Mitsuba serialized file (format version 4) of two meshes: `QUAD_PLY`'s quad with normals
/// in single precision, and the same moved by x + 3, without normals, in double precision.
fn quads_serialized() -> Vec<u8> {
    use std::io::Write;
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let mesh = |name: &str, dx: f64, double: bool| {
        let mut body = Vec::new();
        let flags: u32 = if double { 0x2000 | 0x0002 } else { 0x1000 | 0x0002 | 0x0001 };
        body.extend(flags.to_le_bytes());
        body.extend(name.as_bytes());
        body.push(0);
        body.extend(4u64.to_le_bytes());
        body.extend(2u64.to_le_bytes());
        let mut floats = |values: &[f64]| {
            for v in values {
                if double { body.extend(v.to_le_bytes()) } else { body.extend((*v as f32).to_le_bytes()) }
            }
        };
        corners.iter().for_each(|(x, y)| floats(&[x + dx, *y, 0.0]));
        if !double {
            corners.iter().for_each(|_| floats(&[0.0, 0.0, 1.0]));
        }
        corners.iter().for_each(|(x, y)| floats(&[(x + 1.0) / 2.0, (y + 1.0) / 2.0]));
        for i in [0u32, 1, 2, 0, 2, 3] {
            body.extend(i.to_le_bytes());
        }
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&body).unwrap();
        [&0x041Cu16.to_le_bytes()[..], &4u16.to_le_bytes(), &z.finish().unwrap()].concat()
    };
    let (first, second) = (mesh("quad", 0.0, false), mesh("moved", 3.0, true));
    let mut file = [first.clone(), second].concat();
    file.extend(0u64.to_le_bytes());
    file.extend((first.len() as u64).to_le_bytes());
    file.extend(2u32.to_le_bytes());
    file
}

/// PLY and serialized texture coordinates are read as Mitsuba 3.9.1 reads them. Rendered
/// there, a quad as PLY or serialized and the same quad as OBJ (the same u, v per vertex) show
/// the texture mirrored top to bottom (Mitsuba flips an OBJ's v, not the others'), so tessera's
/// uv must be the OBJ's (u, 1 - v): checked pixel by pixel on the uv AOV, same samples on both
/// sides.
#[test]
fn ply_and_serialized_texture_coordinates_run_as_mitsuba_reads_them() {
    let obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    let scene = |file: &str| {
        format!(
            "[render]\nwidth = 16\nheight = 16\nspp = 2\n[camera]\nprojection = \"orthographic\"\nextent = 1.5\n\
             eye = [0, 0, 3]\ntarget = [0, 0, 0]\n[environment]\ntype = \"constant\"\nradiance = 1\n\
             [[shapes]]\ntype = \"{}\"\nfilename = \"{file}\"\n",
            file.rsplit('.').next().unwrap()
        )
    };
    let uv = |file: &str| {
        let serialized = quads_serialized();
        let files: [(&str, &[u8]); 3] =
            [("quad.ply", QUAD_PLY.as_bytes()), ("quad.obj", obj.as_bytes()), ("quad.serialized", &serialized)];
        let (_dir, scene) = common::scene(&scene(file), &files);
        let film = tessera::integrator::render(&scene, None, &[tessera::image::Aov::Uv], &|_, _| {});
        film.aov(tessera::image::Aov::Uv).unwrap()
    };
    let from_obj = uv("quad.obj");
    for file in ["quad.ply", "quad.serialized"] {
        for (p, o) in uv(file).data.chunks(2).zip(from_obj.data.chunks(2)) {
            assert!((p[0] - o[0]).abs() < 1e-6 && (p[1] - (1.0 - o[1])).abs() < 1e-6, "{file} {p:?} against OBJ {o:?}");
        }
    }
}
