//! The camera's wavelength samples and fast blackbody spectra on them.

use super::{CIE_1NM, LAMBDA_MAX, LAMBDA_MIN, planck};
use glam::DVec3;

/// Most wavelength samples a render may use (1 nm over 380-780 nm).
pub const MAX_WAVELENGTHS: usize = 401;

/// Evenly spaced wavelength samples over [`LAMBDA_MIN`, `LAMBDA_MAX`], both
/// ends included, with the CIE 1931 weights that turn a sampled spectrum
/// into XYZ by a plain sum (the 'Integration' rule on this grid).
#[derive(Clone, Debug)]
pub struct Wavelengths {
    /// Sample wavelengths (nm).
    pub nm: Vec<f64>,
    /// Spacing (nm).
    pub step: f64,
    /// x-bar, y-bar, z-bar at each sample times the spacing; CMFs between
    /// the 1 nm table's points are interpolated linearly.
    pub weights: Vec<DVec3>,
}

impl Wavelengths {
    /// `n` samples, 2 <= n <= [`MAX_WAVELENGTHS`].
    pub fn new(n: usize) -> Wavelengths {
        assert!((2..=MAX_WAVELENGTHS).contains(&n), "validated by the scene");
        let step = (LAMBDA_MAX - LAMBDA_MIN) / (n - 1) as f64;
        let nm: Vec<f64> = (0..n).map(|i| LAMBDA_MIN + i as f64 * step).collect();
        let weights = nm
            .iter()
            .map(|&l| CIE_1NM.lerp(l).expect("380-780 nm lies in the CMF table") * step)
            .collect();
        Wavelengths { nm, step, weights }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.nm.len()
    }

    /// Always false: there are at least two samples.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// XYZ of a sampled spectrum.
    pub fn xyz(&self, spectrum: &[f32]) -> DVec3 {
        spectrum
            .iter()
            .zip(&self.weights)
            .map(|(&s, &w)| w * s as f64)
            .sum()
    }
}

/// Blackbody spectra on a set of wavelengths, tabulated in log temperature:
/// rendering needs hundreds of millions of them, and Planck's exponential
/// per wavelength would dominate.
///
/// Each row holds B_lambda(T) / Y(T), the spectrum scaled to luminance 1
/// (Y from the 1 nm CMFs, so it does not depend on the sample count).
#[derive(Clone, Debug)]
pub struct PlanckTable {
    n: usize,
    ln_t0: f64,
    dln_t: f64,
    rows: usize,
    /// Row-major: rows x n values of B / Y.
    values: Vec<f32>,
    /// ln Y(T) per row.
    ln_y: Vec<f64>,
    /// XYZ of each row on these wavelengths (the weighted sum of its
    /// values): light that is only blackbody skips the per-wavelength sum.
    xyz: Vec<DVec3>,
}

impl PlanckTable {
    const T_MIN: f64 = 100.0;
    const T_MAX: f64 = 1.0e6;
    const ROWS: usize = 4096;

    /// Table for these wavelengths.
    pub fn new(wl: &Wavelengths) -> PlanckTable {
        let n = wl.len();
        let ln_t0 = Self::T_MIN.ln();
        let dln_t = (Self::T_MAX.ln() - ln_t0) / (Self::ROWS - 1) as f64;
        let mut values = Vec::with_capacity(Self::ROWS * n);
        let mut ln_y = Vec::with_capacity(Self::ROWS);
        for r in 0..Self::ROWS {
            let t = (ln_t0 + r as f64 * dln_t).exp();
            let y = luminance(t);
            ln_y.push(y.ln());
            values.extend(wl.nm.iter().map(|&l| (planck(l, t) / y) as f32));
        }
        let xyz = values.chunks_exact(n).map(|row| wl.xyz(row)).collect();
        PlanckTable {
            n,
            ln_t0,
            dln_t,
            rows: Self::ROWS,
            values,
            ln_y,
            xyz,
        }
    }

    /// Row and weight of the next row for temperature `t` (clamped).
    /// The GPU backend's copy: (ln T0, d ln T, rows, the rows of values,
    /// ln Y per row).
    pub(crate) fn gpu_parts(&self) -> (f64, f64, usize, &[f32], &[f64]) {
        (self.ln_t0, self.dln_t, self.rows, &self.values, &self.ln_y)
    }

    #[inline]
    fn row(&self, t: f64) -> (usize, f64) {
        self.row_ln(t.ln())
    }

    /// [`PlanckTable::row`] from ln T.
    #[inline]
    fn row_ln(&self, ln_t: f64) -> (usize, f64) {
        let f = ((ln_t - self.ln_t0) / self.dln_t).clamp(0.0, (self.rows - 1) as f64);
        let i = (f as usize).min(self.rows - 2);
        (i, f - i as f64)
    }

    /// Row i of B(gT) and the factors on rows i and i + 1, from the rows
    /// of gT and of T: `scale` times the luminance of B(gT) relative to
    /// B(T) (both interpolated like the rows) times `g_factor`.
    #[inline]
    fn weights(
        &self,
        (i, w): (usize, f64),
        (i0, w0): (usize, f64),
        scale: f32,
        g_factor: f64,
    ) -> (usize, f64, f64) {
        let ln_y = |i: usize, w: f64| self.ln_y[i] * (1.0 - w) + self.ln_y[i + 1] * w;
        let rel = (ln_y(i, w) - ln_y(i0, w0)).exp();
        let k = scale as f64 * rel * g_factor;
        (i, k * (1.0 - w), k * w)
    }

    /// The XYZ of what [`PlanckTable::add`] adds over all the wavelengths
    /// (the same sum, taken row by row: equal to rounding), from ln T and
    /// ln g (sky pixels have both at hand: two logarithms fewer).
    #[inline]
    pub fn xyz(&self, ln_kelvin: f64, ln_g: f64, beaming: bool, scale: f32) -> DVec3 {
        let g_factor = if beaming { 1.0 } else { (-5.0 * ln_g).exp() };
        let (i, k0, k1) = self.weights(
            self.row_ln(ln_kelvin + ln_g),
            self.row_ln(ln_kelvin),
            scale,
            g_factor,
        );
        self.xyz[i] * k0 + self.xyz[i + 1] * k1
    }

    /// Adds `scale` times the spectrum seen from a blackbody at `kelvin`
    /// whose light arrives with frequency ratio `g`, scaled so that g = 1
    /// gives luminance `scale`. The camera wavelength lambda sees the
    /// emitter at g lambda: B(g lambda; T) = g^-5 B(lambda; g T); with
    /// `beaming` the g^5 radiance factor cancels that exactly, leaving
    /// B(lambda; g T). Only samples in `range` are written.
    pub fn add(
        &self,
        kelvin: f64,
        g: f64,
        beaming: bool,
        scale: f32,
        range: std::ops::Range<usize>,
        out: &mut [f32],
    ) {
        let g_factor = if beaming { 1.0 } else { g.powi(-5) };
        let (i, k0, k1) = self.weights(self.row(kelvin * g), self.row(kelvin), scale, g_factor);
        let (k0, k1) = (k0 as f32, k1 as f32);
        let (a, b) = (
            &self.values[i * self.n..(i + 1) * self.n],
            &self.values[(i + 1) * self.n..(i + 2) * self.n],
        );
        for j in range {
            out[j] += k0 * a[j] + k1 * b[j];
        }
    }
}

/// Luminance Y of an unscaled blackbody (1 nm CMFs over 380-780 nm).
pub fn luminance(kelvin: f64) -> f64 {
    CIE_1NM.integrate(|l| planck(l, kelvin)).y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eighty_one_samples_are_the_5nm_table() {
        let wl = Wavelengths::new(81);
        assert_eq!(wl.step, 5.0);
        assert_eq!(wl.nm[1], 385.0);
        for (l, w) in wl.nm.iter().zip(&wl.weights) {
            assert_eq!(*w, crate::spectrum::CIE_5NM.at(*l) * 5.0);
        }
    }

    #[test]
    fn table_matches_planck_with_and_without_shift() {
        let wl = Wavelengths::new(81);
        let table = PlanckTable::new(&wl);
        for (t, g) in [(5800.0, 1.0), (3000.0, 1.3), (20000.0, 0.6), (7777.0, 1.0)] {
            for beaming in [false, true] {
                let mut out = vec![0.0f32; 81];
                table.add(t, g, beaming, 1.0, 0..81, &mut out);
                let y = luminance(t);
                for (i, &l) in wl.nm.iter().enumerate() {
                    let exact = planck(g * l, t) / y * if beaming { g.powi(5) } else { 1.0 };
                    let rel = (out[i] as f64 - exact).abs() / exact.max(1e-30);
                    assert!(rel < 2e-5, "T {t} g {g} {l} nm: {} vs {exact}", out[i]);
                }
            }
        }
    }

    #[test]
    fn row_xyz_is_the_xyz_of_the_added_spectrum() {
        for n in [41, 81] {
            let wl = Wavelengths::new(n);
            let table = PlanckTable::new(&wl);
            for (t, g, k) in [(5800.0, 1.0, 1.0), (3000.0, 1.3, 0.25), (4.0e4, 0.6, 7.0)] {
                for beaming in [false, true] {
                    let mut out = vec![0.0f32; n];
                    table.add(t, g, beaming, k, 0..n, &mut out);
                    let (a, b) = (wl.xyz(&out), table.xyz(t.ln(), g.ln(), beaming, k));
                    // The spectrum's values are rounded to f32 one by one.
                    assert!(
                        (a - b).abs().max_element() <= 1e-6 * a.max_element(),
                        "{a} vs {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn unshifted_blackbody_has_luminance_one() {
        let wl = Wavelengths::new(81);
        let table = PlanckTable::new(&wl);
        let mut out = vec![0.0f32; 81];
        table.add(6500.0, 1.0, false, 1.0, 0..81, &mut out);
        assert!((wl.xyz(&out).y - 1.0).abs() < 1e-4);
    }
}
