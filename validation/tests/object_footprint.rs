//! Footprints at object hits: the derivatives per pixel of an object's
//! texture coordinates where a sample's ray meets it, against the analytic
//! ones in flat space and tight differences near the hole, never across a
//! silhouette; and an object texture filtered over them.

mod common;

use blackhole::cpu::OBJECT_STEP;
use blackhole::scene::Scene;
use blackhole::shapes::{Hit, Shape};
use blackhole::texture::Footprint;
use common::{SceneText, unit_mass};
use glam::{DVec2, DVec3};
use std::path::Path;

/// A scene of unit mass (lengths in r_s) seen by a 64 x 48 camera at
/// `at` looking at `look`, field of view `fov`, with `extra` TOML.
fn scene(model: &str, at: [f64; 3], look: [f64; 3], fov: f64, extra: &str) -> Scene {
    common::scene(
        &SceneText::new(64, 48)
            .mass(unit_mass())
            .camera(at, look, fov)
            .with(&format!(
                "[physics]\nmodel = \"{model}\"\n[sky]\ncolor = [0.0, 0.0, 0.0]\n{extra}"
            ))
            .text(),
    )
}

/// A checkerboard PNG of `n` x `n` cells of `cell` texels, black and white.
fn checkerboard(dir: &Path, n: u32, cell: u32) -> std::path::PathBuf {
    let size = n * cell;
    let img = image::RgbImage::from_fn(size, size, |x, y| {
        let c = if (x / cell + y / cell).is_multiple_of(2) {
            0
        } else {
            255
        };
        image::Rgb([c, c, c])
    });
    let path = dir.join("checker.png");
    img.save(&path).unwrap();
    path
}

/// A textured `[[object]]` rectangle: centre, normal, width axis, size,
/// texture, filter.
fn rectangle(c: [f64; 3], n: [f64; 3], w: [f64; 3], size: [f64; 2], tex: &Path, f: &str) -> String {
    let v = |a: [f64; 3]| format!("[{:e}, {:e}, {:e}]", a[0], a[1], a[2]);
    format!(
        "[[object]]\nkind = \"rectangle\"\ncenter = {}\nnormal = {}\nwidth_axis = {}\n\
         size = [{:e}, {:e}]\nmaterial = {{ kind = \"color\", color = [1.0, 1.0, 1.0], \
         texture = \"{}\", filter = \"{f}\" }}\n",
        v(c),
        v(n),
        v(w),
        size[0],
        size[1],
        tex.display()
    )
}

/// The footprint of the sample at `at` (pixels) where it meets an object,
/// with the object's index.
fn footprint_at(s: &Scene, at: DVec2) -> Option<(usize, Option<Footprint>)> {
    let (i, hit, plane) = s.object_hit(at)?;
    Some((i, s.object_footprint(at, i, &hit, plane)))
}

#[test]
fn a_rectangle_seen_straight_on_has_the_analytic_footprint() {
    // Flat space (1e6 r_s from the hole, looking away): a rectangle facing
    // the camera 100 r_s ahead spans, per pixel, the camera's pixel at
    // that distance, D 2 tan(fov / 2) / height, over its width in u and
    // its height in v, the same at every pixel (a pinhole maps a parallel
    // plane linearly); u grows to the right, v (rows) down the image.
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 8, 4);
    let (d, fov, size) = (100.0, 40.0f64, [120.0, 90.0]);
    for model in ["gr", "seed"] {
        let rect = rectangle(
            [0.0, -1e6 - d, 0.0],
            [0.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            size,
            &tex,
            "footprint",
        );
        let s = scene(model, [0.0, -1e6, 0.0], [0.0, -2e6, 0.0], fov, &rect);
        let pixel = d * 2.0 * (fov.to_radians() / 2.0).tan() / 48.0;
        let want = Footprint::new(pixel / size[0], 0.0, 0.0, pixel / size[1]);
        let mut worst: f64 = 0.0;
        for at in [(32.0, 24.0), (3.3, 5.7), (60.5, 44.2), (17.9, 30.1)] {
            let (_, fp) = footprint_at(&s, DVec2::from(at)).expect("it meets the rectangle");
            let fp = fp.expect("a footprint");
            for (g, w) in [(fp.dx, want.dx), (fp.dy, want.dy)] {
                worst = worst.max((g - w).length() / want.dx.length());
            }
        }
        eprintln!("{model}: straight-on rectangle, worst relative error {worst:.1e}");
        // The hole's pull at 1e6 r_s bends rays by ~1e-6.
        assert!(worst < 1e-4, "{model}: {worst}");
    }
}

/// The texture coordinates of a sphere `shape` at the radial projection
/// of point `q`.
fn sphere_uv(shape: &Shape, q: DVec3) -> DVec2 {
    let Shape::Sphere(sp) = shape else {
        unreachable!()
    };
    let out = sp.center + (q - sp.center).normalize() * (2.0 * sp.radius);
    let h = shape.intersect(out, sp.center).unwrap();
    DVec2::new(h.uv.0, h.uv.1)
}

/// The footprint a ray differential carried straight from the camera to
/// the hit gives (Igehy's transfer to the tangent plane): exact in flat
/// space, blind to the bending.
fn straight_differential(s: &Scene, at: DVec2, i: usize, hit: &Hit) -> Footprint {
    let c = s.camera.position;
    let t = (hit.point - c).length();
    let d = (hit.point - c) / t;
    let dir = |p: DVec2| s.camera.ray(p.x, p.y).0.normalize();
    let shape = &s.objects[i].shape;
    let axis = |e: DVec2| {
        let h = 1e-4;
        let dd = (dir(at + e * h) - dir(at - e * h)) / (2.0 * h);
        let dp = dd * t;
        let dp = dp - d * (dp.dot(hit.normal) / d.dot(hit.normal));
        let k = 1e-6;
        let (a, b) = (
            sphere_uv(shape, hit.point + dp * k),
            sphere_uv(shape, hit.point - dp * k),
        );
        DVec2::new(blackhole::texture::wrap_du(a.x - b.x), a.y - b.y) / (2.0 * k)
    };
    Footprint {
        dx: axis(DVec2::X),
        dy: axis(DVec2::Y),
    }
}

/// Central differences of the sphere's texture coordinates at neighbouring
/// rays `step` pixels away (None where a neighbour misses it).
fn tight(s: &Scene, at: DVec2, step: f64) -> Option<Footprint> {
    let uv = |p: DVec2| s.object_hit(p).map(|(_, h, _)| DVec2::new(h.uv.0, h.uv.1));
    let axis = |e: DVec2| {
        let (a, b) = (uv(at + e * step)?, uv(at - e * step)?);
        Some(DVec2::new(blackhole::texture::wrap_du(a.x - b.x), a.y - b.y) / (2.0 * step))
    };
    Some(Footprint {
        dx: axis(DVec2::X)?,
        dy: axis(DVec2::Y)?,
    })
}

/// The relative difference of two footprints (of the larger's size).
fn rel(a: &Footprint, b: &Footprint) -> f64 {
    let size = |f: &Footprint| f.dx.length().max(f.dy.length());
    ((a.dx - b.dx).length().max((a.dy - b.dy).length())) / size(a).max(size(b))
}

#[test]
fn near_the_hole_the_footprint_agrees_with_tight_differences() {
    // A textured sphere 6 r_s behind the hole and off its axis, seen from
    // 20 r_s: its image is lensed. The footprint from neighbours
    // OBJECT_STEP pixels away against central differences 10 and 100 times
    // tighter, and the straight-line ray differential for scale, with the
    // cost of each footprint.
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 8, 4);
    let ball = format!(
        "[[object]]\nkind = \"sphere\"\ncenter = [2.5, 6.0, 1.0]\nradius = 2.0\n\
         material = {{ kind = \"color\", texture = \"{}\", filter = \"footprint\" }}\n",
        tex.display()
    );
    for model in ["gr", "seed"] {
        let s = scene(model, [0.0, -20.0, 0.0], [0.0; 3], 30.0, &ball);
        let (mut n, mut worst_tight, mut worst_straight, mut seconds) = (0, 0.0f64, 0.0f64, 0.0);
        let (mut worst_10, mut worst_100) = (0.0f64, 0.0f64);
        for py in (1..48).step_by(2) {
            for px in (1..64).step_by(2) {
                let at = DVec2::new(px as f64 + 0.37, py as f64 + 0.61);
                let Some((i, hit, plane)) = s.object_hit(at) else {
                    continue;
                };
                let t0 = std::time::Instant::now();
                let fp = s.object_footprint(at, i, &hit, plane);
                seconds += t0.elapsed().as_secs_f64();
                // Only where every neighbour of every step meets the sphere
                // (away from its edge and the hole's shadow).
                let (Some(fp), Some(t10), Some(t100)) = (
                    fp,
                    tight(&s, at, OBJECT_STEP / 10.0),
                    tight(&s, at, OBJECT_STEP / 100.0),
                ) else {
                    continue;
                };
                if tight(&s, at, 0.5).is_none() {
                    continue;
                }
                n += 1;
                worst_10 = worst_10.max(rel(&fp, &t10));
                worst_100 = worst_100.max(rel(&fp, &t100));
                worst_tight = worst_tight.max(rel(&t10, &t100));
                worst_straight =
                    worst_straight.max(rel(&straight_differential(&s, at, i, &hit), &t10));
            }
        }
        eprintln!(
            "{model}: {n} hits; footprint vs steps /10 {worst_10:.1e}, /100 {worst_100:.1e} \
             (those two apart {worst_tight:.1e}); straight ray differential {worst_straight:.1e}; \
             {:.1} us a footprint",
            seconds / n as f64 * 1e6
        );
        assert!(n >= 50, "{n}");
        assert!(
            worst_10 < 2e-3 && worst_100 < 2e-3,
            "{model}: {worst_10}, {worst_100}"
        );
    }
}

#[test]
fn no_footprint_reaches_across_a_silhouette() {
    // Flat space: a rectangle 100 r_s ahead in front of a wider one 200 r_s
    // ahead, their widths turned apart. Samples ever closer to the front
    // one's right edge, on both sides: each footprint is its own object's
    // analytic one (a plane's texture coordinates are linear in the pixel,
    // so a one-sided difference is exact), never a mixture of the two.
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 8, 4);
    let fov = 40.0f64;
    let unit = 2.0 * (fov.to_radians() / 2.0).tan() / 48.0;
    let front = rectangle(
        [0.0, -1e6 - 100.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [40.0, 30.0],
        &tex,
        "footprint",
    );
    let back = rectangle(
        [0.0, -1e6 - 200.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [300.0, 400.0],
        &tex,
        "footprint",
    );
    let s = scene(
        "gr",
        [0.0, -1e6, 0.0],
        [0.0, -2e6, 0.0],
        fov,
        &(front + &back),
    );
    // u along the front's width (right on the image), rows down; the back
    // one's u runs up the image, its v to the right.
    let want = [
        Footprint::new(100.0 * unit / 40.0, 0.0, 0.0, 100.0 * unit / 30.0),
        Footprint::new(0.0, 200.0 * unit / 400.0, -200.0 * unit / 300.0, 0.0),
    ];
    // The front's right edge: 20 r_s right of the centre at 100 r_s.
    let edge = 32.0 + 20.0 / (100.0 * unit);
    let (mut seen, mut worst) = ([0, 0], 0.0f64);
    for k in -20..=20 {
        let px = edge + k as f64 * 0.1 * OBJECT_STEP;
        for py in [20.3, 24.0, 27.9] {
            let (i, fp) = footprint_at(&s, DVec2::new(px, py)).expect("a rectangle");
            let fp = fp.unwrap_or_else(|| panic!("a footprint at ({px}, {py})"));
            seen[i] += 1;
            let e = rel(&fp, &want[i]);
            worst = worst.max(e);
            assert!(
                e < 1e-4,
                "object {i} at ({px}, {py}): {fp:?} vs {:?}",
                want[i]
            );
        }
    }
    eprintln!(
        "across the silhouette: {seen:?} samples (front, back), worst relative error {worst:.1e}"
    );
    assert!(seen[0] > 30 && seen[1] > 30, "{seen:?}");
}

/// The mean CIEDE2000 at one sample a pixel against 64 samples
/// (bilinear points) of the footprint filter and of bilinear points, with
/// the seconds each one-sample render took.
fn checkerboard_error(s: &dyn Fn(&str, u32) -> Scene) -> [(f64, f64); 2] {
    let reference = s("bilinear", 64);
    let converged = reference.render(&|_| {}).0;
    let error = |filter: &str| {
        let scene = s(filter, 1);
        let t0 = std::time::Instant::now();
        let film = scene.render(&|_| {}).0;
        let seconds = t0.elapsed().as_secs_f64();
        (common::delta_e(&reference, &film, &converged).0, seconds)
    };
    [error("footprint"), error("bilinear")]
}

#[test]
fn one_footprint_sample_is_nearer_the_converged_object_than_one_point() {
    // A checkerboard floor running away from the camera (cells minified
    // to a fraction of a pixel towards its far end) and a checkered sphere
    // near the hole, each at one sample a pixel read over its footprint
    // and at the point, against 64 samples a pixel (bilinear points).
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 64, 4);
    let floor = |filter: &str, samples: u32| {
        common::scene(
            &SceneText::new(64, 48)
                .samples(samples)
                .mass(unit_mass())
                .camera([0.0, -1e6, 0.0], [0.0, -2e6, -2e5], 40.0)
                .with(&format!(
                    "[sky]\ncolor = [0.0, 0.0, 0.0]\n{}",
                    rectangle(
                        [0.0, -1e6 - 155.0, -10.0],
                        [0.0, 0.0, 1.0],
                        [1.0, 0.0, 0.0],
                        [200.0, 300.0],
                        &tex,
                        filter
                    )
                ))
                .text(),
        )
    };
    let ball = |filter: &str, samples: u32| {
        common::scene(
            &SceneText::new(64, 48)
                .samples(samples)
                .mass(unit_mass())
                .camera([0.0, -20.0, 0.0], [0.0; 3], 30.0)
                .with(&format!(
                    "[sky]\ncolor = [0.0, 0.0, 0.0]\n[[object]]\nkind = \"sphere\"\n\
                     center = [2.5, 6.0, 1.0]\nradius = 2.0\nmaterial = {{ kind = \"color\", \
                     color = [1.0, 1.0, 1.0], texture = \"{}\", filter = \"{filter}\" }}",
                    tex.display()
                ))
                .text(),
        )
    };
    for (name, view) in [
        ("floor", &floor as &dyn Fn(&str, u32) -> Scene),
        ("sphere", &ball),
    ] {
        let [(footprint, t_fp), (point, t_point)] = checkerboard_error(view);
        eprintln!(
            "{name}: mean CIEDE2000 to 64 samples: footprint {footprint:.3}, bilinear point \
             {point:.3} ({t_fp:.3} s and {t_point:.3} s at one sample)"
        );
        assert!(footprint < 0.7 * point, "{name}: {footprint} vs {point}");
    }
}

#[test]
fn object_filters_default_to_footprints_and_the_gpu_takes_them() {
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 8, 4);
    let with = |material: &str| {
        scene(
            "gr",
            [0.0, -1e6, 0.0],
            [0.0, -2e6, 0.0],
            40.0,
            &format!(
                "[[object]]\nkind = \"sphere\"\ncenter = [0.0, -1000100.0, 0.0]\n\
                 radius = 10.0\nmaterial = {{ kind = \"color\"{material} }}\n"
            ),
        )
    };
    let texture = format!(", texture = \"{}\"", tex.display());
    let s = with(&texture);
    assert_eq!(
        s.objects[0].material.filter,
        blackhole::config::Filter::Footprint
    );
    assert!(s.object_footprints);
    // The GPU traces them too (src/gpu/objfoot.wgsl; compared with the
    // CPU's in validation/tests/gpu.rs).
    assert!(blackhole::gpu::check_supported(&s).is_ok());
    let s = with(&format!("{texture}, filter = \"bilinear\""));
    assert!(!s.object_footprints);
    assert!(blackhole::gpu::check_supported(&s).is_ok());
    // Without a texture there is nothing to filter.
    let s = with("");
    assert!(!s.object_footprints && blackhole::gpu::check_supported(&s).is_ok());
}

#[test]
fn an_object_seen_in_a_mirror_is_read_at_the_point() {
    // Flat space: the camera sees a textured rectangle only in a mirror
    // facing it; the reflected ray has left the camera's geodesic, so it
    // has no footprint (nor would the camera's neighbours, which meet the
    // mirror) and "footprint" reads as bilinear, byte for byte.
    let dir = tempfile::tempdir().unwrap();
    let tex = checkerboard(dir.path(), 64, 4);
    let view = |filter: &str| {
        let mirror = "[[object]]\nkind = \"rectangle\"\ncenter = [0.0, -1000100.0, 0.0]\n\
                      normal = [0.0, 1.0, 0.0]\nsize = [400.0, 400.0]\n\
                      material = { kind = \"mirror\", color = [1.0, 1.0, 1.0] }\n";
        let behind = rectangle(
            [0.0, -1e6 + 50.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 0.0],
            [200.0, 200.0],
            &tex,
            filter,
        );
        let s = scene(
            "gr",
            [0.0, -1e6, 0.0],
            [0.0, -2e6, 0.0],
            40.0,
            &format!("{mirror}{behind}"),
        );
        s.render(&|_| {}).0.linear_srgb()
    };
    let (point, footprint) = (view("bilinear"), view("footprint"));
    assert!(point.iter().any(|c| c.x > 0.5) && point.iter().any(|c| c.x < 0.1));
    assert_eq!(point, footprint);
}
