//! `tessera tiles`: paper 001's tile images and tile mapping.

use clap::Subcommand;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;
use tessera::error::{Error, Result};
use tessera::geometry::{QuadMesh, catmull_clark, load_quad_obj};
use tessera::image::{ColorSpace, OutputFormat, read_bitmap, write_image};
use tessera::limits;
use tessera::tiles::{PixelRect, TileLayout, TileTemplates, assign_boundaries, assign_tiles, texture_coordinates};

/// `tessera tiles` commands.
#[derive(Subcommand)]
pub enum TilesCommand {
    /// Synthesise a tile image from any photograph (paper 001 Sec. 4): (2n)^4 tiles whose
    /// edges of complementary types match texel for texel, each in a cell with a guard band.
    Synth {
        /// The photograph (PNG, JPEG, HDR, EXR).
        image: PathBuf,
        /// A boundary template: two stacked squares x,y,width,height (pixels from the top-left,
        /// height = 2 width); the line between them is the boundary. One per condition; the
        /// ones not given are spread along the image's middle.
        #[arg(long, value_name = "x,y,w,h")]
        boundary: Vec<PixelRect>,
        /// The region the tiles' backgrounds are drawn from (default: the whole image).
        #[arg(long, value_name = "x,y,w,h")]
        background: Option<PixelRect>,
        /// Boundary conditions n: (2n)^4 tiles.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=tessera::tiles::layout::MAX_CONDITIONS as i64))]
        conditions: u32,
        /// Tile side in texels (a multiple of 16).
        #[arg(long, default_value_t = 256)]
        tile_res: u32,
        /// Seed of the backgrounds' positions.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Also write a contact sheet: every tile on its own, labelled with its name.
        #[arg(long)]
        sheet: Option<PathBuf>,
        /// The tile image (.png or .exr).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Give every quad of a quad mesh one tile (paper 001 Sec. 3): writes the mesh with
    /// per-corner texture coordinates and a material library naming the tile image.
    Map {
        /// The quad mesh (OBJ, quads only).
        mesh: PathBuf,
        /// Boundary conditions n of the tile image it will read.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=tessera::tiles::layout::MAX_CONDITIONS as i64))]
        conditions: u32,
        /// Seed of the edges' types.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Rounds of Catmull-Clark subdivision after mapping (texture coordinates carried
        /// bilinearly, as the paper's Maya renders do); the subdivided mesh gets smooth vertex
        /// normals.
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=8))]
        subdivide: u32,
        /// The tile image the material library names.
        #[arg(long, default_value = "tiles.png")]
        texture: String,
        /// The mapped mesh (.obj; the .mtl is written beside it).
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// Run a `tessera tiles` command.
pub fn run(command: TilesCommand) -> Result<()> {
    match command {
        TilesCommand::Synth { image, boundary, background, conditions, tile_res, seed, sheet, output } => {
            synth(&image, &boundary, background, conditions, tile_res, seed, sheet.as_deref(), &output)
        }
        TilesCommand::Map { mesh, conditions, seed, subdivide, texture, output } => {
            map(&mesh, conditions, seed, subdivide, &texture, &output)
        }
    }
}

fn spinner(message: String) -> ProgressBar {
    let bar = ProgressBar::new_spinner().with_message(message);
    bar.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("a valid template"));
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}

#[allow(clippy::too_many_arguments)]
fn synth(
    image_path: &Path,
    boundaries: &[PixelRect],
    background: Option<PixelRect>,
    conditions: u32,
    tile_res: u32,
    seed: u64,
    sheet: Option<&Path>,
    output: &Path,
) -> Result<()> {
    OutputFormat::from_path(output)?;
    if let Some(sheet) = sheet {
        OutputFormat::from_path(sheet)?;
    }
    let layout = TileLayout::new(conditions, tile_res).map_err(|msg| Error::param("--tile-res", msg))?;
    let image = read_bitmap(image_path, ColorSpace::Srgb)?;
    let templates =
        TileTemplates::new(&image, conditions, boundaries, background).map_err(|msg| Error::image(image_path, msg))?;
    let start = Instant::now();
    let bar = spinner(format!("synthesising {} tiles of {tile_res} texels", layout.tile_count()));
    let atlas = tessera::tiles::synthesize_tiles(&image, &templates, &layout, seed);
    bar.finish_and_clear();
    write_image(output, &atlas, &[])?;
    let bounds: Vec<String> = templates.boundaries.iter().map(|b| format!("--boundary {b}")).collect();
    eprintln!(
        "{}: {} tiles of {tile_res} texels in {:.2} s, {} x {} cells of {} texels ({}-texel guard band), {} \
         --background {}",
        output.display(),
        layout.tile_count(),
        start.elapsed().as_secs_f64(),
        layout.grid(),
        layout.grid(),
        layout.cell(),
        layout.guard(),
        bounds.join(" "),
        templates.background,
    );
    if let Some(sheet) = sheet {
        // Top row of the grid first, as the tile image shows them.
        let cells: Vec<_> = (0..layout.grid())
            .rev()
            .flat_map(|row| (0..layout.grid()).map(move |column| (column, row)))
            .map(|(column, row)| {
                let name = layout.name_at(column, row);
                (layout.tile_bitmap(&atlas, name), name.to_string())
            })
            .collect();
        let grid = tessera::image::montage(&cells, layout.grid(), limits::MAX_RENDER_PIXELS)
            .map_err(|msg| Error::param("--sheet", msg))?;
        write_image(sheet, &grid, &[])?;
        eprintln!("{}: contact sheet of the {} tiles", sheet.display(), layout.tile_count());
    }
    Ok(())
}

fn map(path: &Path, conditions: u32, seed: u64, subdivide: u32, texture: &str, output: &Path) -> Result<()> {
    if output.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("obj") {
        return Err(Error::param("--output", format!("{}: the mapped mesh is written as .obj", output.display())));
    }
    if texture.is_empty() || texture.chars().any(char::is_control) {
        return Err(Error::param("--texture", "give the tile image's file name (no control characters)"));
    }
    let start = Instant::now();
    let bar = spinner(format!("reading {}", path.display()));
    let mut mesh = load_quad_obj(path)?;
    let final_quads = (mesh.quads.len() as u64).saturating_mul(4u64.saturating_pow(subdivide));
    if final_quads > limits::MAX_TRIANGLES {
        return Err(Error::param(
            "--subdivide",
            format!("{} rounds would make {final_quads} quads, over the limit of {}", subdivide, limits::MAX_TRIANGLES),
        ));
    }
    bar.set_message(format!("mapping {} quads", mesh.quads.len()));
    let (topology, report) = mesh.topology().map_err(|msg| Error::mesh(path, msg))?;
    let types = assign_boundaries(&topology, conditions, seed);
    let tiles = assign_tiles(&topology, &types);
    // Texture coordinates do not depend on the tile size (layout.rs): any valid one will do.
    let layout = TileLayout::new(conditions, 16).expect("a valid number of conditions");
    mesh.uvs = Some(texture_coordinates(&layout, &tiles));
    let mut used = vec![false; layout.tile_count()];
    for &t in &tiles {
        used[layout.index_of(t)] = true;
    }
    let mut topology = topology;
    for round in 0..subdivide {
        bar.set_message(format!("subdividing, round {} of {subdivide}", round + 1));
        mesh = catmull_clark(&mesh, &topology);
        if round + 1 < subdivide {
            topology = QuadMesh::topology(&mesh).map_err(|msg| Error::mesh(path, msg))?.0;
        }
    }
    bar.set_message(format!("writing {}", output.display()));
    let normals = (subdivide > 0).then(|| mesh.vertex_normals());
    mesh.write_obj(output, texture, normals.as_deref())?;
    bar.finish_and_clear();
    eprintln!(
        "{}: {} quads ({} before subdivision), {} of {} tiles used, {} boundary edges (their quads take any type there), \
         {:.2} s; material library {} reads {texture}",
        output.display(),
        mesh.quads.len(),
        tiles.len(),
        used.iter().filter(|&&u| u).count(),
        layout.tile_count(),
        report.boundary_edges,
        start.elapsed().as_secs_f64(),
        output.with_extension("mtl").display(),
    );
    Ok(())
}
