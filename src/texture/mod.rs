//! Textures: anything a material parameter can read at a surface point.
//!
//! A texture is evaluated with a [`TexCtx`]: the hit's texture coordinates and its footprint
//! (the change of uv across one pixel in x and y, from ray differentials, DESIGN.md section 9).
//! Values are RGBA; scalar parameters read one channel or the mean of RGB.

mod mipmap;

pub use mipmap::{Filter, MipMap};

use glam::{Vec2, Vec4};

/// Where and how large a texture lookup is.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCtx {
    /// Texture coordinates (bottom-left origin, v up).
    pub uv: Vec2,
    /// Change of uv for a one-pixel step in x.
    pub duv_dx: Vec2,
    /// Change of uv for a one-pixel step in y.
    pub duv_dy: Vec2,
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
    pub mipmap: MipMap,
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
        // Image coordinates: x right, y down from the top row (DESIGN.md section 3).
        let st = Vec2::new(uv.x, 1.0 - uv.y);
        let flip = |d: Vec2| Vec2::new(d.x * self.scale.x, -d.y * self.scale.y);
        self.mipmap.lookup(self.filter, st, flip(ctx.duv_dx), flip(ctx.duv_dy))
    }
}

/// A texture node. (Constant values are not textures: parameters hold them directly.)
#[derive(Clone, Debug)]
pub enum Texture {
    /// An image.
    Image(ImageTexture),
}

impl Texture {
    /// RGBA value at the lookup.
    #[inline]
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        match self {
            Texture::Image(t) => t.eval(ctx),
        }
    }

    /// True when lookups use the footprint (a filtered image), so hits must compute it.
    pub fn uses_footprint(&self) -> bool {
        matches!(self, Texture::Image(t) if t.filter != Filter::None)
    }

    /// Approximate memory held, in bytes.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Texture::Image(t) => t.mipmap.memory_bytes(),
        }
    }
}
