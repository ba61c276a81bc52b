//! `render`: the image (and EXR, and stereo pair) a scene names, or one
//! tile of it for `merge`.

use super::{load_scene, render_rows, render_scene, set_threads};
use crate::RenderArgs;
use anyhow::{Context, Result, bail};
use blackhole::memory::Job;
use blackhole::pipeline::{Outputs, check_memory, plan_of, summary_line, warn_lost};
use blackhole::scene::Scene;
use std::time::Instant;

/// Renders the scene's image, and with `[stereo]` both eyes on the same
/// prepared backend, then writes every output together.
pub fn render(args: &RenderArgs) -> Result<()> {
    let quiet = args.quiet;
    set_threads(args.engine.threads)?;
    let mut scene = load_scene(&args.scene)?;
    if let Some(t) = args.time {
        scene
            .set_time(t)
            .with_context(|| format!("invalid scene {}", args.scene.config.display()))?;
    }
    if let Some((i, n)) = args.tile {
        if scene.flux_target().is_some() {
            bail!(
                "--tile with medium.flux: a tile cannot fit the whole image's flux; render the whole image once (its closing lines give the fitted m_unit), then render the tiles with --set medium.m_unit=<fitted> --unset medium.flux"
            );
        }
        return render_tile(args, &scene, i, n);
    }
    let outputs = Outputs::of(&scene.config);
    let overrides = args.scene.overrides();
    outputs.check(
        &args.scene.config,
        &overrides,
        &scene.config,
        &[],
        args.overwrite,
    )?;
    let job = Job::render(&scene.config, args.engine.on_gpu());
    check_memory(&scene.config, job, "the render")?;
    let backend = args.engine.open(&scene)?;
    let mut prepared = backend.prepare(&scene)?;
    let (film, stats, elapsed) = match fit_flux(&mut scene, &mut prepared, quiet)? {
        Some(done) => done,
        None => render_scene(&mut prepared, &scene, quiet, "render")?,
    };
    let on = backend.on_timed(prepared.device_seconds());
    let eyes = match scene.stereo_eyes() {
        Some((left, right)) => {
            let mut films = Vec::new();
            for (eye, tag) in [(&left, "left eye"), (&right, "right eye")] {
                let (f, st, t) = render_scene(&mut prepared, eye, quiet, tag)?;
                if !quiet {
                    let on = backend.on_timed(prepared.device_seconds());
                    eprintln!(
                        "{tag}: {}",
                        summary_line(&eye.config, (&f, &st), t, &on, &[])
                    );
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
                summary_line(&scene.config, (&film, &stats), elapsed, &on, written)
            );
            warn_lost(&scene, &stats);
        }
    })
}

/// With `medium.flux`, fits the GRMHD snapshot's mass unit to it, one
/// render a try, and gives the last (the fitted one's) render; None
/// without a target.
fn fit_flux(
    scene: &mut Scene,
    prepared: &mut blackhole::pipeline::Prepared,
    quiet: bool,
) -> Result<Option<(blackhole::film::Film, blackhole::film::Stats, f64)>> {
    let Some((target, _)) = scene.flux_target() else {
        return Ok(None);
    };
    let nu = blackhole::config::quantity::frequency_text(
        scene.observe.as_ref().map_or(0.0, |o| o.frequencies[0]),
    );
    if !quiet {
        eprintln!("fitting m_unit to {target} Jy at {nu}");
    }
    let mut last = None;
    let fit = scene.fit_m_unit(
        |s| {
            let done = render_scene(prepared, s, true, "render")?;
            let jy = done.0.total_flux()[0];
            last = Some(done);
            Ok(jy)
        },
        |t| {
            if !quiet {
                eprintln!("  m_unit {:.6e} g: {:.6} Jy", t.m_unit, t.jy);
            }
        },
    )?;
    if let (Some(f), false) = (fit, quiet) {
        eprintln!(
            "fitted m_unit {:.6e} g: {:.6} Jy at {nu} in {} renders, d ln F / d ln m_unit {:.4}",
            f.m_unit,
            f.jy,
            f.tries.len(),
            f.slope
        );
    }
    Ok(last)
}

/// `render --tile I/N`: the band of rows of tile I, for every view, to
/// its tile file (kept when it is complete already).
fn render_tile(args: &RenderArgs, scene: &Scene, i: u32, n: u32) -> Result<()> {
    let quiet = args.quiet;
    let (w, h) = (scene.camera.width, scene.camera.height);
    blackhole::tiles::check_tile(i, n, h)?;
    let rows = blackhole::tiles::tile_rows(h, i, n);
    let path = blackhole::tiles::tile_path(&scene.image().png, i, n);
    let mut plan = plan_of(&args.scene.config, &scene.config);
    plan.output(format!("tile {i}/{n}"), &path);
    plan.check()?;
    let job = Job {
        rows: rows.len() as u32,
        films: if scene.config.stereo.is_some() { 3 } else { 1 },
        outputs: false,
        gpu: args.engine.on_gpu(),
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
    let backend = args.engine.open(scene)?;
    let mut prepared = backend.prepare(scene)?;
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
        let (film, stats, t) = render_rows(&mut prepared, s, rows.clone(), quiet, &what)?;
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
            backend: backend.label(),
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
                &scene.config,
                (&film, &stats),
                t,
                &backend.on(),
                &[path.display().to_string()]
            )
        );
        warn_lost(scene, &stats);
    }
    Ok(())
}
