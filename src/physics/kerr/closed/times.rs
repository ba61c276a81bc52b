//! The coordinate time along a closed-form ray: the radial integrals of
//! r and r^2 that its polynomial part needs, and the partial fractions of
//! its horizon poles. With M = 1, dt/ds = E (r^2 + 2 r + 4 + ((8 - 2 a
//! lambda) r - 4 a^2) / Delta + a^2 cos^2 theta) (the polar part is
//! [`super::KerrRay::crossing_point_time`]'s).

/// Kappa times the integral of r^2 + 2 r + 4 dX for four real roots
/// ([`Radial::Outer`](super::radial::Radial)) at the amplitude `(sn, cn)`
/// of parameter `k`, from U = `u`, D = `d` and J of the pole at infinity
/// `jn`, with r = r3 + r43 / (1 - N sn^2).
pub(super) fn outer_time(
    (sn, cn): (f64, f64),
    k: f64,
    (u, d, jn): (f64, f64, f64),
    (r3, r43, big_n): (f64, f64, f64),
) -> f64 {
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
    i2 + 2.0 * i1 + 4.0 * u
}

/// Kappa times the integral of r^2 + 2 r + 4 dX for one complex root pair
/// ([`Radial::Pair`](super::radial::Radial)) at the amplitude `(sn, cn)` of
/// parameter `k`, from U = `u` (past a quarter period by reflection), D =
/// `dd` and `r1`, the integral of 1 / (1 + alpha cn) for the pole at
/// infinity `al`, with r = r0 + rc / (1 + alpha cn), `r_lin` = (r0, rc).
pub(super) fn pair_time(
    (sn, cn): (f64, f64),
    k: f64,
    (u, dd, r1): (f64, f64, f64),
    al: f64,
    r_lin: [f64; 2],
) -> f64 {
    // int dU / (1 + alpha cn)^2 from d/dU (sn dn f) = k cn^2 /
    // alpha - k / alpha^3 - (2 alpha^2 k - alpha^2 - 2 k) f /
    // alpha^3 - (alpha^2 - 1) (alpha^2 k - alpha^2 - k) f^2 /
    // alpha^3, f = 1 / (1 + alpha cn), cn^2 = 1 - sn^2.
    let a2 = al * al;
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
    i2 + 2.0 * i1 + 4.0 * u
}

/// The partial fractions of ((8 - 2 a lambda) r - 4 a^2) / Delta over the
/// horizons `[r_plus, r_minus]`, and the time's radial part at the start:
/// `sign0` times its polynomial part `radial_time0` plus the poles'
/// integrals `pole0` (all kappa times, unsigned).
pub(super) fn time_start(
    a: f64,
    lambda: f64,
    [r_plus, r_minus]: [f64; 2],
    sign0: f64,
    radial_time0: f64,
    pole0: [f64; 2],
) -> ([f64; 2], f64) {
    let dr = r_plus - r_minus;
    let slope = 8.0 - 2.0 * a * lambda;
    let tcoef = [
        (slope * r_plus - 4.0 * a * a) / dr,
        -(slope * r_minus - 4.0 * a * a) / dr,
    ];
    let time0 = sign0 * (radial_time0 + tcoef[0] * pole0[0] + tcoef[1] * pole0[1]);
    (tcoef, time0)
}

#[cfg(test)]
mod tests {
    use super::super::radial::{Complete, Radial};
    use super::super::roots::RadialRoots;
    use crate::physics::elliptic::bulirsch_cel;
    use crate::physics::kerr::Kerr;

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
                _ => Complete::none(),
            };
            let time = |r: f64| radial.at::<true>(radial.sn_cn(r), k, &complete, true).2 / kappa;
            let got = time(to) - from.map_or(0.0, time);
            assert!(
                (got - want).abs() < 1e-13 * want,
                "a {a} lambda {lambda} eta {eta}: {got} vs {want}"
            );
        }
    }
}
