//! The radial motion of a photon in Jacobi's functions of Mino time: its
//! amplitude at a radius, the radius at an amplitude, and the Mino time
//! and the azimuth's (and time's) radial integrals there.

use super::roots::RadialRoots;
use super::times;
use crate::physics::dual::{Cel, D2, Real};

/// The radial motion of a photon between the outer horizon and infinity
/// in Jacobi's functions of U = kappa X, X the Mino time from a reference
/// root at which r(U) is even in U (so that one formula carries the photon
/// through its turning point), with the integrals of dX / (r - p) for the
/// two poles p = r_+, r_- of the azimuth's radial part. Written in
/// [`Real`]; what only the coordinate time uses is kept as values.
#[derive(Clone, Copy, Debug)]
pub(super) enum Radial<T = f64> {
    /// Four real roots, the photon at r >= r4 (turning there if r4 > r_+;
    /// Gralla and Lupsasca, eq. B35-B37), or with the roots relabelled
    /// between r_+ and r3: sn^2(U | k) = (r - r4) r31 / ((r - r3) r41), k =
    /// r32 r41 / (r31 r42), kappa = sqrt(r31 r42) / 2. There 1 / (r - p) =
    /// (1 - c sn^2) / ((r4 - p) (1 - n sn^2)), c = r41 / r31, n = (r3 - p)
    /// r41 / ((r4 - p) r31): its integral is U / (r3 - p) + (r3 - r4) /
    /// ((r4 - p) (r3 - p)) Pi(n; am U | k), over kappa.
    Outer {
        r3: T,
        r4: T,
        r31: T,
        r41: T,
        /// n, 1 / (r3 - p) and (r3 - r4) / ((r4 - p) (r3 - p)) per pole.
        n: [T; 2],
        linear: [T; 2],
        third: [T; 2],
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
        r1: T,
        r2: T,
        big_a: T,
        big_b: T,
        /// Per pole: n, alpha, (A + B) / D1, -2 A B r21 / (D0 D1), c, d.
        n: [T; 2],
        alpha: [T; 2],
        linear: [T; 2],
        third: [T; 2],
        c: [T; 2],
        d: [T; 2],
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
        s1: T,
        s2: T,
        /// sqrt(c1), sqrt(d1), and theta at infinity.
        sc1: T,
        sd1: T,
        theta_inf: T,
        /// Per pole: n, the coefficients of U and of Pi, the odd part's
        /// coefficient, sqrt(G), sqrt(H) (H = G - k alpha^2) and its log at
        /// theta = 0.
        n: [T; 2],
        lin: [T; 2],
        pi: [T; 2],
        odd: [T; 2],
        sg: [T; 2],
        sh: [T; 2],
        l1: [T; 2],
    },
}

/// A radial amplitude: its sine and cosine and, for two complex pairs, the
/// whole half turns before it (the amplitude is j pi + atan2(sn, cn), cn
/// >= 0 there).
#[derive(Clone, Copy, Debug)]
pub(super) struct Amp<T = f64> {
    pub(super) sn: T,
    pub(super) cn: T,
    pub(super) j: f64,
}

impl<T: Real> Amp<T> {
    pub(super) fn new(sn: T, cn: T) -> Amp<T> {
        Amp { sn, cn, j: 0.0 }
    }

    /// The amplitude `theta`, as whole half turns and a remainder.
    pub(super) fn of_angle(theta: T) -> Amp<T> {
        let j = (theta.re() / std::f64::consts::PI).round();
        let (sn, cn) = (theta - j * std::f64::consts::PI).sin_cos();
        Amp { sn, cn, j }
    }
}

impl<T: Real> Radial<T> {
    pub(super) fn outer(roots: [T; 4], poles: [f64; 2]) -> (Radial<T>, T, T) {
        let [r1, r2, r3, r4] = roots;
        let (r31, r41, r32, r42) = (r3 - r1, r4 - r1, r3 - r2, r4 - r2);
        let radial = Radial::Outer {
            r3,
            r4,
            r31,
            r41,
            n: poles.map(|p| (r3 - p) * r41 / ((r4 - p) * r31)),
            linear: poles.map(|p| (r3 - p).recip()),
            third: poles.map(|p| (r3 - r4) / ((r4 - p) * (r3 - p))),
            big_n: (r41 / r31).re(),
            r43: (r4 - r3).re(),
        };
        (radial, r32 * r41 / (r31 * r42), (r31 * r42).sqrt() * 0.5)
    }

    pub(super) fn pair(r1: T, r2: T, (re, im): (T, T), poles: [f64; 2]) -> (Radial<T>, T, T) {
        let big_a = (re - r2).hypot(im);
        let big_b = (re - r1).hypot(im);
        let r21 = r2 - r1;
        let sum = big_a + big_b;
        let k = (sum * sum - r21 * r21) / (big_a * 4.0 * big_b);
        let d0 = poles.map(|p| big_b * (r2 - p) - big_a * (r1 - p));
        let d1 = poles.map(|p| big_b * (r2 - p) + big_a * (r1 - p));
        let alpha: [T; 2] = std::array::from_fn(|i| d1[i] / d0[i]);
        // The time's, as values.
        let (a, b, kv) = (big_a.re(), big_b.re(), k.re());
        let al = (b + a) / (b - a);
        let inf = [
            al * al / (al * al - 1.0),
            al,
            1.0 - al * al,
            kv + (1.0 - kv) * al * al,
        ];
        let r_lin = [
            (b * r2.re() + a * r1.re()) / (b + a),
            2.0 * a * b * r21.re() / ((b + a) * (b - a)),
        ];
        let radial = Radial::Pair {
            r1,
            r2,
            big_a,
            big_b,
            n: alpha.map(|al| al * al / (al * al - 1.0)),
            alpha,
            linear: d1.map(|d| (big_a + big_b) / d),
            third: std::array::from_fn(|i| -(big_a * 2.0) * big_b * r21 / (d0[i] * d1[i])),
            c: alpha.map(|al| T::c(1.0) - al * al),
            d: alpha.map(|al| k + (T::c(1.0) - k) * al * al),
            inf,
            r_lin,
        };
        (radial, k, (big_a * big_b).sqrt())
    }

    pub(super) fn quad(roots: &RadialRoots<T>, poles: [f64; 2]) -> Option<(Radial<T>, T, T)> {
        let (a1, b1) = (roots.re[0], roots.im[0].abs());
        let (a2, b2) = (roots.re[2], roots.im[2].abs());
        let sum = (a1 - a2) * (a1 - a2) + b1 * b1 + b2 * b2;
        let disc = (sum * sum - b1 * 4.0 * b1 * b2 * b2).max(0.0);
        let l2 = (sum + disc.sqrt()) / (b2 * 2.0 * b2);
        let l1 = b1 * b1 / (b2 * b2 * l2);
        if !(l1.re() < 1.0 - 1e-12 && l2.re() > 1.0 + 1e-12) {
            return None;
        }
        let one = T::c(1.0);
        let (s1, s2) = ((a1 - l1 * a2) / (one - l1), (a1 - l2 * a2) / (one - l2));
        let span = l2 - l1;
        let (c1, d1, d2) = (
            l2 * (one - l1) / span,
            l1 * (l2 - 1.0) / span,
            (l2 - 1.0) / span,
        );
        let k = one - l1 / l2;
        let t = (d1 / c1).sqrt();
        let alpha = poles.map(|p| s1 - p);
        let gamma = poles.map(|p| (s2 - p) * t);
        let g: [T; 2] = std::array::from_fn(|i| alpha[i] * alpha[i] + gamma[i] * gamma[i]);
        let h: [T; 2] = std::array::from_fn(|i| g[i] - k * alpha[i] * alpha[i]);
        let sg = g.map(T::sqrt);
        let sh = h.map(T::sqrt);
        let log = |i: usize, w: T| ((sg[i] * w - sh[i]) / (sg[i] * w + sh[i])).abs().ln();
        let radial = Radial::Quad {
            s1,
            s2,
            sc1: c1.sqrt(),
            sd1: d1.sqrt(),
            theta_inf: c1.sqrt().atan2(d1.sqrt()),
            n: std::array::from_fn(|i| g[i] / (alpha[i] * alpha[i])),
            lin: std::array::from_fn(|i| (alpha[i] + t * gamma[i]) / g[i]),
            pi: std::array::from_fn(|i| alpha[i].recip() - (alpha[i] + t * gamma[i]) / g[i]),
            odd: std::array::from_fn(|i| -(gamma[i] - t * alpha[i]) / (sg[i] * 2.0 * sh[i])),
            sg,
            sh,
            l1: std::array::from_fn(|i| log(i, one)),
        };
        Some((radial, k, (c1 * d2).sqrt() * (s1 - s2).abs()))
    }

    /// Whether U grows with r.
    pub(super) fn rising(&self) -> bool {
        match *self {
            Radial::Quad { s1, s2, .. } => s1.re() > s2.re(),
            _ => true,
        }
    }

    /// The amplitude at radius `r` (U >= 0 there but for two complex
    /// pairs).
    pub(super) fn sn_cn(&self, r: f64) -> Amp<T> {
        let one = T::c(1.0);
        let r = T::c(r);
        match *self {
            Radial::Outer {
                r3, r4, r31, r41, ..
            } => {
                let s2 = ((r - r4) * r31 / ((r - r3) * r41)).clamp(0.0, 1.0);
                Amp::new(s2.sqrt(), (one - s2).sqrt())
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
                Amp::new((one - c * c).sqrt(), c)
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
                let d = (raw.re() - theta_inf.re() + pi).rem_euclid(std::f64::consts::TAU) - pi;
                Amp::of_angle(T::with(theta_inf.re() + d, raw.rates()))
            }
        }
    }

    /// The amplitude at infinity.
    pub(super) fn sn_cn_at_infinity(&self) -> Amp<T> {
        match *self {
            Radial::Outer { r31, r41, .. } => {
                Amp::new((r31 / r41).sqrt(), ((r41 - r31) / r41).sqrt())
            }
            Radial::Pair { big_a, big_b, .. } => {
                let c = (big_a - big_b) / (big_a + big_b);
                Amp::new((T::c(1.0) - c * c).sqrt(), c)
            }
            Radial::Quad { theta_inf, .. } => Amp::of_angle(theta_inf),
        }
    }

    /// The radius at an amplitude of sine `sn`, cosine `cn`.
    pub(super) fn radius(&self, sn: T, cn: T) -> T {
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
    pub(super) fn integrals<const TIME: bool>(&self, amp: Amp<T>, k: T, poles: bool) -> Ints<T> {
        let (n, n_inf) = match *self {
            Radial::Outer { n, big_n, .. } => (n, big_n),
            Radial::Pair { n, inf, .. } => (n, inf[0]),
            Radial::Quad { n, .. } => (n, 0.0),
        };
        // The Legendre forms take cn >= 0: one complex pair reflects past
        // a quarter period.
        let (s, c) = (amp.sn, amp.cn.abs());
        if TIME {
            let (f, [j0, j1, d, jn]) =
                T::legendre_f_j(s, c, k, [n[0], n[1], T::c(0.0), T::c(n_inf)]);
            Ints {
                f,
                j: [j0, j1],
                d: d.re(),
                jn: jn.re(),
            }
        } else if poles {
            let (f, j) = T::legendre_f_j(s, c, k, n);
            Ints {
                f,
                j,
                d: 0.0,
                jn: 0.0,
            }
        } else {
            Ints {
                f: T::legendre_f_j(s, c, k, []).0,
                j: [T::c(0.0); 2],
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
    /// whose vortical rays cross no plane: NaN), as a value.
    pub(super) fn at<const TIME: bool>(
        &self,
        amp: Amp<T>,
        k: T,
        complete: &Complete<T>,
        poles: bool,
    ) -> (T, [T; 2], f64) {
        let ints = self.integrals::<TIME>(amp, k, poles);
        self.at_ints::<TIME>(amp, k, complete, poles, ints)
    }

    /// [`Radial::at`] with the integrals at the amplitude found before.
    pub(super) fn at_ints<const TIME: bool>(
        &self,
        amp: Amp<T>,
        k: T,
        complete: &Complete<T>,
        poles: bool,
        ints: Ints<T>,
    ) -> (T, [T; 2], f64) {
        let Amp { sn, cn, j } = amp;
        let zero = [T::c(0.0); 2];
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
                let p: [T; 2] = std::array::from_fn(|i| f + n[i] * ints.j[i]);
                let u = f + complete.k * (2.0 * j);
                let time = if TIME { f64::NAN } else { 0.0 };
                if !poles {
                    return (u, zero, time);
                }
                let dn = (T::c(1.0) - k * sn * sn).sqrt();
                (
                    u,
                    std::array::from_fn(|i| {
                        let big_pi = p[i] + complete.pi[i] * (2.0 * j);
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
                    zero
                };
                if !TIME {
                    return (u, pole, 0.0);
                }
                let time = times::outer_time(
                    (sn.re(), cn.re()),
                    k.re(),
                    (u.re(), d, jn),
                    (r3.re(), r43, big_n),
                );
                (u, pole, time)
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
                let pi: [T; 2] = std::array::from_fn(|i| f + n[i] * jp[i]);
                let pi_inf = f.re() + inf[0] * jn;
                // Past a quarter period by reflection: F(pi - phi) = 2K -
                // F(phi), likewise Pi and D.
                let (u, pi, dd, pi_inf) = if cn.re() < 0.0 {
                    (
                        complete.k * 2.0 - f,
                        std::array::from_fn(|i| complete.pi[i] * 2.0 - pi[i]),
                        2.0 * complete.d - dd,
                        2.0 * complete.pi_inf - pi_inf,
                    )
                } else {
                    (f, pi, dd, pi_inf)
                };
                if !poles {
                    return (u, zero, 0.0);
                }
                let w = sn / (T::c(1.0) - k * sn * sn).sqrt();
                let first = |pi: T, alpha: T, c: T, d: T| pair_first(w, pi, alpha, c, d);
                let pole = std::array::from_fn(|i| {
                    linear[i] * u + third[i] * first(pi[i], alpha[i], c[i], d[i])
                });
                if !TIME {
                    return (u, pole, 0.0);
                }
                let r1 = pair_first(w.re(), pi_inf, inf[1], inf[2], inf[3]);
                let time =
                    times::pair_time((sn.re(), cn.re()), k.re(), (u.re(), dd, r1), inf[1], r_lin);
                (u, pole, time)
            }
        }
    }

    /// The complete integrals ([`Complete`]) a photon with a complex root
    /// pair needs at parameter `k`: K, with `poles_on` Pi of the poles,
    /// and for a `timed` ray with one pair D and Pi of infinity.
    pub(super) fn complete(&self, k: T, timed: bool, poles_on: bool) -> Complete<T> {
        if !matches!(self, Radial::Pair { .. } | Radial::Quad { .. }) {
            return Complete::none();
        }
        let n = self.n();
        let (zero, pi) = (Cel::Pi(T::c(0.0)), Cel::Pi);
        // K, and as needed Pi of the poles, D and Pi of infinity, from one
        // sequence.
        match *self {
            Radial::Pair { inf, .. } if timed => {
                let [k, p0, p1, d, pi_inf] =
                    T::cel_many(k, [zero, pi(n[0]), pi(n[1]), Cel::D, pi(T::c(inf[0]))]);
                Complete {
                    k,
                    pi: [p0, p1],
                    d: d.re(),
                    pi_inf: pi_inf.re(),
                }
            }
            _ if poles_on => {
                let [k, p0, p1] = T::cel_many(k, [zero, pi(n[0]), pi(n[1])]);
                Complete {
                    k,
                    pi: [p0, p1],
                    ..Complete::none()
                }
            }
            _ => Complete {
                k: T::cel_many(k, [zero])[0],
                ..Complete::none()
            },
        }
    }

    pub(super) fn n(&self) -> [T; 2] {
        match *self {
            Radial::Outer { n, .. } | Radial::Pair { n, .. } | Radial::Quad { n, .. } => n,
        }
    }
}

/// The integral of 1 / (1 + alpha cn) for one complex root pair at w =
/// sn / dn: Pi / c - alpha W ([`Radial::Pair`]).
fn pair_first<T: Real>(w: T, pi: T, alpha: T, c: T, d: T) -> T {
    let odd = if c.re() > 0.0 {
        (w * (d / c).sqrt()).atan() / (c * d).sqrt()
    } else {
        // c + d w^2 = -(|c| - d w^2): minus atanh, its principal value
        // past the pole.
        let z = w * (d / -c).sqrt();
        ((T::c(1.0) + z) / (T::c(1.0) - z)).abs().ln() * -0.5 / (-c * d).sqrt()
    };
    pi / c - alpha * odd
}

/// Complete integrals K(k) and Pi(n_i | k) of the radial poles (only a
/// photon with a complex root pair needs them), and for the time with one
/// pair D(k) and Pi of the pole at infinity (values).
#[derive(Clone, Copy, Debug)]
pub(super) struct Complete<T = f64> {
    pub(super) k: T,
    pub(super) pi: [T; 2],
    pub(super) d: f64,
    pub(super) pi_inf: f64,
}

impl<T: Real> Complete<T> {
    /// None of them (a photon with four real roots).
    pub(super) fn none() -> Complete<T> {
        Complete {
            k: T::c(0.0),
            pi: [T::c(0.0); 2],
            d: 0.0,
            pi_inf: 0.0,
        }
    }
}

/// Elliptic integrals at a radial amplitude ([`Radial::integrals`]): F,
/// J = (Pi - F) / n of the two poles, and (values) D and J of the pole at
/// infinity.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ints<T = f64> {
    pub(super) f: T,
    pub(super) j: [T; 2],
    pub(super) d: f64,
    pub(super) jn: f64,
}

impl Radial<D2> {
    /// The motion without its rates.
    pub(super) fn value(&self) -> Radial {
        let v = |x: [D2; 2]| x.map(|x| x.v);
        match *self {
            Radial::Outer {
                r3,
                r4,
                r31,
                r41,
                n,
                linear,
                third,
                big_n,
                r43,
            } => Radial::Outer {
                r3: r3.v,
                r4: r4.v,
                r31: r31.v,
                r41: r41.v,
                n: v(n),
                linear: v(linear),
                third: v(third),
                big_n,
                r43,
            },
            Radial::Pair {
                r1,
                r2,
                big_a,
                big_b,
                n,
                alpha,
                linear,
                third,
                c,
                d,
                inf,
                r_lin,
            } => Radial::Pair {
                r1: r1.v,
                r2: r2.v,
                big_a: big_a.v,
                big_b: big_b.v,
                n: v(n),
                alpha: v(alpha),
                linear: v(linear),
                third: v(third),
                c: v(c),
                d: v(d),
                inf,
                r_lin,
            },
            Radial::Quad {
                s1,
                s2,
                sc1,
                sd1,
                theta_inf,
                n,
                lin,
                pi,
                odd,
                sg,
                sh,
                l1,
            } => Radial::Quad {
                s1: s1.v,
                s2: s2.v,
                sc1: sc1.v,
                sd1: sd1.v,
                theta_inf: theta_inf.v,
                n: v(n),
                lin: v(lin),
                pi: v(pi),
                odd: v(odd),
                sg: v(sg),
                sh: v(sh),
                l1: v(l1),
            },
        }
    }
}

impl Complete<D2> {
    /// The integrals without their rates.
    pub(super) fn value(&self) -> Complete {
        Complete {
            k: self.k.v,
            pi: self.pi.map(|x| x.v),
            d: self.d,
            pi_inf: self.pi_inf,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::kerr::Kerr;

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
            let mino = |amp| radial.at::<false>(amp, k, &Complete::none(), false).0 / kappa;
            let got_to = mino(radial.sn_cn(r0));
            let got_beyond = mino(radial.sn_cn_at_infinity()) - got_to;
            assert!(
                (got_to - to_r0).abs() < 1e-14 && (got_beyond - beyond).abs() < 1e-14,
                "a {a} lambda {lambda} eta {eta} r {r0}: {got_to} {got_beyond}"
            );
        }
    }
}
