//! Crops of one render merged into the full image (`tessera merge`): the pieces of a render
//! split over machines (`tessera render --crop`, docs/scale-out.md) put back together exactly.

use super::io::{ExrImage, ExrWindow};

/// The full image from `crops` (OpenEXR images whose data windows sit in the same display
/// window): every pixel must be covered by exactly one crop, and every crop must have the same
/// channels. Values are copied, so the result equals a render of the whole frame bit for bit.
pub fn merge_crops(crops: &[ExrImage]) -> Result<ExrImage, String> {
    let Some(first) = crops.first() else { return Err("no crops to merge".into()) };
    let full = first.window.full;
    let names: Vec<&str> = first.channels.iter().map(|c| c.0.as_str()).collect();
    let pixels = full.0.checked_mul(full.1).filter(|&n| n as u64 <= crate::limits::MAX_RENDER_PIXELS);
    let Some(pixels) = pixels else { return Err(format!("a {} x {} frame is over the render limit", full.0, full.1)) };
    let mut covered = vec![u32::MAX; pixels];
    let mut channels: Vec<(String, Vec<f32>)> = names.iter().map(|n| (n.to_string(), vec![0.0; pixels])).collect();
    for (k, crop) in crops.iter().enumerate() {
        if crop.window.full != full {
            return Err(format!(
                "crop {} belongs to a {} x {} frame, crop 1 to a {} x {} one",
                k + 1,
                crop.window.full.0,
                crop.window.full.1,
                full.0,
                full.1
            ));
        }
        let these: Vec<&str> = crop.channels.iter().map(|c| c.0.as_str()).collect();
        if these != names {
            return Err(format!(
                "crop {} has channels {} where crop 1 has {}",
                k + 1,
                these.join(", "),
                names.join(", ")
            ));
        }
        let (ox, oy) = crop.window.origin;
        for y in 0..crop.height {
            for x in 0..crop.width {
                let (fx, fy) = (ox + x, oy + y);
                let at = fy * full.0 + fx;
                if covered[at] != u32::MAX {
                    return Err(format!("crops {} and {} both cover pixel ({fx}, {fy})", covered[at] + 1, k + 1));
                }
                covered[at] = k as u32;
                for (out, (_, values)) in channels.iter_mut().zip(&crop.channels) {
                    out.1[at] = values[y * crop.width + x];
                }
            }
        }
    }
    if let Some(at) = covered.iter().position(|&c| c == u32::MAX) {
        let missing = covered.iter().filter(|&&c| c == u32::MAX).count();
        return Err(format!("{missing} pixels are in no crop, the first ({}, {})", at % full.0, at / full.0));
    }
    Ok(ExrImage { window: ExrWindow { origin: (0, 0), full }, width: full.0, height: full.1, channels })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn crop(origin: (usize, usize), size: (usize, usize), value: f32) -> ExrImage {
        let n = size.0 * size.1;
        ExrImage {
            window: ExrWindow { origin, full: (4, 2) },
            width: size.0,
            height: size.1,
            channels: vec![("R".into(), vec![value; n]), ("G".into(), (0..n).map(|i| i as f32).collect())],
        }
    }

    #[test]
    fn crops_are_placed_and_gaps_and_overlaps_refused() {
        let merged =
            merge_crops(&[crop((0, 0), (4, 1), 1.0), crop((0, 1), (3, 1), 2.0), crop((3, 1), (1, 1), 3.0)]).unwrap();
        assert_eq!(merged.channels[0].1, [1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0]);
        assert_eq!(merged.channels[1].1, [0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 0.0]);
        let gap = merge_crops(&[crop((0, 0), (4, 1), 1.0)]).unwrap_err();
        assert!(gap.contains("4 pixels are in no crop, the first (0, 1)"), "{gap}");
        let overlap = merge_crops(&[crop((0, 0), (4, 2), 1.0), crop((3, 1), (1, 1), 3.0)]).unwrap_err();
        assert!(overlap.contains("crops 1 and 2 both cover pixel (3, 1)"), "{overlap}");
        let mut other = crop((0, 1), (4, 1), 1.0);
        other.channels.pop();
        assert!(merge_crops(&[crop((0, 0), (4, 1), 1.0), other]).unwrap_err().contains("has channels R where"));
        assert!(merge_crops(&[]).is_err());
    }
}
