//! Gold et al. (2020, ApJ 897, 148, section 3): the analytic flow of the
//! Event Horizon Telescope's code comparison. In Boyer-Lindquist
//! coordinates of a hole of mass M = 1:
//!
//! - density n = n0 exp(-[(r/10)^2 + h^2 cos^2 th] / 2);
//! - specific angular momentum l = l0 R^(3/2) / (1 + R), R = r sin th;
//! - four-velocity u_mu = u_bar (-1, 0, 0, l), with
//!   u_bar = [-(g^tt - 2 g^tph l + g^phph l^2)]^(-1/2);
//! - emission j_nu = n (nu / nu_p)^(-alpha) and absorption
//!   alpha_nu = A n (nu / nu_p)^(-(alpha + 5/2)), in cgs, at the frequency
//!   nu the gas measures.

use super::CUTOFF;
use crate::physics::kerr::Kerr;

/// The flow's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gold {
    /// Absorption's scale A.
    pub a_abs: f64,
    /// Spectral index alpha of the emission.
    pub alpha: f64,
    /// Vertical compactness h (0: the density depends on r alone).
    pub h: f64,
    /// Angular momentum's scale l0.
    pub l0: f64,
    /// Density scale n0 (the paper's C n0: j_nu in erg s^-1 cm^-3 Hz^-1
    /// sr^-1 at nu_p).
    pub n0: f64,
    /// The reference frequency nu_p (Hz).
    pub nu_p: f64,
}

crate::wgsl::gpu_block! {
    /// Gold's flow as the GPU reads it (media.wgsl's gold_*): the fields
    /// of [`Gold`].
    GoldBlock {
        a_abs,
        alpha,
        h,
        l0,
        n0,
        nu_p,
    }
}

impl Gold {
    /// Its parameters for the GPU.
    pub fn gpu_block(&self) -> GoldBlock {
        let f = |x: f64| x as f32;
        GoldBlock {
            a_abs: f(self.a_abs),
            alpha: f(self.alpha),
            h: f(self.h),
            l0: f(self.l0),
            n0: f(self.n0),
            nu_p: f(self.nu_p),
        }
    }
}

/// The five tests' (A, alpha, h, l0) and the spin each is defined at.
pub const TESTS: [(f64, f64, f64, f64, f64); 5] = [
    (0.0, -3.0, 0.0, 0.0, 0.9),
    (0.0, -2.0, 0.0, 1.0, 0.0),
    (0.0, 0.0, 10.0 / 3.0, 1.0, 0.9),
    (1e5, 0.0, 10.0 / 3.0, 1.0, 0.9),
    (1e6, 0.0, 100.0 / 3.0, 1.0, 0.9),
];

/// The published total flux densities (Jy) of the five tests (Gold et al.
/// 2020's exact values at their set-up).
pub const TEST_FLUX_JY: [f64; 5] = [1.6465, 1.4360, 0.4418, 0.2710, 0.0255];

/// n0 of the tests (the paper's C n0, cgs).
pub const N0: f64 = 3e-18;

impl Gold {
    /// Test `n` (1 to 5) at frequency `nu_p` (Hz).
    pub fn test(n: usize, nu_p: f64) -> Gold {
        let (a_abs, alpha, h, l0, _) = TESTS[n - 1];
        Gold {
            a_abs,
            alpha,
            h,
            l0,
            n0: N0,
            nu_p,
        }
    }

    /// The density at (r, cos th), M units.
    #[inline]
    pub fn density(&self, r: f64, cos_th: f64) -> f64 {
        let e = 0.5 * ((r / 10.0).powi(2) + (self.h * cos_th).powi(2));
        if e < CUTOFF {
            self.n0 * (-e).exp()
        } else {
            0.0
        }
    }

    /// Beyond this radius (M) the density is below e^-20 of its scale.
    pub fn extent(&self) -> f64 {
        10.0 * (2.0 * CUTOFF).sqrt()
    }

    /// The length (M) over which the coefficients change by about e at
    /// (r, cos th): the density's radial and vertical scales, the flow's
    /// (and so the Doppler shift's) change with r.
    #[inline]
    pub fn scale(&self, r: f64, cos_th: f64) -> f64 {
        let radial = 100.0 / r.max(1.0);
        let sin_th = (1.0 - cos_th * cos_th).max(0.0).sqrt();
        // d/d(r th) of h^2 cos^2 th / 2 is h^2 cos th sin th / r; within
        // 1/h of the plane the Gaussian's own width r/h rules.
        let vertical = r / (self.h * self.h * (cos_th * sin_th).abs() + self.h).max(1e-300);
        // Beyond the layer where the vertical Gaussian is above the
        // cutoff the gas is nil: pieces may reach a fraction of the way
        // to the layer, and are never finer than the layer's own scale
        // at its edge (they would shrink without end towards it).
        let edge = (2.0 * CUTOFF).sqrt() / self.h;
        if self.h * cos_th.abs() > (2.0 * CUTOFF).sqrt() {
            return radial
                .min(0.5 * r)
                .min((r * (cos_th.abs() - edge)).max(vertical));
        }
        radial.min(vertical).min(0.5 * r)
    }

    /// The frequency the gas at (r, th) measures for a photon of unit
    /// energy at infinity and angular momentum `lz` (M units) around the
    /// hole `kerr`: -k.u with k_mu = (-1, k_r, k_th, lz). None where the
    /// flow is not timelike (near the horizon of a spinning hole, where the
    /// prescribed l cannot be kept) or inside the horizon: the gas there
    /// radiates nothing.
    #[inline]
    pub fn frequency_ratio(&self, kerr: Kerr, r: f64, cos_th: f64, lz: f64) -> Option<f64> {
        // (Off the axis by a hair: l / varpi^2 ~ sin^-1/2 there.)
        let sin = (1.0 - cos_th * cos_th).max(1e-300).sqrt();
        let big_r = r * sin;
        let l = self.l0 * big_r * big_r.sqrt() / (1.0 + big_r);
        // The inverse metric through the locally non-rotating frame:
        // g^tt = -1/alpha^2, g^tph = -omega/alpha^2, g^phph = 1/varpi^2 -
        // omega^2/alpha^2; so g^tt - 2 g^tph l + g^phph l^2 = -(1 -
        // omega l)^2 / alpha^2 + l^2 / varpi^2 = -1 / u_bar^2.
        let z = kerr.zamo_at(r, cos_th, sin);
        let (a2, w2) = (z.alpha * z.alpha, z.varpi * z.varpi);
        let drag = 1.0 - z.omega * l;
        let inv = drag * drag / a2 - l * l / w2;
        if !(inv > 0.0) {
            return None;
        }
        let u_bar = inv.sqrt().recip();
        // u^t - lz u^ph, with u^t = u_bar (1 - omega l) / alpha^2 and
        // u^ph = u_bar [omega (1 - omega l) / alpha^2 + l / varpi^2].
        Some(u_bar * (drag * (1.0 - lz * z.omega) / a2 - lz * l / w2))
    }

    /// (j_nu, alpha_nu) in cgs at density `n` and gas-frame frequency `nu`.
    #[inline]
    pub fn coefficients(&self, n: f64, nu: f64) -> (f64, f64) {
        let x = nu / self.nu_p;
        let j = n * x.powf(-self.alpha);
        let k = if self.a_abs == 0.0 {
            0.0
        } else {
            self.a_abs * n * x.powf(-(self.alpha + 2.5))
        };
        (j, k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flow_is_a_unit_timelike_vector() {
        // u^mu u_mu = -1: with u_mu = u_bar (-1, 0, 0, l), u^mu u_mu =
        // u_bar^2 (g^tt - 2 g^tph l + g^phph l^2) = -1 by construction;
        // check instead the photon's frequency for a radial photon at large
        // r, where the flow is slow: -k.u -> 1.
        let g = Gold::test(3, 230e9);
        let f = g.frequency_ratio(Kerr::new(0.9), 1e6, 0.5, 0.0).unwrap();
        assert!((f - 1.0).abs() < 2e-6, "{f}");
        // A static gas (l0 = 0) at spin 0 measures 1 / sqrt(1 - 2/r).
        let s = Gold::test(1, 230e9);
        let f = s.frequency_ratio(Kerr::new(0.0), 8.0, 0.3, 2.0).unwrap();
        assert!((f - 1.0 / (1.0 - 2.0 / 8.0f64).sqrt()).abs() < 1e-14, "{f}");
    }

    #[test]
    fn keplerian_limit_matches_the_circular_orbit_shift() {
        // At spin 0 in the plane, l = l0 R^1.5 / (1 + R) with l0 = 1 is
        // sub-Keplerian; the gas's u^t (1 - Omega lz) form must equal
        // u_bar [(-g^tt + g^tph l) - lz (-g^tph + g^phph l)].
        let g = Gold::test(2, 230e9);
        let r: f64 = 6.0;
        let l = r.powf(1.5) / (1.0 + r);
        // Schwarzschild: g^tt = -1/(1 - 2/r), g^phph = 1/r^2.
        let norm = -1.0 / (1.0 - 2.0 / r) + l * l / (r * r);
        let u_bar = (-1.0 / norm).sqrt();
        let (u_t, u_p) = (u_bar / (1.0 - 2.0 / r), u_bar * l / (r * r));
        for lz in [-4.0, 0.0, 3.0] {
            let f = g.frequency_ratio(Kerr::new(0.0), r, 0.0, lz).unwrap();
            assert!((f - (u_t - lz * u_p)).abs() < 1e-14, "{f}");
        }
    }

    #[test]
    fn coefficients_follow_the_power_laws() {
        let g = Gold::test(4, 230e9);
        let (j, k) = g.coefficients(2.0, 460e9);
        assert_eq!(j, 2.0);
        assert!((k - 1e5 * 2.0 * 2f64.powf(-2.5)).abs() < 1e-9 * k);
        let t1 = Gold::test(1, 230e9);
        let (j, k) = t1.coefficients(1.0, 460e9);
        assert!((j - 8.0).abs() < 1e-12 && k == 0.0);
    }
}
