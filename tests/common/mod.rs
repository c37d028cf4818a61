//! Helpers shared by the integration tests: scenes from strings, renders, and the chi-square
//! goodness-of-fit harness.
#![allow(dead_code)] // each test file uses a subset

use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use tessera::image::Film;
use tessera::integrator::render;
use tessera::sampling::Sampler;
use tessera::scene::{Scene, SceneOverrides, load_scene};

/// The repository root (for shipped scenes and test data).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Two triangles per cell of a grid of `columns` x `rows` cells whose vertices are numbered
/// column by column, `rows + 1` per column.
pub fn grid_triangles(columns: usize, rows: usize) -> Vec<[u32; 3]> {
    let mut indices = Vec::new();
    for k in 0..columns {
        for r in 0..rows {
            let i = (k * (rows + 1) + r) as u32;
            let j = i + rows as u32 + 1;
            indices.push([i, j, i + 1]);
            indices.push([i + 1, j, j + 1]);
        }
    }
    indices
}

/// `mesh` (with UVs) as OBJ text.
pub fn obj_text(mesh: &tessera::geometry::TriangleMesh) -> String {
    let uvs = mesh.uvs.as_ref().expect("a mesh with UVs");
    let mut obj = String::new();
    for (p, t) in mesh.positions.iter().zip(uvs) {
        obj += &format!("v {} {} {}\nvt {} {}\n", p.x, p.y, p.z, t.x, t.y);
    }
    for [a, b, c] in &mesh.indices {
        obj += &format!("f {0}/{0} {1}/{1} {2}/{2}\n", a + 1, b + 1, c + 1);
    }
    obj
}

/// `mesh` (with UVs) as a glTF file referring to `bin_name` for its data: positions, TEXCOORD_0
/// (glTF's top-left origin: v' = 1 - v) and, if given, TANGENT (w = 1). Returns (json, bin).
pub fn gltf_text(
    mesh: &tessera::geometry::TriangleMesh,
    tangents: Option<&[Vec3]>,
    bin_name: &str,
) -> (String, Vec<u8>) {
    let uvs = mesh.uvs.as_ref().expect("a mesh with UVs");
    let n = mesh.positions.len();
    let mut bin = Vec::new();
    let mut put = |values: &[f32]| values.iter().for_each(|v| bin.extend(v.to_le_bytes()));
    mesh.positions.iter().for_each(|p| put(&p.to_array()));
    uvs.iter().for_each(|t| put(&[t.x, 1.0 - t.y]));
    if let Some(tangents) = tangents {
        tangents.iter().for_each(|t| put(&[t.x, t.y, t.z, 1.0]));
    }
    let index_offset = bin.len();
    mesh.indices.iter().flatten().for_each(|i| bin.extend(i.to_le_bytes()));
    let (lo, hi) =
        mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let tangent_attribute = if tangents.is_some() { r#", "TANGENT": 3"# } else { "" };
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1{tangent_attribute}}}, "indices": 2}}]}}],
  "buffers": [{{"uri": "{bin_name}", "byteLength": {len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": {p}}},
    {{"buffer": 0, "byteOffset": {p}, "byteLength": {t}}},
    {{"buffer": 0, "byteOffset": {index_offset}, "byteLength": {i}}},
    {{"buffer": 0, "byteOffset": {tan_offset}, "byteLength": {tan}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {n}, "type": "VEC3", "min": [{}, {}, {}], "max": [{}, {}, {}]}},
    {{"bufferView": 1, "componentType": 5126, "count": {n}, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5125, "count": {count}, "type": "SCALAR"}},
    {{"bufferView": 3, "componentType": 5126, "count": {n}, "type": "VEC4"}}
  ]}}"#,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        len = bin.len(),
        p = n * 12,
        t = n * 8,
        i = mesh.indices.len() * 12,
        count = mesh.indices.len() * 3,
        tan_offset = n * 20,
        tan = if tangents.is_some() { n * 16 } else { 4 },
    );
    (json, bin)
}

/// Write `toml` as `scene.toml` (and `files` beside it) in a fresh temporary folder.
pub fn scene_dir(toml: &str, files: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temporary folder");
    std::fs::write(dir.path().join("scene.toml"), toml).unwrap();
    for (name, bytes) in files {
        let p = dir.path().join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    dir
}

/// Load `scene.toml` from a folder made by [`scene_dir`].
pub fn load(dir: &Path) -> tessera::Result<Scene> {
    load_scene(&dir.join("scene.toml"), &SceneOverrides::default())
}

/// Load a scene given as text (with files beside it), panicking on errors.
pub fn scene(toml: &str, files: &[(&str, &[u8])]) -> (tempfile::TempDir, Scene) {
    let dir = scene_dir(toml, files);
    let scene = load(dir.path()).unwrap_or_else(|e| panic!("scene failed to load: {e}"));
    (dir, scene)
}

/// Render the whole image on the current thread pool.
pub fn render_film(scene: &Scene) -> Film {
    render(scene, None, &[], &|_, _| {})
}

/// Mean and standard error of the mean of the red channel over all pixels, from the film's
/// per-pixel variance (independent pixels).
pub fn mean_and_error(film: &Film, spp: u32) -> (f64, f64) {
    let r = film.radiance();
    let v = film.variance();
    let n = (r.width * r.height) as f64;
    let mean = r.data.iter().step_by(3).map(|&x| x as f64).sum::<f64>() / n;
    let var_of_mean = v.data.iter().step_by(3).map(|&x| x as f64 / spp as f64).sum::<f64>() / (n * n);
    (mean, var_of_mean.sqrt())
}

/// Settings of a chi-square test over directions on the unit sphere, binned in
/// (z, phi), which is equal-area: the solid angle of a cell is dz dphi.
pub struct Chi2 {
    /// Bins along z = cos(theta) in [-1, 1].
    pub z_bins: usize,
    /// Bins along phi in [0, 2 pi).
    pub phi_bins: usize,
    /// Samples drawn.
    pub samples: usize,
    /// Gauss-Legendre nodes per cell side when integrating the density.
    pub nodes: usize,
    /// Cells whose expected count is below this are pooled into one (pbrt-v4: 5).
    pub min_expected: f64,
}

impl Default for Chi2 {
    fn default() -> Self {
        Chi2 { z_bins: 40, phi_bins: 80, samples: 400_000, nodes: 16, min_expected: 5.0 }
    }
}

/// Outcome of a chi-square test.
#[derive(Debug)]
pub struct Chi2Outcome {
    pub p_value: f64,
    pub statistic: f64,
    pub dof: usize,
    /// Samples that landed in a cell whose integrated density is zero.
    pub in_zero_cells: usize,
    /// Valid samples and the integral of the density over the sphere.
    pub valid: usize,
    pub integral: f64,
}

fn cell_of(w: Vec3, z_bins: usize, phi_bins: usize) -> usize {
    let z = ((w.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * z_bins as f32) as usize;
    let mut phi = w.y.atan2(w.x);
    if phi < 0.0 {
        phi += std::f32::consts::TAU;
    }
    let p = (phi / std::f32::consts::TAU * phi_bins as f32) as usize;
    z.min(z_bins - 1) * phi_bins + p.min(phi_bins - 1)
}

impl Chi2 {
    /// Draw samples with `sample(u1, u2)` (None: no direction) and compare their histogram with
    /// the density `pdf`, integrated over each cell.
    pub fn run(&self, seed: u64, sample: impl Fn(f32, Vec2) -> Option<Vec3>, pdf: impl Fn(Vec3) -> f32) -> Chi2Outcome {
        let cells = self.z_bins * self.phi_bins;
        let mut observed = vec![0usize; cells];
        let mut valid = 0;
        for i in 0..self.samples {
            let mut s = Sampler::new(seed, 0, i as u32);
            let u1 = s.next_1d();
            let u2 = s.next_2d();
            if let Some(w) = sample(u1, u2) {
                assert!((w.length() - 1.0).abs() < 1e-3, "sampled direction {w} is not unit length");
                observed[cell_of(w, self.z_bins, self.phi_bins)] += 1;
                valid += 1;
            }
        }
        let (x, wts) = tessera::math::gauss_legendre(self.nodes);
        let mut expected = vec![0.0f64; cells];
        let dz = 2.0 / self.z_bins as f64;
        let dphi = std::f64::consts::TAU / self.phi_bins as f64;
        for zi in 0..self.z_bins {
            for pi in 0..self.phi_bins {
                let mut integral = 0.0;
                for (a, wa) in x.iter().zip(&wts) {
                    let z = -1.0 + dz * (zi as f64 + 0.5 + 0.5 * a);
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    for (b, wb) in x.iter().zip(&wts) {
                        let phi = dphi * (pi as f64 + 0.5 + 0.5 * b);
                        let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                        integral += wa * wb * pdf(w) as f64;
                    }
                }
                expected[zi * self.phi_bins + pi] = integral * 0.25 * dz * dphi * self.samples as f64;
            }
        }
        let integral = expected.iter().sum::<f64>() / self.samples as f64;
        let in_zero_cells = observed.iter().zip(&expected).filter(|(_, e)| **e == 0.0).map(|(o, _)| *o).sum();
        // Pool the cells with small expected counts (their chi-square terms are unreliable).
        let (mut stat, mut dof) = (0.0, 0usize);
        let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
        for (o, e) in observed.iter().zip(&expected) {
            if *e < self.min_expected {
                pooled_o += *o as f64;
                pooled_e += e;
            } else {
                stat += (*o as f64 - e).powi(2) / e;
                dof += 1;
            }
        }
        if pooled_e >= self.min_expected {
            stat += (pooled_o - pooled_e).powi(2) / pooled_e;
            dof += 1;
        } else if pooled_o > 0.0 {
            // A few stray samples where almost nothing is expected.
            stat += (pooled_o - pooled_e).powi(2) / pooled_e.max(1.0);
            dof += 1;
        }
        let dof = dof.saturating_sub(1).max(1);
        use statrs::distribution::{ChiSquared, ContinuousCDF};
        let p_value = ChiSquared::new(dof as f64).unwrap().sf(stat);
        Chi2Outcome { p_value, statistic: stat, dof, in_zero_cells, valid, integral }
    }
}

/// Per-test significance for `tests` tests sharing an overall level of 0.01 (Sidak).
pub fn sidak(tests: usize) -> f64 {
    1.0 - (1.0f64 - 0.01).powf(1.0 / tests as f64)
}

/// A unit direction from spherical angles in degrees (theta from +z).
pub fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Integrate `f` over the unit sphere with `n` x 2n Gauss-Legendre cells in (z, phi).
pub fn integrate_sphere(n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    let (x, w) = tessera::math::gauss_legendre(4);
    let dz = 2.0 / n as f64;
    let dphi = std::f64::consts::PI / n as f64;
    let mut sum = 0.0;
    for zi in 0..n {
        for pi in 0..2 * n {
            for (a, wa) in x.iter().zip(&w) {
                let z = -1.0 + dz * (zi as f64 + 0.5 + 0.5 * a);
                let r = (1.0 - z * z).max(0.0).sqrt();
                for (b, wb) in x.iter().zip(&w) {
                    let phi = dphi * (pi as f64 + 0.5 + 0.5 * b);
                    let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    sum += wa * wb * f(d);
                }
            }
        }
    }
    sum * 0.25 * dz * dphi
}

/// `render_with(filter, spp)` renders one scene with a texture filter (`none`, `trilinear`,
/// `ewa`): at 8 spp the filtered renders must be closer than the unfiltered one to the
/// unfiltered 2048-spp reference (by 20%), approach it at 1024 spp (3x closer than at 8), and
/// keep its mean within 1%.
pub fn assert_filtered_renders_converge(filters: &[&str], render_with: impl Fn(&str, u32) -> tessera::image::Bitmap) {
    use tessera::image::Bitmap;
    let rmse = |a: &Bitmap, b: &Bitmap| {
        (a.data.iter().zip(&b.data).map(|(x, y)| ((x - y) as f64).powi(2)).sum::<f64>() / a.data.len() as f64).sqrt()
    };
    let mean = |a: &Bitmap| a.data.iter().map(|&x| x as f64).sum::<f64>() / a.data.len() as f64;
    let reference = render_with("none", 2048);
    let unfiltered = render_with("none", 8);
    let e_unfiltered = rmse(&unfiltered, &reference);
    for &filter in filters {
        let low = render_with(filter, 8);
        let high = render_with(filter, 1024);
        let (e_low, e_high) = (rmse(&low, &reference), rmse(&high, &reference));
        assert!(e_low < 0.8 * e_unfiltered, "{filter}: rmse {e_low} at 8 spp vs unfiltered {e_unfiltered}");
        assert!(e_high < 0.3 * e_low, "{filter}: rmse {e_high} at 1024 spp does not approach the reference");
        assert!((mean(&low) - mean(&reference)).abs() < 0.01 * mean(&reference), "{filter}: mean drifts");
    }
}

/// A small glTF document exercising what the importer reads: indexed positions, normals,
/// UVs and tangents, a two-level node hierarchy, a camera, and a material with a base-colour
/// texture whose PNG lies in a buffer view. Returns (JSON, binary buffer); the JSON's buffer
/// ends in the placeholder `BUFFER_URI`, for a `, "uri": ...` or nothing (a GLB).
pub fn small_gltf() -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    let floats = |bin: &mut Vec<u8>, values: &[f32]| values.iter().for_each(|v| bin.extend(v.to_le_bytes()));
    floats(&mut bin, &[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]); // 0..48 positions
    floats(&mut bin, &[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.]); // 48..96 normals
    floats(&mut bin, &[0., 1., 1., 1., 1., 0., 0., 0.]); // 96..128 uvs
    floats(&mut bin, &[1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1.]); // 128..192 tangents
    [0u16, 1, 2, 0, 2, 3].iter().for_each(|i| bin.extend(i.to_le_bytes())); // 192..204 indices
    bin.extend([0, 0]);
    let png_start = bin.len();
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbImage::from_fn(4, 4, |x, y| image::Rgb([x as u8 * 60, y as u8 * 60, 128]))
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    bin.extend(png.into_inner());
    let png_length = bin.len() - png_start;
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 2]}}],
"nodes": [{{"children": [1], "translation": [0, 0, -1]}}, {{"mesh": 0, "scale": [2, 2, 2]}},
 {{"camera": 0, "translation": [0, 0, 3]}}],
"cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.7, "znear": 0.01}}}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, "indices": 4, "material": 0}}]}}],
"materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicFactor": 0.2, "roughnessFactor": 0.5}}}}],
"textures": [{{"source": 0}}], "images": [{{"bufferView": 5, "mimeType": "image/png"}}],
"accessors": [
 {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
 {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
 {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
 {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
 {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}}],
"bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
 {{"buffer": 0, "byteOffset": 96, "byteLength": 32}}, {{"buffer": 0, "byteOffset": 128, "byteLength": 64}},
 {{"buffer": 0, "byteOffset": 192, "byteLength": 12}}, {{"buffer": 0, "byteOffset": {png_start}, "byteLength": {png_length}}}],
"buffers": [{{"byteLength": {}BUFFER_URI}}]}}"#,
        bin.len()
    );
    (json, bin)
}

/// The glTF document as one GLB file.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.replace("BUFFER_URI", "").into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}
