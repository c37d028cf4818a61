// Filtered image lookups in f32 with explicit texel fetches (textureLoad): port of
// src/texture/mipmap.rs (bilinear between texel centres, repeat wrapping, trilinear with the
// level log2 of twice the footprint's largest extent in texels) and of ImageTexture::eval in
// src/texture/mod.rs.

// Image coordinates (s, t) of texture coordinates: t runs down from the image's top row. The
// one v-flip of the shaders (DESIGN.md section 3).
fn image_coordinates(uv: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(uv.x, 1.0 - uv.y);
}

fn wrap_index(i: i32, n: i32) -> i32 {
    return ((i % n) + n) % n;
}

// Texel (x, y) of a level `size` texels large, wrapped (repeat).
fn texel(image: texture_2d<f32>, level: u32, size: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
    return textureLoad(image, vec2<i32>(wrap_index(x, size.x), wrap_index(y, size.y)), i32(level));
}

// The size of MIP level `level`: the finest level's halved `level` times, at least 1 (the
// pyramid of MipMap::new). Computed rather than queried with textureDimensions(image, level),
// which Mesa 22's lavapipe answers with another SIMD lane's level when lanes read different
// levels.
fn level_size(image: texture_2d<f32>, level: u32) -> vec2<i32> {
    return vec2<i32>(max(textureDimensions(image) >> vec2<u32>(level), vec2<u32>(1u)));
}

// Bilinear interpolation between texel centres of one level; `st` in [0, 1).
fn bilinear(image: texture_2d<f32>, level: u32, st: vec2<f32>) -> vec4<f32> {
    let texels = level_size(image, level);
    let size = vec2<f32>(texels);
    let x = st.x * size.x - 0.5;
    let y = st.y * size.y - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let i = i32(x0);
    let j = i32(y0);
    let top = texel(image, level, texels, i, j) * (1.0 - fx) + texel(image, level, texels, i + 1, j) * fx;
    let bottom = texel(image, level, texels, i, j + 1) * (1.0 - fx) + texel(image, level, texels, i + 1, j + 1) * fx;
    return top * (1.0 - fy) + bottom * fy;
}

const FILTER_NONE: u32 = 0u;
const FILTER_TRILINEAR: u32 = 1u;
const FILTER_EWA: u32 = 2u;
const FILTER_HARDWARE: u32 = 3u;
// Longest-to-shortest axis ratio beyond which the EWA ellipse is widened.
const MAX_ANISOTROPY: f32 = 8.0;
// Nodes of the Gaussian EWA weight table.
const EWA_LUT_SIZE: u32 = 128u;
// Most texel rows and columns an EWA loop visits. At the level EWA reads, the ellipse's shorter
// axis is under 2 texels and its longer under 8 times that, widened by one texel: its bounding
// box spans under 40, so the cap never changes a finite lookup (the CPU asserts the same span);
// it bounds the loops whatever the footprint (NaN included), which lets the shader run without
// wgpu's loop counters.
const MAX_EWA_SPAN: i32 = 64;

// The continuous level of a footprint of width `width` texels of the finest level.
fn width_lod(params: ImageParams, width: f32) -> f32 {
    return clamp(log2(max(width, 1e-8)), 0.0, f32(params.levels - 1u));
}

fn trilinear_lod(image: texture_2d<f32>, params: ImageParams, dst0: vec2<f32>, dst1: vec2<f32>) -> f32 {
    let size = vec2<f32>(textureDimensions(image, 0u));
    let extent = max(abs(dst0 * size), abs(dst1 * size));
    return width_lod(params, 2.0 * max(extent.x, extent.y));
}

// The EWA ellipse's axes, longer first, the shorter widened to at most MAX_ANISOTROPY times
// shorter than the longer, and the shorter's length in texels (0: degenerate footprint).
struct EwaAxes {
    dst0: vec2<f32>,
    dst1: vec2<f32>,
    shorter: f32,
}

fn ewa_axes(image: texture_2d<f32>, dst0_in: vec2<f32>, dst1_in: vec2<f32>) -> EwaAxes {
    let size = vec2<f32>(textureDimensions(image, 0u));
    var dst0 = dst0_in;
    var dst1 = dst1_in;
    if dot(dst0 * size, dst0 * size) < dot(dst1 * size, dst1 * size) {
        dst0 = dst1_in;
        dst1 = dst0_in;
    }
    let longer = length(dst0 * size);
    var shorter = length(dst1 * size);
    if shorter * MAX_ANISOTROPY < longer && shorter > 0.0 {
        let scale = longer / (shorter * MAX_ANISOTROPY);
        dst1 *= scale;
        shorter *= scale;
    }
    return EwaAxes(dst0, dst1, shorter);
}

// The continuous MIP level of a footprint (image-coordinate steps `dst0`, `dst1`).
fn filter_lod(image: texture_2d<f32>, params: ImageParams, filtering: u32, dst0: vec2<f32>, dst1: vec2<f32>) -> f32 {
    switch filtering {
        case FILTER_TRILINEAR: {
            return trilinear_lod(image, params, dst0, dst1);
        }
        case FILTER_EWA: {
            let axes = ewa_axes(image, dst0, dst1);
            if axes.shorter > 0.0 {
                return width_lod(params, axes.shorter);
            }
            return 0.0;
        }
        case FILTER_HARDWARE: {
            // The isotropic level of detail of the WGSL specification: log2 of the longer
            // footprint axis in texels.
            let size = vec2<f32>(textureDimensions(image, 0u));
            let g = params.gradient_scale;
            return width_lod(params, g * max(length(dst0 * size), length(dst1 * size)));
        }
        default: {
            return 0.0;
        }
    }
}

// The Gaussian weight exp(-2 r2) - exp(-2) of the table node i.
fn ewa_node(i: u32) -> f32 {
    let r2 = f32(i) / f32(EWA_LUT_SIZE - 1u);
    return exp(-2.0 * r2) - exp(-2.0);
}

// The table's weight at r2 in [0, 1), linear between nodes (continuous in r2).
fn ewa_weight(r2: f32) -> f32 {
    let x = r2 * f32(EWA_LUT_SIZE - 1u);
    let i = min(u32(x), EWA_LUT_SIZE - 2u);
    let t = x - f32(i);
    return ewa_node(i) * (1.0 - t) + ewa_node(i + 1u) * t;
}

// The elliptically weighted average of one level (Heckbert 1989, pbrt's MIPMap::EWA).
fn ewa_level(image: texture_2d<f32>, level: u32, st: vec2<f32>, dst0: vec2<f32>, dst1: vec2<f32>) -> vec4<f32> {
    let texels = level_size(image, level);
    let res = vec2<f32>(texels);
    let c = st * res - vec2<f32>(0.5);
    let d0 = dst0 * res;
    let d1 = dst1 * res;
    var a = d0.y * d0.y + d1.y * d1.y + 1.0;
    var b = -2.0 * (d0.x * d0.y + d1.x * d1.y);
    var cc = d0.x * d0.x + d1.x * d1.x + 1.0;
    let inv_f = 1.0 / (a * cc - b * b * 0.25);
    a *= inv_f;
    b *= inv_f;
    cc *= inv_f;
    let det = -b * b + 4.0 * a * cc;
    let inv_det = 1.0 / det;
    let u_sqrt = sqrt(max(det * cc, 0.0));
    let v_sqrt = sqrt(max(a * det, 0.0));
    let s0 = i32(ceil(c.x - 2.0 * inv_det * u_sqrt));
    let s1 = min(i32(floor(c.x + 2.0 * inv_det * u_sqrt)), s0 + MAX_EWA_SPAN);
    let t0 = i32(ceil(c.y - 2.0 * inv_det * v_sqrt));
    let t1 = min(i32(floor(c.y + 2.0 * inv_det * v_sqrt)), t0 + MAX_EWA_SPAN);
    var sum = vec4<f32>(0.0);
    var weights = 0.0;
    for (var y = t0; y <= t1; y++) {
        let tt = f32(y) - c.y;
        for (var x = s0; x <= s1; x++) {
            let ss = f32(x) - c.x;
            let r2 = a * ss * ss + b * ss * tt + cc * tt * tt;
            if r2 < 1.0 {
                let w = ewa_weight(r2);
                sum += texel(image, level, texels, x, y) * w;
                weights += w;
            }
        }
    }
    if weights > 0.0 {
        return sum / weights;
    }
    return bilinear(image, level, st);
}

// EWA over the two levels bracketing the shorter axis.
fn ewa(image: texture_2d<f32>, params: ImageParams, st: vec2<f32>, dst0: vec2<f32>, dst1: vec2<f32>) -> vec4<f32> {
    let axes = ewa_axes(image, dst0, dst1);
    if !(axes.shorter > 0.0) {
        return bilinear(image, 0u, st);
    }
    if log2(axes.shorter) >= f32(params.levels - 1u) {
        return textureLoad(image, vec2<i32>(0, 0), i32(params.levels - 1u));
    }
    let lod = width_lod(params, axes.shorter);
    let level = u32(lod);
    let t = lod - f32(level);
    if t == 0.0 || level + 1u >= params.levels {
        return ewa_level(image, level, st, axes.dst0, axes.dst1);
    }
    return ewa_level(image, level, st, axes.dst0, axes.dst1) * (1.0 - t) + ewa_level(image, level + 1u, st, axes.dst0, axes.dst1) * t;
}

// The filtered value at image coordinates `st` (wrapped to [0, 1)) for the footprint.
fn mip_lookup(image: texture_2d<f32>, params: ImageParams, filtering: u32, st_in: vec2<f32>, dst0: vec2<f32>, dst1: vec2<f32>) -> vec4<f32> {
    let st = st_in - floor(st_in);
    switch filtering {
        case FILTER_TRILINEAR: {
            let lod = trilinear_lod(image, params, dst0, dst1);
            let level = u32(lod);
            let t = lod - f32(level);
            if t == 0.0 || level + 1u >= params.levels {
                return bilinear(image, level, st);
            }
            return bilinear(image, level, st) * (1.0 - t) + bilinear(image, level + 1u, st) * t;
        }
        case FILTER_EWA: {
            return ewa(image, params, st, dst0, dst1);
        }
        case FILTER_HARDWARE: {
            let g = params.gradient_scale;
            return textureSampleGrad(image, hardware_sampler, st, dst0 * g, dst1 * g);
        }
        default: {
            return bilinear(image, 0u, st);
        }
    }
}

// A uv step as a step in image coordinates (scaled, t down).
fn image_step(params: ImageParams, d: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(d.x * params.scale.x, -d.y * params.scale.y);
}

// An image texture at a lookup (ImageTexture::eval); `filtering` is params.filtering or its
// specialisation.
fn image_lookup(image: texture_2d<f32>, params: ImageParams, filtering: u32, ctx: TexCtx) -> vec4<f32> {
    let uv = ctx.uv * params.scale + params.offset;
    return mip_lookup(image, params, filtering, image_coordinates(uv), image_step(params, ctx.duv_dx), image_step(params, ctx.duv_dy));
}

// The continuous MIP level an image lookup reads (ImageTexture::lod).
fn image_lod(image: texture_2d<f32>, params: ImageParams, filtering: u32, ctx: TexCtx) -> f32 {
    return filter_lod(image, params, filtering, image_step(params, ctx.duv_dx), image_step(params, ctx.duv_dy));
}
