//! Piecewise-constant distributions for sampling by tabulated weights (pbrt-v4
//! `PiecewiseConstant1D/2D`): triangles of an emitter by area, cells of an environment map.

use glam::Vec2;

/// A piecewise-constant density over [0, 1] with `n` equal cells, proportional to the given
/// non-negative weights.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    weights: Vec<f32>,
    /// cdf[i] = mass of cells < i, normalised; n + 1 entries, cdf[n] = 1.
    cdf: Vec<f32>,
    /// Sum of weights / n (the integral of the step function over [0, 1]).
    integral: f32,
    /// A guide table (Chen and Asau 1974, "On generating random variates from an empirical
    /// distribution"): `guide[k]` is the number of `cdf` entries in buckets before `k`
    /// ([`Distribution1D::bucket`]), n + 1 entries, so that a search for u looks only at the
    /// entries of u's own bucket. Empty below [`GUIDED_CELLS`] cells, whose whole search is
    /// shorter than the guide's arithmetic.
    guide: Vec<u32>,
}

/// The fewest cells that [`Distribution1D`] builds a guide table for.
const GUIDED_CELLS: usize = 32;

/// A sample of a 1D distribution.
#[derive(Clone, Copy, Debug)]
pub struct Sample1D {
    /// Cell index.
    pub index: usize,
    /// Probability of the cell.
    pub pmf: f32,
    /// The uniform number rescaled to [0, 1) within the cell (for reuse).
    pub u_remapped: f32,
}

impl Distribution1D {
    /// Build from non-negative finite weights. Negative or non-finite weights count as 0; if
    /// all are 0, the distribution is uniform.
    pub fn new(weights: &[f32]) -> Self {
        assert!(!weights.is_empty(), "Distribution1D needs at least one cell");
        let mut weights: Vec<f32> = weights.iter().map(|&w| if w.is_finite() && w > 0.0 { w } else { 0.0 }).collect();
        let mut total: f64 = weights.iter().map(|&w| w as f64).sum();
        if total == 0.0 {
            weights.iter_mut().for_each(|w| *w = 1.0);
            total = weights.len() as f64;
        }
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut acc = 0.0f64;
        cdf.push(0.0);
        for &w in &weights {
            acc += w as f64;
            cdf.push((acc / total) as f32);
        }
        *cdf.last_mut().expect("non-empty") = 1.0;
        let integral = (total / weights.len() as f64) as f32;
        let guide = if weights.len() >= GUIDED_CELLS { Self::guide_table(&cdf, weights.len()) } else { Vec::new() };
        Distribution1D { weights, cdf, integral, guide }
    }

    /// The guide table of `cdf` over `buckets` buckets: per bucket k in 0..=buckets, the number
    /// of entries in the buckets before k.
    fn guide_table(cdf: &[f32], buckets: usize) -> Vec<u32> {
        let mut entries = 0;
        (0..=buckets)
            .map(|k| {
                while entries < cdf.len() && Self::bucket(cdf[entries], buckets) < k {
                    entries += 1;
                }
                entries as u32
            })
            .collect()
    }

    /// The bucket of a value x among `buckets` (floor(x buckets) in [0, buckets), NaN in 0): a
    /// non-decreasing function of x, so that every `cdf` entry of an earlier bucket than u's is
    /// below u, and every entry of a later one above it.
    #[inline(always)]
    fn bucket(x: f32, buckets: usize) -> usize {
        ((x * buckets as f32) as usize).min(buckets - 1)
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Always false: a distribution has at least one cell.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The integral of the (unnormalised) step function over [0, 1].
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Probability of cell `i`.
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.cdf[i + 1] - self.cdf[i]
    }

    /// Density at a point of cell `i` (per unit length of [0, 1]).
    #[inline]
    pub fn pdf_cell(&self, i: usize) -> f32 {
        self.weights[i] / self.integral
    }

    /// Pick a cell with probability proportional to its weight.
    #[inline]
    pub fn sample_discrete(&self, u: f32) -> Sample1D {
        // Largest i with cdf[i] <= u, skipping empty cells: the entries <= u are those of
        // earlier buckets and the first few of u's own.
        let (first, end) = if self.guide.is_empty() {
            (0, self.cdf.len())
        } else {
            let k = Self::bucket(u, self.len());
            (self.guide[k] as usize, self.guide[k + 1] as usize)
        };
        let at_most_u = first + self.cdf[first..end].partition_point(|&c| c <= u);
        let i = at_most_u.saturating_sub(1).min(self.len() - 1);
        let pmf = self.pmf(i);
        let u_remapped = if pmf > 0.0 { ((u - self.cdf[i]) / pmf).clamp(0.0, 1.0 - f32::EPSILON) } else { 0.0 };
        Sample1D { index: i, pmf, u_remapped }
    }

    /// A continuous sample in [0, 1) and its density.
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let s = self.sample_discrete(u);
        let x = (s.index as f32 + s.u_remapped) / self.len() as f32;
        (x, self.pdf_cell(s.index), s.index)
    }
}

/// A piecewise-constant density over [0, 1]^2 on a `width` x `height` grid: a marginal over
/// rows and a conditional over the columns of each row.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// Build from row-major weights (`height` rows of `width`).
    pub fn new(weights: &[f32], width: usize, height: usize) -> Self {
        assert_eq!(weights.len(), width * height);
        let rows: Vec<Distribution1D> = weights.chunks_exact(width).map(Distribution1D::new).collect();
        // A row whose weights were all zero became uniform; its marginal weight stays zero.
        let row_mass: Vec<f32> = weights
            .chunks_exact(width)
            .map(|r| r.iter().filter(|w| w.is_finite() && **w > 0.0).sum::<f32>() / width as f32)
            .collect();
        Distribution2D { rows, marginal: Distribution1D::new(&row_mass) }
    }

    /// Choose a cell with probability proportional to its weight: (column, row), its
    /// probability, and the uniform numbers rescaled to [0, 1) within the cell.
    pub fn sample_cell(&self, u: Vec2) -> (usize, usize, f32, Vec2) {
        let row = self.marginal.sample_discrete(u.y);
        let col = self.rows[row.index].sample_discrete(u.x);
        (col.index, row.index, col.pmf * row.pmf, Vec2::new(col.u_remapped, row.u_remapped))
    }

    /// Probability of cell (column, row).
    pub fn cell_pmf(&self, col: usize, row: usize) -> f32 {
        self.marginal.pmf(row) * self.rows[row].pmf(col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution1d_frequencies_follow_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0, 4.0]);
        let mut counts = [0usize; 4];
        let n = 80_000;
        for i in 0..n {
            let s = d.sample_discrete((i as f32 + 0.5) / n as f32);
            counts[s.index] += 1;
            assert!((0.0..1.0).contains(&s.u_remapped));
        }
        assert_eq!(counts[1], 0, "a zero-weight cell is never chosen");
        for (c, w) in counts.iter().zip([1.0, 0.0, 3.0, 4.0]) {
            assert!((*c as f32 / n as f32 - w / 8.0).abs() < 1e-3);
        }
        assert!((d.pdf_cell(2) - 3.0 / 2.0).abs() < 1e-6, "density = weight / mean weight");
    }

    #[test]
    fn the_guide_table_finds_the_cell_a_search_of_the_whole_cdf_finds() {
        // Flat stretches (many entries in one bucket), zero cells, one dominant cell, and
        // numbers at and around every cdf entry and bucket edge, out of range and NaN; the
        // first two tables are too small for a guide, the others have one.
        let mut rng = 0x9e37_79b9_u32;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            rng as f32 / u32::MAX as f32
        };
        let tables: Vec<Vec<f32>> = vec![
            vec![1.0],
            vec![0.0, 0.0, 5.0],
            (0..300).map(|i| if i == 150 { 1e6 } else { 1e-3 * (i % 7) as f32 }).collect(),
            (0..257).map(|_| next().powi(8)).collect(),
            (0..64).map(|i| if i % 3 == 0 { 0.0 } else { 1.0 }).collect(),
        ];
        for weights in &tables {
            let d = Distribution1D::new(weights);
            let whole = |u: f32| d.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(d.len() - 1);
            let n = d.len() as f32;
            let mut us: Vec<f32> = vec![-1.0, -0.0, 0.0, 1.0, 2.0, f32::NAN, f32::INFINITY, f32::MIN_POSITIVE];
            for &c in &d.cdf {
                us.extend([c, c.next_up(), c.next_down()]);
            }
            for k in 0..=d.len() {
                let edge = k as f32 / n;
                us.extend([edge, edge.next_up(), edge.next_down()]);
            }
            us.extend((0..20_000).map(|_| next()));
            for u in us {
                assert_eq!(d.sample_discrete(u).index, whole(u), "u = {u:e}, {} cells", d.len());
            }
        }
    }

    #[test]
    fn distribution2d_cells_follow_weights() {
        let weights = [1.0, 2.0, 0.0, 5.0, 0.5, 0.5];
        let d = Distribution2D::new(&weights, 3, 2);
        let total: f32 = weights.iter().sum();
        let mut counts = [0usize; 6];
        let n = 60_000;
        for i in 0..n {
            let u = Vec2::new(((i * 7919) % n) as f32 / n as f32, (i as f32 + 0.5) / n as f32);
            let (col, row, pmf, remapped) = d.sample_cell(u);
            assert!((pmf - weights[row * 3 + col] / total).abs() < 1e-6);
            assert!((d.cell_pmf(col, row) - pmf).abs() < 1e-7);
            assert!((0.0..1.0).contains(&remapped.x) && (0.0..1.0).contains(&remapped.y));
            counts[row * 3 + col] += 1;
        }
        assert_eq!(counts[2], 0, "a zero-weight cell is never chosen");
        for (c, w) in counts.iter().zip(weights) {
            assert!((*c as f32 / n as f32 - w / total).abs() < 0.01, "{counts:?}");
        }
    }
}
