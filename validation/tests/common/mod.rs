//! Helpers shared by the integration tests (each test crate uses a part).
#![allow(dead_code)]

use blackhole::config::SceneConfig;
use blackhole::scene::Scene;
use std::path::{Path, PathBuf};

/// The black hole of the shipped scenes (kg; r_s = 1.27e10 m).
pub const MASS: f64 = 8.57e36;

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The shipped assets.
pub fn assets() -> PathBuf {
    root().join("spectral_assets")
}

/// A scene from TOML text, which must be valid.
pub fn scene(toml: &str) -> Scene {
    let cfg: SceneConfig = toml::from_str(toml).unwrap_or_else(|e| panic!("{e}\n{toml}"));
    Scene::build(cfg).unwrap()
}
