//! The `blackhole` command line: render, info, assets.

use anyhow::{Context, Result, bail};
use blackhole::assets;
use blackhole::config::{Override, SceneConfig};
use blackhole::output::{to_srgb8, write_exr, write_png, write_png_as};
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
    /// Regenerate the shipped assets (disk texture, spectral disk set, star
    /// panorama) from their fixed seeds.
    Assets(AssetArgs),
}

#[derive(clap::Args)]
struct AssetArgs {
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

fn generate_assets(a: AssetArgs) -> Result<()> {
    let out = a.out.as_path();
    let want = |x: Asset| a.only.is_none_or(|o| o == x);
    if !(a.disk_radius > 3.0) || !(a.disk_kelvin > 0.0) {
        bail!("--disk-radius must be > 3 (the ISCO) and --disk-kelvin > 0");
    }
    let params = assets::disk::DiskParams {
        size: a.disk_size,
        outer: a.disk_radius,
        peak_kelvin: a.disk_kelvin,
        ..Default::default()
    };
    if want(Asset::Disk) {
        if a.disk_size == 0 {
            bail!("--disk-size must be >= 1");
        }
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
        let nm = parse_range(&a.spectral_nm)?;
        if a.spectral_size == 0 {
            bail!("--spectral-size must be >= 1");
        }
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
    if want(Asset::Sky) {
        if a.sky_width < 2 || a.sky_width % 2 != 0 {
            bail!("--sky-width {}: expected an even number >= 2", a.sky_width);
        }
        let cat = a
            .catalogue
            .unwrap_or_else(|| out.join("stars").join("hipparcos_mag8.csv"));
        let text = std::fs::read_to_string(&cat)
            .with_context(|| format!("cannot read star catalogue {}", cat.display()))?;
        let stars = blackhole::starmap::parse_catalogue(&text)
            .map_err(|e| anyhow::anyhow!("{}: {e}", cat.display()))?;
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
        Command::Assets(a) => generate_assets(a),
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
