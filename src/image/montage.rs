//! Labelled montages: images laid out on a grid, each with a caption under it, for comparisons
//! such as paper 000's Fig. 8 (classical against deformed, two parameterisations). Captions are
//! drawn with the public-domain 8x8 bitmap font of the `font8x8` crate.

use super::Bitmap;
use font8x8::UnicodeFonts;

/// Pixels between cells and around the montage.
const GAP: usize = 8;

/// Scale of the 8x8 font (16-pixel-high captions).
const FONT_SCALE: usize = 2;

/// Height of a caption strip.
const CAPTION: usize = 8 * FONT_SCALE + GAP;

/// Background and caption colours (linear RGB).
const BACKGROUND: [f32; 3] = [0.02, 0.02, 0.02];
const INK: [f32; 3] = [0.9, 0.9, 0.9];

/// The montage of `images` (linear RGB or grey, any sizes), `columns` per row in reading order,
/// each centred in a cell as large as the largest image and captioned under it. Errors when
/// there are no images, no columns, or the result would exceed `max_pixels`.
pub fn montage(images: &[(Bitmap, String)], columns: usize, max_pixels: u64) -> Result<Bitmap, String> {
    if images.is_empty() || columns == 0 {
        return Err("a montage needs at least one image and one column".into());
    }
    let columns = columns.min(images.len());
    let rows = images.len().div_ceil(columns);
    let cell_w = images.iter().map(|(b, label)| b.width.max(caption_width(label))).max().unwrap_or(0);
    let cell_h = images.iter().map(|(b, _)| b.height).max().unwrap_or(0) + CAPTION;
    let width = columns * (cell_w + GAP) + GAP;
    let height = rows * (cell_h + GAP) + GAP;
    if (width as u64).saturating_mul(height as u64) > max_pixels {
        return Err(format!("a {width} x {height} montage is over the limit of {max_pixels} pixels"));
    }
    let mut out = Bitmap::new(width, height, 3);
    out.data.chunks_exact_mut(3).for_each(|p| p.copy_from_slice(&BACKGROUND));
    for (k, (image, label)) in images.iter().enumerate() {
        let (x0, y0) = (GAP + (k % columns) * (cell_w + GAP), GAP + (k / columns) * (cell_h + GAP));
        let (dx, dy) = ((cell_w - image.width) / 2, (cell_h - CAPTION - image.height) / 2);
        for y in 0..image.height {
            for x in 0..image.width {
                let p = image.pixel(x, y);
                out.values_mut(x0 + dx + x, y0 + dy + y).copy_from_slice(&[p.x, p.y, p.z]);
            }
        }
        let text_x = x0 + (cell_w - caption_width(label).min(cell_w)) / 2;
        draw_text(&mut out, text_x, y0 + cell_h - CAPTION + GAP / 2, label);
    }
    Ok(out)
}

/// Width in pixels of `text` as [`draw_text`] draws it.
fn caption_width(text: &str) -> usize {
    text.chars().count() * 8 * FONT_SCALE
}

/// Draw `text` with its top-left corner at (x, y), clipped to the bitmap; characters the font
/// lacks are drawn as '?'.
fn draw_text(bitmap: &mut Bitmap, x: usize, y: usize, text: &str) {
    for (n, c) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS
            .get(c)
            .or_else(|| font8x8::LATIN_FONTS.get(c))
            .unwrap_or_else(|| font8x8::BASIC_FONTS.get('?').expect("the basic font has '?'"));
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                // Bit 0 is the leftmost pixel.
                if bits >> col & 1 == 0 {
                    continue;
                }
                for sy in 0..FONT_SCALE {
                    for sx in 0..FONT_SCALE {
                        let px = x + (n * 8 + col) * FONT_SCALE + sx;
                        let py = y + row * FONT_SCALE + sy;
                        if px < bitmap.width && py < bitmap.height {
                            bitmap.values_mut(px, py)[..3].copy_from_slice(&INK);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filled(width: usize, height: usize, value: f32) -> Bitmap {
        let mut b = Bitmap::new(width, height, 3);
        b.data.fill(value);
        b
    }

    #[test]
    fn images_land_in_their_cells_with_captions_under_them() {
        let images = vec![
            (filled(20, 10, 0.5), "A".to_string()),
            (filled(10, 10, 0.25), "B".into()),
            (filled(20, 10, 1.0), "".into()),
        ];
        let m = montage(&images, 2, 1 << 20).unwrap();
        let cell_w = 20;
        assert_eq!(m.width, 2 * (cell_w + GAP) + GAP);
        assert_eq!(m.height, 2 * (10 + CAPTION + GAP) + GAP);
        // The first image at the top left, the second centred in its cell, the third below.
        assert_eq!(m.pixel(GAP, GAP).x, 0.5);
        assert_eq!(m.pixel(2 * GAP + cell_w + 5, GAP).x, 0.25);
        assert_eq!(m.pixel(2 * GAP + cell_w + 4, GAP).x, BACKGROUND[0]);
        assert_eq!(m.pixel(GAP, 2 * GAP + 10 + CAPTION).x, 1.0);
        // "A" is drawn in the first caption strip, nothing in the third's (empty label).
        let strip = |row: usize, col: usize| {
            let (x0, y0) = (GAP + col * (cell_w + GAP), GAP + row * (10 + CAPTION + GAP) + 10);
            (0..CAPTION).flat_map(move |y| (0..cell_w).map(move |x| (x0 + x, y0 + y)))
        };
        assert!(strip(0, 0).any(|(x, y)| m.pixel(x, y).x == INK[0]));
        assert!(strip(1, 0).all(|(x, y)| m.pixel(x, y).x != INK[0]));
    }

    #[test]
    fn bad_montages_are_refused() {
        assert!(montage(&[], 2, 1 << 20).is_err());
        assert!(montage(&[(filled(4, 4, 0.0), "x".into())], 0, 1 << 20).is_err());
        assert!(montage(&[(filled(400, 400, 0.0), "x".into())], 1, 1000).unwrap_err().contains("over the limit"));
    }
}
