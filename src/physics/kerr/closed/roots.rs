//! The radial potential's four roots (Gralla and Lupsasca's cases),
//! polished by Newton's method, and their rates: a root r_i of R moves
//! with lambda and eta by -(dR/dp)(r_i) / R'(r_i).

use crate::physics::dual::Real;

/// The four roots of the radial potential, r1 + r2 + r3 + r4 = 0, each as
/// (real part, imaginary part); real roots are ordered, and a complex pair
/// is conjugate (negative imaginary part first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialRoots<T = f64> {
    pub re: [T; 4],
    pub im: [T; 4],
}

/// How the radial roots lie (Gralla and Lupsasca's four cases).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RootCase {
    /// Four real roots, r4 outside the outer horizon: the photon outside
    /// turns at r4 (or, below r3, lives inside).
    OuterTurning,
    /// Four real roots, all inside the outer horizon: the photon crosses
    /// it.
    InnerReal,
    /// r1 < r2 real (inside the horizon), r3 and r4 a complex pair.
    OnePair,
    /// Two complex pairs (vortical rays, eta < 0).
    TwoPairs,
}

impl<T: Real> RadialRoots<T> {
    /// The roots of R for spin `a`, lambda and eta ([`RadialRoots::solve`])
    /// with their rates where `T` carries them.
    pub fn new(a: f64, lambda: T, eta: T) -> RadialRoots<T> {
        let v = RadialRoots::solve(a, lambda.re(), eta.re());
        let mut roots = RadialRoots {
            re: v.re.map(T::c),
            im: v.im.map(T::c),
        };
        if !T::RATED {
            return roots;
        }
        let (l, e) = (lambda.re(), eta.re());
        let big_a = a * a - e - l * l;
        let big_b = 2.0 * (e + (l - a) * (l - a));
        let mul = |(p, q): (f64, f64), (r, s): (f64, f64)| (p * r - q * s, p * s + q * r);
        for i in 0..4 {
            let z = (v.re[i], v.im[i]);
            let z2 = mul(z, z);
            let z3 = mul(z2, z);
            // dR/dlambda = -2 lambda r^2 + 4 (lambda - a) r, dR/deta = -r^2
            // + 2 r - a^2, R' = 4 r^3 + 2 A r + B.
            let r_l = (
                -2.0 * l * z2.0 + 4.0 * (l - a) * z.0,
                -2.0 * l * z2.1 + 4.0 * (l - a) * z.1,
            );
            let r_e = (-z2.0 + 2.0 * z.0 - a * a, -z2.1 + 2.0 * z.1);
            let slope = (
                4.0 * z3.0 + 2.0 * big_a * z.0 + big_b,
                4.0 * z3.1 + 2.0 * big_a * z.1,
            );
            let inv = 1.0 / (slope.0 * slope.0 + slope.1 * slope.1);
            let over = |w: (f64, f64)| mul(w, (-slope.0 * inv, slope.1 * inv));
            let (dl, de) = (over(r_l), over(r_e));
            let rate = |k: usize| {
                let (x, y) = (lambda.rates()[k], eta.rates()[k]);
                (dl.0 * x + de.0 * y, dl.1 * x + de.1 * y)
            };
            let (d0, d1) = (rate(0), rate(1));
            roots.re[i] = T::with(v.re[i], [d0.0, d1.0]);
            // A real root stays real.
            if v.im[i] != 0.0 {
                roots.im[i] = T::with(v.im[i], [d0.1, d1.1]);
            }
        }
        roots
    }

    /// Which of the four cases these roots are, for the outer horizon
    /// `r_plus`.
    pub fn case(&self, r_plus: f64) -> RootCase {
        match (self.im[0].re() == 0.0, self.im[2].re() == 0.0) {
            (true, true) if self.re[3].re() > r_plus => RootCase::OuterTurning,
            (true, true) => RootCase::InnerReal,
            (true, false) => RootCase::OnePair,
            _ => RootCase::TwoPairs,
        }
    }
}

impl RadialRoots {
    /// The roots of R for spin `a`, lambda and eta (Gralla and Lupsasca,
    /// eqs. 95-98): with P = -A^2/12 - C, Q = -A/3 ((A/6)^2 - C) - B^2/8
    /// the resolvent's cube roots omega_+- = (-Q/2 +- sqrt((P/3)^3 +
    /// (Q/2)^2))^(1/3) (principal branches, a conjugate pair where the
    /// root is imaginary), z = sqrt((omega_+ + omega_-)/2 - A/6), and
    /// r_{1,2} = -z -+ sqrt(-A/2 - z^2 + B/(4z)),
    /// r_{3,4} = z -+ sqrt(-A/2 - z^2 - B/(4z)).
    fn solve(a: f64, lambda: f64, eta: f64) -> RadialRoots {
        let big_a = a * a - eta - lambda * lambda;
        let big_b = 2.0 * (eta + (lambda - a) * (lambda - a));
        let big_c = -a * a * eta;
        let p = -big_a * big_a / 12.0 - big_c;
        let q = -big_a / 3.0 * ((big_a / 6.0).powi(2) - big_c) - big_b * big_b / 8.0;
        let d = (p / 3.0).powi(3) + (q / 2.0).powi(2);
        // omega_+ + omega_-: real cube roots, or twice the real part of
        // a conjugate pair's principal cube root.
        let sum = if d >= 0.0 {
            // The larger cube root without cancellation, the other from
            // their product omega_+ omega_- = -P/3.
            let u = -0.5 * q + d.sqrt().copysign(-q);
            let w = u.cbrt();
            if w != 0.0 { w - p / (3.0 * w) } else { 0.0 }
        } else {
            // |omega_+-|^3 = sqrt(-(P/3)^3): |omega| = sqrt(-P/3) (P < 0
            // here).
            let theta = (-d).sqrt().atan2(-0.5 * q);
            2.0 * (-p / 3.0).sqrt() * (theta / 3.0).cos()
        };
        let z = (0.5 * sum - big_a / 6.0).max(0.0).sqrt();
        // Each pair: centre -+ z, half-separation sqrt(s), real or
        // imaginary.
        let pair = |centre: f64, s: f64| -> ([f64; 2], [f64; 2]) {
            if s >= 0.0 {
                ([centre - s.sqrt(), centre + s.sqrt()], [0.0; 2])
            } else {
                ([centre; 2], [-(-s).sqrt(), (-s).sqrt()])
            }
        };
        let base = -0.5 * big_a - z * z;
        let bz = if z > 0.0 { big_b / (4.0 * z) } else { 0.0 };
        let (re12, im12) = pair(-z, base + bz);
        let (re34, im34) = pair(z, base - bz);
        let mut roots = RadialRoots {
            re: [re12[0], re12[1], re34[0], re34[1]],
            im: [im12[0], im12[1], im34[0], im34[1]],
        };
        // Newton's method on R itself: z carries the resolvent's rounding
        // (and where it is small, B / 4z magnifies it). Near a double root
        // it converges only linearly, so it runs while the residual falls
        // (at most 12 steps); a complex pair stays conjugate.
        let coef = (big_a, big_b, big_c);
        for i in [0, 1, 2, 3] {
            if roots.im[i] > 0.0 {
                continue;
            }
            let (x, y) = if roots.im[i] == 0.0 {
                (polish_real(coef, roots.re[i]), 0.0)
            } else {
                polish_complex(coef, (roots.re[i], roots.im[i]))
            };
            roots.re[i] = x;
            roots.im[i] = y;
            if i % 2 == 0 && roots.im[i] < 0.0 {
                roots.re[i + 1] = x;
                roots.im[i + 1] = -y;
            }
        }
        roots
    }
}

/// Newton's method on R = r^4 + A r^2 + B r + C from the real root
/// estimate `x`, while |R| falls (at most 12 steps).
fn polish_real((a, b, c): (f64, f64, f64), x: f64) -> f64 {
    let at = |x: f64| {
        let x2 = x * x;
        ((x2 + a) * x + b) * x + c
    };
    let slope = |x: f64| (4.0 * x * x + 2.0 * a) * x + b;
    let (mut x, mut f) = (x, at(x));
    for _ in 0..12 {
        let step = f / slope(x);
        let nx = x - step;
        // Newton converges quadratically off a double root: after a step
        // below 1e-9 of the root the next would be below rounding.
        if step.abs() < 1e-9 * x.abs() {
            return nx;
        }
        let nf = at(nx);
        if !(nf.abs() < f.abs()) {
            break;
        }
        (x, f) = (nx, nf);
    }
    x
}

/// Newton's method on R from the complex root estimate `z`, while |R|
/// falls (at most 12 steps).
fn polish_complex(coef: (f64, f64, f64), (x, y): (f64, f64)) -> (f64, f64) {
    let (mut x, mut y) = (x, y);
    let (mut f, mut df) = potential_and_slope(coef, (x, y));
    for _ in 0..12 {
        let den = df.0 * df.0 + df.1 * df.1;
        if !(den > 0.0) {
            break;
        }
        let (sx, sy) = (
            (f.0 * df.0 + f.1 * df.1) / den,
            (f.1 * df.0 - f.0 * df.1) / den,
        );
        let (nx, ny) = (x - sx, y - sy);
        // As polish_real: a step below 1e-9 of the root is the last.
        if sx.hypot(sy) < 1e-9 * x.hypot(y) {
            return (nx, ny);
        }
        let (nf, ndf) = potential_and_slope(coef, (nx, ny));
        if !(nf.0 * nf.0 + nf.1 * nf.1 < f.0 * f.0 + f.1 * f.1) {
            break;
        }
        (x, y, f, df) = (nx, ny, nf, ndf);
    }
    (x, y)
}

/// R = r^4 + A r^2 + B r + C and dR/dr at the complex point (x, y), as
/// (real, imaginary) pairs.
fn potential_and_slope((a, b, c): (f64, f64, f64), (x, y): (f64, f64)) -> ((f64, f64), (f64, f64)) {
    let mul = |(p, q): (f64, f64), (r, s): (f64, f64)| (p * r - q * s, p * s + q * r);
    let r2 = mul((x, y), (x, y));
    let r3 = mul(r2, (x, y));
    let r4 = mul(r2, r2);
    (
        (r4.0 + a * r2.0 + b * x + c, r4.1 + a * r2.1 + b * y),
        (4.0 * r3.0 + 2.0 * a * x + b, 4.0 * r3.1 + 2.0 * a * y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// R(r) = r^4 + A r^2 + B r + C at the complex point (x, y).
    fn potential(a: f64, lambda: f64, eta: f64, x: f64, y: f64) -> (f64, f64) {
        let big_a = a * a - eta - lambda * lambda;
        let big_b = 2.0 * (eta + (lambda - a) * (lambda - a));
        let big_c = -a * a * eta;
        let mul = |(p, q): (f64, f64), (r, s): (f64, f64)| (p * r - q * s, p * s + q * r);
        let r2 = mul((x, y), (x, y));
        let r4 = mul(r2, r2);
        (
            r4.0 + big_a * r2.0 + big_b * x + big_c,
            r4.1 + big_a * r2.1 + big_b * y,
        )
    }

    #[test]
    fn the_roots_match_reference_values_in_every_case() {
        // mpmath 1.3 polyroots at 40 digits of r^4 + A r^2 + B r + C.
        let r_plus = |a: f64| 1.0 + (1.0 - a * a).sqrt();
        for (a, lambda, eta, want_re, want_im, case) in [
            (
                0.9,
                2.0,
                20.0,
                [
                    -5.593_841_235_063_287,
                    0.538_357_717_929_030_2,
                    1.522_715_786_653_016_5,
                    3.532_767_730_481_24,
                ],
                [0.0; 4],
                RootCase::OuterTurning,
            ),
            (
                0.998,
                2.2,
                25.3,
                [
                    -6.199_063_772_170_674,
                    0.902_258_919_133_651_6,
                    1.064_505_591_837_258,
                    4.232_299_261_199_765,
                ],
                [0.0; 4],
                RootCase::OuterTurning,
            ),
            (
                0.9,
                1.01,
                -0.01,
                [
                    -0.399_956_373_242_692_6,
                    -0.216_670_599_625_437_55,
                    0.268_474_190_969_358_67,
                    0.348_152_781_898_771_47,
                ],
                [0.0; 4],
                RootCase::InnerReal,
            ),
            (
                0.9,
                -3.0,
                10.0,
                [
                    -5.292_124_554_315_06,
                    0.171_208_497_086_731_9,
                    2.560_458_028_614_164,
                    2.560_458_028_614_164,
                ],
                [0.0, 0.0, -1.543_985_958_558_001_7, 1.543_985_958_558_001_7],
                RootCase::OnePair,
            ),
            (
                0.9,
                -6.8,
                1e-3,
                [
                    -7.788_246_123_556_295,
                    6.830_734_173_498_67e-6,
                    3.894_119_646_411_061,
                    3.894_119_646_411_061,
                ],
                [
                    0.0,
                    0.0,
                    -0.248_106_148_921_725_54,
                    0.248_106_148_921_725_54,
                ],
                RootCase::OnePair,
            ),
            (
                0.9,
                0.5,
                -0.1,
                [
                    -0.131_606_083_578_089_65,
                    -0.131_606_083_578_089_65,
                    0.131_606_083_578_089_65,
                    0.131_606_083_578_089_65,
                ],
                [
                    -0.345_495_547_241_006_56,
                    0.345_495_547_241_006_56,
                    -0.758_467_632_339_155,
                    0.758_467_632_339_155,
                ],
                RootCase::TwoPairs,
            ),
        ] {
            let roots = RadialRoots::new(a, lambda, eta);
            for i in 0..4 {
                let scale = f64::abs(want_re[3]).max(1.0);
                assert!(
                    (roots.re[i] - want_re[i]).abs() < 1e-13 * scale
                        && (roots.im[i] - want_im[i]).abs() < 1e-13 * scale,
                    "a {a} lambda {lambda} eta {eta}: root {i} {:?} vs {:?}",
                    roots,
                    (want_re, want_im)
                );
            }
            assert_eq!(roots.case(r_plus(a)), case);
        }
    }

    #[test]
    fn every_root_is_a_root_and_they_sum_to_zero() {
        // Photons of every kind around a = 0, 0.5, 0.998, -0.9: the
        // potential at each root is zero to rounding (relative to the
        // terms' size), and the roots sum to zero.
        let mut cases = std::collections::HashSet::new();
        for a in [0.0, 0.5, 0.998, -0.9] {
            for lambda in [-7.0, -3.3, -1.0, 0.0, 0.4, 2.0, 5.5, 9.0] {
                for eta in [-0.5, -0.01, 0.0, 1e-6, 0.7, 9.0, 27.0, 60.0] {
                    let roots = RadialRoots::new(a, lambda, eta);
                    let sum: f64 = roots.re.iter().sum();
                    let size = roots
                        .re
                        .iter()
                        .chain(&roots.im)
                        .fold(1.0f64, |m, v| m.max(v.abs()));
                    // Roots that nearly coincide are fixed only to about
                    // sqrt(eps) each (a double root's conditioning).
                    let mut gap = f64::MAX;
                    for i in 0..4 {
                        for j in i + 1..4 {
                            gap = gap
                                .min((roots.re[i] - roots.re[j]).hypot(roots.im[i] - roots.im[j]));
                        }
                    }
                    let tol = if gap > 1e-3 * size { 1e-12 } else { 1e-7 };
                    assert!(sum.abs() < tol * size, "{a} {lambda} {eta}: sum {sum}");
                    let terms = size.powi(4) + (a * a + eta.abs() + lambda * lambda) * size * size;
                    for i in 0..4 {
                        let (re, im) = potential(a, lambda, eta, roots.re[i], roots.im[i]);
                        assert!(
                            re.hypot(im) < 1e-12 * terms,
                            "a {a} lambda {lambda} eta {eta}: R(root {i}) = ({re}, {im}) for {roots:?}"
                        );
                    }
                    cases.insert(format!("{:?}", roots.case(1.0 + (1.0 - a * a).sqrt())));
                }
            }
        }
        assert!(cases.len() >= 3, "{cases:?}");
    }
}
