//! The scene file, mirrored one to one by serde types.
//!
//! Parsing only collects what the file says; [`crate::scene::Scene::build`]
//! checks the values and loads assets. Every table rejects unknown keys. Units
//! are SI (kg, m); the disk's radii are in Schwarzschild radii.
//!
//! ```toml
//! [image]
//! width = 1024
//! height = 1024
//! png = "../img/side.png"
//!
//! [camera]
//! position = [0.0, -2.0e11, 2.5e10]
//! look_at = [0.0, 0.0, 0.0]
//! fov = 50.0
//!
//! [black_hole]
//! mass = 8.57e36
//!
//! [disk]
//! radius = 10.0
//! texture = "../spectral_assets/disk_rgba.png"
//!
//! [sky]
//! texture = "../spectral_assets/sky.png"
//! ```
//!
//! The module's parts: `schema` (the types, one to one with the file),
//! `overrides` (the `--set`/`--unset` language), `quantity` (numbers with units),
//! `load` (reading, applying overrides, resolving paths, the saved form),
//! `problems` (every schema
//! problem of a file at once), `errors` (the messages, in the file's
//! words) and `warnings` (settings that do nothing in a scene).

mod errors;
#[cfg(test)]
mod keys;
mod load;
mod overrides;
mod problems;
pub mod quantity;
mod schema;
mod warnings;

pub use errors::{ConfigError, humanize};
pub use overrides::{Override, from_cli};
pub use schema::*;
