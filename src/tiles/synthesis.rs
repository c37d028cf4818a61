//! Tile images from any photograph (paper 001 Sec. 4, Fig. 9-11).
//!
//! A boundary template is two stacked squares of the photograph: the upper square, whose bottom
//! edge is the boundary, is tile layer 0XXX (type 2k of condition k), and the lower square,
//! turned by 180 degrees, is 1XXX (type 2k + 1): their bottom rows are the same line of the
//! photograph read in opposite directions. Tile ABCD is AXXX over XBXX over XXCX over XXXD over
//! XXXX, where XBXX is layer B turned 90 degrees counter-clockwise (a cyclic shift of the name),
//! and so on, and XXXX is a square of the background region, another one for every tile.
//!
//! Each edge layer's opacity is f1 f2 f3 f4 (Fig. 10): f1 and f2 fade it out towards the two
//! neighbouring edges (here across the tile's diagonals, so the four layers share the tile), f3
//! towards the opposite edge, and f4, column by column, from the first texel where the layer and
//! the background look alike (Sec. 4: "once color values of two image layers become similar").
//!
//! What the paper leaves to luck, tessera makes exact. Along its edge a layer is fully opaque
//! and reads the template's boundary row, so two tiles meeting across an edge (complementary
//! types, opposite directions) hold the same texels there, bit for bit. At a tile's corners the
//! layers of its two edges fade out; there a corner patch, the same in every tile, covers them:
//! a square of the photograph folded along its diagonal (P(x, y) = Q(max(x, y), min(x, y))),
//! so that it reads the same along both edges. Every corner of every tile thus shows the same
//! texels, and a vertex of any valence is continuous.

use super::layout::{TileLayout, TileName};
use crate::image::Bitmap;
use crate::sampling::mix64;
use glam::Vec3;
use rayon::prelude::*;

/// A rectangle of the source image in pixels, x right and y down from the top-left corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl std::str::FromStr for PixelRect {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let values: Vec<u32> = s
            .split(',')
            .map(|v| v.trim().parse::<u32>().map_err(|_| format!("'{s}': expected x,y,width,height in pixels")))
            .collect::<Result<_, _>>()?;
        match values[..] {
            [x, y, width, height] => Ok(PixelRect { x, y, width, height }),
            _ => Err(format!("'{s}': expected four numbers x,y,width,height")),
        }
    }
}

impl std::fmt::Display for PixelRect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x, self.y, self.width, self.height)
    }
}

impl PixelRect {
    fn fits_in(&self, image: &Bitmap) -> bool {
        self.x as u64 + self.width as u64 <= image.width as u64
            && self.y as u64 + self.height as u64 <= image.height as u64
    }
}

/// Smallest side of a template square in pixels.
pub const MIN_SQUARE: u32 = 4;

/// What a tile image is made from: the photograph's templates and the layout.
#[derive(Clone, Debug, PartialEq)]
pub struct TileTemplates {
    /// One boundary template per condition: two squares stacked vertically (height = 2 width).
    pub boundaries: Vec<PixelRect>,
    /// Where the background squares XXXX are drawn from (at least one square's size).
    pub background: PixelRect,
}

impl TileTemplates {
    /// Templates for `image` with `conditions` conditions, defaults where `boundaries` gives
    /// fewer than `conditions` or `background` is None: squares of half the largest that fits
    /// twice vertically; boundary templates where the photograph is most typical
    /// ([`typical_rectangles`]); the background the whole image. Checks that every rectangle
    /// fits the image, that each boundary template is two squares of the same side, and that
    /// the background holds one.
    pub fn new(
        image: &Bitmap,
        conditions: u32,
        boundaries: &[PixelRect],
        background: Option<PixelRect>,
    ) -> Result<Self, String> {
        let (w, h) = (image.width as u32, image.height as u32);
        if boundaries.len() > conditions as usize {
            return Err(format!("{} boundary templates for {conditions} condition(s)", boundaries.len()));
        }
        let side = match boundaries.first() {
            Some(b) => b.width,
            None => (w.min(h / 2) / 2).min(1024),
        };
        if side < MIN_SQUARE {
            return Err(format!(
                "a {w} x {h} image is too small for tile synthesis: a boundary template is two stacked squares of at least \
                 {MIN_SQUARE} pixels"
            ));
        }
        let mut all = boundaries.to_vec();
        if all.len() < conditions as usize && side <= w.min(h / 2) {
            let missing = conditions as usize - all.len();
            all.extend(typical_rectangles(image, side, missing, &all));
        }
        let background = background.unwrap_or(PixelRect { x: 0, y: 0, width: w, height: h });
        for (k, b) in all.iter().enumerate() {
            if b.width != side || b.height != 2 * side {
                return Err(format!(
                    "boundary template {} ({b}) must be two stacked squares of {side} pixels: width {side}, height {}",
                    k + 1,
                    2 * side
                ));
            }
            if !b.fits_in(image) {
                return Err(format!("boundary template {} ({b}) reaches outside the {w} x {h} image", k + 1));
            }
        }
        if !background.fits_in(image) {
            return Err(format!("background region {background} reaches outside the {w} x {h} image"));
        }
        if background.width < side || background.height < side {
            return Err(format!("background region {background} is smaller than one {side}-pixel square"));
        }
        Ok(TileTemplates { boundaries: all, background })
    }

    /// Side of the template squares in pixels: one tile shows this much of the photograph.
    pub fn side(&self) -> u32 {
        self.boundaries[0].width
    }
}

/// `count` boundary templates (two stacked squares of `side` pixels) where the photograph is
/// most typical: of a 9 x 9 grid of positions, those whose rectangle's mean colour and spread
/// are nearest the whole image's (so that the boundary, which every tile edge shows, crosses no
/// rare feature), preferring positions that overlap neither `taken` nor each other.
fn typical_rectangles(image: &Bitmap, side: u32, count: usize, taken: &[PixelRect]) -> Vec<PixelRect> {
    let (mean, spread) = statistics(image, 0.0, 0.0, image.width as f32, image.height as f32);
    let room = (image.width as u32 - side, image.height as u32 - 2 * side);
    let mut candidates: Vec<(f32, PixelRect)> = (0..81)
        .map(|k| {
            let rect = PixelRect { x: room.0 * (k % 9) / 8, y: room.1 * (k / 9) / 8, width: side, height: 2 * side };
            let (m, s) = statistics(image, rect.x as f32, rect.y as f32, side as f32, 2.0 * side as f32);
            (m.distance(mean) + (s - spread).abs(), rect)
        })
        .collect();
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0));
    let overlaps = |a: &PixelRect, b: &PixelRect| {
        a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height
    };
    let mut chosen: Vec<PixelRect> = Vec::new();
    for (_, rect) in &candidates {
        if chosen.len() < count && !taken.iter().chain(&chosen).any(|t| overlaps(t, rect)) {
            chosen.push(*rect);
        }
    }
    // Where the image has no room for separate templates, they overlap.
    for (_, rect) in candidates.iter().cycle().take(count - chosen.len()) {
        chosen.push(*rect);
    }
    chosen
}

/// Bilinear lookup of `image` at continuous pixel coordinates (texel centres at + 0.5), clamped
/// to the image.
fn sample(image: &Bitmap, x: f32, y: f32) -> Vec3 {
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let clamp = |v: f32, n: usize| (v.max(0.0) as usize).min(n - 1);
    let (xa, xb) = (clamp(x0, image.width), clamp(x0 + 1.0, image.width));
    let (ya, yb) = (clamp(y0, image.height), clamp(y0 + 1.0, image.height));
    let p = |x: usize, y: usize| image.pixel(x, y).truncate();
    (p(xa, ya) * (1.0 - tx) + p(xb, ya) * tx) * (1.0 - ty) + (p(xa, yb) * (1.0 - tx) + p(xb, yb) * tx) * ty
}

/// Mean colour and RMS spread about it of the rectangle (x0, y0, w, h) of `image` (pixels),
/// from 16 x 16 samples.
fn statistics(image: &Bitmap, x0: f32, y0: f32, w: f32, h: f32) -> (Vec3, f32) {
    let n = 16;
    let values: Vec<Vec3> = (0..n * n)
        .map(|k| sample(image, x0 + ((k % n) as f32 + 0.5) * w / n as f32, y0 + ((k / n) as f32 + 0.5) * h / n as f32))
        .collect();
    let mean = values.iter().sum::<Vec3>() / values.len() as f32;
    let spread = (values.iter().map(|v| v.distance_squared(mean)).sum::<f32>() / values.len() as f32).sqrt();
    (mean, spread)
}

/// The point of `region` (pixels) from which the corner patch, `extent` pixels wide, is read:
/// of an 8 x 8 grid of candidates, the one whose patch has the mean colour nearest the region's
/// and little structure (its spread counts half as much), so that the patch, repeated at every
/// vertex, draws no motif.
fn corner_source(image: &Bitmap, region: PixelRect, extent: f32) -> (f32, f32) {
    let (x, y, w, h) = (region.x as f32, region.y as f32, region.width as f32, region.height as f32);
    let (target, _) = statistics(image, x, y, w, h);
    let room = ((w - extent).max(0.0), (h - extent).max(0.0));
    let candidates = (0..64).map(|k| {
        let (cx, cy) = (x + room.0 * ((k % 8) as f32 + 0.5) / 8.0, y + extent + room.1 * ((k / 8) as f32 + 0.5) / 8.0);
        (cx, cy.min(y + h))
    });
    candidates
        .min_by(|a, b| {
            let d = |&(cx, cy): &(f32, f32)| {
                let (mean, spread) = statistics(image, cx, cy - extent, extent, extent);
                mean.distance(target) + 0.5 * spread
            };
            d(a).total_cmp(&d(b))
        })
        .expect("64 candidates")
}

/// Cubic smoothstep of t clamped to [0, 1] (exactly 0 and 1 at the ends).
fn smoothstep(t: f32) -> f32 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Shape of the layers, in tile units.
mod shape {
    /// Width of f1 and f2's fade across the tile's diagonals on the edge; it widens by
    /// SIDE_FADE_GROWTH per unit of distance from the edge, so that the layers' borders are
    /// soft inside the tile and sharp only where the corner patch covers them.
    pub const SIDE_FADE: f32 = 0.025;
    pub const SIDE_FADE_GROWTH: f32 = 0.8;
    /// f3 fades the layer out between these distances from its edge.
    pub const FAR_START: f32 = 0.1;
    pub const FAR_END: f32 = 0.3;
    /// The corner patch is opaque up to this distance from the corner and gone at the next.
    /// It must cover where f1 and f2 fade along the edge: SIDE_FADE plus half a texel of a
    /// 16-texel tile stays under CORNER_OPAQUE.
    pub const CORNER_OPAQUE: f32 = 0.045;
    pub const CORNER_END: f32 = 0.09;
    /// f4 looks for similar colours from this distance on...
    pub const SIMILAR_FROM: f32 = 0.04;
    /// ... and fades the layer out over this distance after the first similar texel.
    pub const SIMILAR_FADE: f32 = 0.15;
    /// Colours are similar below this fraction of the layer's mean difference to the background.
    pub const SIMILAR_FRACTION: f32 = 0.25;
}

/// A square of R x R values, texel (i, j) at index j R + i: i along the bottom edge, j up.
type Square = Vec<Vec3>;

/// Texel (i, j) of a square turned `quarter_turns` times 90 degrees counter-clockwise: where the
/// texel lands (Sec. 2: a quarter turn shifts the name by one).
#[inline]
pub fn rotate_texel(quarter_turns: usize, i: usize, j: usize, res: usize) -> (usize, usize) {
    let last = res - 1;
    match quarter_turns % 4 {
        0 => (i, j),
        1 => (last - j, i),
        2 => (last - i, last - j),
        _ => (j, last - i),
    }
}

/// The edge layers of one edge type: colours and opacity f1 f2 f3 (f4 depends on the tile).
struct EdgeLayer {
    colour: Square,
    opacity: Vec<f32>,
}

/// The pieces every tile is composed of.
struct Pieces {
    res: usize,
    /// One per edge type, in the frame where the edge is the bottom one.
    edges: Vec<EdgeLayer>,
    /// The corner patch and its opacity at the lower-left corner.
    corner: EdgeLayer,
}

impl Pieces {
    fn new(image: &Bitmap, templates: &TileTemplates, res: usize) -> Self {
        let r = res as f32;
        let scale = templates.side() as f32 / r;
        // Distance in tile units from the edge of row j, and along it of column i (from the
        // nearer end), both at texel centres and symmetric in i <-> R - 1 - i.
        let up = |j: usize| (j as f32 + 0.5) / r;
        let along = |i: usize| (i.min(res - 1 - i) as f32 + 0.5) / r;
        let half_texel = 0.5 / r;
        let opacity = |i: usize, j: usize| {
            let from_edge = up(j) - half_texel;
            let sides = smoothstep((along(i) - from_edge) / (shape::SIDE_FADE + shape::SIDE_FADE_GROWTH * from_edge));
            let far = 1.0 - smoothstep((up(j) - shape::FAR_START) / (shape::FAR_END - shape::FAR_START));
            sides * far
        };
        let mut edges = Vec::new();
        for b in &templates.boundaries {
            let boundary_y = (b.y + b.width) as f32;
            // Row j of the upper square is j texels above the boundary line (row 0 on it); the
            // lower square's is j texels below, and its columns run backwards (180 degrees).
            let upper = |i: usize, j: usize| {
                sample(image, b.x as f32 + (i as f32 + 0.5) * scale, boundary_y - j as f32 * scale)
            };
            let lower = |i: usize, j: usize| {
                sample(image, b.x as f32 + ((res - 1 - i) as f32 + 0.5) * scale, boundary_y + j as f32 * scale)
            };
            for layer in [&upper as &dyn Fn(usize, usize) -> Vec3, &lower] {
                let colour = (0..res * res).map(|t| layer(t % res, t / res)).collect();
                let opacity = (0..res * res).map(|t| opacity(t % res, t / res)).collect();
                edges.push(EdgeLayer { colour, opacity });
            }
        }
        // The corner patch: a square of the photograph, extending right and up from the
        // background region's point whose patch has the mean colour nearest the region's
        // (no odd stone repeated at every vertex), folded along the diagonal.
        let (cx, cy) = corner_source(image, templates.background, shape::CORNER_END * templates.side() as f32);
        let corner_colour = (0..res * res)
            .map(|t| {
                let (i, j) = (t % res, t / res);
                let (a, b) = (i.max(j), i.min(j));
                sample(image, cx + (a as f32 + 0.5) * scale, cy - (b as f32 + 0.5) * scale)
            })
            .collect();
        let corner_opacity = (0..res * res)
            .map(|t| {
                let (x, y) = (((t % res) as f32 + 0.5) / r, ((t / res) as f32 + 0.5) / r);
                let d = (x * x + y * y).sqrt();
                if d <= shape::CORNER_OPAQUE {
                    1.0
                } else {
                    1.0 - smoothstep((d - shape::CORNER_OPAQUE) / (shape::CORNER_END - shape::CORNER_OPAQUE))
                }
            })
            .collect();
        Pieces { res, edges, corner: EdgeLayer { colour: corner_colour, opacity: corner_opacity } }
    }

    /// f4 of an edge layer over a background (both in the layer's frame): per column, 1 up to
    /// the first texel (from [`shape::SIMILAR_FROM`] on) whose colours are similar, then a
    /// linear fade; the cut rows are smoothed across neighbouring columns.
    fn similarity_fade(&self, layer: &EdgeLayer, background: impl Fn(usize, usize) -> Vec3) -> Vec<f32> {
        let res = self.res;
        let r = res as f32;
        let difference = |i: usize, j: usize| layer.colour[j * res + i].distance(background(i, j));
        let (mut sum, mut count) = (0.0f32, 0usize);
        for t in 0..res * res {
            if layer.opacity[t] > 0.0 {
                sum += difference(t % res, t / res);
                count += 1;
            }
        }
        let threshold = shape::SIMILAR_FRACTION * sum / count.max(1) as f32;
        let first = ((shape::SIMILAR_FROM * r).ceil() as usize).max(1);
        let last = ((shape::FAR_END * r) as usize).max(first);
        let cuts: Vec<f32> =
            (0..res).map(|i| (first..last).find(|&j| difference(i, j) < threshold).unwrap_or(last) as f32).collect();
        let radius = (res / 24).max(1);
        let smoothed: Vec<f32> = (0..res)
            .map(|i| {
                let window = &cuts[i.saturating_sub(radius)..(i + radius + 1).min(res)];
                window.iter().sum::<f32>() / window.len() as f32
            })
            .collect();
        let fade = (shape::SIMILAR_FADE * r).max(1.0);
        (0..res * res)
            .map(|t| {
                let (i, j) = (t % res, t / res);
                // 1 on the edge row itself: every cut is at row 1 or later.
                (1.0 - (j as f32 - smoothed[i]) / fade).clamp(0.0, 1.0)
            })
            .collect()
    }

    /// Tile `name` over `background`: edges 3, 2, 1, 0 composited in that order (so AXXX ends
    /// on top), then the four corner patches.
    fn tile(&self, name: TileName, background: Square) -> Square {
        let res = self.res;
        let mut out = background.clone();
        for k in (0..4).rev() {
            let layer = &self.edges[name.0[k] as usize];
            let f4 = self.similarity_fade(layer, |i, j| {
                let (x, y) = rotate_texel(k, i, j, res);
                background[y * res + x]
            });
            for j in 0..res {
                for i in 0..res {
                    let t = j * res + i;
                    let alpha = layer.opacity[t] * f4[t];
                    if alpha > 0.0 {
                        let (x, y) = rotate_texel(k, i, j, res);
                        let o = &mut out[y * res + x];
                        *o = layer.colour[t] * alpha + *o * (1.0 - alpha);
                    }
                }
            }
        }
        for c in 0..4 {
            for (t, &alpha) in self.corner.opacity.iter().enumerate() {
                if alpha > 0.0 {
                    let (x, y) = rotate_texel(c, t % res, t / res, res);
                    let o = &mut out[y * res + x];
                    *o = self.corner.colour[t] * alpha + *o * (1.0 - alpha);
                }
            }
        }
        out
    }
}

/// Synthesise the tile image of `layout` from `image` (linear RGB): every tile composited
/// from the templates, with its own background square drawn with `seed`, written into its
/// cell with the guard band repeating its outermost texels. Returns the tile image (RGB, row 0
/// at the top).
pub fn synthesize_tiles(image: &Bitmap, templates: &TileTemplates, layout: &TileLayout, seed: u64) -> Bitmap {
    assert_eq!(templates.boundaries.len(), layout.conditions() as usize);
    let res = layout.tile_res();
    let pieces = Pieces::new(image, templates, res);
    let scale = templates.side() as f32 / res as f32;
    let bg = templates.background;
    let side = templates.side();
    let names: Vec<TileName> = layout.names().collect();
    let mut atlas = Bitmap::new(layout.image_side(), layout.image_side(), 3);
    // In batches, so that a large image does not hold every tile twice.
    for batch in names.chunks(64) {
        let tiles: Vec<Square> = batch
            .par_iter()
            .map(|&name| {
                let bits = mix64(seed ^ mix64(layout.index_of(name) as u64 + 1));
                let pick = |bits: u64, room: u32| (((bits & 0xffff_ffff) * (room as u64 + 1)) >> 32) as u32;
                let x0 = (bg.x + pick(bits, bg.width - side)) as f32;
                let y0 = (bg.y + pick(bits >> 32, bg.height - side)) as f32;
                let background = (0..res * res)
                    .map(|t| {
                        let (i, j) = (t % res, t / res);
                        sample(image, x0 + (i as f32 + 0.5) * scale, y0 + side as f32 - (j as f32 + 0.5) * scale)
                    })
                    .collect();
                pieces.tile(name, background)
            })
            .collect();
        for (&name, tile) in batch.iter().zip(&tiles) {
            let g = layout.guard() as isize;
            let last = res as isize - 1;
            for j in -g..=last + g {
                for i in -g..=last + g {
                    let v = tile[j.clamp(0, last) as usize * res + i.clamp(0, last) as usize];
                    let (x, y) = layout.texel(name, i, j);
                    atlas.values_mut(x, y).copy_from_slice(&v.to_array());
                }
            }
        }
    }
    atlas
}
