//! Adaptive sampling's measurements (validation/REFERENCE.md section 17):
//! renders a scene with overrides, writes its film (`OUT.xyz`, raw
//! little-endian float32 XYZ) and a map of the samples each pixel took
//! (`OUT.counts.png`: black where the base samples sufficed), and compares
//! it with a reference film as displayed (CIEDE2000 mean, 99th and 99.9th
//! percentiles, largest).
//!
//! ```text
//! cargo run --release --example adaptive_probe -- CONFIG OUT [REFERENCE.xyz] [--set KEY=VALUE]... [--gpu]
//! cargo run --release --example adaptive_probe -- configs/quick.toml ref --set image.samples=256
//! cargo run --release --example adaptive_probe -- configs/quick.toml a ref.xyz --set image.adaptive=true
//! ```
//!
//! `--gpu` renders on the GPU backend (timed after the shader is compiled).

use blackhole::config::{Override, SceneConfig};
use blackhole::scene::Scene;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut pos, mut sets) = (Vec::new(), Vec::new());
    let mut it = args.iter();
    let mut on_gpu = false;
    while let Some(a) = it.next() {
        if a == "--gpu" {
            on_gpu = true;
        } else if a == "--set" {
            sets.push(Override::parse(it.next().expect("KEY=VALUE"))?);
        } else {
            pos.push(a.clone());
        }
    }
    let cfg = SceneConfig::load(std::path::Path::new(&pos[0]), &sets)?;
    let scene = Scene::build(cfg)?;
    let never = std::sync::atomic::AtomicBool::new(false);
    let rows = 0..scene.camera.height;
    let (secs, (film, stats, counts)) = if on_gpu {
        let gpu = blackhole::gpu::Gpu::new()?;
        let prepared = gpu.prepare(&scene, u32::MAX)?;
        let t = Instant::now();
        let done = prepared.render_rows_counted(rows, &|_| {})?;
        (t.elapsed().as_secs_f64(), done)
    } else {
        let t = Instant::now();
        let done = scene.render_rows_counted(rows, &|_| {}, &never).unwrap();
        (t.elapsed().as_secs_f64(), done)
    };
    let px = counts.len();
    let base = scene.samples;
    let refined = counts.iter().filter(|&&c| c > base).count();
    let bytes: Vec<u8> = film
        .xyz
        .iter()
        .flat_map(|v| v.to_array())
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::write(format!("{}.xyz", pos[1]), bytes)?;
    let max = *counts.iter().max().unwrap_or(&1) as f32;
    let img = image::GrayImage::from_fn(film.width, film.height, |x, y| {
        let c = counts[(y * film.width + x) as usize];
        image::Luma([if c > base {
            (64.0 + 191.0 * c as f32 / max) as u8
        } else {
            0
        }])
    });
    img.save(format!("{}.counts.png", pos[1]))?;
    let mut line = format!(
        "{}: {:.2} s, {} samples ({} extra), refined {:.2}% of pixels, {:.2} samples/px",
        pos[1],
        secs,
        stats.samples,
        stats.extra,
        100.0 * refined as f64 / px as f64,
        stats.samples as f64 / px as f64
    );
    if let Some(r) = pos.get(2) {
        let raw = std::fs::read(r)?;
        let reference: Vec<glam::Vec3> = raw
            .chunks(12)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().unwrap());
                glam::Vec3::new(f(0), f(4), f(8))
            })
            .collect();
        let img = scene.image();
        let shown = |xyz: &[glam::Vec3]| -> Vec<glam::Vec3> {
            xyz.iter()
                .map(|c| {
                    let rgb =
                        blackhole::spectrum::color::xyz_to_linear_srgb(c.as_dvec3()).as_vec3();
                    blackhole::output::tone_map(rgb, img.exposure as f32, img.tonemap)
                })
                .collect()
        };
        let mut de: Vec<f64> = shown(&film.xyz)
            .iter()
            .zip(shown(&reference))
            .map(|(p, q)| blackhole::compare::delta_e(*p, q))
            .collect();
        de.sort_by(f64::total_cmp);
        let n = de.len();
        let q = |f: f64| de[((f * n as f64) as usize).min(n - 1)];
        line += &format!(
            "; CIEDE2000 mean {:.3}, p99 {:.2}, p99.9 {:.2}, max {:.1}",
            de.iter().sum::<f64>() / n as f64,
            q(0.99),
            q(0.999),
            de[n - 1]
        );
    }
    println!("{line}");
    Ok(())
}
