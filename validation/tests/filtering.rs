//! Footprint filtering of textures (the elliptical Gaussian filter over
//! mip levels of `blackhole::texture::ewa`) against analytic averages, its
//! anti-aliasing, the panorama's seam and poles, and `relens`.

mod common;

use blackhole::texture::{Footprint, Texture, equirect_dir, equirect_uv};
use glam::{DVec2, DVec3, Vec4};
use std::path::Path;

/// The filter's weight at r^2 (the ellipse's unit at r = 1).
fn kernel(r2: f64) -> f64 {
    if r2 < 1.0 {
        (-2.0 * r2).exp() - (-2.0f64).exp()
    } else {
        0.0
    }
}

/// Simpson's rule of `f` over [a, b] with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for i in 1..n {
        s += f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// The Gaussian-weighted average of a pattern `p(x)` that varies across
/// only, under an axis-aligned ellipse of half-axes (s1, s2) texels
/// centred at (cx, cy) on a grid whose rows are at y + 0.5: each row the
/// ellipse crosses contributes the continuous integral of p along it
/// (the rows are the texture's, the pattern being constant along them).
fn row_average(p: impl Fn(f64) -> f64, (cx, cy): (f64, f64), (s1, s2): (f64, f64)) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    let first = (cy - s2 - 0.5).ceil() as i64;
    for y in first..=(cy + s2 - 0.5).floor() as i64 {
        let dy = (y as f64 + 0.5 - cy) / s2;
        if dy.abs() >= 1.0 {
            continue;
        }
        let half = s1 * (1.0 - dy * dy).sqrt();
        let k = |dx: f64| kernel((dx / s1).powi(2) + dy * dy);
        num += simpson(|dx| k(dx) * p(cx + dx), -half, half, 4000);
        den += simpson(k, -half, half, 4000);
    }
    num / den
}

/// A linear (f32) texture of grey values `f(x, y)` at texel (x, y).
fn grey(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> Texture {
    let mut t = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let v = f(x, y);
            t.push([v, v, v, 1.0]);
        }
    }
    Texture::linear(w, h, t)
}

#[test]
fn a_sinusoid_filtered_is_its_gaussian_weighted_average() {
    // 0.5 + 0.4 cos(omega x) across a 512 x 64 texture, period 32 texels,
    // under footprints along the pattern 16 (level 0) and 64 (level 2)
    // texels long (the anisotropy cap: minor axes 1 and 4 texels). Level 2 holds the 4-texel box means of the pattern:
    // the same sinusoid, its amplitude times sin(2 omega) / (4 sin(omega /
    // 2)), at its texel centres.
    let (w, h) = (512u32, 64u32);
    let omega = std::f64::consts::TAU / 32.0;
    let t = grey(w, h, |x, _| {
        (0.5 + 0.4 * (omega * (x as f64 + 0.5)).cos()) as f32
    });
    let box4 = (2.0 * omega).sin() / (4.0 * (0.5 * omega).sin());
    let mut worst: f64 = 0.0;
    for (k, s1, s2) in [(0, 16.0, 1.0), (2, 64.0, 4.0)] {
        // (The filter reaches REACH of a pixel step.)
        let r = blackhole::texture::ewa::REACH;
        let fp = Footprint::new(s1 / w as f64 / r, 0.0, 0.0, s2 / h as f64 / r);
        let scale = 2f64.powi(k);
        let (amp, om) = if k == 0 {
            (0.4, omega)
        } else {
            (0.4 * box4, omega * scale)
        };
        for &(cx, cy) in &[(100.3, 30.4), (117.77, 21.0), (260.0, 40.9), (333.1, 12.2)] {
            let got = t
                .sample_footprint(cx / w as f64, cy / h as f64, &fp, false)
                .x as f64;
            let want = row_average(
                |x| 0.5 + amp * (om * x).cos(),
                (cx / scale, cy / scale),
                (s1 / scale, s2 / scale),
            );
            worst = worst.max((got - want).abs());
            assert!(
                (got - want).abs() < 5e-4,
                "level {k} at ({cx}, {cy}): {got} vs {want}"
            );
        }
    }
    println!("sinusoid: largest difference from the weighted average {worst:.2e}");
}

#[test]
fn one_footprint_sample_is_nearer_the_converged_picture_than_one_point() {
    // The disk texture and the sky panorama read over each pixel's
    // footprint at one sample a pixel, against the same view at 64
    // samples (bilinear points): closer than one bilinear point a pixel,
    // in mean CIEDE2000.
    let a = common::assets();
    let view = |filter: &str, samples: u32| {
        common::SceneText::new(64, 40)
            .samples(samples)
            .camera([0.0, -2.2e11, 3.0e10], [0.0; 3], 55.0)
            .with(&format!(
                "[disk]\nradius = 10.0\ntexture = \"{}\"\nfilter = \"{filter}\"\n\
                 [sky]\ntexture = \"{}\"\nfilter = \"{filter}\"",
                a.join("disk_rgba.png").display(),
                a.join("sky.png").display()
            ))
            .build()
    };
    let reference = view("bilinear", 64);
    let converged = reference.render(&|_| {}).0;
    let error = |filter: &str| {
        let film = view(filter, 1).render(&|_| {}).0;
        common::delta_e(&reference, &film, &converged).0
    };
    let (footprint, point) = (error("footprint"), error("bilinear"));
    eprintln!("mean CIEDE2000 to 64 samples: footprint {footprint:.3}, bilinear point {point:.3}");
    assert!(footprint < 0.7 * point, "{footprint} vs {point}");
}

/// A small deterministic generator (the tests' values do not change).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A footprint of half-axes `major` and `major / aniso` texels of a w x h
/// texture, the major axis at `angle`.
fn footprint(w: u32, h: u32, major: f64, aniso: f64, angle: f64) -> Footprint {
    let e = DVec2::new(angle.cos(), angle.sin());
    let size = DVec2::new(w as f64, h as f64);
    Footprint {
        dx: e * major / size,
        dy: e.perp() * (major / aniso) / size,
    }
}

#[test]
fn a_constant_texture_stays_constant_at_every_level_and_anisotropy() {
    let (w, h) = (300u32, 150u32);
    let srgb = |a: u8| {
        Texture::from_image(image::DynamicImage::ImageRgba8(
            image::RgbaImage::from_pixel(w, h, image::Rgba([200, 100, 30, a])),
        ))
    };
    let textures = [
        srgb(255),
        srgb(128),
        Texture::linear(w, h, vec![[0.3, 2.5, 0.01, 0.7]; (w * h) as usize]),
    ];
    let mut rng = Lcg(7);
    for t in &textures {
        let want = t.texel(0, 0);
        for _ in 0..2000 {
            // Half-axes from 0.01 texel to 20 times the texture, ratios to 200.
            let major = 10f64.powf(-2.0 + 5.8 * rng.next());
            let aniso = 10f64.powf(2.3 * rng.next());
            let fp = footprint(w, h, major, aniso, rng.next() * 7.0);
            let (u, v) = (rng.next() * 1.2 - 0.1, rng.next() * 1.2 - 0.1);
            let wrap = rng.next() < 0.5;
            let got = t.sample_footprint(u, v, &fp, wrap);
            assert!(
                (got - want).abs().max_element() <= 1e-6 * want.max_element(),
                "{fp:?} at ({u}, {v}): {got} vs {want}"
            );
        }
    }
}

#[test]
fn a_minified_checkerboard_filters_to_its_mean() {
    // Cells of 3 texels (not aligned with the pyramid's 2^k blocks), black
    // and white (linear 0 and 1): nearest and bilinear lookups alias to
    // anything in [0, 1]; the footprint filter approaches the mean 0.5 as
    // the footprint grows past a cell.
    let (w, h) = (1536u32, 768u32);
    let t = Texture::from_image(image::DynamicImage::ImageRgba8(image::RgbaImage::from_fn(
        w,
        h,
        |x, y| {
            let c = if (x / 3 + y / 3) % 2 == 0 { 0 } else { 255 };
            image::Rgba([c, c, c, 255])
        },
    )));
    let mut rng = Lcg(3);
    let mut previous = f64::INFINITY;
    for (major, aniso, bound) in [
        (12.0, 1.0, 0.08),
        (24.0, 1.0, 0.03),
        (48.0, 1.0, 0.015),
        (96.0, 8.0, 0.03),
    ] {
        let (mut worst, mut worst_bilinear) = (0.0f64, 0.0f64);
        for _ in 0..500 {
            let fp = footprint(w, h, major, aniso, rng.next() * 7.0);
            let (u, v) = (rng.next(), 0.1 + 0.8 * rng.next());
            let got = t.sample_footprint(u, v, &fp, true).x as f64;
            let bl = t.sample(u, v, blackhole::config::Filter::Bilinear, true).x as f64;
            worst = worst.max((got - 0.5).abs());
            worst_bilinear = worst_bilinear.max((bl - 0.5).abs());
        }
        println!(
            "checkerboard, half-axes {major} / {} texels: largest |value - 0.5| {worst:.4} (bilinear {worst_bilinear:.3})",
            major / aniso
        );
        assert!(worst < bound, "{major} / {aniso}: {worst}");
        assert!(worst_bilinear > 0.4, "bilinear aliases: {worst_bilinear}");
        if aniso == 1.0 {
            assert!(worst < previous, "approaches the mean as it grows");
            previous = worst;
        }
    }
}

#[test]
fn the_seam_is_seamless() {
    // A panorama and its copy turned half a turn: a footprint across the
    // seam (u = 0) of one reads what the same footprint reads in the
    // middle of the other.
    let (w, h) = (256u32, 128u32);
    let f = |x: u32, y: u32| ((x * 37 + y * 11) % 17) as f32 / 16.0 + if x < 3 { 1.0 } else { 0.0 };
    let t = grey(w, h, f);
    let turned = grey(w, h, |x, y| f((x + w / 2) % w, y));
    for (major, aniso) in [(0.5, 1.0), (6.0, 1.0), (20.0, 4.0), (40.0, 16.0)] {
        let fp = footprint(w, h, major, aniso, 0.3);
        for u in [0.0, 0.001, 0.999] {
            let a = t.sample_footprint(u, 0.4, &fp, true);
            let b = turned.sample_footprint(u + 0.5, 0.4, &fp, true);
            assert!(
                (a - b).abs().max_element() < 1e-5,
                "{major} at u {u}: {a} vs {b}"
            );
        }
    }
    // Through directions: just either side of phi = 0 the sky reads the same.
    let d = |phi: f64| DVec3::new(phi.sin(), phi.cos(), 0.2).normalize();
    let (ddx, ddy) = (DVec3::new(4e-3, 0.0, 0.0), DVec3::new(0.0, 0.0, 4e-3));
    let a = t.sample_sky_footprint(d(1e-9), ddx, ddy);
    let b = t.sample_sky_footprint(d(-1e-9), ddx, ddy);
    assert!((a - b).abs().max_element() < 1e-5, "{a} vs {b}");
}

#[test]
fn at_the_poles_the_sky_reads_the_whole_row() {
    // Rows 0-15 (within 11 degrees of the north pole): stripes one texel
    // wide, 0 and 1. A footprint at the pole a few milliradians across
    // reads the whole rows there (u is meaningless at the pole): their
    // mean 0.5, not one stripe.
    let (w, h) = (256u32, 128u32);
    let t = grey(w, h, |x, y| if y < 16 { (x % 2) as f32 } else { 0.2 });
    for (dir, tilt) in [
        (DVec3::Z, 0.0),
        (DVec3::new(1e-9, 0.0, 1.0).normalize(), 0.3),
    ] {
        let a = dir.any_orthonormal_vector();
        let b = dir.cross(a);
        for size in [1e-4, 3e-3, 0.02] {
            let got = t.sample_sky_footprint(dir, a * size, (b + a * tilt) * size);
            assert!(got.is_finite(), "{got}");
            assert!((got.x - 0.5).abs() < 0.02, "size {size}: {got}");
        }
    }
    // The south pole's rows are 0.2.
    let got = t.sample_sky_footprint(-DVec3::Z, DVec3::X * 1e-3, DVec3::Y * 1e-3);
    assert!((got.x - 0.2).abs() < 1e-6, "{got}");
}

/// A pinhole camera's view: `w` x `h` pixels, horizontal field `fov`
/// (radians), looking along `forward` with `up` up. Returns each pixel's
/// unit direction and its exact derivatives per pixel step across and
/// down.
fn pinhole(w: u32, h: u32, fov: f64, forward: DVec3, up: DVec3) -> Vec<(DVec3, DVec3, DVec3)> {
    let f = forward.normalize();
    let r = f.cross(up).normalize();
    let u = r.cross(f);
    let s = 2.0 * (0.5 * fov).tan() / w as f64;
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let a = (x as f64 + 0.5 - 0.5 * w as f64) * s;
            let b = (y as f64 + 0.5 - 0.5 * h as f64) * s;
            let p = f + r * a - u * b;
            let (n, d) = (p.length(), p.normalize());
            let tangent = |v: DVec3| (v - d * v.dot(d)) / n;
            out.push((d, tangent(r * s), tangent(-u * s)));
        }
    }
    out
}

/// Writes an EXR of w x h pixels with the float channels `channels`.
fn write_exr(path: &Path, w: u32, h: u32, channels: &[(&str, Vec<f32>)]) {
    use exr::prelude::*;
    let list: Vec<AnyChannel<FlatSamples>> = channels
        .iter()
        .map(|(n, v)| AnyChannel::new(*n, FlatSamples::F32(v.clone())))
        .collect();
    let layer = Layer::new(
        (w as usize, h as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(list)),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// The channels R, G, B, A of an EXR.
fn read_rgba(path: &Path) -> (u32, u32, Vec<Vec4>) {
    use exr::prelude::*;
    let img = read_all_flat_layers_from_file(path).unwrap();
    let layer = &img.layer_data[0];
    let ch = |name: &str| -> Vec<f32> {
        layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.to_string() == name)
            .unwrap_or_else(|| panic!("no {name}"))
            .sample_data
            .values_as_f32()
            .collect()
    };
    let (r, g, b, a) = (ch("R"), ch("G"), ch("B"), ch("A"));
    let px = (0..r.len())
        .map(|i| Vec4::new(r[i], g[i], b[i], a[i]))
        .collect();
    (layer.size.0 as u32, layer.size.1 as u32, px)
}

/// A 2:1 panorama with detail at every scale: a hue gradient, a 1-texel
/// checker and a 20-texel grid, written as a PNG.
fn write_panorama(path: &Path, w: u32) {
    let img = image::RgbImage::from_fn(w, w / 2, |x, y| {
        let fine = if (x + y) % 2 == 0 { 60 } else { 0 };
        let grid = if x % 20 < 2 || y % 20 < 2 { 120 } else { 0 };
        image::Rgb([
            (x * 255 / w) as u8 / 2 + fine,
            (y * 510 / w) as u8 / 2 + grid,
            90 + fine / 2,
        ])
    });
    img.save(path).unwrap();
}

/// The lens map of `view` as a render's EXR writes it: obs.sky.* (NaN
/// where `hole` says the ray fell in), obs.magnification 1, and RGB.
fn write_lens_map(
    path: &Path,
    w: u32,
    h: u32,
    view: &[(DVec3, DVec3, DVec3)],
    hole: impl Fn(u32, u32) -> bool,
) {
    let c = |k: usize| -> Vec<f32> {
        view.iter()
            .enumerate()
            .map(|(i, v)| {
                if hole(i as u32 % w, i as u32 / w) {
                    f32::NAN
                } else {
                    v.0[k] as f32
                }
            })
            .collect()
    };
    let n = view.len();
    write_exr(
        path,
        w,
        h,
        &[
            ("R", vec![0.1; n]),
            ("G", vec![0.1; n]),
            ("B", vec![0.1; n]),
            ("obs.sky.x", c(0)),
            ("obs.sky.y", c(1)),
            ("obs.sky.z", c(2)),
            ("obs.magnification", vec![1.0; n]),
        ],
    );
}

#[test]
fn relens_of_a_flat_lens_map_is_the_pinhole_view() {
    // No lens: the map is a pinhole camera's directions, and relens must
    // give the panorama seen through that camera, each pixel filtered over
    // its exact footprint (the derivatives of the camera's directions).
    // Inside, relens takes central differences of f32 directions; at the
    // image's edges one-sided ones.
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (96u32, 64u32);
    let view = pinhole(w, h, 1.0, DVec3::new(0.3, 1.0, 0.45), DVec3::Z);
    let (map, pano) = (dir.path().join("map.exr"), dir.path().join("pano.png"));
    write_lens_map(&map, w, h, &view, |_, _| false);
    write_panorama(&pano, 1024);
    let out = dir.path().join("out.exr");
    let (code, err) = common::run(
        dir.path(),
        &[
            "relens",
            map.to_str().unwrap(),
            pano.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("relensed"), "{err}");
    let (ow, oh, px) = read_rgba(&out);
    assert_eq!((ow, oh), (w, h));
    let mut texture = Texture::load(&pano).unwrap();
    texture.make_opaque();
    let (mut inside, mut edge) = (0.0f32, 0.0f32);
    for (i, &(d, ddx, ddy)) in view.iter().enumerate() {
        let want = texture.sample_sky_footprint(d, ddx, ddy);
        let diff = (px[i] - want).abs().max_element();
        let (x, y) = (i as u32 % w, i as u32 / w);
        if x == 0 || y == 0 || x == w - 1 || y == h - 1 {
            edge = edge.max(diff);
        } else {
            inside = inside.max(diff);
        }
    }
    println!(
        "relens against the pinhole view: largest difference {inside:.2e} inside, {edge:.2e} at the edges"
    );
    assert!(inside < 2e-3, "{inside}");
    assert!(edge < 0.03, "{edge}");
    // Each pixel's footprint spans several panorama texels here (1 rad
    // over 96 pixels against 2 pi over 1024 texels): filtering did reduce
    // the one-texel checker, which a bilinear lookup keeps.
    let (u, v) = equirect_uv(view[(h / 2 * w + w / 2) as usize].0);
    assert!((equirect_dir(u, v) - view[(h / 2 * w + w / 2) as usize].0).length() < 1e-9);

    // The PNG is the same pixels encoded: within one code.
    let png = dir.path().join("out.png");
    let (code, err) = common::run(
        dir.path(),
        &[
            "relens",
            "-q",
            map.to_str().unwrap(),
            pano.to_str().unwrap(),
            png.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "-q prints nothing: {err}");
    let img = image::open(&png).unwrap().to_rgb8();
    for (i, p) in img.pixels().enumerate() {
        for (c, &code) in p.0.iter().enumerate() {
            let want = blackhole::spectrum::color::encode_u8(px[i][c]);
            assert!(code.abs_diff(want) <= 1, "pixel {i}: {:?} vs {want}", p.0);
        }
    }
}

#[test]
fn relens_leaves_the_shadow_black_and_does_not_filter_across_it() {
    // A disc of rays that fell in: black and transparent there; next to it
    // the footprints come from the sky side only, so the pixels there are
    // the pinhole view's up to one-sided differences.
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (64u32, 48u32);
    let view = pinhole(w, h, 0.8, DVec3::new(-0.5, 1.0, 0.1), DVec3::Z);
    let hole = |x: u32, y: u32| (x as f64 - 30.0).hypot(y as f64 - 22.0) < 9.0;
    let (map, pano, out) = (
        dir.path().join("map.exr"),
        dir.path().join("pano.png"),
        dir.path().join("out.exr"),
    );
    write_lens_map(&map, w, h, &view, hole);
    write_panorama(&pano, 1024);
    let (code, err) = common::run(
        dir.path(),
        &[
            "relens",
            "-q",
            map.to_str().unwrap(),
            pano.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    let (_, _, px) = read_rgba(&out);
    let mut texture = Texture::load(&pano).unwrap();
    texture.make_opaque();
    let mut worst = 0.0f32;
    for (i, &(d, ddx, ddy)) in view.iter().enumerate() {
        let (x, y) = (i as u32 % w, i as u32 / w);
        if hole(x, y) {
            assert_eq!(px[i], Vec4::ZERO, "({x}, {y}) fell in");
            continue;
        }
        assert_eq!(px[i].w, 1.0);
        let want = texture.sample_sky_footprint(d, ddx, ddy);
        worst = worst.max((px[i] - want).abs().max_element());
    }
    println!("beside a shadow: largest difference from the pinhole view {worst:.2e}");
    assert!(worst < 0.03, "{worst}");
}

#[test]
fn relens_matches_the_renderers_sky() {
    // A 1 m hole seen from 1e4 m: rays escape along the camera's own
    // directions (deflections of 1e-4 rad at most). The panorama's colour
    // is its texture coordinates, so the render's sky tells where each ray
    // read it; relens through the lens map of the camera's directions must
    // read the same place (the renderer's orientation, not a mirror).
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (1024u32, 512u32);
    let pano = dir.path().join("uv.exr");
    image::Rgb32FImage::from_fn(w, h, |x, y| {
        image::Rgb([
            (x as f32 + 0.5) / w as f32,
            (y as f32 + 0.5) / h as f32,
            0.25,
        ])
    })
    .save(&pano)
    .unwrap();
    let (iw, ih) = (40u32, 30u32);
    let s = common::SceneText::new(iw, ih)
        .camera([1e4, -1e4, 3e3], [2e4, -1.5e4, 9e3], 50.0)
        .mass(common::unit_mass())
        .with(&format!(
            "[sky]\ntexture = \"{}\"\nfilter = \"bilinear\"",
            pano.display()
        ))
        .build();
    let view: Vec<(DVec3, DVec3, DVec3)> = (0..iw * ih)
        .map(|i| {
            let d = s
                .camera
                .ray_direction((i % iw) as f64 + 0.5, (i / iw) as f64 + 0.5);
            (d.normalize(), DVec3::ZERO, DVec3::ZERO)
        })
        .collect();
    let map = dir.path().join("map.exr");
    write_lens_map(&map, iw, ih, &view, |_, _| false);
    let out = dir.path().join("out.exr");
    let (code, err) = common::run(
        dir.path(),
        &[
            "relens",
            "-q",
            map.to_str().unwrap(),
            pano.to_str().unwrap(),
            out.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    let (_, _, px) = read_rgba(&out);
    let mut worst = 0.0f32;
    for (i, p) in px.iter().enumerate() {
        let (x, y) = ((i as u32 % iw) as f64 + 0.5, (i as u32 / iw) as f64 + 0.5);
        let (rgb, _) = s.radiance(x, y);
        // The view stays clear of the seam (u near 0 or 1).
        assert!(rgb.x > 0.02 && rgb.x < 0.98, "{rgb}");
        worst = worst.max((p.truncate() - rgb).abs().max_element());
    }
    // A pixel spans about 3.5 texels: the filter reads levels 1 and 2,
    // where the lattice of texels moves the weights' centroid by up to a
    // tenth of their texels (8e-3 in v on level 2). A mirrored or turned
    // panorama would be off by tenths.
    println!(
        "relens against the render's sky: largest difference {worst:.2e} (a row of texels is 2e-3)"
    );
    assert!(worst < 2e-3, "{worst}");
}

/// Runs relens with these arguments in `dir`; checks it failed, naming
/// `needles`, without a panic, leaving no OUT and no temporary.
fn refused(dir: &Path, args: &[&str], out: &Path, needles: &[&str]) {
    let before = std::fs::read_dir(dir).unwrap().count();
    let mut all = vec!["relens"];
    all.extend_from_slice(args);
    let (code, err) = common::run(dir, &all);
    assert_ne!(code, 0, "{args:?} should fail");
    for n in needles {
        assert!(err.contains(n), "{args:?}: message lacks {n:?}:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        before,
        "left a file"
    );
}

#[test]
fn relens_refuses_bad_input_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (w, h) = (8u32, 6u32);
    let view = pinhole(w, h, 1.0, DVec3::Y, DVec3::Z);
    write_lens_map(&d.join("map.exr"), w, h, &view, |_, _| false);
    write_panorama(&d.join("pano.png"), 64);
    write_exr(
        &d.join("plain.exr"),
        w,
        h,
        &[
            ("R", vec![0.0; 48]),
            ("G", vec![0.0; 48]),
            ("B", vec![0.0; 48]),
        ],
    );
    std::fs::write(d.join("text.exr"), "not an image").unwrap();
    image::RgbImage::new(60, 40)
        .save(d.join("square.png"))
        .unwrap();
    // Twice as wide as high to 2%, as sky.texture: 203 x 100 is, 205 x 100
    // is not.
    image::RgbImage::new(203, 100)
        .save(d.join("near.png"))
        .unwrap();
    image::RgbImage::new(205, 100)
        .save(d.join("wide.png"))
        .unwrap();
    // Directions stored as unsigned integers are some other file's.
    {
        use exr::prelude::*;
        let n = (w * h) as usize;
        let list: Vec<AnyChannel<FlatSamples>> = ["obs.sky.x", "obs.sky.y", "obs.sky.z"]
            .iter()
            .map(|c| AnyChannel::new(*c, FlatSamples::U32(vec![1; n])))
            .collect();
        let layer = Layer::new(
            (w as usize, h as usize),
            LayerAttributes::default(),
            Encoding::SMALL_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(list)),
        );
        Image::from_layer(layer)
            .write()
            .to_file(d.join("ints.exr"))
            .unwrap();
    }
    let out = d.join("out.png");
    let o = out.to_str().unwrap();
    let cases: [([&str; 3], &[&str]); 7] = [
        (
            ["text.exr", "pano.png", o],
            &["text.exr", "not an OpenEXR file"],
        ),
        (
            ["pano.png", "pano.png", o],
            &["pano.png", "not an OpenEXR file"],
        ),
        (
            ["plain.exr", "pano.png", o],
            &["plain.exr", "no channel obs.sky.x"],
        ),
        (
            ["map.exr", "square.png", o],
            &["square.png", "60 x 40", "twice as wide"],
        ),
        (
            ["map.exr", "wide.png", o],
            &["wide.png", "205 x 100", "to 2%"],
        ),
        (
            ["ints.exr", "pano.png", o],
            &["ints.exr", "obs.sky.x holds unsigned integers"],
        ),
        (["map.exr", "", o], &["<PANORAMA>", "a value is required"]),
    ];
    for (args, said) in cases {
        refused(d, &args, &out, said);
    }
    refused(
        d,
        &["missing.exr", "pano.png", o],
        &out,
        &["missing.exr", "cannot read"],
    );
    refused(
        d,
        &["map.exr", "missing.png", o],
        &out,
        &["missing.png", "cannot read"],
    );
    refused(
        d,
        &["map.exr", "text.exr", o],
        &out,
        &["text.exr", "cannot read panorama"],
    );
    let jpg = d.join("out.jpg");
    refused(
        d,
        &["map.exr", "pano.png", jpg.to_str().unwrap()],
        &jpg,
        &["out.jpg", ".png or .exr"],
    );
    let (code, err) = common::run(d, &["relens", "map.exr", "near.png", "near_out.png"]);
    assert_eq!(code, 0, "203 x 100: {err}");
    std::fs::remove_file(d.join("near_out.png")).unwrap();
    // The output may not be an input.
    let before = std::fs::read(d.join("pano.png")).unwrap();
    let (code, err) = common::run(d, &["relens", "map.exr", "pano.png", "pano.png"]);
    assert_ne!(code, 0);
    assert!(err.contains("pano.png") && err.contains("input"), "{err}");
    assert_eq!(std::fs::read(d.join("pano.png")).unwrap(), before);
}

/// Seconds per call of `f` over `n` calls.
fn per_call(n: usize, mut f: impl FnMut(usize) -> Vec4) -> f64 {
    let start = std::time::Instant::now();
    let mut acc = Vec4::ZERO;
    for i in 0..n {
        acc += f(i);
    }
    std::hint::black_box(acc);
    start.elapsed().as_secs_f64() / n as f64
}

#[test]
#[ignore = "a measurement: cargo test --release --test filtering -- --ignored --nocapture"]
fn lookup_cost_and_pyramid_size() {
    let assets = common::assets();
    measure_sky(&assets);
    measure_disk(&assets);
}

/// The sky panorama's pyramid, lookups and relens.
fn measure_sky(assets: &Path) {
    let start = std::time::Instant::now();
    let mut sky = Texture::load(&assets.join("sky.png")).unwrap();
    sky.make_opaque();
    println!(
        "sky.png {} x {}: decoded in {:.2} s, {} MiB",
        sky.width,
        sky.height,
        start.elapsed().as_secs_f64(),
        sky.memory_bytes() >> 20
    );
    let start = std::time::Instant::now();
    sky.build_pyramid();
    println!(
        "  pyramid built in {:.3} s: {:.1} MiB more ({:.1}% of the texels)",
        start.elapsed().as_secs_f64(),
        sky.pyramid_bytes() as f64 / 1048576.0,
        100.0 * sky.pyramid_bytes() as f64 / (sky.memory_bytes() - sky.pyramid_bytes()) as f64
    );
    // As a render reads it: a raster of pixels stepping by the footprint
    // (neighbouring pixels read neighbouring texels), rotated.
    let raster = |major: f64, aniso: f64, angle: f64| {
        let fp = footprint(sky.width, sky.height, major, aniso, angle);
        move |i: usize| {
            let (x, y) = ((i % 1000) as f64, (i / 1000 % 1000) as f64);
            let uv = DVec2::new(0.3, 0.2) + fp.dx * x + fp.dy * y;
            (fp, uv.x, 0.05 + uv.y.rem_euclid(0.9))
        }
    };
    let n = 1_000_000;
    for (what, major, aniso) in [
        ("magnified (half-axes 0.3 texel)", 0.3, 1.0),
        ("1 texel", 1.0, 1.0),
        ("3 texels (blend of levels 1 and 2)", 3.0, 1.0),
        ("16 texels", 16.0, 1.0),
        ("anisotropic 8:1, minor 1.5 texels", 12.0, 8.0),
        ("anisotropic 16:1, minor 1.5 texels", 24.0, 16.0),
        ("anisotropic 100:1 (capped at 16)", 150.0, 100.0),
    ] {
        let at = raster(major, aniso, 0.4);
        let nearest = per_call(n, |i| {
            let (_, u, v) = at(i);
            sky.sample(u, v, blackhole::config::Filter::Nearest, true)
        });
        let bilinear = per_call(n, |i| {
            let (_, u, v) = at(i);
            sky.sample(u, v, blackhole::config::Filter::Bilinear, true)
        });
        let ewa = per_call(n, |i| {
            let (fp, u, v) = at(i);
            sky.sample_footprint(u, v, &fp, true)
        });
        println!(
            "  {what}: nearest {:.0} ns, bilinear {:.0} ns, footprint {:.0} ns ({:.1} x bilinear)",
            nearest * 1e9,
            bilinear * 1e9,
            ewa * 1e9,
            ewa / bilinear
        );
    }
    // relens of a 960 x 540 pinhole view, 60 and 120 degrees across (a
    // pixel about 0.7 and 1.4 texels of the 4096-texel panorama at the
    // centre).
    for fov in [60f64, 120.0] {
        let view = pinhole(
            960,
            540,
            fov.to_radians(),
            DVec3::new(0.3, 1.0, 0.2),
            DVec3::Z,
        );
        let map = blackhole::relens::LensMap {
            width: 960,
            height: 540,
            sky: view.iter().map(|v| v.0).collect(),
            magnification: None,
        };
        let start = std::time::Instant::now();
        let px = blackhole::relens::relens(&map, &sky);
        println!(
            "  relens 960 x 540, {fov} degrees across: {:.3} s on {} threads",
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        );
        std::hint::black_box(px);
    }
}

/// The disk's RGBA texture and the spectral set.
fn measure_disk(assets: &Path) {
    let disk = Texture::load(&assets.join("disk_rgba.png")).unwrap();
    let start = std::time::Instant::now();
    disk.build_pyramid();
    println!(
        "disk_rgba.png {} x {}: pyramid built in {:.3} s, {:.2} MiB more (texels {:.1} MiB)",
        disk.width,
        disk.height,
        start.elapsed().as_secs_f64(),
        disk.pyramid_bytes() as f64 / 1048576.0,
        (disk.memory_bytes() - disk.pyramid_bytes()) as f64 / 1048576.0
    );
    let set = blackhole::spectral_texture::SpectralTexture::load(
        &assets.join("disk_spectral/manifest.toml"),
    )
    .unwrap();
    let base = set.memory_bytes();
    let mut texels = Vec::new();
    let start = std::time::Instant::now();
    set.build_pyramid();
    println!(
        "disk_spectral ({} x {}, {} planes and alpha): pyramid built in {:.3} s, {:.2} MiB more (planes {:.1} MiB)",
        set.width,
        set.height,
        set.nm.len(),
        start.elapsed().as_secs_f64(),
        set.pyramid_bytes() as f64 / 1048576.0,
        base as f64 / 1048576.0
    );
    let mut rng = Lcg(2);
    for (what, major) in [("1 texel", 1.0), ("3 texels", 3.0)] {
        let fp = footprint(set.width, set.height, major, 1.0, 0.0);
        let start = std::time::Instant::now();
        let mut count = 0;
        for _ in 0..200_000 {
            set.footprint_texels(rng.next(), rng.next(), &fp, &mut texels);
            count += texels.len();
        }
        println!(
            "  footprint texels, {what}: {:.1} ns, {:.1} texels a lookup (bilinear: 4)",
            start.elapsed().as_secs_f64() / 200_000.0 * 1e9,
            count as f64 / 200_000.0
        );
    }
}
