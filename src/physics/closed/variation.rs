//! How a ray in closed form moves as its impact parameter changes, its
//! start and its plane held: the derivatives a footprint needs, in closed
//! form rather than from a neighbouring orbit. With c = 1/b^2 the orbit's
//! cubic P(u) = u^3 - u^2 + c moves its roots by du_i/dc = -1/P'(u_i); the
//! angle from a root to 1/r = y is R_F of quantities rational in the roots
//! and y, so its derivative in c at fixed y is R_F's gradient (the three
//! R_D, [`carlson_rf_rate`]) along theirs. At fixed angle phi from the
//! start, 1/r then moves as
//!     du/dc = sqrt(P(u)) (d psi0/dc - d Psi/dc (u)) (up to the branch's sign),
//! Psi(u) the angle from the orbit's reference point to u, psi0 = Psi(u0)
//! the start's: the point moves along the ray by the start's shift and
//! across it by the orbit's change. Where sqrt(P) vanishes (a turning
//! point) and Psi's derivative does not exist, their product is taken as
//! one finite expression.

use super::{ClosedRay, Orbit, Path, Plunge};
use crate::physics::elliptic::{carlson_rd, carlson_rf_rate};

/// How a closed-form ray changes with c = 1/b^2 (see the module's notes).
#[derive(Clone, Copy, Debug)]
pub struct Rates {
    /// Of the angle from the orbit's reference point (the turning point,
    /// or the root u1 below b_c) to the start.
    dpsi0: f64,
    /// Of the angle it sweeps to infinity; None for a captured ray.
    pub dsweep: Option<f64>,
    /// Of the orbit's roots (those of an orbit with turning points).
    droots: [f64; 3],
    plunge: PlungeRates,
}

/// d u / dc of a root u of u^3 - u^2 + c.
fn root_rate(u: f64) -> f64 {
    -1.0 / (u * (3.0 * u - 2.0))
}

impl Orbit {
    fn root_rates(&self) -> [f64; 3] {
        [root_rate(self.u1), root_rate(self.u2), root_rate(self.u3)]
    }

    /// For 1/r = y <= u2: G(y), the angle from y to the turning point, its
    /// derivative in c at fixed y, and that derivative times sqrt(P(y))
    /// (finite at the turning point, where G's is not). G(y) = 2 sqrt(u2 -
    /// y) R_F((y - u1)(u3 - u2), (u2 - u1)(u3 - u2), (u3 - y)(u2 - u1))
    /// ([`Orbit::sweep`] with x = u2, R_F's homogeneity).
    fn turn_rates(&self, y: f64, d: [f64; 3]) -> (f64, f64, f64) {
        let (u1, u2, u3) = (self.u1, self.u2, self.u3);
        let args = [
            (y - u1) * (u3 - u2),
            (u2 - u1) * (u3 - u2),
            (u3 - y) * (u2 - u1),
        ];
        let dargs = [
            -d[0] * (u3 - u2) + (y - u1) * (d[2] - d[1]),
            (d[1] - d[0]) * (u3 - u2) + (u2 - u1) * (d[2] - d[1]),
            d[2] * (u2 - u1) + (u3 - y) * (d[1] - d[0]),
        ];
        angle_rates(args, dargs, (u2 - y, d[1]), (y - u1) * (u3 - y))
    }

    /// A turning ray's angles from its start (1/r = `u0`) and from
    /// infinity to the turning point, and its rates ([`ClosedRay::rates`]),
    /// from the same duplications: a ray whose footprint is wanted makes
    /// its rates for little more than its sweeps.
    pub(super) fn turning_with_rates(&self, u0: f64, inbound: bool) -> (f64, f64, Rates) {
        let d = self.root_rates();
        let (to_turn, g0, _) = self.turn_rates(u0, d);
        let (half, g_inf, _) = self.turn_rates(0.0, d);
        // psi0 = -G(u0) inbound, G(u0) outbound; the sweep to infinity is
        // G(0) - psi0.
        let dpsi0 = if inbound { -g0 } else { g0 };
        let rates = Rates {
            dpsi0,
            dsweep: Some(g_inf - dpsi0),
            droots: d,
            plunge: PlungeRates::default(),
        };
        (to_turn, half, rates)
    }

    /// For 1/r = u >= u3 (inside the photon sphere): H(u), the angle from
    /// the inner turning point to u, its derivative in c at fixed u, and
    /// that derivative times sqrt(P(u)). H(u) = 2 sqrt(u - u3)
    /// R_F((u3 - u1)(u3 - u2), (u - u1)(u3 - u2), (u - u2)(u3 - u1))
    /// ([`Orbit::inner_sweep`], likewise).
    fn inner_rates(&self, u: f64, d: [f64; 3]) -> (f64, f64, f64) {
        let (u1, u2, u3) = (self.u1, self.u2, self.u3);
        let args = [
            (u3 - u1) * (u3 - u2),
            (u - u1) * (u3 - u2),
            (u - u2) * (u3 - u1),
        ];
        let dargs = [
            (d[2] - d[0]) * (u3 - u2) + (u3 - u1) * (d[2] - d[1]),
            -d[0] * (u3 - u2) + (u - u1) * (d[2] - d[1]),
            -d[1] * (u3 - u1) + (u - u2) * (d[2] - d[0]),
        ];
        angle_rates(args, dargs, (u - u3, -d[2]), (u - u1) * (u - u2))
    }
}

/// An angle 2 sqrt(w) R_F(`args`) from a turning point at distance w (in
/// 1/r) whose rate in c is `dw`, where R_F's arguments move by `dargs`:
/// the angle, its rate and its rate times sqrt(P) = sqrt(w `other`).
fn angle_rates(
    args: [f64; 3],
    dargs: [f64; 3],
    (w, dw): (f64, f64),
    other: f64,
) -> (f64, f64, f64) {
    let (r, dr) = carlson_rf_rate(args, dargs);
    // The rate times sqrt(w): the turning point's motion and the integral's.
    let core = dw * r + 2.0 * w * dr;
    let root = w.sqrt();
    (2.0 * root * r, core / root, core * other.sqrt())
}

/// How a plunging orbit's quantities change with c: its real root, A, the
/// modulus m and K(m) ([`Plunge`]).
#[derive(Clone, Copy, Debug, Default)]
struct PlungeRates {
    du1: f64,
    da: f64,
    dm: f64,
    dk: f64,
}

impl Plunge {
    fn rates(&self) -> PlungeRates {
        let (u1, a) = (self.u1, self.a);
        let c = 1.0 / (self.b * self.b);
        // The complex pair p +- iq: p = (1 - u1) / 2, q^2 = -c / u1 - p^2.
        let du1 = root_rate(u1);
        let p = 0.5 * (1.0 - u1);
        let dp = -0.5 * du1;
        let dq2 = -1.0 / u1 + c * du1 / (u1 * u1) - 2.0 * p * dp;
        let da = ((p - u1) * (dp - du1) + 0.5 * dq2) / a;
        let dm = ((dp - du1) * a - (p - u1) * da) / (2.0 * a * a);
        // K = R_F(0, 1 - m, 1): only its slope in the second argument.
        let dk = carlson_rd(1.0, 0.0, 1.0 - self.m) * dm / 6.0;
        PlungeRates { du1, da, dm, dk }
    }

    /// The derivative in c at fixed u of [`Plunge::from_root`], through
    /// its Legendre form F(phi | m) / sqrt(A).
    fn root_angle_rate(&self, u: f64, k: &PlungeRates) -> f64 {
        let (a, m) = (self.a, self.m);
        let x = u - self.u1;
        let dx = -k.du1;
        let cos = (a - x) / (a + x);
        let sin = 2.0 * (a * x).sqrt() / (a + x);
        let dcos = 2.0 * (k.da * x - a * dx) / ((a + x) * (a + x));
        let dsin = sin * (0.5 * (k.da / a + dx / x) - (k.da + dx) / (a + x));
        let args = [cos * cos, 1.0 - m * sin * sin, 1.0];
        let dargs = [
            2.0 * cos * dcos,
            -k.dm * sin * sin - 2.0 * m * sin * dsin,
            0.0,
        ];
        let (r, dr) = carlson_rf_rate(args, dargs);
        let (f, df) = (sin * r, dsin * r + sin * dr);
        // Past phi = pi / 2 the angle is 2 K - F(pi - phi).
        let (f, df) = if cos >= 0.0 {
            (f, df)
        } else {
            (2.0 * self.k - f, 2.0 * k.dk - df)
        };
        let root_a = self.root_a;
        df / root_a - 0.5 * f * k.da / (a * root_a)
    }
}

impl ClosedRay {
    /// Its rates of change in c = 1/b^2, its start and plane held (made
    /// with the ray where it was made [`ClosedRay::new_rated`]).
    pub fn rates(&self) -> Rates {
        if let Some(rates) = self.rates {
            return rates;
        }
        let u0 = self.u0;
        let none = PlungeRates::default();
        match self.path {
            Path::Turning { orbit, psi0 } => orbit.turning_with_rates(u0, psi0 < 0.0).2,
            Path::Inner { orbit, psi0 } => {
                let d = orbit.root_rates();
                let h0 = orbit.inner_rates(u0, d).1;
                Rates {
                    dpsi0: if psi0 > 0.0 { h0 } else { -h0 },
                    dsweep: None,
                    droots: d,
                    plunge: none,
                }
            }
            Path::Plunging {
                plunge, outbound, ..
            } => {
                let k = plunge.rates();
                let dpsi0 = plunge.root_angle_rate(u0, &k);
                Rates {
                    dpsi0,
                    // psi0 - Psi(0) for an outbound (escaping) ray.
                    dsweep: outbound.then(|| dpsi0 - plunge.root_angle_rate(0.0, &k)),
                    droots: [0.0; 3],
                    plunge: k,
                }
            }
        }
    }

    /// du/dc at the point where 1/r is `u` and du/dphi is `du`
    /// ([`ClosedRay::orbit_at`]), at fixed angle from the start.
    pub fn du_dc(&self, rates: &Rates, u: f64, du: f64) -> f64 {
        match self.path {
            // |psi0 + phi| = G(u): du/dc = sqrt(P) G'(u) + du/dphi psi0'.
            Path::Turning { orbit, .. } => orbit.turn_rates(u, rates.droots).2 + du * rates.dpsi0,
            // |psi0 + phi| = H(u): du/dc = du/dphi psi0' - sqrt(P) H'(u).
            Path::Inner { orbit, .. } => du * rates.dpsi0 - orbit.inner_rates(u, rates.droots).2,
            // psi0 +- phi = Psi(u): du/dc = sqrt(P) (psi0' - Psi'(u)).
            Path::Plunging { plunge, .. } => {
                du.abs() * (rates.dpsi0 - plunge.root_angle_rate(u, &rates.plunge))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The ray from radius r with impact parameter `b`, in the x-y plane.
    fn ray(r: f64, b: f64, inbound: bool) -> ClosedRay {
        ClosedRay::planar(r, b, inbound, (DVec3::X, DVec3::Y)).unwrap()
    }

    #[test]
    fn the_rates_are_central_differences_of_the_closed_form() {
        // Every kind of path: turning rays in and out (near the photon
        // sphere and far), rays inside the photon sphere, plunging rays in
        // and out; d sweep / dc and du/dc at fixed angles along the ray
        // against central differences over c (1e-5 of it, or of the distance
        // to b_c: truncation ~1e-10, rounding ~1e-11).
        let cases = [
            (50.0, 10.0, true),
            (50.0, 2.6 + 1e-3, true),
            (4.0, 3.0, false),
            (1e4, 900.0, true),
            (1.1, 3.0, true),
            (1.1, 3.0, false),
            (30.0, 2.0, true),
            (1.3, 2.0, false),
            (1.3, 0.3, true),
        ];
        let mut worst = 0.0f64;
        for (r, b, inbound) in cases {
            let c = 1.0 / (b * b);
            // Near b_c the orbit changes on the scale of the distance to it.
            let h = 1e-5 * c * (10.0 * (1.0 - b / super::super::B_CRIT).abs()).min(1.0);
            let at = |c: f64| ray(r, 1.0 / c.sqrt(), inbound);
            let (mid, plus, minus) = (at(c), at(c + h), at(c - h));
            let rates = mid.rates();
            let close = |got: f64, want: f64, what: &str| {
                let e = (got - want).abs() / want.abs().max(1e-300);
                assert!(
                    e < 1e-6,
                    "r {r} b {b} in {inbound}, {what}: {got} vs {want}"
                );
                e
            };
            assert_eq!(rates.dsweep.is_some(), !mid.captured);
            if let Some(ds) = rates.dsweep {
                worst = worst.max(close(ds, (plus.sweep - minus.sweep) / (2.0 * h), "sweep"));
            }
            // Angles short of both neighbours' ends.
            let end = mid.sweep.min(plus.sweep).min(minus.sweep);
            for k in 1..8 {
                let phi = end * k as f64 / 8.0;
                let (u, du) = mid.orbit_at(phi);
                let want = (plus.orbit_at(phi).0 - minus.orbit_at(phi).0) / (2.0 * h);
                worst = worst.max(close(
                    mid.du_dc(&rates, u, du),
                    want,
                    &format!("u at {phi}"),
                ));
            }
        }
        eprintln!("worst relative difference {worst:.1e}");
    }

    #[test]
    fn a_ray_made_with_its_rates_is_the_same_ray() {
        // The sweeps of a rated ray come from the rates' duplications (the
        // homogeneous form of the integral): the same angles to rounding,
        // the same rates.
        for (r, b, inbound) in [(50.0, 10.0, true), (4.0, 3.0, false), (1e4, 900.0, true)] {
            let plain = ray(r, b, inbound);
            let rated = ClosedRay::planar_with(r, b, inbound, (DVec3::X, DVec3::Y), true).unwrap();
            let (a, c) = (plain.rates(), rated.rates());
            let close = |x: f64, y: f64| (x - y).abs() <= 1e-13 * x.abs().max(y.abs());
            assert!(rated.rates.is_some() && plain.rates.is_none());
            assert!(
                close(plain.sweep, rated.sweep),
                "{} {}",
                plain.sweep,
                rated.sweep
            );
            assert!(close(a.dpsi0, c.dpsi0) && close(a.dsweep.unwrap(), c.dsweep.unwrap()));
            for phi in [0.1, 0.5 * plain.sweep, 0.9 * plain.sweep] {
                let (p, q) = (plain.orbit_at(phi).0, rated.orbit_at(phi).0);
                assert!(close(p, q), "r {r} b {b}: {p} {q}");
            }
        }
    }
}
