//! Speed of whole renders and of single rays.
//!
//! `cargo bench --bench render` (numbers in validation/PERFORMANCE.md). The 1024 x 1024
//! side view with the exact model, disk and sky is the headline figure.

use blackhole::config::{Override, SceneConfig};
use blackhole::physics::{Flow, Limits, Model};
use blackhole::scene::Scene;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use std::path::Path;
use std::time::Duration;

/// Each group's measurement time, or BLACKHOLE_BENCH_SECONDS where set (for
/// a short run on a borrowed machine).
fn seconds(default: u64) -> Duration {
    let s = std::env::var("BLACKHOLE_BENCH_SECONDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    Duration::from_secs(s)
}

fn load(name: &str, sets: &[&str]) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("configs")
        .join(name);
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    Scene::build(SceneConfig::load(&path, &overrides).unwrap()).unwrap()
}

fn renders(c: &mut Criterion) {
    let mut g = c.benchmark_group("render");
    g.sample_size(10).measurement_time(seconds(20));
    let side = load("side.toml", &["image.width=1024", "image.height=1024"]);
    g.bench_function("side_gr_1024x1024", |b| b.iter(|| side.render(&|_| {})));
    // The same view around a hole of spin 0.9, in Kerr's closed form
    // (issue: at most 1.5 times the Schwarzschild closed form's time).
    let kerr = load(
        "side.toml",
        &[
            "image.width=1024",
            "image.height=1024",
            "black_hole.spin=0.9",
        ],
    );
    g.bench_function("side_kerr_0.9_closed_1024x1024", |b| {
        b.iter(|| kerr.render(&|_| {}))
    });
    // The same view, scene and assets rendered as RGB and spectrally
    // (81 wavelengths, shift, Doppler and beaming): the cost of the spectrum.
    let size = ["image.width=1024", "image.height=1024"];
    let rgb = load(
        "spectral_side.toml",
        &[size[0], size[1], "spectral.enabled=false"],
    );
    g.bench_function("spectral_side_as_rgb_1024x1024", |b| {
        b.iter(|| rgb.render(&|_| {}))
    });
    let spectral = load("spectral_side.toml", &size);
    g.bench_function("spectral_side_81wl_1024x1024", |b| {
        b.iter(|| spectral.render(&|_| {}))
    });
    // The spinning hole against the same view integrated without spin
    // (issue: at most twice the time), tolerance 1e-6.
    for (name, spin) in [
        ("side_integrated_1024x1024", "black_hole.spin=0.0"),
        ("side_kerr_0.9_1024x1024", "black_hole.spin=0.9"),
    ] {
        let s = load(
            "side.toml",
            &[
                size[0],
                size[1],
                "physics.closed_form=false",
                "physics.tolerance=1e-6",
                spin,
            ],
        );
        g.bench_function(name, |b| b.iter(|| s.render(&|_| {})));
    }
    let quick = load("quick.toml", &[]);
    g.bench_function("quick_gr_512x512", |b| b.iter(|| quick.render(&|_| {})));
    let seed = load("seed.toml", &["image.width=512", "image.height=512"]);
    g.bench_function("seed_512x512", |b| b.iter(|| seed.render(&|_| {})));
    g.finish();
}

fn meshes(c: &mut Criterion) {
    // quick.toml's view with and without a 327,680-triangle asteroid
    // (icosphere level 7) filling a fifth of the image.
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("big.obj");
    let (v, f) = blackhole::assets::asteroid::asteroid(11, 7, 0.25);
    std::fs::write(&obj, blackhole::assets::asteroid::to_obj(&v, &f, "bench")).unwrap();
    let without = load("quick.toml", &[]);
    let with_mesh = {
        let mut cfg = without.config.clone();
        let extra: SceneConfig = toml::from_str(&format!(
            r#"
            [image]
            width = 1
            height = 1
            png = "x.png"
            [camera]
            position = [0.0, -1.0, 0.0]
            look_at = [0.0, 0.0, 0.0]
            fov = 10.0
            [black_hole]
            mass = 1.0
            [sky]
            color = [0.0, 0.0, 0.0]
            [[object]]
            kind = "mesh"
            file = "{}"
            position = [-2.8e10, -1.45e11, 2.4e10]
            scale = 1.6e10
            material = {{ kind = "lit", color = [0.3, 0.3, 0.3] }}
            [[light]]
            kind = "ambient"
            "#,
            obj.display()
        ))
        .unwrap();
        cfg.objects = extra.objects;
        cfg.lights = extra.lights;
        Scene::build(cfg).unwrap()
    };
    let mut g = c.benchmark_group("mesh");
    g.sample_size(10).measurement_time(seconds(10));
    g.bench_function("quick_without_mesh", |b| b.iter(|| without.render(&|_| {})));
    g.bench_function("quick_with_327k_triangle_mesh", |b| {
        b.iter(|| with_mesh.render(&|_| {}))
    });
    g.finish();
}

fn rays(c: &mut Criterion) {
    // One ray from 20 r_s passing at b ~ 3 r_s, the costly kind near the
    // shadow's edge; and one that grazes the disk's outer edge.
    let x0 = DVec3::new(-20.0, 0.0, 0.5);
    let near = DVec3::new(1.0, 0.155, 0.0);
    let far = DVec3::new(1.0, 0.45, 0.0);
    let limits = Limits {
        outer: 10.0,
        ..Limits::default()
    };
    let mut g = c.benchmark_group("ray");
    for (name, model) in [
        ("gr", Model::gr(1e-6)),
        ("seed", Model::Seed { step: 0.005 }),
    ] {
        g.bench_function(format!("{name}_b3"), |b| {
            b.iter(|| model.trace(x0, near, &limits, |_| Flow::Continue))
        });
        g.bench_function(format!("{name}_b9"), |b| {
            b.iter(|| model.trace(x0, far, &limits, |_| Flow::Continue))
        });
    }
    g.finish();
}

/// What a footprint costs beside its ray, on the 1024 x 1024 side view at
/// one sample (spin 0 and 0.9): whole renders with the footprint filter
/// (the default) and with `nearest`, and over a grid of 128 x 128 of its
/// image points the ray alone (its direction at infinity in closed form,
/// `Scene::escape_at`) and the footprint alone (`Scene::footprint`).
fn footprints(c: &mut Criterion) {
    let mut g = c.benchmark_group("footprint");
    g.sample_size(10).measurement_time(seconds(10));
    for spin in ["0", "0.9"] {
        let sets = |filter: &str| {
            [
                "image.width=1024".to_string(),
                "image.height=1024".to_string(),
                "image.samples=1".to_string(),
                "image.adaptive=false".to_string(),
                format!("black_hole.spin={spin}"),
                format!("sky.filter=\"{filter}\""),
                format!("disk.filter=\"{filter}\""),
            ]
        };
        let scene = |filter: &str| {
            let sets = sets(filter);
            let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
            load("side.toml", &sets)
        };
        let (fp, nearest) = (scene("footprint"), scene("nearest"));
        g.bench_function(format!("side_a{spin}_render_footprint"), |b| {
            b.iter(|| fp.render(&|_| {}))
        });
        g.bench_function(format!("side_a{spin}_render_nearest"), |b| {
            b.iter(|| nearest.render(&|_| {}))
        });
        let grid: Vec<glam::DVec2> = (0..128 * 128)
            .map(|i| glam::DVec2::new((i % 128) as f64 * 8.0 + 0.5, (i / 128) as f64 * 8.0 + 0.5))
            .collect();
        g.bench_function(format!("side_a{spin}_rays_128x128"), |b| {
            b.iter(|| grid.iter().filter_map(|&at| fp.escape_at(at)).count())
        });
        g.bench_function(format!("side_a{spin}_footprints_128x128"), |b| {
            b.iter(|| {
                grid.iter()
                    .filter_map(|&at| fp.footprint(at.x, at.y))
                    .count()
            })
        });
    }
    g.finish();
}

/// Page faults of this process so far (minor, major).
fn page_faults() -> (i64, i64) {
    // SAFETY: getrusage fills the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    (u.ru_minflt, u.ru_majflt)
}

fn gpu_vs_cpu(c: &mut Criterion) {
    // ms per 1920 x 1080 frame of the side view, RGB and spectral (81
    // wavelengths, shift, Doppler, beaming), on both backends; on the GPU
    // in closed form and integrated. A GPU frame
    // is the film back on the host (dispatch, wait and read-back), with
    // the scene uploaded and the shader compiled once beforehand.
    let size = ["image.width=1920", "image.height=1080"];
    let rgb = load("side.toml", &size);
    let spectral = load("spectral_side.toml", &size);
    let mut g = c.benchmark_group("frame_1080p");
    g.sample_size(10).measurement_time(seconds(20));
    g.bench_function("side_rgb_cpu", |b| b.iter(|| rgb.render(&|_| {})));
    g.bench_function("side_spectral_cpu", |b| b.iter(|| spectral.render(&|_| {})));
    match blackhole::gpu::Gpu::new() {
        Ok(mut gpu) => {
            eprintln!("GPU: {}", gpu.name());
            // Measure the closed form on every device (CPU devices
            // default to the integrator).
            gpu.set_closed_form(true);
            // The closed form (the default here) and the integrator forced.
            let rgb_int = load(
                "side.toml",
                &[size[0], size[1], "physics.closed_form=false"],
            );
            let spectral_int = load(
                "spectral_side.toml",
                &[size[0], size[1], "physics.closed_form=false"],
            );
            // The spectral view's scene in RGB: the star catalogue's sky
            // instead of the side view's panorama.
            let rgb_stars = load(
                "spectral_side.toml",
                &[size[0], size[1], "spectral.enabled=false"],
            );
            // The spinning hole in Kerr's closed form, RGB and spectral,
            // and integrated.
            let rgb_kerr = load("side.toml", &[size[0], size[1], "black_hole.spin=0.9"]);
            let spectral_kerr = load(
                "spectral_side.toml",
                &[size[0], size[1], "black_hole.spin=0.9"],
            );
            let rgb_kerr_int = load(
                "side.toml",
                &[
                    size[0],
                    size[1],
                    "black_hole.spin=0.9",
                    "physics.closed_form=false",
                ],
            );
            for (name, scene) in [
                ("side_rgb_gpu", &rgb),
                ("side_rgb_gpu_kerr_0.9", &rgb_kerr),
                ("side_spectral_gpu_kerr_0.9", &spectral_kerr),
                ("side_rgb_gpu_kerr_0.9_integrator", &rgb_kerr_int),
                ("side_rgb_star_sky_gpu", &rgb_stars),
                ("side_spectral_gpu", &spectral),
                ("side_rgb_gpu_integrator", &rgb_int),
                ("side_spectral_gpu_integrator", &spectral_int),
            ] {
                let prepared = gpu.prepare(scene, u32::MAX).unwrap();
                // The last sample's frames: wall time, the GPU's own (where
                // it keeps timestamps) and page faults, so that a long run
                // shows whether a slower frame is the device's or the
                // host's.
                let last = std::cell::Cell::new(None);
                g.bench_function(name, |b| {
                    b.iter_custom(|iters| {
                        let (faults, mut wall, mut device) = (page_faults(), Duration::ZERO, 0.0);
                        for _ in 0..iters {
                            let t = std::time::Instant::now();
                            prepared.render_image(&|_| {}).unwrap();
                            wall += t.elapsed();
                            device += prepared.device_seconds().unwrap_or(f64::NAN);
                        }
                        let after = page_faults();
                        let n = iters as f64;
                        last.set(Some((
                            wall.as_secs_f64() / n,
                            device / n,
                            (after.0 - faults.0) as f64 / n,
                            (after.1 - faults.1) as f64 / n,
                        )));
                        wall
                    })
                });
                if let Some((wall, device, minor, major)) = last.get() {
                    let device = if device.is_nan() {
                        "no timestamps".to_string()
                    } else {
                        format!("GPU {:.2} ms", device * 1e3)
                    };
                    eprintln!(
                        "{name}: a frame of the last sample: wall {:.2} ms, {device}, {minor:.0} minor and {major:.0} major page faults",
                        wall * 1e3
                    );
                }
            }
        }
        Err(e) => eprintln!("GPU benchmarks skipped: {e}"),
    }
    g.finish();
}

/// The viewer's session of a shipped config at `width` x `height`.
fn view_session(file: &str, width: u32, height: u32) -> blackhole::view::Session {
    let sets = [
        format!("image.width={width}"),
        format!("image.height={height}"),
        "image.samples=64".to_string(),
    ];
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("configs")
        .join(file);
    let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    blackhole::view::Session::open(&path, overrides, std::env::temp_dir()).unwrap()
}

fn gpu_frames(c: &mut Criterion) {
    // Frames that stay on the GPU, at 1080p and 4K, RGB (the side view)
    // and spectral (81 wavelengths, shift, Doppler, beaming), in the
    // closed form on every device:
    // - `trace`: one sample of every pixel traced and resolved, nothing
    //   read back but the counts;
    // - `viewer`: the viewer's frame offscreen: the camera moved (a
    //   1-degree drag, alternately left and right) and uploaded, one sample
    //   traced, added to the view's image, tone-mapped and encoded into the
    //   texture the window draws (no film read back);
    // - `viewer_scale2`: the same at half size, the preview a slow device
    //   shows while the view moves.
    // Groups `gpu_wall_*` time each frame on the host (submit to done);
    // `gpu_time_*` sum the device's own timestamps (where it has them).
    let Ok(mut gpu) = blackhole::gpu::Gpu::new() else {
        eprintln!("GPU frame benchmarks skipped: no GPU adapter");
        return;
    };
    gpu.set_closed_form(true);
    eprintln!("GPU: {}", gpu.name());
    let four_k = !gpu.is_cpu() || std::env::var_os("BLACKHOLE_BENCH_4K").is_some();
    if !four_k {
        eprintln!(
            "4K GPU benchmarks skipped on a CPU device (set BLACKHOLE_BENCH_4K=1 to run them)"
        );
    }
    let sizes: &[(&str, u32, u32)] = if four_k {
        &[("1080p", 1920, 1080), ("4k", 3840, 2160)]
    } else {
        &[("1080p", 1920, 1080)]
    };
    for &(size, w, h) in sizes {
        for clock in ["wall", "time"] {
            if clock == "time" && !gpu.has_timestamps() {
                eprintln!("gpu_time benchmarks skipped: the device has no timestamps");
                continue;
            }
            let mut g = c.benchmark_group(format!("gpu_{clock}_{size}"));
            g.sample_size(10).measurement_time(seconds(10));
            for (kind, file) in [("rgb", "side.toml"), ("spectral", "spectral_side.toml")] {
                let session = view_session(file, w, h);
                let mut state = session.start();
                let mut scene = session.scene(&state, None, None, true).unwrap();
                let mut prepared = gpu.prepare_passes(&scene, 1).unwrap();
                let mut dx = 4.0;
                let mut frame = |what: &str| {
                    match what {
                        "trace" => {
                            prepared.trace_pass(0, 1, 1).unwrap();
                        }
                        _ => {
                            // Back and forth, so the view stays the file's.
                            dx = -dx;
                            state.orbit(dx, 0.0);
                            scene.set_view(&state.pose, state.time).unwrap();
                            prepared.set_frame(&scene).unwrap();
                            let scale = if what == "viewer" { 1 } else { 2 };
                            prepared.view_pass(0, 1, scale, true).unwrap();
                        }
                    }
                    prepared.device_seconds()
                };
                for what in ["trace", "viewer", "viewer_scale2"] {
                    let name = format!("{kind}_{what}");
                    if clock == "wall" {
                        g.bench_function(name, |b| b.iter(|| frame(what)));
                    } else {
                        g.bench_function(name, |b| {
                            b.iter_custom(|iters| {
                                (0..iters)
                                    .map(|_| Duration::from_secs_f64(frame(what).unwrap()))
                                    .sum()
                            })
                        });
                    }
                }
            }
            g.finish();
        }
    }
}

criterion_group!(
    benches, renders, meshes, rays, footprints, gpu_vs_cpu, gpu_frames
);
criterion_main!(benches);
