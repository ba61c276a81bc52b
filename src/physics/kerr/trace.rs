//! The Kerr-Schild tracer: Dormand-Prince 5(4) on Hamilton's equations
//! with error control, and the exact direction at infinity of an escaping
//! photon (the tail, in Mino time). The WGSL twin of the integrator and
//! tail is `src/gpu/kerr.wgsl`.

use super::Kerr;
use super::ks::ks_p_theta;
use glam::DVec3;

impl Kerr {
    /// The exact direction at infinity of the outbound photon at the state
    /// (x, p) of energy `e`, well past its last radial turning point (its
    /// direction within 60 degrees of the outward radial, as for the
    /// Schwarzschild tail). The rest of the path in Mino time (d lambda_M
    /// = d lambda / Sigma, in which Carter's equations separate): the time
    /// to infinity G = integral of dr / sqrt(R) and the radial part of the
    /// azimuth's advance by Gauss-Legendre quadrature in u = 1/r, the
    /// polar motion theta'' = Theta'(theta) / 2 over G with error control
    /// (through a pole if L_z = 0), and the Kerr-Schild azimuth's own term,
    /// the integral of a / Delta dr.
    pub fn ks_escape_direction(self, x: DVec3, p: DVec3, e: f64) -> DVec3 {
        use crate::physics::tail::quad;
        let a = self.a;
        let sph = self.spheroidal(x);
        let (st, ct) = sph.th.sin_cos();
        let lz = x.x * p.y - x.y * p.x;
        // d theta / d lambda_M = p_th.
        let p_th = ks_p_theta(x, p, sph.r, (st, ct));
        let q = self.carter_q(p_th, lz, e, (st, ct));
        let k = q + (lz - a * e).powi(2);
        let u0 = 1.0 / sph.r;
        let energy_term = |u: f64| e * (1.0 + a * a * u * u) - a * lz * u * u;
        let delta_u = |u: f64| 1.0 - 2.0 * u + a * a * u * u;
        // R(r) / r^4 in u: the radial potential, smooth down to u = 0.
        let radial = |u: f64| energy_term(u).powi(2) - u * u * delta_u(u) * k;
        let mino = u0 * quad(|t| 1.0 / radial(u0 * t).sqrt());
        let phi_radial = u0
            * quad(|t| {
                let u = u0 * t;
                a * energy_term(u) / (delta_u(u) * radial(u).sqrt()) + a / delta_u(u)
            });
        // The polar motion and its part of the azimuth over Mino time.
        // How close to the axis the polar motion swings: u = cos theta
        // turns where Q - c1 u^2 - a^2 E^2 u^4 = 0.
        let c1 = q + lz * lz - a * a * e * e;
        let ae2 = a * a * e * e;
        let u_turn2 = if ae2 > 0.0 {
            (-c1 + (c1 * c1 + 4.0 * ae2 * q).max(0.0).sqrt()) / (2.0 * ae2)
        } else {
            q / c1.max(1e-300)
        };
        let (th, phi_polar) = if u_turn2 > 0.9 {
            // Near a pole, in theta (through it if L_z = 0: theta < 0 is
            // the other side): theta'' = Theta'(theta) / 2.
            let f = |y: &DVec3| {
                let (s, c) = y.x.sin_cos();
                let pole = if lz == 0.0 { 0.0 } else { lz / (s * s) };
                DVec3::new(y.y, -ae2 * c * s + pole * pole * c * s, pole - a * e)
            };
            let y = integrate_mino(f, DVec3::new(sph.th, p_th, 0.0), mino, q, a * e);
            (y.x, y.z)
        } else {
            // Elsewhere in u = cos theta, whose equation is polynomial (no
            // trigonometry in the loop): u'' = -c1 u - 2 a^2 E^2 u^3.
            let f = |y: &DVec3| {
                let u = y.x;
                DVec3::new(
                    y.y,
                    -c1 * u - 2.0 * ae2 * u * u * u,
                    lz / (1.0 - u * u) - a * e,
                )
            };
            let y = integrate_mino(f, DVec3::new(ct, -st * p_th, 0.0), mino, q, a * e);
            (y.x.clamp(-1.0, 1.0).acos(), y.z)
        };
        let phi = sph.phi + phi_radial + phi_polar;
        let (s, c) = th.sin_cos();
        DVec3::new(s * phi.cos(), s * phi.sin(), c)
    }

    /// Traces the photon at the Kerr-Schild state (x, p) of energy `e`
    /// (M units) with Dormand-Prince 5(4) on Hamilton's equations, local
    /// error `tolerance` relative to r and |p|; each accepted step is
    /// handed to `visit` as a [`Segment`] in r_s (the scene's units, half
    /// of M's: the cubic Hermite curve through the ends' positions and
    /// d x / d lambda), and the state's momentum at its end. It ends
    /// captured inside the horizon, or inbound inside both the prograde
    /// photon orbit (inside which no photon turns back out) and
    /// `limits.inner`; escaped with the exact tail once outbound beyond
    /// `limits.outer` and 60 degrees from radial; stopped by `visit`; or
    /// abandoned after `limits.max_steps`. With `TIME` each segment
    /// carries the light's travel time from its ends to the start (r_s/c;
    /// the ray runs back in time), its error held to the tolerance too.
    pub fn ks_trace<const TIME: bool>(
        self,
        x: DVec3,
        p: DVec3,
        e: f64,
        tolerance: f64,
        limits: &crate::physics::Limits,
        mut visit: impl FnMut(&crate::physics::Segment, DVec3) -> crate::physics::Flow,
    ) -> crate::physics::Trace {
        use crate::physics::{End, Trace};
        let done = |end, steps| Trace {
            end,
            steps,
            ln_shift: 0.0,
        };
        let (mut x, mut p) = (x, p);
        let (horizon, capture, outer) = self.trace_bounds(limits);
        let outbound = |x: DVec3, v: DVec3, r: f64| {
            r > outer && r > 4.0 && x.dot(v) >= 0.5 * x.length() * v.length()
        };
        let mut r = self.ks_radius(x);
        let mut v = self.ks_flow(x, p, e).dx;
        if outbound(x, v, r) {
            return done(End::Escaped(self.ks_escape_direction(x, p, e)), 0);
        }
        // The state and minus Boyer-Lindquist's time (the travel time back
        // from the start, in M).
        let f = |y: &KsState| {
            let fl = self.flow::<TIME>(y.x, y.p, e);
            KsState {
                x: fl.dx,
                p: fl.dp,
                t: -fl.dt_bl,
            }
        };
        let mut time = 0.0;
        let first = self.ks_flow(x, p, e);
        let mut rate = -first.dt_bl;
        let mut k = KsState {
            x: first.dx,
            p: first.dp,
            t: rate,
        };
        let mut h = 0.05 * r / v.length();
        let mut steps = 0;
        while steps < limits.max_steps {
            let speed = v.length();
            h = h.min(0.5 * r / speed);
            let y = KsState { x, p, t: time };
            let (yn, err, kn) = crate::physics::gr::dp45(f, &y, &k, h);
            let (xn, pn) = (yn.x, yn.p);
            let (ex, ep) = (err.x.length(), err.p.length());
            let rn = self.ks_radius(xn);
            let et = if TIME { err.t.abs() } else { 0.0 };
            let err = (ex.max(et) / (tolerance * r.max(rn))).max(ep / (tolerance * p.length()));
            if !(err <= 1.0) {
                if !err.is_finite() || h < 1e-12 * r / speed {
                    return done(End::Abandoned, steps);
                }
                h *= (0.9 * step_factor(err)).max(0.2);
                continue;
            }
            steps += 1;
            // The step's last stage is the flow at its end.
            let vn = kn.x;
            let (tn, rate_n) = (yn.t, kn.t);
            k = kn;
            let seg = segment::<TIME>([x, xn], [v, vn], (h, e), [time, tn], [rate, rate_n]);
            (time, rate) = (tn, rate_n);
            if visit(&seg, pn) == crate::physics::Flow::Stop {
                return done(End::Stopped, steps);
            }
            (x, p, v, r) = (xn, pn, vn, rn);
            if (r < horizon || r < capture) && x.dot(v) < 0.0 || r < self.horizon() {
                return done(End::Captured, steps);
            }
            if outbound(x, v, r) {
                return done(End::Escaped(self.ks_escape_direction(x, p, e)), steps);
            }
            h *= if err > 0.0 {
                (0.9 * step_factor(err)).min(5.0)
            } else {
                5.0
            };
        }
        done(End::Abandoned, steps)
    }

    /// [`Kerr::ks_trace`]'s radii (M) for `limits` (r_s): where a ray is
    /// captured at the horizon, where an inbound one is captured, and
    /// beyond which an outbound one may escape.
    fn trace_bounds(self, limits: &crate::physics::Limits) -> (f64, f64, f64) {
        // A ray traced back towards the horizon comes from the past one
        // (an eternal hole's white hole), which Kerr-Schild's ingoing
        // chart reaches only as its azimuth winds without end: it is
        // captured (black, as from a collapsed star) once it is within
        // 1e-3 of r_+, a few turns of winding in. Where something lies
        // down to the horizon (`limits.inner` of 0: a medium) it is
        // followed to 1e-5: a medium's light from within r_+ (1 + d)
        // grows as sqrt(d) (Gold et al.'s test 1 gains 0.06% from 1e-3
        // to 1e-5; what 1e-5 leaves is a tenth of that).
        let margin = if limits.inner > 0.0 { 1e-3 } else { 1e-5 };
        let horizon = self.horizon() * (1.0 + margin);
        // Every object lies beyond limits.inner (r_s) from the centre, so
        // beyond Boyer-Lindquist's sqrt(inner^2 - a^2) (in M).
        let inner = ((2.0 * limits.inner).powi(2) - self.a * self.a)
            .max(0.0)
            .sqrt();
        let capture = inner.min(Kerr::new(self.a.abs()).photon_orbit());
        // In M: limits are in r_s.
        let outer = 2.0 * limits.outer;
        (horizon, capture, outer)
    }
}

/// The segment in r_s of a step of parameter length `h` of a photon of
/// energy `e` between the points `x` with velocities `v` (M units), with
/// `TIME` its ends' travel times and their rates.
#[inline(always)]
fn segment<const TIME: bool>(
    [x, xn]: [DVec3; 2],
    [v, vn]: [DVec3; 2],
    (h, e): (f64, f64),
    [time, tn]: [f64; 2],
    [rate, rate_n]: [f64; 2],
) -> crate::physics::Segment {
    crate::physics::Segment {
        x0: x * 0.5,
        v0: v * 0.5,
        x1: xn * 0.5,
        v1: vn * 0.5,
        h,
        // A unit-energy photon's affine parameter is e times this one's;
        // in r_s, half of M's.
        affine: 0.5 * (e * h).abs(),
        curved: true,
        ln_shift: [0.0; 2],
        time: if TIME {
            [0.5 * time, 0.5 * tn]
        } else {
            [0.0; 2]
        },
        time_rate: if TIME {
            crate::physics::TimeRate::Ends([0.5 * rate * h, 0.5 * rate_n * h])
        } else {
            crate::physics::TimeRate::Untimed
        },
    }
}

/// The tracer's state: position, spatial momentum and (last) minus
/// Boyer-Lindquist's time, or their rates.
#[derive(Clone, Copy)]
struct KsState {
    x: DVec3,
    p: DVec3,
    t: f64,
}

impl std::ops::Add for KsState {
    type Output = KsState;
    #[inline(always)]
    fn add(self, o: KsState) -> KsState {
        KsState {
            x: self.x + o.x,
            p: self.p + o.p,
            t: self.t + o.t,
        }
    }
}

impl std::ops::Mul<f64> for KsState {
    type Output = KsState;
    #[inline(always)]
    fn mul(self, c: f64) -> KsState {
        KsState {
            x: self.x * c,
            p: self.p * c,
            t: self.t * c,
        }
    }
}

/// err^(-1/5), the step's growth for an error `err` of the tolerance, to
/// 0.3%: an exponent-halving guess from the float's bits and two Newton
/// steps on y^-5 = err (a factor needs no more; libm's powf, even in f32,
/// cost a tenth of the tracer's time). For err in 1e-30 to 1e30.
#[inline]
fn step_factor(err: f64) -> f64 {
    const ONE: u64 = 0x3ff0_0000_0000_0000;
    // bits(y) = bits(1) - (bits(err) - bits(1)) / 5: y's exponent is
    // -1/5 of err's, its mantissa linear between.
    let bits = err.to_bits();
    let mut y = f64::from_bits(if bits >= ONE {
        ONE - (bits - ONE) / 5
    } else {
        ONE + (ONE - bits) / 5
    });
    for _ in 0..2 {
        let y2 = y * y;
        y *= 0.2 * (6.0 - err * y2 * y2 * y);
    }
    y
}

/// The polar motion's state y = (angle or cos, its rate, the azimuth's
/// polar part) carried over Mino time `mino` by Dormand-Prince 5(4) with
/// error control, 1e-10 of the motion's scale (which a photon of Carter's
/// `q` and a E `ae` sets): directions to 1e-11 rad, far below any pixel
/// (1e-12 cost 40% more of the tail's time for nothing seen).
fn integrate_mino(
    f: impl Fn(&DVec3) -> DVec3 + Copy,
    mut y: DVec3,
    mino: f64,
    q: f64,
    ae: f64,
) -> DVec3 {
    let (mut done, mut h) = (0.0, mino / 4.0);
    let scale = 1.0 + (q.abs() + ae * ae).sqrt() * mino;
    let mut tries = 0;
    let mut k = f(&y);
    while done < mino && tries < 100_000 {
        tries += 1;
        h = h.min(mino - done);
        let (yn, err, kn) = crate::physics::gr::dp45(f, &y, &k, h);
        let err = err.abs().max_element() / (1e-10 * scale);
        if err <= 1.0 {
            (y, k) = (yn, kn);
            done += h;
        }
        h *= (0.9 * step_factor(err.max(1e-10))).clamp(0.2, 5.0);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::kerr::tests::{angle, rk4, zamo_photon};

    #[test]
    fn the_step_factor_is_the_fifth_root_to_three_per_mille() {
        let mut worst = 0.0f64;
        for i in -600..=600 {
            let err = 10f64.powf(i as f64 / 50.0);
            let want = err.powf(-0.2);
            worst = worst.max((step_factor(err) / want - 1.0).abs());
        }
        eprintln!("worst {worst:e}");
        assert!(worst < 3e-3, "{worst}");
    }

    #[test]
    fn the_escape_tail_agrees_with_integrating_on() {
        // From a state at r ~ 20 the tail's direction equals integrating
        // Hamilton's equations on to r ~ 400 and taking the tail there; and
        // without spin it is the Schwarzschild tail's.
        for (a, r, th, n) in [
            (0.9, 20.0, 1.2, [0.8, 0.3, 0.5]),
            (0.9, 20.0, 0.4, [0.7, -0.6, -0.3]),
            (-0.7, 25.0, 2.5, [0.9, 0.2, -0.4]),
            (0.998, 30.0, 1.5, [0.95, 0.0, 0.3]),
            (0.9, 20.0, 0.3, [0.8, -0.6, 0.0]),
        ] {
            let k = Kerr::new(a);
            // Forward, and traced back (the photon arriving along -n:
            // momentum and energy negated), as camera rays are.
            for back in [false, true] {
                let (x0, p0, e0) = zamo_photon(k, r, th, 0.7, n.map(|c| if back { -c } else { c }));
                let (mut x, mut p, e) = if back { (x0, -p0, -e0) } else { (x0, p0, e0) };
                let near = k.ks_escape_direction(x, p, e);
                while k.ks_radius(x) < 400.0 {
                    (x, p) = rk4(k, x, p, e, 0.002 * k.ks_radius(x));
                }
                let far = k.ks_escape_direction(x, p, e);
                assert!(
                    angle(near, far) < 1e-9,
                    "a {a} th {th} back {back}: {}",
                    angle(near, far)
                );
            }
        }
        let k = Kerr::new(0.0);
        let (x, p, e) = zamo_photon(k, 12.0, 1.0, 0.3, [0.7, 0.5, 0.4]);
        let v = k.ks_flow(x, p, e).dx;
        // Schwarzschild's tail works in r_s = 2M.
        let schwarzschild = crate::physics::tail::gr_escape_direction(x / 2.0, v);
        assert!(angle(k.ks_escape_direction(x, p, e), schwarzschild) < 1e-11);
    }

    #[test]
    fn a_traced_ray_keeps_its_constants_to_1e9_at_tolerance_1e10() {
        // E is exact (p_t is not integrated); L_z and Q relative to their
        // scale at every accepted step, for rays that pass close by,
        // through the ergosphere, over a pole, and that fall in.
        let limits = crate::physics::Limits {
            outer: 30.0,
            inner: 0.0,
            max_steps: 100_000,
        };
        for (a, r, th, n, end) in [
            (0.9, 60.0, 1.3, [-0.99, 0.02, 0.1], "escaped"),
            (0.998, 60.0, 1.5, [-0.996, 0.0, 0.09], "any"),
            (0.9, 60.0, 0.2, [-0.995, 0.1, 0.0], "escaped"),
            (-0.9, 60.0, 1.0, [-1.0, 0.01, -0.02], "captured"),
            (0.9, 3.0, 1.5, [0.3, 0.1, 0.9], "any"),
        ] {
            let k = Kerr::new(a);
            let (x, p, e) = zamo_photon(k, r, th, 0.4, n);
            let (lz0, q0) = k.ks_constants(x, p, e);
            let scale_l = 1.0 + lz0.abs();
            let scale_q = 1.0 + q0.abs();
            let mut worst: f64 = 0.0;
            let t = k.ks_trace::<false>(x, p, e, 1e-10, &limits, |seg, pn| {
                let (l, q) = k.ks_constants(seg.x1 * 2.0, pn, e);
                worst = worst
                    .max((l - lz0).abs() / scale_l)
                    .max((q - q0).abs() / scale_q);
                crate::physics::Flow::Continue
            });
            assert!(worst < 1e-9, "a {a} th {th}: drift {worst:e} ({:?})", t.end);
            match end {
                "escaped" => assert!(
                    matches!(t.end, crate::physics::End::Escaped(_)),
                    "{:?}",
                    t.end
                ),
                "captured" => assert_eq!(t.end, crate::physics::End::Captured),
                _ => assert_ne!(t.end, crate::physics::End::Abandoned),
            }
        }
    }

    #[test]
    fn without_spin_the_trace_is_the_schwarzschild_tracers() {
        // The same camera ray traced both ways: the same escape direction
        // and the same path (the disk plane's crossing).
        let k = Kerr::new(0.0);
        let limits = crate::physics::Limits {
            outer: 20.0,
            inner: 0.0,
            max_steps: 100_000,
        };
        let mut crossed = 0;
        for n in [
            [-0.99, 0.05, 0.12],
            [-0.98, -0.1, 0.17],
            [-0.995, 0.0, 0.0995],
        ] {
            let (x, p, e) = zamo_photon(k, 40.0, 1.45, 0.2, n);
            let v = k.ks_flow(x, p, e).dx;
            let mut kerr_cross = None;
            let kt = k.ks_trace::<false>(x, p, e, 1e-10, &limits, |seg, _| {
                if kerr_cross.is_none() {
                    kerr_cross = seg.crossing_z0().map(|s| seg.point(s));
                }
                crate::physics::Flow::Continue
            });
            let mut gr_cross = None;
            let gt = crate::physics::gr::trace::<false>(x / 2.0, v, 1e-10, &limits, |seg| {
                if gr_cross.is_none() {
                    gr_cross = seg.crossing_z0().map(|s| seg.point(s));
                }
                crate::physics::Flow::Continue
            });
            match (kt.end, gt.end) {
                (crate::physics::End::Escaped(a), crate::physics::End::Escaped(b)) => {
                    assert!(angle(a, b) < 1e-8, "{n:?}: {}", angle(a, b))
                }
                (a, b) => assert_eq!(a, b, "{n:?}"),
            }
            if let (Some(a), Some(b)) = (kerr_cross, gr_cross) {
                assert!(a.distance(b) < 1e-7 * a.length(), "{a} vs {b}");
                crossed += 1;
            } else {
                assert_eq!(kerr_cross.is_some(), gr_cross.is_some());
            }
        }
        assert!(crossed >= 2, "{crossed} rays crossed the plane");
    }
}
