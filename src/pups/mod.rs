//! Partition-of-unity parametric textures (paper 002; DESIGN.md section 8): values and labels
//! at control points, interpolated through their Delaunay graph.
//!
//! - [`points`]: Poisson disk control points (Bridson), uniform or with varying spacing,
//!   periodic for tileable textures.
//! - [`field`]: the PUPs weights (Eq. 1-4) and their normalised sum, with a grid that lists
//!   the points near every lookup.
//! - [`presets`]: the textures of Sec. 3 (Fig. 6-17) as named presets.
//! - [`file`]: control points read from CSV or JSON.

pub mod field;
pub mod file;
pub mod points;
pub mod presets;

pub use field::{ControlPoints, PupsField};
pub use file::read_points;
pub use points::Domain;
pub use presets::{Preset, PresetParams, PupsFilter, PupsTexture};
