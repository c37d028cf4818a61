// The pseudo-random shifts h_i (paper 000 Eq. 1): port of src/texture/tiling_blending/shift.rs.

// pcg3d of Jarzynski and Olano (JCGT 9(3), 2020).
fn pcg3d(key: vec3<u32>) -> vec3<u32> {
    var v = key * 1664525u + vec3<u32>(1013904223u);
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> vec3<u32>(16u);
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// The shift of lattice vertex `vertex` under the folded seed: 24 bits per axis in [0, 1).
fn shift(vertex: vec2<i32>, seed: u32) -> vec2<f32> {
    let bits = pcg3d(vec3<u32>(bitcast<vec2<u32>>(vertex), seed));
    return vec2<f32>(f32(bits.x >> 8u), f32(bits.y >> 8u)) * (1.0 / 16777216.0);
}
