//! Exact null geodesics of the Schwarzschild spacetime (the integrator
//! [`super::Spacetime::Schwarzschild`] traces with; the Kerr hole has its
//! own, [`super::kerr`]).
//!
//! In Schwarzschild coordinates read as Cartesian, x = r (sin th cos ph,
//! ...), every null geodesic obeys x'' = -(3/2) r_s h^2 x / |x|^5 with h =
//! |x x x'| conserved, in an affine parameter. |x'| is deliberately NOT renormalised
//! (that would move the capture radius from 2.598 r_s to about 4.08 r_s).
//! Integration is Dormand-Prince 5(4) with local error control; segments are
//! cubic Hermite curves through the accepted states, so a plane crossing is
//! found to the integrator's own order.

use super::{End, Flow, Limits, PHOTON_SPHERE, Segment, TimeRate, Trace, may_escape};
use glam::DVec3;

/// Largest step as a fraction of r / |x'|: keeps segments short enough for
/// plane and object tests even where the error estimate would allow more.
const MAX_STEP_FRACTION: f64 = 0.5;

/// Impact parameter b = h / v_inf of a coordinate state (r_s units).
pub fn impact_parameter(x: DVec3, v: DVec3) -> f64 {
    let h2 = x.cross(v).length_squared();
    let r = x.length();
    (h2 / (v.length_squared() - h2 / (r * r * r))).sqrt()
}

// Dormand-Prince 5(4) tableau.
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

/// The tableau by name, for the GPU's header (its shader reads the same
/// numbers as `DP_A21`, ...).
pub(crate) const DORMAND_PRINCE: [(&str, f64); 26] = [
    ("DP_A21", A21),
    ("DP_A31", A31),
    ("DP_A32", A32),
    ("DP_A41", A41),
    ("DP_A42", A42),
    ("DP_A43", A43),
    ("DP_A51", A51),
    ("DP_A52", A52),
    ("DP_A53", A53),
    ("DP_A54", A54),
    ("DP_A61", A61),
    ("DP_A62", A62),
    ("DP_A63", A63),
    ("DP_A64", A64),
    ("DP_A65", A65),
    ("DP_B1", B1),
    ("DP_B3", B3),
    ("DP_B4", B4),
    ("DP_B5", B5),
    ("DP_B6", B6),
    ("DP_E1", E1),
    ("DP_E3", E3),
    ("DP_E4", E4),
    ("DP_E5", E5),
    ("DP_E6", E6),
    ("DP_E7", E7),
];

/// The geodesic equation's acceleration at `x` of a photon with `k` =
/// (3/2) h^2 (h = |x x x'|, conserved): x'' = -k x / |x|^5.
#[inline(always)]
pub(crate) fn acceleration(x: DVec3, k: f64) -> DVec3 {
    let r2 = x.length_squared();
    let r = r2.sqrt();
    x * (-k / (r2 * r2 * r))
}

/// The conserved `k` of the state (x, v), for [`acceleration`].
#[inline]
pub(crate) fn invariant(x: DVec3, v: DVec3) -> f64 {
    1.5 * x.cross(v).length_squared()
}

/// The photon's energy at infinity of the state (x, v) with invariant `k`
/// (v_inf^2 = |v|^2 - h^2 / r^3).
#[inline]
pub(crate) fn energy(x: DVec3, v: DVec3, k: f64) -> f64 {
    let r = x.length();
    (v.length_squared() - 2.0 / 3.0 * k / (r * r * r)).sqrt()
}

/// Coordinate time per affine parameter of a photon of energy `e` at `x`
/// (dt/dlambda = E / (1 - r_s/r)).
#[inline(always)]
pub(crate) fn time_rate(x: DVec3, e: f64) -> f64 {
    e / (1.0 - 1.0 / x.length())
}

/// One Dormand-Prince 5(4) step of size `h` of the autonomous system y' =
/// `f`(y) of a vector state (any type with + and * f64) from `y`, whose
/// derivative `k1` is known (the last stage of the step before: first same
/// as last): the fifth-order state, its error estimate and its derivative
/// (the Kerr tracer and its escape tail's polar motion).
pub(crate) fn dp45<S>(f: impl Fn(&S) -> S, y: &S, k1: &S, h: f64) -> (S, S, S)
where
    S: Copy + std::ops::Add<Output = S> + std::ops::Mul<f64, Output = S>,
{
    // Written out so that each stage is straight-line vector arithmetic,
    // summed from the state on with the newest stage last: a stage waits
    // only one product and one sum for the one before.
    let (y, k1) = (*y, *k1);
    let k2 = f(&(y + k1 * (A21 * h)));
    let k3 = f(&(y + k1 * (A31 * h) + k2 * (A32 * h)));
    let k4 = f(&(y + k1 * (A41 * h) + k2 * (A42 * h) + k3 * (A43 * h)));
    let k5 = f(&(y + k1 * (A51 * h) + k2 * (A52 * h) + k3 * (A53 * h) + k4 * (A54 * h)));
    let k6 = f(&(y
        + k1 * (A61 * h)
        + k2 * (A62 * h)
        + k3 * (A63 * h)
        + k4 * (A64 * h)
        + k5 * (A65 * h)));
    let yn = y + k1 * (B1 * h) + k3 * (B3 * h) + k4 * (B4 * h) + k5 * (B5 * h) + k6 * (B6 * h);
    let k7 = f(&yn);
    let err = (k1 * E1 + k3 * E3 + k4 * E4 + k5 * E5 + k6 * E6 + k7 * E7) * h;
    (yn, err, k7)
}

/// One Dormand-Prince step of size `h` from (x, v) whose acceleration is
/// `a1`. Returns the new state, its acceleration (first stage of the next
/// step), the error estimates of position and velocity, and with `TIME`
/// the coordinate time the step takes for a photon of energy `e` (the same
/// fifth-order weights over the stages) and its error estimate (both 0
/// without `TIME`).
#[inline(always)]
#[allow(clippy::type_complexity)]
fn dp_step<const TIME: bool>(
    x: DVec3,
    v: DVec3,
    a1: DVec3,
    h: f64,
    k: f64,
    e: f64,
) -> (DVec3, DVec3, DVec3, DVec3, DVec3, [f64; 2]) {
    let v1 = v;
    let x2 = x + v1 * (h * A21);
    let v2 = v + a1 * (h * A21);
    let a2 = acceleration(x2, k);
    let x3 = x + (v1 * A31 + v2 * A32) * h;
    let v3 = v + (a1 * A31 + a2 * A32) * h;
    let a3 = acceleration(x3, k);
    let x4 = x + (v1 * A41 + v2 * A42 + v3 * A43) * h;
    let v4 = v + (a1 * A41 + a2 * A42 + a3 * A43) * h;
    let a4 = acceleration(x4, k);
    let x5 = x + (v1 * A51 + v2 * A52 + v3 * A53 + v4 * A54) * h;
    let v5 = v + (a1 * A51 + a2 * A52 + a3 * A53 + a4 * A54) * h;
    let a5 = acceleration(x5, k);
    let x6 = x + (v1 * A61 + v2 * A62 + v3 * A63 + v4 * A64 + v5 * A65) * h;
    let v6 = v + (a1 * A61 + a2 * A62 + a3 * A63 + a4 * A64 + a5 * A65) * h;
    let a6 = acceleration(x6, k);
    let xn = x + (v1 * B1 + v3 * B3 + v4 * B4 + v5 * B5 + v6 * B6) * h;
    let vn = v + (a1 * B1 + a3 * B3 + a4 * B4 + a5 * B5 + a6 * B6) * h;
    let an = acceleration(xn, k);
    let ex = (v1 * E1 + v3 * E3 + v4 * E4 + v5 * E5 + v6 * E6 + vn * E7) * h;
    let ev = (a1 * E1 + a3 * E3 + a4 * E4 + a5 * E5 + a6 * E6 + an * E7) * h;
    let dt = if TIME {
        let rates = [x, x3, x4, x5, x6, xn].map(|p| time_rate(p, e));
        let [r1, r3, r4, r5, r6, r7] = rates;
        [
            h * (B1 * r1 + B3 * r3 + B4 * r4 + B5 * r5 + B6 * r6),
            h * (E1 * r1 + E3 * r3 + E4 * r4 + E5 * r5 + E6 * r6 + E7 * r7),
        ]
    } else {
        [0.0; 2]
    };
    (xn, vn, an, ex, ev, dt)
}

/// Traces the exact null geodesic from `x` along coordinate direction `v`;
/// with `TIME` each segment also carries the coordinate time the light
/// takes from its ends to `x` (dt/dlambda = E / (1 - r_s/r)).
pub fn trace<const TIME: bool>(
    mut x: DVec3,
    mut v: DVec3,
    tolerance: f64,
    limits: &Limits,
    mut visit: impl FnMut(&Segment) -> Flow,
) -> Trace {
    let r_origin = x.length();
    // The exact model's shifts are closed forms of the observer's and
    // emitter's radii (physics::shift), not a property of the path.
    let done = |end, steps| Trace {
        end,
        steps,
        ln_shift: 0.0,
    };
    let k = invariant(x, v);
    let capture_radius = limits.inner.min(PHOTON_SPHERE);
    let mut r = r_origin;
    if may_escape(x, v, r, limits) {
        return done(End::Escaped(super::tail::gr_escape_direction(x, v)), 0);
    }
    let mut a = acceleration(x, k);
    let mut h = 0.05 * r / v.length();
    let mut steps = 0;
    // The photon's energy: v_inf^2 = |v|^2 - h^2 / r^3, conserved.
    let e = energy(x, v, k);
    let mut time = 0.0;
    while steps < limits.max_steps {
        let speed = v.length();
        h = h.min(MAX_STEP_FRACTION * r / speed);
        let (xn, vn, an, ex, ev, [dt, et]) = dp_step::<TIME>(x, v, a, h, k, e);
        let rn = xn.length();
        // A timed trace also holds the time's error to the tolerance (a
        // radial ray has no position error to hold its steps short).
        let err = (ex.length().max(et.abs()) / (tolerance * r.max(rn)))
            .max(ev.length() / (tolerance * speed));
        if !(err <= 1.0) {
            if !err.is_finite() || h < 1e-12 * r / speed {
                return done(End::Abandoned, steps);
            }
            h *= (0.9 * err.powf(-0.2)).max(0.2);
            continue;
        }
        steps += 1;
        let seg = Segment {
            x0: x,
            v0: v,
            x1: xn,
            v1: vn,
            h,
            affine: (e * h).abs(),
            curved: true,
            ln_shift: [0.0; 2],
            time: [time, time + dt],
            time_rate: if TIME {
                TimeRate::Schwarzschild(e * h)
            } else {
                TimeRate::Untimed
            },
        };
        time += dt;
        if visit(&seg) == Flow::Stop {
            return done(End::Stopped, steps);
        }
        x = xn;
        v = vn;
        a = an;
        r = rn;
        if r < 1.0 || (r < capture_radius && x.dot(v) < 0.0) {
            return done(End::Captured, steps);
        }
        if may_escape(x, v, r, limits) {
            return done(End::Escaped(super::tail::gr_escape_direction(x, v)), steps);
        }
        h *= if err > 0.0 {
            (0.9 * err.powf(-0.2)).min(5.0)
        } else {
            5.0
        };
    }
    done(End::Abandoned, steps)
}
