//! Light propagation around a Schwarzschild black hole.
//!
//! All geometry here is dimensionless: lengths in units of the Schwarzschild
//! radius r_s = 2GM/c^2 and time in r_s/c, so one tracer serves every mass
//! (scale invariance is exact by construction). The black hole sits at the
//! origin.
//!
//! Two models share one interface ([`Model::trace`]): the assignment's
//! Newtonian-with-|v|=c update ([`seed`]) and exact null geodesics in
//! Schwarzschild coordinates treated as Cartesian ([`gr`]). A traced ray is a
//! sequence of [`Segment`]s handed to a visitor, which tests them against the
//! scene and may stop the ray; a ray that can no longer hit anything ends with
//! its exact asymptotic direction ([`tail`]).

pub mod closed;
pub mod dual;
pub mod elliptic;
pub mod gr;
pub mod kerr;
pub mod seed;
pub mod shift;
pub mod spacetime;
pub mod tail;

/// The Kerr closed form's path before it moved under `kerr`.
pub use kerr::closed as kerr_closed;
pub use spacetime::{Frame, Observer, Spacetime};

use glam::DVec3;

/// Photon sphere radius (r_s): inside it, an inbound ray of the exact model
/// cannot come back out.
pub const PHOTON_SPHERE: f64 = 1.5;
/// Critical impact parameter of the exact model, (3 sqrt 3 / 2) r_s.
pub const B_CRIT_GR: f64 = 2.598_076_211_353_316;
/// Capture impact parameter of the seed model, sqrt(e) r_s.
pub const B_CAPTURE_SEED: f64 = 1.648_721_270_700_128;

/// Which equations move the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// The assignment's model with its first-order update and a variable step
    /// dt = `step` * r / c.
    Seed {
        /// Step as a fraction of r/c.
        step: f64,
    },
    /// Exact null geodesics of `spacetime`, Dormand-Prince 5(4) with
    /// error control.
    Gr {
        /// Relative error allowed per step.
        tolerance: f64,
        /// The spacetime the light moves in.
        spacetime: Spacetime,
    },
}

/// Bounds that let a ray end early without losing accuracy.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Every object lies inside this radius (r_s); an outbound ray beyond it
    /// can only reach the sky.
    pub outer: f64,
    /// No object lies inside this radius (r_s); with the exact model an
    /// inbound ray inside both it and the photon sphere is captured.
    pub inner: f64,
    /// Steps before a ray is abandoned.
    pub max_steps: u32,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            outer: 0.0,
            inner: f64::INFINITY,
            max_steps: 100_000,
        }
    }
}

/// One step of a traced ray: the path between two states.
#[derive(Clone, Copy, Debug)]
pub struct Segment {
    /// Position at the start (r_s).
    pub x0: DVec3,
    /// Derivative of position at the start (per unit of the step parameter).
    pub v0: DVec3,
    /// Position at the end.
    pub x1: DVec3,
    /// Derivative of position at the end.
    pub v1: DVec3,
    /// Parameter length of the step (time or affine parameter).
    pub h: f64,
    /// The step's length in the affine parameter of a photon of unit
    /// energy at infinity (k_t = -1; r_s): what radiative transfer
    /// integrates over (the fluid-frame path length is -k.u times it).
    /// The seed model, whose space has no metric, gives the chord's length.
    pub affine: f64,
    /// Whether the path between the ends is the cubic Hermite curve through
    /// both states (exact model) or the straight chord (the seed model's own
    /// polyline).
    pub curved: bool,
    /// Seed model: ln(nu_obs / nu_emit) for light emitted at each end and
    /// received at the ray's origin, from the running sum of a.v dt / c^2
    /// (the shift is linear in between). Exact model: 0; its shift is a
    /// closed form of position ([`gr`]).
    pub ln_shift: [f64; 2],
    /// Coordinate time (r_s/c) the light takes from each end to the
    /// trace's origin, when the trace keeps time (else 0).
    pub time: [f64; 2],
    /// How the time runs between the ends of a curved segment.
    pub time_rate: TimeRate,
}

/// How a curved segment's time runs between its ends
/// ([`Segment::time_at`]); chords run linearly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeRate {
    /// No time kept (the start's time everywhere).
    Untimed,
    /// Schwarzschild: d(time)/ds = scale / (1 - r_s/r), scale = E h (the
    /// photon's energy times the step).
    Schwarzschild(f64),
    /// d(time)/ds at the two ends: the time is the cubic Hermite through
    /// both ends' times and rates (fifth-order steps keep it to the
    /// step's fourth order).
    Ends([f64; 2]),
}

impl Segment {
    /// The straight chord from `a` to `b`: a flat-space step (far from the
    /// hole, where a ray no longer bends), its affine length a unit-energy
    /// photon's there.
    pub(crate) fn chord(a: DVec3, b: DVec3) -> Segment {
        Segment {
            x0: a,
            v0: b - a,
            x1: b,
            v1: b - a,
            h: 1.0,
            affine: (b - a).length(),
            curved: false,
            ln_shift: [0.0; 2],
            time: [0.0; 2],
            time_rate: TimeRate::Untimed,
        }
    }

    /// The light's travel time from fraction `s` of the segment to the
    /// trace's origin: linear along a seed chord; along the exact model's
    /// curve, dt/ds integrated by 4-point Gauss-Legendre from its start
    /// (a cubic in s would be only fourth order in the step, and steps
    /// along nearly radial rays are long).
    #[inline]
    pub fn time_at(&self, s: f64) -> f64 {
        let [t0, t1] = self.time;
        if !self.curved {
            return t0 + (t1 - t0) * s;
        }
        let scale = match self.time_rate {
            TimeRate::Untimed => return t0,
            TimeRate::Ends([d0, d1]) => {
                let (s2, s3) = (s * s, s * s * s);
                return t0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + d0 * (s3 - 2.0 * s2 + s)
                    + t1 * (-2.0 * s3 + 3.0 * s2)
                    + d1 * (s3 - s2);
            }
            TimeRate::Schwarzschild(scale) => scale,
        };
        const X: [f64; 4] = [
            -0.861_136_311_594_052_6,
            -0.339_981_043_584_856_3,
            0.339_981_043_584_856_3,
            0.861_136_311_594_052_6,
        ];
        const W: [f64; 4] = [
            0.347_854_845_137_453_9,
            0.652_145_154_862_546_1,
            0.652_145_154_862_546_1,
            0.347_854_845_137_453_9,
        ];
        let sum: f64 = X
            .iter()
            .zip(W)
            .map(|(x, w)| w / (1.0 - 1.0 / self.point(0.5 * s * (1.0 + x)).length()))
            .sum();
        t0 + scale * 0.5 * s * sum
    }

    /// Seed model: the running ln(nu_obs / nu_emit) at fraction `s` (linear
    /// along the segment); 0 for the exact model.
    #[inline]
    pub fn ln_shift_at(&self, s: f64) -> f64 {
        self.ln_shift[0] + (self.ln_shift[1] - self.ln_shift[0]) * s
    }

    /// Point at fraction `s` in [0, 1] of the segment.
    pub fn point(&self, s: f64) -> DVec3 {
        if !self.curved {
            return self.x0 + (self.x1 - self.x0) * s;
        }
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        self.x0 * h00 + self.v0 * (h10 * self.h) + self.x1 * h01 + self.v1 * (h11 * self.h)
    }

    /// Direction of travel at fraction `s` (not normalised).
    pub fn tangent(&self, s: f64) -> DVec3 {
        if !self.curved {
            return self.x1 - self.x0;
        }
        let s2 = s * s;
        let d00 = 6.0 * s2 - 6.0 * s;
        let d10 = 3.0 * s2 - 4.0 * s + 1.0;
        let d01 = -6.0 * s2 + 6.0 * s;
        let d11 = 3.0 * s2 - 2.0 * s;
        self.x0 * d00 + self.v0 * (d10 * self.h) + self.x1 * d01 + self.v1 * (d11 * self.h)
    }

    /// Fraction `s` in (0, 1] where the path crosses the plane z = 0, if its
    /// ends lie on opposite sides (or it ends on the plane).
    pub fn crossing_z0(&self) -> Option<f64> {
        let (z0, z1) = (self.x0.z, self.x1.z);
        if z0 == 0.0 || (z0 > 0.0) == (z1 > 0.0) && z1 != 0.0 {
            return None;
        }
        let lin = z0 / (z0 - z1);
        if !self.curved {
            return Some(lin);
        }
        // Bracketed root of the Hermite cubic: Illinois false position
        // converges in a handful of iterations and never leaves the bracket.
        let (mut a, mut b, mut fa, mut fb) = (0.0, 1.0, z0, z1);
        let mut s = lin;
        let mut side = 0;
        for _ in 0..40 {
            let fs = self.point(s).z;
            if fs == 0.0 {
                return Some(s);
            }
            if (fs > 0.0) == (fa > 0.0) {
                a = s;
                fa = fs;
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                b = s;
                fb = fs;
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
            if b - a < 1e-13 {
                break;
            }
            s = (a * fb - b * fa) / (fb - fa);
        }
        Some(s)
    }
}

/// What the visitor wants after seeing a segment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Keep tracing.
    Continue,
    /// The ray ended on something the visitor found.
    Stop,
}

/// How a traced ray ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// Crossed the horizon (or, exact model, fell inside the photon sphere).
    Captured,
    /// Left for infinity in this (unit) direction.
    Escaped(DVec3),
    /// The visitor stopped it.
    Stopped,
    /// Ran out of steps or met a non-finite state; shaded black and counted.
    Abandoned,
}

/// Result of tracing one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trace {
    /// How it ended.
    pub end: End,
    /// Accepted integration steps.
    pub steps: u32,
    /// Seed model: ln(nu_obs / nu_emit) for light from infinity, from the
    /// running sum of a.v dt / c^2 along the path plus the exact remainder
    /// beyond the last step (escaped rays only). Exact model: 0; its shift
    /// is a closed form of the radii ([`shift`]).
    pub ln_shift: f64,
}

/// The reflected direction of a ray travelling along `dir` off a surface
/// with normal `n` (either orientation).
#[inline]
pub fn reflect(dir: DVec3, n: DVec3) -> DVec3 {
    dir - n * (2.0 * dir.dot(n))
}

impl Model {
    /// Traces a ray from `x` (r_s) with initial direction `v` (any length;
    /// for the exact model this is the coordinate direction, see
    /// [`Spacetime::camera_direction`]). Each step's segment goes to `visit`.
    pub fn trace(
        &self,
        x: DVec3,
        v: DVec3,
        limits: &Limits,
        visit: impl FnMut(&Segment) -> Flow,
    ) -> Trace {
        self.run::<false>(x, v, limits, visit)
    }

    /// [`Model::trace`] with each segment's light travel time
    /// ([`Segment::time`]): `gr` integrates dt/dlambda = E / (1 - r_s/r)
    /// with the step's own fifth-order weights, `seed` takes the optical
    /// path (length times the index) of each chord.
    pub fn trace_timed(
        &self,
        x: DVec3,
        v: DVec3,
        limits: &Limits,
        visit: impl FnMut(&Segment) -> Flow,
    ) -> Trace {
        self.run::<true>(x, v, limits, visit)
    }

    fn run<const TIME: bool>(
        &self,
        x: DVec3,
        v: DVec3,
        limits: &Limits,
        visit: impl FnMut(&Segment) -> Flow,
    ) -> Trace {
        match *self {
            Model::Seed { step } => seed::trace::<TIME>(x, v, step, limits, visit),
            Model::Gr {
                tolerance,
                spacetime,
            } => spacetime.trace::<TIME>(x, v, tolerance, limits, visit),
        }
    }

    /// The exact model in Schwarzschild spacetime at `tolerance`.
    pub fn gr(tolerance: f64) -> Model {
        Model::Gr {
            tolerance,
            spacetime: Spacetime::Schwarzschild,
        }
    }

    /// The spacetime of the exact model (none for the seed model, whose
    /// space is flat).
    pub fn spacetime(&self) -> Option<Spacetime> {
        match self {
            Model::Gr { spacetime, .. } => Some(*spacetime),
            Model::Seed { .. } => None,
        }
    }

    /// Radius of the shadow's edge seen by an observer at `r` (r_s), as an
    /// angle from the direction to the hole (radians).
    pub fn shadow_angle(&self, r: f64) -> Option<f64> {
        match self {
            Model::Seed { .. } => Some(
                (B_CAPTURE_SEED / r * (-1.0 / (2.0 * r)).exp())
                    .min(1.0)
                    .asin(),
            ),
            Model::Gr { spacetime, .. } => spacetime.shadow_angle(r),
        }
    }
}

/// Whether an outbound ray at `x` moving along `v` can stop integrating:
/// beyond every object and far enough from periapsis that the exact tail
/// quadrature is accurate.
#[inline]
pub(crate) fn may_escape(x: DVec3, v: DVec3, r: f64, limits: &Limits) -> bool {
    // cos(angle to radial) >= 0.5: the tail integrand stays smooth.
    r > limits.outer && r > 2.0 && x.dot(v) >= 0.5 * r * v.length()
}

/// Bending (rad) still ahead of a seed-model ray when it may hand over to
/// the exact tail, estimated in the weak field as (1 - cos psi) / (2 b).
const SEED_REMAINING_BEND: f64 = 2e-3;

/// [`may_escape`] for the seed model, which also waits until little bending
/// is left. Its first-order update makes errors on the way in and on the
/// way out that largely cancel (they are odd about periapsis); handing
/// over early keeps the inbound error and drops the outbound one, which
/// nearly doubles the deflection error at b = 3 r_s (0.30 x step against
/// 0.16 x step when the update runs on to infinity). With at most 2e-3 rad
/// of bending left, the exact tail adds at most about 3e-3 x step
/// (measured at b = 3, 10 and 100 r_s).
#[inline]
pub(crate) fn may_escape_seed(x: DVec3, v: DVec3, r: f64, limits: &Limits) -> bool {
    if !may_escape(x, v, r, limits) {
        return false;
    }
    let len = v.length();
    let cos = x.dot(v) / (r * len);
    // Optical invariant b = n r sin(psi), n = exp(1 / (2r)).
    let b = (0.5 / r).exp() * x.cross(v).length() / len;
    1.0 - cos <= 2.0 * b * SEED_REMAINING_BEND
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn reflection_keeps_the_tangential_part_and_flips_the_normal_part() {
        let d = DVec3::new(1.0, -2.0, 0.5);
        let n = DVec3::Y;
        let r = reflect(d, n);
        assert_eq!(r, DVec3::new(1.0, 2.0, 0.5));
        assert!((r.length() - d.length()).abs() < 1e-15);
        // Angle of incidence equals angle of reflection.
        assert!(((-d).angle_between(n) - r.angle_between(n)).abs() < 1e-15);
    }

    #[test]
    fn shadow_angle_is_defined_at_and_around_the_photon_sphere() {
        let gr = Model::gr(1e-6);
        // At r = 1.5 the shadow's edge is exactly at 90 degrees.
        let a = gr.shadow_angle(PHOTON_SPHERE).unwrap();
        assert!((a - FRAC_PI_2).abs() < 1e-7, "{a}");
        for r in [1.01, 1.2, 1.499_999_999, 1.500_000_001, 2.0, 10.0, 1e6] {
            let a = gr.shadow_angle(r).unwrap();
            assert!(
                a.is_finite() && a > 0.0 && a < std::f64::consts::PI,
                "r = {r}: {a}"
            );
        }
        // Closed form at 10 r_s: asin((b_c / r) sqrt(1 - 1/r)).
        assert!((gr.shadow_angle(10.0).unwrap().to_degrees() - 14.269027).abs() < 1e-6);
        let seed = Model::Seed { step: 0.005 };
        assert!(seed.shadow_angle(1.0001).unwrap().is_finite());
    }
}
