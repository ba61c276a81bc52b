//! The closing lines of a render: what it rendered, how fast, how the
//! rays ended, and warnings about samples that did not come out right.

use crate::config::{DiskEmission, SceneConfig};
use crate::film::{Film, Stats};
use crate::scene::Scene;

/// The closing line of a render. Percentages are of camera samples, each
/// in one class: disk (its light includes the disk's or the gas's), then
/// objects, then sky or captured by how its ray ended. With adaptive
/// sampling it says how many samples were extra and the share of pixels
/// that took them; us/px stays the time per pixel, all its samples
/// included.
pub fn summary_line(
    cfg: &SceneConfig,
    (film, stats): (&Film, &Stats),
    elapsed: f64,
    on: &str,
    written: &[String],
) -> String {
    let px = film.width as f64 * film.height as f64;
    let rays = stats.rays.max(1) as f64;
    let pct = |k: u64| percent(k, stats.samples);
    let mut line = format!(
        "rendered {}x{} ({} samples",
        film.width, film.height, stats.samples
    );
    if stats.extra > 0 {
        // Adaptive sampling: its samples are among the samples above.
        line += &format!(
            ", {} of them adaptive, in {}% of the pixels",
            stats.extra,
            percent(stats.refined, px as u64)
        );
    }
    if stats.rays != stats.samples {
        line += &format!(", {} rays", stats.rays);
    }
    line += &format!(
        "){on} in {:.2} s: {:.0} px/s, {:.2} us/px, {:.1} steps/ray; {}% sky, {}% {}, {}% objects, {}% captured",
        elapsed,
        px / elapsed,
        elapsed * 1e6 / px,
        stats.steps as f64 / rays,
        pct(stats.sky),
        pct(stats.disk),
        stopped_label(cfg),
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
    if let Some(jy) = film.total_flux().first() {
        line += &format!(
            "; total flux {} Jy at {}",
            significant(*jy),
            crate::config::quantity::frequency_text(film.frequencies[0])
        );
    }
    if !written.is_empty() {
        line += &format!(" -> {}", written.join(", "));
    }
    line
}

/// What the closing line calls its samples of the disk class: in a
/// visible scene those whose light includes the disk's or its gas's; in an
/// observed one those stopped at the thin disk or where the gas hides all
/// behind it, not the disk's unless the scene has one.
pub fn stopped_label(cfg: &SceneConfig) -> &'static str {
    if cfg.observe.is_none() {
        return "disk";
    }
    let disk = cfg
        .disk
        .as_ref()
        .is_some_and(|d| matches!(d.emission, DiskEmission::Thin));
    let gas = cfg.medium.is_some() || cfg.volume.is_some();
    match (disk, gas) {
        (true, true) => "disk or opaque gas",
        (false, true) => "opaque gas",
        _ => "disk",
    }
}

/// `x` to 6 significant digits; in scientific notation below 1e-3 and
/// from 1e7.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-3..1e7).contains(&x.abs()) {
        return format!("{x:.5e}");
    }
    let digits = (5 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

/// `k` of `n` as a percentage to one decimal, or as many more as it takes
/// not to read as 0% or 100% when it is neither.
pub fn percent(k: u64, n: u64) -> String {
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
pub fn warn_lost(scene: &Scene, stats: &Stats) {
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
