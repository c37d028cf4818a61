// The rasterised view of `tessera gpu-view` (port of src/integrator/primary.rs): a mesh scene's
// primary visibility with a tiling-and-blending texture on every surface, looked up in the
// fragment shader at the pixel centre. The footprint comes either from screen-space derivatives
// of the interpolated UVs, as a real-time shader gets it (dpdx, or explicitly coarse or fine),
// or as tessera computes it: the rays through this pixel centre and the next ones right and
// down, met with the triangle's plane (ray differentials).

const DERIVATIVES_DPDX: u32 = 0u;
const DERIVATIVES_COARSE: u32 = 1u;
const DERIVATIVES_FINE: u32 = 2u;
const DERIVATIVES_RAY: u32 = 3u;
override DERIVATIVES: u32 = DERIVATIVES_DPDX;

// ViewParams in src/integrator/primary.rs; w components unused.
struct ViewParams {
    clip_from_world: mat4x4<f32>,
    eye: vec4<f32>,
    corner_direction: vec4<f32>,
    pixel_step_x: vec4<f32>,
    pixel_step_y: vec4<f32>,
}

// ViewTriangle in src/integrator/primary.rs: the corners and what the CPU derives from them.
struct ViewTriangle {
    p0: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
    ng: vec4<f32>,
    dpdu: vec4<f32>,
    dpdv: vec4<f32>,
    uv0: vec2<f32>,
    uv1: vec2<f32>,
    uv2: vec2<f32>,
    surface: u32,
    padding: u32,
}

@group(2) @binding(0) var<uniform> view: ViewParams;
@group(2) @binding(1) var<storage, read> view_triangles: array<ViewTriangle>;

struct ViewVertex {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) triangle: u32,
}

@vertex
fn view_vertex(
    @location(0) position: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) triangle: u32,
) -> ViewVertex {
    return ViewVertex(view.clip_from_world * vec4<f32>(position, 1.0), uv, triangle);
}

// True for a finite x (neither infinite nor NaN).
fn is_finite(x: f32) -> bool {
    return abs(x) <= 3.40282347e38;
}

// The UV step of a position step `dp` on the triangle's plane: least squares against dp/du and
// dp/dv (SurfaceInteraction::set_footprint), absurd values (grazing angles) kept from the filters.
fn uv_step(tri: ViewTriangle, dp: vec3<f32>) -> vec2<f32> {
    let a = tri.dpdu.xyz;
    let b = tri.dpdv.xyz;
    let ata00 = dot(a, a);
    let ata01 = dot(a, b);
    let ata11 = dot(b, b);
    let det = ata00 * ata11 - ata01 * ata01;
    let inv = select(0.0, 1.0 / det, abs(det) > 0.0);
    let atb0 = dot(a, dp);
    let atb1 = dot(b, dp);
    let step = vec2<f32>((ata11 * atb0 - ata01 * atb1) * inv, (ata00 * atb1 - ata01 * atb0) * inv);
    return vec2<f32>(
        select(0.0, clamp(step.x, -1e8, 1e8), is_finite(step.x)),
        select(0.0, clamp(step.y, -1e8, 1e8), is_finite(step.y)),
    );
}

// Where the camera ray through the next pixel (direction d + dd, from the eye as the main ray
// d) meets the plane through `p` with normal `n`, less p (RayDifferential::steps_on_plane:
// t' = t - k with k = t (n . dd) / (n . (d + dd)), the step dd (t - k) - d k; no difference of
// nearby points). Zero when the neighbour is parallel to the plane.
fn step_on_plane(d: vec3<f32>, dd: vec3<f32>, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let t = dot(p - view.eye.xyz, d) / dot(d, d);
    let k = (t * dot(n, dd)) / dot(n, d + dd);
    let step = dd * (t - k) - d * k;
    return select(vec3<f32>(0.0), step, is_finite(step.x) && is_finite(step.y) && is_finite(step.z));
}

// The lookup tessera makes where the camera ray through film point `film` (pixels from the
// top-left corner) meets triangle `tri` (primary_lookup: the ray's barycentric coordinates,
// the UV there, and the footprint from the rays through the next pixels right and down).
fn ray_lookup(tri: ViewTriangle, film: vec2<f32>) -> TexCtx {
    let eye = view.eye.xyz;
    let d = view.corner_direction.xyz + view.pixel_step_x.xyz * film.x + view.pixel_step_y.xyz * film.y;
    // Barycentric coordinates (Moller and Trumbore 1997).
    let e1 = tri.p1.xyz - tri.p0.xyz;
    let e2 = tri.p2.xyz - tri.p0.xyz;
    let q = cross(d, e2);
    let s = eye - tri.p0.xyz;
    let b1 = dot(s, q) / dot(e1, q);
    let b2 = dot(d, cross(s, e1)) / dot(e1, q);
    let b0 = 1.0 - b1 - b2;
    let p = tri.p0.xyz * b0 + tri.p1.xyz * b1 + tri.p2.xyz * b2;
    let uv = tri.uv0 * b0 + tri.uv1 * b1 + tri.uv2 * b2;
    let n = tri.ng.xyz;
    let dx = uv_step(tri, step_on_plane(d, view.pixel_step_x.xyz, p, n));
    let dy = uv_step(tri, step_on_plane(d, view.pixel_step_y.xyz, p, n));
    return TexCtx(uv, dx, dy, tri.surface);
}

struct ViewOutput {
    // The texture's value.
    @location(0) value: vec4<f32>,
    // The footprint (du/dx, dv/dx, du/dy, dv/dy).
    @location(1) footprint: vec4<f32>,
    // The triangle, plus one (0: nothing drawn).
    @location(2) triangle: u32,
}

@fragment
fn view_fragment(vertex: ViewVertex) -> ViewOutput {
    let tri = view_triangles[vertex.triangle];
    // Every derivative is taken here, in uniform control flow; the pipeline constant keeps one.
    let implementation = TexCtx(vertex.uv, dpdx(vertex.uv), dpdy(vertex.uv), tri.surface);
    let coarse = TexCtx(vertex.uv, dpdxCoarse(vertex.uv), dpdyCoarse(vertex.uv), tri.surface);
    let fine = TexCtx(vertex.uv, dpdxFine(vertex.uv), dpdyFine(vertex.uv), tri.surface);
    var ctx = implementation;
    switch DERIVATIVES {
        case DERIVATIVES_COARSE: {
            ctx = coarse;
        }
        case DERIVATIVES_FINE: {
            ctx = fine;
        }
        case DERIVATIVES_RAY: {
            ctx = ray_lookup(tri, vertex.position.xy);
        }
        default: {}
    }
    return ViewOutput(tiling_blending(ctx), vec4<f32>(ctx.duv_dx, ctx.duv_dy), vertex.triangle + 1u);
}
