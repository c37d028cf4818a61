//! `tessera shader export`, `tessera bake --gpu`, `tessera gpu-check` and `tessera gpu-view`:
//! the WGSL port of tiling and blending, exported for engines and checked against the CPU texel
//! by texel and pixel by pixel.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tessera::error::{Error, Result};
use tessera::image::Bitmap;
use tessera::image::compare::TexelDifference;
use tessera::integrator::primary::{
    Derivatives, ErrorQuantiles, PrimaryView, ViewDifference, primary_view, ulp_sensitivity,
};
use tessera::shader::{ShaderEntry, ShaderLanguage, export};
use tessera::texture::tiling_blending::params::HardwareSampling;
use tessera::texture::{BakeFootprint, Texture, bake};

/// `tessera shader ...`.
#[derive(clap::Subcommand)]
pub enum ShaderCommand {
    /// Write the tiling-and-blending shader (the bake's compute shader or the view's fragment
    /// shader, and every function it calls) in a shading language, translated from the WGSL by
    /// naga.
    Export {
        /// The language.
        #[arg(long, value_enum, default_value = "wgsl")]
        lang: ShaderLanguage,
        /// Which shader: the compute bake of the UV square, or the rasterised view (its fragment
        /// shader: the lookup with screen-space derivatives or ray differentials).
        #[arg(long, value_enum, default_value = "bake")]
        entry: ShaderEntry,
        /// Output file (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

/// Run `tessera shader ...`.
pub fn shader(command: ShaderCommand) -> Result<()> {
    match command {
        ShaderCommand::Export { lang, entry, output } => {
            let text = export(lang, entry).map_err(|e| Error::param("shader", e.0))?;
            match output {
                Some(path) => tessera::files::write_atomically(&path, |tmp| {
                    std::fs::write(tmp, &text).map_err(|e| Error::io(tmp, e))
                })?,
                None => print!("{text}"),
            }
            Ok(())
        }
    }
}

/// The tiling-and-blending texture of a loaded texture, or an error naming it.
fn tiling_blending<'t>(texture: &'t Texture, name: &str) -> Result<&'t tessera::texture::TilingBlending> {
    match texture {
        Texture::TilingBlending(t) => Ok(t),
        _ => Err(Error::param(
            "--texture",
            format!("'{name}' is not a tiling_blending texture: the GPU port covers tiling and blending"),
        )),
    }
}

#[cfg(feature = "gpu")]
fn gpu_error(e: tessera::gpu::GpuError) -> Error {
    Error::param("gpu", e.0)
}

/// The GPU bakes of `texture` at `res` x `res` on the first adapter, one per way of reading the
/// exemplar (`samplings`: None the shader's f32 filters, Some the texture unit), and that
/// adapter's name.
#[cfg(feature = "gpu")]
pub fn bake_on_gpu(
    texture: &Texture,
    name: &str,
    res: u32,
    footprint: BakeFootprint,
    samplings: &[Option<HardwareSampling>],
) -> Result<(Vec<Bitmap>, String)> {
    let texture = tiling_blending(texture, name)?;
    let gpu = tessera::gpu::Gpu::new().map_err(gpu_error)?;
    let bakes = samplings
        .iter()
        .map(|&sampling| {
            let baker = tessera::gpu::GpuBake::with_sampling(&gpu, texture, sampling).map_err(gpu_error)?;
            baker.bake(res, res, footprint).map_err(gpu_error)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((bakes, gpu.describe()))
}

/// Without the `gpu` feature: an error saying how to build with it.
#[cfg(not(feature = "gpu"))]
pub fn bake_on_gpu(
    texture: &Texture,
    name: &str,
    _res: u32,
    _footprint: BakeFootprint,
    _samplings: &[Option<HardwareSampling>],
) -> Result<(Vec<Bitmap>, String)> {
    tiling_blending(texture, name)?;
    Err(Error::param("gpu", "this tessera was built without the `gpu` feature: cargo build --release --features gpu"))
}

/// How the GPU reads the exemplar.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SamplingArg {
    /// The shader's own filters, in f32 with textureLoad (regime (a) of docs/gpu.md).
    Shader,
    /// The texture unit: textureSampleGrad through a trilinear, anisotropic sampler (regime (b)).
    Hardware,
}

/// `tessera gpu-check`'s arguments.
#[derive(clap::Args)]
pub struct GpuCheckArgs {
    /// Scene file (TOML) that defines the texture.
    scene: PathBuf,
    /// Name of the tiling_blending texture (`[textures.NAME]`).
    #[arg(long)]
    texture: String,
    /// Bake width and height in texels (at most 8192).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=tessera::limits::MAX_BAKE_RES as i64))]
    res: u32,
    /// Footprint of each lookup: `texel` or `point`.
    #[arg(long, default_value = "texel")]
    footprint: super::FootprintArg,
    /// Largest absolute difference allowed in any channel of any texel (regime (a): filtering
    /// in f32 in the shader; docs/gpu.md).
    #[arg(long, default_value_t = 1e-4)]
    tolerance: f32,
    /// How many of the worst texels to print.
    #[arg(long, default_value_t = 8)]
    worst: usize,
    /// Write the error image max_c |gpu - cpu| (EXR, one channel) here.
    #[arg(long)]
    error_image: Option<PathBuf>,
    /// Read 8-bit images as data (no sRGB decoding).
    #[arg(long)]
    data: bool,
    /// How the GPU reads the exemplar. `hardware` bakes it four ways (the shader's filters, then
    /// the texture unit isotropic with the footprint doubled and as it is, then anisotropic)
    /// and prints each one's difference; the verdict and the details are the last one's.
    #[arg(long, value_enum, default_value = "shader")]
    sampling: SamplingArg,
    /// The sampler's anisotropy clamp with `--sampling hardware` (1 to 16).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=16))]
    anisotropy: u16,
}

/// The ways `gpu-check --sampling hardware` reads the exemplar, described: from regime (a) to an
/// engine's textureSampleGrad, one difference at a time.
fn hardware_samplings(anisotropy: u16) -> Vec<(Option<HardwareSampling>, String)> {
    let hardware = |anisotropy, gradient_scale| Some(HardwareSampling { anisotropy, gradient_scale });
    vec![
        (None, "shader, f32 filters (regime (a))".into()),
        (hardware(1, 2.0), "texture unit, isotropic, footprint x2 (about tessera's trilinear level)".into()),
        (hardware(1, 1.0), "texture unit, isotropic, footprint x1 (the GPU's level of detail)".into()),
        (hardware(anisotropy, 1.0), format!("texture unit, anisotropy {anisotropy}, footprint x1 (textureSampleGrad)")),
    ]
}

/// Run `tessera gpu-check`: exit 0 when the GPU bake matches the CPU's within the tolerance.
pub fn check(args: &GpuCheckArgs) -> Result<ExitCode> {
    if args.tolerance.is_nan() || args.tolerance < 0.0 {
        return Err(Error::param("--tolerance", "must be a number >= 0"));
    }
    let texture = tessera::scene::load_texture(&args.scene, &args.texture, !args.data)?;
    let footprint = args.footprint.into();
    let samplings = match args.sampling {
        SamplingArg::Shader => vec![(None, String::new())],
        SamplingArg::Hardware => hardware_samplings(args.anisotropy),
    };
    let sampling_of: Vec<Option<HardwareSampling>> = samplings.iter().map(|(s, _)| *s).collect();
    let (bakes, adapter) = bake_on_gpu(&texture, &args.texture, args.res, footprint, &sampling_of)?;
    let cpu = bake(&texture, args.res as usize, footprint);
    let mut diffs = bakes.iter().map(|gpu| TexelDifference::new(gpu, &cpu, args.worst)).collect::<Result<Vec<_>>>()?;
    let diff = diffs.pop().expect("one bake at least");
    print_report(&args.scene, &args.texture, &adapter, args.res, &diff);
    if args.sampling == SamplingArg::Hardware {
        println!("  the exemplar read by:                                                      max |gpu - cpu|   mean");
        for ((_, name), d) in samplings.iter().zip(diffs.iter().chain([&diff])) {
            let mean = d.mean_abs.iter().cloned().fold(0.0f64, f64::max);
            println!("    {name:<72} {:>9.3e} {:>9.3e}", d.max(), mean);
        }
    }
    if let Some(path) = &args.error_image {
        write_error_image(path, &diff.error_image)?;
    }
    let pass = diff.within(args.tolerance);
    println!(
        "{}: max |gpu - cpu| {:.3e} against the tolerance {:.1e}",
        if pass { "PASS" } else { "FAIL" },
        diff.max(),
        args.tolerance
    );
    Ok(if pass { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

fn print_report(scene: &Path, texture: &str, adapter: &str, res: u32, diff: &TexelDifference) {
    println!("{}: texture '{texture}', {res}x{res} texels, GPU {adapter}", scene.display());
    for (c, name) in ["R", "G", "B", "A"].iter().enumerate() {
        println!("  {name}: max |gpu - cpu| {:.3e}, mean {:.3e}", diff.max_abs[c], diff.mean_abs[c]);
    }
    println!("  worst texels (x, y from the top-left):");
    for t in &diff.worst {
        println!(
            "    ({:4}, {:4}) {:.3e}: gpu {:.6?} cpu {:.6?}",
            t.x,
            t.y,
            t.error,
            t.test.to_array(),
            t.reference.to_array()
        );
    }
}

fn write_error_image(path: &Path, error: &Bitmap) -> Result<()> {
    if tessera::image::OutputFormat::from_path(path)? != tessera::image::OutputFormat::Exr {
        return Err(Error::param("--error-image", "the error image is written as .exr"));
    }
    tessera::image::write_image(path, error, &[])
}

/// `tessera gpu-view`'s arguments.
#[derive(clap::Args)]
pub struct GpuViewArgs {
    /// Scene file (TOML): its meshes, its camera, and the texture.
    scene: PathBuf,
    /// Name of the tiling_blending texture (`[textures.NAME]`), drawn on every surface.
    #[arg(long)]
    texture: String,
    /// View size, WIDTHxHEIGHT (default: the scene's).
    #[arg(long, value_parser = parse_resolution)]
    res: Option<(u32, u32)>,
    /// The GPU view shown in the output image: its footprint from WGSL's dpdx, coarse or fine
    /// screen-space derivatives, or from ray differentials as tessera computes them.
    #[arg(long, value_enum, default_value = "dpdx")]
    derivatives: Derivatives,
    /// Largest absolute difference allowed between the GPU view with ray differentials and
    /// tessera's, in any channel of any pixel where both see the same triangle.
    #[arg(long, default_value_t = 1e-4)]
    tolerance: f32,
    /// How many of the worst pixels to print.
    #[arg(long, default_value_t = 4)]
    worst: usize,
    /// Write the GPU view, tessera's and their difference side by side (.png or .exr).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also time the GPU view: frames per second, median of 5 batches.
    #[arg(long)]
    time: bool,
    /// How the GPU reads the exemplar: the shader's f32 filters, or the texture unit
    /// (textureSampleGrad with the footprint as it is, anisotropic: what an engine's shader does).
    #[arg(long, value_enum, default_value = "shader")]
    sampling: SamplingArg,
    /// The sampler's anisotropy clamp with `--sampling hardware` (1 to 16).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=16))]
    anisotropy: u16,
    /// Read 8-bit images as data (no sRGB decoding).
    #[arg(long)]
    data: bool,
}

/// "WIDTHxHEIGHT", each side at least 1 and within the render limits.
fn parse_resolution(text: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| format!("'{text}' is not WIDTHxHEIGHT"))?;
    let side = |s: &str| -> std::result::Result<u32, String> {
        let v: u32 = s.trim().parse().map_err(|_| format!("'{s}' is not a whole number of pixels"))?;
        if v == 0 || v > tessera::limits::MAX_RENDER_SIDE {
            return Err(format!("{v} pixels is outside 1..={}", tessera::limits::MAX_RENDER_SIDE));
        }
        Ok(v)
    };
    let (w, h) = (side(w)?, side(h)?);
    if w as u64 * h as u64 > tessera::limits::MAX_RENDER_PIXELS {
        return Err(format!("{w}x{h} is more than {} pixels", tessera::limits::MAX_RENDER_PIXELS));
    }
    Ok((w, h))
}

/// What the GPU drew: a view per kind of derivatives, the adapter, and seconds per frame of
/// the view shown where timed.
struct GpuViews {
    views: Vec<(Derivatives, PrimaryView)>,
    adapter: String,
    seconds_per_frame: Option<f64>,
}

#[cfg(feature = "gpu")]
fn draw_on_gpu(
    scene: &tessera::scene::Scene,
    camera: &tessera::camera::Camera,
    texture: &Texture,
    args: &GpuViewArgs,
) -> Result<GpuViews> {
    let texture = tiling_blending(texture, &args.texture)?;
    let gpu = tessera::gpu::Gpu::new().map_err(gpu_error)?;
    let hardware = (args.sampling == SamplingArg::Hardware)
        .then_some(HardwareSampling { anisotropy: args.anisotropy, gradient_scale: 1.0 });
    let view = tessera::gpu::GpuView::new(&gpu, scene, camera, texture, hardware).map_err(gpu_error)?;
    let views =
        Derivatives::ALL.iter().map(|&d| Ok((d, view.render(d).map_err(gpu_error)?))).collect::<Result<Vec<_>>>()?;
    let seconds_per_frame = if args.time {
        // Batches of about 0.2 s.
        let probe = view.time(args.derivatives, 1, 1).map_err(gpu_error)?[0];
        let frames = ((0.2 / probe) as usize).clamp(1, 1000);
        let mut seconds = view.time(args.derivatives, frames, 5).map_err(gpu_error)?;
        seconds.sort_by(f64::total_cmp);
        Some(seconds[seconds.len() / 2])
    } else {
        None
    };
    Ok(GpuViews { views, adapter: gpu.describe(), seconds_per_frame })
}

#[cfg(not(feature = "gpu"))]
fn draw_on_gpu(
    _scene: &tessera::scene::Scene,
    _camera: &tessera::camera::Camera,
    texture: &Texture,
    args: &GpuViewArgs,
) -> Result<GpuViews> {
    tiling_blending(texture, &args.texture)?;
    Err(Error::param("gpu", "this tessera was built without the `gpu` feature: cargo build --release --features gpu"))
}

/// Run `tessera gpu-view`: exit 0 when the GPU view with ray differentials matches tessera's
/// within the tolerance.
pub fn view(args: &GpuViewArgs) -> Result<ExitCode> {
    if args.tolerance.is_nan() || args.tolerance < 0.0 {
        return Err(Error::param("--tolerance", "must be a number >= 0"));
    }
    if let Some(output) = &args.output {
        tessera::image::OutputFormat::from_path(output)?;
    }
    let scene = tessera::scene::load_scene(&args.scene, &Default::default())?;
    let texture = tessera::scene::load_texture(&args.scene, &args.texture, !args.data)?;
    let (width, height) = args.res.unwrap_or((scene.settings.width, scene.settings.height));
    let camera = scene.camera.with_resolution(width, height)?;
    let gpu = draw_on_gpu(&scene, &camera, &texture, args)?;
    let reference = primary_view(&scene, &camera, &texture);
    let seen = reference.triangle.iter().filter(|&&t| t != 0).count();
    println!("{}: texture '{}', {width}x{height} pixels, GPU {}", args.scene.display(), args.texture, gpu.adapter);
    if args.sampling == SamplingArg::Hardware {
        println!("  the GPU samples the exemplar with its texture unit, anisotropy {} (regime (b))", args.anisotropy);
    }
    println!("  tessera: camera rays through pixel centres, ray differentials; {seen} pixels see a surface");
    println!(
        "  {:<7} {:>9} {:>9} {:>9}  {:>9} {:>9}  {:>9} {:>9} {:>9}",
        "GPU", "compared", "coverage", "triangle", "max diff", "mean", "footprint", "error", ""
    );
    println!(
        "  {:<7} {:>9} {:>9} {:>9}  {:>9} {:>9}  {:>9} {:>9} {:>9}",
        "uses", "pixels", "differs", "differs", "", "", "median", "p99", "max"
    );
    let mut ray_difference = None;
    for (derivatives, view) in &gpu.views {
        let diff = ViewDifference::new(view, &reference, args.worst)?;
        let mean = diff.value.mean_abs.iter().cloned().fold(0.0f64, f64::max);
        println!(
            "  {:<7} {:>9} {:>9} {:>9}  {:>9.2e} {:>9.2e}  {:>9.2e} {:>9.2e} {:>9.2e}",
            derivatives.name(),
            diff.compared,
            diff.coverage_differs,
            diff.triangle_differs,
            diff.value.max(),
            mean,
            diff.footprint.median,
            diff.footprint.p99,
            diff.footprint.max
        );
        if *derivatives == Derivatives::Ray {
            ray_difference = Some(diff);
        }
    }
    println!("  (max and mean |gpu - tessera| over channels and the pixels both see on the same triangle;");
    println!("   footprint error: max(|dx - dx'|, |dy - dy'|) / max(|dx'|, |dy'|), ' tessera's)");
    let sensitivity = ulp_sensitivity(&scene, &camera, &texture);
    let sensitivity = ErrorQuantiles::new(
        sensitivity.into_iter().zip(&reference.triangle).filter(|&(_, &t)| t != 0).map(|(s, _)| s).collect(),
    );
    println!(
        "  one f32 ulp of UV moves tessera's value by up to {:.2e} (p99 {:.2e}, median {:.2e}): differences of that order",
        sensitivity.max, sensitivity.p99, sensitivity.median
    );
    println!("  come from the UVs' last bits alone (docs/gpu.md)");
    let ray = ray_difference.expect("the ray view is drawn");
    if !ray.value.worst.is_empty() {
        println!("  worst pixels with ray differentials (x, y from the top-left):");
    }
    for t in &ray.value.worst {
        println!(
            "    ({:4}, {:4}) {:.3e}: gpu {:.6?} tessera {:.6?}",
            t.x,
            t.y,
            t.error,
            t.test.to_array(),
            t.reference.to_array()
        );
    }
    if let Some(seconds) = gpu.seconds_per_frame {
        println!(
            "  speed: {:.1} frames/s at {width}x{height} ({} derivatives; median of 5 batches)",
            1.0 / seconds,
            args.derivatives.name()
        );
    }
    if let Some(output) = &args.output {
        let shown = &gpu.views.iter().find(|(d, _)| *d == args.derivatives).expect("every kind is drawn").1;
        write_side_by_side(output, shown, &reference, args.derivatives)?;
    }
    let pass = ray.value.within(args.tolerance);
    println!(
        "{}: with ray differentials, max |gpu - tessera| {:.3e} against the tolerance {:.1e}",
        if pass { "PASS" } else { "FAIL" },
        ray.value.max(),
        args.tolerance
    );
    Ok(if pass { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// The GPU view, tessera's and 100 |gpu - tessera| side by side, captioned.
fn write_side_by_side(path: &Path, gpu: &PrimaryView, reference: &PrimaryView, derivatives: Derivatives) -> Result<()> {
    let rgb = |b: &Bitmap| {
        let mut out = Bitmap::new(b.width, b.height, 3);
        for (o, i) in out.data.chunks_exact_mut(3).zip(b.data.chunks_exact(4)) {
            o.copy_from_slice(&i[..3]);
        }
        out
    };
    let mut error = Bitmap::new(gpu.value.width, gpu.value.height, 1);
    for (i, e) in error.data.iter_mut().enumerate() {
        let (g, r) = (&gpu.value.data[4 * i..4 * i + 4], &reference.value.data[4 * i..4 * i + 4]);
        *e = 100.0 * g.iter().zip(r).map(|(a, b)| (a - b).abs()).fold(0.0, f32::max);
    }
    let cells = [
        (rgb(&gpu.value), format!("GPU, {} derivatives", derivatives.name())),
        (rgb(&reference.value), "tessera, ray differentials".to_string()),
        (error, "100 |GPU - tessera|".to_string()),
    ];
    let grid = tessera::image::montage(&cells, 3, tessera::limits::MAX_RENDER_PIXELS)
        .map_err(|msg| Error::param("--output", msg))?;
    tessera::image::write_image(path, &grid, &[])
}
