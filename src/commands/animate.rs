//! `animate`: the frames of a scene's `[animation]` (or a slice of them,
//! one job's share), then its video once every frame exists.

use super::{load_scene, set_threads};
use crate::{AnimateArgs, Frames};
use anyhow::{Context, Result, bail};
use blackhole::files::Batch;
use blackhole::film::Stats;
use blackhole::memory::Job;
use blackhole::pipeline::{
    FRAME_NUMBER, FRAME_SCENE, check_memory, frame_file, frame_is_complete, plan_of, warn_lost,
};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Renders the frames of the scene's [animation] (or the slice --frames
/// asks for), skipping complete ones, then the video once every frame
/// exists.
pub fn animate(args: &AnimateArgs) -> Result<()> {
    let quiet = args.quiet;
    let config = args.scene.config.as_path();
    set_threads(args.engine.threads)?;
    let mut scene = load_scene(&args.scene)?;
    let Some(anim) = scene.animation.clone().filter(|a| a.timed) else {
        bail!(
            "{}: animate needs an [animation] table with frames, fps and duration (see GUIDE.md, Animation)",
            config.display()
        );
    };
    let (first, last) = args
        .frames
        .unwrap_or(Frames::Range(0, anim.frames - 1))
        .of(anim.frames)?;
    // Frames carry the scene's hash: a set never mixes scenes.
    let hash = blackhole::tiles::scene_hash(&scene.config, None)?;
    if scene.config.stereo.is_some() {
        eprintln!("warning: [stereo] does nothing under animate, which renders the mono view");
    }
    let img = scene.image().clone();
    let png = |k| frame_file(&img.png, k, "png");
    let exr = |k| img.exr.as_ref().map(|_| frame_file(&img.png, k, "exr"));
    let complete = |k: u32| -> Result<bool> {
        let files: Vec<PathBuf> = std::iter::once(png(k)).chain(exr(k)).collect();
        frame_is_complete(&files, k, (img.width, img.height), &hash, config)
    };
    let mut todo = Vec::new();
    for k in first..=last {
        if args.overwrite || !complete(k)? {
            todo.push(k);
        }
    }
    let skipped = (last - first + 1) as usize - todo.len();
    let video = anim.video.as_ref().filter(|_| !args.no_video);
    if let Some(v) = video {
        check_video(v, anim.fps, anim.frames, (first, last), &complete)?;
    }
    if args.engine.on_gpu() {
        // The frames furthest from t = 0 are the first and the last.
        for k in [todo.first(), todo.last()].into_iter().flatten() {
            blackhole::gpu::check_time(&scene, &format!("frame {k}"), anim.time(*k))?;
        }
    }
    check_plan(config, &scene, &todo, anim.frames, video, &png, &exr)?;
    let job = Job {
        rows: img.height,
        films: 1,
        outputs: true,
        gpu: args.engine.on_gpu(),
    };
    check_memory(&scene.config, job, "each frame")?;
    let backend = args.engine.open(&scene)?;
    // Prepared once (on the GPU: uploaded and compiled once), then moved
    // from frame to frame.
    let mut prepared = if todo.is_empty() {
        None
    } else {
        Some(backend.prepare(&scene)?)
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
        let p = prepared.as_mut().expect("prepared when there are frames");
        let (film, stats) = p.render_image(&scene, &|n| bar.inc(n))?;
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
        backend.on(),
        todo.len() as f64 * 60.0 / elapsed.max(1e-9),
    );
    if let Some(v) = video {
        line += &make_video(v, &anim, &png, &complete)?;
    }
    if !quiet {
        eprintln!("{line}");
    }
    Ok(())
}

/// Checks the video before any frame is rendered: the rate it holds
/// always, and its encoder only when this run ends with every frame (a
/// slice of a job array that leaves frames missing renders without it).
fn check_video(
    v: &Path,
    fps: f64,
    frames: u32,
    (first, last): (u32, u32),
    complete: &dyn Fn(u32) -> Result<bool>,
) -> Result<()> {
    blackhole::video::check(v, fps)?;
    for k in (0..frames).filter(|k| !(first..=last).contains(k)) {
        if !complete(k)? {
            return Ok(());
        }
    }
    blackhole::video::check_encoder(v)
}

/// Encodes the video once every frame exists; the closing line's words
/// for what became of it.
fn make_video(
    v: &Path,
    anim: &blackhole::animation::Timeline,
    png: &dyn Fn(u32) -> PathBuf,
    complete: &dyn Fn(u32) -> Result<bool>,
) -> Result<String> {
    let mut missing = Vec::new();
    for k in 0..anim.frames {
        if !complete(k)? {
            missing.push(k);
        }
    }
    if missing.is_empty() {
        let frames: Vec<PathBuf> = (0..anim.frames).map(png).collect();
        blackhole::video::encode(&frames, anim.fps, anim.quality, v)?;
        Ok(format!(" -> {}", v.display()))
    } else {
        Ok(format!(
            "; the video waits for {} more frame(s) (first missing: {})",
            missing.len(),
            missing[0]
        ))
    }
}

/// Checks the run's files before any is written: the frames to write are
/// outputs, and the video reads every frame.
fn check_plan(
    config: &Path,
    scene: &blackhole::scene::Scene,
    todo: &[u32],
    frames: u32,
    video: Option<&PathBuf>,
    png: &dyn Fn(u32) -> PathBuf,
    exr: &dyn Fn(u32) -> Option<PathBuf>,
) -> Result<()> {
    let mut plan = plan_of(config, &scene.config);
    for &k in todo {
        plan.output(format!("frame {k}"), png(k));
        if let Some(e) = exr(k) {
            plan.output(format!("frame {k}'s EXR"), e);
        }
    }
    if let Some(v) = video {
        for k in (0..frames).filter(|k| todo.binary_search(k).is_err()) {
            plan.input(format!("frame {k} (the video is made from it)"), png(k));
        }
        plan.output("animation.video", v);
    }
    plan.check()?;
    Ok(())
}
