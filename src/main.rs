//! The `blackhole` command line: the argument types and the dispatch to
//! the commands (`commands/`, one file each), which hand their scenes to
//! the library's pipeline.

// Checks write `!(x > 0.0)` on purpose: NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod commands;

use anyhow::{Result, bail};
use blackhole::config::Override;
use blackhole::pipeline::{Backend, BackendKind};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Renders a black hole (Schwarzschild or spinning Kerr), its disk, gas and
/// the starry sky through gravitationally bent light: colour from spectra
/// over 380-780 nm, or flux densities in janskys at any frequency by
/// radiative transfer.
#[derive(Parser)]
#[command(version, about)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// A scene file and the command line's changes to it.
#[derive(clap::Args)]
pub(crate) struct SceneArgs {
    /// Scene file (TOML).
    pub(crate) config: PathBuf,
    /// Override a config value, e.g. --set image.width=256 or
    /// --set object.0.radius=2e10 (repeatable; applied after --unset).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
    pub(crate) set: Vec<Override>,
    /// Remove a config key or list entry, e.g. --unset sky.texture or
    /// --unset object.1 (repeatable; applied before --set).
    #[arg(long = "unset", value_name = "KEY", value_parser = parse_unset)]
    pub(crate) unset: Vec<Override>,
}

impl SceneArgs {
    /// The overrides in the order they apply: removals, then values.
    pub(crate) fn overrides(&self) -> Vec<Override> {
        self.unset.iter().chain(&self.set).cloned().collect()
    }
}

/// clap names the option and value itself: keep only what is wrong.
fn reason(e: blackhole::config::ConfigError) -> String {
    match e {
        blackhole::config::ConfigError::Override { message, .. } => message,
        other => other.to_string(),
    }
}

fn parse_set(s: &str) -> Result<Override, String> {
    Override::parse(s).map_err(reason)
}

fn parse_unset(s: &str) -> Result<Override, String> {
    Override::unset(s).map_err(reason)
}

/// Where and on how many threads the work runs (render, compare, animate).
#[derive(clap::Args)]
pub(crate) struct Engine {
    /// Worker threads (default: one per core). The pixels do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    pub(crate) threads: Option<u16>,
    /// Where the per-sample work runs: `cpu` (the f64 reference) or `gpu`
    /// (WGSL compute shaders, f32).
    #[arg(long, value_enum, default_value = "cpu")]
    pub(crate) backend: BackendArg,
    /// With `--backend gpu`: trace the scenes that allow it
    /// (`physics.closed_form`) in closed form (`on`) or with the integrator
    /// (`off`). Default: on for GPUs, off for CPU devices such as lavapipe.
    #[arg(long, value_enum)]
    pub(crate) gpu_closed_form: Option<Switch>,
}

/// On or off.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Switch {
    On,
    Off,
}

impl Engine {
    /// The backend asked for.
    pub(crate) fn kind(&self) -> BackendKind {
        match self.backend {
            BackendArg::Cpu => BackendKind::Cpu,
            BackendArg::Gpu => BackendKind::Gpu,
        }
    }

    /// The backend asked for, opened for `scene` and set as asked.
    pub(crate) fn open(&self, scene: &blackhole::scene::Scene) -> anyhow::Result<Backend> {
        let mut backend = Backend::open(self.kind(), scene)?;
        if let Some(s) = self.gpu_closed_form {
            backend.set_gpu_closed_form(s == Switch::On)?;
        }
        Ok(backend)
    }

    /// Whether it is the GPU.
    pub(crate) fn on_gpu(&self) -> bool {
        self.backend == BackendArg::Gpu
    }
}

/// Where the per-sample work runs.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum BackendArg {
    /// The f64 reference on every core.
    Cpu,
    /// WGSL compute shaders through wgpu (f32).
    Gpu,
}

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    #[command(flatten)]
    pub(crate) engine: Engine,
    /// No progress bars, summary line or printed comparison summary
    /// (warnings and errors still print).
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// Replace existing images named by the scene file even when their
    /// size differs from this render's; with --tile, render a tile that is
    /// complete already.
    #[arg(long)]
    pub(crate) overwrite: bool,
    /// Render the instant T (seconds of coordinate time) of the scene's
    /// [animation] rather than its start.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    pub(crate) time: Option<f64>,
    /// Render only tile I (0-based) of N, a band of the image's rows, to
    /// <stem>.tile-<I>-of-<N>.exr beside image.png for `merge` (render only).
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    pub(crate) tile: Option<(u32, u32)>,
}

#[derive(clap::Args)]
pub(crate) struct InfoArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// The backend and threads the render time is estimated for.
    #[command(flatten)]
    pub(crate) engine: Engine,
}

#[derive(clap::Args)]
pub(crate) struct MergeArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// The instant the tiles were rendered at (`render --time T`).
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    pub(crate) time: Option<f64>,
    /// No summary line (warnings and errors still print).
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// Replace existing images named by the scene file even when their
    /// size differs from this image's.
    #[arg(long)]
    pub(crate) overwrite: bool,
}

/// `I/N`, two whole numbers (checked against the image when it is known).
fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or("expected I/N, e.g. 0/4 (tile I, 0-based, of N)")?;
    let num = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("{x:?} is not a whole number"))
    };
    Ok((num(i)?, num(n)?))
}

#[derive(clap::Args)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Folder for screenshots and saved views (default: the current one).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
}

#[derive(clap::Args)]
pub(crate) struct ServeArgs {
    /// Port to listen on (0: any free one; the line printed names it).
    #[arg(long, default_value_t = 8080)]
    pub(crate) port: u16,
    /// The built site: the folder `src/web/build.sh` writes [default:
    /// $CARGO_TARGET_DIR/site, else target/site].
    #[arg(long, value_name = "DIR")]
    pub(crate) site: Option<PathBuf>,
}

#[derive(clap::Args)]
pub(crate) struct AnimateArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// Only frames A to B, inclusive and 0-based (e.g. 0..9), or I/N: the
    /// I-th (0-based) of N equal runs of consecutive frames (a job array's
    /// task I of N): a slice of the animation for one job.
    #[arg(long, value_name = "A..B|I/N", value_parser = parse_frames)]
    pub(crate) frames: Option<Frames>,
    /// Render the frames only; leave the video to a later `animate`.
    #[arg(long)]
    pub(crate) no_video: bool,
    #[command(flatten)]
    pub(crate) engine: Engine,
    /// No progress bar or closing line (warnings and errors still print).
    #[arg(long, short)]
    pub(crate) quiet: bool,
    /// Render frames whose files exist too (else they are kept: resume).
    #[arg(long)]
    pub(crate) overwrite: bool,
}

/// A slice of an animation's frames.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Frames {
    /// Frames A to B, inclusive.
    Range(u32, u32),
    /// Run I of N.
    Share(u32, u32),
}

impl Frames {
    /// The first and last frame of an animation of `count` frames.
    pub(crate) fn of(self, count: u32) -> Result<(u32, u32)> {
        match self {
            Frames::Range(a, b) if b < count => Ok((a, b)),
            Frames::Range(a, b) => bail!(
                "--frames {a}..{b}: the animation has {count} frames, 0..{}",
                count - 1
            ),
            Frames::Share(i, n) => {
                if n == 0 || i >= n {
                    bail!("--frames {i}/{n}: expected I/N with 0 <= I < N (run I, 0-based, of N)");
                }
                if n > count {
                    bail!(
                        "--frames {i}/{n}: the animation has {count} frames, so it splits into at most {count} runs"
                    );
                }
                let at = |k: u32| (k as u64 * count as u64 / n as u64) as u32;
                Ok((at(i), at(i + 1) - 1))
            }
        }
    }
}

/// `A..B` with A <= B, or `I/N`.
fn parse_frames(s: &str) -> Result<Frames, String> {
    let num = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|_| format!("{x:?} is not a frame number"))
    };
    if let Some((i, n)) = s.split_once('/') {
        return Ok(Frames::Share(num(i)?, num(n)?));
    }
    let (a, b) = s
        .split_once("..")
        .ok_or("expected A..B, e.g. 0..9 (inclusive, 0-based), or I/N (run I of N)")?;
    let (a, b) = (num(a)?, num(b)?);
    if a > b {
        return Err(format!("{a}..{b}: the first frame comes after the last"));
    }
    Ok(Frames::Range(a, b))
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Render a scene file to the PNG (and EXR) it names.
    Render(RenderArgs),
    /// Render a spectral scene with the frequency shift off and on; write
    /// both images, a side-by-side image, a CIEDE2000 difference map and a
    /// summary.
    Compare(RenderArgs),
    /// Assemble the tiles of `render --tile I/N` into the images `render`
    /// writes (the same bytes), after checking they are one whole set of
    /// this scene.
    Merge(MergeArgs),
    /// Render the [animation] table's frames (PNG, and EXR when the scene
    /// writes one) beside image.png, then its video.
    Animate(AnimateArgs),
    /// Convert sampled spectra to XYZ and sRGB with the renderer's own
    /// colour pipeline (for checking it against colour-science).
    ///
    /// Input CSV: a header `id,<nm>,<nm>,...` whose wavelengths are evenly
    /// spaced from 380 to 780 nm, then one spectrum per row. Output CSV on
    /// stdout: id, X, Y, Z (plain sum times the spacing), linear sRGB (may be
    /// negative or above 1: out of gamut), encoded sRGB of the clipped values.
    Colour {
        /// Spectra (CSV).
        spectra: PathBuf,
    },
    /// Open the scene in a window (GPU backend): fly around the hole,
    /// toggle the physics, save screenshots and the view as a scene file.
    View(ViewArgs),
    /// Serve the built web site (`src/web/build.sh`) to a browser on this
    /// machine, at http://127.0.0.1:PORT/, until stopped (ctrl-C).
    Serve(ServeArgs),
    /// Print the quantities a scene implies (r_s, ISCO, shadow size, memory,
    /// the render's time on the chosen backend, estimated from a short
    /// probe of the scene's rays...).
    Info(InfoArgs),
    /// Regenerate the shipped assets (disk texture, spectral disk set, star
    /// panorama) from their fixed seeds.
    Assets(AssetArgs),
    /// Re-lens any equirectangular panorama with the lens map of a rendered
    /// EXR (its obs.sky channels): each pixel the panorama filtered over
    /// the pixel's footprint on the sky.
    Relens(RelensArgs),
    /// Write the standard initial state of GRMHD runs as an iharm3d-format
    /// dump: the Fishbone-Moncrief torus with one poloidal loop of field,
    /// with the EHT code comparison's parameters (a = 0.9375, r_in = 6,
    /// r_max = 12, beta_min = 100).
    Torus(TorusArgs),
}

#[derive(clap::Args)]
pub(crate) struct TorusArgs {
    /// The dump to write (HDF5).
    pub(crate) out: PathBuf,
    /// The native coordinates: mks or fmks.
    #[arg(long, default_value = "mks", value_parser = ["mks", "fmks"])]
    pub(crate) metric: String,
    /// Cells along X1 (radius), X2 (polar angle) and X3 (azimuth).
    #[arg(long, default_value = "128x64x4")]
    pub(crate) grid: String,
    /// Add a magnetised, hot, tenuous funnel along the axis (sigma = 10):
    /// what the EHT's sigma cut removes.
    #[arg(long)]
    pub(crate) funnel: bool,
    /// No summary line.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(clap::Args)]
pub(crate) struct RelensArgs {
    /// A render's EXR with the channels obs.sky.x, obs.sky.y, obs.sky.z
    /// (image.observables including "sky"; obs.magnification is used where
    /// present).
    pub(crate) exr: PathBuf,
    /// A 2:1 equirectangular panorama (PNG, JPEG, EXR or Radiance HDR).
    pub(crate) panorama: PathBuf,
    /// The image to write, of the EXR's size: .png (8-bit sRGB) or .exr
    /// (linear RGBA, alpha 0 where the ray did not escape).
    pub(crate) out: PathBuf,
    /// No summary line.
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

#[derive(clap::Args)]
pub(crate) struct AssetArgs {
    /// Folder to write disk_rgba.png and sky.png into.
    #[arg(long, default_value = "spectral_assets")]
    pub(crate) out: PathBuf,
    /// Star catalogue CSV for the sky (default: the shipped
    /// spectral_assets/stars/hipparcos_mag8.csv).
    #[arg(long)]
    pub(crate) catalogue: Option<PathBuf>,
    /// Only this asset.
    #[arg(long, value_enum)]
    pub(crate) only: Option<Asset>,
    /// Disk texture side in texels.
    #[arg(long, default_value_t = 1024)]
    pub(crate) disk_size: u32,
    /// Outer disk radius the texture spans, in r_s.
    #[arg(long, default_value_t = 10.0)]
    pub(crate) disk_radius: f64,
    /// Peak disk temperature in kelvin.
    #[arg(long, default_value_t = 5000.0)]
    pub(crate) disk_kelvin: f64,
    /// Side of the spectral disk images in texels.
    #[arg(long, default_value_t = 512)]
    pub(crate) spectral_size: u32,
    /// Wavelengths of the spectral disk set: first,last,step in nm. The
    /// default covers the light that shifts into 380-780 nm for g from
    /// about 0.5 to 1.5.
    #[arg(long, default_value = "200,1200,20")]
    pub(crate) spectral_nm: String,
    /// Panorama width in texels (height is half).
    #[arg(long, default_value_t = 4096)]
    pub(crate) sky_width: u32,
    /// Leave out the Milky Way band.
    #[arg(long)]
    pub(crate) no_milky_way: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Asset {
    Disk,
    Spectral,
    Sky,
    Meshes,
}

/// Whether the command opens the GPU.
fn uses_gpu(c: &Command) -> bool {
    match c {
        Command::Render(a) | Command::Compare(a) => a.engine.on_gpu(),
        Command::Animate(a) => a.engine.on_gpu(),
        Command::View(_) => true,
        Command::Info(a) => a.engine.on_gpu(),
        _ => false,
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(a) => commands::render::render(&a),
        Command::Compare(a) => commands::compare::compare(&a),
        Command::Animate(a) => commands::animate::animate(&a),
        Command::Merge(a) => commands::merge::merge(&a),
        Command::View(a) => commands::view::view(a),
        Command::Serve(a) => commands::serve::serve(&a),
        Command::Colour { spectra } => commands::colour::colour(&spectra),
        Command::Info(a) => commands::info::info(&a),
        Command::Assets(a) => commands::assets::generate_assets(a),
        Command::Relens(a) => commands::relens::relens(&a),
        Command::Torus(a) => commands::torus::torus(&a),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if uses_gpu(&cli.command) {
        // Before any other thread starts (the environment changes).
        blackhole::gpu::ensure_runtime_dir();
    }
    if let Err(e) = blackhole::files::handle_signals() {
        eprintln!("error: {e:#}");
        return ExitCode::FAILURE;
    }
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
