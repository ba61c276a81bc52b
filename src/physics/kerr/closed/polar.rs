//! The polar motion of a photon: ordinary (swinging about the equator)
//! and vortical (in one hemisphere), in Jacobi's functions of Mino time.
//! Written in [`Real`]: f64 for a ray, with its rates for a footprint.

use crate::physics::dual::{Cel, D2, Real};

/// A photon's ordinary polar motion (eta > 0): it swings about the equator
/// between theta_+ and pi - theta_+, where cos^2 theta_+ = u_+, under
/// Theta(theta) = eta + a^2 cos^2 theta - lambda^2 cot^2 theta (Gralla and
/// Lupsasca, section 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolarMotion<T = f64> {
    /// u_+ = cos^2 of the turning angle.
    pub u_plus: T,
    /// sqrt(-u_- a^2), the scale of the Mino time.
    scale: T,
    /// The parameter u_+ / u_- (<= 0) of its elliptic integrals.
    m: T,
}

impl<T: Real> PolarMotion<T> {
    /// The motion of a photon of spin `a`, lambda and eta > 0 (None
    /// otherwise). u_+- = Delta_theta +- sqrt(Delta_theta^2 + eta / a^2),
    /// Delta_theta = (1 - (eta + lambda^2) / a^2) / 2, taken as a^2 u_-
    /// without cancellation and u_+ = -eta / (a^2 u_-): finite as a -> 0.
    pub fn new(a: f64, lambda: T, eta: T) -> Option<PolarMotion<T>> {
        if !(eta.re() > 0.0) {
            return None;
        }
        let half = (T::c(a * a) - eta - lambda * lambda) * 0.5;
        let a2_um = half - (half * half + eta * a * a).sqrt();
        let u_plus = -eta / a2_um;
        Some(PolarMotion {
            u_plus,
            scale: (-a2_um).sqrt(),
            m: u_plus * a * a / a2_um,
        })
    }
}

/// The ordinary polar motion along a ray: cos theta = sqrt(u_+) sn(psi |
/// m), psi = psi0 + scale s.
#[derive(Clone, Copy, Debug)]
pub(super) struct Polar<T = f64> {
    pub(super) u_plus: T,
    /// The parameter and the characteristic of its Pi.
    pub(super) m: T,
    pub(super) n: T,
    pub(super) scale: T,
    /// The polar integral of 1 / sin^2 theta is Pi times this.
    pub(super) g_scale: T,
    pub(super) psi0: T,
    /// K(m), Pi(n | m) and Pi(n; am(psi0) | m).
    pub(super) big_k: T,
    pub(super) pi_c: T,
    pub(super) pi0: T,
    /// Vortical motion (eta < 0): u_- and the hemisphere's sign.
    pub(super) vortical: Option<(T, f64)>,
    /// For the time (ordinary motion): D(m) and D(am(psi0) | m), whose
    /// difference times a^2 u_+ / scale is the integral of a^2 cos^2 theta
    /// (values only: a footprint does not differentiate the time).
    pub(super) d_c: f64,
    pub(super) d0: f64,
}

impl<T: Real> Polar<T> {
    /// Ordinary motion (eta > 0): cos theta = sqrt(u_+) sn(psi | u_+ /
    /// u_-), psi = psi0 + sqrt(-u_- a^2) s, the integral of 1 / sin^2
    /// theta Pi(u_+; am psi) / sqrt(-u_- a^2); psi0 in [-K, 3K), so that
    /// the equatorial crossings are the nodes psi = 2 K j.
    pub(super) fn ordinary(pm: PolarMotion<T>, cos0: f64, u_up: bool, timed: bool) -> Polar<T> {
        let m = pm.m;
        let n = pm.u_plus;
        let sn_th = (T::c(cos0) / n.sqrt()).clamp(-1.0, 1.0);
        let cn_th = (T::c(1.0) - sn_th * sn_th).sqrt();
        // K(m), Pi(u_+ | m) and, for the time, D(m), from one sequence.
        let (f0, p0, [big_k, pi_c, d_c], d0) = if timed {
            let (f, [j, d]) = T::legendre_f_j(sn_th, cn_th, m, [n, T::c(0.0)]);
            let [k, pi, d_c] = T::cel_many(m, [Cel::Pi(T::c(0.0)), Cel::Pi(n), Cel::D]);
            (f, f + n * j, [k, pi, d_c], d.re())
        } else {
            let (f, [j]) = T::legendre_f_j(sn_th, cn_th, m, [n]);
            let [k, pi] = T::cel_many(m, [Cel::Pi(T::c(0.0)), Cel::Pi(n)]);
            (f, f + n * j, [k, pi, T::c(0.0)], 0.0)
        };
        let d_c = d_c.re();
        // Moving away from the equator's crossing ahead: past the turning
        // point, am = pi - asin.
        let (psi0, pi0, d0) = if u_up {
            (f0, p0, d0)
        } else {
            (big_k * 2.0 - f0, pi_c * 2.0 - p0, 2.0 * d_c - d0)
        };
        Polar {
            u_plus: n,
            m,
            n,
            scale: pm.scale,
            g_scale: pm.scale.recip(),
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
    pub(super) fn vortical(a: f64, lambda: T, eta: T, cos0: f64, u_up: bool) -> Option<Polar<T>> {
        let half = (T::c(a * a) - eta - lambda * lambda) * 0.5;
        let disc = half * half + eta * a * a;
        if !(eta.re() < 0.0 && half.re() > 0.0 && disc.re() >= 0.0) {
            return None;
        }
        // a^2 u_+ without cancellation, u_- from the product -eta / a^2.
        let a2_up = half + disc.sqrt();
        let u_plus = a2_up / (a * a);
        let u_minus = -eta / a2_up;
        if !(u_plus.re() < 1.0 - 1e-10) {
            return None;
        }
        let m = T::c(1.0) - u_minus / u_plus;
        let n = -(u_plus - u_minus) / (T::c(1.0) - u_plus);
        let scale = a2_up.sqrt();
        let [big_k, pi_c] = T::cel_many(m, [Cel::Pi(T::c(0.0)), Cel::Pi(n)]);
        let s2 = ((u_plus - cos0 * cos0) / (u_plus - u_minus)).clamp(0.0, 1.0);
        let (f0, [j0]) = T::legendre_f_j(s2.sqrt(), (T::c(1.0) - s2).sqrt(), m, [n]);
        let p0 = f0 + n * j0;
        // Towards the pole (|cos theta| growing) psi runs up to 0.
        let sign = if u_up == (cos0 > 0.0) { -1.0 } else { 1.0 };
        Some(Polar {
            u_plus,
            m,
            n,
            scale,
            g_scale: (scale * (T::c(1.0) - u_plus)).recip(),
            psi0: f0 * sign,
            big_k,
            pi_c,
            pi0: p0 * sign,
            vortical: Some((u_minus, cos0.signum())),
            d_c: 0.0,
            d0: 0.0,
        })
    }
}

impl Polar<D2> {
    /// The motion without its rates.
    pub(super) fn value(&self) -> Polar {
        Polar {
            u_plus: self.u_plus.v,
            m: self.m.v,
            n: self.n.v,
            scale: self.scale.v,
            g_scale: self.g_scale.v,
            psi0: self.psi0.v,
            big_k: self.big_k.v,
            pi_c: self.pi_c.v,
            pi0: self.pi0.v,
            vortical: self.vortical.map(|(u, h)| (u.v, h)),
            d_c: self.d_c,
            d0: self.d0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
