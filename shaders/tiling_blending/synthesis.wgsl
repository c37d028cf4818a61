// The synthesis (paper 000 Eq. 1-3 and Sec. 6.1): port of
// src/texture/tiling_blending/synthesis.rs. Tile i of the paving is read at
// F(u) (u - c_i) + h_i with the footprint F(u) du/dx, F(u) du/dy; near a cut, the cut bands'
// rows of tiles too (cuts.wgsl).

struct TileLookup {
    ctx: TexCtx,
    weight: f32,
}

// Most lookups at a point: the paving's tiles and two tiles per cut band (MAX_LOOKUPS).
const MAX_LOOKUPS: u32 = 8u;

// The first `count` entries are valid: the paving's tile_count(), then the bands'.
struct Lookups {
    lookup: array<TileLookup, 8>,
    count: u32,
}

// How many lookups are valid: a constant without cut bands, so that loops over them unroll.
fn lookup_count(lookups: Lookups) -> u32 {
    return select(tile_count(), lookups.count, cuts_enabled());
}

// How far, per axis, a tile centred at `centre` reaches into the exemplar.
fn tile_reach(centre: vec2<f32>) -> vec2<f32> {
    let f = deformation_at(centre);
    var r = vec2<f32>(0.0);
    for (var i = 0u; i < support_corner_count(tiling_code()); i++) {
        r = max(r, abs(f * (support_corner(tiling_code(), i) * synthesis.tile_size)));
    }
    return r;
}

// A uniform shift narrowed, per axis where the tile fits, to keep the tile inside the square.
fn inset_shift(h: vec2<f32>, reach: vec2<f32>) -> vec2<f32> {
    let narrowed = reach + h * (vec2<f32>(1.0) - 2.0 * reach);
    return select(h, narrowed, reach < vec2<f32>(0.5));
}

// The tiles' exemplar lookups at `ctx` (Eq. 3).
fn synthesis_lookups(ctx: TexCtx) -> Lookups {
    let tiles = paving_tiles(tiling_code(), ctx.uv, synthesis.tile_size);
    let f = deformation_on_surface(ctx.uv, ctx.surface);
    var out: Lookups;
    for (var i = 0u; i < tile_count(); i++) {
        let tile = tiles.tile[i];
        var h = shift(tile.vertex, synthesis.seed);
        if synthesis.inset != 0u {
            h = inset_shift(h, tile_reach(tile.centre));
        }
        let offset = ctx.uv - tile.centre;
        out.lookup[i] = TileLookup(TexCtx(f * offset + h, f * ctx.duv_dx, f * ctx.duv_dy, SURFACE_NONE), tile.weight);
    }
    out.count = tile_count();
    if cuts_enabled() {
        band_lookups(ctx, f, &out);
    }
    return out;
}

// The largest singular value of m = [a b; c d] (math::largest_singular_value): the lengths of
// its conformal and anticonformal parts, with no cancellation.
fn largest_singular_value(m: mat2x2<f32>) -> f32 {
    let a = m[0].x;
    let c = m[0].y;
    let b = m[1].x;
    let d = m[1].y;
    return 0.5 * (length(vec2<f32>(a + d, c - b)) + length(vec2<f32>(a - d, c + b)));
}

// Append the cut bands' lookups at `ctx` after the paving's (f is F there), reweighting both
// (Synthesis::band_lookups): within a band of weight psi the paving weighs 1 - psi and the
// band's row psi; where two bands overlap, band b weighs psi_b (1 - psi_other), normalised.
fn band_lookups(ctx: TexCtx, f: mat2x2<f32>, out: ptr<function, Lookups>) {
    if cut_texel(ctx.uv).x == NO_CUT {
        return;
    }
    let f_map = map_on_surface(ctx.uv, ctx.surface);
    let bands = cut_bands_at(ctx.uv, f_map);
    let det = determinant(f_map);
    if (!bands[0].valid && !bands[1].valid) || !(abs(det) > 1e-20) {
        return;
    }
    // The factors other than the map, which carry map units to the exemplar's.
    let inv_det = 1.0 / det;
    let map_inverse = mat2x2<f32>(f_map[1].y * inv_det, -f_map[0].y * inv_det, -f_map[1].x * inv_det, f_map[0].x * inv_det);
    let other = f * map_inverse;
    let psi = vec2<f32>(select(0.0, bands[0].weight, bands[0].valid), select(0.0, bands[1].weight, bands[1].valid));
    var band_weight = vec2<f32>(psi.x * (1.0 - psi.y), psi.y * (1.0 - psi.x));
    var paving = (1.0 - psi.x) * (1.0 - psi.y);
    var total = paving + (band_weight.x + band_weight.y);
    if !(total > 1e-6) {
        // On two cuts at once (where they meet): the nearest alone.
        band_weight = vec2<f32>(1.0, 0.0);
        paving = 0.0;
        total = 1.0;
    }
    let k = tile_count();
    for (var i = 0u; i < k; i++) {
        (*out).lookup[i].weight *= paving / total;
    }
    let stretch = largest_singular_value(other);
    var n = k;
    for (var b = 0u; b < BANDS_PER_POINT; b++) {
        let band = bands[b];
        let w = band_weight[b];
        if !band.valid || w <= 0.0 {
            continue;
        }
        for (var j = 0u; j < 2u; j++) {
            var h = cut_shift(band.curve, band.m[j], synthesis.seed);
            if synthesis.inset != 0u {
                h = inset_shift(h, vec2<f32>(band.reach * stretch));
            }
            let offset = select(band.offset0, band.offset1, j == 1u);
            let lookup = TexCtx(other * offset + h, f * ctx.duv_dx, f * ctx.duv_dy, SURFACE_NONE);
            (*out).lookup[n] = TileLookup(lookup, band.tile_weight[j] * w / total);
            n++;
        }
    }
    (*out).count = n;
}

// The synthesised value at the lookup (Eq. 1 with the blending operator): port of
// TilingBlending::eval in src/texture/tiling_blending/mod.rs.
fn tiling_blending(ctx: TexCtx) -> vec4<f32> {
    let lookups = synthesis_lookups(ctx);
    let n = lookup_count(lookups);
    var values: array<vec4<f32>, 8>;
    for (var i = 0u; i < n; i++) {
        values[i] = image_lookup(exemplar_image, synthesis.exemplar, exemplar_filtering(), lookups.lookup[i].ctx);
    }
    let w = blend_weights(lookups);
    switch blend_code() {
        case BLEND_VARIANCE_PRESERVING: {
            return variance_preserving(w, values, synthesis.exemplar_mean, n);
        }
        case BLEND_HISTOGRAM_PRESERVING: {
            let g = variance_preserving(w, values, vec4<f32>(GAUSSIAN_MEAN), n);
            return invert_histogram(g, lookups.lookup[0].ctx);
        }
        default: {
            var sum = vec4<f32>(0.0);
            for (var i = 0u; i < n; i++) {
                sum += values[i] * w[i];
            }
            return sum;
        }
    }
}
