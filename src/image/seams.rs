//! How visible a mesh's UV cuts are in a render (issue 20, Fig. 8): the radiance difference
//! between neighbouring pixels on two sides of a cut (their texture coordinates jump), over
//! that between the pixels one step further out on either side, within each chart. About 1: the
//! cut shows no more than the texture around it changes; well above 1: the cut is seen (a
//! classical synthesis' seam, a highlight that breaks). Read from a render's `uv` and `normal`
//! AOVs.

use super::Bitmap;

/// The figure and how many pixel pairs it rests on.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SeamVisibility {
    /// Sum of |L_p - L_q| across cuts over the sum of the neighbouring steps' differences.
    pub ratio: f64,
    /// Neighbouring pixel pairs across a cut.
    pub across: usize,
}

/// The seam visibility of `radiance` (RGB) given the render's `uv` (2 channels) and `normal`
/// (3 channels) AOVs, all the same size. A pair of neighbours (right or below) is across a cut
/// where its texture coordinates differ by more than `jump` and by more than 8 times the steps
/// one pixel further out along the same line on either side (one pixel out, since a pixel
/// straddling the cut averages the two sides' coordinates and splits the jump in two; the
/// steps keep out neighbours of one chart whose coordinates change fast, near a lat-long pole).
/// Its radiance difference is compared with those of the steps one pixel further out, which
/// lie within a chart each: a local reference, so that a cut in a dark part of the image is not
/// flattered by the bright highlight elsewhere. Pixels not wholly on the surface (an averaged
/// normal shorter than 0.999) are left out. None without such pairs.
pub fn seam_visibility(radiance: &Bitmap, uv: &Bitmap, normal: &Bitmap, jump: f32) -> Option<SeamVisibility> {
    let (w, h) = (radiance.width, radiance.height);
    if (uv.width, uv.height, normal.width, normal.height) != (w, h, w, h) || uv.channels < 2 || normal.channels < 3 {
        return None;
    }
    let on_surface = |x: usize, y: usize| {
        let n = normal.values(x, y);
        n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.998
    };
    let uv_at = |x: usize, y: usize| glam::Vec2::new(uv.values(x, y)[0], uv.values(x, y)[1]);
    let difference = |a: (usize, usize), b: (usize, usize)| {
        let (p, q) = (radiance.pixel(a.0, a.1), radiance.pixel(b.0, b.1));
        (((p - q).abs().truncate()).element_sum() / 3.0) as f64
    };
    let (mut across, mut around, mut pairs) = (0.0, 0.0, 0usize);
    for y in 0..h {
        for x in 0..w {
            for (dx, dy) in [(1usize, 0usize), (0, 1)] {
                // The pixels a (two out), b, c (the pair), d (two out) along the line.
                if x < 2 * dx || y < 2 * dy || x + 3 * dx >= w || y + 3 * dy >= h {
                    continue;
                }
                let line = [-2i64, -1, 0, 1, 2, 3]
                    .map(|k| ((x as i64 + k * dx as i64) as usize, (y as i64 + k * dy as i64) as usize));
                if !line.iter().all(|&(px, py)| on_surface(px, py)) {
                    continue;
                }
                let (b, c) = (line[2], line[3]);
                let d = uv_at(b.0, b.1).distance(uv_at(c.0, c.1));
                let before = uv_at(line[0].0, line[0].1).distance(uv_at(line[1].0, line[1].1));
                let after = uv_at(line[4].0, line[4].1).distance(uv_at(line[5].0, line[5].1));
                if !(d > jump && d > 8.0 * before.max(after)) {
                    continue;
                }
                across += difference(b, c);
                around += (difference(line[0], line[1]) + difference(line[4], line[5])) / 2.0;
                pairs += 1;
            }
        }
    }
    (pairs > 0 && around > 0.0).then(|| SeamVisibility { ratio: across / around, across: pairs })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 64 x 32 render of two charts meeting at x = 32: u runs 0..0.5 on the left and
    /// 0.7..1.2 on the right; radiance a ramp as steep along x as along y, plus `step` on the
    /// right.
    fn render(step: f32) -> (Bitmap, Bitmap, Bitmap) {
        let (mut l, mut uv, mut n) = (Bitmap::new(64, 32, 3), Bitmap::new(64, 32, 2), Bitmap::new(64, 32, 3));
        for y in 0..32 {
            for x in 0..64 {
                let right = x >= 32;
                let value = 0.2 + 0.01 * (x + y) as f32 + if right { step } else { 0.0 };
                l.values_mut(x, y).copy_from_slice(&[value; 3]);
                let u = x as f32 / 64.0 + if right { 0.2 } else { 0.0 };
                uv.values_mut(x, y).copy_from_slice(&[u, y as f32 / 64.0]);
                n.values_mut(x, y).copy_from_slice(&[0.0, 0.0, 1.0]);
            }
        }
        (l, uv, n)
    }

    #[test]
    fn a_continuous_cut_gives_one_and_a_step_more() {
        let (l, uv, n) = render(0.0);
        let v = seam_visibility(&l, &uv, &n, 0.1).unwrap();
        assert_eq!(v.across, 32);
        assert!((v.ratio - 1.0).abs() < 1e-4, "{v:?}");
        let (l, uv, n) = render(0.1);
        assert!(seam_visibility(&l, &uv, &n, 0.1).unwrap().ratio > 5.0);
        // Off the surface: nothing to measure.
        let mut off = n.clone();
        off.data.fill(0.0);
        assert!(seam_visibility(&l, &uv, &off, 0.1).is_none());
    }
}
