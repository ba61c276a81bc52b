//! The RGBA disk texture: a thin disk from the ISCO outward.
//!
//! Temperature follows the thin-disk profile T ~ r^-3/4 (1 - sqrt(r_in/r))^1/4
//! (peak at r = 49/36 r_in); colour is the blackbody's, brightness ~ T^4.
//! Turbulence is fractal Perlin noise on a cylinder in (phi, ln r), sheared
//! by differential rotation into trailing streaks; gaps between lanes are
//! rings of alpha 0 whose radii wander a little with angle.

use super::{BlackbodyTable, dither, quantise};
use crate::spectrum::planck;
use crate::spectrum::sampled::luminance;
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
    temperature_shape(r, inner) / temperature_shape(49.0 / 36.0 * inner, inner)
}

/// r^-3/4 (1 - sqrt(inner / r))^1/4, 0 inside `inner`: the shape that
/// [`temperature_profile`] scales to 1 at its peak, r = 49/36 inner.
pub fn temperature_shape(r: f64, inner: f64) -> f64 {
    if r <= inner {
        0.0
    } else {
        r.powf(-0.75) * (1.0 - (inner / r).sqrt()).powf(0.25)
    }
}

/// Emission of a texel of density 1 at the peak temperature, as a
/// luminance: keeps the densest, hottest texels just inside 8 bits.
const PEAK_LUMINANCE: f64 = 0.7;

/// The disk's material at one texel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Texel {
    /// Emissivity-like density (0.05 to 1.4 where there is gas).
    pub density: f32,
    /// Temperature (K).
    pub kelvin: f32,
    /// Coverage (0 in gaps, inside the ISCO and beyond the edge).
    pub alpha: f32,
}

impl Texel {
    /// Spectral radiance at `nm`, relative: PEAK_LUMINANCE x density x
    /// B_lambda(T) / Y(B(T_peak)), so the RGB and spectral textures are the
    /// same light.
    pub fn radiance(&self, nm: f64, peak_luminance_norm: f64) -> f64 {
        if self.alpha <= 0.0 {
            return 0.0;
        }
        PEAK_LUMINANCE * self.density as f64 * planck(nm, self.kelvin as f64) / peak_luminance_norm
    }
}

/// The material on an n x n grid over [-outer, outer]^2, row 0 at +y.
pub fn texels(p: &DiskParams, n: usize) -> Vec<Texel> {
    let turbulence = Fbm::<Perlin>::new(p.seed).set_octaves(6);
    let lanes = Fbm::<Perlin>::new(p.seed + 1).set_octaves(4);
    let mut out = vec![Texel::default(); n * n];
    out.par_chunks_mut(n).enumerate().for_each(|(j, row)| {
        for (i, texel) in row.iter_mut().enumerate() {
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
            let density = (0.55 + 0.75 * streak + 0.3 * fine).clamp(0.05, 1.4);
            // Gaps: rings where a slowly wandering radial noise dips.
            let ring = lanes.get([0.35 * phi.cos(), 0.35 * phi.sin(), 1.7 * r]);
            let gap = smoothstep(-0.30, -0.22, ring);
            let edge = smoothstep(p.inner, p.inner + 0.15, r)
                * (1.0 - smoothstep(p.outer * 0.9, p.outer, r));
            let alpha = (gap * edge * (0.55 + 0.45 * density.min(1.0))).clamp(0.0, 1.0);
            if alpha <= 0.0 {
                continue;
            }
            *texel = Texel {
                density: density as f32,
                kelvin: (p.peak_kelvin * temperature_profile(r, p.inner)) as f32,
                alpha: alpha as f32,
            };
        }
    });
    out
}

/// Generates the RGBA texture (8-bit sRGB colour, linear alpha): the
/// spectral emission's colour and luminance.
pub fn generate(p: &DiskParams) -> image::RgbaImage {
    let n = p.size as usize;
    let grid = texels(p, n);
    let table = BlackbodyTable::new(500.0, p.peak_kelvin + 100.0);
    let peak_y = luminance(p.peak_kelvin);
    // Luminance of B(T) in 5 K steps: a 401-point integral per texel would
    // dominate the run time.
    let lum: Vec<f64> = (0..=(p.peak_kelvin / 5.0).ceil() as usize + 1)
        .map(|k| luminance((5 * k) as f64 + 1e-9))
        .collect();
    let lum_at = |t: f64| {
        let f = t / 5.0;
        let i = (f as usize).min(lum.len() - 2);
        let w = f - i as f64;
        lum[i] * (1.0 - w) + lum[i + 1] * w
    };
    let mut data = vec![0u8; n * n * 4];
    data.par_chunks_mut(n * 4).enumerate().for_each(|(j, row)| {
        for i in 0..n {
            let t = grid[j * n + i];
            if t.alpha <= 0.0 {
                continue;
            }
            // Luminance of B(T) relative to the peak's, times density.
            let y = PEAK_LUMINANCE * t.density as f64 * lum_at(t.kelvin as f64) / peak_y;
            let color = table.get(t.kelvin as f64) * y as f32;
            let k = (j * n + i) as u64;
            let px = &mut row[i * 4..i * 4 + 4];
            px[0] = quantise(color.x, dither(k, 0));
            px[1] = quantise(color.y, dither(k, 1));
            px[2] = quantise(color.z, dither(k, 2));
            px[3] = (t.alpha * 255.0).round().max(1.0) as u8;
        }
    });
    image::RgbaImage::from_raw(p.size, p.size, data).expect("buffer sized to the image")
}

/// The spectral texture set: one 16-bit greyscale image per wavelength
/// (each scaled to its own maximum), an 8-bit alpha image and the manifest
/// text. Returns (file name, image) pairs and the manifest.
pub fn generate_spectral(
    p: &DiskParams,
    size: u32,
    nm: &[f64],
) -> (Vec<(String, image::DynamicImage)>, String) {
    let n = size as usize;
    let grid = texels(p, n);
    let peak_y = luminance(p.peak_kelvin);
    let mut files = Vec::new();
    let alpha = image::GrayImage::from_fn(size, size, |i, j| {
        let a = grid[j as usize * n + i as usize].alpha;
        image::Luma([if a > 0.0 {
            (a * 255.0).round().max(1.0) as u8
        } else {
            0
        }])
    });
    files.push((
        "alpha.png".to_string(),
        image::DynamicImage::ImageLuma8(alpha),
    ));
    let mut manifest = format!(
        "# Spectral texture set of the accretion disk, made by `blackhole assets`\n\
         # (thin disk from {inner} to {outer} r_s, peak temperature {kelvin} K, seed {seed}).\n\
         # Each image is one wavelength (16-bit PNG holding 10 significant bits);\n\
         # value = code / 65535 * scale.\n\
         units = \"relative spectral radiance per nm: density x {PEAK_LUMINANCE} x B_lambda(T) / Y(B(T_peak)), Y = luminance\"\n\
         alpha = \"alpha.png\"\n",
        inner = p.inner,
        outer = p.outer,
        kelvin = p.peak_kelvin,
        seed = p.seed
    );
    for &l in nm {
        let values: Vec<f64> = grid.par_iter().map(|t| t.radiance(l, peak_y)).collect();
        let max = values.iter().cloned().fold(0.0, f64::max);
        let max = if max > 0.0 { max } else { 1.0 };
        // 10 bits of precision (1/1023 of the image's maximum) in the 16-bit
        // container: the low bits are zero, which halves the PNG's size.
        let scale = max * 65535.0 / (1023 << 6) as f64;
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(size, size, |i, j| {
            let q = (values[j as usize * n + i as usize] / max * 1023.0).round() as u16;
            image::Luma([q << 6])
        });
        let name = format!("disk_{:04}nm.png", l.round() as u32);
        manifest +=
            &format!("\n[[wavelength]]\nnm = {l:.1}\nfile = \"{name}\"\nscale = {scale:e}\n");
        files.push((name, image::DynamicImage::ImageLuma16(img)));
    }
    (files, manifest)
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
