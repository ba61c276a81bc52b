//! `compare`: a spectral scene with the frequency shift off and on, both
//! images, a side-by-side image, a CIEDE2000 difference map and a summary.

use super::{print_warnings, render_scene, set_threads};
use crate::RenderArgs;
use anyhow::{Context, Result, bail};
use blackhole::compare;
use blackhole::config::SceneConfig;
use blackhole::files::Batch;
use blackhole::film::{Film, Stats};
use blackhole::memory::Job;
use blackhole::output::{stage_png, stage_shown, tone_map, xyz_to_srgb8};
use blackhole::pipeline::{Backend, check_memory, guard_outputs, plan_of, summary_line, warn_lost};
use blackhole::scene::Scene;
use std::path::{Path, PathBuf};

/// The files of a comparison, after `image.png`'s stem: `NAME_SUFFIX`.
const FILES: [&str; 7] = [
    "shift_off.png",
    "shift_off.exr",
    "shift_on.png",
    "shift_on.exr",
    "side_by_side.png",
    "delta_e.png",
    "summary.txt",
];

/// One setting's render: its film (displayed XYZ), stats, time and 8-bit
/// image.
struct Rendered {
    film: Film,
    stats: Stats,
    elapsed: f64,
    rgb: Vec<u8>,
}

/// Renders a spectral scene with the frequency shift off and on and writes
/// both images (PNG and EXR), a labelled side-by-side image, a CIEDE2000
/// difference map with a colour bar, and a summary, all named after
/// `image.png` ([`FILES`]).
pub fn compare(args: &RenderArgs) -> Result<()> {
    if args.tile.is_some() {
        bail!(
            "--tile is for render (compare writes whole images); render each setting's tiles with render --tile and --set spectral.shift=..."
        );
    }
    let config = args.scene.config.as_path();
    set_threads(args.engine.threads)?;
    let overrides = args.scene.overrides();
    let base = SceneConfig::load(config, &overrides)?;
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
    let backend = args.engine.open(&on)?;
    print_warnings(&on.warnings);
    if base.stereo.is_some() {
        eprintln!("warning: [stereo] does nothing under compare, which renders the mono view");
    }
    let png = &base.image.png;
    let dir = png.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = png
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "compare".into());
    let name = |suffix: &str| dir.join(format!("{stem}_{suffix}"));
    let mut plan = plan_of(config, &base);
    for suffix in FILES {
        plan.output(format!("compare's {suffix}"), name(suffix));
    }
    plan.check()?;
    let job = Job {
        rows: base.image.height,
        films: 2,
        outputs: true,
        gpu: args.engine.on_gpu(),
    };
    check_memory(&base, job, "the comparison")?;
    let (w, h) = (off.camera.width, off.camera.height);
    let images = [
        "shift_off.png",
        "shift_on.png",
        "shift_off.exr",
        "shift_on.exr",
    ];
    guard_outputs(
        &overrides,
        args.overwrite,
        &images.map(|f| (name(f), (w, h))),
    )?;
    // Every file of the comparison is written, or none.
    let mut batch = Batch::new();
    let mut results = Vec::new();
    for (scene, tag) in [(&off, "shift_off"), (&on, "shift_on")] {
        let r = render_setting(&backend, scene, tag, args.quiet, &mut batch, &name)?;
        results.push(r);
    }
    let st = stage_maps(&mut batch, &base, &results, &name)?;
    let summary = summary_text(config, &base, &st, &results, &FILES.map(name));
    batch.write(&name("summary.txt"), |w| {
        std::io::Write::write_all(w, summary.as_bytes())?;
        Ok(())
    })?;
    batch.commit()?;
    if !args.quiet {
        print!("{summary}");
    }
    Ok(())
}

/// Renders one setting (`tag`) and stages its PNG and EXR as render
/// writes a film (the EXR bloomed with bloom.exr).
fn render_setting(
    backend: &Backend,
    scene: &Scene,
    tag: &str,
    quiet: bool,
    batch: &mut Batch,
    name: &dyn Fn(&str) -> PathBuf,
) -> Result<Rendered> {
    let img = scene.image();
    // The two settings differ in the shift: each is prepared on its own.
    let mut prepared = backend.prepare(scene)?;
    let (film, stats, elapsed) = render_scene(&mut prepared, scene, quiet, tag)?;
    drop(prepared);
    let shown = scene.displayed(&film);
    let rgb = xyz_to_srgb8(&shown, img.exposure, img.tonemap);
    let (png, exr) = (name(&format!("{tag}.png")), name(&format!("{tag}.exr")));
    stage_shown(
        batch,
        &scene.config,
        &film,
        &shown,
        &rgb,
        &png,
        Some(&exr),
        &[],
    )?;
    if !quiet {
        eprintln!(
            "{}",
            summary_line(&scene.config, (&film, &stats), elapsed, &backend.on(), &[])
        );
        warn_lost(scene, &stats);
    }
    let xyz = shown.into_owned();
    Ok(Rendered {
        film: Film {
            xyz,
            bloomed: None,
            ..film
        },
        stats,
        elapsed,
        rgb,
    })
}

/// Stages the side-by-side image and the CIEDE2000 map of the two
/// settings' displayed colours; gives the difference's statistics.
fn stage_maps(
    batch: &mut Batch,
    base: &SceneConfig,
    results: &[Rendered],
    name: &dyn Fn(&str) -> PathBuf,
) -> Result<compare::DeltaEStats> {
    let img = &base.image;
    let (w, h) = (
        results[0].film.width as usize,
        results[0].film.height as usize,
    );
    let displayed = |film: &Film| {
        let e = img.exposure as f32;
        film.linear_srgb()
            .into_iter()
            .map(|c| tone_map(c, e, img.tonemap))
            .collect::<Vec<_>>()
    };
    let (a, b) = (displayed(&results[0].film), displayed(&results[1].film));
    let de: Vec<f64> = a
        .iter()
        .zip(&b)
        .map(|(p, q)| compare::delta_e(*p, *q))
        .collect();
    let g = &results[1].stats;
    let g_text = if g.g_min.is_finite() {
        format!("g = {:.2} to {:.2} on the disk", g.g_min, g.g_max)
    } else {
        "no disk in view".to_string()
    };
    let sbs = compare::side_by_side(
        w,
        h,
        &results[0].rgb,
        &results[1].rgb,
        ["shift off", &format!("shift on, {g_text}")],
    );
    let (sw, sh) = (sbs.width as u32, sbs.height as u32);
    stage_png(batch, &name("side_by_side.png"), sw, sh, &sbs.rgb)?;
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
    let (mw, mh) = (map.width as u32, map.height as u32);
    stage_png(batch, &name("delta_e.png"), mw, mh, &map.rgb)?;
    Ok(compare::stats(&de))
}

/// The summary: the scene, the shift's range, the difference and every
/// file the comparison writes.
fn summary_text(
    config: &Path,
    base: &SceneConfig,
    st: &compare::DeltaEStats,
    results: &[Rendered],
    files: &[PathBuf],
) -> String {
    let (w, h) = (results[0].film.width, results[0].film.height);
    let g = &results[1].stats;
    format!(
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
        t0 = results[0].elapsed,
        t1 = results[1].elapsed,
        files = files
            .iter()
            .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect::<Vec<_>>()
            .join(", "),
    )
}
