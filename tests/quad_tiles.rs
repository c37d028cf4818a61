//! Paper 001's invariants: in a synthesised tile image every tile edge holds the texels of its
//! type, which its complementary type holds in reverse; along every edge of a mapped quad mesh
//! the two quads show the same colours (before and after subdivision, at vertices of valence 3
//! to 7); the rotation convention, worked by hand.

mod common;

use glam::{Vec2, Vec3, Vec4};
use tessera::geometry::{QuadMesh, Topology, catmull_clark, load_quad_obj};
use tessera::image::{Bitmap, ColorSpace, read_bitmap, write_png};
use tessera::texture::{Filter, MipMap, QuadTilesTexture, TexCtx};
use tessera::tiles::synthesis::rotate_texel;
use tessera::tiles::{
    PixelRect, TileLayout, TileName, TileTemplates, assign_boundaries, assign_tiles, complementary, synthesize_tiles,
    texture_coordinates,
};

fn photograph() -> Bitmap {
    read_bitmap(&common::repo().join("scenes/textures/rocks_basecolor.jpg"), ColorSpace::Srgb).unwrap()
}

fn tile_image(conditions: u32, res: u32, seed: u64) -> (Bitmap, TileLayout) {
    let image = photograph();
    let layout = TileLayout::new(conditions, res).unwrap();
    let templates = TileTemplates::new(&image, conditions, &[], None).unwrap();
    (synthesize_tiles(&image, &templates, &layout, seed), layout)
}

/// The texels along edge `k` of tile `name`, read counter-clockwise.
fn edge_texels(atlas: &Bitmap, layout: &TileLayout, name: TileName, k: usize) -> Vec<Vec4> {
    let res = layout.tile_res();
    (0..res)
        .map(|i| {
            let (x, y) = rotate_texel(k, i, 0, res);
            let (ix, iy) = layout.texel(name, x as isize, y as isize);
            atlas.pixel(ix, iy)
        })
        .collect()
}

/// Every edge of every tile against the first edge of its type; each type against its
/// complement reversed; the guard band against the edge texels it repeats.
fn check_edges(atlas: &Bitmap, layout: &TileLayout) {
    let res = layout.tile_res();
    let mut reference: Vec<Option<Vec<Vec4>>> = vec![None; layout.edge_types() as usize];
    for name in layout.names() {
        for k in 0..4 {
            let texels = edge_texels(atlas, layout, name, k);
            let slot = &mut reference[name.0[k] as usize];
            match slot {
                Some(r) => assert_eq!(&texels, r, "tile {name} edge {k}"),
                None => *slot = Some(texels),
            }
        }
        let g = layout.guard() as isize;
        for i in 0..res as isize {
            let edge = atlas.pixel(layout.texel(name, i, 0).0, layout.texel(name, i, 0).1);
            let (gx, gy) = layout.texel(name, i, -g);
            assert_eq!(atlas.pixel(gx, gy), edge, "tile {name}: guard band below texel {i}");
        }
    }
    let reference: Vec<Vec<Vec4>> = reference.into_iter().map(|r| r.expect("every type is used")).collect();
    for (t, texels) in reference.iter().enumerate() {
        let partner = &reference[complementary(t as u8) as usize];
        let reversed: Vec<Vec4> = partner.iter().rev().copied().collect();
        assert_eq!(texels, &reversed, "type {t} against its complement");
        // Every tile corner shows the same texel.
        assert_eq!(texels[0], reference[0][0]);
    }
    // The edges are not trivially constant.
    let spread = reference[0].iter().map(|v| (*v - reference[0][0]).abs().max_element()).fold(0.0, f32::max);
    assert!(spread > 0.05, "edge texels vary by {spread} only");
}

#[test]
fn every_tile_edge_matches_its_partner_type_texel_for_texel() {
    let (atlas, layout) = tile_image(1, 48, 1);
    check_edges(&atlas, &layout);
    // Through an 8-bit PNG too.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tiles.png");
    write_png(&path, &atlas).unwrap();
    check_edges(&read_bitmap(&path, ColorSpace::Srgb).unwrap(), &layout);
}

#[test]
fn two_conditions_give_256_tiles_with_the_same_edge_guarantee() {
    let (atlas, layout) = tile_image(2, 16, 2);
    assert_eq!(layout.tile_count(), 256);
    assert_eq!(atlas.width, 16 * 18);
    check_edges(&atlas, &layout);
}

/// Quad `f`'s texture coordinates at parameter `t` along its side `k`.
fn along(uvs: &[[Vec2; 4]], f: usize, k: usize, t: f32) -> Vec2 {
    let c = &uvs[f];
    c[k].lerp(c[(k + 1) % 4], t)
}

/// The largest colour difference between the two sides of any interior edge, at 16 points per
/// edge, read through `lookup`.
fn largest_edge_jump(mesh: &QuadMesh, topology: &Topology, lookup: &dyn Fn(Vec2) -> Vec4) -> f32 {
    let uvs = mesh.uvs.as_ref().unwrap();
    let mut largest = 0.0f32;
    for e in 0..topology.edge_count() {
        let &[a, b] = topology.halves(e) else { continue };
        let (a, b) = (a as usize, b as usize);
        for m in 0..16 {
            let t = (m as f32 + 0.5) / 16.0;
            let from_a = lookup(along(uvs, topology.face_of(a), topology.side_of(a), t));
            // The other quad walks the edge the other way.
            let from_b = lookup(along(uvs, topology.face_of(b), topology.side_of(b), 1.0 - t));
            largest = largest.max((from_a - from_b).abs().max_element());
        }
    }
    largest
}

fn valences(mesh: &QuadMesh, topology: &Topology) -> (u32, u32) {
    let mut valence = vec![0u32; mesh.positions.len()];
    for e in 0..topology.edge_count() {
        for v in topology.edge_vertices(e) {
            valence[v as usize] += 1;
        }
    }
    (*valence.iter().min().unwrap(), *valence.iter().max().unwrap())
}

/// Blub (valences 3 to 7) and the cube (3 everywhere): the tile texture, read tile by tile
/// and as a plain image (as any OBJ viewer reads it), is continuous across every edge before
/// and after two rounds of Catmull-Clark subdivision. A control with the corners given in the
/// wrong order shows jumps, so the check can fail.
#[test]
fn mapped_quad_meshes_show_identical_colours_across_every_edge() {
    let (atlas, layout) = tile_image(1, 32, 3);
    let texture = QuadTilesTexture::new(&atlas, 1, Filter::None).unwrap();
    let whole = MipMap::new(atlas.clone());
    let by_tile = |uv: Vec2| texture.eval(&TexCtx { uv, ..Default::default() });
    let as_image = |uv: Vec2| whole.bilinear(0, Vec2::new(uv.x, 1.0 - uv.y));
    let blub = load_quad_obj(&common::repo().join("scenes/meshes/blub.obj")).unwrap();
    let cube = QuadMesh::new(
        (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)).collect(),
        vec![[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]],
    )
    .unwrap();
    for (name, mut mesh, valence) in [("blub", blub, (3, 7)), ("cube", cube, (3, 3))] {
        let (topology, _) = mesh.topology().unwrap();
        assert_eq!(valences(&mesh, &topology), valence, "{name}");
        let tiles = assign_tiles(&topology, &assign_boundaries(&topology, 1, 11));
        mesh.uvs = Some(texture_coordinates(&layout, &tiles));
        let mut topology = topology;
        for round in 0..3 {
            for (how, lookup) in [("by tile", &by_tile as &dyn Fn(Vec2) -> Vec4), ("as an image", &as_image)] {
                let jump = largest_edge_jump(&mesh, &topology, lookup);
                println!("{name}, {round} subdivisions, {} quads, {how}: largest jump {jump:e}", mesh.quads.len());
                assert!(jump < 1e-5, "{name}, {round} subdivisions, {how}: colours jump by {jump} across an edge");
            }
            mesh = catmull_clark(&mesh, &topology);
            topology = mesh.topology().unwrap().0;
        }
    }
    // The control: every quad's corners shifted by one (a tile turned within its quad).
    let mut control = load_quad_obj(&common::repo().join("scenes/meshes/blub.obj")).unwrap();
    let (topology, _) = control.topology().unwrap();
    let tiles = assign_tiles(&topology, &assign_boundaries(&topology, 1, 11));
    control.uvs = Some(texture_coordinates(&layout, &tiles).into_iter().map(|c| [c[1], c[2], c[3], c[0]]).collect());
    let control_jump = largest_edge_jump(&control, &topology, &by_tile);
    println!("control (corners shifted by one): largest jump {control_jump}");
    assert!(control_jump > 0.05);
}

/// The convention pinned by hand on tile 1001 (Sec. 4's example): an image whose boundary
/// template is red above the boundary and blue below, and whose background is green. Type 0
/// (0XXX, the upper square) shows red beside its edge and type 1 (the lower square turned by
/// 180 degrees) blue; the name reads counter-clockwise from the bottom edge: bottom 1 (blue),
/// right 0 (red), top 0 (red), left 1 (blue); the centre shows the background.
#[test]
fn tile_1001_worked_by_hand() {
    let (w, h) = (128, 128);
    let mut image = Bitmap::new(w, h, 3);
    for y in 0..h {
        for x in 0..w {
            let c = if x >= 64 {
                [0.0, 1.0, 0.0]
            } else if y < 64 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            };
            image.values_mut(x, y).copy_from_slice(&c);
        }
    }
    let templates = TileTemplates::new(
        &image,
        1,
        &[PixelRect { x: 0, y: 0, width: 64, height: 128 }],
        Some(PixelRect { x: 64, y: 0, width: 64, height: 128 }),
    )
    .unwrap();
    let layout = TileLayout::new(1, 32).unwrap();
    let atlas = synthesize_tiles(&image, &templates, &layout, 0);
    let name = TileName([1, 0, 0, 1]);
    let at = |i: isize, j: isize| {
        let (x, y) = layout.texel(name, i, j);
        atlas.pixel(x, y).truncate()
    };
    let (red, green, blue) = (Vec3::X, Vec3::Y, Vec3::Z);
    let close = |a: Vec3, b: Vec3| a.abs_diff_eq(b, 1e-4);
    assert!(close(at(16, 2), blue), "bottom: {}", at(16, 2));
    assert!(close(at(29, 16), red), "right: {}", at(29, 16));
    assert!(close(at(16, 29), red), "top: {}", at(16, 29));
    assert!(close(at(2, 16), blue), "left: {}", at(2, 16));
    assert!(close(at(16, 16), green), "centre: {}", at(16, 16));
    // The same tile turned a quarter counter-clockwise is tile 1100, whose texels are its
    // texels moved by rotate_texel: (i, j) -> (R - 1 - j, i). Hand-checked on a 3 x 3 square.
    assert_eq!(name.rotated_ccw(), TileName([1, 1, 0, 0]));
    assert_eq!(rotate_texel(1, 0, 0, 3), (2, 0));
    assert_eq!(rotate_texel(1, 2, 0, 3), (2, 2));
    assert_eq!(rotate_texel(1, 0, 1, 3), (1, 0));
    assert_eq!(rotate_texel(3, 2, 0, 3), (0, 0));
}

#[test]
fn bad_tile_inputs_are_clear_errors() {
    let tiny = TileTemplates::new(&Bitmap::new(3, 3, 3), 1, &[], None).unwrap_err();
    assert!(tiny.contains("too small"), "{tiny}");
    let not_stacked =
        TileTemplates::new(&Bitmap::new(256, 256, 3), 1, &[PixelRect { x: 0, y: 0, width: 64, height: 64 }], None);
    assert!(not_stacked.unwrap_err().contains("two stacked squares"));
    let outside =
        TileTemplates::new(&Bitmap::new(256, 256, 3), 1, &[PixelRect { x: 200, y: 0, width: 64, height: 128 }], None);
    assert!(outside.unwrap_err().contains("outside"));
    let wrong_size = QuadTilesTexture::new(&Bitmap::new(100, 100, 3), 1, Filter::None).unwrap_err();
    assert!(wrong_size.contains("not a tile image"), "{wrong_size}");
}

/// No filter mixes tiles: a tile image whose every tile (guard band included) is one flat
/// colour, read with footprints from a fraction of a texel to wider than the whole image, gives
/// each tile's own colour at every point of it, near its edges and corners too. A plain image
/// texture of the same file does mix them at coarse levels (the control).
#[test]
fn filtered_lookups_never_mix_tiles_at_any_mip_level() {
    let layout = TileLayout::new(1, 32).unwrap();
    let side = layout.image_side();
    let mut atlas = Bitmap::new(side, side, 3);
    let colour = |name: TileName| {
        let i = layout.index_of(name) as f32;
        Vec3::new(i / 15.0, 1.0 - i / 15.0, (i * 7.0 % 16.0) / 15.0)
    };
    for name in layout.names() {
        let g = layout.guard() as isize;
        for j in -g..32 + g {
            for i in -g..32 + g {
                let (x, y) = layout.texel(name, i, j);
                atlas.values_mut(x, y).copy_from_slice(&colour(name).to_array());
            }
        }
    }
    let whole = MipMap::new(atlas.clone());
    let mut control_mixes = false;
    for filter in [Filter::Trilinear, Filter::Ewa] {
        let texture = QuadTilesTexture::new(&atlas, 1, filter).unwrap();
        for name in layout.names() {
            for (s, t) in [(0.0, 0.0), (0.5, 0.5), (1.0, 0.3), (0.02, 0.98), (1.0, 1.0)] {
                let c = layout.corner_uv(name, 0);
                let uv = c + (layout.corner_uv(name, 2) - c) * Vec2::new(s, t);
                for width in [1e-4, 1e-2, 0.1, 1.0, 10.0] {
                    let ctx = TexCtx {
                        uv,
                        duv_dx: Vec2::new(width, 0.0),
                        duv_dy: Vec2::new(0.0, width * 0.3),
                        ..Default::default()
                    };
                    let v = texture.eval(&ctx).truncate();
                    assert!(
                        v.abs_diff_eq(colour(name), 1e-5),
                        "{filter:?} tile {name} at ({s}, {t}), width {width}: {v}"
                    );
                    let st = Vec2::new(uv.x, 1.0 - uv.y);
                    let plain = whole.lookup(filter, st, ctx.duv_dx, -ctx.duv_dy).truncate();
                    control_mixes |= !plain.abs_diff_eq(colour(name), 1e-3);
                }
            }
        }
    }
    assert!(control_mixes, "a pyramid of the whole image should mix tiles at coarse levels");
}
