// A bake of a tiling-and-blending texture over the UV square (port of src/texture/bake.rs):
// texel (col, row) of a width x height image, row 0 at the top (v near 1), looked up at its
// centre with a one-texel footprint (footprint 0) or a point (footprint 1). One dispatch bakes
// the band of rows from first_row into bake_output (row first_row at index 0).

struct BakeParams {
    width: u32,
    height: u32,
    footprint: u32,
    first_row: u32,
}

@group(1) @binding(0) var<uniform> bake_params: BakeParams;
@group(1) @binding(1) var<storage, read_write> bake_output: array<vec4<f32>>;

@compute @workgroup_size(8, 8, 1)
fn bake(@builtin(global_invocation_id) id: vec3<u32>) {
    let width = bake_params.width;
    let height = bake_params.height;
    let row = bake_params.first_row + id.y;
    if id.x >= width || row >= height {
        return;
    }
    let size = vec2<f32>(f32(width), f32(height));
    var step = 1.0 / size;
    if bake_params.footprint != 0u {
        step = vec2<f32>(0.0);
    }
    let v = f32(height - 1u - row) + 0.5;
    let uv = vec2<f32>(f32(id.x) + 0.5, v) / size;
    let ctx = TexCtx(uv, vec2<f32>(step.x, 0.0), vec2<f32>(0.0, step.y), SURFACE_NONE);
    bake_output[id.y * width + id.x] = tiling_blending(ctx);
}
