// The pavings (paper 000 Sec. 3.1): port of src/texture/tiling_blending/tiling.rs.

const MAX_TILES: u32 = 4u;
// sqrt(3) / 2: the hexagonal lattice's row height for a unit spacing.
const ROW_HEIGHT: f32 = 0.8660254;

struct Tile {
    vertex: vec2<i32>,
    centre: vec2<f32>,
    weight: f32,
}

// The tiles covering a point: the first tile_count() entries are valid.
struct Tiles {
    tile: array<Tile, 4>,
}

fn hex_vertex(v: vec2<i32>, size: f32) -> vec2<f32> {
    return vec2<f32>(f32(v.x) + 0.5 * f32(v.y), f32(v.y) * ROW_HEIGHT) * size;
}

fn hex_tile(vertex: vec2<i32>, size: f32, weight: f32) -> Tile {
    return Tile(vertex, hex_vertex(vertex, size), weight);
}

// k = 3: the triangle lattice; weights are barycentric coordinates.
fn hexagonal_tiles(uv: vec2<f32>, size: f32) -> Tiles {
    let y = uv.y / (size * ROW_HEIGHT);
    let x = uv.x / size - 0.5 * y;
    let base = vec2<f32>(floor(x), floor(y));
    let fx = x - base.x;
    let fy = y - base.y;
    let b = vec2<i32>(base);
    let fz = 1.0 - fx - fy;
    var out: Tiles;
    if fz > 0.0 {
        out.tile[0] = hex_tile(b, size, fz);
        out.tile[1] = hex_tile(b + vec2<i32>(1, 0), size, fx);
        out.tile[2] = hex_tile(b + vec2<i32>(0, 1), size, fy);
    } else {
        out.tile[0] = hex_tile(b + vec2<i32>(1, 1), size, -fz);
        out.tile[1] = hex_tile(b + vec2<i32>(0, 1), size, 1.0 - fx);
        out.tile[2] = hex_tile(b + vec2<i32>(1, 0), size, 1.0 - fy);
    }
    return out;
}

fn smoothstep01(t: f32) -> f32 {
    return t * t * (3.0 - 2.0 * t);
}

// k = 4: the square lattice; bilinear weights through smoothstep.
fn square_tiles(uv: vec2<f32>, size: f32) -> Tiles {
    let p = uv / size;
    let base = floor(p);
    let f = p - base;
    let sx = smoothstep01(f.x);
    let sy = smoothstep01(f.y);
    let b = vec2<i32>(base);
    var out: Tiles;
    out.tile[0] = Tile(b, vec2<f32>(b) * size, (1.0 - sx) * (1.0 - sy));
    out.tile[1] = Tile(b + vec2<i32>(1, 0), vec2<f32>(b + vec2<i32>(1, 0)) * size, sx * (1.0 - sy));
    out.tile[2] = Tile(b + vec2<i32>(0, 1), vec2<f32>(b + vec2<i32>(0, 1)) * size, (1.0 - sx) * sy);
    out.tile[3] = Tile(b + vec2<i32>(1, 1), vec2<f32>(b + vec2<i32>(1, 1)) * size, sx * sy);
    return out;
}

fn paving_tiles(tiling: u32, uv: vec2<f32>, size: f32) -> Tiles {
    if tiling == TILING_SQUARE {
        return square_tiles(uv, size);
    }
    return hexagonal_tiles(uv, size);
}

// Corner i of a tile's support relative to its centre for a unit spacing (support_corner_count of them).
fn support_corner(tiling: u32, i: u32) -> vec2<f32> {
    if tiling == TILING_SQUARE {
        let square = array<vec2<f32>, 4>(vec2(1.0, 1.0), vec2(-1.0, 1.0), vec2(-1.0, -1.0), vec2(1.0, -1.0));
        return square[i];
    }
    let hexagon = array<vec2<f32>, 6>(
        vec2(1.0, 0.0), vec2(0.5, ROW_HEIGHT), vec2(-0.5, ROW_HEIGHT),
        vec2(-1.0, 0.0), vec2(-0.5, -ROW_HEIGHT), vec2(0.5, -ROW_HEIGHT),
    );
    return hexagon[i];
}

fn support_corner_count(tiling: u32) -> u32 {
    if tiling == TILING_SQUARE {
        return 4u;
    }
    return 6u;
}
