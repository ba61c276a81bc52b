//! `info`: what a scene implies, and how long its render will take on the
//! chosen backend.

use super::{load_scene, set_threads};
use crate::InfoArgs;
use anyhow::Result;
use blackhole::pipeline::{duration_text, estimate};
use std::time::Instant;

/// Prints the scene's report, then the render time estimated from a probe
/// of its own rays on the backend asked for.
pub fn info(args: &InfoArgs) -> Result<()> {
    set_threads(args.engine.threads)?;
    let start = Instant::now();
    let scene = load_scene(&args.scene)?;
    let loading = start.elapsed().as_secs_f64();
    print!("{}", blackhole::info::report(&scene));
    let backend = args.engine.open(&scene)?;
    let e = estimate(&backend, &scene)?;
    let mut time = format!(
        "about {} on {} ({}; loading the scene took {}, writing the files is not counted)",
        duration_text(e.seconds + e.setup_seconds),
        backend.label(),
        e.how,
        duration_text(loading)
    );
    if let Some(a) = scene.animation.as_ref().filter(|a| a.timed) {
        time += &format!(
            "; animate: about {} for {} frames",
            duration_text(e.setup_seconds + e.seconds * a.frames as f64),
            a.frames
        );
    }
    println!("{:<28} {time}", "render time (estimate)");
    Ok(())
}
