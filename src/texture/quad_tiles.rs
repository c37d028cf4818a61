//! A tile image of paper 001 read tile by tile: the texture of a quad mesh mapped by
//! `tessera tiles map`.
//!
//! The lookup finds the tile under the texture coordinates ([`TileLayout::locate`]) and filters
//! that tile's own MIP pyramid, clamped to its edge texels. However wide the footprint, no
//! level mixes two tiles, which a pyramid of the whole image does from the level where a texel
//! spans a guard band. At the tile's edge the lookup reads the edge texels, which the tile
//! across the mesh edge shares ([`crate::tiles::synthesis`]).

use super::{Filter, MipMap, TexCtx};
use crate::image::Bitmap;
use crate::tiles::TileLayout;
use glam::{Vec2, Vec4};

/// A tile image and one clamped pyramid per tile.
#[derive(Clone, Debug)]
pub struct QuadTilesTexture {
    layout: TileLayout,
    tiles: Vec<MipMap>,
    /// How lookups are filtered.
    pub filter: Filter,
}

impl QuadTilesTexture {
    /// The tiles of `image`, a tile image of `conditions` conditions (its side gives the tile
    /// size; an image of another size is an error).
    pub fn new(image: &Bitmap, conditions: u32, filter: Filter) -> Result<Self, String> {
        if image.width != image.height {
            return Err(format!("a tile image is square; this one is {} x {}", image.width, image.height));
        }
        let layout = TileLayout::from_image_side(conditions, image.width)?;
        let tiles = layout.names().map(|name| MipMap::clamped(layout.tile_bitmap(image, name))).collect();
        Ok(QuadTilesTexture { layout, tiles, filter })
    }

    /// The layout of the tile image.
    pub fn layout(&self) -> &TileLayout {
        &self.layout
    }

    /// Filtered value at the lookup.
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        let (name, local) = self.layout.locate(ctx.uv);
        let scale = self.layout.tiles_per_uv();
        let image_step = |d: Vec2| Vec2::new(d.x * scale, -d.y * scale);
        let st = Vec2::new(local.x, 1.0 - local.y);
        self.tiles[self.layout.index_of(name)].lookup(self.filter, st, image_step(ctx.duv_dx), image_step(ctx.duv_dy))
    }

    /// Bytes held by the pyramids.
    pub fn memory_bytes(&self) -> usize {
        self.tiles.iter().map(MipMap::memory_bytes).sum()
    }
}
