//! The `blackhole` command line: render, info, assets.

use anyhow::{Context, Result, bail};
use blackhole::assets;
use blackhole::config::{Override, SceneConfig};
use blackhole::output::{to_srgb8, write_exr, write_png};
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

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to the PNG (and EXR) it names.
    Render {
        /// Scene file (TOML).
        config: PathBuf,
        /// Override a config value, e.g. --set image.width=256 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Worker threads (default: one per core). The image does not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress bar or summary.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Print the quantities a scene implies (r_s, ISCO, shadow size, memory...).
    Info {
        /// Scene file (TOML).
        config: PathBuf,
        /// Override a config value (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Regenerate the shipped assets (disk texture, star panorama) from
    /// their fixed seeds.
    Assets {
        /// Folder to write disk_rgba.png and sky.png into.
        #[arg(long, default_value = "spectral_assets")]
        out: PathBuf,
        /// Star catalogue CSV (default: OUT/stars/hipparcos_mag8.csv).
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
        /// Panorama width in texels (height is half).
        #[arg(long, default_value_t = 4096)]
        sky_width: u32,
        /// Leave out the Milky Way band.
        #[arg(long)]
        no_milky_way: bool,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Asset {
    Disk,
    Sky,
}

fn load_scene(config: &Path, set: &[String]) -> Result<Scene> {
    let overrides = set
        .iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let cfg = SceneConfig::load(config, &overrides)?;
    Scene::build(cfg).with_context(|| format!("invalid scene {}", config.display()))
}

fn render(config: &Path, set: &[String], threads: Option<usize>, quiet: bool) -> Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            bail!("--threads 0: expected at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()?;
    }
    let scene = load_scene(config, set)?;
    let img = scene.image().clone();
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(img.height as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} rows, eta {eta}",
        )
        .expect("valid template"),
    );
    let start = Instant::now();
    let (film, stats) = scene.render(&|n| bar.inc(n));
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let rgb = to_srgb8(&film, img.exposure, img.tonemap);
    write_png(&img.png, film.width, film.height, &rgb)?;
    let mut written = vec![img.png.display().to_string()];
    if let Some(exr) = &img.exr {
        write_exr(exr, &film, img.exr_xyz)?;
        written.push(exr.display().to_string());
    }
    if !quiet {
        let px = film.width as f64 * film.height as f64;
        eprintln!(
            "rendered {}x{} ({} rays) in {:.2} s: {:.0} px/s, {:.2} us/px, {:.1} steps/ray; {:.1}% sky, {:.1}% disk, {:.1}% captured -> {}",
            film.width,
            film.height,
            stats.rays,
            elapsed,
            px / elapsed,
            elapsed * 1e6 / px,
            stats.steps as f64 / stats.rays as f64,
            100.0 * stats.sky as f64 / stats.rays as f64,
            100.0 * stats.disk as f64 / stats.rays as f64,
            100.0 * stats.captured as f64 / stats.rays as f64,
            written.join(", ")
        );
        if stats.abandoned > 0 {
            eprintln!(
                "warning: {} rays ran out of steps (physics.max_steps = {}) and are black",
                stats.abandoned, scene.config.physics.max_steps
            );
        }
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn generate_assets(
    out: &Path,
    catalogue: Option<PathBuf>,
    only: Option<Asset>,
    disk_size: u32,
    disk_radius: f64,
    disk_kelvin: f64,
    sky_width: u32,
    no_milky_way: bool,
) -> Result<()> {
    if only != Some(Asset::Sky) {
        if disk_size == 0 || !(disk_radius > 3.0) || !(disk_kelvin > 0.0) {
            bail!("--disk-size must be >= 1, --disk-radius > 3 (the ISCO), --disk-kelvin > 0");
        }
        let p = assets::disk::DiskParams {
            size: disk_size,
            outer: disk_radius,
            peak_kelvin: disk_kelvin,
            ..Default::default()
        };
        let img = assets::disk::generate(&p);
        let path = out.join("disk_rgba.png");
        write_rgba_png(&path, &img)?;
        eprintln!("wrote {}", path.display());
    }
    if only != Some(Asset::Disk) {
        if sky_width < 2 || sky_width % 2 != 0 {
            bail!("--sky-width {sky_width}: expected an even number >= 2");
        }
        let cat = catalogue.unwrap_or_else(|| out.join("stars").join("hipparcos_mag8.csv"));
        let text = std::fs::read_to_string(&cat)
            .with_context(|| format!("cannot read star catalogue {}", cat.display()))?;
        let stars = blackhole::starmap::parse_catalogue(&text)
            .map_err(|e| anyhow::anyhow!("{}: {e}", cat.display()))?;
        let p = assets::sky::SkyParams {
            width: sky_width,
            milky_way: !no_milky_way,
            ..Default::default()
        };
        let img = assets::sky::generate(&stars, &p);
        let path = out.join("sky.png");
        write_png(&path, img.width(), img.height(), img.as_raw())?;
        eprintln!("wrote {} ({} stars)", path.display(), stars.len());
    }
    Ok(())
}

fn write_rgba_png(path: &Path, img: &image::RgbaImage) -> Result<()> {
    use image::ImageEncoder;
    blackhole::output::write_atomic(path, |w| {
        image::codecs::png::PngEncoder::new(w).write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgba8,
        )?;
        Ok(())
    })
}

fn run() -> Result<()> {
    match Cli::parse().command {
        Command::Render {
            config,
            set,
            threads,
            quiet,
        } => render(&config, &set, threads, quiet),
        Command::Info { config, set } => {
            let scene = load_scene(&config, &set)?;
            print!("{}", blackhole::info::report(&scene));
            Ok(())
        }
        Command::Assets {
            out,
            catalogue,
            only,
            disk_size,
            disk_radius,
            disk_kelvin,
            sky_width,
            no_milky_way,
        } => generate_assets(
            &out,
            catalogue,
            only,
            disk_size,
            disk_radius,
            disk_kelvin,
            sky_width,
            no_milky_way,
        ),
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
