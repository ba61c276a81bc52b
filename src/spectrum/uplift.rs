//! RGB -> spectrum uplift (Jakob & Hanika 2019, "A Low-Dimensional Function
//! Space for Efficient Spectral Upsampling").
//!
//! A linear sRGB colour becomes the smooth, bounded reflectance
//! s(lambda) = sigmoid(c0 x^2 + c1 x + c2), x = (lambda - 380 nm) / 400 nm,
//! whose colour under D65 is the given one; an emitter's spectrum is
//! s(lambda) D65(lambda) scaled so that white (1, 1, 1) has luminance 1.
//!
//! Light is linear, so the spectrum's shape depends on the colour's
//! chromaticity alone: a colour is scaled to the table's face (its largest
//! component at a fixed brightness) and the spectrum found there scaled
//! back. (The paper also tabulates brightness,
//! which serves reflectances; for dark colours its CIELAB fit has too
//! little to go on and gave a dark blue a bright cyan spectrum.) The
//! coefficients come from a 3 x 64^2 table over that face (at brightness
//! 0.9, see [`FACE`]), fitted once per process by Gauss-Newton in CIELAB (as the paper's `rgb2spec_opt` does)
//! and interpolated bilinearly. The sigmoid is defined at every
//! wavelength, so shifted lookups outside 380-780 nm stay smooth and in
//! [0, 1].

use super::color::linear_srgb_to_xyz;
use super::{CIE_5NM, LAMBDA_MAX, LAMBDA_MIN, d65};
use glam::{DMat3, DVec3, Vec3};
use rayon::prelude::*;
use std::sync::LazyLock;

/// Grid points along each side of the table's face.
pub(crate) const RES: usize = 64;

/// A smooth spectrum from an RGB colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbSpectrum {
    c: [f64; 3],
    scale: f64,
}

#[inline]
fn sigmoid(p: f64) -> f64 {
    if p.is_infinite() {
        return if p > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + p / (2.0 * (1.0 + p * p).sqrt())
}

#[inline]
fn x_of(nm: f64) -> f64 {
    (nm - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN)
}

impl RgbSpectrum {
    /// The reflectance-like spectrum (times the brightness scale) at `nm`.
    #[inline]
    pub fn reflectance(&self, nm: f64) -> f64 {
        let x = x_of(nm);
        self.scale * sigmoid((self.c[0] * x + self.c[1]) * x + self.c[2])
    }

    /// (c0, c1, c2, scale), as the GPU backend holds it.
    pub(crate) fn gpu_coefficients(&self) -> [f32; 4] {
        [
            self.c[0] as f32,
            self.c[1] as f32,
            self.c[2] as f32,
            self.scale as f32,
        ]
    }

    /// The emission spectrum at `nm`: reflectance times D65, normalised so
    /// that white (1, 1, 1) has luminance 1.
    #[inline]
    pub fn emission(&self, nm: f64) -> f64 {
        self.reflectance(nm) * d65(nm) * *D65_NORM
    }
}

/// 1 / Y of D65 on the 1 nm CMFs (380-780 nm).
static D65_NORM: LazyLock<f64> = LazyLock::new(|| 1.0 / super::CIE_1NM.integrate(d65).y);

/// The GPU backend's copy of the table: coefficients ([channel][y][x],
/// three each) and 1 / Y of D65.
pub(crate) fn gpu_tables() -> (Vec<f32>, f64) {
    (
        LUT.coeffs.iter().flatten().map(|&c| c as f32).collect(),
        *D65_NORM,
    )
}

/// Builds the uplift table now (0.1 s, once), so that it is not
/// counted in the first render that needs it.
pub fn prepare() {
    LazyLock::force(&LUT);
}

/// Uplifts a linear sRGB colour (components >= 0; the largest sets the
/// brightness, the ratios the spectrum's shape).
pub fn uplift(rgb: Vec3) -> RgbSpectrum {
    let rgb = rgb.as_dvec3().max(DVec3::ZERO);
    let m = rgb.max_element();
    if m <= 0.0 || !m.is_finite() {
        return RgbSpectrum {
            c: [0.0, 0.0, 0.0],
            scale: 0.0,
        };
    }
    RgbSpectrum {
        c: LUT.fetch(rgb / m),
        scale: m / FACE,
    }
}

/// Solver grid: D65-weighted CMFs on 5 nm, 380-780 nm, white Y = 1.
struct Solver {
    x: Vec<f64>,
    weights: Vec<DVec3>,
    white: DVec3,
    /// Per-component factor taking the sRGB matrix's white to this grid's
    /// D65 white (they differ by ~1e-4), so that white is reachable: a
    /// bounded spectrum cannot exceed s = 1.
    white_fix: DVec3,
}

impl Solver {
    fn new() -> Solver {
        let n = ((LAMBDA_MAX - LAMBDA_MIN) / 5.0) as usize + 1;
        let nm: Vec<f64> = (0..n).map(|i| LAMBDA_MIN + 5.0 * i as f64).collect();
        let raw: Vec<DVec3> = nm.iter().map(|&l| CIE_5NM.at(l) * d65(l)).collect();
        let y: f64 = raw.iter().map(|w| w.y).sum();
        let weights: Vec<DVec3> = raw.iter().map(|w| *w / y).collect();
        let white: DVec3 = weights.iter().sum();
        Solver {
            x: nm.iter().map(|&l| x_of(l)).collect(),
            white,
            white_fix: white / linear_srgb_to_xyz(DVec3::ONE),
            weights,
        }
    }

    fn lab(&self, xyz: DVec3) -> DVec3 {
        super::color::xyz_to_lab(xyz, self.white)
    }

    fn residual(&self, c: [f64; 3], target: DVec3) -> DVec3 {
        let xyz: DVec3 = self
            .x
            .iter()
            .zip(&self.weights)
            .map(|(&x, &w)| w * sigmoid((c[0] * x + c[1]) * x + c[2]))
            .sum();
        self.lab(xyz) - target
    }

    /// Gauss-Newton from `c` towards the colour `rgb`.
    fn fit(&self, rgb: DVec3, mut c: [f64; 3]) -> [f64; 3] {
        let target = self.lab(linear_srgb_to_xyz(rgb) * self.white_fix);
        for _ in 0..30 {
            let r = self.residual(c, target);
            if r.length() < 1e-7 {
                break;
            }
            let eps = 1e-5;
            let mut cols = [DVec3::ZERO; 3];
            for (j, col) in cols.iter_mut().enumerate() {
                let mut cp = c;
                cp[j] += eps;
                *col = (self.residual(cp, target) - r) / eps;
            }
            let jac = DMat3::from_cols(cols[0], cols[1], cols[2]);
            if jac.determinant().abs() < 1e-15 {
                break;
            }
            let step = jac.inverse() * r;
            for j in 0..3 {
                c[j] -= step[j];
            }
            // Keep the polynomial from running away on unreachable colours.
            let big = c.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if big > 200.0 {
                for v in &mut c {
                    *v *= 200.0 / big;
                }
            }
        }
        c
    }
}

fn smoothstep(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

struct Lut {
    /// [largest channel][y][x] -> coefficients, on the face where that
    /// channel is 1 and the next two (cyclically) are x and y.
    coeffs: Vec<[f64; 3]>,
}

static LUT: LazyLock<Lut> = LazyLock::new(Lut::build);

impl Lut {
    fn build() -> Lut {
        let solver = Solver::new();
        let face = FACE;
        // Gauss-Newton needs a nearby start for saturated colours: the
        // most saturated point of each row (x = 0) is reached by a march
        // in brightness from a dark, nearly grey-reflectance colour, and
        // the row from there, each fit starting from its neighbour's
        // solution.
        let ladder: Vec<f64> = (RES_LADDER / 5..RES_LADDER)
            .map(|k| face * smoothstep(smoothstep(k as f64 / (RES_LADDER - 1) as f64)))
            .collect();
        let rgb = |l: usize, x: f64, y: f64, z: f64| {
            let mut v = [0.0; 3];
            v[l] = z;
            v[(l + 1) % 3] = x * z;
            v[(l + 2) % 3] = y * z;
            DVec3::from_array(v)
        };
        let rows: Vec<Vec<[f64; 3]>> = (0..3 * RES)
            .into_par_iter()
            .map(|idx| {
                let (l, j) = (idx / RES, idx % RES);
                let y = j as f64 / (RES - 1) as f64;
                let mut c = [0.0; 3];
                for &z in &ladder {
                    c = solver.fit(rgb(l, 0.0, y, z), c);
                }
                let mut row = Vec::with_capacity(RES);
                for i in 0..RES {
                    c = solver.fit(rgb(l, i as f64 / (RES - 1) as f64, y, face), c);
                    row.push(c);
                }
                row
            })
            .collect();
        Lut {
            coeffs: rows.into_iter().flatten().collect(),
        }
    }

    /// Bilinearly interpolated coefficients for an RGB whose largest
    /// component is 1.
    fn fetch(&self, rgb: DVec3) -> [f64; 3] {
        let v = rgb.to_array();
        let l = if v[0] >= v[1] && v[0] >= v[2] {
            0
        } else if v[1] >= v[2] {
            1
        } else {
            2
        };
        let k = (RES - 1) as f64 / v[l];
        let x = (v[(l + 1) % 3] * k).clamp(0.0, (RES - 1) as f64);
        let y = (v[(l + 2) % 3] * k).clamp(0.0, (RES - 1) as f64);
        let (xi, yi) = ((x as usize).min(RES - 2), (y as usize).min(RES - 2));
        let (tx, ty) = (x - xi as f64, y - yi as f64);
        let at = |dy: usize, dx: usize| self.coeffs[(l * RES + yi + dy) * RES + xi + dx];
        let mut out = [0.0; 3];
        for (dy, wy) in [(0, 1.0 - ty), (1, ty)] {
            for (dx, wx) in [(0, 1.0 - tx), (1, tx)] {
                let c = at(dy, dx);
                for q in 0..3 {
                    out[q] += wy * wx * c[q];
                }
            }
        }
        out
    }
}

/// Brightness of the table's face: the largest component of the colours
/// it was fitted to. Below 1 so that white and the colours near it are
/// reflectances short of 1, with finite coefficients (at 1 the fits run
/// to the coefficients' bound and the interpolation between them misses
/// by up to CIEDE2000 1.1); a colour brighter than this may reflect up to
/// 1 / 0.9 at some wavelengths.
pub(crate) const FACE: f64 = 0.9;

/// Steps of the brightness ladder the fits climb (from a fifth of the way up).
const RES_LADDER: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::color::xyz_to_linear_srgb;
    use crate::spectrum::sampled::Wavelengths;

    /// Linear sRGB of an uplifted colour's emission on the 81-sample grid.
    fn round_trip(rgb: Vec3) -> DVec3 {
        let wl = Wavelengths::new(81);
        let s = uplift(rgb);
        let spec: Vec<f32> = wl.nm.iter().map(|&l| s.emission(l) as f32).collect();
        xyz_to_linear_srgb(wl.xyz(&spec))
    }

    #[test]
    fn round_trip_error_over_the_cube() {
        // Measured on a 9^3 grid of the unit cube: max |error| 1.9e-4, mean
        // 1.1e-4 (the table's interpolation and the 1e-4 gap between the
        // sRGB matrix's white and D65 on the CMF grid).
        let mut worst: f64 = 0.0;
        let mut sum = 0.0;
        let mut n = 0.0;
        for r in 0..=8 {
            for g in 0..=8 {
                for b in 0..=8 {
                    let rgb = Vec3::new(r as f32, g as f32, b as f32) / 8.0;
                    let e = (round_trip(rgb) - rgb.as_dvec3()).abs().max_element();
                    worst = worst.max(e);
                    sum += e;
                    n += 1.0;
                }
            }
        }
        eprintln!("uplift round trip: max {worst:.2e}, mean {:.2e}", sum / n);
        assert!(worst < 5e-4, "max round-trip error {worst}");
        assert!(sum / n < 2e-4, "mean round-trip error {}", sum / n);
    }

    #[test]
    fn dark_and_saturated_colours_keep_their_colour() {
        // A grid over the cube from black through the darkest 8-bit level
        // (1/255 encoded is 3e-4 linear) and below, to its faces and edges
        // (0 and 1 in every channel), as CIELAB relative to D65 sees it.
        let levels = [
            0.0,
            1e-6,
            1e-5,
            crate::spectrum::color::srgb_decode(1.0 / 255.0) as f64,
            1e-3,
            1.0 / 255.0,
            0.01,
            0.03,
            0.1,
            0.2,
            0.35,
            0.5,
            0.7,
            0.85,
            0.95,
            1.0,
        ];
        let mut worst = (0.0, Vec3::ZERO, DVec3::ZERO);
        for &r in &levels {
            for &g in &levels {
                for &b in &levels {
                    let rgb = Vec3::new(r as f32, g as f32, b as f32);
                    let out = round_trip(rgb).clamp(DVec3::ZERO, DVec3::ONE);
                    let de = crate::compare::delta_e(rgb, out.as_vec3());
                    if de > worst.0 {
                        worst = (de, rgb, out);
                    }
                }
            }
        }
        eprintln!(
            "uplift round trip over {} colours: worst CIEDE2000 {:.3} ({} -> {})",
            levels.len().pow(3),
            worst.0,
            worst.1,
            worst.2
        );
        assert!(
            worst.0 < 1.0,
            "CIEDE2000 {} for {} -> {}",
            worst.0,
            worst.1,
            worst.2
        );
        // The colour reported from a spectral render: (0, 0, 0.01) had come
        // back as a bright cyan.
        let blue = round_trip(Vec3::new(0.0, 0.0, 0.01));
        assert!(
            (blue - DVec3::new(0.0, 0.0, 0.01)).abs().max_element() < 1e-4,
            "{blue}"
        );
    }

    #[test]
    fn the_spectrum_scales_with_the_colour() {
        // Light is linear: k times a colour is k times its spectrum.
        let base = uplift(Vec3::new(0.8, 0.3, 0.05));
        for k in [1e-4, 0.01, 0.5, 3.0] {
            let s = uplift(Vec3::new(0.8, 0.3, 0.05) * k as f32);
            for nm in [300.0, 450.0, 550.0, 650.0, 900.0] {
                let (a, b) = (s.emission(nm), k * base.emission(nm));
                assert!((a - b).abs() <= 1e-6 * b.abs(), "{k} at {nm}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn spectra_are_bounded_and_bright_colours_scale() {
        let s = uplift(Vec3::new(0.2, 0.7, 0.1));
        for l in (200..1200).step_by(10) {
            let v = s.reflectance(l as f64);
            assert!((0.0..=1.0).contains(&v));
        }
        let rgb = Vec3::new(0.3, 0.6, 0.9);
        let b = round_trip(rgb * 4.0) / 4.0;
        assert!((b - rgb.as_dvec3()).abs().max_element() < 5e-3, "{b}");
        assert_eq!(uplift(Vec3::ZERO).emission(500.0), 0.0);
    }
}
#[cfg(test)]
mod probe {
    #[test]
    fn probe_white() {
        for c in [glam::Vec3::ONE, glam::Vec3::splat(0.2158)] {
            let s = super::uplift(c);
            let v: Vec<String> = (0..9)
                .map(|i| format!("{:.5}", s.reflectance(380.0 + 50.0 * i as f64)))
                .collect();
            eprintln!("{c}: {:?} {}", s.c, v.join(" "));
        }
    }
}
