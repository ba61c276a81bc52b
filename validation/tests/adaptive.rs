//! Adaptive sampling (`image.adaptive`): edges converge to the analytic
//! coverage of each pixel, pixels away from edges take no extra samples,
//! the image does not depend on threads or on how its rows are split, thin
//! higher-order rings come out as continuous lines, and bad settings are
//! refused by name.

mod common;

use blackhole::config::{Override, SceneConfig};
use blackhole::film::{Film, Stats};
use blackhole::scene::Scene;
use common::{MASS, SceneText, case, root, run, scene};
use std::sync::atomic::AtomicBool;

/// A render's film, counts and the samples each pixel took.
fn render(s: &Scene) -> (Film, Stats, Vec<u32>) {
    let never = AtomicBool::new(false);
    s.render_rows_counted(0..s.camera.height, &|_| {}, &never)
        .unwrap()
}

/// Scene text with adaptive sampling switched on (`max` samples at most).
fn adaptive(text: &str, max: u32) -> String {
    text.replacen(
        "[image]\n",
        &format!("[image]\nadaptive = true\nmax_samples = {max}\n"),
        1,
    )
}

/// A static camera at 10 r_s looking at a Schwarzschild hole against a
/// uniform white sky, one sample a pixel.
fn shadow_text() -> String {
    let d = 10.0 * blackhole::scene::schwarzschild_radius(MASS);
    SceneText::new(64, 64)
        .camera([0.0, -d, 0.0], [0.0; 3], 40.0)
        .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
        .text()
}

/// The shadow's radius in pixels on a pinhole image of focal length `f`
/// pixels: its angular radius for a static observer at r_o = 10 r_s is
/// sin(alpha) = (b_c / r_o) sqrt(1 - r_s / r_o), b_c = 3 sqrt(3) / 2 r_s
/// (PHYSICS.md section 2).
fn shadow_radius_px(f: f64) -> f64 {
    let r_o = 10.0;
    let alpha = (1.5 * 3f64.sqrt() / r_o * (1.0 - 1.0 / r_o).sqrt()).asin();
    f * alpha.tan()
}

/// The fraction of each pixel that the analytic shadow covers: a disc of
/// radius `r` pixels about the image's centre (the hole's direction),
/// supersampled on a 32 x 32 grid in each pixel.
fn coverage(w: u32, h: u32, r: f64) -> Vec<f64> {
    const K: u32 = 32;
    let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
    let mut c = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let mut inside = 0;
            for a in 0..K {
                for b in 0..K {
                    let px = x as f64 + (a as f64 + 0.5) / K as f64;
                    let py = y as f64 + (b as f64 + 0.5) / K as f64;
                    inside += ((px - cx).hypot(py - cy) < r) as u32;
                }
            }
            c.push(inside as f64 / (K * K) as f64);
        }
    }
    c
}

/// Mean |rendered - analytic| brightness over the pixels the shadow's
/// edge crosses, of a render of the white sky (Y = 1) and the shadow.
fn edge_error(film: &Film, cover: &[f64]) -> (f64, usize) {
    let edge: Vec<usize> = (0..cover.len())
        .filter(|&i| cover[i] > 0.0 && cover[i] < 1.0)
        .collect();
    let err: f64 = edge
        .iter()
        .map(|&i| (film.xyz[i].y as f64 - (1.0 - cover[i])).abs())
        .sum();
    (err / edge.len() as f64, edge.len())
}

#[test]
fn the_shadow_edge_converges_to_the_analytic_coverage() {
    let plain = scene(&shadow_text());
    let s = scene(&adaptive(&shadow_text(), 64));
    let r = shadow_radius_px(s.camera.focal_pixels());
    let cover = coverage(64, 64, r);
    let (one, n) = edge_error(&render(&plain).0, &cover);
    let (film, stats, _) = render(&s);
    let (refined, _) = edge_error(&film, &cover);
    eprintln!(
        "{n} edge pixels: mean error {one:.4} at 1 sample, {refined:.4} adaptive \
         ({} pixels refined, {} extra samples)",
        stats.refined, stats.extra
    );
    assert!(n > 100, "{n} edge pixels");
    // One sample a pixel is either side of the edge: off by the pixel's
    // coverage. 64 stratified samples of an edge are off by about a
    // hundredth; the shadow itself is exact to far less.
    assert!(one > 0.15, "{one}");
    assert!(refined < 0.02, "{refined}");
    assert!(refined < one / 10.0, "{refined} vs {one}");
}

#[test]
fn pixels_away_from_edges_take_no_extra_samples() {
    let s = scene(&adaptive(&shadow_text(), 64));
    let r = shadow_radius_px(s.camera.focal_pixels());
    let (_, stats, counts) = render(&s);
    let (mut far, mut near, mut far_refined) = (0, 0, 0);
    for y in 0..64 {
        for x in 0..64 {
            let d = (x as f64 + 0.5 - 32.0).hypot(y as f64 + 0.5 - 32.0) - r;
            let n = counts[y * 64 + x];
            if d.abs() > 2.5 {
                far += 1;
                far_refined += (n > 1) as u32;
            } else {
                near += 1;
            }
        }
    }
    eprintln!(
        "{far} pixels over 2.5 pixels from the edge, {far_refined} of them refined; \
         {} refined of {near} near it",
        stats.refined
    );
    assert_eq!(far_refined, 0);
    assert!(stats.refined > 0 && stats.refined <= near);
    assert_eq!(
        stats.samples,
        64 * 64 + stats.extra,
        "every sample counted once"
    );
    assert_eq!(counts.iter().map(|&c| c as u64).sum::<u64>(), stats.samples);
}

/// `configs/thin_disk.toml` (the spectral thin disk seen 5 degrees above
/// its plane) at `w` x `h`, adaptive or not.
fn thin_disk(w: u32, h: u32, adaptive: bool) -> Scene {
    let set = [
        Override::value("image.width", i64::from(w).into()),
        Override::value("image.height", i64::from(h).into()),
        Override::value("image.adaptive", adaptive.into()),
    ];
    let cfg = SceneConfig::load(&root().join("configs/thin_disk.toml"), &set).unwrap();
    Scene::build(cfg).unwrap()
}

fn bits(f: &Film) -> Vec<[u32; 3]> {
    f.xyz
        .iter()
        .map(|v| v.to_array().map(f32::to_bits))
        .collect()
}

#[test]
fn same_pixels_whatever_the_threads_and_the_split_into_rows() {
    let s = thin_disk(96, 54, true);
    let on = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| render(&s))
    };
    let (a, sa, ca) = on(1);
    let (b, sb, cb) = on(3);
    assert!(sa.refined > 0);
    assert_eq!(sa, sb);
    assert_eq!(ca, cb);
    assert!(bits(&a) == bits(&b), "the thread count changed pixels");
    // Bands of rows as tiles render them: each row as the whole gives it,
    // the counts adding up to the whole's.
    let mut rows = Vec::new();
    let mut sum = Stats::default();
    for band in [0..7, 7..8, 8..30, 30..54] {
        let (f, st) = s.render_rows(band, &|_| {});
        rows.extend(bits(&f));
        sum = sum + st;
    }
    assert!(rows == bits(&a), "a band of rows differs from the whole");
    assert_eq!(sum, sa);
}

/// Along radial cuts from the hole's image at angles 25 to 155 degrees
/// above the horizontal (where the thin ring next to the shadow stands
/// alone against the dark), the brightest pixel the cut meets between 0.9
/// and 1.25 times the shadow's radius: the ring's crossing.
fn ring_crossings(s: &Scene, film: &Film) -> Vec<f64> {
    let (w, h) = (film.width as f64, film.height as f64);
    let r_o = 30.0; // the camera's distance (r_s)
    let alpha = (1.5 * 3f64.sqrt() / r_o * (1.0 - 1.0 / r_o).sqrt()).asin();
    let r = s.camera.focal_pixels() * alpha.tan();
    (0..66)
        .map(|k| {
            let phi = (25.0 + 2.0 * k as f64).to_radians();
            let mut best = 0.0f64;
            let mut t = 0.9 * r;
            while t < 1.25 * r {
                let x = (w / 2.0 + t * phi.cos()).floor() as usize;
                let y = (h / 2.0 - t * phi.sin()).floor() as usize;
                best = best.max(film.xyz[y * film.width as usize + x].y as f64);
                t += 0.25;
            }
            best
        })
        .collect()
}

#[test]
fn a_thin_higher_order_ring_is_a_continuous_line() {
    // At 320 x 180 the ring next to the shadow is about a third of a
    // pixel wide: one sample a pixel through the centre catches it in
    // some pixels only.
    let plain = thin_disk(320, 180, false);
    let s = thin_disk(320, 180, true);
    let (film, stats, _) = render(&s);
    let cuts = ring_crossings(&s, &film);
    let base = ring_crossings(&plain, &render(&plain).0);
    // A crossing is there if the cut's brightest pixel holds at least a
    // quarter of the median crossing of the adaptive render: a pixel
    // partly covered by the ring; where the ring is missed the cut meets
    // only the dark.
    let mut sorted = cuts.clone();
    sorted.sort_by(f64::total_cmp);
    let there = 0.25 * sorted[sorted.len() / 2];
    let missed = |c: &[f64]| c.iter().filter(|&&v| v < there).count();
    eprintln!(
        "ring crossings missed: {} of {} at 1 sample, {} adaptive ({} pixels refined)",
        missed(&base),
        cuts.len(),
        missed(&cuts),
        stats.refined
    );
    assert!(
        missed(&base) >= 5,
        "the plain render does not break the ring"
    );
    assert_eq!(missed(&cuts), 0);
}

/// A study (43 s on 2 cores: the reference is 33 million samples), run
/// by `cargo test --release -- --ignored` (GUIDE: the test suite).
#[test]
#[ignore = "a study: cargo test --release -- --ignored"]
fn the_shipped_defaults_with_adaptive_sampling_reach_the_converged_picture() {
    // `quick.toml` as shipped (512 x 512; the disk and the sky read over
    // footprints, the catalogue's point stars) with adaptive sampling,
    // against the pixels' true means: REF_SAMPLES samples a pixel with
    // the disk read at the point (bilinear), the point stars placed
    // analytically in both. The mark is the issue's: mean CIEDE2000 0.17,
    // 99th percentile 2. Measured 0.103 and 1.97 (2.94 samples a pixel;
    // against 256 samples 0.098 and 1.79, validation/PERFORMANCE.md; the
    // pixels do not depend on threads, so neither do these). One sample
    // alone is far from it (0.398, 11.4): what it leaves is the edges,
    // which only samples resolve. At half the size the disk's gaps are
    // under a pixel wide and slip between the base samples (0.187, 3.55),
    // and over the rows of the shadow and the disk's near side alone it is
    // 0.250, 4.60: the mark holds for the picture as a whole.
    const REF_SAMPLES: u32 = 128;
    let reference = common::shipped(
        "quick",
        512,
        512,
        &[
            &format!("image.samples={REF_SAMPLES}"),
            "disk.filter=\"bilinear\"",
        ],
    );
    let truth = render(&reference).0;
    let one = common::shipped("quick", 512, 512, &[]);
    let ours = common::shipped("quick", 512, 512, &["image.adaptive=true"]);
    let (film, stats, _) = render(&ours);
    let (mean, p99, _) = common::delta_e(&ours, &film, &truth);
    let (mean1, p991, _) = common::delta_e(&one, &render(&one).0, &truth);
    eprintln!(
        "quick: adaptive ({:.2} samples a pixel) mean {mean:.3}, p99 {p99:.2}; one \
         sample mean {mean1:.3}, p99 {p991:.2}",
        stats.samples as f64 / (512 * 512) as f64
    );
    assert!(mean < 0.17 && p99 < 2.0, "mean {mean}, p99 {p99}");
    assert!(p991 > 2.0 * p99, "one sample {p991} against {p99}");
}

#[test]
fn bad_settings_are_refused_by_name() {
    let base = common::small_scene_text();
    for (text, needles) in [
        (
            adaptive(&base, 1),
            &["image.max_samples", "more than image.samples (1)"][..],
        ),
        (
            adaptive(&base.replace("[image]\n", "[image]\nsamples = 16\n"), 8),
            &["image.max_samples", "more than image.samples (16)"][..],
        ),
        (
            adaptive(&base, 70_000),
            &["image.max_samples", "at most 65536"][..],
        ),
        (
            base.replace("[image]\n", "[image]\nadaptiv = true\n"),
            &["adaptiv"][..],
        ),
        (
            base.replace("[image]\n", "[image]\nadaptive = 1\n"),
            &["adaptive"][..],
        ),
    ] {
        let d = case(&text);
        let (code, err) = run(d.path(), &["render", "-q", "scene.toml"]);
        assert_ne!(code, 0, "{text}");
        for n in needles {
            assert!(err.contains(n), "{n:?} not in {err}");
        }
        assert!(!d.path().join("out.png").exists());
    }
    // A cap without adaptive sampling does nothing, and says so.
    let d = case(&base.replace("[image]\n", "[image]\nadaptive = false\nmax_samples = 16\n"));
    let (code, err) = run(d.path(), &["render", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("image.max_samples = 16 does nothing"), "{err}");
}

#[test]
fn scenes_sample_adaptively_unless_they_say_otherwise() {
    // The default is a converged picture: a scene that does not name
    // image.adaptive refines its edges (the closing line counts the extra
    // samples), one that sets it false or asks for 64 samples a pixel
    // samples uniformly.
    let base = shadow_text();
    for (image, adaptive) in [
        ("samples = 1\n", true),
        ("samples = 1\nadaptive = false\n", false),
        ("samples = 64\n", false),
        ("samples = 64\nadaptive = true\nmax_samples = 128\n", true),
    ] {
        assert!(base.contains("samples = 1\n"));
        let d = case(&base.replacen("samples = 1\n", image, 1));
        let (code, err) = run(d.path(), &["render", "scene.toml"]);
        assert_eq!(code, 0, "{err}");
        assert_eq!(err.contains("of them adaptive"), adaptive, "{image}: {err}");
    }
}

/// The GPU's adaptive render of `s` against the CPU's: CIEDE2000 (mean,
/// p99) and the pixels refined on one backend only, and the counts.
fn gpu_against_cpu(gpu: &blackhole::gpu::Gpu, name: &str, s: &Scene) -> (f64, f64, usize) {
    let never = AtomicBool::new(false);
    let (cf, cs, cc) = s
        .render_rows_counted(0..s.camera.height, &|_| {}, &never)
        .unwrap();
    let p = gpu.prepare(s, u32::MAX).unwrap();
    let (gf, gs, gc) = p.render_rows_counted(0..s.camera.height, &|_| {}).unwrap();
    let (mean, p99, max) = common::delta_e(s, &cf, &gf);
    let flipped = cc
        .iter()
        .zip(&gc)
        .filter(|(a, b)| (**a > s.samples) != (**b > s.samples))
        .count();
    let counts = cc.iter().zip(&gc).filter(|(a, b)| a != b).count();
    eprintln!(
        "{name}: CIEDE2000 mean {mean:.4}, p99 {p99:.4}, max {max:.2}; pixels refined: CPU {}, \
         GPU {}, {flipped} on one backend only, {counts} with other counts; extra samples: \
         CPU {}, GPU {}",
        cs.refined, gs.refined, cs.extra, gs.extra
    );
    // The counts are the samples', whatever f32 changes.
    assert_eq!(gs.samples, s.samples as u64 * cc.len() as u64 + gs.extra);
    assert_eq!(gc.iter().map(|&c| c as u64).sum::<u64>(), gs.samples);
    (mean, p99, flipped)
}

#[test]
fn gpu_adaptive_sampling_refines_the_cpus_pixels() {
    let Some(gpu) = common::gpu() else { return };
    // RGB disk and sky (closed form), the spectral thin disk, and
    // objects (each its own class) with a mirror.
    for (name, w, h) in [
        ("quick", 64, 40),
        ("thin_disk", 96, 54),
        ("planets", 64, 40),
    ] {
        let s = common::shipped(name, w, h, &["image.adaptive=true"]);
        let (mean, p99, flipped) = gpu_against_cpu(gpu, name, &s);
        // The GPU's f32 against the CPU's f64, as for uniform sampling
        // (planets' surfaces: mean 0.047, p99 1.2).
        assert!(mean < 0.1 && p99 < 2.0, "{name}: mean {mean}, p99 {p99}");
        // A pixel flips only where f32 moves a lightness or class across
        // a threshold.
        assert!(
            flipped * 200 <= (w * h) as usize,
            "{name}: {flipped} flipped"
        );
    }
}

#[test]
fn gpu_adaptive_pixels_do_not_depend_on_the_split_into_rows() {
    let Some(gpu) = common::gpu() else { return };
    // 48 pixels wide at one base sample: a pixel's round of 64 samples
    // is summed in two pieces, whatever the groups.
    let s = common::shipped(
        "quick",
        48,
        30,
        &["image.adaptive=true", "image.max_samples=160"],
    );
    let p = gpu.prepare(&s, u32::MAX).unwrap();
    let (whole, stats, counts) = p.render_rows_counted(0..30, &|_| {}).unwrap();
    assert!(
        *counts.iter().max().unwrap() > 100,
        "no pixel took two pieces"
    );
    let (mut rows, mut sum, mut split) = (Vec::new(), Stats::default(), Vec::new());
    for band in [0..7, 7..8, 8..21, 21..30] {
        let (f, st, c) = p.render_rows_counted(band, &|_| {}).unwrap();
        rows.extend(bits(&f));
        sum = sum + st;
        split.extend(c);
    }
    assert!(
        rows == bits(&whole),
        "a band of rows differs from the whole"
    );
    assert_eq!(split, counts);
    assert_eq!(sum, stats);
    // Dispatches of 4 rows at most: other groups, the same pixels.
    let narrow = gpu.prepare(&s, 4).unwrap();
    let (f, st, c) = narrow.render_rows_counted(0..30, &|_| {}).unwrap();
    assert!(
        bits(&f) == bits(&whole),
        "the dispatches' rows changed pixels"
    );
    assert_eq!((st, c), (stats, counts));
}
