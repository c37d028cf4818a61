//! `tessera shader export`, `tessera bake --gpu` and `tessera gpu-check`: the WGSL port of
//! tiling and blending, exported for engines and checked against the CPU texel by texel.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tessera::error::{Error, Result};
use tessera::image::Bitmap;
use tessera::image::compare::TexelDifference;
use tessera::shader::{ShaderLanguage, export};
use tessera::texture::{BakeFootprint, Texture, bake};

/// `tessera shader ...`.
#[derive(clap::Subcommand)]
pub enum ShaderCommand {
    /// Write the tiling-and-blending shader (its bake compute entry point and every function
    /// it calls) in a shading language, translated from the WGSL by naga.
    Export {
        /// The language.
        #[arg(long, value_enum, default_value = "wgsl")]
        lang: ShaderLanguage,
        /// Output file (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

/// Run `tessera shader ...`.
pub fn shader(command: ShaderCommand) -> Result<()> {
    match command {
        ShaderCommand::Export { lang, output } => {
            let text = export(lang).map_err(|e| Error::param("shader", e.0))?;
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

/// The GPU bake of `texture` at `res` x `res` on the first adapter, and that adapter's name.
#[cfg(feature = "gpu")]
pub fn bake_on_gpu(texture: &Texture, name: &str, res: u32, footprint: BakeFootprint) -> Result<(Bitmap, String)> {
    let gpu = tessera::gpu::Gpu::new().map_err(gpu_error)?;
    let baker = tessera::gpu::GpuBake::new(&gpu, tiling_blending(texture, name)?).map_err(gpu_error)?;
    Ok((baker.bake(res, res, footprint).map_err(gpu_error)?, gpu.describe()))
}

/// Without the `gpu` feature: an error saying how to build with it.
#[cfg(not(feature = "gpu"))]
pub fn bake_on_gpu(texture: &Texture, name: &str, _res: u32, _footprint: BakeFootprint) -> Result<(Bitmap, String)> {
    tiling_blending(texture, name)?;
    Err(Error::param("gpu", "this tessera was built without the `gpu` feature: cargo build --release --features gpu"))
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
}

/// Run `tessera gpu-check`: exit 0 when the GPU bake matches the CPU's within the tolerance.
pub fn check(args: &GpuCheckArgs) -> Result<ExitCode> {
    if args.tolerance.is_nan() || args.tolerance < 0.0 {
        return Err(Error::param("--tolerance", "must be a number >= 0"));
    }
    let texture = tessera::scene::load_texture(&args.scene, &args.texture, !args.data)?;
    let footprint = args.footprint.into();
    let (gpu, adapter) = bake_on_gpu(&texture, &args.texture, args.res, footprint)?;
    let cpu = bake(&texture, args.res as usize, footprint);
    let diff = TexelDifference::new(&gpu, &cpu, args.worst)?;
    print_report(&args.scene, &args.texture, &adapter, args.res, &diff);
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
