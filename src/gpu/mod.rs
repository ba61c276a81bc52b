//! The GPU backend: the per-sample work of [`Scene::render`] as WGSL
//! compute shaders through `wgpu`, filling the same [`Film`] and [`Stats`].
//!
//! The scene is built and validated on the CPU as for the CPU backend;
//! [`pack`] flattens it into buffers. The shader ([`shader_source`]: a
//! header written from [`layout`], then common, spacetime, physics,
//! closed, shade, objects and main `.wgsl`) is specialised per scene
//! variant and traces one sample per invocation in f32, in units of r_s
//! (design notes: `src/gpu/README.md`). The image is rendered
//! in bands of rows small enough for the adapter's buffer limits and read
//! back band by band; output stays on the CPU, shared with the CPU backend.
//! The display ([`display`]: adding passes up, bloom, tone curve, sRGB) runs
//! on the GPU too, so that the viewer shows frames without reading them
//! back and `render` reads back the bloomed image, not the bloom bands.

mod display;
mod layout;
mod pack;
#[cfg(not(target_arch = "wasm32"))]
mod runtime;

use crate::film::{BANDS, Film, Observable, PixelProbe, SampleClass, Stats};
use crate::scene::Scene;
use glam::Vec3;
use pack::Packed;
use std::sync::{Arc, Mutex};
use thiserror::Error;

pub use pack::MIN_GPU_TOLERANCE;
#[cfg(not(target_arch = "wasm32"))]
pub use runtime::ensure_runtime_dir;

/// Why the GPU backend cannot render.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter could be opened.
    #[error(
        "no GPU adapter found ({0}). For software rendering install Vulkan's CPU driver \
         (Debian/Ubuntu: apt-get install mesa-vulkan-drivers libvulkan1, which provide \
         lavapipe); if WGPU_BACKEND is set, it must name a backend this machine has; \
         or render with --backend cpu"
    )]
    NoAdapter(String),
    /// The scene holds something the GPU backend does not do yet.
    #[error("the GPU backend does not render {table} yet ({why}); use --backend cpu")]
    Unsupported {
        /// The config table or key.
        table: String,
        /// What is missing.
        why: String,
    },
    /// A buffer would exceed the adapter's limits.
    #[error(
        "{what} needs {need_mib:.1} MiB in one GPU buffer; the adapter allows {limit_mib:.1} MiB"
    )]
    TooLarge {
        /// Which data.
        what: String,
        /// Needed (MiB).
        need_mib: f64,
        /// Allowed (MiB).
        limit_mib: f64,
    },
    /// The shader did not compile or validate.
    #[error("GPU shader: {0}")]
    Shader(String),
    /// The device was lost (driver reset, out of memory...).
    #[error("the GPU device was lost: {0}")]
    DeviceLost(String),
    /// Any other error reported by the device.
    #[error("GPU: {0}")]
    Device(String),
    /// The render was stopped from outside ([`Prepared::stop_on`]).
    #[error("the render was stopped")]
    Stopped,
}

/// Checks that the GPU backend can render everything in `scene`.
pub fn check_supported(scene: &Scene) -> Result<(), GpuError> {
    if scene.spectral.as_ref().is_some_and(|s| s.per_wavelength) {
        return Err(GpuError::Unsupported {
            table: "spectral.per_wavelength = true".into(),
            why: "one ray per wavelength is the CPU's reference path; one geodesic per sample gives the same image".into(),
        });
    }
    if scene.clouds.len() > pack::MAX_GPU_CLOUDS {
        return Err(GpuError::Unsupported {
            table: "[[cloud]]".into(),
            why: format!(
                "{} clouds; the GPU marches at most {}",
                scene.clouds.len(),
                pack::MAX_GPU_CLOUDS
            ),
        });
    }
    check_time(scene, "--time", scene.time * scene.r_s / crate::units::C)?;
    let suns = scene.lighting.suns.len();
    if suns > MAX_GPU_SUNS {
        return Err(GpuError::Unsupported {
            table: "[[light]]".into(),
            why: format!("{suns} suns; the GPU lights surfaces with at most {MAX_GPU_SUNS}"),
        });
    }
    Ok(())
}

/// Refuses an instant `t` (s; `key` names where it comes from) by which
/// the disk has turned too far for the shader: its time and angles are
/// f32, and 2^14 rad keep the angle to 2^14 epsilon, 2e-3 rad, a third of
/// a texel of the shipped disk.
pub fn check_time(scene: &Scene, key: &str, t: f64) -> Result<(), GpuError> {
    const MAX_GPU_PHASE: f64 = 16_384.0;
    scene
        .check_phase(key, t, MAX_GPU_PHASE, f32::EPSILON as f64)
        .map_err(|e| GpuError::Unsupported {
            table: format!("this time ({key})"),
            why: format!("{e}, as the GPU computes the disk's turn in f32"),
        })
}

/// The display's shader (see [`display`]).
pub(crate) fn display_source() -> String {
    layout::display_header() + include_str!("display.wgsl")
}

/// The whole shader of a variant: its `header` (see [`layout::header`]),
/// then the WGSL files.
pub(crate) fn shader_source(header: &str) -> String {
    [
        header,
        include_str!("common.wgsl"),
        include_str!("spacetime.wgsl"),
        include_str!("kerr.wgsl"),
        include_str!("physics.wgsl"),
        include_str!("closed.wgsl"),
        include_str!("kerr_closed.wgsl"),
        include_str!("shade.wgsl"),
        include_str!("objects.wgsl"),
        include_str!("main.wgsl"),
    ]
    .join("\n")
}

/// Most suns the GPU lights surfaces with.
pub(crate) const MAX_GPU_SUNS: usize = 8;

/// An opened GPU device.
pub struct Gpu {
    adapter: wgpu::Adapter,
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    limits: wgpu::Limits,
    errors: Arc<Mutex<Vec<String>>>,
    lost: Arc<Mutex<Option<String>>>,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    pipelines: Mutex<Vec<(String, Arc<Pipelines>)>>,
    /// The display's passes, compiled on first use.
    display: Mutex<Option<Arc<display::DisplayPipelines>>>,
    /// Disk-and-sky scenes of the exact model take the closed form
    /// (`physics.closed_form`) on this device; see [`Gpu::set_closed_form`].
    closed_form: bool,
    /// The device stamps the start and end of passes with its own clock.
    timestamps: bool,
}

/// The start and end stamps of each compute pass of a render (a band of
/// rows, the display), resolved and read back together.
struct Timer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
}

/// Passes stamped before the stamps are read back.
const TIMER_PAIRS: u32 = 64;

/// The two passes of a specialised shader.
struct Pipelines {
    trace: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

/// Waits for `f` (the native backends answer at once or on a poll).
#[cfg(not(target_arch = "wasm32"))]
fn block_on<F: std::future::Future>(f: F) -> F::Output {
    pollster::block_on(f)
}

/// Bindings: the parameters, then eight storage buffers (see common.wgsl).
const BINDINGS: u32 = 9;

const WORKGROUP: u32 = 8;
/// Samples per dispatch: a band of rows of about this many pixel samples.
const TILE_SAMPLES: u64 = 1 << 22;
use layout::{OBSERVED_VEC4S, STATS, Stat};

impl Gpu {
    /// Opens the best adapter (`WGPU_BACKEND` may restrict the backends).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new() -> Result<Gpu, GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        block_on(Gpu::open(&instance, None))
    }

    /// The GPU that can draw to `surface` (a window's), from the instance
    /// the surface was made by.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn for_surface(
        instance: &wgpu::Instance,
        surface: &wgpu::Surface<'_>,
    ) -> Result<Gpu, GpuError> {
        block_on(Gpu::open(instance, Some(surface)))
    }

    /// [`Gpu::for_surface`] for the browser, where the adapter and device
    /// come as promises the page's event loop resolves.
    pub async fn for_surface_async(
        instance: &wgpu::Instance,
        surface: &wgpu::Surface<'_>,
    ) -> Result<Gpu, GpuError> {
        Gpu::open(instance, Some(surface)).await
    }

    async fn open(
        instance: &wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Gpu, GpuError> {
        // Before Vulkan lists its devices (see runtime.rs).
        #[cfg(not(target_arch = "wasm32"))]
        ensure_runtime_dir();
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: surface,
                ..Default::default()
            })
            .await
            .map_err(|e| {
                let backends = std::env::var("WGPU_BACKEND")
                    .map(|b| format!("WGPU_BACKEND={b}"))
                    .unwrap_or_else(|_| "every backend tried".into());
                GpuError::NoAdapter(format!("{backends}: {e}"))
            })?;
        let info = adapter.get_info();
        let limits = adapter.limits();
        // The GPU's own time for the closing line, where the adapter can
        // stamp passes. Not on CPU devices: there the device's time is the
        // host's, and lavapipe's stamps miss the work of a pass once
        // another pipeline (the display's) has run between its passes
        // (a 480 x 270 trace of 80 ms measured 4 ms).
        // Nor in the browser, which cannot wait for the stamps' read-back.
        let features = if info.device_type == wgpu::DeviceType::Cpu || cfg!(target_arch = "wasm32")
        {
            wgpu::Features::empty()
        } else {
            adapter.features() & wgpu::Features::TIMESTAMP_QUERY
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("blackhole"),
                required_features: features,
                required_limits: limits.clone(),
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| GpuError::Device(format!("cannot open {}: {e}", info.name)))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().expect("error list").push(e.to_string());
        }));
        let lost = Arc::new(Mutex::new(None));
        let sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            *sink.lock().expect("lost flag") = Some(format!("{reason:?}: {message}"));
        });
        let entry = |binding: u32| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match binding {
                    0 => wgpu::BufferBindingType::Uniform,
                    4..=7 => wgpu::BufferBindingType::Storage { read_only: false },
                    _ => wgpu::BufferBindingType::Storage { read_only: true },
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..BINDINGS).map(entry).collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tracer"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tracer"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let closed_form = info.device_type != wgpu::DeviceType::Cpu;
        Ok(Gpu {
            adapter,
            device,
            queue,
            info,
            limits,
            errors,
            lost,
            layout,
            pipeline_layout,
            pipelines: Mutex::new(Vec::new()),
            display: Mutex::new(None),
            closed_form,
            timestamps: !features.is_empty(),
        })
    }

    /// Whether scenes that allow it (`physics.closed_form`, see
    /// `Scene::closed_form`) trace their rays in closed form here. By
    /// default on GPUs, where it pays (1080p spectral frame on an H200:
    /// 15.8 ms against 49.2 ms integrated), and not on CPU devices such as
    /// lavapipe, where the integrator measured faster (1.0 s against
    /// 1.1 s RGB, 2.5 s against 3.4 s spectral, on 2 cores). Both give the
    /// same image to within f32 (tested).
    pub fn set_closed_form(&mut self, on: bool) {
        self.closed_form = on;
    }

    /// Whether scenes that allow it take the closed form here (see
    /// [`Gpu::set_closed_form`]).
    pub fn closed_form(&self) -> bool {
        self.closed_form
    }

    /// Whether the device stamps passes with its own clock (the GPU time
    /// of [`Prepared::device_seconds`]).
    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }

    /// Whether the device is a CPU (software Vulkan such as lavapipe).
    pub fn is_cpu(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// The adapter, as "name (backend, device type)".
    pub fn name(&self) -> String {
        format!(
            "{} ({:?}, {:?})",
            self.info.name, self.info.backend, self.info.device_type
        )
    }

    /// The adapter (for a window's surface capabilities).
    pub fn adapter(&self) -> &wgpu::Adapter {
        &self.adapter
    }

    /// The device (for drawing a window with the same GPU).
    pub fn device(&self) -> &wgpu::Device {
        &self.device
    }

    /// The queue.
    pub fn queue(&self) -> &wgpu::Queue {
        &self.queue
    }

    /// Fails with what the device reported since the last check.
    pub fn check(&self) -> Result<(), GpuError> {
        // Runs pending callbacks (a lost device's among them).
        let _ = self.device.poll(wgpu::PollType::Poll);
        if let Some(reason) = self.lost.lock().expect("lost flag").take() {
            return Err(GpuError::DeviceLost(reason));
        }
        let mut errors = self.errors.lock().expect("error list");
        if !errors.is_empty() {
            let all = errors.join("; ");
            errors.clear();
            return Err(GpuError::Device(all));
        }
        Ok(())
    }

    /// Fails with the errors `scope` caught (a shader that does not
    /// compile). The browser cannot wait for them: there they are handed
    /// to the error list when they come, and [`Gpu::check`] reports them.
    fn settle(&self, scope: wgpu::ErrorScopeGuard) -> Result<(), GpuError> {
        #[cfg(not(target_arch = "wasm32"))]
        if let Some(e) = block_on(scope.pop()) {
            return Err(GpuError::Shader(e.to_string()));
        }
        #[cfg(target_arch = "wasm32")]
        {
            let sink = self.errors.clone();
            let popped = scope.pop();
            wasm_bindgen_futures::spawn_local(async move {
                if let Some(e) = popped.await {
                    sink.lock().expect("error list").push(e.to_string());
                }
            });
        }
        Ok(())
    }

    /// The passes of the shader specialised by `header`.
    fn pipelines(&self, header: &str) -> Result<Arc<Pipelines>, GpuError> {
        let mut cache = self.pipelines.lock().expect("pipeline cache");
        if let Some((_, p)) = cache.iter().find(|(h, _)| h == header) {
            return Ok(p.clone());
        }
        let (trace, resolve) = self.build(&shader_source(header))?;
        let p = Arc::new(Pipelines { trace, resolve });
        cache.push((header.to_string(), p.clone()));
        Ok(p)
    }

    /// The display's passes.
    fn display_pipelines(&self) -> Result<Arc<display::DisplayPipelines>, GpuError> {
        let mut slot = self.display.lock().expect("display pipelines");
        if let Some(p) = slot.as_ref() {
            return Ok(p.clone());
        }
        let p = Arc::new(display::DisplayPipelines::new(self)?);
        *slot = Some(p.clone());
        Ok(p)
    }

    /// Compiles WGSL with `main` and `resolve` entry points (a named error
    /// if it does not compile).
    #[doc(hidden)]
    pub fn compile(&self, wgsl: &str) -> Result<(), GpuError> {
        self.build(wgsl).map(|_| ())
    }

    /// Destroys the device, as a driver reset would (for tests).
    #[doc(hidden)]
    pub fn destroy_device(&self) {
        self.device.destroy();
    }

    fn build(
        &self,
        source: &str,
    ) -> Result<(wgpu::ComputePipeline, wgpu::ComputePipeline), GpuError> {
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("blackhole tracer"),
                source: wgpu::ShaderSource::Wgsl(source.to_string().into()),
            });
        let pipeline = |entry: &str| {
            self.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(entry),
                    layout: Some(&self.pipeline_layout),
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    cache: None,
                })
        };
        let (trace, resolve) = (pipeline("main"), pipeline("resolve"));
        self.settle(scope)?;
        self.check()?;
        Ok((trace, resolve))
    }

    /// A buffer holding `bytes` (written through the queue, so that a lost
    /// device gives an error rather than a failed mapping).
    fn storage(
        &self,
        label: &str,
        bytes: &[u8],
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        self.fits(label, bytes.len() as u64)?;
        let buf = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (bytes.len() as u64).max(4),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        self.queue.write_buffer(&buf, 0, bytes);
        Ok(buf)
    }

    /// The largest buffer a binding may hold.
    fn buffer_limit(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    fn fits(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let limit = self.buffer_limit();
        if bytes > limit {
            return Err(GpuError::TooLarge {
                what: what.into(),
                need_mib: bytes as f64 / (1 << 20) as f64,
                limit_mib: limit as f64 / (1 << 20) as f64,
            });
        }
        Ok(())
    }

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
        self.prepare_slots(scene, max_rows, scene.samples)
    }

    /// [`Gpu::prepare`] for rendering in passes of `per_pass` samples
    /// ([`Prepared::render_pass`]): the sample slots are sized for a pass,
    /// so bands of rows can be as tall as the whole image.
    pub fn prepare_passes(&self, scene: &Scene, per_pass: u32) -> Result<Prepared<'_>, GpuError> {
        self.prepare_slots(scene, u32::MAX, per_pass.clamp(1, scene.samples))
    }

    fn prepare_slots(
        &self,
        scene: &Scene,
        max_rows: u32,
        slots: u32,
    ) -> Result<Prepared<'_>, GpuError> {
        check_supported(scene)?;
        self.check()?;
        let mut pack = Packed::new(scene)?;
        pack.closed &= self.closed_form;
        let pipelines = self.pipelines(&pack.shader_header())?;
        let (w, h) = (scene.camera.width, scene.camera.height);
        let spp = scene.samples;
        if spp > 65_535 {
            return Err(GpuError::Unsupported {
                table: "image.samples".into(),
                why: format!("{spp} samples per pixel; the GPU takes at most 65535"),
            });
        }
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
        let probes_px = if pack.observe { 16 * slots as u64 } else { 0 };
        let film_px = 16 + 32 * slots as u64 + probes_px + observed_px;
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

        let read_only = wgpu::BufferUsages::STORAGE;
        let tables = self.storage("tables", bytemuck::cast_slice(&pack.tables), read_only)?;
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
        let out_usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
        let out = |label: &str, size: u64| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage: out_usage,
                mapped_at_creation: false,
            })
        };
        let film = out("film", tile_px * film_px);
        let spectra = out("spectra", tile_px * (spectra_px + sample_spectra_px));
        let bands = out("bands", tile_px * bands_px);
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
        let readback = |size: u64| self.readback("readback", size);
        let timer = self.timestamps.then(|| Timer {
            queries: self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass times"),
                ty: wgpu::QueryType::Timestamp,
                count: 2 * TIMER_PAIRS,
            }),
            resolved: self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pass times"),
                size: wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT * TIMER_PAIRS as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            readback: readback(16 * TIMER_PAIRS as u64),
        });
        let nm = scene
            .spectral
            .as_ref()
            .map_or(Vec::new(), |c| c.wavelengths.nm.clone());
        let look = display::Look::of(scene, &nm, pack.bands);
        Ok(Prepared {
            stop: None,
            gpu: self,
            timer,
            device_seconds: Mutex::new(None),
            width: w,
            height: h,
            samples: spp,
            slots,
            nm,
            look,
            display: Mutex::new(None),
            shown_rb: Mutex::new(None),
            rows_per_tile,
            spectra_px,
            bands_px,
            film_rb: readback(tile_px * 16),
            observed_rb: readback(tile_px * observed_px),
            observables: scene.observables.clone(),
            spectra_rb: readback(tile_px * spectra_px),
            bands_rb: readback(tile_px * bands_px),
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
            _inputs: [tables, disk, sky, objects],
        })
    }

    /// A buffer of `size` bytes to copy results into and read back.
    fn readback(&self, label: &str, size: u64) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        })
    }

    /// Maps `buf`, copies out its first `size` bytes as `T`s, unmaps.
    fn read<T: bytemuck::Pod>(&self, buf: &wgpu::Buffer, size: u64) -> Result<Vec<T>, GpuError> {
        self.read_with(buf, size, |v: &[T]| v.to_vec())
    }

    /// [`Gpu::read`] handing the mapped words to `f` instead of copying
    /// them out (a 1080p film is 33 MB a frame).
    fn read_with<T: bytemuck::Pod, R>(
        &self,
        buf: &wgpu::Buffer,
        size: u64,
        f: impl FnOnce(&[T]) -> R,
    ) -> Result<R, GpuError> {
        if cfg!(target_arch = "wasm32") {
            return Err(GpuError::Device(
                "the browser cannot wait for the GPU's results: read them back with a callback"
                    .into(),
            ));
        }
        let slice = buf.slice(..size);
        let done = Arc::new(Mutex::new(None));
        let flag = done.clone();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            *flag.lock().expect("map flag") = Some(r);
        });
        // Another thread's poll may run this mapping's callback just after
        // ours returns: wait for the callback itself.
        let mut tries = 0u32;
        let result = loop {
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| GpuError::Device(format!("waiting for the GPU: {e}")))?;
            self.check()?;
            if let Some(r) = done.lock().expect("map flag").take() {
                break r;
            }
            tries += 1;
            if tries > 10_000 {
                return Err(GpuError::Device("the GPU did not finish".into()));
            }
            std::thread::sleep(std::time::Duration::from_millis(1));
        };
        result.map_err(|e| GpuError::Device(format!("reading results back: {e}")))?;
        let out = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Device(format!("reading results back: {e}")))?;
            f(bytemuck::cast_slice::<u8, T>(&view))
        };
        buf.unmap();
        Ok(out)
    }
}

/// A scene uploaded to the GPU with its compiled shader, ready to render
/// (again).
pub struct Prepared<'a> {
    gpu: &'a Gpu,
    /// Set from outside to stop a render between bands and passes.
    stop: Option<Arc<std::sync::atomic::AtomicBool>>,
    width: u32,
    height: u32,
    samples: u32,
    slots: u32,
    nm: Vec<f64>,
    /// How the scene shows its film (for the display on the GPU).
    look: display::Look,
    /// The display's buffers and texture, made on first use.
    display: Mutex<Option<display::Display>>,
    /// Where the bloomed image is read back to, made on first use.
    shown_rb: Mutex<Option<wgpu::Buffer>>,
    rows_per_tile: u32,
    spectra_px: u64,
    bands_px: u64,
    pack: Packed,
    pipelines: Arc<Pipelines>,
    bind: wgpu::BindGroup,
    params: wgpu::Buffer,
    film: wgpu::Buffer,
    spectra: wgpu::Buffer,
    bands: wgpu::Buffer,
    stats: wgpu::Buffer,
    film_rb: wgpu::Buffer,
    /// Where each pixel's observables are read back (OBSERVE).
    observed_rb: wgpu::Buffer,
    /// The observables the scene asks for, in its order.
    observables: Vec<Observable>,
    spectra_rb: wgpu::Buffer,
    bands_rb: wgpu::Buffer,
    #[cfg(not(target_arch = "wasm32"))]
    stats_rb: wgpu::Buffer,
    /// The browser's last counts read back (they come after the frame),
    /// with the number of the view they belong to.
    #[cfg(target_arch = "wasm32")]
    late_stats: Arc<Mutex<(u64, Option<Vec<u32>>)>>,
    /// Stamps of each compute pass, where the device has them.
    timer: Option<Timer>,
    /// The GPU's own time for the last render (s).
    device_seconds: Mutex<Option<f64>>,
    // Kept alive for the bind group.
    _inputs: [wgpu::Buffer; 4],
}

/// What a pass of samples keeps of each band of rows it traces.
#[derive(Clone, Copy)]
struct Want {
    /// Read the film (and the spectra when kept) back to the host.
    film: bool,
    /// ... and the bloom bands.
    bands: bool,
    /// Add the bands to the display's image.
    show: Option<Show>,
}

/// What the display does with a pass.
#[derive(Clone, Copy)]
struct Show {
    /// The pass starts the image again (else it is added to it).
    restart: bool,
    /// Encode the image into the 8-bit texture.
    encode: bool,
    /// Read the bloomed image back.
    read_bloomed: bool,
}

/// What a pass of samples gave.
struct Traced {
    width: u32,
    height: u32,
    xyz: Vec<Vec3>,
    kept: Vec<f32>,
    spectra: Vec<f32>,
    band_xyz: Vec<f32>,
    bloomed: Option<Vec<Vec3>>,
    /// Each pixel's observables (where the scene asks for them).
    observed: Vec<PixelProbe>,
    stats: Stats,
}

/// A frame of the viewer ([`Prepared::view_pass`]): its image is on the
/// GPU ([`Prepared::view_texture`]).
#[derive(Clone, Copy, Debug)]
pub struct ViewFrame {
    /// The image's size (smaller than the scene's for a preview).
    pub width: u32,
    pub height: u32,
    /// The pass's counts.
    pub stats: Stats,
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
        let bloom_here = self.look.bloom.is_some()
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

    /// Renders stop with [`GpuError::Stopped`] between bands of rows and
    /// passes once `flag` is set.
    pub fn stop_on(&mut self, flag: Arc<std::sync::atomic::AtomicBool>) {
        self.stop = Some(flag);
    }

    fn check_stop(&self) -> Result<(), GpuError> {
        match &self.stop {
            Some(f) if f.load(std::sync::atomic::Ordering::Relaxed) => Err(GpuError::Stopped),
            _ => Ok(()),
        }
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
    fn scaled_pass(
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

    /// The viewer's frame: samples `first..first + count` of every pixel,
    /// on an image `scale` times smaller each way (a preview) or whole,
    /// added to the view's image on the GPU (`restart`: the image starts
    /// again with them), bloomed and encoded into the 8-bit texture of
    /// [`Prepared::view_texture`]; only the counts are read back.
    pub fn view_pass(
        &self,
        first: u32,
        count: u32,
        scale: u32,
        restart: bool,
    ) -> Result<ViewFrame, GpuError> {
        let want = Want {
            film: false,
            bands: false,
            show: Some(Show {
                restart,
                encode: true,
                read_bloomed: false,
            }),
        };
        let t = self.scaled_pass(first, count, scale, &|_| {}, want)?;
        Ok(ViewFrame {
            width: t.width,
            height: t.height,
            stats: t.stats,
        })
    }

    /// The viewer's 8-bit sRGB texture (RGBA, the scene's size; a
    /// preview fills its top-left corner), for drawing.
    pub fn view_texture(&self) -> Result<wgpu::TextureView, GpuError> {
        self.with_display(|d| Ok(d.view().clone()))
    }

    /// The viewer's image as the window shows it: 8-bit sRGB RGB bytes of
    /// its top-left `width` x `height` (the last [`ViewFrame`]'s size).
    pub fn read_view(&self, width: u32, height: u32) -> Result<Vec<u8>, GpuError> {
        let (row, copy) = view_copy(width, height);
        self.read_display(row as u64 * height as u64, copy, |bytes: &[u8]| {
            unpadded_rgb(bytes, row, width)
        })
    }

    /// [`Prepared::read_view`] for the browser, which cannot wait for the
    /// GPU: `done` gets the bytes when they come.
    pub fn read_view_later(
        &self,
        width: u32,
        height: u32,
        done: impl FnOnce(Result<Vec<u8>, GpuError>) + Send + 'static,
    ) -> Result<(), GpuError> {
        let (row, copy) = view_copy(width, height);
        let buf = self.copy_display(row as u64 * height as u64, copy)?;
        read_later(buf, move |bytes| {
            done(bytes.map(|b| unpadded_rgb(b, row, width)))
        });
        Ok(())
    }

    /// The viewer's image before bloom and tone mapping: the mean XYZ of
    /// its samples so far, `width` x `height` (the last [`ViewFrame`]'s).
    pub fn read_view_film(&self, width: u32, height: u32) -> Result<Vec<Vec3>, GpuError> {
        let size = 16 * width as u64 * height as u64;
        let copy = |enc: &mut wgpu::CommandEncoder, d: &display::Display, buf: &wgpu::Buffer| {
            enc.copy_buffer_to_buffer(d.acc(), 0, buf, 0, size)
        };
        self.read_display(size, copy, |w: &[f32]| {
            w.chunks_exact(4)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect()
        })
    }

    /// `size` bytes of the display that `copy` copies into a read-back
    /// buffer, handed to `read` as `T`s.
    fn read_display<T: bytemuck::Pod, R>(
        &self,
        size: u64,
        copy: impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
        read: impl FnOnce(&[T]) -> R,
    ) -> Result<R, GpuError> {
        let buf = self.copy_display(size, copy)?;
        self.gpu.read_with(&buf, size, read)
    }

    /// A read-back buffer of `size` bytes into which `copy` copies from the
    /// display (submitted, not waited for).
    fn copy_display(
        &self,
        size: u64,
        copy: impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
    ) -> Result<wgpu::Buffer, GpuError> {
        let gpu = self.gpu;
        let buf = gpu.readback("the display, read back", size);
        self.with_display(|d| {
            let mut enc = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            copy(&mut enc, d, &buf);
            gpu.queue.submit([enc.finish()]);
            Ok(())
        })?;
        Ok(buf)
    }

    /// Runs `f` on the display, made first if need be.
    fn with_display<R>(
        &self,
        f: impl FnOnce(&mut display::Display) -> Result<R, GpuError>,
    ) -> Result<R, GpuError> {
        let mut slot = self.display.lock().expect("display");
        if slot.is_none() {
            *slot = Some(display::Display::new(
                self.gpu,
                self.gpu.display_pipelines()?,
                self.look.clone(),
                &self.film,
                &self.bands,
                self.width,
                self.height,
            )?);
        }
        f(slot.as_mut().expect("made"))
    }

    /// The GPU's own time (s) for the last render or pass, from its
    /// timestamps: the tracing, resolving and display passes without the
    /// host's waits, uploads and read-backs. None where the device has no
    /// timestamps.
    pub fn device_seconds(&self) -> Option<f64> {
        *self.device_seconds.lock().expect("device time")
    }

    fn start_device_time(&self) {
        *self.device_seconds.lock().expect("device time") = None;
    }

    fn add_device_time(&self, seconds: f64) {
        *self
            .device_seconds
            .lock()
            .expect("device time")
            .get_or_insert(0.0) += seconds;
    }

    /// The film and counts of a traced pass.
    fn to_pass(&self, t: Traced) -> Pass {
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

    /// Resolves the stamps of the `pair`-th pass, in the command buffer of
    /// the pass itself (lavapipe's stamps resolved in a later submission
    /// measured only a fraction of the work).
    fn resolve_stamps(&self, enc: &mut wgpu::CommandEncoder, pair: u32) {
        if let Some(t) = &self.timer {
            let at = wgpu::QUERY_RESOLVE_BUFFER_ALIGNMENT * pair as u64;
            enc.resolve_query_set(&t.queries, 2 * pair..2 * pair + 2, &t.resolved, at);
            enc.copy_buffer_to_buffer(&t.resolved, at, &t.readback, 16 * pair as u64, 16);
        }
    }

    /// Reads back the stamps of the first `pairs` passes since the last
    /// read (resolved by [`Prepared::resolve_stamps`]): their GPU time (s).
    fn read_times(&self, pairs: u32) -> Result<f64, GpuError> {
        let (Some(t), true) = (&self.timer, pairs > 0) else {
            return Ok(0.0);
        };
        let gpu = self.gpu;
        let stamps: Vec<u64> = gpu.read(&t.readback, 16 * pairs as u64)?;
        let ticks: u64 = stamps
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]))
            .sum();
        Ok(ticks as f64 * gpu.queue.get_timestamp_period() as f64 * 1e-9)
    }

    /// The timestamp writes of the `pair`-th compute pass, where the device
    /// has them.
    fn stamps(&self, pair: u32) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        self.timer
            .as_ref()
            .map(|t| wgpu::ComputePassTimestampWrites {
                query_set: &t.queries,
                beginning_of_pass_write_index: Some(2 * pair),
                end_of_pass_write_index: Some(2 * pair + 1),
            })
    }

    /// Samples `first..first + count` of rows `rows` of the image `scale`
    /// times smaller each way, band by band, keeping what `want` asks.
    fn pass(
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
        let pack = &self.pack;
        let n_wl = pack.n_wl as u64;
        let (spectra_px, bands_px) = (self.spectra_px, self.bands_px);
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
        let reserve = |on: bool, n: usize| if on { n } else { 0 };
        let mut xyz = Vec::with_capacity(reserve(want.film, npx));
        let mut kept = Vec::with_capacity(reserve(want.film, npx));
        let mut spectra =
            Vec::with_capacity(reserve(want.film && pack.keep_spectra, npx * n_wl as usize));
        let band_words = 3 * BANDS;
        let read_bands = want.film && want.bands && pack.bands;
        let mut band_xyz: Vec<f32> = Vec::with_capacity(reserve(read_bands, npx * band_words));
        let read_observed = want.film && pack.observe;
        let mut observed = Vec::with_capacity(reserve(read_observed, npx));
        let mut device_seconds = 0.0;
        let mut pairs = 0;
        let mut y0 = rows.start;
        while y0 < rows.end {
            let rows = self.rows_per_tile.min(rows.end - y0);
            let mut params = pack.params;
            if scale != 1 {
                // A preview keeps the field of view on fewer, larger
                // pixels (whole renders keep the packed f64-derived aspect).
                params.width = w;
                params.height = h;
                params.cam_half_width = params.cam_half_height * w as f32 / h as f32;
            }
            params.tile_first_row = y0;
            params.tile_rows = rows;
            params.pass_first = first;
            params.pass_samples = count;
            gpu.queue
                .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
            if let Some(d) = display {
                d.set_band(gpu, w, h, y0, rows);
            }
            let mut enc = gpu
                .device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("trace"),
                    timestamp_writes: self.stamps(pairs),
                });
                pass.set_bind_group(0, &self.bind, &[]);
                let (gx, gy) = (w.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP));
                pass.set_pipeline(&self.pipelines.trace);
                pass.dispatch_workgroups(gx, gy, count);
                pass.set_pipeline(&self.pipelines.resolve);
                pass.dispatch_workgroups(gx, gy, 1);
                if let (Some(d), Some(p)) = (display, &accumulate) {
                    d.accumulate(&mut pass, p, w, rows);
                }
            }
            self.resolve_stamps(&mut enc, pairs);
            pairs += 1;
            let px = rows as u64 * w as u64;
            if want.film {
                enc.copy_buffer_to_buffer(&self.film, 0, &self.film_rb, 0, px * 16);
                if pack.keep_spectra {
                    enc.copy_buffer_to_buffer(
                        &self.spectra,
                        0,
                        &self.spectra_rb,
                        0,
                        px * spectra_px,
                    );
                }
            }
            if read_bands {
                enc.copy_buffer_to_buffer(&self.bands, 0, &self.bands_rb, 0, px * bands_px);
            }
            let observed_bytes = px * 16 * OBSERVED_VEC4S as u64;
            if read_observed {
                let at = 16 * pack.params.at_observed as u64;
                enc.copy_buffer_to_buffer(&self.film, at, &self.observed_rb, 0, observed_bytes);
            }
            gpu.queue.submit([enc.finish()]);
            if want.film {
                gpu.read_with(&self.film_rb, px * 16, |words: &[f32]| {
                    for c in words.chunks_exact(4) {
                        xyz.push(Vec3::new(c[0], c[1], c[2]));
                        kept.push(c[3]);
                    }
                })?;
                if pack.keep_spectra {
                    spectra.extend(gpu.read::<f32>(&self.spectra_rb, px * spectra_px)?);
                }
            }
            if read_bands {
                band_xyz.extend(gpu.read::<f32>(&self.bands_rb, px * bands_px)?);
            }
            if read_observed {
                gpu.read_with(&self.observed_rb, observed_bytes, |words: &[u32]| {
                    let per = 4 * OBSERVED_VEC4S as usize;
                    observed.extend(words.chunks_exact(per).map(pixel_probe));
                })?;
            }
            // The last pair is the display's.
            if pairs + 1 == TIMER_PAIRS {
                device_seconds += self.read_times(pairs)?;
                pairs = 0;
            }
            progress(rows as u64);
            self.check_stop()?;
            y0 += rows;
        }
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let mut bloomed_rb = None;
        if let (Some(d), Some(show)) = (display, want.show) {
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("display"),
                    timestamp_writes: self.stamps(pairs),
                });
                d.finish(&mut pass, w, h, show.encode);
            }
            self.resolve_stamps(&mut enc, pairs);
            pairs += 1;
            if show.read_bloomed && d.blooms() {
                let size = 16 * w as u64 * h as u64;
                let mut slot = self.shown_rb.lock().expect("bloomed read-back");
                let rb = slot.get_or_insert_with(|| {
                    let size = 16 * self.width as u64 * self.height as u64;
                    gpu.readback("the bloomed image, read back", size)
                });
                enc.copy_buffer_to_buffer(d.shown(), 0, rb, 0, size);
                bloomed_rb = Some((rb.clone(), size));
            }
        }
        #[cfg(not(target_arch = "wasm32"))]
        let s: Vec<u32> = {
            enc.copy_buffer_to_buffer(&self.stats, 0, &self.stats_rb, 0, 4 * STATS as u64);
            gpu.queue.submit([enc.finish()]);
            gpu.read(&self.stats_rb, 4 * STATS as u64)?
        };
        // The browser cannot wait: the counts come back when the GPU is
        // done, and a frame shows the last that came.
        #[cfg(target_arch = "wasm32")]
        let s: Vec<u32> = {
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
            self.late_stats
                .lock()
                .expect("late counts")
                .1
                .clone()
                .unwrap_or(stats_init.to_vec())
        };
        device_seconds += self.read_times(pairs)?;
        let bloomed = match bloomed_rb {
            Some((rb, size)) => Some(gpu.read_with(&rb, size, |w: &[f32]| {
                w.chunks_exact(4)
                    .map(|c| Vec3::new(c[0], c[1], c[2]))
                    .collect::<Vec<_>>()
            })?),
            None => None,
        };
        let samples = npx as u64 * count as u64;
        let at = |k: Stat| s[k.slot()];
        let count_of = |k: Stat| at(k) as u64;
        let g_found = at(Stat::GMax) != 0;
        let stats = Stats {
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
        };
        if self.timer.is_some() {
            self.add_device_time(device_seconds);
        }
        Ok(Traced {
            width: w,
            height: rows.len() as u32,
            xyz,
            kept,
            spectra,
            band_xyz,
            bloomed,
            observed,
            stats,
        })
    }
}

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
        let mix = |a: &mut [Vec3], b: &[Vec3], wa: &[f32], wb: &[f32]| {
            for (i, (x, y)) in a.iter_mut().zip(b).enumerate() {
                let n = wa[i] + wb[i];
                if n > 0.0 {
                    *x = (*x * wa[i] + *y * wb[i]) / n;
                }
            }
        };
        let (wa, wb) = (self.kept.clone(), other.kept.clone());
        let spread = |w: &[f32], per: usize| -> Vec<f32> {
            w.iter()
                .flat_map(|&k| std::iter::repeat_n(k, per))
                .collect()
        };
        mix(&mut self.film.xyz, &other.film.xyz, &wa, &wb);
        if let (Some(a), Some(b)) = (self.film.spectra.as_mut(), other.film.spectra.as_ref()) {
            let per = self.film.nm.len();
            let (sa, sb) = (spread(&wa, per), spread(&wb, per));
            for (i, (x, y)) in a.iter_mut().zip(b).enumerate() {
                let n = sa[i] + sb[i];
                if n > 0.0 {
                    *x = (*x * sa[i] + *y * sb[i]) / n;
                }
            }
        }
        if let (Some(a), Some(b)) = (self.film.bands.as_mut(), other.film.bands.as_ref()) {
            for ((_, pa), (_, pb)) in a.iter_mut().zip(b) {
                mix(pa, pb, &wa, &wb);
            }
        }
        for (a, b) in self.kept.iter_mut().zip(other.kept) {
            *a += b;
        }
        for (a, b) in self.observed.iter_mut().zip(&other.observed) {
            a.merge(b);
        }
        let order: Vec<Observable> = self.film.observables.iter().map(|(o, _)| *o).collect();
        self.film.observables = observable_maps(&order, &self.observed);
        self.stats = self.stats + other.stats;
        self
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
/// radius and time (f32), the least order plus one (0: none), and the
/// samples per class in their counter slots.
fn pixel_probe(w: &[u32]) -> PixelProbe {
    let mut classes = [0; 6];
    for (stat, class) in CLASSES {
        classes[class.code() as usize] = w[8 + stat.slot()];
    }
    PixelProbe {
        sums: [0, 1, 2].map(|i| f32::from_bits(w[i]) as f64),
        counts: [w[4], w[5], w[6]],
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

/// The bytes per row of the viewer's `width`-wide texture read back, and
/// the copy of its top-left `width` x `height` into a read-back buffer.
fn view_copy(
    width: u32,
    height: u32,
) -> (
    u32,
    impl FnOnce(&mut wgpu::CommandEncoder, &display::Display, &wgpu::Buffer),
) {
    let row = (4 * width).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let copy = move |enc: &mut wgpu::CommandEncoder, d: &display::Display, buf: &wgpu::Buffer| {
        enc.copy_texture_to_buffer(
            d.texture().as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: buf,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: None,
                },
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        )
    };
    (row, copy)
}

/// Maps the read-back buffer `buf` and hands its bytes to `f` when the GPU
/// has them, without waiting (the browser's read-back; natively `f` runs
/// on a later poll); unmapped after.
fn read_later(buf: wgpu::Buffer, f: impl FnOnce(Result<&[u8], GpuError>) + Send + 'static) {
    let mapped = buf.clone();
    buf.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let failed = |e: &dyn std::fmt::Display| GpuError::Device(format!("reading back: {e}"));
        match r
            .map_err(|e| failed(&e))
            .and_then(|()| mapped.slice(..).get_mapped_range().map_err(|e| failed(&e)))
        {
            Ok(view) => {
                f(Ok(&view));
                drop(view);
                mapped.unmap();
            }
            Err(e) => f(Err(e)),
        }
    });
}

/// RGB bytes of RGBA rows `row` bytes apart, `width` pixels each.
fn unpadded_rgb(bytes: &[u8], row: u32, width: u32) -> Vec<u8> {
    bytes
        .chunks_exact(row as usize)
        .flat_map(|r| {
            r[..4 * width as usize]
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
        })
        .collect()
}
