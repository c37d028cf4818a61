//! The cut map as the tiling-and-blending lookup reads it (paper 000 Sec. 5 and 6.1, Eq. 8;
//! DESIGN.md section 6): per texel of the UV square, the boundary cell whose band holds it and
//! that side's cell centre. `tessera deform` writes it (`cut_map.exr`).

use crate::image::Bitmap;
use glam::Vec2;

/// One texel of a cut map inside a cell's band.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellTexel {
    /// The cell index l.
    pub cell: u32,
    /// This side's centre, b_l or b'_l, in UV.
    pub centre: Vec2,
    /// How far from its origin a tile of the cell reads in the exemplar through the F map, on
    /// either side of the cut (for shifts that keep the cell's tiles inside the exemplar).
    pub reach: f32,
}

/// A cut map: texels (l + 1, b.x, b.y, reach), 0 outside every cell; row 0 at the top (v = 1).
#[derive(Clone, Debug)]
pub struct CutMap {
    width: usize,
    height: usize,
    texels: Vec<Option<CellTexel>>,
}

impl CutMap {
    /// Read a four-channel cut map, checking that it holds what `tessera deform` writes.
    pub fn new(map: &Bitmap) -> Result<Self, String> {
        if map.channels != 4 {
            return Err(format!("a cut map needs 4 channels (cell + 1, b.x, b.y, reach), found {}", map.channels));
        }
        let texels = map
            .data
            .chunks_exact(4)
            .map(|t| {
                if !t.iter().all(|v| v.is_finite()) {
                    return Err("the cut map holds NaN or infinite values".to_string());
                }
                if t[0] == 0.0 {
                    return Ok(None);
                }
                if !(t[0] >= 1.0 && t[0] < 16_777_216.0 && t[0].fract() == 0.0) {
                    return Err(format!("the cut map's first channel holds {}, not a cell number (0 or l + 1)", t[0]));
                }
                if !(t[3] > 0.0) {
                    return Err(format!("the cut map gives cell {} a reach of {}", t[0] - 1.0, t[3]));
                }
                Ok(Some(CellTexel { cell: t[0] as u32 - 1, centre: Vec2::new(t[1], t[2]), reach: t[3] }))
            })
            .collect::<Result<_, _>>()?;
        Ok(CutMap { width: map.width, height: map.height, texels })
    }

    /// The cell at `uv` (nearest texel; points outside the UV square take the texel at its
    /// border: a tile centred just outside a chart's edge belongs to that edge's side).
    #[inline]
    pub fn at(&self, uv: Vec2) -> Option<CellTexel> {
        let x = ((uv.x * self.width as f32).max(0.0) as usize).min(self.width - 1);
        let y = (((1.0 - uv.y) * self.height as f32).max(0.0) as usize).min(self.height - 1);
        self.texels[y * self.width + x]
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.texels.len() * std::mem::size_of::<Option<CellTexel>>()
    }
}
