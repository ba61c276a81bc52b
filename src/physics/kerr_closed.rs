//! Kerr light rays in closed form (Gralla and Lupsasca, "Null geodesics
//! of the Kerr exterior", PRD 101, 044032, 2020), in units of M: the
//! radial potential's roots and their cases, from which the Mino time
//! between radii, and so each equatorial crossing and the escape, are
//! elliptic integrals (`super::elliptic`).
//!
//! A photon of energy-rescaled angular momentum lambda = L_z / E and
//! Carter constant eta = Q / E^2 moves in r under the quartic
//! R(r) = (r^2 + a^2 - a lambda)^2 - Delta (eta + (lambda - a)^2)
//!      = r^4 + A r^2 + B r + C,
//! A = a^2 - eta - lambda^2, B = 2 (eta + (lambda - a)^2), C = -a^2 eta.

/// The four roots of the radial potential, r1 + r2 + r3 + r4 = 0, each as
/// (real part, imaginary part); real roots are ordered, and a complex pair
/// is conjugate (negative imaginary part first).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialRoots {
    pub re: [f64; 4],
    pub im: [f64; 4],
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

impl RadialRoots {
    /// The roots of R for spin `a`, lambda and eta (Gralla and Lupsasca,
    /// eqs. 95-98): with P = -A^2/12 - C, Q = -A/3 ((A/6)^2 - C) - B^2/8
    /// the resolvent's cube roots omega_+- = (-Q/2 +- sqrt((P/3)^3 +
    /// (Q/2)^2))^(1/3) (principal branches, a conjugate pair where the
    /// root is imaginary), z = sqrt((omega_+ + omega_-)/2 - A/6), and
    /// r_{1,2} = -z -+ sqrt(-A/2 - z^2 + B/(4z)),
    /// r_{3,4} = z -+ sqrt(-A/2 - z^2 - B/(4z)).
    pub fn new(a: f64, lambda: f64, eta: f64) -> RadialRoots {
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
            let rho = (-(p / 3.0).powi(3)).sqrt();
            let theta = (-d).sqrt().atan2(-0.5 * q);
            2.0 * rho.cbrt() * (theta / 3.0).cos()
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
        for i in [0, 1, 2, 3] {
            if roots.im[i] > 0.0 {
                continue;
            }
            let (mut x, mut y) = (roots.re[i], roots.im[i]);
            let (mut f, mut df) = potential_and_slope((big_a, big_b, big_c), (x, y));
            for _ in 0..12 {
                let den = df.0 * df.0 + df.1 * df.1;
                if !(den > 0.0) {
                    break;
                }
                let (nx, ny) = (
                    x - (f.0 * df.0 + f.1 * df.1) / den,
                    y - (f.1 * df.0 - f.0 * df.1) / den,
                );
                let (nf, ndf) = potential_and_slope((big_a, big_b, big_c), (nx, ny));
                if !(nf.0.hypot(nf.1) < f.0.hypot(f.1)) {
                    break;
                }
                (x, y, f, df) = (nx, ny, nf, ndf);
            }
            roots.re[i] = x;
            roots.im[i] = y;
            if i % 2 == 0 && roots.im[i] < 0.0 {
                roots.re[i + 1] = x;
                roots.im[i + 1] = -y;
            }
        }
        roots
    }

    /// Which of the four cases these roots are, for the outer horizon
    /// `r_plus`.
    pub fn case(&self, r_plus: f64) -> RootCase {
        match (self.im[0] == 0.0, self.im[2] == 0.0) {
            (true, true) if self.re[3] > r_plus => RootCase::OuterTurning,
            (true, true) => RootCase::InnerReal,
            (true, false) => RootCase::OnePair,
            _ => RootCase::TwoPairs,
        }
    }
}

impl RadialRoots {
    /// For a photon outside its turning point r4 (four real roots, r >=
    /// r4): the Mino time from r4 out to `r`, and on to infinity, the
    /// integrals of dr / sqrt(R) (Gralla and Lupsasca, eq. B35):
    /// 2 / sqrt(r31 r42) F(asin x(r) | k), x(r)^2 = (r - r4) r31 / ((r -
    /// r3) r41), k = r32 r41 / (r31 r42), rij = ri - rj.
    pub fn mino_outside(&self, r: f64) -> (f64, f64) {
        let [r1, r2, r3, r4] = self.re;
        let (r31, r41, r32, r42) = (r3 - r1, r4 - r1, r3 - r2, r4 - r2);
        let k = r32 * r41 / (r31 * r42);
        let scale = 2.0 / (r31 * r42).sqrt();
        let x2 = ((r - r4) * r31 / ((r - r3) * r41)).clamp(0.0, 1.0);
        let to_r = scale * super::elliptic::legendre_f(x2.sqrt().asin(), k);
        let total = scale * super::elliptic::legendre_f((r31 / r41).sqrt().asin(), k);
        (to_r, total - to_r)
    }
}

/// A photon's ordinary polar motion (eta > 0): it swings about the equator
/// between theta_+ and pi - theta_+, where cos^2 theta_+ = u_+, under
/// Theta(theta) = eta + a^2 cos^2 theta - lambda^2 cot^2 theta (Gralla and
/// Lupsasca, section 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolarMotion {
    /// u_+ = cos^2 of the turning angle.
    pub u_plus: f64,
    /// sqrt(-u_- a^2), the scale of the Mino time.
    scale: f64,
    /// The parameter u_+ / u_- (<= 0) of its elliptic integrals.
    m: f64,
}

impl PolarMotion {
    /// The motion of a photon of spin `a`, lambda and eta > 0 (None
    /// otherwise). u_+- = Delta_theta +- sqrt(Delta_theta^2 + eta / a^2),
    /// Delta_theta = (1 - (eta + lambda^2) / a^2) / 2, taken as a^2 u_-
    /// without cancellation and u_+ = -eta / (a^2 u_-): finite as a -> 0.
    pub fn new(a: f64, lambda: f64, eta: f64) -> Option<PolarMotion> {
        if !(eta > 0.0) {
            return None;
        }
        let half = 0.5 * (a * a - eta - lambda * lambda);
        let a2_um = half - (half * half + eta * a * a).sqrt();
        let u_plus = -eta / a2_um;
        Some(PolarMotion {
            u_plus,
            scale: (-a2_um).sqrt(),
            m: u_plus * a * a / a2_um,
        })
    }

    /// The Mino time from the equator to `theta` along the motion, signed
    /// as cos theta (Gralla and Lupsasca, eq. 29):
    /// F(asin(cos theta / sqrt(u_+)) | u_+ / u_-) / sqrt(-u_- a^2).
    pub fn mino_from_equator(&self, theta: f64) -> f64 {
        let s = (theta.cos() / self.u_plus.sqrt()).clamp(-1.0, 1.0);
        super::elliptic::legendre_f(s.asin(), self.m) / self.scale
    }

    /// The Mino time from the equator to a turning point, a quarter of a
    /// whole swing: K(u_+ / u_-) / sqrt(-u_- a^2).
    pub fn quarter(&self) -> f64 {
        super::elliptic::carlson_rf(0.0, 1.0 - self.m, 1.0) / self.scale
    }
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
    fn the_mino_time_outside_the_turning_point_is_the_radial_integral() {
        // mpmath 1.3 quad at 30 digits: from r4 to r0 (r = r4 + s^2) and
        // from r0 to infinity of dr / sqrt(R).
        for (a, lambda, eta, r0, to_r0, beyond) in [
            (
                0.9,
                2.0,
                20.0,
                10.0,
                0.401_942_173_282_991_2,
                0.103_683_174_133_766_74,
            ),
            (
                0.998,
                2.2,
                25.3,
                4.5,
                0.095_664_332_012_941_09,
                0.309_609_985_971_688_7,
            ),
            (
                0.5,
                6.0,
                30.0,
                50.0,
                0.217_172_245_551_579_5,
                0.020_086_249_270_463_78,
            ),
            (
                0.9,
                2.0,
                20.0,
                3.6,
                0.069_243_692_566_612_44,
                0.436_381_654_850_145_6,
            ),
        ] {
            let roots = RadialRoots::new(a, lambda, eta);
            let (got_to, got_beyond) = roots.mino_outside(r0);
            assert!(
                (got_to - to_r0).abs() < 1e-14 && (got_beyond - beyond).abs() < 1e-14,
                "a {a} lambda {lambda} eta {eta} r {r0}: {got_to} {got_beyond}"
            );
        }
    }

    #[test]
    fn the_polar_mino_time_is_the_angular_integral() {
        // From theta to the equator: mpmath 1.3 quad of dtheta /
        // sqrt(Theta) at 30 digits; to the turning point: K(u_+/u_-) /
        // sqrt(-u_- a^2) by mpmath's ellipk (its quad, singular at the
        // turning point, agrees to 1e-8).
        for (a, lambda, eta, theta, to_equator, quarter) in [
            (
                0.9,
                2.0,
                20.0,
                1.0,
                0.129_007_246_169_540_06,
                0.319_268_303_828_814_2,
            ),
            (
                0.5,
                0.3,
                27.0,
                0.2,
                0.264_447_747_311_682_6,
                0.301_111_446_125_036_8,
            ),
            (
                0.998,
                4.0,
                5.0,
                1.3,
                0.126_246_072_546_369_17,
                0.348_013_865_425_140_3,
            ),
            (
                -0.9,
                -2.5,
                12.0,
                2.0,
                -0.125_877_751_057_025_42,
                0.367_701_919_581_584_45,
            ),
        ] {
            let polar = PolarMotion::new(a, lambda, eta).unwrap();
            let got = polar.mino_from_equator(theta);
            assert!(
                (got - to_equator).abs() < 1e-14 && (polar.quarter() - quarter).abs() < 1e-14,
                "a {a} lambda {lambda} eta {eta}: {got}, {}",
                polar.quarter()
            );
        }
        // Without spin the swing is a great circle's: Theta = eta -
        // lambda^2 cot^2 theta gives asin(cos theta / sqrt(u_+)) /
        // sqrt(eta + lambda^2), u_+ = eta / (eta + lambda^2).
        let (lambda, eta) = (3.0, 16.0);
        let polar = PolarMotion::new(0.0, lambda, eta).unwrap();
        let l2 = eta + lambda * lambda;
        assert!((polar.u_plus - eta / l2).abs() < 1e-16);
        for theta in [0.7f64, 1.2, 2.0] {
            let want = (theta.cos() / polar.u_plus.sqrt()).asin() / l2.sqrt();
            assert!((polar.mino_from_equator(theta) - want).abs() < 1e-15);
        }
        assert!((polar.quarter() - std::f64::consts::FRAC_PI_2 / l2.sqrt()).abs() < 1e-15);
        // Only ordinary motion has a swing about the equator.
        assert!(PolarMotion::new(0.9, 0.5, -0.1).is_none());
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
