//! Transfer along Kerr's closed-form rays ([`KerrRay`]).
//!
//! The ray is walked in stretches of Mino time s. At each stretch's ends
//! the closed form gives r and cos theta and, from the geodesic, their
//! rates (dr/ds = +-sqrt(R), d cos theta / ds from the polar motion's
//! Jacobi functions). Between them:
//! - the affine length, the integral of Sigma ds (Sigma = r^2 + a^2 cos^2
//!   theta), by three-point Gauss-Legendre quadrature on cubic Hermite
//!   curves of 1/r and cos theta in s (far out 1/r is nearly linear in s,
//!   where r^2 is not: over a stretch of affine length h r its relative
//!   error is about h^6 / 400);
//! - the points, cubic Hermite curves of r and cos theta in the affine
//!   parameter (far out r is nearly linear in it), whose rates are the
//!   Mino ones over Sigma; through a medium that is not the same at every
//!   azimuth, the azimuth's likewise ([`KerrRay::azimuth_at`]), a stretch
//!   then sweeping at most [`TURN`] of it.
//!
//! Each stretch is then walked by the pieces' loop as an integrator's
//! segment is, its parameter even in the affine length, so each piece's
//! middle is its affine middle. A stretch's affine length is at most
//! [`STRETCH`] of its radius, its polar phase at most [`SWING`] rad, and
//! near the horizon it covers at most half the way to it.

use super::{Bounds, Path, RayTransfer, Transport};
use crate::physics::kerr::Kerr;
use crate::physics::kerr_closed::{KerrRay, State};
use glam::DVec3;

/// Most affine length of a stretch, as a fraction of its radius.
pub const STRETCH: f64 = 0.2;

/// Most polar phase a stretch sweeps (rad of the Jacobi argument).
pub const SWING: f64 = 0.5;

/// Most azimuth a stretch sweeps (rad, judged by its rate at the start)
/// through a medium that is not the same at every azimuth: its cubic's
/// error is then below about 1e-5 rad.
pub const TURN: f64 = 0.25;

/// Gauss-Legendre's three nodes on [-1, 1] (0 and +-sqrt(3/5)) and
/// weights (8/9 and 5/9).
const GAUSS_NODE: f64 = 0.774_596_669_241_483_4;
const GAUSS_MID: f64 = 8.0 / 9.0;
const GAUSS_SIDE: f64 = 5.0 / 9.0;

/// The cubic through values `f` with rates `d` (per unit of t) at t = 0
/// and 1, at t.
#[inline]
fn hermite((f0, f1): (f64, f64), (d0, d1): (f64, f64), t: f64) -> f64 {
    let (t2, t3) = (t * t, t * t * t);
    f0 * (2.0 * t3 - 3.0 * t2 + 1.0)
        + f1 * (3.0 * t2 - 2.0 * t3)
        + d0 * (t3 - 2.0 * t2 + t)
        + d1 * (t3 - t2)
}

/// The least and greatest of the cubic [`hermite`] on [t0, t1] (at the
/// ends or where its rate vanishes between them), and its values at t0
/// and t1.
#[allow(clippy::type_complexity)]
fn hermite_range(f: (f64, f64), d: (f64, f64), (t0, t1): (f64, f64)) -> ((f64, f64), (f64, f64)) {
    let at = |t: f64| hermite(f, d, t);
    let ends = (at(t0), at(t1));
    let (mut lo, mut hi) = (ends.0.min(ends.1), ends.0.max(ends.1));
    // The rate a t^2 + b t + c (hermite's derivative).
    let a = 6.0 * (f.0 - f.1) + 3.0 * (d.0 + d.1);
    let b = 6.0 * (f.1 - f.0) - 4.0 * d.0 - 2.0 * d.1;
    let c = d.0;
    let mut root = |t: f64| {
        if t > t0 && t < t1 {
            let v = at(t);
            (lo, hi) = (lo.min(v), hi.max(v));
        }
    };
    if a == 0.0 {
        if b != 0.0 {
            root(-c / b);
        }
    } else {
        let disc = b * b - 4.0 * a * c;
        if disc >= 0.0 {
            // Without cancellation: q = -(b + sign(b) sqrt(disc)) / 2.
            let q = -0.5 * (b + disc.sqrt().copysign(b));
            root(q / a);
            if q != 0.0 {
                root(c / q);
            }
        }
    }
    ((lo, hi), ends)
}

/// One stretch of a closed-form Kerr ray, parametrised by t from 0 to 1
/// evenly in its affine length; lengths in M.
struct Stretch {
    /// r and cos theta at the ends, and their rates per unit of t.
    r: ((f64, f64), (f64, f64)),
    cos: ((f64, f64), (f64, f64)),
    /// The Kerr-Schild azimuth at the ends and its rates per unit of t,
    /// where the medium is not the same at every azimuth (the points
    /// stand at azimuth 0 otherwise); the hole's spin, for the points.
    phi: Option<((f64, f64), (f64, f64))>,
    spin: f64,
    /// Affine length per unit of Mino time's rate at the ends (length /
    /// Sigma): a rate d/ds there times it is the rate per unit of t.
    per: (f64, f64),
    /// Its affine length (M).
    length: f64,
    cm_per_m: f64,
    /// The ray's least and greatest cos theta ([`KerrRay::cos_range`]):
    /// the curve of cos theta overshoots a polar turning point by about
    /// 1e-4 of a swing's amplitude, which near the axis would carry it
    /// past the pole, where the flow's angular velocity diverges.
    cos_range: (f64, f64),
}

impl Stretch {
    /// The stretch from state `a` to state `b`, `ds` of Mino time apart,
    /// of a hole of spin `spin`, its points at azimuth 0 until it is
    /// [`Stretch::turned`].
    fn new(
        (a, b): (State, State),
        ds: f64,
        (spin, cos_range): (f64, (f64, f64)),
        cm_per_m: f64,
    ) -> Stretch {
        let sigma = |r: f64, c: f64| Kerr::new(spin).sigma_cos(r, c);
        let (ra, ra_dot, ca, ca_dot) = (a.r, a.r_dot, a.cos, a.cos_dot);
        let (rb, rb_dot, cb, cb_dot) = (b.r, b.r_dot, b.cos, b.cos_dot);
        // 1/r and cos theta in s, the rates per unit of the stretch.
        let inv = (
            (1.0 / ra, 1.0 / rb),
            (-ra_dot / (ra * ra) * ds, -rb_dot / (rb * rb) * ds),
        );
        let cos_s = ((ca, cb), (ca_dot * ds, cb_dot * ds));
        let sigma_at = |t: f64| {
            let (i, c) = (hermite(inv.0, inv.1, t), hermite(cos_s.0, cos_s.1, t));
            sigma(1.0 / i, c)
        };
        let side = sigma_at(0.5 - 0.5 * GAUSS_NODE) + sigma_at(0.5 + 0.5 * GAUSS_NODE);
        let length = 0.5 * ds * (GAUSS_MID * sigma_at(0.5) + GAUSS_SIDE * side);
        // d/dlambda = (d/ds) / Sigma; per unit of t, times the length.
        let (per_a, per_b) = (length / sigma(ra, ca), length / sigma(rb, cb));
        Stretch {
            r: ((ra, rb), (ra_dot * per_a, rb_dot * per_b)),
            cos: ((ca, cb), (ca_dot * per_a, cb_dot * per_b)),
            phi: None,
            spin,
            per: (per_a, per_b),
            length,
            cm_per_m,
            cos_range,
        }
    }
}

impl Stretch {
    /// The stretch with its points at the azimuths and d phi / ds at its
    /// ends ([`KerrRay::azimuth_at`]), for a medium not the same at every
    /// azimuth.
    fn turned(mut self, ((pa, da), (pb, db)): ((f64, f64), (f64, f64))) -> Stretch {
        self.phi = Some(((pa, pb), (da * self.per.0, db * self.per.1)));
        self
    }
}

impl Path for Stretch {
    #[inline]
    fn at(&self, t: f64) -> (f64, f64, DVec3) {
        let r = hermite(self.r.0, self.r.1, t);
        let c = hermite(self.cos.0, self.cos.1, t).clamp(self.cos_range.0, self.cos_range.1);
        let sin = (1.0 - c * c).max(0.0).sqrt();
        let Some((phi, rates)) = self.phi else {
            return (r, c, DVec3::new(r * sin, 0.0, r * c));
        };
        // Kerr::cartesian, with sin and cos theta at hand.
        let (sp, cp) = hermite(phi, rates, t).sin_cos();
        let a = self.spin;
        (
            r,
            c,
            DVec3::new(sin * (r * cp - a * sp), sin * (r * sp + a * cp), r * c),
        )
    }

    #[inline]
    fn length(&self, t0: f64, t1: f64) -> f64 {
        (t1 - t0) * self.length
    }

    #[inline]
    fn cm(&self, t0: f64, t1: f64) -> f64 {
        (t1 - t0) * self.length * self.cm_per_m
    }

    fn bounds(&self, t0: f64, t1: f64) -> Option<Bounds> {
        // Widened by 1e-12 of the values for the round-off of the points'
        // own coordinates.
        let pad = |(lo, hi): (f64, f64)| {
            let e = 1e-12 * lo.abs().max(hi.abs()).max(1.0);
            (lo - e, hi + e)
        };
        let span = |(f, d): ((f64, f64), (f64, f64))| {
            let (range, ends) = hermite_range(f, d, (t0, t1));
            (pad(range), ends)
        };
        let (r, r_ends) = span(self.r);
        let ((c0, c1), cos_ends) = span(self.cos);
        let (lo, hi) = self.cos_range;
        let angle = |c: f64| c.clamp(lo, hi).clamp(-1.0, 1.0).acos();
        let theta = (angle(c1), angle(c0));
        let phi = self.phi.map(span);
        // Over so short a stretch a curve turns back at most once: its
        // way is then twice its range less the net change.
        let way = |(lo, hi): (f64, f64), (a, b): (f64, f64)| {
            (2.0 * (hi - lo) - (b - a).abs()).max(hi - lo)
        };
        let travel = [
            way(r, r_ends),
            way(theta, (angle(cos_ends.0), angle(cos_ends.1))),
            phi.map_or(0.0, |(p, ends)| way(p, ends)),
        ];
        let phi = phi.map(|(p, _)| p);
        Some(Bounds {
            r,
            theta,
            phi,
            travel,
        })
    }

    #[inline]
    fn k_at(&self, t: f64) -> (f64, f64) {
        let rate = |((r0, r1), (d0, d1)): ((f64, f64), (f64, f64))| {
            let t2 = t * t;
            r0 * (6.0 * t2 - 6.0 * t)
                + r1 * (6.0 * t - 6.0 * t2)
                + d0 * (3.0 * t2 - 4.0 * t + 1.0)
                + d1 * (3.0 * t2 - 2.0 * t)
        };
        (-rate(self.r) / self.length, -rate(self.cos) / self.length)
    }
}

/// Beyond this radius (M), going out, a ray is walked to the medium's end
/// as a straight line: what is left of its bending is below 1e-6 rad, and
/// Mino time near the ray's end at infinity runs out of digits (its step
/// at radius r is 0.2 / r of a time of order 1, so that past about 1e15 M
/// it stops advancing).
pub const FAR: f64 = 1e6;

/// The straight radial path of a ray far out, from radius `r0` (M) to
/// `r0 + length` along the unit `direction` (its direction at infinity
/// there, to b / r).
struct Straight {
    r0: f64,
    direction: DVec3,
    length: f64,
    cm_per_m: f64,
}

impl Path for Straight {
    #[inline]
    fn at(&self, t: f64) -> (f64, f64, DVec3) {
        let r = self.r0 + t * self.length;
        (r, self.direction.z, r * self.direction)
    }

    #[inline]
    fn length(&self, t0: f64, t1: f64) -> f64 {
        (t1 - t0) * self.length
    }

    #[inline]
    fn cm(&self, t0: f64, t1: f64) -> f64 {
        (t1 - t0) * self.length * self.cm_per_m
    }

    #[inline]
    fn k_at(&self, _: f64) -> (f64, f64) {
        // Far out dr/dlambda is 1 and the ray radial; the photon runs
        // inward.
        (-1.0, 0.0)
    }
}

/// Gathers the medium along `ray` from Mino time `s_start` to `s_stop`,
/// at the camera frequencies `nu_cam`; gives the stretches walked.
pub fn along_kerr_ray(
    transfer: &mut RayTransfer,
    t: &Transport,
    ray: &KerrRay,
    (s_start, s_stop): (f64, f64),
    nu_cam: &[f64],
) -> u32 {
    let polar_rate = ray.polar_rate();
    // Past this radius, going out, the ray has left the medium for good
    // (it turns in r once at most).
    let beyond = 1.2 * t.medium.extent();
    let horizon = t.kerr.horizon();
    // The azimuth, where the medium is not the same at every one: found
    // at a stretch's ends only where it may shine there.
    let turning = !t.medium.axisymmetric();
    let mut s = s_start;
    let mut here = ray.state_at(s);
    // A ray that never comes near enough meets nothing; one coming in
    // from beyond starts where it comes within reach (the closed form's
    // Mino time of that radius on the way in, checked by its point).
    if ray.min_radius() > beyond {
        return 0;
    }
    if here.r > beyond && here.r_dot < 0.0 {
        let s_in = ray.mino_at_approach(beyond);
        if s_in > s && s_in < s_stop {
            let there = ray.state_at(s_in);
            if (there.r / beyond - 1.0).abs() < 1e-9 {
                (s, here) = (s_in, there);
            }
        }
    }
    let mut here_phi = None;
    let mut stretches = 0;
    while s < s_stop && !transfer.spent() {
        let State {
            r, r_dot, cos: c, ..
        } = here;
        if r > FAR && r_dot > 0.0 {
            if r < beyond {
                let sin = (1.0 - c * c).max(0.0).sqrt();
                let phi = if turning {
                    here_phi.unwrap_or_else(|| ray.azimuth_at(s, &here)).0
                } else {
                    0.0
                };
                let (sp, cp) = phi.sin_cos();
                let path = Straight {
                    r0: r,
                    direction: DVec3::new(sin * cp, sin * sp, c),
                    length: beyond - r,
                    cm_per_m: t.cm_per_m,
                };
                transfer.run(t, &path, (0.0, 1.0), nu_cam);
                stretches += 1;
            }
            break;
        }
        let sigma = t.kerr.sigma_cos(r, c);
        // Towards the horizon, as the pieces do, covering at most half
        // the way to it, and again shorter where the radius ran faster.
        let fall = 0.5 * (r - horizon) / r_dot.abs().max(1e-300);
        let turn = if turning {
            TURN / ray.azimuth_rate(&here).abs()
        } else {
            f64::INFINITY
        };
        let mut ds = (STRETCH * r / sigma)
            .min(SWING / polar_rate)
            .min(fall)
            .min(turn);
        let (mut e, mut there);
        loop {
            e = (s + ds).min(s_stop);
            there = ray.state_at(e);
            if e == s_stop || there.r - horizon > 0.4 * (r - horizon) {
                break;
            }
            ds *= 0.5;
        }
        if there.r > r && r > beyond {
            break;
        }
        let stretch = Stretch::new(
            (here, there),
            e - s,
            (t.kerr.a, ray.cos_range()),
            t.cm_per_m,
        );
        // Dark at every azimuth: no azimuths needed.
        let mut there_phi = None;
        if !turning {
            transfer.run(t, &stretch, (0.0, 1.0), nu_cam);
        } else if !stretch.bounds(0.0, 1.0).is_some_and(|b| t.medium.dark(&b)) {
            let from = here_phi.unwrap_or_else(|| ray.azimuth_at(s, &here));
            there_phi = Some(ray.azimuth_at(e, &there));
            let stretch = stretch.turned((from, there_phi.unwrap()));
            transfer.run(t, &stretch, (0.0, 1.0), nu_cam);
        }
        (s, here, here_phi) = (e, there, there_phi);
        stretches += 1;
    }
    stretches
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::kerr_closed::sample_rays as rays;

    /// The Mino time where `ray` ends: near the horizon or at infinity.
    fn ray_end(kerr: Kerr, ray: &KerrRay) -> f64 {
        if ray.captured {
            ray.mino_at_fall(1.01 * kerr.horizon())
        } else {
            ray.mino_to_end()
        }
    }

    /// Each stretch of `ray` (to its end, within radius `within`) as the
    /// walk's limits on length and polar phase cut it, with the states at
    /// its ends.
    fn each_stretch(
        kerr: Kerr,
        ray: &KerrRay,
        within: f64,
        mut f: impl FnMut(&Stretch, State, State),
    ) {
        let end = ray_end(kerr, ray);
        let (mut s, mut here) = (0.0, ray.state_at(0.0));
        while s < end && here.r < within {
            let e = (s + STRETCH * here.r / (here.r * here.r))
                .min(s + SWING / ray.polar_rate())
                .min(end);
            let there = ray.state_at(e);
            f(
                &Stretch::new((here, there), e - s, (kerr.a, ray.cos_range()), 1.0),
                here,
                there,
            );
            (s, here) = (e, there);
        }
    }

    #[test]
    fn a_stretchs_travel_is_its_curves_way_there_and_back() {
        // Rays about a = 0.9 from 50 M, passing the hole at 3 to 12 M and
        // over its pole (r and theta turn back within stretches): the
        // travel a stretch's bounds give in r and theta is the way its
        // points go, summed over 4096 steps.
        let kerr = Kerr::new(0.9);
        let x = DVec3::new(25.0, 0.0, 43.3);
        let (mut stretches, mut turned) = (0, 0);
        for i in 0..40 {
            let aim = DVec3::new(0.0, 3.0 + 0.3 * i as f64, 2.0 - 0.1 * i as f64);
            let Some(ray) = KerrRay::from_ks(kerr, x, (aim - x).normalize(), false) else {
                continue;
            };
            each_stretch(kerr, &ray, 60.0, |stretch, here, there| {
                let b = stretch.bounds(0.0, 1.0).unwrap();
                let (mut way, mut last) = ([0.0; 2], stretch.at(0.0));
                for k in 1..=4096 {
                    let p = stretch.at(k as f64 / 4096.0);
                    way[0] += (p.0 - last.0).abs();
                    way[1] += (p.1.acos() - last.1.acos()).abs();
                    last = p;
                }
                for d in 0..2 {
                    let (got, want) = (b.travel[d], way[d]);
                    assert!(
                        (got - want).abs() <= 1e-6 * want + 1e-9,
                        "{i}: travel {got} against {want} ({d})"
                    );
                }
                stretches += 1;
                turned += usize::from(way[0] > (here.r - there.r).abs() + 1e-9);
            });
        }
        assert!(
            stretches > 500 && turned > 10,
            "{stretches} stretches, {turned} turning"
        );
    }

    #[test]
    fn stretches_near_the_axis_stay_on_the_rays_side_of_it() {
        // Rays from 50 M passing the axis of a = 0.9 at 1e-3 to 0.3 M
        // (eta up to about 60): the curves between a stretch's ends
        // overshoot a polar turning point inside it, which put points on
        // the axis itself, where Gold's flow turns infinitely fast (NaN
        // samples). Every point within the ray's range of cos theta, and
        // the light through test 4's flow finite.
        let kerr = Kerr::new(0.9);
        let gold = crate::transfer::Medium::Gold2020(crate::transfer::Gold::test(4, 230e9));
        let t = Transport {
            medium: &gold,
            kerr,
            cm_per_m: 6e11,
        };
        let x = DVec3::new(25.0, 0.0, 43.3);
        let mut walked = 0;
        for i in 0..300 {
            let side = 2e-5 * 300f64.powf(i as f64 / 299.0);
            let v = ((DVec3::new(0.0, 0.0, 14.0) - x).normalize() + DVec3::new(0.0, side, 0.0))
                .normalize();
            let Some(ray) = KerrRay::from_ks(kerr, x, v, false) else {
                continue;
            };
            let (lo, hi) = ray.cos_range();
            each_stretch(kerr, &ray, 100.0, |stretch, _, _| {
                for k in 0..=64 {
                    let c = stretch.at(k as f64 / 64.0).1;
                    assert!(lo <= c && c <= hi, "{side}: {c} outside {lo}..{hi}");
                }
            });
            let mut transfer = RayTransfer::new(1.0, ray.lambda(), 1);
            along_kerr_ray(
                &mut transfer,
                &t,
                &ray,
                (0.0, ray_end(kerr, &ray)),
                &[230e9],
            );
            assert!(
                transfer.intensity[0].is_finite(),
                "{side}: {:?}",
                transfer.intensity
            );
            walked += 1;
        }
        assert!(walked > 250, "{walked}");
    }

    #[test]
    fn stretches_give_the_rays_affine_length() {
        // The stretches' lengths, added along the walk, against Simpson's
        // rule on Sigma from the closed form over 200000 intervals; a
        // captured ray's fall reaches the radius asked for.
        for (kerr, ray, end) in rays() {
            if ray.captured {
                let r = ray.state_at(end).r;
                assert!((r - 1.01 * kerr.horizon()).abs() < 1e-9, "{r}");
            }
            let sigma = |s: f64| {
                let at = ray.state_at(s);
                kerr.sigma_cos(at.r, at.cos)
            };
            let n = 200_000;
            let h = end / n as f64;
            let want: f64 = (0..n)
                .map(|i| {
                    let s = i as f64 * h;
                    h / 6.0 * (sigma(s) + 4.0 * sigma(s + 0.5 * h) + sigma(s + h))
                })
                .sum();
            let (mut s, mut here, mut got) = (0.0, ray.state_at(0.0), 0.0);
            while s < end {
                let (r, c) = (here.r, here.cos);
                let ds = (STRETCH * r / kerr.sigma_cos(r, c)).min(SWING / ray.polar_rate());
                let e = (s + ds).min(end);
                let there = ray.state_at(e);
                got += Stretch::new((here, there), e - s, (kerr.a, ray.cos_range()), 1.0).length;
                (s, here) = (e, there);
            }
            assert!(
                ((got - want) / want).abs() < 2e-6,
                "a {}: {got} against {want}",
                kerr.a
            );
        }
    }
}
