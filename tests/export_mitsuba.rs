//! The Mitsuba 3 export: its XML says what tessera renders. (The golden tests check the whole
//! chain: Mitsuba renders these exports and tessera must agree with the images.)

mod common;

use glam::{Mat4, Vec3, Vec4};
use tessera::image::{ColorSpace, read_bitmap};
use tessera::scene::{SceneOverrides, export_mitsuba, load_scene};

fn export(scene_toml: &str, files: &[(&str, &[u8])]) -> (tempfile::TempDir, std::path::PathBuf, String) {
    let dir = common::scene_dir(scene_toml, files);
    let scene = common::load(dir.path()).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("mitsuba");
    export_mitsuba(&scene, &out, 256).unwrap_or_else(|e| panic!("{e}"));
    let xml = std::fs::read_to_string(out.join("scene.xml")).unwrap();
    (dir, out, xml)
}

fn attr<'a>(node: roxmltree::Node<'a, 'a>, name: &str) -> Option<&'a str> {
    node.children().find(|c| c.attribute("name") == Some(name)).and_then(|c| c.attribute("value"))
}

#[test]
fn brushed_metal_exports_as_mitsuba_scene_a() {
    let path = common::repo().join("scenes/golden/brushed_metal.toml");
    let scene = load_scene(&path, &SceneOverrides::default()).unwrap();
    let out = tempfile::tempdir().unwrap();
    export_mitsuba(&scene, out.path(), 256).unwrap();
    let xml = std::fs::read_to_string(out.path().join("scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
    let root = doc.root_element();
    let integrator = root.children().find(|n| n.has_tag_name("integrator")).unwrap();
    assert_eq!(integrator.attribute("type"), Some("path"));
    assert_eq!(attr(integrator, "max_depth"), Some("8"));
    assert_eq!(attr(integrator, "rr_depth"), Some("5"));

    let sensor = root.children().find(|n| n.has_tag_name("sensor")).unwrap();
    assert_eq!((attr(sensor, "fov"), attr(sensor, "fov_axis")), (Some("40"), Some("x")));
    let matrix: Vec<f32> = sensor
        .descendants()
        .find(|n| n.has_tag_name("matrix"))
        .and_then(|n| n.attribute("value"))
        .unwrap()
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let m = Mat4::from_cols_array(&matrix.try_into().unwrap()).transpose();
    // Mitsuba's camera looks down its +z, with +x to the left of the image.
    let forward = m.transform_vector3(Vec3::Z).normalize();
    let expected = (Vec3::new(0.0, -0.3, 0.0) - Vec3::new(0.0, 2.0, 4.6)).normalize();
    assert!(forward.distance(expected) < 1e-5, "{forward} vs {expected}");
    assert!(m.transform_vector3(Vec3::X).distance(-Vec3::X) < 1e-5, "image left is world -x");
    assert!((m * Vec4::W).truncate().distance(Vec3::new(0.0, 2.0, 4.6)) < 1e-5);
    let film = sensor.descendants().find(|n| n.has_tag_name("film")).unwrap();
    assert_eq!((attr(film, "width"), attr(film, "height")), (Some("128"), Some("128")));
    assert!(film.children().any(|n| n.has_tag_name("rfilter") && n.attribute("type") == Some("box")));

    let metal = root.children().find(|n| n.attribute("type") == Some("roughconductor")).expect("roughconductor");
    assert_eq!(attr(metal, "distribution"), Some("ggx"));
    assert_eq!((attr(metal, "alpha_u"), attr(metal, "alpha_v")), (Some("0.05"), Some("0.3")));
    assert_eq!(attr(metal, "eta"), Some("1.6575, 0.880405, 0.521244"));
    let shapes: Vec<_> = root.children().filter(|n| n.has_tag_name("shape")).collect();
    assert_eq!(shapes.len(), 3);
    let emitters: Vec<_> = shapes.iter().filter_map(|s| s.children().find(|n| n.has_tag_name("emitter"))).collect();
    assert_eq!(emitters.len(), 1);
    assert_eq!(attr(emitters[0], "radiance"), Some("30, 30, 30"));
    // The emitter's material is black (Mitsuba's default for emitters), the others are not.
    let env = root.children().find(|n| n.has_tag_name("emitter")).unwrap();
    assert_eq!((env.attribute("type"), attr(env, "radiance")), (Some("constant"), Some("0.25, 0.3, 0.4")));

    // Each exported mesh reloads as exactly the scene's geometry, triangle by triangle (the OBJ
    // loader numbers vertices in order of first use, so compare corners, not vertex arrays).
    let g = &scene.geometry;
    for (i, shape) in g.shapes.iter().enumerate() {
        let mesh = tessera::geometry::obj::load_obj(&out.path().join(format!("meshes/shape{i}.obj"))).unwrap();
        let triangles: Vec<usize> = (0..g.triangles.len()).filter(|&t| g.triangle_shape[t] as usize == i).collect();
        assert_eq!(mesh.triangle_count(), triangles.len(), "shape {i}");
        for (k, &t) in triangles.iter().enumerate() {
            let exported = mesh.indices[k];
            let original = g.triangle_vertices(t);
            for c in 0..3 {
                let v = exported[c] as usize;
                assert!(mesh.positions[v] == original.p[c], "shape {i} triangle {k} corner {c}: position differs");
                if let (Some(uvs), Some(orig)) = (&mesh.uvs, original.uv) {
                    assert!(uvs[v] == orig[c], "shape {i} triangle {k} corner {c}: uv differs");
                }
            }
        }
        assert_eq!(mesh.uvs.is_some(), shape.has_uvs);
        assert_eq!(mesh.normals.is_some(), shape.has_normals);
    }
}

#[test]
fn exported_texture_lookups_match_tessera() {
    // A 4 x 2 image; a colour use, and a scalar use of its green channel scaled by 0.5, with a
    // uv scale and offset.
    let img = image::RgbImage::from_fn(4, 2, |x, y| image::Rgb([(x * 60) as u8, (y * 200 + 10) as u8, 100]));
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    let toml = "[camera]\nfov = 30\neye = [0, 0, 4]\ntarget = [0, 0, 0]\n\
        [textures.t]\ntype = \"image\"\nfilename = \"t.png\"\nscale = [3, 2]\noffset = [0.1, 0.25]\n\
        [materials.m]\ntype = \"conductor\"\nalpha_u = { texture = \"t\", channel = \"g\", scale = 0.5 }\nalpha_v = 0.2\nspecular_reflectance = \"t\"\n\
        [[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n";
    let (_dir, out, xml) = export(toml, &[("t.png", &png)]);
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let texture = |name: &str| {
        doc.descendants()
            .find(|n| n.has_tag_name("texture") && n.attribute("name") == Some(name))
            .unwrap_or_else(|| panic!("{name}"))
    };
    // The scalar bake: 0.5 * green, as tessera reads it (linear for a scalar use).
    let alpha = texture("alpha_u");
    let file = attr(alpha, "filename").unwrap();
    let baked = read_bitmap(&out.join(file), ColorSpace::Linear).unwrap();
    assert_eq!((baked.width, baked.height, baked.channels), (4, 2, 1));
    for y in 0..2 {
        for x in 0..4 {
            let expected = 0.5 * (y * 200 + 10) as f32 / 255.0;
            assert!((baked.values(x, y)[0] - expected).abs() < 1e-6);
        }
    }
    // The colour bake is sRGB-decoded.
    let colour =
        read_bitmap(&out.join(attr(texture("specular_reflectance"), "filename").unwrap()), ColorSpace::Linear).unwrap();
    assert!((colour.values(1, 0)[0] - tessera::color::srgb_to_linear(60.0 / 255.0)).abs() < 1e-6);
    // to_uv: Mitsuba maps (u, 1 - v) through scale then translate and reads row v_m from the
    // top; tessera reads row 1 - (v s_y + o_y). They must agree modulo 1.
    let t = alpha.children().find(|n| n.attribute("name") == Some("to_uv")).unwrap();
    let get = |tag: &str, a: &str| -> f32 {
        t.children().find(|n| n.has_tag_name(tag)).unwrap().attribute(a).unwrap().parse().unwrap()
    };
    let (sx, sy, tx, ty) = (get("scale", "x"), get("scale", "y"), get("translate", "x"), get("translate", "y"));
    for (u, v) in [(0.1f32, 0.2f32), (0.7, 0.9), (0.33, 0.01)] {
        let (tessera_col, tessera_row) = (u * 3.0 + 0.1, 1.0 - (v * 2.0 + 0.25));
        let (mitsuba_col, mitsuba_row) = (u * sx + tx, (1.0 - v) * sy + ty);
        let frac = |x: f32| x - x.floor();
        assert!((frac(tessera_col) - frac(mitsuba_col)).abs() < 1e-5);
        assert!((frac(tessera_row) - frac(mitsuba_row)).abs() < 1e-5, "v {v}: {tessera_row} vs {mitsuba_row}");
    }
}

#[test]
fn two_sided_and_normal_mapped_materials_are_wrapped() {
    let toml = std::fs::read_to_string(common::repo().join("scenes/golden/normal_map.toml")).unwrap();
    let bumps = std::fs::read(common::repo().join("scenes/golden/textures/bumps.png")).unwrap();
    let (_dir, _out, xml) = export(&toml, &[("textures/bumps.png", &bumps)]);
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let twosided = doc.descendants().find(|n| n.attribute("type") == Some("twosided")).expect("twosided");
    let normalmap =
        twosided.children().find(|n| n.attribute("type") == Some("normalmap")).expect("normalmap inside twosided");
    assert!(normalmap.children().any(|n| n.attribute("type") == Some("diffuse")));
    assert!(doc.descendants().any(|n| n.attribute("type") == Some("normalmap")
        && n.children().any(|c| c.attribute("type") == Some("roughconductor"))));
}

/// The sensor each camera becomes, and the emitters of point, spot, directional lights and suns
/// (the golden scenes `punctual_lights` and `thin_lens` check that Mitsuba renders them alike).
#[test]
fn cameras_and_punctual_lights_export_as_their_mitsuba_plugins() {
    let lights = "[[lights]]\ntype = \"point\"\nposition = [1, 2, 3]\nintensity = 4\n\
                  [[lights]]\ntype = \"spot\"\nposition = [0, 3, 0]\ndirection = [0, -1, 0]\nintensity = 2\n\
                  cutoff_angle = 40\nfalloff = \"gltf\"\n\
                  [[lights]]\ntype = \"sun\"\ndirection = [0, -1, 1]\nirradiance = 5\n\
                  [[shapes]]\ntype = \"cube\"\n";
    let ortho = format!(
        "[render]\nwidth = 200\nheight = 100\n[camera]\nprojection = \"orthographic\"\nextent = 3\n\
         eye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear_clip = 0.5\n{lights}"
    );
    let dir = common::scene_dir(&ortho, &[]);
    let scene = common::load(dir.path()).unwrap();
    let report = export_mitsuba(&scene, &dir.path().join("out"), 16).unwrap();
    let xml = std::fs::read_to_string(dir.path().join("out/scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");
    let sensor = doc.descendants().find(|n| n.has_tag_name("sensor")).unwrap();
    assert_eq!(sensor.attribute("type"), Some("orthographic"));
    assert_eq!(attr(sensor, "near_clip"), Some("0.5"));
    // Mitsuba's film spans x in [-1, 1] before to_world: scaled by the half-width, 3 units.
    let matrix = sensor.descendants().find(|n| n.has_tag_name("matrix")).unwrap().attribute("value").unwrap();
    let m: Vec<f32> = matrix.split_whitespace().map(|v| v.parse().unwrap()).collect();
    assert!((Vec3::new(m[0], m[4], m[8]).length() - 3.0).abs() < 1e-5, "{matrix}");
    let emitters: Vec<_> = doc.descendants().filter(|n| n.has_tag_name("emitter")).collect();
    let kinds: Vec<_> = emitters.iter().map(|e| e.attribute("type").unwrap()).collect();
    assert_eq!(kinds, ["point", "spot", "directional"]);
    assert_eq!(attr(emitters[1], "cutoff_angle").map(|v| v.parse::<f32>().unwrap().round()), Some(40.0));
    assert_eq!(attr(emitters[1], "beam_width").map(|v| v.parse::<f32>().unwrap().round()), Some(30.0));
    let warnings = report.warnings.join("\n");
    assert!(warnings.contains("point light 1") && warnings.contains("spot falloff"), "{warnings}");
    assert!(warnings.contains("distant light 0") && warnings.contains("no sun disc"), "{warnings}");

    let lens = format!(
        "[camera]\nfov = 30\neye = [0, 0, 5]\ntarget = [0, 0, 0]\naperture_radius = 0.1\nfocus_distance = 4\n{lights}"
    );
    let (_dir, _out, xml) = export(&lens, &[]);
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let sensor = doc.descendants().find(|n| n.has_tag_name("sensor")).unwrap();
    assert_eq!(sensor.attribute("type"), Some("thinlens"));
    assert_eq!((attr(sensor, "aperture_radius"), attr(sensor, "focus_distance")), (Some("0.1"), Some("4")));
}

#[test]
fn pbr_materials_are_not_exported_silently() {
    let dir = common::scene_dir(
        "[camera]\nfov = 30\neye = [0, 0, 4]\ntarget = [0, 0, 0]\n[materials.gold]\ntype = \"pbr\"\n\
         base_color = [1, 0.8, 0.3]\nmetallic = 0.7\nroughness = 0.5\nanisotropy = 0.5\n\
         [[shapes]]\ntype = \"cube\"\nmaterial = \"gold\"\n",
        &[],
    );
    let scene = common::load(dir.path()).unwrap();
    let report = export_mitsuba(&scene, &dir.path().join("out"), 256).unwrap();
    // Warnings name the material as the scene does.
    let warnings = report.warnings.join("\n");
    assert!(warnings.contains("materials.gold: glTF's metallic-roughness has no exact Mitsuba 3 equivalent"));
    assert!(warnings.contains("materials.gold: its anisotropy is not exported"), "{warnings}");
    let xml = std::fs::read_to_string(dir.path().join("out/scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let blend = doc.descendants().find(|n| n.attribute("type") == Some("blendbsdf")).expect("a blendbsdf");
    assert_eq!(attr(blend, "weight"), Some("0.7"));
    let lobes: Vec<_> = blend.children().filter(|n| n.has_tag_name("bsdf")).collect();
    assert_eq!(
        lobes.iter().map(|n| n.attribute("type").unwrap()).collect::<Vec<_>>(),
        ["roughplastic", "roughconductor"]
    );
    // alpha = roughness^2 in both lobes; the metal's F0 is the base colour: eta of F0 = 1 is huge.
    assert_eq!(attr(lobes[0], "alpha"), Some("0.25"));
    let eta: Vec<f32> = attr(lobes[1], "eta").unwrap().split(',').map(|v| v.trim().parse().unwrap()).collect();
    let f0 = |eta: f32| ((eta - 1.0) / (eta + 1.0)).powi(2);
    assert!((f0(eta[1]) - 0.8).abs() < 1e-4 && (f0(eta[2]) - 0.3).abs() < 1e-4, "{eta:?}");
}

#[test]
fn procedural_textures_are_baked_over_the_uv_square() {
    // The Fig. 2 rotation scene: its tiling-and-blending reflectance becomes a bitmap holding
    // exactly tessera's point lookups at the bake's texel centres, with the identity uv map.
    let path = common::repo().join("scenes/fig2_rotation.toml");
    let scene = load_scene(&path, &SceneOverrides::default()).unwrap();
    let out = tempfile::tempdir().unwrap();
    let export = export_mitsuba(&scene, out.path(), 64).unwrap();
    // Warnings name the texture as the scene file does.
    assert!(
        export.warnings.iter().any(|w| w.starts_with("textures.") && w.contains("is procedural")),
        "{:?}",
        export.warnings
    );
    let xml = std::fs::read_to_string(out.path().join("scene.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap();
    let bitmap = doc.descendants().find(|n| n.attribute("type") == Some("bitmap")).expect("a bitmap texture");
    let file = attr(bitmap, "filename").unwrap();
    let baked = read_bitmap(&out.path().join(file), ColorSpace::Linear).unwrap();
    assert_eq!((baked.width, baked.height), (64, 64));
    let expected = tessera::texture::bake(&scene.textures[0], 64, tessera::texture::BakeFootprint::Point);
    for (y, x) in [(0, 0), (5, 40), (63, 63), (31, 7)] {
        let (a, b) = (baked.pixel(x, y).truncate(), expected.pixel(x, y).truncate());
        assert!((a - b).abs().max_element() < 1e-6, "texel ({x}, {y}): {a} vs {b}");
    }
    let scale = bitmap.descendants().find(|n| n.has_tag_name("scale")).unwrap();
    assert_eq!((scale.attribute("x"), scale.attribute("y")), (Some("1"), Some("1")));
}
