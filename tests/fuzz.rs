//! Seeded mutation fuzzing of everything that reads a file: scene loading (the shipped scenes),
//! OBJ, glTF and GLB meshes, PNG, JPEG, Radiance HDR and OpenEXR images, `tessera deform`'s
//! mesh reading and maps, `tessera tiles map`'s quad meshes (mapping, subdivision, the OBJ it
//! writes, a `quad_tiles` texture on it), PUPs points files (CSV, JSON) as `pups` textures, then
//! a tiny render (every AOV and the variance) and a bake of each
//! texture of what loaded. The properties checked, for every case:
//! - no panic (a panic inside a third-party parser that tessera catches is an error, which is
//!   fine; one that escapes fails the case),
//! - no case runs longer than [`CASE_TIME`] (a hang fails the run at once),
//! - no allocation takes the process past [`MEMORY_BUDGET`] (a counting allocator refuses it
//!   and names the case; the process then aborts),
//! - every image a loaded scene produces is finite.
//!
//! `cargo test --test fuzz` runs [`DEFAULT_CASES`] cases from seed 1. A longer run, in release
//! mode: `TESSERA_FUZZ_CASES=100000 TESSERA_FUZZ_SEED=7 cargo test --release --test fuzz -- --nocapture`.
//! A failing case's input is written to `target/fuzz-failures/`, named by seed and case, to be
//! turned into a regression test in `tests/bad_input.rs`.

mod common;

use common::{glb, small_gltf};
use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};
use tessera::deform::{Orientation, Smoothing, deformation_maps};
use tessera::image::{Aov, Bitmap, ColorSpace};
use tessera::integrator::{Crop, render};
use tessera::scene::{SceneOverrides, load_scene_str, load_surface};
use tessera::texture::{BakeFootprint, bake};

/// Cases of a `cargo test` run.
const DEFAULT_CASES: usize = 2500;
/// Longest time one case may take (loading, deform, render and bakes of a few-kilobyte input).
const CASE_TIME: Duration = Duration::from_secs(20);
/// Most memory the test process may hold at once: above what every limit of docs/limits.md
/// allows one item (about 3 GiB), far below what an unchecked header claims.
const MEMORY_BUDGET: usize = 5 << 30;

/// The global allocator of this test binary: the system's, counting live bytes and refusing
/// an allocation past [`MEMORY_BUDGET`] (which aborts the process) after naming the case.
struct BudgetAllocator;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static CURRENT_CASE: AtomicUsize = AtomicUsize::new(usize::MAX);
/// Per kind of seed: cases run, and cases whose mutated input still loaded as a scene and was
/// rendered (the fuzzer's depth).
static CASES: [AtomicUsize; 8] = [const { AtomicUsize::new(0) }; 8];
static RENDERED: [AtomicUsize; 8] = [const { AtomicUsize::new(0) }; 8];

#[global_allocator]
static ALLOCATOR: BudgetAllocator = BudgetAllocator;

// SAFETY: every method forwards to `System` with the same arguments; the counter only observes.
unsafe impl GlobalAlloc for BudgetAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as is.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !reserve(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as is.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: forwarded as is.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > layout.size() && !reserve(new_size - layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded as is.
        let out = unsafe { System.realloc(ptr, layout, new_size) };
        if new_size < layout.size() {
            LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        out
    }
}

/// Count `bytes` more as live, or say which case went over the budget and refuse.
fn reserve(bytes: usize) -> bool {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    if live <= MEMORY_BUDGET {
        return true;
    }
    LIVE.fetch_sub(bytes, Ordering::Relaxed);
    use std::io::Write;
    // Formatting integers to stderr allocates nothing.
    let _ = writeln!(
        std::io::stderr(),
        "fuzz: case {} asked for {bytes} bytes with {live} live, over the budget of {MEMORY_BUDGET}",
        CURRENT_CASE.load(Ordering::Relaxed)
    );
    false
}

/// SplitMix64: the cases' only source of randomness.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Numbers that break parsers and arithmetic.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "0.5",
    "-0.5",
    "1e-30",
    "1e30",
    "-1e30",
    "1e38",
    "3.5e38",
    "nan",
    "inf",
    "-inf",
    "255",
    "256",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "-2147483648",
    "9007199254740993",
    "1e300",
    "100000",
    "12",
    "7",
];

/// 32-bit values for binary fields (lengths, counts, offsets).
const WORDS: &[u32] =
    &[0, 1, 2, 3, 4, 0x7f, 0x80, 0xff, 0x100, 0xffff, 0x10000, 0x7fff_ffff, 0x8000_0000, 0xffff_ffff, 100_000];

/// Mutate binary data: bit flips, interesting bytes and words, chunks inserted, deleted,
/// duplicated, truncation.
fn mutate_bytes(rng: &mut Rng, data: &mut Vec<u8>) {
    for _ in 0..1 + rng.below(4) {
        let len = data.len();
        match rng.below(8) {
            0 if len > 0 => {
                let i = rng.below(len);
                data[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                data[i] = *rng.pick(&[0, 1, 0x7f, 0x80, 0xff]);
            }
            2 if len >= 4 => {
                // Headers hold their sizes near the start: favour it.
                let i = if rng.below(2) == 0 { rng.below(len.min(64) - 3) } else { rng.below(len - 3) };
                data[i..i + 4].copy_from_slice(&rng.pick(WORDS).to_le_bytes());
            }
            3 if len > 0 => {
                let i = rng.below(len);
                let n = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                data.splice(i..i, bytes);
            }
            4 if len > 1 => {
                let i = rng.below(len);
                let n = 1 + rng.below((len - i).min(64));
                data.drain(i..i + n);
            }
            5 if len > 1 => {
                let i = rng.below(len);
                let n = 1 + rng.below((len - i).min(64));
                let copy = data[i..i + n].to_vec();
                let at = rng.below(len);
                data.splice(at..at, copy);
            }
            6 if len > 1 => data.truncate(rng.below(len)),
            _ if len > 0 => {
                let i = rng.below(len);
                data[i] = rng.next() as u8;
            }
            _ => data.push(rng.next() as u8),
        }
    }
}

/// Mutate text: numbers replaced by hostile ones, lines deleted, duplicated, swapped, strings
/// exchanged; sometimes a byte-level mutation.
fn mutate_text(rng: &mut Rng, text: &str) -> Vec<u8> {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for _ in 0..1 + rng.below(3) {
        if lines.is_empty() {
            break;
        }
        let i = rng.below(lines.len());
        match rng.below(7) {
            0..=2 => lines[i] = replace_number(rng, &lines[i]),
            3 => {
                lines.remove(i);
            }
            4 => {
                let copy = lines[rng.below(lines.len())].clone();
                lines.insert(i, copy);
            }
            5 => {
                let j = rng.below(lines.len());
                lines.swap(i, j);
            }
            _ => {
                let quoted: Vec<&str> = text.split('"').skip(1).step_by(2).collect();
                if let (Some(start), false) = (lines[i].find('"'), quoted.is_empty())
                    && let Some(end) = lines[i][start + 1..].find('"')
                {
                    let with = (*rng.pick(&quoted)).to_string();
                    lines[i].replace_range(start + 1..start + 1 + end, &with);
                }
            }
        }
    }
    let mut bytes = lines.join("\n").into_bytes();
    bytes.push(b'\n');
    if rng.below(8) == 0 {
        mutate_bytes(rng, &mut bytes);
    }
    bytes
}

/// Mutate a JSON document (glTF) mostly where it stays valid JSON, so that the mutation
/// reaches the importer's checks rather than the JSON parser: one to three numbers replaced
/// by hostile ones that JSON allows; otherwise any text mutation.
fn mutate_json(rng: &mut Rng, json: &str) -> Vec<u8> {
    if rng.below(4) == 0 {
        return mutate_text(rng, json);
    }
    let mut text = json.to_string();
    for _ in 0..1 + rng.below(3) {
        text = replace_number_from(rng, &text, &json_numbers());
    }
    text.into_bytes()
}

/// [`NUMBERS`] that JSON can spell, and the glTF component types (valid and not for each use).
fn json_numbers() -> Vec<&'static str> {
    let spelled = NUMBERS.iter().copied().filter(|n| n.parse::<f64>().is_ok_and(f64::is_finite));
    spelled.chain(["5120", "5121", "5122", "5123", "5125", "5126"]).collect()
}

/// `line` with one of its numbers replaced by one of [`NUMBERS`].
fn replace_number(rng: &mut Rng, line: &str) -> String {
    replace_number_from(rng, line, NUMBERS)
}

/// `line` with one of its numbers replaced by one of `numbers`.
fn replace_number_from(rng: &mut Rng, line: &str, numbers: &[&str]) -> String {
    let bytes = line.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        // A number starts after punctuation or a space, not inside a word or base64 text.
        let after_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || b"+/_".contains(&bytes[i - 1]));
        if bytes[i].is_ascii_digit() && !after_word {
            let mut start = i;
            if start > 0 && bytes[start - 1] == b'-' {
                start -= 1;
            }
            while i < bytes.len() && (bytes[i].is_ascii_digit() || b".eE+-".contains(&bytes[i])) {
                i += 1;
            }
            if i >= bytes.len() || !bytes[i].is_ascii_alphanumeric() {
                spans.push((start, i));
            }
        } else {
            i += 1;
        }
    }
    if spans.is_empty() {
        return line.to_string();
    }
    let (start, end) = *rng.pick(&spans);
    format!("{}{}{}", &line[..start], rng.pick(numbers), &line[end..])
}

/// A GLB with its JSON chunk mutated as text and the lengths rebuilt, so that the mutation
/// reaches the document rather than the container; or its binary chunk mutated.
fn mutate_glb(rng: &mut Rng, glb: &[u8]) -> Vec<u8> {
    let Some((json, bin)) = glb_chunks(glb) else {
        let mut out = glb.to_vec();
        mutate_bytes(rng, &mut out);
        return out;
    };
    let (mut json, mut bin) = (json.to_vec(), bin.map(<[u8]>::to_vec));
    match (rng.below(4), bin.as_mut()) {
        (0, Some(bin)) => mutate_bytes(rng, bin),
        (1, _) => mutate_bytes(rng, &mut json),
        _ => json = mutate_json(rng, &String::from_utf8_lossy(&json)),
    }
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut out = Vec::new();
    let total = 12 + 8 + json.len() + bin.as_ref().map_or(0, |b| 8 + b.len().next_multiple_of(4));
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    if let Some(mut bin) = bin {
        bin.resize(bin.len().next_multiple_of(4), 0);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
    }
    if rng.below(16) == 0 {
        mutate_bytes(rng, &mut out);
    }
    out
}

/// The JSON chunk and the binary chunk (if any) of a GLB file.
fn glb_chunks(glb: &[u8]) -> Option<(&[u8], Option<&[u8]>)> {
    let word = |at: usize| Some(u32::from_le_bytes(glb.get(at..at + 4)?.try_into().ok()?) as usize);
    let json_end = 20 + word(12)?;
    let json = glb.get(20..json_end)?;
    let bin = word(json_end).and_then(|len| glb.get(json_end + 8..json_end + 8 + len));
    Some((json, bin))
}

/// What a seed file is, which decides how it is mutated and read.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// A scene file, loaded from its own folder so that its references resolve.
    Scene,
    Obj,
    Gltf,
    Glb,
    Image,
    /// A cuts file of `tessera deform`, read by a tiling-and-blending texture with the lat-long
    /// sphere's F map.
    Cuts,
    /// A quad mesh for `tessera tiles map`: mapped, subdivided, written, and rendered with a
    /// `quad_tiles` texture.
    QuadObj,
    /// A PUPs points file (CSV or JSON), read by a `pups` texture.
    PupsPoints,
}

/// An input to mutate.
struct Seed {
    kind: Kind,
    /// The file name it is written under (its extension matters), or the scene's own path.
    name: PathBuf,
    bytes: Vec<u8>,
}

/// A small image file of the given format.
fn small_image(format: image::ImageFormat) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let image = image::Rgb32FImage::from_fn(6, 5, |x, y| image::Rgb([x as f32 * 0.2, y as f32 * 0.25, 0.5]));
    match format {
        image::ImageFormat::Hdr => image.write_to(&mut out, format).unwrap(),
        _ => image::DynamicImage::ImageRgb32F(image).to_rgb8().write_to(&mut out, format).unwrap(),
    }
    out.into_inner()
}

/// Every seed: the shipped scenes, the shipped meshes and some images, and small generated
/// files of each format.
fn seeds() -> Vec<Seed> {
    let root = common::repo();
    let mut seeds = Vec::new();
    for folder in ["scenes", "scenes/golden"] {
        let mut scenes: Vec<PathBuf> = std::fs::read_dir(root.join(folder))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        scenes.sort();
        for path in scenes {
            seeds.push(Seed { kind: Kind::Scene, bytes: std::fs::read(&path).unwrap(), name: path });
        }
    }
    let file = |kind, name: &str, bytes: Vec<u8>| Seed { kind, name: PathBuf::from(name), bytes };
    seeds.push(file(Kind::Obj, "smiley.obj", std::fs::read(root.join("scenes/meshes/smiley.obj")).unwrap()));
    seeds.push(file(
        Kind::Obj,
        "quad.obj",
        b"o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
          f 1/1/1 2/2/1 3/3/1 4/4/1\no tri\nv 0 0 1\nv 1 0 1\nv 0 1 1\nvt 0 0\nvt 1 0\nvt 0 1\nf 5/5 6/6 7/7\n"
            .to_vec(),
    ));
    seeds.push(file(Kind::Glb, "spot.glb", std::fs::read(root.join("scenes/meshes/spot.glb")).unwrap()));
    let (json, bin) = small_gltf();
    seeds.push(file(Kind::Glb, "small.glb", glb(&json, &bin)));
    let data_uri = format!(r#", "uri": "data:application/octet-stream;base64,{}""#, base64(&bin));
    seeds.push(file(Kind::Gltf, "small.gltf", json.replace("BUFFER_URI", &data_uri).into_bytes()));
    for (name, path) in [("asym.png", "scenes/golden/textures/asym.png"), ("bark.jpg", "scenes/textures/bark.jpg")] {
        seeds.push(file(Kind::Image, name, std::fs::read(root.join(path)).unwrap()));
    }
    seeds.push(file(Kind::Image, "small.png", small_image(image::ImageFormat::Png)));
    seeds.push(file(Kind::Image, "small.jpg", small_image(image::ImageFormat::Jpeg)));
    seeds.push(file(Kind::Image, "small.hdr", small_image(image::ImageFormat::Hdr)));
    let dir = tempfile::tempdir().unwrap();
    let exr = dir.path().join("small.exr");
    let planes = ["A", "B", "G", "R"].map(|c| (c.to_string(), (0..30).map(|i| i as f32 * 0.03).collect()));
    tessera::image::write_exr(&exr, 6, 5, planes.into()).unwrap();
    seeds.push(file(Kind::Image, "small.exr", std::fs::read(&exr).unwrap()));
    seeds.push(file(Kind::Cuts, "cuts.json", std::fs::read(root.join("scenes/maps/smiley/cuts.json")).unwrap()));
    seeds.push(file(Kind::QuadObj, "cube.obj", std::fs::read(root.join("scenes/meshes/cube_quads.obj")).unwrap()));
    seeds.push(file(
        Kind::QuadObj,
        "strip.obj",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\ng a\nf 1 2 5 4\ng b\nf 2 3 6 5\n".to_vec(),
    ));
    seeds.push(file(
        Kind::PupsPoints,
        "points.csv",
        b"x,y,r,g,b,label,ox,oy,oz\n0.1,0.2,1,0,0,0,1,0,0\n0.9,0.1,0,1,0,1,0,1,0\n0.5,0.8,0,0,1,2,0,0,1\n0.4,0.4,1,1,0,0,1,1,0\n"
            .to_vec(),
    ));
    seeds.push(file(
        Kind::PupsPoints,
        "points.json",
        br#"[{"x":0.1,"y":0.2,"value":0.3},{"x":0.9,"y":0.1,"colour":[1,0,0],"label":4},{"x":0.5,"y":0.8,"orientation":[1,0,0]},{"x":0.3,"y":0.6}]"#
            .to_vec(),
    ));
    seeds
}

/// Standard base64 (for the data URI of the glTF seed).
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (i, b)| n | (*b as u32) << (16 - 8 * i));
        for k in 0..4 {
            out.push(if k <= chunk.len() { ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// A scene that reads `file` as what its kind is.
fn scene_using(kind: Kind, file: &str) -> String {
    let head = "[render]\nwidth = 16\nheight = 12\nspp = 2\nmax_depth = 6\n\
                [camera]\nfov = 50\neye = [0.5, 0.5, 3]\ntarget = [0.5, 0.5, 0]\n";
    match kind {
        Kind::Obj => format!("{head}[[shapes]]\ntype = \"obj\"\nfilename = \"{file}\"\nemission = 1\n"),
        Kind::PupsPoints => format!(
            "{head}[textures.p]\ntype = \"pups\"\npoints_file = \"{file}\"\ntileable = true\nlabels = true\n\
             [materials.m]\ntype = \"diffuse\"\nreflectance = \"p\"\n\
             [[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n\
             [environment]\ntype = \"constant\"\nradiance = 1\n"
        ),
        Kind::QuadObj => format!(
            "{head}[textures.t]\ntype = \"quad_tiles\"\nfilename = \"{}\"\nfilter = \"ewa\"\n\
             [materials.m]\ntype = \"diffuse\"\nreflectance = \"t\"\n\
             [[shapes]]\ntype = \"obj\"\nfilename = \"mapped.obj\"\nmaterial = \"m\"\n\
             [environment]\ntype = \"constant\"\nradiance = 1\n",
            common::repo().join("scenes/quad_tiles/rock2_tiles.png").display()
        ),
        Kind::Cuts => {
            let root = common::repo().join("scenes");
            let (f_map, mesh) = (root.join("maps/smiley/f_map.exr"), root.join("meshes/smiley.obj"));
            format!(
                "{head}[textures.e]\ntype = \"image\"\nfilename = \"{}\"\n\
                 [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"e\"\ntile_size = 0.1\n\
                 deformation = [{{ type = \"map\", filename = \"{}\" }}]\ncuts = \"{file}\"\n\
                 [materials.m]\ntype = \"diffuse\"\nreflectance = \"tb\"\n\
                 [[shapes]]\ntype = \"obj\"\nfilename = \"{}\"\nmaterial = \"m\"\n\
                 [environment]\ntype = \"constant\"\nradiance = 1\n",
                root.join("textures/brushed.png").display(),
                f_map.display(),
                mesh.display()
            )
        }
        Kind::Gltf | Kind::Glb => format!(
            "{head}[[shapes]]\ntype = \"gltf\"\nfilename = \"{file}\"\n[environment]\ntype = \"constant\"\nradiance = 1\n"
        ),
        _ => format!(
            "{head}[textures.t]\ntype = \"image\"\nfilename = \"{file}\"\nfilter = \"ewa\"\n\
             [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"t\"\nblend = \"histogram_preserving\"\n\
             [materials.m]\ntype = \"diffuse\"\nreflectance = \"tb\"\n\
             [[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\n\
             [environment]\ntype = \"envmap\"\nfilename = \"{file}\"\n"
        ),
    }
}

/// Load `text` as a scene at `path`; if it loads, render its first 8 x 8 pixels at 1 spp with
/// every AOV, bake each texture at 8 x 8 (every value must be finite) and export it for
/// Mitsuba into `out`.
fn load_and_render(text: &str, path: &Path, kind: Kind, out: &Path) -> Result<(), String> {
    let overrides = SceneOverrides { spp: Some(1), ..Default::default() };
    let Ok(scene) = load_scene_str(text, path, &overrides) else { return Ok(()) };
    RENDERED[kind as usize].fetch_add(1, Ordering::Relaxed);
    let s = scene.settings;
    let crop = Crop { x0: 0, y0: 0, x1: s.width.min(8), y1: s.height.min(8) };
    let aovs = [Aov::Albedo, Aov::Normal, Aov::Uv, Aov::Footprint];
    let film = render(&scene, Some(crop), &aovs, &|_, _| {});
    let mut images: Vec<(String, Bitmap)> =
        vec![("radiance".into(), film.radiance()), ("variance".into(), film.variance())];
    images.extend(aovs.iter().map(|a| (format!("{a:?}"), film.aov(*a).unwrap())));
    images.extend(
        scene
            .textures
            .iter()
            .enumerate()
            .map(|(i, t)| (format!("bake of texture {i}"), bake(t, 8, BakeFootprint::Texel))),
    );
    // The Mitsuba export reads every part of the scene too (a failure is fine, a panic is not).
    let _ = tessera::scene::export_mitsuba(&scene, &out.join("export"), 8);
    match images.iter().find(|(_, b)| b.non_finite_count() > 0) {
        Some((name, b)) => Err(format!("{} non-finite values in the {name}", b.non_finite_count())),
        None => Ok(()),
    }
}

/// Run one case: mutate `seed` and read the result every way tessera reads such a file.
fn run_case(seed: &Seed, rng: &mut Rng, dir: &Path) -> Result<(), String> {
    CASES[seed.kind as usize].fetch_add(1, Ordering::Relaxed);
    let bytes = match seed.kind {
        Kind::Glb => mutate_glb(rng, &seed.bytes),
        Kind::Gltf | Kind::Cuts => mutate_json(rng, &String::from_utf8_lossy(&seed.bytes)),
        Kind::PupsPoints if seed.name.extension().is_some_and(|e| e == "json") => {
            mutate_json(rng, &String::from_utf8_lossy(&seed.bytes))
        }
        Kind::PupsPoints => mutate_text(rng, &String::from_utf8_lossy(&seed.bytes)),
        Kind::Scene | Kind::Obj | Kind::QuadObj => mutate_text(rng, &String::from_utf8_lossy(&seed.bytes)),
        Kind::Image => {
            let mut b = seed.bytes.clone();
            mutate_bytes(rng, &mut b);
            b
        }
    };
    if seed.kind == Kind::Scene {
        // Loaded from the scene's own folder, so that its meshes and textures resolve.
        let text = String::from_utf8_lossy(&bytes);
        std::fs::write(dir.join("input.toml"), text.as_bytes()).unwrap();
        return load_and_render(&text, &seed.name, seed.kind, dir);
    }
    let name = seed.name.to_string_lossy();
    let file = dir.join(&*name);
    std::fs::write(&file, &bytes).unwrap();
    if matches!(seed.kind, Kind::Obj | Kind::Gltf | Kind::Glb) {
        if let Ok((mesh, _)) = load_surface(&file)
            && mesh.uvs.is_some()
        {
            let _ = deformation_maps(&mesh, &Orientation::Uv, Smoothing::Vertices(1), 32, 0.25);
        }
    } else if seed.kind == Kind::QuadObj {
        let _ = std::fs::remove_file(dir.join("mapped.obj"));
        if let Ok(mut mesh) = tessera::geometry::load_quad_obj(&file)
            && let Ok((topology, _)) = mesh.topology()
        {
            let layout = tessera::tiles::TileLayout::new(1, 16).unwrap();
            let types = tessera::tiles::assign_boundaries(&topology, 1, 0);
            mesh.uvs =
                Some(tessera::tiles::texture_coordinates(&layout, &tessera::tiles::assign_tiles(&topology, &types)));
            if mesh.quads.len() < 10_000 {
                mesh = tessera::geometry::catmull_clark(&mesh, &topology);
            }
            mesh.write_obj(&dir.join("mapped.obj"), "tiles.png", Some(&mesh.vertex_normals()))
                .map_err(|e| format!("writing the mapped mesh: {e}"))?;
        }
    } else if seed.kind == Kind::PupsPoints {
        if let Ok(points) = tessera::pups::read_points(&file) {
            let _ = tessera::pups::PupsTexture::from_points(points, false, 1.0, 0.5, false);
        }
    } else if seed.kind == Kind::Cuts {
        let _ = tessera::texture::tiling_blending::cuts_from_json(&String::from_utf8_lossy(&bytes));
    } else {
        let _ = tessera::image::read_bitmap_raw(&file, ColorSpace::Srgb);
    }
    load_and_render(&scene_using(seed.kind, &name), &dir.join("scene.toml"), seed.kind, dir)
}

#[test]
fn fuzz_loaders_with_mutated_inputs() {
    let cases: usize = std::env::var("TESSERA_FUZZ_CASES").map_or(DEFAULT_CASES, |v| v.parse().expect("a case count"));
    let seed: u64 = std::env::var("TESSERA_FUZZ_SEED").map_or(1, |v| v.parse().expect("a seed"));
    let seeds = Arc::new(seeds());
    let dir = tempfile::tempdir().unwrap();
    // The case running now and its seed input, for the message when it hangs.
    let current = Arc::new(Mutex::new((0, 0)));
    let (tx, rx) = mpsc::channel();
    let worker = {
        let (seeds, current, dir) = (seeds.clone(), current.clone(), dir.path().to_path_buf());
        std::thread::spawn(move || {
            for case in 0..cases {
                let mut rng = Rng(seed.wrapping_mul(0x2545_f491_4f6c_dd1d) ^ case as u64);
                let index = rng.below(seeds.len());
                let input = &seeds[index];
                *current.lock().unwrap() = (case, index);
                CURRENT_CASE.store(case, Ordering::Relaxed);
                let outcome =
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run_case(input, &mut rng, &dir)));
                let failure = match outcome {
                    Ok(Ok(())) => None,
                    Ok(Err(msg)) => Some(msg),
                    Err(panic) => Some(format!(
                        "panic: {}",
                        panic
                            .downcast_ref::<String>()
                            .cloned()
                            .or(panic.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_default()
                    )),
                };
                if failure.is_some() {
                    keep_failure(&dir, input, seed, case);
                }
                tx.send((case, failure)).unwrap();
            }
        })
    };
    let start = Instant::now();
    let mut failures = Vec::new();
    for _ in 0..cases {
        match rx.recv_timeout(CASE_TIME) {
            Ok((case, Some(msg))) => failures.push(format!("case {case}: {msg}")),
            Ok(_) => {}
            Err(_) => {
                let (case, index) = *current.lock().unwrap();
                let input = &seeds[index];
                let kept = keep_failure(dir.path(), input, seed, case);
                panic!(
                    "case {case} (seed {seed}, mutating {}) ran past {CASE_TIME:?}: {}",
                    input.name.display(),
                    kept.display()
                );
            }
        }
    }
    worker.join().unwrap();
    let per_kind: Vec<String> = ["scene", "OBJ", "glTF", "GLB", "image", "cuts", "quad OBJ", "PUPs points"]
        .iter()
        .enumerate()
        .map(|(k, name)| format!("{name} {}/{}", RENDERED[k].load(Ordering::Relaxed), CASES[k].load(Ordering::Relaxed)))
        .collect();
    println!(
        "fuzz: {cases} cases from seed {seed} in {:.1} s, {} failures; loaded and rendered per seed kind: {}",
        start.elapsed().as_secs_f64(),
        failures.len(),
        per_kind.join(", ")
    );
    assert!(
        failures.is_empty(),
        "{} failing cases (inputs in target/fuzz-failures):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Copy a failing case's input to `target/fuzz-failures/seed-S-case-N-NAME`.
fn keep_failure(dir: &Path, input: &Seed, seed: u64, case: usize) -> PathBuf {
    let out = common::repo().join("target/fuzz-failures");
    let _ = std::fs::create_dir_all(&out);
    let name =
        if input.kind == Kind::Scene { "input.toml".to_string() } else { input.name.to_string_lossy().into_owned() };
    let kept = out.join(format!("seed-{seed}-case-{case}-{name}"));
    let _ = std::fs::copy(dir.join(&name), &kept);
    kept
}
