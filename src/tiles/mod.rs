//! Seamless tiled textures on quadrilateral meshes (paper 001; DESIGN.md section 7).
//!
//! - [`layout`]: tile names (edge types e0 e1 e2 e3) and where each tile sits in the tile
//!   image (Sec. 2, Sec. 6).
//! - [`mapping`]: AssignBoundaries and AssignTextureCoordinates (Sec. 3, Fig. 6).
//! - [`synthesis`]: tile images from any photograph (Sec. 4, Fig. 10-11).

pub mod layout;
pub mod mapping;
pub mod synthesis;

pub use layout::{TileLayout, TileName, complementary};
pub use mapping::{assign_boundaries, assign_tiles, texture_coordinates};
pub use synthesis::{PixelRect, TileTemplates, synthesize_tiles};
