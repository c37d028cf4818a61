// The parameter block shared with tessera's CPU code (src/texture/tiling_blending/params.rs,
// whose #[repr(C)] structs a test checks against these, member by member), and the images a
// tiling-and-blending lookup reads.

const TILING_HEXAGONAL: u32 = 0u;
const TILING_SQUARE: u32 = 1u;

const BLEND_LINEAR: u32 = 0u;
const BLEND_VARIANCE_PRESERVING: u32 = 1u;
const BLEND_HISTOGRAM_PRESERVING: u32 = 2u;
const BLEND_MIX_MAX: u32 = 3u;

const FACTOR_CONSTANT: u32 = 0u;
const FACTOR_ROTATION: u32 = 1u;
const FACTOR_SCALE: u32 = 2u;
const FACTOR_SHEAR: u32 = 3u;
const FACTOR_MAP: u32 = 4u;

const MAX_GPU_FACTORS: u32 = 4u;

// How an image is read: a FILTER_* code (mipmap.wgsl), its level count, uv * scale + offset,
// and for FILTER_HARDWARE the factor the footprint is scaled by before textureSampleGrad.
struct ImageParams {
    filtering: u32,
    levels: u32,
    scale: vec2<f32>,
    offset: vec2<f32>,
    gradient_scale: f32,
    padding: u32,
}

// One factor of the deformation field; `values` by kind as params.rs documents.
struct FactorParams {
    kind: u32,
    @size(12) padding: u32,
    values: vec4<f32>,
}

struct SynthesisParams {
    tiling: u32,
    seed: u32,
    blend: u32,
    inset: u32,
    tile_size: f32,
    factor_count: u32,
    mix_max: vec2<f32>,
    exemplar_mean: vec4<f32>,
    exemplar: ImageParams,
    priority: ImageParams,
    factors: array<FactorParams, 4>,
    cuts: u32,
    @size(12) padding: u32,
}

@group(0) @binding(0) var<uniform> synthesis: SynthesisParams;

// Pipeline constants that specialise the shader to one configuration, so that the compiler
// drops the code of the others (tessera sets them from the same SynthesisParams it uploads).
// Left at ANY, the default (and in `tessera shader export`), the uniform block decides.
const ANY: u32 = 0xffffffffu;
override TILING: u32 = ANY;
override BLEND: u32 = ANY;
override EXEMPLAR_FILTERING: u32 = ANY;
override PRIORITY_FILTERING: u32 = ANY;
override FACTOR_COUNT: u32 = ANY;
override FACTOR0_KIND: u32 = ANY;
override FACTOR1_KIND: u32 = ANY;
override FACTOR2_KIND: u32 = ANY;
override FACTOR3_KIND: u32 = ANY;
override CUTS: u32 = ANY;

fn specialised(constant: u32, uniform: u32) -> u32 {
    return select(constant, uniform, constant == ANY);
}

fn tiling_code() -> u32 {
    return specialised(TILING, synthesis.tiling);
}

// Tiles per point (k): 3 for the hexagonal paving, 4 for the square one. A constant where the
// paving is specialised, so that the loops over tiles unroll and their arrays stay in registers.
fn tile_count() -> u32 {
    return select(3u, 4u, tiling_code() == TILING_SQUARE);
}

fn blend_code() -> u32 {
    return specialised(BLEND, synthesis.blend);
}

fn exemplar_filtering() -> u32 {
    return specialised(EXEMPLAR_FILTERING, synthesis.exemplar.filtering);
}

fn priority_filtering() -> u32 {
    return specialised(PRIORITY_FILTERING, synthesis.priority.filtering);
}

// Whether the synthesis has cut bands (cuts.wgsl).
fn cuts_enabled() -> bool {
    return specialised(CUTS, synthesis.cuts) != 0u;
}

fn factor_count() -> u32 {
    return specialised(FACTOR_COUNT, synthesis.factor_count);
}

fn factor_kind(i: u32) -> u32 {
    let kinds = array<u32, 4>(FACTOR0_KIND, FACTOR1_KIND, FACTOR2_KIND, FACTOR3_KIND);
    return specialised(kinds[i], synthesis.factors[i].kind);
}
// The exemplar's MIP pyramid (the Gaussianized exemplar's for histogram preservation), f32 RGBA.
@group(0) @binding(1) var exemplar_image: texture_2d<f32>;
// The F map: channels F00, F01, F10, F11 (row-major), one level.
@group(0) @binding(2) var f_map_image: texture_2d<f32>;
// The Mix-Max priority map's pyramid: RGB = s less its mean, A its square.
@group(0) @binding(3) var priority_image: texture_2d<f32>;
// The inverse histogram tables: row L the tables of MIP level L, texel i at g = i / (width - 1).
@group(0) @binding(4) var inverse_tables_image: texture_2d<f32>;
// The sampler of FILTER_HARDWARE lookups: trilinear, repeat, anisotropic as tessera sets it.
@group(0) @binding(5) var hardware_sampler: sampler;

// Whether the surface a lookup is on has its UV map mirrored (TexCtx::uv_mirrored on the CPU):
// unknown without a surface (a bake of the UV square), or known from the sign of
// (dp/du x dp/dv) . n at a ray hit.
const SURFACE_NONE: u32 = 0u;
const SURFACE_UNMIRRORED: u32 = 1u;
const SURFACE_MIRRORED: u32 = 2u;

// A lookup: texture coordinates (bottom-left origin, v up), the footprint, and the surface's
// handedness (one of SURFACE_*).
struct TexCtx {
    uv: vec2<f32>,
    duv_dx: vec2<f32>,
    duv_dy: vec2<f32>,
    surface: u32,
}
