//! Numbers that carry their derivatives, for closed forms whose rates a
//! footprint needs: [`Real`] is what the Kerr closed form is written in,
//! f64 for a ray and [`D2`] (a value and its derivatives along the two
//! pixel axes) for a ray with its rates. Arithmetic carries the rates by
//! the chain rule; the elliptic integrals and Jacobi's functions carry
//! theirs by their closed-form derivatives in amplitude, parameter and
//! characteristic (DLMF 19.4.1-19.4.4, 22.13 with 19.4), which need only
//! the integral of the second kind beside the values, so a rated ray costs
//! its values and a little more rather than a second ray.

use crate::physics::elliptic::{bulirsch_cel_many, jacobi_sn_cn_dn, legendre_f_d_j, legendre_f_j};
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A complete elliptic integral of parameter m ([`Real::cel_many`]).
#[derive(Clone, Copy, Debug)]
pub enum Cel<T> {
    /// Pi(n | m) (K(m) at n = 0).
    Pi(T),
    /// D(m) = (K - E) / m, for the coordinate time only: its rate is not
    /// carried (a rated ray's time is its value).
    D,
}

/// A real number as the closed forms use it: f64, or [`D2`] with its
/// rates.
pub trait Real:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// Whether it carries rates.
    const RATED: bool;
    /// A constant (no rates).
    fn c(v: f64) -> Self;
    /// The value.
    fn re(self) -> f64;
    /// The value with rates `d` (dropped by f64).
    fn with(v: f64, d: [f64; 2]) -> Self;
    /// The rates (none for f64).
    fn rates(self) -> [f64; 2];
    fn sqrt(self) -> Self;
    fn ln(self) -> Self;
    fn atan(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn recip(self) -> Self {
        Self::c(1.0) / self
    }
    fn abs(self) -> Self {
        if self.re() < 0.0 { -self } else { self }
    }
    fn hypot(self, y: Self) -> Self {
        (self * self + y * y).sqrt()
    }
    /// The larger by value (its rates with it).
    fn max(self, y: f64) -> Self {
        if self.re() >= y { self } else { Self::c(y) }
    }
    fn clamp(self, lo: f64, hi: f64) -> Self {
        if self.re() < lo {
            Self::c(lo)
        } else if self.re() > hi {
            Self::c(hi)
        } else {
            self
        }
    }
    /// Legendre's F(phi | m) and J_i = (Pi(n_i; phi | m) - F) / n_i at the
    /// amplitude of sine `s`, cosine `c` >= 0 ([`legendre_f_j`]).
    fn legendre_f_j<const N: usize>(s: Self, c: Self, m: Self, n: [Self; N]) -> (Self, [Self; N]);
    /// Complete integrals of parameter m < 1 from one Gauss sequence
    /// ([`bulirsch_cel_many`]).
    fn cel_many<const N: usize>(m: Self, what: [Cel<Self>; N]) -> [Self; N];
    /// Jacobi's sn, cn and dn of (u | m), m < 1.
    fn jacobi_sn_cn_dn(u: Self, m: Self) -> (Self, Self, Self);
    /// Jacobi's sn, cn and dn of (u | m), whose values `jac` are known,
    /// and Legendre's F and J_i at the amplitude of sine sn and cosine |cn|
    /// ([`Real::legendre_f_j`]).
    fn jacobi_legendre<const N: usize>(
        u: Self,
        m: Self,
        jac: (f64, f64, f64),
        n: [Self; N],
    ) -> ((Self, Self, Self), (Self, [Self; N]));
}

/// Bulirsch's (p, a, b) of a complete integral.
fn cel_pab(c: Cel<f64>) -> (f64, f64, f64) {
    match c {
        Cel::Pi(n) => (1.0 - n, 1.0, 1.0),
        Cel::D => (1.0, 0.0, 1.0),
    }
}

impl Real for f64 {
    const RATED: bool = false;
    #[inline]
    fn c(v: f64) -> f64 {
        v
    }
    #[inline]
    fn re(self) -> f64 {
        self
    }
    #[inline]
    fn with(v: f64, _: [f64; 2]) -> f64 {
        v
    }
    #[inline]
    fn rates(self) -> [f64; 2] {
        [0.0; 2]
    }
    #[inline]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline]
    fn ln(self) -> f64 {
        f64::ln(self)
    }
    #[inline]
    fn atan(self) -> f64 {
        f64::atan(self)
    }
    #[inline]
    fn atan2(self, x: f64) -> f64 {
        f64::atan2(self, x)
    }
    #[inline]
    fn sin_cos(self) -> (f64, f64) {
        f64::sin_cos(self)
    }
    #[inline]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline]
    fn hypot(self, y: f64) -> f64 {
        f64::hypot(self, y)
    }
    #[inline]
    fn max(self, y: f64) -> f64 {
        f64::max(self, y)
    }
    #[inline]
    fn clamp(self, lo: f64, hi: f64) -> f64 {
        f64::clamp(self, lo, hi)
    }
    #[inline]
    fn legendre_f_j<const N: usize>(s: f64, c: f64, m: f64, n: [f64; N]) -> (f64, [f64; N]) {
        legendre_f_j(s, c, m, n)
    }
    #[inline]
    fn cel_many<const N: usize>(m: f64, what: [Cel<f64>; N]) -> [f64; N] {
        bulirsch_cel_many((1.0 - m).sqrt(), what.map(cel_pab))
    }
    #[inline]
    fn jacobi_sn_cn_dn(u: f64, m: f64) -> (f64, f64, f64) {
        jacobi_sn_cn_dn(u, m)
    }
    #[inline]
    fn jacobi_legendre<const N: usize>(
        _: f64,
        m: f64,
        jac: (f64, f64, f64),
        n: [f64; N],
    ) -> ((f64, f64, f64), (f64, [f64; N])) {
        (jac, legendre_f_j(jac.0, jac.1.abs(), m, n))
    }
}

/// A value and its derivatives along two directions (the pixel's axes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct D2 {
    pub v: f64,
    pub d: [f64; 2],
}

impl D2 {
    /// Value `v` whose rates are `k` times those of `x` plus `l` times
    /// those of `y` (the chain rule's step).
    #[inline]
    fn chain(v: f64, x: D2, k: f64, y: D2, l: f64) -> D2 {
        D2 {
            v,
            d: [k * x.d[0] + l * y.d[0], k * x.d[1] + l * y.d[1]],
        }
    }

    /// Value `v` whose rates are `k` times those of `x`.
    #[inline]
    fn scaled(v: f64, x: D2, k: f64) -> D2 {
        D2 {
            v,
            d: [k * x.d[0], k * x.d[1]],
        }
    }
}

impl Add for D2 {
    type Output = D2;
    #[inline]
    fn add(self, y: D2) -> D2 {
        D2 {
            v: self.v + y.v,
            d: [self.d[0] + y.d[0], self.d[1] + y.d[1]],
        }
    }
}

impl Sub for D2 {
    type Output = D2;
    #[inline]
    fn sub(self, y: D2) -> D2 {
        D2 {
            v: self.v - y.v,
            d: [self.d[0] - y.d[0], self.d[1] - y.d[1]],
        }
    }
}

impl Mul for D2 {
    type Output = D2;
    #[inline]
    fn mul(self, y: D2) -> D2 {
        D2::chain(self.v * y.v, self, y.v, y, self.v)
    }
}

impl Div for D2 {
    type Output = D2;
    #[inline]
    fn div(self, y: D2) -> D2 {
        let q = self.v / y.v;
        D2::chain(q, self, 1.0 / y.v, y, -q / y.v)
    }
}

impl Neg for D2 {
    type Output = D2;
    #[inline]
    fn neg(self) -> D2 {
        D2 {
            v: -self.v,
            d: [-self.d[0], -self.d[1]],
        }
    }
}

impl Add<f64> for D2 {
    type Output = D2;
    #[inline]
    fn add(self, y: f64) -> D2 {
        D2 {
            v: self.v + y,
            d: self.d,
        }
    }
}

impl Sub<f64> for D2 {
    type Output = D2;
    #[inline]
    fn sub(self, y: f64) -> D2 {
        D2 {
            v: self.v - y,
            d: self.d,
        }
    }
}

impl Mul<f64> for D2 {
    type Output = D2;
    #[inline]
    fn mul(self, y: f64) -> D2 {
        D2::scaled(self.v * y, self, y)
    }
}

impl Div<f64> for D2 {
    type Output = D2;
    #[inline]
    fn div(self, y: f64) -> D2 {
        D2::scaled(self.v / y, self, 1.0 / y)
    }
}

/// The complete integrals asked, with K and D beside them (their rates
/// need both), from one Gauss sequence.
fn cel_k_d<const N: usize>(m: f64, what: [Cel<f64>; N]) -> (f64, f64, [f64; N]) {
    let kc = (1.0 - m).sqrt();
    macro_rules! with_k_d {
        ($($k:literal),*) => {
            match N {
                $($k => {
                    let mut q = [(1.0, 1.0, 1.0); $k + 2];
                    q[$k + 1] = (1.0, 0.0, 1.0);
                    for i in 0..N {
                        q[i] = cel_pab(what[i]);
                    }
                    let v = bulirsch_cel_many(kc, q);
                    let mut out = [0.0; N];
                    out.copy_from_slice(&v[..N]);
                    (v[N], v[N + 1], out)
                })*
                _ => unreachable!("at most 5 complete integrals"),
            }
        };
    }
    with_k_d!(0, 1, 2, 3, 4, 5)
}

/// Legendre's F and J_i at the amplitude of sine `s`, cosine `c` with
/// their rates, from their values `(F, D, J_i)` there (DLMF 19.4.1-19.4.4
/// in m = k^2 with E = F - m D: dF/dphi = 1 / Delta, dF/dm = (F - D) / (2
/// (1 - m)) - s c / (2 (1 - m) Delta); dPi/dphi = 1 / ((1 - n s^2)
/// Delta), dPi/dm = (E / (m - 1) + Pi - m s c / ((m - 1) Delta)) / (2 (n -
/// m)), dPi/dn = (E + (n - 1) F + (n^2 - m) J - n Delta s c / (1 - n s^2))
/// / (2 (m - n) (n - 1)); the amplitude's rate is c ds - s dc, s^2 + c^2 =
/// 1).
fn legendre_rates<const N: usize>(
    s: D2,
    c: D2,
    m: D2,
    n: [D2; N],
    (f, d, j): (f64, f64, [f64; N]),
) -> (D2, [D2; N]) {
    let (sv, cv, mv) = (s.v, c.v, m.v);
    let s2 = sv * sv;
    let delta = (1.0 - mv * s2).sqrt();
    let sc = sv * cv;
    let e = f - mv * d;
    let dphi = D2::chain(0.0, s, cv, c, -sv);
    let f_m = ((f - d) - sc / delta) / (2.0 * (1.0 - mv));
    let big_f = D2::chain(f, dphi, 1.0 / delta, m, f_m);
    // A loop, not array::from_fn: its closure is not inlined.
    let mut js = [D2::default(); N];
    for i in 0..N {
        let nv = n[i].v;
        let jv = j[i];
        if nv == 0.0 {
            // D itself: dD/dphi = s^2 / Delta and, from D = (F - E) /
            // m with dE/dm = -D / 2, dD/dm = (dF/dm - D / 2) / m (at m
            // = 0, half the integral of sin^4).
            let phi = sv.atan2(cv);
            let d_m = if mv != 0.0 {
                (f_m - 0.5 * d) / mv
            } else {
                0.5 * (3.0 * phi / 8.0 - sc / 2.0 + sc * (cv * cv - s2) / 8.0)
            };
            js[i] = D2::chain(jv, dphi, s2 / delta, m, d_m);
            continue;
        }
        let pi = f + nv * jv;
        let w = 1.0 - nv * s2;
        let pi_m = (e / (mv - 1.0) + pi - mv * sc / ((mv - 1.0) * delta)) / (2.0 * (nv - mv));
        let pi_n = (e + (nv - 1.0) * f + (nv * nv - mv) * jv - nv * delta * sc / w)
            / (2.0 * (mv - nv) * (nv - 1.0));
        // J = (Pi - F) / n: its rate in the amplitude directly (no
        // cancellation at small n), in m and n through Pi's.
        let j_phi = s2 / (w * delta);
        let j_m = (pi_m - f_m) / nv;
        let j_n = (pi_n - jv) / nv;
        let rate = |k: usize| j_phi * dphi.d[k] + j_m * m.d[k] + j_n * n[i].d[k];
        js[i] = D2::with(jv, [rate(0), rate(1)]);
    }
    (big_f, js)
}

/// Jacobi's sn, cn, dn at u (values `jac`) with their rates: am u = phi
/// with F(phi | m) = u, so dphi = Delta (du - dF/dm dm), dF/dm at phi from
/// u and D(phi | m). `(f, d)` are F and D at the amplitude of sine sn and
/// cosine |cn| (phi itself, or pi - phi past a quarter period; whole
/// periods by F's, D(phi + pi) = D(phi) + 2 D(m)).
fn jacobi_rates(u: D2, m: D2, (sn, cn, dn): (f64, f64, f64), (f, d): (f64, f64)) -> (D2, D2, D2) {
    let mv = m.v;
    let (mut f_phi, mut d_phi) = (f, d);
    let past_quarter = cn < 0.0;
    if past_quarter || (u.v - f).abs() > 1e-9 * u.v.abs().max(1.0) {
        let (big_k, big_d, []) = cel_k_d(mv, []);
        if past_quarter {
            (f_phi, d_phi) = (2.0 * big_k - f, 2.0 * big_d - d);
        }
        let periods = ((u.v - f_phi) / (2.0 * big_k)).round();
        d_phi += 2.0 * periods * big_d;
    }
    let f_m = ((u.v - d_phi) - sn * cn / dn) / (2.0 * (1.0 - mv));
    let dphi = D2::chain(0.0, u, dn, m, -dn * f_m);
    let dn_m = -0.5 * sn * sn / dn;
    (
        D2::scaled(sn, dphi, cn),
        D2::scaled(cn, dphi, -sn),
        D2::chain(dn, dphi, -mv * sn * cn / dn, m, dn_m),
    )
}

/// Below this |n| the rates of Pi in n lose digits to cancellation (about
/// eps / |n|): there its rate in n is taken at n = 0, where it is D.
const SMALL_N: f64 = 1e-8;

impl Real for D2 {
    const RATED: bool = true;
    #[inline]
    fn c(v: f64) -> D2 {
        D2 { v, d: [0.0; 2] }
    }
    #[inline]
    fn re(self) -> f64 {
        self.v
    }
    #[inline]
    fn with(v: f64, d: [f64; 2]) -> D2 {
        D2 { v, d }
    }
    #[inline]
    fn rates(self) -> [f64; 2] {
        self.d
    }
    fn sqrt(self) -> D2 {
        let r = self.v.sqrt();
        D2::scaled(r, self, 0.5 / r)
    }
    fn ln(self) -> D2 {
        D2::scaled(self.v.ln(), self, 1.0 / self.v)
    }
    fn atan(self) -> D2 {
        D2::scaled(self.v.atan(), self, 1.0 / (1.0 + self.v * self.v))
    }
    fn atan2(self, x: D2) -> D2 {
        let r2 = self.v * self.v + x.v * x.v;
        D2::chain(self.v.atan2(x.v), self, x.v / r2, x, -self.v / r2)
    }
    fn sin_cos(self) -> (D2, D2) {
        let (s, c) = self.v.sin_cos();
        (D2::scaled(s, self, c), D2::scaled(c, self, -s))
    }
    fn hypot(self, y: D2) -> D2 {
        let h = self.v.hypot(y.v);
        D2::chain(h, self, self.v / h, y, y.v / h)
    }

    /// See [`legendre_rates`].
    fn legendre_f_j<const N: usize>(s: D2, c: D2, m: D2, n: [D2; N]) -> (D2, [D2; N]) {
        let values = legendre_f_d_j(s.v, c.v, m.v, n.map(|n| n.v));
        legendre_rates(s, c, m, n, values)
    }

    /// The Jacobi functions' rates (as [`Real::jacobi_sn_cn_dn`]) from the
    /// amplitude's D, which the integrals there give: one duplication
    /// sequence for both.
    fn jacobi_legendre<const N: usize>(
        u: D2,
        m: D2,
        (sn, cn, dn): (f64, f64, f64),
        n: [D2; N],
    ) -> ((D2, D2, D2), (D2, [D2; N])) {
        let values = legendre_f_d_j(sn, cn.abs(), m.v, n.map(|n| n.v));
        let jac = jacobi_rates(u, m, (sn, cn, dn), (values.0, values.1));
        let c = if cn < 0.0 { -jac.1 } else { jac.1 };
        (jac, legendre_rates(jac.0, c, m, n, values))
    }

    /// The complete forms of the rates above (s c = 0): dK/dm = (K - D) /
    /// (2 (1 - m)), dPi/dm = (E / (m - 1) + Pi) / (2 (n - m)), dPi/dn = (n
    /// E + (m - n) K + (n^2 - m) Pi) / (2 n (m - n) (n - 1)), D at n = 0.
    fn cel_many<const N: usize>(m: D2, what: [Cel<D2>; N]) -> [D2; N] {
        let mv = m.v;
        let plain = what.map(|w| match w {
            Cel::Pi(n) => Cel::Pi(n.v),
            Cel::D => Cel::D,
        });
        let (k, d, v) = cel_k_d(mv, plain);
        let e = k - mv * d;
        let mut out = [D2::default(); N];
        for i in 0..N {
            out[i] = match what[i] {
                Cel::D => D2::c(v[i]),
                Cel::Pi(n) if n.v == 0.0 && n.d == [0.0; 2] => {
                    D2::scaled(v[i], m, (k - d) / (2.0 * (1.0 - mv)))
                }
                Cel::Pi(n) => {
                    let (nv, pi) = (n.v, v[i]);
                    let pi_m = (e / (mv - 1.0) + pi) / (2.0 * (nv - mv));
                    let pi_n = if nv.abs() < SMALL_N {
                        d
                    } else {
                        (nv * e + (mv - nv) * k + (nv * nv - mv) * pi)
                            / (2.0 * nv * (mv - nv) * (nv - 1.0))
                    };
                    D2::chain(pi, m, pi_m, n, pi_n)
                }
            };
        }
        out
    }

    /// am u = phi with F(phi | m) = u: dphi = Delta (du - dF/dm dm), dF/dm
    /// at phi from u and D(phi | m) (D by its quasi-period: phi = j pi +
    /// psi, |psi| <= pi / 2, D(phi) = 2 j D(m) + D(psi)).
    fn jacobi_sn_cn_dn(u: D2, m: D2) -> (D2, D2, D2) {
        D2::jacobi_legendre(u, m, jacobi_sn_cn_dn(u.v, m.v), []).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of `f` along the first rate of its D2 input.
    fn numeric(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
        (f(x + h) - f(x - h)) / (2.0 * h)
    }

    fn seed(v: f64) -> D2 {
        D2::with(v, [1.0, 0.0])
    }

    fn close(got: f64, want: f64, tol: f64, what: &str) {
        assert!(
            (got - want).abs() <= tol * want.abs().max(1.0),
            "{what}: {got} against {want}"
        );
    }

    #[test]
    fn incomplete_integrals_carry_their_rates() {
        // Each of amplitude, parameter and characteristic in turn, at
        // parameters of both signs and characteristics either side of 1
        // (a principal value beyond), against central differences.
        for (phi, m, n) in [
            (0.7, 0.3, 0.5),
            (1.3, -2.0, 0.2),
            (0.4, 0.9, -3.0),
            (1.1, 0.5, 1.7),
            (-0.6, -0.4, 0.8),
        ] {
            let value = |phi: f64, m: f64, n: f64| {
                let (s, c) = f64::sin_cos(phi);
                let (f, [j, d]) = legendre_f_j(s, c, m, [n, 0.0]);
                (f, j, d)
            };
            for axis in 0..3 {
                let at = |x: f64| match axis {
                    0 => value(x, m, n),
                    1 => value(phi, x, n),
                    _ => value(phi, m, x),
                };
                let x0 = [phi, m, n][axis];
                let sd = |i: usize| {
                    if i == axis {
                        seed([phi, m, n][i])
                    } else {
                        D2::c([phi, m, n][i])
                    }
                };
                let (s, c) = sd(0).sin_cos();
                let (f, [j, d]) = D2::legendre_f_j(s, c, sd(1), [sd(2), D2::c(0.0)]);
                let h = 1e-5;
                close(f.d[0], numeric(|x| at(x).0, x0, h), 1e-8, "F");
                close(j.d[0], numeric(|x| at(x).1, x0, h), 1e-7, "J");
                if axis < 2 {
                    close(d.d[0], numeric(|x| at(x).2, x0, h), 1e-8, "D");
                }
            }
        }
    }

    #[test]
    fn complete_integrals_carry_their_rates() {
        for (m, n) in [
            (0.3, 0.5),
            (-2.0, 0.2),
            (0.9, -3.0),
            (0.5, 1.7),
            (-0.4, 1e-12),
        ] {
            let value = |m: f64, n: f64| {
                let [k, p] = f64::cel_many(m, [Cel::Pi(0.0), Cel::Pi(n)]);
                (k, p)
            };
            let [k, p] = D2::cel_many(seed(m), [Cel::Pi(D2::c(0.0)), Cel::Pi(D2::c(n))]);
            close(k.d[0], numeric(|x| value(x, n).0, m, 1e-5), 1e-8, "K in m");
            close(p.d[0], numeric(|x| value(x, n).1, m, 1e-5), 1e-8, "Pi in m");
            let [p] = D2::cel_many(D2::c(m), [Cel::Pi(seed(n))]);
            let h = if n.abs() < 1e-6 { 1e-9 } else { 1e-5 };
            close(p.d[0], numeric(|x| value(m, x).1, n, h), 1e-6, "Pi in n");
        }
    }

    #[test]
    fn jacobi_functions_carry_their_rates() {
        // Arguments past a quarter and a half period, where the amplitude's
        // D needs the quasi-period.
        for (u, m) in [(0.5, 0.3), (2.4, 0.7), (-3.9, 0.5), (5.0, -1.5), (1.0, 0.0)] {
            let at = |u: f64, m: f64| jacobi_sn_cn_dn(u, m);
            for axis in 0..2 {
                let (uu, mm) = if axis == 0 {
                    (seed(u), D2::c(m))
                } else {
                    (D2::c(u), seed(m))
                };
                let (sn, cn, dn) = D2::jacobi_sn_cn_dn(uu, mm);
                let x0 = [u, m][axis];
                let f = |x: f64| if axis == 0 { at(x, m) } else { at(u, x) };
                let h = 1e-6;
                close(
                    sn.d[0],
                    numeric(|x| f(x).0, x0, h),
                    1e-7,
                    &format!("sn {u} {m} {axis}"),
                );
                close(cn.d[0], numeric(|x| f(x).1, x0, h), 1e-7, "cn");
                close(dn.d[0], numeric(|x| f(x).2, x0, h), 1e-7, "dn");
            }
        }
    }

    #[test]
    fn arithmetic_follows_the_chain_rule() {
        let x = D2::with(0.7, [1.0, 2.0]);
        let y = D2::with(-1.3, [0.5, -1.0]);
        // x y + x / y < 0 here: through abs, as its value goes.
        let z = (x * y + x / y).abs().sqrt().ln() * 3.0 - y.atan2(x) + x.hypot(y);
        let f = |a: f64, b: f64| 3.0 * (a * b + a / b).abs().sqrt().ln() - b.atan2(a) + a.hypot(b);
        for k in 0..2 {
            let h = 1e-6;
            let (dx, dy) = (x.d[k], y.d[k]);
            let want = (f(x.v + h * dx, y.v + h * dy) - f(x.v - h * dx, y.v - h * dy)) / (2.0 * h);
            close(z.d[k], want, 1e-8, "chain");
        }
    }
}
