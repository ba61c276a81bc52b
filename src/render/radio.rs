//! Camera samples of an observed scene (`[observe]`): the medium's light,
//! and the thin disk's or a blackbody sky's behind it, carried to the
//! camera by radiative transfer ([`crate::transfer`]) at each observed
//! frequency, in janskys per pixel.

use super::pixels::Sample;
use super::{Probing, Scene};
use crate::film::Outcome;
use crate::physics::closed::HORIZON_MARGIN;
use crate::physics::kerr::Kerr;
use crate::physics::kerr_closed::KerrRay;
use crate::physics::spacetime::Closed;
use crate::physics::{End, Flow, Observer, Segment, Spacetime, Trace};
use crate::thin_disk::ThinDisk;
use crate::transfer::closed::along_kerr_ray;
use crate::transfer::{JANSKY, Observe, RayTransfer, Transport};
use glam::{DVec3, Vec3};

use crate::colormap::DISPLAY_KELVIN;

impl Scene {
    /// Centimetres per M (G M / c^2) of the scene's hole.
    pub fn cm_per_m(&self) -> f64 {
        0.5 * self.r_s * 100.0
    }

    /// The camera's distance from the hole (cm; Boyer-Lindquist's radius
    /// with spin).
    pub fn camera_distance_cm(&self) -> f64 {
        let x = self.camera.position;
        let r = self.model.spacetime().map_or(x.length(), |st| st.radius(x));
        r * self.r_s * 100.0
    }

    /// The thin disk's material where a ray crosses its plane at `p`
    /// (r_s), and its temperature there.
    fn thin_disk_at(&self, p: DVec3) -> Option<(&ThinDisk, f64)> {
        let d = self.disk.as_ref()?;
        let thin = d.thin.as_ref()?;
        let plane = self
            .rotation
            .unturn_plane(d.spacetime.disk_plane(p), self.time);
        let h = d.hit(plane).filter(|h| h.alpha > 0.0)?;
        Some((thin, thin.temperature(h.r)))
    }

    /// A Kerr ray `k` in closed form through an axisymmetric medium (or
    /// none): the gas up to the thin disk's first crossing with material
    /// (then its light, by `shine`), or to the ray's end (1.00001 r_+ for
    /// a captured ray).
    fn kerr_transfer(
        &self,
        k: &KerrRay,
        ray: &mut RayTransfer,
        transport: Option<&Transport>,
        nu: &[f64],
        shine: impl Fn(&mut RayTransfer, DVec3, (&ThinDisk, f64)),
    ) -> Trace {
        let hit = k.crossings().find_map(|c| {
            let p = k.crossing_point(&c) * 0.5;
            Some((c.s, p, self.thin_disk_at(p)?))
        });
        let s_stop = match hit {
            Some((s, ..)) => s,
            None if k.captured => k.mino_at_fall(k.horizon() * (1.0 + HORIZON_MARGIN)),
            None => k.mino_to_end(),
        };
        let steps = transport.map_or(0, |t| along_kerr_ray(ray, t, k, s_stop, nu));
        let end = if let Some((_, p, at)) = hit {
            shine(ray, p, at);
            End::Stopped
        } else if ray.spent() {
            End::Stopped
        } else if k.captured {
            End::Captured
        } else {
            End::Escaped(k.escape_direction())
        };
        Trace {
            end,
            steps,
            ln_shift: 0.0,
        }
    }

    /// One camera sample through (`px`, `py`) of an observed scene: the
    /// flux density it gives its pixel at each frequency (Jy) in `out`,
    /// its brightness temperature at the first as the sample's light.
    pub(super) fn radio_sample(
        &self,
        observe: &Observe,
        px: f64,
        py: f64,
        out: &mut [f32],
    ) -> Sample {
        let origin = self.camera.position;
        let (dir, ln_camera) = self.camera.ray(px, py);
        let st = self
            .model
            .spacetime()
            .expect("observed scenes are built with a spacetime");
        let native = st.photon_lz_over_e(origin, dir);
        // Schwarzschild's L_z / E is in r_s, Kerr's in M.
        let lz = match st {
            Spacetime::Schwarzschild => 2.0 * native,
            Spacetime::Kerr { .. } => native,
        };
        let observer = Observer {
            at: origin,
            frame: self.camera.rest_frame,
            lz_over_e: native,
        };
        let ln_sky = st.static_ln_shift(None, observer) + ln_camera;
        let nu = &observe.frequencies;
        let mut ray = RayTransfer::new(ln_sky.exp(), lz, nu.len());
        let transport = observe.medium.as_ref().map(|medium| Transport {
            medium,
            kerr: Kerr::new(st.spin()),
            cm_per_m: self.cm_per_m(),
        });
        // The disk's light where the ray meets it, through the gas in
        // front of it.
        let shine = |ray: &mut RayTransfer, p: DVec3, (thin, kelvin): (&ThinDisk, f64)| {
            let ln_g = st.disk_ln_shift(p, native, observer, true) + ln_camera;
            ray.surface(ln_g, nu, |nu_e| thin.intensity_nu(nu_e, kelvin));
        };
        let visit = |seg: &Segment| {
            // The disk, where the segment meets it, ends the ray there: the
            // gas in front of it, then its light through that gas.
            let hit = seg.crossing_z0().and_then(|s| {
                let p = seg.point(s);
                Some((s, p, self.thin_disk_at(p)?))
            });
            if let Some(t) = &transport {
                ray.march(t, seg, (0.0, hit.map_or(1.0, |h| h.0)), nu);
            }
            if let Some((_, p, at)) = hit {
                shine(&mut ray, p, at);
                return Flow::Stop;
            }
            if ray.spent() {
                Flow::Stop
            } else {
                Flow::Continue
            }
        };
        // Rays in closed form where the scene allows it (Schwarzschild's
        // segments from the exact orbit; Kerr's points at any Mino time,
        // through an axisymmetric medium), else integrated.
        let closed = match self.closed_form {
            true => st.closed_ray(&self.camera.closed_start(st, origin), dir, false),
            false => None,
        };
        let (trace, closed) = match closed {
            Some(Closed::Schwarzschild(c)) => {
                let (end, steps) = c.segments(self.limits.outer, visit);
                (
                    Trace {
                        end,
                        steps,
                        ln_shift: 0.0,
                    },
                    true,
                )
            }
            Some(Closed::Kerr(k)) if observe.medium.as_ref().is_none_or(|m| m.axisymmetric()) => {
                let trace = self.kerr_transfer(&k, &mut ray, transport.as_ref(), nu, shine);
                (trace, true)
            }
            _ => (self.model.trace(origin, dir, &self.limits, visit), false),
        };
        // A blackbody sky (at infinity, where the photon's frequency is
        // nu_cam / camera_ratio) behind whatever the ray crossed.
        if let (End::Escaped(_), crate::sky::Sky::Blackbody { kelvin, .. }) = (trace.end, &self.sky)
        {
            let ln_g = ray.camera_ratio.ln();
            ray.surface(ln_g, nu, |nu_e| crate::transfer::planck(nu_e, *kelvin));
        }
        // The pixel's solid angle as the distant observer sees it: its
        // area at the hole's distance from the camera, seen from Earth.
        let r_cam = self.camera_distance_cm();
        let sr = self.camera.pixel_solid_angle(px, py) * (r_cam / observe.distance_cm).powi(2);
        for (o, i) in out.iter_mut().zip(&ray.intensity) {
            *o = (i * sr / JANSKY) as f32;
        }
        // Rayleigh-Jeans: T_b = I c^2 / (2 k nu^2), in cgs.
        let (c, k) = (crate::units::C * 1e2, crate::units::BOLTZMANN * 1e7);
        let kelvin = ray.intensity[0] * c * c / (2.0 * k * nu[0] * nu[0]);
        let y = (kelvin / DISPLAY_KELVIN) as f32;
        let finite = ray.intensity.iter().all(|i| i.is_finite());
        Sample {
            rgb: Vec3::ZERO,
            xyz: DVec3::new(0.950_47, 1.0, 1.088_83) * y as f64,
            finite,
            outcome: Outcome {
                end: trace.end,
                steps: trace.steps,
                // Stopped at the thin disk, or where the gas hides all
                // behind it (as gas that stops a visible-band ray).
                disk: trace.end == End::Stopped,
                object: false,
                closed,
            },
            rays: 1,
            g: (f64::INFINITY, f64::NEG_INFINITY),
            probing: Probing::default(),
        }
    }
}
