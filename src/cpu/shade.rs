//! The shades: what a sample's light is made of as the walk meets its
//! sources. Each band (RGB, spectral, janskys) implements the same hooks;
//! [`Integrator::trace_sample`] tells them what the ray meets, in order.

use super::{Integrator, Probing, Shifts};
use crate::disk::DiskHit;
use crate::objects::{self, Object};
use crate::physics::Segment;
use crate::physics::kerr_closed::KerrRay;
use crate::scene::Scene;
use crate::shapes::Hit;
use crate::sky::SkyView;
use crate::spectral::SpectralContext;
use crate::spectrum::uplift::uplift;
use crate::texture::Footprint as TexFootprint;
use crate::transfer::Piece;
use crate::volume::Cloud;
use glam::{DVec3, Vec3};

/// Where a sample's light comes from, told to a shader as the walk finds
/// it: `k` weights premultiplied emission (transmittance, and for cutout
/// disks 1 / alpha), `ln_g` is ln(nu_obs / nu_emit).
pub(super) trait Shade: Sized {
    /// Whether the frequency shift is needed at all.
    const SHIFT: bool;
    /// The shade is in physical units (an observed scene's): its light is
    /// always shifted, the disk's orbital Doppler shift in.
    const PHYSICAL: bool = false;
    fn disk(&mut self, scene: &Scene, hit: &DiskHit, k: f32, ln_g: f64);
    /// Sky light along `dir`, over the sample's footprint where known.
    fn sky(&mut self, scene: &Scene, dir: DVec3, fp: Option<SkyView>, k: f32, ln_g: f64);
    /// An object's surface at `hit`, with the sample's footprint there in
    /// texture coordinates where known.
    fn object(
        &mut self,
        scene: &Scene,
        obj: &Object,
        hit: (&Hit, Option<&TexFootprint>),
        towards_viewer: DVec3,
        k: f32,
        ln_g: f64,
    );
    /// A mirror of this colour (met with frequency ratio `g`) filters all
    /// light found after it.
    fn tint(&mut self, scene: &Scene, rgb: Vec3, g: f64);
    /// Emission of the volumetric disk's gas at `kelvin`, weighted `k`
    /// (luminance relative to the peak temperature's source function).
    fn volume(&mut self, scene: &Scene, kelvin: f64, k: f32, ln_g: f64);
    /// A sample of a cloud of optical depth `kappa_dl` at 550 nm: adds its
    /// glow and filters all light behind it.
    fn cloud(&mut self, scene: &Scene, cloud: &Cloud, kappa_dl: f64, through: f32, ln_g: f64);
    /// Whether the scene holds gas that this shade sees: the visible
    /// band's volumetric disk and clouds.
    fn has_gas(&self, scene: &Scene) -> bool {
        scene.volume.is_some() || !scene.clouds.is_empty()
    }
    /// The gas along fraction `range` of `seg`, in front of whatever the
    /// walk meets next, its light seen through `through` (which it then
    /// reduces); `glowed` is set where it shone. Returns whether the ray
    /// is spent. The visible band's gas is marched in samples of each
    /// medium ([`Integrator::march`]).
    fn gas(
        &mut self,
        it: &Integrator,
        seg: &Segment,
        range: (f64, f64),
        (through, shifts): (&mut f32, &Shifts),
        state: (&mut bool, &mut Probing),
    ) -> bool {
        it.march(seg, range, self, through, shifts, state)
    }
    /// The gas along a Kerr ray in closed form between Mino times
    /// `range`, `glowed` set as by [`Shade::gas`]; gives the stretches
    /// walked. Only physical media ride closed-form rays (a scene with
    /// visible gas is integrated: [`Scene::closed_form`]), so the visible
    /// shades meet none here.
    fn kerr_gas(&mut self, _: &Scene, _: &KerrRay, _: (f64, f64), _: &mut bool) -> u32 {
        0
    }
    /// The camera's path starts: its photon's constants are in `shifts`.
    fn camera_path(&mut self, _shifts: &Shifts) {}
    /// No light from farther along can reach the camera any more (an
    /// opaque surface or gas met).
    fn spent(&self) -> bool {
        false
    }
}

/// Effective wavelengths (nm) of the sRGB channels, for wavelength-dependent
/// extinction in RGB renders.
pub(super) const RGB_NM: [f64; 3] = [610.0, 550.0, 465.0];

/// Linear sRGB shading.
pub(super) struct RgbShade {
    pub(super) color: Vec3,
    pub(super) filter: Vec3,
}

impl RgbShade {
    pub(super) fn new() -> RgbShade {
        RgbShade {
            color: Vec3::ZERO,
            filter: Vec3::ONE,
        }
    }
}

impl Shade for RgbShade {
    const SHIFT: bool = false;
    #[inline]
    fn disk(&mut self, scene: &Scene, hit: &DiskHit, k: f32, _: f64) {
        if let Some(d) = &scene.disk {
            self.color += d.rgb(hit) * self.filter * k;
        }
    }
    #[inline]
    fn sky(&mut self, scene: &Scene, dir: DVec3, fp: Option<SkyView>, k: f32, _: f64) {
        self.color += scene.sky.radiance(dir, fp) * self.filter * k;
    }
    fn object(
        &mut self,
        scene: &Scene,
        obj: &Object,
        hit: (&Hit, Option<&TexFootprint>),
        towards_viewer: DVec3,
        k: f32,
        _: f64,
    ) {
        self.color += objects::shade_rgb(obj, hit, towards_viewer, &scene.lighting, &scene.objects)
            * self.filter
            * k;
    }
    fn tint(&mut self, _: &Scene, rgb: Vec3, _: f64) {
        self.filter *= rgb;
    }
    fn volume(&mut self, scene: &Scene, kelvin: f64, k: f32, _: f64) {
        if let Some(v) = &scene.volume {
            self.color += v.rgb(kelvin) * self.filter * k;
        }
    }
    fn cloud(&mut self, _: &Scene, cloud: &Cloud, kappa_dl: f64, through: f32, _: f64) {
        // Each channel at an effective wavelength, its glow the source
        // function.
        let pieces = RGB_NM.map(|l| Piece::new(kappa_dl * cloud.extinction(l)));
        let glow = Vec3::from(std::array::from_fn(|k| {
            pieces[k].source(cloud.glow[k] as f64) as f32
        }));
        self.color += glow * self.filter * through;
        self.filter *= Vec3::from(pieces.map(|p| p.kept as f32));
    }
}

/// Spectral shading of the camera wavelengths in `range`.
pub(super) struct SpectralShade<'a> {
    pub(super) out: &'a mut [f32],
    pub(super) range: std::ops::Range<usize>,
    pub(super) g_min: f64,
    pub(super) g_max: f64,
    /// Per-wavelength transmittance of the mirrors and clouds met so far;
    /// empty while it is 1 everywhere.
    pub(super) filter: Vec<f32>,
    /// Scratch for light that has to pass the filter.
    pub(super) scratch: Vec<f32>,
    /// Light whose XYZ is known without the spectrum (blackbody skies)
    /// goes to `xyz` instead of `out`: for renders that keep no spectra
    /// and take all wavelengths on one ray.
    pub(super) direct: bool,
    pub(super) xyz: DVec3,
    /// Something was written to `out`.
    pub(super) touched: bool,
}

impl SpectralShade<'_> {
    /// Runs `add` into `out`, through the tints if there are any.
    fn filtered(&mut self, add: impl FnOnce(&mut [f32])) {
        self.touched = true;
        if self.filter.is_empty() {
            add(self.out);
            return;
        }
        self.scratch.clear();
        self.scratch.resize(self.out.len(), 0.0);
        add(&mut self.scratch);
        for i in self.range.clone() {
            self.out[i] += self.scratch[i] * self.filter[i];
        }
    }

    /// Multiplies the filter by `f(camera wavelength)`.
    fn attenuate(&mut self, ctx: &SpectralContext, f: impl Fn(f64) -> f64) {
        if self.filter.is_empty() {
            self.filter = vec![1.0; self.out.len()];
        }
        for i in self.range.clone() {
            self.filter[i] *= f(ctx.wavelengths.nm[i]) as f32;
        }
    }
}

impl Shade for SpectralShade<'_> {
    const SHIFT: bool = true;
    #[inline]
    fn disk(&mut self, scene: &Scene, hit: &DiskHit, k: f32, ln_g: f64) {
        let (Some(d), Some(ctx)) = (&scene.disk, &scene.spectral) else {
            return;
        };
        let g = ln_g.exp();
        self.g_min = self.g_min.min(g);
        self.g_max = self.g_max.max(g);
        let range = self.range.clone();
        self.filtered(|out| d.add_spectrum(hit, g, ctx, k, range, out));
    }
    #[inline]
    fn sky(&mut self, scene: &Scene, dir: DVec3, fp: Option<SkyView>, k: f32, ln_g: f64) {
        if let Some(ctx) = &scene.spectral {
            if self.direct
                && self.filter.is_empty()
                && let Some(xyz) = scene.sky.xyz(dir, fp, ln_g, ctx, k)
            {
                self.xyz += xyz;
                return;
            }
            let g = ln_g.exp();
            let range = self.range.clone();
            self.filtered(|out| scene.sky.add_spectrum(dir, fp, g, ctx, k, range, out));
        }
    }
    fn object(
        &mut self,
        scene: &Scene,
        obj: &Object,
        hit: (&Hit, Option<&TexFootprint>),
        towards_viewer: DVec3,
        k: f32,
        ln_g: f64,
    ) {
        if let Some(ctx) = &scene.spectral {
            let range = self.range.clone();
            let g = ln_g.exp();
            self.filtered(|out| {
                objects::add_spectrum(
                    obj,
                    hit,
                    towards_viewer,
                    &scene.lighting,
                    &scene.objects,
                    g,
                    ctx,
                    k,
                    range,
                    out,
                )
            });
        }
    }
    fn tint(&mut self, scene: &Scene, rgb: Vec3, g: f64) {
        if let Some(ctx) = &scene.spectral {
            // The mirror reflects the light it receives, at g times the
            // camera wavelength.
            let spec = uplift(rgb);
            self.attenuate(ctx, |l| spec.reflectance(g * l));
        }
    }
    fn volume(&mut self, scene: &Scene, kelvin: f64, k: f32, ln_g: f64) {
        if let Some(ctx) = &scene.spectral {
            let range = self.range.clone();
            let g = ln_g.exp();
            self.g_min = self.g_min.min(g);
            self.g_max = self.g_max.max(g);
            self.filtered(|out| ctx.planck.add(kelvin, g, ctx.beaming, k, range, out));
        }
    }
    fn cloud(&mut self, scene: &Scene, cloud: &Cloud, kappa_dl: f64, through: f32, ln_g: f64) {
        let Some(ctx) = &scene.spectral else {
            return;
        };
        let glow = cloud
            .glow_spectrum
            .as_ref()
            .expect("spectral scenes build their clouds for the wavelengths");
        let g = ln_g.exp();
        // The glow is light emitted in the cloud: beamed like all emission.
        let through = through * ctx.radiance_factor(g);
        // (g lambda / 550)^-beta = g^-beta (lambda / 550)^-beta.
        let g_beta = if cloud.beta == 0.0 {
            1.0
        } else {
            g.powf(-cloud.beta)
        };
        let range = self.range.clone();
        if self.filter.is_empty() {
            self.filter = vec![1.0; self.out.len()];
        }
        self.touched = true;
        for i in range {
            let l = ctx.wavelengths.nm[i];
            let piece = Piece::new(kappa_dl * g_beta * cloud.extinction_table[i]);
            // Glow in (the source function at the gas's wavelength), then
            // the cloud's absorption for all behind it.
            self.out[i] += self.filter[i] * through * piece.source(glow.emission(g * l)) as f32;
            self.filter[i] *= piece.kept as f32;
        }
    }
}
