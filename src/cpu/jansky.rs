//! The jansky shade: an observed scene's (`[observe]`) light at each
//! observed frequency, carried to the camera by radiative transfer
//! ([`crate::transfer`]): the medium's along the walk's stretches, and the
//! thin disk's or a blackbody sky's behind it, in janskys per pixel.

use super::pixels::Sample;
use super::shade::Shade;
use super::{Probing, Shifts};
use crate::colormap::DISPLAY_KELVIN;
use crate::cpu::Integrator;
use crate::disk::DiskHit;
use crate::objects::Object;
use crate::physics::Segment;
use crate::physics::kerr::Kerr;
use crate::physics::kerr_closed::KerrRay;
use crate::scene::Scene;
use crate::shapes::Hit;
use crate::sky::{Sky, SkyView};
use crate::spectrum::planck_nu;
use crate::texture::Footprint as TexFootprint;
use crate::transfer::closed::along_kerr_ray;
use crate::transfer::{Observe, RayTransfer, Transport};
use crate::units::cgs::{BOLTZMANN, JANSKY, LIGHT};
use crate::volume::Cloud;
use glam::{DVec3, Vec3};

/// One ray's light at the observed frequencies.
pub(super) struct JanskyShade<'a> {
    /// The camera frequencies (Hz).
    nu: &'a [f64],
    /// The medium and the units it is transferred in, if there is one.
    transport: Option<Transport<'a>>,
    ray: RayTransfer,
}

impl<'a> JanskyShade<'a> {
    /// The shade of a camera ray of an observed scene; its photon's
    /// constants come with the camera's path ([`Shade::camera_path`]).
    fn new(scene: &'a Scene, observe: &'a Observe) -> Self {
        let spin = scene.model.spacetime().map_or(0.0, |st| st.spin());
        JanskyShade {
            nu: &observe.frequencies,
            transport: observe.medium.as_ref().map(|medium| Transport {
                medium,
                kerr: Kerr::new(spin),
                cm_per_m: scene.cm_per_m(),
            }),
            ray: RayTransfer::new(1.0, 0.0, observe.frequencies.len()),
        }
    }
}

impl Shade for JanskyShade<'_> {
    const SHIFT: bool = true;
    const PHYSICAL: bool = true;
    /// The thin disk's blackbody at its temperature there: opaque.
    fn disk(&mut self, scene: &Scene, hit: &DiskHit, _: f32, ln_g: f64) {
        if let Some(thin) = scene.disk.as_ref().and_then(|d| d.thin.as_ref()) {
            let kelvin = thin.temperature(hit.r);
            self.ray
                .surface(ln_g, self.nu, |nu_e| thin.intensity_nu(nu_e, kelvin));
        }
    }
    /// A blackbody sky at infinity (a dark one gives nothing).
    fn sky(&mut self, scene: &Scene, _: DVec3, _: Option<SkyView>, _: f32, ln_g: f64) {
        if let Sky::Blackbody { kelvin, .. } = &scene.sky {
            self.ray
                .surface(ln_g, self.nu, |nu_e| planck_nu(nu_e, *kelvin));
        }
    }
    // Observed scenes hold no objects or clouds (refused as they are
    // built: they have no emission in physical units), and their
    // volumetric disk's gas is their medium, which `gas` transfers.
    fn object(
        &mut self,
        _: &Scene,
        _: &Object,
        _: (&Hit, Option<&TexFootprint>),
        _: DVec3,
        _: f32,
        _: f64,
    ) {
    }
    fn tint(&mut self, _: &Scene, _: Vec3, _: f64) {}
    fn volume(&mut self, _: &Scene, _: f64, _: f32, _: f64) {}
    fn cloud(&mut self, _: &Scene, _: &Cloud, _: f64, _: f32, _: f64) {}
    fn has_gas(&self, _: &Scene) -> bool {
        self.transport.is_some()
    }
    fn gas(
        &mut self,
        _: &Integrator,
        seg: &Segment,
        range: (f64, f64),
        _: (&mut f32, &Shifts),
        (glowed, _): (&mut bool, &mut Probing),
    ) -> bool {
        if let Some(t) = &self.transport {
            self.ray.march(t, seg, range, self.nu);
        }
        // Gas that hides all behind it ends the ray, as in the visible band.
        let spent = self.ray.spent();
        *glowed |= spent;
        spent
    }
    fn kerr_gas(&mut self, _: &Scene, ray: &KerrRay, range: (f64, f64), glowed: &mut bool) -> u32 {
        let Some(t) = &self.transport else {
            return 0;
        };
        let stretches = along_kerr_ray(&mut self.ray, t, ray, range, self.nu);
        *glowed |= self.ray.spent();
        stretches
    }
    /// The camera's measure of a unit-energy photon (its frame's shift of
    /// the sky's light) and the photon's L_z / E, which the medium's
    /// shifts take in M (Schwarzschild's model has it in r_s).
    fn camera_path(&mut self, shifts: &Shifts) {
        self.ray.lz = shifts.in_m(shifts.camera_lz_over_e());
        self.ray.camera_ratio = shifts.sky(0.0).exp();
    }
    fn spent(&self) -> bool {
        self.ray.spent()
    }
}

impl Integrator<'_> {
    /// One camera sample through (`px`, `py`) of an observed scene, walked
    /// as every sample is: the flux density it gives its pixel at each
    /// frequency (Jy) in `out`, its brightness temperature at the first as
    /// the sample's light.
    pub(super) fn jansky_sample(
        &self,
        observe: &Observe,
        px: f64,
        py: f64,
        out: &mut [f32],
    ) -> Sample {
        let mut probing = Probing::default();
        let origin = self.camera.position;
        let ray = self.camera.ray(px, py);
        self.note_footprint(px, py, &mut probing);
        let mut shade = JanskyShade::new(self, observe);
        let outcome = self.trace_sample(origin, ray, &mut shade, &mut probing);
        let intensity = &shade.ray.intensity;
        // The pixel's solid angle as the distant observer sees it: its
        // area at the hole's distance from the camera, seen from Earth.
        let sr = self.camera.pixel_solid_angle(px, py) * self.seen_from_earth;
        for (o, i) in out.iter_mut().zip(intensity) {
            *o = (i * sr / JANSKY) as f32;
        }
        // Rayleigh-Jeans: T_b = I c^2 / (2 k nu^2), in cgs.
        let (c, k) = (LIGHT, BOLTZMANN);
        let nu = observe.frequencies[0];
        let kelvin = intensity[0] * c * c / (2.0 * k * nu * nu);
        let y = (kelvin / DISPLAY_KELVIN) as f32;
        Sample {
            rgb: Vec3::ZERO,
            xyz: DVec3::new(0.950_47, 1.0, 1.088_83) * y as f64,
            finite: intensity.iter().all(|i| i.is_finite()),
            outcome,
            rays: 1,
            g: (f64::INFINITY, f64::NEG_INFINITY),
            probing,
        }
    }
}
