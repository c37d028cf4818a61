//! The parameter block shared by tessera's CPU synthesis and its WGSL port
//! (`shaders/tiling_blending/params.wgsl`): one `#[repr(C)]` struct whose layout a test checks
//! against the shader's, so that the two cannot drift, and the images a GPU lookup reads.
//!
//! What the port supports is decided here, once: a [`TilingBlending`] that uses something it
//! lacks (cut bands, the sharpened operator, a procedural exemplar) gets an
//! error naming it rather than a different image.

use super::{Blend, Deformation, Exemplar, FieldAt, Tiling, TilingBlending, fold_seed};
use crate::image::Bitmap;
use crate::texture::{Filter, ImageTexture, MipMap};
use bytemuck::{Pod, Zeroable};

/// Most factors of a deformation field the shader takes.
pub const MAX_GPU_FACTORS: usize = 4;

/// [`Tiling`] codes of `SynthesisParams::tiling`.
pub const TILING_HEXAGONAL: u32 = 0;
/// See [`TILING_HEXAGONAL`].
pub const TILING_SQUARE: u32 = 1;

/// [`Filter`] codes of `ImageParams::filtering`.
pub const FILTER_NONE: u32 = 0;
/// See [`FILTER_NONE`].
pub const FILTER_TRILINEAR: u32 = 1;
/// See [`FILTER_NONE`].
pub const FILTER_EWA: u32 = 2;
/// GPU only: `textureSampleGrad` through a linear sampler, the texture unit filtering (regime
/// (b) of docs/gpu.md); the CPU has no such filter.
pub const FILTER_HARDWARE: u32 = 3;

/// [`Blend`] codes of `SynthesisParams::blend`.
pub const BLEND_LINEAR: u32 = 0;
/// See [`BLEND_LINEAR`].
pub const BLEND_VARIANCE_PRESERVING: u32 = 1;
/// See [`BLEND_LINEAR`].
pub const BLEND_HISTOGRAM_PRESERVING: u32 = 2;
/// See [`BLEND_LINEAR`].
pub const BLEND_MIX_MAX: u32 = 3;

/// [`Deformation`] codes of `FactorParams::kind`.
pub const FACTOR_CONSTANT: u32 = 0;
/// See [`FACTOR_CONSTANT`].
pub const FACTOR_ROTATION: u32 = 1;
/// See [`FACTOR_CONSTANT`].
pub const FACTOR_SCALE: u32 = 2;
/// See [`FACTOR_CONSTANT`].
pub const FACTOR_SHEAR: u32 = 3;
/// See [`FACTOR_CONSTANT`].
pub const FACTOR_MAP: u32 = 4;

/// How an image is read (WGSL `ImageParams`): its [`Filter`] and the affine map
/// uv * scale + offset of [`ImageTexture`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ImageParams {
    /// FILTER_* code.
    pub filtering: u32,
    /// Number of MIP levels.
    pub levels: u32,
    /// Scale of the texture coordinates.
    pub scale: [f32; 2],
    /// Offset added after scaling.
    pub offset: [f32; 2],
    /// With `FILTER_HARDWARE`: the factor the footprint is scaled by before `textureSampleGrad`
    /// (1: the GPU's level of detail; 2: about tessera's trilinear level). Unused otherwise.
    pub gradient_scale: f32,
    /// Padding to 8-byte alignment (WGSL's vec2).
    pub padding: u32,
}

/// One factor of the deformation field (WGSL `FactorParams`). `values` by kind: constant
/// (F00, F10, F01, F11) column-major; rotation (angle, gradient u, gradient v, -); scale
/// (scale u, scale v, gradient u, gradient v); shear (shear, gradient u, gradient v, -); map:
/// unused (the F map image).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FactorParams {
    /// FACTOR_* code.
    pub kind: u32,
    /// Padding to 16-byte alignment.
    pub padding: [u32; 3],
    /// The factor's parameters.
    pub values: [f32; 4],
}

/// A synthesis and its exemplar as the shader reads them (WGSL `SynthesisParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SynthesisParams {
    /// TILING_* code.
    pub tiling: u32,
    /// The seed folded to 32 bits ([`fold_seed`]).
    pub seed: u32,
    /// BLEND_* code.
    pub blend: u32,
    /// 1 when shifts are inset ([`super::Synthesis::inset`]).
    pub inset: u32,
    /// Lattice spacing in UV units.
    pub tile_size: f32,
    /// Number of valid entries of `factors`.
    pub factor_count: u32,
    /// Mix-Max: the priority contrast c and the spread lambda.
    pub mix_max: [f32; 2],
    /// The exemplar's mean (variance-preserving operator).
    pub exemplar_mean: [f32; 4],
    /// How the exemplar (its Gaussianized image for the histogram-preserving operator) is read.
    pub exemplar: ImageParams,
    /// How the priority map is read (Mix-Max).
    pub priority: ImageParams,
    /// The deformation field's factors, F = F_1 ... F_n.
    pub factors: [FactorParams; MAX_GPU_FACTORS],
    /// 1 when the synthesis has cut bands ([`GpuCuts`]).
    pub cuts: u32,
    /// Padding to 16-byte alignment.
    pub padding: [u32; 3],
}

/// A point of a cut as `shaders/tiling_blending/cuts.wgsl` reads it ([`super::CutPoint`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CutPointParams {
    /// UV on side 0.
    pub uv0: [f32; 2],
    /// UV on side 1.
    pub uv1: [f32; 2],
    /// The developed exemplar coordinate g(s).
    pub g: [f32; 2],
    /// Arc length.
    pub s: f32,
    /// Padding to 8-byte alignment.
    pub padding: u32,
}

/// A cut as `cuts.wgsl` reads it: where its points and its row's anchors g(s_m) start in
/// [`GpuCuts`]' arrays, how many, and its row's tile spacing.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CutCurveParams {
    /// Index of its first point.
    pub first_point: u32,
    /// Its number of points.
    pub point_count: u32,
    /// Index of its first anchor.
    pub first_anchor: u32,
    /// Its number of anchors.
    pub anchor_count: u32,
    /// Tile spacing along it, in map units.
    pub spacing: f32,
    /// Padding to 16-byte alignment.
    pub padding: [u32; 3],
}

/// The cut bands ([`super::CutBands`]) as the shader reads them.
pub struct GpuCuts {
    /// Side of the square raster of nearest cut sides.
    pub res: usize,
    /// Per texel, row 0 at v = 1: the two nearest cut sides as (curve, segment index times 2
    /// plus the side), curve `u32::MAX` for none.
    pub texels: Vec<[u32; 4]>,
    /// Every cut's points, one cut after the other.
    pub points: Vec<CutPointParams>,
    /// The cuts.
    pub curves: Vec<CutCurveParams>,
    /// Every cut's anchors g(s_m), one cut after the other.
    pub anchors: Vec<[f32; 2]>,
}

/// Regime (b) of docs/gpu.md: the exemplar read by the GPU's texture unit (`textureSampleGrad`
/// through a trilinear sampler) instead of the shader's f32 filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HardwareSampling {
    /// The sampler's anisotropy clamp: 1 (isotropic trilinear) to 16.
    pub anisotropy: u16,
    /// The footprint's scale (see [`ImageParams::gradient_scale`]).
    pub gradient_scale: f32,
}

impl SynthesisParams {
    /// Read the exemplar in hardware (`FILTER_HARDWARE`), its footprint scaled by `gradient_scale`.
    pub fn sample_exemplar_in_hardware(&mut self, gradient_scale: f32) {
        self.exemplar.filtering = FILTER_HARDWARE;
        self.exemplar.gradient_scale = gradient_scale;
    }

    /// The pipeline constants that specialise the shader to this configuration (the overrides
    /// of `params.wgsl`): the compiler then drops the code of other pavings, operators,
    /// filters and factors. The uniform block still carries the same codes.
    pub fn pipeline_constants(&self) -> Vec<(&'static str, f64)> {
        let mut constants = vec![
            ("TILING", self.tiling as f64),
            ("BLEND", self.blend as f64),
            ("EXEMPLAR_FILTERING", self.exemplar.filtering as f64),
            ("PRIORITY_FILTERING", self.priority.filtering as f64),
            ("FACTOR_COUNT", self.factor_count as f64),
            ("CUTS", self.cuts as f64),
        ];
        const KINDS: [&str; MAX_GPU_FACTORS] = ["FACTOR0_KIND", "FACTOR1_KIND", "FACTOR2_KIND", "FACTOR3_KIND"];
        for (name, factor) in KINDS.iter().zip(&self.factors).take(self.factor_count as usize) {
            constants.push((name, factor.kind as f64));
        }
        constants
    }
}

/// Everything a GPU lookup of a tiling-and-blending texture reads: the parameter block and the
/// MIP pyramids to upload.
pub struct GpuSynthesis<'a> {
    /// The parameter block.
    pub params: SynthesisParams,
    /// The exemplar's pyramid (the Gaussianized exemplar's for histogram preservation).
    pub exemplar: &'a MipMap,
    /// The F map (a one-level image), if the field has one.
    pub f_map: Option<&'a MipMap>,
    /// The priority map's pyramid (RGB the priority less its mean, A its square), for Mix-Max.
    pub priority: Option<&'a MipMap>,
    /// The inverse histogram tables ([`super::GaussianizedExemplar::inverse_tables`]).
    pub inverse_tables: Option<Bitmap>,
    /// The cut bands.
    pub cuts: Option<GpuCuts>,
}

impl ImageParams {
    fn new(image: &ImageTexture) -> Result<Self, String> {
        let filtering = match image.filter {
            Filter::None => FILTER_NONE,
            Filter::Trilinear => FILTER_TRILINEAR,
            Filter::Ewa => FILTER_EWA,
        };
        Ok(ImageParams {
            filtering,
            levels: image.mipmap.level_count() as u32,
            scale: image.scale.to_array(),
            offset: image.offset.to_array(),
            gradient_scale: 1.0,
            padding: 0,
        })
    }
}

impl FactorParams {
    fn new(factor: &Deformation) -> Self {
        let (kind, values) = match factor {
            Deformation::Constant(m) => (FACTOR_CONSTANT, m.to_cols_array()),
            Deformation::Rotation { angle, gradient } => (FACTOR_ROTATION, [*angle, gradient.x, gradient.y, 0.0]),
            Deformation::Scale { scale, gradient } => (FACTOR_SCALE, [scale.x, scale.y, gradient.x, gradient.y]),
            Deformation::Shear { shear, gradient } => (FACTOR_SHEAR, [*shear, gradient.x, gradient.y, 0.0]),
            Deformation::Map(_) => (FACTOR_MAP, [0.0; 4]),
        };
        FactorParams { kind, padding: [0; 3], values }
    }
}

impl TilingBlending {
    /// This texture as the WGSL port reads it, or what the port lacks to read it.
    pub fn gpu_synthesis(&self) -> Result<GpuSynthesis<'_>, String> {
        let s = &*self.synthesis;
        let factors = s.deformation.as_ref().map_or(&[][..], |d| d.factors());
        if factors.len() > MAX_GPU_FACTORS {
            return Err(format!(
                "the GPU port takes at most {MAX_GPU_FACTORS} deformation factors, this field has {}",
                factors.len()
            ));
        }
        if s.deformation.as_ref().is_some_and(|d| d.field_at() == FieldAt::TileCentre) {
            return Err("the GPU port reads F at the point; field_at = \"tile_centre\" is not ported".into());
        }
        let maps: Vec<&MipMap> =
            factors.iter().filter_map(|f| if let Deformation::Map(m) = f { Some(m) } else { None }).collect();
        if maps.len() > 1 {
            return Err("the GPU port takes one F map per deformation field".into());
        }
        let mut params = SynthesisParams {
            tiling: match s.tiling {
                Tiling::Hexagonal => TILING_HEXAGONAL,
                Tiling::Square => TILING_SQUARE,
            },
            seed: fold_seed(s.seed),
            inset: s.inset as u32,
            tile_size: s.tile_size,
            factor_count: factors.len() as u32,
            ..Default::default()
        };
        for (slot, factor) in params.factors.iter_mut().zip(factors) {
            *slot = FactorParams::new(factor);
        }
        let mut priority = None;
        params.blend = match &s.blend {
            Blend::Linear => BLEND_LINEAR,
            Blend::VariancePreserving => BLEND_VARIANCE_PRESERVING,
            Blend::HistogramPreserving => BLEND_HISTOGRAM_PRESERVING,
            Blend::MixMax { priority: map, contrast, lambda } => {
                params.priority = ImageParams::new(map.image())?;
                params.mix_max = [*contrast, *lambda];
                priority = Some(&*map.image().mipmap);
                BLEND_MIX_MAX
            }
            Blend::Sharpened { .. } => return Err("the sharpened operator is not ported to the GPU".into()),
        };
        let (exemplar, inverse_tables) = match &self.exemplar {
            Exemplar::Plain { texture, mean, .. } => {
                let crate::texture::Texture::Image(image) = texture.as_ref() else {
                    return Err("the GPU port reads image exemplars only".into());
                };
                params.exemplar_mean = mean.to_array();
                (image, None)
            }
            Exemplar::Gaussianized(g) => (&g.gaussian, Some(g.inverse_tables())),
        };
        params.exemplar = ImageParams::new(exemplar)?;
        let cuts = s.cuts.as_ref().map(|c| c.gpu_cuts());
        params.cuts = cuts.is_some() as u32;
        Ok(GpuSynthesis {
            params,
            exemplar: &exemplar.mipmap,
            f_map: maps.first().copied(),
            priority,
            inverse_tables,
            cuts,
        })
    }
}
