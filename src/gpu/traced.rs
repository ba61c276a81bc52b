//! What a pass of samples is asked for ([`Want`], [`Show`]) and what it
//! gives ([`Traced`]): the terms the bands of rows (bands.rs), the films
//! read back (films.rs) and the passes (passes.rs) share.

use crate::film::{PixelProbe, Stats};
use glam::Vec3;

/// What a pass of samples gave.
pub(super) struct Traced {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) xyz: Vec<Vec3>,
    pub(super) kept: Vec<f32>,
    pub(super) spectra: Vec<f32>,
    pub(super) band_xyz: Vec<f32>,
    pub(super) bloomed: Option<Vec<Vec3>>,
    /// Each pixel's observables (where the scene asks for them).
    pub(super) observed: Vec<PixelProbe>,
    /// Each pixel's adaptive sampling sums (the last vec4 of its
    /// observables' words; with adaptive sampling).
    pub(super) adaptive: Vec<[u32; 4]>,
    pub(super) stats: Stats,
}

/// What a pass of samples keeps of each band of rows it traces.
#[derive(Clone, Copy)]
pub(super) struct Want {
    /// Read the film (and the spectra when kept) back to the host.
    pub(super) film: bool,
    /// ... and the bloom bands.
    pub(super) bands: bool,
    /// Add the bands to the display's image.
    pub(super) show: Option<Show>,
}

/// What the display does with a pass.
#[derive(Clone, Copy)]
pub(super) struct Show {
    /// The pass starts the image again (else it is added to it).
    pub(super) restart: bool,
    /// Encode the image into the 8-bit texture.
    pub(super) encode: bool,
    /// Read the bloomed image back.
    pub(super) read_bloomed: bool,
}
