//! Thermal synchrotron emission and absorption, in cgs.
//!
//! Electrons in a relativistic Maxwell-Juttner distribution of
//! dimensionless temperature Theta_e = k T_e / (m_e c^2), density n_e, in
//! a field B. Leung, Gammie and Noble 2011 (ApJ 737, 21, eq. 31) fit the
//! emissivity at pitch angle th between the ray and the field:
//!
//! j_nu = n_e sqrt(2) pi e^2 nu_s / (3 K_2(1/Theta_e) c)
//!        (X^1/2 + 2^(11/12) X^1/6)^2 exp(-X^1/3),
//!
//! X = nu / nu_s, nu_s = (2/9) nu_c Theta_e^2 sin th, nu_c = e B / (2 pi
//! m_e c). A tangled field has every pitch angle: [`emissivity`] averages
//! the fit over the sphere, j = (1/2) int j_nu(th) sin th dth, through a
//! table of that average (its shape depends on nu / nu_s alone). The gas
//! absorbs as Kirchhoff's law says of a thermal emitter, alpha_nu = j_nu /
//! B_nu(T_e).

use crate::spectrum::planck_nu as planck;
use crate::units::cgs::{BOLTZMANN, ELECTRON_CHARGE, ELECTRON_MASS, LIGHT};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Below this Theta_e (T_e ~ 1.2e7 K) the electrons emit nothing at any
/// frequency the fit applies to: K_2(1/Theta_e) ~ e^-500 would underflow.
pub const COLDEST: f64 = 2e-3;

/// Theta_e = k T / (m_e c^2) of a temperature (K).
pub fn theta_e(kelvin: f64) -> f64 {
    BOLTZMANN * kelvin / (ELECTRON_MASS * LIGHT * LIGHT)
}

/// The cyclotron frequency nu_c = e B / (2 pi m_e c) (Hz) of a field (G).
pub fn cyclotron(field: f64) -> f64 {
    ELECTRON_CHARGE * field / (2.0 * PI * ELECTRON_MASS * LIGHT)
}

/// The fit's shape (X^1/2 + 2^(11/12) X^1/6)^2 exp(-X^1/3).
#[inline]
pub fn shape(x: f64) -> f64 {
    let c = x.cbrt();
    let s = x.sqrt() + 2f64.powf(11.0 / 12.0) * c.sqrt();
    s * s * (-c).exp()
}

/// Leung et al. 2011's j_nu (cgs) at pitch angle th (`sin_th` its sine)
/// between the ray and the field.
pub fn pitch_emissivity(n: f64, theta: f64, field: f64, nu: f64, sin_th: f64) -> f64 {
    if theta < COLDEST || sin_th <= 0.0 {
        return 0.0;
    }
    let nu_s = 2.0 / 9.0 * cyclotron(field) * theta * theta * sin_th;
    prefactor(n, theta) * nu_s * shape(nu / nu_s)
}

/// n_e sqrt(2) pi e^2 / (3 K_2(1/Theta_e) c).
#[inline]
fn prefactor(n: f64, theta: f64) -> f64 {
    n * 2f64.sqrt() * PI * ELECTRON_CHARGE * ELECTRON_CHARGE
        / (3.0 * bessel_k2(1.0 / theta) * LIGHT)
}

/// Thermal electrons of one density, temperature and field: what their
/// coefficients at every frequency share (K_2 and nu_s0), found once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thermal {
    /// prefactor nu_s0: j_nu = norm G(nu / nu_s0).
    norm: f64,
    /// (2/9) nu_c Theta_e^2 (Hz).
    nu_s0: f64,
    /// T_e (K), for Kirchhoff's law.
    kelvin: f64,
}

impl Thermal {
    /// Electrons of density `n` (cm^-3) at `kelvin` in a tangled field of
    /// strength `field` (G); None where they emit nothing.
    #[inline]
    pub fn new(n: f64, kelvin: f64, field: f64) -> Option<Thermal> {
        let theta = theta_e(kelvin);
        if theta < COLDEST || n <= 0.0 || field <= 0.0 {
            return None;
        }
        let nu_s0 = 2.0 / 9.0 * cyclotron(field) * theta * theta;
        Some(Thermal {
            norm: prefactor(n, theta) * nu_s0,
            nu_s0,
            kelvin,
        })
    }

    /// The angle-averaged emissivity j_nu (erg s^-1 cm^-3 Hz^-1 sr^-1) at
    /// frequency `nu` (Hz).
    #[inline]
    pub fn emissivity(&self, nu: f64) -> f64 {
        self.norm * Average::get().at(nu / self.nu_s0)
    }

    /// (j_nu, alpha_nu), absorption by Kirchhoff's law.
    #[inline]
    pub fn coefficients(&self, nu: f64) -> (f64, f64) {
        let j = self.emissivity(nu);
        if j == 0.0 {
            return (0.0, 0.0);
        }
        (j, j / planck(nu, self.kelvin))
    }
}

/// Thermal electrons seen at one pitch angle to an ordered field (the
/// GRMHD dumps' b^mu): Leung et al.'s fit at that angle, as ipole's
/// unpolarised pass evaluates it, absorbed by Kirchhoff's law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pitched {
    /// prefactor nu_s: j_nu = norm shape(nu / nu_s).
    norm: f64,
    /// (2/9) nu_c Theta_e^2 sin th (Hz).
    nu_s: f64,
    kelvin: f64,
}

impl Pitched {
    /// Electrons of density `n` (cm^-3) at `theta` (Theta_e) in a field of
    /// `field` (G) at pitch angle th (`sin_th`); None where they emit
    /// nothing.
    #[inline]
    pub fn new(n: f64, theta: f64, field: f64, sin_th: f64) -> Option<Pitched> {
        if theta < COLDEST || n <= 0.0 || field <= 0.0 || sin_th <= 0.0 {
            return None;
        }
        let nu_s = 2.0 / 9.0 * cyclotron(field) * theta * theta * sin_th;
        Some(Pitched {
            norm: prefactor(n, theta) * nu_s,
            nu_s,
            kelvin: theta * ELECTRON_MASS * LIGHT * LIGHT / BOLTZMANN,
        })
    }

    /// (j_nu, alpha_nu) at `nu` (Hz); nothing above 10^12 nu_s, where the
    /// fit's exponential is below e^-10^4 (ipole's cut).
    #[inline]
    pub fn coefficients(&self, nu: f64) -> (f64, f64) {
        let x = nu / self.nu_s;
        if x > 1e12 {
            return (0.0, 0.0);
        }
        let j = self.norm * shape(x);
        if j == 0.0 {
            return (0.0, 0.0);
        }
        (j, j / planck(nu, self.kelvin))
    }
}

/// The angle-averaged thermal synchrotron emissivity j_nu (erg s^-1
/// cm^-3 Hz^-1 sr^-1) of electrons of density `n` (cm^-3) at Theta_e
/// `theta` in a tangled field of strength `field` (G), at frequency `nu`
/// (Hz).
pub fn emissivity(n: f64, theta: f64, field: f64, nu: f64) -> f64 {
    let kelvin = theta * ELECTRON_MASS * LIGHT * LIGHT / BOLTZMANN;
    Thermal::new(n, kelvin, field).map_or(0.0, |t| t.emissivity(nu))
}

/// (j_nu, alpha_nu) of thermal synchrotron, absorption by Kirchhoff's law.
pub fn coefficients(n: f64, kelvin: f64, field: f64, nu: f64) -> (f64, f64) {
    Thermal::new(n, kelvin, field).map_or((0.0, 0.0), |t| t.coefficients(nu))
}

/// The pitch-angle average's table as the GPU reads it: ln G + y^1/3 at
/// [`AVERAGE_POINTS`] points of ln y evenly over [`AVERAGE_RANGE`].
pub fn average_table() -> &'static [f64] {
    &Average::get().ln_g
}

/// Points of [`average_table`], and the range of y = nu / nu_s0 they
/// span.
pub const AVERAGE_POINTS: usize = TABLE;
pub const AVERAGE_RANGE: (f64, f64) = (Y_LOW, Y_HIGH);

/// G(y) = int_0^(pi/2) sin^2 th shape(y / sin th) dth, so that the
/// average over pitch angles of the fit is prefactor nu_s0 G(nu / nu_s0),
/// nu_s0 = (2/9) nu_c Theta_e^2: ln G + y^1/3 on a grid of ln y (the
/// fit's exponential taken out, what is left is nearly straight).
struct Average {
    ln_g: Vec<f64>,
}

/// The table's range of y = nu / nu_s0: below it G ~ y^1/3 (the fit's
/// small-X law), above it G < e^-580, nil.
const Y_LOW: f64 = 1e-8;
const Y_HIGH: f64 = 2e8;
const TABLE: usize = 2048;

impl Average {
    fn get() -> &'static Average {
        static TABLE_ONCE: OnceLock<Average> = OnceLock::new();
        TABLE_ONCE.get_or_init(|| {
            let (lo, hi) = (Y_LOW.ln(), Y_HIGH.ln());
            let ln_g = (0..TABLE)
                .map(|i| {
                    let y = (lo + (hi - lo) * i as f64 / (TABLE - 1) as f64).exp();
                    average_shape(y, 400).ln() + y.cbrt()
                })
                .collect();
            Average { ln_g }
        })
    }

    /// G(y), linear in (ln y, ln G) between the table's points.
    #[inline]
    fn at(&self, y: f64) -> f64 {
        let (lo, hi) = (Y_LOW.ln(), Y_HIGH.ln());
        let step = (hi - lo) / (TABLE - 1) as f64;
        let u = (y.ln() - lo) / step;
        if u < 0.0 {
            return (self.ln_g[0] - Y_LOW.cbrt() + u * step / 3.0).exp();
        }
        if !(u < (TABLE - 1) as f64) {
            return 0.0;
        }
        let i = u as usize;
        let f = u - i as f64;
        (self.ln_g[i] + f * (self.ln_g[i + 1] - self.ln_g[i]) - y.cbrt()).exp()
    }
}

/// G(y) by Simpson's rule on `intervals` (even) pieces of [0, pi/2].
fn average_shape(y: f64, intervals: usize) -> f64 {
    let h = 0.5 * PI / intervals as f64;
    let f = |i: usize| {
        let s = (i as f64 * h).sin();
        if s <= 0.0 { 0.0 } else { s * s * shape(y / s) }
    };
    let mut sum = f(0) + f(intervals);
    for i in 1..intervals {
        sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i);
    }
    sum * h / 3.0
}

/// K_2(x) = K_0(x) + (2 / x) K_1(x), with K_0 and K_1 from Abramowitz and
/// Stegun's polynomial approximations 9.8.1-9.8.8 (relative error below
/// 3e-7).
pub fn bessel_k2(x: f64) -> f64 {
    let (k0, k1) = bessel_k01(x);
    k0 + 2.0 / x * k1
}

/// (K_0(x), K_1(x)) for x > 0.
fn bessel_k01(x: f64) -> (f64, f64) {
    let poly = |t: f64, c: &[f64]| c.iter().rev().fold(0.0, |acc, &k| acc * t + k);
    if x <= 2.0 {
        let t = (x / 3.75).powi(2);
        let i0 = poly(
            t,
            &[
                1.0,
                3.515_622_9,
                3.089_942_4,
                1.206_749_2,
                0.265_973_2,
                0.036_076_8,
                0.004_581_3,
            ],
        );
        let i1 = x * poly(
            t,
            &[
                0.5,
                0.878_905_94,
                0.514_988_69,
                0.150_849_34,
                0.026_587_33,
                0.003_015_32,
                0.000_324_11,
            ],
        );
        let q = (0.5 * x).powi(2);
        let ln = (0.5 * x).ln();
        let k0 = -ln * i0
            + poly(
                q,
                &[
                    -0.577_215_66,
                    0.422_784_20,
                    0.230_697_56,
                    0.034_885_90,
                    0.002_626_98,
                    0.000_107_50,
                    0.000_007_40,
                ],
            );
        let k1 = (x * ln * i1
            + poly(
                q,
                &[
                    1.0,
                    0.154_431_44,
                    -0.672_785_79,
                    -0.181_568_97,
                    -0.019_194_02,
                    -0.001_104_04,
                    -0.000_046_86,
                ],
            ))
            / x;
        (k0, k1)
    } else {
        let t = 2.0 / x;
        let scale = (-x).exp() / x.sqrt();
        let k0 = poly(
            t,
            &[
                1.253_314_14,
                -0.078_323_58,
                0.021_895_68,
                -0.010_624_46,
                0.005_878_72,
                -0.002_515_40,
                0.000_532_08,
            ],
        );
        let k1 = poly(
            t,
            &[
                1.253_314_14,
                0.234_986_19,
                -0.036_556_20,
                0.015_042_68,
                -0.007_803_53,
                0.003_256_14,
                -0.000_682_45,
            ],
        );
        (k0 * scale, k1 * scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// int_0^inf e^(-x cosh t) f(t) dt by the trapezoid rule, which
    /// converges geometrically for such integrands.
    fn laplace_cosh(x: f64, f: impl Fn(f64) -> f64) -> f64 {
        let h: f64 = 0.005;
        let mut sum = 0.5 * f(0.0) * (-x).exp();
        let mut t = h;
        loop {
            let v = (-x * t.cosh()).exp() * f(t);
            sum += v;
            if x * t.cosh() > 60.0 + t && v.abs() < 1e-30 * sum.abs() + 1e-300 {
                break;
            }
            t += h;
        }
        sum * h
    }

    #[test]
    fn bessel_k2_matches_its_integral_form() {
        // K_2(x) = int_0^inf e^(-x cosh t) cosh 2t dt.
        for x in [0.01, 0.1, 0.5, 1.0, 1.9, 2.1, 5.0, 20.0, 100.0] {
            let want = laplace_cosh(x, |t| (2.0 * t).cosh());
            let got = bessel_k2(x);
            assert!(
                ((got - want) / want).abs() < 3e-7,
                "K2({x}): {got} vs {want}"
            );
        }
    }

    /// F(x) = x int_x^inf K_5/3: the synchrotron spectrum of one electron,
    /// as x int_0^inf cosh(5t/3) / cosh t e^(-x cosh t) dt.
    fn synchrotron_function(x: f64) -> f64 {
        x * laplace_cosh(x, |t| (5.0 * t / 3.0).cosh() / t.cosh())
    }

    /// The thermal emissivity at pitch angle th of ultra-relativistic
    /// electrons: one electron's power per unit frequency (Rybicki and
    /// Lightman 6.18), sqrt(3) e^3 B sin th / (m c^2) F(nu / nu_cr) with
    /// nu_cr = (3/2) gamma^2 nu_c sin th, over 4 pi steradians for an
    /// isotropic distribution, integrated over the Maxwell-Juttner
    /// distribution by Simpson's rule in ln gamma.
    fn ultra_relativistic(n: f64, theta: f64, field: f64, nu: f64, sin_th: f64) -> f64 {
        let e = ELECTRON_CHARGE;
        let nu_c = cyclotron(field);
        let k2 = laplace_cosh(1.0 / theta, |t| (2.0 * t).cosh());
        let density =
            |g: f64| n * g * g * (1.0 - 1.0 / (g * g)).sqrt() * (-g / theta).exp() / (theta * k2);
        let (lo, hi) = (0.0f64, (200.0 * theta).ln());
        let m = 600;
        let h = (hi - lo) / m as f64;
        let f = |i: usize| {
            let g = (lo + h * i as f64).exp();
            if g <= 1.0 {
                return 0.0;
            }
            let nu_cr = 1.5 * nu_c * g * g * sin_th;
            g * density(g) * synchrotron_function(nu / nu_cr)
        };
        let mut sum = f(0) + f(m);
        for i in 1..m {
            sum += if i % 2 == 1 { 4.0 } else { 2.0 } * f(i);
        }
        let integral = sum * h / 3.0;
        3f64.sqrt() * e * e * e * field * sin_th / (4.0 * PI * ELECTRON_MASS * LIGHT * LIGHT)
            * integral
    }

    #[test]
    fn the_fit_follows_the_ultra_relativistic_emissivity() {
        // Leung et al. fit the exact (harmonic) emissivity; where the
        // electrons are ultra-relativistic that is the integral of one
        // electron's synchrotron spectrum over the distribution. The fit
        // lies 0.3% (X = 1e4) to 2.3% (X = 1) above it at Theta_e = 10
        // and 30, and up to 5.3% at Theta_e = 3 (X = 1), where the
        // electrons' lower energies make the ultra-relativistic form the
        // poorer one.
        let field = 10.0;
        for (theta, tol_low, tol_high) in [(3.0, 0.06, 0.01), (10.0, 0.03, 0.008)] {
            for (x, sin_th) in [
                (1.0, 1.0),
                (10.0, 0.5),
                (100.0, 1.0),
                (1e3, 0.7),
                (1e4, 1.0),
            ] {
                let nu = x * 2.0 / 9.0 * cyclotron(field) * theta * theta * sin_th;
                let fit = pitch_emissivity(1.0, theta, field, nu, sin_th);
                let exact = ultra_relativistic(1.0, theta, field, nu, sin_th);
                let tol = if x >= 1e3 { tol_high } else { tol_low };
                let d = fit / exact - 1.0;
                assert!(
                    (0.0..tol).contains(&d),
                    "Theta {theta}, X {x}: fit {fit:e}, integral {exact:e} ({d:+.4})"
                );
            }
        }
    }

    #[test]
    fn the_average_is_the_fit_averaged_over_pitch_angles() {
        // (1/2) int_0^pi j(th) sin th dth by a finer rule than the table's,
        // between and on the table's points.
        let (theta, field) = (8.0, 30.0);
        let nu_s0 = 2.0 / 9.0 * cyclotron(field) * theta * theta;
        for y in [1e-9, 1e-3, 0.37, 1.0, 12.5, 300.0, 7e3, 1e5, 1e7] {
            let nu = y * nu_s0;
            let m = 4000;
            let h = PI / m as f64;
            let mut sum = 0.0;
            for i in 0..m {
                let th = (i as f64 + 0.5) * h;
                sum += pitch_emissivity(2.0, theta, field, nu, th.sin()) * th.sin();
            }
            let want = 0.5 * sum * h;
            let got = emissivity(2.0, theta, field, nu);
            assert!(
                ((got - want) / want).abs() < 1e-4,
                "y {y}: {got:e} vs {want:e}"
            );
        }
    }

    #[test]
    fn kirchhoff_gives_the_planck_function_as_source() {
        let (n, t, b) = (1e6, 5e10, 20.0);
        for nu in [1e9, 230e9, 1e13] {
            let (j, a) = coefficients(n, t, b, nu);
            assert!((j / a / planck(nu, t) - 1.0).abs() < 1e-12);
        }
        // Rayleigh-Jeans at radio frequencies: 2 nu^2 k T / c^2.
        let rj = 2.0 * 230e9f64.powi(2) * BOLTZMANN * 5e10 / (LIGHT * LIGHT);
        assert!((planck(230e9, 5e10) / rj - 1.0).abs() < 1e-6);
        // Cold gas emits nothing (and so absorbs nothing).
        assert_eq!(coefficients(n, 1e6, b, 230e9), (0.0, 0.0));
    }
}
