//! Command-line interface: argument parsing (clap) and progress display (indicatif). The
//! library does the work and reports progress through a callback.

mod bench;

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use tessera::error::{Error, Result};
use tessera::image::{Aov, write_image};
use tessera::integrator::{Crop, render};
use tessera::scene::{Scene, SceneOverrides, load_scene};

/// tessera: a reference path tracer for procedural surface textures.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to an image (EXR: linear float; PNG: 8-bit sRGB).
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output image, .exr or .png (default: the scene's name with .exr, in the current folder).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Samples per pixel (replaces the scene's).
        #[arg(long)]
        spp: Option<u32>,
        /// Worker threads (default: all cores). The image does not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Sampler seed (replaces the scene's).
        #[arg(long)]
        seed: Option<u64>,
        /// Render only the pixels x0 <= x < x1, y0 <= y < y1; the image has the crop's size.
        #[arg(long, value_name = "x0,y0,x1,y1")]
        crop: Option<String>,
        /// Auxiliary outputs to add to an EXR, comma separated.
        #[arg(long, value_delimiter = ',')]
        aov: Vec<Aov>,
        /// Print nothing but errors.
        #[arg(short, long)]
        quiet: bool,
    },
    /// Print what a scene contains: triangles, bounds, lights, memory.
    Info {
        /// Scene file (TOML).
        scene: PathBuf,
    },
    /// Measure ray casting (Mrays/s) and rendering (samples/s) throughput.
    Bench {
        /// Runs per figure (the median is printed).
        #[arg(long, default_value_t = 5)]
        runs: usize,
        /// Worker threads for the parallel figures (default: 2, the size of the machines
        /// Mitsuba's reference figures were measured on; 0 = all cores).
        #[arg(long, default_value_t = 2)]
        threads: usize,
        /// Folder of the shipped scenes.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
    },
}

/// Parse the command line and run it.
pub fn run() -> Result<ExitCode> {
    match Cli::parse().command {
        Command::Render { scene, output, spp, threads, seed, crop, aov, quiet } => {
            let overrides = SceneOverrides { spp, seed, ..Default::default() };
            let output = output.unwrap_or_else(|| default_output(&scene));
            tessera::image::OutputFormat::from_path(&output)?;
            let scene = load(&scene, &overrides, quiet)?;
            let crop = crop.map(|c| parse_crop(&c, &scene)).transpose()?;
            render_to_file(&scene, &output, threads, crop, &aov, quiet)?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Info { scene } => {
            let scene = load(&scene, &SceneOverrides::default(), false)?;
            print_info(&scene);
            Ok(ExitCode::SUCCESS)
        }
        Command::Bench { runs, threads, scenes } => {
            if runs == 0 {
                return Err(Error::param("--runs", "must be at least 1"));
            }
            bench::run(&scenes, runs, threads)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}.exr"))
}

fn load(path: &Path, overrides: &SceneOverrides, quiet: bool) -> Result<Scene> {
    let scene = load_scene(path, overrides)?;
    if !quiet {
        for w in &scene.warnings {
            eprintln!("warning: {w}");
        }
    }
    Ok(scene)
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

fn render_to_file(
    scene: &Scene,
    output: &Path,
    threads: Option<usize>,
    crop: Option<Crop>,
    aovs: &[Aov],
    quiet: bool,
) -> Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::param("--threads", e.to_string()))?;
    let s = scene.settings;
    let (w, h) = crop.map_or((s.width, s.height), |c| c.size());
    let total = w as u64 * h as u64 * s.spp as u64;
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(total) };
    bar.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta_precise} {msg}")
            .expect("valid template"),
    );
    bar.set_message(format!("{w}x{h}, {} spp, {} threads", s.spp, pool.current_num_threads()));
    let start = Instant::now();
    let film = pool.install(|| render(scene, crop, aovs, &|done, _| bar.set_position(done)));
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();

    let extra: Vec<(&[&str], tessera::image::Bitmap)> =
        aovs.iter().filter_map(|a| film.aov(*a).map(|b| (a.channel_names(), b))).collect();
    if !extra.is_empty() && tessera::image::OutputFormat::from_path(output)? == tessera::image::OutputFormat::Png {
        eprintln!("warning: AOVs are written to EXR outputs only");
    }
    write_image(output, &film.radiance(), &extra)?;
    if !quiet {
        let invalid = film.invalid_sample_count();
        if invalid > 0 {
            eprintln!("warning: {invalid} samples had non-finite radiance and were counted as black");
        }
        eprintln!(
            "{}: {w}x{h}, {} spp in {seconds:.2} s ({:.2} M samples/s) -> {}",
            scene.path.display(),
            s.spp,
            film.sample_count() as f64 / seconds / 1e6,
            output.display()
        );
    }
    Ok(())
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
    let emissive = g.triangle_shape.iter().filter(|&&s| g.shapes[s as usize].light.is_some()).count();
    println!("lights     {} area ({emissive} triangles), environment: {env}", scene.lights.area.len());
    println!("memory     {:.1} MiB (geometry, BVH, textures)", scene.memory_bytes() as f64 / (1 << 20) as f64);
}
