//! The spinning (Kerr) hole on the CPU against closed-form Kerr results:
//! the shadow's outline against Bardeen's curve, continuity with
//! Schwarzschild as the spin goes to 0, and bad spins refused by name.

mod common;

use blackhole::physics::kerr::Kerr;
use common::{SceneText, delta_e, run, shipped, unit_mass};

/// A far camera at `r_m` (units of M) at inclination `incl` (degrees from
/// the spin axis) looking at the hole of spin `a` over a white sky, with
/// `px_per_m` pixels per M of Bardeen's screen coordinates: the shadow's
/// pixels against the curve's inside, and the mismatches farther than
/// `tol_px` from the curve (counted, and the largest distance).
fn shadow_against_bardeen(a: f64, incl: f64, r_m: f64, px_per_m: f64, size: u32) -> (usize, f64) {
    // With a mass whose r_s is 1 m, metres are r_s = 2M.
    let d = 0.5 * r_m;
    let i = incl.to_radians();
    let pos = [0.0, -d * i.sin(), d * i.cos()];
    // The image's half-height in M at the camera's distance.
    let half = 0.5 * size as f64 / px_per_m;
    let fov = 2.0 * (half / r_m).atan().to_degrees();
    let s = SceneText::new(size, size)
        .mass(unit_mass())
        .spin(a)
        .camera(pos, [0.0; 3], fov)
        .up([0.0, 0.0, 1.0])
        .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
        .build();
    let (film, _) = s.render(&|_| {});
    // The curve: the upper half, mirrored; screen x to the right (+x in
    // space, where the hole's rotation recedes from this camera), y up.
    let k = Kerr::new(a);
    let r_o = k.spheroidal(2.0 * glam::DVec3::from_array(pos)).r;
    let upper = k.shadow_curve(i, 4000);
    let f = s.camera.focal_pixels();
    // Bardeen's (alpha, beta) are angles times r_o.
    let to_px = |(al, be): (f64, f64)| {
        (
            0.5 * size as f64 + f * (al / r_o),
            0.5 * size as f64 - f * (be / r_o),
        )
    };
    let mut poly: Vec<(f64, f64)> = upper.iter().map(|&p| to_px(p)).collect();
    poly.extend(upper.iter().rev().map(|&(al, be)| to_px((al, -be))));
    let inside = |x: f64, y: f64| {
        // Even-odd rule on the closed polygon.
        let mut c = false;
        for j in 0..poly.len() {
            let (a, b) = (poly[j], poly[(j + 1) % poly.len()]);
            if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
                c = !c;
            }
        }
        c
    };
    let dist = |x: f64, y: f64| {
        (0..poly.len())
            .map(|j| {
                let (a, b) = (poly[j], poly[(j + 1) % poly.len()]);
                let (dx, dy) = (b.0 - a.0, b.1 - a.1);
                let t = (((x - a.0) * dx + (y - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
                (x - a.0 - t * dx).hypot(y - a.1 - t * dy)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let (mut off, mut worst) = (0, 0.0f64);
    let mut dark = 0;
    for py in 0..size {
        for px in 0..size {
            let shadow = film.xyz[(py * size + px) as usize].y < 0.5;
            dark += shadow as usize;
            let (x, y) = (px as f64 + 0.5, py as f64 + 0.5);
            if shadow != inside(x, y) {
                off += 1;
                worst = worst.max(dist(x, y));
            }
        }
    }
    assert!(dark > 1000, "a = {a}, {incl} deg: only {dark} dark pixels");
    (off, worst)
}

#[test]
fn the_shadow_is_bardeens_curve_from_a_far_camera() {
    // r = 1e3 M; the curve spans about 10 M across: 6 px per M. Every
    // pixel classified against the curve's inside as its centre lies, but
    // for those within one pixel of the curve (the edge's own pixels).
    for a in [0.5, 0.9, 0.998] {
        for incl in [90.0, 60.0] {
            let (off, worst) = shadow_against_bardeen(a, incl, 1e3, 6.0, 96);
            eprintln!(
                "a = {a}, inclination {incl} deg: {off} edge pixels off, farthest {worst:.3} px from the curve"
            );
            assert!(
                worst < 1.0,
                "a = {a}, {incl} deg: a pixel {worst:.3} px from the curve is misclassified"
            );
        }
    }
}

#[test]
fn a_vanishing_spin_renders_the_schwarzschild_hole() {
    // a = 1e-6 next to a = 0 (which is the Schwarzschild member itself):
    // the disk, the sky and the shadow in one image.
    let base = shipped("quick", 96, 96, &["physics.closed_form=false"]);
    let tiny = shipped(
        "quick",
        96,
        96,
        &["physics.closed_form=false", "black_hole.spin=1e-6"],
    );
    let (a, _) = base.render(&|_| {});
    let (b, _) = tiny.render(&|_| {});
    let (mean, p99, _) = delta_e(&base, &a, &b);
    eprintln!("spin 1e-6 against 0: CIEDE2000 mean {mean:.5}, p99 {p99:.4}");
    assert!(mean < 0.01 && p99 < 0.5, "mean {mean}, p99 {p99}");
}

#[test]
fn bad_spins_are_refused_by_name_and_nothing_is_written() {
    for (set, want) in [
        ("black_hole.spin=1.0", "from -0.9999 to 0.9999"),
        ("black_hole.spin=-1.5", "from -0.9999 to 0.9999"),
        ("black_hole.spin=nan", "from -0.9999 to 0.9999"),
        ("black_hole.spin=0.5", "has no spin"),
    ] {
        let mut text = SceneText::new(16, 16)
            .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
            .text()
            .replace("png = \"unused.png\"", "png = \"out.png\"");
        if set.ends_with("0.5") {
            text.push_str("[physics]\nmodel = \"seed\"\n");
        }
        let dir = common::case(&text);
        let (code, err) = run(dir.path(), &["render", "scene.toml", "--set", set]);
        assert_ne!(code, 0, "{set}: {err}");
        assert!(
            err.contains("black_hole.spin") && err.contains(want),
            "{set}: {err}"
        );
        assert!(
            !dir.path().join("out.png").exists(),
            "{set}: wrote an image"
        );
    }
    // Objects in the ergosphere: named, nothing written.
    let text = SceneText::new(16, 16)
        .spin(0.9)
        .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
        .with(&format!(
            "[[object]]\nkind = \"sphere\"\ncenter = [{:e}, 0.0, 0.0]\nradius = {:e}\nmaterial = {{ kind = \"mirror\" }}",
            1.2 * blackhole::scene::schwarzschild_radius(common::MASS),
            0.3 * blackhole::scene::schwarzschild_radius(common::MASS)
        ))
        .text()
        .replace("png = \"unused.png\"", "png = \"out.png\"");
    let dir = common::case(&text);
    let (code, err) = run(dir.path(), &["render", "scene.toml"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("object.0") && err.contains("ergosphere"),
        "{err}"
    );
    assert!(!dir.path().join("out.png").exists());
    // The GPU refuses a spinning hole by name (before any device opens).
    let text = SceneText::new(16, 16)
        .spin(0.9)
        .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
        .text()
        .replace("png = \"unused.png\"", "png = \"out.png\"");
    let dir = common::case(&text);
    let (code, err) = run(dir.path(), &["render", "scene.toml", "--backend", "gpu"]);
    assert_ne!(code, 0);
    assert!(err.contains("black_hole.spin"), "{err}");
    assert!(!dir.path().join("out.png").exists());
}

#[test]
fn a_face_on_thin_disk_is_page_thorne_at_the_shift_of_every_radius() {
    // a = 0.9, seen down the spin axis from 1000 r_s: every photon has
    // L_z = 0, so each disk pixel shows B(lambda, g T) with g = 1 / (u^t
    // alpha_camera) (Kerr's closed forms, PHYSICS.md section 7) and T
    // Page and Thorne's at the radius its ray crossed the plane (traced
    // here again, its radius checked against the image).
    use blackhole::physics::{Flow, Spacetime};
    use blackhole::spectrum::planck;
    use blackhole::spectrum::sampled::Wavelengths;
    let (a, d, size, outer) = (0.9, 1000.0, 64u32, 12.0);
    let r_s = blackhole::scene::schwarzschild_radius(common::MASS);
    let s = SceneText::new(size, size)
        .spin(a)
        .camera([0.0, 0.0, d * r_s], [0.0; 3], 1.6)
        .up([0.0, 1.0, 0.0])
        .with("[physics]\nmodel = \"gr\"\ntolerance = 1e-10")
        .with(&format!(
            "[disk]\nradius = {outer:e}\nemission = \"thin\"\npeak_temperature = 9000.0"
        ))
        .with("[sky]\ncolor = [0.0, 0.0, 0.0]")
        .with("[spectral]\nenabled = true\ndoppler = true\nbeaming = true")
        .build();
    let thin = s.disk.as_ref().unwrap().thin.clone().unwrap();
    let k = Kerr::new(a);
    // The thin disk starts at the prograde ISCO.
    assert!(
        (thin.inner - 0.5 * k.isco()).abs() < 1e-12,
        "{}",
        thin.inner
    );
    let film = s.render(&|_| {}).0;
    let st = Spacetime::Kerr { a };
    let cam = s.camera.position;
    let z = k.zamo(2.0 * st.radius(cam), 0.0);
    let wl = Wavelengths::new(81);
    let chroma = |xyz: glam::DVec3| {
        let t = xyz.x + xyz.y + xyz.z;
        (xyz.x / t, xyz.y / t)
    };
    let (mut checked, mut worst, mut g_lo, mut g_hi) = (0, 0.0f64, f64::MAX, 0.0f64);
    for j in 0..size {
        for i in 0..size {
            let dir = s.camera.ray_direction(i as f64 + 0.5, j as f64 + 0.5);
            let mut hit = None;
            s.model.trace(cam, dir, &s.limits, |seg| {
                if let Some(t) = seg.crossing_z0() {
                    hit = Some(seg.point(t));
                    return Flow::Stop;
                }
                Flow::Continue
            });
            let Some(p) = hit else { continue };
            let r = st.radius(p);
            if !(r > thin.inner * 1.01 && r < outer * 0.99) {
                continue;
            }
            let g = 1.0 / (k.orbit_ut(2.0 * r) * z.alpha);
            let t = thin.temperature(r);
            let b: Vec<f32> = wl
                .nm
                .iter()
                .map(|&l| (planck(l, g * t) * 1e-9) as f32)
                .collect();
            let want = chroma(wl.xyz(&b));
            let got = chroma(film.xyz[(j * size + i) as usize].as_dvec3());
            worst = worst
                .max((got.0 - want.0).abs())
                .max((got.1 - want.1).abs());
            (g_lo, g_hi) = (g_lo.min(g), g_hi.max(g));
            checked += 1;
        }
    }
    eprintln!("{checked} disk pixels, g {g_lo:.4} to {g_hi:.4}, worst xy difference {worst:.2e}");
    assert!(checked > 1500, "{checked}");
    // Next to the prograde ISCO g goes far below Schwarzschild's least,
    // sqrt(1 - 3M/r) = 0.707 at its ISCO.
    assert!(g_lo < 0.5, "{g_lo}");
    assert!(worst < 2e-4, "worst xy difference {worst}");
}

#[test]
fn rays_traced_back_to_the_horizon_end_captured_not_out_of_steps() {
    // An opaque disk down to the horizon of a = 0.99: rays traced back
    // towards r_+ wind around in Kerr-Schild's chart without crossing it
    // (they come from the past horizon); every one must still end.
    let tex = format!(
        "disk.texture=\"{}\"",
        common::assets().join("sky.png").display()
    );
    let s = shipped(
        "kerr_edge",
        96,
        54,
        &[tex.as_str(), "physics.max_steps=20000"],
    );
    let (_, stats) = s.render(&|_| {});
    assert_eq!(stats.abandoned, 0, "{stats:?}");
    assert!(stats.captured > 0 && stats.disk > 0, "{stats:?}");
}
