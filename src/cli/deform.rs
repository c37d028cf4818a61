//! `tessera deform` and `tessera analyze`: the deformation field and cuts of a UV-mapped mesh
//! (paper 000 Sec. 4 and 5), and the distortion and seam metrics they are judged by.

use clap::Args;
use glam::{Mat2, Vec3};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;
use tessera::deform::{
    AnalysisInput, DeformationMaps, Distortion, Orientation, Smoothing, analysis, deformation_maps, distortion,
    pack_charts, uv_charts,
};
use tessera::error::{Error, Result};
use tessera::files::StagedFolder;
use tessera::geometry::TriangleMesh;
use tessera::geometry::obj::obj_text;
use tessera::image::{ColorSpace, read_bitmap, write_exr, write_image};
use tessera::limits;
use tessera::texture::tiling_blending::{Deformation, DeformationField, FieldAt, cuts_to_json};
use tessera::texture::{Filter, ImageTexture, MipMap, Texture};

/// The mesh and the parameters of its deformation field.
#[derive(Args)]
pub struct MeshArgs {
    /// The mesh with texture coordinates: OBJ, PLY, Mitsuba serialized (its first mesh), or
    /// glTF 2.0 (.gltf, .glb; all its triangle primitives in world space).
    mesh: PathBuf,
    /// Rounds of averaging of the field over each UV vertex's triangles, within its chart
    /// (Sec. 4.4; 0 keeps each vertex the mean of its triangles; at most 256), or `triangles`:
    /// each triangle's own F, not smoothed (paper 000 Fig. 4 c).
    #[arg(long, default_value = "1", value_parser = parse_smoothing)]
    smoothing: Smoothing,
    /// Texels per side of the F map (and of the cut bands' raster; at most 4096).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=limits::MAX_DEFORM_RES as i64))]
    res: u32,
    /// Tangent field orienting the texture: `uv` (F = S), `fixed:X,Y,Z` (a direction projected
    /// on the surface), `parallels:X,Y,Z` (circles around an axis through the origin) or
    /// `geodesic:X,Y,Z[;X,Y,Z...]` (away from the vertices nearest to these points, along the
    /// gradient of the distance over the surface), or `tangents` (per vertex from a glTF
    /// file's TANGENT attribute).
    #[arg(long, default_value = "uv")]
    orientation: String,
    /// Lattice spacing of the tiles in UV units (the scene's `tile_size`): the width of the
    /// cut bands pictured and analysed (the renderer lays them for the scene's own).
    #[arg(long, default_value_t = 0.25)]
    tile_size: f32,
    /// Pack the mesh's UV charts apart first (each moved and scaled by one common factor), so
    /// that overlapping islands get a field each; `deform` writes the mesh it made as mesh.obj
    /// beside the maps, the mesh to render with them.
    #[arg(long)]
    repack: bool,
}

/// What [`MeshArgs::maps`] derives.
struct Derived {
    /// The mesh the maps are for: the file's, or with its charts packed apart (`--repack`).
    mesh: TriangleMesh,
    /// The factor `--repack` scaled every chart's UVs by.
    repacked_scale: Option<f32>,
    maps: DeformationMaps,
    orientation: Orientation,
    /// Seconds spent loading and deriving.
    times: [f64; 2],
}

impl MeshArgs {
    /// Load the mesh and derive its maps, with the orientation field they follow; also says how
    /// long each took.
    fn maps(&self) -> Result<Derived> {
        if !(self.tile_size > 1e-6 && self.tile_size <= 1e4) {
            return Err(Error::param("--tile-size", format!("{} is not in (1e-6, 1e4] UV units", self.tile_size)));
        }
        let start = Instant::now();
        let (mut mesh, tangents) = tessera::scene::load_surface(&self.mesh)?;
        let mut repacked_scale = None;
        if self.repack {
            let (charts, _) = uv_charts(&mesh)
                .ok_or_else(|| Error::mesh(&self.mesh, "--repack: the mesh has no texture coordinates"))?;
            // Four texels of the maps apart: a bilinear lookup at a chart's border reads its own
            // chart's texels (a gutter's texels take the nearest chart's field).
            let repacked =
                pack_charts(&mesh, &charts, 4.0 / self.res as f32).map_err(|msg| Error::mesh(&self.mesh, msg))?;
            (mesh, repacked_scale) = (repacked.mesh, Some(repacked.scale));
        }
        let loaded = start.elapsed().as_secs_f64();
        let orientation = match (self.orientation.as_str(), tangents) {
            ("tangents", Some(tangents)) => Orientation::PerVertex(tangents),
            ("tangents", None) => {
                return Err(Error::mesh(
                    &self.mesh,
                    "--orientation tangents: the file has no per-vertex tangents (glTF TANGENT)",
                ));
            }
            (text, _) => parse_orientation(text)?,
        };
        let maps = deformation_maps(&mesh, &orientation, self.smoothing, self.res as usize, self.tile_size)
            .map_err(|msg| Error::mesh(&self.mesh, msg))?;
        if maps.degenerate > 0 {
            eprintln!(
                "warning: {}: {} triangles are degenerate in 3D or in UV; their corners take their neighbours' values",
                self.mesh.display(),
                maps.degenerate
            );
        }
        // Slivers just beyond the edge are common in artists' UVs (Spot: 0.13%, the lat-long
        // smiley: 0.94%, whose excess wraps onto its own meridian); more is a layout error.
        if maps.outside_square > 0.01 {
            eprintln!(
                "warning: {}: {:.2}% of the UV area lies outside the unit square [0, 1]^2, which the F map spans: \
                 lookups there wrap into the square and read the field of another part of the surface",
                self.mesh.display(),
                100.0 * maps.outside_square
            );
        }
        let overlap = maps.overlap();
        if overlap.overlapped > 0 {
            eprintln!(
                "warning: {}: {:.2}% of the UV area is covered by more than one triangle (overlapping UV islands): \
                 the F map holds one deformation per texel, the unmirrored island's; a mirrored island on it reads it \
                 mirrored (exact for mirror-image halves under a mirror-symmetric orientation field), any other \
                 shares it as it is; --repack packs the charts apart, each with its own field",
                self.mesh.display(),
                100.0 * overlap.fraction()
            );
        }
        if maps.cuts.non_manifold > 0 {
            eprintln!(
                "warning: {}: {} edges have more than two faces; they are not treated as cuts",
                self.mesh.display(),
                maps.cuts.non_manifold
            );
        }
        let singular = maps.cuts.edges.iter().filter(|e| e.is_singular()).count();
        let banded: usize = maps.bands.curves().iter().map(|c| c.points().len() - 1).sum();
        if maps.cuts.edges.len() > banded && singular > 0 {
            eprintln!(
                "warning: {}: {} cut edges are UV singularities (fans around a pole, a dart's tip) that make cuts of \
                 their own; no band closes them, and the texture can show a seam there",
                self.mesh.display(),
                maps.cuts.edges.len() - banded
            );
        }
        let times = [loaded, start.elapsed().as_secs_f64() - loaded];
        Ok(Derived { mesh, repacked_scale, maps, orientation, times })
    }
}

/// Parse `triangles` or a number of rounds up to [`limits::MAX_DEFORM_SMOOTHING`].
fn parse_smoothing(text: &str) -> std::result::Result<Smoothing, String> {
    if text == "triangles" {
        return Ok(Smoothing::Triangles);
    }
    match text.parse::<usize>() {
        Ok(rounds) if rounds <= limits::MAX_DEFORM_SMOOTHING as usize => Ok(Smoothing::Vertices(rounds)),
        _ => Err(format!("expected `triangles` or a number of rounds from 0 to {}", limits::MAX_DEFORM_SMOOTHING)),
    }
}

/// Parse `uv`, `fixed:X,Y,Z`, `parallels:X,Y,Z` or `geodesic:X,Y,Z[;X,Y,Z...]`.
fn parse_orientation(text: &str) -> Result<Orientation> {
    let bad = || {
        Error::param(
            "--orientation",
            format!("'{text}': expected uv, fixed:X,Y,Z, parallels:X,Y,Z, geodesic:X,Y,Z[;X,Y,Z...] or tangents"),
        )
    };
    if text == "uv" {
        return Ok(Orientation::Uv);
    }
    let (kind, vectors) = text.split_once(':').ok_or_else(bad)?;
    let points = vectors
        .split(';')
        .map(|v| {
            let c: Vec<f32> =
                v.split(',').map(|x| x.trim().parse::<f32>()).collect::<std::result::Result<_, _>>().ok()?;
            let [x, y, z] = c[..] else { return None };
            Some(Vec3::new(x, y, z)).filter(|p| p.is_finite())
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(bad)?;
    let single = || match points[..] {
        [d] if d.length_squared() > 0.0 => Ok(d),
        _ => Err(bad()),
    };
    match kind {
        "fixed" => Ok(Orientation::Fixed(single()?)),
        "parallels" => Ok(Orientation::Parallels(single()?.normalize())),
        "geodesic" => Ok(Orientation::Geodesic(points)),
        _ => Err(bad()),
    }
}

/// The F map as the renderer reads it (`deformation = [{ type = "map" }]`).
fn f_map_field(maps: &DeformationMaps) -> DeformationField {
    DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))])
}

/// Print the distortion metric, classical against deformed.
fn print_distortion(classical: Option<Distortion>, deformed: Option<Distortion>) {
    if let (Some(c), Some(d)) = (classical, deformed) {
        println!(
            "distortion over {} triangles (area-weighted): mean sigma_max/sigma_min classical {:.3}, deformed {:.3}; \
             std of ln(sigma_1 sigma_2) classical {:.3}, deformed {:.3}",
            c.triangles, c.mean_anisotropy, d.mean_anisotropy, c.std_log_area, d.std_log_area
        );
    }
}

/// `tessera deform`.
pub fn deform(args: &MeshArgs, output: &Path) -> Result<ExitCode> {
    let Derived { mesh, repacked_scale, maps, times: [loaded, computed], .. } = args.maps()?;
    // (`analyze` prints the fold-over among its figures.)
    let charts = maps.chart_of_texels();
    let fold = analysis::fold_over(&maps.f_map, &maps.coverage, &charts, args.tile_size, FieldAt::Point);
    if fold.folded > 0.01 {
        // Tiles that read F at their centres are affine, and fold only where they fall back to
        // F(u): no point of the texel's chart within a tile's reach of the centre, or islands
        // that overlap. Say how much, rather than never.
        let centres = analysis::fold_over(&maps.f_map, &maps.coverage, &charts, args.tile_size, FieldAt::TileCentre);
        eprintln!(
            "warning: {}: tiles of {} fold their lookups F(u)(u - c) on {:.1}% of the texels (F varies across a tile \
             faster than a tile can follow: the texture tears there); smaller tiles fold less, and tiles that read F \
             at their centres (field_at = \"tile_centre\", with charts = \"charts.exr\") fold on {:.1}%",
            args.mesh.display(),
            args.tile_size,
            100.0 * fold.folded,
            100.0 * centres.folded
        );
    }
    // All six files or none: a failure halfway leaves the folder as it was.
    let staged = StagedFolder::new(output)?;
    let write_map = |name: &str, map: &tessera::image::Bitmap| {
        let plane = |c: usize| map.data.iter().skip(c).step_by(4).copied().collect::<Vec<f32>>();
        let channels = ["R", "G", "B", "A"].iter().enumerate().map(|(c, name)| (name.to_string(), plane(c))).collect();
        write_exr(&staged.path().join(name), map.width, map.height, channels)
    };
    write_map("f_map.exr", &maps.f_map)?;
    let chart_map = tessera::deform::chart_map_of(maps.raster.res, &charts);
    write_exr(
        &staged.path().join("charts.exr"),
        chart_map.width,
        chart_map.height,
        vec![("Y".into(), chart_map.data)],
    )?;
    let cuts_file = staged.path().join("cuts.json");
    std::fs::write(&cuts_file, cuts_to_json(maps.bands.curves())).map_err(|e| Error::io(&cuts_file, e))?;
    let (det, orientation_picture) = tessera::deform::f_map_pictures(&maps.f_map);
    write_image(&staged.path().join("det_f.png"), &det, &[])?;
    write_image(&staged.path().join("orientation.png"), &orientation_picture, &[])?;
    write_image(&staged.path().join("cut_bands.png"), &tessera::deform::bands_picture(&maps.bands, &maps.f_map), &[])?;
    if repacked_scale.is_some() {
        let comment = format!("{} with its UV charts packed apart by tessera deform --repack", args.mesh.display());
        let obj = staged.path().join("mesh.obj");
        std::fs::write(&obj, obj_text(&mesh, &comment)).map_err(|e| Error::io(&obj, e))?;
    }
    staged.commit()?;
    let field = f_map_field(&maps);
    print_distortion(distortion(&mesh, |_| Mat2::IDENTITY), distortion(&mesh, |uv| field.at(uv)));
    let res = args.res;
    eprintln!(
        "{}: {} triangles ({} mirrored in UV) in {}, smoothing {} ({} texels outside every triangle, \
         extrapolated from the nearest), \
         {} in {} (bands for tile size {}), maps {res}x{res}; load {loaded:.2} s, deform {computed:.2} s; \
         wrote f_map.exr, charts.exr, cuts.json, det_f.png, orientation.png, cut_bands.png{} to {}",
        args.mesh.display(),
        mesh.indices.len(),
        maps.mirrored,
        counted(maps.field.charts, "chart"),
        match args.smoothing {
            Smoothing::Triangles => "none (each triangle's own F)".to_string(),
            Smoothing::Vertices(rounds) => format!("per chart, {}", counted(rounds, "round")),
        },
        maps.raster.filled,
        counted(maps.cuts.edges.len(), "cut edge"),
        counted(maps.cuts.chains.len(), "cut"),
        args.tile_size,
        if repacked_scale.is_some() { ", mesh.obj" } else { "" },
        output.display(),
    );
    if let Some(scale) = repacked_scale {
        eprintln!(
            "packed the {} apart at {scale:.4} times their UV size and wrote that mesh as mesh.obj: render it with \
             these maps (the texture keeps its size on the surface; a tile_size in UV units spans 1/{scale:.4} times \
             the length on the surface it spanned on the original UVs: multiply it by {scale:.4} to keep the tiles)",
            counted(maps.field.charts, "chart")
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// "1 chart", "5 charts".
fn counted(n: usize, noun: &str) -> String {
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}

/// `tessera analyze`: the figures of [`tessera::deform::analysis`], as text or JSON.
pub fn analyze(args: &MeshArgs, exemplar_path: &Path, seed: u64, samples: usize, json: bool) -> Result<ExitCode> {
    let Derived { mesh, repacked_scale, maps, orientation, .. } = args.maps()?;
    if let Some(scale) = repacked_scale {
        eprintln!("note: the mesh's UV charts packed apart at {scale:.4} times their size (--repack)");
    }
    let bitmap = read_bitmap(exemplar_path, ColorSpace::Srgb)?;
    let exemplar = Arc::new(Texture::Image(ImageTexture {
        mipmap: Arc::new(MipMap::new(bitmap)),
        filter: Filter::None,
        scale: glam::Vec2::ONE,
        offset: glam::Vec2::ZERO,
    }));
    let input = AnalysisInput {
        mesh: &mesh,
        maps: &maps,
        orientation: &orientation,
        exemplar,
        tile_size: args.tile_size,
        seed,
        samples,
    };
    let a = tessera::deform::analyze(&input).map_err(|msg| Error::mesh(&args.mesh, msg))?;
    if json {
        let text = serde_json::to_string_pretty(&a).map_err(|e| Error::param("--json", e.to_string()))?;
        println!("{text}");
        return Ok(ExitCode::SUCCESS);
    }
    print_distortion(a.distortion_classical, a.distortion_deformed);
    match a.seams {
        None => println!("seams: the mesh has no UV cuts"),
        Some(s) => {
            if a.seam_samples < samples {
                eprintln!(
                    "note: {} cut edges: {} point pairs per edge (at most {} in all)",
                    a.cut_edges,
                    a.seam_samples,
                    limits::MAX_SEAM_SAMPLES
                );
            }
            // Ordinary cuts, then UV singularities (pole fans, darts) where the mesh has them.
            let f = |s: analysis::SeamFigures| {
                let figure =
                    |s: Option<analysis::Seams>| s.map_or("n/a".to_string(), |s| format!("{:.4}", s.normalised));
                match s.singular {
                    None => figure(s.ordinary),
                    Some(_) => format!("{} (singular cuts {})", figure(s.ordinary), figure(s.singular)),
                }
            };
            println!(
                "seams over {} cut edges in {} cuts (mean |T_left - T_right| over that of independent point pairs; \
                 hexagonal tiles of {}, linear blending): classical {}; deformed {}, deformed with cut bands {}",
                a.cut_edges,
                a.cuts,
                args.tile_size,
                f(s.classical),
                f(s.deformed),
                f(s.deformed_bands)
            );
        }
    }
    let angles = |e: Option<analysis::AngleError>| {
        e.map_or("n/a".to_string(), |e| format!("mean {:.2} degrees, 95th percentile {:.2}", e.mean, e.p95))
    };
    if a.orientation_error.is_some() {
        println!(
            "orientation error (the texture's x axis J F^-1 e1 against the orientation field, area-weighted): \
             classical {}; deformed {}",
            angles(a.orientation_error_classical),
            angles(a.orientation_error)
        );
    }
    if let Some(jumps) = a.frame_jumps {
        println!(
            "frame jumps (the angle between the texture's x axis on an edge's two faces, unfolded, edge-length \
             weighted): across cuts {}; inside charts {}",
            angles(jumps.cuts),
            angles(jumps.interior)
        );
    }
    if let Some(b) = a.continuity_bound {
        println!(
            "what no F continuous in UV can beat, over {} edges inside charts (J_B J_A^-1 across each edge, \
             edge-length weighted): orientation error on the worse face {}; anisotropy on the worse face mean {:.3}; \
             ln area jumps by {:.3} (rms)",
            b.edges,
            angles(b.orientation),
            b.anisotropy,
            b.log_area_jump
        );
    }
    if let Some(v) = a.lattice_visibility {
        println!(
            "lattice visibility (power at the paving's lattice frequencies over the exemplar's there, classical \
             synthesis, four seeds; about 1 for a stationary exemplar): {v:.2}"
        );
    }
    println!(
        "fold-over of the tiles' lookups, tile centres {} away, over {} texels: F(u)(u - c) (field_at = \"point\") \
         {:.3}% fold, {:.3}% stretch beyond 2:1; F(c)(u - c) (\"tile_centre\") {:.3}% fold, {:.3}% stretch; \
         UV area covered more than once: {:.3}%",
        args.tile_size,
        a.fold_over.texels,
        100.0 * a.fold_over.folded,
        100.0 * a.fold_over.stretched,
        100.0 * a.fold_over_at_centres.folded,
        100.0 * a.fold_over_at_centres.stretched,
        100.0 * a.uv_overlap
    );
    Ok(ExitCode::SUCCESS)
}
