//! Reproducible generators for the shipped assets (`blackhole assets`).
//!
//! Everything is a pure function of its parameters and a fixed seed, so the
//! committed files can be rebuilt byte for byte.

pub mod disk;
pub mod sky;

use crate::spectrum::{blackbody_xyz, color::xyz_to_linear_srgb};
use glam::Vec3;

/// Linear sRGB of a blackbody at `kelvin`, luminance 1 (negative channels,
/// outside the sRGB gamut, clipped to 0).
pub fn blackbody_rgb(kelvin: f64) -> Vec3 {
    xyz_to_linear_srgb(blackbody_xyz(kelvin))
        .as_vec3()
        .max(Vec3::ZERO)
}

/// Blackbody colours tabulated in 25 K steps: per-texel Planck integrals
/// would dominate the generators' run time.
pub struct BlackbodyTable {
    min: f64,
    colors: Vec<Vec3>,
}

impl BlackbodyTable {
    const STEP: f64 = 25.0;

    /// Table over [min, max] kelvin.
    pub fn new(min: f64, max: f64) -> BlackbodyTable {
        let n = ((max - min) / Self::STEP).ceil() as usize + 1;
        BlackbodyTable {
            min,
            colors: (0..n)
                .map(|i| blackbody_rgb(min + i as f64 * Self::STEP))
                .collect(),
        }
    }

    /// Colour at `kelvin`, linearly interpolated, clamped to the table.
    pub fn get(&self, kelvin: f64) -> Vec3 {
        let f = ((kelvin - self.min) / Self::STEP).clamp(0.0, (self.colors.len() - 1) as f64);
        let i = (f as usize).min(self.colors.len() - 2);
        self.colors[i].lerp(self.colors[i + 1], (f - i as f64) as f32)
    }
}

/// Deterministic dither in [-0.5, 0.5) for pixel `i`, so smooth gradients do
/// not band when quantised to 8 bits.
pub(crate) fn dither(i: u64, channel: u64) -> f32 {
    let mut z = i
        .wrapping_mul(3)
        .wrapping_add(channel)
        .wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 24) as f32 - 0.5
}

/// 8-bit sRGB code of a linear value, with dither.
pub(crate) fn quantise(x: f32, dither: f32) -> u8 {
    let e = crate::spectrum::color::srgb_encode(x.clamp(0.0, 1.0)) * 255.0 + 0.5 + dither;
    e.clamp(0.0, 255.0) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_matches_direct_integration() {
        let t = BlackbodyTable::new(1000.0, 20000.0);
        for k in [1500.0, 4321.0, 5800.0, 12000.0] {
            let d = (t.get(k) - blackbody_rgb(k)).abs().max_element();
            assert!(d < 2e-3, "{k}: {d}");
        }
    }

    #[test]
    fn hot_is_blue_cool_is_red() {
        let cool = blackbody_rgb(3000.0);
        let hot = blackbody_rgb(15000.0);
        assert!(cool.x > cool.z && hot.z > hot.x);
    }
}
