//! Continuity across UV cuts (paper 000 Sec. 5, Eq. 8): the cut edges and boundary cells of a
//! mesh, the cut map, and the seam metric mean |T_left - T_right| / std(exemplar) with Eq. 8 on
//! and off, on a cylinder whose UV seam is known exactly.

mod common;

use glam::{Vec2, Vec3};
use std::path::Path;
use std::sync::Arc;
use tessera::deform::{DeformationMaps, Orientation, channel_std, deformation_maps, seam_metric};
use tessera::geometry::TriangleMesh;
use tessera::image::{ColorSpace, read_bitmap};
use tessera::texture::tiling_blending::{Blend, CutMap, Deformation, DeformationField, PriorityMap, Synthesis, Tiling};
use tessera::texture::{Filter, ImageTexture, MipMap, TexCtx, Texture, TilingBlending};

const TILE: f32 = 0.25;

/// A closed tube of radius 0.3 about y (height 0.6), unrolled isometrically up to scale into a
/// `width` x `height` rectangle centred in the UV square and turned by `angle` radians. The
/// column at angle 0 around the tube is duplicated: that is the cut, its right copy the left
/// one moved by `width` along the turned u axis.
fn tube(width: f32, height: f32, angle: f32) -> TriangleMesh {
    let (segments, rows) = (32, 12);
    let turn = Vec2::from_angle(angle);
    let mut mesh = TriangleMesh::default();
    let mut uvs = Vec::new();
    for k in 0..=segments {
        let a = std::f32::consts::TAU * (k % segments) as f32 / segments as f32;
        for r in 0..=rows {
            let t = r as f32 / rows as f32;
            mesh.positions.push(Vec3::new(0.3 * a.cos(), 0.6 * t, -0.3 * a.sin()));
            let flat = Vec2::new(width * (k as f32 / segments as f32 - 0.5), height * (t - 0.5));
            uvs.push(Vec2::splat(0.5) + turn.rotate(flat));
        }
    }
    mesh.indices = common::grid_triangles(segments, rows);
    mesh.uvs = Some(uvs);
    mesh
}

fn maps(mesh: &TriangleMesh, tile: f32) -> DeformationMaps {
    deformation_maps(mesh, &Orientation::Parallels(Vec3::Y), 32, 512, tile).unwrap()
}

/// The bark exemplar (point lookups) and its channels' standard deviations, read once.
fn bark() -> &'static (Arc<Texture>, Vec3) {
    static BARK: std::sync::OnceLock<(Arc<Texture>, Vec3)> = std::sync::OnceLock::new();
    BARK.get_or_init(|| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/textures/bark.jpg");
        let bitmap = read_bitmap(&path, ColorSpace::Srgb).unwrap();
        let spread = channel_std(&bitmap);
        let texture = ImageTexture {
            mipmap: Arc::new(MipMap::new(bitmap)),
            filter: Filter::None,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        };
        (Arc::new(Texture::Image(texture)), spread)
    })
}

/// Deformed T&B with the maps' F, with or without Eq. 8.
fn texture(maps: &DeformationMaps, tile: f32, blend: Blend, eq8: bool) -> TilingBlending {
    let synthesis = Synthesis {
        tiling: Tiling::Hexagonal,
        tile_size: tile,
        seed: 11,
        deformation: Some(DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))])),
        cuts: eq8.then(|| CutMap::new(&maps.cut_map).unwrap()),
        blend,
        inset: false,
    };
    TilingBlending::new(Arc::new(synthesis), bark().0.clone()).unwrap()
}

fn seams(maps: &DeformationMaps, tile: f32, blend: Blend, eq8: bool) -> f64 {
    seam_metric(&maps.cuts, &texture(maps, tile, blend, eq8), bark().1, 16).unwrap()
}

fn blends() -> Vec<(&'static str, Blend)> {
    let Texture::Image(image) = bark().0.as_ref().clone() else { unreachable!() };
    vec![
        ("linear", Blend::Linear),
        ("variance-preserving", Blend::VariancePreserving),
        ("histogram-preserving", Blend::HistogramPreserving),
        ("mix-max", Blend::MixMax { priority: PriorityMap::new(&image), contrast: 4.0, lambda: 0.05 }),
    ]
}

#[test]
fn the_seam_of_a_tube_is_found_and_split_into_cells_longer_than_a_tile() {
    let mesh = tube(0.9, 0.9, 0.0);
    let m = maps(&mesh, TILE);
    // One cut: the 12 edges of the duplicated column.
    assert_eq!(m.cuts.edges.len(), 12);
    for (e, edge) in m.cuts.edges.iter().enumerate() {
        // Left and right consistent within the cell: the right copy is the left moved by +-0.9.
        let cell = m.cuts.cell_of_edge[e] as usize;
        let shift = m.cuts.cells[cell].centres[1] - m.cuts.cells[cell].centres[0];
        for k in 0..2 {
            assert!((edge.sides[1][k] - edge.sides[0][k] - shift).length() < 1e-5, "edge {e}: {edge:?}");
        }
        assert!((shift.x.abs() - 0.9).abs() < 1e-5 && shift.y.abs() < 1e-5, "{shift}");
    }
    // A cut 0.9 long with tiles of diameter 0.5: cells of at least 0.5, so one or two.
    assert!(!m.cuts.cells.is_empty() && m.cuts.cells.len() <= 2, "{:?}", m.cuts.cells);
    assert!(m.cuts.cells.iter().all(|c| c.lengths[0] > 2.0 * TILE - 1e-5 && c.lengths[1] > 2.0 * TILE - 1e-5));
    // The centres are midpoints of the same edge on the two sides.
    for cell in &m.cuts.cells {
        let on_edge = m.cuts.edges.iter().any(|e| {
            (e.point(0, 0.5) - cell.centres[0]).length() < 1e-6 && (e.point(1, 0.5) - cell.centres[1]).length() < 1e-6
        });
        assert!(on_edge, "{cell:?}");
    }
}

#[test]
fn the_cut_map_names_the_nearest_side_within_the_band() {
    let mesh = tube(0.9, 0.9, 0.0);
    let m = maps(&mesh, TILE);
    let cuts = CutMap::new(&m.cut_map).unwrap();
    let cell_at = |uv: Vec2| cuts.at(uv);
    for v in [0.1, 0.5, 0.9] {
        // Just right of the left copy (u = 0.05) and left of the right copy (u = 0.95).
        let left = cell_at(Vec2::new(0.1, v)).expect("in the left band");
        let right = cell_at(Vec2::new(0.9, v)).expect("in the right band");
        assert_eq!(left.cell, right.cell);
        assert!((right.centre - left.centre - Vec2::new(0.9, 0.0)).length() < 1e-5);
        // Tiles centred outside the square belong to the side at its border.
        assert_eq!(cell_at(Vec2::new(-0.1, v)), Some(left));
        // Beyond the band (sqrt 2 tile sizes from either copy): no cell.
        assert_eq!(cell_at(Vec2::new(0.5, v)), None);
    }
}

#[test]
fn eq8_makes_a_seam_within_one_cell_continuous_for_every_operator() {
    // A cut 0.4 long (shorter than a tile's diameter): a single cell, and the two sides 0.9
    // apart, which is not a lattice vector, so that without Eq. 8 they blend unrelated tiles.
    let m = maps(&tube(0.9, 0.4, 0.0), TILE);
    assert_eq!(m.cuts.cells.len(), 1);
    for (name, blend) in blends() {
        let off = seams(&m, TILE, blend.clone(), false);
        let on = seams(&m, TILE, blend, true);
        eprintln!("{name}: seam metric without Eq. 8 {off:.4}, with {on:.6}");
        assert!(on < 0.01, "{name}: {on}");
        assert!(off > 0.4, "{name}: {off}");
    }
}

/// Tiles of 0.1: a cut 0.9 long is split into 4 cells.
const SMALL_TILE: f32 = 0.1;

/// The seam metric without and with Eq. 8 (linear blending, small tiles) on `mesh`, which must
/// give `cells` boundary cells.
fn seams_off_and_on(mesh: &TriangleMesh, cells: usize, what: &str) -> (f64, f64) {
    let m = maps(mesh, SMALL_TILE);
    assert_eq!(m.cuts.cells.len(), cells, "{:?}", m.cuts.cells);
    let off = seams(&m, SMALL_TILE, Blend::Linear, false);
    let on = seams(&m, SMALL_TILE, Blend::Linear, true);
    eprintln!("{what}, {cells} cells: without Eq. 8 {off:.4}, with {on:.6}");
    (off, on)
}

#[test]
fn eq8_makes_a_lattice_aligned_seam_continuous_across_cells() {
    // The lat-long layout: the sides 1 apart (10 lattice spacings), so both sides see the same
    // paving weights, also where cells meet.
    let (off, on) = seams_off_and_on(&tube(1.0, 0.9, 0.0), 4, "lattice-aligned seam");
    assert!(on < 0.01 && off > 0.4, "{on} {off}");
}

#[test]
fn eq8_lowers_seams_where_cells_meet() {
    // A turned chart: the sides are not a lattice vector apart, nor along a lattice row, so
    // where two cells meet the paving weighs their tiles differently on the two sides, a limit
    // of Sec. 5's method that the note reports.
    let (off, on) = seams_off_and_on(&tube(0.6, 0.6, 0.3), 2, "turned seam");
    assert!(on < 0.5 * off, "{on} {off}");
}

#[test]
fn eq8_keeps_the_texture_continuous_inside_a_chart() {
    // Walk across the bands' edges and the cells' boundaries: Eq. 8 changes tiles by their
    // centres only, so the texture must not jump. The largest change between consecutive points
    // shrinks with the step where the texture is continuous (bilinear lookups: linearly) and
    // not at a jump.
    let m = maps(&tube(0.6, 0.6, 0.3), SMALL_TILE);
    let t = texture(&m, SMALL_TILE, Blend::Linear, true);
    let at = |uv: Vec2| t.eval(&TexCtx { uv, ..Default::default() }).truncate();
    let worst_step = |start: Vec2, direction: Vec2, step: f32| {
        let mut worst = 0.0f32;
        for k in 0..(0.8 / step) as usize {
            let uv = start + direction * (k as f32 * step);
            worst = worst.max((at(uv + direction * step) - at(uv)).abs().max_element());
        }
        worst
    };
    for (start, direction) in [(Vec2::new(0.1, 0.45), Vec2::X), (Vec2::new(0.3, 0.1), Vec2::Y)] {
        let coarse = worst_step(start, direction, 4e-5);
        let fine = worst_step(start, direction, 1e-5);
        assert!(fine < 0.5 * coarse, "from {start} along {direction}: {coarse} at step 4e-5, {fine} at 1e-5");
    }
}

#[test]
fn analyze_reports_the_normalised_seams_with_and_without_eq8_as_json() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tube.obj"), common::obj_text(&tube(0.9, 0.4, 0.0))).unwrap();
    let run = |json: bool| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"));
        command
            .arg("analyze")
            .arg(dir.path().join("tube.obj"))
            .arg("--exemplar")
            .arg(common::repo().join("scenes/textures/bark.jpg"))
            .args(["--orientation", "parallels:0,1,0", "--grid", "32"]);
        if json {
            command.arg("--json");
        }
        let out = command.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let text = run(false);
    assert!(text.contains("deformed with Eq. 8") && text.contains("orientation error"), "{text}");
    let figures: serde_json::Value = serde_json::from_str(&run(true)).unwrap();
    let number = |path: &[&str]| -> f64 {
        path.iter().fold(&figures, |v, key| &v[*key]).as_f64().unwrap_or_else(|| panic!("{path:?} in {figures}"))
    };
    // Independent sides read about as differently as unrelated points; Eq. 8 closes the seam.
    assert!(number(&["seams", "deformed_eq8", "ordinary", "normalised"]) < 0.01, "{figures}");
    let open = number(&["seams", "deformed", "ordinary", "normalised"]);
    assert!((0.6..1.4).contains(&open), "{figures}");
    assert!(number(&["distortion_deformed", "mean_anisotropy"]) < 1.05, "{figures}");
    assert!(number(&["distortion_classical", "mean_anisotropy"]) > 1.2, "{figures}");
    // The tube is developable and the parallels are its circles: the texture follows them.
    assert!(number(&["orientation_error", "mean"]) < 1.0, "{figures}");
    assert_eq!(number(&["uv_overlap"]), 0.0);
    // A tube has no UV singularity.
    assert!(figures["seams"]["deformed"]["singular"].is_null(), "{figures}");
}

#[test]
fn inset_keeps_the_tiles_of_a_cell_inside_the_exemplar() {
    // tileable = false: a cell's tiles, which read the exemplar up to a cell away from their
    // centre b_l, must stay inside its square wherever they weigh, on both sides of the cut,
    // for every shift h_l (one per seed: the tube has one cell).
    let m = maps(&tube(0.9, 0.4, 0.0), TILE);
    assert_eq!(m.cuts.cells.len(), 1);
    let cuts = CutMap::new(&m.cut_map).unwrap();
    let mut cell_tiles = 0;
    for seed in 0..64 {
        let field = vec![
            Deformation::Constant(glam::Mat2::from_diagonal(Vec2::splat(0.2))),
            Deformation::Map(MipMap::new(m.f_map.clone())),
        ];
        let synthesis = Synthesis {
            tiling: Tiling::Hexagonal,
            tile_size: TILE,
            seed,
            deformation: Some(DeformationField::new(field)),
            cuts: Some(cuts.clone()),
            blend: Blend::Linear,
            inset: true,
        };
        for i in 0..50 {
            for j in 0..20 {
                let uv = Vec2::new(i as f32 / 50.0, 0.3 + 0.4 * j as f32 / 20.0);
                let tiles = Tiling::Hexagonal.tiles(uv, TILE);
                let lookups = synthesis.lookups(&TexCtx { uv, ..Default::default() });
                for (tile, lookup) in tiles.iter().zip(&lookups).take(3) {
                    if lookup.weight > 0.0 && cuts.at(tile.centre).is_some() {
                        cell_tiles += 1;
                        let x = lookup.ctx.uv;
                        assert!(
                            x.cmpge(Vec2::ZERO).all() && x.cmple(Vec2::ONE).all(),
                            "seed {seed} at {uv}: reads {x}"
                        );
                    }
                }
            }
        }
    }
    assert!(cell_tiles > 10_000, "{cell_tiles}");
}

#[test]
fn pole_fans_are_singular_cuts_and_a_meridian_is_an_ordinary_one() {
    // The lat-long icosphere: its meridian seam runs between two copies of u = 0 and 1, and the
    // fans at its poles open from one UV point.
    let (mesh, _) = tessera::scene::load_surface(&common::repo().join("scenes/meshes/smiley.obj")).unwrap();
    let cuts = tessera::deform::Cuts::new(&mesh, 0.2);
    let singular: Vec<_> = cuts.edges.iter().filter(|e| e.is_singular()).collect();
    assert!(!singular.is_empty() && singular.len() < cuts.edges.len(), "{} of {}", singular.len(), cuts.edges.len());
    for edge in &cuts.edges {
        // A meridian edge has its sides a whole period apart in u; a fan edge shares an end.
        let apart =
            (edge.sides[0][0].x - edge.sides[1][0].x).abs().min((edge.sides[0][1].x - edge.sides[1][1].x).abs());
        assert_eq!(edge.is_singular(), apart < 1e-6, "{edge:?}");
    }
    assert!(maps(&tube(0.9, 0.4, 0.0), 0.25).cuts.edges.iter().all(|e| !e.is_singular()));
}
