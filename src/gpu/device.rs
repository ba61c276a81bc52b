//! The device: opening an adapter, its error and device-lost sinks, the
//! tracer's bind group layout, the cache of compiled pipelines keyed by
//! variant, and uploads within the adapter's limits.

use super::layout::Variant;
use super::{GpuError, display, shader_source};
use std::sync::{Arc, Mutex};

#[cfg(not(target_arch = "wasm32"))]
use super::ensure_runtime_dir;

/// An opened GPU device.
pub struct Gpu {
    pub(super) adapter: wgpu::Adapter,
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) info: wgpu::AdapterInfo,
    pub(super) limits: wgpu::Limits,
    pub(super) errors: Arc<Mutex<Vec<String>>>,
    pub(super) lost: Arc<Mutex<Option<String>>>,
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) pipeline_layout: wgpu::PipelineLayout,
    pub(super) pipelines: Mutex<Vec<(Variant, Arc<Pipelines>)>>,
    /// The display's passes, compiled on first use.
    pub(super) display: Mutex<Option<Arc<display::DisplayPipelines>>>,
    /// Disk-and-sky scenes of the exact model take the closed form
    /// (`physics.closed_form`) on this device; see [`Gpu::set_closed_form`].
    pub(super) closed_form: bool,
    /// The device stamps the start and end of passes with its own clock.
    pub(super) timestamps: bool,
}

/// The two passes of a specialised shader.
pub(super) struct Pipelines {
    pub(super) trace: wgpu::ComputePipeline,
    pub(super) resolve: wgpu::ComputePipeline,
}

/// Waits for `f` (the native backends answer at once or on a poll).
#[cfg(not(target_arch = "wasm32"))]
pub(super) fn block_on<F: std::future::Future>(f: F) -> F::Output {
    pollster::block_on(f)
}

/// Bindings: the parameters, then eight storage buffers (see common.wgsl).
const BINDINGS: u32 = 9;

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
        let (layout, pipeline_layout) = tracer_layouts(&device);
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
    pub(super) fn settle(&self, scope: wgpu::ErrorScopeGuard) -> Result<(), GpuError> {
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

    /// The passes of the shader of variant `v`.
    pub(super) fn pipelines(&self, v: &Variant) -> Result<Arc<Pipelines>, GpuError> {
        let mut cache = self.pipelines.lock().expect("pipeline cache");
        if let Some((_, p)) = cache.iter().find(|(k, _)| k == v) {
            return Ok(p.clone());
        }
        let (trace, resolve) = self.build(&shader_source(v))?;
        let p = Arc::new(Pipelines { trace, resolve });
        cache.push((*v, p.clone()));
        Ok(p)
    }

    /// The display's passes.
    pub(super) fn display_pipelines(&self) -> Result<Arc<display::DisplayPipelines>, GpuError> {
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

    pub(super) fn build(
        &self,
        source: &str,
    ) -> Result<(wgpu::ComputePipeline, wgpu::ComputePipeline), GpuError> {
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = self
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("blackhole tracer"),
                source: shader(source),
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
    pub(super) fn storage(
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
    pub(super) fn buffer_limit(&self) -> u64 {
        self.limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size)
    }

    pub(super) fn fits(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
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
}

/// The tracer's bind group layout (the parameters, then the storage
/// buffers; see common.wgsl) and its pipeline layout.
fn tracer_layouts(device: &wgpu::Device) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
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
    (layout, pipeline_layout)
}

/// `source` as the driver gets it: natively the IR without the code the
/// variant's switches turn off ([`super::specialise`]), in the browser the
/// text (its compiler drops dead code itself). Text that does not parse
/// goes as it is, for wgpu's own error.
fn shader(source: &str) -> wgpu::ShaderSource<'static> {
    #[cfg(not(target_arch = "wasm32"))]
    if let Ok(mut module) = naga::front::wgsl::parse_str(source) {
        super::specialise::specialise(&mut module);
        return wgpu::ShaderSource::Naga(std::borrow::Cow::Owned(module));
    }
    wgpu::ShaderSource::Wgsl(source.to_string().into())
}
