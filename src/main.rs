//! The `blackhole` command line: render, compare, info, colour, assets.

// Checks write `!(x > 0.0)` on purpose: NaN must fail them.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use anyhow::{Context, Result, bail};
use blackhole::assets;
use blackhole::compare;
use blackhole::config::{Override, SceneConfig};
use blackhole::files::{Batch, Plan};
use blackhole::output::{stage_exr, stage_png, tone_map, write_png_as, xyz_to_srgb8};
use blackhole::render::{Film, Stats};
use blackhole::scene::Scene;
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Renders a Schwarzschild black hole, its accretion disk and the starry sky
/// through gravitationally bent light.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// A scene file and the command line's changes to it.
#[derive(clap::Args)]
struct SceneArgs {
    /// Scene file (TOML).
    config: PathBuf,
    /// Override a config value, e.g. --set image.width=256 or
    /// --set object.0.radius=2e10 (repeatable; applied after --unset).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
    set: Vec<Override>,
    /// Remove a config key or list entry, e.g. --unset sky.texture or
    /// --unset object.1 (repeatable; applied before --set).
    #[arg(long = "unset", value_name = "KEY", value_parser = parse_unset)]
    unset: Vec<Override>,
}

impl SceneArgs {
    /// The overrides in the order they apply: removals, then values.
    fn overrides(&self) -> Vec<Override> {
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

#[derive(clap::Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    threads: Option<u16>,
    /// No progress bars, summary line or printed comparison summary
    /// (warnings and errors still print).
    #[arg(long, short)]
    quiet: bool,
    /// Replace existing images named by the scene file even when their
    /// size differs from this render's; with --tile, render a tile that is
    /// complete already.
    #[arg(long)]
    overwrite: bool,
    /// Where the per-sample work runs: `cpu` (the f64 reference) or `gpu`
    /// (WGSL compute shaders, f32).
    #[arg(long, value_enum, default_value = "cpu")]
    backend: Backend,
    /// Render the instant T (seconds of coordinate time) of the scene's
    /// [animation] rather than its start.
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    time: Option<f64>,
    /// Render only tile I (0-based) of N, a band of the image's rows, to
    /// <stem>.tile-<I>-of-<N>.exr beside image.png for `merge` (render only).
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    tile: Option<(u32, u32)>,
}

#[derive(clap::Args)]
struct MergeArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// The instant the tiles were rendered at (`render --time T`).
    #[arg(long, value_name = "T", allow_hyphen_values = true)]
    time: Option<f64>,
    /// No summary line (warnings and errors still print).
    #[arg(long, short)]
    quiet: bool,
    /// Replace existing images named by the scene file even when their
    /// size differs from this image's.
    #[arg(long)]
    overwrite: bool,
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
struct ViewArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Folder for screenshots and saved views (default: the current one).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

#[derive(clap::Args)]
struct AnimateArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Only frames A to B, inclusive and 0-based (e.g. 0..9), or I/N: the
    /// I-th (0-based) of N equal runs of consecutive frames (a job array's
    /// task I of N): a slice of the animation for one job.
    #[arg(long, value_name = "A..B|I/N", value_parser = parse_frames)]
    frames: Option<Frames>,
    /// Render the frames only; leave the video to a later `animate`.
    #[arg(long)]
    no_video: bool,
    /// Worker threads (default: one per core). The frames do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=1024))]
    threads: Option<u16>,
    /// No progress bar or closing line (warnings and errors still print).
    #[arg(long, short)]
    quiet: bool,
    /// Render frames whose files exist too (else they are kept: resume).
    #[arg(long)]
    overwrite: bool,
    /// Where the per-sample work runs: `cpu` or `gpu`.
    #[arg(long, value_enum, default_value = "cpu")]
    backend: Backend,
}

/// A slice of an animation's frames.
#[derive(Clone, Copy, Debug)]
enum Frames {
    /// Frames A to B, inclusive.
    Range(u32, u32),
    /// Run I of N.
    Share(u32, u32),
}

impl Frames {
    /// The first and last frame of an animation of `count` frames.
    fn of(self, count: u32) -> Result<(u32, u32)> {
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
enum Command {
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
    /// Print the quantities a scene implies (r_s, ISCO, shadow size, memory...).
    Info(SceneArgs),
    /// Regenerate the shipped assets (disk texture, spectral disk set, star
    /// panorama) from their fixed seeds.
    Assets(AssetArgs),
}

#[derive(clap::Args)]
struct AssetArgs {
    /// Folder to write disk_rgba.png and sky.png into.
    #[arg(long, default_value = "spectral_assets")]
    out: PathBuf,
    /// Star catalogue CSV for the sky (default: the shipped
    /// spectral_assets/stars/hipparcos_mag8.csv).
    #[arg(long)]
    catalogue: Option<PathBuf>,
    /// Only this asset.
    #[arg(long, value_enum)]
    only: Option<Asset>,
    /// Disk texture side in texels.
    #[arg(long, default_value_t = 1024)]
    disk_size: u32,
    /// Outer disk radius the texture spans, in r_s.
    #[arg(long, default_value_t = 10.0)]
    disk_radius: f64,
    /// Peak disk temperature in kelvin.
    #[arg(long, default_value_t = 5000.0)]
    disk_kelvin: f64,
    /// Side of the spectral disk images in texels.
    #[arg(long, default_value_t = 512)]
    spectral_size: u32,
    /// Wavelengths of the spectral disk set: first,last,step in nm. The
    /// default covers the light that shifts into 380-780 nm for g from
    /// about 0.5 to 1.5.
    #[arg(long, default_value = "200,1200,20")]
    spectral_nm: String,
    /// Panorama width in texels (height is half).
    #[arg(long, default_value_t = 4096)]
    sky_width: u32,
    /// Leave out the Milky Way band.
    #[arg(long)]
    no_milky_way: bool,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Asset {
    Disk,
    Spectral,
    Sky,
    Meshes,
}

/// Loads and builds a scene, printing its warnings.
fn load_scene(args: &SceneArgs) -> Result<Scene> {
    let cfg = SceneConfig::load(&args.config, &args.overrides())?;
    let scene =
        Scene::build(cfg).with_context(|| format!("invalid scene {}", args.config.display()))?;
    print_warnings(&scene.warnings);
    Ok(scene)
}

fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// A plan whose inputs are the scene file and every file the scene reads.
fn plan_of(args: &SceneArgs, cfg: &SceneConfig) -> Plan {
    let mut plan = Plan::new();
    plan.input("the scene file", &args.config);
    for (key, path) in blackhole::files::scene_inputs(cfg) {
        plan.input(key, path);
    }
    plan
}

/// Refuses to replace an existing image named by the scene file (not on
/// the command line) with one of another size, unless `overwrite`: a
/// reduced trial render must not silently replace a full-size result
/// (such as the shipped images in img/).
fn guard_outputs(args: &SceneArgs, overwrite: bool, files: &[(PathBuf, (u32, u32))]) -> Result<()> {
    let overrides = args.overrides();
    if overwrite || blackhole::config::from_cli(&overrides, "image.png") {
        return Ok(());
    }
    for (path, (w, h)) in files {
        if let Ok((ew, eh)) = image::image_dimensions(path)
            && (ew, eh) != (*w, *h)
        {
            bail!(
                "{} exists at {ew} x {eh} and this render is {w} x {h}: name another output with --set image.png=PATH (every output follows it), or pass --overwrite to replace it",
                path.display()
            );
        }
    }
    Ok(())
}

/// Refuses a job whose memory (the scene's assets, its films and the
/// copies its outputs make) would not fit, before it starts.
fn check_memory(cfg: &SceneConfig, job: blackhole::memory::Job, what: &str) -> Result<()> {
    blackhole::memory::film(cfg, job, blackhole::memory::assets(cfg))
        .check(what)
        .map_err(anyhow::Error::msg)
}

/// Sets the worker count (the image does not depend on it).
fn set_threads(threads: Option<u16>) -> Result<()> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()?;
    }
    Ok(())
}

/// Renders with a progress bar (unless quiet); returns the film, the
/// counts and the wall time in seconds.
/// Where the per-sample work runs.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Backend {
    /// The f64 reference on every core.
    Cpu,
    /// WGSL compute shaders through wgpu (f32).
    Gpu,
}

/// A backend ready to render.
enum Renderer {
    Cpu,
    Gpu(Box<blackhole::gpu::Gpu>),
}

impl Renderer {
    /// Opens the backend and checks that it can render `scene`, before
    /// anything is rendered or written.
    fn new(backend: Backend, scene: &Scene) -> Result<Renderer> {
        Ok(match backend {
            Backend::Cpu => Renderer::Cpu,
            Backend::Gpu => {
                blackhole::gpu::check_supported(scene)?;
                Renderer::Gpu(Box::new(blackhole::gpu::Gpu::new()?))
            }
        })
    }

    /// Renders the rows `rows` of `scene`'s image.
    fn render(
        &self,
        scene: &Scene,
        rows: std::ops::Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats)> {
        Ok(match self {
            Renderer::Cpu => scene.render_rows(rows, progress),
            Renderer::Gpu(gpu) => gpu.prepare(scene, u32::MAX)?.render_rows(rows, progress)?,
        })
    }

    /// `cpu`, or `gpu: DEVICE`, for tiles.
    fn backend(&self) -> String {
        match self {
            Renderer::Cpu => "cpu".into(),
            Renderer::Gpu(gpu) => format!("gpu: {}", gpu.name()),
        }
    }

    /// " on DEVICE" for the closing line, or nothing for the CPU.
    fn on(&self) -> String {
        match self {
            Renderer::Cpu => String::new(),
            Renderer::Gpu(gpu) => format!(" on {}", gpu.name()),
        }
    }
}

fn render_scene(
    renderer: &Renderer,
    scene: &Scene,
    quiet: bool,
    what: &str,
) -> Result<(Film, Stats, f64)> {
    render_rows(renderer, scene, 0..scene.camera.height, quiet, what)
}

/// [`render_scene`] of the image's rows `rows` only.
fn render_rows(
    renderer: &Renderer,
    scene: &Scene,
    rows: std::ops::Range<u32>,
    quiet: bool,
    what: &str,
) -> Result<(Film, Stats, f64)> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(rows.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(&format!("{{spinner}} {what} [{{elapsed_precise}}] {{wide_bar}} {{pos}}/{{len}} rows, eta {{eta}}"))
            .expect("valid template"),
    );
    let start = Instant::now();
    let (film, stats) = renderer.render(scene, rows, &|n| bar.inc(n))?;
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    Ok((film, stats, elapsed))
}

/// The closing line of a render. Percentages are of camera samples, each
/// in one class: disk (its light includes the disk's or the gas's), then
/// objects, then sky or captured by how its ray ended.
fn summary_line(film: &Film, stats: &Stats, elapsed: f64, on: &str, written: &[String]) -> String {
    let px = film.width as f64 * film.height as f64;
    let rays = stats.rays.max(1) as f64;
    let pct = |k: u64| percent(k, stats.samples);
    let mut line = format!(
        "rendered {}x{} ({} samples",
        film.width, film.height, stats.samples
    );
    if stats.rays != stats.samples {
        line += &format!(", {} rays", stats.rays);
    }
    line += &format!(
        "){on} in {:.2} s: {:.0} px/s, {:.2} us/px, {:.1} steps/ray; {}% sky, {}% disk, {}% objects, {}% captured",
        elapsed,
        px / elapsed,
        elapsed * 1e6 / px,
        stats.steps as f64 / rays,
        pct(stats.sky),
        pct(stats.disk),
        pct(stats.objects),
        pct(stats.captured),
    );
    for (k, what) in [
        (stats.abandoned, "out of steps"),
        (stats.non_finite, "non-finite"),
    ] {
        if k > 0 {
            line += &format!(", {}% {what}", pct(k));
        }
    }
    if stats.closed == stats.samples && stats.closed > 0 {
        line += "; every sample in closed form";
    } else if stats.closed > 0 {
        line += &format!(
            "; {}% of samples in closed form, the rest integrated",
            pct(stats.closed)
        );
    }
    if stats.g_min.is_finite() && (stats.g_min, stats.g_max) != (1.0, 1.0) {
        line += &format!("; disk g {:.3} to {:.3}", stats.g_min, stats.g_max);
    }
    if !written.is_empty() {
        line += &format!(" -> {}", written.join(", "));
    }
    line
}

/// `k` of `n` as a percentage to one decimal, or as many more as it takes
/// not to read as 0% or 100% when it is neither.
fn percent(k: u64, n: u64) -> String {
    let p = 100.0 * k as f64 / n.max(1) as f64;
    for digits in 1..=12 {
        let text = format!("{p:.digits$}");
        let shown: f64 = text.parse().unwrap_or(p);
        if (shown == 100.0 && k < n) || (shown == 0.0 && k > 0) {
            continue;
        }
        return text;
    }
    format!("{p:e}")
}

/// Warnings about samples that did not come out right.
fn warn_lost(scene: &Scene, stats: &Stats) {
    if stats.abandoned > 0 {
        eprintln!(
            "warning: {} samples ran out of steps (physics.max_steps = {}) and are black beyond where they stopped",
            stats.abandoned, scene.config.physics.max_steps
        );
    }
    if stats.non_finite > 0 {
        eprintln!(
            "warning: {} samples gave no finite value and were left out of their pixels' averages",
            stats.non_finite
        );
    }
}

fn render(args: &RenderArgs) -> Result<()> {
    let quiet = args.quiet;
    set_threads(args.threads)?;
    let mut scene = load_scene(&args.scene)?;
    if let Some(t) = args.time {
        scene
            .set_time(t)
            .with_context(|| format!("invalid scene {}", args.scene.config.display()))?;
    }
    if let Some((i, n)) = args.tile {
        return render_tile(args, &scene, i, n);
    }
    let outputs = Outputs::of(&scene.config);
    outputs.check(&args.scene, &scene.config, &[], args.overwrite)?;
    let job = blackhole::memory::Job::render(&scene.config, args.backend == Backend::Gpu);
    check_memory(&scene.config, job, "the render")?;
    let renderer = Renderer::new(args.backend, &scene)?;
    let (film, stats, elapsed) = render_scene(&renderer, &scene, quiet, "render")?;
    let eyes = match scene.stereo_eyes() {
        Some((left, right)) => {
            let mut films = Vec::new();
            for (eye, tag) in [(&left, "left eye"), (&right, "right eye")] {
                let (f, st, t) = render_scene(&renderer, eye, quiet, tag)?;
                if !quiet {
                    eprintln!("{tag}: {}", summary_line(&f, &st, t, &renderer.on(), &[]));
                }
                films.push(f);
            }
            let right = films.pop().expect("two eyes");
            Some((films.pop().expect("two eyes"), right))
        }
        None => None,
    };
    outputs.write(&scene.config, &film, eyes.as_ref(), quiet, |written| {
        if !quiet {
            eprintln!(
                "{}",
                summary_line(&film, &stats, elapsed, &renderer.on(), written)
            );
            warn_lost(&scene, &stats);
        }
    })
}

/// The files `render` writes for a scene: image.png, the EXR, and with
/// `[stereo]` the eyes and their composites (named after image.png).
struct Outputs {
    main: Vec<PathBuf>,
    stereo: Option<[PathBuf; 4]>,
    size: (u32, u32),
}

impl Outputs {
    fn of(cfg: &SceneConfig) -> Outputs {
        let img = &cfg.image;
        let stem = img.png.with_extension("");
        let stereo_name = |tag: &str| PathBuf::from(format!("{}_{tag}.png", stem.display()));
        Outputs {
            main: std::iter::once(&img.png).chain(&img.exr).cloned().collect(),
            stereo: cfg
                .stereo
                .as_ref()
                .map(|_| ["left", "right", "side_by_side", "anaglyph"].map(stereo_name)),
            size: (img.width, img.height),
        }
    }

    /// Checks every output against the inputs (the scene's and `more`)
    /// and each other, that it can be written, and that it would not
    /// replace an image of another size that the scene file names (unless
    /// `overwrite`).
    fn check(
        &self,
        args: &SceneArgs,
        cfg: &SceneConfig,
        more: &[(String, PathBuf)],
        overwrite: bool,
    ) -> Result<()> {
        let mut plan = plan_of(args, cfg);
        plan.inputs.extend(more.iter().cloned());
        for (p, key) in self.main.iter().zip(["image.png", "image.exr"]) {
            plan.output(key, p);
        }
        let mut sized: Vec<(PathBuf, (u32, u32))> =
            self.main.iter().map(|p| (p.clone(), self.size)).collect();
        if let Some(st) = &self.stereo {
            for (p, tag) in st
                .iter()
                .zip(["left eye", "right eye", "side by side", "anaglyph"])
            {
                plan.output(format!("the stereo {tag}"), p);
            }
            sized.extend(st.iter().enumerate().map(|(i, p)| {
                let w = if i == 2 { 2 * self.size.0 } else { self.size.0 };
                (p.clone(), (w, self.size.1))
            }));
        }
        plan.check()?;
        guard_outputs(args, overwrite, &sized)
    }

    /// Writes the image, the EXR and the stereo files, all or none, then
    /// calls `done` with the names of the image and EXR.
    fn write(
        &self,
        cfg: &SceneConfig,
        film: &Film,
        eyes: Option<&(Film, Film)>,
        quiet: bool,
        done: impl FnOnce(&[String]),
    ) -> Result<()> {
        let img = &cfg.image;
        let mut batch = Batch::new();
        blackhole::output::stage_film(&mut batch, cfg, film, &img.png, img.exr.as_deref(), &[])?;
        if let (Some(files), Some((left, right))) = (&self.stereo, eyes) {
            let srgb = |f: &Film| {
                xyz_to_srgb8(
                    &blackhole::output::displayed(cfg, f),
                    img.exposure,
                    img.tonemap,
                )
            };
            let eyes = [srgb(left), srgb(right)];
            let (w, h) = (film.width, film.height);
            stage_png(&mut batch, &files[0], w, h, &eyes[0])?;
            stage_png(&mut batch, &files[1], w, h, &eyes[1])?;
            let sbs = blackhole::post::side_by_side(w as usize, h as usize, &eyes[0], &eyes[1]);
            stage_png(&mut batch, &files[2], 2 * w, h, &sbs)?;
            let anaglyph = blackhole::post::anaglyph(&eyes[0], &eyes[1]);
            stage_png(&mut batch, &files[3], w, h, &anaglyph)?;
        }
        batch.commit()?;
        let written: Vec<String> = self.main.iter().map(|p| p.display().to_string()).collect();
        done(&written);
        if let Some(files) = &self.stereo
            && eyes.is_some()
            && !quiet
        {
            let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
            eprintln!("stereo pair -> {}", names.join(", "));
        }
        Ok(())
    }
}

/// `render --tile I/N`: the band of rows of tile I, for every view, to
/// its tile file.
fn render_tile(args: &RenderArgs, scene: &Scene, i: u32, n: u32) -> Result<()> {
    let quiet = args.quiet;
    let (w, h) = (scene.camera.width, scene.camera.height);
    blackhole::tiles::check_tile(i, n, h)?;
    let rows = blackhole::tiles::tile_rows(h, i, n);
    let path = blackhole::tiles::tile_path(&scene.image().png, i, n);
    let mut plan = plan_of(&args.scene, &scene.config);
    plan.output(format!("tile {i}/{n}"), &path);
    plan.check()?;
    let job = blackhole::memory::Job {
        rows: rows.len() as u32,
        films: if scene.config.stereo.is_some() { 3 } else { 1 },
        outputs: false,
        gpu: args.backend == Backend::Gpu,
    };
    check_memory(&scene.config, job, &format!("tile {i}/{n}"))?;
    let hash = blackhole::tiles::scene_hash(&scene.config, args.time)?;
    // A complete tile of this scene is kept (a job array submitted again
    // renders only what is missing); one of another scene is an error.
    if path.exists() && !args.overwrite {
        let again = "remove it, or pass --overwrite to render it again";
        let tile = blackhole::tiles::read_tile(&path).with_context(|| {
            format!("{} exists and is not a whole tile: {again}", path.display())
        })?;
        if tile.scene != hash || (tile.index, tile.count) != (i, n) || tile.rows != rows {
            bail!(
                "{} exists and is not tile {i}/{n} of this scene ({} with these settings): {again}",
                path.display(),
                args.scene.config.display()
            );
        }
        if !quiet {
            eprintln!("tile {i}/{n} is complete: kept {}", path.display());
        }
        return Ok(());
    }
    let renderer = Renderer::new(args.backend, scene)?;
    let start = Instant::now();
    let mut views = Vec::new();
    let mut scenes = vec![("main", None)];
    if let Some((left, right)) = scene.stereo_eyes() {
        scenes.push(("left", Some(left)));
        scenes.push(("right", Some(right)));
    }
    let mut main_line = None;
    for (name, eye) in &scenes {
        let s = eye.as_ref().unwrap_or(scene);
        let what = format!("tile {i}/{n} {name}");
        let (film, stats, t) = render_rows(&renderer, s, rows.clone(), quiet, &what)?;
        if main_line.is_none() {
            main_line = Some((film.clone(), stats, t));
        }
        views.push(blackhole::tiles::View {
            name: name.to_string(),
            film,
            stats,
        });
    }
    let seconds = start.elapsed().as_secs_f64();
    blackhole::tiles::write_tile(
        &path,
        &blackhole::tiles::Tile {
            index: i,
            count: n,
            width: w,
            height: h,
            rows: rows.clone(),
            scene: hash,
            backend: renderer.backend(),
            seconds,
            views,
        },
    )?;
    if !quiet {
        let (film, stats, t) = main_line.expect("the main view");
        eprintln!(
            "tile {i} of {n}, rows {}..{} of {w}x{h}: {}",
            rows.start,
            rows.end - 1,
            summary_line(
                &film,
                &stats,
                t,
                &renderer.on(),
                &[path.display().to_string()]
            )
        );
        warn_lost(scene, &stats);
    }
    Ok(())
}

/// `merge`: checks the tiles beside image.png are one whole set of this
/// scene, assembles every view's film and writes what `render` writes.
fn merge(args: &MergeArgs) -> Result<()> {
    let start = Instant::now();
    let config = args.scene.config.as_path();
    let cfg = SceneConfig::load(config, &args.scene.overrides())?;
    let hash = blackhole::tiles::scene_hash(&cfg, args.time)?;
    let found = blackhole::tiles::find_tiles(&cfg.image.png)?;
    let outputs = Outputs::of(&cfg);
    let tiles: Vec<(String, PathBuf)> = found
        .iter()
        .map(|(i, n, p)| (format!("tile {i}/{n}"), p.clone()))
        .collect();
    outputs.check(&args.scene, &cfg, &tiles, args.overwrite)?;
    // The tiles as read, and the films joined from them.
    let views = if cfg.stereo.is_some() { 3 } else { 1 };
    let job = blackhole::memory::Job {
        rows: cfg.image.height,
        films: 2 * views,
        outputs: true,
        gpu: false,
    };
    check_memory(&cfg, job, "the merge")?;
    let (w, h) = (cfg.image.width, cfg.image.height);
    let n = found[0].1;
    let mut views: Vec<(String, Vec<Film>, Stats)> = Vec::new();
    let (mut seconds, mut backend) = (0.0, None::<String>);
    for (i, _, path) in &found {
        let tile = blackhole::tiles::read_tile(path)?;
        if tile.scene != hash {
            // Enough digits to tell the two apart.
            let differ = tile
                .scene
                .bytes()
                .zip(hash.bytes())
                .position(|(a, b)| a != b)
                .unwrap_or(0);
            let digits = (differ + 4).clamp(12, hash.len());
            let cut = |h: &str| h.get(..digits.min(h.len())).unwrap_or(h).to_string();
            bail!(
                "{} belongs to another scene (hash {}...) than {} with these settings (hash {}...): render it again from this scene, or merge with the settings it was rendered with (--set, --unset, --time)",
                path.display(),
                cut(&tile.scene),
                config.display(),
                cut(&hash)
            );
        }
        if (tile.index, tile.count) != (*i, n) {
            bail!(
                "{} holds tile {}/{}, not the {i}/{n} its name says",
                path.display(),
                tile.index,
                tile.count
            );
        }
        let rows = blackhole::tiles::tile_rows(h, *i, n);
        if (tile.width, tile.height) != (w, h) || tile.rows != rows {
            bail!(
                "{} holds rows {}..{} of a {}x{} image; tile {i}/{n} of {w}x{h} is rows {}..{} (inclusive): render it again from this scene",
                path.display(),
                tile.rows.start,
                tile.rows.end.saturating_sub(1),
                tile.width,
                tile.height,
                rows.start,
                rows.end - 1
            );
        }
        let kind = |b: &str| b.split(':').next().unwrap_or("").to_string();
        match &backend {
            None => backend = Some(tile.backend.clone()),
            Some(b) if kind(b) != kind(&tile.backend) => bail!(
                "{} was rendered on {}, other tiles on {b}: the backends give slightly different pixels, so a set must come from one",
                path.display(),
                tile.backend
            ),
            _ => {}
        }
        seconds += tile.seconds;
        if views.is_empty() {
            views = tile
                .views
                .iter()
                .map(|v| (v.name.clone(), Vec::new(), Stats::default()))
                .collect();
        }
        for v in tile.views {
            let slot = views.iter_mut().find(|s| s.0 == v.name).ok_or_else(|| {
                anyhow::anyhow!("{}: an unexpected view {}", path.display(), v.name)
            })?;
            slot.1.push(v.film);
            slot.2 = slot.2 + v.stats;
        }
    }
    let mut films: Vec<(String, Film, Stats)> = views
        .into_iter()
        .map(|(name, parts, st)| (name, blackhole::tiles::join(parts), st))
        .collect();
    let take = |films: &mut Vec<(String, Film, Stats)>, name: &str| {
        films
            .iter()
            .position(|f| f.0 == name)
            .map(|i| films.remove(i))
    };
    let (_, film, stats) =
        take(&mut films, "main").ok_or_else(|| anyhow::anyhow!("the tiles hold no main view"))?;
    let eyes = match (take(&mut films, "left"), take(&mut films, "right")) {
        (Some(l), Some(r)) => Some((l.1, r.1)),
        _ => None,
    };
    let backend = backend.unwrap_or_default();
    let on = match backend.split_once(": ") {
        Some((_, device)) => format!(" on {device}"),
        None => String::new(),
    };
    outputs.write(&cfg, &film, eyes.as_ref(), args.quiet, |written| {
        if !args.quiet {
            eprintln!(
                "merged {n} tile(s) in {:.2} s; {}",
                start.elapsed().as_secs_f64(),
                summary_line(&film, &stats, seconds, &on, written)
            );
        }
    })
}

/// Renders a spectral scene with the frequency shift off and on and writes
/// both images (PNG and EXR), a labelled side-by-side image, a CIEDE2000
/// difference map with a colour bar, and a summary, all named after
/// `image.png` (`NAME_shift_off.png`, `NAME_shift_on.png`, `.exr`,
/// `NAME_side_by_side.png`, `NAME_delta_e.png`, `NAME_summary.txt`).
fn compare(args: &RenderArgs) -> Result<()> {
    let quiet = args.quiet;
    if args.tile.is_some() {
        bail!(
            "--tile is for render (compare writes whole images); render each setting's tiles with render --tile and --set spectral.shift=..."
        );
    }
    let config = args.scene.config.as_path();
    set_threads(args.threads)?;
    let base = SceneConfig::load(config, &args.scene.overrides())?;
    if !base.spectral.enabled {
        bail!(
            "{}: compare needs a spectral scene ([spectral] enabled = true): the shift exists only in spectral renders",
            config.display()
        );
    }
    let build = |shift: bool| {
        let mut c = base.clone();
        c.spectral.shift = shift;
        let mut scene =
            Scene::build(c).with_context(|| format!("invalid scene {}", config.display()))?;
        if let Some(t) = args.time {
            scene
                .set_time(t)
                .with_context(|| format!("invalid scene {}", config.display()))?;
        }
        anyhow::Ok(scene)
    };
    let (off, on) = (build(false)?, build(true)?);
    let renderer = Renderer::new(args.backend, &on)?;
    print_warnings(&on.warnings);
    if base.stereo.is_some() {
        eprintln!("warning: [stereo] does nothing under compare, which renders the mono view");
    }
    let img = base.image.clone();
    let dir = img.png.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = img
        .png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "compare".into());
    let name = |suffix: &str| dir.join(format!("{stem}_{suffix}"));
    let mut plan = plan_of(&args.scene, &base);
    for suffix in [
        "shift_off.png",
        "shift_off.exr",
        "shift_on.png",
        "shift_on.exr",
        "side_by_side.png",
        "delta_e.png",
        "summary.txt",
    ] {
        plan.output(format!("compare's {suffix}"), name(suffix));
    }
    plan.check()?;
    let job = blackhole::memory::Job {
        rows: base.image.height,
        films: 2,
        outputs: true,
        gpu: args.backend == Backend::Gpu,
    };
    check_memory(&base, job, "the comparison")?;
    let (w, h) = (off.camera.width, off.camera.height);
    guard_outputs(
        &args.scene,
        args.overwrite,
        &[
            (name("shift_off.png"), (w, h)),
            (name("shift_on.png"), (w, h)),
            (name("shift_off.exr"), (w, h)),
            (name("shift_on.exr"), (w, h)),
        ],
    )?;
    let mut written = Vec::new();
    let mut results = Vec::new();
    // Every file of the comparison is written, or none.
    let mut batch = Batch::new();
    for (scene, tag) in [(&off, "shift_off"), (&on, "shift_on")] {
        let (film, stats, elapsed) = render_scene(&renderer, scene, quiet, tag)?;
        let shown = scene.displayed(&film);
        let rgb = xyz_to_srgb8(&shown, img.exposure, img.tonemap);
        let (png, exr) = (name(&format!("{tag}.png")), name(&format!("{tag}.exr")));
        stage_png(&mut batch, &png, film.width, film.height, &rgb)?;
        stage_exr(&mut batch, &exr, &film, img.exr_xyz, img.exr_half)?;
        if !quiet {
            eprintln!(
                "{}",
                summary_line(&film, &stats, elapsed, &renderer.on(), &[])
            );
            warn_lost(scene, &stats);
        }
        written.extend([png.display().to_string(), exr.display().to_string()]);
        let xyz = shown.into_owned();
        results.push((Film { xyz, ..film }, stats, elapsed, rgb));
    }
    let (w, h) = (results[0].0.width as usize, results[0].0.height as usize);
    let displayed = |film: &Film| {
        let e = img.exposure as f32;
        film.linear_srgb()
            .into_iter()
            .map(|c| tone_map(c, e, img.tonemap))
            .collect::<Vec<_>>()
    };
    let (a, b) = (displayed(&results[0].0), displayed(&results[1].0));
    let de: Vec<f64> = a
        .iter()
        .zip(&b)
        .map(|(p, q)| compare::delta_e(*p, *q))
        .collect();
    let st = compare::stats(&de);
    let g = &results[1].1;
    let g_text = if g.g_min.is_finite() {
        format!("g = {:.2} to {:.2} on the disk", g.g_min, g.g_max)
    } else {
        "no disk in view".to_string()
    };
    let sbs = compare::side_by_side(
        w,
        h,
        &results[0].3,
        &results[1].3,
        ["shift off", &format!("shift on, {g_text}")],
    );
    let sbs_path = name("side_by_side.png");
    stage_png(
        &mut batch,
        &sbs_path,
        sbs.width as u32,
        sbs.height as u32,
        &sbs.rgb,
    )?;
    // Colour bar up to a round number above the 99.5th percentile, so a
    // few extreme pixels do not wash out the map.
    let mut sorted = de.clone();
    sorted.sort_by(f64::total_cmp);
    let p995 = sorted[((0.995 * sorted.len() as f64) as usize).min(sorted.len() - 1)];
    let top = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        .into_iter()
        .find(|&t| t >= p995)
        .unwrap_or(100.0);
    let map = compare::delta_e_map(w, h, &de, top);
    let map_path = name("delta_e.png");
    stage_png(
        &mut batch,
        &map_path,
        map.width as u32,
        map.height as u32,
        &map.rgb,
    )?;
    let summary = format!(
        "shift on/off comparison of {config}\n\
         image: {w} x {h}, {wl} wavelengths, model {model}, beaming {beaming}, doppler {doppler}\n\
         frequency shift on the disk: g from {gmin:.4} to {gmax:.4}\n\
         CIEDE2000 (displayed colours, D65): mean {mean:.3}, 95th percentile {p95:.3}, max {max:.3}\n\
         pixels differing noticeably (dE00 > 2.3): {frac:.1}%\n\
         render time: shift off {t0:.2} s, shift on {t1:.2} s\n\
         files: {files}\n",
        config = config.display(),
        wl = base.spectral.wavelengths,
        model = base.physics.model.name(),
        beaming = base.spectral.beaming,
        doppler = base.spectral.doppler,
        gmin = g.g_min,
        gmax = g.g_max,
        mean = st.mean,
        p95 = st.p95,
        max = st.max,
        frac = 100.0 * st.noticeable,
        t0 = results[0].2,
        t1 = results[1].2,
        files = written
            .iter()
            .map(PathBuf::from)
            .chain([sbs_path.clone(), map_path.clone()])
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect::<Vec<_>>()
            .join(", "),
    );
    let summary_path = name("summary.txt");
    batch.write(&summary_path, |w| {
        std::io::Write::write_all(w, summary.as_bytes())?;
        Ok(())
    })?;
    batch.commit()?;
    if !quiet {
        print!("{summary}");
    }
    Ok(())
}

/// The shipped star catalogue: in the current folder's checkout, else in
/// the one this binary was built from.
fn shipped_catalogue() -> PathBuf {
    let rel = Path::new("spectral_assets/stars/hipparcos_mag8.csv");
    if rel.is_file() {
        return rel.to_path_buf();
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The PNG text chunks of an animation frame: its scene's hash and number.
const FRAME_SCENE: &str = "blackhole:scene";
const FRAME_NUMBER: &str = "blackhole:frame";

/// `NAME_<k:05>.EXT` beside image.png.
fn frame_file(png: &Path, k: u32, ext: &str) -> PathBuf {
    let stem = png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "frame".into());
    png.with_file_name(format!("{stem}_{k:05}.{ext}"))
}

/// Renders the frames of the scene's [animation] (or the slice --frames
/// asks for), skipping complete ones, then the video once every frame
/// exists.
fn animate(args: &AnimateArgs) -> Result<()> {
    let quiet = args.quiet;
    let config = args.scene.config.as_path();
    set_threads(args.threads)?;
    let mut scene = load_scene(&args.scene)?;
    let Some(anim) = scene.animation.clone().filter(|a| a.timed) else {
        bail!(
            "{}: animate needs an [animation] table with frames, fps and duration (see the README)",
            config.display()
        );
    };
    let (first, last) = args
        .frames
        .unwrap_or(Frames::Range(0, anim.frames - 1))
        .of(anim.frames)?;
    // Frames carry the scene's hash: a set never mixes scenes.
    let hash = blackhole::tiles::scene_hash(&scene.config, None)?;
    if let Some(v) = &anim.video {
        blackhole::video::check(v, anim.fps)?;
    }
    if scene.config.stereo.is_some() {
        eprintln!("warning: [stereo] does nothing under animate, which renders the mono view");
    }
    let img = scene.image().clone();
    let png = |k| frame_file(&img.png, k, "png");
    let exr = |k| img.exr.as_ref().map(|_| frame_file(&img.png, k, "exr"));
    // A frame is complete when its files exist (they are written
    // atomically, together); one of another size, or whose PNG or EXR
    // carries another scene's hash or frame number, is a stale frame.
    let complete = |k: u32| -> Result<bool> {
        let files: Vec<PathBuf> = std::iter::once(png(k)).chain(exr(k)).collect();
        if !files.iter().all(|f| f.exists()) {
            return Ok(false);
        }
        if let Ok((w, h)) = image::image_dimensions(&files[0])
            && (w, h) != (img.width, img.height)
        {
            bail!(
                "{} exists at {w} x {h} and this animation renders {} x {}: remove the stale frames or pass --overwrite",
                files[0].display(),
                img.width,
                img.height
            );
        }
        for f in &files {
            let tag = |key| {
                if f.extension().is_some_and(|e| e == "exr") {
                    blackhole::output::exr_tag(f, key).ok().flatten()
                } else {
                    blackhole::output::png_text(f, key).ok().flatten()
                }
            };
            if tag(FRAME_SCENE).as_deref() != Some(hash.as_str())
                || tag(FRAME_NUMBER) != Some(k.to_string())
            {
                bail!(
                    "{} is not frame {k} of this scene ({} with these settings): it was rendered from another config or by another version; remove the frames, name another image.png, or pass --overwrite to render them again",
                    f.display(),
                    config.display()
                );
            }
        }
        Ok(true)
    };
    let mut todo = Vec::new();
    for k in first..=last {
        if args.overwrite || !complete(k)? {
            todo.push(k);
        }
    }
    let skipped = (last - first + 1) as usize - todo.len();
    if args.backend == Backend::Gpu {
        // The frames furthest from t = 0 are the first and the last.
        for k in [todo.first(), todo.last()].into_iter().flatten() {
            blackhole::gpu::check_time(&scene, &format!("frame {k}"), anim.time(*k))?;
        }
    }
    // Frames to write are outputs; the video reads every frame.
    let mut plan = plan_of(&args.scene, &scene.config);
    for &k in &todo {
        plan.output(format!("frame {k}"), png(k));
        if let Some(e) = exr(k) {
            plan.output(format!("frame {k}'s EXR"), e);
        }
    }
    let video = anim.video.as_ref().filter(|_| !args.no_video);
    if let Some(v) = video {
        for k in (0..anim.frames).filter(|k| todo.binary_search(k).is_err()) {
            plan.input(format!("frame {k} (the video is made from it)"), png(k));
        }
        plan.output("animation.video", v);
    }
    plan.check()?;
    let job = blackhole::memory::Job {
        rows: img.height,
        films: 1,
        outputs: true,
        gpu: args.backend == Backend::Gpu,
    };
    check_memory(&scene.config, job, "each frame")?;
    let renderer = Renderer::new(args.backend, &scene)?;
    let mut prepared = match &renderer {
        Renderer::Gpu(gpu) if !todo.is_empty() => Some(gpu.prepare(&scene, u32::MAX)?),
        _ => None,
    };
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(todo.len() as u64 * img.height as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} frame {msg} [{elapsed_precise}] {wide_bar} {percent}%, eta {eta}",
        )
        .expect("valid template"),
    );
    let start = Instant::now();
    let mut lost = Stats::default();
    for &k in &todo {
        bar.set_message(format!("{k} of {first}..{last}"));
        scene
            .set_time(anim.time(k))
            .with_context(|| format!("invalid scene {}", config.display()))?;
        let (film, stats) = match &mut prepared {
            Some(p) => {
                p.set_frame(&scene)?;
                p.render(&|n| bar.inc(n))?
            }
            None => scene.render(&|n| bar.inc(n)),
        };
        lost.abandoned += stats.abandoned;
        lost.non_finite += stats.non_finite;
        let mut batch = Batch::new();
        blackhole::output::stage_film(
            &mut batch,
            &scene.config,
            &film,
            &png(k),
            exr(k).as_deref(),
            &[(FRAME_SCENE, hash.clone()), (FRAME_NUMBER, k.to_string())],
        )?;
        batch.commit()?;
    }
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    warn_lost(&scene, &lost);
    let mut line = format!(
        "animated {} frame(s) of {first}..{last}{}{} in {elapsed:.2} s: {:.1} frames per minute",
        todo.len(),
        if skipped > 0 {
            format!(" ({skipped} already complete)")
        } else {
            String::new()
        },
        renderer.on(),
        todo.len() as f64 * 60.0 / elapsed.max(1e-9),
    );
    if let Some(v) = video {
        let mut missing = Vec::new();
        for k in 0..anim.frames {
            if !complete(k)? {
                missing.push(k);
            }
        }
        if missing.is_empty() {
            let frames: Vec<PathBuf> = (0..anim.frames).map(png).collect();
            blackhole::video::encode(&frames, anim.fps, anim.quality, v)?;
            line += &format!(" -> {}", v.display());
        } else {
            line += &format!(
                "; the video waits for {} more frame(s) (first missing: {})",
                missing.len(),
                missing[0]
            );
        }
    }
    if !quiet {
        eprintln!("{line}");
    }
    Ok(())
}

fn generate_assets(a: AssetArgs) -> Result<()> {
    let out = a.out.as_path();
    let want = |x: Asset| a.only.is_none_or(|o| o == x);
    if !(a.disk_radius > 3.0 && a.disk_radius.is_finite()) {
        bail!(
            "--disk-radius {}: expected a finite radius beyond 3 r_s (the ISCO)",
            a.disk_radius
        );
    }
    if !(a.disk_kelvin > 0.0 && a.disk_kelvin.is_finite()) {
        bail!(
            "--disk-kelvin {}: expected a finite temperature > 0",
            a.disk_kelvin
        );
    }
    // Sizes a texture can have, and the memory their making takes, before
    // anything is written.
    for (flag, n, most) in [
        ("--disk-size", a.disk_size, 65_536),
        ("--spectral-size", a.spectral_size, 65_536),
        ("--sky-width", a.sky_width, 65_536),
    ] {
        if n > most {
            bail!("{flag} {n}: expected at most {most} texels");
        }
    }
    // Check every input before writing anything.
    let stars = if want(Asset::Sky) {
        if a.sky_width < 2 || !a.sky_width.is_multiple_of(2) {
            bail!("--sky-width {}: expected an even number >= 2", a.sky_width);
        }
        let cat = a.catalogue.clone().unwrap_or_else(shipped_catalogue);
        let text = std::fs::read_to_string(&cat).with_context(|| {
            format!(
                "cannot read the star catalogue {} (name one with --catalogue CSV)",
                cat.display()
            )
        })?;
        Some(
            blackhole::starmap::parse_catalogue(&text)
                .map_err(|e| anyhow::anyhow!("--catalogue {}: {e}", cat.display()))?,
        )
    } else {
        None
    };
    let nm = if want(Asset::Spectral) {
        if a.spectral_size == 0 {
            bail!("--spectral-size must be >= 1");
        }
        parse_range(&a.spectral_nm)?
    } else {
        Vec::new()
    };
    if want(Asset::Disk) && a.disk_size == 0 {
        bail!("--disk-size must be >= 1");
    }
    let mut need = blackhole::memory::Need::default();
    let sq = |n: u32| n as u64 * n as u64;
    if want(Asset::Disk) {
        // The disk's texels (density, temperature, alpha) and the image.
        need.parts
            .push(("--disk-size".into(), 16 * sq(a.disk_size)));
    }
    if want(Asset::Spectral) {
        // The texels, the alpha and every wavelength's 16-bit image.
        let bytes = (13 + 2 * nm.len() as u64) * sq(a.spectral_size);
        need.parts.push(("--spectral-size".into(), bytes));
    }
    if want(Asset::Sky) {
        // The star map while it is built, and the 8-bit panorama.
        let texels = a.sky_width as u64 * (a.sky_width as u64 / 2);
        need.parts.push(("--sky-width".into(), 15 * texels));
    }
    need.check("making the assets")
        .map_err(anyhow::Error::msg)?;
    let params = assets::disk::DiskParams {
        size: a.disk_size,
        outer: a.disk_radius,
        peak_kelvin: a.disk_kelvin,
        ..Default::default()
    };
    if want(Asset::Disk) {
        let img = assets::disk::generate(&params);
        let path = out.join("disk_rgba.png");
        write_png_as(
            &path,
            img.width(),
            img.height(),
            img.as_raw(),
            image::ExtendedColorType::Rgba8,
            true,
        )?;
        eprintln!("wrote {}", path.display());
    }
    if want(Asset::Spectral) {
        let (files, manifest) = assets::disk::generate_spectral(&params, a.spectral_size, &nm);
        let dir = out.join("disk_spectral");
        for (name, img) in &files {
            let color = img.color().into();
            write_png_as(
                &dir.join(name),
                img.width(),
                img.height(),
                img.as_bytes(),
                color,
                true,
            )?;
        }
        blackhole::output::write_atomic(&dir.join("manifest.toml"), |w| {
            std::io::Write::write_all(w, manifest.as_bytes())?;
            Ok(())
        })?;
        eprintln!(
            "wrote {} ({} wavelengths)",
            dir.join("manifest.toml").display(),
            nm.len()
        );
    }
    if want(Asset::Meshes) {
        let dir = out.join("meshes");
        for seed in 0..3u32 {
            let (v, f) = assets::asteroid::asteroid(seed, 4, 0.28);
            let name = format!("asteroid_{seed}.obj");
            let header = format!(
                "blackhole assets: asteroid, seed {seed}, icosphere level 4, roughness 0.28"
            );
            let text = assets::asteroid::to_obj(&v, &f, &header);
            blackhole::output::write_atomic(&dir.join(&name), |w| {
                std::io::Write::write_all(w, text.as_bytes())?;
                Ok(())
            })?;
            eprintln!(
                "wrote {} ({} triangles)",
                dir.join(&name).display(),
                f.len()
            );
        }
    }
    if let Some(stars) = stars {
        let p = assets::sky::SkyParams {
            width: a.sky_width,
            milky_way: !a.no_milky_way,
        };
        let img = assets::sky::generate(&stars, &p);
        let path = out.join("sky.png");
        write_png_as(
            &path,
            img.width(),
            img.height(),
            img.as_raw(),
            image::ExtendedColorType::Rgb8,
            true,
        )?;
        eprintln!("wrote {} ({} stars)", path.display(), stars.len());
    }
    Ok(())
}

fn colour(path: &Path) -> Result<()> {
    use blackhole::spectrum::color::{srgb_encode, xyz_to_linear_srgb};
    use blackhole::spectrum::sampled::{MAX_WAVELENGTHS, Wavelengths};
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines
        .next()
        .with_context(|| format!("{}: empty file", path.display()))?;
    let nm: Vec<f64> = header
        .split(',')
        .skip(1)
        .map(|h| h.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{}: header must be id,<nm>,<nm>,...", path.display()))?;
    let n = nm.len();
    if !(2..=MAX_WAVELENGTHS).contains(&n) {
        bail!(
            "{}: expected 2 to {MAX_WAVELENGTHS} wavelengths, found {n}",
            path.display()
        );
    }
    let wl = Wavelengths::new(n);
    if nm.iter().zip(&wl.nm).any(|(a, b)| (a - b).abs() > 1e-9) {
        bail!(
            "{}: the wavelengths must be {n} evenly spaced samples from 380 to 780 nm ({} nm apart)",
            path.display(),
            wl.step
        );
    }
    let mut out = String::from("id,X,Y,Z,R,G,B,sR,sG,sB\n");
    for (i, line) in lines {
        let mut f = line.split(',');
        let id = f.next().unwrap_or_default().trim();
        let v: Vec<f32> = f
            .map(|x| x.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("{} line {}: expected numbers", path.display(), i + 1))?;
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            bail!(
                "{} line {}: the value at {} nm is {}: expected finite numbers",
                path.display(),
                i + 1,
                nm.get(k).copied().unwrap_or(f64::NAN),
                v[k]
            );
        }
        if v.len() != n {
            bail!(
                "{} line {}: {} values for {n} wavelengths",
                path.display(),
                i + 1,
                v.len()
            );
        }
        let xyz = wl.xyz(&v);
        let rgb = xyz_to_linear_srgb(xyz);
        let enc = rgb
            .to_array()
            .map(|c| srgb_encode(c.clamp(0.0, 1.0) as f32));
        out += &format!(
            "{id},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.9},{:.9},{:.9}\n",
            xyz.x, xyz.y, xyz.z, rgb.x, rgb.y, rgb.z, enc[0], enc[1], enc[2]
        );
    }
    print!("{out}");
    Ok(())
}

/// Parses "first,last,step" (nm) into the wavelengths it spans.
fn parse_range(text: &str) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--spectral-nm {text}: expected first,last,step in nm"))?;
    match v[..] {
        [a, b, d] if a > 0.0 && b >= a && d > 0.0 && ((b - a) / d) < 10_000.0 => {
            Ok((0..=((b - a) / d + 1e-9) as usize)
                .map(|i| a + i as f64 * d)
                .collect())
        }
        _ => bail!(
            "--spectral-nm {text}: expected first,last,step with 0 < first <= last and step > 0"
        ),
    }
}

fn view(a: ViewArgs) -> Result<()> {
    let out = match a.out {
        Some(d) => d,
        None => std::env::current_dir().context("cannot read the current directory")?,
    };
    if out.exists() && !out.is_dir() {
        bail!("--out {}: not a folder", out.display());
    }
    let session =
        blackhole::view::Session::open(&a.scene.config, a.scene.overrides(), out.clone())?;
    // Made once the scene is known to be good, as render makes its
    // outputs' folders.
    std::fs::create_dir_all(&out)
        .with_context(|| format!("--out {}: cannot create the folder", out.display()))?;
    for w in &session.original.warnings {
        eprintln!("warning: {w}");
    }
    blackhole::view::run(session)
}

/// Whether the command opens the GPU.
fn uses_gpu(c: &Command) -> bool {
    match c {
        Command::Render(a) | Command::Compare(a) => a.backend == Backend::Gpu,
        Command::Animate(a) => a.backend == Backend::Gpu,
        Command::View(_) => true,
        _ => false,
    }
}

/// Gives the process a private runtime folder when `XDG_RUNTIME_DIR` is
/// unset or not a folder of ours (as on servers and in containers), where
/// Mesa's Vulkan drivers otherwise print an error on every run although it
/// succeeds. Called before any other thread starts: the environment is
/// changed while nothing else reads it.
fn ensure_runtime_dir() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    // SAFETY: getuid cannot fail.
    let uid = unsafe { libc::getuid() };
    let ours = |p: &Path| {
        std::fs::metadata(p).is_ok_and(|m| m.is_dir() && m.uid() == uid && m.mode() & 0o077 == 0)
    };
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| ours(Path::new(&d))) {
        return;
    }
    let dir = std::env::temp_dir().join(format!("blackhole-runtime-{uid}"));
    let made = std::fs::create_dir(&dir).is_ok();
    if made {
        let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
    }
    if ours(&dir) {
        // SAFETY: no other thread exists yet (see above).
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(a) => render(&a),
        Command::Compare(a) => compare(&a),
        Command::Animate(a) => animate(&a),
        Command::Merge(a) => merge(&a),
        Command::View(a) => view(a),
        Command::Colour { spectra } => colour(&spectra),
        Command::Info(a) => {
            let scene = load_scene(&a)?;
            print!("{}", blackhole::info::report(&scene));
            Ok(())
        }
        Command::Assets(a) => generate_assets(a),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if uses_gpu(&cli.command) {
        ensure_runtime_dir();
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

#[cfg(test)]
mod tests {
    #[test]
    fn shares_never_read_as_all_or_none_when_they_are_not() {
        assert_eq!(super::percent(1, 3), "33.3");
        assert_eq!(super::percent(999_999, 1_000_000), "99.9999");
        assert_eq!(super::percent(1, 1_000_000), "0.0001");
        assert_eq!(super::percent(5, 5), "100.0");
        assert_eq!(super::percent(0, 5), "0.0");
    }
}
