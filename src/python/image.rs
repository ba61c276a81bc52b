//! A rendered image: the film, and numpy arrays that view it (read-only,
//! kept alive by the image) rather than copies.

use super::{BlackholeError, error};
use crate::config::SceneConfig;
use crate::film::{Film, Stats};
use crate::scene::Scene;
use crate::transfer::sky::{Card, SkyFrame};
use glam::{DVec3, Vec3};
use numpy::ndarray::{ArrayView, Dimension, Ix2, Ix3, IxDyn};
use numpy::{Element, PyArray};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::ops::Range;
use std::path::PathBuf;

/// What the FITS writer needs of the camera: its axes and image plane.
struct Optics {
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    half_height: f64,
    shift: f64,
    height: u32,
}

/// A rendered image (or tile of one).
#[pyclass(frozen, module = "blackhole._native", name = "Image")]
pub struct Image {
    film: Film,
    stats: Stats,
    seconds: f64,
    gpu_seconds: Option<f64>,
    backend: String,
    config: SceneConfig,
    /// Linear sRGB of every pixel.
    rgb: Vec<Vec3>,
    /// The film bloomed as the scene asks (None: the film's XYZ).
    shown: Option<Vec<Vec3>>,
    /// The PNG's bytes.
    srgb8: Vec<u8>,
    rows: Range<u32>,
    optics: Optics,
    /// An observed scene's place on Earth's sky.
    sky: Option<SkyFrame>,
}

impl Image {
    /// The image of `film` rendered from `scene` in `seconds` (and the
    /// GPU's own time) on `backend`, holding the image's rows `rows`.
    pub fn new(
        scene: &Scene,
        film: Film,
        stats: Stats,
        (seconds, gpu_seconds): (f64, Option<f64>),
        backend: String,
        rows: Range<u32>,
    ) -> Image {
        let cfg = &scene.config;
        let shown = crate::output::displayed(cfg, &film);
        let srgb8 = crate::output::picture(cfg, &shown);
        let shown = match shown {
            std::borrow::Cow::Owned(v) => Some(v),
            std::borrow::Cow::Borrowed(_) => None,
        };
        let c = &scene.camera;
        Image {
            rgb: film.linear_srgb(),
            shown,
            srgb8,
            film,
            stats,
            seconds,
            gpu_seconds,
            backend,
            config: cfg.clone(),
            rows,
            optics: Optics {
                forward: c.forward,
                right: c.right,
                up: c.up,
                half_height: c.half_height,
                shift: c.shift,
                height: c.height,
            },
            sky: SkyFrame::of(cfg),
        }
    }

    fn shape(&self) -> (usize, usize) {
        (self.film.height as usize, self.film.width as usize)
    }
}

/// A read-only numpy array of `shape` viewing `data`, which `owner` holds
/// (frozen: never changed nor moved while the array lives).
fn view<'py, T: Element, D: Dimension>(
    owner: &Bound<'py, Image>,
    data: &[T],
    shape: D,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let a = ArrayView::from_shape(shape, data)
        .map_err(|e| BlackholeError::new_err(format!("a film of the wrong size: {e}")))?;
    // SAFETY: `data` lives in `owner`, a frozen pyclass whose fields are
    // never mutated; the array keeps `owner` alive as its base.
    let arr = unsafe { PyArray::borrow_from_array(&a, owner.clone().into_any()) };
    arr.getattr("flags")?.setattr("writeable", false)?;
    Ok(arr)
}

fn floats(v: &[Vec3]) -> &[f32] {
    bytemuck::cast_slice(v)
}

#[pymethods]
impl Image {
    /// CIE XYZ, float32 (H, W, 3): Y = 1 is the display white before
    /// exposure.
    #[getter]
    fn xyz<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray<f32, Ix3>>> {
        let (h, w) = slf.get().shape();
        view(slf, floats(&slf.get().film.xyz), Ix3(h, w, 3))
    }

    /// Linear sRGB (Rec. 709 primaries, D65), float32 (H, W, 3): the EXR's
    /// R, G, B.
    #[getter]
    fn rgb<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray<f32, Ix3>>> {
        let (h, w) = slf.get().shape();
        view(slf, floats(&slf.get().rgb), Ix3(h, w, 3))
    }

    /// The 8-bit sRGB the PNG holds (bloom, exposure, tone curve,
    /// encoding), uint8 (H, W, 3).
    #[getter]
    fn srgb8<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray<u8, Ix3>>> {
        let (h, w) = slf.get().shape();
        view(slf, &slf.get().srgb8, Ix3(h, w, 3))
    }

    /// Each pixel's spectrum, float32 (H, W, N) on `wavelengths`, when the
    /// scene keeps spectra (`spectral.exr_layers`); else None.
    #[getter]
    fn spectra<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray<f32, Ix3>>>> {
        let me = slf.get();
        let (h, w) = me.shape();
        match &me.film.spectra {
            Some(s) if me.film.frequencies.is_empty() => {
                Ok(Some(view(slf, s, Ix3(h, w, me.film.nm.len()))?))
            }
            _ => Ok(None),
        }
    }

    /// An observed scene's (`[observe]`) flux density of each pixel at
    /// each frequency, Jy, float32 (H, W, N) on `frequencies`; else None.
    #[getter]
    fn flux<'py>(slf: &Bound<'py, Self>) -> PyResult<Option<Bound<'py, PyArray<f32, Ix3>>>> {
        let me = slf.get();
        let (h, w) = me.shape();
        match &me.film.spectra {
            Some(s) if !me.film.frequencies.is_empty() => {
                Ok(Some(view(slf, s, Ix3(h, w, me.film.frequencies.len()))?))
            }
            _ => Ok(None),
        }
    }

    /// The observed frequencies (Hz, float64) of an observed scene; None
    /// for others.
    #[getter]
    fn frequencies<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<Option<Bound<'py, PyArray<f64, IxDyn>>>> {
        let hz = &slf.get().film.frequencies;
        if hz.is_empty() {
            return Ok(None);
        }
        Ok(Some(view(slf, hz, IxDyn(&[hz.len()]))?))
    }

    /// The wavelengths (nm, float64) of a spectral render; None for RGB.
    #[getter]
    fn wavelengths<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<Option<Bound<'py, PyArray<f64, IxDyn>>>> {
        let nm = &slf.get().film.nm;
        if nm.is_empty() {
            return Ok(None);
        }
        Ok(Some(view(slf, nm, IxDyn(&[nm.len()]))?))
    }

    /// {name: float32 (H, W)} for each observable the scene asks for.
    #[getter]
    fn observables<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let (h, w) = slf.get().shape();
        let d = PyDict::new(slf.py());
        let film = &slf.get().film;
        for (o, plane) in &film.observables {
            d.set_item(o.name(), view(slf, plane, Ix2(h, w))?)?;
        }
        // The sky direction also as one (h, w, 3) array of unit vectors.
        let axis = |o: crate::film::Observable| {
            film.observables
                .iter()
                .find(|(k, _)| *k == o)
                .map(|(_, p)| p)
        };
        use crate::film::Observable::{SkyX, SkyY, SkyZ};
        if let (Some(x), Some(y), Some(z)) = (axis(SkyX), axis(SkyY), axis(SkyZ)) {
            let xyz: Vec<f32> = (0..w * h).flat_map(|i| [x[i], y[i], z[i]]).collect();
            let a = numpy::ndarray::Array3::from_shape_vec((h, w, 3), xyz)
                .map_err(|e| BlackholeError::new_err(format!("a film of the wrong size: {e}")))?;
            d.set_item("sky", PyArray::from_owned_array(slf.py(), a))?;
        }
        Ok(d)
    }

    /// The render's counts and timings: samples, rays, steps, the samples'
    /// classes (counts and shares), closed-form samples, the pixels
    /// adaptive sampling refined and its extra samples, the disk's g
    /// range, an observed scene's total flux density at each frequency
    /// (`flux_jy`, Jy; None for others), seconds, gpu_seconds, backend.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.stats;
        let d = PyDict::new(py);
        let n = s.samples.max(1) as f64;
        d.set_item("samples", s.samples)?;
        d.set_item("rays", s.rays)?;
        d.set_item("steps", s.steps)?;
        for (k, v) in [
            ("sky", s.sky),
            ("disk", s.disk),
            ("objects", s.objects),
            ("captured", s.captured),
            ("abandoned", s.abandoned),
            ("non_finite", s.non_finite),
        ] {
            d.set_item(k, v)?;
            d.set_item(format!("{k}_share"), v as f64 / n)?;
        }
        d.set_item("closed", s.closed)?;
        d.set_item("refined", s.refined)?;
        d.set_item("extra_samples", s.extra)?;
        let g = |x: f64| x.is_finite().then_some(x);
        d.set_item("g_min", g(s.g_min))?;
        d.set_item("g_max", g(s.g_max))?;
        // An observed scene's total flux density (Jy) at each frequency.
        let flux = self.film.total_flux();
        d.set_item("flux_jy", (!flux.is_empty()).then_some(flux))?;
        // A GRMHD snapshot's mass unit rendered with (fitted, where
        // medium.flux asked).
        if let Some(crate::config::MediumConfig::Grmhd(g)) = &self.config.medium {
            d.set_item("m_unit", g.m_unit)?;
        }
        d.set_item("seconds", self.seconds)?;
        d.set_item("gpu_seconds", self.gpu_seconds)?;
        d.set_item("backend", &self.backend)?;
        Ok(d)
    }

    /// (width, height) in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.film.width, self.film.height)
    }

    /// The image's rows (first, end) in the whole image (a tile's band).
    #[getter]
    fn rows(&self) -> (u32, u32) {
        (self.rows.start, self.rows.end)
    }

    /// The FITS celestial WCS of the pixels, {keyword: value}, for FITS
    /// rows bottom-up as `write` stores them. An observed scene's is
    /// Earth's: RA---SIN / DEC--SIN in degrees about the source, East to
    /// the left (the FITS files' own, ehtim's layout); others' the
    /// camera's sky (galactic longitude and latitude, the panorama's
    /// frame; TAN about the camera's look direction).
    #[getter]
    fn wcs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        if let Some(sky) = &self.sky {
            let d = PyDict::new(py);
            for (key, card) in sky.wcs(self.rows.clone()) {
                match card {
                    Card::Text(t) => d.set_item(key, t)?,
                    Card::Number(x) => d.set_item(key, x)?,
                }
            }
            return Ok(d);
        }
        let o = &self.optics;
        let f = o.forward;
        // Scene -> galactic: the panorama's frame (see `starmap`).
        let (l, b) = ((-f.x).atan2(f.y), f.z.clamp(-1.0, 1.0).asin());
        let east = DVec3::new(-l.cos(), -l.sin(), 0.0);
        let north = DVec3::new(b.sin() * l.sin(), -b.sin() * l.cos(), b.cos());
        let (h_full, w) = (o.height as f64, self.film.width as f64);
        // Image-plane units per pixel (both axes).
        let s = 2.0 * o.half_height / h_full;
        let deg = s.to_degrees();
        let d = PyDict::new(py);
        d.set_item("CTYPE1", "GLON-TAN")?;
        d.set_item("CTYPE2", "GLAT-TAN")?;
        d.set_item("CUNIT1", "deg")?;
        d.set_item("CUNIT2", "deg")?;
        // (+ 0 turns a -0 into 0.)
        d.set_item("CRVAL1", l.to_degrees().rem_euclid(360.0) + 0.0)?;
        d.set_item("CRVAL2", b.to_degrees())?;
        // The look direction is where the image plane's x is 0: the
        // window is offset by `shift` (stereo eyes); FITS pixel centres
        // are whole numbers from 1.
        let half_width = w / h_full * o.half_height;
        d.set_item("CRPIX1", w / 2.0 * (1.0 - o.shift / half_width) + 0.5)?;
        // Rows bottom-up; a tile's band ends `rows.end` from the top.
        let rows_below = h_full - self.rows.end as f64;
        d.set_item("CRPIX2", h_full / 2.0 + 0.5 - rows_below)?;
        d.set_item("CD1_1", deg * o.right.dot(east))?;
        d.set_item("CD1_2", deg * o.up.dot(east))?;
        d.set_item("CD2_1", deg * o.right.dot(north))?;
        d.set_item("CD2_2", deg * o.up.dot(north))?;
        Ok(d)
    }

    /// An observed scene's pixel as Earth sees it (micro-arcseconds, both
    /// axes, at the image's centre); None for others.
    #[getter]
    fn pixel_uas(&self) -> Option<f64> {
        self.sky.as_ref().map(SkyFrame::pixel_uas)
    }

    /// An observed scene's place on the sky, as its FITS files and EXR
    /// say it: {ra, dec (degrees), source, mjd, distance_pc,
    /// frequencies (Hz), pixel_uas, channels (the EXR's flux channels)};
    /// None for others.
    #[getter]
    fn sky<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(sky) = &self.sky else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("ra", sky.ra)?;
        d.set_item("dec", sky.dec)?;
        d.set_item("source", &sky.source)?;
        d.set_item("mjd", sky.mjd)?;
        d.set_item("distance_pc", sky.distance_pc)?;
        d.set_item("frequencies", sky.frequencies.clone())?;
        d.set_item("pixel_uas", sky.pixel_uas())?;
        let channels: Vec<String> = sky
            .frequencies
            .iter()
            .map(|&f| crate::film::flux_channel_name(f))
            .collect();
        d.set_item("channels", channels)?;
        Ok(Some(d))
    }

    /// An observed scene's ring at its first frequency, as the EHT's ring
    /// extractor finds it: {diameter_uas, center_uas (x right, y up, from
    /// the image's centre), spread_uas}; None for others or without a
    /// ring.
    #[getter]
    fn ring<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let (Some(uas), Some(ring)) = (self.pixel_uas(), self.film.ring()) else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        let (w, h) = (self.film.width as f64, self.film.height as f64);
        d.set_item("diameter_uas", ring.diameter * uas)?;
        d.set_item(
            "center_uas",
            (
                (ring.center.0 - 0.5 * w) * uas,
                (0.5 * h - ring.center.1) * uas,
            ),
        )?;
        d.set_item("spread_uas", ring.spread * uas)?;
        Ok(Some(d))
    }

    /// Whether the scene's disk radiates in SI units (`disk.emission =
    /// "thin"`): the spectra are then W m^-2 sr^-1 nm^-1.
    #[getter]
    fn si_units(&self) -> bool {
        self.config
            .disk
            .as_ref()
            .is_some_and(|d| matches!(d.emission, crate::config::DiskEmission::Thin))
    }

    /// Writes the image by extension: `.png` (what `image.png` holds),
    /// `.exr` (as `image.exr`, with the scene's `exr_xyz`, `exr_half`,
    /// spectral layers and observables), `.fits` (astropy: the spectral
    /// or colour cube with its WCS, the observables as extra HDUs; an
    /// observed scene's flux density in ehtim's layout, one file a
    /// frequency, or with `cube` all frequencies in one cube). Atomic: a
    /// failed write leaves no file.
    #[pyo3(signature = (path, cube = false))]
    fn write(slf: &Bound<'_, Self>, path: PathBuf, cube: bool) -> PyResult<()> {
        let me = slf.get();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        let (w, h) = (me.film.width, me.film.height);
        let py = slf.py();
        match ext.as_str() {
            "png" => py
                .detach(|| {
                    let (w, h, rgb) = crate::output::png_canvas(&me.config, w, h, &me.srgb8);
                    crate::output::write_png(&path, w, h, &rgb)
                })
                .map_err(error),
            "exr" => py
                .detach(|| {
                    let shown = me.shown.as_deref().unwrap_or(&me.film.xyz);
                    let mut batch = crate::files::Batch::new();
                    crate::output::stage_scene_exr(
                        &mut batch,
                        &path,
                        &me.config,
                        (&me.film, shown),
                        &[],
                    )?;
                    batch.commit()
                })
                .map_err(error),
            "fits" | "fit" | "fts" => {
                py.import("blackhole._fits")?
                    .call_method1("write", (slf, path, cube))?;
                Ok(())
            }
            _ => Err(BlackholeError::new_err(format!(
                "{}: expected a .png, .exr or .fits file name",
                path.display()
            ))),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "<blackhole.Image {}x{}, {} samples, {:.3} s on {}>",
            self.film.width, self.film.height, self.stats.samples, self.seconds, self.backend
        )
    }
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Image>()
}
