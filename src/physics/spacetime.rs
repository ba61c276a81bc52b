//! The spacetime the exact model's light moves in: everything that depends
//! on the metric, behind one type chosen when the scene is built.
//!
//! The geodesic equation (as the integrator's right-hand side) and its
//! conserved quantities, the local frame of a camera, the frequency shift
//! of an emitter or of sky light, the disk's orbital angular velocity and
//! its innermost stable orbit, the shadow's size, the exact tail and the
//! closed-form tracer: the renderer asks a [`Spacetime`] for each, so a
//! second spacetime (a spinning hole) is a second variant here, not
//! conditions scattered through the code. An enum and `match`, resolved at
//! compile time per call, not a trait object per ray. Lengths in r_s, times
//! in r_s/c.

use super::Flow;
use super::closed::ClosedRay;
use super::dual::D2;
use super::kerr::Kerr;
use super::kerr::closed::{KerrRay, KsStart};
use glam::{DVec2, DVec3};

/// The frame a camera (or anything that shifts light) is at rest in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Frame {
    /// At rest with respect to the stars (d_t): only outside the
    /// ergosphere.
    Static,
    /// The locally non-rotating observer, turning with the frame dragging
    /// (zero angular momentum); the static observer without spin.
    #[default]
    Zamo,
}

/// Who receives the light, as the shifts need it: where, in which frame,
/// and the photon's L_z / E on its own path (see
/// [`Spacetime::photon_lz_over_e`]).
#[derive(Clone, Copy, Debug)]
pub struct Observer {
    /// Its position (r_s).
    pub at: DVec3,
    /// The frame it is at rest in (before any velocity of its own).
    pub frame: Frame,
    /// L_z / E of the light reaching it.
    pub lz_over_e: f64,
}

/// ln (E_emitted / E) of light of L_z / E `b_e` (M units) leaving the
/// Kerr disk's gas at Boyer-Lindquist `r` (M): u^t (1 - Omega b_e) on its
/// circular orbit with `doppler` (where one exists), else at rest in the
/// locally non-rotating frame, (1 - omega b_e) / alpha.
pub(crate) fn kerr_emitter_ln(k: Kerr, r: f64, b_e: f64, doppler: bool) -> f64 {
    if doppler && k.has_circular_orbit(r) {
        (k.orbit_ut(r) * (1.0 - k.orbital_angular_velocity(r) * b_e)).ln()
    } else {
        let z = k.zamo(r, std::f64::consts::FRAC_PI_2);
        ((1.0 - z.omega * b_e) / z.alpha).ln()
    }
}

/// Kerr-Schild's azimuth less Boyer-Lindquist's on the ring of radius `r`
/// (r_s) outside the horizon of spin `a`: the integral of a / Delta dr
/// from infinity.
fn kerr_twist(a: f64, r: f64) -> f64 {
    let r_plus = Kerr::new(a).horizon();
    super::kerr::closed::ks_azimuth_term(a, [r_plus, a * a / r_plus], 2.0 * r)
}

/// A spacetime of the exact model.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Spacetime {
    /// A spinning hole of spin `a` = J c / (G M^2) along +z (|a| < 1),
    /// in Kerr-Schild Cartesian coordinates ([`super::kerr`], whose
    /// lengths are in M = r_s / 2; here, as everywhere, in r_s).
    Kerr {
        /// The dimensionless spin.
        a: f64,
    },
    /// A non-rotating hole: Schwarzschild coordinates read as Cartesian,
    /// x = r (sin th cos ph, sin th sin ph, cos th).
    #[default]
    Schwarzschild,
}

impl Spacetime {
    /// Its name, as reports give it.
    pub fn name(self) -> &'static str {
        match self {
            Spacetime::Schwarzschild => "Schwarzschild",
            Spacetime::Kerr { .. } => "Kerr",
        }
    }

    /// The horizon's radius.
    #[inline]
    pub fn horizon(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => 1.0,
            Spacetime::Kerr { a } => 0.5 * Kerr::new(a).horizon(),
        }
    }

    /// The photon sphere's radius: inside it an inbound ray cannot come
    /// back out.
    #[inline]
    pub fn photon_sphere(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => super::PHOTON_SPHERE,
            // The prograde circular photon orbit, the innermost.
            Spacetime::Kerr { a } => 0.5 * Kerr::new(a.abs()).photon_orbit(),
        }
    }

    /// The innermost stable circular orbit of the disk's
    /// (counter-clockwise) orbit: prograde for a > 0, retrograde for a < 0.
    #[inline]
    pub fn isco(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => 3.0,
            Spacetime::Kerr { a } => 0.5 * Kerr::new(a).isco(),
        }
    }

    /// The hole's spin a (0 for Schwarzschild).
    #[inline]
    pub fn spin(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => 0.0,
            Spacetime::Kerr { a } => a,
        }
    }

    /// The radius (Boyer-Lindquist's for Kerr) of the point `x`.
    #[inline]
    pub fn radius(self, x: DVec3) -> f64 {
        match self {
            Spacetime::Schwarzschild => x.length(),
            Spacetime::Kerr { a } => 0.5 * Kerr::new(a).ks_radius(2.0 * x),
        }
    }

    /// The radius of the ring in the equatorial plane at cylindrical
    /// radius `rho` (Kerr-Schild's circles of radius r lie at sqrt(r^2 +
    /// a^2)).
    #[inline]
    pub fn ring_radius(self, rho: f64) -> f64 {
        match self {
            Spacetime::Schwarzschild => rho,
            Spacetime::Kerr { a } => (rho * rho - 0.25 * a * a).max(0.0).sqrt(),
        }
    }

    /// Where the point `p` of the equatorial plane lies in the disk's own
    /// polar coordinates, as the disk's texture reads it: (r cos phi, r
    /// sin phi), r and phi the ring's radius and azimuth. Without spin
    /// they are p's; with spin Boyer-Lindquist's, which the disk's orbits,
    /// its radii and the peers' pattern disks count, where Kerr-Schild's
    /// Cartesian x + i y = (r + i a) e^(i phi_KS) with phi_KS = phi +
    /// [`super::kerr::closed::ks_azimuth_term`]: a ring of radius r lies at
    /// sqrt(r^2 + a^2) and turns by that term plus atan(a / r). Inside the
    /// horizon, which no light leaves and where phi is undefined, the
    /// origin.
    #[inline]
    pub fn disk_plane(self, p: DVec3) -> DVec2 {
        match self {
            Spacetime::Schwarzschild => p.truncate(),
            Spacetime::Kerr { a } => {
                let r = self.ring_radius((p.x * p.x + p.y * p.y).sqrt());
                if !(r > self.horizon()) {
                    return DVec2::ZERO;
                }
                // e^(i phi_KS) = (x + i y) (r - i a) / (r^2 + a^2), in r_s.
                let am = 0.5 * a;
                let e_ks = DVec2::new(p.x * r + p.y * am, p.y * r - p.x * am) / (r * r + am * am);
                r * e_ks.rotate(DVec2::from_angle(-kerr_twist(a, r)))
            }
        }
    }

    /// The point of the equatorial plane (r_s) at ring radius `r` and
    /// azimuth `phi` of the disk's polar coordinates: the inverse of
    /// [`Spacetime::disk_plane`].
    pub fn disk_plane_point(self, r: f64, phi: f64) -> DVec3 {
        match self {
            Spacetime::Schwarzschild => DVec3::new(r * phi.cos(), r * phi.sin(), 0.0),
            Spacetime::Kerr { a } => {
                // x + i y = (r + i a) e^(i phi_KS).
                let (s, c) = (phi + kerr_twist(a, r)).sin_cos();
                let am = 0.5 * a;
                DVec3::new(r * c - am * s, r * s + am * c, 0.0)
            }
        }
    }

    /// A direction measured by the camera at `x` (a static observer's
    /// orthonormal frame aligned with the coordinate axes; with spin, the
    /// locally non-rotating observer's frame closest to the axes) as the
    /// coordinate direction the integrator traces: in Schwarzschild the
    /// radial component shrinks by sqrt(1 - r_s/r).
    #[inline]
    pub fn camera_direction(self, x: DVec3, local: DVec3) -> DVec3 {
        match self {
            Spacetime::Schwarzschild => {
                let r = x.length();
                let n = x / r;
                let radial = local.dot(n);
                local + n * (radial * ((1.0 - 1.0 / r).sqrt() - 1.0))
            }
            Spacetime::Kerr { a } => Kerr::new(a).ks_camera_ray(2.0 * x, local),
        }
    }

    /// [`Spacetime::camera_direction`] for a camera at rest in `frame`:
    /// without spin both frames are the static one; a static camera with
    /// spin (outside the ergosphere) sees through a static observer's
    /// frame.
    pub fn camera_direction_in(self, x: DVec3, local: DVec3, frame: Frame) -> DVec3 {
        match self.camera_basis(x, frame) {
            Some((map, offset)) => map * local + offset,
            None => self.camera_direction(x, local),
        }
    }

    /// The reflection of the photon direction `d` (coordinate) off a static
    /// mirror at `p` with coordinate-space normal `n`, by the law of
    /// reflection in the mirror's local static frame.
    pub fn reflect(self, p: DVec3, d: DVec3, n: DVec3) -> DVec3 {
        match self {
            Spacetime::Schwarzschild => schwarzschild_reflect(p, d, n),
            Spacetime::Kerr { a } => Kerr::new(a).ks_reflect(2.0 * p, d, n),
        }
    }

    /// The photon's L_z / E of the state (x, v) (a ray traced back from
    /// the camera or a mirror, for the shifts; with spin in units of M).
    #[inline]
    pub fn photon_lz_over_e(self, x: DVec3, v: DVec3) -> f64 {
        match self {
            Spacetime::Schwarzschild => super::shift::gr_photon_lz_over_e(x, v),
            Spacetime::Kerr { a } => {
                let (p, e) = Kerr::new(a).ks_backward(2.0 * x, v);
                (2.0 * (x.x * p.y - x.y * p.x)) / e
            }
        }
    }

    /// ln g of light from the disk's material at `x_e` (on its circular
    /// orbit, or without `doppler` at rest: static in Schwarzschild, the
    /// locally non-rotating observer with spin) reaching the camera at
    /// `x_o`; `b_e` and `b_o` are the photon's L_z / E on the path from
    /// the disk and on the camera's path ([`Spacetime::photon_lz_over_e`]:
    /// they differ after a mirror, which keeps E).
    #[inline]
    pub fn disk_ln_shift(self, x_e: DVec3, b_e: f64, obs: Observer, doppler: bool) -> f64 {
        match self {
            Spacetime::Schwarzschild => {
                super::shift::gr_disk_ln_shift(x_e.length(), b_e, obs.at.length(), doppler)
            }
            Spacetime::Kerr { a } => {
                let k = Kerr::new(a);
                self.kerr_observer(obs) - kerr_emitter_ln(k, k.ks_radius(2.0 * x_e), b_e, doppler)
            }
        }
    }

    /// ln g of light from a static emitter at `x_e` (None: sky light)
    /// reaching `obs` (see [`Spacetime::disk_ln_shift`]).
    #[inline]
    pub fn static_ln_shift(self, x_e: Option<DVec3>, obs: Observer) -> f64 {
        match (self, x_e) {
            (Spacetime::Schwarzschild, None) => -0.5 * (1.0 - 1.0 / obs.at.length()).ln(),
            (Spacetime::Schwarzschild, Some(x_e)) => {
                0.5 * ((1.0 - 1.0 / x_e.length()) / (1.0 - 1.0 / obs.at.length())).ln()
            }
            (Spacetime::Kerr { .. }, None) => self.kerr_observer(obs),
            (Spacetime::Kerr { a }, Some(x_e)) => {
                // A static emitter's clock runs at sqrt(-g_tt) = sqrt(1 - f).
                let f = Kerr::new(a).ks_f(2.0 * x_e);
                self.kerr_observer(obs) + 0.5 * (1.0 - f).ln()
            }
        }
    }

    /// ln (nu / E) at a Kerr observer: (1 - omega L_z/E) / alpha for the
    /// locally non-rotating one, 1 / sqrt(1 - f) for a static one.
    fn kerr_observer(self, obs: Observer) -> f64 {
        let Spacetime::Kerr { a } = self else {
            return 0.0;
        };
        let k = Kerr::new(a);
        match obs.frame {
            Frame::Zamo => {
                let s = k.spheroidal(2.0 * obs.at);
                k.zamo_sky_shift(s.r, s.th, obs.lz_over_e).ln()
            }
            Frame::Static => -0.5 * (1.0 - k.ks_f(2.0 * obs.at)).ln(),
        }
    }

    /// The Kerr hole whose Kerr-Schild machinery serves this spacetime (a
    /// = 0 for Schwarzschild: its space is the same).
    fn kerr(self) -> Kerr {
        match self {
            Spacetime::Schwarzschild => Kerr::new(0.0),
            Spacetime::Kerr { a } => Kerr::new(a),
        }
    }

    /// The 4-velocity (Kerr-Schild components) of an observer at rest in
    /// `frame` at `x` (r_s); None for a static one inside the ergosphere.
    pub fn observer_velocity(self, x: DVec3, frame: Frame) -> Option<[f64; 4]> {
        let k = self.kerr();
        match frame {
            Frame::Static => k.ks_static_velocity(2.0 * x),
            Frame::Zamo => Some(k.ks_zamo_velocity(2.0 * x)),
        }
    }

    /// [`Spacetime::camera_direction_in`] as an affine map of the local
    /// direction (M, offset), for a spinning hole: the frame's spatial
    /// vectors and minus the observer's spatial 4-velocity
    /// ([`Kerr::ks_observer_ray`]). None without spin, whose conversion
    /// is already a few flops.
    pub fn camera_basis(self, x: DVec3, frame: Frame) -> Option<(glam::DMat3, DVec3)> {
        let Spacetime::Kerr { a } = self else {
            return None;
        };
        // A static frame inside the ergosphere is refused when the scene is
        // built; the ZAMO's stands in.
        let u = self
            .observer_velocity(x, frame)
            .or_else(|| self.observer_velocity(x, Frame::Zamo))?;
        let e = Kerr::new(a).ks_frame(2.0 * x, u);
        let col = |i: usize| DVec3::new(e[i][1], e[i][2], e[i][3]);
        Some((
            glam::DMat3::from_cols(col(0), col(1), col(2)),
            -DVec3::new(u[1], u[2], u[3]),
        ))
    }

    /// The velocity (units of c, in the frame of `frame` at `x`, closest to
    /// the axes) of a body moving with coordinate velocity `w` (r_s per
    /// r_s/c of Boyer-Lindquist's, or Schwarzschild's, time); None where
    /// that is not slower than light or the frame has no observer.
    pub fn relative_velocity(self, x: DVec3, frame: Frame, w: DVec3) -> Option<DVec3> {
        let u = self.observer_velocity(x, frame)?;
        self.kerr().ks_relative_velocity(2.0 * x, u, w)
    }

    /// The coordinate velocity of the counter-clockwise circular orbit
    /// through `x` (see [`Kerr::ks_circular_velocity`]); None where there
    /// is none.
    pub fn circular_velocity(self, x: DVec3) -> Option<DVec3> {
        self.kerr().ks_circular_velocity(2.0 * x)
    }

    /// The angular velocity (per r_s/c of coordinate time) of the disk's
    /// circular orbit at (Boyer-Lindquist) radius `r`: sqrt(GM / r^3)
    /// without spin, 1 / (r^1.5 + a) in units of M with it.
    #[inline]
    pub fn orbital_angular_velocity(self, r: f64) -> f64 {
        match self {
            Spacetime::Schwarzschild => (0.5 / (r * r * r)).sqrt(),
            // One r_s/c is two of M's time units.
            Spacetime::Kerr { a } => 2.0 * Kerr::new(a).orbital_angular_velocity(2.0 * r),
        }
    }

    /// The shadow edge's angle from the direction to the hole (radians) for
    /// a camera at radius `r`; None with spin, whose shadow is not round
    /// (see [`super::kerr::Kerr::shadow_curve`]).
    pub fn shadow_angle(self, r: f64) -> Option<f64> {
        Some(match self {
            Spacetime::Kerr { .. } => return None,
            Spacetime::Schwarzschild => {
                // At the photon sphere the product is 1 up to rounding (1 +
                // 1 ulp at r = 1.5): clamp so asin stays defined.
                let a = (super::B_CRIT_GR / r * (1.0 - 1.0 / r).sqrt())
                    .min(1.0)
                    .asin();
                // Inside the photon sphere the shadow covers more than half
                // the sky: the escape cone points outward.
                if r <= self.photon_sphere() {
                    std::f64::consts::PI - a
                } else {
                    a
                }
            }
        })
    }

    /// Traces the ray from `x` along coordinate direction `v` (the
    /// camera's, [`Spacetime::camera_direction`]) with this spacetime's
    /// integrator at `tolerance`; with `TIME` each segment carries the
    /// light's coordinate travel time.
    pub fn trace<const TIME: bool>(
        self,
        x: DVec3,
        v: DVec3,
        tolerance: f64,
        limits: &super::Limits,
        visit: impl FnMut(&super::Segment) -> super::Flow,
    ) -> super::Trace {
        match self {
            Spacetime::Schwarzschild => super::gr::trace::<TIME>(x, v, tolerance, limits, visit),
            Spacetime::Kerr { a } => {
                let k = Kerr::new(a);
                let (p, e) = k.ks_backward(2.0 * x, v);
                let mut visit = visit;
                k.ks_trace::<TIME>(2.0 * x, p, e, tolerance, limits, |seg, _| visit(seg))
            }
        }
    }

    /// What every closed-form ray from `x` (r_s) shares, to be found once
    /// for a camera.
    pub fn closed_start(self, x: DVec3) -> ClosedStart {
        match self {
            Spacetime::Schwarzschild => ClosedStart::Schwarzschild(x),
            Spacetime::Kerr { a } => ClosedStart::Kerr(KsStart::new(Kerr::new(a), 2.0 * x)),
        }
    }

    /// The ray from `start` ([`Spacetime::closed_start`]) along coordinate
    /// direction `v` in closed form, where it applies (see
    /// [`super::closed`] and [`super::kerr::closed`]); None where the
    /// integrator takes it. A `timed` ray also gives the light's travel
    /// time from each crossing (Kerr only: Schwarzschild's timed rays
    /// integrate).
    #[inline]
    pub fn closed_ray(self, start: &ClosedStart, v: DVec3, timed: bool) -> Option<Closed> {
        match (self, start) {
            (Spacetime::Schwarzschild, _) if timed => None,
            (Spacetime::Schwarzschild, ClosedStart::Schwarzschild(x)) => {
                ClosedRay::new(*x, v).map(Closed::Schwarzschild)
            }
            (Spacetime::Kerr { a }, ClosedStart::Kerr(s)) => {
                KerrRay::from_start(Kerr::new(a), s, v, timed).map(Closed::Kerr)
            }
            // Another spacetime's start: this one's from its point.
            (st, start) => self.closed_ray(&st.closed_start(start.point()), v, timed),
        }
    }

    /// [`Spacetime::closed_ray`] of a camera sample whose footprint is
    /// wanted, with the rates the footprint is read from: Schwarzschild's
    /// ray makes its rates in b with its sweeps ([`ClosedRay::new_rated`]),
    /// Kerr's carries every quantity's along the pixel's axes
    /// ([`KerrRay::rated`]), given the camera direction's derivatives `dv`
    /// along them.
    pub fn closed_ray_rated(
        self,
        start: &ClosedStart,
        v: DVec3,
        dv: [DVec3; 2],
        timed: bool,
    ) -> Option<Rated> {
        match (self, start) {
            (Spacetime::Schwarzschild, _) if timed => None,
            (Spacetime::Schwarzschild, ClosedStart::Schwarzschild(x)) => {
                ClosedRay::new_rated(*x, v).map(Rated::Schwarzschild)
            }
            (Spacetime::Kerr { a }, ClosedStart::Kerr(s)) => {
                KerrRay::rated(Kerr::new(a), s, v, dv, timed).map(Rated::Kerr)
            }
            (st, start) => self.closed_ray_rated(&st.closed_start(start.point()), v, dv, timed),
        }
    }

    /// Whether [`Spacetime::closed_ray`] gives timed rays.
    pub fn closed_form_keeps_time(self) -> bool {
        matches!(self, Spacetime::Kerr { .. })
    }
}

/// Where closed-form rays start ([`Spacetime::closed_start`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ClosedStart {
    /// The point (r_s).
    Schwarzschild(DVec3),
    Kerr(KsStart),
}

impl ClosedStart {
    /// The start's point (r_s).
    pub fn point(&self) -> DVec3 {
        match self {
            ClosedStart::Schwarzschild(x) => *x,
            ClosedStart::Kerr(s) => s.x * 0.5,
        }
    }
}

/// A ray in closed form, in the scene's units (r_s).
// Each lives on one sample's stack: boxing the larger would allocate a
// pixel.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Closed {
    Schwarzschild(ClosedRay),
    Kerr(KerrRay),
}

/// A ray in closed form with its rates ([`Spacetime::closed_ray_rated`]).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum Rated {
    Schwarzschild(ClosedRay),
    Kerr(KerrRay<D2>),
}

impl Rated {
    /// The ray itself (what the trace walks).
    pub fn ray(&self) -> Closed {
        match self {
            Rated::Schwarzschild(c) => Closed::Schwarzschild(*c),
            Rated::Kerr(k) => Closed::Kerr(k.value()),
        }
    }
}

impl Closed {
    /// It ends in the hole rather than at infinity.
    #[inline]
    pub fn captured(&self) -> bool {
        match self {
            Closed::Schwarzschild(c) => c.captured,
            Closed::Kerr(k) => k.captured,
        }
    }

    /// Hands `visit` the ray's crossings of the plane z = 0 whose ring
    /// radius (r_s) lies in `[lo, hi]`, in order, until it stops: each
    /// crossing's image order (how many crossings, in the range or not, came
    /// before it), its point, the point in the disk's polar coordinates
    /// ([`Spacetime::disk_plane`]), the light's travel time (r_s / c)
    /// from there to the start for a timed ray (NaN otherwise), and where
    /// along the ray it lies (a Kerr ray's Mino time, as its stretches
    /// count it; Schwarzschild's orbital angle).
    #[inline]
    pub fn crossings(
        &self,
        (lo, hi): (f64, f64),
        mut visit: impl FnMut(u32, DVec3, DVec2, f64, f64) -> Flow,
    ) {
        let keep = |r: f64| r >= lo && r <= hi;
        match self {
            Closed::Schwarzschild(c) => {
                for (order, phi) in c.z0_crossings().enumerate() {
                    let p = c.point(phi);
                    if keep(p.length())
                        && visit(order as u32, p, p.truncate(), f64::NAN, phi) == Flow::Stop
                    {
                        return;
                    }
                }
            }
            Closed::Kerr(k) => {
                // A ray that keeps beyond the range crosses it nowhere.
                if k.min_radius() > 2.0 * hi {
                    return;
                }
                for (order, c) in k.crossings().enumerate() {
                    // The point's azimuth costs more than its radius.
                    if !keep(0.5 * c.r) {
                        continue;
                    }
                    // The closed form finds Boyer-Lindquist's azimuth
                    // first: the disk's coordinates without a round trip.
                    let at = k.crossing_point_time(&c);
                    let plane = 0.5 * c.r * DVec2::from_angle(at.phi);
                    if visit(order as u32, 0.5 * at.x, plane, 0.5 * at.t, c.s) == Flow::Stop {
                        return;
                    }
                }
            }
        }
    }

    /// The photon's L_z / E (M units) where the ray already holds it (a
    /// Kerr ray's lambda, as [`Spacetime::photon_lz_over_e`] gives it).
    #[inline]
    pub fn lz_over_e(&self) -> Option<f64> {
        match self {
            Closed::Schwarzschild(_) => None,
            Closed::Kerr(k) => Some(k.lambda()),
        }
    }

    /// The direction of motion at infinity (of an escaping ray).
    #[inline]
    pub fn escape_direction(&self) -> DVec3 {
        match self {
            Closed::Schwarzschild(c) => c.escape_direction(),
            Closed::Kerr(k) => k.escape_direction(),
        }
    }
}

/// The exact model's reflection off a static mirror at `x` (r_s) for a
/// photon of coordinate velocity `dir` and a surface whose coordinate
/// normal is `n` (the gradient of its defining function, either
/// orientation). The law of reflection holds in the mirror's local static
/// frame, where space is measured with the Schwarzschild metric: there a
/// vector's radial component is its coordinate one divided by
/// sqrt(1 - r_s/r), while a normal (a gradient) has its radial component
/// multiplied by it. The direction is reflected there and mapped back; its
/// local length, the photon's energy in that frame, is kept.
#[inline]
fn schwarzschild_reflect(x: DVec3, dir: DVec3, n: DVec3) -> DVec3 {
    let r = x.length();
    let e = x / r;
    let s = (1.0 - 1.0 / r).sqrt();
    let local = dir + e * (dir.dot(e) * (1.0 / s - 1.0));
    let normal = (n + e * (n.dot(e) * (s - 1.0))).normalize();
    let out = super::reflect(local, normal);
    out + e * (out.dot(e) * (s - 1.0))
}

#[cfg(test)]
mod tests {
    use super::super::reflect;
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_disk_plane_of_a_spinning_hole_is_boyer_lindquists() {
        // a = 0.9: Kerr-Schild's Cartesian azimuth leads Boyer-Lindquist's
        // by F(r) + atan(a / r), F = a / (r_+ - r_-) ln((r - r_+) / (r -
        // r_-)): -19.36 degrees at the prograde ISCO (2.3209 M), -4.63 at 4
        // M; a ring of radius r lies at sqrt(r^2 + a^2).
        let st = Spacetime::Kerr { a: 0.9 };
        for (r_m, twist) in [
            (Kerr::new(0.9).isco(), -19.361),
            (4.0, -4.631),
            (40.0, -0.033),
        ] {
            let r = 0.5 * r_m;
            for phi in [0.0, 1.0, -2.5] {
                let p = st.disk_plane_point(r, phi);
                assert!((p.length() - (r * r + 0.2025).sqrt()).abs() < 1e-12, "{p}");
                let q = st.disk_plane(p);
                assert!((q.length() - r).abs() < 1e-12 * r, "{q} at {r}");
                let back = (q.y.atan2(q.x) - phi + 3.0 * PI).rem_euclid(2.0 * PI) - PI;
                assert!(back.abs() < 1e-12, "{back}");
                let lead = (p.y.atan2(p.x) - phi + 3.0 * PI).rem_euclid(2.0 * PI) - PI;
                assert!(
                    (lead.to_degrees() - twist).abs() < 0.001,
                    "{r_m}: {}",
                    lead.to_degrees()
                );
            }
        }
        // The ring r = R of a disk of radius R lands on the texture
        // square's edge.
        let q = st.disk_plane(st.disk_plane_point(10.0, 0.0));
        assert!((q.length() - 10.0).abs() < 1e-12);
        // Without spin the plane point is the point's own x and y, bit for
        // bit; inside a spinning hole's horizon the origin (no azimuth).
        let p = DVec3::new(0.3, -7.1, 0.0);
        assert_eq!(Spacetime::Schwarzschild.disk_plane(p), p.truncate());
        assert_eq!(st.disk_plane(DVec3::new(0.5, 0.3, 0.0)), DVec2::ZERO);
    }

    #[test]
    fn static_frame_reflection_limits() {
        let d = DVec3::new(0.3, 1.0, -0.2);
        let n = DVec3::new(1.0, -1.0, 0.5).normalize();
        // Far from the hole it is the flat law.
        let far = DVec3::new(1e9, 0.0, 0.0);
        assert!(
            Spacetime::Schwarzschild
                .reflect(far, d, n)
                .distance(reflect(d, n))
                < 1e-8
        );
        // A radial normal: only the radial part flips, in any frame.
        let x = DVec3::new(0.0, 2.0, 0.0);
        let r = Spacetime::Schwarzschild.reflect(x, d, DVec3::Y);
        assert!(r.distance(DVec3::new(0.3, -1.0, -0.2)) < 1e-12, "{r}");
        // Near the hole a slanted mirror differs from the flat law, and
        // the local length (the photon's energy there) is kept.
        let x = DVec3::new(3.0, 0.0, 0.0);
        let n = DVec3::new(1.0, -1.0, 0.0).normalize();
        let d = DVec3::Y;
        let r = Spacetime::Schwarzschild.reflect(x, d, n);
        assert!(r.angle_between(reflect(d, n)) > 0.1);
        let local = |v: DVec3| {
            let s = (1.0 - 1.0 / 3.0f64).sqrt();
            DVec3::new(v.x / s, v.y, v.z).length()
        };
        assert!((local(r) - local(d)).abs() < 1e-12);
    }

    /// A camera ray's end and its first crossing of the disk's plane, with
    /// the travel time there.
    fn follow(st: Spacetime, x: DVec3, look: DVec3) -> (super::super::End, Option<(DVec3, f64)>) {
        let limits = super::super::Limits {
            outer: 15.0,
            inner: 1.2,
            max_steps: 100_000,
        };
        let v = st.camera_direction(x, look);
        let mut cross = None;
        let t = st.trace::<true>(x, v, 1e-10, &limits, |seg| {
            if cross.is_none()
                && let Some(s) = seg.crossing_z0()
            {
                cross = Some((seg.point(s), seg.time_at(s)));
            }
            super::super::Flow::Continue
        });
        (t.end, cross)
    }

    #[test]
    fn a_hole_without_spin_is_schwarzschild_through_the_seam() {
        // Kerr at a = 0 (Kerr-Schild's own integrator, camera frame,
        // shifts and times) against the Schwarzschild member, and a = 1e-6
        // next to it.
        let s = Spacetime::Schwarzschild;
        let k0 = Spacetime::Kerr { a: 0.0 };
        assert_eq!(
            (k0.horizon(), k0.photon_sphere(), k0.isco()),
            (1.0, 1.5, 3.0)
        );
        for r in [2.0, 3.0, 10.0] {
            let w = |st: Spacetime| st.orbital_angular_velocity(r);
            assert!((w(k0) - w(s)).abs() < 1e-15 * w(s));
        }
        let cam = DVec3::new(0.5, -20.0, 2.0);
        let mut crossed = 0;
        for look in [
            DVec3::new(0.0, 1.0, -0.12),
            DVec3::new(0.05, 1.0, -0.08),
            DVec3::new(-0.1, 1.0, 0.02),
            DVec3::new(0.0, 1.0, -0.3),
        ] {
            let look = look.normalize();
            let (end_s, cross_s) = follow(s, cam, look);
            for (st, tol) in [(k0, 1e-7), (Spacetime::Kerr { a: 1e-6 }, 1e-5)] {
                let (end_k, cross_k) = follow(st, cam, look);
                match (end_s, end_k) {
                    (super::super::End::Escaped(a), super::super::End::Escaped(b)) => {
                        assert!(a.distance(b) < tol, "{look}: {a} vs {b}")
                    }
                    (a, b) => assert_eq!(a, b, "{look}"),
                }
                if let (Some((ps, ts)), Some((pk, tk))) = (cross_s, cross_k) {
                    assert!(ps.distance(pk) < tol * ps.length(), "{ps} vs {pk}");
                    assert!((ts - tk).abs() < tol * ts, "travel time {ts} vs {tk}");
                    // The disk's and a static emitter's light, and the sky's.
                    let (bs, bk) = (
                        s.photon_lz_over_e(cam, s.camera_direction(cam, look)),
                        st.photon_lz_over_e(cam, st.camera_direction(cam, look)),
                    );
                    // L_z / E in r_s against M: b_M = 2 b_rs.
                    assert!((2.0 * bs - bk).abs() < tol * (1.0 + bk.abs()), "{bs} {bk}");
                    for doppler in [false, true] {
                        let gs = s.disk_ln_shift(ps, bs, obs(cam, bs), doppler);
                        let gk = st.disk_ln_shift(ps, bk, obs(cam, bk), doppler);
                        assert!((gs - gk).abs() < tol, "doppler {doppler}: {gs} vs {gk}");
                    }
                    let (fs, fk) = (
                        s.static_ln_shift(Some(ps), obs(cam, bs)),
                        st.static_ln_shift(Some(ps), obs(cam, bk)),
                    );
                    assert!((fs - fk).abs() < tol, "{fs} vs {fk}");
                    crossed += 1;
                }
                let (ss, sk) = (
                    s.static_ln_shift(None, obs(cam, bs_of(s, cam, look))),
                    st.static_ln_shift(None, obs(cam, bs_of(st, cam, look))),
                );
                assert!((ss - sk).abs() < tol);
            }
        }
        assert!(crossed >= 4, "{crossed}");
    }

    fn obs(at: DVec3, lz_over_e: f64) -> Observer {
        Observer {
            at,
            frame: Frame::Zamo,
            lz_over_e,
        }
    }

    fn bs_of(st: Spacetime, cam: DVec3, look: DVec3) -> f64 {
        st.photon_lz_over_e(cam, st.camera_direction(cam, look))
    }

    #[test]
    fn a_mirror_without_spin_reflects_as_in_schwarzschild() {
        let k = Spacetime::Kerr { a: 0.0 };
        for (x, d, n) in [
            (
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::Y,
                DVec3::new(1.0, -1.0, 0.0),
            ),
            (
                DVec3::new(1.5, 2.0, 0.5),
                DVec3::new(0.3, 1.0, -0.2),
                DVec3::new(0.2, -1.0, 0.4),
            ),
        ] {
            let want = Spacetime::Schwarzschild.reflect(x, d, n.normalize());
            let got = k.reflect(x, d, n.normalize());
            assert!(
                got.normalize().distance(want.normalize()) < 1e-12,
                "{got} vs {want}"
            );
        }
        // Far from a spinning hole it is the flat law.
        let far = Spacetime::Kerr { a: 0.9 }.reflect(
            DVec3::new(1e8, 0.0, 0.0),
            DVec3::new(0.3, 1.0, -0.2),
            DVec3::new(1.0, -1.0, 0.5).normalize(),
        );
        let flat = reflect(
            DVec3::new(0.3, 1.0, -0.2),
            DVec3::new(1.0, -1.0, 0.5).normalize(),
        );
        assert!(far.normalize().distance(flat.normalize()) < 1e-7);
    }
}
