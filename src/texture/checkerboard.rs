//! Mitsuba's `checkerboard` texture: two colours alternating over the cells of side 1/2 of the
//! (scaled, offset) texture coordinates, unfiltered, as Mitsuba evaluates it.

use super::{TexCtx, image_coordinates};
use glam::{Vec2, Vec4};

/// A checkerboard of two colours (linear RGB, alpha 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkerboard {
    /// The colour of the cells whose two half-period tests agree (Mitsuba's `color0`).
    pub color0: Vec4,
    /// The colour of the other cells (`color1`).
    pub color1: Vec4,
    /// Multiplier of the texture coordinates.
    pub scale: Vec2,
    /// Offset added after scaling.
    pub offset: Vec2,
}

impl Checkerboard {
    /// The colour at the lookup. In image coordinates (s, t) = (u', 1 - v') of the scaled
    /// coordinates u' (Mitsuba's uv, whose v runs down), a cell is `color0` where
    /// frac(s) > 1/2 and frac(t) > 1/2 agree, `color1` where they differ: Mitsuba's rule in
    /// Mitsuba's coordinates, so that the same `to_uv` gives the same squares.
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        let st = image_coordinates(ctx.uv * self.scale + self.offset);
        let upper = |x: f32| x - x.floor() > 0.5;
        if upper(st.x) == upper(st.y) { self.color0 } else { self.color1 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkerboard_squares_are_mitsubas() {
        // Mitsuba's rule written in its own uv (v down), at cell centres of a board scaled 2x3
        // and offset: uv_m = (u, 1 - v), st = uv_m * s + (o_x, 1 - s_y - o_y).
        let board = Checkerboard {
            color0: Vec4::splat(0.4),
            color1: Vec4::splat(0.2),
            scale: Vec2::new(2.0, 3.0),
            offset: Vec2::new(0.1, 0.3),
        };
        let mut seen = [0, 0];
        for i in 0..40 {
            for j in 0..40 {
                let uv = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / 40.0;
                let (s, o) = (board.scale, board.offset);
                let st = Vec2::new(uv.x * s.x + o.x, (1.0 - uv.y) * s.y + (1.0 - s.y - o.y));
                let frac = |x: f32| x - x.floor();
                let mitsuba = if (frac(st.x) > 0.5) == (frac(st.y) > 0.5) { 0.4 } else { 0.2 };
                let got = board.eval(&TexCtx { uv, ..Default::default() }).x;
                assert_eq!(got, mitsuba, "at {uv}");
                seen[usize::from(got == 0.4)] += 1;
            }
        }
        assert!(seen[0] > 600 && seen[1] > 600, "{seen:?}");
    }
}
