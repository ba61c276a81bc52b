//! The commands, one file each: each reads its arguments, loads the scene
//! and hands it to the library's pipeline (`blackhole::pipeline`).

pub mod animate;
pub mod assets;
pub mod colour;
pub mod compare;
pub mod info;
pub mod merge;
pub mod relens;
pub mod render;
pub mod serve;
pub mod torus;
pub mod view;

use crate::SceneArgs;
use anyhow::{Context, Result};
use blackhole::config::SceneConfig;
use blackhole::film::{Film, Stats};
use blackhole::pipeline::Prepared;
use blackhole::scene::Scene;
use indicatif::{ProgressBar, ProgressStyle};
use std::time::Instant;

/// Loads and builds a scene, printing its warnings.
pub fn load_scene(args: &SceneArgs) -> Result<Scene> {
    let cfg = SceneConfig::load(&args.config, &args.overrides())?;
    let scene =
        Scene::build(cfg).with_context(|| format!("invalid scene {}", args.config.display()))?;
    print_warnings(&scene.warnings);
    Ok(scene)
}

/// One `warning:` line each.
pub fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// Sets the worker count (the image does not depend on it).
pub fn set_threads(threads: Option<u16>) -> Result<()> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()?;
    }
    Ok(())
}

/// Renders the rows `rows` of `scene` on `prepared`, with a progress bar
/// (unless `quiet`) labelled `what`; returns the film, the counts and the
/// wall time in seconds.
pub fn render_rows(
    prepared: &mut Prepared,
    scene: &Scene,
    rows: std::ops::Range<u32>,
    quiet: bool,
    what: &str,
) -> Result<(Film, Stats, f64)> {
    let n = rows.len() as u64;
    with_bar(n, quiet, what, |bar| prepared.render(scene, rows, bar))
}

/// Runs `render` with a progress bar of `rows` rows (unless `quiet`)
/// labelled `what`; returns its film and counts, and the wall time.
fn with_bar(
    rows: u64,
    quiet: bool,
    what: &str,
    render: impl FnOnce(&(dyn Fn(u64) + Sync)) -> Result<(Film, Stats)>,
) -> Result<(Film, Stats, f64)> {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(rows)
    };
    bar.set_style(
        ProgressStyle::with_template(&format!("{{spinner}} {what} [{{elapsed_precise}}] {{wide_bar}} {{pos}}/{{len}} rows, eta {{eta}}"))
            .expect("valid template"),
    );
    let start = Instant::now();
    let (film, stats) = render(&|n| bar.inc(n))?;
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    Ok((film, stats, elapsed))
}

/// [`render_rows`] of the whole image, for the scene's outputs (on the
/// GPU bloomed there: see `Prepared::render_image`).
pub fn render_scene(
    prepared: &mut Prepared,
    scene: &Scene,
    quiet: bool,
    what: &str,
) -> Result<(Film, Stats, f64)> {
    let n = scene.camera.height as u64;
    with_bar(n, quiet, what, |bar| prepared.render_image(scene, bar))
}
