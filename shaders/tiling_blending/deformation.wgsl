// The deformation field F(u) (paper 000 Eq. 3): port of
// src/texture/tiling_blending/deformation.rs. F = F_1 F_2 ... F_n, each factor and each partial
// product with its entries clamped to +-MAX_DEFORMATION (NaN to 0).

const MAX_DEFORMATION: f32 = 1048576.0;

fn bounded_entry(x: f32) -> f32 {
    // x != x is NaN's test.
    return select(clamp(x, -MAX_DEFORMATION, MAX_DEFORMATION), 0.0, x != x);
}

fn bounded(m: mat2x2<f32>) -> mat2x2<f32> {
    return mat2x2<f32>(
        bounded_entry(m[0].x), bounded_entry(m[0].y),
        bounded_entry(m[1].x), bounded_entry(m[1].y),
    );
}

fn factor_at(kind: u32, factor: FactorParams, uv: vec2<f32>) -> mat2x2<f32> {
    let p = factor.values;
    switch kind {
        case FACTOR_ROTATION: {
            let theta = p.x + dot(p.yz, uv);
            let s = sin(theta);
            let c = cos(theta);
            return mat2x2<f32>(c, s, -s, c);
        }
        case FACTOR_SCALE: {
            let s = p.xy * exp2(dot(p.zw, uv));
            return mat2x2<f32>(s.x, 0.0, 0.0, s.y);
        }
        case FACTOR_SHEAR: {
            return mat2x2<f32>(1.0, 0.0, p.x + dot(p.yz, uv), 1.0);
        }
        case FACTOR_MAP: {
            let f = bilinear(f_map_image, 0u, image_coordinates(uv - floor(uv)));
            return mat2x2<f32>(f.x, f.z, f.y, f.w);
        }
        default: {
            return mat2x2<f32>(p.x, p.y, p.z, p.w);
        }
    }
}

// An F map's value `m` mirrored, M m, where its handedness (det < 0 or not) is not the
// surface's (`surface`, one of SURFACE_*; as it is without a surface).
fn with_handedness(m: mat2x2<f32>, surface: u32) -> mat2x2<f32> {
    if surface != SURFACE_NONE && (determinant(m) < 0.0) != (surface == SURFACE_MIRRORED) {
        return mat2x2<f32>(1.0, 0.0, 0.0, -1.0) * m;
    }
    return m;
}

// F at `uv` on a surface of handedness `surface` (DeformationField::at_surface: the F map
// factor, of which the port takes one, is mirrored to the surface's handedness; the identity
// without factors).
fn deformation_on_surface(uv: vec2<f32>, surface: u32) -> mat2x2<f32> {
    var m = mat2x2<f32>(1.0, 0.0, 0.0, 1.0);
    for (var i = 0u; i < factor_count(); i++) {
        let kind = factor_kind(i);
        var f = bounded(factor_at(kind, synthesis.factors[i], uv));
        if kind == FACTOR_MAP {
            f = with_handedness(f, surface);
        }
        if i == 0u {
            m = f;
        } else {
            m = bounded(m * f);
        }
    }
    return m;
}

// F at `uv`, without a surface (DeformationField::at).
fn deformation_at(uv: vec2<f32>) -> mat2x2<f32> {
    return deformation_on_surface(uv, SURFACE_NONE);
}

// The F map factor at `uv`, mirrored as deformation_on_surface mirrors it
// (DeformationField::map_at): the field whose units cut bands measure in. Zero without a map.
fn map_on_surface(uv: vec2<f32>, surface: u32) -> mat2x2<f32> {
    for (var i = 0u; i < factor_count(); i++) {
        if factor_kind(i) == FACTOR_MAP {
            return with_handedness(bounded(factor_at(FACTOR_MAP, synthesis.factors[i], uv)), surface);
        }
    }
    return mat2x2<f32>(0.0, 0.0, 0.0, 0.0);
}
