//! The native coordinates of iharm3d-format dumps: (X1, X2, X3) with r =
//! e^X1 (Boyer-Lindquist's radius, also Kerr-Schild's), X3 = Kerr-Schild
//! azimuth, and theta a function of X2 (and, in FMKS, of X1) that packs
//! cells towards the midplane. Formulae as iharm3d writes them and ipole
//! reads them (`bl_coord`, `set_dxdX`).

use std::f64::consts::PI;

/// How theta follows X2 (and X1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Theta {
    /// Kerr-Schild's own: theta = X2 ("EKS", X1 = ln r).
    Exponential,
    /// "MKS": theta = pi X2 + ((1 - h) / 2) sin 2 pi X2.
    Modified { hslope: f64 },
    /// "BHAC_MKS": theta = X2 + (h / 2) sin 2 X2.
    Bhac { hslope: f64 },
    /// "FMKS" (or "MMKS"): MKS's theta blended into a polynomial that
    /// widens the cells at the poles, the more the nearer to the grid's
    /// inner edge: theta = theta_G + e^(s (x1_0 - X1)) (theta_J - theta_G).
    Funky {
        hslope: f64,
        poly_xt: f64,
        /// An integer (the polynomial is odd in 2 X2 - 1 only then).
        poly_alpha: i32,
        mks_smooth: f64,
        /// The grid's first X1 (its inner edge).
        startx1: f64,
        /// (pi / 2) / (1 + 1 / ((alpha + 1) xt^alpha)).
        poly_norm: f64,
    },
}

impl Theta {
    /// FMKS's parameters, with its normalisation.
    pub fn funky(
        hslope: f64,
        poly_xt: f64,
        poly_alpha: i32,
        mks_smooth: f64,
        startx1: f64,
    ) -> Theta {
        let a = poly_alpha as f64;
        Theta::Funky {
            hslope,
            poly_xt,
            poly_alpha,
            mks_smooth,
            startx1,
            poly_norm: 0.5 * PI / (1.0 + 1.0 / ((a + 1.0) * poly_xt.powi(poly_alpha))),
        }
    }

    /// The range of X2 that spans theta from 0 to pi.
    pub fn x2_span(&self) -> f64 {
        match self {
            Theta::Exponential | Theta::Bhac { .. } => PI,
            Theta::Modified { .. } | Theta::Funky { .. } => 1.0,
        }
    }

    /// theta, d theta / d X1 and d theta / d X2 at (X1, X2).
    #[inline]
    pub fn at(&self, x1: f64, x2: f64) -> (f64, f64, f64) {
        match *self {
            Theta::Exponential => (x2, 0.0, 1.0),
            Theta::Modified { hslope } => {
                let (s, c) = (2.0 * PI * x2).sin_cos();
                (
                    PI * x2 + 0.5 * (1.0 - hslope) * s,
                    0.0,
                    PI * (1.0 + (1.0 - hslope) * c),
                )
            }
            Theta::Bhac { hslope } => {
                let (s, c) = (2.0 * x2).sin_cos();
                (x2 + 0.5 * hslope * s, 0.0, 1.0 + hslope * c)
            }
            Theta::Funky {
                hslope,
                poly_xt,
                poly_alpha,
                mks_smooth,
                startx1,
                poly_norm,
            } => {
                let (s, c) = (2.0 * PI * x2).sin_cos();
                let (th_g, dg) = (
                    PI * x2 + 0.5 * (1.0 - hslope) * s,
                    PI * (1.0 + (1.0 - hslope) * c),
                );
                let y = 2.0 * x2 - 1.0;
                let p = (y / poly_xt).powi(poly_alpha);
                let a = poly_alpha as f64;
                let th_j = poly_norm * y * (1.0 + p / (a + 1.0)) + 0.5 * PI;
                let dj = 2.0 * poly_norm * (1.0 + p);
                let e = (mks_smooth * (startx1 - x1)).exp();
                (
                    th_g + e * (th_j - th_g),
                    -mks_smooth * e * (th_j - th_g),
                    dg + e * (dj - dg),
                )
            }
        }
    }

    /// The X2 of theta `th` at `x1`: Newton's method kept inside a
    /// bracket (theta rises with X2 in every system), to 1e-14.
    pub fn x2_of(&self, x1: f64, th: f64) -> f64 {
        match *self {
            Theta::Exponential => th,
            _ => {
                let (mut lo, mut hi) = (0.0, self.x2_span());
                let mut x = th / PI * hi;
                for _ in 0..60 {
                    let (t, _, d) = self.at(x1, x);
                    let f = t - th;
                    if f > 0.0 {
                        hi = x;
                    } else {
                        lo = x;
                    }
                    let step = f / d;
                    let mut next = x - step;
                    if !(next > lo && next < hi) {
                        next = 0.5 * (lo + hi);
                    }
                    if (next - x).abs() < 1e-15 {
                        return next;
                    }
                    x = next;
                }
                x
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn systems() -> Vec<Theta> {
        vec![
            Theta::Exponential,
            Theta::Modified { hslope: 0.3 },
            Theta::Bhac { hslope: 0.3 },
            Theta::funky(0.3, 0.82, 14, 0.5, 0.2),
        ]
    }

    #[test]
    fn theta_spans_the_sphere_and_turns_back_to_x2() {
        // Every system maps X2's ends to the poles and the middle to the
        // midplane (FMKS at any X1), and the inverse recovers X2.
        for sys in systems() {
            let span = sys.x2_span();
            for x1 in [0.2, 1.0, 3.0] {
                assert!(sys.at(x1, 0.0).0.abs() < 1e-14, "{sys:?}");
                assert!((sys.at(x1, span).0 - PI).abs() < 1e-14, "{sys:?}");
                assert!((sys.at(x1, 0.5 * span).0 - 0.5 * PI).abs() < 1e-14);
                for i in 1..40 {
                    let x2 = span * i as f64 / 40.0;
                    let th = sys.at(x1, x2).0;
                    assert!((sys.x2_of(x1, th) - x2).abs() < 1e-13, "{sys:?} {x2}");
                }
            }
        }
    }

    #[test]
    fn the_derivatives_are_the_slopes() {
        // Against central differences (step 1e-6: error ~1e-11).
        let h = 1e-6;
        for sys in systems() {
            let span = sys.x2_span();
            for (x1, x2) in [(0.5, 0.1 * span), (2.0, 0.37 * span), (1.3, 0.8 * span)] {
                let (_, d1, d2) = sys.at(x1, x2);
                let n1 = (sys.at(x1 + h, x2).0 - sys.at(x1 - h, x2).0) / (2.0 * h);
                let n2 = (sys.at(x1, x2 + h).0 - sys.at(x1, x2 - h).0) / (2.0 * h);
                assert!((d1 - n1).abs() < 1e-8, "{sys:?} d1 {d1} {n1}");
                assert!((d2 - n2).abs() < 1e-8, "{sys:?} d2 {d2} {n2}");
            }
        }
    }
}
