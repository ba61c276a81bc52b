//! Where the per-sample work runs, opened once, and a scene prepared on it
//! once for every film it renders.

use crate::film::{Film, Stats};
use crate::gpu::Gpu;
use crate::scene::Scene;
use anyhow::Result;
use std::ops::Range;
use std::sync::Arc;

/// The kinds of backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendKind {
    /// The f64 reference on every core.
    Cpu,
    /// WGSL compute shaders through wgpu (f32).
    Gpu,
}

/// A backend ready to render.
pub enum Backend {
    /// The CPU.
    Cpu,
    /// A GPU device (shared where a process keeps one open for all its
    /// renders: the Python package).
    Gpu(Arc<Gpu>),
}

#[cfg(not(target_arch = "wasm32"))]
fn open_gpu() -> Result<Gpu> {
    Ok(Gpu::new()?)
}

/// The page opens the browser's GPU itself, asynchronously.
#[cfg(target_arch = "wasm32")]
fn open_gpu() -> Result<Gpu> {
    anyhow::bail!("in the browser the page opens the GPU")
}

impl Backend {
    /// Opens the backend and checks that it can render `scene`, before
    /// anything is rendered or written.
    // wgpu's types are not Send in the browser, which has one thread.
    #[cfg_attr(target_arch = "wasm32", allow(clippy::arc_with_non_send_sync))]
    pub fn open(kind: BackendKind, scene: &Scene) -> Result<Backend> {
        Ok(match kind {
            BackendKind::Cpu => Backend::Cpu,
            BackendKind::Gpu => {
                crate::gpu::check_supported(scene)?;
                Backend::Gpu(Arc::new(open_gpu()?))
            }
        })
    }

    /// The GPU backend on a device opened before (whose compiled shaders
    /// it reuses), checked against `scene` as [`Backend::open`] checks.
    pub fn on_gpu(gpu: Arc<Gpu>, scene: &Scene) -> Result<Backend> {
        crate::gpu::check_supported(scene)?;
        Ok(Backend::Gpu(gpu))
    }

    /// `scene` made ready to render: nothing to do on the CPU; on the GPU
    /// uploaded with its shader compiled, once, for all its films.
    pub fn prepare(&self, scene: &Scene) -> Result<Prepared<'_>> {
        Ok(match self {
            Backend::Cpu => Prepared::Cpu,
            Backend::Gpu(gpu) => Prepared::Gpu(Box::new(gpu.prepare(scene, u32::MAX)?)),
        })
    }

    /// On the GPU, whether scenes that allow it take the closed form
    /// (by default on GPUs, not on CPU devices such as lavapipe: see
    /// [`Gpu::set_closed_form`]). The CPU's own choice is the scene's
    /// `physics.closed_form`; this refuses to change it.
    pub fn set_gpu_closed_form(&mut self, on: bool) -> Result<()> {
        match self {
            Backend::Cpu => anyhow::bail!(
                "--gpu-closed-form applies to --backend gpu (the CPU follows physics.closed_form)"
            ),
            Backend::Gpu(gpu) => {
                Arc::get_mut(gpu)
                    .ok_or_else(|| {
                        anyhow::anyhow!("the GPU is shared: choose the closed form before")
                    })?
                    .set_closed_form(on);
                Ok(())
            }
        }
    }

    /// `cpu`, or `gpu: DEVICE` (with `, integrated` where the device does
    /// not take the closed form), for tiles: tiles traced both ways do not
    /// mix.
    pub fn label(&self) -> String {
        match self {
            Backend::Cpu => "cpu".into(),
            Backend::Gpu(gpu) if gpu.closed_form() => format!("gpu: {}", gpu.name()),
            Backend::Gpu(gpu) => format!("gpu: {}, integrated", gpu.name()),
        }
    }

    /// " on DEVICE" for the closing line, or nothing for the CPU.
    pub fn on(&self) -> String {
        match self {
            Backend::Cpu => String::new(),
            Backend::Gpu(gpu) => format!(" on {}", gpu.name()),
        }
    }

    /// [`Backend::on`] with the GPU's own time of the render where the
    /// device measured it: " on DEVICE (GPU time 12.3 ms)".
    pub fn on_timed(&self, device_seconds: Option<f64>) -> String {
        match device_seconds {
            Some(t) => format!("{} (GPU time {:.1} ms)", self.on(), t * 1e3),
            None => self.on(),
        }
    }
}

/// A scene prepared on a backend.
pub enum Prepared<'a> {
    /// The CPU renders the scene it is given.
    Cpu,
    /// The GPU's uploaded scene and compiled shader.
    Gpu(Box<crate::gpu::Prepared<'a>>),
}

impl Prepared<'_> {
    /// The GPU's own time (s) of the last render, where the device keeps
    /// timestamps; None on the CPU.
    pub fn device_seconds(&self) -> Option<f64> {
        match self {
            Prepared::Cpu => None,
            Prepared::Gpu(p) => p.device_seconds(),
        }
    }

    /// Renders the rows `rows` of `scene` with everything a tile keeps
    /// (the bloom bands among it): the scene prepared, or the same scene
    /// moved since (another instant by [`Scene::set_time`], a stereo eye's
    /// camera), never another scene.
    pub fn render(
        &mut self,
        scene: &Scene,
        rows: Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats)> {
        Ok(match self {
            Prepared::Cpu => scene.render_rows(rows, progress),
            Prepared::Gpu(p) => {
                p.set_frame(scene)?;
                p.render_rows(rows, progress)?
            }
        })
    }

    /// [`Prepared::render_image`] (`rows` None) or [`Prepared::render`]
    /// of `rows`, giving up, returning None, once `stop` is set: the CPU
    /// between pixels, the GPU between bands of rows and passes.
    pub fn render_until(
        &mut self,
        scene: &Scene,
        rows: Option<Range<u32>>,
        progress: &(dyn Fn(u64) + Sync),
        stop: &Arc<std::sync::atomic::AtomicBool>,
    ) -> Result<Option<(Film, Stats)>> {
        Ok(match self {
            Prepared::Cpu => {
                let rows = rows.unwrap_or(0..scene.camera.height);
                scene.render_rows_until(rows, progress, stop)
            }
            Prepared::Gpu(p) => {
                p.set_frame(scene)?;
                p.stop_on(stop.clone());
                let done = match rows {
                    None => p.render_image(progress),
                    Some(rows) => p.render_rows(rows, progress),
                };
                match done {
                    Ok(done) => Some(done),
                    Err(crate::gpu::GpuError::Stopped) => None,
                    Err(e) => return Err(e.into()),
                }
            }
        })
    }

    /// Renders the whole image of `scene` (as [`Prepared::render`]) for
    /// the scene's outputs: on the GPU, bloomed there where the scene
    /// blooms (`Film::bloomed`), without reading the bloom bands back.
    pub fn render_image(
        &mut self,
        scene: &Scene,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats)> {
        Ok(match self {
            Prepared::Cpu => scene.render_rows(0..scene.camera.height, progress),
            Prepared::Gpu(p) => {
                p.set_frame(scene)?;
                p.render_image(progress)?
            }
        })
    }
}
