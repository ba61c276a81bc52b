//! The GPU backend: the per-sample work of [`Scene::render`] as WGSL
//! compute shaders through `wgpu`, filling the same [`Film`] and [`Stats`].
//!
//! The scene is built and validated on the CPU as for the CPU backend;
//! [`pack`] flattens it into buffers. The shader ([`shader_source`]: a
//! header written from [`layout`], then common, spacetime, physics,
//! closed, shade, the footprint parts a variant uses, objects and main
//! `.wgsl`) is specialised per scene variant and traces one sample per
//! invocation in f32, in units of r_s
//! (design notes: `src/gpu/README.md`). The image is rendered
//! in bands of rows small enough for the adapter's buffer limits and read
//! back band by band; output stays on the CPU, shared with the CPU backend.
//! The display ([`display`]: adding passes up, bloom, tone curve, sRGB) runs
//! on the GPU too, so that the viewer shows frames without reading them
//! back and `render` reads back the bloomed image, not the bloom bands.
//!
//! The files: [`device`] (opening the adapter, compiling pipelines),
//! [`prepare`] (a scene uploaded, its bands of rows sized), [`passes`] and
//! [`bands`] (rendering in passes of samples, band by band), [`refine`]
//! (adaptive sampling's rounds), [`films`] (the results as a film), [`view`] (the viewer's frames), [`timing`] (the
//! GPU's own time), [`readback`] and [`error`].

mod bands;
mod device;
mod display;
mod error;
mod ewa;
mod films;
mod layout;
#[cfg(test)]
mod objfoot_tests;
mod pack;
mod passes;
mod prepare;
mod readback;
mod refine;
#[cfg(not(target_arch = "wasm32"))]
mod runtime;
#[cfg(not(target_arch = "wasm32"))]
pub(crate) mod specialise;
mod stars;
mod timing;
mod traced;
mod view;

use crate::scene::Scene;

pub use device::Gpu;
pub use error::GpuError;
pub use films::Pass;
pub use pack::MIN_GPU_TOLERANCE;
pub use prepare::Prepared;
#[cfg(not(target_arch = "wasm32"))]
pub use runtime::ensure_runtime_dir;
pub use view::ViewFrame;

/// The farthest a medium may reach on the GPU (M): measured, Sgr A*'s flow
/// to 1e12 M gives the CPU's flux, to 1e14 M its escaping rays run out of
/// steps.
pub const MAX_GPU_MEDIUM_EXTENT: f64 = 1e12;

/// Checks that the GPU backend can render everything in `scene`.
pub fn check_supported(scene: &Scene) -> Result<(), GpuError> {
    if let Some(o) = &scene.observe {
        if o.frequencies.len() > layout::MAX_GPU_FREQUENCIES {
            return Err(GpuError::Unsupported {
                table: "observe.frequency".into(),
                why: format!(
                    "{} frequencies; the GPU observes at most {}",
                    o.frequencies.len(),
                    layout::MAX_GPU_FREQUENCIES
                ),
            });
        }
        if let Some(m) = &o.medium
            && m.extent() > MAX_GPU_MEDIUM_EXTENT
        {
            return Err(GpuError::Unsupported {
                table: format!("a [medium] reaching past {MAX_GPU_MEDIUM_EXTENT:e} M"),
                why: format!(
                    "this one reaches {:e} M; beyond 1e13 M the error control of the GPU's f32 steps no longer holds, where the CPU walks far rays as straight lines",
                    m.extent()
                ),
            });
        }
    }
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

/// The whole shader of variant `v`: its header (see [`layout::header`]),
/// then the WGSL files. Footprint code goes only into the variants that
/// use it (the others get its inert stand-ins): a driver compiles a call
/// before it drops the branch that never makes it (llvmpipe inlines every
/// call first), so it would cost every variant.
pub(crate) fn shader_source(v: &layout::Variant) -> String {
    let footprint = v.footprint || v.object_footprint;
    [
        layout::header(v).as_str(),
        include_str!("common.wgsl"),
        include_str!("spacetime.wgsl"),
        include_str!("kerr.wgsl"),
        include_str!("physics.wgsl"),
        include_str!("closed.wgsl"),
        include_str!("kerr_closed.wgsl"),
        include_str!("shade.wgsl"),
        include_str!("footprint_state.wgsl"),
        &match footprint {
            true => ewa::wgsl(),
            false => include_str!("ewa_off.wgsl").to_string(),
        },
        &match v.footprint {
            true => {
                stars::wgsl()
                    + include_str!("footprint_closed.wgsl")
                    + include_str!("footprint.wgsl")
            }
            false => include_str!("footprint_off.wgsl").to_string(),
        },
        include_str!("objects.wgsl"),
        include_str!("motion.wgsl"),
        match v.object_footprint {
            true => include_str!("objfoot.wgsl"),
            false => include_str!("objfoot_off.wgsl"),
        },
        match (v.medium, v.grmhd) {
            (true, true) => concat!(
                include_str!("media.wgsl"),
                "\n",
                include_str!("grmhd.wgsl"),
                "\n",
                include_str!("transfer.wgsl")
            ),
            (true, false) => concat!(
                include_str!("media.wgsl"),
                "\n",
                include_str!("grmhd_off.wgsl"),
                "\n",
                include_str!("transfer.wgsl")
            ),
            (false, _) => include_str!("transfer_off.wgsl"),
        },
        include_str!("pieces.wgsl"),
        include_str!("gas.wgsl"),
        include_str!("main.wgsl"),
    ]
    .join("\n")
}

/// Most suns the GPU lights surfaces with.
pub(crate) const MAX_GPU_SUNS: usize = 8;

/// Workgroup size (each way) of the tracer's passes (see main.wgsl).
const WORKGROUP: u32 = 8;
/// Samples per dispatch: a band of rows of about this many pixel samples.
const TILE_SAMPLES: u64 = 1 << 22;
