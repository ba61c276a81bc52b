//! A pass's results as a film: the traced words read back made into a
//! [`Film`], passes added together, and each pixel's observables.

use super::Prepared;
use super::layout::Stat;
use super::traced::Traced;
use crate::film::{BANDS, Film, Observable, PixelProbe, SampleClass, Stats};
use glam::Vec3;

/// One pass of samples ([`Prepared::render_pass`]).
pub struct Pass {
    /// Each pixel's mean over the pass's kept samples.
    pub film: Film,
    /// The pass's counts.
    pub stats: Stats,
    /// Samples kept per pixel (those whose light is a finite number).
    pub kept: Vec<f32>,
    /// Each pixel's observables as sums over the pass's samples (where
    /// the scene asks for them), for adding passes together exactly.
    observed: Vec<PixelProbe>,
}

impl Pass {
    /// This pass and `other` as one, each pixel weighted by its kept
    /// samples (the mean over both passes' kept samples).
    pub fn merged(mut self, other: Pass) -> Pass {
        self.merge_rows(other, 0);
        self
    }

    /// Adds `other`, a pass over this pass's rows from `first_row` on
    /// (adaptive sampling's rounds over some rows): each pixel weighted by
    /// its kept samples; a pixel `other` kept none of is left as it was.
    pub(super) fn merge_rows(&mut self, other: Pass, first_row: u32) {
        let at = first_row as usize * self.film.width as usize;
        let mix = |a: &mut [Vec3], b: &[Vec3], wa: &[f32], wb: &[f32]| {
            for (i, (x, y)) in a.iter_mut().zip(b).enumerate() {
                if wb[i] > 0.0 {
                    *x = (*x * wa[i] + *y * wb[i]) / (wa[i] + wb[i]);
                }
            }
        };
        let (wa, wb) = (&self.kept[at..at + other.kept.len()], &other.kept[..]);
        let spread = |w: &[f32], per: usize| -> Vec<f32> {
            w.iter()
                .flat_map(|&k| std::iter::repeat_n(k, per))
                .collect()
        };
        let n = other.kept.len();
        mix(&mut self.film.xyz[at..at + n], &other.film.xyz, wa, wb);
        if let (Some(a), Some(b)) = (self.film.spectra.as_mut(), other.film.spectra.as_ref()) {
            let per = self.film.nm.len().max(self.film.frequencies.len());
            let (sa, sb) = (spread(wa, per), spread(wb, per));
            mix_flat(&mut a[at * per..(at + n) * per], b, &sa, &sb);
        }
        if let (Some(a), Some(b)) = (self.film.bands.as_mut(), other.film.bands.as_ref()) {
            for ((_, pa), (_, pb)) in a.iter_mut().zip(b) {
                mix(&mut pa[at..at + n], pb, wa, wb);
            }
        }
        for (a, b) in self.kept[at..at + n].iter_mut().zip(other.kept) {
            *a += b;
        }
        let from = at.min(self.observed.len());
        for (a, b) in self.observed[from..].iter_mut().zip(&other.observed) {
            a.merge(b);
        }
        let order: Vec<Observable> = self.film.observables.iter().map(|(o, _)| *o).collect();
        self.film.observables = observable_maps(&order, &self.observed);
        self.stats = self.stats + other.stats;
    }
}

/// [`Pass::merge_rows`]'s weighted mean of values one to a weight.
fn mix_flat(a: &mut [f32], b: &[f32], wa: &[f32], wb: &[f32]) {
    for (i, (x, y)) in a.iter_mut().zip(b).enumerate() {
        if wb[i] > 0.0 {
            *x = (*x * wa[i] + *y * wb[i]) / (wa[i] + wb[i]);
        }
    }
}

impl Prepared<'_> {
    /// The film and counts of a traced pass.
    pub(super) fn to_pass(&self, t: Traced) -> Pass {
        let nm = self.nm.clone();
        let band_words = 3 * BANDS;
        let bands = (self.pack.bands && !t.band_xyz.is_empty()).then(|| {
            crate::film::band_centres(&nm)
                .into_iter()
                .enumerate()
                .map(|(b, centre)| {
                    let plane = t
                        .band_xyz
                        .chunks_exact(band_words)
                        .map(|px| Vec3::new(px[3 * b], px[3 * b + 1], px[3 * b + 2]))
                        .collect();
                    (centre, plane)
                })
                .collect()
        });
        Pass {
            film: Film {
                width: t.width,
                height: t.height,
                xyz: t.xyz,
                nm,
                frequencies: self.frequencies.clone(),
                spectra: self.pack.keep_spectra.then_some(t.spectra),
                bands,
                bloomed: None,
                observables: observable_maps(&self.observables, &t.observed),
            },
            stats: t.stats,
            kept: t.kept,
            observed: t.observed,
        }
    }
}

/// The sample classes as the shader counts them (by `Stat` slot).
const CLASSES: [(Stat, SampleClass); 6] = [
    (Stat::Sky, SampleClass::Sky),
    (Stat::Disk, SampleClass::Disk),
    (Stat::Objects, SampleClass::Objects),
    (Stat::Captured, SampleClass::Captured),
    (Stat::Abandoned, SampleClass::Abandoned),
    (Stat::NonFinite, SampleClass::NonFinite),
];

/// A pixel's record as `resolve` writes it: the sums and counts of g,
/// radius and time (f32), the least order plus one (0: none), the samples
/// per class in their counter slots, and the sums and counts of the
/// magnification and the sky direction.
pub(super) fn pixel_probe(w: &[u32]) -> PixelProbe {
    let mut classes = [0; 6];
    for (stat, class) in CLASSES {
        classes[class.code() as usize] = w[8 + stat.slot()];
    }
    let f = |i: usize| f32::from_bits(w[i]) as f64;
    PixelProbe {
        sums: [f(0), f(1), f(2), f(16), f(17), f(18), f(19)],
        counts: [w[4], w[5], w[6], w[20], w[21], w[21], w[21]],
        order: w[3].checked_sub(1).map(f64::from),
        classes,
    }
}

/// The film's maps of `observables` (in that order) from each pixel's
/// record; none where the pass kept no film.
fn observable_maps(observables: &[Observable], px: &[PixelProbe]) -> Vec<(Observable, Vec<f32>)> {
    if px.is_empty() {
        return Vec::new();
    }
    observables
        .iter()
        .map(|&o| (o, px.iter().map(|p| p.value(o)).collect()))
        .collect()
}
