//! MIP pyramids and filtered lookups: bilinear at the finest level (`none`), trilinear, and
//! elliptically weighted averaging (`ewa`), with pbrt-v4's `MIPMap` semantics.
//! Texture coordinates wrap (repeat), or clamp to the edge texels ([`MipMap::clamped`]: the
//! tiles of paper 001, each filtered on its own).

use crate::image::Bitmap;
use crate::math::{ceil, floor, floor_index, floor_x4, floor2, int_x4, wrap_index};
use glam::{IVec4, Mat4, Vec2, Vec4};

/// How an image texture is filtered over the hit's footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Filter {
    /// Bilinear interpolation at the point, ignoring the footprint: the supersampled ground
    /// truth, and what Mitsuba 3.9's `bitmap` does.
    #[default]
    None,
    /// Bilinear on the two MIP levels bracketing the footprint's width, linearly blended.
    Trilinear,
    /// Elliptically weighted average over the footprint ellipse (Heckbert 1989; max anisotropy 8).
    Ewa,
}

/// Longest-to-shortest axis ratio beyond which the EWA ellipse is widened (pbrt-v4's default).
pub const MAX_ANISOTROPY: f32 = 8.0;
/// Entries of the Gaussian EWA weight table.
pub const EWA_LUT_SIZE: usize = 128;
/// Most texel rows and columns beyond the first that one EWA level visits. At the level EWA
/// reads, the ellipse's shorter axis is under 2 texels and its longer under 8 times that, so its
/// bounding box spans under 40 texels and the cap changes nothing, except on images whose
/// levels stop halving along one axis (a 1024 x 1 image read with a footprint of many
/// repeats): there it bounds the work, as the WGSL port must bound its loops.
pub const MAX_EWA_SPAN: i64 = 64;

/// Gaussian EWA weights exp(-2 r^2) - exp(-2) over r^2 in [0, 1] (pbrt's table).
static EWA_WEIGHTS: std::sync::LazyLock<[f32; EWA_LUT_SIZE]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|i| {
        let r2 = i as f32 / (EWA_LUT_SIZE - 1) as f32;
        (-2.0 * r2).exp() - (-2.0f32).exp()
    })
});

/// A footprint prepared for the lookups of one pyramid ([`MipMap::prepare`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PreparedFootprint {
    /// Bilinear at the finest level (no filter, or a degenerate EWA ellipse).
    Point,
    /// Trilinear at this continuous level.
    Levels(f32),
    /// EWA over an ellipse, at a continuous level.
    Ellipse {
        /// The longer axis, in image units.
        dst0: Vec2,
        /// The shorter axis (widened to the largest anisotropy), in image units.
        dst1: Vec2,
        /// The level.
        lod: f32,
    },
    /// Wider than the image: the coarsest level's one texel.
    Coarsest,
}

/// An image and its successively halved, box-filtered reductions down to 1x1.
#[derive(Clone, Debug)]
pub struct MipMap {
    levels: Vec<Bitmap>,
    /// Lookups outside the image read its edge texels instead of wrapping.
    clamp: bool,
}

/// Box-filter `src` to `new_len` samples along one axis (`horizontal` or vertical); each output
/// sample averages the input interval it covers, with fractional weights at the ends.
fn downsample_axis(src: &Bitmap, new_len: usize, horizontal: bool) -> Bitmap {
    let (w, h, ch) = (src.width, src.height, src.channels);
    let old_len = if horizontal { w } else { h };
    let ratio = old_len as f64 / new_len as f64;
    let mut out = if horizontal { Bitmap::new(new_len, h, ch) } else { Bitmap::new(w, new_len, ch) };
    // Per output index: (input index, weight) pairs.
    let taps: Vec<Vec<(usize, f32)>> = (0..new_len)
        .map(|i| {
            let (a, b) = (i as f64 * ratio, (i + 1) as f64 * ratio);
            (a.floor() as usize..(b.ceil() as usize).min(old_len))
                .map(|j| {
                    let overlap = (b.min(j as f64 + 1.0) - a.max(j as f64)).max(0.0);
                    (j, (overlap / ratio) as f32)
                })
                .filter(|t| t.1 > 0.0)
                .collect()
        })
        .collect();
    for y in 0..out.height {
        for x in 0..out.width {
            let (i, fixed) = if horizontal { (x, y) } else { (y, x) };
            let mut acc = [0.0f32; 4];
            for &(j, wt) in &taps[i] {
                let v = if horizontal { src.values(j, fixed) } else { src.values(fixed, j) };
                for c in 0..ch {
                    acc[c] += v[c] * wt;
                }
            }
            out.values_mut(x, y).copy_from_slice(&acc[..ch]);
        }
    }
    out
}

/// The Gaussian weight of a texel at squared ellipse radius `r2` in [0, 1): the table
/// interpolated linearly between its nodes r2 = i / (EWA_LUT_SIZE - 1), so that the weight is
/// continuous in r2 and a GPU, whose r2 differs from the CPU's in the last bits, gives the same
/// filtered value to within those bits (`ewa_weight` in `shaders/tiling_blending/mipmap.wgsl`).
#[inline(always)]
fn ewa_weight(lut: &[f32; EWA_LUT_SIZE], r2: f32) -> f32 {
    let x = r2 * (EWA_LUT_SIZE - 1) as f32;
    // Through u32, which x86-64 converts to and from f32 in an instruction or two (usize takes
    // a branch each way); the same saturation at 0 for negative r2 and NaN.
    let i = (x as u32).min(EWA_LUT_SIZE as u32 - 2);
    let t = x - i as f32;
    let i = i as usize;
    lut[i] * (1.0 - t) + lut[i + 1] * t
}

/// What a filtered lookup blends: one pyramid's texel, or two pyramids' read at one address
/// ([`MipMap::gather_pair`]). The filters are written once for both.
trait Texel:
    Copy + std::ops::Add<Output = Self> + std::ops::Mul<f32, Output = Self> + std::ops::Div<f32, Output = Self>
{
    const ZERO: Self;
}

impl Texel for Vec4 {
    const ZERO: Self = Vec4::ZERO;
}

/// The texels of two pyramids at one address, blended alike.
#[derive(Clone, Copy)]
struct TexelPair(Vec4, Vec4);

impl Texel for TexelPair {
    const ZERO: Self = TexelPair(Vec4::ZERO, Vec4::ZERO);
}

impl std::ops::Add for TexelPair {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        TexelPair(self.0 + o.0, self.1 + o.1)
    }
}

impl std::ops::Mul<f32> for TexelPair {
    type Output = Self;
    #[inline(always)]
    fn mul(self, w: f32) -> Self {
        TexelPair(self.0 * w, self.1 * w)
    }
}

impl std::ops::Div<f32> for TexelPair {
    type Output = Self;
    #[inline(always)]
    fn div(self, w: f32) -> Self {
        TexelPair(self.0 / w, self.1 / w)
    }
}

/// The texels a filtered lookup reads and how it weighs them ([`MipMap::taps`]), found once and
/// read from any pyramid of the same layout ([`MipMap::gather`], [`MipMap::same_layout`]): the
/// tiles of a Mix-Max blend read their priority maps there first, and their exemplar only where
/// their weight is not 0. An EWA ellipse's texels are found as they are read (they are too many
/// to list), so that its taps are read again in full: [`MipMap::gather_pair`] reads two pyramids
/// in one pass.
#[derive(Clone, Copy, Debug)]
pub struct Taps {
    kind: TapsKind,
    /// Level 0's width and height: a gather from a pyramid of another layout is a bug.
    #[cfg(debug_assertions)]
    base: (usize, usize),
}

impl Taps {
    /// Whether these are an EWA ellipse's, whose texels every gather finds again.
    pub fn is_ellipse(&self) -> bool {
        matches!(self.kind, TapsKind::Ellipse { .. })
    }
}

/// The taps of four lookups with one footprint, a lookup per lane of glam's `Vec4` (SSE2 on
/// x86-64): [`MipMap::taps`] of each point, addressed in one pass of lane arithmetic, which
/// [`MipMap::gather_two_channels_x4`] filters four lanes at once. The tiles of a tiling and
/// blending are up to four lookups with one footprint ([`MipMap::taps_x4`] says which
/// footprints).
#[derive(Clone, Copy, Debug)]
pub struct TapsX4 {
    /// The level at or below the footprint's.
    lower: BilinearTapsX4,
    /// The level above and its weight, where the footprint lies between two levels.
    upper: Option<(BilinearTapsX4, f32)>,
    /// Level 0's width and height, as in [`Taps`].
    #[cfg(debug_assertions)]
    base: (usize, usize),
}

impl TapsX4 {
    /// Lane `l`'s taps: bit for bit [`MipMap::taps`] at its point.
    #[inline(always)]
    pub fn lane(&self, l: usize) -> Taps {
        let kind = match self.upper {
            None => TapsKind::One(self.lower.lane(l)),
            Some((upper, t)) => TapsKind::Two(self.lower.lane(l), upper.lane(l), t),
        };
        Taps {
            kind,
            #[cfg(debug_assertions)]
            base: self.base,
        }
    }
}

/// [`BilinearTaps`] of four points at one level, a point per lane.
#[derive(Clone, Copy, Debug)]
struct BilinearTapsX4 {
    level: usize,
    /// The columns x0 and x1 of each lane.
    x: [IVec4; 2],
    /// The rows y0 and y1 of each lane.
    y: [IVec4; 2],
    fx: Vec4,
    fy: Vec4,
}

impl BilinearTapsX4 {
    /// Lane `l`'s taps. The lanes are read as arrays: glam's indexing of a vector by a
    /// run-time lane is a jump table, an indirect branch per lookup.
    #[inline(always)]
    fn lane(&self, l: usize) -> BilinearTaps {
        BilinearTaps {
            level: self.level as u32,
            x: self.x.map(|x| x.to_array()[l] as u32),
            y: self.y.map(|y| y.to_array()[l] as u32),
            fx: self.fx.to_array()[l],
            fy: self.fy.to_array()[l],
        }
    }

    /// [`BilinearTapsX4::read_channels`] of both channels of a two-channel `level`, bit for bit,
    /// a texel pair a load: each lane's two texels of a row side by side in one vector (the
    /// first column's two channels, then the second's), the four lanes' vectors transposed into
    /// a vector per column and channel.
    #[inline(always)]
    fn read_two_channels(&self, level: &Bitmap) -> [Vec4; 2] {
        debug_assert_eq!(level.channels, 2);
        let ([t00, t10], [t01, t11]) = (self.row_of_two_channels(level, 0), self.row_of_two_channels(level, 1));
        let (fx, gx, fy, gy) = (self.fx, Vec4::ONE - self.fx, self.fy, Vec4::ONE - self.fy);
        let blend = |c: usize| (t00[c] * gx + t10[c] * fx) * gy + (t01[c] * gx + t11[c] * fx) * fy;
        [blend(0), blend(1)]
    }

    /// Row `r` (0 or 1) of [`BilinearTapsX4::read_two_channels`]: at its first column and at
    /// its second, the two channels of each lane's texel.
    #[inline(always)]
    fn row_of_two_channels(&self, level: &Bitmap, r: usize) -> [[Vec4; 2]; 2] {
        let (texels, _) = level.data.as_chunks::<2>();
        let start = self.y[r] * IVec4::splat(level.width as i32);
        let (first, second) = ((start + self.x[0]).to_array(), (start + self.x[1]).to_array());
        let m = Mat4::from_cols(
            texel_pair(texels, first[0], second[0]),
            texel_pair(texels, first[1], second[1]),
            texel_pair(texels, first[2], second[2]),
            texel_pair(texels, first[3], second[3]),
        )
        .transpose();
        [[m.x_axis, m.y_axis], [m.z_axis, m.w_axis]]
    }

    /// The bilinear blend, in lanes, of channels `picks` of `level` (`C` channels a texel) at
    /// each lane's four texels, a vector per pick.
    #[inline(always)]
    fn read_channels<const C: usize, const N: usize>(&self, level: &Bitmap, picks: [usize; N]) -> [Vec4; N] {
        let width = IVec4::splat(level.width as i32);
        let (row0, row1) = (self.y[0] * width, self.y[1] * width);
        // A texel as one `[f32; C]`: one bounds check and one load each.
        let (texels, _) = level.data.as_chunks::<C>();
        let t00 = channels_x4(texels, row0 + self.x[0], picks);
        let t10 = channels_x4(texels, row0 + self.x[1], picks);
        let t01 = channels_x4(texels, row1 + self.x[0], picks);
        let t11 = channels_x4(texels, row1 + self.x[1], picks);
        let (fx, gx, fy, gy) = (self.fx, Vec4::ONE - self.fx, self.fy, Vec4::ONE - self.fy);
        let mut blended = [Vec4::ZERO; N];
        for (c, b) in blended.iter_mut().enumerate() {
            *b = (t00[c] * gx + t10[c] * fx) * gy + (t01[c] * gx + t11[c] * fx) * fy;
        }
        blended
    }
}

/// Along one axis of a level `n` texels long, the two texels a bilinear lookup at each lane's
/// wrapped coordinate `st` (in [0, 1], or NaN) reads and the fraction toward the second: as
/// [`MipMap::bilinear_taps`] finds them (`floor_index`, then `wrap_index`), in float lanes.
/// The first texel lies in [-1, n - 1] and the second in [0, n] before wrapping (a NaN
/// coordinate reads texels 0 and 1, with a NaN fraction).
#[inline(always)]
fn wrapped_texels_x4(st: Vec4, n: f32) -> ([IVec4; 2], Vec4) {
    let x = st * n - 0.5;
    let floor = floor_x4(x);
    let first = Vec4::select(floor.cmpeq(floor), floor, Vec4::ZERO);
    let n = Vec4::splat(n);
    let second = first + Vec4::ONE;
    let first = Vec4::select(first.cmplt(Vec4::ZERO), first + n, first);
    let second = Vec4::select(second.cmpge(n), second - n, second);
    ([int_x4(first), int_x4(second)], x - floor)
}

/// The blend of two adjacent levels' values in lanes, the upper weighing `t`: as
/// [`MipMap::gather`] blends a lookup's two levels.
#[inline(always)]
fn between_levels<const N: usize>(lower: [Vec4; N], upper: [Vec4; N], t: f32) -> [Vec4; N] {
    let mut blended = lower;
    for (b, u) in blended.iter_mut().zip(upper) {
        *b = *b * (1.0 - t) + u * t;
    }
    blended
}

/// The two channels of a two-channel level's texels at `first` and `second` (row-major
/// indices), side by side.
#[inline(always)]
fn texel_pair(texels: &[[f32; 2]], first: i32, second: i32) -> Vec4 {
    let (a, b) = (texels[first as usize], texels[second as usize]);
    Vec4::new(a[0], a[1], b[0], b[1])
}

/// Channels `picks` of the texels at `offsets` (row-major indices, a texel per lane) of a
/// level's `texels`, as a vector per pick.
#[inline(always)]
fn channels_x4<const C: usize, const N: usize>(texels: &[[f32; C]], offsets: IVec4, picks: [usize; N]) -> [Vec4; N] {
    // Lane by lane: an `array::map` over the lanes was a call that LLVM left out of line (the
    // picks, two or three, are mapped).
    let (a, b, c, d) = (
        texels[offsets.x as usize],
        texels[offsets.y as usize],
        texels[offsets.z as usize],
        texels[offsets.w as usize],
    );
    picks.map(|k| Vec4::new(a[k], b[k], c[k], d[k]))
}

#[derive(Clone, Copy, Debug)]
enum TapsKind {
    /// Bilinear at one level.
    One(BilinearTaps),
    /// Bilinear at two adjacent levels, the second weighing `t`.
    Two(BilinearTaps, BilinearTaps, f32),
    /// EWA over the ellipse at the levels around `lod` (`st` wrapped), its texels found as it is
    /// read.
    Ellipse { st: Vec2, dst0: Vec2, dst1: Vec2, lod: f32 },
    /// The coarsest level's one texel.
    Coarsest,
}

/// The four texels of a bilinear lookup at `level` (columns `x`, rows `y`, in range; levels are
/// narrower than 2^32 texels, [`Bitmap::size_f32`]) and the fractions toward the second of each.
#[derive(Clone, Copy, Debug)]
struct BilinearTaps {
    level: u32,
    x: [u32; 2],
    y: [u32; 2],
    fx: f32,
    fy: f32,
}

impl BilinearTaps {
    /// The bilinear blend of what `texel(level, x, y)` reads at the four texels.
    #[inline(always)]
    fn read<T: Texel>(&self, texel: impl Fn(usize, usize, usize) -> T) -> T {
        let Self { level, x, y, fx, fy } = *self;
        let texel = |x: u32, y: u32| texel(level as usize, x as usize, y as usize);
        let top = texel(x[0], y[0]) * (1.0 - fx) + texel(x[1], y[0]) * fx;
        let bottom = texel(x[0], y[1]) * (1.0 - fx) + texel(x[1], y[1]) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

impl MipMap {
    /// Build the pyramid: each level halves each side (rounding down, at least 1).
    pub fn new(base: Bitmap) -> Self {
        let mut levels = vec![base];
        loop {
            let last = levels.last().expect("at least the base");
            if last.width == 1 && last.height == 1 {
                break;
            }
            let (w, h) = ((last.width / 2).max(1), (last.height / 2).max(1));
            let half = downsample_axis(&downsample_axis(last, w, true), h, false);
            levels.push(half);
        }
        MipMap { levels, clamp: false }
    }

    /// The pyramid of `base` whose lookups clamp to the edge texels at every level instead of
    /// wrapping: nothing beyond the image's edge is ever read.
    pub fn clamped(base: Bitmap) -> Self {
        MipMap { clamp: true, ..MipMap::new(base) }
    }

    /// Number of levels.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Level `i` (0 = full resolution).
    pub fn level(&self, i: usize) -> &Bitmap {
        &self.levels[i]
    }

    /// Bytes held by all levels.
    pub fn memory_bytes(&self) -> usize {
        self.levels.iter().map(|l| l.data.len() * 4).sum()
    }

    /// Column or row `i` of a level `n` texels long: wrapped, or clamped to the edge.
    #[inline(always)]
    fn index(&self, i: i64, n: usize) -> usize {
        if self.clamp { i.clamp(0, n as i64 - 1) as usize } else { wrap_index(i, n) }
    }

    /// Bilinear interpolation of `level` at `st` (image coordinates in [0, 1]: x right, y down),
    /// with texel centres at ((i + 0.5) / W, (j + 0.5) / H).
    #[inline]
    pub fn bilinear(&self, level: usize, st: Vec2) -> Vec4 {
        self.bilinear_taps(level, st).read(|level, x, y| self.levels[level].pixel(x, y))
    }

    /// The texels and fractions of a bilinear lookup of `level` at `st`.
    #[inline(always)]
    fn bilinear_taps(&self, level: usize, st: Vec2) -> BilinearTaps {
        let l = &self.levels[level];
        let size = l.size_f32();
        let x = st.x * size.x - 0.5;
        let y = st.y * size.y - 0.5;
        let ((x0, fx), (y0, fy)) = (floor_index(x), floor_index(y));
        let x = [self.index(x0, l.width), self.index(x0 + 1, l.width)].map(|x| x as u32);
        let y = [self.index(y0, l.height), self.index(y0 + 1, l.height)].map(|y| y as u32);
        BilinearTaps { level: level as u32, x, y, fx, fy }
    }

    /// Filtered lookup at `st` with the footprint's image-space derivatives `dst0`, `dst1` (in
    /// [0, 1] image units per pixel).
    pub fn lookup(&self, filter: Filter, st: Vec2, dst0: Vec2, dst1: Vec2) -> Vec4 {
        self.lookup_prepared(&self.prepare(filter, dst0, dst1), st)
    }

    /// What every lookup with `filter` over the footprint `dst0`, `dst1` shares, wherever it
    /// reads: the MIP levels and the EWA ellipse. Lookups of several points with one footprint
    /// (the tiles of a tiling and blending) prepare it once.
    pub fn prepare(&self, filter: Filter, dst0: Vec2, dst1: Vec2) -> PreparedFootprint {
        match filter {
            Filter::None => PreparedFootprint::Point,
            Filter::Trilinear => PreparedFootprint::Levels(self.trilinear_lod(dst0, dst1)),
            Filter::Ewa => match self.ewa_axes(dst0, dst1) {
                // A footprint wider than the whole image reads the coarsest level, whose one
                // texel every weight would fall on (pbrt-v4 returns it too): looping over the
                // ellipse there would cost its area in texels, without bound.
                Some((_, _, shorter)) if shorter.log2() >= (self.levels.len() - 1) as f32 => {
                    PreparedFootprint::Coarsest
                }
                Some((dst0, dst1, shorter)) => PreparedFootprint::Ellipse { dst0, dst1, lod: self.lod(shorter) },
                None => PreparedFootprint::Point,
            },
        }
    }

    /// [`MipMap::lookup`] at `st` with a footprint prepared by [`MipMap::prepare`] (bit for bit).
    #[inline]
    pub fn lookup_prepared(&self, footprint: &PreparedFootprint, st: Vec2) -> Vec4 {
        self.gather(&self.taps(footprint, st))
    }

    /// Where [`MipMap::lookup_prepared`] reads at `st`: its texels and their weights, to be read
    /// from this pyramid or any of the same layout by [`MipMap::gather`].
    #[inline(always)]
    pub fn taps(&self, footprint: &PreparedFootprint, st: Vec2) -> Taps {
        // Wrap first so that f32 precision does not degrade far from the origin.
        let st = if self.clamp { st.clamp(Vec2::ZERO, Vec2::ONE) } else { st - floor2(st) };
        let kind = match *footprint {
            PreparedFootprint::Point => TapsKind::One(self.bilinear_taps(0, st)),
            PreparedFootprint::Levels(lod) => match self.levels_around(lod) {
                (i, None) => TapsKind::One(self.bilinear_taps(i, st)),
                (i, Some(t)) => TapsKind::Two(self.bilinear_taps(i, st), self.bilinear_taps(i + 1, st), t),
            },
            PreparedFootprint::Ellipse { dst0, dst1, lod } => TapsKind::Ellipse { st, dst0, dst1, lod },
            PreparedFootprint::Coarsest => TapsKind::Coarsest,
        };
        Taps {
            kind,
            #[cfg(debug_assertions)]
            base: (self.levels[0].width, self.levels[0].height),
        }
    }

    /// [`MipMap::taps`] of four points (image coordinates `s`, `t` by lane) with one footprint,
    /// in lanes ([`TapsX4`]); None where lanes do not pay: an EWA ellipse's taps, and those of a
    /// pyramid that clamps at its edges (wrapping alone is written in lanes).
    #[inline(always)]
    pub fn taps_x4(&self, footprint: &PreparedFootprint, s: Vec4, t: Vec4) -> Option<TapsX4> {
        let (lower, upper) = match *footprint {
            // Lanes hold texel columns and rows below 2^22 ([`int_x4`]), and texel indices
            // within a level as i32.
            _ if self.clamp
                || self.levels[0].width.max(self.levels[0].height) >= 1 << 22
                || self.levels[0].data.len() > i32::MAX as usize =>
            {
                return None;
            }
            PreparedFootprint::Point => (0, None),
            PreparedFootprint::Levels(lod) => self.levels_around(lod),
            PreparedFootprint::Ellipse { .. } | PreparedFootprint::Coarsest => return None,
        };
        // Wrapped first, as `taps` wraps.
        let (s, t) = (s - floor_x4(s), t - floor_x4(t));
        Some(TapsX4 {
            lower: self.bilinear_taps_x4(lower, s, t),
            upper: upper.map(|w| (self.bilinear_taps_x4(lower + 1, s, t), w)),
            #[cfg(debug_assertions)]
            base: (self.levels[0].width, self.levels[0].height),
        })
    }

    /// [`MipMap::bilinear_taps`] of four wrapped points, in lanes.
    #[inline(always)]
    fn bilinear_taps_x4(&self, level: usize, s: Vec4, t: Vec4) -> BilinearTapsX4 {
        let l = &self.levels[level];
        let size = l.size_f32();
        let (x, fx) = wrapped_texels_x4(s, size.x);
        let (y, fy) = wrapped_texels_x4(t, size.y);
        BilinearTapsX4 { level, x, y, fx, fy }
    }

    /// The two channels of this pyramid (which has two) filtered at each lane of `taps`, a
    /// vector per channel: bit for bit [`MipMap::gather`] of each [`TapsX4::lane`] (its x and w).
    #[inline(always)]
    pub fn gather_two_channels_x4(&self, taps: &TapsX4) -> [Vec4; 2] {
        assert_eq!(self.levels[0].channels, 2, "a two-channel gather of a {}-channel pyramid", self.levels[0].channels);
        #[cfg(debug_assertions)]
        assert_eq!(taps.base, (self.levels[0].width, self.levels[0].height), "taps of another layout");
        // A load per texel pair ([`BilinearTapsX4::read_two_channels`]).
        let lower = taps.lower.read_two_channels(&self.levels[taps.lower.level]);
        match taps.upper {
            None => lower,
            Some((upper, t)) => between_levels(lower, upper.read_two_channels(&self.levels[upper.level]), t),
        }
    }

    /// The red, green and blue of this pyramid filtered at each lane of `taps`, a vector per
    /// channel: bit for bit the x, y and z of [`MipMap::gather`] of each [`TapsX4::lane`]. None
    /// for more than four channels.
    #[inline(always)]
    pub fn gather_rgb_x4(&self, taps: &TapsX4) -> Option<[Vec4; 3]> {
        // Grey (and grey with alpha) is its grey in red, green and blue, as `Bitmap::pixel_of`.
        Some(match self.levels[0].channels {
            1 => self.gather_channels_x4::<1, 3>(taps, [0; 3]),
            2 => self.gather_channels_x4::<2, 3>(taps, [0; 3]),
            3 => self.gather_channels_x4::<3, 3>(taps, [0, 1, 2]),
            4 => self.gather_channels_x4::<4, 3>(taps, [0, 1, 2]),
            _ => return None,
        })
    }

    /// Channels `picks` of this pyramid (`C` channels a texel) filtered at each lane of `taps`.
    #[inline(always)]
    fn gather_channels_x4<const C: usize, const N: usize>(&self, taps: &TapsX4, picks: [usize; N]) -> [Vec4; N] {
        #[cfg(debug_assertions)]
        assert_eq!(taps.base, (self.levels[0].width, self.levels[0].height), "taps of another layout");
        let lower = taps.lower.read_channels::<C, N>(&self.levels[taps.lower.level], picks);
        match taps.upper {
            None => lower,
            Some((upper, t)) => between_levels(lower, upper.read_channels::<C, N>(&self.levels[upper.level], picks), t),
        }
    }

    /// The filtered value of this pyramid at `taps`, which [`MipMap::taps`] of a pyramid of the
    /// same layout ([`MipMap::same_layout`]) gave: that pyramid's lookup's weights applied to
    /// this one's texels, bit for bit this pyramid's own lookup.
    #[inline(always)]
    pub fn gather(&self, taps: &Taps) -> Vec4 {
        // Every level has the base's channels: their count is matched once, not at each texel.
        match self.levels[0].channels {
            1 => self.gather_with(taps, |level, x, y| self.levels[level].pixel_of::<1>(x, y)),
            2 => self.gather_with(taps, |level, x, y| self.levels[level].pixel_of::<2>(x, y)),
            3 => self.gather_with(taps, |level, x, y| self.levels[level].pixel_of::<3>(x, y)),
            _ => self.gather_with(taps, |level, x, y| self.levels[level].pixel_of::<4>(x, y)),
        }
    }

    /// [`MipMap::gather`] of this pyramid and of `other` (of the same layout) in one pass over
    /// the taps: for an EWA ellipse, one search of its texels.
    #[inline(always)]
    pub fn gather_pair(&self, other: &MipMap, taps: &Taps) -> (Vec4, Vec4) {
        // The channel counts matched once for the common pairs (an RGB or RGBA exemplar and
        // its two-channel Mix-Max priority map), at each texel for the others.
        let pair = match (self.levels[0].channels, other.levels[0].channels) {
            (3, 2) => self.gather_with(taps, |level, x, y| {
                TexelPair(self.levels[level].pixel_of::<3>(x, y), other.levels[level].pixel_of::<2>(x, y))
            }),
            (4, 2) => self.gather_with(taps, |level, x, y| {
                TexelPair(self.levels[level].pixel_of::<4>(x, y), other.levels[level].pixel_of::<2>(x, y))
            }),
            _ => self.gather_with(taps, |level, x, y| {
                TexelPair(self.levels[level].pixel(x, y), other.levels[level].pixel(x, y))
            }),
        };
        (pair.0, pair.1)
    }

    /// The filtered value at `taps` of what `texel(level, x, y)` reads (x, y in range).
    #[inline(always)]
    fn gather_with<T: Texel>(&self, taps: &Taps, texel: impl Fn(usize, usize, usize) -> T) -> T {
        #[cfg(debug_assertions)]
        assert_eq!(taps.base, (self.levels[0].width, self.levels[0].height), "taps of another layout");
        match taps.kind {
            TapsKind::One(taps) => taps.read(texel),
            TapsKind::Two(lower, upper, t) => lower.read(&texel) * (1.0 - t) + upper.read(&texel) * t,
            TapsKind::Ellipse { st, dst0, dst1, lod } => match self.levels_around(lod) {
                (i, None) => self.ewa_level(i, st, dst0, dst1, &texel),
                (i, Some(t)) => {
                    self.ewa_level(i, st, dst0, dst1, &texel) * (1.0 - t)
                        + self.ewa_level(i + 1, st, dst0, dst1, &texel) * t
                }
            },
            TapsKind::Coarsest => texel(self.levels.len() - 1, 0, 0),
        }
    }

    /// Whether `other`'s levels have the sizes of this one's, with the same edge handling, so
    /// that one texel address serves both ([`Taps`]). Constant time: every level's size follows
    /// from the base's (each halves the one before).
    pub fn same_layout(&self, other: &MipMap) -> bool {
        let (a, b) = (&self.levels[0], &other.levels[0]);
        self.clamp == other.clamp && (a.width, a.height) == (b.width, b.height)
    }

    /// The continuous MIP level a lookup with `filter` over the footprint `dst0`, `dst1` reads
    /// (0 for `none`; for `ewa`, the level of the ellipse's shorter axis after clamping).
    pub fn filter_lod(&self, filter: Filter, dst0: Vec2, dst1: Vec2) -> f32 {
        match filter {
            Filter::None => 0.0,
            Filter::Trilinear => self.trilinear_lod(dst0, dst1),
            Filter::Ewa => self.ewa_axes(dst0, dst1).map_or(0.0, |(_, _, shorter)| self.lod(shorter)),
        }
    }

    fn size(&self) -> Vec2 {
        self.levels[0].size_f32()
    }

    /// Level of a trilinear lookup: where the footprint's bounding square spans one texel.
    fn trilinear_lod(&self, dst0: Vec2, dst1: Vec2) -> f32 {
        let size = self.size();
        self.lod(2.0 * (dst0 * size).abs().max((dst1 * size).abs()).max_element())
    }

    /// Continuous level at which a footprint `width` texels wide (at level 0) spans one texel.
    fn lod(&self, width: f32) -> f32 {
        width.max(1e-8).log2().clamp(0.0, (self.levels.len() - 1) as f32)
    }

    /// The level at or below the continuous level `lod`, and the weight of the next one where
    /// `lod` lies strictly between two levels.
    #[inline(always)]
    fn levels_around(&self, lod: f32) -> (usize, Option<f32>) {
        // lod is not negative (or NaN: level 0, as the cast gives): its floor is its integer part.
        let (i, t) = floor_index(lod);
        let i = i as usize;
        (i, (t != 0.0 && i + 1 < self.levels.len()).then_some(t))
    }

    /// The EWA ellipse's axes (longer first, the shorter widened to at most `MAX_ANISOTROPY`
    /// times shorter than the longer) and the shorter one's length in texels (infinite when
    /// it overflows); None when the ellipse is degenerate.
    fn ewa_axes(&self, mut dst0: Vec2, mut dst1: Vec2) -> Option<(Vec2, Vec2, f32)> {
        let size = self.size();
        if (dst0 * size).length_squared() < (dst1 * size).length_squared() {
            std::mem::swap(&mut dst0, &mut dst1);
        }
        let longer = (dst0 * size).length();
        let mut shorter = (dst1 * size).length();
        // Widen overly eccentric ellipses: the lookup cost grows with the eccentricity.
        if shorter * MAX_ANISOTROPY < longer && shorter > 0.0 {
            let scale = longer / (shorter * MAX_ANISOTROPY);
            dst1 *= scale;
            shorter *= scale;
        }
        // An infinite length (a footprint beyond f32's range) is wider than any image.
        (shorter > 0.0).then_some((dst0, dst1, shorter))
    }

    /// EWA over one level: Gaussian weights inside the ellipse spanned by `dst0` and `dst1`
    /// (pbrt-v4 `MIPMap::EWA`). Not inlined: a loop over tens of texels gains nothing from it,
    /// and each gather would carry two copies.
    #[inline(never)]
    fn ewa_level<T: Texel>(
        &self,
        level: usize,
        st: Vec2,
        dst0: Vec2,
        dst1: Vec2,
        texel: &impl Fn(usize, usize, usize) -> T,
    ) -> T {
        let l = &self.levels[level];
        let res = l.size_f32();
        // The image repeats: start from the first period, so that the ellipse's bounds below are
        // a few texels apart however far out `st` is (far out, adjacent floats are millions of
        // texels apart, and the loops would run over all of them).
        let st = if self.clamp { st } else { st - floor2(st) };
        let c = st * res - Vec2::splat(0.5);
        let (d0, d1) = (dst0 * res, dst1 * res);
        // Implicit ellipse A x^2 + B x y + C y^2 < 1; the +1 keeps at least a texel's width.
        let mut a = d0.y * d0.y + d1.y * d1.y + 1.0;
        let mut b = -2.0 * (d0.x * d0.y + d1.x * d1.y);
        let mut cc = d0.x * d0.x + d1.x * d1.x + 1.0;
        let inv_f = 1.0 / (a * cc - b * b * 0.25);
        a *= inv_f;
        b *= inv_f;
        cc *= inv_f;
        let det = -b * b + 4.0 * a * cc;
        let inv_det = 1.0 / det;
        let u_sqrt = (det * cc).max(0.0).sqrt();
        let v_sqrt = (a * det).max(0.0).sqrt();
        let s0 = ceil(c.x - 2.0 * inv_det * u_sqrt) as i64;
        let s1 = (floor(c.x + 2.0 * inv_det * u_sqrt) as i64).min(s0 + MAX_EWA_SPAN);
        let t0 = ceil(c.y - 2.0 * inv_det * v_sqrt) as i64;
        let t1 = (floor(c.y + 2.0 * inv_det * v_sqrt) as i64).min(t0 + MAX_EWA_SPAN);
        let lut = &*EWA_WEIGHTS;
        let mut sum = T::ZERO;
        let mut weights = 0.0;
        for it in t0..=t1 {
            let tt = it as f32 - c.y;
            // The row's index once for the row (LLVM left it in the inner loop: 2.9% of scene
            // D's instructions).
            let y = self.index(it, l.height);
            for is in s0..=s1 {
                let ss = is as f32 - c.x;
                let r2 = a * ss * ss + b * ss * tt + cc * tt * tt;
                if r2 < 1.0 {
                    let w = ewa_weight(lut, r2);
                    sum = sum + texel(level, self.index(is, l.width), y) * w;
                    weights += w;
                }
            }
        }
        if weights > 0.0 { sum / weights } else { self.bilinear_taps(level, st).read(texel) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(n: usize) -> Bitmap {
        let mut b = Bitmap::new(n, n, 1);
        for y in 0..n {
            for x in 0..n {
                b.data[y * n + x] = ((x + y) % 2) as f32;
            }
        }
        b
    }

    #[test]
    fn mipmap_levels_preserve_the_mean() {
        for (w, h) in [(16, 16), (13, 7), (5, 1)] {
            let mut b = Bitmap::new(w, h, 1);
            for (i, v) in b.data.iter_mut().enumerate() {
                *v = ((i * 7919) % 13) as f32;
            }
            let mean = b.channel_means()[0];
            let m = MipMap::new(b);
            assert_eq!(m.level(m.level_count() - 1).width, 1);
            for i in 0..m.level_count() {
                let lm = m.level(i).channel_means()[0];
                assert!((lm - mean).abs() < 1e-4 * mean.max(1.0), "{w}x{h} level {i}: {lm} vs {mean}");
            }
        }
    }

    #[test]
    fn bilinear_hits_texel_centres_and_wraps() {
        let m = MipMap::new(checker(4));
        // Texel (1, 0) centre: st = (1.5/4, 0.5/4).
        assert_eq!(m.bilinear(0, Vec2::new(1.5 / 4.0, 0.5 / 4.0)).x, 1.0);
        // Halfway between texels: the mean.
        assert!((m.bilinear(0, Vec2::new(0.25, 0.125)).x - 0.5).abs() < 1e-6);
        // Wrapping: the left edge averages the first and last columns.
        assert!((m.bilinear(0, Vec2::new(0.0, 0.125)).x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn wide_footprints_average_the_checker() {
        let m = MipMap::new(checker(64));
        let d = Vec2::new(0.2, 0.0);
        for filter in [Filter::Trilinear, Filter::Ewa] {
            let v = m.lookup(filter, Vec2::new(0.3, 0.6), d, d.perp()).x;
            assert!((v - 0.5).abs() < 0.02, "{filter:?}: {v}");
        }
        // A footprint smaller than a texel reproduces the bilinear value.
        let st = Vec2::new(5.5 / 64.0, 9.5 / 64.0);
        let tiny = Vec2::new(1e-5, 0.0);
        for filter in [Filter::Trilinear, Filter::Ewa] {
            let v = m.lookup(filter, st, tiny, tiny.perp()).x;
            assert!((v - m.bilinear(0, st).x).abs() < 0.05, "{filter:?}: {v}");
        }
    }

    #[test]
    fn ewa_of_a_footprint_wider_than_the_image_is_its_mean() {
        let m = MipMap::new(checker(16));
        let mean = m.level(m.level_count() - 1).pixel(0, 0);
        for width in [1.0, 3.0, 1e6, 1e30] {
            let v = m.lookup(Filter::Ewa, Vec2::new(0.3, 0.6), Vec2::new(width, 0.0), Vec2::new(0.0, width));
            assert_eq!(v, mean, "width {width}");
        }
        // Far from the first period, the lookup is that of the same point in the first period
        // (to float rounding of the far coordinate).
        let near = m.lookup(Filter::Ewa, Vec2::new(0.25, 0.5), Vec2::new(0.1, 0.0), Vec2::new(0.0, 0.05));
        let far = m.lookup(Filter::Ewa, Vec2::new(4096.25, -8191.5), Vec2::new(0.1, 0.0), Vec2::new(0.0, 0.05));
        assert!((near - far).abs().max_element() < 1e-4, "{near} vs {far}");
    }

    #[test]
    fn bilinear_addresses_are_the_floors_and_wraps_of_the_texel_grid() {
        // The textbook address: texel centres at (i + 0.5) / n, repeat or clamp.
        let reference = |m: &MipMap, level: usize, st: Vec2| {
            let l = m.level(level);
            let axis = |s: f32, n: usize| {
                let x = s * n as f32 - 0.5;
                let i = x.floor() as i64;
                let at = |i: i64| if m.clamp { i.clamp(0, n as i64 - 1) } else { i.rem_euclid(n as i64) } as u32;
                ([at(i), at(i + 1)], x - x.floor())
            };
            let ((x, fx), (y, fy)) = (axis(st.x, l.width), axis(st.y, l.height));
            (level as u32, x, y, fx, fy)
        };
        for m in [MipMap::new(checker(37)), MipMap::clamped(checker(16)), MipMap::new(Bitmap::new(5, 64, 1))] {
            let mut points: Vec<Vec2> =
                (0..2000).map(|i| Vec2::new(i as f32 / 1999.0, (i * i % 1999) as f32 / 1998.0)).collect();
            points.extend([Vec2::ZERO, Vec2::ONE, Vec2::new(1.0, 0.0)]);
            for level in 0..m.level_count() {
                for &st in &points {
                    let taps = m.bilinear_taps(level, st);
                    assert_eq!((taps.level, taps.x, taps.y, taps.fx, taps.fy), reference(&m, level, st), "{st}");
                }
            }
            // A NaN coordinate reads texel 0 along its axis, with a NaN fraction.
            let taps = m.bilinear_taps(0, Vec2::new(f32::NAN, 0.5));
            assert!(taps.x == [0, 1] && taps.fx.is_nan());
        }
    }

    #[test]
    fn taps_gathered_from_two_pyramids_are_their_lookups_bit_for_bit() {
        let noise = |w: usize, h: usize, channels: usize, seed: usize| {
            let mut b = Bitmap::new(w, h, channels);
            for (i, v) in b.data.iter_mut().enumerate() {
                *v = (((i + seed) * 2_654_435_761) % 1000) as f32 / 1000.0;
            }
            b
        };
        for (a, b) in [
            (MipMap::new(noise(37, 20, 4, 1)), MipMap::new(noise(37, 20, 2, 2))),
            (MipMap::new(noise(20, 33, 3, 5)), MipMap::new(noise(20, 33, 2, 6))),
            (MipMap::clamped(noise(16, 16, 3, 3)), MipMap::clamped(noise(16, 16, 1, 4))),
        ] {
            for filter in [Filter::None, Filter::Trilinear, Filter::Ewa] {
                for i in 0..500 {
                    let st = Vec2::new(i as f32 * 0.0137 - 2.0, (i * i) as f32 * 0.0031 - 1.0);
                    let d0 = Vec2::from_angle(i as f32) * (0.3 / (1 + i % 50) as f32);
                    let d1 = d0.perp() * 0.4;
                    let taps = a.taps(&a.prepare(filter, d0, d1), st);
                    assert_eq!(a.gather(&taps), a.lookup(filter, st, d0, d1), "{filter:?} {st}");
                    assert_eq!(b.gather(&taps), b.lookup(filter, st, d0, d1), "{filter:?} {st}");
                    assert_eq!(a.gather_pair(&b, &taps), (a.gather(&taps), b.gather(&taps)), "{filter:?} {st}");
                }
            }
        }
        // Four points' taps in lanes are each point's taps, and their two-channel gather each
        // point's gather, bit for bit; far and NaN coordinates included.
        for (a, b) in [
            (MipMap::new(noise(37, 20, 3, 1)), MipMap::new(noise(37, 20, 2, 2))),
            (MipMap::new(noise(1, 9, 4, 3)), MipMap::new(noise(1, 9, 2, 4))),
        ] {
            for filter in [Filter::None, Filter::Trilinear] {
                for i in 0..500 {
                    let st: [Vec2; 4] = std::array::from_fn(|l| {
                        let j = (4 * i + l) as f32;
                        match (i + l) % 50 {
                            0 => Vec2::new(f32::NAN, 0.5),
                            1 => Vec2::new(1e9 + j, -3e7),
                            2 => Vec2::new(-1e-9, 1.0),
                            _ => Vec2::new(j * 0.0137 - 2.0, j * j * 0.0031 - 1.0),
                        }
                    });
                    let d0 = Vec2::from_angle(i as f32) * (0.3 / (1 + i % 50) as f32);
                    let footprint = a.prepare(filter, d0, d0.perp() * 0.4);
                    let lanes = |f: fn(Vec2) -> f32| Vec4::new(f(st[0]), f(st[1]), f(st[2]), f(st[3]));
                    let taps = a.taps_x4(&footprint, lanes(|p| p.x), lanes(|p| p.y)).expect("wrapping pyramids");
                    let [s, s2] = b.gather_two_channels_x4(&taps);
                    for (l, &p) in st.iter().enumerate() {
                        let one = a.taps(&footprint, p);
                        let bits = |v: Vec4| v.to_array().map(f32::to_bits);
                        assert_eq!(bits(a.gather(&taps.lane(l))), bits(a.gather(&one)), "{filter:?} {p}");
                        let v = b.gather(&one);
                        assert_eq!([s[l].to_bits(), s2[l].to_bits()], [v.x.to_bits(), v.w.to_bits()], "{filter:?} {p}");
                    }
                }
            }
        }
        // Lanes wrap only; an ellipse's taps are found as they are read.
        let clamped = MipMap::clamped(noise(16, 16, 3, 3));
        assert!(clamped.taps_x4(&PreparedFootprint::Point, Vec4::ZERO, Vec4::ZERO).is_none());
        let ewa = MipMap::new(noise(16, 16, 3, 3));
        let ellipse = ewa.prepare(Filter::Ewa, Vec2::new(0.1, 0.0), Vec2::new(0.0, 0.02));
        assert!(ewa.taps_x4(&ellipse, Vec4::ZERO, Vec4::ZERO).is_none());
        // Pyramids of other sizes or edge handling do not share taps.
        let square = MipMap::new(noise(8, 8, 1, 0));
        assert!(square.same_layout(&MipMap::new(noise(8, 8, 3, 0))));
        assert!(!square.same_layout(&MipMap::new(noise(8, 4, 1, 0))));
        assert!(!square.same_layout(&MipMap::clamped(noise(8, 8, 1, 0))));
    }
}
