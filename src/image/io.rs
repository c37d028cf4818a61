//! Reading and writing image files. Writes go to a temporary file beside the target and are
//! renamed over it only when complete, so a failed or interrupted write never replaces a good
//! image with a partial one.

use super::{Bitmap, ColorSpace};
use crate::color::{linear_to_srgb, srgb_to_linear, srgb_u8_table};
use crate::error::guard_parser;
use crate::error::{Error, Result};
use crate::files::{read_bounded, write_atomically};
use crate::limits;
use std::path::Path;

/// Output file formats, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// OpenEXR, 32-bit float, linear.
    Exr,
    /// PNG, 8-bit sRGB, clamped to [0, 1].
    Png,
    /// Portable float map: RGB 32-bit float, linear, no extra channels.
    Pfm,
    /// Radiance HDR (RGBE: an 8-bit mantissa per channel and a shared exponent), linear.
    Hdr,
}

impl OutputFormat {
    /// The format of `path` from its extension.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("exr") => Ok(OutputFormat::Exr),
            Some("png") => Ok(OutputFormat::Png),
            Some("pfm") => Ok(OutputFormat::Pfm),
            Some("hdr") => Ok(OutputFormat::Hdr),
            _ => Err(Error::image(path, "the output must end in .exr, .pfm or .hdr (linear) or .png (sRGB)")),
        }
    }
}

/// Read an image of colours or radiance as floats: [`read_bitmap_raw`], then negative values
/// (lossy EXR compression) and non-finite ones become 0.
pub fn read_bitmap(path: &Path, space: ColorSpace) -> Result<Bitmap> {
    let mut bitmap = read_bitmap_raw(path, space)?;
    bitmap.zero_negative_and_non_finite();
    Ok(bitmap)
}

/// Read an image file as floats, as stored (signed data such as F maps). Integer colour
/// channels are divided by their maximum and, with [`ColorSpace::Srgb`], sRGB-decoded (alpha
/// never is); float files (EXR, HDR) are linear whatever `space` says.
pub fn read_bitmap_raw(path: &Path, space: ColorSpace) -> Result<Bitmap> {
    let is_exr = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let bitmap = if is_exr { read_exr(path)? } else { read_with_image_crate(path, space)? };
    if bitmap.width == 0 || bitmap.height == 0 {
        return Err(Error::image(path, "the image is empty"));
    }
    Ok(bitmap)
}

fn read_with_image_crate(path: &Path, space: ColorSpace) -> Result<Bitmap> {
    let bytes = read_bounded(path, limits::MAX_IMAGE_FILE_BYTES, "an image file")?;
    decode_image(&bytes, path, space)
}

/// Decode an encoded image (PNG, JPEG, Radiance HDR, by its content) held in memory; `path`
/// names it in errors (the file it came from). Sizes are checked against [`crate::limits`]
/// before the pixels are allocated. Channels as in [`read_bitmap_raw`].
pub fn decode_image(bytes: &[u8], path: &Path, space: ColorSpace) -> Result<Bitmap> {
    use ::image::DynamicImage;
    let mut reader =
        ::image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(|e| Error::io(path, e))?;
    let mut image_limits = ::image::Limits::default();
    image_limits.max_image_width = Some(limits::MAX_IMAGE_SIDE);
    image_limits.max_image_height = Some(limits::MAX_IMAGE_SIDE);
    // The decoder's own buffers: 16-bit RGBA at the largest pixel count.
    image_limits.max_alloc = Some(limits::MAX_IMAGE_PIXELS * 8);
    reader.limits(image_limits);
    let decoded =
        guard_parser(path, || reader.decode().map_err(|e| Error::image(path, format!("cannot decode: {e}"))))?;
    check_image_size(path, decoded.width() as u64, decoded.height() as u64, decoded.color().channel_count() as u64)?;
    let (w, h) = (decoded.width() as usize, decoded.height() as usize);
    let srgb = space == ColorSpace::Srgb;
    // Integer formats: (channels, has alpha, values scaled to [0, 1]).
    let (channels, values): (usize, Vec<f32>) = match decoded {
        DynamicImage::ImageLuma8(i) => (1, i.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        DynamicImage::ImageLumaA8(i) => (2, i.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        DynamicImage::ImageRgb8(i) => (3, i.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        DynamicImage::ImageRgba8(i) => (4, i.into_raw().into_iter().map(|v| v as f32 / 255.0).collect()),
        DynamicImage::ImageLuma16(i) => (1, i.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        DynamicImage::ImageLumaA16(i) => (2, i.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        DynamicImage::ImageRgb16(i) => (3, i.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        DynamicImage::ImageRgba16(i) => (4, i.into_raw().into_iter().map(|v| v as f32 / 65535.0).collect()),
        DynamicImage::ImageRgb32F(i) => {
            return Ok(Bitmap { width: w, height: h, channels: 3, data: i.into_raw() });
        }
        DynamicImage::ImageRgba32F(i) => {
            return Ok(Bitmap { width: w, height: h, channels: 4, data: i.into_raw() });
        }
        other => {
            let i = other.to_rgba32f();
            return Ok(Bitmap { width: w, height: h, channels: 4, data: i.into_raw() });
        }
    };
    let mut data = values;
    if srgb {
        srgb_decode_colors(&mut data, channels);
    }
    Ok(Bitmap { width: w, height: h, channels, data })
}

/// sRGB-decode the colour channels (not alpha) of interleaved integer-sourced values in [0, 1].
pub(crate) fn srgb_decode_colors(data: &mut [f32], channels: usize) {
    let color_channels = if channels == 2 || channels == 4 { channels - 1 } else { channels };
    let table = srgb_u8_table();
    for px in data.chunks_exact_mut(channels) {
        for v in &mut px[..color_channels] {
            // Exact table for 8-bit values, the formula otherwise.
            let byte = (*v * 255.0).round();
            *v = if (byte / 255.0 - *v).abs() < 1e-7 { table[byte as usize] } else { srgb_to_linear(*v) };
        }
    }
}

/// An error if an image of `width` x `height` pixels of `channels` values is over the limits.
fn check_image_size(path: &Path, width: u64, height: u64, channels: u64) -> Result<()> {
    let side = width.max(height);
    if side > limits::MAX_IMAGE_SIDE as u64 {
        return Err(Error::image(path, limits::exceeded("the image's side", side, limits::MAX_IMAGE_SIDE)));
    }
    if width * height > limits::MAX_IMAGE_PIXELS {
        let size = format!("{width}x{height} pixels");
        return Err(Error::image(
            path,
            limits::exceeded("the image", size, format!("{} pixels", limits::MAX_IMAGE_PIXELS)),
        ));
    }
    if width * height * channels > limits::MAX_IMAGE_VALUES {
        let size = format!("{width}x{height} pixels of {channels} channels");
        return Err(Error::image(
            path,
            limits::exceeded("the image", size, format!("{} values", limits::MAX_IMAGE_VALUES)),
        ));
    }
    Ok(())
}

/// Check an OpenEXR file's headers before its pixels are allocated: the exr crate allocates
/// what the data window claims.
fn check_exr_header(path: &Path, bytes: &[u8]) -> Result<()> {
    let meta = guard_parser(path, || {
        exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
            .map_err(|e| Error::image(path, format!("cannot read OpenEXR: {e}")))
    })?;
    for header in &meta.headers {
        let size = header.layer_size;
        check_image_size(path, size.width() as u64, size.height() as u64, header.channels.list.len() as u64)?;
    }
    Ok(())
}

/// The named channels of an OpenEXR layer.
type NamedPlanes = Vec<(String, Vec<f32>)>;

/// The channels of an OpenEXR file's first valid layer, by name, with its size.
fn decode_exr(path: &Path) -> Result<(usize, usize, NamedPlanes)> {
    let image = read_exr_image(path)?;
    Ok((image.width, image.height, image.channels))
}

/// Where an image's pixels sit in a larger one: the OpenEXR data window's origin within the
/// display window (a `--crop` render in its full frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExrWindow {
    /// Column and row of the first pixel in the full image.
    pub origin: (usize, usize),
    /// Width and height of the full image.
    pub full: (usize, usize),
}

/// All named float channels of an OpenEXR file and where they sit in its display window.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Where the pixels sit.
    pub window: ExrWindow,
    /// Width of the data.
    pub width: usize,
    /// Height of the data.
    pub height: usize,
    /// Channels by name, each `width * height` values, row 0 at the top.
    pub channels: NamedPlanes,
}

/// Read every channel of an OpenEXR file with its data window (bounded, checked like every
/// image read).
pub fn read_exr_image(path: &Path) -> Result<ExrImage> {
    use exr::prelude::traits::*;
    let bytes = read_bounded(path, limits::MAX_IMAGE_FILE_BYTES, "an image file")?;
    check_exr_header(path, &bytes)?;
    let image = guard_parser(path, || {
        read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(&bytes[..]))
            .map_err(|e| Error::image(path, format!("cannot read OpenEXR: {e}")))
    })?;
    let display = image.attributes.display_window;
    let layer = image.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let channels =
        layer.channel_data.list.iter().map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect())).collect();
    let position = layer.attributes.layer_position;
    let (ox, oy) =
        (position.x() as i64 - display.position.x() as i64, position.y() as i64 - display.position.y() as i64);
    let full = (display.size.width(), display.size.height());
    // A data window beyond the display window (overscan) is read as a whole image of its own.
    let inside = ox >= 0 && oy >= 0 && ox as usize + w <= full.0 && oy as usize + h <= full.1;
    let window = if inside {
        ExrWindow { origin: (ox as usize, oy as usize), full }
    } else {
        ExrWindow { origin: (0, 0), full: (w, h) }
    };
    Ok(ExrImage { window, width: w, height: h, channels })
}

/// Interleave planes into a bitmap.
fn interleave(w: usize, h: usize, planes: &[&Vec<f32>]) -> Bitmap {
    let n = planes.len();
    let mut data = vec![0.0; w * h * n];
    for (c, plane) in planes.iter().enumerate() {
        for (p, v) in plane.iter().enumerate() {
            data[p * n + c] = *v;
        }
    }
    Bitmap { width: w, height: h, channels: n, data }
}

fn read_exr(path: &Path) -> Result<Bitmap> {
    let (w, h, channels) = decode_exr(path)?;
    let find = |name: &str| channels.iter().position(|c| c.0.eq_ignore_ascii_case(name));
    // RGB(A) by name; else luminance; else the first four channels in the file's (sorted) order.
    let order: Vec<usize> = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => [Some(r), Some(g), Some(b), find("A")].into_iter().flatten().collect(),
        (_, _, _, Some(y)) => [Some(y), find("A")].into_iter().flatten().collect(),
        _ => (0..channels.len().min(4)).collect(),
    };
    if order.is_empty() {
        return Err(Error::image(path, "the OpenEXR file has no channels"));
    }
    Ok(interleave(w, h, &order.iter().map(|&i| &channels[i].1).collect::<Vec<_>>()))
}

/// The channels `names` (at most four, e.g. a render's AOVs "uv.U", "uv.V") of an OpenEXR
/// file, in that order; an error naming the file and the missing channel otherwise.
pub fn read_exr_channels(path: &Path, names: &[&str]) -> Result<Bitmap> {
    assert!((1..=4).contains(&names.len()));
    let (w, h, channels) = decode_exr(path)?;
    let planes = names
        .iter()
        .map(|name| {
            channels.iter().find(|c| c.0 == *name).map(|c| &c.1).ok_or_else(|| {
                let present: Vec<&str> = channels.iter().map(|c| c.0.as_str()).collect();
                Error::image(path, format!("no channel '{name}' (the file has {})", present.join(", ")))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(interleave(w, h, &planes))
}

/// Write named float channels (each `width * height` values, row 0 at the top) to an OpenEXR
/// file (32-bit float, ZIP compression).
pub fn write_exr(path: &Path, width: usize, height: usize, channels: Vec<(String, Vec<f32>)>) -> Result<()> {
    write_exr_window(path, ExrWindow { origin: (0, 0), full: (width, height) }, width, height, channels)
}

/// [`write_exr`] of pixels that sit at `window` in a larger image (the data window of a crop).
pub fn write_exr_window(
    path: &Path,
    window: ExrWindow,
    width: usize,
    height: usize,
    channels: Vec<(String, Vec<f32>)>,
) -> Result<()> {
    use exr::prelude::traits::*;
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, Image, ImageAttributes, IntegerBounds, Layer, LayerAttributes,
        SmallVec, Vec2,
    };
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> =
        channels.into_iter().map(|(name, values)| AnyChannel::new(name.as_str(), FlatSamples::F32(values))).collect();
    let position = Vec2(window.origin.0 as i32, window.origin.1 as i32);
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("tessera").with_position(position),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
    );
    let display = IntegerBounds::new((0, 0), (window.full.0, window.full.1));
    let image = Image::new(ImageAttributes::new(display), layer);
    write_atomically(path, |tmp| {
        image.write().to_file(tmp).map_err(|e| match e {
            exr::error::Error::Io(io) => Error::io(path, io),
            other => Error::image(path, format!("cannot write OpenEXR: {other}")),
        })
    })
}

/// Write an RGB bitmap as an 8-bit sRGB PNG (values clamped to [0, 1]).
pub fn write_png(path: &Path, rgb: &Bitmap) -> Result<()> {
    assert_eq!(rgb.channels, 3);
    let bytes: Vec<u8> = rgb.data.iter().map(|&v| (linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8).collect();
    let img = ::image::RgbImage::from_raw(rgb.width as u32, rgb.height as u32, bytes).expect("buffer size matches");
    write_atomically(path, |tmp| {
        img.save_with_format(tmp, ::image::ImageFormat::Png).map_err(|e| match e {
            ::image::ImageError::IoError(io) => Error::io(path, io),
            other => Error::image(path, format!("cannot write PNG: {other}")),
        })
    })
}

/// Write an RGB bitmap as a little-endian portable float map: the header `PF`, the size and
/// -1 (little-endian), then the rows from the bottom one up.
pub fn write_pfm(path: &Path, rgb: &Bitmap) -> Result<()> {
    assert_eq!(rgb.channels, 3);
    let mut bytes = format!("PF\n{} {}\n-1.0\n", rgb.width, rgb.height).into_bytes();
    for row in rgb.data.chunks_exact(3 * rgb.width).rev() {
        bytes.extend(row.iter().flat_map(|v| v.to_le_bytes()));
    }
    write_atomically(path, |tmp| std::fs::write(tmp, &bytes).map_err(|e| Error::io(path, e)))
}

/// Write an RGB bitmap as a Radiance HDR (RGBE) file, through the `image` crate's encoder.
pub fn write_hdr(path: &Path, rgb: &Bitmap) -> Result<()> {
    assert_eq!(rgb.channels, 3);
    let pixels: Vec<::image::Rgb<f32>> = rgb.data.chunks_exact(3).map(|c| ::image::Rgb([c[0], c[1], c[2]])).collect();
    write_atomically(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::io(path, e))?;
        ::image::codecs::hdr::HdrEncoder::new(std::io::BufWriter::new(file))
            .encode(&pixels, rgb.width, rgb.height)
            .map_err(|e| match e {
                ::image::ImageError::IoError(io) => Error::io(path, io),
                other => Error::image(path, format!("cannot write HDR: {other}")),
            })
    })
}

/// Write an RGB image and optional extra bitmaps (named channel groups, EXR only) in the format
/// of `path`'s extension. PNG, PFM and HDR keep only the RGB image.
pub fn write_image(path: &Path, rgb: &Bitmap, extra: &[(&[&str], Bitmap)]) -> Result<()> {
    write_image_in(path, rgb, extra, ExrWindow { origin: (0, 0), full: (rgb.width, rgb.height) })
}

/// [`write_image`] of pixels that sit at `window` in a larger image (EXR keeps the window).
pub fn write_image_in(path: &Path, rgb: &Bitmap, extra: &[(&[&str], Bitmap)], window: ExrWindow) -> Result<()> {
    match OutputFormat::from_path(path)? {
        OutputFormat::Png => write_png(path, rgb),
        OutputFormat::Pfm => write_pfm(path, rgb),
        OutputFormat::Hdr => write_hdr(path, rgb),
        OutputFormat::Exr => {
            let mut channels = Vec::new();
            let mut push = |names: &[&str], b: &Bitmap| {
                for (c, name) in names.iter().enumerate() {
                    channels.push((name.to_string(), b.data.iter().skip(c).step_by(b.channels).copied().collect()));
                }
            };
            push(&["R", "G", "B"], rgb);
            for (names, b) in extra {
                push(names, b);
            }
            write_exr_window(path, window, rgb.width, rgb.height, channels)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let mut b = Bitmap::new(3, 2, 3);
        for (i, v) in b.data.iter_mut().enumerate() {
            *v = i as f32 * 0.37 + 0.001;
        }
        write_image(&path, &b, &[]).unwrap();
        let back = read_bitmap(&path, ColorSpace::Linear).unwrap();
        assert_eq!(back, b);
        // No temporary file is left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn png_srgb_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let mut b = Bitmap::new(2, 1, 3);
        b.data = vec![0.577_581, 0.021_219, 1.0, 0.0, 0.5, 2.0];
        write_image(&path, &b, &[]).unwrap();
        let back = read_bitmap(&path, ColorSpace::Srgb).unwrap();
        // 200/255 and 40/255 decode to exactly these values (Mitsuba's numbers); 2.0 clamps.
        let expected = [0.577_581, 0.021_219, 1.0, 0.0, 0.5, 1.0];
        for (a, e) in back.data.iter().zip(expected) {
            assert!((a - e).abs() < 4e-3, "{a} vs {e}");
        }
        assert!((back.data[0] - 0.577_581).abs() < 1e-5);
    }

    #[test]
    fn jpeg_is_decoded_with_srgb_or_linear() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.jpg");
        ::image::RgbImage::from_pixel(8, 8, ::image::Rgb([200, 200, 200])).save(&path).unwrap();
        let srgb = read_bitmap(&path, ColorSpace::Srgb).unwrap();
        let linear = read_bitmap(&path, ColorSpace::Linear).unwrap();
        assert_eq!((srgb.width, srgb.height, srgb.channels), (8, 8, 3));
        // JPEG is lossy: within a couple of code values of 200.
        assert!((srgb.data[0] - 0.5776).abs() < 0.01, "{}", srgb.data[0]);
        assert!((linear.data[0] - 200.0 / 255.0).abs() < 0.01, "{}", linear.data[0]);
    }

    #[test]
    fn output_format_from_extension() {
        assert_eq!(OutputFormat::from_path(Path::new("a.EXR")).unwrap(), OutputFormat::Exr);
        assert!(OutputFormat::from_path(Path::new("a.jpg")).is_err());
    }
}
