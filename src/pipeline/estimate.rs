//! How long a render will take, from a short probe of the scene's own
//! rays on the chosen backend (`blackhole info`).
//!
//! The probe renders the same view on an image a whole number of times
//! smaller each way: the same field of view, so the same mix of sky, disk,
//! objects and captured rays, through the backend's whole per-pixel path
//! (samples, spectra, observables). Its time per sample, times the image's
//! samples, is the estimate. Loading the scene and writing the files are
//! not counted (the report gives the load's time beside it).

use super::Backend;
use crate::scene::Scene;
use anyhow::Result;
use std::time::Instant;

/// Samples the CPU probe traces: a few milliseconds on the shipped
/// scenes, and a mean per sample within a few per cent.
const CPU_PROBE_SAMPLES: u64 = 4096;

/// A render time estimated from a probe.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Seconds to trace the image (both eyes of a stereo pair).
    pub seconds: f64,
    /// Camera samples the probe traced.
    pub probe_samples: u64,
    /// Its wall time (s).
    pub probe_seconds: f64,
    /// Seconds of preparation before the first sample (the GPU's upload
    /// and shader compilation; 0 on the CPU).
    pub setup_seconds: f64,
    /// How the estimate was made, in words.
    pub how: String,
}

/// The image's camera samples: pixels times samples, times two eyes.
fn image_samples(scene: &Scene) -> u64 {
    let eyes = if scene.config.stereo.is_some() { 2 } else { 1 };
    scene.camera.width as u64 * scene.camera.height as u64 * scene.samples as u64 * eyes
}

/// `scene` on an image `scale` times smaller each way.
fn smaller(scene: &Scene, scale: u32) -> Scene {
    let mut probe = scene.clone();
    probe.camera.width = scene.camera.width.div_ceil(scale);
    probe.camera.height = scene.camera.height.div_ceil(scale);
    probe
}

/// Estimates the render of `scene` on `backend`.
pub fn estimate(backend: &Backend, scene: &Scene) -> Result<Estimate> {
    match backend {
        Backend::Cpu => on_cpu(scene),
        Backend::Gpu(gpu) => on_gpu(gpu, scene),
    }
}

/// The CPU: the probe on one thread, the image on every worker thread.
fn on_cpu(scene: &Scene) -> Result<Estimate> {
    let (w, h, spp) = (
        scene.camera.width,
        scene.camera.height,
        scene.samples as u64,
    );
    // The smallest scale whose image holds at most the probe's samples.
    let mut scale = 1;
    while (w.div_ceil(scale) as u64) * (h.div_ceil(scale) as u64) * spp > CPU_PROBE_SAMPLES
        && scale < w.max(h)
    {
        scale += 1;
    }
    let probe = smaller(scene, scale);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    // A first tiny render builds what the scene makes on first use (the
    // camera's frame, tables), which the image pays once.
    one.install(|| smaller(scene, w.max(h)).render(&|_| {}));
    let start = Instant::now();
    let (_, stats) = one.install(|| probe.render(&|_| {}));
    let took = start.elapsed().as_secs_f64();
    let threads = rayon::current_num_threads();
    let per_sample = took / stats.samples.max(1) as f64;
    // Adaptive sampling refines along edges, which are curves: an image
    // `scale` times larger each way has about `scale` times the probe's
    // extra samples, not scale^2 times.
    let eyes = if scene.config.stereo.is_some() { 2 } else { 1 };
    let extra = stats.extra * scale as u64 * eyes;
    let adaptive = if scene.adaptive {
        format!(
            " plus about {extra} adaptive samples (the probe's {} times {scale}, as edges grow with the image's width)",
            stats.extra
        )
    } else {
        String::new()
    };
    Ok(Estimate {
        seconds: per_sample * (image_samples(scene) + extra) as f64 / threads as f64,
        probe_samples: stats.samples,
        probe_seconds: took,
        setup_seconds: 0.0,
        how: format!(
            "{} samples of the view at 1/{scale} scale traced on one thread in {:.1} ms, \
             scaled to the image's {} samples{adaptive} on {threads} thread(s)",
            stats.samples,
            took * 1e3,
            image_samples(scene)
        ),
    })
}

/// The GPU: prepared (uploaded, shaders compiled), then one pass of a
/// sample per pixel at a quarter of the size each way.
fn on_gpu(gpu: &crate::gpu::Gpu, scene: &Scene) -> Result<Estimate> {
    let start = Instant::now();
    let prepared = gpu.prepare_passes(scene, 1)?;
    let setup = start.elapsed().as_secs_f64();
    let scale = 4.min(scene.camera.width.min(scene.camera.height)).max(1);
    let start = Instant::now();
    let pass = prepared.render_pass_scaled(0, 1, scale, &|_| {})?;
    let took = start.elapsed().as_secs_f64();
    let per_sample = took / pass.stats.samples.max(1) as f64;
    Ok(Estimate {
        seconds: per_sample * image_samples(scene) as f64,
        probe_samples: pass.stats.samples,
        probe_seconds: took,
        setup_seconds: setup,
        how: format!(
            "{:.2} s to upload and compile, then a pass of {} samples of the view at 1/{scale} scale \
             in {:.1} ms, scaled to the image's {} samples (a hardware GPU that the small pass does \
             not fill does better)",
            setup,
            pass.stats.samples,
            took * 1e3,
            image_samples(scene)
        ),
    })
}

/// Seconds as a person reads them.
pub fn duration_text(s: f64) -> String {
    if s < 1.0 {
        format!("{:.0} ms", s * 1e3)
    } else if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}
