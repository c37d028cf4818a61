//! Every size that a file or a flag controls, with its limit. Each limit is checked before the
//! memory or time it bounds is spent, and each error message names it. `docs/limits.md` lists
//! them with the memory they stand for; keep the two together.
//!
//! The principle: at its limit, one item costs at most a few GiB of memory (the machines this
//! project runs on have 8-32 GiB) and time that grows with what the user asked for, shown by a
//! progress bar where it can be long. A file's size bounds what parsing it allocates, so the
//! file limits come first; the counts that a file's few bytes can blow up (instanced glTF
//! meshes, procedural spheres, image headers) have limits of their own.

/// Largest scene file (TOML) read, in bytes. Scenes are short texts; this stops `/dev/zero`.
pub const MAX_SCENE_FILE_BYTES: u64 = 16 << 20;

/// Largest mesh file (OBJ, glTF, GLB, and each glTF buffer) read, in bytes: an OBJ of about
/// 30 million triangles.
pub const MAX_MESH_FILE_BYTES: u64 = 2 << 30;

/// Largest image file read, in bytes.
pub const MAX_IMAGE_FILE_BYTES: u64 = 1 << 30;

/// Largest side of an image read, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 65_536;

/// Largest pixel count of an image read (8192 x 8192): 1 GiB as four float channels, 1.33 GiB
/// with its MIP pyramid.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Largest number of values (pixels times channels) of an image read: 1 GiB of floats.
pub const MAX_IMAGE_VALUES: u64 = 1 << 28;

/// Largest number of triangles in a scene or a mesh given to `tessera deform`: about 7 GiB
/// with the vertices and the BVH's build.
pub const MAX_TRIANGLES: u64 = 1 << 25;

/// Most segments or rings of a procedural `uv_sphere`. Besides [`MAX_TRIANGLES`]: a sphere of
/// many more segments than rings is made of slivers, on which obvhs's PLOC build slows down
/// far more than linearly (65535 x 32: 4 million triangles, 105 s to build, against 3 s for
/// as many ordinary triangles).
pub const MAX_SPHERE_SEGMENTS: u32 = 8192;

/// Largest side of a rendered image, in pixels.
pub const MAX_RENDER_SIDE: u32 = 32_768;

/// Largest pixel count of a rendered image (an 8K UHD frame, 7680 x 4320, fits): the film
/// keeps about 80 bytes per pixel, so 2.7 GiB, plus the images written.
pub const MAX_RENDER_PIXELS: u64 = 1 << 25;

/// Largest sample count per pixel.
pub const MAX_SPP: u32 = 1 << 24;

/// Largest worker thread count (`--threads`): far above any machine's core count, far below
/// what spawning would take long for.
pub const MAX_THREADS: usize = 1024;

/// Largest side of a bake (`tessera bake --res`, `export-mitsuba --bake-res`): 1 GiB of RGBA
/// floats, 3.2 GiB at the peak of writing it.
pub const MAX_BAKE_RES: u32 = 8192;

/// Largest side of the F map of `tessera deform` (`--res`): 256 MiB per map, 1.9 GiB
/// at the peak with the pictures.
pub const MAX_DEFORM_RES: u32 = 4096;

/// Most rounds of `tessera deform`'s per-chart smoothing (`--smoothing`): each is one pass over
/// the triangles, so that the largest mesh takes minutes, not hours.
pub const MAX_DEFORM_SMOOTHING: u32 = 256;

/// Largest cuts file (`cuts = "cuts.json"`, written by `tessera deform`): a few hundred
/// thousand cut edges.
pub const MAX_CUTS_FILE_BYTES: u64 = 64 << 20;

/// Most point pairs `tessera analyze` evaluates per seam metric (cut edges times samples per
/// edge): the samples per edge are lowered to fit.
pub const MAX_SEAM_SAMPLES: usize = 1 << 22;

/// Deepest nesting of tiling-and-blending textures (one whose exemplar is another): each level
/// multiplies the cost of a lookup by the tiles per point (3 for hexagonal tiles), at load
/// (the exemplar's mean) and at every hit.
pub const MAX_TILING_BLENDING_NESTING: usize = 3;

/// The message of a size over its limit: `what` (`"the image"`), the size and the limit.
pub(crate) fn exceeded(what: &str, size: impl std::fmt::Display, limit: impl std::fmt::Display) -> String {
    format!("{what} is {size}, over tessera's limit of {limit} (docs/limits.md)")
}
