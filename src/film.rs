//! The film both backends fill: CIE XYZ per pixel (and spectra or bloom
//! bands when kept), and the counts gathered while rendering.

use crate::physics::End;
use glam::Vec3;

/// The rendered image: CIE XYZ per pixel (Y = 1 is the display white before
/// exposure), row 0 at the top, and optionally each pixel's spectrum.
#[derive(Clone, Debug)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major XYZ.
    pub xyz: Vec<Vec3>,
    /// Wavelengths (nm) of `spectra`.
    pub nm: Vec<f64>,
    /// Row-major spectra, `nm.len()` values per pixel, when kept.
    pub spectra: Option<Vec<f32>>,
    /// For spectral bloom: (centre wavelength in nm, the XYZ of that band
    /// of wavelengths per pixel).
    pub bands: Option<Vec<(f64, Vec<Vec3>)>>,
    /// The image bloomed as the scene's `[bloom]` asks, where the device
    /// that rendered it bloomed it (the GPU, which then reads back this
    /// instead of the bands); None: bloom is applied on the host.
    pub bloomed: Option<Vec<Vec3>>,
}

impl Film {
    /// Linear sRGB of every pixel.
    pub fn linear_srgb(&self) -> Vec<Vec3> {
        self.xyz
            .iter()
            .map(|c| crate::spectrum::color::xyz_to_linear_srgb(c.as_dvec3()).as_vec3())
            .collect()
    }
}

/// Counts gathered while rendering. Every camera sample falls in exactly
/// one class: `disk`, `objects`, `sky`, `captured`, `abandoned` or
/// `non_finite` (see [`Outcome::class`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Camera samples (pixels times samples per pixel).
    pub samples: u64,
    /// Rays traced: one per sample, or one per wavelength with
    /// `spectral.per_wavelength`.
    pub rays: u64,
    /// Accepted integration steps over all rays.
    pub steps: u64,
    /// Samples whose light includes the disk's: an opaque or blended
    /// crossing of its material, or the volumetric disk's gas.
    pub disk: u64,
    /// Samples that met an object (and no disk).
    pub objects: u64,
    /// Samples that reached the sky and met nothing else.
    pub sky: u64,
    /// Samples that fell into the hole and met nothing else.
    pub captured: u64,
    /// Samples whose ray ran out of steps (black where it stopped).
    pub abandoned: u64,
    /// Samples whose light was not a finite number: left out of their
    /// pixel's average.
    pub non_finite: u64,
    /// Camera samples traced in closed form (the rest were integrated).
    pub closed: u64,
    /// Smallest frequency ratio g of light from the disk (spectral renders).
    pub g_min: f64,
    /// Largest frequency ratio g of light from the disk.
    pub g_max: f64,
}

impl Default for Stats {
    fn default() -> Self {
        Stats {
            samples: 0,
            rays: 0,
            steps: 0,
            disk: 0,
            objects: 0,
            sky: 0,
            captured: 0,
            abandoned: 0,
            non_finite: 0,
            closed: 0,
            g_min: f64::INFINITY,
            g_max: f64::NEG_INFINITY,
        }
    }
}

impl std::ops::Add for Stats {
    type Output = Stats;
    fn add(self, o: Stats) -> Stats {
        Stats {
            samples: self.samples + o.samples,
            rays: self.rays + o.rays,
            steps: self.steps + o.steps,
            disk: self.disk + o.disk,
            objects: self.objects + o.objects,
            sky: self.sky + o.sky,
            captured: self.captured + o.captured,
            abandoned: self.abandoned + o.abandoned,
            non_finite: self.non_finite + o.non_finite,
            closed: self.closed + o.closed,
            g_min: self.g_min.min(o.g_min),
            g_max: self.g_max.max(o.g_max),
        }
    }
}

impl Stats {
    /// Counts one sample of `rays` traced rays (`finite`: its light was a
    /// finite number).
    pub fn count(&mut self, outcome: &Outcome, rays: u64, finite: bool) {
        self.samples += 1;
        self.closed += outcome.closed as u64;
        self.rays += rays;
        self.steps += outcome.steps as u64;
        let class = if finite {
            outcome.class()
        } else {
            SampleClass::NonFinite
        };
        *match class {
            SampleClass::Disk => &mut self.disk,
            SampleClass::Objects => &mut self.objects,
            SampleClass::Sky => &mut self.sky,
            SampleClass::Captured => &mut self.captured,
            SampleClass::Abandoned => &mut self.abandoned,
            SampleClass::NonFinite => &mut self.non_finite,
        } += 1;
    }
}

/// Where a camera sample's light came from, for the counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleClass {
    /// Disk material or gas contributed.
    Disk,
    /// An object was met (no disk).
    Objects,
    /// Only the sky.
    Sky,
    /// Only the hole.
    Captured,
    /// The ray ran out of steps.
    Abandoned,
    /// The light was not finite.
    NonFinite,
}

/// How one camera sample's trace went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// How the (last) ray ended.
    pub end: End,
    /// Integration steps over all its rays and reflections.
    pub steps: u32,
    /// It met the disk's material (opaque or blended) or glowing gas.
    pub disk: bool,
    /// It met an object (mirrors included).
    pub object: bool,
    /// Traced in closed form rather than integrated.
    pub closed: bool,
}

impl Outcome {
    /// The sample's class: running out of steps first, then the disk,
    /// then objects, then how the ray ended.
    pub fn class(&self) -> SampleClass {
        match self.end {
            End::Abandoned => SampleClass::Abandoned,
            _ if self.disk => SampleClass::Disk,
            _ if self.object => SampleClass::Objects,
            End::Captured => SampleClass::Captured,
            // A stop always comes from the disk, gas or an object.
            End::Escaped(_) | End::Stopped => SampleClass::Sky,
        }
    }
}

/// Wavelength bands of spectral bloom.
pub const BANDS: usize = 9;

/// The band of wavelength index `i` of `n`.
#[inline]
pub fn band_of(i: usize, n: usize) -> usize {
    i * BANDS / n
}

/// The mean wavelength (nm) of each bloom band's members.
pub fn band_centres(nm: &[f64]) -> Vec<f64> {
    let n = nm.len();
    (0..BANDS)
        .map(|b| {
            let members: Vec<f64> = (0..n)
                .filter(|&i| band_of(i, n) == b)
                .map(|i| nm[i])
                .collect();
            members.iter().sum::<f64>() / members.len().max(1) as f64
        })
        .collect()
}
