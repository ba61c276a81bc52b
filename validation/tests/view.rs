//! The viewer: saved views and screenshots against `render`, and the
//! window itself under Xvfb (software Vulkan), driven with synthetic input
//! and captured from the X display.
//!
//! The window tests need Xvfb, xdotool and ImageMagick's `import`, the
//! GPU ones an adapter: without them they print why and pass, unless `CI`
//! is set (CI installs them all).

mod common;

use blackhole::config::{ModelKind, Override, SceneConfig};
use blackhole::scene::Scene;
use blackhole::view::Session;
use blackhole::view::state::Toggle;
use common::{bin, gpu, mean_delta_e, pixels, small_scene_text};
use glam::DVec3;
use std::path::Path;
use std::process::Command;

/// `blackhole render -q --backend gpu FILE` in `dir`, which must succeed.
fn render_gpu(dir: &Path, file: &Path) {
    let out = bin()
        .args(["render", "-q", "--backend", "gpu"])
        .arg(file)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The small scene at 160 x 120 with 4 samples per pixel.
fn scene_text() -> String {
    small_scene_text()
        .replace("width = 64", "width = 160")
        .replace("height = 48", "height = 120\nsamples = 4")
}

fn folder(text: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    dir
}

/// Whether every program in `tools` runs; with `CI` set a missing one
/// fails the test.
fn have(tools: &[&str]) -> bool {
    for t in tools {
        let ok = Command::new("sh")
            .args(["-c", &format!("command -v {t}")])
            .output()
            .is_ok_and(|o| o.status.success());
        let why = format!("{t} is not installed (apt-get install xvfb xauth xdotool imagemagick)");
        if !common::available(ok.then_some(()).ok_or(why)) {
            return false;
        }
    }
    true
}

#[test]
fn a_saved_view_is_the_scene_file_with_the_camera_switches_and_clock_changed() {
    let dir = folder(&scene_text());
    let d = dir.path();
    let cli = vec![Override::parse("image.exposure=0.5").unwrap()];
    let session = Session::open(&d.join("scene.toml"), cli, d.to_path_buf()).unwrap();
    let mut state = session.start();
    state.orbit(80.0, -40.0);
    state.zoom(2.0);
    state.zoom_fov(1.0);
    state.pan(5.0, -3.0, 120.0);
    state.toggle(Toggle::Model);
    state.time = 1234.5;
    let saved = session.save(&state).unwrap();
    assert_eq!(saved, d.join("scene_view1.toml"));
    let cfg = SceneConfig::load(&saved, &[]).unwrap();
    // The camera exactly, the switch, the clock, the command line's
    // override, and outputs beside the saved file.
    let c = &cfg.camera;
    assert_eq!(DVec3::from_array(c.position), state.pose.position);
    assert_eq!(DVec3::from_array(c.look_at), state.pose.look_at);
    assert_eq!(DVec3::from_array(c.up), state.pose.up);
    assert_eq!(c.fov, state.pose.fov);
    assert_eq!(cfg.physics.model, ModelKind::Seed);
    let a = cfg.animation.as_ref().expect("the clock needs [animation]");
    assert_eq!(
        (a.start, a.frames, a.fps, a.duration),
        (1234.5, None, None, None)
    );
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.contains("[animation]\nstart = 1234.5\n"), "{text}");
    assert!(text.contains("mass = 8.57e36"), "{text}");
    assert_eq!(cfg.image.exposure, 0.5);
    assert_eq!(cfg.image.png, d.join("scene_view1.png"));
    // Paths absolute: the file loads the same textures from anywhere.
    let original = SceneConfig::load(&d.join("scene.toml"), &[]).unwrap();
    assert_eq!(cfg.sky.texture, original.sky.texture);
    let text = std::fs::read_to_string(&saved).unwrap();
    assert!(text.contains(&original.sky.texture.unwrap().display().to_string()));
    // The saved scene's camera is the viewer's.
    let built = Scene::build(cfg).unwrap();
    let shown = session.scene(&state, None, Some(64), true).unwrap();
    assert_eq!(built.camera.position, shown.camera.position);
    assert_eq!(built.camera.forward, shown.camera.forward);
    assert_eq!(built.time, shown.time);
    // The next save takes the next name; an unchanged view adds no
    // [animation].
    let plain = session.save(&session.start()).unwrap();
    assert_eq!(plain, d.join("scene_view2.toml"));
    assert!(SceneConfig::load(&plain, &[]).unwrap().animation.is_none());
}

#[test]
fn a_saved_view_of_an_animation_keeps_its_clock_and_drops_its_camera_path() {
    let text = format!(
        "{}\n[animation]\nframes = 10\nfps = 5.0\nduration = 500.0\nrotation = \"rigid\"\nperiod = 300.0\n\
         [animation.orbit]\nazimuth = [0.0, 90.0]\nelevation = [10.0, 20.0]\ndistance = 2.0e11\n",
        scene_text()
    );
    let dir = folder(&text);
    let d = dir.path();
    let session = Session::open(&d.join("scene.toml"), vec![], d.to_path_buf()).unwrap();
    let mut state = session.start();
    state.time = 77.0;
    let cfg = SceneConfig::load(&session.save(&state).unwrap(), &[]).unwrap();
    let a = cfg.animation.unwrap();
    assert!(a.orbit.is_none() && a.keyframes.is_none());
    assert_eq!((a.start, a.frames, a.period), (77.0, Some(10), Some(300.0)));
    assert_eq!(cfg.camera.position, [0.0, -2.2e11, 3.0e10]);
}

#[test]
fn every_shipped_scene_opens_in_the_viewer_or_says_why_the_gpu_cannot() {
    // The viewer's own scene (a fixed camera; an animation's path and its
    // motion dropped) of every shipped config loads; the only refusal is
    // a table the GPU backend does not render, said as such.
    let configs = common::root().join("configs");
    let mut opened = 0;
    for entry in std::fs::read_dir(&configs).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let out = tempfile::tempdir().unwrap();
        match Session::open(&path, vec![], out.path().to_path_buf()) {
            Ok(_) => opened += 1,
            Err(e) => {
                let e = format!("{e:#}");
                assert!(
                    e.contains("the viewer renders on the GPU, which does not render"),
                    "{}: {e}",
                    path.display()
                );
            }
        }
    }
    assert!(opened >= 15, "{opened} shipped scenes open");
}

#[test]
fn a_saved_view_of_a_moving_path_camera_is_at_rest() {
    let text = format!(
        "{}\n[animation]\nframes = 10\nfps = 5.0\nduration = 2.0\ncamera_motion = \"path\"\n\
         [animation.orbit]\nazimuth = [0.0, 90.0]\nelevation = [10.0, 20.0]\ndistance = 2.0e11\n",
        scene_text()
    );
    let dir = folder(&text);
    let d = dir.path();
    let session = Session::open(&d.join("scene.toml"), vec![], d.to_path_buf()).unwrap();
    let cfg = SceneConfig::load(&session.save(&session.start()).unwrap(), &[]).unwrap();
    let a = cfg.animation.unwrap();
    assert!(a.orbit.is_none());
    assert_eq!(a.camera_motion, blackhole::config::CameraMotion::Rest);
}

#[test]
fn a_saved_view_keeps_the_spin_set_with_the_keys() {
    // Three steps up from a still hole: a = 0.3 in the saved file, and the
    // viewer's scene (and so the render of the saved file) is Kerr's.
    let dir = folder(&scene_text());
    let d = dir.path();
    let session = Session::open(&d.join("scene.toml"), vec![], d.to_path_buf()).unwrap();
    let mut state = session.start();
    for _ in 0..3 {
        state.change_spin(true);
    }
    let cfg = SceneConfig::load(&session.save(&state).unwrap(), &[]).unwrap();
    assert_eq!(cfg.black_hole.spin, 0.3);
    let shown = session.scene(&state, None, Some(4), true).unwrap();
    assert_eq!(
        shown.model.spacetime(),
        Some(blackhole::physics::Spacetime::Kerr { a: 0.3 })
    );
    assert_eq!(
        Scene::build(cfg).unwrap().model.spacetime(),
        shown.model.spacetime()
    );
    // Under the seed model the spin is refused by name, as the viewer says.
    state.toggle(Toggle::Model);
    let e = session.scene(&state, None, Some(4), true).unwrap_err();
    assert!(format!("{e:#}").contains("black_hole.spin"), "{e:#}");
}

#[test]
fn a_screenshot_is_the_render_of_the_saved_view() {
    if gpu().is_none() {
        return;
    }
    // The device's own choice of ray path, as `render --backend gpu` makes
    // it (the shared test GPU always takes the closed form).
    let gpu = &blackhole::gpu::Gpu::new().unwrap();
    let dir = folder(&scene_text());
    let d = dir.path();
    let session = Session::open(&d.join("scene.toml"), vec![], d.to_path_buf()).unwrap();
    let mut state = session.start();
    state.orbit(-60.0, -30.0);
    state.zoom(-1.0);
    state.time = 900.0;
    let shot = session.screenshot(&state, gpu).unwrap();
    assert_eq!(shot, d.join("scene_shot1.png"));
    assert!(d.join("scene_shot1.exr").exists());
    let saved = session.save(&state).unwrap();
    render_gpu(d, &saved);
    assert_eq!(pixels(&shot), pixels(&d.join("scene_view1.png")));
}

#[test]
fn an_observed_scene_keeps_its_stepped_frequencies_in_the_saved_view_and_screenshot() {
    // Gold et al.'s test 3 with a thin disk at 48 x 48: three steps of the
    // frequency key (a third of an octave each) make 230 GHz 460 GHz in
    // the saved file; its render is the screenshot, pixel for pixel (the
    // false colour of the PNG the window's, afmhot).
    let text = std::fs::read_to_string(common::root().join("configs/gold2020.toml"))
        .unwrap()
        .replace("width = 256", "width = 48")
        .replace("height = 256", "height = 48")
        .replace("png = \"../img/gold2020.png\"", "png = \"out.png\"")
        .replace("exr = \"../img/gold2020.exr\"\n", "")
        .replace("colorbar = true", "colorbar = false")
        + "[disk]\nemission = \"thin\"\nradius = 10.0\npeak_temperature = 3e10\n";
    let dir = folder(&text);
    let d = dir.path();
    let session = Session::open(&d.join("scene.toml"), vec![], d.to_path_buf()).unwrap();
    let mut state = session.start();
    for _ in 0..3 {
        state.change_frequency(true);
    }
    let saved = session.save(&state).unwrap();
    let cfg = SceneConfig::load(&saved, &[]).unwrap();
    let nu = cfg.observe.expect("observed").frequency.list();
    assert!(
        nu.len() == 1 && (nu[0] / 460e9 - 1.0).abs() < 1e-12,
        "{nu:?}"
    );
    if gpu().is_none() {
        return;
    }
    let gpu = &blackhole::gpu::Gpu::new().unwrap();
    let shot = session.screenshot(&state, gpu).unwrap();
    render_gpu(d, &saved);
    let shown = pixels(&shot);
    assert!(shown.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 500);
    assert_eq!(shown, pixels(&d.join("scene_view1.png")));
}

/// Runs `script` (sh) under a fresh Xvfb display with the binary as $BIN
/// and `dir` as the working folder; returns its exit status and output.
fn under_xvfb(dir: &Path, script: &str) -> (bool, String) {
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 800x600x24", "sh", "-c", script])
        .current_dir(dir)
        .env("BIN", env!("CARGO_BIN_EXE_blackhole"))
        .output()
        .unwrap();
    (
        out.status.success(),
        format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ),
    )
}

/// Shell: waits until the top-left `w` x `h` of the screen holds still
/// for one and a half seconds (the view has all its samples; a loaded
/// machine can pause the view for half a second between passes), into
/// `$1`.
const SETTLE: &str = r#"
settle() {
  i=0
  still=0
  import -window root -crop "$2" "$1.a.png"
  while [ $i -lt 120 ]; do
    sleep 0.5
    import -window root -crop "$2" "$1.b.png"
    if cmp -s "$1.a.png" "$1.b.png"; then still=$((still + 1)); else still=0; fi
    mv "$1.b.png" "$1.a.png"
    if [ $still -ge 3 ]; then mv "$1.a.png" "$1"; return 0; fi
    i=$((i + 1))
  done
  echo "the view did not settle"; return 1
}
# Waits until the top-left $2 of the screen differs from the image $1.
changed() {
  i=0
  while [ $i -lt 240 ]; do
    import -window root -crop "$2" changed.png
    if ! cmp -s changed.png "$1"; then rm -f changed.png; return 0; fi
    sleep 0.25
    i=$((i + 1))
  done
  echo "the view did not change"; return 1
}
"#;

#[test]
fn the_window_shows_the_render_and_follows_the_mouse_and_keys() {
    if !have(&["xvfb-run", "xdotool", "import"]) || gpu().is_none() {
        return;
    }
    let dir = folder(&scene_text());
    let d = dir.path();
    // Open, hide the overlay, capture the still view; drag 80 px right,
    // switch to the seed model, save and take a screenshot; quit.
    let script = format!(
        r#"set -e
{SETTLE}
"$BIN" view scene.toml > view.log 2>&1 &
pid=$!
wid=$(timeout 60 xdotool search --sync --onlyvisible --name "blackhole view")
xdotool mousemove 20 20
xdotool windowfocus --sync "$wid" || true
xdotool key i
# Nothing on the screen holds still until the first frame is drawn.
n=0
while ! grep -q "first frame" view.log && [ $n -lt 240 ]; do sleep 0.25; n=$((n + 1)); done
settle still.png 160x120+0+0
xdotool mousemove 40 60 mousedown 1 mousemove 80 60 mousemove 120 60 mouseup 1
xdotool key m
# One wheel notch towards the hole (a press and a release of button 4).
xdotool click 4
changed still.png 160x120+0+0
settle moved.png 160x120+0+0
xdotool key s
xdotool key p
n=0
while ! grep -q "wrote" view.log && [ $n -lt 240 ]; do sleep 0.5; n=$((n + 1)); done
xdotool key q
wait $pid
cat view.log
"#
    );
    let (ok, log) = under_xvfb(d, &script);
    assert!(ok, "{log}");
    // The still window is what `render --backend gpu` gives.
    render_gpu(d, Path::new("scene.toml"));
    let de = mean_delta_e(&pixels(&d.join("still.png")), &pixels(&d.join("out.png")));
    eprintln!("window vs render: mean CIEDE2000 {de:.4}");
    assert!(de < 1.0, "window vs render: mean CIEDE2000 {de}");
    // The drag orbited by 80 px x 0.25 deg, clockwise seen from above;
    // the key switched the model; the saved view renders to the
    // screenshot and to what the window showed.
    let saved = d.join("scene_view1.toml");
    let cfg = SceneConfig::load(&saved, &[]).unwrap();
    let p = cfg.camera.position;
    let azimuth = p[0].atan2(-p[1]).to_degrees();
    assert!((azimuth + 20.0).abs() < 1e-9, "azimuth {azimuth}\n{log}");
    // One notch: the distance divided by 1.1, once (not 1.21).
    let start = SceneConfig::load(&d.join("scene.toml"), &[]).unwrap();
    // From the hole, which the wheel moves the camera towards.
    let dist = |c: &SceneConfig| DVec3::from_array(c.camera.position).length();
    let ratio = dist(&start) / dist(&cfg);
    assert!(
        (ratio - 1.1).abs() < 1e-9,
        "one wheel notch: {ratio}\n{log}"
    );
    assert_eq!(cfg.physics.model, ModelKind::Seed);
    render_gpu(d, &saved);
    let rendered = pixels(&d.join("scene_view1.png"));
    assert_eq!(pixels(&d.join("scene_shot1.png")), rendered);
    let de = mean_delta_e(&pixels(&d.join("moved.png")), &rendered);
    assert!(de < 1.0, "moved window vs render of the saved view: {de}");
    let de_still = mean_delta_e(&pixels(&d.join("still.png")), &rendered);
    eprintln!("moved window vs saved render {de:.4}, still vs saved {de_still:.2}");
    assert!(de_still > 2.0, "the view did change: {de_still}");
}

#[test]
fn viewer_errors_are_named_and_exit_1() {
    let dir = folder(&scene_text());
    let d = dir.path();
    let run = |envs: &[(&str, &str)], args: &[&str]| {
        let mut c = bin();
        c.current_dir(d).arg("view").arg("scene.toml").args(args);
        c.env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
        for (k, v) in envs {
            c.env(k, v);
        }
        let out = c.output().unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, err) = run(&[], &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("display") && err.contains("xvfb-run"), "{err}");
    let (code, err) = run(
        &[],
        &[
            "--set",
            "spectral.enabled=true",
            "--set",
            "spectral.per_wavelength=true",
        ],
    );
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("spectral.per_wavelength") && err.contains("viewer"),
        "{err}"
    );
    // --out names a file: refused; a folder that does not exist yet is
    // made (as render makes its outputs' folders), here before the missing
    // display is found.
    std::fs::write(d.join("a_file"), "x").unwrap();
    let (code, err) = run(&[], &["--out", "a_file"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--out a_file: not a folder"), "{err}");
    let (code, err) = run(&[], &["--out", "shots/new"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("display") && d.join("shots/new").is_dir(),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    // A display but no GPU backend that can draw into it.
    if have(&["xvfb-run"]) {
        let (ok, log) = under_xvfb(d, "WGPU_BACKEND=dx12 \"$BIN\" view scene.toml");
        assert!(
            !ok && log.contains("WGPU_BACKEND") && !log.contains("panicked"),
            "{log}"
        );
    }
}
