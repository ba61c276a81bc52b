//! Radiative transfer in physical units against what is known outside the
//! code: Gold et al. 2020's published fluxes of the five analytic tests,
//! and the closed form of an optically thick shell at rest deep in the
//! potential, I_nu(nu) = g^3 S(nu / g).

mod common;
#[path = "grmhd.rs"]
mod grmhd;

use blackhole::scene::Scene;
use blackhole::transfer::gold::TEST_FLUX_JY;
use std::f64::consts::PI;

/// The hole of Gold et al.'s set-up (ipole's `tests/analytic/analytic.par`):
/// 4.063e6 solar masses, its G M / c^2 (m).
const GOLD_MASS: f64 = 8.079_154e36;
const GOLD_M_METRES: f64 = 5.999_439e9;

/// An observed scene of `pixels` square over `fov` degrees, the camera
/// at `position` (m) looking at a hole of Gold's mass, `tables` after its
/// mass (a spin, the sky, the sources), observed from `distance` pc at
/// `frequency` (a TOML value).
fn observed(
    (pixels, fov): (u32, f64),
    position: [f64; 3],
    tables: &str,
    (distance, frequency): (f64, &str),
) -> String {
    let [x, y, z] = position;
    format!(
        r#"
[image]
width = {pixels}
height = {pixels}
png = "unused.png"
[camera]
position = [{x:e}, {y:e}, {z:e}]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov = {fov}
[black_hole]
mass = {GOLD_MASS:e}
{tables}[observe]
distance = {distance:?}
frequency = {frequency}
"#
    )
}

/// Gold et al.'s test `n` at their set-up: the camera at 1000 M and 60
/// degrees from the spin axis, a 30 M x 30 M field of 128 x 128 pixels,
/// 230 GHz, 7778 pc.
fn gold(n: usize, pixels: u32) -> String {
    let r = 1000.0 * GOLD_M_METRES;
    let (s, c) = 60f64.to_radians().sin_cos();
    let spin = if n == 2 { 0.0 } else { 0.9 };
    observed(
        (pixels, (30.0f64 / 1000.0).to_degrees()),
        [r * s, 0.0, r * c],
        &format!(
            "spin = {spin}\n[sky]\ncolor = [0.0, 0.0, 0.0]\n[medium]\nkind = \"gold2020\"\ntest = {n}\n"
        ),
        (7778.0, "230e9"),
    )
}

fn flux(scene: &Scene) -> Vec<f64> {
    let (film, _) = scene.render(&|_| {});
    film.total_flux()
}

/// The closed-form fluxes (Jy) of Gold's five tests in REFERENCE.md
/// section 19's table (`validation/transfer_table.sh`'s output).
fn documented_gold_fluxes() -> Vec<f64> {
    let text = std::fs::read_to_string(common::root().join("validation/REFERENCE.md")).unwrap();
    let header = "| test | published (Jy) | ours, closed form (Jy) |";
    let at = text
        .find(header)
        .expect("REFERENCE.md holds the table of Gold's tests");
    text[at..]
        .lines()
        .skip(2)
        .take(5)
        .map(|row| {
            let cell = row.split('|').nth(3).unwrap().trim();
            cell.split_whitespace().next().unwrap().parse().unwrap()
        })
        .collect()
}

#[test]
fn the_gold_2020_tests_land_on_the_published_fluxes() {
    // The codes of the comparison land 0.4% to 2.4% from the published
    // values; ipole, built and run here at this very set-up (commit
    // cbbc370), lands +0.68%, +0.98%, +1.58%, +1.16% and +1.60%. Ours,
    // rays in closed form (the default), converged in pixels (256 x 256
    // moves them by under 2.3e-4), in the rays (the integrator lands
    // within 7e-6) and in the pieces (4e-6), land +0.7% to +1.2%: the
    // published values' own set-up differs by that much from the one both
    // codes follow (REFERENCE.md section 19). The bounds: 1.5% of the
    // published values, and 1% of ipole's. And REFERENCE.md's table says
    // what the binary gives, to its six digits: rerun
    // validation/transfer_table.sh when these move.
    let ipole = [1.65763, 1.45007, 0.448791, 0.274148, 0.0259092];
    let documented = documented_gold_fluxes();
    for n in 1..=5 {
        let spin = if n == 2 { "0" } else { "0.9" };
        let scene = common::shipped(
            "gold2020",
            128,
            128,
            &[
                &format!("medium.test={n}"),
                &format!("black_hole.spin={spin}"),
            ],
        );
        let f = flux(&scene)[0];
        let published = TEST_FLUX_JY[n - 1];
        let off = f / published - 1.0;
        println!("test {n}: {f:.6} Jy, {:+.3}% from {published}", 100.0 * off);
        assert!(off.abs() < 0.015, "test {n}: {f} Jy against {published}");
        assert!(
            (f / ipole[n - 1] - 1.0).abs() < 0.01,
            "test {n}: {f} Jy against ipole's {}",
            ipole[n - 1]
        );
        let doc = documented[n - 1];
        assert!(
            (f - doc).abs() <= 5.01e-6 * doc,
            "test {n}: the binary gives {f} Jy, REFERENCE.md says {doc}: rerun validation/transfer_table.sh"
        );
    }
}

#[test]
fn several_frequencies_scale_as_the_emission_law() {
    // Test 1 (alpha = -3, no absorption): j_nu / nu^3 is the same at every
    // frequency, so the flux scales as (nu / nu_p)^3 exactly.
    let text = gold(1, 32).replace("frequency = 230e9", "frequency = [230e9, 115e9, 460e9]");
    let f = flux(&common::scene(&text));
    assert!(
        (f[1] / f[0] - 0.125).abs() < 1e-12 && (f[2] / f[0] - 8.0).abs() < 1e-11,
        "{f:?}"
    );
}

#[test]
fn a_thick_shell_at_rest_shows_its_source_function_redshifted() {
    // A shell at rest around a Schwarzschild hole, so thick (tau = 1e4 in
    // 1e-3 M) that a ray sees its surface at r_e = 6.5 M: I_nu(nu) =
    // g^3 S(nu / g) = g^(3 + alpha) S(nu), g = sqrt(1 - 2/r_e) /
    // sqrt(1 - 2/r_cam) between it and a static camera.
    let r_cam: f64 = 1000.0;
    let text = static_view(
        (4, 0.2, r_cam),
        "[230e9, 690e9]",
        "[sky]\ncolor = [0.0, 0.0, 0.0]\n[medium]\nkind = \"uniform\"\ninner = 6.0\nouter = 6.5\nemission = 3e-12\nabsorption = 1e-2\nalpha = 1.0\nnu_p = 230e9\n",
    );
    let scene = common::scene(&text);
    let (film, _) = scene.render(&|_| {});
    let g = (1.0 - 2.0 / 6.5f64).sqrt() / (1.0 - 2.0 / r_cam).sqrt();
    let spectra = film.spectra.as_ref().expect("fluxes kept");
    let d_cm = 8000.0 * blackhole::units::cgs::PARSEC;
    for py in 0..4 {
        for px in 0..4 {
            let sr = seen_from(&scene, d_cm, px, py);
            for (k, nu) in [230e9, 690e9].into_iter().enumerate() {
                let s = 3e-12 / 1e-2 * (nu / 230e9f64).powi(-1);
                let want = g.powi(4) * s * sr / 1e-23;
                let got = spectra[(py * 4 + px) * 2 + k] as f64;
                assert!(
                    (got / want - 1.0).abs() < 1e-4,
                    "pixel ({px}, {py}) at {nu} Hz: {got} Jy against {want}"
                );
            }
        }
    }
}

/// A static camera `r` M from a hole of Gold's mass (without spin), on the
/// -y axis looking at it over `fov` degrees with `pixels` square, observed
/// from 8000 pc at `frequencies` (a TOML list), and the scene's `tables`.
fn static_view((pixels, fov, r): (u32, f64, f64), frequencies: &str, tables: &str) -> String {
    observed(
        (pixels, fov),
        [0.0, -r * GOLD_M_METRES, 0.0],
        tables,
        (8000.0, frequencies),
    )
}

/// `render` of `text` in a scratch folder: exit code, stderr, and the
/// folder.
fn render_cli(text: &str) -> (i32, String, tempfile::TempDir) {
    let dir = common::case(text);
    let (code, err) = common::run(dir.path(), &["render", "scene.toml"]);
    (code, err, dir)
}

#[test]
fn bad_media_and_observations_are_refused_by_name_with_nothing_written() {
    let base = gold(3, 8);
    for (from, to, named) in [
        ("test = 3", "test = 3\nn0 = -1e-18", "medium.n0"),
        ("test = 3", "test = 3\nA = -2.0", "medium.A"),
        ("frequency = 230e9", "frequency = nan", "observe.frequency"),
        (
            "frequency = 230e9",
            "frequency = [230e9, inf]",
            "observe.frequency",
        ),
        ("frequency = 230e9", "frequency = -1e9", "observe.frequency"),
        ("distance = 7778.0", "distance = 0.0", "observe.distance"),
        // Earth beyond the camera, within the observable universe.
        ("distance = 7778.0", "distance = 1e-30", "observe.distance"),
        ("distance = 7778.0", "distance = 1e30", "observe.distance"),
        (
            "distance = 7778.0",
            "distance = \"8 parsec\"",
            "observe.distance",
        ),
        (
            "frequency = 230e9",
            "frequency = \"230 Ghz\"",
            "observe.frequency",
        ),
        // Each frequency is a channel of its own (jy.230GHz).
        (
            "frequency = 230e9",
            "frequency = [230e9, 230e9]",
            "observe.frequency",
        ),
        (
            "frequency = 230e9",
            "frequency = [230e9, 230.0000001e9]",
            "observe.frequency",
        ),
        ("test = 3", "test = 6", "medium.test"),
        // A value of the wrong type is named at its key, not at the
        // table's header (serde reads a tagged table whole).
        (
            "test = 3",
            "A = \"NaN\"\nalpha = 0.0\nh = 1.0\nl0 = 1.0",
            "medium.A: invalid type",
        ),
        (
            "kind = \"gold2020\"\ntest = 3",
            "kind = \"synchrotron\"\ndensity = \"dense\"\ntemperature = 1e11",
            "medium.density: invalid type",
        ),
        ("spin = 0.9", "spin = 0.5", "black_hole.spin"),
        (
            "[observe]\ndistance = 7778.0\nfrequency = 230e9\n",
            "",
            "observe",
        ),
        (
            "kind = \"gold2020\"",
            "kind = \"gold2020\"\ncolour = 1",
            "colour",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let (code, err, dir) = render_cli(&base.replace(from, to));
        assert_eq!(code, 1, "{to}: {err}");
        assert!(err.contains(named), "{to}: {err}");
        let written: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(written.len(), 1, "{to}: wrote more than the scene file");
    }
    // An observed scene's disk is the thin disk, its light unmodulated.
    let thin = "[disk]\nemission = \"thin\"\nradius = 10.0\npeak_temperature = 1e10\n";
    for (disk, named) in [
        (thin.replace("thin", "texture"), "disk.emission"),
        (format!("{thin}texture = \"disk.png\"\n"), "disk.texture"),
        (format!("{thin}intensity = 2.0\n"), "disk.intensity"),
    ] {
        let (code, err, dir) = render_cli(&format!("{base}{disk}"));
        assert_eq!(code, 1, "{disk}: {err}");
        assert!(err.contains(named), "{disk}: {err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "{disk}");
    }
    // An observed scene's sky is dark or a blackbody in physical units.
    for (from, to, named) in [
        (
            "color = [0.0, 0.0, 0.0]",
            "color = [0.1, 0.1, 0.1]",
            "sky.color",
        ),
        (
            "color = [0.0, 0.0, 0.0]",
            "texture = \"sky.png\"",
            "sky.texture",
        ),
        (
            "color = [0.0, 0.0, 0.0]",
            "blackbody = 2.7255\nintensity = 2.0",
            "sky.intensity",
        ),
    ] {
        let (code, err, dir) = render_cli(&base.replace(from, to));
        assert_eq!(code, 1, "{to}: {err}");
        assert!(err.contains(named), "{to}: {err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "{to}");
    }
    // An observed volume is the scene's one medium, shining by Planck's
    // function (no luminance of its own), and still.
    let volume = "[volume]\nouter = 20.0\nthickness = 1.0\n";
    let without_medium = base.replace("[medium]\nkind = \"gold2020\"\ntest = 3\n", "");
    for (text, named) in [
        (format!("{base}{volume}"), "volume"),
        (
            format!("{without_medium}{volume}emission = 2.0\n"),
            "volume.emission",
        ),
        (
            format!("{without_medium}{volume}[animation]\nframes = 2\nfps = 24.0\n"),
            "animation",
        ),
    ] {
        let (code, err, dir) = render_cli(&text);
        assert_eq!(code, 1, "{text}: {err}");
        assert!(err.contains(named), "{text}: {err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "{text}");
    }
    // A uniform shell inside the horizon cannot be at rest.
    let shell = base.replace(
        "kind = \"gold2020\"\ntest = 3",
        "kind = \"uniform\"\ninner = 1.2\nouter = 3.0\nemission = 1e-17",
    );
    let (code, err, dir) = render_cli(&shell);
    assert!(code == 1 && err.contains("medium.inner"), "{err}");
    assert!(!dir.path().join("unused.png").exists());
    // Thermal synchrotron: densities and temperatures are positive, the
    // motion a blend between 0 and 1, the gas outside the horizon.
    let flow = "kind = \"synchrotron\"\ndensity = 1e6\ntemperature = 1e11";
    for (extra, named) in [
        ("density = -1e6", "medium.density"),
        ("temperature = -5.0", "medium.temperature"),
        ("temperature = nan", "medium.temperature"),
        ("beta = 0.0", "medium.beta"),
        ("keplerian = 1.5", "medium.keplerian"),
        ("outer = 1.0", "medium.outer"),
        ("density_index = inf", "medium.density_index"),
        ("pressure = 3.0", "pressure"),
    ] {
        let key = extra.split(" =").next().unwrap();
        let lines: Vec<&str> = flow.lines().filter(|l| !l.starts_with(key)).collect();
        let text = base.replace(
            "kind = \"gold2020\"\ntest = 3",
            &format!("{}\n{extra}", lines.join("\n")),
        );
        let (code, err, dir) = render_cli(&text);
        assert_eq!(code, 1, "{extra}: {err}");
        assert!(err.contains(named), "{extra}: {err}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "{extra}");
    }
}

/// The total flux of `scene` at its first frequency, or a failure if the
/// render takes more than a minute (a loop that stops advancing).
fn flux_within_a_minute(scene: Scene) -> f64 {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(flux(&scene)[0]));
    rx.recv_timeout(std::time::Duration::from_secs(60))
        .expect("the render never finished")
}

#[test]
fn media_reaching_far_out_render_in_a_moment() {
    // Sgr A*'s flow out to 1e16 M (Kerr's closed form, and the
    // integrator) and a uniform shell from 3 to 1e16 M about a hole
    // without spin (Schwarzschild's closed form): the closed forms' steps
    // in Mino time and in sweep stopped advancing past about 1e15 M, and
    // the renders never finished. Far out the rays are walked as straight
    // lines; the flow's gas beyond 1e15 M adds nothing (its density and
    // temperature fall as r^-1.1 and r^-0.84), and the shell's light is
    // finite and grows with its thickness (the camera looks away from the
    // hole, out through the shell).
    let sgra = |outer: &str, closed: &str| {
        common::shipped(
            "sgra",
            4,
            4,
            &[
                &format!("medium.outer={outer}"),
                &format!("physics.closed_form={closed}"),
            ],
        )
    };
    let near = flux_within_a_minute(sgra("1e15", "true"));
    for closed in ["true", "false"] {
        let far = flux_within_a_minute(sgra("1e16", closed));
        close(
            &format!("Sgr A* to 1e16 M, closed form {closed}"),
            far,
            near,
            1e-4,
        );
    }
    let shell = |outer: &str| {
        let text = static_view(
            (4, 0.01, 1000.0),
            "230e9",
            "[sky]\ncolor = [0.0, 0.0, 0.0]\n",
        ) + &format!(
            "[medium]\nkind = \"uniform\"\ninner = 3.0\nouter = {outer}\nemission = 1e-30\n"
        );
        let away = text.replace(
            "look_at = [0.0, 0.0, 0.0]",
            &format!("look_at = [0.0, {:e}, 0.0]", -2000.0 * GOLD_M_METRES),
        );
        flux_within_a_minute(common::scene(&away))
    };
    // j is constant: the light grows as the path from the camera at 1000
    // M, to 1e16 M against 1e6 M.
    let (thin, thick) = (shell("1e6"), shell("1e16"));
    let ratio = (1e16 - 1e3) / (1e6 - 1e3);
    close(
        "a shell to 1e16 M over one to 1e6 M",
        thick / thin,
        ratio,
        1e-4,
    );
}

#[test]
fn units_are_taken_as_radio_astronomers_write_them() {
    // "230 GHz" and "7.778 kpc" are 230e9 Hz and 7778 pc, in the file and
    // on the command line; bare numbers that read as another unit was
    // meant are said; the closing line gives the frequency in a unit that
    // suits it and calls samples hidden by the gas the gas's.
    let base = gold(3, 8);
    let (code, err, _dir) = render_cli(&base);
    assert_eq!(code, 0, "{err}");
    let total = |err: &str| {
        err.split("total flux ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .to_string()
    };
    let bare = total(&err);
    assert!(err.contains("Jy at 230 GHz"), "{err}");
    let written = base
        .replace("frequency = 230e9", "frequency = \"230 GHz\"")
        .replace("distance = 7778.0", "distance = \"7.778 kpc\"");
    let (code, err, _dir) = render_cli(&written);
    assert_eq!(code, 0, "{err}");
    assert_eq!(total(&err), bare, "{err}");
    assert!(!err.contains("warning"), "{err}");
    let dir = common::case(&base);
    let (code, err) = common::run(
        dir.path(),
        &[
            "render",
            "scene.toml",
            "--set",
            "observe.frequency=230GHz",
            "--set",
            "observe.distance=\"7.778 kpc\"",
        ],
    );
    assert!(code == 0 && total(&err) == bare, "{err}");
    // A bare 230 is 230 Hz, a bare 8.178 is 8.178 pc: rendered, and said.
    for (from, to, said) in [
        (
            "frequency = 230e9",
            "frequency = 230",
            "observe.frequency = 230: a bare number is in Hz",
        ),
        (
            "distance = 7778.0",
            "distance = 8.178",
            "observe.distance = 8.178: a bare number is in parsecs",
        ),
    ] {
        let (code, err, _dir) = render_cli(&base.replace(from, to));
        assert_eq!(code, 0, "{err}");
        assert!(err.contains(said), "{to}: {err}");
    }
    // At 230 Hz test 4's absorbing flow is opaque: every sample is the
    // gas's.
    let (_, err, _dir) = render_cli(&gold(4, 8).replace("frequency = 230e9", "frequency = 230"));
    assert!(
        err.contains("100.0% opaque gas") && err.contains("at 230 Hz"),
        "{err}"
    );
    let (_, err, _dir) = render_cli(&base.replace("frequency = 230e9", "frequency = 1e15"));
    assert!(err.contains("Jy at 1 PHz"), "{err}");
}

#[test]
fn a_render_writes_the_spectrum_and_names_the_total_on_its_closing_line() {
    let text = gold(1, 16).replace("frequency = 230e9", "frequency = [230e9, 460e9]");
    let (code, said, dir) = render_cli(&text);
    assert_eq!(code, 0, "{said}");
    let csv = std::fs::read_to_string(dir.path().join("unused.spectrum.csv")).unwrap();
    let rows: Vec<(f64, f64)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let (f, jy) = l.split_once(',').unwrap();
            (f.parse().unwrap(), jy.parse().unwrap())
        })
        .collect();
    assert!(csv.starts_with("frequency_hz,flux_jy\n"), "{csv}");
    assert_eq!((rows[0].0, rows[1].0), (230e9, 460e9));
    // alpha = -3 without absorption: the flux goes as nu^3.
    assert!((rows[1].1 / rows[0].1 - 8.0).abs() < 1e-9, "{rows:?}");
    let line = said
        .lines()
        .find(|l| l.contains("total flux"))
        .expect("closing line");
    let jy: f64 = line
        .split("total flux ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .expect("a number of janskys");
    assert!(
        (jy / rows[0].1 - 1.0).abs() < 1e-5,
        "{line} against {rows:?}"
    );
    assert!(line.contains("unused.spectrum.csv"), "{line}");
    // The EXR's header says what its flux channels are: Jy per pixel of
    // 30 M at 1000 M seen from 7778 pc over 16 rows (M is 5.1561 uas),
    // the distance, the frequencies.
    let with_exr = gold(1, 16).replace(
        "png = \"unused.png\"",
        "png = \"unused.png\"\nexr = \"unused.exr\"",
    );
    let (code, said, dir) = render_cli(&with_exr);
    assert_eq!(code, 0, "{said}");
    let tag = |k: &str| {
        blackhole::output::exr_tag(&dir.path().join("unused.exr"), k)
            .unwrap()
            .unwrap_or_else(|| panic!("no {k}"))
    };
    assert_eq!(tag("observe.unit"), "Jy/pixel");
    let uas: f64 = tag("observe.pixel_uas").parse().unwrap();
    assert!((uas / (30.0 / 16.0 * 5.1561) - 1.0).abs() < 1e-4, "{uas}");
    assert_eq!(tag("observe.distance_pc").parse::<f64>().unwrap(), 7778.0);
    assert_eq!(tag("observe.frequencies_hz"), "2.3e11");
}

#[test]
fn tiles_of_an_observed_scene_merge_into_the_whole_render_byte_for_byte() {
    let text = gold(3, 24).replace("png = \"unused.png\"", "png = \"g.png\"\nexr = \"g.exr\"");
    let tiled = common::case(&text);
    for tile in ["0/3", "1/3", "2/3"] {
        let (code, err) = common::run(
            tiled.path(),
            &["render", "-q", "scene.toml", "--tile", tile],
        );
        assert_eq!(code, 0, "{err}");
    }
    let (code, err) = common::run(tiled.path(), &["merge", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    let whole = common::case(&text);
    let (code, err) = common::run(whole.path(), &["render", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    for f in ["g.png", "g.exr", "g.spectrum.csv"] {
        let a = std::fs::read(tiled.path().join(f)).unwrap();
        let b = std::fs::read(whole.path().join(f)).unwrap();
        assert!(
            a == b,
            "{f} differs between the merged tiles and the whole render"
        );
    }
}

/// A shipped RIAF scene at `pixels` square, one sample a pixel: its total
/// flux density (Jy) at each frequency and its ring's diameter (micro-
/// arcseconds) at the first.
fn riaf(name: &str, pixels: u32, extra: &[&str]) -> (Vec<f64>, f64) {
    let scene = common::shipped(name, pixels, pixels, extra);
    let (film, _) = scene.render(&|_| {});
    let observe = scene.observe.as_ref().expect("an observed scene");
    let c = 0.5 * pixels as f64;
    let pixel_rad = scene.camera.pixel_solid_angle(c, c).sqrt() * scene.camera_distance_cm()
        / observe.distance_cm;
    let ring = film.ring().expect("a ring");
    let diameter = blackhole::transfer::micro_arcseconds(ring.diameter * pixel_rad);
    (film.total_flux(), diameter)
}

#[test]
fn the_sgr_a_and_m87_flows_show_the_rings_the_eht_measured() {
    // The shipped RIAF scenes' density and temperature scales were chosen
    // for the total flux the EHT measured at 230 GHz (Sgr A*: 2.4 Jy, M87*:
    // about 0.6 Jy in the compact ring); their rings' diameters follow from
    // the hole's mass and distance and the light's paths alone, and must
    // land within the EHT's published uncertainties: 51.8 +- 2.3 uas (Sgr
    // A*, 2022) and 42 +- 3 uas (M87*, 2019). Measured: 52.6 and 39.6
    // uas; a thin flow's ring is its photon ring, 10.3 to 10.5 G M / (c^2
    // D) across, where the EHT's images have 11 (its mass of M87* was
    // calibrated on simulations with that ratio).
    for (name, jy, (ring, tol)) in [("sgra", 2.4, (51.8, 2.3)), ("m87", 0.6, (42.0, 3.0))] {
        let (flux, d) = riaf(name, 128, &[]);
        println!("{name}: {:.4} Jy, ring {d:.2} uas", flux[0]);
        assert!((flux[0] / jy - 1.0).abs() < 0.15, "{name}: {} Jy", flux[0]);
        assert!(
            (d - ring).abs() < tol,
            "{name}: ring {d} uas against {ring} +- {tol}"
        );
    }
}

#[test]
fn the_flows_spectrum_is_self_absorbed_below_its_peak_and_thin_above() {
    // Thermal synchrotron from a flow whose density and temperature fall
    // outwards. Optically thin, its spectrum could rise no faster than
    // nu^0.334: the steepest log slope of the fit's angle average (at X ~
    // 1e-4; of one electron population, and so of any sum of them however
    // shifted). Below its peak it rises faster, as only absorption makes
    // it (a thick photosphere, B_nu ~ nu^2 k T); above it falls ever
    // faster, as the thin emission's exp(-X^1/3). The peak lies in the
    // submillimetre, as Sgr A*'s.
    let nu: [f64; 7] = [1e10, 3e10, 1e11, 2.3e11, 1e12, 3e12, 1e13];
    let list = format!(
        "observe.frequency=[{}]",
        nu.map(|f| format!("{f:e}")).join(", ")
    );
    let (flux, _) = riaf("sgra", 48, &[&list]);
    println!("{flux:?}");
    let peak = (0..nu.len())
        .max_by(|&a, &b| flux[a].total_cmp(&flux[b]))
        .unwrap();
    assert!(
        nu[peak] > 5e10 && nu[peak] < 1e12,
        "peak at {} Hz: {flux:?}",
        nu[peak]
    );
    let index = |a: usize, b: usize| (flux[b] / flux[a]).ln() / (nu[b] / nu[a]).ln();
    assert!(peak >= 2, "{flux:?}");
    for (k, f) in nu.iter().enumerate().take(peak - 1) {
        let s = index(k, k + 1);
        assert!(s > 0.34, "index {s} from {f} Hz: {flux:?}");
    }
    let (s1, s2) = (index(4, 5), index(5, 6));
    assert!(
        s1 < -1.0 && s2 < s1,
        "thin indices {s1} then {s2}: {flux:?}"
    );
}

#[test]
fn the_gpu_transfers_as_the_cpu_does() {
    let Some(gpu) = common::gpu() else { return };
    // f32 on the GPU against the CPU's f64, both in closed form (Kerr's
    // stretches, Schwarzschild's segments): Gold et al.'s five tests at 64
    // x 64 (-2.2e-6 to +1.9e-7; integrated in f32 on the GPU they were
    // -1.4e-4 to +2.4e-4), and the RIAF of Sgr A* at three frequencies,
    // from self-absorbed to thin (-2.0e-6 to +4.9e-5; integrated on both,
    // -6.6e-5 to +5.0e-4).
    let gpu_flux = |scene: &Scene| -> Vec<f64> {
        let p = gpu.prepare(scene, u32::MAX).unwrap();
        let (film, stats) = p.render(&|_| {}).unwrap();
        // f32 loses a few rays that graze the photon sphere (out of
        // steps); none gives a number that is not one.
        assert!(
            stats.abandoned * 200 <= stats.samples && stats.non_finite == 0,
            "{stats:?}"
        );
        film.total_flux()
    };
    let parity = |label: &str, c: f64, g: f64, tol: f64| close(&format!("{label}, GPU"), g, c, tol);
    for n in 1..=5 {
        let scene = common::scene(&gold(n, 64));
        let (c, g) = (flux(&scene)[0], gpu_flux(&scene)[0]);
        parity(&format!("test {n}"), c, g, 5e-5);
        assert!(
            (g / TEST_FLUX_JY[n - 1] - 1.0).abs() < 0.015,
            "test {n}: {g}"
        );
    }
    // A thin disk inside test 4's absorbing flow, seen through it at 230
    // GHz and nearly hidden at 86 GHz (measured -4.0e-7 and +7.5e-7).
    let text = gold(4, 64).replace("frequency = 230e9", "frequency = [230e9, 86e9]")
        + "[disk]\nemission = \"thin\"\nradius = 10.0\npeak_temperature = 3e10\n";
    let scene = common::scene(&text);
    let (c, g) = (flux(&scene), gpu_flux(&scene));
    for (k, (c, g)) in c.iter().zip(&g).enumerate() {
        parity(
            &format!("test 4 with a thin disk, frequency {k}"),
            *c,
            *g,
            5e-5,
        );
    }
    // The volumetric disk's gas, thick, at four frequencies (measured
    // -5.9e-6 to +2.3e-7).
    let scene = common::scene(&far_volume(1.0, 48));
    let (c, g) = (flux(&scene), gpu_flux(&scene));
    for (k, (c, g)) in c.iter().zip(&g).enumerate() {
        parity(&format!("the volume, frequency {k}"), *c, *g, 5e-4);
    }
    // The thin disk far out before a blackbody sky at 3000 K (measured
    // -5.4e-6 to +1.9e-8).
    let scene =
        common::scene(&far_disk(0.0, 32).replace("color = [0.0, 0.0, 0.0]", "blackbody = 3000.0"));
    let (c, g) = (flux(&scene), gpu_flux(&scene));
    for (k, (c, g)) in c.iter().zip(&g).enumerate() {
        parity(
            &format!("a disk before a blackbody sky, frequency {k}"),
            *c,
            *g,
            5e-4,
        );
    }
    // The RIAF's rays in closed form on both (integrated ones, walked in
    // other pieces, lie up to 8e-4 from them at 1 THz, where the pieces of
    // either are within 6e-4 of pieces an eighth as long: the
    // emissivity's exponential in the temperature changes faster than the
    // gas).
    let scene = common::shipped("sgra", 32, 32, &["observe.frequency=[1e10, 230e9, 1e12]"]);
    let (c, g) = (flux(&scene), gpu_flux(&scene));
    for (k, (c, g)) in c.iter().zip(&g).enumerate() {
        parity(&format!("sgra, frequency {k}"), *c, *g, 3e-4);
    }
}

#[test]
fn closed_form_rays_carry_the_transfer_as_the_integrated_ones() {
    // Rays in closed form (physics.closed_form, the default) against the
    // integrator's, at 64 x 64: Schwarzschild's segments from the exact
    // orbit (Gold's test 2, measured +2.0e-6); Kerr's stretches from the
    // closed form's points and rates (tests 1 and 5 at a = 0.9, measured
    // +3.9e-7 and -7.0e-6); and Sgr A*'s infalling flow, whose frequency
    // takes the photon's dr/dlambda (measured -7.2e-5 at 128 x 128 and
    // one sample). Before the pieces took the gas at two Gauss-Legendre
    // nodes the paths differed by as much as the pieces' midpoint rule
    // (-2.5e-4, +8.7e-5, -4e-5, +9.5e-5).
    type Build = Box<dyn Fn(bool) -> Scene>;
    let mut cases: Vec<(String, Build)> = Vec::new();
    for n in [2, 1, 5] {
        let text = gold(n, 64);
        let build = move |closed: bool| {
            common::scene(&format!("{text}\n[physics]\nclosed_form = {closed}\n"))
        };
        cases.push((format!("Gold test {n}"), Box::new(build)));
    }
    let sgra = |closed: bool| {
        common::shipped(
            "sgra",
            128,
            128,
            &[&format!("physics.closed_form={closed}")],
        )
    };
    cases.push(("Sgr A*".into(), Box::new(sgra)));
    for (label, scene) in cases {
        let closed_scene = scene(true);
        let (film, stats) = closed_scene.render(&|_| {});
        assert_eq!(stats.closed, stats.samples, "{label}");
        let closed = film.total_flux()[0];
        let integrated = flux(&scene(false))[0];
        close(&format!("{label}, closed form"), closed, integrated, 2e-4);
    }
}

/// Gold's flow without rotation or height (l0 = 0, h = 0, alpha = -2, no
/// absorption) at spin `spin`, one pixel of a 1e-3 degree field aimed
/// `offset` M to the side of the hole from a static camera at 1000 M and
/// 60 degrees from the axis (off the plane, where Kerr's closed form
/// takes no ray), rays `closed` or integrated (at a tolerance of 1e-10).
fn static_gold_ray(spin: f64, offset: f64, closed: bool) -> Scene {
    let r = 1000.0 * GOLD_M_METRES;
    let (s, c) = 60f64.to_radians().sin_cos();
    common::scene(
        &observed(
            (1, 1e-3),
            [0.0, -r * s, r * c],
            &format!(
                "spin = {spin:e}\n[sky]\ncolor = [0.0, 0.0, 0.0]\n[medium]\nkind = \"gold2020\"\n\
                 A = 0.0\nalpha = -2.0\nh = 0.0\nl0 = 0.0\n\
                 [physics]\nclosed_form = {closed}\ntolerance = 1e-10\n"
            ),
            (7778.0, "230e9"),
        )
        .replace(
            "look_at = [0.0, 0.0, 0.0]",
            &format!("look_at = [{:e}, 0.0, 0.0]", offset * GOLD_M_METRES),
        ),
    )
}

/// The intensity (cgs) a static camera at `r_cam` (M) sees of that gas
/// along the Schwarzschild ray of impact parameter `b` (M) that escapes:
/// j_nu(x nu) x_inf / x^3 = n c_r at nu = nu_p for alpha = -2, so I = 2 n0
/// (cm per M) c_r int_{r_t}^{r_cut} e^(-r^2 / 200) dlambda/dr dr, dlambda/dr =
/// r^(3/2) / sqrt(P(r)), P = r^3 - b^2 r + 2 b^2 = (r - r_t) Q(r) with Q =
/// r^2 + r_t r + r_t^2 - b^2 and r_t the turning point (P's largest root);
/// with r = r_t + u^2 the integrand, 2 r^(3/2) / sqrt(Q), is smooth: by
/// Simpson's rule on 20000 panels (to 1e-12).
fn static_gold_intensity(b: f64, r_cam: f64, cm_per_m: f64) -> f64 {
    let r_t = 2.0 * b / 3f64.sqrt() * ((-3.0 * 3f64.sqrt() / b).acos() / 3.0).cos();
    let cut = 10.0 * 40f64.sqrt();
    let g = |u: f64| {
        let r: f64 = r_t + u * u;
        let q = r * r + r_t * r + r_t * r_t - b * b;
        (-r * r / 200.0).exp() * 2.0 * r.powf(1.5) / q.sqrt()
    };
    let (n, top) = (20_000, (cut - r_t).sqrt());
    let h = top / n as f64;
    let sum: f64 = (0..n)
        .map(|i| {
            let u = i as f64 * h;
            h / 6.0 * (g(u) + 4.0 * g(u + 0.5 * h) + g(u + h))
        })
        .sum();
    let c_r = 1.0 / (1.0 - 2.0 / r_cam).sqrt();
    2.0 * blackhole::transfer::gold::N0 * cm_per_m * c_r * sum
}

#[test]
fn a_ray_through_static_gas_carries_the_integral_of_its_emission() {
    // Rays passing 6.6 to 15 M from the hole through Gold's density at
    // rest, at spin 0 and 1e-6, in closed form and integrated: each
    // pixel's intensity against the integral along the exact orbit. The
    // pieces take the gas at two Gauss-Legendre nodes; with the midpoint
    // alone (before) these rays were off by -4.6e-4 to +8.4e-4, by as
    // much as the pieces fell differently on the two spins' paths
    // (measured, with these nodes: integrated within 1e-7, closed forms
    // within 8e-6, the paths' own interpolation).
    for spin in [0.0, 1e-6] {
        for closed in [true, false] {
            for offset in [6.6, 8.0, 15.0] {
                let scene = static_gold_ray(spin, offset, closed);
                let (film, stats) = scene.render(&|_| {});
                assert_eq!(stats.closed, u64::from(closed));
                let origin = scene.camera.position;
                let (dir, _) = scene.camera.ray(0.5, 0.5);
                let b = 2.0 * blackhole::physics::gr::impact_parameter(origin, dir);
                let r_cam = 2.0 * origin.length();
                let d_cm = 7778.0 * blackhole::units::cgs::PARSEC;
                let sr = scene.camera.pixel_solid_angle(0.5, 0.5)
                    * (scene.camera_distance_cm() / d_cm).powi(2);
                let got = film.total_flux()[0] * blackhole::units::cgs::JANSKY / sr;
                let want = static_gold_intensity(b, r_cam, scene.cm_per_m());
                let label = format!("spin {spin}, closed {closed}, b {b:.3} M");
                println!(
                    "{label}: {got:.9e} against {want:.9e} ({:+.1e})",
                    got / want - 1.0
                );
                assert!(
                    (got / want - 1.0).abs() < 2e-5,
                    "{label}: {got} against {want}"
                );
            }
        }
    }
}

#[test]
fn spin_zero_and_a_hair_of_spin_give_one_flux() {
    // Gold's test 2 (a = 0) and the same flow at a = 1e-6 (Kerr's
    // closed-form stretches where a = 0 takes Schwarzschild's segments)
    // at 64 x 64: 2.1e-4 apart at 128 x 128 before the pieces took two
    // nodes.
    let text = |spin: f64| {
        gold(2, 64)
            .replace("test = 2\n", "A = 0.0\nalpha = -2.0\nh = 0.0\nl0 = 1.0\n")
            .replace("spin = 0\n", &format!("spin = {spin:e}\n"))
    };
    let (zero, hair) = (
        flux(&common::scene(&text(0.0)))[0],
        flux(&common::scene(&text(1e-6)))[0],
    );
    close("test 2 at a = 0 against a = 1e-6", zero, hair, 5e-5);
}

/// The least distance (M) from the spin axis of Kerr ray `k` of spin `a`:
/// sqrt(r^2 + a^2) sin theta (the Kerr-Schild cylinder's radius), least
/// along the ray by a scan and golden sections about its least sample.
fn distance_from_axis(k: &blackhole::physics::kerr_closed::KerrRay, a: f64) -> f64 {
    let at = |s: f64| {
        let p = k.state_at(s);
        (p.r * p.r + a * a).sqrt() * (1.0 - p.cos * p.cos).max(0.0).sqrt()
    };
    let end = k.mino_to_end();
    let n = 4000;
    let i = (0..=n)
        .min_by(|&i, &j| at(end * i as f64 / n as f64).total_cmp(&at(end * j as f64 / n as f64)))
        .unwrap();
    let (mut lo, mut hi) = (
        end * (i.max(1) - 1) as f64 / n as f64,
        end * (i + 1).min(n) as f64 / n as f64,
    );
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let (x1, x2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
        if at(x1) < at(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    at(0.5 * (lo + hi))
}

#[test]
fn rays_that_graze_the_spin_axis_give_finite_light() {
    // Gold's flow turns as l / varpi^2 ~ varpi^-1/2 near the axis; a ray
    // with angular momentum turns short of it, and so must the curve its
    // points are interpolated on (it overshot the polar turning point, to
    // the pole: two NaN samples of test 4 at 256 x 256, both on rays
    // passing the axis at about 0.005 M). One pixel whose ray passes the
    // axis at 1e-3 M (the closed form), 1e-6 and 1e-9 M (too near the
    // axis for the closed form's polar integrals: the integrator): each
    // finite, the three within 1e-3 of each other (the light varies
    // smoothly across the axis).
    let (s, c) = 60f64.to_radians().sin_cos();
    let r = 1000.0 * GOLD_M_METRES;
    let at = |offset: f64| {
        observed(
            (1, 1e-4),
            [r * s, 0.0, r * c],
            "spin = 0.9\n[sky]\ncolor = [0.0, 0.0, 0.0]\n[medium]\nkind = \"gold2020\"\ntest = 4\n",
            (7778.0, "230e9"),
        )
        .replace(
            "look_at = [0.0, 0.0, 0.0]",
            &format!(
                "look_at = [0.0, {:e}, {:e}]",
                offset * GOLD_M_METRES,
                12.0 * GOLD_M_METRES
            ),
        )
    };
    // The ray's L_z / E (in M), which the aim's offset sets linearly
    // (the ray passes the axis itself where it is 0: not at offset 0, as
    // Kerr-Schild's axes turn with the radius), and its Kerr ray.
    let ray = |offset: f64| {
        let scene = common::scene(&at(offset));
        let st = scene.model.spacetime().unwrap();
        let origin = scene.camera.position;
        let (dir, _) = scene.camera.ray(0.5, 0.5);
        let lambda = st.photon_lz_over_e(origin, dir);
        let k = match st.closed_ray(&scene.camera.closed_start(st, origin), dir, false) {
            Some(blackhole::physics::spacetime::Closed::Kerr(k)) => Some(k),
            _ => None,
        };
        (lambda, k)
    };
    // The offset of a given L_z / E, by the secant (exact for a linear
    // map, to rounding), and the distance from the axis per unit of L_z /
    // E, measured at 1e-2 and 1e-3 M.
    let aim = |lambda: f64| {
        let (mut o0, mut o1) = (0.0, 1e-2);
        let (mut l0, mut l1) = (ray(o0).0, ray(o1).0);
        for _ in 0..3 {
            let o2 = o1 + (lambda - l1) * (o1 - o0) / (l1 - l0);
            (o0, l0, o1, l1) = (o1, l1, o2, ray(o2).0);
        }
        o1
    };
    let passes = |lambda: f64| {
        let (l, k) = ray(aim(lambda));
        assert!((l / lambda - 1.0).abs() < 1e-6, "{l} {lambda}");
        distance_from_axis(&k.expect("a closed-form ray"), 0.9)
    };
    let per_lambda = passes(1e-2) / 1e-2;
    let check = passes(1e-3) / 1e-3;
    assert!(
        (check / per_lambda - 1.0).abs() < 1e-2,
        "{per_lambda} {check}"
    );
    let mut seen = Vec::new();
    for d in [1e-3, 1e-6, 1e-9] {
        let offset = aim(d / per_lambda);
        let (_, k) = ray(offset);
        if d == 1e-3 {
            let got = distance_from_axis(&k.expect("a closed-form ray"), 0.9);
            assert!(
                (got / d - 1.0).abs() < 1e-2,
                "aimed at {d} M, passes at {got} M"
            );
        }
        let scene = common::scene(&at(offset));
        let (film, stats) = scene.render(&|_| {});
        // The last two pass too near the axis for the closed form's polar
        // integrals: the integrator takes them.
        assert_eq!(stats.closed, u64::from(d >= 1e-3), "{d} M");
        let f = film.total_flux()[0];
        assert!(
            stats.non_finite == 0 && f.is_finite() && f > 0.0,
            "{d} M: {f} Jy, {stats:?}"
        );
        seen.push(f);
    }
    for f in &seen[1..] {
        close("a ray through the axis", *f, seen[0], 1e-3);
    }
}

/// Every sample of Gold's five tests at `pixels` x `pixels` is finite.
fn gold_samples_are_finite(pixels: u32) {
    for n in 1..=5 {
        let text = gold(n, pixels).replace("[image]\n", "[image]\nsamples = 1\n");
        let (film, stats) = common::scene(&text).render(&|_| {});
        assert_eq!(stats.non_finite, 0, "test {n} at {pixels}: {stats:?}");
        assert!(film.total_flux()[0].is_finite());
    }
}

#[test]
fn every_sample_of_the_gold_tests_is_finite() {
    // All five tests at 256 pixels (test 4 there gave two NaN samples near
    // the axis).
    gold_samples_are_finite(256);
}

/// The same at 512 pixels, a sweep of 1.3 million samples (20 s on 2
/// cores), run by `cargo test --release -- --ignored`.
#[test]
#[ignore = "a study: cargo test --release -- --ignored"]
fn every_sample_of_the_gold_tests_at_512_pixels_is_finite() {
    gold_samples_are_finite(512);
}

/// A hole of 1e8 solar masses (kg), its r_s (m), and a thin disk round it
/// from 1e4 to 1e5 r_s (so far out that gravity's shifts and the orbits'
/// Doppler shifts stay below 1e-3 of the flux) with an accretion rate of
/// 1.6e29 kg/s (1e4 K at its hottest), seen from 1e8 r_s at `inclination`
/// degrees and 1 Mpc, at four frequencies from Rayleigh-Jeans to Wien.
const DISK_MASS: f64 = 1.98847e38;
const DISK_FREQUENCIES: [f64; 4] = [2e12, 2e13, 2e14, 6e14];
fn far_disk(inclination: f64, pixels: u32) -> String {
    let r_s = 2.0 * 6.6743e-11 * DISK_MASS / 299_792_458f64.powi(2);
    let (s, c) = inclination.to_radians().sin_cos();
    let r = 1e8 * r_s;
    format!(
        r#"
[image]
width = {pixels}
height = {pixels}
samples = 4
png = "unused.png"
[camera]
position = [{x:e}, 0.0, {z:e}]
look_at = [0.0, 0.0, 0.0]
up = [{ux}, 0.0, {uz}]
fov = {fov}
[black_hole]
mass = {DISK_MASS:e}
[sky]
color = [0.0, 0.0, 0.0]
[disk]
emission = "thin"
inner_radius = 1e4
radius = 1e5
accretion_rate = 1.6e29
[observe]
distance = 1e6
frequency = [2e12, 2e13, 2e14, 6e14]
"#,
        x = r * s,
        z = r * c,
        // The up vector: the spin axis, or x when looking down it.
        ux = if s.abs() < 1e-9 { 1.0 } else { 0.0 },
        uz = if s.abs() < 1e-9 { 0.0 } else { 1.0 },
        fov = 2.0 * (1.1e5f64 / 1e8).atan().to_degrees(),
    )
}

/// The solid angle (sr) of pixel (`px`, `py`) as seen from `d_cm`: the
/// camera's, scaled by its distance from the hole over `d_cm`, squared.
fn seen_from(scene: &Scene, d_cm: f64, px: usize, py: usize) -> f64 {
    let r_cm = scene.camera_distance_cm();
    scene
        .camera
        .pixel_solid_angle(px as f64 + 0.5, py as f64 + 0.5)
        * (r_cm / d_cm).powi(2)
}

/// Says how far `got` (Jy) is from `want`, and asserts it within `tol`.
fn close(label: &str, got: f64, want: f64, tol: f64) {
    println!(
        "{label}: {got:.6e} Jy against {want:.6e} ({:+.2e})",
        got / want - 1.0
    );
    assert!(
        (got / want - 1.0).abs() < tol,
        "{label}: {got} Jy against {want}"
    );
}

/// The multicolour blackbody a distant observer sees of that disk (Jy):
/// F_nu = (2 pi cos i / D^2) int B_nu(T(r)) r dr with Shakura and Sunyaev's
/// sigma T^4 = 3 G M Mdot / (8 pi r^3) (1 - sqrt(r_in / r)), SI, CODATA
/// 2018 (Simpson's rule in ln r).
fn multicolour_blackbody_jy(nu: f64, inclination: f64) -> f64 {
    let (g, c, sigma) = (6.6743e-11, 299_792_458.0, 5.670_374_419e-8);
    let r_s = 2.0 * g * DISK_MASS / (c * c);
    let (r_in, mdot) = (1e4 * r_s, 1.6e29);
    let d = 1e6 * 3.085_677_581_491_367e16;
    let kelvin = |r: f64| {
        (3.0 * g * DISK_MASS * mdot / (8.0 * PI * sigma * r.powi(3)) * (1.0 - (r_in / r).sqrt()))
            .powf(0.25)
    };
    let integral = ring_integral((r_in, 1e5 * r_s), |r| planck_si(nu, kelvin(r)));
    2.0 * PI * inclination.to_radians().cos() * integral / (d * d) / 1e-26
}

/// int f(r) r dr from r0 to r1, by Simpson's rule in ln r (r dr = r^2
/// d(ln r)) on 20,000 panels.
fn ring_integral((r0, r1): (f64, f64), f: impl Fn(f64) -> f64) -> f64 {
    let n = 20_000;
    let (a, b) = (r0.ln(), r1.ln());
    let step = (b - a) / n as f64;
    let sum: f64 = (0..=n)
        .map(|i| {
            let r = (a + i as f64 * step).exp();
            let w = match i {
                0 => 1.0,
                _ if i == n => 1.0,
                _ if i % 2 == 1 => 4.0,
                _ => 2.0,
            };
            w * f(r) * r * r
        })
        .sum();
    sum * step / 3.0
}

#[test]
fn a_thin_disk_shows_the_multicolour_blackbody_in_janskys() {
    // Face-on and at 60 degrees, at 128 x 128 (measured: within 2e-4
    // face-on, 6e-4 at 60 degrees, where the orbits' Doppler shifts enter
    // at second order on the Wien side; at 256 x 256 within 4e-4).
    for inclination in [0.0, 60.0] {
        let got = flux(&common::scene(&far_disk(inclination, 128)));
        for (k, &nu) in DISK_FREQUENCIES.iter().enumerate() {
            let want = multicolour_blackbody_jy(nu, inclination);
            close(&format!("{inclination} deg, {nu:e} Hz"), got[k], want, 1e-3);
        }
    }
}

#[test]
fn a_thin_disk_behind_an_absorbing_shell_is_dimmed_by_e_to_the_minus_tau() {
    // A shell from 1e7 to 1.1e7 M, absorbing 1 / L per cm across its L =
    // 1e6 M (tau = 1 radially), between the disk and the camera: the rays
    // that reach the disk cross it within 0.01 rad of radially, so each
    // frequency's flux falls by e^-1 (to 1e-4).
    let text = far_disk(0.0, 64);
    let cm_per_m = 6.6743e-11 * DISK_MASS / 299_792_458f64.powi(2) * 100.0;
    let shell = format!(
        "[medium]\nkind = \"uniform\"\ninner = 1e7\nouter = 1.1e7\nemission = 0.0\nabsorption = {:e}\n",
        1.0 / (1e6 * cm_per_m)
    );
    let clear = flux(&common::scene(&text));
    let dimmed = flux(&common::scene(&format!("{text}{shell}")));
    for (k, (c, d)) in clear.iter().zip(&dimmed).enumerate() {
        let ratio = d / c;
        println!("frequency {k}: {ratio:.6} of the clear flux");
        assert!(
            (ratio / (-1f64).exp() - 1.0).abs() < 3e-4,
            "frequency {k}: {ratio}"
        );
    }
}

/// The far disk's hole seen the same way, with a volumetric disk in place
/// of the thin one: gas from 1e4 to 1e5 r_s, 5e3 r_s thick at its edge,
/// 1e4 K at its hottest, absorbing `opacity` per r_s at density 1.
fn far_volume(opacity: f64, pixels: u32) -> String {
    far_disk(0.0, pixels).replace(
        "[disk]\nemission = \"thin\"\ninner_radius = 1e4\nradius = 1e5\naccretion_rate = 1.6e29\n",
        &format!(
            "[volume]\ninner = 1e4\nouter = 1e5\nthickness = 5e3\nstep = 300.0\nopacity = {opacity:e}\npeak_kelvin = 1e4\n"
        ),
    )
}

/// Planck's B_nu(T) in SI (CODATA 2018).
fn planck_si(nu: f64, kelvin: f64) -> f64 {
    let (c, h, k) = (299_792_458.0, 6.626_070_15e-34, 1.380_649e-23);
    let x = h * nu / (k * kelvin);
    if kelvin <= 0.0 || x > 700.0 {
        0.0
    } else {
        2.0 * h * nu.powi(3) / (c * c) / x.exp_m1()
    }
}

/// The volume's temperature (GUIDE: T = peak_kelvin r^-3/4 (1 -
/// sqrt(inner / r))^1/4, scaled to the peak at r = 49/36 inner).
fn volume_kelvin(r: f64) -> f64 {
    let f = |r: f64| {
        if r <= 1e4 {
            0.0
        } else {
            r.powf(-0.75) * (1.0 - (1e4 / r).sqrt()).powf(0.25)
        }
    };
    1e4 * f(r) / f(49.0 / 36.0 * 1e4)
}

#[test]
fn the_volumetric_disk_shines_as_a_blackbody_when_thick_and_as_its_emissivity_when_thin() {
    let r_s = 2.0 * 6.6743e-11 * DISK_MASS / 299_792_458f64.powi(2);
    let d = 1e6 * 3.085_677_581_491_367e16;
    // Optically thick (tau ~ 1e3 through the layer): face-on, each ray
    // sees Planck's function at its cylinder's temperature, so the flux
    // is the multicolour blackbody (2 pi / D^2) int B_nu(T(r)) r dr.
    let thick = flux(&common::scene(&far_volume(1.0, 128)));
    for (k, &nu) in DISK_FREQUENCIES.iter().enumerate() {
        let integral = ring_integral((1e4, 1e5), |r| planck_si(nu, volume_kelvin(r)));
        let want = 2.0 * PI * integral * (r_s / d).powi(2) / 1e-26;
        close(&format!("thick, {nu:e} Hz"), thick[k], want, 1.5e-3);
    }
    // Optically thin (tau ~ 1e-5): the flux is the emissivity's volume
    // integral over D^2, F = int alpha B_nu(T) dV / D^2, alpha = opacity
    // rho / r_s, over the density field the scene holds (sampled at the
    // centres of 2 x 2 x 2 sub-cells of its grid).
    let scene = common::scene(&far_volume(1e-8, 128));
    let thin = flux(&scene);
    let gas = scene.volume.as_ref().expect("the volume");
    let (n_xy, n_z) = (640, 66);
    let (h_xy, h_z) = (2e5 / n_xy as f64, 6.0 * 5e3 / n_z as f64);
    let mut want = [0.0; 4];
    for iz in 0..n_z {
        for iy in 0..n_xy {
            for ix in 0..n_xy {
                let p = glam::DVec3::new(
                    -1e5 + (ix as f64 + 0.5) * h_xy,
                    -1e5 + (iy as f64 + 0.5) * h_xy,
                    -1.5e4 + (iz as f64 + 0.5) * h_z,
                );
                let rho = gas.density.sample(p) as f64;
                if rho > 0.0 {
                    let t = volume_kelvin(p.x.hypot(p.y));
                    for (w, &nu) in want.iter_mut().zip(&DISK_FREQUENCIES) {
                        *w += rho * planck_si(nu, t);
                    }
                }
            }
        }
    }
    for (k, w) in want.iter().enumerate() {
        // alpha (m^-1) = 1e-8 rho / r_s; dV = h_xy^2 h_z r_s^3.
        let want = w * 1e-8 * h_xy * h_xy * h_z * r_s * r_s / (d * d) / 1e-26;
        close(&format!("thin, frequency {k}"), thin[k], want, 2e-3);
    }
}

#[test]
fn a_blackbody_sky_shows_planck_blueshifted_around_the_shadow() {
    // A static camera at 10 r_s sees the sky at infinity blueshifted by g
    // = 1 / sqrt(1 - r_s / r): each ray that escapes brings B_nu(g T)
    // (g^3 B_nu(nu / g; T)), each one the hole takes nothing; one sample a
    // pixel, so each pixel is one or the other.
    let text = static_view(
        (48, 60.0, 20.0),
        "[1e14, 3e14]",
        "[sky]\nblackbody = 3000.0\n",
    );
    let scene = common::scene(&text);
    let (film, _) = scene.render(&|_| {});
    let spectra = film.spectra.as_ref().expect("fluxes kept");
    let g = 1.0 / (1.0 - 0.1f64).sqrt();
    let d_cm = 8000.0 * blackhole::units::cgs::PARSEC;
    let (mut dark, mut lit) = (0, 0);
    for py in 0..48 {
        for px in 0..48 {
            let sr = seen_from(&scene, d_cm, px, py);
            for (k, nu) in [1e14, 3e14].into_iter().enumerate() {
                let got = spectra[(py * 48 + px) * 2 + k] as f64;
                if got == 0.0 {
                    dark += 1;
                    continue;
                }
                lit += 1;
                let want = planck_si(nu, g * 3000.0) * 1e3 * sr / 1e-23;
                assert!(
                    (got / want - 1.0).abs() < 1e-6,
                    "pixel ({px}, {py}) at {nu:e} Hz: {got} Jy against {want}"
                );
            }
        }
    }
    // The shadow: sin alpha = (3 sqrt 3 / 2) sqrt(1 - 1/r) / r at r = 10
    // r_s, 14.3 degrees: a disk of 10.6 pixels' radius in a
    // 60-degree field of 48 (351; measured: 348 pixels' centres inside).
    let alpha = (1.5 * 3f64.sqrt() * 0.9f64.sqrt() / 10.0).asin();
    let half = 30f64.to_radians().tan();
    let expected = PI * (alpha.tan() / half * 24.0).powi(2);
    println!("{} dark pixels, the shadow's area {expected:.1}", dark / 2);
    assert!(
        (dark as f64 / 2.0 - expected).abs() < 0.03 * expected,
        "{dark} {lit}"
    );
}

#[test]
fn observed_scenes_are_walked_as_visible_ones() {
    // The jansky shade rides the walk every sample takes: a thin disk
    // about a = 0.9 (quasar.toml's, 48 x 48 at one sample) seen in
    // janskys and in visible light meets the disk at the same points, in
    // the same image order, with the same shift, footprint and light
    // travel time (each pixel's observables equal); and its janskys are
    // its blackbody's there. Before, the observed scene's rays kept none
    // of this (their observables were empty).
    let text = |observe: &str| {
        format!(
            r#"
[image]
width = 48
height = 48
samples = 1
adaptive = false
observables = ["g", "radius", "order", "time", "magnification"]
png = "unused.png"
[camera]
position = [2.557667e+15, 0.0, 1.476670e+15]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov = 0.378151
[black_hole]
mass = 1.988470e+38
spin = 0.9
[sky]
color = [0.0, 0.0, 0.0]
[disk]
emission = "thin"
radius = 30.0
peak_temperature = 1e5
{observe}"#
        )
    };
    let observed = common::scene(&text(
        "[observe]\ndistance = \"100 Mpc\"\nfrequency = 1e15\n",
    ));
    let visible = common::scene(&text(""));
    let (jy, _) = observed.render(&|_| {});
    let (light, _) = visible.render(&|_| {});
    let mut on_disk = 0;
    for ((o, a), (_, b)) in jy.observables.iter().zip(&light.observables) {
        assert_eq!(a.len(), b.len(), "{o:?}");
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                x == y || x.is_nan() && y.is_nan(),
                "{o:?} at pixel {k}: observed {x}, visible {y}"
            );
        }
        if *o == blackhole::film::Observable::Radius {
            on_disk = a.iter().filter(|r| r.is_finite()).count();
        }
    }
    assert!(on_disk > 300, "{on_disk} pixels on the disk");
    // Each disk pixel's janskys: its blackbody at the temperature of its
    // radius, shifted by its g, over its solid angle, as found by hand.
    let plane = |o| &jy.observables.iter().find(|(p, _)| *p == o).unwrap().1;
    let (g, radius) = (
        plane(blackhole::film::Observable::G),
        plane(blackhole::film::Observable::Radius),
    );
    let thin = observed.disk.as_ref().unwrap().thin.as_ref().unwrap();
    let spectra = jy.spectra.as_ref().expect("janskys per pixel");
    let d_cm = 100e6 * blackhole::units::cgs::PARSEC;
    let r_cam = observed.camera_distance_cm();
    let mut worst: f64 = 0.0;
    for k in 0..48 * 48 {
        if !radius[k].is_finite() {
            continue;
        }
        let (px, py) = ((k % 48) as f64 + 0.5, (k / 48) as f64 + 0.5);
        let sr = observed.camera.pixel_solid_angle(px, py) * (r_cam / d_cm).powi(2);
        let g = g[k] as f64;
        let kelvin = thin.temperature(radius[k] as f64);
        let want =
            g.powi(3) * thin.intensity_nu(1e15 / g, kelvin) * sr / blackhole::units::cgs::JANSKY;
        worst = worst.max((spectra[k] as f64 / want - 1.0).abs());
    }
    // The maps are f32 (g and r to 6e-8 relative, which the Wien tail at
    // 1 PHz, h nu / k T of 5 to 50, multiplies): measured 2.2e-7.
    eprintln!("{on_disk} pixels on the disk, worst relative difference {worst:.2e}");
    assert!(worst < 2e-6, "worst relative difference {worst:.2e}");
}

#[test]
fn the_gpus_observed_samples_are_walked_as_the_cpus() {
    let Some(gpu) = common::gpu() else { return };
    // The GPU's observed samples take the walk every sample takes, as
    // the CPU's do: the quasar's thin disk (48 x 48) refines exactly the
    // CPU's pixels by exactly as many samples (adaptive sampling tells
    // the disk's image orders apart on both), and its per-pixel
    // observables are the CPU's within f32 (g, ring radius, image order).
    let scene = common::shipped(
        "quasar",
        48,
        48,
        &["image.observables=[\"g\", \"radius\", \"order\"]"],
    );
    let (cpu, cpu_stats) = scene.render(&|_| {});
    let p = gpu.prepare(&scene, u32::MAX).unwrap();
    let (gpu_film, gpu_stats) = p.render(&|_| {}).unwrap();
    assert_eq!(
        (gpu_stats.samples, gpu_stats.refined),
        (cpu_stats.samples, cpu_stats.refined),
        "GPU {gpu_stats:?}, CPU {cpu_stats:?}"
    );
    // Without a medium both take the spinning hole's closed form: the
    // same pixels on the disk (NaN masks), the image order equal on every
    // pixel, g and the ring radius within 1e-5 on 99% of them (f32).
    // Measured on lavapipe: all of them (integrated in f32, before the
    // GPU took the closed form for observed scenes, 95.6% of the radii
    // were within 1e-4).
    for ((o, a), (_, b)) in cpu.observables.iter().zip(&gpu_film.observables) {
        let masks = a.iter().zip(b).all(|(x, y)| x.is_nan() == y.is_nan());
        let finite: Vec<(f32, f32)> = a
            .iter()
            .zip(b)
            .map(|(x, y)| (*x, *y))
            .filter(|(x, _)| x.is_finite())
            .collect();
        let tol = match o {
            blackhole::film::Observable::Order => 0.0,
            _ => 1e-5,
        };
        let within = finite
            .iter()
            .filter(|(x, y)| ((x - y) as f64).abs() <= tol * (*x as f64).abs())
            .count() as f64
            / finite.len().max(1) as f64;
        eprintln!(
            "{o:?}: masks equal {masks}, {within:.4} of {} within {tol:e}",
            finite.len()
        );
        let share = if tol == 0.0 { 1.0 } else { 0.99 };
        assert!(masks && within >= share, "{o:?}: masks {masks}, {within}");
    }
    // And so the janskys at every frequency (measured within 3e-6).
    for (k, (c, g)) in cpu
        .total_flux()
        .iter()
        .zip(gpu_film.total_flux())
        .enumerate()
    {
        close(
            &format!("the quasar on the GPU, frequency {k}"),
            g,
            *c,
            2e-5,
        );
    }
}
