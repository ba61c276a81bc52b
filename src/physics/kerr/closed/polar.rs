//! The polar motion of a photon: ordinary (swinging about the equator)
//! and vortical (in one hemisphere), in Jacobi's functions of Mino time.

use crate::physics::elliptic::bulirsch_cel_many;

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

/// The ordinary polar motion along a ray: cos theta = sqrt(u_+) sn(psi |
/// m), psi = psi0 + scale s.
#[derive(Clone, Copy, Debug)]
pub(super) struct Polar {
    pub(super) u_plus: f64,
    /// The parameter and the characteristic of its Pi.
    pub(super) m: f64,
    pub(super) n: f64,
    pub(super) scale: f64,
    /// The polar integral of 1 / sin^2 theta is Pi times this.
    pub(super) g_scale: f64,
    pub(super) psi0: f64,
    /// K(m), Pi(n | m) and Pi(n; am(psi0) | m).
    pub(super) big_k: f64,
    pub(super) pi_c: f64,
    pub(super) pi0: f64,
    /// Vortical motion (eta < 0): u_- and the hemisphere's sign.
    pub(super) vortical: Option<(f64, f64)>,
    /// For the time (ordinary motion): D(m) and D(am(psi0) | m), whose
    /// difference times a^2 u_+ / scale is the integral of a^2 cos^2 theta.
    pub(super) d_c: f64,
    pub(super) d0: f64,
}

impl Polar {
    /// Ordinary motion (eta > 0): cos theta = sqrt(u_+) sn(psi | u_+ /
    /// u_-), psi = psi0 + sqrt(-u_- a^2) s, the integral of 1 / sin^2
    /// theta Pi(u_+; am psi) / sqrt(-u_- a^2); psi0 in [-K, 3K), so that
    /// the equatorial crossings are the nodes psi = 2 K j.
    pub(super) fn ordinary(pm: PolarMotion, cos0: f64, u_up: bool, timed: bool) -> Polar {
        let m = pm.m;
        let kc = (1.0 - m).sqrt();
        // K(m), Pi(u_+ | m) and, for the time, D(m) = cel(kc, 1, 0, 1).
        let (k, pi) = ((1.0, 1.0, 1.0), (1.0 - pm.u_plus, 1.0, 1.0));
        let sn_th = (cos0 / pm.u_plus.sqrt()).clamp(-1.0, 1.0);
        let cn_th = (1.0 - sn_th * sn_th).sqrt();
        let (f0, p0, [big_k, pi_c, d_c], d0) = if timed {
            let (f, [j, d]) =
                crate::physics::elliptic::legendre_f_j(sn_th, cn_th, m, [pm.u_plus, 0.0]);
            (
                f,
                f + pm.u_plus * j,
                bulirsch_cel_many(kc, [k, pi, (1.0, 0.0, 1.0)]),
                d,
            )
        } else {
            let (f, [p]) = crate::physics::elliptic::legendre_f_pi(sn_th, cn_th, m, [pm.u_plus]);
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
    pub(super) fn vortical(a: f64, lambda: f64, eta: f64, cos0: f64, u_up: bool) -> Option<Polar> {
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
        let (f0, [p0]) =
            crate::physics::elliptic::legendre_f_pi(s2.sqrt(), (1.0 - s2).sqrt(), m, [n]);
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
