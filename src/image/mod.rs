//! Images: the float bitmap type, reading textures (PNG, JPEG, Radiance HDR, OpenEXR), writing
//! renders (EXR linear, PNG sRGB) without ever leaving a partial file, and the film that
//! accumulates samples.

mod bitmap;
pub mod compare;
mod film;
mod io;
mod merge;
mod montage;
mod pixel_filter;
mod seams;
mod tonemap;

pub use bitmap::{Bitmap, ColorSpace};
pub use film::{Aov, Film, PixelSum};
pub use io::{
    ExrImage, ExrWindow, OutputFormat, decode_image, read_bitmap, read_bitmap_raw, read_exr_channels, read_exr_image,
    write_exr, write_exr_window, write_image, write_image_in, write_png,
};
pub use merge::merge_crops;
pub use montage::montage;
pub use pixel_filter::{MAX_FILTER_RADIUS, PixelFilter};
pub use seams::{SeamVisibility, seam_visibility};
pub use tonemap::ToneMap;
