//! Textures seen through whole renders: the UV convention (pinned by an asymmetric texture, for
//! OBJ and glTF alike), ray-differential footprints against geometry, and filtered lookups
//! converging to the unfiltered render.

mod common;

use common::scene;
use tessera::image::{Aov, Bitmap, Film};
use tessera::integrator::render;
use tessera::scene::Scene;

/// A 2 x 2 PNG: top row red, green; bottom row blue, white.
fn quadrant_png() -> Vec<u8> {
    let img = image::RgbImage::from_fn(2, 2, |x, y| match (x, y) {
        (0, 0) => image::Rgb([255, 0, 0]),
        (1, 0) => image::Rgb([0, 255, 0]),
        (0, 1) => image::Rgb([0, 0, 255]),
        _ => image::Rgb([255, 255, 255]),
    });
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

fn albedo(scene: &Scene) -> Bitmap {
    let film: Film = render(scene, None, &[Aov::Albedo], &|_, _| {});
    film.aov(Aov::Albedo).unwrap()
}

const QUAD_OBJ: &str =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";

/// The same unit quad in glTF (a child node whose translation cancels its parent's; the parent
/// shows its own quad out of view), glTF's top-left UV origin (v' = 1 - y), the
/// texture as baseColorTexture, and a camera node at (0.5, 0.5, 2) looking down -z.
fn quad_gltf() -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]] {
        p.iter().for_each(|v| bin.extend(v.to_le_bytes()));
    }
    for uv in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        uv.iter().for_each(|v| bin.extend(v.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let json = r#"{
      "asset": {"version": "2.0"},
      "scene": 0,
      "scenes": [{"nodes": [0, 1]}],
      "nodes": [
        {"mesh": 0, "translation": [-3, 0, 0], "children": [2]},
        {"camera": 0, "translation": [0.5, 0.5, 2]},
        {"mesh": 0, "translation": [3, 0, 0]}
      ],
      "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.01}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
      "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0, "roughnessFactor": 1}}],
      "textures": [{"source": 0}],
      "images": [{"uri": "tex.png"}],
      "buffers": [{"uri": "quad.bin", "byteLength": 92}],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
        {"buffer": 0, "byteOffset": 80, "byteLength": 12}
      ],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}
      ]
    }"#;
    (json.to_string(), bin)
}

const SETTINGS: &str = "[render]\nwidth = 64\nheight = 64\nspp = 4\n";

#[test]
fn asymmetric_texture_pins_uv_convention_for_obj_and_gltf() {
    let png = quadrant_png();
    let obj_scene = format!(
        "{SETTINGS}[camera]\nfov = {}\neye = [0.5, 0.5, 2]\ntarget = [0.5, 0.5, 0]\n\
         [textures.t]\ntype = \"image\"\nfilename = \"tex.png\"\n\
         [materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n\
         [[shapes]]\ntype = \"obj\"\nfilename = \"quad.obj\"\nmaterial = \"m\"\n",
        0.5f32.to_degrees()
    );
    let (_d1, obj) = scene(&obj_scene, &[("tex.png", &png), ("quad.obj", QUAD_OBJ.as_bytes())]);
    let (json, bin) = quad_gltf();
    let gltf_scene =
        format!("{SETTINGS}[camera]\ngltf = \"quad.gltf\"\n[[shapes]]\ntype = \"gltf\"\nfilename = \"quad.gltf\"\n");
    let (_d2, gltf) = scene(&gltf_scene, &[("tex.png", &png), ("quad.gltf", json.as_bytes()), ("quad.bin", &bin)]);

    let (a, b) = (albedo(&obj), albedo(&gltf));
    // Image top-left is the texture's top-left (uv near (0, 1)), as in Mitsuba with an OBJ.
    let expect = [
        ((16, 16), [1.0, 0.0, 0.0]),
        ((48, 16), [0.0, 1.0, 0.0]),
        ((16, 48), [0.0, 0.0, 1.0]),
        ((48, 48), [1.0, 1.0, 1.0]),
    ];
    for ((x, y), rgb) in expect {
        for (name, img) in [("obj", &a), ("gltf", &b)] {
            let px = img.values(x, y);
            for c in 0..3 {
                assert!((px[c] - rgb[c]).abs() < 0.15, "{name} pixel ({x}, {y}) = {px:?}, expected {rgb:?}");
            }
        }
    }
    // The two files describe the same scene: the images agree everywhere.
    let max_diff = a.data.iter().zip(&b.data).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
    assert!(max_diff < 0.02, "OBJ and glTF albedo differ by {max_diff}");
}

/// A square of side 2 s facing a camera at distance d: a pixel spans 2 d tan(fov / 2) / H in
/// world units, i.e. that / (2 s) in u and v, times the differential scale max(1/8, 1/sqrt(spp)).
#[test]
fn footprint_matches_pixel_size_on_a_facing_plane() {
    let (d, s, fov, h) = (3.0f32, 2.0f32, 40.0f32, 32u32);
    for spp in [1u32, 16, 256] {
        let toml = format!(
            "[render]\nwidth = {h}\nheight = {h}\nspp = {spp}\n\
             [camera]\nfov = {fov}\neye = [0, 0, {d}]\ntarget = [0, 0, 0]\n\
             [[shapes]]\ntype = \"rectangle\"\ntransform = [{{ scale = {s} }}]\n"
        );
        let (_dir, scene) = scene(&toml, &[]);
        let film = render(&scene, None, &[Aov::Footprint], &|_, _| {});
        let fp = film.aov(Aov::Footprint).unwrap();
        let pixel = 2.0 * d * (fov.to_radians() / 2.0).tan() / h as f32;
        let expected = pixel / (2.0 * s) * (1.0 / (spp as f32).sqrt()).max(0.125);
        let centre = fp.values(h as usize / 2, h as usize / 2)[0];
        assert!((centre - expected).abs() < 0.01 * expected, "spp {spp}: footprint {centre}, expected {expected}");
    }
}

/// A gradient times a fine checker on a receding plane: at 8 spp, trilinear and EWA lookups
/// must be closer to the converged unfiltered render than unfiltered lookups are (that is what
/// filtering is for), keep the image mean, and converge to the unfiltered render as spp grows
/// (the footprint shrinks to 1/8 pixel).
#[test]
fn filtered_lookups_converge_to_unfiltered_render() {
    let texture = image::RgbImage::from_fn(256, 256, |x, y| {
        let check = if (x / 2 + y / 2) % 2 == 0 { 1.0 } else { 0.25 };
        let v = ((0.15 + 0.8 * x as f32 / 255.0) * check * 255.0) as u8;
        image::Rgb([v, v, v])
    });
    let mut png = Vec::new();
    texture.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    let render_with = |filter: &str, spp: u32| {
        let toml = format!(
            "[render]\nwidth = 32\nheight = 32\nspp = {spp}\nmax_depth = 2\n\
             [camera]\nfov = 30\neye = [0, 1, 3]\ntarget = [0, 0, 0]\n\
             [environment]\ntype = \"constant\"\nradiance = 1\n\
             [textures.t]\ntype = \"image\"\nfilename = \"t.png\"\ncolorspace = \"linear\"\nfilter = \"{filter}\"\nscale = [4, 4]\n\
             [materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n\
             [[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\ntransform = [{{ scale = 4 }}, {{ rotate = [1, 0, 0], angle = -90 }}]\n"
        );
        let (_dir, scene) = scene(&toml, &[("t.png", &png)]);
        render(&scene, None, &[], &|_, _| {}).radiance()
    };
    common::assert_filtered_renders_converge(&["trilinear", "ewa"], render_with);
}
