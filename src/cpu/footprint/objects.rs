//! Footprints at object hits: the derivatives per pixel of the texture
//! coordinates where a sample's ray meets an object, for an object texture
//! read over the pixel's footprint.
//!
//! They come from neighbouring rays a small fraction of a pixel away on
//! each side, traced as the sample's ray is, each to its own first object
//! hit: the differences of the hits' texture coordinates. The ray that
//! meets an object is a chord of a curved path, so a ray differential
//! carried along that chord (Igehy's transfer to the surface's tangent
//! plane) needs the derivatives of the position and direction where the
//! chord starts, which only neighbouring rays give here (the tracer does
//! not integrate the geodesic deviation); carried instead straight from
//! the camera it is exact in flat space only. REFERENCE §18 has the
//! measurements that chose this.
//!
//! A difference never reaches across a discontinuity: a neighbour counts
//! only where it meets the same object, on the same smooth piece of its
//! surface ([`crate::shapes::Shape::continuous`]: not across a mesh's seam
//! or silhouette), after as many crossings of the plane z = 0 (the same
//! image); else the neighbour on the other side is taken, and where neither
//! does the hit has no footprint (its texture is read at the point). Rays
//! after a mirror have none, as for the disk.

use crate::cpu::Integrator;
use crate::physics::{Flow, Segment};
use crate::shapes::{Hit, Shape};
use crate::texture::{Footprint, wrap_du};
use glam::DVec2;

/// Neighbour step (pixels) of the rays that find an object hit's
/// footprint (REFERENCE §18: the derivatives agree with a hundred times
/// tighter steps to 1e-6 and better).
pub const OBJECT_STEP: f64 = 1e-2;

/// The largest u extent of a sphere's footprint: half a turn each way
/// (towards a pole a pixel spans ever more of a row; beyond the whole row
/// the filter would only read it again).
const MAX_U_EXTENT: f64 = 0.5;

/// A hit found on a curved segment's chord `seg`, moved onto the curve
/// itself: the chord meets the surface where the step sequence puts it, and
/// a neighbouring ray's steps may differ (an error-controlled step taken
/// again) by far more than the curve, held to the tolerance, moves; a
/// difference of chord hits would carry that jump. Chords ever shorter
/// about the hit, each a fifth of the last, close in on the curve's own
/// crossing (a chord's distance from its curve falls as its length
/// squared); where one misses (at the surface's edge) the last hit stands.
pub(crate) fn on_curve(shape: &Shape, seg: &Segment, hit: Hit) -> Hit {
    if !seg.curved {
        return hit;
    }
    let (mut best, mut s) = (hit, hit.s);
    let mut half = 0.25;
    for _ in 0..6 {
        let (a, b) = ((s - half).max(0.0), (s + half).min(1.0));
        let Some(h) = shape.intersect(seg.point(a), seg.point(b)) else {
            break;
        };
        s = a + (b - a) * h.s;
        best = Hit { s, ..h };
        half *= 0.2;
    }
    best
}

/// Crossings of the plane z = 0 along `seg` up to fraction `s` (0 or 1).
#[inline]
pub(crate) fn plane_crossings(seg: &Segment, s: f64) -> u32 {
    seg.crossing_z0().is_some_and(|c| c <= s) as u32
}

impl Integrator<'_> {
    /// The first object the ray through image point `at` (pixels) meets:
    /// its index, the hit (on the ray's curve, [`on_curve`], not the chord
    /// the render takes), and the crossings of the plane z = 0 before it.
    /// Traced as a sample's ray is, the geodesic alone (the disk and gas
    /// do not bend it).
    pub fn object_hit(&self, at: DVec2) -> Option<(usize, Hit, u32)> {
        let (dir, _) = self.camera.ray(at.x, at.y);
        let origin = self.camera.position;
        let mut found = None;
        let mut plane = 0;
        let visit = |seg: &Segment| {
            let object = self.nearest_object(seg);
            plane += plane_crossings(seg, object.as_ref().map_or(1.0, |o| o.1.s));
            match object {
                Some((i, h)) => {
                    found = Some((i, on_curve(&self.objects[i].shape, seg, h), plane));
                    Flow::Stop
                }
                None => Flow::Continue,
            }
        };
        // The same trace as the sample's (a timed trace holds its steps to
        // the time's error too): the neighbours' steps follow the sample's.
        if self.timed {
            self.model.trace_timed(origin, dir, &self.limits, visit);
        } else {
            self.model.trace(origin, dir, &self.limits, visit);
        }
        found
    }

    /// The footprint in texture coordinates (derivatives of (u, v) per
    /// pixel along x and y) of the sample at image point `at` whose ray met
    /// object `i` at `hit` after `plane` crossings of the plane z = 0 (see
    /// the module's notes); None where no neighbour on an axis meets the
    /// same surface alike.
    pub fn object_footprint(
        &self,
        at: DVec2,
        i: usize,
        hit: &Hit,
        plane: u32,
    ) -> Option<Footprint> {
        let shape = &self.objects[i].shape;
        let sphere = matches!(shape, Shape::Sphere(_));
        let step = OBJECT_STEP;
        let uv = |h: &Hit| DVec2::new(h.uv.0, h.uv.1);
        let alike = |d: DVec2| {
            self.object_hit(at + d * step)
                .filter(|(j, h, p)| *j == i && *p == plane && shape.continuous(hit, h))
                .map(|(_, h, _)| uv(&h))
        };
        // A sphere's u is an angle: the short way across its seam.
        let diff = |a: DVec2, b: DVec2| {
            let d = a - b;
            if sphere {
                DVec2::new(wrap_du(d.x), d.y)
            } else {
                d
            }
        };
        let here = uv(hit);
        let axis = |d: DVec2| match (alike(d), alike(-d)) {
            (Some(a), Some(b)) => Some(diff(a, b) / (2.0 * step)),
            (Some(a), None) => Some(diff(a, here) / step),
            (None, Some(b)) => Some(diff(here, b) / step),
            (None, None) => None,
        };
        let mut fp = Footprint {
            dx: axis(DVec2::X)?,
            dy: axis(DVec2::Y)?,
        };
        let extent = fp.dx.x.hypot(fp.dy.x);
        if sphere && extent > MAX_U_EXTENT {
            fp.dx.x *= MAX_U_EXTENT / extent;
            fp.dy.x *= MAX_U_EXTENT / extent;
        }
        Some(fp)
    }
}
