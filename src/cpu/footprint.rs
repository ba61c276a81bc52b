//! Footprints: how where a camera sample's ray ends moves as the sample
//! moves on the image. A pixel is an area, not a point: its footprint on
//! the sky (the derivatives of the escape direction per pixel) gives the
//! lensing magnification, the filter a panorama is read through and the
//! stars a pixel holds; on the disk (the derivatives of the disk-plane
//! point the texture reads) the texture's filter and the disk's area ratio.
//!
//! Schwarzschild's rays in closed form take the symmetry of their plane
//! ([`Integrator::footprint`]): the orbit's own derivative in the impact
//! parameter ([`ClosedRay::rates`]), and the plane's turn about the
//! camera's axis is exact. Kerr's rays in closed form carry their rates
//! ([`KerrRay::rated`]: every quantity of the closed form with its
//! derivatives along the pixel's axes), from which the escape direction's
//! and each crossing's are read. Every other path differences neighbouring
//! rays a small fraction of a pixel away, traced in closed form where the
//! spacetime has one (a smooth function of the direction, good to near
//! machine precision: one neighbour per axis, [`CLOSED_STEP`] pixels
//! after the sample, is a forward difference accurate to about 1e-4, the
//! step chosen between its own error and rounding). The closed form of the camera's ray is
//! used whatever the scene traces with: the geodesic is the same, and the
//! integrator's adaptive steps would put their own tolerance-sized jumps
//! into a difference. The seed model has no closed form: its rays are
//! traced with their fixed step sequence (smooth in the direction) over
//! [`TRACED_STEP`] pixels.
//!
//! A difference must never reach across a discontinuity (the shadow's
//! edge, the disk's edges, a change of image order): a neighbour counts
//! only where it ends the same way (it escapes too; it crosses the disk
//! at the same crossing of the plane), else the neighbour on the other
//! side is taken; where neither does, the footprint has no value there.
//!
//! Object hits take theirs in texture coordinates, from neighbouring rays
//! traced to the same surface ([`objects`]).

mod objects;

pub use objects::OBJECT_STEP;
pub(crate) use objects::{on_curve, plane_crossings};

use super::Probing;
use crate::cpu::Integrator;
use crate::footprint::{DiskFootprint, Footprint, MAX_CROSSINGS};
use crate::physics::closed::ClosedRay;
use crate::physics::dual::{D2, Real};
use crate::physics::kerr_closed::KerrRay;
use crate::physics::spacetime::{Closed, Rated};
use crate::physics::{End, Flow, Model, Segment, Spacetime};
use glam::{DVec2, DVec3};

/// Neighbour step (pixels) of rays in closed form.
pub const CLOSED_STEP: f64 = 1e-6;

/// Neighbour step (pixels) of traced rays (the seed model's).
pub const TRACED_STEP: f64 = 1e-2;

/// Where one ray ends, as much as a footprint compares.
#[derive(Clone, Copy, Debug, Default)]
pub struct Ends {
    /// Its direction at infinity, if it escapes.
    pub escape: Option<DVec3>,
    /// Its crossings of the disk's annulus: the plane crossing's order,
    /// the point (scene coordinates, r_s) and the disk-plane point the
    /// texture reads (turned back by the disk's rotation), in order.
    crossings: [(u32, DVec3, DVec2); MAX_CROSSINGS],
    n: usize,
}

impl Ends {
    fn push(&mut self, order: u32, p: DVec3, q: DVec2) {
        if self.n < MAX_CROSSINGS {
            self.crossings[self.n] = (order, p, q);
            self.n += 1;
        }
    }

    /// `other` ends every way this one does: it escapes if this does, and
    /// crosses the disk at each of this one's crossing orders.
    fn alike(&self, other: &Ends) -> bool {
        self.escape.is_none_or(|_| other.escape.is_some())
            && self.crossings[..self.n]
                .iter()
                .all(|c| other.crossing(c.0).is_some())
    }

    /// The crossing of plane-crossing order `order`.
    fn crossing(&self, order: u32) -> Option<(DVec3, DVec2)> {
        self.crossings[..self.n]
            .iter()
            .find(|c| c.0 == order)
            .map(|&(_, p, q)| (p, q))
    }
}

impl Integrator<'_> {
    /// The direction at infinity of the ray through image point `at`,
    /// None where it does not escape (the geodesic only, as footprints
    /// follow it).
    pub fn escape_at(&self, at: DVec2) -> Option<DVec3> {
        let Some(st) = self.model.spacetime() else {
            return self.ends(at.x, at.y)?.escape;
        };
        // (Where the closed form has no ray, within a hair of the critical
        // curve, neither has the footprint: `ends`.)
        let (v, _) = self.camera.ray(at.x, at.y);
        let start = self.camera.closed_start(st, self.camera.position);
        let ray = st.closed_ray(&start, v, false)?;
        (!ray.captured()).then(|| ray.escape_direction())
    }

    /// Where a ray in closed form ends.
    fn closed_ends(&self, ray: &Closed) -> Ends {
        let mut ends = Ends::default();
        if let Some(d) = &self.disk {
            let turn = |q: DVec2| self.rotation.unturn_plane(q, self.time);
            ray.crossings((d.inner, d.outer), |order, p, q, _, _| {
                ends.push(order, p, turn(q));
                if ends.n == MAX_CROSSINGS {
                    Flow::Stop
                } else {
                    Flow::Continue
                }
            });
        }
        if !ray.captured() {
            ends.escape = Some(ray.escape_direction());
        }
        ends
    }

    /// Where the ray through image point (`px`, `py`) ends: in closed form
    /// where the spacetime has one for it, else traced (ignoring objects
    /// and gas: a footprint follows the geodesic).
    fn ends(&self, px: f64, py: f64) -> Option<Ends> {
        let (dir, _) = self.camera.ray(px, py);
        let origin = self.camera.position;
        let disk = self.disk.as_ref();
        if let Some(st) = self.model.spacetime()
            && let Some(ray) = st.closed_ray(&self.camera.closed_start(st, origin), dir, false)
        {
            return Some(self.closed_ends(&ray));
        }
        let mut ends = Ends::default();
        let turn = |q: DVec2| self.rotation.unturn_plane(q, self.time);
        if let Model::Gr { .. } = self.model {
            // Within a hair of the critical curve: no closed form, and a
            // difference there means nothing.
            return None;
        }
        let mut order = 0u32;
        let trace = self
            .model
            .trace(origin, dir, &self.limits, |seg: &Segment| {
                if let Some(s) = seg.crossing_z0() {
                    let p = seg.point(s);
                    if let Some(d) = disk {
                        let q = d.spacetime.disk_plane(p);
                        if (d.inner..=d.outer).contains(&q.length()) {
                            ends.push(order, p, turn(q));
                        }
                    }
                    order += 1;
                }
                Flow::Continue
            });
        match trace.end {
            End::Escaped(d) => ends.escape = Some(d),
            End::Captured => {}
            End::Stopped | End::Abandoned => return None,
        }
        Some(ends)
    }

    /// The footprint of the sample at image point (`px`, `py`) (see the
    /// module's notes); None where its own ends are not known.
    pub fn footprint(&self, px: f64, py: f64) -> Option<Footprint> {
        if let Some(st) = self.model.spacetime() {
            let (v, dv) = self.camera.ray_rates(px, py);
            let start = self.camera.closed_start(st, self.camera.position);
            if let Some(ray) = st.closed_ray_rated(&start, v, dv, false) {
                return Some(self.rated_footprint(px, py, &ray, (v, dv)));
            }
        }
        Some(self.neighbour_footprint_of(px, py, self.ends(px, py)?))
    }

    /// The closed-form ray of the camera sample from `origin` along `dir`
    /// (None where the closed form has none), made with its rates where
    /// `probing` wants the sample's footprint, which it then takes from
    /// them.
    pub(crate) fn closed_sample_ray(
        &self,
        st: Spacetime,
        origin: DVec3,
        dir: DVec3,
        timed: bool,
        probing: &mut Probing,
    ) -> Option<Closed> {
        let start = self.camera.closed_start(st, origin);
        let Some((px, py)) = probing.footprint_at else {
            return st.closed_ray(&start, dir, timed);
        };
        let rates = self.camera.ray_rates(px, py);
        let rated = st.closed_ray_rated(&start, dir, rates.1, timed)?;
        probing.footprint_at = None;
        probing.footprint = Some(self.rated_footprint(px, py, &rated, rates));
        Some(rated.ray())
    }

    /// [`Integrator::footprint`] of a ray in closed form from its rates, the
    /// camera direction's `rates` ([`crate::camera::Camera::ray_rates`])
    /// given.
    fn rated_footprint(
        &self,
        px: f64,
        py: f64,
        ray: &Rated,
        rates: (DVec3, [DVec3; 2]),
    ) -> Footprint {
        match ray {
            Rated::Schwarzschild(c) => self.planar_footprint(px, py, c, rates),
            Rated::Kerr(k) => self.kerr_footprint(px, py, k).unwrap_or_else(|| {
                self.neighbour_footprint_of(px, py, self.closed_ends(&ray.ray()))
            }),
        }
    }

    /// [`Integrator::footprint`] from neighbouring rays on each axis, for every
    /// spacetime and model (the way Schwarzschild's closed form is checked).
    pub fn neighbour_footprint(&self, px: f64, py: f64) -> Option<Footprint> {
        let main = self.ends(px, py)?;
        Some(self.neighbour_footprint_of(px, py, main))
    }

    /// [`Scene::neighbour_footprint`] of the sample whose ray ends `main`.
    fn neighbour_footprint_of(&self, px: f64, py: f64, main: Ends) -> Footprint {
        let closed = self.model.spacetime().is_some();
        let step = if closed { CLOSED_STEP } else { TRACED_STEP };
        // Each axis: the neighbours after and before. Closed forms are
        // smooth to near machine precision, so a forward difference over
        // their tiny step is as good as a central one (error ~ step / 2
        // times the map's relative curvature per pixel) for half the rays:
        // the neighbour before is traced only where the one after does not
        // end like the sample. The seed model's rays, over its larger
        // step, take both.
        let axis = |(ax, ay): (f64, f64)| {
            let after = self.ends(px + ax * step, py + ay * step);
            let before = (!closed || !after.is_some_and(|a| main.alike(&a)))
                .then(|| self.ends(px - ax * step, py - ay * step))
                .flatten();
            (after, before)
        };
        let (x_after, x_before) = axis((1.0, 0.0));
        let (y_after, y_before) = axis((0.0, 1.0));
        let mut fp = self.empty_footprint(px, py);
        // A derivative from the neighbours that end alike: central if both
        // do, else whichever does.
        let derive =
            |after: Option<DVec3>, before: Option<DVec3>, here: DVec3| match (after, before) {
                (Some(a), Some(b)) => Some((a - b) / (2.0 * step)),
                (Some(a), None) => Some((a - here) / step),
                (None, Some(b)) => Some((here - b) / step),
                (None, None) => None,
            };
        if let Some(d) = main.escape {
            let esc = |e: &Option<Ends>| e.and_then(|e| e.escape);
            let dx = derive(esc(&x_after), esc(&x_before), d);
            let dy = derive(esc(&y_after), esc(&y_before), d);
            if let (Some(dx), Some(dy)) = (dx, dy) {
                fp.sky = Some((d, [dx, dy]));
            }
        }
        let eye = self.camera.position;
        for (order, p, q) in main.crossings[..main.n].iter().copied() {
            let at = |e: &Option<Ends>| e.and_then(|e| e.crossing(order)).map(|c| c.1.extend(0.0));
            let here = q.extend(0.0);
            let dx = derive(at(&x_after), at(&x_before), here);
            let dy = derive(at(&y_after), at(&y_before), here);
            let (Some(dx), Some(dy)) = (dx, dy) else {
                continue;
            };
            push_crossing(&mut fp, order, (q, [dx.truncate(), dy.truncate()]), p - eye);
        }
        fp
    }
}

impl Integrator<'_> {
    /// [`Integrator::footprint`] of a Schwarzschild ray in closed form, from
    /// the symmetry of its plane: turning the plane about the camera's
    /// radial axis turns the whole ray rigidly, so only the derivative in
    /// the impact parameter needs the orbit (in closed form:
    /// [`ClosedRay::rates`]; the plane's crossings of z = 0 stay where they
    /// were), and the pixel's derivatives are the camera's
    /// ([`crate::camera::Camera::ray_rates`]) split into those two motions.
    fn planar_footprint(
        &self,
        px: f64,
        py: f64,
        ray: &ClosedRay,
        (v, dv): (DVec3, [DVec3; 2]),
    ) -> Footprint {
        let x = self.camera.position;
        let (e1, e2) = ray.plane();
        let n = e1.cross(e2);
        let b = ray.b();
        // Each pixel axis as (db, d angle of the plane about e1).
        let motion = dv.map(|dv| plane_motion(x, v, dv, n));
        let mut fp = self.empty_footprint(px, py);
        // The orbit's rates in c = 1 / b^2, per unit b.
        let rates = ray.rates();
        let dc_db = -2.0 / (b * b * b);
        if let Some(dsweep) = rates.dsweep {
            let d = ray.escape_direction();
            // Along the plane, towards the motion.
            let by_b = n.cross(d) * (dsweep * dc_db);
            let along = |(d_b, d_a): (f64, f64)| by_b * d_b + e1.cross(d) * d_a;
            fp.sky = Some((d, [along(motion[0]), along(motion[1])]));
        }
        let Some(disk) = &self.disk else {
            return fp;
        };
        let eye = self.camera.position;
        for (order, phi) in ray.z0_crossings().enumerate().take(MAX_CROSSINGS) {
            let (u, du) = ray.orbit_at(phi);
            let p = ray.point_at(phi, u);
            let rho = p.length();
            if !(disk.inner..=disk.outer).contains(&rho) {
                continue;
            }
            // At fixed angle the point moves along its radius.
            let by_b = -p * (ray.du_dc(&rates, u, du) * dc_db / u);
            // The tangent, to slide back onto the plane z = 0 after the
            // plane turns.
            let t = ray.tangent_at(phi, u, du);
            let slide = |(d_b, d_a): (f64, f64)| {
                let a = by_b * d_b + e1.cross(p) * d_a;
                a - t * (a.z / t.z)
            };
            let dp = [slide(motion[0]).truncate(), slide(motion[1]).truncate()];
            push_crossing(
                &mut fp,
                order as u32,
                self.turned(p.truncate(), dp),
                p - eye,
            );
        }
        fp
    }

    /// [`Integrator::footprint`] of a Kerr ray from its rates
    /// ([`KerrRay::rated`]): the escape direction's and each crossing's
    /// Boyer-Lindquist radius and azimuth, whose plane point the disk
    /// reads. None where a rate is not finite (within a hair of the
    /// critical curve or the axis).
    fn kerr_footprint(&self, px: f64, py: f64, ray: &KerrRay<D2>) -> Option<Footprint> {
        let mut fp = self.empty_footprint(px, py);
        if !ray.captured {
            let (d, dd) = ray.escape_rated();
            if !dd.iter().all(|d| d.is_finite()) {
                return None;
            }
            fp.sky = Some((d, dd));
        }
        let Some(disk) = &self.disk else {
            return Some(fp);
        };
        // A ray that keeps beyond the disk crosses it nowhere (M: twice
        // the scene's r_s).
        if ray.min_radius() > 2.0 * disk.outer {
            return Some(fp);
        }
        let eye = self.camera.position;
        for (order, c) in ray.crossings().enumerate() {
            if !(disk.inner..=disk.outer).contains(&(0.5 * c.r)) {
                continue;
            }
            // The disk's plane point (Spacetime::disk_plane): half the
            // Boyer-Lindquist radius at its azimuth.
            let (r, phi, p) = ray.crossing_rated(&c);
            let (s, co) = phi.sin_cos();
            let (x, y) = (r * co * 0.5, r * s * 0.5);
            let rate = |k: usize| DVec2::new(x.d[k], y.d[k]);
            let (q, dq) = self.turned(DVec2::new(x.v, y.v), [rate(0), rate(1)]);
            if !dq.iter().all(|d| d.is_finite()) {
                return None;
            }
            push_crossing(&mut fp, order as u32, (q, dq), 0.5 * p - eye);
            if fp.n == MAX_CROSSINGS {
                break;
            }
        }
        Some(fp)
    }

    /// A footprint at image point (`px`, `py`) holding nothing yet.
    fn empty_footprint(&self, px: f64, py: f64) -> Footprint {
        Footprint {
            pixel_sr: self.camera.pixel_solid_angle(px, py),
            at: DVec2::new(px, py),
            ..Footprint::default()
        }
    }

    /// A disk-plane point `q` and its rates `dq`, turned back by the
    /// disk's rotation (rings turn by their own angles: the rates through
    /// a central difference of the turn where it turns).
    fn turned(&self, q: DVec2, dq: [DVec2; 2]) -> (DVec2, [DVec2; 2]) {
        let turn = |q: DVec2| self.rotation.unturn_plane(q, self.time);
        if !self.rotation.turns(self.time) {
            return (turn(q), dq);
        }
        let rho = q.length();
        let qd = |d: DVec2| {
            let k = 1e-6 * rho / d.length().max(1e-300);
            (turn(q + d * k) - turn(q - d * k)) / (2.0 * k)
        };
        (turn(q), dq.map(qd))
    }
}

/// How a change `dv` of the coordinate direction `v` of a ray from `x`
/// moves its orbit: the change of its impact parameter b (with b^2 =
/// h^2 / v_inf^2, h = |x x v|, v_inf^2 = |v|^2 - h^2 / r^3) and the angle
/// its plane (normal `n`) turns about x.
fn plane_motion(x: DVec3, v: DVec3, dv: DVec3, n: DVec3) -> (f64, f64) {
    let r = x.length();
    let l = x.cross(v);
    let h2 = l.length_squared();
    let v_inf2 = v.length_squared() - h2 / (r * r * r);
    let dh2 = 2.0 * l.dot(x.cross(dv));
    let dv_inf2 = 2.0 * v.dot(dv) - dh2 / (r * r * r);
    let b = (h2 / v_inf2).sqrt();
    let db = (dh2 * v_inf2 - h2 * dv_inf2) / (v_inf2 * v_inf2) / (2.0 * b);
    let e1 = x / r;
    let perp = v - e1 * v.dot(e1);
    let da = (dv - e1 * dv.dot(e1)).dot(n) / perp.length();
    (db, da)
}

/// Adds to `fp` the disk crossing of plane-crossing order `order` at
/// plane point `q` (turned back by the disk's rotation) with derivatives
/// `dq` per pixel, `to` from the camera (at most [`MAX_CROSSINGS`]).
fn push_crossing(fp: &mut Footprint, order: u32, (q, dq): (DVec2, [DVec2; 2]), to: DVec3) {
    if fp.n < MAX_CROSSINGS {
        fp.disk[fp.n] = DiskFootprint {
            order,
            q,
            dq,
            magnification: disk_magnification(fp.pixel_sr, to, dq),
        };
        fp.n += 1;
    }
}

/// The disk's magnification at a crossing `to` from the camera whose
/// footprint on the plane has derivatives `dq` per pixel: the pixel's
/// solid angle `pixel_sr` over the solid angle |A e_z| / rho^2 that
/// footprint (signed area A) would subtend seen straight from the camera
/// at distance rho along unit e, signed by the orientation relative to a
/// straight view's, whose signed area has the sign of e_z.
fn disk_magnification(pixel_sr: f64, to: DVec3, dq: [DVec2; 2]) -> f64 {
    let rho2 = to.length_squared();
    let e_z = to.z / rho2.sqrt();
    pixel_sr * rho2 / (dq[0].perp_dot(dq[1]) * e_z)
}
