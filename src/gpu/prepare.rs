//! Preparing a scene: packed and uploaded once, its shader compiled, its
//! image cut into bands of rows that fit the adapter's buffers.

use super::device::Pipelines;
use super::layout::{FLAG_ADAPTIVE, OBSERVED_VEC4S, PROBE_VEC4S, STATS};
use super::pack::{self, Packed};
use super::timing::Timer;
use super::{Gpu, GpuError, TILE_SAMPLES, WORKGROUP, check_supported, display};
use crate::film::{BANDS, Film, Observable, Stats};
use crate::scene::Scene;
use std::sync::{Arc, Mutex};

impl Gpu {
    /// Renders the whole image; `progress` is called with the number of
    /// rows finished since its last call.
    pub fn render(
        &self,
        scene: &Scene,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats), GpuError> {
        self.prepare(scene, u32::MAX)?.render(progress)
    }

    /// [`Gpu::render`] with at most `max_rows` rows per dispatch (the
    /// image does not depend on it).
    pub fn render_in_bands(
        &self,
        scene: &Scene,
        max_rows: u32,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats), GpuError> {
        self.prepare(scene, max_rows)?.render(progress)
    }

    /// Uploads `scene` and compiles its shader once, for renders of it
    /// (at most `max_rows` rows per dispatch).
    pub fn prepare(&self, scene: &Scene, max_rows: u32) -> Result<Prepared<'_>, GpuError> {
        self.prepare_slots(scene, max_rows, scene.samples, scene.adaptive)
    }

    /// [`Gpu::prepare`] for rendering in passes of `per_pass` samples
    /// ([`Prepared::render_pass`]): the sample slots are sized for a pass,
    /// so bands of rows can be as tall as the whole image. Passes are
    /// uniform: renders of it take no adaptive sampling (the viewer's
    /// progressive passes).
    pub fn prepare_passes(&self, scene: &Scene, per_pass: u32) -> Result<Prepared<'_>, GpuError> {
        self.prepare_slots(scene, u32::MAX, per_pass.clamp(1, scene.samples), false)
    }

    fn prepare_slots(
        &self,
        scene: &Scene,
        max_rows: u32,
        slots: u32,
        adaptive: bool,
    ) -> Result<Prepared<'_>, GpuError> {
        check_supported(scene)?;
        self.check()?;
        let mut pack = Packed::new(scene)?;
        pack.closed &= self.closed_form;
        let adaptive = adaptive && scene.adaptive;
        if adaptive {
            // Adaptive sampling takes the classes from the probe.
            pack.observe = true;
            pack.params.flags |= FLAG_ADAPTIVE;
            pack.params.white = (-scene.image().exposure).exp2() as f32;
        }
        let pipelines = self.pipelines(&pack.variant())?;
        let (w, h) = (scene.camera.width, scene.camera.height);
        let spp = scene.samples;
        if spp > 65_535 {
            return Err(GpuError::Unsupported {
                table: "image.samples".into(),
                why: format!("{spp} samples per pixel; the GPU takes at most 65535"),
            });
        }
        let sizes = self.band_sizes(&mut pack, w, h, slots, max_rows)?;
        let Uploaded {
            bind,
            params,
            film,
            spectra,
            bands,
            stats,
            inputs,
        } = self.upload(&pack, &sizes)?;
        let readback = |size: u64| self.readback("readback", size);
        let timer = Timer::new(self);
        let nm = scene
            .spectral
            .as_ref()
            .map_or(Vec::new(), |c| c.wavelengths.nm.clone());
        let look = display::Look::of(scene, &nm, pack.bands);
        let tile_px = sizes.tile_px;
        Ok(Prepared {
            stop: None,
            gpu: self,
            timer,
            device_seconds: Mutex::new(None),
            width: w,
            height: h,
            samples: spp,
            slots,
            adaptive: adaptive.then_some(super::refine::Adaptive {
                room: scene.max_samples.saturating_sub(spp),
                contrast: scene.refine_contrast(),
            }),
            nm,
            frequencies: scene
                .observe
                .as_ref()
                .map_or(Vec::new(), |o| o.frequencies.clone()),
            look,
            display: Mutex::new(None),
            shown_rb: Mutex::new(None),
            rows_per_tile: sizes.rows_per_tile,
            spectra_px: sizes.spectra_px,
            bands_px: sizes.bands_px,
            film_rb: readback(tile_px * 16),
            observed_rb: readback(tile_px * sizes.observed_px),
            observables: scene.observables.clone(),
            spectra_rb: readback(tile_px * sizes.spectra_px),
            bands_rb: readback(tile_px * sizes.bands_px),
            #[cfg(not(target_arch = "wasm32"))]
            stats_rb: readback(4 * STATS as u64),
            #[cfg(target_arch = "wasm32")]
            late_stats: Arc::new(Mutex::new((0, None))),
            pack,
            pipelines,
            bind,
            params,
            film,
            spectra,
            bands,
            stats,
            _inputs: inputs,
        })
    }

    /// The bands of rows of an image `w` x `h` traced `slots` samples at a
    /// time (at most `max_rows` rows), and where each output starts in
    /// its buffer (written into `pack`'s parameters).
    fn band_sizes(
        &self,
        pack: &mut Packed,
        w: u32,
        h: u32,
        slots: u32,
        max_rows: u32,
    ) -> Result<BandSizes, GpuError> {
        let n_wl = pack.n_wl as u64;
        // Bytes per pixel of the outputs, to size the bands of rows.
        // Bytes per pixel: the film, each sample's slot (two vec4), kept
        // spectra, each sample's spectrum when spectra or bands are kept,
        // bloom bands.
        let spectra_px = if pack.keep_spectra { 4 * n_wl } else { 0 };
        let sample_spectra_px = if pack.keep_spectra || pack.bands {
            4 * n_wl * slots as u64
        } else {
            0
        };
        // With observables, each sample's probe (one vec4) and each
        // pixel's sums (OBSERVED_VEC4S) follow.
        let observed_px = if pack.observe {
            16 * OBSERVED_VEC4S as u64
        } else {
            0
        };
        let probes_px = if pack.observe {
            16 * PROBE_VEC4S as u64 * slots as u64
        } else {
            0
        };
        // Adaptive sampling: a round's list, an entry per pixel at most.
        let list_px = if pack.params.flags & FLAG_ADAPTIVE != 0 {
            16
        } else {
            0
        };
        let film_px = 16 + 32 * slots as u64 + probes_px + observed_px + list_px;
        // Each band as X, Y, Z floats.
        let bands_px = if pack.bands { 4 * 3 * BANDS as u64 } else { 0 };
        // Bands of rows: at most TILE_SAMPLES samples, and buffers within
        // the adapter's limits.
        let biggest = film_px.max(spectra_px + sample_spectra_px).max(bands_px);
        let max_rows_by_limit = (self.buffer_limit() / (w as u64 * biggest)).max(1);
        let rows_per_tile = (TILE_SAMPLES / (w as u64 * slots as u64))
            .clamp(1, max_rows_by_limit)
            .min(h as u64)
            .min(WORKGROUP as u64 * 65_535)
            .min(max_rows.max(1) as u64) as u32;
        let tile_px = rows_per_tile as u64 * w as u64;
        self.fits("one band of the image's samples", tile_px * biggest)?;
        pack.params.slots_per_sample = tile_px as u32;
        pack.params.at_spectra = (tile_px * spectra_px / 4) as u32;
        pack.params.at_probes = (tile_px * (1 + 2 * slots as u64)) as u32;
        pack.params.at_observed = pack.params.at_probes + (tile_px * probes_px / 16) as u32;
        Ok(BandSizes {
            rows_per_tile,
            tile_px,
            spectra_px,
            sample_spectra_px,
            observed_px,
            film_px,
            bands_px,
        })
    }

    /// Uploads the packed scene and makes the band's output buffers and
    /// the bind group that ties them to the tracer.
    fn upload(&self, pack: &Packed, sizes: &BandSizes) -> Result<Uploaded, GpuError> {
        let tile_px = sizes.tile_px;
        let read_only = wgpu::BufferUsages::STORAGE;
        let tables = self.storage(
            &pack.tables_label,
            bytemuck::cast_slice(&pack.tables),
            read_only,
        )?;
        let disk = self.storage(
            "the disk texture",
            bytemuck::cast_slice(&pack.disk),
            read_only,
        )?;
        let sky = self.storage("the sky", bytemuck::cast_slice(&pack.sky), read_only)?;
        let objects = self.storage(
            "objects, lights and gas",
            bytemuck::cast_slice(&pack.objects),
            read_only,
        )?;
        // COPY_DST: adaptive sampling's lists are written into the film.
        let out_usage = wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST;
        let out = |label: &str, size: u64| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage: out_usage,
                mapped_at_creation: false,
            })
        };
        let film = out("film", tile_px * sizes.film_px);
        let spectra = out(
            "spectra",
            tile_px * (sizes.spectra_px + sizes.sample_spectra_px),
        );
        let bands = out("bands", tile_px * sizes.bands_px);
        let stats = self.storage("stats", &[0; 4 * STATS], out_usage)?;
        let params = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: std::mem::size_of::<pack::Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tracer"),
            layout: &self.layout,
            entries: &[
                (0, &params),
                (1, &tables),
                (2, &disk),
                (3, &sky),
                (4, &film),
                (5, &spectra),
                (6, &bands),
                (7, &stats),
                (8, &objects),
            ]
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            }),
        });
        Ok(Uploaded {
            bind,
            params,
            film,
            spectra,
            bands,
            stats,
            inputs: [tables, disk, sky, objects],
        })
    }
}

/// How a prepared scene's image is cut into bands of rows, and the bytes
/// per pixel of each output.
struct BandSizes {
    rows_per_tile: u32,
    /// Pixels in a band.
    tile_px: u64,
    /// Kept spectra; each sample's spectrum (when spectra or bands are kept).
    spectra_px: u64,
    sample_spectra_px: u64,
    /// Each pixel's observables (OBSERVE).
    observed_px: u64,
    /// The film, the sample slots and the probes.
    film_px: u64,
    /// The bloom bands.
    bands_px: u64,
}

/// The buffers of a prepared scene on the device.
struct Uploaded {
    bind: wgpu::BindGroup,
    params: wgpu::Buffer,
    film: wgpu::Buffer,
    spectra: wgpu::Buffer,
    bands: wgpu::Buffer,
    stats: wgpu::Buffer,
    /// The scene's tables, disk, sky and objects.
    inputs: [wgpu::Buffer; 4],
}

/// A scene uploaded to the GPU with its compiled shader, ready to render
/// (again).
pub struct Prepared<'a> {
    pub(super) gpu: &'a Gpu,
    /// Set from outside to stop a render between bands and passes.
    pub(super) stop: Option<Arc<std::sync::atomic::AtomicBool>>,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) samples: u32,
    pub(super) slots: u32,
    /// Renders refine adaptively (see `refine.rs`).
    pub(super) adaptive: Option<super::refine::Adaptive>,
    pub(super) nm: Vec<f64>,
    /// An observed scene's frequencies (Hz): its spectra's channels.
    pub(super) frequencies: Vec<f64>,
    /// How the scene shows its film (for the display on the GPU).
    pub(super) look: display::Look,
    /// The display's buffers and texture, made on first use.
    pub(super) display: Mutex<Option<display::Display>>,
    /// Where the bloomed image is read back to, made on first use.
    pub(super) shown_rb: Mutex<Option<wgpu::Buffer>>,
    pub(super) rows_per_tile: u32,
    pub(super) spectra_px: u64,
    pub(super) bands_px: u64,
    pub(super) pack: Packed,
    pub(super) pipelines: Arc<Pipelines>,
    pub(super) bind: wgpu::BindGroup,
    pub(super) params: wgpu::Buffer,
    pub(super) film: wgpu::Buffer,
    pub(super) spectra: wgpu::Buffer,
    pub(super) bands: wgpu::Buffer,
    pub(super) stats: wgpu::Buffer,
    pub(super) film_rb: wgpu::Buffer,
    /// Where each pixel's observables are read back (OBSERVE).
    pub(super) observed_rb: wgpu::Buffer,
    /// The observables the scene asks for, in its order.
    pub(super) observables: Vec<Observable>,
    pub(super) spectra_rb: wgpu::Buffer,
    pub(super) bands_rb: wgpu::Buffer,
    #[cfg(not(target_arch = "wasm32"))]
    pub(super) stats_rb: wgpu::Buffer,
    /// The browser's last counts read back (they come after the frame),
    /// with the number of the view they belong to.
    #[cfg(target_arch = "wasm32")]
    pub(super) late_stats: Arc<Mutex<(u64, Option<Vec<u32>>)>>,
    /// Stamps of each compute pass, where the device has them.
    pub(super) timer: Option<Timer>,
    /// The GPU's own time for the last render (s).
    pub(super) device_seconds: Mutex<Option<f64>>,
    // Kept alive for the bind group.
    pub(super) _inputs: [wgpu::Buffer; 4],
}

impl Prepared<'_> {
    /// Moves to the frame `scene` is at now (after [`Scene::set_time`]):
    /// its camera and time, and the disk light's turned patches. The scene
    /// must be the one prepared.
    pub fn set_frame(&mut self, scene: &Scene) -> Result<(), GpuError> {
        pack::set_frame(&mut self.pack.params, scene);
        if !scene.lighting.glow.is_empty() {
            let mut params = self.pack.params;
            let (objects, _) = pack::pack_objects(scene, &mut params)?;
            self.gpu
                .queue
                .write_buffer(&self._inputs[3], 0, bytemuck::cast_slice(&objects));
        }
        Ok(())
    }

    /// Renders stop with [`GpuError::Stopped`] between bands of rows and
    /// passes once `flag` is set.
    pub fn stop_on(&mut self, flag: Arc<std::sync::atomic::AtomicBool>) {
        self.stop = Some(flag);
    }

    pub(super) fn check_stop(&self) -> Result<(), GpuError> {
        match &self.stop {
            Some(f) if f.load(std::sync::atomic::Ordering::Relaxed) => Err(GpuError::Stopped),
            _ => Ok(()),
        }
    }
}
