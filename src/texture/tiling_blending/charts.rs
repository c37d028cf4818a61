//! The UV charts of an F map, for tiles that read F at their centres
//! ([`super::FieldAt::TileCentre`]): the chart of each texel (the chart map `tessera deform`
//! writes), and, on a coarse grid of cells, for each chart within a tile's reach of a cell, that
//! chart's texel nearest to the cell. A tile whose centre lies in another chart than the point
//! then reads the point's chart's field at that texel: F extrapolated from the chart to the
//! centre, the same for every point of the chart, so the tile's lookup stays affine.

use crate::image::Bitmap;
use glam::Vec2;
use std::collections::VecDeque;

/// Most cell visits of [`Charts::new`] (about a second).
pub const MAX_CELL_VISITS: u64 = 1 << 27;

/// Most charts remembered per cell: the nearest ones.
const NEAR_CHARTS: usize = 6;

/// Cells per side of the grid at most (a chart's texel nearest to a cell, not to the point: F is
/// smooth on that scale).
const MAX_GRID: usize = 128;

/// A chart near a cell and its texel nearest to the cell's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
struct NearChart {
    chart: u32,
    /// Index of the texel in the chart map (row-major from row 0, the top).
    texel: u32,
    /// Squared distance from the cell's centre to the texel's, in UV units.
    distance2: f32,
}

/// The charts of an F map, and the charts near each cell of a coarse grid.
#[derive(Clone, Debug)]
pub struct Charts {
    width: usize,
    height: usize,
    /// The chart of each texel, row-major from row 0 (v = 1).
    chart: Vec<u32>,
    /// Cells per side.
    grid: usize,
    /// Per cell (row-major from the cell at v = 1), the nearest charts within reach, nearest first.
    near: Vec<Vec<NearChart>>,
}

impl Charts {
    /// The charts of `map` (one channel of whole chart numbers, row 0 at v = 1), with the charts
    /// within `reach` UV units of each cell found (a tile's support radius). An error when
    /// finding them would visit more than [`MAX_CELL_VISITS`] cells (charts times the cells
    /// within reach of one: a map of millions of charts, or tiles as large as the map).
    pub fn new(map: &Bitmap, reach: f32) -> Result<Charts, String> {
        let (width, height) = (map.width, map.height);
        let chart: Vec<u32> = map.data.iter().step_by(map.channels).map(|&c| c as u32).collect();
        let grid = width.max(height).clamp(1, MAX_GRID);
        let cell_centre = |cell: usize| Vec2::new((cell % grid) as f32 + 0.5, (cell / grid) as f32 + 0.5) / grid as f32;
        let size = Vec2::new(width as f32, height as f32);
        let texel_centre = |t: usize| Vec2::new((t % width) as f32 + 0.5, (t / width) as f32 + 0.5) / size;
        let cell_of_texel = |t: usize| {
            let p = texel_centre(t) * grid as f32;
            (p.y as usize).min(grid - 1) * grid + (p.x as usize).min(grid - 1)
        };
        // Each chart's texel nearest to each cell centre it covers: the seeds.
        let mut seeds: Vec<(u32, usize, u32)> = Vec::new(); // (chart, cell, texel)
        {
            let mut best: std::collections::HashMap<(u32, usize), (f32, u32)> = std::collections::HashMap::new();
            for (t, &c) in chart.iter().enumerate() {
                let cell = cell_of_texel(t);
                let d = texel_centre(t).distance_squared(cell_centre(cell));
                let entry = best.entry((c, cell)).or_insert((f32::INFINITY, 0));
                if d < entry.0 {
                    *entry = (d, t as u32);
                }
            }
            seeds.extend(best.into_iter().map(|((c, cell), (_, t))| (c, cell, t)));
            seeds.sort_unstable_by_key(|s| (s.0, s.1));
        }
        // A cell's centre is within half a cell's diagonal of any point in it.
        let reach_cells = (reach.max(0.0) * grid as f32).ceil().min(grid as f32) as i64 + 2;
        let charts = seeds.chunk_by(|a, b| a.0 == b.0).count() as u64;
        let box_cells = ((2 * reach_cells + 1) as u64).pow(2).min((grid * grid) as u64);
        if charts.saturating_mul(box_cells) > MAX_CELL_VISITS {
            return Err(format!(
                "{charts} charts with tiles reaching {reach} UV units would take over {MAX_CELL_VISITS} steps to \
                 relate: too many charts for field_at = \"tile_centre\""
            ));
        }
        let mut near: Vec<Vec<NearChart>> = vec![Vec::new(); grid * grid];
        // Per chart, a breadth-first spread of its seeds over the cells within reach, each cell
        // keeping the seed nearest to its centre among those its neighbours offer.
        let mut found: Vec<Option<(u32, f32, usize)>> = vec![None; grid * grid]; // (texel, d2, origin cell)
        let mut touched: Vec<usize> = Vec::new();
        let mut queue = VecDeque::new();
        for group in seeds.chunk_by(|a, b| a.0 == b.0) {
            let c = group[0].0;
            for &(_, cell, texel) in group {
                found[cell] = Some((texel, texel_centre(texel as usize).distance_squared(cell_centre(cell)), cell));
                touched.push(cell);
                queue.push_back(cell);
            }
            while let Some(cell) = queue.pop_front() {
                let (texel, _, origin) = found[cell].expect("queued cells are found");
                let (x, y) = ((cell % grid) as i64, (cell / grid) as i64);
                for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (1, -1), (-1, 1), (1, 1)] {
                    let (nx, ny) = (x + dx, y + dy);
                    let (ox, oy) = ((origin % grid) as i64, (origin / grid) as i64);
                    if nx < 0 || ny < 0 || nx >= grid as i64 || ny >= grid as i64 {
                        continue;
                    }
                    if (nx - ox).abs() > reach_cells || (ny - oy).abs() > reach_cells {
                        continue;
                    }
                    let next = ny as usize * grid + nx as usize;
                    let d = texel_centre(texel as usize).distance_squared(cell_centre(next));
                    match found[next] {
                        Some((_, best, _)) if best <= d => {}
                        previous => {
                            if previous.is_none() {
                                touched.push(next);
                            }
                            found[next] = Some((texel, d, origin));
                            queue.push_back(next);
                        }
                    }
                }
            }
            for cell in touched.drain(..) {
                let (texel, distance2, _) = found[cell].take().expect("touched cells are found");
                let list = &mut near[cell];
                list.push(NearChart { chart: c, texel, distance2 });
                list.sort_by(|a, b| a.distance2.total_cmp(&b.distance2));
                list.truncate(NEAR_CHARTS);
            }
        }
        Ok(Charts { width, height, chart, grid, near })
    }

    /// The texel under `uv` (the map repeats), row-major from row 0 at v = 1.
    fn texel(&self, uv: Vec2) -> usize {
        let p = super::super::image_coordinates(uv - crate::math::floor2(uv));
        let col = ((p.x * self.width as f32) as usize).min(self.width - 1);
        let row = ((p.y * self.height as f32) as usize).min(self.height - 1);
        row * self.width + col
    }

    /// The chart under `uv`.
    pub fn chart(&self, uv: Vec2) -> u32 {
        self.chart[self.texel(uv)]
    }

    /// Where a tile centred at `centre` reads F for the points of `chart`: the centre itself
    /// where it lies in that chart (the map repeats); else the centre of the chart's texel
    /// nearest to the centre's cell (off the UV square, to the border cell nearest to the
    /// centre), when the chart is within reach of it; None otherwise.
    pub fn field_point(&self, centre: Vec2, chart: u32) -> Option<Vec2> {
        if self.chart(centre) == chart {
            return Some(centre);
        }
        let p = super::super::image_coordinates(centre.clamp(Vec2::ZERO, Vec2::ONE));
        let cell = ((p.y * self.grid as f32) as usize).min(self.grid - 1) * self.grid
            + ((p.x * self.grid as f32) as usize).min(self.grid - 1);
        let near = self.near[cell].iter().find(|n| n.chart == chart)?;
        let (col, row) = (near.texel as usize % self.width, near.texel as usize / self.width);
        // Back from image coordinates (row 0 at v = 1) to UV.
        let image = Vec2::new((col as f32 + 0.5) / self.width as f32, (row as f32 + 0.5) / self.height as f32);
        Some(super::super::image_coordinates(image))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64 x 64 chart map: chart 0 left of u = 0.5, chart 1 right of it.
    fn halves() -> Bitmap {
        let mut map = Bitmap::new(64, 64, 1);
        for (k, c) in map.data.iter_mut().enumerate() {
            *c = if k % 64 >= 32 { 1.0 } else { 0.0 };
        }
        map
    }

    #[test]
    fn a_centre_in_another_chart_reads_the_nearest_point_of_the_point_s_chart() {
        let charts = Charts::new(&halves(), 0.1).unwrap();
        assert_eq!((charts.chart(Vec2::new(0.2, 0.3)), charts.chart(Vec2::new(0.7, 0.3))), (0, 1));
        // A centre inside the chart reads itself.
        let centre = Vec2::new(0.3, 0.4);
        assert_eq!(charts.field_point(centre, 0), Some(centre));
        // A centre 0.05 into chart 1 reads chart 0 at its border, at the same height.
        let p = charts.field_point(Vec2::new(0.55, 0.4), 0).unwrap();
        assert!((p.x - (31.5 / 64.0)).abs() < 1e-6 && (p.y - 0.4).abs() < 1.0 / 64.0, "{p}");
        assert_eq!(charts.chart(p), 0);
        // Beyond reach (0.1 and a cell) there is none.
        assert_eq!(charts.field_point(Vec2::new(0.75, 0.4), 0), None);
        // The map repeats: a centre left of u = 0 lies in chart 1 (at u = 0.98).
        let centre = Vec2::new(-0.02, 0.4);
        assert_eq!(charts.field_point(centre, 1), Some(centre));
    }

    #[test]
    fn a_map_of_too_many_charts_is_refused_at_once() {
        // 512 x 512 texels, each its own chart: 262,144 charts, with tiles reaching a quarter of
        // the map, would take about 10^12 steps.
        let mut map = Bitmap::new(512, 512, 1);
        map.data.iter_mut().enumerate().for_each(|(k, c)| *c = k as f32);
        let start = std::time::Instant::now();
        let msg = Charts::new(&map, 0.25).unwrap_err();
        assert!(msg.contains("too many charts"), "{msg}");
        assert!(start.elapsed().as_secs() < 10);
    }
}
