//! Point stars' data side: a synthetic catalogue of 250,000 stars (and
//! one of Tycho-2's size, 2.5 million) parsed, indexed and queried; the
//! index against brute force, the summed levels against exact star sums.
//!
//! `measure_catalogue_sizes` (ignored) records the figures of
//! validation/PERFORMANCE.md's "Star catalogue size":
//! `cargo test --release --test stars measure -- --ignored --nocapture`.

use blackhole::stars::index::{chord2, within};
use blackhole::stars::{
    PointStar, StarField, StarIndex, SumRule, cap_solid_angle, parse_catalogue, parse_point_stars,
    synthetic, to_csv,
};
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::OnceLock;
use std::time::Instant;

/// Uniform random directions, deterministic.
fn random_dirs(n: usize, seed: u64) -> Vec<DVec3> {
    let mut s = seed;
    let mut next = || {
        s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = 2.0 * PI * next();
            let r = (1.0 - z * z).sqrt();
            DVec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// The cube's seams: face centres (the poles among them), edge midpoints
/// and corners.
fn seams() -> Vec<DVec3> {
    let mut v = Vec::new();
    for a in [-1.0, 0.0, 1.0] {
        for b in [-1.0, 0.0, 1.0] {
            for c in [-1.0, 0.0, 1.0] {
                if (a, b, c) != (0.0, 0.0, 0.0) {
                    v.push(DVec3::new(a, b, c).normalize());
                }
            }
        }
    }
    v
}

/// 250,000 synthetic stars: the CSV text and its index, built once.
fn catalogue() -> &'static (String, StarIndex) {
    static CAT: OnceLock<(String, StarIndex)> = OnceLock::new();
    CAT.get_or_init(|| {
        let csv = to_csv(&synthetic(250_000, 1));
        let idx = StarIndex::build(parse_point_stars(&csv).unwrap());
        (csv, idx)
    })
}

/// Brute force: the indices of the stars within `r` of `c`.
fn brute(stars: &[PointStar], c: DVec3, r: f64) -> Vec<usize> {
    let c2 = chord2(r);
    (0..stars.len())
        .filter(|&i| within(&stars[i], c, c2))
        .collect()
}

/// Checks queries against brute force: the visitor's set, each star
/// once, and the hierarchical sum's count and flux.
fn check_queries(idx: &StarIndex, centres: &[DVec3], radii: &[f64]) {
    let stars = idx.stars();
    for &c in centres {
        for &r in radii {
            let mut got = Vec::new();
            idx.for_each_within(c, r, |s| {
                got.push((s as *const PointStar as usize - stars.as_ptr() as usize) / 20)
            });
            got.sort();
            let want = brute(stars, c, r);
            assert_eq!(got, want, "at {c}, radius {r}");
            let sum = idx.cap_sum(c, r);
            assert_eq!(sum.stars, want.len() as u64, "at {c}, radius {r}");
            let flux: f64 = want.iter().map(|&i| stars[i].flux as f64).sum();
            let err = (sum.light.total() - flux).abs();
            assert!(err <= 1e-6 * flux, "at {c}, radius {r}: {sum:?} {flux}");
        }
    }
}

/// From 1 arcsecond to 60 degrees.
fn radii() -> Vec<f64> {
    [1.0 / 3600.0, 1.0 / 60.0, 0.1, 1.0, 10.0, 60.0]
        .map(f64::to_radians)
        .to_vec()
}

#[test]
fn the_index_finds_exactly_the_brute_force_set() {
    let (_, idx) = catalogue();
    assert_eq!(idx.stars().len(), 250_000);
    let mut centres = seams();
    centres.extend(random_dirs(20, 3));
    // On stars themselves, so that the smallest queries find something.
    centres.extend((0..10).map(|k| idx.stars()[k * 24_999].direction()));
    check_queries(idx, &centres, &radii());
}

#[test]
fn summed_levels_hold_the_catalogue_flux() {
    let (csv, idx) = catalogue();
    let total: f64 = parse_catalogue(csv)
        .unwrap()
        .iter()
        .map(|s| PointStar::from_star(s).flux as f64)
        .sum();
    assert!((idx.total_flux() / total - 1.0).abs() < 1e-12);
    let faces: f64 = (0..6)
        .map(|f| {
            idx.cell_sum(0, f)
                .flux
                .iter()
                .map(|&x| x as f64)
                .sum::<f64>()
        })
        .sum();
    assert!((faces / total - 1.0).abs() < 1e-6, "{faces} {total}");
    let sphere = idx.cap_sum(DVec3::new(0.3, 0.1, -0.2), PI);
    assert_eq!(sphere.stars, 250_000);
    assert!((sphere.light.total() / total - 1.0).abs() < 1e-6);
    // The smooth density over the whole sky at its coarsest: 4 pi times
    // it is the total to within the interpolation across faces.
    let mean: f64 = random_dirs(2000, 5)
        .iter()
        .map(|&d| idx.smooth_density(d, PI).light.total())
        .sum::<f64>()
        / 2000.0;
    assert!(
        (4.0 * PI * mean / total - 1.0).abs() < 0.05,
        "{}",
        4.0 * PI * mean / total
    );
}

/// Median and 90th percentile of |x|.
fn quantiles(mut v: Vec<f64>) -> (f64, f64) {
    v.iter_mut().for_each(|x| *x = x.abs());
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[v.len() * 9 / 10])
}

/// An estimate of the flux within caps (`estimate(dir, radius)`, total
/// flux) against the exact star sum over random caps of radius `deg`:
/// (median, p90) of the relative error and the mean number of stars.
fn flux_errors(
    idx: &StarIndex,
    deg: f64,
    n: usize,
    estimate: impl Fn(DVec3, f64) -> f64,
) -> ((f64, f64), f64) {
    let r = deg.to_radians();
    let (mut err, mut stars) = (Vec::new(), 0.0);
    for d in random_dirs(n, 7) {
        let e = idx.cap_sum(d, r);
        if e.stars == 0 {
            continue;
        }
        err.push(estimate(d, r) / e.light.total() - 1.0);
        stars += e.stars as f64;
    }
    let m = err.len() as f64;
    (quantiles(err), stars / m)
}

/// The smooth density of one index against the exact star sum over random
/// caps of radius `deg`: (median, p90) relative error of the flux, the
/// same of the star count, the mean exact count and the bias of the total.
fn density_errors(idx: &StarIndex, deg: f64, n: usize) -> ((f64, f64), (f64, f64), f64, f64) {
    let r = deg.to_radians();
    let omega = cap_solid_angle(r);
    let (mut flux, mut count, mut stars, mut smooth, mut exact) =
        (Vec::new(), Vec::new(), 0.0, 0.0, 0.0);
    for d in random_dirs(n, 7) {
        let e = idx.cap_sum(d, r);
        if e.stars == 0 {
            continue;
        }
        let s = idx.smooth_density(d, r);
        flux.push(s.light.total() * omega / e.light.total() - 1.0);
        count.push(s.stars_per_sr * omega / e.stars as f64 - 1.0);
        stars += e.stars as f64;
        smooth += s.light.total() * omega;
        exact += e.light.total();
    }
    let m = flux.len() as f64;
    (
        quantiles(flux),
        quantiles(count),
        stars / m,
        smooth / exact - 1.0,
    )
}

#[test]
fn flux_density_converges_to_the_star_sum() {
    let (_, idx) = catalogue();
    // Measured (250,000 stars, 400 caps): flux error median 0.136 / 0.070 /
    // 0.049 at 3 / 10 / 30 degrees, star count 0.046 / 0.015 / 0.020;
    // the flux's spread is its brightest stars on the rim.
    let mut last = f64::MAX;
    for (deg, flux_max, count_max) in [(3.0, 0.2, 0.08), (10.0, 0.11, 0.03), (30.0, 0.08, 0.04)] {
        let ((flux, _), (count, _), stars, bias) = density_errors(idx, deg, 400);
        assert!(
            flux < flux_max && count < count_max,
            "{deg} deg: {flux} {count}"
        );
        assert!(flux < last, "{deg} deg: {flux} after {last}");
        assert!(bias.abs() < 0.02, "{deg} deg: bias {bias}");
        assert!(stars > 100.0, "{stars}");
        last = flux;
    }
    // One pixel (0.1 degree): few stars, so the rule answers exactly.
    let r = 0.1f64.to_radians();
    for d in random_dirs(200, 9) {
        let got = idx.flux_density(d, r, SumRule::default());
        let exact = idx.cap_sum(d, r).light.total() / cap_solid_angle(r);
        assert_eq!(got.exact, 1.0);
        assert!((got.light.total() - exact).abs() <= 1e-9 * exact, "{d}");
    }
}

#[test]
fn brightness_tiers_keep_footprints_close_to_the_star_sum() {
    let (csv, idx) = catalogue();
    let field = StarField::build(parse_point_stars(csv).unwrap());
    assert_eq!(field.len(), 250_000);
    let rule = SumRule::default();
    // Measured (250,000 stars, 400 caps): median 0.025 / 0.015 / 0.019 at
    // 3 / 10 / 30 degrees, against 0.136 / 0.070 / 0.049 for one index.
    for (deg, max) in [(3.0, 0.05), (10.0, 0.03), (30.0, 0.04)] {
        let omega = cap_solid_angle(f64::to_radians(deg));
        let ((median, _), _) = flux_errors(idx, deg, 400, |d, r| {
            field.flux_density(d, r, rule).light.total() * omega
        });
        assert!(median < max, "{deg} deg: {median}");
        // The footprint: its visited stars plus its sums are the same
        // light, and few stars are visited.
        for d in random_dirs(20, 13) {
            let r = deg.to_radians();
            let (mut visited, mut n) = (0.0, 0);
            let fp = field.footprint(d, r, rule, |s, w| {
                visited += w * s.flux as f64;
                n += 1;
            });
            let total = visited + fp.light.total() * omega;
            let want = field.flux_density(d, r, rule).light.total() * omega;
            // (The cap sum reads whole cells' f32 sums: 1e-7.)
            assert!(
                (total / want - 1.0).abs() < 1e-6,
                "{deg} deg at {d}: {total} {want}"
            );
            assert!(
                n <= 2 * field.tiers().len() * rule.max_stars as usize,
                "{n}"
            );
        }
    }
}

#[test]
fn bad_rows_are_named_in_a_large_catalogue() {
    let (csv, _) = catalogue();
    // Line 200,001 (a row of the fourth of the parser's chunks, and a
    // later bad row too): the first is named.
    let mut lines: Vec<&str> = csv.lines().collect();
    lines[200_000] = "200000,12.5,91.5,7.0,0.5";
    lines[240_000] = "x";
    let e = parse_point_stars(&lines.join("\n")).unwrap_err();
    assert!(
        e.starts_with("line 200001: dec_deg = 91.5: expected a number from -90 to 90"),
        "{e}"
    );
    lines[100] = "1,2,3";
    let e = parse_catalogue(&lines.join("\n")).unwrap_err();
    assert!(
        e.starts_with("line 101: expected 5 fields hip,ra,dec,vmag,bv"),
        "{e}"
    );
    let e = parse_point_stars("hip,ra_deg,dec_deg,vmag,bv\n\n").unwrap_err();
    assert!(e.contains("no stars"), "{e}");
}

#[test]
fn tycho_size_catalogue_parses_builds_and_queries() {
    let csv = to_csv(&synthetic(2_500_000, 2));
    let t = Instant::now();
    let stars = parse_point_stars(&csv).unwrap();
    let parse = t.elapsed().as_secs_f64();
    let total: f64 = stars.iter().map(|s| s.flux as f64).sum();
    let t = Instant::now();
    let idx = StarIndex::build(stars);
    let build = t.elapsed().as_secs_f64();
    println!(
        "2.5 M stars: parse {parse:.2} s, build {build:.2} s, {} bytes",
        idx.memory_bytes()
    );
    assert_eq!(idx.level(), 8);
    assert!((idx.total_flux() / total - 1.0).abs() < 1e-12);
    // About 24 bytes a star: the star itself (20) and the cells.
    assert!(
        idx.memory_bytes() < 25 * 2_500_000,
        "{}",
        idx.memory_bytes()
    );
    let mut centres = seams();
    centres.truncate(8);
    centres.extend(random_dirs(4, 11));
    check_queries(&idx, &centres, &radii());
}

/// Peak resident memory of this process (MiB), from the kernel.
fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find(|l| l.starts_with("VmHWM"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|k| k.parse::<f64>().ok())
        .unwrap_or(f64::NAN)
        / 1024.0
}

/// Microseconds per call of `f` over `dirs`: the fastest of 5 rounds (the
/// machine is shared).
fn time_us(dirs: &[DVec3], f: &dyn Fn(DVec3) -> f64) -> f64 {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            let s: f64 = dirs.iter().map(|&d| f(d)).sum();
            std::hint::black_box(s);
            t.elapsed().as_secs_f64() / dirs.len() as f64 * 1e6
        })
        .fold(f64::MAX, f64::min)
}

/// One catalogue file measured in this process (spawned by
/// `measure_catalogue_sizes` so that its peak memory is its own): read,
/// parse, then one index (`STARS_MEASURE_WHAT=index`) or the tiers
/// (`field`), and their queries.
#[test]
#[ignore = "run by measure_catalogue_sizes"]
fn measure_child() {
    let (Ok(path), Ok(what)) = (
        std::env::var("STARS_MEASURE_FILE"),
        std::env::var("STARS_MEASURE_WHAT"),
    ) else {
        return;
    };
    let t = Instant::now();
    let text = std::fs::read_to_string(&path).unwrap();
    let read = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let stars = parse_point_stars(&text).unwrap();
    let parse = t.elapsed().as_secs_f64();
    drop(text);
    let n = stars.len();
    let dirs = random_dirs(2000, 3);
    let t = Instant::now();
    let mut line = if what == "index" {
        let idx = StarIndex::build(stars);
        let build = t.elapsed().as_secs_f64();
        let mut line = format!(
            "MEASURE | {n} | {} | {read:.3} | {parse:.3} | {build:.3} | {:.1} | {:.0} |",
            idx.level(),
            idx.memory_bytes() as f64 / (1 << 20) as f64,
            peak_rss_mib()
        );
        for deg in [0.1f64, 10.0] {
            let r = deg.to_radians();
            let mut found = 0usize;
            dirs.iter().for_each(|&d| {
                idx.for_each_within(d, r, |_| found += 1);
            });
            let visit = time_us(&dirs, &|d| {
                let mut f = 0.0;
                idx.for_each_within(d, r, |s| f += s.flux as f64);
                f
            });
            let cap = time_us(&dirs, &|d| idx.cap_sum(d, r).light.total());
            let smooth = time_us(&dirs, &|d| idx.smooth_density(d, r).light.total());
            line += &format!(
                " {:.1} | {visit:.2} | {cap:.2} | {smooth:.2} |",
                found as f64 / dirs.len() as f64
            );
        }
        line
    } else {
        let field = StarField::build(stars);
        let build = t.elapsed().as_secs_f64();
        let mut line = format!(
            "MEASURE | {n} | {} | {build:.3} | {:.1} | {:.0} |",
            field.tiers().len(),
            field.memory_bytes() as f64 / (1 << 20) as f64,
            peak_rss_mib()
        );
        for deg in [0.1f64, 1.0, 10.0, 30.0] {
            let r = deg.to_radians();
            let mut visited = 0usize;
            dirs.iter().for_each(|&d| {
                field.footprint(d, r, SumRule::default(), |_, _| visited += 1);
            });
            let us = time_us(&dirs, &|d| {
                let mut f = 0.0;
                let sums = field.footprint(d, r, SumRule::default(), |s, w| f += w * s.flux as f64);
                f + sums.light.total()
            });
            line += &format!(" {us:.2} ({:.0}) |", visited as f64 / dirs.len() as f64);
        }
        line
    };
    line = line.replace("MEASURE ", "");
    println!("MEASURE {line}");
}

/// Parse, build, memory and query times for 10 k, 250 k and 2.5 M stars,
/// each size in a fresh process; prints the table rows.
#[test]
#[ignore = "a measurement: about a minute"]
fn measure_catalogue_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let files: Vec<(usize, std::path::PathBuf)> = [10_000, 250_000, 2_500_000]
        .into_iter()
        .map(|n| {
            let path = dir.path().join(format!("stars{n}.csv"));
            std::fs::write(&path, to_csv(&synthetic(n, 1))).unwrap();
            (n, path)
        })
        .collect();
    for (what, head) in [
        (
            "index",
            "| stars | level | read (s) | parse (s) | build (s) | index (MiB) | peak RSS (MiB) | stars in 0.1 deg | visit (us) | cap sum (us) | smooth (us) | stars in 10 deg | visit (us) | cap sum (us) | smooth (us) |",
        ),
        (
            "field",
            "| stars | tiers | build (s) | tiers (MiB) | peak RSS (MiB) | footprint 0.1 deg, us (stars visited) | 1 deg | 10 deg | 30 deg |",
        ),
    ] {
        println!("{head}");
        for (_, path) in &files {
            let out = std::process::Command::new(std::env::current_exe().unwrap())
                .args(["--exact", "measure_child", "--ignored", "--nocapture"])
                .args(["--test-threads=1"])
                .env("STARS_MEASURE_FILE", path)
                .env("STARS_MEASURE_WHAT", what)
                .output()
                .unwrap();
            let text = String::from_utf8_lossy(&out.stdout);
            // libtest writes "test measure_child ... " before the output.
            let row = text
                .lines()
                .find_map(|l| l.split_once("MEASURE "))
                .map(|p| p.1);
            println!("{}", row.unwrap_or("| failed |"));
        }
    }
    // The smooth density against exact sums, 250,000 and 2.5 million
    // stars: one index summed whole, and the tiers under the default rule.
    println!(
        "| stars | cap (deg) | stars in it | one index: flux error median / p90 | star count median / p90 | bias of the total | tiers: flux error median / p90 | stars visited |"
    );
    for n in [250_000, 2_500_000] {
        let stars: Vec<PointStar> = synthetic(n, 1).iter().map(PointStar::from_star).collect();
        let field = StarField::build(stars.clone());
        let idx = StarIndex::build(stars);
        for deg in [0.1, 1.0, 3.0, 10.0, 30.0] {
            let ((f50, f90), (c50, c90), stars, bias) = density_errors(&idx, deg, 400);
            let omega = cap_solid_angle(deg.to_radians());
            let ((t50, t90), _) = flux_errors(&idx, deg, 400, |d, r| {
                field.flux_density(d, r, SumRule::default()).light.total() * omega
            });
            let mut visited = 0.0;
            for d in random_dirs(400, 7) {
                field.footprint(d, deg.to_radians(), SumRule::default(), |_, _| {
                    visited += 1.0
                });
            }
            println!(
                "| {n} | {deg} | {stars:.0} | {f50:.3} / {f90:.3} | {c50:.3} / {c90:.3} | {bias:+.3} | {t50:.3} / {t90:.3} | {:.0} |",
                visited / 400.0
            );
        }
    }
}
