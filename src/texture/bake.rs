//! Evaluate a texture over the UV square into an image, with no light transport: for
//! inspection, for comparisons with GPU shaders, and for exporting procedural textures.

use super::{TexCtx, Texture};
use crate::image::Bitmap;
use glam::Vec2;
use rayon::prelude::*;

/// The footprint a bake gives each lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BakeFootprint {
    /// One texel of the bake (what a GPU shader drawing the UV square at that resolution sees).
    #[default]
    Texel,
    /// Zero: point lookups (filtered textures read their finest level).
    Point,
}

/// A bake's parameters as the WGSL bake reads them (`shaders/bake.wgsl`, `BakeParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BakeParams {
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// 0: one texel ([`BakeFootprint::Texel`]); 1: a point.
    pub footprint: u32,
    /// The band's first row: a large bake runs as bands of rows that each fit one storage
    /// buffer binding.
    pub first_row: u32,
}

/// The RGBA texture over [0, 1]^2 at `res` x `res` texel centres. Row 0 is the top of the UV
/// square (v near 1), as the texture conventions of DESIGN.md section 3 lay images out, so the
/// bake of an image texture at the image's resolution with point lookups is the image itself.
pub fn bake(texture: &Texture, res: usize, footprint: BakeFootprint) -> Bitmap {
    bake_rect(texture, res, res, footprint)
}

/// [`bake`] at `width` x `height` texel centres.
pub fn bake_rect(texture: &Texture, width: usize, height: usize, footprint: BakeFootprint) -> Bitmap {
    let mut out = Bitmap::new(width, height, 4);
    let size = Vec2::new(width as f32, height as f32);
    let step = match footprint {
        BakeFootprint::Texel => 1.0 / size,
        BakeFootprint::Point => Vec2::ZERO,
    };
    out.data.par_chunks_mut(width * 4).enumerate().for_each(|(row, line)| {
        let v = (height - 1 - row) as f32 + 0.5;
        for (col, px) in line.chunks_exact_mut(4).enumerate() {
            let uv = Vec2::new(col as f32 + 0.5, v) / size;
            let ctx = TexCtx { uv, duv_dx: Vec2::new(step.x, 0.0), duv_dy: Vec2::new(0.0, step.y), uv_mirrored: None };
            px.copy_from_slice(&texture.eval(&ctx).to_array());
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{Filter, ImageTexture, MipMap};

    #[test]
    fn baking_an_image_at_its_resolution_gives_the_image() {
        let mut b = Bitmap::new(8, 8, 4);
        for (i, v) in b.data.iter_mut().enumerate() {
            *v = ((i * 37) % 11) as f32;
        }
        let tex = Texture::Image(ImageTexture {
            mipmap: std::sync::Arc::new(MipMap::new(b.clone())),
            filter: Filter::None,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        });
        assert_eq!(bake(&tex, 8, BakeFootprint::Point), b);
    }
}
