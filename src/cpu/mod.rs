//! The CPU backend: the per-sample walk and the parallel driver, an
//! [`Integrator`] over a [`Scene`].
//!
//! A pixel sample flows: seed from (image seed, pixel, sample index) ->
//! position in the pixel -> camera ray -> the one walk
//! (`Integrator::trace_sample`: integrated segments, or the closed form's
//! segments, stretches and crossings) -> its shade (RGB, spectral or
//! janskys: `shade.rs`, `jansky.rs`), averaged with a box filter. Seeding
//! from the pixel makes the image independent of thread count and
//! scheduling.

mod adaptive;
pub(crate) mod footprint;
mod gas;
mod jansky;
mod pixels;
mod shade;

use crate::film::{BANDS, band_of};
pub use crate::film::{Film, Observable, Outcome, PixelProbe, Probe, SampleClass, Stats};
pub use crate::footprint::{DiskFootprint, Footprint};
pub use footprint::OBJECT_STEP;

use crate::config::AlphaMode;
use crate::disk::DiskHit;
use crate::objects::Finish;
use crate::physics::closed::HORIZON_MARGIN;
use crate::physics::kerr::Kerr;
use crate::physics::shift::seed_disk_ln_shift;
use crate::physics::spacetime::Closed;
use crate::physics::{End, Flow, Frame, Model, Observer, Segment, Spacetime, Trace, reflect};
use crate::scene::Scene;
use crate::shapes::Hit;
use crate::sky::SkyView;
use crate::transfer::riaf::Motion;
use crate::transfer::segment_k_r;
use glam::{DVec2, DVec3, Vec3};
use pixels::{Layout, Row, Sample};
use rayon::prelude::*;
use shade::{RgbShade, Shade, SpectralShade};
use std::sync::atomic::AtomicBool;

/// The CPU backend: renders a scene it reads (its fields through
/// `Deref`), sample by sample, in parallel rows. [`Scene`]'s own entry
/// points (`render`, `radiance`, `footprint`...) hand their work to one.
#[derive(Clone, Copy)]
pub struct Integrator<'a> {
    scene: &'a Scene,
    /// An observed scene's pixel solid angle's factor as the distant
    /// observer sees it, (r_cam / D)^2: the camera's place at the scene's
    /// time, the same for every sample.
    seen_from_earth: f64,
}

impl<'a> Integrator<'a> {
    pub fn new(scene: &'a Scene) -> Integrator<'a> {
        let seen_from_earth = scene.observe.as_ref().map_or(0.0, |o| {
            (scene.camera_distance_cm() / o.distance_cm).powi(2)
        });
        Integrator {
            scene,
            seen_from_earth,
        }
    }

    /// The scene it renders.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }
}

impl std::ops::Deref for Integrator<'_> {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        self.scene
    }
}

/// The scene's entry points to the CPU backend, each an [`Integrator`]'s.
impl Scene {
    /// Renders the whole image; `progress` is called with the number of
    /// rows finished since its last call.
    pub fn render(&self, progress: &(dyn Fn(u64) + Sync)) -> (Film, Stats) {
        Integrator::new(self).render(progress)
    }

    /// Renders rows `rows` only (a tile of the whole image).
    pub fn render_rows(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> (Film, Stats) {
        Integrator::new(self).render_rows(rows, progress)
    }

    /// [`Scene::render_rows`], giving up (None) once `stop` is set.
    pub fn render_rows_until(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        stop: &AtomicBool,
    ) -> Option<(Film, Stats)> {
        Integrator::new(self).render_rows_until(rows, progress, stop)
    }

    /// [`Scene::render_rows_until`] with each pixel's sample count.
    pub fn render_rows_counted(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        stop: &AtomicBool,
    ) -> Option<(Film, Stats, Vec<u32>)> {
        Integrator::new(self).render_rows_counted(rows, progress, stop)
    }

    /// Linear sRGB arriving through image point (`px`, `py`) with RGB
    /// shading, and how its trace went.
    pub fn radiance(&self, px: f64, py: f64) -> (Vec3, Outcome) {
        Integrator::new(self).radiance(px, py)
    }

    /// The spectrum arriving through image point (`px`, `py`) on the
    /// render's wavelengths ([`Integrator::spectrum`]).
    pub fn spectrum(&self, px: f64, py: f64, out: &mut [f32]) -> (Outcome, f64, f64) {
        Integrator::new(self).spectrum(px, py, out)
    }

    /// Where the ray through image-plane point `at` goes at infinity
    /// ([`Integrator::escape_at`]).
    pub fn escape_at(&self, at: DVec2) -> Option<DVec3> {
        Integrator::new(self).escape_at(at)
    }

    /// The footprint of the sample at (`px`, `py`) ([`Integrator::footprint`]).
    pub fn footprint(&self, px: f64, py: f64) -> Option<Footprint> {
        Integrator::new(self).footprint(px, py)
    }

    /// [`Scene::footprint`] from neighbouring rays on each axis.
    pub fn neighbour_footprint(&self, px: f64, py: f64) -> Option<Footprint> {
        Integrator::new(self).neighbour_footprint(px, py)
    }

    /// The first object the ray through image point `at` meets
    /// ([`Integrator::object_hit`]).
    pub fn object_hit(&self, at: DVec2) -> Option<(usize, crate::shapes::Hit, u32)> {
        Integrator::new(self).object_hit(at)
    }

    /// The footprint in texture coordinates of object `i`'s hit
    /// ([`Integrator::object_footprint`]).
    pub fn object_footprint(
        &self,
        at: DVec2,
        i: usize,
        hit: &crate::shapes::Hit,
        plane: u32,
    ) -> Option<crate::texture::Footprint> {
        Integrator::new(self).object_footprint(at, i, hit, plane)
    }
}

/// What a sample's trace tells the observables as it goes: the first
/// light it meets, and the equatorial crossings so far (the image order).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Probing {
    pub(crate) probe: Probe,
    /// The first light was noted.
    met: bool,
    /// Crossings of the plane z = 0 so far.
    crossings: u32,
    /// Where (fraction of the step) the step being marched crosses the
    /// plane off the disk, not yet counted: gas beyond it is one later.
    pending: Option<f64>,
    /// The sample's footprint, where the scene keeps them (it follows the
    /// camera's ray up to the first mirror).
    pub(crate) footprint: Option<Footprint>,
    /// The sample's image point while its footprint is still to be found.
    footprint_at: Option<(f64, f64)>,
    /// The sample's image point while its ray follows the camera's
    /// geodesic, where an object's texture may read over a footprint.
    object_at: Option<DVec2>,
    /// Crossings of the plane z = 0 so far, counted where `object_at` is:
    /// an object hit's footprint takes neighbours of the same image order.
    plane: u32,
    /// The first object met (its index), for adaptive sampling's classes.
    pub(crate) object: Option<u32>,
}

impl Probing {
    /// The image order of light at fraction `s` of the step.
    #[inline]
    fn order_at(&self, s: f64) -> f64 {
        (self.crossings + self.pending.is_some_and(|c| s > c) as u32) as f64
    }

    /// Notes light of ln g `ln_g` from a point at ring radius `radius`
    /// (NaN: not the disk), `order` crossings in, `time` from the camera
    /// (NaN: not kept), if it is the first.
    #[inline]
    fn light(&mut self, ln_g: f64, radius: f64, order: f64, time: f64) {
        self.light_magnified(ln_g, radius, order, time, f64::NAN);
    }

    /// [`Probing::light`] of the disk's material at plane crossing
    /// `order`, with the footprint's magnification there.
    #[inline]
    fn disk_light(&mut self, ln_g: f64, radius: f64, order: u32, time: f64) {
        if !self.met {
            let mu = self
                .footprint
                .and_then(|f| f.disk(order).map(|d| d.magnification))
                .unwrap_or(f64::NAN);
            self.light_magnified(ln_g, radius, order as f64, time, mu);
        }
    }

    /// [`Probing::light`] of the sky, with the footprint's magnification.
    #[inline]
    fn sky_light(&mut self, ln_g: f64) {
        if !self.met {
            let mu = self
                .footprint
                .and_then(|f| f.sky_magnification())
                .unwrap_or(f64::NAN);
            self.light_magnified(ln_g, f64::NAN, f64::NAN, f64::NAN, mu);
        }
    }

    #[inline]
    fn light_magnified(&mut self, ln_g: f64, radius: f64, order: f64, time: f64, mu: f64) {
        if !self.met {
            self.met = true;
            let sky = self.probe.sky;
            self.probe = Probe {
                g: ln_g.exp(),
                radius,
                order,
                time,
                magnification: mu,
                sky,
            };
        }
    }

    /// The footprint on the disk's plane (derivatives of the point the
    /// texture reads per pixel) of plane crossing `order`, where known.
    #[inline]
    fn disk_footprint(&self, order: u32) -> Option<[DVec2; 2]> {
        self.footprint.and_then(|f| f.disk(order).map(|d| d.dq))
    }

    /// Notes where the ray went at infinity.
    #[inline]
    fn escaped(&mut self, d: DVec3) {
        self.probe.sky = d.to_array();
    }

    /// The ray left the camera's geodesic (a mirror): the footprint no
    /// longer describes it.
    #[inline]
    fn bounced(&mut self) {
        self.footprint = None;
        self.object_at = None;
    }
}

/// The frequency shift of light reaching the camera along one traced path
/// (one trace between mirrors), as ln g.
#[derive(Clone, Copy, Debug)]
struct Shifts {
    /// The model tracing the path.
    model: Model,
    /// Whether shifts are computed at all: a spectral render with the
    /// shift on, or the `g` observable.
    on: bool,
    /// Whether they apply to the light (a spectral render with the shift
    /// on); else only the observable sees them.
    render: bool,
    /// Include the disk's Keplerian Doppler shift.
    doppler: bool,
    /// The camera's position (r_s) and the frame it is at rest in.
    cam: DVec3,
    cam_frame: Frame,
    /// ln D of the camera's own motion for light along this sample's ray
    /// (0 at rest).
    ln_camera: f64,
    /// Exact model: the photon's L_z / E on this path, and on the camera's
    /// path (the first; mirrors change it, and the camera's frame measures
    /// the light that reaches it along that one).
    lz_over_e: f64,
    lz_cam: Option<f64>,
    /// The exact model's measure of a unit-energy photon at the camera, ln
    /// (nu_cam / E) with the camera's own motion: set with the camera's
    /// path (it depends on that path's L_z / E alone).
    camera_ln: Option<f64>,
    /// Seed model: the running sum from the camera to this path's start.
    ln_offset: f64,
    /// The frame's time (r_s/c).
    frame_time: f64,
    /// Whether the disk is seen as it was when its light left it.
    travel: bool,
    /// Whether the trace keeps light's travel time (then segments carry
    /// it): for `travel` or the `time` observable.
    timed: bool,
    /// Travel time from this path's start back to the camera (r_s/c).
    time_offset: f64,
}

impl Shifts {
    /// The shift the light gets (none where only the observable sees it).
    #[inline]
    fn light(&self, ln_g: f64) -> f64 {
        if self.render { ln_g } else { 0.0 }
    }

    /// The light's travel time (r_s/c) from fraction `s` of `seg` to the
    /// camera, where the trace keeps it (else NaN).
    #[inline]
    fn travel_time(&self, seg: &Segment, s: f64) -> f64 {
        if self.timed {
            self.time_offset + seg.time_at(s)
        } else {
            f64::NAN
        }
    }

    /// When the light reaching the camera at the frame's time left
    /// fraction `s` of `seg` (r_s/c).
    #[inline]
    fn emitted_at(&self, seg: &Segment, s: f64) -> f64 {
        self.emitted(|| seg.time_at(s))
    }

    /// When the light left a point whose travel time to this path's start
    /// is `travel` (r_s/c, asked only when kept): the frame's time less
    /// the whole travel time.
    #[inline]
    fn emitted(&self, travel: impl FnOnce() -> f64) -> f64 {
        if self.travel {
            self.frame_time - (self.time_offset + travel())
        } else {
            self.frame_time
        }
    }

    /// Light from rotating gas at fraction `s` of `seg` (point `p`).
    #[inline]
    fn disk(&self, seg: &Segment, s: f64, p: DVec3) -> f64 {
        match self.model {
            Model::Gr { spacetime, .. } => self.gr_disk(spacetime, p),
            Model::Seed { .. } if self.on => {
                self.ln_offset + seed_disk_ln_shift(seg, s, self.doppler) + self.ln_camera
            }
            Model::Seed { .. } => 0.0,
        }
    }

    /// A path starting at `origin` along `dir`: the exact model's photon
    /// L_z/E there (for the disk's Doppler shift, and with spin for the
    /// camera's frame, which drags).
    #[inline]
    fn start_path(&mut self, origin: DVec3, dir: DVec3) {
        self.start_path_with(origin, dir, None);
    }

    /// [`Shifts::start_path`] where the path's L_z / E may be known already
    /// (`known`: a Kerr ray in closed form has it).
    #[inline]
    fn start_path_with(&mut self, origin: DVec3, dir: DVec3, known: Option<f64>) {
        self.lz_over_e = match self.model {
            Model::Gr { spacetime, .. }
                if self.doppler || (self.on && matches!(spacetime, Spacetime::Kerr { .. })) =>
            {
                known.unwrap_or_else(|| spacetime.photon_lz_over_e(origin, dir))
            }
            _ => 0.0,
        };
        if self.lz_cam.is_none() {
            self.lz_cam = Some(self.lz_over_e);
            if let Model::Gr { spacetime, .. } = self.model
                && self.on
            {
                self.camera_ln =
                    Some(spacetime.static_ln_shift(None, self.observer()) + self.ln_camera);
            }
        }
    }

    /// The photon's L_z / E on the camera's path, in the model's own units
    /// (r_s without spin, M with), as [`Spacetime::photon_lz_over_e`].
    #[inline]
    fn camera_lz_over_e(&self) -> f64 {
        self.lz_cam.unwrap_or(self.lz_over_e)
    }

    /// The camera as the exact model's shifts see it.
    #[inline]
    fn observer(&self) -> Observer {
        Observer {
            at: self.cam,
            frame: self.cam_frame,
            lz_over_e: self.camera_lz_over_e(),
        }
    }

    /// The exact model's disk light at `p`: it depends on the point and
    /// the photon's conserved L_z/E only, not on the path.
    #[inline]
    fn gr_disk(&self, st: Spacetime, p: DVec3) -> f64 {
        if !self.on {
            return 0.0;
        }
        st.disk_ln_shift(p, self.lz_over_e, self.observer(), self.doppler) + self.ln_camera
    }

    /// Light from gas moving as `motion` at fraction `s` of `seg` (point
    /// `p`): the exact model's photon measured by the gas
    /// ([`Motion::frequency_ratio`], the same as an observed scene's
    /// transfer takes) against the camera's measure of it; without the
    /// Doppler shift, a static emitter's; the seed model's flat space has
    /// no such orbits: its disk's. None where the motion is not timelike.
    #[inline]
    fn moving(&self, seg: &Segment, s: f64, p: DVec3, motion: &Motion) -> Option<f64> {
        let Model::Gr { spacetime, .. } = self.model else {
            return Some(self.disk(seg, s, p));
        };
        if !(self.on && self.doppler) {
            return Some(self.fixed(seg, s, p));
        }
        let kerr = Kerr::new(spacetime.spin());
        let q = 2.0 * p;
        let r = kerr.ks_radius(q);
        let photon = (self.in_m(self.lz_over_e), segment_k_r(kerr, seg, s));
        let ratio = motion.frequency_ratio(kerr, r, (q.z / r).clamp(-1.0, 1.0), photon)?;
        Some(self.sky(0.0) - ratio.ln())
    }

    /// An angular momentum `lz` of this model's in M (Schwarzschild's is in
    /// r_s).
    #[inline]
    fn in_m(&self, lz: f64) -> f64 {
        match self.model {
            Model::Gr {
                spacetime: Spacetime::Schwarzschild,
                ..
            } => 2.0 * lz,
            _ => lz,
        }
    }

    /// Light from a static emitter (object, cloud, mirror) there.
    #[inline]
    fn fixed(&self, seg: &Segment, s: f64, p: DVec3) -> f64 {
        if !self.on {
            return 0.0;
        }
        (match self.model {
            Model::Gr { spacetime, .. } => spacetime.static_ln_shift(Some(p), self.observer()),
            Model::Seed { .. } => self.ln_offset + seg.ln_shift_at(s),
        }) + self.ln_camera
    }

    /// Sky light, with the trace's own result for the seed model.
    #[inline]
    fn sky(&self, trace_ln_shift: f64) -> f64 {
        if !self.on {
            return 0.0;
        }
        match self.model {
            // At the camera's frame, whatever the path.
            Model::Gr { spacetime, .. } => self.camera_ln.unwrap_or_else(|| {
                spacetime.static_ln_shift(None, self.observer()) + self.ln_camera
            }),
            Model::Seed { .. } => self.ln_offset + trace_ln_shift + self.ln_camera,
        }
    }
}

/// A mirror's reflection: where the ray starts again and in which
/// direction, the mirror's tint, ln g at the mirror, and the light's travel
/// time from the mirror on this trace.
struct Bounce {
    start: DVec3,
    dir: DVec3,
    tint: Vec3,
    ln_g: f64,
    travelled: f64,
}

impl Integrator<'_> {
    /// The frequency shifts' state for one camera sample from `origin`,
    /// the camera's own Doppler factor e^`ln_camera` in it.
    #[inline]
    fn shifts<S: Shade>(&self, origin: DVec3, ln_camera: f64) -> Shifts {
        let render = S::PHYSICAL || S::SHIFT && self.spectral.as_ref().is_some_and(|c| c.shift);
        let on = render || self.observables.contains(&Observable::G);
        Shifts {
            model: self.model,
            on,
            render,
            // An RGB render's g map takes the file's Doppler setting.
            doppler: S::PHYSICAL
                || on
                    && self
                        .spectral
                        .as_ref()
                        .map_or(self.config.spectral.doppler, |c| c.doppler),
            cam: origin,
            cam_frame: self.camera.rest_frame,
            ln_camera,
            lz_over_e: 0.0,
            lz_cam: None,
            camera_ln: None,
            // Each trace's own running sum starts at zero.
            ln_offset: 0.0,
            frame_time: self.time,
            travel: self.light_travel_time,
            timed: self.timed,
            time_offset: 0.0,
        }
    }

    /// The first object the segment meets outside the horizon (a chord may
    /// cut into the horizon; the light cannot come back out).
    #[inline]
    fn nearest_object(&self, seg: &Segment) -> Option<(usize, Hit)> {
        let mut object: Option<(usize, Hit)> = None;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(h) = o.shape.intersect(seg.x0, seg.x1)
                && h.point.length_squared() > 1.0
                && object.as_ref().is_none_or(|(_, b)| h.s < b.s)
            {
                object = Some((i, h));
            }
        }
        object
    }

    /// The light of object `i` where the ray meets it at `h`: shaded, or
    /// for a mirror the reflection that goes on.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn meet_object<S: Shade>(
        &self,
        i: usize,
        h: &Hit,
        seg: &Segment,
        shifts: &Shifts,
        shade: &mut S,
        probing: &mut Probing,
        through: f32,
    ) -> Option<Bounce> {
        // The ray's own direction at the hit (the curve's tangent,
        // not the chord's).
        let incoming = seg.tangent(h.s);
        let towards_viewer = -incoming;
        let ln_g = shifts.fixed(seg, h.s, h.point);
        let obj = &self.objects[i];
        let fp = match probing.object_at {
            Some(at) if obj.material.filter == crate::config::Filter::Footprint => {
                let on = footprint::on_curve(&obj.shape, seg, *h);
                self.object_footprint(at, i, &on, probing.plane)
            }
            _ => None,
        };
        match obj.material.finish {
            Finish::Mirror => {
                let n = if h.normal.dot(towards_viewer) < 0.0 {
                    -h.normal
                } else {
                    h.normal
                };
                let start = h.point + n * (1e-9 * h.point.length().max(1.0));
                let out = match self.model {
                    Model::Gr { spacetime, .. } => spacetime.reflect(h.point, incoming, n),
                    // Flat space with an isotropic index: the
                    // coordinate law of reflection is the law.
                    Model::Seed { .. } => reflect(incoming, n),
                };
                Some(Bounce {
                    start,
                    dir: out,
                    tint: obj.color(h, fp.as_ref()),
                    ln_g,
                    travelled: seg.time_at(h.s),
                })
            }
            _ => {
                probing.light(ln_g, f64::NAN, f64::NAN, shifts.travel_time(seg, h.s));
                let hit = (h, fp.as_ref());
                shade.object(self, obj, hit, towards_viewer, through, shifts.light(ln_g));
                None
            }
        }
    }

    /// The disk's plane and the gas along `seg` up to `s_object` (where an
    /// object stops it, 1 for none), in order: the gas up to the disk if
    /// the ray meets the disk's material first, the disk, then (through a
    /// blended disk) the gas on to the object or the segment's end.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn disk_and_gas<S: Shade>(
        &self,
        seg: &Segment,
        s_object: f64,
        shifts: &Shifts,
        shade: &mut S,
        through: &mut f32,
        met_disk: &mut bool,
        probing: &mut Probing,
    ) -> Flow {
        let gas = shade.has_gas(self);
        // Gas is marched in order along the segment: up to the disk
        // if the ray meets the disk's material before any object,
        // then (through a blended disk) on to the object or the end.
        let mut s_gas = 0.0;
        // The plane is crossed before any object (the image order
        // counts every crossing, on the disk or not: without a
        // disk, only the observables need it).
        let crossing = if self.disk.is_some() || (gas && !self.observables.is_empty()) {
            seg.crossing_z0().filter(|&s| s < s_object)
        } else {
            None
        };
        // A crossing that missed the disk is counted after this
        // step's gas, the gas beyond it one order later.
        let mut missed = crossing.is_some();
        if let Some(disk) = &self.disk
            && let Some(s) = crossing
            && let Some(hit) = disk.hit_footprint(
                self.rotation.unturn_plane(
                    disk.spacetime.disk_plane(seg.point(s)),
                    shifts.emitted_at(seg, s),
                ),
                probing.disk_footprint(probing.crossings),
            )
        {
            if gas
                && shade.gas(
                    self,
                    seg,
                    (0.0, s),
                    (&mut *through, shifts),
                    (&mut *met_disk, &mut *probing),
                )
            {
                return Flow::Stop;
            }
            *met_disk = true;
            let ln_g = shifts.disk(seg, s, seg.point(s));
            probing.disk_light(ln_g, hit.r, probing.crossings, shifts.travel_time(seg, s));
            probing.crossings += 1;
            if self.shade_disk_hit(&hit, shifts.light(ln_g), shade, through) == Flow::Stop {
                return Flow::Stop;
            }
            s_gas = s;
            missed = false;
        }
        probing.pending = crossing.filter(|_| missed);
        if gas
            && shade.gas(
                self,
                seg,
                (s_gas, s_object),
                (&mut *through, shifts),
                (&mut *met_disk, &mut *probing),
            )
        {
            return Flow::Stop;
        }
        probing.pending = None;
        probing.crossings += missed as u32;
        Flow::Continue
    }

    /// Traces one camera ray from `origin` along coordinate direction
    /// `dir`, following mirror reflections, telling `shade` what light
    /// reaches it. Frequency shifts are for the camera at `origin`, at rest
    /// in its frame, times its own motion's Doppler factor e^`ln_camera`:
    /// static mirrors do not change them.
    /// `probing` hears of the first light met.
    fn trace_sample<S: Shade>(
        &self,
        origin: DVec3,
        (dir, ln_camera): (DVec3, f64),
        shade: &mut S,
        probing: &mut Probing,
    ) -> Outcome {
        let mut through = 1.0f32;
        let (mut met_disk, mut met_object) = (false, false);
        let mut shifts = self.shifts::<S>(origin, ln_camera);
        let closed_ray = match (self.closed_form, self.model.spacetime()) {
            (true, Some(st)) => self.closed_sample_ray(st, origin, dir, shifts.timed, probing),
            _ => None,
        };
        // The camera's path: its photon's constants once, for the shifts
        // and the shade.
        shifts.start_path_with(origin, dir, closed_ray.as_ref().and_then(Closed::lz_over_e));
        shade.camera_path(&shifts);
        // Schwarzschild's closed form through a medium: its exact orbit's
        // segments, walked as the integrator's are.
        let mut segments = None;
        match (closed_ray, self.model.spacetime()) {
            (Some(Closed::Schwarzschild(c)), _) if shade.has_gas(self) => segments = Some(c),
            (Some(ray), Some(st)) => return self.trace_closed(st, &ray, &shifts, shade, probing),
            _ => {}
        }
        let closed = segments.is_some();
        if let Some((px, py)) = probing.footprint_at.take() {
            probing.footprint = self.footprint(px, py);
        }
        let (mut origin, mut dir) = (origin, dir);
        let mut steps = 0;
        for _ in 0..=crate::objects::MAX_BOUNCES {
            let mut bounce: Option<Bounce> = None;
            let visit = |seg: &Segment| {
                let object = self.nearest_object(seg);
                let s_object = object.as_ref().map_or(1.0, |(_, h)| h.s);
                if self.disk_and_gas(
                    seg,
                    s_object,
                    &shifts,
                    shade,
                    &mut through,
                    &mut met_disk,
                    probing,
                ) == Flow::Stop
                {
                    return Flow::Stop;
                }
                if probing.object_at.is_some() {
                    probing.plane += footprint::plane_crossings(seg, s_object);
                }
                let Some((i, h)) = object else {
                    return Flow::Continue;
                };
                met_object = true;
                probing.object.get_or_insert(i as u32);
                bounce = self.meet_object(i, &h, seg, &shifts, shade, probing, through);
                Flow::Stop
            };
            let trace = if let Some(c) = segments.take() {
                let (end, steps) = c.segments(self.limits.outer, visit);
                Trace {
                    end,
                    steps,
                    ln_shift: 0.0,
                }
            } else if shifts.timed {
                self.model.trace_timed(origin, dir, &self.limits, visit)
            } else {
                self.model.trace(origin, dir, &self.limits, visit)
            };
            steps += trace.steps;
            if let Some(b) = bounce {
                probing.bounced();
                shade.tint(self, b.tint, shifts.light(b.ln_g).exp());
                origin = b.start;
                dir = b.dir;
                shifts.start_path(origin, dir);
                shifts.time_offset += b.travelled;
                if let Model::Seed { .. } = self.model {
                    // The running sum from the mirror on; the camera's own
                    // Doppler factor is added once, at the end.
                    shifts.ln_offset = b.ln_g - shifts.ln_camera;
                }
                continue;
            }
            if let End::Escaped(d) = trace.end {
                self.sky_light(
                    d,
                    shifts.sky(trace.ln_shift),
                    &shifts,
                    shade,
                    probing,
                    through,
                );
            }
            return Outcome {
                end: trace.end,
                steps,
                disk: met_disk,
                object: met_object,
                closed,
            };
        }
        Outcome {
            end: End::Abandoned,
            steps,
            disk: met_disk,
            object: met_object,
            closed,
        }
    }

    /// Shades a crossing of the disk's material seen through `through`:
    /// cutout alpha ends the ray there, blended alpha lets the light behind
    /// through (the ray stops once almost nothing gets through, or where
    /// the shade takes the disk as opaque).
    fn shade_disk_hit<S: Shade>(
        &self,
        hit: &DiskHit,
        ln_g: f64,
        shade: &mut S,
        through: &mut f32,
    ) -> Flow {
        let disk = self.disk.as_ref().expect("a disk was hit");
        match disk.alpha {
            AlphaMode::Cutout => {
                shade.disk(self, hit, *through / hit.alpha, ln_g);
                Flow::Stop
            }
            AlphaMode::Blend => {
                shade.disk(self, hit, *through, ln_g);
                *through *= 1.0 - hit.alpha;
                if *through < 1e-4 || shade.spent() {
                    Flow::Stop
                } else {
                    Flow::Continue
                }
            }
        }
    }

    /// [`Integrator::trace_sample`] of a ray in closed form (a scene of the flat
    /// disk, the sky and a physical medium): its crossings of the disk
    /// plane in order, a Kerr ray's medium in the stretches between them,
    /// then the sky in its direction at infinity, or the hole.
    fn trace_closed<S: Shade>(
        &self,
        st: Spacetime,
        ray: &Closed,
        shifts: &Shifts,
        shade: &mut S,
        probing: &mut Probing,
    ) -> Outcome {
        let mut through = 1.0f32;
        let mut met_disk = false;
        let mut stopped = false;
        let mut steps = 0;
        let done = |end, met_disk, steps| Outcome {
            end,
            steps,
            disk: met_disk,
            object: false,
            closed: true,
        };
        // The medium's stretch so far ends at Mino time `gas_from`.
        let kerr = match ray {
            Closed::Kerr(k) if shade.has_gas(self) => Some(k),
            _ => None,
        };
        let mut gas_from = 0.0;
        if let Some(disk) = &self.disk {
            ray.crossings((disk.inner, disk.outer), |order, p, plane, travel, at| {
                let Some(hit) = disk.hit_footprint(
                    self.rotation.unturn_plane(plane, shifts.emitted(|| travel)),
                    probing.disk_footprint(order),
                ) else {
                    return Flow::Continue;
                };
                if let Some(k) = kerr {
                    steps += shade.kerr_gas(self, k, (gas_from, at), &mut met_disk);
                    gas_from = at;
                    if shade.spent() {
                        stopped = true;
                        return Flow::Stop;
                    }
                }
                met_disk = true;
                let ln_g = shifts.gr_disk(st, p);
                probing.disk_light(ln_g, hit.r, order, travel);
                let flow = self.shade_disk_hit(&hit, shifts.light(ln_g), shade, &mut through);
                stopped = flow == Flow::Stop;
                flow
            });
            if stopped {
                return done(End::Stopped, met_disk, steps);
            }
        }
        if let Some(k) = kerr {
            // To the ray's end: out of the medium, or just outside the
            // horizon for a captured ray.
            let end = match k.captured {
                true => k.mino_at_fall(k.horizon() * (1.0 + HORIZON_MARGIN)),
                false => k.mino_to_end(),
            };
            steps += shade.kerr_gas(self, k, (gas_from, end), &mut met_disk);
            if shade.spent() {
                return done(End::Stopped, met_disk, steps);
            }
        }
        if ray.captured() {
            return done(End::Captured, met_disk, steps);
        }
        let d = ray.escape_direction();
        self.sky_light(d, shifts.sky(0.0), shifts, shade, probing, through);
        done(End::Escaped(d), met_disk, steps)
    }

    /// The sky's light along escape direction `d`, arriving with ln g
    /// `ln_g`, through `through`: told to the observables and shaded over
    /// the sample's footprint, with the lens to place point stars.
    fn sky_light<S: Shade>(
        &self,
        d: DVec3,
        ln_g: f64,
        shifts: &Shifts,
        shade: &mut S,
        probing: &mut Probing,
        through: f32,
    ) {
        probing.escaped(d);
        probing.sky_light(ln_g);
        let lens = |at| self.escape_at(at);
        let view = probing.footprint.as_ref().map(|footprint| SkyView {
            footprint,
            lens: &lens,
        });
        shade.sky(self, d, view, through, shifts.light(ln_g));
    }

    /// Tells `probing` to find the footprint of the sample at (`px`, `py`)
    /// where the scene keeps them (the trace does, once).
    #[inline]
    fn note_footprint(&self, px: f64, py: f64, probing: &mut Probing) {
        if self.footprints {
            probing.footprint_at = Some((px, py));
        }
        if self.object_footprints {
            probing.object_at = Some(DVec2::new(px, py));
        }
    }

    /// Linear sRGB arriving at the camera through image point (`px`, `py`)
    /// with RGB shading (whatever the render mode), and how its trace went.
    pub fn radiance(&self, px: f64, py: f64) -> (Vec3, Outcome) {
        self.radiance_probed(px, py, &mut Probing::default())
    }

    /// [`Scene::radiance`], telling `probing` of the first light met.
    fn radiance_probed(&self, px: f64, py: f64, probing: &mut Probing) -> (Vec3, Outcome) {
        let mut shade = RgbShade::new();
        let ray = self.camera.ray(px, py);
        self.note_footprint(px, py, probing);
        let outcome = self.trace_sample(self.camera.position, ray, &mut shade, probing);
        (shade.color, outcome)
    }

    /// The spectrum arriving through image point (`px`, `py`) on the
    /// render's wavelengths, written to `out` (spectral renders only);
    /// with `per_wavelength` one ray is traced for each wavelength.
    /// Returns how the trace went (steps summed over the rays) and the
    /// range of g seen on the disk.
    pub fn spectrum(&self, px: f64, py: f64, out: &mut [f32]) -> (Outcome, f64, f64) {
        let (outcome, g_min, g_max, _) =
            self.spectrum_xyz(px, py, out, false, &mut Probing::default());
        (outcome, g_min, g_max)
    }

    /// [`Scene::spectrum`], with `direct` the light whose XYZ is known
    /// without its spectrum (blackbody skies) left out of `out`, which must
    /// then come zeroed and is left zeroed; returns the pixel's whole XYZ
    /// as the last item.
    fn spectrum_xyz(
        &self,
        px: f64,
        py: f64,
        out: &mut [f32],
        direct: bool,
        probing: &mut Probing,
    ) -> (Outcome, f64, f64, DVec3) {
        // In direct mode `out` comes zeroed and is left zeroed (most
        // samples never touch it).
        if !direct {
            out.fill(0.0);
        }
        let ray = self.camera.ray(px, py);
        self.note_footprint(px, py, probing);
        let n = out.len();
        let per_wavelength = self.spectral.as_ref().is_some_and(|c| c.per_wavelength);
        // One range covering every wavelength, or one per wavelength.
        let step = if per_wavelength { 1 } else { n };
        let mut last = Outcome {
            end: End::Abandoned,
            steps: 0,
            disk: false,
            object: false,
            closed: false,
        };
        let mut steps = 0;
        let (mut g_min, mut g_max) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut xyz, mut touched) = (DVec3::ZERO, false);
        for start in (0..n).step_by(step.max(1)) {
            let range = start..start + step;
            let mut shade = SpectralShade {
                out: &mut *out,
                range,
                g_min,
                g_max,
                filter: Vec::new(),
                scratch: Vec::new(),
                direct: direct && !per_wavelength,
                xyz: DVec3::ZERO,
                touched: false,
            };
            last = self.trace_sample(self.camera.position, ray, &mut shade, probing);
            g_min = shade.g_min;
            g_max = shade.g_max;
            xyz += shade.xyz;
            touched |= shade.touched;
            steps += last.steps;
        }
        if touched && let Some(ctx) = &self.spectral {
            xyz += ctx.wavelengths.xyz(out);
            if direct {
                out.fill(0.0);
            }
        }
        // Every wavelength's ray follows the same path.
        (Outcome { steps, ..last }, g_min, g_max, xyz)
    }

    /// Renders the whole image; `progress` is called with the number of rows
    /// finished since its last call.
    pub fn render(&self, progress: &(dyn Fn(u64) + Sync)) -> (Film, Stats) {
        self.render_rows(0..self.camera.height, progress)
    }

    /// Renders the image's rows `rows` (0 at the top): the film holds
    /// those rows, each pixel exactly as a whole render gives it (its
    /// samples are seeded by its place in the whole image).
    pub fn render_rows(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> (Film, Stats) {
        let never = std::sync::atomic::AtomicBool::new(false);
        self.render_rows_until(rows, progress, &never)
            .expect("a render nobody stops ends")
    }

    /// [`Scene::render_rows`] that gives up, returning None, once `stop`
    /// is set (rows not yet started are skipped): for renders a user can
    /// interrupt without ending the process.
    pub fn render_rows_until(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        stop: &std::sync::atomic::AtomicBool,
    ) -> Option<(Film, Stats)> {
        self.render_rows_counted(rows, progress, stop)
            .map(|(film, stats, _)| (film, stats))
    }

    /// [`Scene::render_rows_until`], also giving the samples each pixel
    /// took (row-major; more than `image.samples` where adaptive sampling
    /// refined it).
    pub fn render_rows_counted(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        stop: &std::sync::atomic::AtomicBool,
    ) -> Option<(Film, Stats, Vec<u32>)> {
        use std::sync::atomic::Ordering;
        assert!(rows.end <= self.camera.height, "rows within the image");
        let w = self.camera.width as usize;
        let h = rows.len();
        let n_wl = self.channels();
        // Spectral bloom: the XYZ of each of BANDS groups of wavelengths.
        let band_of: Option<Vec<usize>> = self
            .bloom_bands
            .then(|| (0..n_wl).map(|i| band_of(i, n_wl)).collect());
        let nb = if band_of.is_some() { BANDS } else { 0 };
        // Only the XYZ of each sample is needed.
        let direct = !self.keep_spectra && band_of.is_none();
        // Every row is written straight into the film's planes: the film
        // exists once in memory, not also as a list of rows.
        let mut xyz = vec![Vec3::ZERO; w * h];
        let mut spectra = vec![0.0f32; if self.keep_spectra { w * h * n_wl } else { 0 }];
        let mut band_planes: Vec<Vec<Vec3>> = (0..nb).map(|_| vec![Vec3::ZERO; w * h]).collect();
        // The observables, interleaved per pixel while rendering.
        let obs = &self.observables;
        let mut obs_values = vec![0.0f32; w * h * obs.len()];
        let layout = Layout {
            width: w,
            spectral: self.spectral.is_some() || self.observe.is_some(),
            n_wl,
            keep_spectra: self.keep_spectra,
            bands: band_of
                .as_deref()
                .zip(self.spectral.as_ref().map(|c| &c.wavelengths.weights[..])),
            observables: obs,
            white: (-self.image().exposure).exp2(),
        };
        // Adaptive sampling decides from neighbours: rows around the band
        // are sampled too, not kept.
        let margin = if self.adaptive {
            crate::adaptive::MARGIN
        } else {
            0
        };
        let band = rows.start.saturating_sub(margin)..(rows.end + margin).min(self.camera.height);
        let mut counts = Vec::new();
        let stats = {
            let outs = pixels::row_outs(
                &mut xyz,
                &mut spectra,
                &mut band_planes,
                &mut obs_values,
                (w, h, if self.keep_spectra { n_wl } else { 0 }, obs.len()),
            );
            let mut outs = outs.into_iter();
            let mut work: Vec<Row> = band
                .map(|y| {
                    let out = rows.contains(&y).then(|| outs.next().expect("a row each"));
                    Row::new(y as usize, out, &layout, self.adaptive)
                })
                .collect();
            work.par_iter_mut().for_each(|row| {
                self.base_pass(row, &layout, direct, stop);
                if row.kept() {
                    if !self.adaptive {
                        row.finish(&layout);
                    }
                    progress(1);
                }
            });
            if self.adaptive {
                self.refine(&mut work, &layout, direct, stop);
                work.par_iter_mut().for_each(|row| row.finish(&layout));
                for row in work.iter().filter(|r| r.kept()) {
                    counts.extend(row.px.iter().map(|p| self.samples + p.extra));
                }
            } else {
                counts = vec![self.samples; w * h];
            }
            work.iter().fold(Stats::default(), |a, r| a + r.stats)
        };
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        let film = self.film_of(
            w,
            h,
            xyz,
            self.keep_spectra.then_some(spectra),
            band_of.is_some(),
            band_planes,
            &obs_values,
        );
        Some((film, stats, counts))
    }

    /// The base pass of one row: `image.samples` samples a pixel at
    /// [`crate::sampling::sample_offset`]'s positions; gives up between pixels once `stop`
    /// is set.
    fn base_pass(&self, row: &mut Row, layout: &Layout, direct: bool, stop: &AtomicBool) {
        let (samples, seed) = (self.samples, self.seed);
        let mut spec = vec![0.0f32; layout.n_wl];
        for x in 0..layout.width {
            if stop.load(std::sync::atomic::Ordering::Relaxed) {
                return;
            }
            let pixel = (row.y * layout.width + x) as u64;
            for i in 0..samples {
                let (ox, oy) = crate::sampling::sample_offset(seed, pixel, i, samples);
                let s = self.camera_sample(x as f64 + ox, row.y as f64 + oy, direct, &mut spec);
                row.add(layout, x, &s, &spec);
            }
        }
    }

    /// One camera sample through image point (`px`, `py`): its light, in
    /// spectral renders its spectrum left in `spec` (unless `direct`, see
    /// [`Integrator::spectrum_xyz`]), and how its trace went.
    #[inline]
    fn camera_sample(&self, px: f64, py: f64, direct: bool, spec: &mut [f32]) -> Sample {
        if let Some(o) = &self.observe {
            return self.jansky_sample(o, px, py, spec);
        }
        let mut probing = Probing::default();
        match &self.spectral {
            None => {
                let (rgb, outcome) = self.radiance_probed(px, py, &mut probing);
                Sample {
                    rgb,
                    xyz: DVec3::ZERO,
                    finite: rgb.is_finite(),
                    outcome,
                    rays: 1,
                    g: (f64::INFINITY, f64::NEG_INFINITY),
                    probing,
                }
            }
            Some(ctx) => {
                let (outcome, g0, g1, xyz) = self.spectrum_xyz(px, py, spec, direct, &mut probing);
                Sample {
                    rgb: Vec3::ZERO,
                    xyz,
                    finite: xyz.is_finite(),
                    outcome,
                    rays: if ctx.per_wavelength {
                        spec.len() as u64
                    } else {
                        1
                    },
                    g: (g0, g1),
                    probing,
                }
            }
        }
    }

    /// The film of a render's planes: the bands' centres named, the
    /// interleaved observables split into one plane each.
    #[allow(clippy::too_many_arguments)]
    fn film_of(
        &self,
        w: usize,
        h: usize,
        xyz: Vec<Vec3>,
        spectra: Option<Vec<f32>>,
        banded: bool,
        band_planes: Vec<Vec<Vec3>>,
        obs_values: &[f32],
    ) -> Film {
        let obs = &self.observables;
        let bands = banded.then(|| {
            let nm = &self
                .spectral
                .as_ref()
                .expect("bands need a spectral render")
                .wavelengths
                .nm;
            crate::film::band_centres(nm)
                .into_iter()
                .zip(band_planes)
                .collect()
        });
        Film {
            width: w as u32,
            height: h as u32,
            xyz,
            nm: self
                .spectral
                .as_ref()
                .map_or(Vec::new(), |c| c.wavelengths.nm.clone()),
            frequencies: self
                .observe
                .as_ref()
                .map_or(Vec::new(), |o| o.frequencies.clone()),
            spectra,
            bands,
            bloomed: None,
            observables: obs
                .iter()
                .enumerate()
                .map(|(k, &o)| {
                    let plane = obs_values.iter().skip(k).step_by(obs.len());
                    (o, plane.copied().collect())
                })
                .collect(),
        }
    }
}

/// Adds a sample's spectrum into its pixel's sum (`acc`, empty when the
/// spectra are not kept) and, for spectral bloom, its XYZ into each
/// wavelength's band (`bands`: each wavelength's band and XYZ weight).
#[inline]
pub(super) fn add_spectrum(
    spec: &[f32],
    acc: &mut [f32],
    bands: Option<(&[usize], &[DVec3])>,
    band_row: &mut [&mut [Vec3]],
    x: usize,
) {
    for (a, v) in acc.iter_mut().zip(spec) {
        *a += v;
    }
    if let Some((band_of, weights)) = bands {
        for (i, (&v, w8)) in spec.iter().zip(weights).enumerate() {
            band_row[band_of[i]][x] += (*w8 * v as f64).as_vec3();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Override, SceneConfig};

    /// The shipped volumetric scene as a spectral render with the shift,
    /// at `spin`.
    fn volumetric(spin: f64) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/volumetric.toml");
        let sets = [
            "image.width=8".to_string(),
            "image.height=8".to_string(),
            "spectral.enabled=true".to_string(),
            format!("black_hole.spin={spin}"),
        ];
        let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        Scene::build(SceneConfig::load(&path, &overrides).unwrap()).unwrap()
    }

    #[test]
    fn the_volumes_light_is_shifted_as_its_gas_moves_in_both_bands() {
        // In the plane of a Schwarzschild hole, the photon crossing the
        // radius (k^r = 0), to a static camera at r_cam (r_s):
        // g = sqrt(1 - r_s / r_cam)^-1 / (u^t - L_z u^ph) for the gas's
        // u (M units, E = 1 for the photon): outside the ISCO (r = 10 M)
        // the circular orbit, u^t = (1 - 3 / r)^-1/2, u^ph = Omega u^t,
        // Omega = r^-3/2; inside it (r = 5 M) the plunge from the ISCO,
        // u^t = E / (1 - 2 / r), u^ph = L / r^2, E = sqrt(8/9), L =
        // sqrt(12) (Cunningham 1975).
        let scene = volumetric(0.0);
        let it = Integrator::new(&scene);
        let cam = scene.camera.position;
        let mut shifts = it.shifts::<SpectralShade<'_>>(cam, 0.0);
        let dir = (DVec3::new(0.3, 0.0, 0.0) - cam).normalize();
        shifts.start_path(cam, dir);
        let lz = 2.0 * shifts.lz_over_e;
        assert!(lz.abs() > 0.1, "{lz}");
        let camera = -0.5 * (1.0 - 1.0 / cam.length()).ln();
        let circular = |r: f64| {
            let ut = 1.0 / (1.0 - 3.0 / r).sqrt();
            ut * (1.0 - r.powf(-1.5) * lz)
        };
        let (e, l) = ((8.0f64 / 9.0).sqrt(), 12.0f64.sqrt());
        let plunge = |r: f64| e / (1.0 - 2.0 / r) - lz * l / (r * r);
        let v = scene.volume.as_ref().unwrap();
        for (r, ratio) in [(10.0, circular(10.0)), (5.0, plunge(5.0))] {
            // r_s: a chord across the radius at (0, r / 2, 0).
            let y = 0.5 * r;
            let seg = Segment::chord(DVec3::new(0.01, y, 0.0), DVec3::new(-0.01, y, 0.0));
            let p = seg.point(0.5);
            let got = shifts.moving(&seg, 0.5, p, &v.motion).unwrap();
            let want = camera - ratio.ln();
            assert!((got - want).abs() < 1e-12, "r {r} M: {got} {want}");
        }
        // An observed scene's medium is the same gas: the ratio its
        // transfer takes at the outer point is the visible band's.
        let gas = crate::transfer::VolumeGas::new(v.clone(), 1.0);
        let q = DVec3::new(0.0, 10.0, 0.0);
        let state = gas.state(Kerr::new(0.0), (10.0, 0.0), q, (lz, 0.0));
        let ratio = state.expect("gas at 5 r_s in the plane").ratio;
        assert!((ratio / circular(10.0) - 1.0).abs() < 1e-12, "{ratio}");
    }
}
