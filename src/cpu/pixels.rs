//! The rows a render fills: each camera sample's light summed into its
//! pixel's share of the film's planes, then averaged over the pixel's
//! finite samples.

use super::{Probing, add_spectrum};
use crate::adaptive::{self as refine, Pixel};
use crate::film::{Observable, Outcome, PixelProbe, SampleClass, Stats};
use crate::spectrum::color::linear_srgb_to_xyz;
use glam::{DVec3, Vec3};

/// One camera sample: its light and how its trace went.
pub(super) struct Sample {
    /// Linear sRGB (RGB renders).
    pub rgb: Vec3,
    /// CIE XYZ (spectral renders; the spectrum, when needed, is in the
    /// buffer the sample was traced into).
    pub xyz: DVec3,
    /// Its light is a finite number (else it is left out of the pixel).
    pub finite: bool,
    pub outcome: Outcome,
    /// Rays traced: one, or one per wavelength.
    pub rays: u64,
    /// The range of g its disk light had (spectral renders).
    pub g: (f64, f64),
    /// What it tells the observables (and adaptive sampling's classes).
    pub probing: Probing,
}

impl Sample {
    /// Its class, as the counts give it.
    pub fn class(&self) -> SampleClass {
        if self.finite {
            self.outcome.class()
        } else {
            SampleClass::NonFinite
        }
    }

    /// Its luminance Y (white 1 before exposure), None when not finite.
    pub fn luminance(&self, spectral: bool) -> Option<f64> {
        self.finite.then(|| {
            if spectral {
                self.xyz.y
            } else {
                crate::spectrum::color::luminance(self.rgb) as f64
            }
        })
    }
}

/// What every row shares: which planes the film keeps.
pub(super) struct Layout<'a> {
    pub width: usize,
    pub spectral: bool,
    /// Wavelengths of a spectral render (0 for RGB).
    pub n_wl: usize,
    pub keep_spectra: bool,
    /// Spectral bloom: each wavelength's band and XYZ weight.
    pub bands: Option<(&'a [usize], &'a [DVec3])>,
    pub observables: &'a [Observable],
    /// Luminance shown as white: 2^-exposure (for adaptive sampling's
    /// lightness).
    pub white: f64,
}

/// One kept row's share of the film's planes.
pub(super) struct RowOut<'a> {
    /// RGB renders: the sum of the samples' linear sRGB until the row is
    /// finished; then (every render) the pixels' XYZ.
    pub xyz: &'a mut [Vec3],
    /// Each pixel's summed spectrum (empty when spectra are not kept).
    pub spec: &'a mut [f32],
    /// Each bloom band's row (empty without spectral bloom).
    pub bands: Vec<&'a mut [Vec3]>,
    /// The observables, interleaved per pixel.
    pub obs: &'a mut [f32],
}

/// Sums kept while a row is sampled, for its finish.
struct Sums {
    /// Spectral renders: the samples' summed XYZ.
    xyz: Vec<DVec3>,
    /// Each pixel's observables so far (empty without).
    probes: Vec<PixelProbe>,
    /// Finite samples per pixel.
    kept: Vec<u32>,
}

/// A row being rendered: a row of the film, or (adaptive sampling) a row
/// around them that is sampled only for the decisions of its neighbours.
pub(super) struct Row<'a> {
    /// Its place in the image (0 at the top).
    pub y: usize,
    /// Its share of the film; None for the rows around.
    out: Option<RowOut<'a>>,
    sums: Option<Sums>,
    /// Adaptive sampling's state of each pixel (empty without).
    pub px: Vec<Pixel>,
    /// Counts of a kept row's samples.
    pub stats: Stats,
}

impl AsRef<[Pixel]> for Row<'_> {
    fn as_ref(&self) -> &[Pixel] {
        &self.px
    }
}

impl AsMut<[Pixel]> for Row<'_> {
    fn as_mut(&mut self) -> &mut [Pixel] {
        &mut self.px
    }
}

impl<'a> Row<'a> {
    /// Row `y`, keeping `out` (if any), with adaptive sampling's state if
    /// `adaptive`.
    pub fn new(y: usize, out: Option<RowOut<'a>>, layout: &Layout, adaptive: bool) -> Row<'a> {
        let w = layout.width;
        let sums = out.as_ref().map(|_| Sums {
            xyz: vec![DVec3::ZERO; if layout.spectral { w } else { 0 }],
            probes: vec![PixelProbe::default(); if layout.observables.is_empty() { 0 } else { w }],
            kept: vec![0; w],
        });
        Row {
            y,
            out,
            sums,
            px: if adaptive {
                vec![Pixel::default(); w]
            } else {
                Vec::new()
            },
            stats: Stats::default(),
        }
    }

    /// Whether the row is one of the film's.
    pub fn kept(&self) -> bool {
        self.out.is_some()
    }

    /// Adds sample `s` to pixel `x` (`spec`: its spectrum, where traced).
    #[inline]
    pub fn add(&mut self, layout: &Layout, x: usize, s: &Sample, spec: &[f32]) {
        let class = s.class();
        if let Some(p) = self.px.get_mut(x) {
            let v = s
                .luminance(layout.spectral)
                .map(|y| refine::lightness(y, layout.white));
            p.add(
                refine::class_bit(class, s.probing.probe.order, s.probing.object),
                v,
            );
        }
        let (Some(out), Some(sums)) = (&mut self.out, &mut self.sums) else {
            return;
        };
        if s.finite {
            if layout.spectral {
                sums.xyz[x] += s.xyz;
                self.stats.g_min = self.stats.g_min.min(s.g.0);
                self.stats.g_max = self.stats.g_max.max(s.g.1);
                let n = if layout.keep_spectra { layout.n_wl } else { 0 };
                add_spectrum(
                    spec,
                    &mut out.spec[x * n..(x + 1) * n],
                    layout.bands,
                    &mut out.bands,
                    x,
                );
            } else {
                out.xyz[x] += s.rgb;
            }
        }
        // A non-finite sample is left out of the pixel rather than
        // poisoning it, and counted.
        sums.kept[x] += s.finite as u32;
        self.stats.count(&s.outcome, s.rays, s.finite);
        if let Some(probe) = sums.probes.get_mut(x) {
            probe.add(&s.probing.probe, class);
        }
    }

    /// Averages each pixel over its finite samples into the film's
    /// planes; the sums are dropped.
    pub fn finish(&mut self, layout: &Layout) {
        let (Some(out), Some(sums)) = (&mut self.out, self.sums.take()) else {
            return;
        };
        let no = layout.observables.len();
        let n = if layout.keep_spectra { layout.n_wl } else { 0 };
        for x in 0..layout.width {
            for (k, &o) in layout.observables.iter().enumerate() {
                out.obs[x * no + k] = sums.probes[x].value(o);
            }
            let k = 1.0 / sums.kept[x].max(1) as f64;
            for v in &mut out.spec[x * n..(x + 1) * n] {
                *v *= k as f32;
            }
            for plane in out.bands.iter_mut() {
                plane[x] *= k as f32;
            }
            let xyz = if layout.spectral {
                sums.xyz[x] * k
            } else {
                linear_srgb_to_xyz((out.xyz[x] * k as f32).as_dvec3())
            };
            out.xyz[x] = xyz.as_vec3();
        }
    }
}

/// The film's planes cut into `h` rows of `w` pixels each (`n_wl`
/// wavelengths a pixel in `spectra`, `no` observables in `obs`); a plane
/// not kept (empty) gives empty rows.
pub(super) fn row_outs<'a>(
    xyz: &'a mut [Vec3],
    spectra: &'a mut [f32],
    band_planes: &'a mut [Vec<Vec3>],
    obs: &'a mut [f32],
    (w, h, n_wl, no): (usize, usize, usize, usize),
) -> Vec<RowOut<'a>> {
    let mut spec = rows_of(spectra, w * n_wl, h).into_iter();
    let mut obs = rows_of(obs, w * no, h).into_iter();
    let mut bands: Vec<Vec<&'a mut [Vec3]>> = (0..h)
        .map(|_| Vec::with_capacity(band_planes.len()))
        .collect();
    for plane in band_planes {
        for (r, row) in plane.chunks_mut(w).enumerate() {
            bands[r].push(row);
        }
    }
    xyz.chunks_mut(w)
        .zip(bands)
        .map(|(xyz, bands)| RowOut {
            xyz,
            spec: spec.next().expect("a row each"),
            bands,
            obs: obs.next().expect("a row each"),
        })
        .collect()
}

/// A plane's `h` rows of `per_row` values each, or `h` empty rows where
/// the plane is not kept (empty).
fn rows_of<T>(plane: &mut [T], per_row: usize, h: usize) -> Vec<&mut [T]> {
    if plane.is_empty() || per_row == 0 {
        (0..h).map(|_| &mut [][..]).collect()
    } else {
        plane.chunks_mut(per_row).collect()
    }
}
