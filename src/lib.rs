//! tessera: a reference path tracer for procedural surface textures.
//!
//! tessera path-traces scenes of triangle meshes with physically based materials whose
//! parameters come from textures evaluated at every ray hit, with ray-differential footprints
//! for filtering. Its first duty is to be right: every module has an independent truth it is
//! tested against (see `DESIGN.md` in the project's design folder and the tests).
//!
//! ```
//! use tessera::scene::{load_scene_str, SceneOverrides};
//! // A diffuse square lit by a white environment: a furnace.
//! let scene = load_scene_str(r#"
//!     [render]
//!     width = 8
//!     height = 8
//!     spp = 4
//!     [camera]
//!     fov = 30
//!     eye = [0, 0, 5]
//!     target = [0, 0, 0]
//!     [environment]
//!     type = "constant"
//!     radiance = 1.0
//!     [materials.white]
//!     type = "diffuse"
//!     reflectance = 0.8
//!     [[shapes]]
//!     type = "rectangle"
//!     material = "white"
//! "#, std::path::Path::new("inline.toml"), &SceneOverrides::default()).unwrap();
//! let film = tessera::integrator::render(&scene, None, &[], &|_, _| {});
//! // A flat diffuse surface under a uniform sky reflects albedo x radiance.
//! let centre = film.radiance().pixel(4, 4);
//! assert!((centre.x - 0.8).abs() < 1e-3);
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
pub mod error;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod light;
pub mod material;
pub mod math;
pub mod sampling;
pub mod scene;
pub mod texture;

pub use error::{Error, Result};
