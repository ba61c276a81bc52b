//! A validated, loaded scene ready to render, built from a [`SceneConfig`].
//!
//! Everything the file says is checked here, with messages that name the key
//! or file and what was expected; no render starts and no file is written
//! until the whole scene is valid.

use crate::animation::{CameraPath, DiskRotation, Pose, Timeline};
use crate::camera::{Camera, CameraError};
use crate::config::{
    DiskEmission, ImageConfig, LightConfig, MaterialConfig, ModelKind, ObjectConfig, SceneConfig,
};
use crate::disk::{Disk, DiskMaterial};
use crate::objects::{self, Finish, Lighting, Material, Object};
use crate::physics::{Limits, Model};
use crate::shapes::{Mesh, Rectangle, Shape, Sphere};
use crate::sky::Sky;
use crate::spectral::SpectralContext;
use crate::spectral_texture::SpectralTexture;
use crate::spectrum::sampled::{MAX_WAVELENGTHS, Wavelengths};
use crate::spectrum::uplift::uplift;
use crate::spectrum::{BlackbodyTable, blackbody_rgb, color::xyz_to_linear_srgb};
use crate::starmap::{StarMap, parse_catalogue};
use crate::texture::Texture;
use crate::volume::{Cloud, VolumeDisk};
use glam::{DAffine3, DQuat, DVec3, EulerRot, Vec3, Vec4};
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
}

fn invalid(key: &str, value: impl std::fmt::Debug, expected: &str) -> SceneError {
    SceneError::Invalid {
        key: key.to_string(),
        value: format!("{value:?}"),
        expected: expected.to_string(),
    }
}

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
    /// Rays may take the closed form (`physics.closed_form`, `gr`, only a
    /// flat disk and the sky, no light travel time).
    pub closed_form: bool,
    /// The `[camera]` table's pose (lengths in metres).
    base_pose: Pose,
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
    /// Validates the configuration and loads its assets.
    pub fn build(config: SceneConfig) -> Result<Scene, SceneError> {
        let img = &config.image;
        if img.width == 0 || img.width > 65_535 {
            return Err(invalid(
                "image.width",
                img.width,
                "expected 1 to 65535 pixels",
            ));
        }
        if img.height == 0 || img.height > 65_535 {
            return Err(invalid(
                "image.height",
                img.height,
                "expected 1 to 65535 pixels",
            ));
        }
        if img.samples == 0 || img.samples > 65_536 {
            return Err(invalid(
                "image.samples",
                img.samples,
                "expected 1 to 65536 rays per pixel",
            ));
        }
        if !img.exposure.is_finite() {
            return Err(invalid(
                "image.exposure",
                img.exposure,
                "expected a finite number of stops",
            ));
        }
        check_output("image.png", &img.png, "png")?;
        if let Some(exr) = &img.exr {
            check_output("image.exr", exr, "exr")?;
        }
        if let Some(st) = &config.stereo {
            if !(st.separation.is_finite() && st.separation > 0.0) {
                return Err(invalid(
                    "stereo.separation",
                    st.separation,
                    "expected a positive distance in metres",
                ));
            }
            if let Some(c) = st.convergence
                && !(c.is_finite() && c > 0.0)
            {
                return Err(invalid(
                    "stereo.convergence",
                    c,
                    "expected a positive distance in metres",
                ));
            }
        }
        if let Some(b) = &config.bloom {
            if !(b.strength.is_finite() && (0.0..=1.0).contains(&b.strength)) {
                return Err(invalid("bloom.strength", b.strength, "expected 0 to 1"));
            }
            if !(b.radius.is_finite() && b.radius > 0.0 && b.radius <= 1.0) {
                return Err(invalid(
                    "bloom.radius",
                    b.radius,
                    "expected 0 < radius <= 1 (fraction of the image height)",
                ));
            }
        }
        let pixels = img.width as u64 * img.height as u64;
        if pixels > MAX_PIXELS {
            return Err(invalid(
                "image.width x image.height",
                (img.width, img.height),
                &format!("is {pixels} pixels; at most {MAX_PIXELS} (one gigapixel) are supported"),
            ));
        }

        let mass = config.black_hole.mass;
        if !(mass.is_finite() && mass > 0.0) {
            return Err(invalid(
                "black_hole.mass",
                mass,
                "expected a positive mass in kg",
            ));
        }
        let r_s = schwarzschild_radius(mass);
        if !(r_s.is_finite() && r_s > 0.0) {
            return Err(invalid(
                "black_hole.mass",
                mass,
                "gives no finite Schwarzschild radius",
            ));
        }

        let cam = &config.camera;
        let position = finite_vec("camera.position", cam.position)? / r_s;
        let look_at = finite_vec("camera.look_at", cam.look_at)? / r_s;
        let up = finite_vec("camera.up", cam.up)?;
        if !(cam.fov > 0.0 && cam.fov < 180.0) {
            return Err(invalid(
                "camera.fov",
                cam.fov,
                "expected degrees between 0 and 180 (exclusive)",
            ));
        }
        for (key, v, raw) in [
            ("camera.position", position, cam.position),
            ("camera.look_at", look_at, cam.look_at),
        ] {
            if !v.is_finite() {
                return Err(invalid(
                    key,
                    raw,
                    &format!(
                        "is out of range in units of r_s = {r_s:.6e} m (black_hole.mass too small?)"
                    ),
                ));
            }
        }
        let r_cam = position.length();
        if !(r_cam > 1.0) {
            return Err(invalid(
                "camera.position",
                cam.position,
                &format!(
                    "is {:.4} r_s from the hole, inside the horizon (r_s = {r_s:.6e} m); the camera must be outside",
                    r_cam
                ),
            ));
        }

        let phys = &config.physics;
        let model = match phys.model {
            ModelKind::Gr => {
                if !(phys.tolerance > 0.0 && phys.tolerance <= 1e-2) {
                    return Err(invalid(
                        "physics.tolerance",
                        phys.tolerance,
                        "expected 0 < tolerance <= 1e-2",
                    ));
                }
                Model::Gr {
                    tolerance: phys.tolerance,
                }
            }
            ModelKind::Seed => {
                if !(phys.step > 0.0 && phys.step <= 0.1) {
                    return Err(invalid(
                        "physics.step",
                        phys.step,
                        "expected 0 < step <= 0.1 (fraction of r/c)",
                    ));
                }
                Model::Seed { step: phys.step }
            }
        };
        if phys.max_steps == 0 {
            return Err(invalid(
                "physics.max_steps",
                phys.max_steps,
                "expected at least 1",
            ));
        }

        let camera = Camera::new(
            position,
            look_at,
            up,
            cam.fov,
            img.width,
            img.height,
            phys.model == ModelKind::Gr,
        )
        .map_err(|e| match e {
            CameraError::NoViewDirection => invalid(
                "camera.look_at",
                cam.look_at,
                "must differ from camera.position",
            ),
            CameraError::UpAlongView => invalid(
                "camera.up",
                cam.up,
                "must be non-zero and not parallel to the view direction (look_at - position)",
            ),
        })?;

        // Both stereo eyes must be outside the horizon, like the camera.
        if let Some(st) = &config.stereo {
            let conv = st
                .convergence
                .unwrap_or_else(|| (look_at - position).length() * r_s);
            let (l, r) = camera.stereo_pair(st.separation / r_s, conv / r_s);
            for (eye, side) in [(l, "left"), (r, "right")] {
                let r_eye = eye.position.length();
                if !(r_eye > 1.0) {
                    return Err(invalid(
                        "stereo.separation",
                        st.separation,
                        &format!(
                            "puts the {side} eye {r_eye:.4} r_s from the hole, inside the horizon (r_s = {r_s:.6e} m); both eyes must be outside"
                        ),
                    ));
                }
            }
        }

        let mut warnings = config.warnings.clone();
        let sc = &config.spectral;
        let spectral = if sc.enabled {
            if !(2..=MAX_WAVELENGTHS as u32).contains(&sc.wavelengths) {
                return Err(invalid(
                    "spectral.wavelengths",
                    sc.wavelengths,
                    &format!("expected 2 to {MAX_WAVELENGTHS} samples over 380-780 nm"),
                ));
            }
            Some(SpectralContext::new(sc))
        } else {
            // Spectral keys without spectral.enabled are warned about
            // with the other settings that do nothing.
            None
        };

        // Before anything loads: a scene whose assets cannot fit is refused
        // now, not after minutes of decoding.
        crate::memory::assets(&config)
            .check("loading the scene")
            .map_err(SceneError::Memory)?;

        let disk = match &config.disk {
            None => None,
            Some(d) => {
                if !(d.radius.is_finite() && d.radius > 1.0) {
                    return Err(invalid(
                        "disk.radius",
                        d.radius,
                        "expected an outer radius > 1 (in r_s)",
                    ));
                }
                if !(d.inner_radius >= 0.0 && d.inner_radius < d.radius) {
                    return Err(invalid(
                        "disk.inner_radius",
                        d.inner_radius,
                        &format!("expected 0 <= inner_radius < radius = {}", d.radius),
                    ));
                }
                if !(d.intensity.is_finite() && d.intensity >= 0.0) {
                    return Err(invalid(
                        "disk.intensity",
                        d.intensity,
                        "expected a finite number >= 0",
                    ));
                }
                let load_set = |path: &PathBuf| {
                    SpectralTexture::load(path).map_err(|e| SceneError::Invalid {
                        key: "disk.spectrum".into(),
                        value: format!("{:?}", path),
                        expected: e.to_string(),
                    })
                };
                let thin = match d.emission {
                    DiskEmission::Texture => {
                        for (key, set) in [
                            ("disk.accretion_rate", d.accretion_rate.is_some()),
                            ("disk.peak_temperature", d.peak_temperature.is_some()),
                        ] {
                            if set {
                                return Err(invalid(
                                    key,
                                    "set",
                                    "only with disk.emission = \"thin\"",
                                ));
                            }
                        }
                        None
                    }
                    DiskEmission::Thin => Some(thin_disk(d, &config)?),
                };
                let material = match (&d.texture, &d.spectrum, spectral.is_some()) {
                    // The thin disk's own light; a texture only modulates it.
                    _ if thin.is_some() => match &d.texture {
                        Some(tex) => DiskMaterial::Rgb(load_texture("disk.texture", tex)?),
                        None => DiskMaterial::Rgb(Texture::uniform(Vec4::ONE)),
                    },
                    (None, None, _) => {
                        return Err(invalid(
                            "disk",
                            "no texture",
                            "expected disk.texture (RGBA image) and/or disk.spectrum (spectral set manifest)",
                        ));
                    }
                    (_, Some(set), true) => DiskMaterial::Spectral(load_set(set)?),
                    (Some(tex), _, _) => DiskMaterial::Rgb(load_texture("disk.texture", tex)?),
                    (None, Some(set), false) => DiskMaterial::Rgb(spectral_to_rgb(&load_set(set)?)),
                };
                if let (DiskMaterial::Rgb(t), Some(path)) = (&material, &d.texture)
                    && !t.has_alpha
                {
                    warnings.push(format!(
                        "disk.texture {} has no alpha channel: the disk is opaque everywhere from r = {} r_s ({}) to disk.radius = {} r_s",
                        path.display(),
                        d.inner_radius.max(1.0),
                        if d.inner_radius > 1.0 {
                            "disk.inner_radius"
                        } else {
                            "the horizon; set disk.inner_radius, e.g. 3 for the ISCO"
                        },
                        d.radius
                    ));
                }
                Some(Disk {
                    // Nothing is seen inside the horizon; a thin disk
                    // begins at its inner edge.
                    inner: thin.as_ref().map_or(d.inner_radius.max(1.0), |t| t.inner),
                    thin,
                    outer: d.radius,
                    material,
                    filter: d.filter,
                    alpha: d.alpha,
                    intensity: d.intensity as f32,
                })
            }
        };

        let s = &config.sky;
        if !(s.intensity.is_finite() && s.intensity >= 0.0) {
            return Err(invalid(
                "sky.intensity",
                s.intensity,
                "expected a finite number >= 0",
            ));
        }
        let k = s.intensity as f32;
        let sky = match (&s.texture, s.color, s.blackbody, &s.stars) {
            (Some(path), None, None, None) => {
                let mut texture = load_texture("sky.texture", path)?;
                // The sky has nothing behind it: alpha means nothing there.
                texture.make_opaque();
                let aspect = texture.width as f64 / texture.height as f64;
                if (aspect - 2.0).abs() > 0.02 {
                    return Err(invalid(
                        "sky.texture",
                        path,
                        &format!(
                            "is {} x {}; an equirectangular panorama must be twice as wide as high",
                            texture.width, texture.height
                        ),
                    ));
                }
                Sky::Panorama {
                    texture,
                    filter: s.filter,
                    intensity: k,
                }
            }
            (None, Some(c), None, None) => {
                if !c.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    return Err(invalid(
                        "sky.color",
                        c,
                        "expected three finite linear values >= 0",
                    ));
                }
                let rgb = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * k;
                Sky::Uniform {
                    rgb,
                    spectrum: spectral.is_some().then(|| uplift(rgb)),
                }
            }
            (None, None, Some(t), None) => {
                if !(t.is_finite() && (100.0..=1e6).contains(&t)) {
                    return Err(invalid(
                        "sky.blackbody",
                        t,
                        "expected a temperature of 100 to 1e6 K",
                    ));
                }
                Sky::Blackbody {
                    kelvin: t,
                    intensity: k,
                    rgb: blackbody_rgb(t) * k,
                }
            }
            (None, None, None, Some(path)) => {
                if !(2..=65_536).contains(&s.resolution) || !s.resolution.is_multiple_of(2) {
                    return Err(invalid(
                        "sky.resolution",
                        s.resolution,
                        "expected an even width of 2 to 65536 texels",
                    ));
                }
                let text = std::fs::read_to_string(path).map_err(|e| {
                    invalid(
                        "sky.stars",
                        path,
                        &format!("cannot read the star catalogue: {e}"),
                    )
                })?;
                let stars = parse_catalogue(&text).map_err(|e| invalid("sky.stars", path, &e))?;
                Sky::Stars {
                    map: StarMap::build(&stars, s.resolution, s.milky_way),
                    filter: s.filter,
                    intensity: k,
                    colours: BlackbodyTable::new(500.0, 60000.0),
                }
            }
            _ => {
                let set: Vec<&str> = [
                    s.texture.as_ref().map(|_| "texture"),
                    s.color.map(|_| "color"),
                    s.blackbody.map(|_| "blackbody"),
                    s.stars.as_ref().map(|_| "stars"),
                ]
                .into_iter()
                .flatten()
                .collect();
                let keys: Vec<String> = set.iter().map(|k| format!("sky.{k}")).collect();
                return Err(SceneError::Keys(if keys.is_empty() {
                    "[sky] gives no sky: give exactly one of sky.texture, sky.color, sky.blackbody, sky.stars".into()
                } else {
                    format!(
                        "[sky] gives {}: give exactly one of sky.texture, sky.color, sky.blackbody, sky.stars",
                        keys.join(" and ")
                    )
                }));
            }
        };

        let volume = match &config.volume {
            None => None,
            Some(v) => {
                if disk.is_some() {
                    return Err(invalid(
                        "volume",
                        "[volume] and [disk]",
                        "choose one: the volumetric disk replaces the flat one",
                    ));
                }
                let pos = |k: &str, x: f64| {
                    if x.is_finite() && x > 0.0 {
                        Ok(x)
                    } else {
                        Err(invalid(
                            &format!("volume.{k}"),
                            x,
                            "expected a positive number",
                        ))
                    }
                };
                let inner = pos("inner", v.inner)?;
                let outer = pos("outer", v.outer)?;
                if !(inner >= 1.0) {
                    return Err(invalid(
                        "volume.inner",
                        inner,
                        "expected at least 1 (r_s): no gas inside the horizon",
                    ));
                }
                if !(outer > inner) {
                    return Err(invalid(
                        "volume.inner",
                        inner,
                        &format!("expected volume.inner < volume.outer = {outer} (r_s)"),
                    ));
                }
                let step = pos("step", v.step)?;
                if step > 0.5 * pos("thickness", v.thickness)? {
                    return Err(invalid(
                        "volume.step",
                        step,
                        "must be at most half the thickness, or the gas is skipped over",
                    ));
                }
                for (key, x) in [
                    ("volume.opacity", v.opacity),
                    ("volume.emission", v.emission),
                ] {
                    if !(x.is_finite() && x >= 0.0) {
                        return Err(invalid(key, x, "expected a finite number >= 0"));
                    }
                }
                if !(v.peak_kelvin.is_finite() && (500.0..=1e6).contains(&v.peak_kelvin)) {
                    return Err(invalid(
                        "volume.peak_kelvin",
                        v.peak_kelvin,
                        "expected 500 to 1e6 K",
                    ));
                }
                Some(VolumeDisk::new(
                    inner,
                    outer,
                    v.thickness,
                    v.opacity,
                    v.emission as f32,
                    v.peak_kelvin,
                    step,
                    v.seed,
                ))
            }
        };
        let clouds = config
            .clouds
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let key = |k: &str| format!("cloud[{i}].{k}");
                let center = finite_vec(&key("center"), c.center)? / r_s;
                if !(c.radius.is_finite() && c.radius > 0.0) {
                    return Err(invalid(
                        &key("radius"),
                        c.radius,
                        "expected a positive radius in metres",
                    ));
                }
                if !(c.depth.is_finite() && (0.0..=3.0).contains(&c.depth)) {
                    return Err(invalid(
                        &key("depth"),
                        c.depth,
                        "expected 0 to 3: a cloud may dim the hole, never hide it",
                    ));
                }
                if !(c.beta.is_finite() && (0.0..=4.0).contains(&c.beta)) {
                    return Err(invalid(&key("beta"), c.beta, "expected 0 to 4"));
                }
                let radius = c.radius / r_s;
                if center.length() < radius + 1.0 {
                    return Err(invalid(
                        &key("radius"),
                        c.radius,
                        "the cloud must not reach the hole",
                    ));
                }
                let cloud = Cloud::new(
                    center,
                    radius,
                    c.depth,
                    c.beta,
                    colour(&key("color"), c.color)?,
                    c.seed,
                );
                // Spectral renders read per-wavelength extinction and the
                // glow's spectrum; without them a cloud would do nothing.
                Ok(match &spectral {
                    Some(ctx) => cloud.for_wavelengths(&ctx.wavelengths.nm),
                    None => cloud,
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let objects = config
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| build_object(i, o, r_s))
            .collect::<Result<Vec<_>, _>>()?;
        let mut lighting = Lighting::default();
        for (i, l) in config.lights.iter().enumerate() {
            let key = |k: &str| format!("light[{i}].{k}");
            let check_intensity = |v: f64| {
                if v.is_finite() && v >= 0.0 {
                    Ok(v as f32)
                } else {
                    Err(invalid(
                        &key("intensity"),
                        v,
                        "expected a finite number >= 0",
                    ))
                }
            };
            match l {
                LightConfig::Sun(s) => {
                    let d = finite_vec(&key("direction"), s.direction)?;
                    if d.length() == 0.0 {
                        return Err(invalid(
                            &key("direction"),
                            s.direction,
                            "expected a non-zero direction towards the star",
                        ));
                    }
                    let color = match (s.kelvin, s.color) {
                        (Some(_), Some(_)) => {
                            return Err(invalid(
                                &key("kelvin"),
                                s.kelvin,
                                "give kelvin or color, not both",
                            ));
                        }
                        (Some(t), None) if !(t.is_finite() && (100.0..=1e6).contains(&t)) => {
                            return Err(invalid(
                                &key("kelvin"),
                                t,
                                "expected a temperature of 100 to 1e6 K",
                            ));
                        }
                        (_, Some(c)) => Some(colour(&key("color"), c)?),
                        _ => None,
                    };
                    lighting.suns.push(objects::sun(
                        d,
                        s.kelvin,
                        color,
                        check_intensity(s.intensity)?,
                    ));
                }
                LightConfig::Ambient(a) => {
                    lighting.ambient +=
                        colour(&key("color"), a.color)? * check_intensity(a.intensity)?;
                }
                LightConfig::Disk(g) => {
                    let Some(d) = &disk else {
                        return Err(invalid(&key("kind"), "disk", "a disk light needs a [disk]"));
                    };
                    let k = check_intensity(g.intensity)?;
                    let rgb_texture = match &d.material {
                        // The thin disk's light sampled like a texture.
                        _ if d.thin.is_some() => d.thin_texture(256),
                        DiskMaterial::Rgb(t) => t.clone(),
                        DiskMaterial::Spectral(s) => spectral_to_rgb(s),
                    };
                    lighting.glow = Lighting::disk_glow(d, &rgb_texture, d.material_radii(), k);
                }
            }
        }

        let (inner, outer) = disk
            .as_ref()
            .map_or((f64::INFINITY, 0.0), Disk::material_radii);
        let (inner, outer) = objects.iter().fold((inner, outer), |(lo, hi), o| {
            let (near, far) = o.shape.radial_extent();
            (lo.min(near), hi.max(far))
        });
        let (inner, outer) = match &volume {
            // The gas starts just inside `inner` (smooth edge) and reaches
            // 3 scale heights above the plane.
            Some(v) => (inner.min(0.9 * v.inner), outer.max(v.outer.hypot(v.zmax()))),
            None => (inner, outer),
        };
        let (inner, outer) = clouds.iter().fold((inner, outer), |(lo, hi), c| {
            let d = c.center.length();
            (lo.min(d - c.radius), hi.max(d + c.radius))
        });
        let limits = Limits {
            outer,
            inner,
            max_steps: phys.max_steps,
        };

        // RGB content of a spectral render is uplifted as it is met: build
        // the table before any render starts.
        if spectral.is_some()
            && (matches!(sky, Sky::Panorama { .. })
                || disk
                    .as_ref()
                    .is_some_and(|d| matches!(d.material, DiskMaterial::Rgb(_)))
                || !objects.is_empty())
        {
            crate::spectrum::uplift::prepare();
        }
        let animation = match &config.animation {
            None => None,
            Some(a) => Some(Timeline::new(a, r_s).map_err(|(key, value, expected)| {
                SceneError::Invalid {
                    key,
                    value,
                    expected,
                }
            })?),
        };
        let base_pose = Pose {
            position: DVec3::from_array(cam.position),
            look_at: DVec3::from_array(cam.look_at),
            up: DVec3::from_array(cam.up),
            fov: cam.fov,
        };
        let closed_form = config.physics.closed_form
            && config.physics.model == ModelKind::Gr
            && objects.is_empty()
            && volume.is_none()
            && clouds.is_empty()
            && !animation.as_ref().is_some_and(|a| a.light_travel_time);
        let mut scene = Scene {
            r_s,
            camera,
            model,
            limits,
            disk,
            sky,
            spectral,
            volume,
            clouds,
            objects,
            glow_base: lighting.glow.clone(),
            lighting,
            warnings,
            time: 0.0,
            rotation: animation
                .as_ref()
                .map_or(DiskRotation::None, |a| a.rotation),
            light_travel_time: animation.as_ref().is_some_and(|a| a.light_travel_time),
            closed_form,
            animation,
            base_pose,
            config: config.clone(),
        };
        if let Some(a) = scene.animation.clone() {
            let eps = f64::EPSILON;
            scene.check_phase("animation.start", a.start, MAX_PHASE, eps)?;
            scene.check_phase("animation.duration", a.start + a.duration, MAX_PHASE, eps)?;
            scene.check_camera_path(&a)?;
            scene.set_time(a.start)?;
        }
        Ok(scene)
    }

    /// Moves the scene to time `t` (seconds of coordinate time): the
    /// camera along its path, the disk turned, the disk light's patches
    /// with it.
    pub fn set_time(&mut self, t: f64) -> Result<(), SceneError> {
        let Some(a) = &self.animation else {
            return Err(invalid(
                "--time",
                t,
                "needs an [animation] table (the disk's rotation and the camera's path)",
            ));
        };
        if !t.is_finite() {
            return Err(invalid("--time", t, "expected a finite time in seconds"));
        }
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
            DiskRotation::Keplerian => DiskRotation::Keplerian.angle(inner.max(1.0), 1.0),
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
        let r = position.length();
        if !(r > 1.0) {
            return Err(invalid(
                key,
                pose.position.to_array(),
                &format!(
                    "the camera path's position at t = {t} s, {r:.4} r_s from the hole, inside the horizon; it must stay outside"
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
        Camera::new(
            position,
            pose.look_at / self.r_s,
            pose.up,
            pose.fov,
            self.camera.width,
            self.camera.height,
            self.camera.static_observer,
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
        })
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

/// Builds object `i` (lengths to r_s).
fn build_object(i: usize, o: &ObjectConfig, r_s: f64) -> Result<Object, SceneError> {
    let key = |k: &str| format!("object[{i}].{k}");
    let positive = |k: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(invalid(&key(k), v, "expected a positive length in metres"))
        }
    };
    let unit = |k: &str, v: [f64; 3]| {
        finite_vec(&key(k), v)?
            .try_normalize()
            .ok_or_else(|| invalid(&key(k), v, "expected a non-zero direction"))
    };
    let (shape, mat) = match o {
        ObjectConfig::Sphere(s) => {
            let pole = unit("pole", s.pole)?;
            let meridian = pole.any_orthonormal_vector();
            let shape = Shape::Sphere(Sphere {
                center: finite_vec(&key("center"), s.center)? / r_s,
                radius: positive("radius", s.radius)? / r_s,
                pole,
                meridian,
            });
            (shape, &s.material)
        }
        ObjectConfig::Rectangle(r) => {
            let normal = unit("normal", r.normal)?;
            let u_axis = match r.width_axis {
                Some(w) => {
                    let w = unit("width_axis", w)?;
                    (w - normal * w.dot(normal))
                        .try_normalize()
                        .ok_or_else(|| {
                            invalid(&key("width_axis"), w, "must not be along the normal")
                        })?
                }
                None => normal.any_orthonormal_vector(),
            };
            let shape = Shape::Rectangle(Rectangle {
                center: finite_vec(&key("center"), r.center)? / r_s,
                normal,
                u_axis,
                half: (
                    0.5 * positive("size", r.size[0])? / r_s,
                    0.5 * positive("size", r.size[1])? / r_s,
                ),
            });
            (shape, &r.material)
        }
        ObjectConfig::Mesh(m) => {
            let scale = positive("scale", m.scale)? / r_s;
            let rot = finite_vec(&key("rotation"), m.rotation)?;
            let q = DQuat::from_euler(
                EulerRot::ZYX,
                rot.z.to_radians(),
                rot.y.to_radians(),
                rot.x.to_radians(),
            );
            let t = DAffine3::from_scale_rotation_translation(
                DVec3::splat(scale),
                q,
                finite_vec(&key("position"), m.position)? / r_s,
            );
            let mesh = Mesh::load_obj(&m.file, t, m.smooth)
                .map_err(|e| invalid(&key("file"), &m.file, &format!("cannot load: {e}")))?;
            (Shape::Mesh(std::sync::Arc::new(mesh)), &m.material)
        }
    };
    let (finish, surface) = match mat {
        MaterialConfig::Color(s) => (Finish::Color, s),
        MaterialConfig::Mirror(s) => (Finish::Mirror, s),
        MaterialConfig::Lit(s) => {
            if !(s.specular.is_finite() && (0.0..=1.0).contains(&s.specular)) {
                return Err(invalid(
                    &key("material.specular"),
                    s.specular,
                    "expected 0 to 1",
                ));
            }
            if !(s.shininess.is_finite() && s.shininess >= 1.0) {
                return Err(invalid(
                    &key("material.shininess"),
                    s.shininess,
                    "expected a Phong exponent >= 1",
                ));
            }
            (
                Finish::Lit {
                    specular: s.specular as f32,
                    shininess: s.shininess as f32,
                },
                s,
            )
        }
    };
    let texture = match &surface.texture {
        Some(p) => Some(load_texture(&key("material.texture"), p)?),
        None => None,
    };
    Ok(Object {
        shape,
        material: Material {
            finish,
            color: colour(&key("material.color"), surface.color)?,
            texture,
        },
    })
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

/// Most radians the disk may have turned by the time rendered: f64 keeps
/// the angle to 2^32 epsilon, 1e-6 rad, a thousandth of a texel of the
/// shipped disk.
pub const MAX_PHASE: f64 = 4_294_967_296.0;

/// Largest image (pixels): its film alone is 12 GiB.
pub const MAX_PIXELS: u64 = 1 << 30;

/// The thin disk `[disk]` describes (`emission = "thin"`), its keys checked.
fn thin_disk(
    d: &crate::config::DiskConfig,
    config: &SceneConfig,
) -> Result<crate::thin_disk::ThinDisk, SceneError> {
    use crate::thin_disk::{Profile, ThinDisk};
    let profile = match config.physics.model {
        crate::config::ModelKind::Gr => Profile::NovikovThorne,
        crate::config::ModelKind::Seed => Profile::ShakuraSunyaev,
    };
    if d.spectrum.is_some() {
        return Err(invalid(
            "disk.spectrum",
            "set",
            "nothing with disk.emission = \"thin\", whose light is a blackbody (a disk.texture may modulate it)",
        ));
    }
    let inner = if d.inner_radius == 0.0 {
        3.0
    } else {
        d.inner_radius
    };
    if !(inner > 1.0) {
        return Err(invalid(
            "disk.inner_radius",
            d.inner_radius,
            "an inner edge outside the horizon, > 1 r_s (or 0 for the ISCO, 3 r_s)",
        ));
    }
    if profile == Profile::NovikovThorne && inner < 3.0 {
        return Err(invalid(
            "disk.inner_radius",
            d.inner_radius,
            "at least 3 r_s (the ISCO) for a thin disk under physics.model = \"gr\": Novikov-Thorne gas has no stable circular orbits further in (0 means the ISCO)",
        ));
    }
    if !(d.f_col.is_finite() && d.f_col >= 1.0) {
        return Err(invalid(
            "disk.f_col",
            d.f_col,
            "a colour-correction factor >= 1 (1: a pure blackbody)",
        ));
    }
    let mass = config.black_hole.mass;
    let rate = match (d.accretion_rate, d.peak_temperature) {
        (Some(m), None) if m.is_finite() && m > 0.0 => m,
        (Some(m), None) => {
            return Err(invalid("disk.accretion_rate", m, "a rate > 0, in kg/s"));
        }
        (None, Some(t)) if t.is_finite() && t > 0.0 => {
            ThinDisk::rate_for_peak(profile, mass, inner, t)
        }
        (None, Some(t)) => {
            return Err(invalid(
                "disk.peak_temperature",
                t,
                "a temperature > 0, in kelvin",
            ));
        }
        (Some(_), Some(_)) => {
            return Err(invalid(
                "disk.peak_temperature",
                "set",
                "one of disk.accretion_rate (kg/s) and disk.peak_temperature (K), not both",
            ));
        }
        (None, None) => {
            return Err(invalid(
                "disk.emission",
                "thin",
                "disk.accretion_rate (kg/s) or disk.peak_temperature (K) with it",
            ));
        }
    };
    Ok(ThinDisk::new(profile, mass, rate, inner, d.f_col))
}
