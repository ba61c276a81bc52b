//! Closed-form Schwarzschild light rays (r_s = 1): the orbit equation
//! (du/dphi)^2 = u^3 - u^2 + 1/b^2 for u = 1/r is an elliptic integral, so
//! the angle a ray sweeps between two radii is Carlson's R_F of its cubic's
//! roots, and the radius after sweeping an angle is a Jacobi sn. This is
//! the ground work of the exact fast path for disk-and-sky scenes; the
//! integrator remains the reference it is tested against.
//!
//! For b above the critical b_c = 3 sqrt(3) / 2 the cubic has three real
//! roots u1 < 0 < u2 <= u3: a ray outside the photon sphere lives on
//! [0, u2] and turns at r_min = 1 / u2.

mod variation;

pub use variation::Rates;

use super::{End, Flow, Segment, TimeRate};
use glam::DVec3;

/// b_c = 3 sqrt(3) / 2 (r_s): rays below it from afar are captured.
pub const B_CRIT: f64 = super::B_CRIT_GR;

pub use super::elliptic::{carlson_rf, jacobi_am, jacobi_sn, jacobi_sn_cn_dn};

/// The roots u1 < u2 <= u3 of u^3 - u^2 + 1/b^2 for b > b_c (u2 = 1/r of
/// the turning point outside the photon sphere), polished by Newton's
/// method to the last bits.
pub fn roots(b: f64) -> [f64; 3] {
    debug_assert!(b > B_CRIT);
    let c = 1.0 / (b * b);
    let mut r = if c < 1e-3 {
        // Far rays: u^2 (1 - u) = c has the small roots
        // +-sqrt(c / (1 - u)), found by fixed-point iteration, and the
        // roots sum to 1.
        let (mut u1, mut u2) = (-c.sqrt(), c.sqrt());
        for _ in 0..60 {
            u1 = -(c / (1.0 - u1)).sqrt();
            u2 = (c / (1.0 - u2)).sqrt();
        }
        [u1, u2, 1.0 - u1 - u2]
    } else {
        // u = t + 1/3: t^3 - t/3 + q = 0, q = c - 2/27; trigonometric roots.
        let arg = (1.0 - 13.5 * c).clamp(-1.0, 1.0);
        let theta = arg.acos() / 3.0;
        let third = 1.0 / 3.0;
        let mut r = [
            third + 2.0 * third * (theta + 4.0 * std::f64::consts::FRAC_PI_3).cos(),
            third + 2.0 * third * (theta + 2.0 * std::f64::consts::FRAC_PI_3).cos(),
            third + 2.0 * third * theta.cos(),
        ];
        r.sort_by(f64::total_cmp);
        // The middle root from the product of the roots, -c: no
        // cancellation.
        r[1] = -c / (r[0] * r[2]);
        r
    };
    for u in &mut r {
        for _ in 0..3 {
            let f = *u * *u * (*u - 1.0) + c;
            let df = *u * (3.0 * *u - 2.0);
            if df.abs() > 1e-8 {
                *u -= f / df;
            }
        }
    }
    r
}

/// A planar ray of impact parameter b > b_c outside the photon sphere.
#[derive(Clone, Copy, Debug)]
pub struct Orbit {
    pub b: f64,
    pub u1: f64,
    pub u2: f64,
    pub u3: f64,
    /// m = (u2 - u1) / (u3 - u1), K(m), sqrt(u3 - u1) / 2.
    m: f64,
    k: f64,
    half_root: f64,
}

impl Orbit {
    pub fn new(b: f64) -> Orbit {
        let [u1, u2, u3] = roots(b);
        let m = (u2 - u1) / (u3 - u1);
        Orbit {
            b,
            u1,
            u2,
            u3,
            m,
            k: carlson_rf(0.0, 1.0 - m, 1.0),
            half_root: 0.5 * (u3 - u1).sqrt(),
        }
    }

    /// The angle swept between 1/r = y and 1/r = x, 0 <= y < x <= u2:
    /// int_y^x du / sqrt((u - u1)(u2 - u)(u3 - u)) = 2 R_F(U12^2, U13^2,
    /// U23^2) (DLMF 19.29.4).
    pub fn sweep(&self, y: f64, x: f64) -> f64 {
        if x <= y {
            return 0.0;
        }
        let (x1, y1) = ((x - self.u1).sqrt(), (y - self.u1).sqrt());
        let (x2, y2) = ((self.u2 - x).max(0.0).sqrt(), (self.u2 - y).sqrt());
        let (x3, y3) = ((self.u3 - x).sqrt(), (self.u3 - y).sqrt());
        let d = x - y;
        let u12 = (x1 * x2 * y3 + y1 * y2 * x3) / d;
        let u13 = (x1 * x3 * y2 + y1 * y3 * x2) / d;
        let u23 = (x2 * x3 * y1 + y2 * y3 * x1) / d;
        2.0 * carlson_rf(u12 * u12, u13 * u13, u23 * u23)
    }

    /// The angle from the turning point to infinity.
    pub fn half_sweep(&self) -> f64 {
        self.sweep(0.0, self.u2)
    }

    /// 1/r after sweeping `psi` from the turning point (either way). With
    /// t = u1 + (u2 - u1) w^2 the sweep from u to u2 is
    /// 2 / sqrt(u3 - u1) (K(m) - F(asin w | m)), m = (u2 - u1) / (u3 - u1),
    /// so u = u1 + (u2 - u1) sn^2(K - psi sqrt(u3 - u1) / 2 | m).
    pub fn u_at(&self, psi: f64) -> f64 {
        let w = jacobi_sn_cn_dn(self.k - psi.abs() * self.half_root, self.m).0;
        self.u1 + (self.u2 - self.u1) * w * w
    }

    /// The angle swept between the inner turning point 1/r = u3 and
    /// 1/r = u >= u3 (a ray inside the photon sphere, which cannot get
    /// out): int_u3^u dt / sqrt((t - u1)(t - u2)(t - u3)), DLMF 19.29.4
    /// with all three factors positive.
    pub fn inner_sweep(&self, u: f64) -> f64 {
        if u <= self.u3 {
            return 0.0;
        }
        let (x1, x2, x3) = (
            (u - self.u1).sqrt(),
            (u - self.u2).sqrt(),
            (u - self.u3).sqrt(),
        );
        let (y1, y2) = ((self.u3 - self.u1).sqrt(), (self.u3 - self.u2).sqrt());
        let d = u - self.u3;
        let u12 = y1 * y2 * x3 / d;
        let u13 = x1 * x3 * y2 / d;
        let u23 = x2 * x3 * y1 / d;
        2.0 * carlson_rf(u12 * u12, u13 * u13, u23 * u23)
    }

    /// 1/r after sweeping `psi` from the inner turning point (either way):
    /// the sweep is 2 / sqrt(u3 - u1) F(phi | m) with
    /// sin^2 phi = (u - u3) / (u - u2) (Byrd and Friedman 236.00), so
    /// u = (u3 - u2 sn^2) / (1 - sn^2), sn = sn(psi sqrt(u3 - u1) / 2 | m).
    pub fn u_inner(&self, psi: f64) -> f64 {
        let s = jacobi_sn_cn_dn(psi.abs() * self.half_root, self.m).0;
        let s2 = s * s;
        (self.u3 - self.u2 * s2) / (1.0 - s2)
    }

    /// Total deflection from infinity to infinity.
    pub fn deflection(&self) -> f64 {
        2.0 * self.half_sweep() - std::f64::consts::PI
    }
}

/// A planar ray of impact parameter b < b_c: no turning point, it falls
/// in from infinity (or leaves to it). The cubic has one real root u1 < 0
/// and the complex pair p +- iq; with A^2 = (p - u1)^2 + q^2 the angle swept
/// from u1 to u is F(phi | k^2) / sqrt(A), cos phi = (A - (u - u1)) /
/// (A + (u - u1)), k^2 = (A + p - u1) / (2 A) (Byrd and Friedman 239.00).
#[derive(Clone, Copy, Debug)]
pub struct Plunge {
    pub b: f64,
    pub u1: f64,
    a: f64,
    m: f64,
    k: f64,
    root_a: f64,
}

impl Plunge {
    pub fn new(b: f64) -> Plunge {
        debug_assert!(b < B_CRIT);
        let c = 1.0 / (b * b);
        // Cardano: u = t + 1/3, t^3 - t/3 + q = 0, q = c - 2/27 > 2/27 - ...
        let q = c - 2.0 / 27.0;
        let d = (0.25 * q * q - 1.0 / 729.0).max(0.0).sqrt();
        let mut u1 = (-0.5 * q + d).cbrt() + (-0.5 * q - d).cbrt() + 1.0 / 3.0;
        for _ in 0..3 {
            let f = u1 * u1 * (u1 - 1.0) + c;
            let df = u1 * (3.0 * u1 - 2.0);
            if df.abs() > 1e-12 {
                u1 -= f / df;
            }
        }
        // The roots sum to 1 and multiply to -c.
        let p = 0.5 * (1.0 - u1);
        let q2 = (-c / u1 - p * p).max(0.0);
        let a = ((p - u1) * (p - u1) + q2).sqrt();
        let m = ((a + p - u1) / (2.0 * a)).min(1.0 - 1e-16);
        Plunge {
            b,
            u1,
            a,
            m,
            k: carlson_rf(0.0, 1.0 - m, 1.0),
            root_a: a.sqrt(),
        }
    }

    /// The angle swept from the root u1 to 1/r = u (> u1).
    pub fn from_root(&self, u: f64) -> f64 {
        let x = u - self.u1;
        let cos = (self.a - x) / (self.a + x);
        let sin = 2.0 * (self.a * x).sqrt() / (self.a + x);
        let f = sin * carlson_rf(cos * cos, 1.0 - self.m * sin * sin, 1.0);
        (if cos >= 0.0 { f } else { 2.0 * self.k - f }) / self.root_a
    }

    /// 1/r after sweeping `psi` from the root u1.
    pub fn u_at(&self, psi: f64) -> f64 {
        let cn = jacobi_sn_cn_dn(psi * self.root_a, self.m).1;
        self.u1 + self.a * (1.0 - cn) / (1.0 + cn)
    }
}

/// The orbit a closed-form ray follows.
#[derive(Clone, Copy, Debug)]
pub enum Path {
    /// b > b_c outside the turning point; `psi0`: angle from the turning
    /// point at the start (negative before it).
    Turning { orbit: Orbit, psi0: f64 },
    /// b > b_c inside the inner turning point 1/u3 (a start inside the
    /// photon sphere): out to that point, if outbound, and down to the
    /// horizon; `psi0`: angle from the turning point at the start
    /// (negative before it).
    Inner { orbit: Orbit, psi0: f64 },
    /// b < b_c: no turning point; `psi0`: angle from the root u1 at the
    /// start, which grows inbound (down to the horizon) and shrinks
    /// outbound (out to infinity).
    Plunging {
        plunge: Plunge,
        psi0: f64,
        outbound: bool,
    },
}

/// A ray of the exact model in closed form, from its start `x` with
/// coordinate velocity `v` (the 3D form the integrator takes): its plane,
/// orbit and where along it it is. Exists for every ray that starts
/// outside the horizon with b not within 1e-6 of b_c (there the integrator
/// takes it): b > b_c on either side of the photon sphere, b < b_c inbound
/// or outbound.
#[derive(Clone, Copy, Debug)]
pub struct ClosedRay {
    pub path: Path,
    /// The plane: e1 towards the start, e2 along the motion.
    e1: DVec3,
    e2: DVec3,
    /// The angle swept from the start to infinity or to the horizon.
    pub sweep: f64,
    /// It ends in the hole (at r = r_s) rather than at infinity.
    pub captured: bool,
    /// 1/r at the start.
    u0: f64,
    /// Its rates in c = 1/b^2, where made with it.
    rates: Option<Rates>,
}

impl ClosedRay {
    pub fn new(x: DVec3, v: DVec3) -> Option<ClosedRay> {
        ClosedRay::new_with(x, v, false)
    }

    /// [`ClosedRay::new`] of a ray whose footprint is wanted: a turning
    /// ray makes its [`ClosedRay::rates`] with its sweeps, sharing their
    /// duplications.
    pub fn new_rated(x: DVec3, v: DVec3) -> Option<ClosedRay> {
        ClosedRay::new_with(x, v, true)
    }

    fn new_with(x: DVec3, v: DVec3, rated: bool) -> Option<ClosedRay> {
        let r = x.length();
        let l = x.cross(v);
        let h2 = l.length_squared();
        let v_inf2 = v.length_squared() - h2 / (r * r * r);
        if !(h2 > 0.0 && v_inf2 > 0.0 && r > 1.0) {
            return None;
        }
        let b = (h2 / v_inf2).sqrt();
        let e1 = x / r;
        let e2 = (v - e1 * v.dot(e1)).normalize();
        ClosedRay::planar_with(r, b, x.dot(v) < 0.0, (e1, e2), rated)
    }

    /// The ray from radius `r` (> 1) of impact parameter `b`, moving
    /// inward or not, in the plane of unit `e1` (towards the start) and
    /// `e2` (perpendicular, along the motion); None where `b` lies within
    /// 1e-6 of b_c or the start is where no ray of `b` can be.
    pub fn planar(r: f64, b: f64, inbound: bool, plane: (DVec3, DVec3)) -> Option<ClosedRay> {
        ClosedRay::planar_with(r, b, inbound, plane, false)
    }

    fn planar_with(
        r: f64,
        b: f64,
        inbound: bool,
        (e1, e2): (DVec3, DVec3),
        rated: bool,
    ) -> Option<ClosedRay> {
        let u = 1.0 / r;
        let ray = |path, sweep, captured| ClosedRay {
            path,
            e1,
            e2,
            sweep,
            captured,
            u0: u,
            rates: None,
        };
        if b > B_CRIT * (1.0 + 1e-6) {
            let orbit = Orbit::new(b);
            if u >= orbit.u3 {
                // Inside the photon sphere: it falls in, after turning at
                // 1/u3 if it starts outbound.
                let from_turn = orbit.inner_sweep(u);
                let psi0 = if inbound { from_turn } else { -from_turn };
                let path = Path::Inner { orbit, psi0 };
                return Some(ray(path, orbit.inner_sweep(1.0) - psi0, true));
            }
            // Between the turning points no ray exists (up to rounding).
            if !(u <= orbit.u2) {
                return None;
            }
            if rated {
                let (to_turn, half, rates) = orbit.turning_with_rates(u, inbound);
                let (psi0, sweep) = match inbound {
                    true => (-to_turn, to_turn + half),
                    false => (to_turn, orbit.sweep(0.0, u)),
                };
                let ray = ray(Path::Turning { orbit, psi0 }, sweep, false);
                return Some(ClosedRay {
                    rates: Some(rates),
                    ..ray
                });
            }
            let to_turn = orbit.sweep(u, orbit.u2);
            Some(if inbound {
                let path = Path::Turning {
                    orbit,
                    psi0: -to_turn,
                };
                ray(path, to_turn + orbit.half_sweep(), false)
            } else {
                let path = Path::Turning {
                    orbit,
                    psi0: to_turn,
                };
                ray(path, orbit.sweep(0.0, u), false)
            })
        } else if b < B_CRIT * (1.0 - 1e-6) {
            let plunge = Plunge::new(b);
            let psi0 = plunge.from_root(u);
            let path = Path::Plunging {
                plunge,
                psi0,
                outbound: !inbound,
            };
            Some(if inbound {
                ray(path, plunge.from_root(1.0) - psi0, true)
            } else {
                ray(path, psi0 - plunge.from_root(0.0), false)
            })
        } else {
            None
        }
    }

    /// Its impact parameter (r_s).
    pub fn b(&self) -> f64 {
        match self.path {
            Path::Turning { orbit, .. } | Path::Inner { orbit, .. } => orbit.b,
            Path::Plunging { plunge, .. } => plunge.b,
        }
    }

    /// Its plane: unit e1 towards the start, e2 along the motion.
    pub fn plane(&self) -> (DVec3, DVec3) {
        (self.e1, self.e2)
    }

    /// 1/r after sweeping `phi` from the start, and du/dphi there (from
    /// the orbit's equation, signed by its branch).
    pub fn orbit_at(&self, phi: f64) -> (f64, f64) {
        let (u, rising) = match self.path {
            // u falls away from the turning point either way.
            Path::Turning { orbit, psi0 } => (orbit.u_at(psi0 + phi), psi0 + phi < 0.0),
            // u grows away from the inner turning point.
            Path::Inner { orbit, psi0 } => (orbit.u_inner(psi0 + phi), psi0 + phi > 0.0),
            Path::Plunging {
                plunge,
                psi0,
                outbound,
            } => (
                plunge.u_at(if outbound { psi0 - phi } else { psi0 + phi }),
                !outbound,
            ),
        };
        let rate = self.rate(u);
        (u, if rising { rate } else { -rate })
    }

    /// The point after sweeping `phi` from the start.
    pub fn point(&self, phi: f64) -> DVec3 {
        self.point_at(phi, self.orbit_at(phi).0)
    }

    /// [`ClosedRay::point`] where 1/r is known to be `u`.
    pub fn point_at(&self, phi: f64, u: f64) -> DVec3 {
        let (s, c) = phi.sin_cos();
        (self.e1 * c + self.e2 * s) / u
    }

    /// The ray's direction dx/dphi after sweeping `phi` from the start
    /// (not unit): d/dphi of (e1 cos phi + e2 sin phi) / u, with du/dphi
    /// = +-sqrt(u^3 - u^2 + 1/b^2), signed by the branch of the orbit.
    pub fn tangent(&self, phi: f64) -> DVec3 {
        let (u, du) = self.orbit_at(phi);
        self.tangent_at(phi, u, du)
    }

    /// [`ClosedRay::tangent`] where 1/r and du/dphi are known.
    pub fn tangent_at(&self, phi: f64, u: f64, du: f64) -> DVec3 {
        let (s, c) = phi.sin_cos();
        let dir = self.e2 * c - self.e1 * s;
        let p = self.e1 * c + self.e2 * s;
        (dir - p * (du / u)) / u
    }

    /// The direction of motion at infinity (of an escaping ray).
    pub fn escape_direction(&self) -> DVec3 {
        let (s, c) = self.sweep.sin_cos();
        self.e1 * c + self.e2 * s
    }

    /// The angles (from the start, increasing, below the sweep to
    /// infinity) at which the ray crosses the plane z = 0; none when it
    /// lies in that plane.
    pub fn z0_crossings(&self) -> impl Iterator<Item = f64> + '_ {
        // z(phi) is proportional to e1.z cos phi + e2.z sin phi.
        let (a, c) = (self.e1.z, self.e2.z);
        let flat = a.abs() < 1e-300 && c.abs() < 1e-300;
        let mut first = (-a).atan2(c).rem_euclid(std::f64::consts::PI);
        // A start on the plane is not a crossing.
        if first <= 1e-12 {
            first += std::f64::consts::PI;
        }
        (0..)
            .map(move |k| first + k as f64 * std::f64::consts::PI)
            .take_while(move |&phi| !flat && phi < self.sweep)
    }
}

/// Most angle (rad) one closed-form segment sweeps, and most relative
/// change of 1/r along it ([`ClosedRay::segments`]; near the horizon, half
/// the way to it): its Hermite curve through exact ends and tangents then
/// lies within 3.5e-6 of the orbit.
pub const SEGMENT_SWEEP: f64 = 0.1;
pub const SEGMENT_SPAN: f64 = 0.1;

/// Beyond this radius (r_s), going out, an escaping ray's segments end in
/// one straight chord to the outer radius they were asked for.
pub const FAR: f64 = 1e6;

/// How far outside the horizon (a fraction of r_s) a captured ray's
/// segments end, as a medium's integrated rays do with spin.
pub const HORIZON_MARGIN: f64 = 1e-5;

impl ClosedRay {
    /// du/dphi's size at `u`, from the orbit's equation (du/dphi)^2 =
    /// 1/b^2 - u^2 (1 - u).
    fn rate(&self, u: f64) -> f64 {
        let b = self.b();
        (u * u * (u - 1.0) + 1.0 / (b * b)).max(0.0).sqrt()
    }

    /// The ray as a path of segments, as the integrator gives them (cubic
    /// Hermite curves through exact points and tangents of the orbit,
    /// each sweeping at most [`SEGMENT_SWEEP`] and changing 1/r by at most
    /// [`SEGMENT_SPAN`] of itself, with their unit-energy affine lengths
    /// r^2 dphi / b by Simpson's rule), to the horizon or out past radius
    /// `outer` (r_s): the radiative transfer's path on rays the closed
    /// form traces. `visit` may stop it.
    pub fn segments(&self, outer: f64, mut visit: impl FnMut(&Segment) -> Flow) -> (End, u32) {
        let b = self.b();
        // A captured ray ends just outside the horizon, where the gas's
        // clocks and frequencies still are finite.
        let end = match self.path {
            _ if !self.captured => self.sweep,
            Path::Inner { orbit, psi0 } => orbit.inner_sweep(1.0 / (1.0 + HORIZON_MARGIN)) - psi0,
            Path::Plunging { plunge, psi0, .. } => {
                plunge.from_root(1.0 / (1.0 + HORIZON_MARGIN)) - psi0
            }
            Path::Turning { .. } => self.sweep,
        }
        .min(self.sweep);
        let mut steps = 0;
        let mut phi = 0.0;
        let (mut x0, mut t0) = (self.point(0.0), self.tangent(0.0));
        while phi < end {
            // The end of an escaping ray is at infinity: it stops once out
            // past `outer`, moving away.
            let r0 = x0.length();
            let out = x0.dot(t0) > 0.0;
            if !self.captured && r0 > outer && out {
                break;
            }
            // Far out, going away, it is a straight line to `outer` (what
            // is left of its bending is below 1e-6 rad, and its sweep's
            // steps, about r_s b / r^2, would stop advancing past 1e15
            // r_s).
            if !self.captured && r0 > FAR && out {
                let d = t0.normalize();
                let along = x0.dot(d);
                let reach = -along + (along * along - r0 * r0 + outer * outer).max(0.0).sqrt();
                let seg = Segment::chord(x0, x0 + d * reach * (1.0 + 1e-9));
                steps += 1;
                if visit(&seg) == Flow::Stop {
                    return (End::Stopped, steps);
                }
                break;
            }
            let u = 1.0 / r0;
            // Towards the horizon the segments shrink with the distance to
            // it (half of it in 1/r at most), as the medium's scale does.
            let rate = self.rate(u).max(1e-300);
            let dphi = SEGMENT_SWEEP.min(SEGMENT_SPAN.min(0.5 * (1.0 - u)) * u / rate);
            let next = (phi + dphi).min(end);
            if next == self.sweep && !self.captured {
                // Infinity itself is no point.
                break;
            }
            let dphi = next - phi;
            let (x1, t1) = (self.point(next), self.tangent(next));
            let rm = self.point(phi + 0.5 * dphi).length();
            // The segment's parameter is the affine one (the transfer
            // spreads a segment's length evenly over it): its length by
            // Simpson's rule, the tangents dx/dlambda = dx/dphi b / r^2.
            let affine = dphi / 6.0 * (r0 * r0 + 4.0 * rm * rm + x1.length_squared()) / b;
            let seg = Segment {
                x0,
                v0: t0 * (b / (r0 * r0)),
                x1,
                v1: t1 * (b / x1.length_squared()),
                h: affine,
                affine,
                curved: true,
                ln_shift: [0.0; 2],
                time: [0.0; 2],
                time_rate: TimeRate::Untimed,
            };
            steps += 1;
            if visit(&seg) == Flow::Stop {
                return (End::Stopped, steps);
            }
            (phi, x0, t0) = (next, x1, t1);
        }
        match self.captured {
            true => (End::Captured, steps),
            false => (End::Escaped(self.escape_direction()), steps),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Composite Simpson's rule over [0, 1] with `n` (even) panels.
    fn simpson(g: impl Fn(f64) -> f64, n: usize) -> f64 {
        let h = 1.0 / n as f64;
        let mut sum = g(0.0) + g(1.0);
        for i in 1..n {
            sum += if i % 2 == 1 { 4.0 } else { 2.0 } * g(i as f64 * h);
        }
        sum * h / 3.0
    }

    #[test]
    fn tangents_are_the_derivatives_of_points() {
        // Each path: turning inbound and outbound, inside the photon
        // sphere, plunging in and out.
        let x = DVec3::new(7.0, 0.0, 0.0);
        let cases = [
            (x, DVec3::new(-1.0, 0.4, 0.2)),
            (x, DVec3::new(1.0, 0.6, -0.1)),
            (DVec3::new(1.3, 0.0, 0.0), DVec3::new(0.3, 1.0, 0.0)),
            (x, DVec3::new(-1.0, 0.05, 0.0)),
            (x, DVec3::new(1.0, 0.05, 0.0)),
        ];
        for (x, v) in cases {
            let ray = ClosedRay::new(x, v).expect("a closed ray");
            for k in 1..6 {
                let phi = ray.sweep * k as f64 / 6.0;
                let h = 1e-5;
                let fd = (ray.point(phi + h) - ray.point(phi - h)) / (2.0 * h);
                let t = ray.tangent(phi);
                assert!(
                    (t - fd).length() < 1e-5 * t.length().max(1.0),
                    "{v} at {phi}: {t} vs {fd}"
                );
            }
        }
    }

    #[test]
    fn deflection_is_darwins() {
        // validation/REFERENCE.md (Darwin 1959), to 1e-8 rad.
        for (b, want) in [
            (2.7, 2.919_396_339_61),
            (3.0, 1.719_388_310_23),
            (5.0, 0.590_395_787_606),
            (10.0, 0.236_135_995_388),
            (50.0, 0.041_222_539_749_3),
            (100.0, 0.020_299_966_239_5),
        ] {
            let d = Orbit::new(b).deflection();
            assert!((d - want).abs() < 1e-10, "b {b}: {d} vs {want}");
        }
    }

    #[test]
    fn plunging_rays_invert_their_sweep() {
        for b in [0.5, 1.5, 2.3, 2.59] {
            let p = Plunge::new(b);
            assert!(p.u1 < 0.0);
            let f = |u: f64| u * u * (u - 1.0) + 1.0 / (b * b);
            assert!(f(p.u1).abs() < 1e-14, "b {b}: root {}", p.u1);
            for u in [0.0, 0.3, 0.7, 1.0, 3.0] {
                let psi = p.from_root(u);
                assert!(
                    (p.u_at(psi) - u).abs() < 1e-11 * (1.0 + u),
                    "b {b} u {u}: {}",
                    p.u_at(psi)
                );
            }
            // The sweep from infinity to the horizon against a direct
            // quadrature of dphi/du = 1 / sqrt(u^3 - u^2 + 1/b^2) (smooth on
            // [0, 1] below b_c): composite Simpson on 20000 panels.
            let want = simpson(|u| 1.0 / f(u).sqrt(), 20_000);
            let got = p.from_root(1.0) - p.from_root(0.0);
            assert!((got - want).abs() < 1e-9 * want, "b {b}: {got} vs {want}");
        }
    }

    #[test]
    fn rays_inside_the_photon_sphere_invert_their_sweep() {
        for b in [2.62, 3.0, 5.0, 30.0, 1e3] {
            let o = Orbit::new(b);
            assert!(o.u3 > 2.0 / 3.0 && o.u3 < 1.0, "b {b}: u3 {}", o.u3);
            for k in 0..=10 {
                let u = o.u3 + (1.0 - o.u3) * k as f64 / 10.0;
                let psi = o.inner_sweep(u);
                assert!(
                    (o.u_inner(psi) - u).abs() < 1e-11,
                    "b {b} u {u}: {}",
                    o.u_inner(psi)
                );
                assert!(
                    (o.u_inner(-psi) - u).abs() < 1e-11,
                    "symmetric about the turn"
                );
            }
            // From the turning point to the horizon against a direct
            // quadrature: with t = u3 + s^2, dphi = 2 ds / sqrt((t - u1)(t - u2)),
            // smooth on [0, sqrt(1 - u3)].
            let top = (1.0 - o.u3).sqrt();
            let want = simpson(
                |w| {
                    let t = o.u3 + (w * top).powi(2);
                    2.0 * top / ((t - o.u1) * (t - o.u2)).sqrt()
                },
                20_000,
            );
            let got = o.inner_sweep(1.0);
            assert!((got - want).abs() < 1e-10 * want, "b {b}: {got} vs {want}");
        }
    }

    #[test]
    fn outbound_rays_below_b_c_escape() {
        // Leaving r = 2 and 1.2 r_s outward at angles a to the radial:
        // the sweep to infinity against a direct quadrature of
        // dphi/du = 1 / sqrt(u^3 - u^2 + 1/b^2) from 0 to the start's u.
        let mut checked = 0;
        for r in [2.0f64, 1.2] {
            for a in [0.05f64, 0.3, 0.6, 0.9, 1.2] {
                let x = DVec3::new(r, 0.0, 0.0);
                let v = DVec3::new(a.cos(), a.sin(), 0.0);
                let h2 = x.cross(v).length_squared();
                let b = (h2 / (1.0 - h2 / (r * r * r))).sqrt();
                if b > B_CRIT * 0.999 {
                    continue;
                }
                let ray = ClosedRay::new(x, v).expect("closed form");
                assert!(!ray.captured, "r {r} a {a}");
                let u0 = 1.0 / r;
                let f = |u: f64| u * u * (u - 1.0) + 1.0 / (b * b);
                let want = simpson(|w| u0 / f(w * u0).sqrt(), 20_000);
                assert!(
                    (ray.sweep - want).abs() < 1e-9 * want,
                    "r {r} a {a}: {} vs {want}",
                    ray.sweep
                );
                checked += 1;
            }
        }
        assert!(checked >= 6, "{checked}");
    }

    #[test]
    fn deflection_next_to_the_photon_sphere() {
        // b from 2.6 to 2.7 r_s, where the ray circles the photon sphere:
        // against a direct quadrature of the half sweep with u = u2 (1 - s^2),
        // which removes the turning point's singularity (composite Simpson,
        // 200000 panels; the roots checked as roots).
        for b in [2.6, 2.61, 2.63, 2.65, 2.678_479, 2.7] {
            let o = Orbit::new(b);
            for u in [o.u1, o.u2, o.u3] {
                assert!((u * u * (u - 1.0) + 1.0 / (b * b)).abs() < 1e-15);
            }
            let g = |s: f64| {
                let u = o.u2 * (1.0 - s * s);
                2.0 * o.u2 / (o.u2 * (u - o.u1) * (o.u3 - u)).sqrt()
            };
            let want = 2.0 * simpson(g, 200_000) - std::f64::consts::PI;
            let got = o.deflection();
            assert!((got - want).abs() < 1e-6, "b {b}: {got} vs {want}");
            if b == 2.678_479 {
                // validation/REFERENCE.md: deflection pi at b = 2.678479 r_s
                // (to the 7 digits given, about 4e-5 rad).
                assert!((got - std::f64::consts::PI).abs() < 1e-4, "{got}");
            }
        }
    }

    #[test]
    fn far_rays_follow_the_weak_field_series() {
        // Keeton and Petters (2005): delta = 4 (M/b) + (15 pi / 4)(M/b)^2
        // + (128/3)(M/b)^3 + (3465 pi / 64)(M/b)^4 + O((M/b)^5), M = 1/2;
        // the next term is below 3e-14 rad here.
        for b in [1e3, 3e3, 1e4] {
            let m = 0.5;
            let series = 4.0 * m / b
                + 15.0 * std::f64::consts::PI * m * m / (4.0 * b * b)
                + 128.0 * m * m * m / (3.0 * b * b * b)
                + 3465.0 * std::f64::consts::PI / 64.0 * (m / b).powi(4);
            let d = Orbit::new(b).deflection();
            assert!((d - series).abs() < 1e-13, "b {b}: {d} vs {series}");
        }
    }

    #[test]
    fn the_radius_after_a_sweep_inverts_the_sweep() {
        for b in [2.61, 3.0, 7.0, 1e4] {
            let o = Orbit::new(b);
            for f in [0.0, 0.1, 0.5, 0.9, 1.0] {
                let u = f * o.u2;
                let psi = o.sweep(u, o.u2);
                let err = (o.u_at(psi) - u).abs() / o.u2;
                assert!(err < 1e-12, "b {b} f {f}: {err:e}");
            }
        }
    }
}

#[cfg(test)]
mod segment_tests {
    use super::*;

    #[test]
    fn closed_segments_follow_the_orbit() {
        // Rays from 500 r_s towards the hole at b = 2 (captured), 2.7 (near
        // the photon sphere), 5 and 40 r_s: each segment's Hermite curve,
        // in its affine parameter, passes its middle on the exact orbit
        // (the radius there against the orbit's at the same angle).
        for b in [2.0, 2.7, 5.0, 40.0] {
            let r0: f64 = 500.0;
            let x = DVec3::new(r0, 0.0, 0.0);
            let sin = b / r0;
            let v = DVec3::new(-(1.0 - sin * sin).sqrt(), sin, 0.0);
            let ray = ClosedRay::new(x, v).unwrap();
            let (e1, e2) = ray.plane();
            let mut worst = 0.0f64;
            let mut last = x;
            let (end, steps) = ray.segments(600.0, |seg| {
                let mid = seg.point(0.5);
                let angle = mid
                    .dot(e2)
                    .atan2(mid.dot(e1))
                    .rem_euclid(std::f64::consts::TAU);
                let exact = ray.point(angle).length();
                worst = worst.max((mid.length() - exact).abs() / exact);
                last = seg.x1;
                Flow::Continue
            });
            println!("b {b}: {steps} segments, worst {worst:e}, {end:?}");
            assert!(worst < 5e-6, "b {b}: {worst}");
            assert_eq!(matches!(end, End::Captured), b < 2.598);
            if b < 2.598 {
                // It ends 1e-5 outside the horizon.
                assert!((last.length() - 1.00001).abs() < 1e-9, "{}", last.length());
            }
        }
    }
}
