//! `tessera pups`: a PUPs preset (paper 002) baked to an image.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use tessera::error::{Error, Result};
use tessera::image::{ColorSpace, OutputFormat, read_bitmap, write_image};
use tessera::limits;
use tessera::pups::{Preset, PresetParams, PupsFilter, PupsTexture};
use tessera::texture::{BakeFootprint, PupsLookup, Texture, bake_rect};

/// `tessera pups` arguments.
#[derive(clap::Args)]
pub struct PupsArgs {
    /// The preset: a texture of paper 002 Sec. 3 (or give --points-file).
    #[arg(required_unless_present = "points_file")]
    preset: Option<Preset>,
    /// Control points from a CSV or JSON file instead of a preset (docs/scene-format.md).
    #[arg(long, conflicts_with_all = ["preset", "reference"])]
    points_file: Option<PathBuf>,
    /// With --points-file: each label's colour where its points weigh most (cells), instead of
    /// the blended values.
    #[arg(long, requires = "points_file")]
    labels: bool,
    /// About how many control points the base layer has over the unit square.
    #[arg(long, default_value_t = 700)]
    points: u32,
    /// Seed of the points and their attributes.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Image width and height in pixels (at most 8192 each).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [512, 512],
          value_parser = clap::value_parser!(u32).range(1..=limits::MAX_BAKE_RES as i64))]
    res: Vec<u32>,
    /// A tileable texture (a periodic domain): its left and right, top and bottom edges meet.
    #[arg(long)]
    tileable: bool,
    /// Orientation strength epsilon of Eq. 4.
    #[arg(long, default_value_t = 0.5)]
    epsilon: f32,
    /// Axis length scale (Fig. 4).
    #[arg(long, default_value_t = 1.0)]
    axis_scale: f32,
    /// A grey reference image for `reference-labels` and `iterative` (default: a built-in disc
    /// on a ramp).
    #[arg(long)]
    reference: Option<PathBuf>,
    /// A grey density image: the points' spacing from twice the base (black) to half (white),
    /// for presets without their own density ramp.
    #[arg(long, conflicts_with = "points_file")]
    density: Option<PathBuf>,
    /// Output image (.png or .exr).
    #[arg(short, long)]
    output: PathBuf,
}

/// Build the preset and bake it over the unit square.
pub fn run(args: PupsArgs) -> Result<()> {
    OutputFormat::from_path(&args.output)?;
    let reference = args.reference.as_deref().map(|p| read_bitmap(p, ColorSpace::Linear)).transpose()?;
    let params = PresetParams {
        points: args.points,
        seed: args.seed,
        tileable: args.tileable,
        epsilon: args.epsilon,
        axis_scale: args.axis_scale,
        reference,
        density: args.density.as_deref().map(|p| read_bitmap(p, ColorSpace::Linear)).transpose()?,
    };
    let start = Instant::now();
    let (texture, what) = match (args.preset, &args.points_file) {
        (Some(preset), _) => {
            (PupsTexture::preset(preset, &params).map_err(|msg| Error::param(preset.name(), msg))?, preset.name())
        }
        (None, Some(file)) => {
            let points = tessera::pups::read_points(file)?;
            let texture = PupsTexture::from_points(points, args.tileable, args.axis_scale, args.epsilon, args.labels)
                .map_err(|msg| Error::scene(file, msg))?;
            (texture, file.display().to_string())
        }
        (None, None) => unreachable!("clap requires a preset or a points file"),
    };
    let built = start.elapsed().as_secs_f64();
    let points = texture.point_count();
    let (w, h) = (args.res[0] as usize, args.res[1] as usize);
    let lookup = PupsLookup { texture: Arc::new(texture), scale: glam::Vec2::ONE, filter: PupsFilter::None };
    let image = bake_rect(&Texture::Pups(lookup), w, h, BakeFootprint::Point);
    write_image(&args.output, &image.without_alpha(), &[])?;
    eprintln!(
        "{}: {} ({points} control points), {w} x {h}, built in {built:.3} s, evaluated in {:.3} s",
        args.output.display(),
        what,
        start.elapsed().as_secs_f64() - built
    );
    Ok(())
}
