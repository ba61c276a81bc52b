//! The RGBA disk texture: a thin disk from the ISCO outward.
//!
//! Temperature follows the thin-disk profile T ~ r^-3/4 (1 - sqrt(r_in/r))^1/4
//! (peak at r = 49/36 r_in); colour is the blackbody's, brightness ~ T^4.
//! Turbulence is fractal Perlin noise on a cylinder in (phi, ln r), sheared
//! by differential rotation into trailing streaks; gaps between lanes are
//! rings of alpha 0 whose radii wander a little with angle.

use super::{BlackbodyTable, dither, quantise};
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;

/// Parameters of the disk texture.
#[derive(Clone, Debug)]
pub struct DiskParams {
    /// Texture side (texels).
    pub size: u32,
    /// Outer radius the texture spans (r_s); match `disk.radius`.
    pub outer: f64,
    /// Inner edge (r_s); the ISCO is 3.
    pub inner: f64,
    /// Peak temperature (K).
    pub peak_kelvin: f64,
    /// Noise seed.
    pub seed: u32,
}

impl Default for DiskParams {
    fn default() -> Self {
        DiskParams {
            size: 1024,
            outer: 10.0,
            inner: 3.0,
            peak_kelvin: 5000.0,
            seed: 7,
        }
    }
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Thin-disk temperature shape, 1 at its peak.
pub fn temperature_profile(r: f64, inner: f64) -> f64 {
    let f = |r: f64| {
        if r <= inner {
            0.0
        } else {
            r.powf(-0.75) * (1.0 - (inner / r).sqrt()).powf(0.25)
        }
    };
    f(r) / f(49.0 / 36.0 * inner)
}

/// Generates the texture (RGBA, 8-bit sRGB colour, linear alpha).
pub fn generate(p: &DiskParams) -> image::RgbaImage {
    let turbulence = Fbm::<Perlin>::new(p.seed).set_octaves(6);
    let lanes = Fbm::<Perlin>::new(p.seed + 1).set_octaves(4);
    let table = BlackbodyTable::new(500.0, p.peak_kelvin + 100.0);
    let n = p.size as usize;
    let mut data = vec![0u8; n * n * 4];
    data.par_chunks_mut(n * 4).enumerate().for_each(|(j, row)| {
        for i in 0..n {
            let x = ((i as f64 + 0.5) / n as f64 * 2.0 - 1.0) * p.outer;
            let y = (1.0 - (j as f64 + 0.5) / n as f64 * 2.0) * p.outer;
            let r = x.hypot(y);
            if r <= p.inner || r >= p.outer {
                continue;
            }
            let phi = y.atan2(x);
            let lr = r.ln();
            // Keplerian shear winds features into trailing spirals.
            let sheared = phi + 2.5 * lr;
            let (c, s) = (sheared.cos(), sheared.sin());
            let streak = turbulence.get([1.6 * c, 1.6 * s, 14.0 * lr]);
            let fine = turbulence.get([6.0 * c, 6.0 * s, 60.0 * lr + 100.0]);
            let density = (0.55 + 0.75 * streak + 0.3 * fine).clamp(0.05, 1.5);
            // Gaps: rings where a slowly wandering radial noise dips.
            let ring = lanes.get([0.35 * phi.cos(), 0.35 * phi.sin(), 1.7 * r]);
            let gap = smoothstep(-0.30, -0.22, ring);
            let edge = smoothstep(p.inner, p.inner + 0.15, r)
                * (1.0 - smoothstep(p.outer * 0.9, p.outer, r));
            let alpha = (gap * edge * (0.55 + 0.45 * density.min(1.0))).clamp(0.0, 1.0);
            if alpha <= 0.0 {
                continue;
            }
            let t = temperature_profile(r, p.inner);
            let kelvin = p.peak_kelvin * t;
            let color = table.get(kelvin) * (0.95 * (t * t * t * t * density) as f32);
            let k = (j * n + i) as u64;
            let px = &mut row[i * 4..i * 4 + 4];
            px[0] = quantise(color.x, dither(k, 0));
            px[1] = quantise(color.y, dither(k, 1));
            px[2] = quantise(color.z, dither(k, 2));
            px[3] = (alpha * 255.0).round().max(1.0) as u8;
        }
    });
    image::RgbaImage::from_raw(p.size, p.size, data).expect("buffer sized to the image")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_peaks_at_49_36_of_inner_edge() {
        let inner = 3.0;
        let peak = 49.0 / 36.0 * inner;
        assert!((temperature_profile(peak, inner) - 1.0).abs() < 1e-12);
        assert!(temperature_profile(peak * 1.01, inner) < 1.0);
        assert!(temperature_profile(peak * 0.99, inner) < 1.0);
        assert_eq!(temperature_profile(inner, inner), 0.0);
        // Far out, T ~ r^-3/4.
        let ratio = temperature_profile(1000.0, inner) / temperature_profile(2000.0, inner);
        assert!((ratio - 2f64.powf(0.75)).abs() < 0.01);
    }

    #[test]
    fn texture_is_transparent_inside_isco_and_outside_radius_and_has_gaps() {
        let p = DiskParams {
            size: 256,
            ..DiskParams::default()
        };
        let img = generate(&p);
        let at = |x: f64, y: f64| {
            let i = ((x / p.outer + 1.0) * 0.5 * 256.0) as u32;
            let j = ((1.0 - y / p.outer) * 0.5 * 256.0) as u32;
            img.get_pixel(i, j).0
        };
        assert_eq!(at(0.0, 0.0)[3], 0);
        assert_eq!(at(2.0, 1.0)[3], 0);
        assert_eq!(at(9.9, 9.9)[3], 0);
        // Along a radius, some texels are gaps and most are opaque.
        let alphas: Vec<u8> = (0..200)
            .map(|k| at(3.2 + 6.5 * k as f64 / 200.0, 0.01)[3])
            .collect();
        let gaps = alphas.iter().filter(|&&a| a == 0).count();
        assert!(gaps > 3 && gaps < 100, "{gaps} gap texels of 200");
        // Hot inner edge brighter than the outer part.
        let inner = at(4.1, 0.0);
        let outer = at(8.5, 0.0);
        let lum = |p: [u8; 4]| p[0] as u32 + p[1] as u32 + p[2] as u32;
        assert!(lum(inner) > lum(outer), "{inner:?} vs {outer:?}");
    }
}
