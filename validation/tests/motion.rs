//! Moving cameras (PHYSICS.md section 8): aberration and the Doppler factor
//! against special relativity's closed forms in flat space, the circular
//! orbit's speed against its closed forms, the static and locally
//! non-rotating frames, and bad motion refused by name.

mod common;

use blackhole::physics::{End, Flow};
use blackhole::spectrum::planck;
use blackhole::spectrum::sampled::Wavelengths;
use common::{SceneText, run, unit_mass};
use glam::DVec3;

/// A camera 1e12 r_s from a hole (whose r_s is 1 m: space is flat to 1e-12)
/// looking away from it along -y with `fov`, moving at `velocity`.
fn far(size: u32, fov: f64, velocity: [f64; 3], extra: &str) -> SceneText {
    SceneText::new(size, size)
        .mass(unit_mass())
        .camera([0.0, -1e12, 0.0], [0.0, -2e12, 0.0], fov)
        .with(&format!(
            "velocity = [{:e}, {:e}, {:e}]",
            velocity[0], velocity[1], velocity[2]
        ))
        .with(extra)
}

/// `far`'s text with the velocity line in the [camera] table.
fn text_of(s: &SceneText) -> String {
    // The first `with` lands after [black_hole]: move it under [camera].
    let t = s.text();
    let line = t
        .lines()
        .find(|l| l.starts_with("velocity"))
        .unwrap()
        .to_string();
    t.replace(&format!("{line}\n"), "")
        .replacen("[camera]\n", &format!("[camera]\n{line}\n"), 1)
}

fn build(s: &SceneText) -> blackhole::scene::Scene {
    common::scene(&text_of(s))
}

#[test]
fn a_moving_camera_sees_the_sky_aberrated_by_the_exact_formula() {
    // Each pixel's ray leaves along the rest-frame direction: cos th =
    // (cos th' - beta) / (1 - beta cos th'), th' the look direction's
    // angle from the velocity, in the plane of both.
    let beta = DVec3::new(0.3, -0.35, 0.1);
    let s = build(&far(
        24,
        100.0,
        beta.to_array(),
        "[sky]\ncolor = [1.0, 1.0, 1.0]",
    ));
    let b = beta.length();
    let vhat = beta / b;
    let mut worst: f64 = 0.0;
    for j in 0..24 {
        for i in 0..24 {
            let (px, py) = (i as f64 + 0.5, j as f64 + 0.5);
            let look = s.camera.local_direction(px, py);
            let (dir, _) = s.camera.ray(px, py);
            let t = s
                .model
                .trace(s.camera.position, dir, &s.limits, |_| Flow::Continue);
            let End::Escaped(d) = t.end else {
                panic!("{:?}", t.end)
            };
            let c1 = look.dot(vhat);
            let want = (c1 - b) / (1.0 - b * c1);
            worst = worst.max((d.dot(vhat) - want).abs());
            // In the plane of the look direction and the velocity.
            worst = worst.max(d.dot(look.cross(vhat).normalize()).abs());
        }
    }
    assert!(worst < 1e-9, "worst {worst:e}");
}

#[test]
fn a_moving_camera_sees_a_blackbody_sky_at_d_t() {
    // A uniform blackbody sky of T seen at 0.5 c: in each direction the
    // blackbody of D T, D = 1 / (gamma (1 - beta cos th')).
    let t_sky = 5800.0;
    let beta = DVec3::new(0.5, 0.0, 0.0);
    let s = build(&far(
        16,
        120.0,
        beta.to_array(),
        &format!("[sky]\nblackbody = {t_sky:e}\n[spectral]\nenabled = true\nwavelengths = 81"),
    ));
    let (film, _) = s.render(&|_| {});
    let wl = Wavelengths::new(81);
    let chroma = |x: DVec3| (x.x / (x.x + x.y + x.z), x.y / (x.x + x.y + x.z));
    let gamma = 1.0 / (1.0f64 - 0.25).sqrt();
    let (mut worst, mut d_lo, mut d_hi) = (0.0f64, f64::MAX, 0.0f64);
    for j in 0..16 {
        for i in 0..16 {
            let look = s.camera.local_direction(i as f64 + 0.5, j as f64 + 0.5);
            let d = 1.0 / (gamma * (1.0 - 0.5 * look.dot(DVec3::X)));
            let b: Vec<f32> = wl.nm.iter().map(|&l| planck(l, d * t_sky) as f32).collect();
            let want = chroma(wl.xyz(&b));
            let got = chroma(film.xyz[(j * 16 + i) as usize].as_dvec3());
            worst = worst
                .max((got.0 - want.0).abs())
                .max((got.1 - want.1).abs());
            (d_lo, d_hi) = (d_lo.min(d), d_hi.max(d));
        }
    }
    eprintln!("D from {d_lo:.3} to {d_hi:.3}: worst xy difference {worst:.2e}");
    assert!(d_hi > 1.3 && d_lo < 0.8);
    assert!(worst < 1e-6, "worst {worst}");
}

#[test]
fn a_circular_orbit_moves_at_its_closed_form_speed() {
    // Schwarzschild, r = 10 r_s: v = sqrt(M / (r - 2M)) = sqrt(1/18)
    // relative to the static observer, along z x r (counter-clockwise).
    let r_s = blackhole::scene::schwarzschild_radius(common::MASS);
    let s = common::scene(
        &SceneText::new(8, 8)
            .camera([10.0 * r_s, 0.0, 0.0], [0.0; 3], 30.0)
            .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
            .text()
            .replacen("[camera]\n", "[camera]\norbit = \"circular\"\n", 1),
    );
    let v = s.camera.velocity;
    assert!((v.length() - (1.0f64 / 18.0).sqrt()).abs() < 1e-12, "{v}");
    assert!(v.normalize().distance(DVec3::Y) < 1e-12, "{v}");
    // Kerr, a = 0.9, r = 6 M on the equator: relative to the locally
    // non-rotating observer v = (Omega - omega) varpi / alpha.
    let k = blackhole::physics::kerr::Kerr::new(0.9);
    let rho = (36.0f64 + 0.81).sqrt() / 2.0;
    let s = common::scene(
        &SceneText::new(8, 8)
            .spin(0.9)
            .camera([rho * r_s, 0.0, 0.0], [0.0; 3], 30.0)
            .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
            .text()
            .replacen("[camera]\n", "[camera]\norbit = \"circular\"\n", 1),
    );
    let z = k.zamo(6.0, std::f64::consts::FRAC_PI_2);
    let want = (k.orbital_angular_velocity(6.0) - z.omega) * z.varpi / z.alpha;
    let v = s.camera.velocity;
    assert!((v.length() - want).abs() < 1e-9, "{} vs {want}", v.length());
    // Counter-clockwise, along the frame's y axis up to the twist of
    // Kerr-Schild's axes near the hole (a ZAMO frame closest to them is
    // turned from Boyer-Lindquist's r, phi by about a / r).
    assert!(v.normalize().distance(DVec3::Y) < 0.05, "{v}");
}

#[test]
fn without_spin_the_static_and_zamo_cameras_see_the_same() {
    let base = SceneText::new(32, 32)
        .with("[sky]\ncolor = [0.5, 0.7, 1.0]")
        .with("[disk]\nradius = 8.0\ninner_radius = 3.0\ntexture = \"TEX\"");
    let tex = common::assets().join("disk_rgba.png");
    let text = base.text().replace("TEX", &tex.display().to_string());
    let a = common::scene(&text.replacen("[camera]\n", "[camera]\nframe = \"static\"\n", 1));
    let b = common::scene(&text.replacen("[camera]\n", "[camera]\nframe = \"zamo\"\n", 1));
    assert_eq!(a.render(&|_| {}).0.xyz, b.render(&|_| {}).0.xyz);
}

#[test]
fn bad_motion_is_refused_by_name_and_nothing_is_written() {
    let r_s = blackhole::scene::schwarzschild_radius(common::MASS);
    let sky = "[sky]\ncolor = [1.0, 1.0, 1.0]";
    // A scene with one more line in its [camera] table.
    let camera_line = |t: SceneText, line: &str| {
        t.with(sky)
            .text()
            .replacen("[camera]\n", &format!("[camera]\n{line}\n"), 1)
    };
    let cases: Vec<(String, &str, &str)> =
        vec![
        (
            camera_line(SceneText::new(8, 8), "velocity = [0.8, 0.7, 0.0]"),
            "camera.velocity",
            "slower than light",
        ),
        (
            camera_line(
                SceneText::new(8, 8).camera([1.3 * r_s, 0.0, 0.0], [0.0; 3], 30.0),
                "orbit = \"circular\"",
            ),
            "camera.orbit",
            "circular orbit",
        ),
        (
            camera_line(
                SceneText::new(8, 8)
                    .spin(0.9)
                    .camera([0.0, -20.0 * r_s, 5.0 * r_s], [0.0; 3], 30.0),
                "orbit = \"circular\"",
            ),
            "camera.orbit",
            "z = 0",
        ),
        (
            camera_line(
                SceneText::new(8, 8)
                    .spin(0.9)
                    .camera([0.95 * r_s, 0.0, 0.0], [0.0, 1.0 * r_s, 0.0], 30.0),
                "frame = \"static\"",
            ),
            "camera.frame",
            "ergosphere",
        ),
        (
            SceneText::new(8, 8)
                .with(sky)
                .with(
                    "[animation]\nframes = 2\nfps = 1.0\nduration = 1.0\ncamera_motion = \"path\"",
                )
                .text(),
            "animation.camera_motion",
            "camera path",
        ),
    ];
    for (text, key, why) in cases {
        let text = text.replace("png = \"unused.png\"", "png = \"out.png\"");
        let dir = common::case(&text);
        let (code, err) = run(dir.path(), &["render", "scene.toml"]);
        assert_ne!(code, 0, "{key}: {err}");
        assert!(err.contains(key) && err.contains(why), "{key}: {err}");
        assert!(
            !dir.path().join("out.png").exists(),
            "{key}: wrote an image"
        );
    }
}

#[test]
fn a_camera_path_moves_the_camera_with_its_own_velocity() {
    // An orbit in the disk's plane at 20 r_s turning 90 degrees in T
    // seconds: coordinate speed w = (pi / 2) 20 r_s / (c T); the static
    // observer there measures w / sqrt(1 - r_s / r) (its clock runs slow,
    // tangential lengths are as in the coordinates), counter-clockwise.
    let r_s = blackhole::scene::schwarzschild_radius(common::MASS);
    let duration = 3000.0;
    let text = SceneText::new(8, 8)
        .with("[sky]\ncolor = [1.0, 1.0, 1.0]")
        .with(&format!(
            "[animation]\nframes = 3\nfps = 1.0\nduration = {duration:e}\ncamera_motion = \"path\"\n\
             [animation.orbit]\nazimuth = [0.0, 90.0]\nelevation = [0.0, 0.0]\ndistance = {:e}",
            20.0 * r_s
        ))
        .text();
    let mut s = common::scene(&text);
    let c = 2.997_924_58e8;
    let w = std::f64::consts::FRAC_PI_2 * 20.0 * r_s / (c * duration);
    for t in [0.0, 1000.0, 2500.0] {
        s.set_time(t).unwrap();
        let v = s.camera.velocity;
        let want = w / (1.0f64 - 1.0 / 20.0).sqrt();
        assert!(
            (v.length() - want).abs() < 1e-7 * want,
            "t {t}: {} vs {want}",
            v.length()
        );
        // Along the orbit: perpendicular to the position, counter-clockwise.
        let x = s.camera.position;
        assert!(v.dot(x).abs() < 1e-6 * v.length() * x.length());
        assert!(x.cross(v).z > 0.0);
    }
    // At rest by default (the camera path's motion not seen).
    let mut rest = common::scene(&text.replace("camera_motion = \"path\"\n", ""));
    rest.set_time(1000.0).unwrap();
    assert_eq!(rest.camera.velocity, DVec3::ZERO);
}
