//! Helpers shared by the integration tests (each test crate uses a part).
#![allow(dead_code)]

use blackhole::config::{Override, SceneConfig};
use blackhole::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

pub mod lens;
pub mod photon;

/// The black hole of the shipped scenes (kg; r_s = 1.27e10 m).
pub const MASS: f64 = 8.57e36;

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).to_path_buf()
}

/// The shipped assets.
pub fn assets() -> PathBuf {
    root().join("spectral_assets")
}

/// A scene from TOML text, which must be valid. The tests' scenes sample
/// uniformly unless they say `image.adaptive` (the renderer's default is
/// adaptive sampling): what they check is not its choice of pixels.
pub fn scene(toml: &str) -> Scene {
    let mut cfg: SceneConfig = toml::from_str(toml).unwrap_or_else(|e| panic!("{e}\n{toml}"));
    cfg.image.adaptive.get_or_insert(false);
    Scene::build(cfg).unwrap()
}

/// The shared GPU, or None (with the reason printed) where there is none
/// and `CI` is not set. It takes the closed form wherever a scene allows
/// it, as hardware GPUs do by default, also on lavapipe (whose default is
/// the integrator): the tests check the path that GPUs ship.
pub fn gpu() -> Option<&'static blackhole::gpu::Gpu> {
    static GPU: OnceLock<Result<blackhole::gpu::Gpu, String>> = OnceLock::new();
    let open = || {
        quick_shader_compiles();
        let mut g = blackhole::gpu::Gpu::new().map_err(|e| e.to_string())?;
        g.set_closed_form(true);
        Ok(g)
    };
    match GPU.get_or_init(open) {
        Ok(g) => Some(g),
        Err(e) => {
            available(Err(format!("there is no GPU adapter ({e})")));
            None
        }
    }
}

/// Lavapipe (the software Vulkan the tests run on without a GPU) compiles
/// shaders without LLVM's optimisation passes: the tests' images are small
/// and their shader variants many, so compiling is most of their time
/// (gpu.rs: 230 s cold with the passes, 170 s without), and pixels agree
/// with the CPU's as closely. Hardware drivers ignore the variable; one a
/// user sets is kept.
const LAVAPIPE_FLAGS: (&str, &str) = ("GALLIVM_PERF", "nopt");

/// Sets [`LAVAPIPE_FLAGS`] in this process, for its GPU opens and the
/// children it starts, once and before its first GPU open.
pub fn quick_shader_compiles() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let (key, value) = LAVAPIPE_FLAGS;
        if std::env::var_os(key).is_none() {
            // SAFETY: Rust readers of the environment take the lock this
            // write takes; the environment's C readers in a test process
            // are the Vulkan loader and driver, loaded by a GPU open, and
            // every GPU open of the tests comes after this (`gpu`).
            unsafe { std::env::set_var(key, value) };
        }
    });
}

/// Per-pixel CIEDE2000 between two films as displayed with the scene's
/// exposure and tone curve: (mean, 99th percentile, max).
pub fn delta_e(s: &Scene, a: &blackhole::film::Film, b: &blackhole::film::Film) -> (f64, f64, f64) {
    let img = s.image();
    let shown = |f: &blackhole::film::Film| -> Vec<glam::Vec3> {
        f.linear_srgb()
            .into_iter()
            .map(|c| blackhole::output::tone_map(c, img.exposure as f32, img.tonemap))
            .collect()
    };
    let mut de: Vec<f64> = shown(a)
        .iter()
        .zip(shown(b))
        .map(|(p, q)| blackhole::compare::delta_e(*p, q))
        .collect();
    de.sort_by(f64::total_cmp);
    let n = de.len();
    (
        de.iter().sum::<f64>() / n as f64,
        de[((0.99 * n as f64) as usize).min(n - 1)],
        de[n - 1],
    )
}

/// A mass whose Schwarzschild radius is 1 m, so distances in metres are in
/// r_s.
pub fn unit_mass() -> f64 {
    let c: f64 = 2.997_924_58e8;
    c * c / (2.0 * blackhole::units::G)
}

/// A shipped config at a reduced size, with extra overrides.
pub fn shipped(name: &str, width: u32, height: u32, extra: &[&str]) -> Scene {
    let w = format!("image.width={width}");
    let h = format!("image.height={height}");
    // Uniform sampling unless `extra` says image.adaptive (later wins).
    let overrides: Vec<Override> = [
        w.as_str(),
        h.as_str(),
        "image.samples=1",
        "image.adaptive=false",
    ]
    .iter()
    .chain(extra)
    .map(|s| Override::parse(s).unwrap())
    .collect();
    let path = root().join("configs").join(format!("{name}.toml"));
    Scene::build(SceneConfig::load(&path, &overrides).unwrap()).unwrap()
}

/// Point lookups for the disk and the sky: the filters the tests of the
/// physics (not of footprints) were written for. Footprint filtering, the
/// shipped default, has tests of its own (footprint.rs, filtering.rs and
/// the GPU's parity tests on the shipped views). Later overrides win.
pub const POINTS: [&str; 2] = ["disk.filter=\"nearest\"", "sky.filter=\"nearest\""];

/// A shipped scene with point lookups ([`POINTS`]; the disk's only where
/// it has one) and `extra`.
pub fn shipped_points(name: &str, width: u32, height: u32, extra: &[&str]) -> Scene {
    let path = root().join("configs").join(format!("{name}.toml"));
    let text = std::fs::read_to_string(path).unwrap();
    let disk = text.lines().any(|l| l.trim() == "[disk]");
    let points: Vec<&str> = POINTS
        .iter()
        .copied()
        .filter(|p| disk || !p.starts_with("disk."))
        .collect();
    shipped(name, width, height, &[&points[..], extra].concat())
}

/// The disk-and-sky views the closed form is checked on, each as (label,
/// the scene in closed form, the same scene with the integrator forced):
/// the shipped `quick`, `side`, `top` and `spectral_side`, and `quick`
/// from 2.5 r_s and from inside the photon sphere (1.3 r_s), both across
/// the shadow's edge; `with` set on every one.
pub fn closed_form_views(with: &[&str]) -> Vec<(String, Scene, Scene)> {
    let near = [
        "camera.position=[0.0,-3.17e10,2.5e9]",
        "camera.look_at=[3.17e10,0.0,0.0]",
    ];
    let inside = [
        "camera.position=[0.0,-1.65e10,1.0e9]",
        "camera.look_at=[1.0e11,-1.65e10,0.0]",
    ];
    let views: [(&str, u32, u32, &[&str]); 6] = [
        ("quick", 96, 96, &[]),
        ("side", 128, 72, &[]),
        ("top", 96, 96, &[]),
        ("spectral_side", 128, 72, &[]),
        ("quick", 96, 96, &near),
        ("quick", 96, 96, &inside),
    ];
    views
        .into_iter()
        .map(|(name, w, h, extra)| {
            let extra = [with, extra].concat();
            let forced = [&extra[..], &["physics.closed_form=false"]].concat();
            (
                format!("{name} {extra:?}"),
                shipped(name, w, h, &extra),
                shipped(name, w, h, &forced),
            )
        })
        .collect()
}

/// A small valid scene whose output goes to `out.png` beside it.
pub fn small_scene_text() -> String {
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

/// The `blackhole` binary of this build.
pub fn bin() -> std::process::Command {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_blackhole"));
    let (key, value) = LAVAPIPE_FLAGS;
    if std::env::var_os(key).is_none() {
        cmd.env(key, value);
    }
    cmd
}

/// Runs the binary in `dir`; returns (exit code, stderr).
pub fn run(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = bin().current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A scratch folder holding `text` as scene.toml.
pub fn case(text: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    dir
}

/// A test scene's TOML built from its parts: the image (its PNG never
/// written by the tests that build scenes in memory), the camera and the
/// hole every scene needs, then the tables a test adds as they are.
#[derive(Clone, Debug)]
pub struct SceneText {
    width: u32,
    height: u32,
    samples: u32,
    position: [f64; 3],
    look_at: [f64; 3],
    up: Option<[f64; 3]>,
    fov: f64,
    mass: f64,
    spin: f64,
    tables: Vec<String>,
}

impl SceneText {
    /// A `width` x `height` image, one sample per pixel, the hole of the
    /// shipped scenes, looking at it from 20 r_s along -y with a 20 degree
    /// field of view.
    pub fn new(width: u32, height: u32) -> SceneText {
        let r_s = blackhole::scene::schwarzschild_radius(MASS);
        SceneText {
            width,
            height,
            samples: 1,
            position: [0.0, -20.0 * r_s, 0.0],
            look_at: [0.0; 3],
            up: None,
            fov: 20.0,
            mass: MASS,
            spin: 0.0,
            tables: Vec::new(),
        }
    }

    /// Rays per pixel.
    pub fn samples(mut self, n: u32) -> SceneText {
        self.samples = n;
        self
    }

    /// The camera's position and the point it looks at (m) and its field
    /// of view (degrees).
    pub fn camera(mut self, position: [f64; 3], look_at: [f64; 3], fov: f64) -> SceneText {
        self.position = position;
        self.look_at = look_at;
        self.fov = fov;
        self
    }

    /// The camera's up direction.
    pub fn up(mut self, up: [f64; 3]) -> SceneText {
        self.up = Some(up);
        self
    }

    /// The hole's mass (kg).
    pub fn mass(mut self, kg: f64) -> SceneText {
        self.mass = kg;
        self
    }

    /// The hole's spin.
    pub fn spin(mut self, a: f64) -> SceneText {
        self.spin = a;
        self
    }

    /// More of the file (tables or keys), as TOML text.
    pub fn with(mut self, toml: &str) -> SceneText {
        self.tables.push(toml.to_string());
        self
    }

    /// The scene file.
    pub fn text(&self) -> String {
        // {:e} keeps every float exactly (the shortest form that reads back).
        let v = |a: [f64; 3]| format!("[{:e}, {:e}, {:e}]", a[0], a[1], a[2]);
        let up = self
            .up
            .map(|u| format!("up = {}\n", v(u)))
            .unwrap_or_default();
        format!(
            "[image]\nwidth = {}\nheight = {}\nsamples = {}\npng = \"unused.png\"\n\
             [camera]\nposition = {}\nlook_at = {}\n{up}fov = {:e}\n\
             [black_hole]\nmass = {:e}\n{}{}\n",
            self.width,
            self.height,
            self.samples,
            v(self.position),
            v(self.look_at),
            self.fov,
            self.mass,
            if self.spin == 0.0 {
                String::new()
            } else {
                format!("spin = {:e}\n", self.spin)
            },
            self.tables.join("\n")
        )
    }

    /// The built scene (the text must be valid).
    pub fn build(&self) -> Scene {
        scene(&self.text())
    }
}

/// Whether what a test needs is here: with `CI` set its absence fails the
/// test (CI installs everything); elsewhere the test says why it skips,
/// on stderr itself so that the harness's capture of passing tests'
/// output does not hide it.
pub fn available(found: Result<(), String>) -> bool {
    use std::io::Write;
    match found {
        Ok(()) => true,
        Err(why) => {
            assert!(std::env::var_os("CI").is_none(), "CI is set and {why}");
            let _ = writeln!(std::io::stderr(), "skipped: {why}");
            false
        }
    }
}

/// An 8-bit RGB image file's pixels.
pub fn pixels(p: &Path) -> image::RgbImage {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgb8()
}

/// Mean CIEDE2000 between two 8-bit sRGB images of one size.
pub fn mean_delta_e(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    use blackhole::spectrum::color::srgb_decode;
    assert_eq!(a.dimensions(), b.dimensions());
    let linear = |p: &image::Rgb<u8>| glam::Vec3::from(p.0.map(|v| srgb_decode(v as f32 / 255.0)));
    let sum: f64 = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| blackhole::compare::delta_e(linear(p), linear(q)))
        .sum();
    sum / (a.width() * a.height()) as f64
}
