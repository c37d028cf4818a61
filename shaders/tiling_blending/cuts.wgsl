// Cut bands: continuity of deformed tiling and blending across UV cuts (port of
// src/texture/tiling_blending/cuts.rs, where the construction is explained). Near a cut a point
// reads a 1D row of tiles laid along the cut's shared arc length s, at the developed coordinate
// g(s) - g(s_m) + F(u)(u - p) + h_m, blended against the paving by psi(d).

// Cut bands a point can be in at once.
const BANDS_PER_POINT: u32 = 2u;
// Segments either side of a texel's nearest one searched for a point's nearest.
const CUT_SEARCH: u32 = 4u;
// A texel's empty reference to a cut side.
const NO_CUT: u32 = 0xffffffffu;
// The key salt of the cut rows' shifts (shift.rs).
const CUT_SALT: u32 = 0x9e3779b9u;

// A point of a cut: its UV on both sides, its developed coordinate g and its arc length s.
struct CutPointParams {
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    g: vec2<f32>,
    s: f32,
    padding: u32,
}

// A cut: its points and its row's anchors g(s_m) in the buffers, and its tile spacing.
struct CutCurveParams {
    first_point: u32,
    point_count: u32,
    first_anchor: u32,
    anchor_count: u32,
    spacing: f32,
    @size(12) padding: u32,
}

// Per texel of the UV square (row 0 at v = 1): the nearest two cut sides, (curve, segment
// index times 2 plus the side) each; curve NO_CUT for none.
@group(0) @binding(6) var cut_texels: texture_2d<u32>;
@group(0) @binding(7) var<storage, read> cut_points: array<CutPointParams>;
@group(0) @binding(8) var<storage, read> cut_curves: array<CutCurveParams>;
@group(0) @binding(9) var<storage, read> cut_anchors: array<vec2<f32>>;

// A point's place in one cut's band (BandLookup): psi, the two tiles of the row covering it
// (index m, 1D weight, offset in map units) and the row's reach.
struct BandLookup {
    valid: bool,
    weight: f32,
    curve: u32,
    m: vec2<u32>,
    tile_weight: vec2<f32>,
    offset0: vec2<f32>,
    offset1: vec2<f32>,
    reach: f32,
}

// The shift of tile m of cut `curve`'s row.
fn cut_shift(curve: u32, m: u32, seed: u32) -> vec2<f32> {
    let bits = pcg3d(vec3<u32>(m, curve, seed ^ CUT_SALT));
    return vec2<f32>(f32(bits.x >> 8u), f32(bits.y >> 8u)) * (1.0 / 16777216.0);
}

// The references of the texel holding `uv` (clamped to the square).
fn cut_texel(uv: vec2<f32>) -> vec4<u32> {
    let res = i32(textureDimensions(cut_texels, 0u).x);
    let i = min(i32(max(uv.x * f32(res), 0.0)), res - 1);
    let j = min(i32(max(image_coordinates(uv).y * f32(res), 0.0)), res - 1);
    return textureLoad(cut_texels, vec2<i32>(i, j), 0);
}

// The parameter t in [0, 1] of the point of segment a-b nearest to p.
fn nearest_on_segment(p: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    let ab = b - a;
    return clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
}

fn cut_point_uv(point: CutPointParams, side: u32) -> vec2<f32> {
    return select(point.uv0, point.uv1, side == 1u);
}

// The band of cut side (curve, segment_side) at `uv`, f the F map's value there (CutBands::band).
fn cut_band(curve_index: u32, segment_side: u32, uv: vec2<f32>, f: mat2x2<f32>) -> BandLookup {
    var out: BandLookup;
    out.valid = false;
    let curve = cut_curves[curve_index];
    let side = segment_side % 2u;
    let segment = segment_side / 2u;
    let last = curve.point_count - 2u;
    let first = select(0u, segment - CUT_SEARCH, segment >= CUT_SEARCH);
    let count = min(segment + CUT_SEARCH, last) + 1u - first;
    // (distance, s, g, point) per segment of the window.
    var dist: array<f32, 9>;
    var arc: array<f32, 9>;
    var developed: array<vec2<f32>, 9>;
    var nearest: array<vec2<f32>, 9>;
    var closest = 3.40282347e38;
    var closest_k = 0u;
    for (var k = 0u; k < 2u * CUT_SEARCH + 1u; k++) {
        if k >= count {
            break;
        }
        let a = cut_points[curve.first_point + first + k];
        let b = cut_points[curve.first_point + first + k + 1u];
        let ua = cut_point_uv(a, side);
        let t = nearest_on_segment(uv, ua, cut_point_uv(b, side));
        let q = ua + (cut_point_uv(b, side) - ua) * t;
        dist[k] = distance(q, uv);
        arc[k] = a.s + (b.s - a.s) * t;
        developed[k] = a.g + (b.g - a.g) * t;
        nearest[k] = q;
        if dist[k] < closest {
            closest = dist[k];
            closest_k = k;
        }
    }
    let g = developed[closest_k];
    let p = nearest[closest_k];
    // The arc length for the row's weights: averaged over the segments nearly as near.
    let spread = 0.5 * closest + 1e-9;
    var s_sum = 0.0;
    var w_sum = 0.0;
    for (var k = 0u; k < 2u * CUT_SEARCH + 1u; k++) {
        if k >= count {
            break;
        }
        let x = max(1.0 - (dist[k] - closest) / spread, 0.0);
        let w = x * x;
        s_sum += w * arc[k];
        w_sum += w;
    }
    let s = s_sum / w_sum;
    let h = curve.spacing;
    let offset = f * (uv - p);
    let d = length(offset) / h;
    if !(d < 1.0) {
        return out;
    }
    let sigma = (s - cut_points[curve.first_point].s) / h;
    let m = u32(clamp(floor(sigma), 0.0, f32(curve.anchor_count - 2u)));
    let t = clamp(sigma - f32(m), 0.0, 1.0);
    out.valid = true;
    out.weight = 1.0 - d * d * (3.0 - 2.0 * d);
    out.curve = curve_index;
    out.m = vec2<u32>(m, m + 1u);
    out.tile_weight = vec2<f32>(1.0 - t, t);
    out.offset0 = g - cut_anchors[curve.first_anchor + m] + offset;
    out.offset1 = g - cut_anchors[curve.first_anchor + m + 1u] + offset;
    out.reach = 2.0 * h;
    return out;
}

// The bands `uv` lies in (CutBands::at), f the F map's value there.
fn cut_bands_at(uv: vec2<f32>, f: mat2x2<f32>) -> array<BandLookup, 2> {
    let refs = cut_texel(uv);
    var bands: array<BandLookup, 2>;
    bands[0].valid = false;
    bands[1].valid = false;
    if refs.x != NO_CUT {
        bands[0] = cut_band(refs.x, refs.y, uv, f);
    }
    if refs.z != NO_CUT {
        bands[1] = cut_band(refs.z, refs.w, uv, f);
    }
    return bands;
}
