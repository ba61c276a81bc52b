//! Reproducible generators for the shipped assets (`blackhole assets`).
//!
//! Everything is a pure function of its parameters and a fixed seed, so the
//! committed files can be rebuilt byte for byte.

pub mod asteroid;
pub mod disk;
pub mod sky;

pub use crate::spectrum::{BlackbodyTable, blackbody_rgb};

/// Deterministic dither in [-0.5, 0.5) for pixel `i`, so smooth gradients do
/// not band when quantised to 8 bits.
pub(crate) fn dither(i: u64, channel: u64) -> f32 {
    let z = crate::sampling::mix(
        i.wrapping_mul(3)
            .wrapping_add(channel)
            .wrapping_add(0x9e37_79b9_7f4a_7c15),
    );
    (z >> 40) as f32 / (1u64 << 24) as f32 - 0.5
}

/// 8-bit sRGB code of a linear value, with dither.
pub(crate) fn quantise(x: f32, dither: f32) -> u8 {
    let e = crate::spectrum::color::srgb_encode(x.clamp(0.0, 1.0)) * 255.0 + 0.5 + dither;
    e.clamp(0.0, 255.0) as u8
}
