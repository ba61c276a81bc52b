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
    /// An observed scene's frequencies (Hz): then `spectra` holds each
    /// pixel's flux density (Jy) at each, and `nm` is empty.
    pub frequencies: Vec<f64>,
    /// For spectral bloom: (centre wavelength in nm, the XYZ of that band
    /// of wavelengths per pixel).
    pub bands: Option<Vec<(f64, Vec<Vec3>)>>,
    /// The image bloomed as the scene's `[bloom]` asks, where the device
    /// that rendered it bloomed it (the GPU, which then reads back this
    /// instead of the bands); None: bloom is applied on the host.
    pub bloomed: Option<Vec<Vec3>>,
    /// The per-pixel maps the scene asks for (`image.observables`), in its
    /// order, each row-major.
    pub observables: Vec<(Observable, Vec<f32>)>,
}

impl Film {
    /// An observed scene's total flux density (Jy) at each frequency: the
    /// sum over its pixels (empty for other films).
    pub fn total_flux(&self) -> Vec<f64> {
        let n = self.frequencies.len();
        match &self.spectra {
            Some(s) if n > 0 => (0..n)
                .map(|k| s.iter().skip(k).step_by(n).map(|&v| v as f64).sum())
                .collect(),
            _ => Vec::new(),
        }
    }

    /// An observed scene's ring at its first frequency (pixels; see
    /// [`crate::ring`]), None for others or where there is none.
    pub fn ring(&self) -> Option<crate::ring::Ring> {
        let n = self.frequencies.len();
        let s = self.spectra.as_ref().filter(|_| n > 0)?;
        let first: Vec<f32> = s.iter().step_by(n).copied().collect();
        crate::ring::find(&first, self.width as usize, self.height as usize)
    }

    /// The names of the EXR channels of `spectra`'s values: a spectral
    /// render's wavelengths, or an observed scene's frequencies.
    pub fn channel_names(&self) -> Vec<String> {
        channel_names(&self.nm, &self.frequencies)
    }

    /// Linear sRGB of every pixel.
    pub fn linear_srgb(&self) -> Vec<Vec3> {
        self.xyz
            .iter()
            .map(|c| crate::spectrum::color::xyz_to_linear_srgb(c.as_dvec3()).as_vec3())
            .collect()
    }
}

/// The EXR channel names of a film's `spectra` at wavelengths `nm` or,
/// for an observed scene, frequencies `hz`.
pub fn channel_names(nm: &[f64], hz: &[f64]) -> Vec<String> {
    if hz.is_empty() {
        nm.iter().map(|&l| spectral_channel_name(l)).collect()
    } else {
        hz.iter().map(|&f| flux_channel_name(f)).collect()
    }
}

/// Counts gathered while rendering. Every camera sample falls in exactly
/// one class: `disk`, `objects`, `sky`, `captured`, `abandoned` or
/// `non_finite` (see [`Outcome::class`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// Camera samples (pixels times samples per pixel, plus adaptive
    /// sampling's extra ones).
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
    /// Pixels adaptive sampling refined (gave extra samples).
    pub refined: u64,
    /// Adaptive sampling's extra samples (counted in `samples` too).
    pub extra: u64,
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
            refined: 0,
            extra: 0,
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
            refined: self.refined + o.refined,
            extra: self.extra + o.extra,
        }
    }
}

impl Stats {
    /// Counts one sample of `rays` traced rays (`finite`: its light was a
    /// finite number); returns its class.
    pub fn count(&mut self, outcome: &Outcome, rays: u64, finite: bool) -> SampleClass {
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
        class
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

impl SampleClass {
    /// The class's code in the `class` observable.
    pub fn code(self) -> u8 {
        match self {
            SampleClass::Sky => 0,
            SampleClass::Disk => 1,
            SampleClass::Objects => 2,
            SampleClass::Captured => 3,
            SampleClass::Abandoned => 4,
            SampleClass::NonFinite => 5,
        }
    }
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

/// A per-pixel map a scene can ask for besides its light
/// (`image.observables`), written to the EXR as channel `obs.NAME`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Observable {
    /// The frequency ratio g = nu_observed / nu_emitted of the light the
    /// pixel's samples met first (disk, object or sky).
    G,
    /// The ring radius (r_s; Boyer-Lindquist r with spin) where the light
    /// left the disk.
    Radius,
    /// The image order of the disk light: how many times the ray crossed
    /// the equatorial plane before it met the disk (0: the direct image).
    Order,
    /// The coordinate time (r_s/c) the light took from the disk or object
    /// it left to the camera.
    Time,
    /// How the samples ended ([`SampleClass::code`]): sky 0, disk 1,
    /// object 2, captured 3, out of steps 4, not finite 5.
    Class,
    /// The signed lensing magnification of the first light met: for the
    /// sky the pixel's solid angle over its footprint's on the celestial
    /// sphere, for the disk the ratio of the solid angle to the one its
    /// footprint on the disk would subtend seen straight; negative for an
    /// image of odd parity.
    Magnification,
    /// The x, y and z of the ray's unit direction at infinity (scene
    /// axes; NaN where it does not escape): the `sky` observable's three
    /// channels.
    SkyX,
    SkyY,
    SkyZ,
}

impl Observable {
    /// Every observable, in the order of the docs.
    pub const ALL: [Observable; 9] = [
        Observable::G,
        Observable::Radius,
        Observable::Order,
        Observable::Time,
        Observable::Class,
        Observable::Magnification,
        Observable::SkyX,
        Observable::SkyY,
        Observable::SkyZ,
    ];

    /// The names a config asks for: each channel's, but `sky` for its
    /// three.
    pub const CONFIG_NAMES: [&'static str; 7] = [
        "g",
        "radius",
        "order",
        "time",
        "class",
        "magnification",
        "sky",
    ];

    /// The channels of a config's name ([`Observable::CONFIG_NAMES`]).
    pub fn of_config_name(name: &str) -> Option<Vec<Observable>> {
        match name {
            "sky" => Some(vec![Observable::SkyX, Observable::SkyY, Observable::SkyZ]),
            "sky.x" | "sky.y" | "sky.z" => None,
            _ => Observable::from_name(name).map(|o| vec![o]),
        }
    }

    /// The name a config gives it by (the three sky channels share one).
    pub fn config_name(self) -> &'static str {
        match self {
            Observable::SkyX | Observable::SkyY | Observable::SkyZ => "sky",
            o => o.name(),
        }
    }

    /// Whether it needs each sample's footprint (not only its ray).
    pub fn needs_footprint(self) -> bool {
        self == Observable::Magnification
    }

    /// Its name in configs, EXR channels (`obs.NAME`) and Python.
    pub fn name(self) -> &'static str {
        match self {
            Observable::G => "g",
            Observable::Radius => "radius",
            Observable::Order => "order",
            Observable::Time => "time",
            Observable::Class => "class",
            Observable::Magnification => "magnification",
            Observable::SkyX => "sky.x",
            Observable::SkyY => "sky.y",
            Observable::SkyZ => "sky.z",
        }
    }

    /// The observable of that name.
    pub fn from_name(name: &str) -> Option<Observable> {
        Observable::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Its EXR channel.
    pub fn channel(self) -> String {
        format!("obs.{}", self.name())
    }
}

/// `image.observables` from a config: each name's channels in order
/// ([`Observable::of_config_name`]).
pub fn deserialize_observables<'de, D>(d: D) -> Result<Vec<Observable>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let names = <Vec<String> as serde::Deserialize>::deserialize(d)?;
    let mut out = Vec::new();
    for name in names {
        let Some(channels) = Observable::of_config_name(&name) else {
            return Err(serde::de::Error::custom(format!(
                "unknown observable {name:?}, expected one of {}",
                Observable::CONFIG_NAMES.join(", ")
            )));
        };
        out.extend(channels);
    }
    Ok(out)
}

/// What one camera sample tells the observables: each NaN where the
/// sample has none (g where it met no light: captured; radius and order
/// where it met no disk; time where it met neither disk nor object;
/// magnification where its footprint is not known; sky where it did not
/// escape).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// Frequency ratio of the first light met.
    pub g: f64,
    /// Ring radius (r_s) of the first disk light.
    pub radius: f64,
    /// Equatorial crossings before the first disk light.
    pub order: f64,
    /// Light travel time (r_s/c) from the first disk or object light.
    pub time: f64,
    /// Signed lensing magnification of the first light met.
    pub magnification: f64,
    /// The ray's unit direction at infinity.
    pub sky: [f64; 3],
}

impl Default for Probe {
    fn default() -> Self {
        Probe {
            g: f64::NAN,
            radius: f64::NAN,
            order: f64::NAN,
            time: f64::NAN,
            magnification: f64::NAN,
            sky: [f64::NAN; 3],
        }
    }
}

/// The averaged quantities of a [`Probe`], in [`PixelProbe::sums`]'
/// order: g, radius, time, magnification, sky x, y, z.
pub const AVERAGED: usize = 7;

/// One pixel's observables gathered over its samples: g, radius, time,
/// magnification and the sky direction averaged over the samples that
/// have one (the direction then made unit again), order the least (the
/// lowest image order seen in the pixel), class the most frequent (ties
/// to the lower code). NaN where no sample has a value. Both backends
/// reduce their samples with it (the GPU's passes [`PixelProbe::merge`]d).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelProbe {
    /// The averaged quantities' sums over the samples that have one.
    pub sums: [f64; AVERAGED],
    /// How many samples had each.
    pub counts: [u32; AVERAGED],
    /// The least image order seen.
    pub order: Option<f64>,
    /// Samples per class, by [`SampleClass::code`].
    pub classes: [u32; 6],
}

impl PixelProbe {
    /// Adds one sample.
    pub fn add(&mut self, p: &Probe, class: SampleClass) {
        let [sx, sy, sz] = p.sky;
        let values = [p.g, p.radius, p.time, p.magnification, sx, sy, sz];
        for (i, v) in values.into_iter().enumerate() {
            if v.is_finite() {
                self.sums[i] += v;
                self.counts[i] += 1;
            }
        }
        if p.order.is_finite() {
            self.order = Some(self.order.map_or(p.order, |o| o.min(p.order)));
        }
        self.classes[class.code() as usize] += 1;
    }

    /// Adds another set of the pixel's samples.
    pub fn merge(&mut self, o: &PixelProbe) {
        for i in 0..AVERAGED {
            self.sums[i] += o.sums[i];
            self.counts[i] += o.counts[i];
        }
        self.order = match (self.order, o.order) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        for (a, b) in self.classes.iter_mut().zip(o.classes) {
            *a += b;
        }
    }

    /// The pixel's value of `o`.
    pub fn value(&self, o: Observable) -> f32 {
        let mean = |i: usize| {
            if self.counts[i] == 0 {
                f64::NAN
            } else {
                self.sums[i] / self.counts[i] as f64
            }
        };
        // The mean of unit directions, made unit again.
        let sky = |i: usize| {
            let d = [mean(4), mean(5), mean(6)];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            (d[i] / n) as f32
        };
        match o {
            Observable::G => mean(0) as f32,
            Observable::Radius => mean(1) as f32,
            Observable::Time => mean(2) as f32,
            Observable::Magnification => mean(3) as f32,
            Observable::SkyX => sky(0),
            Observable::SkyY => sky(1),
            Observable::SkyZ => sky(2),
            Observable::Order => self.order.map_or(f32::NAN, |v| v as f32),
            Observable::Class => {
                let mut best = 0;
                for (c, &n) in self.classes.iter().enumerate() {
                    if n > self.classes[best] {
                        best = c;
                    }
                }
                best as f32
            }
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

/// Name of a spectral channel in the layout of Fichet et al. (2021), "An
/// OpenEXR Layout for Spectral Images": Stokes S0 (emission), the
/// wavelength with a comma for the decimal point (a dot separates layers).
pub fn spectral_channel_name(nm: f64) -> String {
    format!("S0.{}nm", format!("{nm:.6}").replace('.', ","))
}

/// Name of an observed scene's flux channel at `hz`: `jy.` and the
/// frequency in GHz, its decimals after a comma as in the spectral layout
/// (a dot would start a layer), trailing zeros dropped: `jy.230GHz`,
/// `jy.345,5GHz`.
pub fn flux_channel_name(hz: f64) -> String {
    let ghz = format!("{:.6}", hz / 1e9);
    let ghz = ghz.trim_end_matches('0').trim_end_matches('.');
    format!("jy.{}GHz", ghz.replace('.', ","))
}
