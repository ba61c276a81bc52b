//! # blackhole
//!
//! A spectral, physically-motivated renderer of a Schwarzschild black hole
//! acting as a gravitational lens: an accretion disk and a star panorama seen
//! through light rays that gravity bends.
//!
//! The pipeline: a TOML scene file is parsed into a [`config::SceneConfig`]
//! (nothing but what the file says), then validated and loaded into a
//! [`scene::Scene`] in units of the Schwarzschild radius. For every pixel
//! sample the [`camera::Camera`] gives a ray, a [`physics::Model`] traces it
//! step by step and hands each step's [`physics::Segment`] to the scene,
//! which tests it against the [`disk::Disk`]; a ray that leaves the scene
//! takes its exact asymptotic direction to the [`sky::Sky`]. The linear film
//! is tone-mapped and written as PNG and EXR by [`output`].
//!
//! ```no_run
//! use blackhole::{config::SceneConfig, scene::Scene};
//! let config = SceneConfig::load("configs/quick.toml".as_ref(), &[])?;
//! let scene = Scene::build(config)?;
//! let (film, stats) = scene.render(&|_| {});
//! println!("{} rays, {} captured", stats.rays, stats.captured);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

// Validation writes `!(x > 0.0)` on purpose: NaN must fail it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod adaptive;
pub mod animation;
pub mod assets;
pub mod camera;
pub mod canvas;
pub mod colormap;
pub mod compare;
pub mod config;
pub mod cpu;
pub mod disk;
pub mod files;
pub mod film;
pub mod footprint;
pub mod gpu;
pub mod info;
pub mod inputs;
pub mod memory;
pub mod objects;
pub mod output;
pub mod physics;
pub mod pipeline;
pub mod post;
#[cfg(feature = "python")]
mod python;
pub mod relens;
pub mod ring;
pub mod sampling;
pub mod scene;
pub mod shapes;
pub mod sky;
pub mod spectral;
pub mod spectral_texture;
pub mod spectrum;
pub mod starmap;
pub mod stars;
pub mod texture;
pub mod thin_disk;
pub mod tiles;
pub mod transfer;
pub mod units;
pub mod video;
pub mod view;
pub mod volume;
pub mod wgsl;
