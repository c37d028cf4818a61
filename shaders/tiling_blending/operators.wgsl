// The blending operators (paper 000 Eq. 1, DESIGN.md section 4): port of
// src/texture/tiling_blending/operators.rs (linear, variance-preserving, Mix-Max) and of the
// inverse histogram transformation of histogram.rs.

const GAUSSIAN_MEAN: f32 = 0.5;
const NEG_INFINITY: f32 = -3.40282347e38;

// Phi(x): Abramowitz-Stegun 7.1.26 for erf (as math::normal_cdf_f32).
fn normal_cdf(x: f32) -> f32 {
    let z = abs(x) * 0.70710677;
    let t = 1.0 / (1.0 + 0.3275911 * z);
    let poly = t * (0.2548296 + t * (-0.28449674 + t * (1.4214137 + t * (-1.4531521 + t * 1.0614054))));
    let erf = 1.0 - poly * exp(-z * z);
    return select(0.5 - 0.5 * erf, 0.5 + 0.5 * erf, x >= 0.0);
}

// P(X > 0) for X normal with mean `difference` and variance `variance`; a step at variance 0.
fn win_probability(difference: f32, variance: f32) -> f32 {
    if variance > 0.0 {
        return normal_cdf(difference / sqrt(variance));
    }
    if difference > 0.0 {
        return 1.0;
    }
    if difference < 0.0 {
        return 0.0;
    }
    return 0.5;
}

// The tiles' blending weights: the paving's, or Mix-Max's duels, normalised.
fn blend_weights(lookups: Lookups) -> array<f32, 8> {
    let n = lookup_count(lookups);
    var w: array<f32, 8>;
    for (var i = 0u; i < n; i++) {
        w[i] = lookups.lookup[i].weight;
    }
    if blend_code() != BLEND_MIX_MAX {
        return w;
    }
    let contrast = synthesis.mix_max.x;
    let lambda = synthesis.mix_max.y;
    var score: array<f32, 8>;
    var variance: array<f32, 8>;
    for (var i = 0u; i < n; i++) {
        score[i] = NEG_INFINITY;
        variance[i] = 0.0;
        if lookups.lookup[i].weight > 0.0 {
            let v = image_lookup(priority_image, synthesis.priority, priority_filtering(), lookups.lookup[i].ctx);
            score[i] = contrast * v.x + log(lookups.lookup[i].weight);
            variance[i] = contrast * contrast * max(v.w - v.x * v.x, 0.0);
        }
    }
    // Each pair of live tiles duels once: p to one weight, 1 - p to the other.
    var mixed: array<f32, 8>;
    for (var i = 0u; i < n; i++) {
        mixed[i] = select(0.0, 1.0, lookups.lookup[i].weight > 0.0);
    }
    for (var i = 0u; i < n; i++) {
        if lookups.lookup[i].weight > 0.0 {
            for (var j = i + 1u; j < n; j++) {
                if lookups.lookup[j].weight > 0.0 {
                    let p = win_probability(score[i] - score[j], variance[i] + variance[j] + 2.0 * lambda * lambda);
                    mixed[i] *= p;
                    mixed[j] *= 1.0 - p;
                }
            }
        }
    }
    var sum = 0.0;
    for (var i = 0u; i < n; i++) {
        sum += mixed[i];
    }
    if sum > 0.0 {
        for (var i = 0u; i < n; i++) {
            mixed[i] /= sum;
        }
        return mixed;
    }
    // Every tile lost every duel: the paving's weights.
    return w;
}

// m + sum w_i (v_i - m) / sqrt(sum w_i^2) over the first n lookups.
fn variance_preserving(w: array<f32, 8>, values: array<vec4<f32>, 8>, mean: vec4<f32>, n: u32) -> vec4<f32> {
    var norm2 = 0.0;
    var deviation = vec4<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        norm2 += w[i] * w[i];
        deviation += (values[i] - mean) * w[i];
    }
    return mean + deviation / sqrt(norm2);
}

// One inverse table (row `level`, channel `c`) at g, linear between entries, clamped.
fn inverse_table(level: u32, c: u32, g: f32) -> f32 {
    let n = textureDimensions(inverse_tables_image, 0u).x;
    let x = min(clamp(g, 0.0, 1.0) * f32(n - 1u), f32(n - 1u));
    let i = min(u32(x), n - 2u);
    let t = x - f32(i);
    let a = textureLoad(inverse_tables_image, vec2<u32>(i, level), 0)[c];
    let b = textureLoad(inverse_tables_image, vec2<u32>(i + 1u, level), 0)[c];
    return a * (1.0 - t) + b * t;
}

fn inverse_tables_at(level: u32, g: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(inverse_table(level, 0u, g.x), inverse_table(level, 1u, g.y), inverse_table(level, 2u, g.z), inverse_table(level, 3u, g.w));
}

// T^-1 of a blended Gaussian value for the MIP level the lookup `ctx` reads.
fn invert_histogram(g: vec4<f32>, ctx: TexCtx) -> vec4<f32> {
    let levels = textureDimensions(inverse_tables_image, 0u).y;
    let lod = clamp(image_lod(exemplar_image, synthesis.exemplar, exemplar_filtering(), ctx), 0.0, f32(levels - 1u));
    let level = u32(floor(lod));
    let t = lod - f32(level);
    if t == 0.0 {
        return inverse_tables_at(level, g);
    }
    return inverse_tables_at(level, g) * (1.0 - t) + inverse_tables_at(level + 1u, g) * t;
}
