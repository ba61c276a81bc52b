//! Tracing a pass band by band: each band's parameters, the trace and
//! resolve dispatches (and the display's accumulation), its outputs copied
//! and read back; then the display's closing pass and the counts.

use super::films::pixel_probe;
use super::layout::{OBSERVED_VEC4S, STATS, Stat};
#[cfg(target_arch = "wasm32")]
use super::readback::read_later;
use super::timing::TIMER_PAIRS;
use super::traced::{Show, Traced, Want};
use super::{GpuError, Prepared, WORKGROUP, display};
use crate::film::{BANDS, PixelProbe, Stats};
use glam::Vec3;

/// A band of rows of a pass: the image `w` x `h` (`scale` times smaller
/// than the scene's each way), its rows `first_row..first_row + rows`,
/// and the pass's samples `first..first + count`.
struct Band {
    w: u32,
    h: u32,
    scale: u32,
    first_row: u32,
    rows: u32,
    first: u32,
    count: u32,
}

/// What a pass reads back of its bands, gathered band by band.
pub(super) struct Readout {
    /// The film (and the spectra when kept) is read back.
    film: bool,
    /// The bloom bands are read back.
    bands: bool,
    /// Each pixel's observables are read back.
    observe: bool,
    xyz: Vec<Vec3>,
    kept: Vec<f32>,
    spectra: Vec<f32>,
    band_xyz: Vec<f32>,
    observed: Vec<PixelProbe>,
    adaptive: Vec<[u32; 4]>,
}

/// Bytes of `px` pixels' observables.
fn observed_bytes(px: u64) -> u64 {
    px * 16 * OBSERVED_VEC4S as u64
}

impl Readout {
    /// Room for `npx` pixels of what `want` keeps of `p`'s outputs.
    pub(super) fn new(p: &Prepared<'_>, want: Want, npx: usize) -> Readout {
        let pack = &p.pack;
        let n_wl = pack.n_wl as u64;
        let reserve = |on: bool, n: usize| if on { n } else { 0 };
        let band_words = 3 * BANDS;
        let read_bands = want.film && want.bands && pack.bands;
        let read_observed = want.film && pack.observe;
        Readout {
            film: want.film,
            bands: read_bands,
            observe: read_observed,
            xyz: Vec::with_capacity(reserve(want.film, npx)),
            kept: Vec::with_capacity(reserve(want.film, npx)),
            spectra: Vec::with_capacity(reserve(
                want.film && pack.keep_spectra,
                npx * n_wl as usize,
            )),
            band_xyz: Vec::with_capacity(reserve(read_bands, npx * band_words)),
            observed: Vec::with_capacity(reserve(read_observed, npx)),
            adaptive: Vec::new(),
        }
    }

    /// Copies the outputs of a band of `px` pixels into `p`'s read-back
    /// buffers.
    pub(super) fn copy(&self, p: &Prepared<'_>, enc: &mut wgpu::CommandEncoder, px: u64) {
        if self.film {
            enc.copy_buffer_to_buffer(&p.film, 0, &p.film_rb, 0, px * 16);
            if p.pack.keep_spectra {
                enc.copy_buffer_to_buffer(&p.spectra, 0, &p.spectra_rb, 0, px * p.spectra_px);
            }
        }
        if self.bands {
            enc.copy_buffer_to_buffer(&p.bands, 0, &p.bands_rb, 0, px * p.bands_px);
        }
        if self.observe {
            let at = 16 * p.pack.params.at_observed as u64;
            enc.copy_buffer_to_buffer(&p.film, at, &p.observed_rb, 0, observed_bytes(px));
        }
    }

    /// What was read back, as a pass's results of `w` x `h` pixels.
    pub(super) fn traced(self, w: u32, h: u32, stats: Stats) -> Traced {
        Traced {
            width: w,
            height: h,
            xyz: self.xyz,
            kept: self.kept,
            spectra: self.spectra,
            band_xyz: self.band_xyz,
            bloomed: None,
            observed: self.observed,
            adaptive: self.adaptive,
            stats,
        }
    }

    /// Reads back the band of `px` pixels [`Readout::copy`] copied (once
    /// submitted).
    pub(super) fn read(&mut self, p: &Prepared<'_>, px: u64) -> Result<(), GpuError> {
        let gpu = p.gpu;
        if self.film {
            let (xyz, kept) = (&mut self.xyz, &mut self.kept);
            gpu.read_with(&p.film_rb, px * 16, |words: &[f32]| {
                for c in words.chunks_exact(4) {
                    xyz.push(Vec3::new(c[0], c[1], c[2]));
                    kept.push(c[3]);
                }
            })?;
            if p.pack.keep_spectra {
                self.spectra
                    .extend(gpu.read::<f32>(&p.spectra_rb, px * p.spectra_px)?);
            }
        }
        if self.bands {
            self.band_xyz
                .extend(gpu.read::<f32>(&p.bands_rb, px * p.bands_px)?);
        }
        if self.observe {
            let (observed, adaptive) = (&mut self.observed, &mut self.adaptive);
            let sums = p.adaptive.is_some();
            gpu.read_with(&p.observed_rb, observed_bytes(px), |words: &[u32]| {
                let per = 4 * OBSERVED_VEC4S as usize;
                observed.extend(words.chunks_exact(per).map(pixel_probe));
                if sums {
                    let last = |w: &[u32]| [w[per - 4], w[per - 3], w[per - 2], w[per - 1]];
                    adaptive.extend(words.chunks_exact(per).map(last));
                }
            })?;
        }
        Ok(())
    }
}

impl Prepared<'_> {
    /// Samples `first..first + count` of rows `rows` of the image `scale`
    /// times smaller each way, band by band, keeping what `want` asks.
    pub(super) fn pass(
        &self,
        first: u32,
        count: u32,
        scale: u32,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
        want: Want,
    ) -> Result<Traced, GpuError> {
        if count == 0 || count > self.slots || first + count > self.samples {
            return Err(GpuError::Device(format!(
                "samples {first}..{} of {} in passes of at most {}",
                first + count,
                self.samples,
                self.slots
            )));
        }
        let gpu = self.gpu;
        let (w, h) = (self.width.div_ceil(scale), self.height.div_ceil(scale));
        let mut display = None;
        if want.show.is_some() {
            self.with_display(|_| Ok(()))?;
            let mut guard = self.display.lock().expect("display");
            guard.as_mut().expect("made").set_size(gpu, w, h);
            display = Some(guard);
        }
        let display = display.as_ref().map(|g| g.as_ref().expect("made"));
        let accumulate = match (display, want.show) {
            (Some(d), Some(show)) => Some(d.accumulate_pipeline(gpu, show.restart, show.encode)?),
            _ => None,
        };
        let mut stats_init = [0u32; STATS];
        stats_init[Stat::GMin.slot()] = f32::MAX.to_bits();
        gpu.queue
            .write_buffer(&self.stats, 0, bytemuck::cast_slice(&stats_init));
        let npx = w as usize * rows.len();
        let mut out = Readout::new(self, want, npx);
        let mut device_seconds = 0.0;
        let mut pairs = 0;
        let mut y0 = rows.start;
        while y0 < rows.end {
            let band = Band {
                w,
                h,
                scale,
                first_row: y0,
                rows: self.rows_per_tile.min(rows.end - y0),
                first,
                count,
            };
            self.trace_band(&band, display.zip(accumulate.as_ref()), &out, pairs);
            pairs += 1;
            out.read(self, band.rows as u64 * w as u64)?;
            // The last pair is the display's.
            if pairs + 1 == TIMER_PAIRS {
                device_seconds += self.read_times(pairs)?;
                pairs = 0;
            }
            progress(band.rows as u64);
            self.check_stop()?;
            y0 += band.rows;
        }
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let bloomed_rb = match (display, want.show) {
            (Some(d), Some(show)) => self.finish_display(&mut enc, d, show, w, h, &mut pairs),
            _ => None,
        };
        let s = self.read_stats(enc, want, &stats_init)?;
        device_seconds += self.read_times(pairs)?;
        let bloomed = match bloomed_rb {
            Some((rb, size)) => Some(gpu.read_with(&rb, size, |w: &[f32]| {
                w.chunks_exact(4)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect::<Vec<_>>()
            })?),
            None => None,
        };
        let stats = stats_of(&s, npx as u64 * count as u64);
        if self.timer.is_some() {
            self.add_device_time(device_seconds);
        }
        Ok(Traced {
            width: w,
            height: rows.len() as u32,
            xyz: out.xyz,
            kept: out.kept,
            spectra: out.spectra,
            band_xyz: out.band_xyz,
            bloomed,
            observed: out.observed,
            adaptive: out.adaptive,
            stats,
        })
    }

    /// Traces and resolves `band` as the `pair`-th stamped pass, adds it to
    /// the display's image with the `accumulate` pipeline where shown, and
    /// copies what `out` reads back (submitted, not waited for).
    fn trace_band(
        &self,
        band: &Band,
        display: Option<(&display::Display, &wgpu::ComputePipeline)>,
        out: &Readout,
        pair: u32,
    ) {
        let gpu = self.gpu;
        let (w, h, rows) = (band.w, band.h, band.rows);
        let mut params = self.pack.params;
        if band.scale != 1 {
            // A preview keeps the field of view on fewer, larger
            // pixels (whole renders keep the packed f64-derived aspect).
            params.width = w;
            params.height = h;
            params.cam_half_width = params.cam_half_height * w as f32 / h as f32;
        }
        params.tile_first_row = band.first_row;
        params.tile_rows = rows;
        params.pass_first = band.first;
        params.pass_samples = band.count;
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        if let Some((d, _)) = display {
            d.set_band(gpu, w, h, band.first_row, rows);
        }
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace"),
                timestamp_writes: self.stamps(pair),
            });
            pass.set_bind_group(0, &self.bind, &[]);
            let (gx, gy) = (w.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
            pass.set_pipeline(&self.pipelines.trace);
            pass.dispatch_workgroups(gx, gy, band.count);
            pass.set_pipeline(&self.pipelines.resolve);
            pass.dispatch_workgroups(gx, gy, 1);
            if let Some((d, p)) = display {
                d.accumulate(&mut pass, p, w, rows);
            }
        }
        self.resolve_stamps(&mut enc, pair);
        out.copy(self, &mut enc, rows as u64 * w as u64);
        gpu.queue.submit([enc.finish()]);
    }

    /// Encodes the display's closing pass (bloom, tone curve, encoding) of
    /// the image `w` x `h` as the `pairs`-th stamped pass, and the copy of
    /// the bloomed image where `show` reads it back: that buffer and its
    /// size.
    fn finish_display(
        &self,
        enc: &mut wgpu::CommandEncoder,
        d: &display::Display,
        show: Show,
        w: u32,
        h: u32,
        pairs: &mut u32,
    ) -> Option<(wgpu::Buffer, u64)> {
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("display"),
                timestamp_writes: self.stamps(*pairs),
            });
            d.finish(&mut pass, w, h, show.encode);
        }
        self.resolve_stamps(enc, *pairs);
        *pairs += 1;
        if !(show.read_bloomed && d.blooms()) {
            return None;
        }
        let size = 16 * w as u64 * h as u64;
        let mut slot = self.shown_rb.lock().expect("bloomed read-back");
        let rb = slot.get_or_insert_with(|| {
            let size = 16 * self.width as u64 * self.height as u64;
            self.gpu.readback("the bloomed image, read back", size)
        });
        enc.copy_buffer_to_buffer(d.shown(), 0, rb, 0, size);
        Some((rb.clone(), size))
    }

    /// Submits `enc` with the copy of the pass's counters, and reads them.
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) fn read_stats(
        &self,
        mut enc: wgpu::CommandEncoder,
        _want: Want,
        _init: &[u32; STATS],
    ) -> Result<Vec<u32>, GpuError> {
        let gpu = self.gpu;
        enc.copy_buffer_to_buffer(&self.stats, 0, &self.stats_rb, 0, 4 * STATS as u64);
        gpu.queue.submit([enc.finish()]);
        gpu.read(&self.stats_rb, 4 * STATS as u64)
    }

    /// The browser cannot wait: the counts come back when the GPU is
    /// done, and a frame shows the last that came (`init` before any).
    #[cfg(target_arch = "wasm32")]
    pub(super) fn read_stats(
        &self,
        mut enc: wgpu::CommandEncoder,
        want: Want,
        init: &[u32; STATS],
    ) -> Result<Vec<u32>, GpuError> {
        let gpu = self.gpu;
        let size = 4 * STATS as u64;
        let rb = gpu.readback("the counts, read back", size);
        enc.copy_buffer_to_buffer(&self.stats, 0, &rb, 0, size);
        gpu.queue.submit([enc.finish()]);
        // A view started again forgets the last view's counts, also
        // those still on their way.
        let view = {
            let mut late = self.late_stats.lock().expect("late counts");
            if want.show.is_some_and(|s| s.restart) {
                *late = (late.0 + 1, None);
            }
            late.0
        };
        let slot = self.late_stats.clone();
        read_later(rb, move |words| {
            let mut late = slot.lock().expect("late counts");
            if late.0 == view
                && let Ok(words) = words
            {
                late.1 = Some(bytemuck::cast_slice::<u8, u32>(words).to_vec());
            }
        });
        Ok(self
            .late_stats
            .lock()
            .expect("late counts")
            .1
            .clone()
            .unwrap_or(init.to_vec()))
    }
}

/// A pass's counts of `samples` samples from the shader's counters `s`.
pub(super) fn stats_of(s: &[u32], samples: u64) -> Stats {
    let at = |k: Stat| s[k.slot()];
    let count_of = |k: Stat| at(k) as u64;
    let g_found = at(Stat::GMax) != 0;
    Stats {
        samples,
        rays: samples,
        steps: count_of(Stat::StepsLo) | count_of(Stat::StepsHi) << 32,
        disk: count_of(Stat::Disk),
        objects: count_of(Stat::Objects),
        sky: count_of(Stat::Sky),
        captured: count_of(Stat::Captured),
        abandoned: count_of(Stat::Abandoned),
        non_finite: count_of(Stat::NonFinite),
        closed: count_of(Stat::Closed),
        g_min: if g_found {
            f32::from_bits(at(Stat::GMin)) as f64
        } else {
            f64::INFINITY
        },
        g_max: if g_found {
            f32::from_bits(at(Stat::GMax)) as f64
        } else {
            f64::NEG_INFINITY
        },
        refined: 0,
        extra: 0,
    }
}
