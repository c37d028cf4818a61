//! The deformation field F(u) of deformed tiling and blending (paper 000 Eq. 3): a 2x2 matrix
//! at every point of the UV plane that maps UV offsets from a tile's centre to exemplar offsets.
//!
//! The texture's own axes appear in UV along the columns of F^-1: F = s I shows the pattern
//! 1/s times as large, F = R(theta) shows it turned by -theta (DESIGN.md section 3).

use crate::texture::MipMap;
use glam::{Mat2, Vec2, Vec4};

/// One factor of a deformation field.
#[derive(Clone, Debug)]
pub enum Deformation {
    /// The same matrix everywhere.
    Constant(Mat2),
    /// F = R(theta(u)), theta(u) = angle + gradient . u (radians).
    Rotation {
        /// Angle at uv = (0, 0), radians.
        angle: f32,
        /// Change of the angle per UV unit along u and v, radians.
        gradient: Vec2,
    },
    /// F = diag(s(u)), s(u) = scale 2^(gradient . u).
    Scale {
        /// Scale along u and v at uv = (0, 0).
        scale: Vec2,
        /// Change of log2 of the scale per UV unit along u and v.
        gradient: Vec2,
    },
    /// F = [[1, k(u)], [0, 1]], k(u) = shear + gradient . u: the exemplar's x offset grows with
    /// the UV v offset.
    Shear {
        /// Shear at uv = (0, 0).
        shear: f32,
        /// Change of the shear per UV unit along u and v.
        gradient: Vec2,
    },
    /// An F map: four channels (F00, F01, F10, F11, row-major), interpolated bilinearly between
    /// texel centres with the texture conventions of DESIGN.md section 3 (bottom-left origin,
    /// repeat).
    Map(MipMap),
}

impl Deformation {
    /// F at `uv`.
    #[inline]
    pub fn at(&self, uv: Vec2) -> Mat2 {
        match self {
            Deformation::Constant(m) => *m,
            Deformation::Rotation { angle, gradient } => {
                let (s, c) = (angle + gradient.dot(uv)).sin_cos();
                Mat2::from_cols(Vec2::new(c, s), Vec2::new(-s, c))
            }
            Deformation::Scale { scale, gradient } => Mat2::from_diagonal(*scale * gradient.dot(uv).exp2()),
            Deformation::Shear { shear, gradient } => {
                Mat2::from_cols(Vec2::X, Vec2::new(shear + gradient.dot(uv), 1.0))
            }
            Deformation::Map(map) => {
                let uv = uv - crate::math::floor2(uv);
                let f = map.bilinear(0, crate::texture::image_coordinates(uv));
                Mat2::from_cols(Vec2::new(f.x, f.z), Vec2::new(f.y, f.w))
            }
        }
    }
}

/// Largest magnitude of an entry of F: a texture shown 2^20 times smaller than its exemplar
/// is far below any texel of any exemplar, so larger values change nothing but the risk of
/// overflow.
pub const MAX_DEFORMATION: f32 = (1 << 20) as f32;

/// `m` with each entry clamped to [-MAX_DEFORMATION, MAX_DEFORMATION], NaN to 0 (the four
/// entries in one `Vec4`).
#[inline]
fn bounded(m: Mat2) -> Mat2 {
    let entries = Vec4::from_array(m.to_cols_array());
    let clamped = entries.clamp(Vec4::splat(-MAX_DEFORMATION), Vec4::splat(MAX_DEFORMATION));
    Mat2::from_cols_array(&Vec4::select(entries.cmpeq(entries), clamped, Vec4::ZERO).to_array())
}

/// An F map's value `m` mirrored, M m, where its handedness (det < 0 or not) is not the
/// surface's (`uv_mirrored`; as it is without a surface).
#[inline]
fn with_handedness(m: Mat2, uv_mirrored: Option<bool>) -> Mat2 {
    if uv_mirrored.is_some_and(|mirrored| (m.determinant() < 0.0) != mirrored) { crate::math::MIRROR * m } else { m }
}

/// Where each tile of the paving reads the field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FieldAt {
    /// At the point: tile i reads the exemplar at F(u)(u - c_i) + h_i (paper 000 Eq. 3). Its
    /// Jacobian F(u) + dF (u - c_i) folds where F varies faster than a tile spans (the paper's
    /// open "cracks"; `tessera analyze` measures where).
    #[default]
    Point,
    /// At the tile's centre: F(c_i)(u - c_i) + h_i, an affine image of the exemplar per tile,
    /// which never folds; each tile carries the field of its centre, off F(u) by dF (c_i - u)
    /// (what `analyze` reports as stretch). Where c_i lies in another UV chart than u (the
    /// chart map that `tessera deform` writes), the tile reads u's chart's field at the chart's
    /// point nearest to c_i ([`super::Charts`]), and F(u) if no point of the chart is within
    /// reach of c_i.
    TileCentre,
}

/// A deformation field: the product F = F_1 F_2 ... F_n of its factors (identity when empty),
/// and where tiles read it.
#[derive(Clone, Debug, Default)]
pub struct DeformationField {
    factors: Vec<Deformation>,
    field_at: FieldAt,
    /// The UV charts of the F map, for [`FieldAt::TileCentre`]; None: one chart.
    charts: Option<std::sync::Arc<super::Charts>>,
}

impl DeformationField {
    /// The field F_1 F_2 ... F_n, read at the point.
    pub fn new(factors: Vec<Deformation>) -> Self {
        DeformationField { factors, field_at: FieldAt::Point, charts: None }
    }

    /// This field read by the tiles at `field_at`, with the UV charts `charts` for
    /// [`FieldAt::TileCentre`].
    pub fn read_at(self, field_at: FieldAt, charts: Option<super::Charts>) -> Self {
        DeformationField { field_at, charts: charts.map(std::sync::Arc::new), ..self }
    }

    /// Where tiles read the field.
    pub fn field_at(&self) -> FieldAt {
        self.field_at
    }

    /// The UV chart of the point `uv` whose field tiles read at their centres (None when read
    /// at the point, or without a chart map): found once per point, for all its tiles.
    #[inline]
    pub fn chart_at(&self, uv: Vec2) -> Option<u32> {
        match (self.field_at, &self.charts) {
            (FieldAt::TileCentre, Some(charts)) => Some(charts.chart(uv)),
            _ => None,
        }
    }

    /// Where the tile centred at `centre` reads F for a point of chart `chart`
    /// ([`DeformationField::chart_at`]): None at the point; read at tile centres, the centre
    /// itself, or (in another chart) that chart's point nearest to it
    /// ([`super::Charts::field_point`]; None beyond reach).
    #[inline]
    pub fn tile_field_point(&self, centre: Vec2, chart: Option<u32>) -> Option<Vec2> {
        match (self.field_at, &self.charts, chart) {
            (FieldAt::Point, ..) => None,
            (FieldAt::TileCentre, Some(charts), Some(chart)) => charts.field_point(centre, chart),
            (FieldAt::TileCentre, ..) => Some(centre),
        }
    }

    /// The field that the tile centred at `centre` reads for a point of chart `chart`, given F
    /// at the point (`f_at_uv`, as [`DeformationField::at_surface`] gives it with
    /// `uv_mirrored`): F at [`DeformationField::tile_field_point`] with the surface's
    /// handedness at the point, or `f_at_uv` where that is None.
    #[inline]
    pub fn for_tile(&self, centre: Vec2, chart: Option<u32>, uv_mirrored: Option<bool>, f_at_uv: Mat2) -> Mat2 {
        self.tile_field_point(centre, chart).map_or(f_at_uv, |p| self.at_surface(p, uv_mirrored))
    }

    /// F at `uv`.
    #[inline]
    /// Each factor and the product have their entries bounded by [`MAX_DEFORMATION`] (NaN, as
    /// infinity times zero would give, becomes 0): an analytic field grows without bound over
    /// the UV plane (a scale 2^(gradient . u)), and what it gives must stay finite.
    pub fn at(&self, uv: Vec2) -> Mat2 {
        match self.factors.as_slice() {
            [] => Mat2::IDENTITY,
            [only] => bounded(only.at(uv)),
            [first, rest @ ..] => rest.iter().fold(bounded(first.at(uv)), |m, f| bounded(m * bounded(f.at(uv)))),
        }
    }

    /// F at `uv` on a surface whose UV map reverses orientation there or not (`uv_mirrored`;
    /// None, no surface known, is [`DeformationField::at`]):
    /// where the first F map factor has the other handedness (det < 0 against a surface that is
    /// not mirrored, or the reverse: the map holds the field of an overlapping mirrored UV
    /// island), that factor is mirrored, M F_map with M = diag(1, -1). For the two halves of a
    /// mirror-symmetric mesh sharing their UVs, under an orientation field that is symmetric
    /// too, M F_map is exactly the other half's field (DESIGN.md section 5); elsewhere the
    /// handedness always agrees and this is [`DeformationField::at`].
    pub fn at_surface(&self, uv: Vec2, uv_mirrored: Option<bool>) -> Mat2 {
        if uv_mirrored.is_none() {
            return self.at(uv);
        }
        let first_map = self.factors.iter().position(|f| matches!(f, Deformation::Map(_)));
        self.factors.iter().enumerate().fold(Mat2::IDENTITY, |product, (k, f)| {
            let m = bounded(f.at(uv));
            bounded(product * if Some(k) == first_map { with_handedness(m, uv_mirrored) } else { m })
        })
    }

    /// The first F map factor at `uv` (None without one), mirrored as
    /// [`DeformationField::at_surface`] does: the field whose units cut bands measure in.
    pub fn map_at(&self, uv: Vec2, uv_mirrored: Option<bool>) -> Option<Mat2> {
        let m = bounded(self.factors.iter().find(|f| matches!(f, Deformation::Map(_)))?.at(uv));
        Some(with_handedness(m, uv_mirrored))
    }

    /// The factors F_1 ... F_n.
    pub fn factors(&self) -> &[Deformation] {
        &self.factors
    }

    /// The first F map factor's texels (None without one).
    pub fn map_texels(&self) -> Option<&crate::image::Bitmap> {
        self.factors.iter().find_map(|f| if let Deformation::Map(m) = f { Some(m.level(0)) } else { None })
    }

    /// Bytes held by F maps.
    pub fn memory_bytes(&self) -> usize {
        self.factors.iter().map(|f| if let Deformation::Map(m) = f { m.memory_bytes() } else { 0 }).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Bitmap;

    #[test]
    fn analytic_fields_have_their_documented_form() {
        let uv = Vec2::new(0.3, 0.7);
        let rot = Deformation::Rotation { angle: 0.1, gradient: Vec2::new(1.0, 0.5) }.at(uv);
        let theta: f32 = 0.1 + 0.3 + 0.35;
        assert!((rot * Vec2::X - Vec2::new(theta.cos(), theta.sin())).length() < 1e-6);
        assert!((rot.determinant() - 1.0).abs() < 1e-6);
        let scale = Deformation::Scale { scale: Vec2::new(2.0, 3.0), gradient: Vec2::new(1.0, 0.0) }.at(uv);
        assert!((scale * Vec2::ONE - Vec2::new(2.0, 3.0) * 0.3f32.exp2()).length() < 1e-5);
        let shear = Deformation::Shear { shear: 0.5, gradient: Vec2::new(0.0, 1.0) }.at(uv);
        assert!((shear * Vec2::new(0.0, 1.0) - Vec2::new(1.2, 1.0)).length() < 1e-6);
    }

    #[test]
    fn fields_are_bounded_and_nan_free() {
        let m = Mat2::from_cols_array(&[f32::NAN, f32::INFINITY, -3e30, -0.0]);
        let field = DeformationField::new(vec![Deformation::Constant(m)]);
        let bounded = field.at(Vec2::ZERO).to_cols_array();
        assert_eq!(bounded.map(f32::to_bits), [0.0, MAX_DEFORMATION, -MAX_DEFORMATION, -0.0].map(f32::to_bits));
        let ordinary = Mat2::from_cols_array(&[0.5, -2.0, 1e5, MAX_DEFORMATION]);
        assert_eq!(DeformationField::new(vec![Deformation::Constant(ordinary)]).at(Vec2::ONE), ordinary);
    }

    #[test]
    fn product_of_factors_in_order() {
        let a = Mat2::from_cols_array(&[1.0, 2.0, 3.0, 4.0]);
        let b = Mat2::from_cols_array(&[0.0, 1.0, -1.0, 0.0]);
        let field = DeformationField::new(vec![Deformation::Constant(a), Deformation::Constant(b)]);
        assert_eq!(field.at(Vec2::ZERO), a * b);
        assert_eq!(DeformationField::default().at(Vec2::ONE), Mat2::IDENTITY);
    }

    #[test]
    fn f_map_is_read_row_major_at_texel_centres() {
        // 2x1 map: left texel F = [[1, 2], [3, 4]], right texel the identity.
        let mut b = Bitmap::new(2, 1, 4);
        b.data.copy_from_slice(&[1.0, 2.0, 3.0, 4.0, 1.0, 0.0, 0.0, 1.0]);
        let field = Deformation::Map(MipMap::new(b));
        let left = field.at(Vec2::new(0.25, 0.5));
        assert_eq!(left * Vec2::X, Vec2::new(1.0, 3.0));
        assert_eq!(left * Vec2::Y, Vec2::new(2.0, 4.0));
        // Halfway between the two texel centres: the mean.
        let mid = field.at(Vec2::new(0.5, 0.5));
        assert!((mid * Vec2::Y - Vec2::new(1.0, 2.5)).length() < 1e-6);
    }
}
