//! Command-line interface: argument parsing (clap) and progress display (indicatif). The
//! library does the work and reports progress through a callback.

mod bench;
mod deform;
mod gpu;
mod pups;
mod regress;
mod tiles;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use tessera::error::{Error, Result};
use tessera::image::{Aov, Bitmap, ColorSpace, OutputFormat, read_bitmap, write_image};
use tessera::integrator::Crop;
use tessera::limits;
use tessera::scene::{Scene, SceneOverrides, load_scene};
use tessera::texture::{BakeFootprint, bake};

/// tessera: a reference path tracer for procedural surface textures.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (EXR, PFM, HDR: linear float; PNG: 8-bit sRGB).
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output image, .exr or .png (default: the scene's name with .exr, in the current folder).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Samples per pixel (replaces the scene's).
        #[arg(long)]
        spp: Option<u32>,
        /// Worker threads (default: all cores; at most 1024). The image does not depend on it.
        #[arg(long, value_parser = thread_count)]
        threads: Option<usize>,
        /// Sampler seed (replaces the scene's).
        #[arg(long)]
        seed: Option<u64>,
        /// Render only the pixels x0 <= x < x1, y0 <= y < y1; the image has the crop's size (an
        /// EXR keeps its place in the frame, for `tessera merge`).
        #[arg(long, value_name = "x0,y0,x1,y1")]
        crop: Option<String>,
        /// Auxiliary outputs to add to an EXR, comma separated.
        #[arg(long, value_delimiter = ',')]
        aov: Vec<Aov>,
        /// Add the per-pixel variance of one sample to an EXR (channels variance.R/G/B), as
        /// `tessera diff --variance` takes it.
        #[arg(long)]
        variance: bool,
        /// Replace a scene value before loading: KEY is a dotted path into the scene file
        /// (`camera.fov`, `render.width`, `shapes[0].filename`), VALUE a TOML value (text that is
        /// none is a string). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE", value_parser = key_value)]
        set: Vec<(String, String)>,
        /// Stop before the time runs out (seconds, from the start of rendering): as many whole
        /// samples per pixel as fit, the image written with its real count.
        #[arg(long, value_name = "SECONDS", value_parser = seconds)]
        time_limit: Option<std::time::Duration>,
        /// Write the image so far to the output every SECONDS (atomically), between passes,
        /// with its state (OUTPUT.state) for --resume. Without it, Ctrl-C and --time-limit
        /// still write the image and the state of the passes done (Ctrl-C: exit status 130).
        #[arg(long, value_name = "SECONDS", value_parser = seconds)]
        checkpoint: Option<std::time::Duration>,
        /// Continue the unfinished render whose state is OUTPUT.state (same scene, --set
        /// values, crop and AOVs; the sample count may grow): the image equals an uninterrupted
        /// render's bit for bit.
        #[arg(long)]
        resume: bool,
        /// PNG output: exposure in stops, applied to the linear radiance before the tone curve
        /// (EXR output keeps the linear radiance).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = stops)]
        exposure: f32,
        /// PNG output: the tone curve (clamp: values above 1 clip; aces: Narkowicz's fit of the
        /// ACES filmic curve, highlights roll off).
        #[arg(long, value_enum, default_value_t = tessera::image::ToneMap::Clamp)]
        tonemap: tessera::image::ToneMap,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Print what a scene contains: triangles, spheres, bounds, lights, memory.
    Info {
        /// Scene file (TOML).
        scene: PathBuf,
    },
    /// Compare a rendered image with a reference: relMSE, MAE, mean FLIP, and Mitsuba's per-pixel
    /// Z-test when the reference's variance is given. Exits 0 on pass, 1 on fail.
    Diff {
        /// The image under test (EXR).
        test: PathBuf,
        /// The reference image (EXR).
        reference: PathBuf,
        /// Per-pixel variance of one sample of the reference (EXR): enables the Z-test.
        #[arg(long, requires = "spp")]
        variance: Option<PathBuf>,
        /// Samples per pixel of the test image (for the Z-test).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        spp: Option<u32>,
        /// Fail when relMSE exceeds this.
        #[arg(long, value_parser = non_negative)]
        max_relmse: Option<f64>,
        /// Fail when the mean FLIP exceeds this.
        #[arg(long, value_parser = non_negative)]
        max_flip: Option<f64>,
        /// Write an error image (EXR): |test - reference| as RGB, the FLIP map, and with the Z-test
        /// the smallest p-value of each pixel.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Merge the EXR crops of one render (`render --crop`, each keeping its place in the frame)
    /// into the full image: every pixel from exactly one crop, bit for bit.
    Merge {
        /// The crops (EXR).
        #[arg(required = true)]
        crops: Vec<PathBuf>,
        /// The full image (EXR).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Run a regression suite (a TOML file of cases: a scene to render or a test image, a
    /// reference, criteria), or one shard of it; print each case's metrics and verdict, the
    /// worst first. Exits 0 when every case passes, 1 otherwise.
    Regress(regress::RegressArgs),
    /// Lay images out on a labelled grid (PNG or EXR), e.g. classical against deformed renders.
    Montage {
        /// The images, in reading order (EXR, PNG, JPEG, HDR).
        #[arg(required = true)]
        images: Vec<PathBuf>,
        /// Images per row.
        #[arg(long, visible_alias = "cols", default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=1024))]
        columns: u32,
        /// A caption per image, in order (default: the files' names without extension).
        #[arg(long = "label")]
        labels: Vec<String>,
        /// All the captions after one flag, in order (after the images: `--labels a b c`).
        #[arg(long = "labels", num_args = 1.., conflicts_with = "labels")]
        label_list: Vec<String>,
        /// Output image (.png or .exr).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// How visible the UV cuts are in a render made with `--aov uv,normal`: the radiance
    /// difference of neighbouring pixels across a cut over that of the steps beside them (about
    /// 1: the cut does not show).
    Seams {
        /// The render (EXR with the uv and normal AOVs).
        render: PathBuf,
        /// A jump of the texture coordinates between neighbouring pixels larger than this is a
        /// cut (UV units).
        #[arg(long, default_value_t = 0.05, value_parser = positive_uv_length)]
        jump: f32,
    },
    /// Write a scene as Mitsuba 3 XML (meshes as OBJ, textures baked to EXR) to render it there.
    ExportMitsuba {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder (created; scene.xml, meshes/ and textures/ go in it).
        #[arg(short, long)]
        output: PathBuf,
        /// Samples per pixel written into the exported scene (default: the scene's).
        #[arg(long)]
        spp: Option<u32>,
        /// Resolution at which procedural textures are baked over the UV square (at most 8192).
        #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=limits::MAX_BAKE_RES as i64))]
        bake_res: u32,
    },
    /// Translate a Mitsuba 3 XML scene into a tessera scene file, listing what was not
    /// translated exactly (on stderr and in the file's header).
    ImportMitsuba {
        /// Mitsuba scene (XML).
        scene: PathBuf,
        /// The scene file to write (TOML); its file names are relative to its folder.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Evaluate one texture of a scene over the UV square [0, 1]^2, with no light transport
    /// (EXR: linear RGBA; PNG: sRGB RGB). Row 0 is the top (v = 1).
    Bake {
        /// Scene file (TOML) that defines the texture.
        scene: PathBuf,
        /// Name of the texture (`[textures.NAME]`).
        #[arg(long)]
        texture: String,
        /// Image width and height in texels (at most 8192).
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=limits::MAX_BAKE_RES as i64))]
        res: u32,
        /// Output image, .exr or .png.
        #[arg(short, long)]
        output: PathBuf,
        /// Read 8-bit images as data (no sRGB decoding), as scalar parameters and normal maps do.
        #[arg(long)]
        data: bool,
        /// Footprint of each lookup: `texel` (one texel of the bake, as a GPU shader drawing the
        /// UV square sees it) or `point` (unfiltered).
        #[arg(long, default_value = "texel")]
        footprint: FootprintArg,
        /// Bake on the GPU with the WGSL port (feature `gpu`; tiling_blending textures).
        #[arg(long)]
        gpu: bool,
    },
    /// Compare the WGSL port's bake of a tiling_blending texture with the CPU's, texel by
    /// texel: per channel the largest and mean difference, the worst texels, an error image.
    /// Exits 0 when every difference is within the tolerance, 1 otherwise (feature `gpu`).
    GpuCheck(gpu::GpuCheckArgs),
    /// Draw a mesh scene's primary visibility with a tiling_blending texture on every surface,
    /// rasterised with the WGSL port in a fragment shader, beside tessera's lookups at
    /// pixel-centre camera rays with ray differentials; print their difference for screen-space
    /// derivatives (dpdx, coarse, fine) and for ray differentials in the shader. Exits 0 when
    /// the latter is within the tolerance, 1 otherwise (feature `gpu`).
    GpuView(gpu::GpuViewArgs),
    /// The WGSL port of tiling and blending (`shaders/`), for engines.
    Shader {
        #[command(subcommand)]
        command: gpu::ShaderCommand,
    },
    /// Derive the deformation field of a UV-mapped mesh (paper 000 Sec. 4) and its UV cuts:
    /// writes f_map.exr (F00, F01, F10, F11), charts.exr (each texel's UV chart), cuts.json (the
    /// cut curves the synthesis' cut bands follow) and pictures of |det F|, the orientation and
    /// the cut bands.
    Deform {
        #[command(flatten)]
        mesh: deform::MeshArgs,
        /// Output folder (created).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Print the figures of tiling and blending on a mesh: distortion and seams (classical
    /// against deformed, with and without cut bands), orientation error, fold-over.
    Analyze {
        #[command(flatten)]
        mesh: deform::MeshArgs,
        /// The exemplar image the seam metric synthesises.
        #[arg(long)]
        exemplar: PathBuf,
        /// Seed of the tiles' shifts.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Point pairs per cut edge for the seam metric.
        #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
        samples: u32,
        /// Print the figures as JSON (for scripts).
        #[arg(long)]
        json: bool,
    },
    /// Bake a partition-of-unity parametric texture (paper 002) from a named preset.
    Pups(pups::PupsArgs),
    /// Seamless tiled textures on quad meshes (paper 001): synthesise a tile image, map a mesh.
    Tiles {
        #[command(subcommand)]
        command: tiles::TilesCommand,
    },
    /// Measure ray casting (Mrays/s) and rendering (samples/s) throughput.
    Bench {
        /// Runs per figure (the median is printed; at most 1000).
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
        runs: u32,
        /// Worker threads for the parallel figures (default: 2, the size of the machines
        /// Mitsuba's reference figures were measured on; 0 = all cores; at most 1024).
        #[arg(long, default_value_t = 2, value_parser = thread_count)]
        threads: usize,
        /// Folder of the shipped scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Which figures to measure, comma separated (default: all).
        #[arg(long, value_delimiter = ',', default_values = ["rays", "render", "textures", "lanes", "deform", "tiles", "pups"])]
        only: Vec<bench::Suite>,
    },
}

/// Footprints of `tessera bake`.
#[derive(Clone, Copy, clap::ValueEnum)]
enum FootprintArg {
    Texel,
    Point,
}

impl From<FootprintArg> for BakeFootprint {
    fn from(footprint: FootprintArg) -> Self {
        match footprint {
            FootprintArg::Texel => BakeFootprint::Texel,
            FootprintArg::Point => BakeFootprint::Point,
        }
    }
}

/// Parse the command line and run it.
pub fn run() -> Result<ExitCode> {
    let command = Cli::parse().command;
    // The lanes' instruction set, forced with TESSERA_SIMD: a bad value stops here, not later
    // in a render that would quietly take another.
    tessera::simd::Isa::from_env().map_err(|e| tessera::Error::param("TESSERA_SIMD", e))?;
    match command {
        Command::Render {
            scene,
            output,
            spp,
            threads,
            seed,
            crop,
            aov,
            variance,
            set,
            time_limit,
            checkpoint,
            resume,
            exposure,
            tonemap,
            quiet,
        } => {
            let overrides = SceneOverrides { spp, seed, set: set.clone(), ..Default::default() };
            let output = output.unwrap_or_else(|| default_output(&scene));
            tessera::image::OutputFormat::from_path(&output)?;
            let text = tessera::files::read_bounded(&scene, limits::MAX_SCENE_FILE_BYTES, "a scene file")?;
            let scene = load(&scene, &overrides, quiet)?;
            let crop = crop.map(|c| parse_crop(&c, &scene)).transpose()?;
            // The state of an unfinished render belongs to this scene text, these values set and
            // these settings, whatever the sample count.
            let settings = tessera::scene::RenderSettings { spp: 0, ..scene.settings };
            let made_from = [text, format!("{set:?}{settings:?}").into_bytes()].concat();
            let fingerprint = tessera::integrator::fingerprint(&made_from);
            let display = (tonemap, exposure);
            let control = RenderControl { time_limit, checkpoint, variance, quiet, resume, fingerprint, display };
            render_to_file(&scene, &output, threads, crop, &aov, control)
        }
        Command::Info { scene } => {
            let scene = load(&scene, &SceneOverrides::default(), false)?;
            print_info(&scene);
            Ok(ExitCode::SUCCESS)
        }
        Command::Diff { test, reference, variance, spp, max_relmse, max_flip, output } => {
            diff(&test, &reference, variance.as_deref().zip(spp), max_relmse, max_flip, output.as_deref())
        }
        Command::Pups(args) => {
            pups::run(args)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Tiles { command } => {
            tiles::run(command)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Merge { crops, output } => {
            if OutputFormat::from_path(&output)? != OutputFormat::Exr {
                return Err(Error::param("--output", "the merged image is written as .exr"));
            }
            let parts = crops.iter().map(|p| tessera::image::read_exr_image(p)).collect::<Result<Vec<_>>>()?;
            let full = tessera::image::merge_crops(&parts).map_err(|msg| Error::param("merge", msg))?;
            tessera::image::write_exr(&output, full.width, full.height, full.channels)?;
            eprintln!("{} crops -> {} ({} x {})", crops.len(), output.display(), full.width, full.height);
            Ok(ExitCode::SUCCESS)
        }
        Command::Regress(args) => regress::run(&args),
        Command::Montage { images, columns, labels, label_list, output } => {
            montage(&images, columns as usize, if label_list.is_empty() { &labels } else { &label_list }, &output)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Seams { render, jump } => {
            let radiance = tessera::image::read_exr_channels(&render, &["R", "G", "B"])?;
            let uv = tessera::image::read_exr_channels(&render, Aov::Uv.channel_names())?;
            let normal = tessera::image::read_exr_channels(&render, Aov::Normal.channel_names())?;
            match tessera::image::seam_visibility(&radiance, &uv, &normal, jump) {
                Some(v) => println!(
                    "seam visibility {:.3}: |L_p - L_q| of neighbouring pixels across UV cuts ({} pairs) over that of \
                     the neighbouring steps on either side",
                    v.ratio, v.across
                ),
                None => println!("seam visibility: no neighbouring pixels across a UV cut (jump {jump}) in view"),
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::ExportMitsuba { scene, output, spp, bake_res } => {
            let scene = load(&scene, &SceneOverrides { spp, ..Default::default() }, false)?;
            let export = tessera::scene::export_mitsuba(&scene, &output, bake_res as usize)?;
            for w in &export.warnings {
                eprintln!("warning: {w}");
            }
            eprintln!("{}: wrote {} files to {}", scene.path.display(), export.files.len(), output.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::ImportMitsuba { scene, output } => {
            let out_dir = output.parent().map(Path::to_path_buf).unwrap_or_default();
            let import = tessera::scene::import_mitsuba(&scene, &out_dir)?;
            let text = import.to_toml(&scene);
            // The scene must load (its files found, its values valid) before it replaces a file.
            tessera::files::write_atomically(&output, |tmp| {
                std::fs::write(tmp, &text).map_err(|e| Error::io(tmp, e))?;
                tessera::scene::load_scene(tmp, &SceneOverrides::default()).map(drop)
            })?;
            for line in &import.untranslated {
                eprintln!("warning: not translated exactly: {line}");
            }
            eprintln!(
                "{}: wrote {} ({} items not translated exactly)",
                scene.display(),
                output.display(),
                import.untranslated.len()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Bake { scene, texture, res, output, data, footprint, gpu } => {
            tessera::image::OutputFormat::from_path(&output)?;
            let tex = tessera::scene::load_texture(&scene, &texture, !data)?;
            let footprint = footprint.into();
            let start = Instant::now();
            let (image, device) = if gpu {
                let (mut images, adapter) = gpu::bake_on_gpu(&tex, &texture, res, footprint, &[None])?;
                let image = images.pop().expect("one bake");
                (image, format!(" on {adapter}"))
            } else {
                (bake(&tex, res as usize, footprint), String::new())
            };
            let rgb = image.without_alpha();
            let mut alpha = Bitmap::new(image.width, image.height, 1);
            alpha.data = image.data.chunks_exact(4).map(|p| p[3]).collect();
            write_image(&output, &rgb, &[(&["A"], alpha)])?;
            eprintln!(
                "{}: baked texture '{texture}' at {res}x{res}{device} in {:.2} s to {}",
                scene.display(),
                start.elapsed().as_secs_f64(),
                output.display()
            );
            if let tessera::texture::Texture::TilingBlending(t) = &tex {
                let seed = t.synthesis.seed;
                let seeds: Vec<u64> = (0..4).map(|k| seed.wrapping_add(k)).collect();
                let figure = tessera::texture::tiling_blending::synthesis_lattice_visibility(
                    t,
                    tessera::deform::analysis::LATTICE_BAKE_RES,
                    &seeds,
                );
                if let Some(v) = figure {
                    eprintln!(
                        "lattice visibility {v:.2} (power at the paving's lattice frequencies over the exemplar's there, \
                         seeds {seed} to {}; about 1 for a stationary exemplar)",
                        seed.wrapping_add(3)
                    );
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::GpuCheck(args) => gpu::check(&args),
        Command::GpuView(args) => gpu::view(&args),
        Command::Shader { command } => {
            gpu::shader(command)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Deform { mesh, output } => deform::deform(&mesh, &output),
        Command::Analyze { mesh, exemplar, seed, samples, json } => {
            deform::analyze(&mesh, &exemplar, seed, samples as usize, json)
        }
        Command::Bench { runs, threads, scenes, only } => {
            bench::run(&scenes, runs as usize, threads, &only)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// A worker thread count: 0 (all cores) to [`limits::MAX_THREADS`].
fn thread_count(text: &str) -> std::result::Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n <= limits::MAX_THREADS => Ok(n),
        _ => Err(format!("'{text}' is not a thread count from 0 (all cores) to {}", limits::MAX_THREADS)),
    }
}

/// A command-line number that must be finite and at least 0 (`nan` would pass every test).
fn non_negative(text: &str) -> std::result::Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("'{text}' is not a finite number >= 0")),
    }
}

/// A UV length in (0, 10].
fn positive_uv_length(text: &str) -> std::result::Result<f32, String> {
    match text.parse::<f32>() {
        Ok(x) if x > 0.0 && x <= 10.0 => Ok(x),
        _ => Err(format!("'{text}' is not a UV length in (0, 10]")),
    }
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.exr"))
}

fn load(path: &Path, overrides: &SceneOverrides, quiet: bool) -> Result<Scene> {
    // Loading grows with the scene (meshes, BVH, textures' MIP maps): a spinner with the
    // elapsed time shows that a long load is working (drawn only on a terminal).
    let spinner = if quiet { ProgressBar::hidden() } else { ProgressBar::new_spinner() };
    spinner.set_style(ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}").expect("valid template"));
    spinner.set_message(format!("loading {}", path.display()));
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    let scene = load_scene(path, overrides);
    spinner.finish_and_clear();
    let scene = scene?;
    if !quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    Ok(scene)
}

/// An exposure in stops, within +-64 (`--exposure`).
fn stops(text: &str) -> std::result::Result<f32, String> {
    let s: f32 = text.trim().parse().map_err(|_| format!("'{text}' is not a number of stops"))?;
    if !(-64.0..=64.0).contains(&s) {
        return Err(format!("{s} stops is not within [-64, 64]"));
    }
    Ok(s)
}

/// A positive, finite number of seconds (`--time-limit`, `--checkpoint`).
fn seconds(text: &str) -> std::result::Result<std::time::Duration, String> {
    let s: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number of seconds"))?;
    if !(s > 0.0 && s <= 1e9) {
        return Err(format!("{s} seconds is not within (0, 1e9]"));
    }
    Ok(std::time::Duration::from_secs_f64(s))
}

/// `KEY=VALUE` of `--set`.
fn key_value(text: &str) -> std::result::Result<(String, String), String> {
    let (key, value) = text.split_once('=').ok_or_else(|| format!("'{text}' is not KEY=VALUE"))?;
    Ok((key.trim().to_string(), value.trim().to_string()))
}

fn parse_crop(text: &str, scene: &Scene) -> Result<Crop> {
    let bad = |msg: String| Error::param("--crop", msg);
    let v: Vec<u32> = text
        .split(',')
        .map(|s| s.trim().parse::<u32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad(format!("'{text}' is not four non-negative integers x0,y0,x1,y1")))?;
    let [x0, y0, x1, y1] = v[..] else {
        return Err(bad(format!("'{text}' is not four integers x0,y0,x1,y1")));
    };
    let (w, h) = (scene.settings.width, scene.settings.height);
    if !(x0 < x1 && y0 < y1 && x1 <= w && y1 <= h) {
        return Err(bad(format!("{x0},{y0},{x1},{y1} is empty or outside the {w}x{h} image")));
    }
    Ok(Crop { x0, y0, x1, y1 })
}

/// How a render may end early, how often it writes what it has, and what it writes and prints.
#[derive(Clone, Copy, Debug)]
struct RenderControl {
    /// `--time-limit`.
    time_limit: Option<std::time::Duration>,
    /// `--checkpoint`.
    checkpoint: Option<std::time::Duration>,
    /// `--variance`: the per-pixel variance in the EXR.
    variance: bool,
    /// `-q`.
    quiet: bool,
    /// `--resume`: continue from the output's state file.
    resume: bool,
    /// What the render is made from, for its state file ([`tessera::integrator::Checkpoint`]).
    fingerprint: u64,
    /// `--tonemap` and `--exposure`, for PNG output.
    display: (tessera::image::ToneMap, f32),
}

/// The state file of an unfinished render beside its output: `OUTPUT.state`.
fn state_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".state");
    output.with_file_name(name)
}

/// Longest pass of a render without checkpoints: what Ctrl-C can lose.
const LONGEST_PASS: std::time::Duration = std::time::Duration::from_secs(30);

fn render_to_file(
    scene: &Scene,
    output: &Path,
    threads: Option<usize>,
    crop: Option<Crop>,
    aovs: &[Aov],
    control: RenderControl,
) -> Result<ExitCode> {
    let (variance, quiet) = (control.variance, control.quiet);
    use std::sync::atomic::{AtomicBool, Ordering};
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::param("--threads", e.to_string()))?;
    let s = scene.settings;
    let crop = crop.unwrap_or(Crop::full(s.width, s.height));
    let (w, h) = crop.size();
    let total = w as u64 * h as u64 * s.spp as u64;
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(total) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta_precise} {msg}")
            .expect("valid template"),
    );
    bar.set_message(format!("{w}x{h}, {} spp, {} threads", s.spp, pool.current_num_threads()));
    // Ctrl-C ends the pass under way and writes the image of the passes done; a second one
    // ends the process at once.
    static STOP: AtomicBool = AtomicBool::new(false);
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    });
    let limits = tessera::integrator::PassLimits {
        time_limit: control.time_limit,
        longest_pass: control.checkpoint.unwrap_or(LONGEST_PASS).min(LONGEST_PASS),
    };
    let state = state_path(output);
    let checkpoint = |film: &tessera::image::Film, samples: u32| {
        let film = film.clone();
        tessera::integrator::Checkpoint { fingerprint: control.fingerprint, crop, samples, film }.write(&state)
    };
    let start_film = if control.resume {
        if !state.exists() {
            let msg = format!("no unfinished render to resume: {} does not exist", state.display());
            return Err(Error::param("--resume", msg));
        }
        let resumed = tessera::integrator::Checkpoint::read(&state, control.fingerprint, crop, aovs)?;
        if !quiet {
            eprintln!("resuming {} from {} of {} spp", output.display(), resumed.samples, s.spp);
        }
        resumed.film
    } else {
        tessera::image::Film::new(w as usize, h as usize, aovs)
    };
    bar.set_length(w as u64 * h as u64 * s.spp.saturating_sub(start_film.samples_per_pixel().unwrap_or(0)) as u64);
    let start = Instant::now();
    let mut last_checkpoint = Instant::now();
    let (film, spp, ending) = pool.install(|| {
        tessera::integrator::render_in_passes(
            scene,
            crop,
            start_film,
            limits,
            &STOP,
            &|done, _| bar.set_position(done),
            |film, spp| {
                if control.checkpoint.is_some_and(|every| last_checkpoint.elapsed() >= every) && spp < s.spp {
                    write_film(output, film, scene, crop, variance, control.display)?;
                    checkpoint(film, spp)?;
                    last_checkpoint = Instant::now();
                    bar.set_message(format!("{w}x{h}, checkpoint of {spp} of {} spp written", s.spp));
                }
                Ok(())
            },
        )
    })?;
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    use tessera::integrator::Ending;
    if spp == 0 {
        let why = if ending == Ending::Stopped { "interrupted" } else { "the time limit came" };
        return Err(Error::param("render", format!("{why} before one sample per pixel was done: nothing written")));
    }
    write_film(output, &film, scene, crop, variance, control.display)?;
    // An unfinished render leaves its state for --resume; a finished one removes it.
    if ending == Ending::Complete {
        if state.exists() {
            std::fs::remove_file(&state).map_err(|e| Error::io(&state, e))?;
        }
    } else {
        checkpoint(&film, spp)?;
    }
    if !quiet {
        let invalid = film.invalid_sample_count();
        if invalid > 0 {
            eprintln!("warning: {invalid} samples had non-finite radiance and were counted as black");
        }
        match ending {
            Ending::Complete => {}
            Ending::TimeLimit => eprintln!("time limit: {spp} of {} spp rendered", s.spp),
            Ending::Stopped => eprintln!("interrupted: {spp} of {} spp rendered", s.spp),
        }
        eprintln!(
            "{}: {w}x{h}, {spp} spp in {seconds:.2} s ({:.2} M samples/s) -> {}",
            scene.path.display(),
            film.sample_count() as f64 / seconds / 1e6,
            output.display()
        );
    }
    Ok(if ending == Ending::Stopped { ExitCode::from(130) } else { ExitCode::SUCCESS })
}

/// Write a render's film (radiance, its AOVs and optionally the variance) to `output`,
/// atomically; a crop's EXR keeps its place in the frame (the data window), for `tessera merge`;
/// a PNG shows the radiance through `display` (tone curve, exposure in stops).
fn write_film(
    output: &Path,
    film: &tessera::image::Film,
    scene: &Scene,
    crop: Crop,
    variance: bool,
    display: (tessera::image::ToneMap, f32),
) -> Result<()> {
    use tessera::image::OutputFormat;
    let format = OutputFormat::from_path(output)?;
    if format != OutputFormat::Exr && (!film.aovs().is_empty() || variance) {
        eprintln!("warning: AOVs are written to EXR outputs only");
    }
    let (radiance, extra) = match format {
        OutputFormat::Png => (display.0.apply(&film.radiance(), display.1), Vec::new()),
        OutputFormat::Pfm | OutputFormat::Hdr => (film.radiance(), Vec::new()),
        OutputFormat::Exr => {
            let mut extra: Vec<(&[&str], tessera::image::Bitmap)> =
                film.aovs().iter().filter_map(|a| film.aov(*a).map(|b| (a.channel_names(), b))).collect();
            if variance {
                extra.push((&["variance.R", "variance.G", "variance.B"], film.variance()));
            }
            (film.radiance(), extra)
        }
    };
    let s = scene.settings;
    let window = tessera::image::ExrWindow {
        origin: (crop.x0 as usize, crop.y0 as usize),
        full: (s.width as usize, s.height as usize),
    };
    tessera::image::write_image_in(output, &radiance, &extra, window)
}

fn diff(
    test: &Path,
    reference: &Path,
    variance: Option<(&Path, u32)>,
    max_relmse: Option<f64>,
    max_flip: Option<f64>,
    output: Option<&Path>,
) -> Result<ExitCode> {
    use tessera::image::compare;
    if variance.is_none() && max_relmse.is_none() && max_flip.is_none() {
        return Err(Error::param(
            "diff",
            "give a criterion: --variance with --spp (Z-test), --max-relmse or --max-flip",
        ));
    }
    let (t, invalid) = compare::read_test_image(test)?;
    let r = compare::read_reference(reference)?;
    let v = variance.map(|(path, spp)| Ok((compare::read_reference(path)?, spp))).transpose()?;
    let criteria = compare::Criteria { z_test: v.as_ref().map(|(v, spp)| (v, *spp)), max_relmse, max_flip };
    let verdict = compare::judge(&t, invalid, &r, &criteria)?;
    let m = &verdict.metrics;
    println!("relmse     {:.6e}", m.relmse);
    println!("mae        {:.6e}", m.mae);
    println!("flip       {:.6}  (mean LDR-FLIP)", m.mean_flip);
    println!("mean       test {:?}, reference {:?}", m.mean_test.map(|v| v as f32), m.mean_reference.map(|v| v as f32));
    if let Some(z) = &verdict.z {
        println!(
            "z-test     {:.4}% of pixels accepted (need {}%), alpha {:.3e}, min p {:.3e}",
            100.0 * z.accepted_fraction,
            100.0 * compare::PASS_FRACTION,
            z.alpha,
            z.min_p
        );
        println!("mean z     {:?}", z.mean_z.map(|v| (v * 100.0).round() / 100.0));
    }
    if let Some(out) = output {
        let mut extra: Vec<(&[&str], tessera::image::Bitmap)> = vec![(&["flip.Y"], compare::flip_map(&t, &r)?)];
        if let Some(z) = &verdict.z {
            extra.push((&["pvalue.Y"], z.min_p_image()));
        }
        write_image(out, &compare::absolute_difference(&t, &r)?, &extra)?;
    }
    if verdict.passes() {
        println!("PASS");
        Ok(ExitCode::SUCCESS)
    } else {
        println!("FAIL: {}", verdict.failures.join("; "));
        Ok(ExitCode::FAILURE)
    }
}

fn print_info(scene: &Scene) {
    let g = &scene.geometry;
    let b = g.bounds();
    let s = scene.settings;
    println!("scene      {}", scene.path.display());
    println!(
        "image      {}x{}, {} spp, max depth {}, seed {}",
        s.width,
        s.height,
        s.spp,
        s.max_depth.map_or("unlimited".to_string(), |d| d.to_string()),
        s.seed
    );
    println!("shapes     {}", g.shapes.len());
    println!("triangles  {}", g.triangles.len());
    println!("spheres    {}", g.spheres.len());
    println!("vertices   {}", g.positions.len());
    if b.is_empty() {
        println!("bounds     (empty)");
    } else {
        println!(
            "bounds     [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}]",
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
        );
    }
    println!("materials  {}", scene.materials.len());
    println!("textures   {}", scene.textures.len());
    let env = match &scene.lights.environment {
        None => "none".to_string(),
        Some(tessera::light::Environment::Constant(c)) => format!("constant {c}"),
        Some(tessera::light::Environment::Map(_)) => "equirectangular map".to_string(),
    };
    let emits = |shapes: &[u32]| shapes.iter().filter(|&&s| g.shapes[s as usize].light.is_some()).count();
    let (emissive, emissive_spheres) = (emits(&g.triangle_shape), emits(&g.sphere_shape));
    let l = &scene.lights;
    let spots = l.points.iter().filter(|p| p.spot.is_some()).count();
    let suns = l.distant.iter().filter(|d| !d.is_delta()).count();
    println!(
        "lights     {} area ({emissive} triangles, {emissive_spheres} spheres), {} point, {spots} spot, {} directional, {suns} sun; environment: {env}",
        l.area.len(),
        l.points.len() - spots,
        l.distant.len() - suns
    );
    println!("memory     {:.1} MiB (geometry, BVH, textures)", scene.memory_bytes() as f64 / (1 << 20) as f64);
    let tracer = tessera::integrator::PathTracer::new(scene, false, false);
    let in_lanes: Vec<&str> = (0..scene.materials.len() as u32)
        .filter(|&m| tracer.shades_in_lanes(m))
        .map(|m| scene.materials[m as usize].name.as_str())
        .collect();
    let isa = tessera::simd::Isa::selected();
    match in_lanes.is_empty() {
        true => println!("lanes      none: every hit is shaded one at a time"),
        false => println!("lanes      {isa:?}, 8 hits at a time on triangles of: {}", in_lanes.join(", ")),
    }
}

/// `tessera montage`: read the images, caption them, grid them, write the result.
fn montage(images: &[PathBuf], columns: usize, labels: &[String], output: &Path) -> Result<()> {
    if !labels.is_empty() && labels.len() != images.len() {
        return Err(Error::param(
            "--label",
            format!("{} labels for {} images: give one per image, or none", labels.len(), images.len()),
        ));
    }
    OutputFormat::from_path(output)?;
    let mut cells = Vec::with_capacity(images.len());
    for (k, path) in images.iter().enumerate() {
        let bitmap = read_bitmap(path, ColorSpace::Srgb)?;
        let label = match labels.get(k) {
            Some(label) => label.clone(),
            None => path.file_stem().map_or(String::new(), |s| s.to_string_lossy().into_owned()),
        };
        cells.push((bitmap, label));
    }
    let grid = tessera::image::montage(&cells, columns, limits::MAX_RENDER_PIXELS)
        .map_err(|msg| Error::param("montage", msg))?;
    write_image(output, &grid, &[])?;
    eprintln!(
        "{} images on {} columns -> {} ({} x {})",
        images.len(),
        columns.min(images.len()),
        output.display(),
        grid.width,
        grid.height
    );
    Ok(())
}
