//! The `blackhole` binary: bad input fails with a message naming the problem
//! and writes nothing; good input writes the image it names.

mod common;

use common::assets;
use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_blackhole"))
}

/// A small valid scene whose output goes to `out.png` beside it.
fn scene_text() -> String {
    format!(
        r#"[image]
width = 64
height = 48
png = "out.png"

[camera]
position = [0.0, -2.2e11, 3.0e10]
look_at = [0.0, 0.0, 0.0]
fov = 55.0

[black_hole]
mass = 8.57e36

[disk]
radius = 10.0
texture = "{}"

[sky]
texture = "{}"
"#,
        assets().join("disk_rgba.png").display(),
        assets().join("sky.png").display()
    )
}

struct Case {
    dir: tempfile::TempDir,
}

impl Case {
    fn new(text: &str) -> Case {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), text).unwrap();
        Case { dir }
    }
    fn config(&self) -> PathBuf {
        self.dir.path().join("scene.toml")
    }
    /// Runs `render` with extra arguments; returns (success, stderr).
    fn render(&self, args: &[&str]) -> (bool, String) {
        let out = bin()
            .arg("render")
            .arg("-q")
            .arg(self.config())
            .args(args)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }
    fn output_exists(&self) -> bool {
        self.dir.path().join("out.png").exists()
    }
    /// Nothing but the scene file is left in the folder.
    fn untouched(&self) -> bool {
        std::fs::read_dir(self.dir.path()).unwrap().count() == 1
    }
}

fn fails_with(text: &str, args: &[&str], needles: &[&str]) {
    let case = Case::new(text);
    let (ok, err) = case.render(args);
    assert!(!ok, "should fail: {text}");
    for n in needles {
        assert!(err.contains(n), "message lacks {n:?}:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!case.output_exists() && case.untouched(), "wrote something");
}

#[test]
fn valid_scene_renders_with_relative_output_path() {
    let case = Case::new(&scene_text());
    let (ok, err) = case.render(&[]);
    assert!(ok, "{err}");
    let img = image::open(case.dir.path().join("out.png")).unwrap();
    assert_eq!((img.width(), img.height()), (64, 48));
}

#[test]
fn overrides_change_values_and_cli_paths_are_relative_to_cwd() {
    let case = Case::new(&scene_text());
    let cwd = tempfile::tempdir().unwrap();
    let out = bin()
        .current_dir(cwd.path())
        .args(["render", "-q"])
        .arg(case.config())
        .args(["--set", "image.width=32", "--set", "image.png=here.png"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let img = image::open(cwd.path().join("here.png")).unwrap();
    assert_eq!(img.width(), 32);
    assert!(!case.output_exists());
}

#[test]
fn unknown_key_is_named() {
    let text = scene_text().replace("fov = 55.0", "fov = 55.0\nzoom = 2.0");
    fails_with(&text, &[], &["unknown field `zoom`", "line 10"]);
}

#[test]
fn toml_syntax_error_has_line_and_column() {
    let text = scene_text().replace("width = 64", "width = 64 64");
    fails_with(&text, &[], &["scene.toml", "line 2, column"]);
}

#[test]
fn missing_texture_is_named() {
    let text = scene_text().replace("disk_rgba.png", "no_such_disk.png");
    fails_with(&text, &[], &["disk.texture", "no_such_disk.png"]);
}

#[test]
fn undecodable_texture_is_named() {
    let case_dir = tempfile::tempdir().unwrap();
    let bad = case_dir.path().join("bad.png");
    std::fs::write(&bad, b"not a png").unwrap();
    let text = scene_text().replace(
        &assets().join("sky.png").display().to_string(),
        &bad.display().to_string(),
    );
    fails_with(&text, &[], &["sky.texture", "bad.png"]);
}

#[test]
fn negative_mass_is_named() {
    let text = scene_text().replace("mass = 8.57e36", "mass = -1.0e30");
    fails_with(&text, &[], &["black_hole.mass", "positive"]);
}

#[test]
fn camera_inside_horizon_is_named() {
    let text = scene_text().replace(
        "position = [0.0, -2.2e11, 3.0e10]",
        "position = [0.0, -1.0e10, 0.0]",
    );
    fails_with(&text, &[], &["camera.position", "inside the horizon"]);
}

#[test]
fn bad_values_are_named() {
    fails_with(
        &scene_text(),
        &["--set", "camera.fov=180"],
        &["camera.fov", "between 0 and 180"],
    );
    fails_with(&scene_text(), &["--set", "image.width=0"], &["image.width"]);
    fails_with(
        &scene_text(),
        &[
            "--set",
            "camera.up=[0.0, 1.0, 0.0]",
            "--set",
            "camera.position=[0.0, -2.2e11, 0.0]",
        ],
        &["camera.up"],
    );
    fails_with(
        &scene_text(),
        &["--set", "sky.color=[1.0, 1.0, 1.0]"],
        &["exactly one of"],
    );
    fails_with(
        &scene_text(),
        &["--set", "disk.radius=0.5"],
        &["disk.radius"],
    );
    fails_with(
        &scene_text(),
        &["--set", "image.png=out.jpg"],
        &["image.png", ".png"],
    );
}

#[test]
fn override_type_errors_are_named() {
    fails_with(
        &scene_text(),
        &["--set", "image.width=wide"],
        &["image.width", "invalid type"],
    );
    fails_with(
        &scene_text(),
        &["--set", "image.zoom=2"],
        &["unknown field `zoom`"],
    );
    fails_with(&scene_text(), &["--set", "image"], &["key=value"]);
}

#[test]
fn oversized_render_is_refused_before_allocating() {
    fails_with(
        &scene_text(),
        &[
            "--set",
            "image.width=65535",
            "--set",
            "image.height=65535",
            "--set",
            "image.samples=1",
        ],
        &["image.width x image.height", "gigapixel"],
    );
}

#[test]
fn info_reports_derived_quantities() {
    let case = Case::new(&scene_text());
    let out = bin().arg("info").arg(case.config()).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    // r_s = 2GM/c^2 for 8.57e36 kg.
    assert!(text.contains("1.272787e10 m"), "{text}");
    assert!(text.contains("shadow angular radius"), "{text}");
    assert!(case.untouched());
}

#[test]
fn table_overrides_resolve_paths_against_the_current_directory() {
    // `--set 'image={...}'` sets image.png from the command line too.
    let case = Case::new(&scene_text());
    let cwd = tempfile::tempdir().unwrap();
    let out = bin()
        .current_dir(cwd.path())
        .args(["render", "-q"])
        .arg(case.config())
        .args(["--set", r#"image={width=16, height=8, png="t.png"}"#])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(cwd.path().join("t.png").exists());
    assert!(!case.dir.path().join("t.png").exists());
}

#[test]
fn unwritable_output_fails_before_rendering() {
    // The output's folder would be below a regular file.
    let case = Case::new(&scene_text());
    std::fs::write(case.dir.path().join("file"), b"x").unwrap();
    let target = case.dir.path().join("file").join("out.png");
    let (ok, err) = case.render(&["--set", &format!("image.png={}", target.display())]);
    assert!(!ok);
    assert!(err.contains("cannot create folder"), "{err}");
    assert!(!err.contains("rendered"), "{err}");
}

#[test]
fn output_may_not_overwrite_an_input() {
    let tex = assets().join("disk_rgba.png").display().to_string();
    fails_with(
        &scene_text(),
        &["--set", &format!("image.png={tex}")],
        &["image.png", "also an input"],
    );
}

#[test]
fn compare_writes_both_renders_the_map_and_a_summary() {
    let text = scene_text()
        .replacen("texture = \"", "spectrum = \"MANIFEST\"\ntexture = \"", 1)
        .replace(
            "MANIFEST",
            &assets()
                .join("disk_spectral/manifest.toml")
                .display()
                .to_string(),
        )
        + "\n[spectral]\nenabled = true\nwavelengths = 21\n";
    let case = Case::new(&text);
    let out = bin()
        .args(["compare", "-q"])
        .arg(case.config())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        summary.contains("CIEDE2000") && summary.contains("g from"),
        "{summary}"
    );
    for f in [
        "out_shift_off.png",
        "out_shift_on.png",
        "out_shift_off.exr",
        "out_shift_on.exr",
        "out_side_by_side.png",
        "out_delta_e.png",
        "out_summary.txt",
    ] {
        assert!(case.dir.path().join(f).exists(), "{f} missing");
    }
    let sbs = image::open(case.dir.path().join("out_side_by_side.png")).unwrap();
    assert!(sbs.width() > 2 * 64);
}

#[test]
fn compare_refuses_an_rgb_scene() {
    let case = Case::new(&scene_text());
    let out = bin()
        .args(["compare", "-q"])
        .arg(case.config())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("spectral"));
    assert!(case.untouched());
}

#[test]
fn stereo_writes_both_eyes_beside_the_mono_image() {
    let text = scene_text() + "\n[stereo]\nseparation = 1.0e10\n";
    let case = Case::new(&text);
    let (ok, err) = case.render(&[]);
    assert!(ok, "{err}");
    for f in [
        "out.png",
        "out_left.png",
        "out_right.png",
        "out_anaglyph.png",
    ] {
        let img = image::open(case.dir.path().join(f)).unwrap();
        assert_eq!((img.width(), img.height()), (64, 48), "{f}");
    }
    let sbs = image::open(case.dir.path().join("out_side_by_side.png")).unwrap();
    assert_eq!((sbs.width(), sbs.height()), (128, 48));
    // The eyes see different images.
    let l = image::open(case.dir.path().join("out_left.png"))
        .unwrap()
        .to_rgb8();
    let r = image::open(case.dir.path().join("out_right.png"))
        .unwrap()
        .to_rgb8();
    assert_ne!(l, r);
}

#[test]
fn stereo_eye_inside_the_horizon_is_named() {
    // The camera looks along +x at 1.57 r_s; its right eye, 1.5e10 m along
    // +y, lands 0.39 r_s from the hole.
    let text = scene_text()
        .replace(
            "position = [0.0, -2.2e11, 3.0e10]",
            "position = [0.0, -2.0e10, 0.0]",
        )
        .replace(
            "look_at = [0.0, 0.0, 0.0]",
            "look_at = [1.0e11, -2.0e10, 0.0]",
        )
        + "\n[stereo]\nseparation = 3.0e10\n";
    fails_with(
        &text,
        &[],
        &["stereo.separation", "eye", "inside the horizon"],
    );
}
