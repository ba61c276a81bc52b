//! `merge`: the images `render` writes, from the tiles of `render --tile`.

use crate::MergeArgs;
use anyhow::Result;
use blackhole::config::SceneConfig;
use blackhole::memory::Job;
use blackhole::pipeline::{Outputs, check_memory, summary_line};
use std::path::PathBuf;
use std::time::Instant;

/// Checks the tiles beside image.png are one whole set of this scene,
/// assembles every view's film and writes what `render` writes.
pub fn merge(args: &MergeArgs) -> Result<()> {
    let start = Instant::now();
    let config = args.scene.config.as_path();
    let overrides = args.scene.overrides();
    let cfg = SceneConfig::load(config, &overrides)?;
    if let Some(t) = args.time {
        blackhole::scene::check_time(&cfg, t)?;
    }
    let hash = blackhole::tiles::scene_hash(&cfg, args.time)?;
    let found = blackhole::tiles::find_tiles(&cfg.image.png)?;
    let outputs = Outputs::of(&cfg);
    let tiles: Vec<(String, PathBuf)> = found
        .iter()
        .map(|(i, n, p)| (format!("tile {i}/{n}"), p.clone()))
        .collect();
    outputs.check(config, &overrides, &cfg, &tiles, args.overwrite)?;
    // The tiles as read, and the films joined from them.
    let views = if cfg.stereo.is_some() { 3 } else { 1 };
    let job = Job {
        rows: cfg.image.height,
        films: 2 * views,
        outputs: true,
        gpu: false,
    };
    check_memory(&cfg, job, "the merge")?;
    let n = found[0].1;
    let merged = blackhole::tiles::merge(&found, &hash, config, cfg.image.width, cfg.image.height)?;
    let on = match merged.backend.split_once(": ") {
        Some((_, device)) => format!(" on {device}"),
        None => String::new(),
    };
    let (film, stats) = &merged.main;
    outputs.write(&cfg, film, merged.eyes.as_ref(), args.quiet, |written| {
        if !args.quiet {
            eprintln!(
                "merged {n} tile(s) in {:.2} s; {}",
                start.elapsed().as_secs_f64(),
                summary_line(&cfg, (film, stats), merged.seconds, &on, written)
            );
        }
    })
}
