//! Tile names and where each tile sits in the tile image (paper 001 Sec. 2, Fig. 4-5; Sec. 6
//! for n boundary conditions).
//!
//! A tile's name is its four edge types e0 e1 e2 e3, read counter-clockwise from the lower-left
//! corner: e0 the bottom edge, e1 the right, e2 the top, e3 the left. With n conditions a type
//! is a digit in 0..2n, condition k giving the complementary pair 2k, 2k + 1. The tile sits at
//! column 2n e0 + e1 and row 2n e2 + e3 of a (2n)^2 x (2n)^2 grid, rows counted from the bottom
//! (texture origin at the bottom-left, DESIGN.md section 3).
//!
//! Each grid cell holds the tile's R x R texels framed by a guard band of R/16 texels that repeat
//! the tile's outermost texels, so that bilinear lookups and the first log2(R/16) MIP levels of
//! any viewer never mix two tiles. Because the guard is a fixed fraction of the tile, the texture
//! coordinates of a tile corner depend on the number of conditions only, not on R: a mapped
//! mesh works with every tile image of its number of conditions (the paper's Sec. 1 promise).

use crate::image::Bitmap;
use glam::Vec2;

/// A tile's name: its edge types e0 e1 e2 e3, counter-clockwise from the bottom edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TileName(pub [u8; 4]);

impl TileName {
    /// The name of this tile turned 90 degrees counter-clockwise: the bottom edge becomes the
    /// right edge, so the name shifts cyclically by one (paper Sec. 2: 1101 -> 1110).
    pub fn rotated_ccw(self) -> TileName {
        let [e0, e1, e2, e3] = self.0;
        TileName([e3, e0, e1, e2])
    }
}

impl std::fmt::Display for TileName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for e in self.0 {
            write!(f, "{e}")?;
        }
        Ok(())
    }
}

/// The partner of an edge type: the type the other side of the edge has (2k <-> 2k + 1).
#[inline]
pub fn complementary(edge_type: u8) -> u8 {
    edge_type ^ 1
}

/// Guard texels on each side of a tile, per tile texel.
const GUARD_FRACTION: u32 = 16;

/// The geometry of a tile image: n conditions, tiles of R x R texels, guard bands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileLayout {
    conditions: u32,
    tile_res: u32,
}

/// Most boundary conditions: (2n)^4 tiles grow fast (4 conditions are 4096 tiles).
pub const MAX_CONDITIONS: u32 = 4;
/// Largest tile side in texels.
pub const MAX_TILE_RES: u32 = 4096;

impl TileLayout {
    /// A layout of (2n)^4 tiles of `tile_res` texels. `tile_res` must be a multiple of 16 (the
    /// guard band is a sixteenth of it) and the image at most [`crate::limits::MAX_IMAGE_SIDE`]
    /// texels on a side.
    pub fn new(conditions: u32, tile_res: u32) -> Result<Self, String> {
        if !(1..=MAX_CONDITIONS).contains(&conditions) {
            return Err(format!("{conditions} boundary conditions: give 1 to {MAX_CONDITIONS}"));
        }
        if tile_res == 0 || !tile_res.is_multiple_of(GUARD_FRACTION) || tile_res > MAX_TILE_RES {
            return Err(format!(
                "tile resolution {tile_res}: give a multiple of {GUARD_FRACTION} up to {MAX_TILE_RES} (the guard band is a \
                 sixteenth of a tile)"
            ));
        }
        let layout = TileLayout { conditions, tile_res };
        let side = layout.image_side() as u64;
        if side > crate::limits::MAX_IMAGE_SIDE as u64 || side * side > crate::limits::MAX_IMAGE_PIXELS {
            return Err(format!(
                "{} tiles of {tile_res} texels make a {side} x {side} image, larger than {} pixels: lower the tile \
                 resolution",
                layout.tile_count(),
                crate::limits::MAX_IMAGE_PIXELS
            ));
        }
        Ok(layout)
    }

    /// The layout of an existing tile image of `side` x `side` texels with `conditions`
    /// conditions (what a scene's `quad_tiles` texture reads).
    pub fn from_image_side(conditions: u32, side: usize) -> Result<Self, String> {
        let grid = (2 * conditions.min(MAX_CONDITIONS) as usize).pow(2);
        // A cell is 18 sixteenths of a tile whose side is a multiple of 16.
        let unit = grid * (GUARD_FRACTION as usize + 2);
        if side == 0 || !side.is_multiple_of(unit) {
            return Err(format!(
                "a {side} x {side} image is not a tile image of {conditions} condition(s): its side must be {grid} cells of \
                 18/16 of a tile, a multiple of {unit} (e.g. {} for tiles of 256 texels)",
                unit * 256 / GUARD_FRACTION as usize
            ));
        }
        TileLayout::new(conditions, u32::try_from(side / unit * GUARD_FRACTION as usize).unwrap_or(u32::MAX))
    }

    /// Number of boundary conditions n.
    pub fn conditions(&self) -> u32 {
        self.conditions
    }

    /// Tile side in texels (R).
    pub fn tile_res(&self) -> usize {
        self.tile_res as usize
    }

    /// Guard texels on each side of a tile (R / 16).
    pub fn guard(&self) -> usize {
        (self.tile_res / GUARD_FRACTION) as usize
    }

    /// Edge types: 2n.
    pub fn edge_types(&self) -> u8 {
        2 * self.conditions as u8
    }

    /// Tiles per row and per column of the grid: (2n)^2.
    pub fn grid(&self) -> usize {
        (self.edge_types() as usize).pow(2)
    }

    /// Number of tiles: (2n)^4.
    pub fn tile_count(&self) -> usize {
        self.grid() * self.grid()
    }

    /// Side of a grid cell in texels: the tile and its two guard bands.
    pub fn cell(&self) -> usize {
        self.tile_res() + 2 * self.guard()
    }

    /// Side of the tile image in texels.
    pub fn image_side(&self) -> usize {
        self.grid() * self.cell()
    }

    /// Grid column and row (from the bottom) of a tile: (2n e0 + e1, 2n e2 + e3).
    pub fn cell_of(&self, name: TileName) -> (usize, usize) {
        let [e0, e1, e2, e3] = name.0.map(usize::from);
        let t = self.edge_types() as usize;
        (t * e0 + e1, t * e2 + e3)
    }

    /// The tile at grid column `column` and row `row` (from the bottom).
    pub fn name_at(&self, column: usize, row: usize) -> TileName {
        let t = self.edge_types() as usize;
        TileName([column / t, column % t, row / t, row % t].map(|d| d as u8))
    }

    /// Every tile, in the order of [`TileLayout::index_of`].
    pub fn names(&self) -> impl Iterator<Item = TileName> + '_ {
        (0..self.tile_count()).map(|i| self.name_at(i % self.grid(), i / self.grid()))
    }

    /// A tile's index: row-major over the grid, from the bottom row.
    pub fn index_of(&self, name: TileName) -> usize {
        let (column, row) = self.cell_of(name);
        row * self.grid() + column
    }

    /// Texture coordinates of corner `corner` (0..4, counter-clockwise from the lower-left) of a
    /// tile: Fig. 6's AssignTextureCoordinates, u = (2n e0 + e1 + j) / (2n)^2 and v = (2n e2 +
    /// e3 + floor(i / 2)) / (2n)^2 with j = floor(((i + 1) mod 4) / 2), here with the guard
    /// band: the corner lands on the outer boundary of the tile's corner texel.
    pub fn corner_uv(&self, name: TileName, corner: usize) -> Vec2 {
        let (column, row) = self.cell_of(name);
        let j = ((corner + 1) % 4) / 2;
        let i = corner / 2;
        // In cells: the cell's origin, the guard (1/18 of a cell), the corner (16/18 of a cell).
        let along = |cell: usize, far: usize| (cell * 18 + 1 + 16 * far) as f32 / (18 * self.grid()) as f32;
        Vec2::new(along(column, j), along(row, i))
    }

    /// Tile widths per unit of texture coordinates: a cell spans 1 / grid and 18/16 of a tile.
    pub fn tiles_per_uv(&self) -> f32 {
        self.grid() as f32 * 18.0 / 16.0
    }

    /// The tile under texture coordinates `uv` and the point's coordinates within the tile
    /// (0 to 1 across the tile's texels; outside that range in its guard band).
    pub fn locate(&self, uv: Vec2) -> (TileName, Vec2) {
        let grid = self.grid() as f32;
        let cell = |t: f32| ((t * grid).floor().max(0.0) as usize).min(self.grid() - 1);
        let (column, row) = (cell(uv.x), cell(uv.y));
        let local = |t: f32, c: usize| t * self.tiles_per_uv() - (c as f32 * 18.0 + 1.0) / 16.0;
        (self.name_at(column, row), Vec2::new(local(uv.x, column), local(uv.y, row)))
    }

    /// The image texel (x right, y down from the top row) of texel (i, j) of tile `name`, with
    /// i along the tile's bottom edge and j up from it; i, j in -guard..R + guard.
    pub fn texel(&self, name: TileName, i: isize, j: isize) -> (usize, usize) {
        let (column, row) = self.cell_of(name);
        let g = self.guard() as isize;
        let x = (column * self.cell()) as isize + g + i;
        let y_up = (row * self.cell()) as isize + g + j;
        (x as usize, self.image_side() - 1 - y_up as usize)
    }

    /// The R x R texels of tile `name` cut out of a tile image of this layout (row 0 at the top).
    pub fn tile_bitmap(&self, image: &Bitmap, name: TileName) -> Bitmap {
        let res = self.tile_res();
        let mut tile = Bitmap::new(res, res, image.channels);
        for y in 0..res {
            for x in 0..res {
                let (ix, iy) = self.texel(name, x as isize, (res - 1 - y) as isize);
                tile.values_mut(x, y).copy_from_slice(image.values(ix, iy));
            }
        }
        tile
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_sit_at_their_binary_digits_and_rotate_by_cyclic_shifts() {
        let layout = TileLayout::new(1, 16).unwrap();
        // Fig. 5: the first two digits are the column, the last two the row.
        assert_eq!(layout.cell_of(TileName([1, 0, 0, 1])), (2, 1));
        assert_eq!(layout.name_at(3, 2), TileName([1, 1, 1, 0]));
        // Sec. 2: 1101 -> 1110 -> 0111 -> 1011 -> 1101.
        let mut name = TileName([1, 1, 0, 1]);
        let mut seen = Vec::new();
        for _ in 0..4 {
            name = name.rotated_ccw();
            seen.push(name.to_string());
        }
        assert_eq!(seen, ["1110", "0111", "1011", "1101"]);
        let names: std::collections::HashSet<_> = layout.names().collect();
        assert_eq!(names.len(), 16);
        assert!(layout.names().enumerate().all(|(i, n)| layout.index_of(n) == i));
        assert_eq!(TileLayout::new(2, 16).unwrap().tile_count(), 256);
    }

    /// Fig. 6's corners, worked by hand for tile 1001 (column 2, row 1 of 4, one condition):
    /// without the guard band its corners would be (2/4, 1/4), (3/4, 1/4), (3/4, 2/4), (2/4, 2/4).
    /// The cell is 18 units, the tile the 16 in its middle: u = (2 * 18 + 1) / 72 = 37/72, ...
    #[test]
    fn corners_of_tile_1001_worked_by_hand() {
        let layout = TileLayout::new(1, 256).unwrap();
        let name = TileName([1, 0, 0, 1]);
        let expected =
            [(37.0, 19.0), (53.0, 19.0), (53.0, 35.0), (37.0, 35.0)].map(|(u, v)| Vec2::new(u / 72.0, v / 72.0));
        for (corner, want) in expected.iter().enumerate() {
            assert!(layout.corner_uv(name, corner).abs_diff_eq(*want, 1e-7), "corner {corner}");
        }
        // The image is 4 cells of 288 texels; the tile's lower-left texel is at column
        // 2 * 288 + 16, row 1 * 288 + 16 from the bottom.
        assert_eq!(layout.image_side(), 1152);
        assert_eq!(layout.texel(name, 0, 0), (592, 1152 - 1 - 304));
        let (at, local) = layout.locate(layout.corner_uv(name, 0) + Vec2::splat(1e-4));
        assert_eq!(at, name);
        assert!(local.abs_diff_eq(Vec2::splat(1e-4 * 72.0 / 16.0), 1e-4));
    }

    #[test]
    fn layouts_are_validated_and_recovered_from_the_image_side() {
        assert!(TileLayout::new(0, 256).is_err());
        assert!(TileLayout::new(1, 100).is_err());
        assert!(TileLayout::new(4, 4096).is_err());
        for (n, r) in [(1, 16), (1, 256), (2, 64), (3, 32)] {
            let layout = TileLayout::new(n, r).unwrap();
            assert_eq!(TileLayout::from_image_side(n, layout.image_side()), Ok(layout));
            assert!(TileLayout::from_image_side(n, layout.image_side() + 4).is_err());
        }
        assert!(TileLayout::from_image_side(1, 1000).is_err());
    }
}
