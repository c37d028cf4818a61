//! The textures of paper 002 Sec. 3 as named presets: point distributions and attribute
//! assignments that build one or more PUPs fields, summed into a [`PupsTexture`].

use super::field::{ControlPoints, PupsField};
use super::points::{Domain, poisson_disk, spacing_for_count};
use crate::image::Bitmap;
use crate::sampling::Sampler;
use glam::{Vec2, Vec3, Vec4};

/// The named presets, each after a figure of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// Fig. 7: random values at Poisson disk points, interpolated (Perlin-like noise).
    Noise,
    /// Fig. 6, Eq. 5: four octaves of noise, each with twice the density and half the amplitude.
    Octaves,
    /// Fig. 8: the octaves folded (2 |T - 0.5|) and summed (Perlin turbulence).
    Turbulence,
    /// Fig. 9a: one cell per point, oriented points curving the borders (Voronoi-like cells).
    Cells,
    /// Fig. 9b: cells of three or four points.
    ClusteredCells,
    /// Fig. 10: four layers of grey cells of increasing density, summed like octaves.
    MultiscaleCells,
    /// Fig. 11: random binary labels (cow).
    Cow,
    /// Fig. 12: spots ringed by pairs of inner (spot) and outer (background) points.
    SpaceGiraffe,
    /// Fig. 13: labels drawn with the intensity of a reference image as probability.
    ReferenceLabels,
    /// Fig. 14: four rounds of reference labels, each with twice the points, its probabilities
    /// read from the previous round's interpolated intensity (fractal boundaries).
    Iterative,
    /// Fig. 15: cow labels on points whose density grows from left to right.
    ProgressiveCow,
    /// Fig. 16: space giraffe spots whose density grows from left to right.
    ProgressiveGiraffe,
    /// Fig. 17: stationary points labelled white with a probability that grows with x.
    LabelRamp,
}

impl Preset {
    /// Every preset, in the paper's order.
    pub const ALL: [Preset; 13] = [
        Preset::Noise,
        Preset::Octaves,
        Preset::Turbulence,
        Preset::Cells,
        Preset::ClusteredCells,
        Preset::MultiscaleCells,
        Preset::Cow,
        Preset::SpaceGiraffe,
        Preset::ReferenceLabels,
        Preset::Iterative,
        Preset::ProgressiveCow,
        Preset::ProgressiveGiraffe,
        Preset::LabelRamp,
    ];

    /// The preset's name as the command line and scenes spell it (kebab case).
    pub fn name(self) -> String {
        clap::ValueEnum::to_possible_value(&self).map_or_else(String::new, |v| v.get_name().to_string())
    }
}

/// What a preset is built from.
#[derive(Clone, Debug)]
pub struct PresetParams {
    /// About how many control points the preset's base layer has over the unit square.
    pub points: u32,
    /// Seed of the points and their attributes.
    pub seed: u64,
    /// Whether the texture tiles (a periodic domain).
    pub tileable: bool,
    /// Orientation strength epsilon of Eq. 4 (the paper's default 0.5).
    pub epsilon: f32,
    /// Axis length scale (Fig. 4; 1 is the paper's normal length).
    pub axis_scale: f32,
    /// A grey reference image for the label presets of Fig. 13-14 (a built-in disc and ramp
    /// when None).
    pub reference: Option<Bitmap>,
    /// A grey density image: the base points' spacing goes from twice the base where it is
    /// black to half where it is white (presets without their own density ramp).
    pub density: Option<Bitmap>,
}

impl Default for PresetParams {
    fn default() -> Self {
        PresetParams {
            points: 700,
            seed: 0,
            tileable: false,
            epsilon: 0.5,
            axis_scale: 1.0,
            reference: None,
            density: None,
        }
    }
}

/// How a layer turns its field into a colour.
#[derive(Clone, Debug)]
enum Output {
    /// The interpolated value (Eq. 3).
    Value,
    /// The value folded: 2 |T - 0.5| (turbulence).
    Folded,
    /// The colour of the label with the largest weight.
    Label(Vec<Vec3>),
}

/// One field of a texture, its output and its amplitude.
#[derive(Clone, Debug)]
struct Layer {
    field: PupsField,
    output: Output,
    amplitude: f32,
}

/// How a PUPs texture is filtered over a lookup's footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum PupsFilter {
    /// The value at the point (the ground truth when pixels are supersampled).
    #[default]
    None,
    /// The mean of k x k stratified points over the footprint's parallelogram, k from 1 to
    /// [`MAX_TAPS`] growing with the footprint's width over the finest point spacing.
    Supersample,
}

/// Most taps per side of the footprint supersampling.
pub const MAX_TAPS: usize = 4;

/// A PUPs texture: the sum of its layers' amplitudes times their outputs.
#[derive(Clone, Debug)]
pub struct PupsTexture {
    layers: Vec<Layer>,
    /// The finest layer's typical point spacing (the size of its features).
    feature: f32,
}

impl PupsTexture {
    /// The value over the footprint `duv_dx`, `duv_dy` around `uv` with `filter`.
    pub fn eval_filtered(&self, uv: Vec2, duv_dx: Vec2, duv_dy: Vec2, filter: PupsFilter) -> Vec4 {
        let width = duv_dx.abs().max(duv_dy.abs()).max_element();
        let taps = match filter {
            PupsFilter::None => 1,
            // Two taps per feature across the footprint.
            PupsFilter::Supersample => ((2.0 * width / self.feature).ceil() as usize).clamp(1, MAX_TAPS),
        };
        if taps == 1 {
            return self.eval(uv);
        }
        let mut sum = Vec4::ZERO;
        for j in 0..taps {
            for i in 0..taps {
                let (s, t) = ((i as f32 + 0.5) / taps as f32 - 0.5, (j as f32 + 0.5) / taps as f32 - 0.5);
                sum += self.eval(uv + duv_dx * s + duv_dy * t);
            }
        }
        sum / (taps * taps) as f32
    }

    /// RGBA value at `uv` (alpha 1).
    pub fn eval(&self, uv: Vec2) -> Vec4 {
        let mut sum = Vec3::ZERO;
        for layer in &self.layers {
            let v = match &layer.output {
                Output::Value => layer.field.value(uv),
                Output::Folded => (layer.field.value(uv) - Vec3::splat(0.5)).abs() * 2.0,
                Output::Label(palette) => palette[layer.field.label(uv) as usize % palette.len()],
            };
            sum += v * layer.amplitude;
        }
        sum.extend(1.0)
    }

    /// Control points over all layers.
    pub fn point_count(&self) -> usize {
        self.layers.iter().map(|l| l.field.point_count()).sum()
    }

    /// Approximate memory held, in bytes.
    pub fn memory_bytes(&self) -> usize {
        // Centres, axes (about six per centre), grid entries and attributes.
        self.point_count() * (8 + 6 * 8 + 8 * 4 + 40)
    }

    /// The texture of `preset` with `params`.
    pub fn preset(preset: Preset, params: &PresetParams) -> Result<Self, String> {
        Builder::new(params)?.build(preset)
    }

    /// The texture of given control points (a points file): their values blended (Eq. 3), or
    /// with `labels` each point's label showing the colour of the label's first point, taken
    /// by the largest weight (cells).
    pub fn from_points(
        mut points: ControlPoints,
        tileable: bool,
        axis_scale: f32,
        epsilon: f32,
        labels: bool,
    ) -> Result<Self, String> {
        let domain = if tileable { Domain::Periodic } else { Domain::Square { margin: 0.0 } };
        let output = if labels {
            // Labels renumbered densely in order of appearance; each shows its first point's colour.
            let mut dense = std::collections::HashMap::new();
            let mut palette = Vec::new();
            for (label, value) in points.labels.iter_mut().zip(&points.values) {
                *label = *dense.entry(*label).or_insert_with(|| {
                    palette.push(*value);
                    palette.len() as u32 - 1
                });
            }
            Output::Label(palette)
        } else {
            Output::Value
        };
        let field = PupsField::new(&points, domain, axis_scale, epsilon)?;
        Ok(PupsTexture::new(vec![Layer { field, output, amplitude: 1.0 }]))
    }

    fn new(layers: Vec<Layer>) -> Self {
        let finest = layers.iter().map(|l| l.field.point_count()).max().unwrap_or(1);
        PupsTexture { layers, feature: (1.0 / finest.max(1) as f32).sqrt() }
    }
}

/// Fewest points a preset is asked for: a Poisson disk draw of fewer may leave fewer than three.
pub const MIN_POINTS: u32 = 16;

/// Builds presets: draws points, assigns attributes, makes fields.
struct Builder<'a> {
    params: &'a PresetParams,
    domain: Domain,
    sampler: Sampler,
    spacing: f32,
}

/// The two colours of binary labels (cow, giraffe backgrounds): near black and near white.
const BLACK_WHITE: [Vec3; 2] = [Vec3::new(0.03, 0.03, 0.03), Vec3::new(0.9, 0.88, 0.85)];
/// Space giraffe: spots and the background between them.
const GIRAFFE: [Vec3; 2] = [Vec3::new(0.85, 0.75, 0.55), Vec3::new(0.35, 0.17, 0.05)];

impl<'a> Builder<'a> {
    fn new(params: &'a PresetParams) -> Result<Self, String> {
        if !(MIN_POINTS..=super::points::MAX_POINTS as u32).contains(&params.points) {
            return Err(format!("{} points: give {MIN_POINTS} to {}", params.points, super::points::MAX_POINTS));
        }
        let spacing = spacing_for_count(params.points);
        let domain = if params.tileable { Domain::Periodic } else { Domain::Square { margin: 3.0 * spacing } };
        Ok(Builder { params, domain, sampler: Sampler::new(params.seed, 0x7075_7073, 0), spacing })
    }

    /// A Poisson disk distribution with `spacing` times the base spacing (uniform), or from
    /// `dense` to `sparse` times it across x (a density ramp, denser to the right).
    fn points(&mut self, scale: f32, ramp: Option<(f32, f32)>) -> Result<Vec<Vec2>, String> {
        let seed = (self.sampler.next_1d() * 16_777_216.0) as u64;
        let base = self.spacing * scale;
        // A density image, where the preset has no ramp of its own: bright is dense, the
        // spacing from 2 (black) to 0.5 (white) times the base.
        let image = if ramp.is_none() { self.params.density.as_ref() } else { None };
        let ramp = ramp.or(image.map(|_| (2.0, 0.5)));
        let domain = match self.domain {
            Domain::Square { .. } => Domain::Square { margin: 3.0 * base * ramp.map_or(1.0, |r| r.0) },
            periodic => periodic,
        };
        match (ramp, image) {
            (None, _) => poisson_disk(domain, base, base, &|_| base, seed),
            (Some((sparse, dense)), Some(image)) => {
                let spacing = |p: Vec2| base * (sparse + (dense - sparse) * intensity(image, p));
                poisson_disk(domain, base * dense, base * sparse, &spacing, seed)
            }
            (Some((sparse, dense)), None) => {
                let spacing = |p: Vec2| base * (sparse + (dense - sparse) * p.x.clamp(0.0, 1.0));
                poisson_disk(domain, base * dense.min(sparse), base * dense.max(sparse), &spacing, seed)
            }
        }
    }

    /// A spacing `scale` times the base, capped so that the layer keeps [`MIN_POINTS`] points.
    fn coarser(&self, scale: f32) -> f32 {
        scale.min((self.params.points as f32 / MIN_POINTS as f32).sqrt())
    }

    fn random_orientations(&mut self, n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|_| {
                let a = self.sampler.next_1d() * std::f32::consts::TAU;
                Vec3::new(libm::cosf(a), libm::sinf(a), 0.0)
            })
            .collect()
    }

    fn field(&self, points: &ControlPoints) -> Result<PupsField, String> {
        PupsField::new(points, self.domain, self.params.axis_scale, self.params.epsilon)
    }

    /// Random grey values, one label per point.
    fn value_layer(&mut self, scale: f32, output: Output, amplitude: f32) -> Result<Layer, String> {
        let positions = self.points(scale, None)?;
        let values = positions.iter().map(|_| Vec3::splat(self.sampler.next_1d())).collect();
        let labels = (0..positions.len() as u32).collect();
        let field = self.field(&ControlPoints::new(positions, values, labels))?;
        Ok(Layer { field, output, amplitude })
    }

    /// Labelled points: `label(point, sampler)` for each, oriented at random.
    fn label_layer(
        &mut self,
        positions: Vec<Vec2>,
        label: &mut dyn FnMut(Vec2, &mut Sampler) -> u32,
        palette: Vec<Vec3>,
        amplitude: f32,
    ) -> Result<Layer, String> {
        let labels: Vec<u32> = positions.iter().map(|p| label(*p, &mut self.sampler)).collect();
        let values = labels.iter().map(|&l| palette[l as usize % palette.len()]).collect();
        let mut points = ControlPoints::new(positions, values, labels);
        points.orientations = self.random_orientations(points.positions.len());
        Ok(Layer { field: self.field(&points)?, output: Output::Label(palette), amplitude })
    }

    /// A palette of `n` random greys or colours.
    fn random_palette(&mut self, n: usize, colour: bool) -> Vec<Vec3> {
        (0..n)
            .map(|_| {
                let g = self.sampler.next_1d();
                if colour {
                    Vec3::new(g, self.sampler.next_1d(), self.sampler.next_1d()) * 0.8 + Vec3::splat(0.1)
                } else {
                    Vec3::splat(g)
                }
            })
            .collect()
    }

    /// The reference image's intensity at `p` (the unit square, v up), or the built-in one: a
    /// disc on a ramp.
    fn reference(&self, p: Vec2) -> f32 {
        match &self.params.reference {
            Some(image) => intensity(image, p),
            None => {
                let p = p.clamp(Vec2::ZERO, Vec2::ONE);
                let disc = if p.distance(Vec2::new(0.45, 0.55)) < 0.28 { 1.0 } else { 0.0 };
                (disc * 0.85 + p.x * 0.3).min(1.0)
            }
        }
    }

    /// The space giraffe's points (Sec. 3.2): spot centres, and around each pairs of an inner
    /// (spot) and an outer (background) point at n angles, n in [10, 20], radii in [0, r], r half
    /// the distance to the nearest centre.
    fn giraffe(&mut self, ramp: Option<(f32, f32)>) -> Result<Layer, String> {
        let centres = self.points(2.5, ramp)?;
        let nearest: Vec<f32> = centres
            .iter()
            .map(|c| {
                // At most 1: on the torus a lone centre's nearest neighbour is its own image.
                centres.iter().filter(|o| *o != c).map(|o| self.domain.offset(*c, *o).length()).fold(1.0, f32::min)
            })
            .collect();
        let mut positions = Vec::new();
        let mut labels = Vec::new();
        for (c, d) in centres.iter().zip(nearest) {
            let r = 0.5 * d;
            positions.push(*c);
            labels.push(1);
            let n = 10 + (self.sampler.next_1d() * 11.0) as usize;
            let phase = self.sampler.next_1d();
            for k in 0..n {
                let angle = std::f32::consts::TAU * (k as f32 + phase) / n as f32;
                let dir = Vec2::new(libm::cosf(angle), libm::sinf(angle));
                // Two random radii in [0, r], the smaller for the spot point; kept off the centre
                // (0.15 r) and apart (the outer at least a tenth of the way from the inner to r),
                // so that no two points meet.
                let (a, b) = (self.sampler.next_1d(), self.sampler.next_1d());
                let inner = r * (0.15 + 0.7 * a.min(b));
                let outer = inner + (r - inner) * (0.1 + 0.9 * a.max(b));
                for (radius, label) in [(inner, 1), (outer, 0)] {
                    let p = *c + dir * radius;
                    positions.push(if self.domain == Domain::Periodic { p - p.floor() } else { p });
                    labels.push(label);
                }
            }
        }
        let mut labels = labels.into_iter();
        self.label_layer(positions, &mut |_, _| labels.next().expect("one label per point"), GIRAFFE.to_vec(), 1.0)
    }

    fn build(mut self, preset: Preset) -> Result<PupsTexture, String> {
        let octave_norm = 1.0 / (1.0 + 0.5 + 0.25 + 0.125);
        let layers = match preset {
            Preset::Noise => vec![self.value_layer(1.0, Output::Value, 1.0)?],
            Preset::Octaves | Preset::Turbulence => {
                let output = if preset == Preset::Octaves { Output::Value } else { Output::Folded };
                // Octave i: spacing 2^(3 - i) times the base (the finest octave has the
                // points asked for, each coarser one a quarter as many, at least 16), amplitude 2^-i.
                (0..4)
                    .map(|i| {
                        let s = 0.5f32.powi(i);
                        self.value_layer(self.coarser(8.0 * s), output.clone(), s * octave_norm)
                    })
                    .collect::<Result<_, _>>()?
            }
            Preset::Cells | Preset::MultiscaleCells => {
                let count = if preset == Preset::Cells { 1 } else { 4 };
                let mut layers = Vec::new();
                for i in 0..count {
                    let s = 0.5f32.powi(i);
                    let positions = self.points(if count == 1 { 1.0 } else { self.coarser(8.0 * s) }, None)?;
                    let palette = self.random_palette(positions.len(), preset == Preset::Cells);
                    let mut next = 0..;
                    let amplitude = if count == 1 { 1.0 } else { s * octave_norm };
                    layers.push(self.label_layer(
                        positions,
                        &mut |_, _| next.next().unwrap_or(0),
                        palette,
                        amplitude,
                    )?);
                }
                layers
            }
            Preset::ClusteredCells => {
                let positions = self.points(1.0, None)?;
                let labels = clusters(&positions, self.domain, &mut self.sampler);
                let palette = self.random_palette(positions.len(), true);
                let mut labels = labels.into_iter();
                vec![self.label_layer(positions, &mut |_, _| labels.next().unwrap_or(0), palette, 1.0)?]
            }
            Preset::Cow | Preset::ProgressiveCow => {
                let ramp = (preset == Preset::ProgressiveCow).then_some((2.0, 0.5));
                let positions = self.points(1.0, ramp)?;
                vec![self.label_layer(
                    positions,
                    &mut |_, s| u32::from(s.next_1d() < 0.5),
                    BLACK_WHITE.to_vec(),
                    1.0,
                )?]
            }
            Preset::SpaceGiraffe => vec![self.giraffe(None)?],
            Preset::ProgressiveGiraffe => vec![self.giraffe(Some((2.0, 0.6)))?],
            Preset::LabelRamp => {
                let positions = self.points(1.0, None)?;
                vec![self.label_layer(
                    positions,
                    &mut |p, s| u32::from(s.next_1d() < p.x),
                    BLACK_WHITE.to_vec(),
                    1.0,
                )?]
            }
            Preset::ReferenceLabels => {
                let positions = self.points(1.0, None)?;
                let intensity: Vec<f32> = positions.iter().map(|p| self.reference(*p)).collect();
                let mut k = 0;
                let mut label = |_: Vec2, s: &mut Sampler| {
                    k += 1;
                    u32::from(s.next_1d() < intensity[k - 1])
                };
                vec![self.label_layer(positions, &mut label, BLACK_WHITE.to_vec(), 1.0)?]
            }
            Preset::Iterative => {
                // Round 0 reads the reference; each later round doubles the points and draws
                // each label with the previous round's interpolated intensity as probability.
                let mut previous: Option<PupsField> = None;
                for round in 0..4 {
                    let positions = self.points(1.5 * libm::powf(0.5, round as f32 * 0.5), None)?;
                    let values: Vec<Vec3> = positions
                        .iter()
                        .map(|p| {
                            let probability = match &previous {
                                None => self.reference(*p),
                                Some(field) => field.value(*p).x,
                            };
                            Vec3::splat(f32::from(u8::from(self.sampler.next_1d() < probability)))
                        })
                        .collect();
                    let labels = values.iter().map(|v| v.x as u32).collect();
                    previous = Some(self.field(&ControlPoints::new(positions, values, labels))?);
                }
                let field = previous.expect("four rounds");
                vec![Layer { field, output: Output::Value, amplitude: 1.0 }]
            }
        };
        Ok(PupsTexture::new(layers))
    }
}

/// The grey intensity of `image` at `p` (the unit square, v up; nearest pixel, clamped).
fn intensity(image: &Bitmap, p: Vec2) -> f32 {
    let p = p.clamp(Vec2::ZERO, Vec2::ONE);
    let x = ((p.x * image.width as f32) as usize).min(image.width - 1);
    let y = (((1.0 - p.y) * image.height as f32) as usize).min(image.height - 1);
    let c = image.pixel(x, y);
    ((c.x + c.y + c.z) / 3.0).clamp(0.0, 1.0)
}

/// Groups of three or four neighbouring points (Fig. 9b): each point not yet grouped starts a
/// group with its nearest ungrouped points within a few spacings (found through a grid of
/// buckets of that size).
fn clusters(points: &[Vec2], domain: Domain, sampler: &mut Sampler) -> Vec<u32> {
    let mut label = vec![u32::MAX; points.len()];
    let mut next = 0;
    let (lo, hi) =
        points.iter().fold((Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)), |(a, b), p| (a.min(*p), b.max(*p)));
    let reach = 4.0 / (points.len() as f32).sqrt();
    let buckets = (((hi - lo).max_element() / reach).ceil() as usize).clamp(1, 4096);
    let bucket = |p: Vec2| {
        let b = ((p - lo) / (hi - lo).max(Vec2::splat(1e-9)) * buckets as f32).floor();
        ((b.x as usize).min(buckets - 1), (b.y as usize).min(buckets - 1))
    };
    let mut grid: Vec<Vec<usize>> = vec![Vec::new(); buckets * buckets];
    for (j, p) in points.iter().enumerate() {
        let (x, y) = bucket(*p);
        grid[y * buckets + x].push(j);
    }
    for i in 0..points.len() {
        if label[i] != u32::MAX {
            continue;
        }
        let size = 3 + usize::from(sampler.next_1d() < 0.5);
        let (bx, by) = bucket(points[i]);
        let wrap = |v: isize| {
            if domain == Domain::Periodic {
                Some(v.rem_euclid(buckets as isize) as usize)
            } else {
                (0..buckets as isize).contains(&v).then_some(v as usize)
            }
        };
        let mut near: Vec<(f32, usize)> = Vec::new();
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (Some(x), Some(y)) = (wrap(bx as isize + dx), wrap(by as isize + dy)) else { continue };
                for &j in &grid[y * buckets + x] {
                    if j != i && label[j] == u32::MAX {
                        near.push((domain.offset(points[i], points[j]).length(), j));
                    }
                }
            }
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // A small periodic grid visits a bucket more than once.
        near.dedup_by_key(|n| n.1);
        label[i] = next;
        for &(_, j) in near.iter().take(size - 1) {
            label[j] = next;
        }
        next += 1;
    }
    label
}
