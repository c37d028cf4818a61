//! tessera: a reference path tracer for procedural surface textures.
//!
//! tessera path-traces scenes of triangle meshes with physically based materials whose
//! parameters come from textures evaluated at every ray hit, with ray-differential footprints
//! for filtering. Its first duty is to be right: every module has an independent truth it is
//! tested against (see `DESIGN.md` in the project's design folder and the tests).
//!
//! ```
//! use tessera::scene::{load_scene_str, SceneOverrides};
//! // A camera looking at a square light: every pixel sees exactly its radiance.
//! let scene = load_scene_str(r#"
//!     [render]
//!     width = 8
//!     height = 8
//!     spp = 4
//!     [camera]
//!     fov = 20
//!     eye = [0, 0, 5]
//!     target = [0, 0, 0]
//!     [[shapes]]
//!     type = "rectangle"
//!     emission = [2.5, 1.0, 0.5]
//! "#, std::path::Path::new("inline.toml"), &SceneOverrides::default()).unwrap();
//! let film = tessera::integrator::render(&scene, None, &[], &|_, _| {});
//! let image = film.radiance();
//! assert_eq!(image.values(3, 4), &[2.5, 1.0, 0.5]);
//! ```

#![warn(missing_docs)]
#![deny(unsafe_code)]
// Comparisons such as `!(x > 0.0)` are deliberate: they are also true for NaN, which is how
// invalid input is rejected throughout.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod color;
pub mod deform;
pub mod error;
pub mod files;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod image;
pub mod integrator;
pub mod light;
pub mod limits;
pub mod material;
pub mod math;
pub mod pups;
pub mod regress;
pub mod sampling;
pub mod scene;
pub mod shader;
pub mod simd;
pub mod texture;
pub mod tiles;

pub use error::{Error, Result};
