// The synthesis (paper 000 Eq. 1-3 and Sec. 6.1): port of
// src/texture/tiling_blending/synthesis.rs. Tile i of the paving is read at
// F(u) (u - c_i) + h_i with the footprint F(u) du/dx, F(u) du/dy.

struct TileLookup {
    ctx: TexCtx,
    weight: f32,
}

// The first tile_count() entries are valid.
struct Lookups {
    lookup: array<TileLookup, 4>,
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
    return out;
}

// The synthesised value at the lookup (Eq. 1 with the blending operator): port of
// TilingBlending::eval in src/texture/tiling_blending/mod.rs.
fn tiling_blending(ctx: TexCtx) -> vec4<f32> {
    let lookups = synthesis_lookups(ctx);
    var values: array<vec4<f32>, 4>;
    for (var i = 0u; i < tile_count(); i++) {
        values[i] = image_lookup(exemplar_image, synthesis.exemplar, exemplar_filtering(), lookups.lookup[i].ctx);
    }
    let w = blend_weights(lookups);
    switch blend_code() {
        case BLEND_VARIANCE_PRESERVING: {
            return variance_preserving(w, values, synthesis.exemplar_mean);
        }
        case BLEND_HISTOGRAM_PRESERVING: {
            let g = variance_preserving(w, values, vec4<f32>(GAUSSIAN_MEAN));
            return invert_histogram(g, lookups.lookup[0].ctx);
        }
        default: {
            var sum = vec4<f32>(0.0);
            for (var i = 0u; i < tile_count(); i++) {
                sum += values[i] * w[i];
            }
            return sum;
        }
    }
}
