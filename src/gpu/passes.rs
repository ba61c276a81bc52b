//! Rendering a prepared scene: the whole image or some of its rows, in
//! passes of samples added together, and single passes for the viewer and
//! benchmarks.

use super::films::Pass;
use super::traced::{Show, Traced, Want};
use super::{GpuError, Prepared};
use crate::film::{Film, Stats};

impl Prepared<'_> {
    /// Renders the image band by band, with everything a tile keeps (the
    /// bloom bands among it); `progress` gets the rows finished.
    pub fn render(&self, progress: &(dyn Fn(u64) + Sync)) -> Result<(Film, Stats), GpuError> {
        self.render_rows(0..self.height, progress)
    }

    /// Renders the image's rows `rows` (0 at the top), each pixel exactly
    /// as a whole render gives it: one tile of a render split over jobs.
    pub fn render_rows(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats), GpuError> {
        self.render_wanting(rows, progress, |_| Want {
            film: true,
            bands: true,
            show: None,
        })
    }

    /// The whole image for the scene's outputs: the film and the spectra
    /// when kept are read back, and where the scene blooms, the bloomed
    /// image (`Film::bloomed`, bloomed on the GPU) instead of the bloom
    /// bands. Where the device cannot hold the whole image for bloom, the
    /// bands are read back and bloomed on the host, as for tiles.
    pub fn render_image(&self, progress: &(dyn Fn(u64) + Sync)) -> Result<(Film, Stats), GpuError> {
        // Adaptive sampling's rounds are read back: bloomed on the host.
        let bloom_here = self.adaptive.is_none()
            && self.look.bloom.is_some()
            && match self.with_display(|_| Ok(())) {
                Ok(()) => true,
                Err(GpuError::TooLarge { .. }) => false,
                Err(e) => return Err(e),
            };
        let first = std::sync::atomic::AtomicBool::new(true);
        self.render_wanting(0..self.height, progress, |_| Want {
            film: true,
            bands: !bloom_here,
            show: bloom_here.then(|| Show {
                restart: first.swap(false, std::sync::atomic::Ordering::Relaxed),
                encode: false,
                read_bloomed: true,
            }),
        })
    }

    /// Renders `rows` in passes of the slots' samples, added together.
    fn render_wanting(
        &self,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        want: impl Fn(u32) -> Want,
    ) -> Result<(Film, Stats), GpuError> {
        if rows.is_empty() || rows.end > self.height {
            return Err(GpuError::Device(format!(
                "rows {}..{} of an image {} rows high",
                rows.start, rows.end, self.height
            )));
        }
        if let Some(a) = self.adaptive {
            let (film, stats, _) = self.render_adaptive(a, rows, progress)?;
            return Ok((film, stats));
        }
        self.start_device_time();
        // One pass when the slots hold every sample (prepare), else passes
        // added together (prepare_passes).
        let mut all: Option<Pass> = None;
        let mut bloomed = None;
        let mut first = 0;
        while first < self.samples {
            let count = self.slots.min(self.samples - first);
            self.check_stop()?;
            let mut t = self.pass(first, count, 1, rows.clone(), progress, want(first))?;
            bloomed = t.bloomed.take().or(bloomed);
            let pass = self.to_pass(t);
            all = Some(match all {
                None => pass,
                Some(acc) => acc.merged(pass),
            });
            first += count;
        }
        let mut all = all.expect("at least one sample");
        if bloomed.is_some() {
            all.film.bands = None;
            all.film.bloomed = bloomed;
        }
        Ok((all.film, all.stats))
    }

    /// Samples `first..first + count` of each pixel's `image.samples` (the
    /// very samples a whole render takes, so passes add up to it): the
    /// film holds each pixel's mean over the pass's kept samples, `kept`
    /// their number. Progress counts rows.
    pub fn render_pass(
        &self,
        first: u32,
        count: u32,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Pass, GpuError> {
        self.render_pass_scaled(first, count, 1, progress)
    }

    /// [`Prepared::render_pass`] of the same view on an image `scale`
    /// times smaller each way (rounded up; same field of view, square
    /// pixels).
    pub fn render_pass_scaled(
        &self,
        first: u32,
        count: u32,
        scale: u32,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<Pass, GpuError> {
        let want = Want {
            film: true,
            bands: true,
            show: None,
        };
        Ok(self.to_pass(self.scaled_pass(first, count, scale, progress, want)?))
    }

    /// Samples `first..first + count` of every row of the image `scale`
    /// times smaller each way, keeping what `want` asks, its GPU time
    /// alone.
    pub(super) fn scaled_pass(
        &self,
        first: u32,
        count: u32,
        scale: u32,
        progress: &(dyn Fn(u64) + Sync),
        want: Want,
    ) -> Result<Traced, GpuError> {
        let scale = scale.max(1);
        self.start_device_time();
        let rows = 0..self.height.div_ceil(scale);
        self.pass(first, count, scale, rows, progress, want)
    }

    /// Samples `first..first + count` of every pixel of the image `scale`
    /// times smaller each way, traced and resolved on the GPU and nothing
    /// kept but the counts: the trace's own cost (for benchmarks against
    /// the viewer's frame and a render).
    pub fn trace_pass(&self, first: u32, count: u32, scale: u32) -> Result<Stats, GpuError> {
        let want = Want {
            film: false,
            bands: false,
            show: None,
        };
        Ok(self.scaled_pass(first, count, scale, &|_| {}, want)?.stats)
    }
}
