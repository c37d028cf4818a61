//! Textures: anything a material parameter can read at a surface point.
//!
//! A texture is evaluated with a [`TexCtx`]: the hit's texture coordinates and its footprint
//! (the change of uv across one pixel in x and y, from ray differentials, DESIGN.md section 9).
//! Values are RGBA; scalar parameters read one channel or the mean of RGB.

mod bake;
mod checkerboard;
mod mipmap;
mod quad_tiles;
pub mod tiling_blending;

pub use bake::{BakeFootprint, BakeParams, bake, bake_rect};
pub use checkerboard::Checkerboard;
pub use mipmap::{EWA_LUT_SIZE, Filter, MAX_ANISOTROPY, MAX_EWA_SPAN, MipMap, PreparedFootprint, Taps, TapsX4};
pub use quad_tiles::QuadTilesTexture;
pub use tiling_blending::TilingBlending;

use glam::{Vec2, Vec3, Vec4};
use std::sync::Arc;

/// Where and how large a texture lookup is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCtx {
    /// Texture coordinates (bottom-left origin, v up).
    pub uv: Vec2,
    /// Change of uv for a one-pixel step in x.
    pub duv_dx: Vec2,
    /// Change of uv for a one-pixel step in y.
    pub duv_dy: Vec2,
    /// Whether the UV map reverses the surface's orientation here ((dp/du x dp/dv) . n < 0, n
    /// the triangle's winding normal); None where no surface is known (bakes, exemplars). A
    /// deformation field whose F map holds the other handedness there (overlapping mirrored UV
    /// islands) is mirrored to match ([`tiling_blending::DeformationField::at_surface`]).
    pub uv_mirrored: Option<bool>,
}

/// Image coordinates (s, t) of texture coordinates `uv`: s = u, t = 1 - v, so that t runs down
/// from the image's top row (DESIGN.md section 3). The one v-flip of CPU lookups; the shaders'
/// is `image_coordinates` in `shaders/tiling_blending/mipmap.wgsl`.
#[inline]
pub fn image_coordinates(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x, 1.0 - uv.y)
}

/// Which value of a texture a scalar parameter reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Channel {
    /// The mean of red, green and blue.
    #[default]
    Mean,
    /// Red.
    R,
    /// Green.
    G,
    /// Blue.
    B,
    /// Alpha.
    A,
}

impl Channel {
    /// Select the channel from an RGBA value.
    #[inline]
    pub fn select(self, v: Vec4) -> f32 {
        match self {
            Channel::Mean => (v.x + v.y + v.z) * (1.0 / 3.0),
            Channel::R => v.x,
            Channel::G => v.y,
            Channel::B => v.z,
            Channel::A => v.w,
        }
    }
}

/// An image texture: a MIP pyramid, a filter, and an affine map of the texture coordinates
/// (`uv' = uv * scale + offset`, wrapping with period 1).
#[derive(Clone, Debug)]
pub struct ImageTexture {
    /// The image and its pyramid.
    pub mipmap: Arc<MipMap>,
    /// How lookups are filtered.
    pub filter: Filter,
    /// Scale applied to the texture coordinates.
    pub scale: Vec2,
    /// Offset added after scaling.
    pub offset: Vec2,
}

impl ImageTexture {
    /// Filtered value at the lookup.
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        let uv = ctx.uv * self.scale + self.offset;
        let st = image_coordinates(uv);
        self.mipmap.lookup(self.filter, st, self.image_step(ctx.duv_dx), self.image_step(ctx.duv_dy))
    }

    /// The lookup's footprint prepared for [`ImageTexture::eval_prepared`]: lookups at several
    /// points with one footprint share it.
    pub fn prepare(&self, duv_dx: Vec2, duv_dy: Vec2) -> PreparedFootprint {
        self.mipmap.prepare(self.filter, self.image_step(duv_dx), self.image_step(duv_dy))
    }

    /// [`ImageTexture::eval`] at `uv` with the footprint [`ImageTexture::prepare`] gave (bit for
    /// bit).
    pub fn eval_prepared(&self, uv: Vec2, footprint: &PreparedFootprint) -> Vec4 {
        self.mipmap.lookup_prepared(footprint, image_coordinates(uv * self.scale + self.offset))
    }

    /// Where [`ImageTexture::eval_prepared`] reads at `uv`: [`MipMap::gather`] of this image's
    /// pyramid gives its value, and of another pyramid of the same layout read with this image's
    /// filter and mapping, that pyramid's (both bit for bit as their own lookups).
    #[inline]
    pub fn taps(&self, uv: Vec2, footprint: &PreparedFootprint) -> Taps {
        self.mipmap.taps(footprint, image_coordinates(uv * self.scale + self.offset))
    }

    /// [`ImageTexture::taps`] at four points with one footprint, in lanes ([`MipMap::taps_x4`]).
    #[inline(always)]
    pub fn taps_x4(&self, uv: [Vec2; 4], footprint: &PreparedFootprint) -> Option<TapsX4> {
        let st = uv.map(|uv| image_coordinates(uv * self.scale + self.offset));
        let lanes = |f: fn(Vec2) -> f32| Vec4::new(f(st[0]), f(st[1]), f(st[2]), f(st[3]));
        self.mipmap.taps_x4(footprint, lanes(|st| st.x), lanes(|st| st.y))
    }

    /// The red, green and blue of [`ImageTexture::eval_prepared`] at four points with one
    /// footprint, bit for bit, a vector per channel, found in lanes ([`ImageTexture::taps_x4`],
    /// [`MipMap::gather_rgb_x4`]); None where lanes do not serve the pyramid or the footprint.
    #[inline]
    pub fn eval_rgb_x4(&self, uv: [Vec2; 4], footprint: &PreparedFootprint) -> Option<[Vec4; 3]> {
        self.mipmap.gather_rgb_x4(&self.taps_x4(uv, footprint)?)
    }

    /// The continuous MIP level that [`ImageTexture::eval`] reads at the lookup.
    pub fn lod(&self, ctx: &TexCtx) -> f32 {
        self.mipmap.filter_lod(self.filter, self.image_step(ctx.duv_dx), self.image_step(ctx.duv_dy))
    }

    /// A uv step as a step in image coordinates (scaled, y down).
    #[inline]
    fn image_step(&self, d: Vec2) -> Vec2 {
        Vec2::new(d.x * self.scale.x, -d.y * self.scale.y)
    }
}

/// A texture node. (Constant values are not textures: parameters hold them directly.)
#[derive(Clone, Debug)]
pub enum Texture {
    /// An image.
    Image(ImageTexture),
    /// Tiling and blending of an exemplar, optionally deformed (paper 000).
    TilingBlending(TilingBlending),
    /// A tile image of paper 001 read tile by tile (a quad mesh mapped by `tessera tiles map`).
    QuadTiles(QuadTilesTexture),
    /// A partition-of-unity parametric texture (paper 002).
    Pups(PupsLookup),
    /// Mitsuba's two-colour checkerboard.
    Checkerboard(Checkerboard),
}

/// A PUPs texture as a scene reads it: texture coordinates scaled, the footprint filtered.
#[derive(Clone, Debug)]
pub struct PupsLookup {
    /// The texture.
    pub texture: Arc<crate::pups::PupsTexture>,
    /// Multiplier of the texture coordinates.
    pub scale: Vec2,
    /// How the footprint is filtered.
    pub filter: crate::pups::PupsFilter,
}

impl PupsLookup {
    /// Filtered value at the lookup.
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        let s = self.scale;
        self.texture.eval_filtered(ctx.uv * s, ctx.duv_dx * s, ctx.duv_dy * s, self.filter)
    }
}

impl Texture {
    /// RGBA value at the lookup.
    #[inline]
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        match self {
            Texture::Image(t) => t.eval(ctx),
            Texture::TilingBlending(t) => t.eval(ctx),
            Texture::QuadTiles(t) => t.eval(ctx),
            Texture::Pups(t) => t.eval(ctx),
            Texture::Checkerboard(t) => t.eval(ctx),
        }
    }

    /// A tangent-space normal map's unit normal at the lookup, in the frame whose x axis is
    /// [`Texture::tangent_direction`] (or dp/du without one). Images decode n = 2 rgb - 1;
    /// tiling and blending blends the tiles' slopes.
    pub fn eval_normal(&self, ctx: &TexCtx) -> Option<Vec3> {
        match self {
            Texture::TilingBlending(t) => t.eval_normal(ctx),
            _ => (self.eval(ctx).truncate() * 2.0 - Vec3::ONE).try_normalize(),
        }
    }

    /// Where a deformation field orients the texture: the UV direction of the texture's own x
    /// axis at `uv` and whether the field reverses orientation (DESIGN.md section 3).
    pub fn tangent_direction(&self, uv: Vec2, uv_mirrored: Option<bool>) -> Option<(Vec2, bool)> {
        match self {
            Texture::TilingBlending(t) => t.tangent_direction(uv, uv_mirrored),
            _ => None,
        }
    }

    /// True when lookups use the footprint (a filtered image), so hits must compute it.
    pub fn uses_footprint(&self) -> bool {
        match self {
            Texture::Image(t) => t.filter != Filter::None,
            Texture::TilingBlending(t) => t.uses_footprint(),
            Texture::QuadTiles(t) => t.filter != Filter::None,
            Texture::Pups(t) => t.filter != crate::pups::PupsFilter::None,
            Texture::Checkerboard(_) => false,
        }
    }

    /// Approximate memory held, in bytes.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Texture::Image(t) => t.mipmap.memory_bytes(),
            Texture::TilingBlending(t) => t.memory_bytes(),
            Texture::QuadTiles(t) => t.memory_bytes(),
            Texture::Pups(t) => t.texture.memory_bytes(),
            Texture::Checkerboard(_) => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Bitmap;

    #[test]
    fn image_lookups_in_lanes_are_the_lookups_bit_for_bit() {
        // Grey, grey and alpha, RGB and RGBA; at the point and between two levels.
        for channels in 1..=4 {
            let mut bitmap = Bitmap::new(23, 14, channels);
            for (i, v) in bitmap.data.iter_mut().enumerate() {
                *v = ((i * 2_654_435_761) % 1000) as f32 / 1000.0;
            }
            let mipmap = Arc::new(MipMap::new(bitmap));
            for (filter, duv_dx, duv_dy) in [
                (Filter::None, Vec2::ZERO, Vec2::ZERO),
                (Filter::Trilinear, Vec2::ZERO, Vec2::ZERO),
                (Filter::Trilinear, Vec2::new(0.03, 0.01), Vec2::new(-0.01, 0.02)),
            ] {
                let image = ImageTexture {
                    mipmap: mipmap.clone(),
                    filter,
                    scale: Vec2::new(3.0, -1.5),
                    offset: Vec2::splat(0.25),
                };
                let footprint = image.prepare(duv_dx, duv_dy);
                for i in 0..300 {
                    let uv: [Vec2; 4] = std::array::from_fn(|l| {
                        let j = (4 * i + l) as f32;
                        match (i + l) % 40 {
                            0 => Vec2::new(f32::NAN, 0.5),
                            1 => Vec2::new(-2e6 - j, 3e5),
                            _ => Vec2::new(j * 0.0191 - 3.0, (j * 0.37).sin()),
                        }
                    });
                    let [r, g, b] = image.eval_rgb_x4(uv, &footprint).expect("a wrapping image");
                    for (lane, &uv) in uv.iter().enumerate() {
                        let ctx = TexCtx { uv, duv_dx, duv_dy, uv_mirrored: None };
                        let lanes = [r, g, b].map(|c| c.to_array()[lane].to_bits());
                        let one = image.eval(&ctx).truncate().to_array().map(f32::to_bits);
                        assert_eq!(lanes, one, "{channels} channels, {filter:?} {duv_dx} {uv}");
                    }
                }
            }
        }
    }
}
