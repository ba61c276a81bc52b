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

use super::elliptic::{bulirsch_cel, bulirsch_cel_many, legendre_f_j};
use super::kerr::Kerr;
use glam::DVec3;

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
}

/// The radial motion of a photon between the outer horizon and infinity
/// in Jacobi's functions of U = kappa X, X the Mino time from a reference
/// root at which r(U) is even in U (so that one formula carries the photon
/// through its turning point), with the integrals of dX / (r - p) for the
/// two poles p = r_+, r_- of the azimuth's radial part.
#[derive(Clone, Copy, Debug)]
enum Radial {
    /// Four real roots, the photon at r >= r4 (turning there if r4 > r_+;
    /// Gralla and Lupsasca, eq. B35-B37), or with the roots relabelled
    /// between r_+ and r3: sn^2(U | k) = (r - r4) r31 / ((r - r3) r41), k =
    /// r32 r41 / (r31 r42), kappa = sqrt(r31 r42) / 2. There 1 / (r - p) =
    /// (1 - c sn^2) / ((r4 - p) (1 - n sn^2)), c = r41 / r31, n = (r3 - p)
    /// r41 / ((r4 - p) r31): its integral is U / (r3 - p) + (r3 - r4) /
    /// ((r4 - p) (r3 - p)) Pi(n; am U | k), over kappa.
    Outer {
        r3: f64,
        r4: f64,
        r31: f64,
        r41: f64,
        /// n, 1 / (r3 - p) and (r3 - r4) / ((r4 - p) (r3 - p)) per pole.
        n: [f64; 2],
        linear: [f64; 2],
        third: [f64; 2],
        /// For the time: r = r3 + r43 / (1 - N sn^2), N = r41 / r31 (the
        /// pole at infinity), so the integrals of r and r^2 are Pi(N) and
        /// int dU / (1 - N sn^2)^2 (Byrd and Friedman 336.02).
        big_n: f64,
        r43: f64,
    },
    /// r1 < r2 real, r3 = conj r4 (eqs. B57-B60): cn(U | k) = (A (r - r1) -
    /// B (r - r2)) / (A (r - r1) + B (r - r2)), A = |r3 - r2|, B = |r3 -
    /// r1|, k = ((A + B)^2 - r21^2) / (4 A B), kappa = sqrt(A B). There 1 /
    /// (r - p) = (A + B) / D1 - 2 A B r21 / (D0 D1 (1 + alpha cn)), D0,1 =
    /// B (r2 - p) -+ A (r1 - p), alpha = D1 / D0, and the integral of 1 /
    /// (1 + alpha cn) is Pi(n; am U | k) / (1 - alpha^2) - alpha W, n =
    /// alpha^2 / (alpha^2 - 1), W the integral of dw / (c + d w^2) in w =
    /// sn / dn, c = 1 - alpha^2, d = k + (1 - k) alpha^2.
    Pair {
        r1: f64,
        r2: f64,
        big_a: f64,
        big_b: f64,
        /// Per pole: n, alpha, (A + B) / D1, -2 A B r21 / (D0 D1), c, d.
        n: [f64; 2],
        alpha: [f64; 2],
        linear: [f64; 2],
        third: [f64; 2],
        c: [f64; 2],
        d: [f64; 2],
        /// For the time: r = r0 + r1 / (1 + alpha cn) with the pole at
        /// infinity, alpha = (B + A) / (B - A): its n, alpha, c, d as the
        /// horizons' and (r0, r1).
        inf: [f64; 4],
        r_lin: [f64; 2],
    },
    /// Two complex pairs a1 +- i b1, a2 +- i b2 (vortical rays): the pencil
    /// q1 - lambda q2 of the two quadratic factors is a square at two
    /// lambdas 0 < lambda1 < 1 < lambda2, (1 - lambda) (r - s)^2, whence
    /// q_i = c_i (r - s1)^2 + d_i (r - s2)^2 with all c_i, d_i > 0; in x =
    /// (r - s1) / (r - s2), tan theta = x sqrt(c1 / d1), dr / sqrt(R) =
    /// d theta / (sqrt(c1 d2) (s1 - s2) sqrt(1 - k sin^2 theta)), k = 1 -
    /// lambda1 / lambda2. Then 1 / (r - p) = (cn - t sn) / (alpha cn -
    /// gamma sn), t = sqrt(d1 / c1), alpha = s1 - p, gamma = (s2 - p) t,
    /// whose integral is (alpha + t gamma) / G U + (1 / alpha - (alpha + t
    /// gamma) / G) Pi(G / alpha^2; theta | k) plus an odd part, a
    /// logarithm of dn, G = alpha^2 + gamma^2. theta takes whole half
    /// turns: the amplitude carries their count.
    Quad {
        s1: f64,
        s2: f64,
        /// sqrt(c1), sqrt(d1), and theta at infinity.
        sc1: f64,
        sd1: f64,
        theta_inf: f64,
        /// Per pole: n, the coefficients of U and of Pi, the odd part's
        /// coefficient, sqrt(G), sqrt(H) (H = G - k alpha^2) and its log at
        /// theta = 0.
        n: [f64; 2],
        lin: [f64; 2],
        pi: [f64; 2],
        odd: [f64; 2],
        sg: [f64; 2],
        sh: [f64; 2],
        l1: [f64; 2],
    },
}

/// A radial amplitude: its sine and cosine and, for two complex pairs, the
/// whole half turns before it (the amplitude is j pi + atan2(sn, cn), cn
/// >= 0 there).
#[derive(Clone, Copy, Debug)]
struct Amp {
    sn: f64,
    cn: f64,
    j: f64,
}

impl Amp {
    fn new(sn: f64, cn: f64) -> Amp {
        Amp { sn, cn, j: 0.0 }
    }

    /// The amplitude `theta`, as whole half turns and a remainder.
    fn of_angle(theta: f64) -> Amp {
        let j = (theta / std::f64::consts::PI).round();
        let (sn, cn) = (theta - j * std::f64::consts::PI).sin_cos();
        Amp { sn, cn, j }
    }
}

impl Radial {
    fn outer(roots: [f64; 4], poles: [f64; 2]) -> (Radial, f64, f64) {
        let [r1, r2, r3, r4] = roots;
        let (r31, r41, r32, r42) = (r3 - r1, r4 - r1, r3 - r2, r4 - r2);
        let radial = Radial::Outer {
            r3,
            r4,
            r31,
            r41,
            n: poles.map(|p| (r3 - p) * r41 / ((r4 - p) * r31)),
            linear: poles.map(|p| 1.0 / (r3 - p)),
            third: poles.map(|p| (r3 - r4) / ((r4 - p) * (r3 - p))),
            big_n: r41 / r31,
            r43: r4 - r3,
        };
        (radial, r32 * r41 / (r31 * r42), 0.5 * (r31 * r42).sqrt())
    }

    fn pair(r1: f64, r2: f64, (re, im): (f64, f64), poles: [f64; 2]) -> (Radial, f64, f64) {
        let big_a = (re - r2).hypot(im);
        let big_b = (re - r1).hypot(im);
        let r21 = r2 - r1;
        let k = ((big_a + big_b).powi(2) - r21 * r21) / (4.0 * big_a * big_b);
        let d0 = poles.map(|p| big_b * (r2 - p) - big_a * (r1 - p));
        let d1 = poles.map(|p| big_b * (r2 - p) + big_a * (r1 - p));
        let alpha: [f64; 2] = std::array::from_fn(|i| d1[i] / d0[i]);
        let al = (big_b + big_a) / (big_b - big_a);
        let inf = [
            al * al / (al * al - 1.0),
            al,
            1.0 - al * al,
            k + (1.0 - k) * al * al,
        ];
        let r_lin = [
            (big_b * r2 + big_a * r1) / (big_b + big_a),
            2.0 * big_a * big_b * r21 / ((big_b + big_a) * (big_b - big_a)),
        ];
        let radial = Radial::Pair {
            r1,
            r2,
            big_a,
            big_b,
            n: alpha.map(|al| al * al / (al * al - 1.0)),
            alpha,
            linear: d1.map(|d| (big_a + big_b) / d),
            third: std::array::from_fn(|i| -2.0 * big_a * big_b * r21 / (d0[i] * d1[i])),
            c: alpha.map(|al| 1.0 - al * al),
            d: alpha.map(|al| k + (1.0 - k) * al * al),
            inf,
            r_lin,
        };
        (radial, k, (big_a * big_b).sqrt())
    }

    fn quad(roots: &RadialRoots, poles: [f64; 2]) -> Option<(Radial, f64, f64)> {
        let (a1, b1) = (roots.re[0], roots.im[0].abs());
        let (a2, b2) = (roots.re[2], roots.im[2].abs());
        let sum = (a1 - a2) * (a1 - a2) + b1 * b1 + b2 * b2;
        let disc = (sum * sum - 4.0 * b1 * b1 * b2 * b2).max(0.0);
        let l2 = (sum + disc.sqrt()) / (2.0 * b2 * b2);
        let l1 = b1 * b1 / (b2 * b2 * l2);
        if !(l1 < 1.0 - 1e-12 && l2 > 1.0 + 1e-12) {
            return None;
        }
        let (s1, s2) = ((a1 - l1 * a2) / (1.0 - l1), (a1 - l2 * a2) / (1.0 - l2));
        let span = l2 - l1;
        let (c1, d1, d2) = (
            l2 * (1.0 - l1) / span,
            l1 * (l2 - 1.0) / span,
            (l2 - 1.0) / span,
        );
        let k = 1.0 - l1 / l2;
        let t = (d1 / c1).sqrt();
        let alpha = poles.map(|p| s1 - p);
        let gamma = poles.map(|p| (s2 - p) * t);
        let g: [f64; 2] = std::array::from_fn(|i| alpha[i] * alpha[i] + gamma[i] * gamma[i]);
        let h: [f64; 2] = std::array::from_fn(|i| g[i] - k * alpha[i] * alpha[i]);
        let sg = g.map(f64::sqrt);
        let sh = h.map(f64::sqrt);
        let log = |i: usize, w: f64| ((sg[i] * w - sh[i]) / (sg[i] * w + sh[i])).abs().ln();
        let radial = Radial::Quad {
            s1,
            s2,
            sc1: c1.sqrt(),
            sd1: d1.sqrt(),
            theta_inf: c1.sqrt().atan2(d1.sqrt()),
            n: std::array::from_fn(|i| g[i] / (alpha[i] * alpha[i])),
            lin: std::array::from_fn(|i| (alpha[i] + t * gamma[i]) / g[i]),
            pi: std::array::from_fn(|i| 1.0 / alpha[i] - (alpha[i] + t * gamma[i]) / g[i]),
            odd: std::array::from_fn(|i| -(gamma[i] - t * alpha[i]) / (2.0 * sg[i] * sh[i])),
            sg,
            sh,
            l1: std::array::from_fn(|i| log(i, 1.0)),
        };
        Some((radial, k, (c1 * d2).sqrt() * (s1 - s2).abs()))
    }

    /// Whether U grows with r.
    fn rising(&self) -> bool {
        match *self {
            Radial::Quad { s1, s2, .. } => s1 > s2,
            _ => true,
        }
    }

    /// The amplitude at radius `r` (U >= 0 there but for two complex
    /// pairs).
    fn sn_cn(&self, r: f64) -> Amp {
        match *self {
            Radial::Outer {
                r3, r4, r31, r41, ..
            } => {
                let s2 = ((r - r4) * r31 / ((r - r3) * r41)).clamp(0.0, 1.0);
                Amp::new(s2.sqrt(), (1.0 - s2).sqrt())
            }
            Radial::Pair {
                r1,
                r2,
                big_a,
                big_b,
                ..
            } => {
                let (p, q) = (big_a * (r - r1), big_b * (r - r2));
                let c = ((p - q) / (p + q)).clamp(-1.0, 1.0);
                Amp::new((1.0 - c * c).sqrt(), c)
            }
            Radial::Quad {
                s1,
                s2,
                sc1,
                sd1,
                theta_inf,
                ..
            } => {
                // theta on the branch through theta at infinity: the ray's
                // r covers less than a half turn of it.
                let raw = ((r - s1) * sc1).atan2((r - s2) * sd1);
                let pi = std::f64::consts::PI;
                let d = (raw - theta_inf + pi).rem_euclid(std::f64::consts::TAU) - pi;
                Amp::of_angle(theta_inf + d)
            }
        }
    }

    /// The amplitude at infinity.
    fn sn_cn_at_infinity(&self) -> Amp {
        match *self {
            Radial::Outer { r31, r41, .. } => {
                Amp::new((r31 / r41).sqrt(), ((r41 - r31) / r41).sqrt())
            }
            Radial::Pair { big_a, big_b, .. } => {
                let c = (big_a - big_b) / (big_a + big_b);
                Amp::new((1.0 - c * c).sqrt(), c)
            }
            Radial::Quad { theta_inf, .. } => Amp::of_angle(theta_inf),
        }
    }

    /// The radius at an amplitude of sine `sn`, cosine `cn`.
    fn radius(&self, sn: f64, cn: f64) -> f64 {
        match *self {
            Radial::Quad {
                s1, s2, sc1, sd1, ..
            } => (s1 * cn * sc1 - s2 * sn * sd1) / (cn * sc1 - sn * sd1),
            Radial::Outer {
                r3, r4, r31, r41, ..
            } => {
                let s2 = sn * sn;
                (r4 * r31 - r3 * r41 * s2) / (r31 - r41 * s2)
            }
            Radial::Pair {
                r1,
                r2,
                big_a,
                big_b,
                ..
            } => {
                ((big_b * r2 - big_a * r1) + (big_b * r2 + big_a * r1) * cn)
                    / ((big_b - big_a) + (big_b + big_a) * cn)
            }
        }
    }

    /// The elliptic integrals [`Radial::at`] needs at an amplitude, from
    /// one duplication sequence: F and, with `poles`, J of the two poles,
    /// with `TIME` D and J of the pole at infinity.
    #[inline]
    fn integrals<const TIME: bool>(&self, amp: Amp, k: f64, poles: bool) -> Ints {
        let (n, n_inf) = match *self {
            Radial::Outer { n, big_n, .. } => (n, big_n),
            Radial::Pair { n, inf, .. } => (n, inf[0]),
            Radial::Quad { n, .. } => (n, 0.0),
        };
        // The Legendre forms take cn >= 0: one complex pair reflects past
        // a quarter period.
        let (s, c) = (amp.sn, amp.cn.abs());
        if TIME {
            let (f, [j0, j1, d, jn]) = legendre_f_j(s, c, k, [n[0], n[1], 0.0, n_inf]);
            Ints {
                f,
                j: [j0, j1],
                d,
                jn,
            }
        } else if poles {
            let (f, j) = legendre_f_j(s, c, k, n);
            Ints {
                f,
                j,
                d: 0.0,
                jn: 0.0,
            }
        } else {
            Ints {
                f: legendre_f_j(s, c, k, []).0,
                j: [0.0; 2],
                d: 0.0,
                jn: 0.0,
            }
        }
    }

    /// U at the amplitude (sn, cn) (cn < 0 past a quarter period, where
    /// the photon has no pair of real roots) and, with `poles`, kappa times
    /// the integrals of dX / (r - p) from U = 0 (odd in U); with `TIME`
    /// (and `poles`) also kappa times the integral of r^2 + 2 r + 4 dX, the
    /// coordinate time's polynomial part (none for two complex pairs,
    /// whose vortical rays cross no plane: NaN).
    fn at<const TIME: bool>(
        &self,
        amp: Amp,
        k: f64,
        complete: &Complete,
        poles: bool,
    ) -> (f64, [f64; 2], f64) {
        let ints = self.integrals::<TIME>(amp, k, poles);
        let Amp { sn, cn, j } = amp;
        match *self {
            Radial::Quad {
                n,
                lin,
                pi,
                odd,
                sg,
                sh,
                l1,
                ..
            } => {
                let f = ints.f;
                let p: [f64; 2] = std::array::from_fn(|i| f + n[i] * ints.j[i]);
                let u = f + 2.0 * j * complete.k;
                let time = if TIME { f64::NAN } else { 0.0 };
                if !poles {
                    return (u, [0.0; 2], time);
                }
                let dn = (1.0 - k * sn * sn).sqrt();
                (
                    u,
                    std::array::from_fn(|i| {
                        let big_pi = p[i] + 2.0 * j * complete.pi[i];
                        let log = ((sg[i] * dn - sh[i]) / (sg[i] * dn + sh[i])).abs().ln();
                        lin[i] * u + pi[i] * big_pi + odd[i] * (log - l1[i])
                    }),
                    time,
                )
            }
            Radial::Outer {
                n,
                linear,
                third,
                r3,
                big_n,
                r43,
                ..
            } => {
                let Ints { f: u, j: jp, d, jn } = ints;
                let pole = if poles {
                    std::array::from_fn(|i| u * linear[i] + third[i] * (u + n[i] * jp[i]))
                } else {
                    [0.0; 2]
                };
                if !TIME {
                    return (u, pole, 0.0);
                }
                // int dU / (1 - N sn^2)^2 from d/dU (sn cn dn g) = k / N^2 -
                // k sn^2 / N + (2 k N - 3 k - N^2 + 2 N) g / N^2 - 2 (k - N)
                // (N - 1) g^2 / N^2, g = 1 / (1 - N sn^2).
                let pn = u + big_n * jn;
                let g = 1.0 / (1.0 - big_n * sn * sn);
                let dn = (1.0 - k * sn * sn).sqrt();
                let nn = big_n;
                let v2 = (k * u - k * nn * d + (2.0 * k * nn - 3.0 * k - nn * nn + 2.0 * nn) * pn
                    - nn * nn * sn * cn * dn * g)
                    / (2.0 * (k - nn) * (nn - 1.0));
                let i1 = r3 * u + r43 * pn;
                let i2 = r3 * r3 * u + 2.0 * r3 * r43 * pn + r43 * r43 * v2;
                (u, pole, i2 + 2.0 * i1 + 4.0 * u)
            }
            Radial::Pair {
                n,
                alpha,
                linear,
                third,
                c,
                d,
                inf,
                r_lin,
                ..
            } => {
                let Ints {
                    f,
                    j: jp,
                    d: dd,
                    jn,
                } = ints;
                let pi: [f64; 2] = std::array::from_fn(|i| f + n[i] * jp[i]);
                let pi_inf = f + inf[0] * jn;
                // Past a quarter period by reflection: F(pi - phi) = 2K -
                // F(phi), likewise Pi and D.
                let (u, pi, dd, pi_inf) = if cn < 0.0 {
                    (
                        2.0 * complete.k - f,
                        std::array::from_fn(|i| 2.0 * complete.pi[i] - pi[i]),
                        2.0 * complete.d - dd,
                        2.0 * complete.pi_inf - pi_inf,
                    )
                } else {
                    (f, pi, dd, pi_inf)
                };
                if !poles {
                    return (u, [0.0; 2], 0.0);
                }
                // The integral of 1 / (1 + alpha cn): Pi / c - alpha W.
                let w = sn / (1.0 - k * sn * sn).sqrt();
                let first = |pi: f64, alpha: f64, c: f64, d: f64| {
                    let odd = if c > 0.0 {
                        (w * (d / c).sqrt()).atan() / (c * d).sqrt()
                    } else {
                        // c + d w^2 = -(|c| - d w^2): minus atanh, its
                        // principal value past the pole.
                        let z = w * (d / -c).sqrt();
                        -0.5 * ((1.0 + z) / (1.0 - z)).abs().ln() / (-c * d).sqrt()
                    };
                    pi / c - alpha * odd
                };
                let pole = std::array::from_fn(|i| {
                    linear[i] * u + third[i] * first(pi[i], alpha[i], c[i], d[i])
                });
                if !TIME {
                    return (u, pole, 0.0);
                }
                // int dU / (1 + alpha cn)^2 from d/dU (sn dn f) = k cn^2 /
                // alpha - k / alpha^3 - (2 alpha^2 k - alpha^2 - 2 k) f /
                // alpha^3 - (alpha^2 - 1) (alpha^2 k - alpha^2 - k) f^2 /
                // alpha^3, f = 1 / (1 + alpha cn), cn^2 = 1 - sn^2.
                let al = inf[1];
                let a2 = al * al;
                let r1 = first(pi_inf, al, inf[2], inf[3]);
                let dn = (1.0 - k * sn * sn).sqrt();
                let f_inf = 1.0 / (1.0 + al * cn);
                let r2 = (k * a2 * (u - dd)
                    - k * u
                    - (2.0 * a2 * k - a2 - 2.0 * k) * r1
                    - a2 * al * sn * dn * f_inf)
                    / ((a2 - 1.0) * (a2 * k - a2 - k));
                let [r0, rc] = r_lin;
                let i1 = r0 * u + rc * r1;
                let i2 = r0 * r0 * u + 2.0 * r0 * rc * r1 + rc * rc * r2;
                (u, pole, i2 + 2.0 * i1 + 4.0 * u)
            }
        }
    }

    fn n(&self) -> [f64; 2] {
        match *self {
            Radial::Outer { n, .. } | Radial::Pair { n, .. } | Radial::Quad { n, .. } => n,
        }
    }
}

/// Complete integrals K(k) and Pi(n_i | k) of the radial poles (only a
/// photon with a complex root pair needs them), and for the time with one
/// pair D(k) and Pi of the pole at infinity.
#[derive(Clone, Copy, Debug, Default)]
struct Complete {
    k: f64,
    pi: [f64; 2],
    d: f64,
    pi_inf: f64,
}

/// Elliptic integrals at a radial amplitude ([`Radial::integrals`]): F,
/// J = (Pi - F) / n of the two poles, D, and J of the pole at infinity.
#[derive(Clone, Copy, Debug)]
struct Ints {
    f: f64,
    j: [f64; 2],
    d: f64,
    jn: f64,
}

/// A Kerr light ray in closed form from a start outside the horizon (in
/// M): its equatorial crossings in order, then the sky in its direction at
/// infinity or the hole. The ray runs in Mino time s from the start; r, cos
/// theta and the azimuth are Jacobi functions and elliptic integrals of s.
#[derive(Clone, Copy, Debug)]
pub struct KerrRay {
    a: f64,
    lambda: f64,
    /// The sign of the photon's energy along the ray's direction (-1 for a
    /// ray traced back from a camera): the azimuth runs with it.
    energy_sign: f64,
    radial: Radial,
    /// The radial motion's parameter and scale; its complete integrals.
    k: f64,
    kappa: f64,
    complete: Complete,
    /// U at the start and its direction (U = U0 + dir kappa s).
    u0: f64,
    dir: f64,
    /// The Mino time to the end.
    s_end: f64,
    /// The partial fractions of a (2 r - a lambda) / Delta = sum of coef /
    /// (r - r_+-), over kappa; their pole integrals at the start.
    coef: [f64; 2],
    pole0: [f64; 2],
    /// And at infinity (an escaping ray).
    pole_end: [f64; 2],
    polar: Polar,
    /// r_+ and r_-.
    horizons: [f64; 2],
    /// The Kerr-Schild azimuth at the start, less its radial term at r0.
    phi0: f64,
    /// It ends in the hole rather than at infinity.
    pub captured: bool,
    /// The least radius along the ray.
    min_r: f64,
    /// Whether it keeps the coordinate time: then kappa times the radial
    /// part of its integral at the start (signed as `pole0`) and the
    /// partial fractions of ((8 - 2 a lambda) r - 4 a^2) / Delta.
    timed: bool,
    time0: f64,
    tcoef: [f64; 2],
}

/// The ordinary polar motion along a ray: cos theta = sqrt(u_+) sn(psi |
/// m), psi = psi0 + scale s.
#[derive(Clone, Copy, Debug)]
struct Polar {
    u_plus: f64,
    /// The parameter and the characteristic of its Pi.
    m: f64,
    n: f64,
    scale: f64,
    /// The polar integral of 1 / sin^2 theta is Pi times this.
    g_scale: f64,
    psi0: f64,
    /// K(m), Pi(n | m) and Pi(n; am(psi0) | m).
    big_k: f64,
    pi_c: f64,
    pi0: f64,
    /// Vortical motion (eta < 0): u_- and the hemisphere's sign.
    vortical: Option<(f64, f64)>,
    /// For the time (ordinary motion): D(m) and D(am(psi0) | m), whose
    /// difference times a^2 u_+ / scale is the integral of a^2 cos^2 theta.
    d_c: f64,
    d0: f64,
}

impl Polar {
    /// Ordinary motion (eta > 0): cos theta = sqrt(u_+) sn(psi | u_+ /
    /// u_-), psi = psi0 + sqrt(-u_- a^2) s, the integral of 1 / sin^2
    /// theta Pi(u_+; am psi) / sqrt(-u_- a^2); psi0 in [-K, 3K), so that
    /// the equatorial crossings are the nodes psi = 2 K j.
    fn ordinary(pm: PolarMotion, cos0: f64, u_up: bool, timed: bool) -> Polar {
        let m = pm.m;
        let kc = (1.0 - m).sqrt();
        // K(m), Pi(u_+ | m) and, for the time, D(m) = cel(kc, 1, 0, 1).
        let (k, pi) = ((1.0, 1.0, 1.0), (1.0 - pm.u_plus, 1.0, 1.0));
        let sn_th = (cos0 / pm.u_plus.sqrt()).clamp(-1.0, 1.0);
        let cn_th = (1.0 - sn_th * sn_th).sqrt();
        let (f0, p0, [big_k, pi_c, d_c], d0) = if timed {
            let (f, [j, d]) = super::elliptic::legendre_f_j(sn_th, cn_th, m, [pm.u_plus, 0.0]);
            (
                f,
                f + pm.u_plus * j,
                bulirsch_cel_many(kc, [k, pi, (1.0, 0.0, 1.0)]),
                d,
            )
        } else {
            let (f, [p]) = super::elliptic::legendre_f_pi(sn_th, cn_th, m, [pm.u_plus]);
            let [big_k, pi_c] = bulirsch_cel_many(kc, [k, pi]);
            (f, p, [big_k, pi_c, 0.0], 0.0)
        };
        // Moving away from the equator's crossing ahead: past the turning
        // point, am = pi - asin.
        let (psi0, pi0, d0) = if u_up {
            (f0, p0, d0)
        } else {
            (2.0 * big_k - f0, 2.0 * pi_c - p0, 2.0 * d_c - d0)
        };
        Polar {
            u_plus: pm.u_plus,
            m,
            n: pm.u_plus,
            scale: pm.scale,
            g_scale: 1.0 / pm.scale,
            psi0,
            big_k,
            pi_c,
            pi0,
            vortical: None,
            d_c,
            d0,
        }
    }

    /// Vortical motion (eta < 0, a != 0): cos^2 theta swings between u_-
    /// and u_+ in one hemisphere. In w = cos^2 theta, (dw/ds)^2 = 4 a^2 w
    /// (u_+ - w)(w - u_-), so w = u_+ - (u_+ - u_-) sn^2(psi | k), k = 1 -
    /// u_- / u_+, psi = a sqrt(u_+) s from the turn nearest the pole (Byrd
    /// and Friedman 233.00), and the integral of 1 / sin^2 theta is Pi(n;
    /// am psi | k) / ((1 - u_+) a sqrt(u_+)), n = -(u_+ - u_-) / (1 - u_+).
    /// None where the ray passes within ~1e-5 rad of the axis.
    fn vortical(a: f64, lambda: f64, eta: f64, cos0: f64, u_up: bool) -> Option<Polar> {
        let half = 0.5 * (a * a - eta - lambda * lambda);
        let disc = half * half + eta * a * a;
        if !(eta < 0.0 && half > 0.0 && disc >= 0.0) {
            return None;
        }
        // a^2 u_+ without cancellation, u_- from the product -eta / a^2.
        let a2_up = half + disc.sqrt();
        let u_plus = a2_up / (a * a);
        let u_minus = -eta / a2_up;
        if !(u_plus < 1.0 - 1e-10) {
            return None;
        }
        let m = 1.0 - u_minus / u_plus;
        let n = -(u_plus - u_minus) / (1.0 - u_plus);
        let scale = a2_up.sqrt();
        let kc = (1.0 - m).sqrt();
        let [big_k, pi_c] = bulirsch_cel_many(kc, [(1.0, 1.0, 1.0), (1.0 - n, 1.0, 1.0)]);
        let s2 = ((u_plus - cos0 * cos0) / (u_plus - u_minus)).clamp(0.0, 1.0);
        let (f0, [p0]) = super::elliptic::legendre_f_pi(s2.sqrt(), (1.0 - s2).sqrt(), m, [n]);
        // Towards the pole (|cos theta| growing) psi runs up to 0.
        let sign = if u_up == (cos0 > 0.0) { -1.0 } else { 1.0 };
        Some(Polar {
            u_plus,
            m,
            n,
            scale,
            g_scale: 1.0 / (scale * (1.0 - u_plus)),
            psi0: sign * f0,
            big_k,
            pi_c,
            pi0: sign * p0,
            vortical: Some((u_minus, cos0.signum())),
            d_c: 0.0,
            d0: 0.0,
        })
    }
}

/// An equatorial crossing of a [`KerrRay`]: its Boyer-Lindquist radius and
/// where it lies along the ray.
#[derive(Clone, Copy, Debug)]
pub struct Crossing {
    pub r: f64,
    sn: f64,
    cn: f64,
    /// The number of half swings of the polar motion to it.
    j: f64,
}

/// Where a [`KerrRay`] crosses the equatorial plane (M).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossingPoint {
    /// The Kerr-Schild Cartesian point.
    pub x: DVec3,
    /// Its Boyer-Lindquist azimuth, which the closed form finds first
    /// (Kerr-Schild's adds the radial term of [`ks_azimuth_term`]).
    pub phi: f64,
    /// The Boyer-Lindquist coordinate time the light takes from it to the
    /// start (NaN for a ray not made `timed`).
    pub t: f64,
}

/// Where a camera's rays start (M): the Kerr-Schild point, its
/// Boyer-Lindquist r and cos theta, and what every ray from there shares
/// (found once per camera, not per ray).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KsStart {
    pub x: DVec3,
    pub r: f64,
    pub cos: f64,
    sin: f64,
    /// The Kerr-Schild azimuth less its radial term at r.
    phi_rest: f64,
    /// r_+ and r_-.
    horizons: [f64; 2],
    /// The metric's f and l there, and the gradient of r.
    fields: (f64, DVec3),
    grad_r: DVec3,
}

impl KsStart {
    /// The start at Kerr-Schild point `x` (M), outside the ring.
    pub fn new(kerr: Kerr, x: DVec3) -> KsStart {
        let r = kerr.ks_radius(x);
        let cos = x.z / r;
        let r_plus = kerr.horizon();
        let horizons = [r_plus, kerr.a * kerr.a / r_plus];
        // The Kerr-Schild azimuth (Kerr::spheroidal).
        let phi = x.y.atan2(x.x) - kerr.a.atan2(r);
        KsStart {
            x,
            r,
            cos,
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
            phi_rest: phi - ks_azimuth_term(kerr.a, horizons, r),
            horizons,
            fields: kerr.ks_f_l(x),
            grad_r: kerr.ks_radius_gradient(x, r),
        }
    }
}

impl KerrRay {
    /// The ray of the photon at `start` with lambda, eta, energy sign and
    /// the signs of d r / d s and d cos theta / d s; None where the closed form
    /// does not apply (the integrator takes the ray): eta = 0 (in the
    /// plane), a ray that passes within ~1e-5 rad of the axis, or anything
    /// not finite (exactly critical). A `timed` ray also gives each
    /// crossing's coordinate time ([`KerrRay::crossing_point_time`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        a: f64,
        (lambda, eta): (f64, f64),
        energy_sign: f64,
        start: &KsStart,
        (r_out, u_up): (bool, bool),
        timed: bool,
    ) -> Option<KerrRay> {
        let (r0, cos0) = (start.r, start.cos);
        let polar = match PolarMotion::new(a, lambda, eta) {
            Some(pm) if pm.u_plus < 1.0 - 1e-10 => Polar::ordinary(pm, cos0, u_up, timed),
            Some(_) => return None,
            None => Polar::vortical(a, lambda, eta, cos0, u_up)?,
        };
        let [r_plus, r_minus] = start.horizons;
        if !(r0 > r_plus) {
            return None;
        }
        let poles = [r_plus, r_minus];
        let roots = RadialRoots::new(a, lambda, eta);
        let [r1, r2, r3, r4] = roots.re;
        let case = roots.case(r_plus);
        let turning = case == RootCase::OuterTurning;
        // Between r+ and r3 (a camera near the hole): the photon turns at
        // r3, if at all, and falls in. The same forms hold with the roots
        // relabelled (r1, r2, r3, r4) -> (r2, r1, r4, r3): U = 0 at r3 and
        // r = r+ before r2.
        let inner = turning && r0 < r4 * (1.0 - 1e-12);
        if inner && !(r0 <= r3 && r2 < r_plus) {
            // Between r3 and r4 only by rounding.
            return None;
        }
        // Without spin r_- = 0 may be a root: the time's pole there has
        // no weight, r_+ stands in for it.
        let spin = a != 0.0;
        let at_poles = if spin { poles } else { [r_plus; 2] };
        let (radial, k, kappa) = match case {
            RootCase::OuterTurning if inner => Radial::outer([r2, r1, r4, r3], at_poles),
            RootCase::OuterTurning | RootCase::InnerReal => Radial::outer(roots.re, at_poles),
            RootCase::OnePair => Radial::pair(r1, r2, (roots.re[2], roots.im[2]), at_poles),
            RootCase::TwoPairs => Radial::quad(&roots, at_poles)?,
        };
        // Only rays that cross the plane need their time (two complex
        // pairs are vortical).
        let timed = timed && polar.vortical.is_none();
        if timed && matches!(radial, Radial::Quad { .. }) {
            return None;
        }
        let poles_on = spin || timed;
        let complete = if matches!(radial, Radial::Pair { .. } | Radial::Quad { .. }) {
            let kc = (1.0 - k).sqrt();
            let n = radial.n();
            let pi = |n: f64| (1.0 - n, 1.0, 1.0);
            // K, and as needed Pi of the poles, D and Pi of infinity, from
            // one sequence.
            match radial {
                Radial::Pair { inf, .. } if timed => {
                    let [k, p0, p1, d, pi_inf] = bulirsch_cel_many(
                        kc,
                        [pi(0.0), pi(n[0]), pi(n[1]), (1.0, 0.0, 1.0), pi(inf[0])],
                    );
                    Complete {
                        k,
                        pi: [p0, p1],
                        d,
                        pi_inf,
                    }
                }
                _ if poles_on => {
                    let [k, p0, p1] = bulirsch_cel_many(kc, [pi(0.0), pi(n[0]), pi(n[1])]);
                    Complete {
                        k,
                        pi: [p0, p1],
                        ..Complete::default()
                    }
                }
                _ => Complete {
                    k: bulirsch_cel(kc, 1.0, 1.0, 1.0),
                    ..Complete::default()
                },
            }
        } else {
            Complete::default()
        };
        // U = U0 + dir kappa s: through the turning point (U = 0) when the
        // photon turns, towards the end otherwise.
        let amp0 = radial.sn_cn(r0);
        let (sign0, dir) = if turning {
            (if r_out == inner { -1.0 } else { 1.0 }, 1.0)
        } else {
            (1.0, if r_out == radial.rising() { 1.0 } else { -1.0 })
        };
        let captured = inner || !turning && !r_out;
        let amp_end = if captured {
            radial.sn_cn(r_plus)
        } else {
            radial.sn_cn_at_infinity()
        };
        // An escaping ray's azimuth needs the pole integrals at infinity.
        let poles_end = spin && !captured;
        let (u0, pole0, radial_time0) = if timed {
            radial.at::<true>(amp0, k, &complete, true)
        } else {
            radial.at::<false>(amp0, k, &complete, spin)
        };
        let (u_end, pole_end, _) = radial.at::<false>(amp_end, k, &complete, poles_end);
        let dr = r_plus - r_minus;
        let (tcoef, time0) = if timed {
            let slope = 8.0 - 2.0 * a * lambda;
            let tcoef = [
                (slope * r_plus - 4.0 * a * a) / dr,
                -(slope * r_minus - 4.0 * a * a) / dr,
            ];
            let time0 = sign0 * (radial_time0 + tcoef[0] * pole0[0] + tcoef[1] * pole0[1]);
            (tcoef, time0)
        } else {
            ([0.0; 2], 0.0)
        };
        let (u0, pole0) = (sign0 * u0, pole0.map(|p| sign0 * p));
        let s_end = (u_end - u0) * dir / kappa;
        let coef = [
            a * (2.0 * r_plus - a * lambda) / (dr * kappa),
            -a * (2.0 * r_minus - a * lambda) / (dr * kappa),
        ];
        let ray = KerrRay {
            a,
            lambda,
            energy_sign,
            radial,
            k,
            kappa,
            complete,
            u0,
            dir,
            s_end,
            coef,
            pole0,
            pole_end,
            polar,
            horizons: poles,
            phi0: start.phi_rest,
            captured,
            min_r: if captured {
                r_plus
            } else if turning {
                r4
            } else {
                r0
            },
            timed,
            time0,
            tcoef,
        };
        let finite = s_end.is_finite()
            && s_end >= 0.0
            && pole0.iter().chain(&pole_end).all(|p| p.is_finite())
            && polar.psi0.is_finite()
            && polar.pi0.is_finite()
            && polar.pi_c.is_finite()
            && time0.is_finite()
            && polar.d0.is_finite()
            && complete.k.is_finite()
            && complete.pi.iter().all(|p| p.is_finite());
        finite.then_some(ray)
    }

    /// The ray traced from the Kerr-Schild point `x` (M) along coordinate
    /// velocity `v`, back in time as from a camera ([`Kerr::ks_backward`]).
    pub fn from_ks(kerr: Kerr, x: DVec3, v: DVec3, timed: bool) -> Option<KerrRay> {
        KerrRay::from_start(kerr, &KsStart::new(kerr, x), v, timed)
    }

    /// [`KerrRay::from_ks`] from a start found before.
    pub fn from_start(kerr: Kerr, start: &KsStart, v: DVec3, timed: bool) -> Option<KerrRay> {
        let x = start.x;
        let (p, e) = kerr.ks_backward_in(x, start.fields, v);
        let [_, lz, p_th, r_dot, cos_dot] =
            kerr.ks_ray_terms(x, (start.r, start.grad_r), [-e, p.x, p.y, p.z], v);
        let q = kerr.carter_q(p_th, lz, e, (start.sin, start.cos));
        KerrRay::new(
            kerr.a,
            (lz / e, q / (e * e)),
            e.signum(),
            start,
            (r_dot > 0.0, cos_dot > 0.0),
            timed,
        )
    }

    /// The photon's equatorial crossings in order (the image order n = 0,
    /// 1, 2, ...), before it ends.
    pub fn crossings(&self) -> impl Iterator<Item = Crossing> + '_ {
        let p = &self.polar;
        let half = 2.0 * p.big_k;
        // A start on the plane is not a crossing.
        let first = (p.psi0 / half + 1e-12).floor() + 1.0;
        (0..)
            .map(move |i| {
                let j = first + i as f64;
                (j, (j * half - p.psi0) / p.scale)
            })
            // Vortical motion stays in one hemisphere.
            .take_while(move |&(_, s)| s < self.s_end && p.vortical.is_none())
            .map(move |(j, s)| {
                // |U| stays below K outside a complex pair, below 2K with
                // one, where sn >= 0 (two pairs are vortical: no crossings).
                let u = self.u0 + self.dir * self.kappa * s;
                let (sn, cn, _) = super::elliptic::jacobi_sn_cn_dn(u, self.k);
                Crossing {
                    r: self.radial.radius(sn, cn),
                    sn,
                    cn,
                    j,
                }
            })
    }

    /// The Boyer-Lindquist azimuth where the radial pole integrals are
    /// `pole` and the polar integral of 1 / sin^2 theta from the start is
    /// `g_phi` (Kerr-Schild's at radius r adds [`ks_azimuth_term`]).
    fn bl_azimuth(&self, pole: [f64; 2], g_phi: f64) -> f64 {
        let radial = (0..2)
            .map(|i| self.coef[i] * (pole[i] - self.pole0[i]))
            .sum::<f64>()
            * self.dir;
        self.phi0 + self.energy_sign * (radial + self.lambda * g_phi)
    }

    /// The Kerr-Schild Cartesian point (M) of a crossing.
    pub fn crossing_point(&self, c: &Crossing) -> DVec3 {
        self.untimed_point(c).0
    }

    /// [`KerrRay::point`] without the time's integrals.
    fn untimed_point(&self, c: &Crossing) -> (DVec3, f64) {
        let pole = if self.a == 0.0 {
            [0.0; 2]
        } else {
            self.radial
                .at::<false>(Amp::new(c.sn, c.cn), self.k, &self.complete, true)
                .1
        };
        self.point(c, pole)
    }

    /// The Kerr-Schild Cartesian point (M) of a crossing, its
    /// Boyer-Lindquist azimuth and the Boyer-Lindquist coordinate time (M)
    /// the light takes from it to the start, of a ray made `timed` (NaN
    /// otherwise). With M = 1, dt/ds =
    /// E (r^2 + 2 r + 4 + ((8 - 2 a lambda) r - 4 a^2) / Delta + a^2 cos^2
    /// theta): the radial part is the integrals of r and r^2 and the time's
    /// horizon poles at the crossing's amplitude, the polar part D at the
    /// j-th node, 2 j D(m).
    pub fn crossing_point_time(&self, c: &Crossing) -> CrossingPoint {
        if !self.timed {
            let (x, phi) = self.untimed_point(c);
            return CrossingPoint {
                x,
                phi,
                t: f64::NAN,
            };
        }
        let (_, pole, radial_time) =
            self.radial
                .at::<true>(Amp::new(c.sn, c.cn), self.k, &self.complete, true);
        let radial = self.dir
            * (radial_time + self.tcoef[0] * pole[0] + self.tcoef[1] * pole[1] - self.time0)
            / self.kappa;
        let p = &self.polar;
        let polar = self.a * self.a * p.u_plus / p.scale * (2.0 * c.j * p.d_c - p.d0);
        let (x, phi) = self.point(c, pole);
        CrossingPoint {
            x,
            phi,
            t: -self.energy_sign * (radial + polar),
        }
    }

    /// A crossing's Kerr-Schild Cartesian point and Boyer-Lindquist
    /// azimuth, with its radial pole integrals `pole`.
    fn point(&self, c: &Crossing, pole: [f64; 2]) -> (DVec3, f64) {
        let p = &self.polar;
        // At the j-th node am = j pi exactly.
        let g_phi = (2.0 * c.j * p.pi_c - p.pi0) * p.g_scale;
        let bl = self.bl_azimuth(pole, g_phi);
        let phi = bl + ks_azimuth_term(self.a, self.horizons, c.r);
        let (s, co) = phi.sin_cos();
        (
            DVec3::new(c.r * co - self.a * s, c.r * s + self.a * co, 0.0),
            bl,
        )
    }

    /// The direction at infinity of an escaping ray (unit, Cartesian).
    pub fn escape_direction(&self) -> DVec3 {
        let p = &self.polar;
        let psi = p.psi0 + p.scale * self.s_end;
        // psi = 2K j + psi_r, |psi_r| <= K: am = j pi + am(psi_r).
        let j = (psi / (2.0 * p.big_k)).round();
        let (sn, cn, _) = super::elliptic::jacobi_sn_cn_dn(psi - 2.0 * j * p.big_k, p.m);
        let (_, [pi_r]) = super::elliptic::legendre_f_pi(sn, cn, p.m, [p.n]);
        let cos_th = match p.vortical {
            None => {
                let sign = if j % 2.0 == 0.0 { 1.0 } else { -1.0 };
                p.u_plus.sqrt() * sn * sign
            }
            Some((u_minus, hemisphere)) => {
                hemisphere * (p.u_plus - (p.u_plus - u_minus) * sn * sn).max(0.0).sqrt()
            }
        };
        let g_phi = (2.0 * j * p.pi_c + pi_r - p.pi0) * p.g_scale;
        // Kerr-Schild's azimuth is Boyer-Lindquist's at infinity.
        let phi = self.bl_azimuth(self.pole_end, g_phi);
        let sin_th = (1.0 - cos_th * cos_th).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        DVec3::new(sin_th * c, sin_th * s, cos_th)
    }

    /// A bound below the radius (M) all along the ray: its turning point,
    /// or the nearer end.
    pub fn min_radius(&self) -> f64 {
        self.min_r
    }

    /// The photon's lambda = L_z / E.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The Mino time from the start to the end (infinity or the horizon).
    pub fn mino_to_end(&self) -> f64 {
        self.s_end
    }
}

/// The Kerr-Schild azimuth's radial term, the integral of a / Delta dr
/// (its difference between two radii; 0 at infinity): phi_KS = phi_BL +
/// this at r (M), outside the outer horizon `r_plus`.
pub(crate) fn ks_azimuth_term(a: f64, [r_plus, r_minus]: [f64; 2], r: f64) -> f64 {
    if a == 0.0 || r.is_infinite() {
        return 0.0;
    }
    a / (r_plus - r_minus) * ((r - r_plus) / (r - r_minus)).ln()
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
            // The Mino time is U / kappa, U = F(am) from r4.
            let roots = RadialRoots::new(a, lambda, eta);
            let r_plus = Kerr::new(a).horizon();
            let (radial, k, kappa) = Radial::outer(roots.re, [r_plus, a * a / r_plus]);
            let mino = |amp| radial.at::<false>(amp, k, &Complete::default(), false).0 / kappa;
            let got_to = mino(radial.sn_cn(r0));
            let got_beyond = mino(radial.sn_cn_at_infinity()) - got_to;
            assert!(
                (got_to - to_r0).abs() < 1e-14 && (got_beyond - beyond).abs() < 1e-14,
                "a {a} lambda {lambda} eta {eta} r {r0}: {got_to} {got_beyond}"
            );
        }
    }

    #[test]
    fn the_time_integral_is_the_radial_quadrature() {
        // The coordinate time's polynomial part, the integral of (r^2 + 2 r
        // + 4) dr / sqrt(R): mpmath 1.3 quad at 40 digits, from the turning
        // point r4 (as t^2 = r - r4) for four real roots, between two radii
        // for one complex pair (a = 0: r = 0 is a root).
        for (a, lambda, eta, from, to, want) in [
            (0.9, 2.0, 20.0, None, 10.0, 16.072_968_601_379_58),
            (0.5, 6.0, 30.0, None, 50.0, 57.058_987_198_621_83),
            (0.9, 1.0, 5.0, Some(3.0), 10.0, 11.021_127_725_499_25),
            (0.0, 1.0, 12.0, Some(2.5), 40.0, 47.294_446_716_275_95),
        ] {
            let roots = RadialRoots::new(a, lambda, eta);
            let r_plus = Kerr::new(a).horizon();
            let poles = [r_plus, r_plus.max(a * a / r_plus)];
            let (radial, k, kappa) = match from {
                None => Radial::outer(roots.re, poles),
                Some(_) => {
                    Radial::pair(roots.re[0], roots.re[1], (roots.re[2], roots.im[2]), poles)
                }
            };
            let kc = (1.0 - k).sqrt();
            let complete = match radial {
                Radial::Pair { n, inf, .. } => Complete {
                    k: bulirsch_cel(kc, 1.0, 1.0, 1.0),
                    pi: n.map(|n| bulirsch_cel(kc, 1.0 - n, 1.0, 1.0)),
                    d: bulirsch_cel(kc, 1.0, 0.0, 1.0),
                    pi_inf: bulirsch_cel(kc, 1.0 - inf[0], 1.0, 1.0),
                },
                _ => Complete::default(),
            };
            let time = |r: f64| radial.at::<true>(radial.sn_cn(r), k, &complete, true).2 / kappa;
            let got = time(to) - from.map_or(0.0, time);
            assert!(
                (got - want).abs() < 1e-13 * want,
                "a {a} lambda {lambda} eta {eta}: {got} vs {want}"
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
            // psi / scale from the equator moving up, K / scale.
            let polar = Polar::ordinary(
                PolarMotion::new(a, lambda, eta).unwrap(),
                f64::cos(theta),
                true,
                true,
            );
            let got = polar.psi0 / polar.scale;
            let got_quarter = polar.big_k / polar.scale;
            assert!(
                (got - to_equator).abs() < 1e-14 && (got_quarter - quarter).abs() < 1e-14,
                "a {a} lambda {lambda} eta {eta}: {got}, {got_quarter}"
            );
        }
        // Without spin the swing is a great circle's: Theta = eta -
        // lambda^2 cot^2 theta gives asin(cos theta / sqrt(u_+)) /
        // sqrt(eta + lambda^2), u_+ = eta / (eta + lambda^2).
        let (lambda, eta) = (3.0, 16.0);
        let motion = PolarMotion::new(0.0, lambda, eta).unwrap();
        let l2 = eta + lambda * lambda;
        assert!((motion.u_plus - eta / l2).abs() < 1e-16);
        for theta in [0.7f64, 1.2, 2.0] {
            let want = (theta.cos() / motion.u_plus.sqrt()).asin() / l2.sqrt();
            let polar = Polar::ordinary(motion, theta.cos(), true, false);
            assert!((polar.psi0 / polar.scale - want).abs() < 1e-15);
            assert!(
                (polar.big_k / polar.scale - std::f64::consts::FRAC_PI_2 / l2.sqrt()).abs() < 1e-15
            );
        }
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
