//! `blackhole view`: the scene in a window, rendered by the GPU backend,
//! with the camera, the physics switches and the disk's clock under the
//! mouse and keyboard (`app`), and what the window writes: screenshots
//! through `render`'s output code and the view saved as a scene file
//! (`Session`). The controls themselves are plain functions (`state`).

mod app;
mod event;
#[cfg(target_arch = "wasm32")]
mod page;
pub mod state;
#[cfg(target_arch = "wasm32")]
pub mod web;

#[cfg(not(target_arch = "wasm32"))]
pub use app::run;
#[cfg(target_arch = "wasm32")]
pub use app::run_in_page;
pub use event::Event;

use crate::config::{Override, SceneConfig};
use crate::scene::Scene;
use anyhow::{Context, Result};
use state::ViewState;
use std::path::{Path, PathBuf};

/// A scene file opened in the viewer, with the command line's overrides.
pub struct Session {
    /// The scene file.
    pub config: PathBuf,
    /// `--set` and `--unset`, in the order they apply.
    pub cli: Vec<Override>,
    /// The config they give (paths absolute).
    pub original: SceneConfig,
    /// Where screenshots and saved views go.
    pub out_dir: PathBuf,
}

impl Session {
    /// Loads and checks the scene (also for the GPU backend) before any
    /// window opens.
    pub fn open(config: &Path, cli: Vec<Override>, out_dir: PathBuf) -> Result<Session> {
        let original = SceneConfig::load(config, &cli)
            .with_context(|| format!("invalid scene {}", config.display()))?;
        let s = Session {
            config: config.to_path_buf(),
            cli,
            original,
            out_dir,
        };
        let scene = s.scene(&s.start(), None, None, true)?;
        if let Err(crate::gpu::GpuError::Unsupported { table, why }) =
            crate::gpu::check_supported(&scene)
        {
            anyhow::bail!(
                "{}: the viewer renders on the GPU, which does not render {table} ({why}); \
                 view the scene without it (--set or --unset the key) or render it with \
                 `blackhole render --backend cpu`",
                config.display()
            );
        }
        if s.original.image.adaptive == Some(true) {
            // Asked for, so said, not silently left out (see the guide's
            // Viewer); the default is no news.
            eprintln!(
                "{}: the viewer's frames add up uniform passes of one sample a pixel; \
                 image.adaptive applies to its screenshots and to `blackhole render`",
                config.display()
            );
        }
        Ok(s)
    }

    /// The view the scene file describes.
    pub fn start(&self) -> ViewState {
        let r_s = crate::scene::schwarzschild_radius(self.original.black_hole.mass);
        ViewState::new(&self.original, r_s)
    }

    /// The overrides that turn the scene file into `state`'s view: the
    /// camera, every switch that differs from the file, and the clock.
    /// A camera path of the file's `[animation]` gives way to the fixed
    /// camera; the clock becomes `animation.start` (an `[animation]` table
    /// holding only `start` is added where the file has none and the time
    /// is not 0, or always with `clock`, which the viewer's own scene needs
    /// to turn the disk).
    pub fn view_overrides(&self, state: &ViewState, clock: bool) -> Vec<Override> {
        let mut o = state.camera_overrides();
        o.extend(state.changed_physics(&self.start()));
        match &self.original.animation {
            Some(a) => {
                o.push(Override::value("animation.start", state.time.into()));
                if a.orbit.is_some() {
                    o.push(Override::unset("animation.orbit").expect("valid key"));
                }
                if a.keyframes.is_some() {
                    o.push(Override::unset("animation.keyframe").expect("valid key"));
                }
                // The path's own motion goes with it: the viewer's camera
                // is at rest.
                if a.camera_motion == crate::config::CameraMotion::Path {
                    o.push(Override::unset("animation.camera_motion").expect("valid key"));
                }
            }
            None if clock || state.time != 0.0 => {
                // A still's clock: the time alone.
                let mut t = toml::Table::new();
                t.insert("start".into(), state.time.into());
                o.push(Override::value("animation", t.into()));
            }
            None => {}
        }
        o
    }

    /// All overrides for `state`, optionally with new outputs and sample
    /// count.
    fn overrides(
        &self,
        state: &ViewState,
        outputs: Option<(&Path, Option<&Path>)>,
        samples: Option<u32>,
        clock: bool,
    ) -> Vec<Override> {
        let mut o = self.cli.clone();
        o.extend(self.view_overrides(state, clock));
        if let Some((png, exr)) = outputs {
            o.push(Override::value(
                "image.png",
                png.display().to_string().into(),
            ));
            if let Some(exr) = exr {
                o.push(Override::value(
                    "image.exr",
                    exr.display().to_string().into(),
                ));
            }
        }
        if let Some(n) = samples {
            o.push(Override::value("image.samples", i64::from(n).into()));
        }
        o
    }

    /// The scene of `state`'s view.
    pub fn scene(
        &self,
        state: &ViewState,
        outputs: Option<(&Path, Option<&Path>)>,
        samples: Option<u32>,
        clock: bool,
    ) -> Result<Scene> {
        let cfg = SceneConfig::load(
            &self.config,
            &self.overrides(state, outputs, samples, clock),
        )
        .with_context(|| format!("invalid view of {}", self.config.display()))?;
        Scene::build(cfg).with_context(|| format!("invalid view of {}", self.config.display()))
    }

    /// The scene file's name without its extension.
    pub fn stem(&self) -> String {
        self.config
            .file_stem()
            .map_or("view".into(), |s| s.to_string_lossy().into_owned())
    }

    /// The first `<stem>_<tag><n>` in the output folder (n from 1) for
    /// which none of the extensions `exts` names a file yet.
    #[cfg(not(target_arch = "wasm32"))]
    fn free_name(&self, tag: &str, exts: &[&str]) -> PathBuf {
        let stem = self.stem();
        (1..)
            .map(|n| self.out_dir.join(format!("{stem}_{tag}{n}")))
            .find(|base| exts.iter().all(|e| !base.with_extension(e).exists()))
            .expect("a free name")
    }

    /// Writes `state`'s view as a scene file, `<stem>_view<n>.toml` in the
    /// output folder, which renders to `<stem>_view<n>.png` beside it (and
    /// `.exr` if the scene writes one): the scene file with the camera,
    /// switches and clock changed, every path absolute. Returns its path.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn save(&self, state: &ViewState) -> Result<PathBuf> {
        let base = self.free_name("view", &["toml", "png", "exr"]);
        let toml_path = base.with_extension("toml");
        let text = self.saved_text(state, &base, false)?;
        let text = format!(
            "# The view of {} saved by `blackhole view`; render it with\n#   blackhole render {}\n{text}",
            self.config.display(),
            toml_path.display()
        );
        crate::output::write_atomic(&toml_path, |w| Ok(w.write_all(text.as_bytes())?))?;
        Ok(toml_path)
    }

    /// `state`'s view as scene-file text that renders to `base`'s `.png`
    /// (and `.exr` if the scene writes one); paths absolute, or with
    /// `relative` relative to the scene file's folder.
    pub fn saved_text(&self, state: &ViewState, base: &Path, relative: bool) -> Result<String> {
        let png = base.with_extension("png");
        let exr = self
            .original
            .image
            .exr
            .as_ref()
            .map(|_| base.with_extension("exr"));
        let o = self.overrides(state, Some((&png, exr.as_deref())), None, false);
        SceneConfig::saved_text(&self.config, &o, relative)
            .with_context(|| format!("cannot save the view of {}", self.config.display()))
    }

    /// Renders `state`'s view at the scene's own quality on `gpu` and
    /// writes `<stem>_shot<n>.png` and `.exr` in the output folder through
    /// `render`'s output code. Returns the PNG's path.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn screenshot(&self, state: &ViewState, gpu: &crate::gpu::Gpu) -> Result<PathBuf> {
        let base = self.free_name("shot", &["png", "exr"]);
        let (png, exr) = (base.with_extension("png"), base.with_extension("exr"));
        let scene = self.scene(state, Some((&png, Some(&exr))), None, false)?;
        let (film, _) = gpu.prepare(&scene, u32::MAX)?.render_image(&|_| {})?;
        crate::output::write_film(&scene.config, &film, &png, Some(&exr))?;
        Ok(png)
    }
}

#[cfg(not(target_arch = "wasm32"))]
use std::io::Write as _;
