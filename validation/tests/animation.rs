//! Animation: the disk's rotation and the light's travel time measured in
//! rendered frames against closed forms, the camera's path, and frames as
//! independent jobs with their video.

mod common;

use blackhole::animation::CameraPath;
use blackhole::scene::Scene;
use blackhole::units::{C, G};
use common::photon::Lens;
use common::{
    SceneText, assets, bin, case, delta_e, gpu, run, scene, shipped, small_scene_text, unit_mass,
};
use glam::Vec3;
use std::f64::consts::{PI, TAU};
use std::path::{Path, PathBuf};
use std::process::Command;

// The face-on view of the spoke tests: a camera SIZE px square, FOV
// degrees, at D r_s on the +z axis looking down on a disk of radius
// R_DISK r_s whose texture (TEX texels square) has one bright spoke of
// half-width WEDGE radians along +x. The field of view just holds the
// outermost measured ring (60 r_s at 0.87 of the half height).
const SIZE: u32 = 384;
const FOV: f64 = 8.0;
const D: f64 = 1000.0;
const R_DISK: f64 = 100.0;
const TEX: u32 = 512;
const WEDGE: f64 = 0.15;
/// Radii (r_s) at which the spoke is measured.
const RADII: [f64; 4] = [12.0, 20.0, 35.0, 60.0];

fn spoke_texture(dir: &Path) -> PathBuf {
    let p = dir.join("spoke.png");
    let texel = 2.0 * R_DISK / TEX as f64;
    // The texture square spans [-R, R]^2, +x to the right, +y up.
    image::RgbaImage::from_fn(TEX, TEX, |i, j| {
        let x = -R_DISK + (i as f64 + 0.5) * texel;
        let y = R_DISK - (j as f64 + 0.5) * texel;
        let v = if y.atan2(x).abs() < WEDGE { 255 } else { 0 };
        image::Rgba([v, v, v, 255])
    })
    .save(&p)
    .unwrap();
    p
}

fn spoke_scene(texture: &Path, model: &str, animation: &str) -> Scene {
    SceneText::new(SIZE, SIZE)
        .samples(4)
        .camera([0.0, 0.0, D], [0.0; 3], FOV)
        .up([0.0, 1.0, 0.0])
        .mass(unit_mass())
        .with(&format!("[physics]\nmodel = \"{model}\""))
        .with(&format!(
            "[disk]\nradius = {R_DISK:e}\ntexture = \"{}\"\nfilter = \"bilinear\"",
            texture.display()
        ))
        .with("[sky]\ncolor = [0.0, 0.0, 0.0]")
        .with(&format!(
            "[animation]\nframes = 1\nfps = 1.0\nduration = 1.0\n{animation}"
        ))
        .build()
}

/// The angle (counter-clockwise from +x, seen from +z) at which the
/// spoke's image crosses the ring where the camera sees disk radius `r`:
/// the brightness-weighted circular mean over pixels within a pixel of
/// that ring.
fn spoke_angle(px: &[Vec3], lens: Lens, r: f64) -> f64 {
    let alpha = lens.face_on(r, D).0;
    let ring = alpha.tan() / (FOV.to_radians() / 2.0).tan() * SIZE as f64 / 2.0;
    let (mut s, mut c) = (0.0, 0.0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            // Image right is +x, image up is +y.
            let dx = x as f64 + 0.5 - SIZE as f64 / 2.0;
            let dy = SIZE as f64 / 2.0 - (y as f64 + 0.5);
            if ((dx * dx + dy * dy).sqrt() - ring).abs() < 1.0 {
                let w = px[(y * SIZE + x) as usize].element_sum() as f64;
                let a = dy.atan2(dx);
                s += w * a.sin();
                c += w * a.cos();
            }
        }
    }
    assert!(c * c + s * s > 0.0, "no spoke on the ring at r = {r}");
    s.atan2(c)
}

/// `a - b` wrapped into (-pi, pi].
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// Renders `s` at `t` seconds (on the GPU when given) and checks the
/// spoke at every radius against `want(r)` (radians) to one texel.
fn check_spoke(
    s: &mut Scene,
    gpu: Option<&blackhole::gpu::Gpu>,
    lens: Lens,
    t: f64,
    want: impl Fn(f64) -> f64,
    what: &str,
) {
    s.set_time(t).unwrap();
    let film = match gpu {
        Some(g) => g.render(s, &|_| {}).unwrap().0,
        None => s.render(&|_| {}).0,
    };
    let px = film.linear_srgb();
    for r in RADII {
        let got = spoke_angle(&px, lens, r);
        let texel = 2.0 * R_DISK / TEX as f64 / r;
        let err = wrap(got - want(r));
        assert!(
            err.abs() < texel,
            "{what}, t = {t:e} s, r = {r}: spoke at {got:.4} rad, expected {:.4} (off {err:.4}, one texel {texel:.4})",
            wrap(want(r))
        );
    }
}

/// Omega(r) = sqrt(GM / r^3), per r_s/c.
fn omega(r: f64) -> f64 {
    (0.5 / (r * r * r)).sqrt()
}

/// Keplerian spokes in both models, on the CPU or the given GPU: after
/// tau = 123 r_s/c the ring at r has turned by Omega(r) tau (2.1 rad at
/// 12 r_s, 0.19 at 60); the spoke is measured where the model's own rays
/// see each radius.
fn keplerian_spokes(gpu: Option<&blackhole::gpu::Gpu>) {
    let tmp = tempfile::tempdir().unwrap();
    let tex = spoke_texture(tmp.path());
    for (model, lens) in [("gr", Lens::Gr), ("seed", Lens::Seed)] {
        let mut s = spoke_scene(&tex, model, "rotation = \"keplerian\"");
        check_spoke(&mut s, gpu, lens, 0.0, |_| 0.0, model);
        let tau = 123.0;
        check_spoke(&mut s, gpu, lens, tau / C, |r| omega(r) * tau, model);
    }
}

/// With light travel time, in both models: the camera at t sees the ring
/// at r as it was at t - dt(r), dt the travel time along the ray from
/// (r, 0) to the camera a quarter turn away (closed-form quadrature;
/// ~1005 r_s/c, of which ~5 is the Shapiro delay, itself 0.06 rad of turn
/// at 12 r_s: more than a texel).
fn delayed_spokes(gpu: Option<&blackhole::gpu::Gpu>) {
    let tmp = tempfile::tempdir().unwrap();
    let tex = spoke_texture(tmp.path());
    for (model, lens) in [("gr", Lens::Gr), ("seed", Lens::Seed)] {
        let mut s = spoke_scene(
            &tex,
            model,
            "rotation = \"keplerian\"\nlight_travel_time = true",
        );
        let tau = 1123.0;
        check_spoke(
            &mut s,
            gpu,
            lens,
            tau / C,
            |r| omega(r) * (tau - lens.face_on(r, D).1),
            &format!("{model}, light travel time"),
        );
    }
}

#[test]
fn keplerian_spokes_turn_by_omega_t_in_both_models() {
    keplerian_spokes(None);
}

#[test]
fn with_light_travel_time_each_ring_is_seen_as_it_was_when_its_light_left() {
    delayed_spokes(None);
}

#[test]
fn gpu_spokes_turn_like_the_cpus_with_and_without_travel_time() {
    let Some(gpu) = gpu() else { return };
    keplerian_spokes(Some(gpu));
    delayed_spokes(Some(gpu));
}

#[test]
fn rigid_spokes_turn_together_by_two_pi_t_over_the_period() {
    // period 1e-6 s; at t = 0.3e-6 s every ring has turned 0.6 pi; a
    // negative period turns the other way.
    let tmp = tempfile::tempdir().unwrap();
    let tex = spoke_texture(tmp.path());
    for period in [1e-6, -1e-6] {
        let mut s = spoke_scene(
            &tex,
            "gr",
            &format!("rotation = \"rigid\"\nperiod = {period:e}"),
        );
        let t = 0.3e-6;
        check_spoke(&mut s, None, Lens::Gr, t, |_| TAU * t / period, "rigid");
    }
}

/// A 64 x 64 face-on view of a scene with `body` (disk or volume) turning
/// rigidly with period 1e-6 s, at 0 and at t = 0.25e-6 s (a quarter
/// turn): the two images, in linear sRGB.
fn quarter_turn(body: &str, spectral: bool) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut s = SceneText::new(64, 64)
        .camera([0.0, 0.0, 60.0], [0.0; 3], 30.0)
        .up([0.0, 1.0, 0.0])
        .mass(unit_mass())
        .with(body)
        .with("[sky]\ncolor = [0.0, 0.0, 0.0]")
        .with(&format!(
            "[spectral]\nenabled = {spectral}\nwavelengths = 21"
        ))
        .with(
            "[animation]\nframes = 1\nfps = 1.0\nduration = 1.0\nrotation = \"rigid\"\nperiod = 1e-6",
        )
        .build();
    let before = s.render(&|_| {}).0.linear_srgb();
    s.set_time(0.25e-6).unwrap();
    let after = s.render(&|_| {}).0.linear_srgb();
    (before, after)
}

/// `after` is `before` turned a quarter counter-clockwise: with the camera
/// on the axis and one sample at each pixel's centre the pixel grid maps
/// onto itself, so pixel (x, y) now shows what pixel (63 - y, x) showed.
fn assert_quarter_turned(before: &[Vec3], after: &[Vec3], what: &str) {
    let mut lit = 0;
    for y in 0..64 {
        for x in 0..64 {
            let a = after[y * 64 + x];
            let b = before[x * 64 + (63 - y)];
            assert!(
                (a - b).abs().max_element() <= 1e-4 * b.max_element().max(1e-3),
                "{what}: pixel ({x}, {y}) {a} vs {b}"
            );
            lit += (b.max_element() > 1e-3) as usize;
        }
    }
    // The image has structure that a wrong turn would move.
    let moved = before
        .iter()
        .zip(after)
        .filter(|(b, a)| (**a - **b).abs().max_element() > 0.05 * b.max_element())
        .count();
    assert!(
        lit > 1000 && moved > 100,
        "{what}: {lit} lit, {moved} moved"
    );
}

#[test]
fn the_spectral_disk_set_and_the_volume_turn_like_the_texture() {
    let set = assets().join("disk_spectral/manifest.toml");
    let tex = assets().join("disk_rgba.png");
    let disk = format!(
        "[disk]\nradius = 12.0\nspectrum = \"{}\"\ntexture = \"{}\"",
        set.display(),
        tex.display()
    );
    let (b, a) = quarter_turn(&disk, true);
    assert_quarter_turned(&b, &a, "spectral disk set");
    let volume = "[volume]\ninner = 3.0\nouter = 12.0\nthickness = 0.5\nopacity = 2.0\n\
                  emission = 1.5\npeak_kelvin = 6000.0\nstep = 0.1\nseed = 3";
    let (b, a) = quarter_turn(volume, false);
    assert_quarter_turned(&b, &a, "volume");
}

#[test]
fn keyframes_are_hit_exactly_and_the_path_between_is_smooth() {
    let mut s = scene(&format!(
        r#"
        [image]
        width = 32
        height = 32
        png = "unused.png"
        [camera]
        position = [0.0, -50.0, 5.0]
        look_at = [0.0, 0.0, 0.0]
        fov = 40.0
        [black_hole]
        mass = {m:e}
        [sky]
        color = [0.0, 0.0, 0.0]
        [animation]
        frames = 10
        fps = 10.0
        duration = 1e-6
        [[animation.keyframe]]
        time = 0.0
        position = [0.0, -50.0, 5.0]
        look_at = [0.0, 0.0, 0.0]
        [[animation.keyframe]]
        time = 3e-7
        position = [40.0, -30.0, 10.0]
        look_at = [1.0, 0.0, 0.0]
        fov = 30.0
        [[animation.keyframe]]
        time = 7e-7
        position = [30.0, 30.0, 2.0]
        look_at = [0.0, 1.0, 0.0]
        up = [0.0, 0.1, 1.0]
        [[animation.keyframe]]
        time = 1e-6
        position = [-45.0, 10.0, 20.0]
        look_at = [0.0, 0.0, 0.0]
        "#,
        m = unit_mass(),
    ));
    let keys = match &s.animation.as_ref().unwrap().camera {
        CameraPath::Keyframes(k) => k.clone(),
        other => panic!("{other:?}"),
    };
    for (t, pose) in &keys {
        s.set_time(*t).unwrap();
        // Metres are r_s here: the camera sits exactly on the keyframe.
        assert_eq!(s.camera.position, pose.position, "t = {t}");
    }
    // C1: position and velocity continuous across each inner keyframe
    // (one-sided differences agree to their own truncation error).
    let pos = |s: &mut Scene, t: f64| {
        s.set_time(t).unwrap();
        s.camera.position
    };
    for (t, _) in &keys[1..keys.len() - 1] {
        let h = 1e-12;
        let p = pos(&mut s, *t);
        let left = (p - pos(&mut s, t - h)) / h;
        let right = (pos(&mut s, t + h) - p) / h;
        let scale = left.length().max(1.0);
        assert!(
            (left - right).length() < 1e-3 * scale,
            "t = {t}: velocity {left} before, {right} after"
        );
    }
    // Each key's view, and its fov where set ([camera]'s where not).
    for (i, (t, pose)) in keys.iter().enumerate() {
        s.set_time(*t).unwrap();
        let forward = (pose.look_at - pose.position).normalize();
        assert!(
            (s.camera.forward - forward).length() < 1e-12,
            "key {i}: {} vs {forward}",
            s.camera.forward
        );
        let fov = if i == 1 { 30.0f64 } else { 40.0 };
        let want = (fov.to_radians() / 2.0).tan();
        assert!((s.camera.half_height - want).abs() < 1e-12, "key {i}");
    }
}

// ---------------------------------------------------------------- CLI

/// A small animated scene (64 x 48, 4 frames) writing `out.png` beside
/// it, with extra `[animation]` keys.
fn animated_text(extra: &str) -> String {
    format!(
        r#"{}
[animation]
frames = 4
fps = 8.0
duration = 2000.0
light_travel_time = true
{extra}

[animation.orbit]
azimuth = [0.0, 40.0]
elevation = [10.0, 30.0]
distance = 2.2e11
"#,
        small_scene_text()
    )
}

fn frame(dir: &Path, k: u32) -> PathBuf {
    dir.join(format!("out_{k:05}.png"))
}

fn pixels(p: &Path) -> Vec<u8> {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgb8()
        .into_raw()
}

#[test]
fn frame_zero_is_the_render_and_time_renders_any_frame() {
    let dir = case(&animated_text(""));
    let d = dir.path();
    let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    let (code, err) = run(d, &["render", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(pixels(&d.join("out.png")), pixels(&frame(d, 0)));
    // Frame 2 is at t = 2 * 2000 / 4 s.
    let (code, err) = run(
        d,
        &[
            "render",
            "-q",
            "scene.toml",
            "--time",
            "1000",
            "--set",
            "image.png=t2.png",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(pixels(&d.join("t2.png")), pixels(&frame(d, 2)));
    // Frames differ: the camera moves and the disk turns.
    assert_ne!(pixels(&frame(d, 1)), pixels(&frame(d, 2)));
}

#[test]
fn slices_resume_and_thread_counts_give_the_bits_of_one_full_run() {
    let text = animated_text("video = \"out.gif\"");
    let full = case(&text);
    let (code, err) = run(
        full.path(),
        &["animate", "-q", "--threads", "3", "scene.toml"],
    );
    assert_eq!(code, 0, "{err}");

    let sliced = case(&text);
    let d = sliced.path();
    let (code, err) = run(
        d,
        &[
            "animate",
            "--threads",
            "1",
            "--frames",
            "0..1",
            "scene.toml",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("the video waits for 2 more frame(s)"), "{err}");
    assert!(!d.join("out.gif").exists());
    let (code, err) = run(d, &["animate", "-q", "--frames", "3..3", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    let stamp = std::fs::metadata(frame(d, 0)).unwrap().modified().unwrap();
    // The rest: only frame 2 is rendered, then the video.
    let (code, err) = run(d, &["animate", "--threads", "2", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("animated 1 frame(s) of 0..3 (3 already complete)"),
        "{err}"
    );
    assert_eq!(
        std::fs::metadata(frame(d, 0)).unwrap().modified().unwrap(),
        stamp
    );
    for k in 0..4 {
        assert_eq!(
            std::fs::read(frame(d, k)).unwrap(),
            std::fs::read(frame(full.path(), k)).unwrap(),
            "frame {k}"
        );
    }
    assert_eq!(gif_frames(&d.join("out.gif")), 4);
}

#[test]
fn an_interrupted_run_leaves_whole_frames_and_resumes() {
    let text = animated_text("").replace("frames = 4", "frames = 40");
    let dir = case(&text);
    let d = dir.path();
    let mut child = bin()
        .current_dir(d)
        .args(["animate", "-q", "--threads", "1", "scene.toml"])
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !frame(d, 1).exists() && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // Whatever frames exist are whole (written to a temporary file and
    // renamed).
    let done: Vec<u32> = (0..40).filter(|&k| frame(d, k).exists()).collect();
    assert!(!done.is_empty() && done.len() < 40, "{done:?}");
    for &k in &done {
        assert_eq!(image::image_dimensions(frame(d, k)).unwrap(), (64, 48));
    }
    let (code, err) = run(d, &["animate", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("already complete")
            && err.contains(&format!("animated {} frame(s)", 40 - done.len())),
        "{err}"
    );
    // The resumed frames are those of an uninterrupted run.
    let full = case(&text);
    let (code, err) = run(
        full.path(),
        &["animate", "-q", "--frames", "0..3", "scene.toml"],
    );
    assert_eq!(code, 0, "{err}");
    for k in 0..4 {
        assert_eq!(
            pixels(&frame(d, k)),
            pixels(&frame(full.path(), k)),
            "frame {k}"
        );
    }
}

fn gif_frames(p: &Path) -> usize {
    use image::AnimationDecoder;
    let f = std::io::BufReader::new(std::fs::File::open(p).unwrap());
    image::codecs::gif::GifDecoder::new(f)
        .unwrap()
        .into_frames()
        .map(|f| {
            let f = f.unwrap();
            assert_eq!(f.buffer().dimensions(), (64, 48));
            // 8 fps: 12.5 centiseconds, rounded to GIF's hundredths.
            let (num, den) = f.delay().numer_denom_ms();
            assert!(
                (num as f64 / den as f64 - 125.0).abs() <= 5.0,
                "{num}/{den} ms"
            );
        })
        .count()
}

#[test]
fn gif_and_animated_png_videos_hold_every_frame() {
    for name in ["out.gif", "out.png.apng.png"] {
        let dir = case(&animated_text(&format!("video = \"{name}\"")));
        let (code, err) = run(dir.path(), &["animate", "-q", "scene.toml"]);
        assert_eq!(code, 0, "{err}");
        let video = dir.path().join(name);
        if name.ends_with(".gif") {
            assert_eq!(gif_frames(&video), 4);
            continue;
        }
        let mut dec = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&video).unwrap(),
        ))
        .read_info()
        .unwrap();
        let ctl = dec.info().animation_control().copied().unwrap();
        assert_eq!(ctl.num_frames, 4);
        let mut buf = vec![0; dec.output_buffer_size().unwrap()];
        let mut n = 0;
        let mut first = None;
        while let Ok(info) = dec.next_frame(&mut buf) {
            assert_eq!((info.width, info.height), (64, 48));
            first.get_or_insert_with(|| buf[..info.buffer_size()].to_vec());
            n += 1;
        }
        assert_eq!(n, 4);
        // Lossless: the first frame is frame 0's pixels.
        assert_eq!(first.unwrap(), pixels(&frame(dir.path(), 0)));
    }
}

/// Whether `program` runs; with `CI` set its absence fails the test.
fn have(program: &str) -> bool {
    let ok = Command::new(program)
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    common::available(ok.then_some(()).ok_or(format!(
        "{program} is not installed (apt-get install ffmpeg)"
    )))
}

#[test]
fn mp4_through_ffmpeg_decodes_to_every_frame() {
    if !have("ffmpeg") || !have("ffprobe") {
        return;
    }
    let dir = case(&animated_text("video = \"out.mp4\"\nquality = 18"));
    let (code, err) = run(dir.path(), &["animate", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=nb_read_frames,width,height,codec_name,pix_fmt,r_frame_rate",
        ])
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(dir.path().join("out.mp4"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    for want in [
        "codec_name=h264",
        "pix_fmt=yuv420p",
        "width=64",
        "height=48",
        "r_frame_rate=8/1",
        "nb_read_frames=4",
    ] {
        assert!(text.lines().any(|l| l == want), "{want} not in:\n{text}");
    }
}

#[test]
fn mp4_without_ffmpeg_is_refused_before_any_frame() {
    let dir = case(&animated_text("video = \"out.mp4\""));
    let out = bin()
        .current_dir(dir.path())
        .env("PATH", "")
        .args(["animate", "-q", "scene.toml"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("animation.video") && err.contains("ffmpeg"),
        "{err}"
    );
    assert!(!frame(dir.path(), 0).exists());
}

#[test]
fn frames_alone_are_rendered_without_ffmpeg() {
    let dir = case(&animated_text("video = \"out.mp4\""));
    let d = dir.path();
    let without_ffmpeg = |args: &[&str]| {
        let out = bin()
            .current_dir(d)
            .env("PATH", "")
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        (out.status.code(), err)
    };
    // --no-video renders the frames only: the encoder is not asked for.
    let (code, err) = without_ffmpeg(&[
        "animate",
        "-q",
        "--no-video",
        "scene.toml",
        "--frames",
        "0..1",
    ]);
    assert_eq!(code, Some(0), "{err}");
    assert!(frame(d, 1).exists() && !d.join("out.mp4").exists());
    // A slice that leaves frames missing makes no video either.
    let (code, err) = without_ffmpeg(&["animate", "-q", "scene.toml", "--frames", "2..2"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(frame(d, 2).exists() && !frame(d, 3).exists());
    // The slice that completes the set makes the video: there ffmpeg is
    // needed, and asked for before the frame is rendered.
    let (code, err) = without_ffmpeg(&["animate", "-q", "scene.toml", "--frames", "3..3"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("animation.video") && err.contains("ffmpeg"),
        "{err}"
    );
    assert!(!frame(d, 3).exists());
}

/// The animated scene with its orbit replaced by `keys` (TOML).
fn keyframed_text(keys: &str) -> String {
    let text = animated_text("");
    let cut = text.find("[animation.orbit]").unwrap();
    format!("{}{keys}", &text[..cut])
}

#[test]
fn bad_animations_are_named_before_anything_renders() {
    let base = animated_text("");
    let edit = |from: &str, to: &str| {
        assert!(base.contains(from));
        base.replace(from, to)
    };
    let key = |t: f64, x: f64| {
        format!(
            "[[animation.keyframe]]\ntime = {t:?}\nposition = [{x:e}, -1.0e10, 0.0]\nlook_at = [0.0, 0.0, 0.0]\n"
        )
    };
    let cases: Vec<(String, &[&str], &[&str])> = vec![
        (
            edit("frames = 4", "frames = 0"),
            &[],
            &["animation.frames", "0", "1 to 1000000"],
        ),
        (
            edit("frames = 4", "frames = 5000000"),
            &[],
            &["animation.frames", "5000000"],
        ),
        (
            edit("fps = 8.0", "fps = 0.0"),
            &[],
            &["animation.fps", "0 < fps"],
        ),
        (
            edit("fps = 8.0", "fps = -24.0"),
            &[],
            &["animation.fps", "-24"],
        ),
        (
            edit("duration = 2000.0", "duration = -5.0"),
            &[],
            &["animation.duration", "-5"],
        ),
        (
            animated_text("rotation = \"rigid\""),
            &[],
            &["animation.period", "rigid"],
        ),
        (
            animated_text("period = 100.0"),
            &[],
            &["animation.period", "Keplerian"],
        ),
        (
            animated_text("video = \"out.avi\""),
            &[],
            &["animation.video", ".mp4"],
        ),
        (animated_text("spin = 1.0"), &[], &["spin"]),
        (
            edit("distance = 2.2e11", "distance = 1.0e10"),
            &[],
            &["animation.orbit.distance", "horizon"],
        ),
        (
            keyframed_text(&format!(
                "{}{}{}",
                key(0.0, -2.2e11),
                key(1000.0, 1.5e11),
                key(500.0, 2.2e11)
            )),
            &[],
            &["animation.keyframe[2].time", "increasing"],
        ),
        (
            // Straight through the hole at t = 900 s, between frames 1 and 2.
            keyframed_text(
                &format!("{}{}", key(0.0, -2.2e11), key(1800.0, 2.2e11)).replace("-1.0e10", "0.0"),
            ),
            &[],
            &["animation.keyframe", "inside the horizon", "t = 871.875 s"],
        ),
        (
            format!("{}{}", base, key(0.0, -2.2e11)),
            &[],
            &["animation.orbit", "choose one camera path"],
        ),
        (
            keyframed_text("keyframe = []\n"),
            &[],
            &["animation.keyframe = []", "one or more"],
        ),
        (
            // Angles whose sine has lost all precision.
            edit("azimuth = [0.0, 40.0]", "azimuth = [1e308, -1e308]"),
            &[],
            &["animation.orbit.azimuth = [1e308, -1e308]", "degrees"],
        ),
        (
            base.clone(),
            &["--frames", "2..9"],
            &["--frames 2..9", "4 frames"],
        ),
    ];
    for (text, args, needles) in cases {
        let dir = case(&text);
        let mut all = vec!["animate", "scene.toml"];
        all.extend_from_slice(args);
        let (code, err) = run(dir.path(), &all);
        assert_eq!(code, 1, "{args:?}: {err}\n{text}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: message lacks {n:?}:\n{err}");
        }
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "wrote something:\n{text}"
        );
    }
    // A malformed slice is a usage error; --time needs an [animation].
    let dir = case(&base);
    let (code, err) = run(dir.path(), &["animate", "scene.toml", "--frames", "3..1"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("3..1") && err.contains("comes after"), "{err}");
    let dir = case(&base[..base.find("[animation]").unwrap()]);
    let (code, err) = run(dir.path(), &["render", "scene.toml", "--time", "5"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--time") && err.contains("[animation]"),
        "{err}"
    );
    let (code, err) = run(dir.path(), &["animate", "scene.toml"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("[animation]"), "{err}");
}

#[test]
fn gpu_frames_of_one_prepared_scene_are_fresh_renders_and_match_the_cpu() {
    // The animate command prepares the GPU once and moves it from frame
    // to frame; each frame must be what a fresh GPU render of that
    // instant gives, and close to the CPU's. The planets scene adds the
    // disk's turning light on lit objects.
    let Some(gpu) = gpu() else { return };
    let planets = [
        "animation.frames=8",
        "animation.fps=8.0",
        "animation.duration=3000.0",
        "animation.light_travel_time=true",
    ];
    for (name, extra, frames) in [
        ("orbit", &[][..], [50, 10, 71]),
        ("planets", &planets[..], [5, 1, 7]),
    ] {
        let mut s = shipped(name, 96, 54, extra);
        let a = s.animation.clone().unwrap();
        let mut prepared = gpu.prepare(&s, u32::MAX).unwrap();
        // Out of order: frames do not depend on each other.
        for k in frames {
            s.set_time(a.time(k)).unwrap();
            prepared.set_frame(&s).unwrap();
            let (framed, stats) = prepared.render(&|_| {}).unwrap();
            let fresh = gpu.render(&s, &|_| {}).unwrap().0;
            assert!(framed.xyz == fresh.xyz, "{name} frame {k}");
            let cpu = s.render(&|_| {}).0;
            let (mean, p99, _) = delta_e(&s, &cpu, &framed);
            assert!(
                mean < 0.5 && p99 < 2.0,
                "{name} frame {k}: mean {mean}, p99 {p99}"
            );
            assert_eq!(stats.non_finite, 0);
        }
    }
}

#[test]
fn gpu_frames_have_the_same_bits_whichever_job_renders_them() {
    if gpu().is_none() {
        return;
    }
    let text = animated_text("");
    let (a, b) = (case(&text), case(&text));
    let (code, err) = run(
        a.path(),
        &["animate", "-q", "--backend", "gpu", "scene.toml"],
    );
    assert_eq!(code, 0, "{err}");
    for slice in ["2..3", "0..1"] {
        let (code, err) = run(
            b.path(),
            &[
                "animate",
                "-q",
                "--backend",
                "gpu",
                "--frames",
                slice,
                "scene.toml",
            ],
        );
        assert_eq!(code, 0, "{err}");
    }
    for k in 0..4 {
        assert_eq!(
            std::fs::read(frame(a.path(), k)).unwrap(),
            std::fs::read(frame(b.path(), k)).unwrap(),
            "frame {k}"
        );
    }
}

#[test]
fn info_reports_the_animation_and_its_files() {
    let dir = case(&animated_text("video = \"out.gif\""));
    let out = bin()
        .current_dir(dir.path())
        .args(["info", "scene.toml"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // 2000 s over 4 frames; r_s / c = 42.37 s for this mass.
    let r_s = 2.0 * G * 8.57e36 / (C * C);
    let per_frame = 500.0 * C / r_s;
    for want in [
        "4 frames at 8 fps (0.50 s of video); t = 0 to 1500 s".to_string(),
        format!("{per_frame:.4} r_s/c per frame; light travel time on"),
        "Keplerian: per frame".into(),
        "orbit at 2.200000e11 m".into(),
        "out_00000.png to ".into(),
        "out_00003.png".into(),
        "out.gif".into(),
    ] {
        assert!(text.contains(&want), "{want:?} not in:\n{text}");
    }
    // The ring at the disk's outer edge (10 r_s) turns Omega t per frame.
    let deg = (0.5f64 / 1000.0).sqrt() * per_frame * 180.0 / PI;
    assert!(
        text.contains(&format!("{deg:.3} deg at 10.000 r_s")),
        "{deg}\n{text}"
    );
}

/// `animate` (or any command) in `dir` with `args` under a limit of
/// `bytes` on the size of any file it or its children write (SIGXFSZ
/// ignored, so a write past it fails as on a full disk).
fn run_with_file_limit(dir: &Path, args: &[&str], bytes: u64) -> (i32, String) {
    let mut cmd = bin();
    cmd.current_dir(dir).args(args);
    // SAFETY: setrlimit and signal between fork and exec touch only the child.
    unsafe {
        std::os::unix::process::CommandExt::pre_exec(&mut cmd, move || {
            let lim = libc::rlimit {
                rlim_cur: bytes,
                rlim_max: bytes,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            Ok(())
        });
    }
    let out = cmd.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Temporary files left in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn an_mp4_that_cannot_be_finished_is_an_error_and_leaves_nothing() {
    if !have("ffmpeg") || !have("ffprobe") {
        return;
    }
    let text = animated_text("video = \"out.mp4\"").replace("frames = 4", "frames = 24");
    let dir = case(&text);
    let d = dir.path();
    let (code, err) = run(d, &["animate", "-q", "--no-video", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    // The frames are there; the video cannot grow past 4 KiB, as on a
    // full disk, where ffmpeg can still end with status 0.
    let (code, err) = run_with_file_limit(d, &["animate", "scene.toml"], 4096);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("out.mp4") && err.contains("ffmpeg"), "{err}");
    // ffmpeg's own words; no success status beside them.
    assert!(!err.contains("exit status: 0"), "{err}");
    assert!(!err.contains("->"), "no video reported: {err}");
    assert!(!d.join("out.mp4").exists());
    assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
    // With room, the same run makes it, readable and as readable as
    // the frames (one file mode for all outputs).
    let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    use std::os::unix::fs::PermissionsExt;
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&d.join("out.mp4")), mode(&frame(d, 0)));
    assert!(mode(&d.join("out.mp4")) & 0o044 != 0);
}

#[test]
fn a_full_disk_between_the_png_and_the_exr_leaves_the_old_pair() {
    let text =
        small_scene_text().replace("png = \"out.png\"", "png = \"out.png\"\nexr = \"out.exr\"");
    let dir = case(&text);
    let d = dir.path();
    let (code, err) = run(d, &["render", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    let (png, exr) = (
        std::fs::read(d.join("out.png")).unwrap(),
        std::fs::read(d.join("out.exr")).unwrap(),
    );
    assert!(
        png.len() < 20_000 && exr.len() > 20_000,
        "{} {}",
        png.len(),
        exr.len()
    );
    // Another exposure: the new PNG fits under 20 kB, the EXR does not.
    let (code, err) = run_with_file_limit(
        d,
        &["render", "-q", "scene.toml", "--set", "image.exposure=1.0"],
        20_000,
    );
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("out.exr"), "{err}");
    assert_eq!(err.lines().count(), 1, "one error, said once: {err}");
    assert_eq!(
        std::fs::read(d.join("out.png")).unwrap(),
        png,
        "the PNG was replaced"
    );
    assert_eq!(std::fs::read(d.join("out.exr")).unwrap(), exr);
    assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
}

/// The pids of `pid`'s children.
fn children(pid: u32) -> Vec<u32> {
    std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"))
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|p| p.parse().ok())
        .collect()
}

/// Whether process `pid` is running (not gone, not a zombie).
fn alive(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/status")).is_ok_and(|s| {
        !s.lines()
            .any(|l| l.starts_with("State:") && l.contains('Z'))
    })
}

/// Waits up to `secs` seconds for `done`.
fn wait_for(secs: f64, mut done: impl FnMut() -> bool) -> bool {
    let t0 = std::time::Instant::now();
    while t0.elapsed().as_secs_f64() < secs {
        if done() {
            return true;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    done()
}

#[test]
fn signals_remove_temporaries_and_stop_the_encoder() {
    use std::os::unix::fs::PermissionsExt;
    // A stand-in for ffmpeg that answers -version and then takes its time,
    // so that the encoder is caught running.
    let tools = tempfile::tempdir().unwrap();
    let fake = tools.path().join("ffmpeg");
    std::fs::write(
        &fake,
        "#!/bin/sh\n[ \"$1\" = -version ] && { echo fake; exit 0; }\nexec sleep 60\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!(
        "{}:{}",
        tools.path().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let dir = case(&animated_text("video = \"out.mp4\""));
    let d = dir.path();
    let (code, err) = run(d, &["animate", "-q", "--no-video", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    for (signal, cleaned) in [(libc::SIGTERM, true), (libc::SIGKILL, false)] {
        let mut child = bin()
            .current_dir(d)
            .env("PATH", &path)
            .args(["animate", "-q", "scene.toml"])
            .spawn()
            .unwrap();
        let pid = child.id();
        assert!(
            wait_for(30.0, || !children(pid).is_empty()),
            "no encoder started"
        );
        let encoder = children(pid)[0];
        assert!(
            wait_for(10.0, || temporaries(d).len() >= 2),
            "{:?}",
            temporaries(d)
        );
        // SAFETY: signals our own child.
        unsafe { libc::kill(pid as i32, signal) };
        let status = child.wait().unwrap();
        assert_eq!(
            std::os::unix::process::ExitStatusExt::signal(&status),
            Some(signal)
        );
        // The encoder goes with us, however we go.
        assert!(
            wait_for(10.0, || !alive(encoder)),
            "signal {signal}: the encoder {encoder} outlived us"
        );
        assert!(!d.join("out.mp4").exists());
        if cleaned {
            assert!(
                temporaries(d).is_empty(),
                "SIGTERM left {:?}",
                temporaries(d)
            );
        } else {
            assert!(!temporaries(d).is_empty(), "SIGKILL cannot clean up");
        }
    }
    // The next run that writes the video removes what the killed one left.
    let (code, err) = run(
        d,
        &[
            "animate",
            "-q",
            "--no-video",
            "scene.toml",
            "--overwrite",
            "--frames",
            "0..0",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let before = temporaries(d);
    assert!(!before.is_empty());
    if have("ffmpeg") {
        let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
        assert_eq!(code, 0, "{err}");
        assert!(temporaries(d).is_empty(), "{:?} stayed", temporaries(d));
    }
}

#[test]
fn a_signal_during_a_render_leaves_neither_image() {
    let text = small_scene_text().replace(
        "png = \"out.png\"",
        "png = \"out.png\"\nexr = \"out.exr\"\nexr_xyz = true",
    );
    let dir = case(&text);
    let d = dir.path();
    let mut child = bin()
        .current_dir(d)
        .args([
            "render",
            "-q",
            "scene.toml",
            "--set",
            "image.width=2048",
            "--set",
            "image.height=2048",
        ])
        .spawn()
        .unwrap();
    // The EXR is written after the PNG, both to temporaries.
    let exr_started = || temporaries(d).iter().any(|n| n.starts_with(".out.exr."));
    assert!(wait_for(120.0, exr_started), "{:?}", temporaries(d));
    // SAFETY: signals our own child.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = child.wait().unwrap();
    assert_eq!(
        std::os::unix::process::ExitStatusExt::signal(&status),
        Some(libc::SIGTERM)
    );
    assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
    assert!(!d.join("out.png").exists() && !d.join("out.exr").exists());
}

#[test]
fn stale_exr_frames_bad_rates_and_unwritable_videos_are_named_first() {
    // A frame's EXR from another frame is not taken for it.
    let dir = case(
        &animated_text("").replace("png = \"out.png\"", "png = \"out.png\"\nexr = \"out.exr\""),
    );
    let d = dir.path();
    let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
    assert_eq!(code, 0, "{err}");
    std::fs::copy(d.join("out_00003.exr"), d.join("out_00002.exr")).unwrap();
    let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("out_00002.exr is not frame 2"), "{err}");
    // Rates a container cannot hold, and a video folder that cannot be
    // written, before any frame.
    for (video, extra, needle) in [
        ("out.gif", "fps = 1000.0", "0.01 to 655.35 s"),
        ("out.png.apng.png", "fps = 1e-9", "1/65535 to 65535 s"),
        ("blocked/out.gif", "", "cannot create folder"),
    ] {
        let text = animated_text(&format!("video = \"{video}\"")).replace(
            "fps = 8.0",
            if extra.is_empty() { "fps = 8.0" } else { extra },
        );
        let dir = case(&text);
        let d = dir.path();
        std::fs::write(d.join("blocked"), "a file, not a folder").unwrap();
        let (code, err) = run(d, &["animate", "-q", "scene.toml"]);
        assert_eq!(code, 1, "{video}: {err}");
        assert!(err.contains(needle), "{video}: {err}");
        assert!(!frame(d, 0).exists(), "{video}: a frame was rendered first");
    }
}

#[test]
fn times_whose_disk_angle_is_lost_are_refused_by_name() {
    let dir = case(&animated_text(""));
    let d = dir.path();
    for (args, needle) in [
        (
            vec!["render", "scene.toml", "--time", "1e300"],
            "--time = 1e300",
        ),
        (
            vec!["render", "scene.toml", "--set", "animation.start=1e14"],
            "animation.start = 100000000000000.0",
        ),
        (
            vec!["animate", "scene.toml", "--set", "animation.duration=1e14"],
            "animation.duration",
        ),
    ] {
        let (code, err) = run(d, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains(needle) && err.contains("cannot be computed"),
            "{args:?}: {err}"
        );
    }
    assert!(!d.join("out.png").exists());
    // Far but fine on the CPU.
    let (code, err) = run(d, &["render", "-q", "scene.toml", "--time", "1e9"]);
    assert_eq!(code, 0, "{err}");
}
