//! A validated, loaded scene ready to render, built from a [`SceneConfig`]
//! (in `build`, part by part), and moved in time or to a view.
//!
//! Everything the file says is checked, with messages that name the key or
//! file and what was expected; no render starts and no file is written
//! until the whole scene is valid.

mod build;
pub mod motion;

pub use crate::animation::MAX_PHASE;
use crate::animation::{CameraPath, DiskRotation, Pose, Timeline};
use crate::camera::{Camera, CameraError};
use crate::config::{ImageConfig, SceneConfig};
use crate::disk::Disk;
use crate::objects::{self, Lighting, Object};
use crate::physics::{Limits, Model};
use crate::sky::Sky;
use crate::spectral::SpectralContext;
use crate::spectral_texture::SpectralTexture;
use crate::spectrum::color::xyz_to_linear_srgb;
use crate::spectrum::sampled::Wavelengths;
use crate::texture::Texture;
use crate::volume::{Cloud, VolumeDisk};
use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};
use thiserror::Error;

pub use crate::units::{C, G};

/// Schwarzschild radius 2GM/c^2 (m) of a mass (kg).
pub fn schwarzschild_radius(mass: f64) -> f64 {
    2.0 * G * mass / (C * C)
}

/// Why a scene cannot be built.
#[derive(Debug, Error)]
pub enum SceneError {
    /// A value is out of range or inconsistent.
    #[error("{key} = {value}: {expected}")]
    Invalid {
        /// Dotted key.
        key: String,
        /// The offending value as written.
        value: String,
        /// What was expected instead.
        expected: String,
    },
    /// Keys that do not go together (or a choice not made), said in full.
    #[error("{0}")]
    Keys(String),
    /// An asset file is missing or cannot be decoded.
    #[error("{key}: cannot load {path}: {cause}")]
    Asset {
        /// Dotted key naming the file.
        key: String,
        /// The file.
        path: PathBuf,
        /// Why.
        cause: image::ImageError,
    },
    /// The scene or its render would not fit in memory (what it needs,
    /// its largest parts, what is available and what limits it).
    #[error("{0}")]
    Memory(String),
    /// A GRMHD dump (`medium.dump`) that cannot be read or is not what it
    /// claims.
    #[error("medium.dump: {0}")]
    Dump(#[from] crate::transfer::grmhd::dump::DumpError),
}

fn invalid(key: &str, value: impl std::fmt::Debug, expected: &str) -> SceneError {
    SceneError::Invalid {
        key: key.to_string(),
        value: format!("{value:?}"),
        expected: expected.to_string(),
    }
}

/// How near a fitted mass unit's flux comes to `medium.flux` (relative).
pub const FIT_TOLERANCE: f64 = 1e-4;

/// A scene ready to render. Lengths are in Schwarzschild radii.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The configuration it was built from (paths absolute).
    pub config: SceneConfig,
    /// Schwarzschild radius (m): the unit of all lengths below.
    pub r_s: f64,
    /// The camera.
    pub camera: Camera,
    /// Ray model.
    pub model: Model,
    /// Early-exit bounds for the tracer.
    pub limits: Limits,
    /// The disk, if any.
    pub disk: Option<Disk>,
    /// The panorama.
    pub sky: Sky,
    /// Wavelengths and tables of a spectral render; `None` renders RGB.
    pub spectral: Option<SpectralContext>,
    /// The volumetric disk, if any (instead of `disk`).
    pub volume: Option<VolumeDisk>,
    /// Absorbing gas clouds.
    pub clouds: Vec<Cloud>,
    /// Plasma in physical units (`[medium]`) and how it is observed
    /// (`[observe]`): the film then holds janskys per pixel at its
    /// frequencies.
    pub observe: Option<crate::transfer::Observe>,
    /// Solid objects.
    pub objects: Vec<Object>,
    /// Lights on `lit` objects.
    pub lighting: Lighting,
    /// Things the user should know that do not stop the render, one line
    /// each (settings that do nothing, an opaque disk texture...).
    pub warnings: Vec<String>,
    /// The `[animation]` timeline, if any.
    pub animation: Option<Timeline>,
    /// The instant rendered, in r_s/c of coordinate time (0 without
    /// `[animation]`).
    pub time: f64,
    /// How the disk (flat or volumetric) has turned by then.
    pub rotation: DiskRotation,
    /// Rays see the disk as it was when their light left it.
    pub light_travel_time: bool,
    /// Rays keep their light's travel time: for `light_travel_time` or
    /// the `time` observable.
    pub timed: bool,
    /// The per-pixel maps the film keeps (`image.observables`).
    pub observables: Vec<crate::film::Observable>,
    /// Samples carry their footprints: the `magnification` map or a
    /// footprint filter reads them ([`Scene::footprint`]).
    pub footprints: bool,
    /// Object hits on the camera's geodesic carry their footprint in
    /// texture coordinates: an object's texture filters by footprint
    /// ([`Scene::object_footprint`]).
    pub object_footprints: bool,
    /// Rays may take the closed form (`physics.closed_form`, `gr`, only a
    /// flat disk and the sky; with light travel time only with spin).
    pub closed_form: bool,
    /// Rays per pixel (`image.samples`) and the seed of their positions.
    pub samples: u32,
    /// See `samples`.
    pub seed: u64,
    /// Adaptive sampling (`image.adaptive`): pixels holding an edge take
    /// more samples after the first `samples`.
    pub adaptive: bool,
    /// The most samples a pixel takes: `image.max_samples` with adaptive
    /// sampling, else `samples`.
    pub max_samples: u32,
    /// A spectral render's film keeps every pixel's spectrum (for the
    /// EXR's spectral layers).
    pub keep_spectra: bool,
    /// A spectral render's film keeps the bands of spectral bloom.
    pub bloom_bands: bool,
    /// The `[camera]` table's pose (lengths in metres).
    base_pose: Pose,
    /// The camera's frame and motion.
    pub motion: motion::CameraMotion,
    /// The disk light's patches at time 0.
    glow_base: Vec<objects::Glow>,
}

fn load_texture(key: &str, path: &Path) -> Result<Texture, SceneError> {
    Texture::load(path).map_err(|cause| SceneError::Asset {
        key: key.to_string(),
        path: path.to_path_buf(),
        cause,
    })
}

/// Whether the scene of `config` can be shown at instant `t` (`--time`, s):
/// it has an [animation] (the disk's rotation and the camera's path), and
/// `t` is finite. `render` and `merge` refuse the same times.
pub fn check_time(config: &crate::config::SceneConfig, t: f64) -> Result<(), SceneError> {
    if config.animation.is_none() {
        return Err(invalid(
            "--time",
            t,
            "needs an [animation] table (the disk's rotation and the camera's path)",
        ));
    }
    if !t.is_finite() {
        return Err(invalid("--time", t, "expected a finite time in seconds"));
    }
    Ok(())
}

fn finite_vec(key: &str, v: [f64; 3]) -> Result<DVec3, SceneError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(invalid(key, v, "expected three finite numbers"))
    }
}

fn check_output(key: &str, path: &std::path::Path, ext: &str) -> Result<(), SceneError> {
    let ok = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(ext));
    if !ok {
        return Err(invalid(
            key,
            path,
            &format!("expected a file name ending in .{ext}"),
        ));
    }
    if path.is_dir() {
        return Err(invalid(key, path, "is a directory; expected a file name"));
    }
    Ok(())
}

impl Scene {
    /// The lightness difference between neighbouring pixels that makes
    /// both refine: [`crate::adaptive::CONTRAST`], or none (infinite) where every light the
    /// scene holds is read over the samples' footprints (the sky's
    /// panorama or point stars, the disk's texture, objects that glow with
    /// their textures) or is uniform. There a pixel's samples differ only
    /// across an edge between classes, which the classes find; a mirror,
    /// a lit surface (its highlights and shadows), gas, clouds or any
    /// texture read at the point keep the contrast test.
    pub fn refine_contrast(&self) -> f64 {
        use crate::config::Filter;
        use crate::objects::Finish;
        let footprint = |f: Filter| f == Filter::Footprint;
        let sky = self.sky.filter().is_none_or(footprint);
        let disk = self.disk.as_ref().is_none_or(|d| footprint(d.filter));
        let objects = self.objects.iter().all(|o| {
            let m = &o.material;
            m.finish == Finish::Color && (m.texture.is_none() || footprint(m.filter))
        });
        let gas = self.volume.is_some() || !self.clouds.is_empty();
        if sky && disk && objects && !gas {
            f64::INFINITY
        } else {
            crate::adaptive::CONTRAST
        }
    }

    /// The scene's GRMHD snapshot, if its medium is one.
    pub fn grmhd_mut(&mut self) -> Option<&mut crate::transfer::grmhd::Grmhd> {
        self.observe.as_mut()?.medium.as_mut()?.grmhd_mut()
    }

    /// Sets the GRMHD snapshot's mass unit (g), in its medium and its
    /// configuration (which the outputs' metadata come from).
    pub fn set_m_unit(&mut self, m_unit: f64) {
        if let Some(g) = self.grmhd_mut() {
            g.set_m_unit(m_unit);
        }
        if let Some(crate::config::MediumConfig::Grmhd(g)) = self.config.medium.as_mut() {
            g.m_unit = m_unit;
        }
    }

    /// The GRMHD snapshot's flux target (Jy), where `medium.flux` gives
    /// one, and the mass unit to start from.
    pub fn flux_target(&self) -> Option<(f64, f64)> {
        match self.observe.as_ref()?.medium.as_ref()? {
            crate::transfer::Medium::Grmhd(g) => Some((g.settings.flux?, g.settings.m_unit)),
            _ => None,
        }
    }

    /// With `medium.flux`: fits the mass unit so that `render` (the total
    /// flux density at the first frequency of a render of the scene)
    /// gives it within [`FIT_TOLERANCE`], telling `report` of each try,
    /// and leaves the scene at the fitted unit, its target dropped. None
    /// without a target.
    pub fn fit_m_unit(
        &mut self,
        mut render: impl FnMut(&Scene) -> anyhow::Result<f64>,
        report: impl FnMut(&crate::transfer::grmhd::fit::Try),
    ) -> anyhow::Result<Option<crate::transfer::grmhd::fit::Fit>> {
        let Some((target, start)) = self.flux_target() else {
            return Ok(None);
        };
        let fit = crate::transfer::grmhd::fit::fit_m_unit(
            start,
            target,
            FIT_TOLERANCE,
            |m| {
                self.set_m_unit(m);
                render(self)
            },
            report,
        )?;
        self.set_m_unit(fit.m_unit);
        // Fitted: it renders at that unit from now on.
        if let Some(g) = self.grmhd_mut() {
            g.settings.flux = None;
        }
        if let Some(crate::config::MediumConfig::Grmhd(g)) = self.config.medium.as_mut() {
            g.flux = None;
        }
        Ok(Some(fit))
    }

    /// Centimetres per M (G M / c^2) of the scene's hole.
    pub fn cm_per_m(&self) -> f64 {
        0.5 * self.r_s * 100.0
    }

    /// The camera's distance from the hole (cm; Boyer-Lindquist's radius
    /// with spin).
    pub fn camera_distance_cm(&self) -> f64 {
        let x = self.camera.position;
        let r = self.model.spacetime().map_or(x.length(), |st| st.radius(x));
        r * self.r_s * 100.0
    }

    /// Values each sample gives its pixel besides its XYZ: the spectral
    /// render's wavelengths, or an observed scene's frequencies.
    pub fn channels(&self) -> usize {
        match (&self.spectral, &self.observe) {
            (Some(c), _) => c.wavelengths.len(),
            (None, Some(o)) => o.frequencies.len(),
            (None, None) => 0,
        }
    }
}

impl Scene {
    /// Moves the scene to time `t` (seconds of coordinate time): the
    /// camera along its path, the disk turned, the disk light's patches
    /// with it.
    pub fn set_time(&mut self, t: f64) -> Result<(), SceneError> {
        check_time(&self.config, t)?;
        let a = self
            .animation
            .as_ref()
            .ok_or_else(|| invalid("--time", t, "needs an [animation] table"))?;
        self.check_phase("--time", t, MAX_PHASE, f64::EPSILON)?;
        let pose = a.pose(t, &self.base_pose);
        self.camera = self.camera_at(&pose, t)?;
        self.time = t * C / self.r_s;
        let (rotation, tau) = (self.rotation, self.time);
        self.lighting.glow = self
            .glow_base
            .iter()
            .map(|g| {
                let r = g.position.truncate().length();
                let a = rotation.angle(r, tau);
                let (s, c) = a.sin_cos();
                let p = g.position;
                objects::Glow {
                    position: DVec3::new(c * p.x - s * p.y, s * p.x + c * p.y, p.z),
                    ..*g
                }
            })
            .collect();
        Ok(())
    }

    /// The fastest angular velocity of the turning material (radians per
    /// r_s/c): the innermost ring of the disk or gas under Keplerian
    /// rotation, the one rate of a rigid one, 0 when nothing turns.
    pub fn fastest_turn(&self) -> f64 {
        let inner = match (&self.disk, &self.volume) {
            (Some(d), _) => d.material_radii().0,
            (None, Some(v)) => v.inner,
            (None, None) => return 0.0,
        };
        match self.rotation {
            DiskRotation::None => 0.0,
            DiskRotation::Rigid(w) => w.abs(),
            // No material inside the horizon turns.
            rot @ DiskRotation::Keplerian(_) => rot.angle(inner.max(1.0), 1.0),
        }
    }

    /// Refuses a time `t` (s) by which the fastest material has turned by
    /// more than `limit` radians: its angle's rounding error, `limit`
    /// times the float's epsilon `eps`, would then show (`key` names the
    /// time).
    pub fn check_phase(&self, key: &str, t: f64, limit: f64, eps: f64) -> Result<(), SceneError> {
        let w = self.fastest_turn();
        let phase = w * (t * C / self.r_s).abs();
        if phase > limit {
            let most = limit / w * self.r_s / C;
            return Err(invalid(
                key,
                t,
                &format!(
                    "by then the disk's innermost material has turned {}, and past {limit:.0} rad its angle cannot be computed to {:.0e} rad; expected |t| <= {most:.4e} s",
                    if phase.is_finite() {
                        format!("{phase:.3e} rad")
                    } else {
                        "beyond any angle a number holds".into()
                    },
                    limit * eps
                ),
            ));
        }
        Ok(())
    }

    /// Puts the camera at `pose` (metres) and the clock at `t` (s): the
    /// viewer's moves. Needs an `[animation]` table without a camera path
    /// of its own (the pose replaces `[camera]`).
    pub fn set_view(&mut self, pose: &Pose, t: f64) -> Result<(), SceneError> {
        let saved = self.base_pose;
        self.base_pose = *pose;
        let r = self.set_time(t);
        if r.is_err() {
            self.base_pose = saved;
        }
        r
    }

    /// The camera of `pose` (metres) at time `t` (s, for messages).
    fn camera_at(&self, pose: &Pose, t: f64) -> Result<Camera, SceneError> {
        let key = match self.animation.as_ref().map(|a| &a.camera) {
            Some(CameraPath::Orbit { .. }) => "animation.orbit",
            Some(CameraPath::Keyframes(_)) => "animation.keyframe",
            _ => "camera",
        };
        let position = pose.position / self.r_s;
        let st = self.model.spacetime().unwrap_or_default();
        let r = st.radius(position);
        if !(r > st.horizon()) {
            return Err(invalid(
                key,
                pose.position.to_array(),
                &format!(
                    "the camera path's position at t = {t} s, at r = {r:.4} r_s, inside the horizon at {:.4} r_s; it must stay outside",
                    st.horizon()
                ),
            ));
        }
        if !(pose.fov > 0.0 && pose.fov < 180.0) {
            return Err(invalid(
                key,
                pose.fov,
                &format!("the camera path's field of view at t = {t} s; expected (0, 180) degrees"),
            ));
        }
        let mut camera = Camera::new(
            position,
            pose.look_at / self.r_s,
            pose.up,
            pose.fov,
            self.camera.width,
            self.camera.height,
            self.camera.frame,
        )
        .map_err(|e| {
            invalid(
                key,
                (pose.position.to_array(), pose.look_at.to_array()),
                &format!(
                    "the camera path's position and look_at at t = {t} s give no camera: {}",
                    match e {
                        CameraError::NoViewDirection => "it looks at its own position",
                        CameraError::UpAlongView => "up is along the view direction",
                    }
                ),
            )
        })?;
        // The path's own velocity (units of c) about t, where it is asked
        // for.
        let path_velocity = || match &self.animation {
            Some(a) => {
                // A central difference, one-sided at the path's ends (it
                // holds still beyond them).
                let h = 1e-6 * a.duration.max(1.0);
                let (lo, hi) = ((t - h).max(a.start), (t + h).min(a.start + a.duration));
                if hi > lo {
                    let at = |t: f64| a.pose(t, &self.base_pose).position;
                    (at(hi) - at(lo)) / ((hi - lo) * C)
                } else {
                    DVec3::ZERO
                }
            }
            None => DVec3::ZERO,
        };
        self.motion
            .apply(&mut camera, self.model.spacetime(), path_velocity, t)?;
        Ok(camera)
    }

    /// Checks the camera at every frame and, along keyframes, densely in
    /// between: outside the horizon and well defined everywhere.
    fn check_camera_path(&self, a: &Timeline) -> Result<(), SceneError> {
        let mut times: Vec<f64> = (0..a.frames).map(|k| a.time(k)).collect();
        if let CameraPath::Keyframes(keys) = &a.camera {
            for w in keys.windows(2) {
                times.extend((0..=64).map(|i| w[0].0 + (w[1].0 - w[0].0) * i as f64 / 64.0));
            }
        }
        for t in times {
            self.camera_at(&a.pose(t, &self.base_pose), t)?;
        }
        Ok(())
    }

    /// Output settings.
    pub fn image(&self) -> &ImageConfig {
        &self.config.image
    }

    /// The two eyes of `[stereo]` (lengths in the config's metres).
    pub fn stereo_eyes(&self) -> Option<(Scene, Scene)> {
        let st = self.config.stereo.as_ref()?;
        let conv = st.convergence.unwrap_or_else(|| {
            (DVec3::from_array(self.config.camera.look_at)
                - DVec3::from_array(self.config.camera.position))
            .length()
        });
        let (l, r) = self
            .camera
            .stereo_pair(st.separation / self.r_s, conv / self.r_s);
        let eye = |camera| Scene {
            camera,
            ..self.clone()
        };
        Some((eye(l), eye(r)))
    }

    /// The film as shown: bloomed when `[bloom]` asks.
    pub fn displayed<'a>(&self, film: &'a crate::film::Film) -> std::borrow::Cow<'a, [Vec3]> {
        crate::output::displayed(&self.config, film)
    }
}

/// A linear colour, checked.
fn colour(key: &str, c: [f64; 3]) -> Result<Vec3, SceneError> {
    if c.iter().all(|x| x.is_finite() && *x >= 0.0) {
        Ok(Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32))
    } else {
        Err(invalid(key, c, "expected three finite linear values >= 0"))
    }
}

/// An RGB texture from a spectral set (no shift): each texel's spectrum
/// integrated against the CMFs on the 1 nm grid, to linear sRGB.
fn spectral_to_rgb(set: &SpectralTexture) -> Texture {
    let wl = Wavelengths::new(401);
    let interp = crate::config::Interpolation::Linear;
    let (w, h) = (set.width, set.height);
    let img = image::Rgba32FImage::from_fn(w, h, |x, y| {
        let t = (y * w + x) as usize;
        let spec: Vec<f32> = wl.nm.iter().map(|&l| set.value(t, l, interp)).collect();
        let rgb = xyz_to_linear_srgb(wl.xyz(&spec));
        image::Rgba([rgb.x as f32, rgb.y as f32, rgb.z as f32, set.alpha(t)])
    });
    Texture::from_image(image::DynamicImage::ImageRgba32F(img))
}

/// Largest image (pixels): its film alone is 12 GiB.
pub const MAX_PIXELS: u64 = 1 << 30;
