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

/// MKS's theta = pi X2 + ((1 - h) / 2) sin 2 pi X2 and its slope.
#[inline]
fn modified(hslope: f64, x2: f64) -> (f64, f64) {
    let (s, c) = (2.0 * PI * x2).sin_cos();
    (
        PI * x2 + 0.5 * (1.0 - hslope) * s,
        PI * (1.0 + (1.0 - hslope) * c),
    )
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

    /// theta at X2 as FMKS blends it, (theta_G, theta_J - theta_G): theta
    /// = the first + [`Theta::weight`] at X1 times the second, as
    /// [`Theta::at`] has it (the other systems: (theta, 0)).
    pub fn parts(&self, x2: f64) -> (f64, f64) {
        match *self {
            Theta::Funky { .. } => {
                let (g, _, _) = self.at(f64::INFINITY, x2);
                let (j, _, _) = self.at(self.start_x1(), x2);
                (g, j - g)
            }
            _ => (self.at(0.0, x2).0, 0.0),
        }
    }

    /// The weight of [`Theta::parts`]' second at X1: FMKS's e^(s (x1_0 -
    /// X1)), falling as X1 rises; 0 for the others.
    pub fn weight(&self, x1: f64) -> f64 {
        match *self {
            Theta::Funky {
                mks_smooth,
                startx1,
                ..
            } => (mks_smooth * (startx1 - x1)).exp(),
            _ => 0.0,
        }
    }

    /// FMKS's first X1 (0 for the others).
    fn start_x1(&self) -> f64 {
        match *self {
            Theta::Funky { startx1, .. } => startx1,
            _ => 0.0,
        }
    }

    /// theta, d theta / d X1 and d theta / d X2 at (X1, X2).
    #[inline]
    pub fn at(&self, x1: f64, x2: f64) -> (f64, f64, f64) {
        match *self {
            Theta::Exponential => (x2, 0.0, 1.0),
            Theta::Modified { hslope } => {
                let (th, d) = modified(hslope, x2);
                (th, 0.0, d)
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
                let (th_g, dg) = modified(hslope, x2);
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

/// theta's inverse by table: X2 at evenly spaced theta (and, for FMKS,
/// X1), each lookup polished by Newton's method to the exact root.
#[derive(Clone, Debug)]
pub struct Inverse {
    pub theta: Theta,
    /// X1 of the table's first row, its step and rows (one row unless
    /// theta depends on X1).
    x1: (f64, f64, usize),
    /// X2 at theta = i pi / (THETAS - 1), row by row.
    x2: Vec<f64>,
    /// d X2 / d theta there, times the table's step in theta: the guess
    /// between two points is the cubic through both values and slopes
    /// (within about 1e-13 of X2 on MKS, so that one Newton step finds
    /// it to round-off).
    slopes: Vec<f64>,
}

/// Points of theta in each row of an [`Inverse`].
pub const THETAS: usize = 2049;

impl Inverse {
    /// The table for `theta` over X1 from `x1_lo` to `x1_hi`.
    pub fn new(theta: Theta, (x1_lo, x1_hi): (f64, f64)) -> Inverse {
        let rows = if matches!(theta, Theta::Funky { .. }) {
            65
        } else {
            1
        };
        let step = if rows > 1 {
            (x1_hi - x1_lo) / (rows - 1) as f64
        } else {
            0.0
        };
        let mut x2 = Vec::with_capacity(rows * THETAS);
        let mut slopes = Vec::with_capacity(rows * THETAS);
        let h = PI / (THETAS - 1) as f64;
        for row in 0..rows {
            let x1 = x1_lo + row as f64 * step;
            for i in 0..THETAS {
                let x = theta.x2_of(x1, h * i as f64);
                x2.push(x);
                slopes.push(h / theta.at(x1, x).2);
            }
        }
        Inverse {
            theta,
            x1: (x1_lo, step, rows),
            x2,
            slopes,
        }
    }

    /// The table: (X1 of its first row, its step, its rows) and X2 at
    /// theta = i pi / (THETAS - 1), row by row.
    pub fn table(&self) -> ((f64, f64, usize), &[f64]) {
        (self.x1, &self.x2)
    }

    /// d theta / d X2 at theta `th` and `x1` as the table has it (to its
    /// accuracy, about 1e-6: enough for the pieces' scale).
    #[inline]
    pub fn slope(&self, x1: f64, th: f64) -> f64 {
        let (x1_lo, step, rows) = self.x1;
        let row = (((x1 - x1_lo) / step).round().max(0.0) as usize).min(rows - 1);
        let u = (th / PI * (THETAS - 1) as f64).clamp(0.0, (THETAS - 1) as f64 - 1e-9);
        let (i, r) = (u as usize, &self.x2[row * THETAS..]);
        PI / ((THETAS - 1) as f64 * (r[i + 1] - r[i]))
    }

    /// X2 of theta `th` at `x1`, with d theta / d X1 and d theta / d X2
    /// there: the table's guess, then Newton's steps until they no longer
    /// move it (one on MKS, two on FMKS, whose rows in X1 are linear).
    #[inline]
    pub fn x2(&self, x1: f64, th: f64) -> (f64, f64, f64) {
        let (x1_lo, step, rows) = self.x1;
        let u = (th / PI * (THETAS - 1) as f64).clamp(0.0, (THETAS - 1) as f64 - 1e-9);
        let i = u as usize;
        let f = u - i as f64;
        let (f2, f3) = (f * f, f * f * f);
        let at = |row: usize| {
            let (r, d) = (
                &self.x2[row * THETAS + i..],
                &self.slopes[row * THETAS + i..],
            );
            r[0] * (2.0 * f3 - 3.0 * f2 + 1.0)
                + r[1] * (3.0 * f2 - 2.0 * f3)
                + d[0] * (f3 - 2.0 * f2 + f)
                + d[1] * (f3 - f2)
        };
        let mut x = if rows == 1 {
            at(0)
        } else {
            let v = ((x1 - x1_lo) / step).clamp(0.0, (rows - 1) as f64 - 1e-9);
            let row = v as usize;
            let f = v - row as f64;
            at(row) + f * (at(row + 1) - at(row))
        };
        let (mut d1, mut d2) = (0.0, 1.0);
        for _ in 0..4 {
            let (t, a, b) = self.theta.at(x1, x);
            (d1, d2) = (a, b);
            let dx = (t - th) / b;
            x -= dx;
            if dx.abs() < 1e-13 {
                break;
            }
        }
        (x, d1, d2)
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
    fn the_table_finds_the_exact_inverse() {
        // Within 1e-13 of the bracketed root everywhere, the derivatives
        // those at the root.
        for sys in systems() {
            let inv = Inverse::new(sys, (0.1, 4.0));
            for x1 in [0.1, 0.77, 2.5, 4.0] {
                for i in 0..=300 {
                    let th = PI * i as f64 / 300.0;
                    let (x2, d1, d2) = inv.x2(x1, th);
                    let want = sys.x2_of(x1, th);
                    assert!((x2 - want).abs() < 1e-13, "{sys:?} {x1} {th}: {x2} {want}");
                    let (_, w1, w2) = sys.at(x1, want);
                    assert!((d1 - w1).abs() < 1e-10 && (d2 - w2).abs() < 1e-10);
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
