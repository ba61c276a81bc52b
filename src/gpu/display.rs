//! The display on the GPU (`display.wgsl`): the tracer's passes added up
//! over frames, bloom, exposure, the tone curve and the sRGB encoding, into
//! an 8-bit texture the viewer's window draws, with nothing read back; and
//! bloom for `render`, so that it reads back the bloomed XYZ instead of the
//! bloom bands. The same arithmetic as the host's `Pass::merged`,
//! `post::bloom` and `output::xyz_to_srgb8`, in f32.

use super::layout::{
    COLORMAP_LINEAR, COLORMAP_LOG, COLORMAP_NONE, DISPLAY_GROUP, DISPLAY_PIXELS, DisplayParams,
    TONE_ACES, TONE_CLIP, TONE_REINHARD,
};
use super::{Gpu, GpuError};
use crate::config::ToneMap;
use crate::film::BANDS;

/// The display's passes, compiled once per device.
pub(crate) struct DisplayPipelines {
    layout: wgpu::BindGroupLayout,
    /// `accumulate` by (restart, keep bands, encode), made on first use.
    accumulate: std::sync::Mutex<Vec<(AccumulateKind, wgpu::ComputePipeline)>>,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    blur_rows: wgpu::ComputePipeline,
    blur_columns: wgpu::ComputePipeline,
    tonemap: wgpu::ComputePipeline,
}

impl DisplayPipelines {
    pub(crate) fn new(gpu: &Gpu) -> Result<DisplayPipelines, GpuError> {
        let device = &gpu.device;
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let ty = |binding: u32| match binding {
            0 => wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<DisplayParams>() as u64),
            },
            1 | 2 | 7 => storage(true),
            8 => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba8Unorm,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            _ => storage(false),
        };
        let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..9)
            .map(|binding| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: ty(binding),
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("blackhole display"),
            source: wgpu::ShaderSource::Wgsl(super::display_source().into()),
        });
        let pipeline = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let p = DisplayPipelines {
            accumulate: std::sync::Mutex::new(Vec::new()),
            blur_rows: pipeline("blur_rows"),
            blur_columns: pipeline("blur_columns"),
            tonemap: pipeline("tonemap"),
            layout,
            module: module.clone(),
            pipeline_layout: pipeline_layout.clone(),
        };
        gpu.settle(scope)?;
        gpu.check()?;
        Ok(p)
    }
}

/// What an `accumulate` pipeline is specialised for (its pipeline
/// constants).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct AccumulateKind {
    /// The band starts the image again.
    pub restart: bool,
    /// The bloom bands are added too.
    pub keep_bands: bool,
    /// The pixels are encoded into the 8-bit texture as they are added.
    pub encode: bool,
}

impl DisplayPipelines {
    /// The `accumulate` pipeline of `kind`, compiled on first use.
    fn accumulate(
        &self,
        gpu: &Gpu,
        kind: AccumulateKind,
    ) -> Result<wgpu::ComputePipeline, GpuError> {
        let mut cache = self.accumulate.lock().expect("accumulate pipelines");
        if let Some((_, p)) = cache.iter().find(|(k, _)| *k == kind) {
            return Ok(p.clone());
        }
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let constants = [
            ("RESTART", flag(kind.restart)),
            ("KEEP_BANDS", flag(kind.keep_bands)),
            ("ENCODE", flag(kind.encode)),
        ];
        let scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let p = gpu
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("accumulate"),
                layout: Some(&self.pipeline_layout),
                module: &self.module,
                entry_point: Some("accumulate"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    ..Default::default()
                },
                cache: None,
            });
        gpu.settle(scope)?;
        cache.push((kind, p.clone()));
        Ok(p)
    }
}

/// How the scene shows its film: exposure, tone curve and bloom.
#[derive(Clone, Debug)]
pub(crate) struct Look {
    pub exposure: f64,
    pub tonemap: ToneMap,
    /// Bloom's Gaussians (`post::bloom_terms`).
    pub bloom: Option<Vec<crate::post::BloomTerm>>,
    /// Each plane's sigma relative to bloom's: 1 for the XYZ, or each
    /// band's centre over 550 nm with the bands kept.
    pub sigma_scale: Vec<f64>,
    /// An observed scene's false colour.
    pub radio: Option<crate::colormap::RadioLook>,
}

impl Look {
    /// Bloom's Gaussians (0 without bloom).
    fn terms(&self) -> u64 {
        self.bloom.as_ref().map_or(0, |t| t.len() as u64)
    }

    pub(crate) fn of(scene: &crate::scene::Scene, nm: &[f64], bands: bool) -> Look {
        let img = scene.image();
        Look {
            exposure: img.exposure,
            tonemap: img.tonemap,
            bloom: scene.config.bloom.as_ref().map(crate::post::bloom_terms),
            radio: crate::colormap::RadioLook::of(&scene.config),
            sigma_scale: if bands {
                crate::film::band_centres(nm)
                    .into_iter()
                    .map(|c| c / 550.0)
                    .collect()
            } else {
                vec![1.0]
            },
        }
    }
}

/// The display's buffers and texture for one prepared scene.
pub(crate) struct Display {
    pipelines: std::sync::Arc<DisplayPipelines>,
    look: Look,
    /// Planes kept: the XYZ, and the bloom bands when the scene keeps them.
    planes: u32,
    params: wgpu::Buffer,
    /// Bytes between parameter slots (the device's uniform alignment).
    slot: u64,
    acc: wgpu::Buffer,
    shown: wgpu::Buffer,
    kern: wgpu::Buffer,
    image: wgpu::Texture,
    view: wgpu::TextureView,
    bind: wgpu::BindGroup,
    /// The size the bloom's tables were last written for.
    tables_for: Option<(u32, u32)>,
    _keep: [wgpu::Buffer; 2],
}

/// Words of `kern` before bloom's kernels: the false colour's table.
const TABLE_WORDS: u64 = 256;

impl Display {
    /// The display of an image `width` x `height` (previews are smaller)
    /// fed by the tracer's `film` and `bands` buffers (a band of rows).
    pub(crate) fn new(
        gpu: &Gpu,
        pipelines: std::sync::Arc<DisplayPipelines>,
        look: Look,
        film: &wgpu::Buffer,
        bands: &wgpu::Buffer,
        width: u32,
        height: u32,
    ) -> Result<Display, GpuError> {
        let device = &gpu.device;
        let px = width as u64 * height as u64;
        let planes = look.sigma_scale.len() as u32 + u32::from(look.sigma_scale.len() > 1);
        let bloom = look.bloom.is_some();
        let rw = |label: &str, bytes: u64| -> Result<wgpu::Buffer, GpuError> {
            gpu.fits(label, bytes)?;
            Ok(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }))
        };
        let acc = rw("the view's image", 16 * px)?;
        let acc_bands = rw(
            "the view's bloom bands",
            if planes > 1 {
                12 * BANDS as u64 * px
            } else {
                0
            },
        )?;
        let scratch = rw("bloom's blurred rows", if bloom { 16 * px } else { 0 })?;
        let shown = rw("the bloomed image", if bloom { 16 * px } else { 0 })?;
        // Each plane's kernel for each of bloom's Gaussians (at most 6
        // sigma + 3 weights at full size) and a weight per column and per
        // row.
        let kern_words: u64 = look.bloom.as_ref().map_or(0, |terms| {
            look.sigma_scale
                .iter()
                .flat_map(|k| terms.iter().map(move |t| t.sigma * k))
                .map(|radius| {
                    let sigma = radius * height as f64;
                    (6.0 * sigma).ceil() as u64 + 3 + width as u64 + height as u64
                })
                .sum()
        });
        // The false colour's table comes first.
        let kern_words = kern_words + TABLE_WORDS;
        gpu.fits("bloom's kernels", 4 * kern_words)?;
        let kern = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bloom's kernels"),
            size: (4 * kern_words).max(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let align = gpu.limits.min_uniform_buffer_offset_alignment as u64;
        let slot = (std::mem::size_of::<DisplayParams>() as u64).div_ceil(align) * align;
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display parameters"),
            size: slot * (1 + look.sigma_scale.len() as u64 * look.terms()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let image = view_image(device, width, height);
        let view = image.create_view(&wgpu::TextureViewDescriptor::default());
        let bind = bind_group(
            device,
            &pipelines.layout,
            &params,
            [film, bands, &acc, &acc_bands, &scratch, &shown, &kern],
            &view,
        );
        if let Some(radio) = &look.radio {
            // Each colour as the number r + 256 g + 65536 b, exact in f32
            // (kern is a float array).
            let table: Vec<f32> = radio
                .table()
                .iter()
                .map(|c| u32::from_le_bytes([c[0], c[1], c[2], 0]) as f32)
                .collect();
            gpu.queue
                .write_buffer(&kern, 0, bytemuck::cast_slice(&table));
        }
        gpu.check()?;
        Ok(Display {
            pipelines,
            look,
            planes,
            params,
            slot,
            acc,
            shown,
            kern,
            image,
            view,
            bind,
            tables_for: None,
            _keep: [acc_bands, scratch],
        })
    }

    /// The parameters shared by every pass for an image `w` x `h`.
    fn base(&self, w: u32, h: u32) -> DisplayParams {
        let m = crate::spectrum::color::xyz_to_linear_srgb_matrix();
        let col = |c: usize| {
            let v = m.col(c);
            [v.x as f32, v.y as f32, v.z as f32, 0.0]
        };
        DisplayParams {
            width: w,
            height: h,
            first_row: 0,
            rows: 0,
            plane: 0,
            first_plane: 0,
            k_radius: 0,
            at_kernel: 0,
            at_inside_rows: 0,
            at_inside_columns: 0,
            keep: 0.0,
            _pad_keep0: 0,
            _pad_keep1: 0,
            _pad_keep2: 0,
            strength: 0.0,
            exposure_scale: self.look.exposure.exp2() as f32,
            tonemap: match self.look.tonemap {
                ToneMap::Clip => TONE_CLIP,
                ToneMap::Reinhard => TONE_REINHARD,
                ToneMap::Aces => TONE_ACES,
            },
            bloom: u32::from(self.blooms()),
            colormap: match self.look.radio.map(|r| r.log) {
                None => COLORMAP_NONE,
                Some(None) => COLORMAP_LINEAR,
                Some(Some(_)) => COLORMAP_LOG,
            },
            decades: self.look.radio.and_then(|r| r.log).unwrap_or(1.0) as f32,
            xyz_to_srgb: [col(0), col(1), col(2)],
        }
    }

    /// Whether the image shown is bloomed.
    pub(crate) fn blooms(&self) -> bool {
        self.look.bloom.is_some()
    }

    /// Sets up the addition of the tracer's band of rows `first_row..
    /// first_row + rows` of an image `w` x `h` (to be encoded by
    /// [`Display::accumulate`] and submitted before the next call).
    pub(crate) fn set_band(&self, gpu: &Gpu, w: u32, h: u32, first_row: u32, rows: u32) {
        let p = DisplayParams {
            first_row,
            rows,
            ..self.base(w, h)
        };
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }

    /// The `accumulate` pipeline for a pass that starts the image again
    /// (`restart`) or adds to it, and is shown in the window (`encode`):
    /// without bloom its pixels are encoded as they are added.
    pub(crate) fn accumulate_pipeline(
        &self,
        gpu: &Gpu,
        restart: bool,
        encode: bool,
    ) -> Result<wgpu::ComputePipeline, GpuError> {
        self.pipelines.accumulate(
            gpu,
            AccumulateKind {
                restart,
                keep_bands: self.planes > 1,
                encode: encode && !self.blooms(),
            },
        )
    }

    /// Adds the band set by [`Display::set_band`] to the view's image with
    /// `pipeline` (from [`Display::accumulate_pipeline`]).
    pub(crate) fn accumulate(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        w: u32,
        rows: u32,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.bind, &[0]);
        let span = w.div_ceil(DISPLAY_PIXELS);
        pass.dispatch_workgroups(
            span.div_ceil(DISPLAY_GROUP.0),
            rows.div_ceil(DISPLAY_GROUP.1),
            1,
        );
    }

    /// Writes bloom's kernels and per-plane parameters for an image
    /// `w` x `h`, where they were written for another size.
    pub(crate) fn set_size(&mut self, gpu: &Gpu, w: u32, h: u32) {
        if self.tables_for == Some((w, h)) {
            return;
        }
        self.tables_for = Some((w, h));
        let Some(terms) = &self.look.bloom else {
            return;
        };
        let mut words: Vec<f32> = Vec::new();
        let at = TABLE_WORDS as usize;
        let first = u32::from(self.planes > 1);
        let entries = self
            .look
            .sigma_scale
            .iter()
            .enumerate()
            .flat_map(|(i, scale)| {
                terms
                    .iter()
                    .map(move |t| (i, t, t.sigma * h as f64 * scale))
            });
        for (e, (i, term, sigma)) in entries.enumerate() {
            // sigma <= 0 leaves the image as it is, as `post::blur` does.
            let k = if sigma > 0.0 {
                crate::post::kernel(sigma)
            } else {
                vec![1.0]
            };
            let p = DisplayParams {
                plane: first + i as u32,
                first_plane: u32::from(e == 0),
                keep: term.keep,
                strength: term.weight,
                k_radius: (k.len() / 2) as u32,
                at_kernel: (at + words.len()) as u32,
                at_inside_rows: (at + words.len() + k.len()) as u32,
                at_inside_columns: (at + words.len() + k.len() + w as usize) as u32,
                ..self.base(w, h)
            };
            words.extend_from_slice(&k);
            words.extend(crate::post::inside(w as usize, &k));
            words.extend(crate::post::inside(h as usize, &k));
            gpu.queue.write_buffer(
                &self.params,
                self.slot * (1 + e as u64),
                bytemuck::bytes_of(&p),
            );
        }
        gpu.queue
            .write_buffer(&self.kern, 4 * TABLE_WORDS, bytemuck::cast_slice(&words));
    }

    /// Blooms the view's image (when the scene asks) and, with `encode`,
    /// turns it into the 8-bit texture: an image `w` x `h` whose tables
    /// [`Display::set_size`] wrote.
    pub(crate) fn finish(&self, pass: &mut wgpu::ComputePass<'_>, w: u32, h: u32, encode: bool) {
        let groups = (w.div_ceil(DISPLAY_GROUP.0), h.div_ceil(DISPLAY_GROUP.1));
        if self.blooms() {
            for i in 0..self.look.sigma_scale.len() as u64 * self.look.terms() {
                let offset = (self.slot * (1 + i)) as u32;
                pass.set_bind_group(0, &self.bind, &[offset]);
                pass.set_pipeline(&self.pipelines.blur_rows);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
                pass.set_pipeline(&self.pipelines.blur_columns);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
        }
        // Without bloom the pixels were encoded as they were added.
        if encode && self.blooms() {
            pass.set_bind_group(0, &self.bind, &[0]);
            pass.set_pipeline(&self.pipelines.tonemap);
            let span = w.div_ceil(DISPLAY_PIXELS);
            pass.dispatch_workgroups(span.div_ceil(DISPLAY_GROUP.0), groups.1, 1);
        }
    }

    /// The bloomed image (vec4 per pixel), for reading back.
    pub(crate) fn shown(&self) -> &wgpu::Buffer {
        &self.shown
    }

    /// The view's image so far (vec4 per pixel: mean XYZ, samples kept).
    pub(crate) fn acc(&self) -> &wgpu::Buffer {
        &self.acc
    }

    /// The 8-bit sRGB texture (RGBA; the image in its top-left corner).
    pub(crate) fn texture(&self) -> &wgpu::Texture {
        &self.image
    }

    /// A view of [`Display::texture`], for drawing it.
    pub(crate) fn view(&self) -> &wgpu::TextureView {
        &self.view
    }
}

/// The viewer's 8-bit texture, `width` x `height`.
fn view_image(device: &wgpu::Device, width: u32, height: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("the view"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::STORAGE_BINDING
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The display's bind group: its parameters (a slot at a time), the
/// storage `buffers` at bindings 1 to 7 (the tracer's film and bands, the
/// view's image and bands, bloom's scratch rows, the bloomed image and
/// the kernels) and the texture's `view`.
fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    params: &wgpu::Buffer,
    buffers: [&wgpu::Buffer; 7],
    view: &wgpu::TextureView,
) -> wgpu::BindGroup {
    fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
        wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        }
    }
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("display"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: params,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of::<DisplayParams>() as u64),
                }),
            },
            buffer(1, buffers[0]),
            buffer(2, buffers[1]),
            buffer(3, buffers[2]),
            buffer(4, buffers[3]),
            buffer(5, buffers[4]),
            buffer(6, buffers[5]),
            buffer(7, buffers[6]),
            wgpu::BindGroupEntry {
                binding: 8,
                resource: wgpu::BindingResource::TextureView(view),
            },
        ],
    })
}
