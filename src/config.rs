//! The scene file, mirrored one to one by serde types.
//!
//! Parsing only collects what the file says; [`crate::scene::Scene::build`]
//! checks the values and loads assets. Every table rejects unknown keys. Units
//! are SI (kg, m); the disk's radii are in Schwarzschild radii.
//!
//! ```toml
//! [image]
//! width = 1024
//! height = 1024
//! png = "../img/side.png"
//!
//! [camera]
//! position = [0.0, -2.0e11, 2.5e10]
//! look_at = [0.0, 0.0, 0.0]
//! fov = 50.0
//!
//! [black_hole]
//! mass = 8.57e36
//!
//! [disk]
//! radius = 10.0
//! texture = "../spectral_assets/disk_rgba.png"
//!
//! [sky]
//! texture = "../spectral_assets/sky.png"
//! ```

use serde::Deserialize;
use std::path::{Path, PathBuf};
use thiserror::Error;

mod problems;

/// A whole scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// `[image]`: output size, sampling and files.
    pub image: ImageConfig,
    /// `[camera]`: the pinhole camera.
    pub camera: CameraConfig,
    /// `[black_hole]`: the lens.
    pub black_hole: BlackHoleConfig,
    /// `[physics]`: which ray model and how accurately.
    #[serde(default)]
    pub physics: PhysicsConfig,
    /// `[disk]`: the accretion disk; leave the table out for none.
    pub disk: Option<DiskConfig>,
    /// `[sky]`: the panorama at infinity.
    pub sky: SkyConfig,
    /// `[spectral]`: wavelength-sampled rendering with frequency shift.
    #[serde(default)]
    pub spectral: SpectralConfig,
    /// `[volume]`: a volumetric accretion disk (instead of `[disk]`).
    pub volume: Option<VolumeConfig>,
    /// `[[cloud]]`: absorbing gas clouds.
    #[serde(default, rename = "cloud")]
    pub clouds: Vec<CloudConfig>,
    /// `[stereo]`: also render an off-axis stereo pair.
    pub stereo: Option<StereoConfig>,
    /// `[bloom]`: glow around bright light.
    pub bloom: Option<BloomConfig>,
    /// `[[object]]`: spheres, rectangles and meshes.
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectConfig>,
    /// `[[light]]`: what lights `lit` objects.
    #[serde(default, rename = "light")]
    pub lights: Vec<LightConfig>,
    /// `[animation]`: frames over time, the disk turning, the camera moving.
    pub animation: Option<AnimationConfig>,
    /// Settings in the document that do nothing in this scene (filled by
    /// [`SceneConfig::load`]), one line each.
    #[serde(skip)]
    pub warnings: Vec<String>,
}

/// `[volume]`: a volumetric accretion disk of glowing gas, instead of the
/// flat `[disk]`.
///
/// ```toml
/// [volume]
/// inner = 3.0            # r_s (the ISCO)
/// outer = 12.0           # r_s
/// thickness = 0.6        # r_s: Gaussian scale height at the outer edge (flares outward)
/// opacity = 1.5          # absorption per r_s at density 1
/// emission = 1.0         # source luminance at the peak temperature
/// peak_kelvin = 5000.0   # thin-disk temperature profile's peak
/// step = 0.05            # r_s between samples along the ray
/// seed = 7               # turbulence
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VolumeConfig {
    /// Inner radius (r_s).
    #[serde(default = "isco")]
    pub inner: f64,
    /// Outer radius (r_s).
    pub outer: f64,
    /// Scale height at the outer edge (r_s).
    pub thickness: f64,
    /// Absorption coefficient per r_s at density 1.
    #[serde(default = "default_opacity")]
    pub opacity: f64,
    /// Source-function luminance at the peak temperature.
    #[serde(default = "one_f")]
    pub emission: f64,
    /// Peak temperature (K).
    #[serde(default = "default_peak_kelvin")]
    pub peak_kelvin: f64,
    /// Sampling step along the ray (r_s).
    #[serde(default = "default_volume_step")]
    pub step: f64,
    /// Turbulence seed.
    #[serde(default = "default_seed")]
    pub seed: u32,
}

/// `[[cloud]]`: an absorbing gas cloud (Beer-Lambert). It dims what lies
/// behind but never hides it (optical depth at most 3 through its centre),
/// and glows faintly with the light it scatters, so it is never black.
///
/// ```toml
/// [[cloud]]
/// center = [0.0, -1.2e11, 1.0e10]  # metres
/// radius = 3.0e10                  # metres
/// depth = 1.0                      # optical depth through the centre at 550 nm
/// beta = 1.0                       # extinction ~ (lambda / 550 nm)^-beta (0: grey)
/// color = [0.05, 0.04, 0.035]      # glow where opaque (linear sRGB)
/// seed = 1                         # lumpiness
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudConfig {
    /// Centre (m).
    pub center: [f64; 3],
    /// Radius (m).
    pub radius: f64,
    /// Optical depth through the centre at 550 nm.
    pub depth: f64,
    /// Extinction exponent.
    #[serde(default)]
    pub beta: f64,
    /// Glow (linear sRGB).
    #[serde(default = "cloud_glow")]
    pub color: [f64; 3],
    /// Lumpiness seed.
    #[serde(default = "default_seed")]
    pub seed: u32,
}

/// `[animation]`: what `blackhole animate` renders.
///
/// ```toml
/// [animation]
/// frames = 120              # frame k shows t = start + k * duration / frames
/// fps = 30.0                # frames per second of the video
/// duration = 4000.0         # seconds of simulated (coordinate) time spanned
/// start = 0.0               # seconds
/// rotation = "keplerian"    # or "rigid" (with period, seconds)
/// light_travel_time = false # each ray sees the disk when its light left it
/// video = "../img/orbit.gif"  # .mp4 (ffmpeg), .gif or .png (animated)
/// quality = 20              # mp4: x264's crf (0-51, lower is better)
///
/// [animation.orbit]         # or [[animation.keyframe]]s; neither: fixed camera
/// azimuth = [0.0, 60.0]     # degrees about +z, 0 = on the -y axis
/// elevation = [45.0, 5.0]   # degrees above the disk's plane
/// distance = 2.5e11         # metres from the hole
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimationConfig {
    /// Number of frames (with `fps` and `duration`: all three, or none
    /// for a still's clock).
    pub frames: Option<u32>,
    /// Frames per second of the video.
    pub fps: Option<f64>,
    /// Simulated time spanned (s).
    pub duration: Option<f64>,
    /// Time of frame 0 (s).
    #[serde(default)]
    pub start: f64,
    /// How the disk turns.
    #[serde(default)]
    pub rotation: RotationKind,
    /// Rigid rotation's period (s).
    pub period: Option<f64>,
    /// Each ray sees the disk at the time its light left it.
    #[serde(default)]
    pub light_travel_time: bool,
    /// The video file (.mp4, .gif or animated .png).
    pub video: Option<PathBuf>,
    /// MP4 quality: x264's constant rate factor, 0-51.
    #[serde(default = "default_quality")]
    pub quality: u32,
    /// A camera circling the hole's axis.
    pub orbit: Option<OrbitConfig>,
    /// A camera through keyframes.
    #[serde(default, rename = "keyframe")]
    pub keyframes: Vec<KeyframeConfig>,
}

/// How the disk turns.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum RotationKind {
    /// Each ring at its Keplerian angular velocity sqrt(GM / r^3).
    #[default]
    Keplerian,
    /// All of it with one period.
    Rigid,
}

/// `[animation.orbit]`: the camera on a sphere about the hole, its
/// azimuth and elevation moving linearly in time from start to end.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitConfig {
    /// Azimuth at the start and the end (degrees about +z from the -y axis).
    pub azimuth: [f64; 2],
    /// Elevation above the disk's plane at the start and the end (degrees).
    pub elevation: [f64; 2],
    /// Distance from the hole (m).
    pub distance: f64,
    /// Point the camera looks at (m).
    #[serde(default)]
    pub look_at: [f64; 3],
}

/// `[[animation.keyframe]]`: the camera at one instant.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeConfig {
    /// Time (s).
    pub time: f64,
    /// Position (m).
    pub position: [f64; 3],
    /// Point looked at (m).
    pub look_at: [f64; 3],
    /// Up direction.
    #[serde(default = "z_up")]
    pub up: [f64; 3],
    /// Vertical field of view (degrees); the camera's when left out.
    pub fov: Option<f64>,
}

/// `[stereo]`: an off-axis stereo pair rendered beside the mono image.
///
/// ```toml
/// [stereo]
/// separation = 2.0e10    # metres between the eyes (black-hole scale!)
/// convergence = 2.5e11   # metres to the zero-parallax plane (default: look_at)
/// ```
/// Writes NAME_left.png, NAME_right.png, NAME_side_by_side.png (left image
/// on the left) and NAME_anaglyph.png (red-cyan) next to `image.png`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StereoConfig {
    /// Distance between the eyes (m).
    pub separation: f64,
    /// Distance from the camera to the plane of zero parallax (m).
    pub convergence: Option<f64>,
}

/// `[bloom]`: light spread around bright regions, on linear values before
/// tone mapping; the total light is kept.
///
/// ```toml
/// [bloom]
/// strength = 0.15        # fraction of the light spread out
/// radius = 0.01          # Gaussian sigma, fraction of the image height
/// spectral = false       # spectral renders: spread grows with wavelength
/// exr = false            # also bloom the EXR (else it stays unbloomed)
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BloomConfig {
    /// Fraction of the light spread out.
    pub strength: f64,
    /// Gaussian sigma as a fraction of the image height.
    pub radius: f64,
    /// Spectral renders: a point spread whose width grows with wavelength
    /// (like an Airy disc, radius ~ lambda; `radius` is at 550 nm).
    #[serde(default)]
    pub spectral: bool,
    /// Apply to the EXR too.
    #[serde(default)]
    pub exr: bool,
}

/// `[[object]]`: a solid object, by `kind`.
///
/// ```toml
/// [[object]]
/// kind = "sphere"
/// center = [3.0e11, 1.0e11, 2.0e10]   # metres
/// radius = 2.0e10                     # metres
/// material = { kind = "lit", color = [0.6, 0.5, 0.4] }
///
/// [[object]]
/// kind = "rectangle"
/// center = [0.0, 2.0e11, 0.0]
/// normal = [0.0, -1.0, 0.0]           # front side
/// size = [1.0e11, 5.0e10]             # width, height in metres
/// material = { kind = "mirror" }
///
/// [[object]]
/// kind = "mesh"
/// file = "../spectral_assets/meshes/asteroid_0.obj"
/// position = [1.5e11, -1.0e11, 3.0e10] # metres
/// rotation = [10.0, 20.0, 30.0]        # degrees about x, then y, then z
/// scale = 4.0e9                        # metres per model unit
/// smooth = true                        # vertex normals if the file has none
/// material = { kind = "lit", color = [0.4, 0.38, 0.35] }
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ObjectConfig {
    /// A sphere.
    Sphere(SphereConfig),
    /// A rectangle.
    Rectangle(RectangleConfig),
    /// A triangle mesh from an OBJ file.
    Mesh(MeshConfig),
}

/// A sphere (planet, moon).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereConfig {
    /// Centre (m).
    pub center: [f64; 3],
    /// Radius (m).
    pub radius: f64,
    /// Axis of the texture's poles.
    #[serde(default = "z_up")]
    pub pole: [f64; 3],
    /// Surface.
    pub material: MaterialConfig,
}

/// A rectangle (a bounded plane).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleConfig {
    /// Centre (m).
    pub center: [f64; 3],
    /// Normal of the front side.
    pub normal: [f64; 3],
    /// Direction of the width (default: any perpendicular to the normal).
    pub width_axis: Option<[f64; 3]>,
    /// Width and height (m).
    pub size: [f64; 2],
    /// Surface.
    pub material: MaterialConfig,
}

/// A triangle mesh.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshConfig {
    /// OBJ file.
    pub file: PathBuf,
    /// Where the model's origin goes (m).
    pub position: [f64; 3],
    /// Rotation in degrees about x, then y, then z.
    #[serde(default)]
    pub rotation: [f64; 3],
    /// Metres per model unit.
    pub scale: f64,
    /// Without normals in the file: smooth (vertex) normals rather than
    /// flat faces.
    #[serde(default = "yes")]
    pub smooth: bool,
    /// Surface.
    pub material: MaterialConfig,
}

/// A surface, by `kind`.
///
/// ```toml
/// material = { kind = "color", color = [1.0, 0.5, 0.2] }  # glows with this colour
/// material = { kind = "mirror", color = [0.9, 0.9, 0.9] } # reflects, tinted
/// material = { kind = "lit", color = [0.5, 0.5, 0.5], texture = "moon.png",
///              specular = 0.2, shininess = 30.0 }         # Phong-lit
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum MaterialConfig {
    /// Self-coloured, unlit.
    Color(SurfaceConfig),
    /// A perfect mirror; reflected rays keep bending.
    Mirror(SurfaceConfig),
    /// Lit by the `[[light]]`s (Phong).
    Lit(SurfaceConfig),
}

/// Parameters of a surface (unused ones are ignored by the kind).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceConfig {
    /// Colour (linear sRGB): emission, mirror tint or diffuse albedo.
    #[serde(default = "grey")]
    pub color: [f64; 3],
    /// Texture multiplying the colour (sphere: longitude-latitude;
    /// rectangle: its face; mesh: its UVs).
    pub texture: Option<PathBuf>,
    /// Lit: specular reflectance.
    #[serde(default)]
    pub specular: f64,
    /// Lit: Phong exponent.
    #[serde(default = "default_shininess")]
    pub shininess: f64,
}

/// `[[light]]`: light on `lit` objects, by `kind`.
///
/// ```toml
/// [[light]]
/// kind = "sun"                  # a distant star
/// direction = [1.0, -0.5, 0.3]  # towards the star
/// kelvin = 5800.0               # or color = [r, g, b]
/// intensity = 1.0               # irradiance on a surface facing it
///
/// [[light]]
/// kind = "disk"                 # the accretion disk's own glow
/// intensity = 1.0               # times its emission
///
/// [[light]]
/// kind = "ambient"
/// intensity = 0.02
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LightConfig {
    /// A distant star.
    Sun(SunConfig),
    /// The disk's emission.
    Disk(GlowConfig),
    /// Uniform light from everywhere.
    Ambient(GlowConfig),
}

/// A distant star.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunConfig {
    /// Direction towards the star.
    pub direction: [f64; 3],
    /// Its colour temperature (K); or give `color`.
    pub kelvin: Option<f64>,
    /// Its colour (linear sRGB).
    pub color: Option<[f64; 3]>,
    /// Irradiance on a surface facing it.
    #[serde(default = "one_f")]
    pub intensity: f64,
}

/// A light with only a strength (and, for ambient, a colour).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GlowConfig {
    /// Strength.
    #[serde(default = "one_f")]
    pub intensity: f64,
    /// Ambient colour (linear sRGB).
    #[serde(default = "white")]
    pub color: [f64; 3],
}

/// `[image]`
///
/// ```toml
/// [image]
/// width = 1024             # pixels
/// height = 1024            # pixels
/// samples = 1              # rays per pixel, stratified
/// png = "../img/front.png" # always written, 8-bit sRGB
/// exr = "../img/front.exr" # optional, scene-linear float
/// exr_xyz = false          # also write an XYZ layer into the EXR
/// exr_half = false         # 16-bit instead of 32-bit floats in the EXR
/// exposure = 0.0           # stops (EV) applied before tone mapping
/// tonemap = "clip"         # "clip", "reinhard" or "aces"
/// seed = 0                 # sampler seed
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageConfig {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Rays per pixel (stratified jitter; 1 = through the pixel centre).
    #[serde(default = "one")]
    pub samples: u32,
    /// PNG output path (8-bit sRGB).
    pub png: PathBuf,
    /// Optional EXR output path (scene-linear float RGB).
    pub exr: Option<PathBuf>,
    /// Also write CIE XYZ channels into the EXR.
    #[serde(default)]
    pub exr_xyz: bool,
    /// Store the EXR's channels as 16-bit floats.
    #[serde(default)]
    pub exr_half: bool,
    /// Exposure in stops, applied to the PNG only.
    #[serde(default)]
    pub exposure: f64,
    /// Tone-mapping curve for the PNG.
    #[serde(default)]
    pub tonemap: ToneMap,
    /// Seed of the per-pixel sample sequence.
    #[serde(default)]
    pub seed: u64,
}

/// How linear values become displayable ones.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ToneMap {
    /// Clip to [0, 1]: a texture comes out exactly as stored.
    #[default]
    Clip,
    /// Reinhard L / (1 + L) on luminance, hue kept.
    Reinhard,
    /// The ACES filmic fit of Narkowicz (2015), per channel.
    Aces,
}

/// `[camera]`
///
/// ```toml
/// [camera]
/// position = [0.0, -2.0e11, 2.5e10] # metres; hole at the origin
/// look_at = [0.0, 0.0, 0.0]         # metres
/// up = [0.0, 0.0, 1.0]              # any vector not along the view
/// fov = 50.0                        # vertical field of view, degrees
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// Position (m).
    pub position: [f64; 3],
    /// Point the camera looks at (m).
    pub look_at: [f64; 3],
    /// Up direction.
    #[serde(default = "z_up")]
    pub up: [f64; 3],
    /// Vertical field of view (degrees).
    pub fov: f64,
}

/// `[black_hole]`
///
/// ```toml
/// [black_hole]
/// mass = 8.57e36   # kg
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlackHoleConfig {
    /// Mass (kg).
    pub mass: f64,
}

/// `[physics]`
///
/// ```toml
/// [physics]
/// model = "gr"        # "gr" (exact) or "seed" (the assignment's)
/// tolerance = 1e-6    # gr: relative error per step
/// step = 0.005        # seed: dt as a fraction of r / c
/// max_steps = 100000  # per ray
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicsConfig {
    /// Ray model.
    #[serde(default)]
    pub model: ModelKind,
    /// Exact model: relative error allowed per integration step.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Seed model: step as a fraction of r / c.
    #[serde(default = "default_step")]
    pub step: f64,
    /// Steps after which a ray is abandoned (drawn black and counted).
    #[serde(default = "default_max_steps")]
    pub max_steps: u32,
    /// `gr` scenes of disk and sky only: trace rays in closed form where
    /// the closed form applies (false: always the integrator).
    #[serde(default = "yes")]
    pub closed_form: bool,
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        PhysicsConfig {
            model: ModelKind::default(),
            tolerance: default_tolerance(),
            step: default_step(),
            max_steps: default_max_steps(),
            closed_form: true,
        }
    }
}

/// The two ray models.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// Exact Schwarzschild null geodesics.
    #[default]
    Gr,
    /// The assignment's Newtonian model with |v| = c.
    Seed,
}

impl ModelKind {
    /// The name as written in `physics.model`.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Gr => "gr",
            ModelKind::Seed => "seed",
        }
    }
}

/// `[disk]`
///
/// ```toml
/// [disk]
/// radius = 10.0          # outer radius, in r_s
/// inner_radius = 0.0     # in r_s; 0 lets the texture's alpha decide
/// texture = "../spectral_assets/disk_rgba.png"  # spans [-radius, radius]^2
/// spectrum = "../spectral_assets/disk_spectral/manifest.toml" # per-wavelength set
/// filter = "nearest"     # or "bilinear"
/// alpha = "cutout"       # alpha 0 = hole, else opaque; or "blend"
/// intensity = 1.0        # multiplies the texture's linear colour
/// emission = "texture"   # or "thin": blackbody at the thin-disk temperature
/// accretion_rate = 1e19  # thin: kg/s (or peak_temperature, K)
/// f_col = 1.0            # thin: colour correction, B(f_col T) / f_col^4
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiskConfig {
    /// Outer radius in Schwarzschild radii.
    pub radius: f64,
    /// Inner radius in Schwarzschild radii.
    #[serde(default)]
    pub inner_radius: f64,
    /// RGBA texture over the square [-radius, radius]^2 of the disk plane.
    pub texture: Option<PathBuf>,
    /// Spectral texture set (manifest) over the same square; used in
    /// spectral mode, and in RGB mode when there is no `texture`.
    pub spectrum: Option<PathBuf>,
    /// Texture filter.
    #[serde(default)]
    pub filter: Filter,
    /// How the texture's alpha is used.
    #[serde(default)]
    pub alpha: AlphaMode,
    /// Linear multiplier of the texture colour.
    #[serde(default = "one_f")]
    pub intensity: f64,
    /// Where the disk's light comes from.
    #[serde(default)]
    pub emission: DiskEmission,
    /// Thin disk: accretion rate (kg/s).
    pub accretion_rate: Option<f64>,
    /// Thin disk: the highest effective temperature (K), which sets the
    /// accretion rate.
    pub peak_temperature: Option<f64>,
    /// Thin disk: colour-correction factor (spectrum B(f_col T) / f_col^4).
    #[serde(default = "one_f")]
    pub f_col: f64,
}

/// `disk.emission`.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum DiskEmission {
    /// The texture (uplifted RGB) or the spectral set.
    #[default]
    Texture,
    /// A geometrically thin, optically thick accretion disk radiating as
    /// a blackbody at its effective temperature.
    Thin,
}

/// `[sky]`: exactly one of `texture`, `color`, `blackbody`, `stars`.
///
/// ```toml
/// [sky]
/// texture = "../spectral_assets/sky.png" # 2:1 equirectangular
/// # color = [1.0, 1.0, 1.0]             # uniform, linear sRGB
/// # blackbody = 5800.0                   # uniform, kelvin, luminance 1
/// # stars = "../spectral_assets/stars/hipparcos_mag8.csv" # catalogue
/// milky_way = true                       # stars: add the Milky Way band
/// resolution = 4096                      # stars: panorama width, texels
/// filter = "nearest"                     # or "bilinear"
/// intensity = 1.0                        # linear multiplier
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkyConfig {
    /// Equirectangular panorama (2:1).
    pub texture: Option<PathBuf>,
    /// Uniform colour, linear sRGB.
    pub color: Option<[f64; 3]>,
    /// Uniform blackbody colour at this temperature (K), luminance 1.
    pub blackbody: Option<f64>,
    /// Star catalogue CSV (`hip,ra_deg,dec_deg,vmag,bv`): every star a
    /// blackbody at its B-V temperature.
    pub stars: Option<PathBuf>,
    /// With `stars`: add the faint Milky Way band.
    #[serde(default = "yes")]
    pub milky_way: bool,
    /// With `stars`: width of the star map in texels (height is half).
    #[serde(default = "default_star_resolution")]
    pub resolution: u32,
    /// Texture filter.
    #[serde(default)]
    pub filter: Filter,
    /// Linear multiplier.
    #[serde(default = "one_f")]
    pub intensity: f64,
}

/// `[spectral]`
///
/// ```toml
/// [spectral]
/// enabled = true          # false (or no table): RGB rendering
/// wavelengths = 81        # samples over 380-780 nm, 2 to 401
/// shift = true            # frequency shift on/off
/// beaming = false         # radiance times g^5
/// doppler = true          # disk rotation's Doppler shift (with shift)
/// interpolation = "nearest" # emitter lookup at g*lambda: or "linear"
/// per_wavelength = false  # reference path: one traced ray per wavelength
/// exr_layers = false      # per-wavelength layers in the EXR
/// ```
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpectralConfig {
    /// Render spectra instead of RGB.
    #[serde(default)]
    pub enabled: bool,
    /// Wavelength samples over 380-780 nm.
    #[serde(default = "default_wavelengths")]
    pub wavelengths: u32,
    /// Apply the frequency shift g = nu_obs / nu_emit.
    #[serde(default = "yes")]
    pub shift: bool,
    /// Scale radiance by g^5 (relativistic beaming).
    #[serde(default)]
    pub beaming: bool,
    /// Include the Doppler shift of the disk's Keplerian rotation.
    #[serde(default = "yes")]
    pub doppler: bool,
    /// How an emitter's spectrum is read at g * lambda.
    #[serde(default)]
    pub interpolation: Interpolation,
    /// Trace one ray per wavelength (the assignment's literal method; for
    /// checking that one geodesic per sample gives the same image).
    #[serde(default)]
    pub per_wavelength: bool,
    /// Write each wavelength as an EXR layer (spectral OpenEXR layout).
    #[serde(default)]
    pub exr_layers: bool,
}

impl Default for SpectralConfig {
    fn default() -> Self {
        SpectralConfig {
            enabled: false,
            wavelengths: default_wavelengths(),
            shift: true,
            beaming: false,
            doppler: true,
            interpolation: Interpolation::default(),
            per_wavelength: false,
            exr_layers: false,
        }
    }
}

/// Reading a tabulated spectrum between its wavelengths.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    /// The nearest tabulated wavelength.
    #[default]
    Nearest,
    /// Linear between the two nearest.
    Linear,
}

/// Texture lookup.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// The nearest texel.
    #[default]
    Nearest,
    /// Bilinear interpolation of the four nearest texels.
    Bilinear,
}

/// What a disk texel's alpha means.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum AlphaMode {
    /// 0 lets the ray through, anything else stops it (the assignment's base).
    #[default]
    Cutout,
    /// Colour = a * texel + (1 - a) * what lies behind; the ray goes on.
    Blend,
}

fn one() -> u32 {
    1
}
fn one_f() -> f64 {
    1.0
}
fn z_up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}
fn default_tolerance() -> f64 {
    1e-6
}
fn default_step() -> f64 {
    0.005
}
fn default_max_steps() -> u32 {
    100_000
}
fn isco() -> f64 {
    3.0
}
fn default_opacity() -> f64 {
    1.5
}
fn default_peak_kelvin() -> f64 {
    5000.0
}
fn default_volume_step() -> f64 {
    0.05
}
fn default_seed() -> u32 {
    7
}
fn cloud_glow() -> [f64; 3] {
    [0.03, 0.025, 0.02]
}
fn grey() -> [f64; 3] {
    [0.8, 0.8, 0.8]
}
fn white() -> [f64; 3] {
    [1.0, 1.0, 1.0]
}
fn default_shininess() -> f64 {
    32.0
}
fn yes() -> bool {
    true
}
fn default_wavelengths() -> u32 {
    81
}
fn default_star_resolution() -> u32 {
    4096
}
fn default_quality() -> u32 {
    20
}

/// A failure to read or parse a scene file.
#[derive(Debug, Error)]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read scene file {path}: {cause}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// The file is not valid TOML or does not match the schema.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What and where (line and column), in the scene file's terms.
        message: String,
    },
    /// Keys the schema does not take, values of the wrong type, missing
    /// keys: every one of them, one line each.
    #[error("{path}: {}", schema_text(.problems))]
    Schema {
        /// The file.
        path: PathBuf,
        /// Each problem, with its line or the override it comes from.
        problems: Vec<String>,
    },
    /// A `--set` or `--unset` is malformed or does not fit the schema.
    #[error("{flag}: {message}")]
    Override {
        /// The option as given, e.g. `--set image.width=wide`.
        flag: String,
        /// What is wrong.
        message: String,
    },
    /// A path cannot be resolved.
    #[error("{key} = {path:?}: {message}")]
    Path {
        /// Dotted key.
        key: String,
        /// The path as written.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

fn schema_text(problems: &[String]) -> String {
    match problems {
        [one] => one.clone(),
        all => format!("{} problems:\n  {}", all.len(), all.join("\n  ")),
    }
}

/// Rewrites serde's type names in a schema error as the scene file's
/// words ("u32" -> "a whole number", "struct ImageConfig" -> "a table").
pub fn humanize(message: &str) -> String {
    let mut out = message.trim_end().to_string();
    for t in [
        "u8", "u16", "u32", "u64", "usize", "i8", "i16", "i32", "i64", "isize",
    ] {
        out = replace_word(&out, &format!("expected {t}"), "expected a whole number");
    }
    for t in ["f32", "f64"] {
        out = replace_word(&out, &format!("expected {t}"), "expected a number");
    }
    // "expected struct ImageConfig": the name after it is Rust's.
    for (from, to) in [
        (
            "expected internally tagged enum ",
            "expected a table with a `kind`",
        ),
        ("expected struct ", "expected a table"),
        ("expected enum ", "expected one of its names"),
    ] {
        while let Some(i) = out.find(from) {
            let rest = &out[i + from.len()..];
            let name = rest
                .find(|c: char| !c.is_alphanumeric() && c != '_')
                .unwrap_or(rest.len());
            out = format!("{}{to}{}", &out[..i], &rest[name..]);
        }
    }
    for (from, to) in [
        ("expected a sequence", "expected an array"),
        ("invalid type: sequence", "invalid type: array"),
        ("invalid type: map", "invalid type: table"),
        ("expected a map", "expected a table"),
        ("floating point", "number"),
    ] {
        out = out.replace(from, to);
    }
    out
}

/// Replaces `from` where it is not followed by a letter or digit.
fn replace_word(text: &str, from: &str, to: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find(from) {
        let after = &rest[i + from.len()..];
        out += &rest[..i];
        if after.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
            out += from;
        } else {
            out += to;
        }
        rest = after;
    }
    out + rest
}

/// One part of a dotted key: a table key or an index into an array of
/// tables (`object.0.radius`).
#[derive(Clone, Debug, PartialEq)]
enum Part {
    Key(String),
    Index(usize),
}

/// A `--set key=value` or `--unset key` from the command line.
#[derive(Clone, Debug)]
pub struct Override {
    /// Dotted key, e.g. `image.width` or `object.0.radius`.
    pub key: String,
    /// Value as TOML (a bare word that is not TOML counts as a string);
    /// `None` removes the key.
    pub value: Option<toml::Value>,
    parts: Vec<Part>,
    flag: String,
}

impl Override {
    /// Parses `key=value` (the argument of `--set`).
    pub fn parse(assignment: &str) -> Result<Override, ConfigError> {
        let flag = format!("--set {assignment}");
        let err = |message: &str| ConfigError::Override {
            flag: flag.clone(),
            message: message.to_string(),
        };
        let (key, raw) = assignment
            .split_once('=')
            .ok_or_else(|| err("expected key=value, e.g. image.width=256"))?;
        let (key, parts) = parse_key(key).map_err(|m| err(&m))?;
        let raw = raw.trim();
        let value = toml::from_str::<toml::Table>(&format!("v = {raw}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(raw.to_string()));
        Ok(Override {
            key,
            value: Some(value),
            parts,
            flag,
        })
    }

    /// Parses the argument of `--unset`.
    pub fn unset(key: &str) -> Result<Override, ConfigError> {
        let flag = format!("--unset {key}");
        let (key, parts) = parse_key(key).map_err(|message| ConfigError::Override {
            flag: flag.clone(),
            message,
        })?;
        Ok(Override {
            key,
            value: None,
            parts,
            flag,
        })
    }

    /// Sets `key` (dotted, as for `--set`) to `value`: for programs that
    /// change a config, such as the viewer.
    pub fn value(key: &str, value: toml::Value) -> Override {
        let (key, parts) = parse_key(key).unwrap_or_else(|m| panic!("key {key:?}: {m}"));
        Override {
            flag: format!("{key}={value}"),
            key,
            value: Some(value),
            parts,
        }
    }

    /// The option as given on the command line.
    pub fn flag(&self) -> &str {
        &self.flag
    }

    fn apply(&self, table: &mut toml::Table) -> Result<(), ConfigError> {
        let err = |message: String| ConfigError::Override {
            flag: self.flag.clone(),
            message,
        };
        let name = |upto: usize| key_text(&self.parts[..upto]);
        let (last, parents) = self.parts.split_last().expect("keys are checked non-empty");
        let set = self.value.is_some();
        let mut node = TomlSlot::Table(table);
        for (i, p) in parents.iter().enumerate() {
            node = match (node, p) {
                (TomlSlot::Table(t), Part::Key(k)) => {
                    if !t.contains_key(k) {
                        if !set {
                            return Err(err(format!("`{}` is not set", name(i + 1))));
                        }
                        // A list when an index follows (`object.0` on a
                        // scene without objects), else a table.
                        let empty = match self.parts[i + 1] {
                            Part::Index(_) => toml::Value::Array(Vec::new()),
                            Part::Key(_) => toml::Value::Table(toml::Table::new()),
                        };
                        t.insert(k.clone(), empty);
                    }
                    TomlSlot::from_value(t.get_mut(k).expect("present"))
                        .ok_or_else(|| err(format!("`{}` is not a table", name(i + 1))))?
                }
                (TomlSlot::Array(a), Part::Index(n)) => {
                    let len = a.len();
                    let v = a.get_mut(*n).ok_or_else(|| {
                        err(format!("`{}` has {len} entries: no index {n}", name(i)))
                    })?;
                    TomlSlot::from_value(v)
                        .ok_or_else(|| err(format!("`{}` is not a table", name(i + 1))))?
                }
                (TomlSlot::Table(_), Part::Index(_)) => {
                    return Err(err(format!(
                        "`{}` is a table, not a list: give a key after `{}`",
                        name(i),
                        name(i)
                    )));
                }
                (TomlSlot::Array(_), Part::Key(_)) => {
                    return Err(err(format!(
                        "`{}` is a list: give an entry's index, e.g. {}.0",
                        name(i),
                        name(i)
                    )));
                }
            };
        }
        match (node, last, &self.value) {
            (TomlSlot::Table(t), Part::Key(k), Some(v)) => {
                t.insert(k.clone(), v.clone());
            }
            (TomlSlot::Table(t), Part::Key(k), None) => {
                t.remove(k)
                    .ok_or_else(|| err(format!("`{}` is not set", self.key)))?;
            }
            (TomlSlot::Array(a), Part::Index(n), value) => {
                let len = a.len();
                match value {
                    Some(v) if *n < len => a[*n] = v.clone(),
                    // One past the end appends an entry.
                    Some(v) if *n == len => a.push(v.clone()),
                    None if *n < len => {
                        a.remove(*n);
                    }
                    _ => {
                        return Err(err(format!(
                            "`{}` has {len} entries: no index {n}",
                            name(self.parts.len() - 1)
                        )));
                    }
                }
            }
            (TomlSlot::Array(_), Part::Key(_), _) => {
                let n = name(self.parts.len() - 1);
                return Err(err(format!(
                    "`{n}` is a list: give an entry's index, e.g. {n}.0"
                )));
            }
            (TomlSlot::Table(_), Part::Index(_), _) => {
                let n = name(self.parts.len() - 1);
                return Err(err(format!("`{n}` is a table, not a list")));
            }
        }
        Ok(())
    }
}

/// A place in a TOML document that keys or indices lead into.
enum TomlSlot<'a> {
    Table(&'a mut toml::Table),
    Array(&'a mut Vec<toml::Value>),
}

impl<'a> TomlSlot<'a> {
    fn from_value(v: &'a mut toml::Value) -> Option<TomlSlot<'a>> {
        match v {
            toml::Value::Table(t) => Some(TomlSlot::Table(t)),
            toml::Value::Array(a) => Some(TomlSlot::Array(a)),
            _ => None,
        }
    }
}

/// Splits a dotted key into table keys and (numeric) list indices.
fn parse_key(key: &str) -> Result<(String, Vec<Part>), String> {
    let words: Vec<&str> = key.split('.').map(str::trim).collect();
    if words.iter().any(|w| w.is_empty()) {
        return Err("the key must be a dotted name such as image.width or object.0.radius".into());
    }
    let parts: Vec<Part> = words
        .iter()
        .map(|w| match w.parse::<usize>() {
            Ok(n) if w.bytes().all(|b| b.is_ascii_digit()) => Part::Index(n),
            _ => Part::Key(w.to_string()),
        })
        .collect();
    if let Some(Part::Index(_)) = parts.first() {
        return Err("the key must start with a table's name, e.g. object.0.radius".into());
    }
    Ok((words.join("."), parts))
}

fn key_text(parts: &[Part]) -> String {
    parts
        .iter()
        .map(|p| match p {
            Part::Key(k) => k.clone(),
            Part::Index(n) => n.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// Expands a leading `~` or `~/` to the home folder, as a shell would.
fn expand_home(key: &str, p: &Path) -> Result<PathBuf, ConfigError> {
    let text = p.to_string_lossy();
    let err = |message: &str| ConfigError::Path {
        key: key.to_string(),
        path: p.to_path_buf(),
        message: message.to_string(),
    };
    if !text.starts_with('~') {
        return Ok(p.to_path_buf());
    }
    let rest = match text.strip_prefix('~') {
        Some("") => "",
        Some(r) if r.starts_with('/') => &r[1..],
        _ => {
            return Err(err(
                "only ~ and ~/ are expanded (to $HOME); write the full path",
            ));
        }
    };
    let home = std::env::var_os("HOME")
        .filter(|h| !h.is_empty())
        .ok_or_else(|| err("~ means $HOME, which is not set; write the full path"))?;
    Ok(PathBuf::from(home).join(rest))
}

/// Whether `key` (e.g. `image.png`, `object.0.file`) was set from the
/// command line: the key itself, or a table or entry above it.
pub fn from_cli(overrides: &[Override], key: &str) -> bool {
    overrides.iter().any(|o| {
        o.value.is_some()
            && (o.key == key
                || key
                    .strip_prefix(o.key.as_str())
                    .is_some_and(|r| r.starts_with('.')))
    })
}

impl SceneConfig {
    /// Reads a scene file, applies overrides (in the order given), and
    /// makes every path absolute: paths from the file against the file's
    /// folder, paths from overrides against the current directory, `~/`
    /// as the home folder. When `image.png` comes from the command line,
    /// the EXR and the animation's video (unless named there too) move
    /// beside the PNG with the same stem, so every output follows it.
    pub fn load(path: &Path, overrides: &[Override]) -> Result<SceneConfig, ConfigError> {
        let text = read_scene_text(path)?;
        let parse_err = |e: toml::de::Error| ConfigError::Parse {
            path: path.to_path_buf(),
            message: humanize(&e.to_string()),
        };
        let file: toml::Table = toml::from_str(&text).map_err(parse_err)?;
        let mut table = file.clone();
        for o in overrides {
            o.apply(&mut table)?;
        }
        let mut config = problems::check(&table).map_err(|mut list| {
            // In the file's order within each kind.
            list.sort_by_key(|p| {
                let at = span_of(&text, &p.parts).map_or(usize::MAX, |s| s.0);
                (p.kind.rank(), at)
            });
            ConfigError::Schema {
                path: path.to_path_buf(),
                problems: list.iter().map(|p| describe(p, &text, overrides)).collect(),
            }
        })?;
        let base = path.parent().unwrap_or(Path::new(""));
        let cwd = std::env::current_dir().unwrap_or_default();
        let base = if base.is_absolute() {
            base.to_path_buf()
        } else {
            cwd.join(base)
        };
        for (key, p) in config.paths_mut() {
            let cli = from_cli(overrides, &key);
            *p = expand_home(&key, p)?;
            if p.is_relative() {
                *p = normalize(&if cli { cwd.join(&*p) } else { base.join(&*p) });
            }
        }
        if from_cli(overrides, "image.png") {
            let png = config.image.png.clone();
            if !from_cli(overrides, "image.exr") && config.image.exr.is_some() {
                config.image.exr = Some(png.with_extension("exr"));
            }
            if let Some(a) = config.animation.as_mut()
                && !from_cli(overrides, "animation.video")
                && let Some(v) = a.video.as_mut()
            {
                let ext = v.extension().unwrap_or_default().to_os_string();
                *v = png.with_extension(ext);
            }
        }
        config.warnings = inert_settings(&table, &config);
        Ok(config)
    }

    /// The scene file at `path` with `overrides` applied, as TOML text
    /// that loads to the same config wherever it is written: every path
    /// in it absolute. (Comments and the file's layout are not kept.)
    pub fn saved_text(path: &Path, overrides: &[Override]) -> Result<String, ConfigError> {
        let mut config = SceneConfig::load(path, overrides)?;
        let text = read_scene_text(path)?;
        let mut table: toml::Table = toml::from_str(&text).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: humanize(&e.to_string()),
        })?;
        for o in overrides {
            o.apply(&mut table)?;
        }
        for (key, p) in config.paths_mut() {
            Override::value(&key, p.display().to_string().into()).apply(&mut table)?;
        }
        let text = toml::to_string_pretty(&table).map_err(|e| ConfigError::Parse {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Ok(tidy_floats(&text))
    }

    /// Every path-valued key with its dotted name.
    pub fn paths_mut(&mut self) -> Vec<(String, &mut PathBuf)> {
        let mut v: Vec<(String, &mut PathBuf)> = vec![("image.png".into(), &mut self.image.png)];
        if let Some(p) = self.image.exr.as_mut() {
            v.push(("image.exr".into(), p));
        }
        if let Some(d) = self.disk.as_mut() {
            if let Some(p) = d.texture.as_mut() {
                v.push(("disk.texture".into(), p));
            }
            if let Some(p) = d.spectrum.as_mut() {
                v.push(("disk.spectrum".into(), p));
            }
        }
        if let Some(p) = self.sky.texture.as_mut() {
            v.push(("sky.texture".into(), p));
        }
        if let Some(p) = self.sky.stars.as_mut() {
            v.push(("sky.stars".into(), p));
        }
        if let Some(p) = self.animation.as_mut().and_then(|a| a.video.as_mut()) {
            v.push(("animation.video".into(), p));
        }
        for (i, o) in self.objects.iter_mut().enumerate() {
            let (file, mat) = match o {
                ObjectConfig::Sphere(s) => (None, &mut s.material),
                ObjectConfig::Rectangle(r) => (None, &mut r.material),
                ObjectConfig::Mesh(m) => (Some(&mut m.file), &mut m.material),
            };
            if let Some(f) = file {
                v.push((format!("object.{i}.file"), f));
            }
            let (MaterialConfig::Color(s) | MaterialConfig::Mirror(s) | MaterialConfig::Lit(s)) =
                mat;
            if let Some(t) = s.texture.as_mut() {
                v.push((format!("object.{i}.material.texture"), t));
            }
        }
        v
    }
}

/// Settings present in the document that change nothing in this scene,
/// one line each (for warnings).
fn inert_settings(table: &toml::Table, c: &SceneConfig) -> Vec<String> {
    let has = |t: &str, k: &str| {
        table
            .get(t)
            .and_then(toml::Value::as_table)
            .is_some_and(|t| t.contains_key(k))
    };
    let mut out = Vec::new();
    let mut note = |key: &str, why: &str| out.push(format!("{key} does nothing: {why}"));
    match c.physics.model {
        ModelKind::Gr if has("physics", "step") => note(
            "physics.step",
            "it is the seed model's step; physics.model = \"gr\" uses physics.tolerance",
        ),
        ModelKind::Seed if has("physics", "tolerance") => note(
            "physics.tolerance",
            "it is the gr model's error control; physics.model = \"seed\" uses physics.step",
        ),
        _ => {}
    }
    if c.image.exr.is_none() {
        for k in ["exr_xyz", "exr_half"] {
            if has("image", k) {
                note(&format!("image.{k}"), "no image.exr is written");
            }
        }
        if has("spectral", "exr_layers") {
            note("spectral.exr_layers", "no image.exr is written");
        }
        if c.bloom.as_ref().is_some_and(|b| b.exr) {
            note("bloom.exr", "no image.exr is written");
        }
    }
    if !c.spectral.enabled {
        for k in [
            "wavelengths",
            "shift",
            "beaming",
            "doppler",
            "interpolation",
            "per_wavelength",
            "exr_layers",
        ] {
            if has("spectral", k) {
                note(
                    &format!("spectral.{k}"),
                    "spectral.enabled is not true (an RGB render)",
                );
            }
        }
        if c.bloom.as_ref().is_some_and(|b| b.spectral) {
            note(
                "bloom.spectral",
                "spectral.enabled is not true (an RGB render)",
            );
        }
    }
    if c.sky.stars.is_none() {
        for k in ["milky_way", "resolution"] {
            if has("sky", k) {
                note(&format!("sky.{k}"), "it applies to sky.stars only");
            }
        }
    }
    if (c.sky.color.is_some() || c.sky.blackbody.is_some()) && has("sky", "filter") {
        note("sky.filter", "a uniform sky has nothing to filter");
    }
    out
}

/// Removes `.` and `name/..` pairs without touching the file system, so
/// `text` (TOML) with every float of 1e16 and above, or below 1e-4, in
/// scientific notation (`8.57e36`, not 37 digits), the shortest that
/// reads back as the same number.
fn tidy_floats(text: &str) -> String {
    use toml::de::{DeTable, DeValue};
    fn walk(v: &toml::Spanned<DeValue>, out: &mut Vec<(std::ops::Range<usize>, String)>) {
        match v.get_ref() {
            DeValue::Float(f) => {
                if let Ok(x) = f.as_str().replace('_', "").parse::<f64>()
                    && x.is_finite()
                    && x != 0.0
                    && !(1e-4..1e16).contains(&x.abs())
                {
                    out.push((v.span(), format!("{x:e}")));
                }
            }
            DeValue::Array(a) => a.iter().for_each(|e| walk(e, out)),
            DeValue::Table(t) => t.values().for_each(|e| walk(e, out)),
            _ => {}
        }
    }
    let Ok(doc) = DeTable::parse(text) else {
        return text.to_string();
    };
    let mut edits = Vec::new();
    doc.get_ref().values().for_each(|v| walk(v, &mut edits));
    edits.sort_by_key(|e| e.0.start);
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (span, repl) in edits {
        out += &text[at..span.start];
        out += &repl;
        at = span.end;
    }
    out + &text[at..]
}

/// Largest scene file read (bytes): scenes are a few kilobytes.
const MAX_SCENE_BYTES: u64 = 16 << 20;

/// The text of a scene file: a regular file of sane size (not a device,
/// a pipe or a folder, which could hang or exhaust memory).
fn read_scene_text(path: &Path) -> Result<String, ConfigError> {
    let read = |cause| ConfigError::Read {
        path: path.to_path_buf(),
        cause,
    };
    let meta = std::fs::metadata(path).map_err(read)?;
    let other = |why: String| read(std::io::Error::other(why));
    if !meta.is_file() {
        return Err(other(
            "not a regular file (a scene is a TOML text file)".into(),
        ));
    }
    if meta.len() > MAX_SCENE_BYTES {
        return Err(other(format!(
            "{} bytes: a scene file is TOML text of at most {} MiB",
            meta.len(),
            MAX_SCENE_BYTES >> 20
        )));
    }
    std::fs::read_to_string(path).map_err(read)
}

/// One schema problem as a line: where it is (the file's line and column,
/// or the override it comes from), the key and what is wrong.
fn describe(p: &problems::Problem, text: &str, overrides: &[Override]) -> String {
    use problems::Kind;
    let key = key_text(&p.parts);
    // The override that set this key or a table above it, or below it
    // (`--set image={...}` for image.width; `--set image.zoom=2` for an
    // unknown image.zoom).
    let flag = overrides.iter().rev().find(|o| {
        o.value.is_some() && (p.parts.starts_with(&o.parts) || o.parts.starts_with(&p.parts))
    });
    // Removing a list entry renumbers the rest: the file's lines would
    // then point at the wrong entry.
    let renumbered = overrides.iter().any(|o| {
        o.value.is_none()
            && matches!(o.parts.last(), Some(Part::Index(_)))
            && p.parts.starts_with(&o.parts[..o.parts.len() - 1])
    });
    let place = match flag {
        Some(o) => format!("{}: ", o.flag),
        None if renumbered => String::new(),
        None => match (&p.kind, span_of(text, &p.parts)) {
            (Kind::Missing, _) | (_, None) => String::new(),
            (Kind::Unknown(_), Some((key_at, _))) => format!("{}: ", line_col(text, key_at)),
            (Kind::Invalid(_), Some((_, value_at))) => format!("{}: ", line_col(text, value_at)),
        },
    };
    match &p.kind {
        Kind::Unknown(names) => {
            let (last, up) = p.parts.split_last().expect("a key");
            let name = key_text(std::slice::from_ref(last));
            let table = match up {
                [] => "the top level".to_string(),
                [Part::Key(t)] => format!("[{t}]"),
                up => key_text(up),
            };
            let hint = match problems::nearest(&name, names) {
                Some(n) => format!("did you mean `{n}`?"),
                None if names.is_empty() => "it takes no keys".to_string(),
                None => format!("it takes {}", names.join(", ")),
            };
            format!("{place}unknown key `{name}` in {table} ({hint})")
        }
        Kind::Invalid(message) => format!("{place}{key}: {message}"),
        Kind::Missing => {
            let what = match p.parts.as_slice() {
                [Part::Key(t)] => format!("[{t}]"),
                _ => key,
            };
            format!("{place}missing {what}")
        }
    }
}

/// Byte offsets of the key and of the value at `parts` in the document.
fn span_of(text: &str, parts: &[Part]) -> Option<(usize, usize)> {
    use toml::de::{DeTable, DeValue};
    let doc = DeTable::parse(text).ok()?;
    let mut table: &DeTable = doc.get_ref();
    let mut found = None;
    let mut i = 0;
    while i < parts.len() {
        let Part::Key(k) = &parts[i] else {
            return None;
        };
        let (key, value) = table.get_key_value(k.as_str())?;
        found = Some((key.span().start, value.span().start));
        let mut v: &DeValue = value.get_ref();
        if let Some(Part::Index(n)) = parts.get(i + 1) {
            let entry = v.as_array()?.get(*n)?;
            found = Some((entry.span().start, entry.span().start));
            v = entry.get_ref();
            i += 1;
        }
        i += 1;
        if i < parts.len() {
            table = v.as_table()?;
        }
    }
    found
}

/// "line L, column C" of a byte offset (both from 1).
fn line_col(text: &str, at: usize) -> String {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    format!("line {line}, column {col}")
}

/// messages show `/a/img/x.png` rather than `/a/configs/../img/x.png`.
fn normalize(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saved_floats_are_short() {
        let text = "a = 8570000000000000000000000000000000000.0\nb = [0.00001, 2.5, 1e300]\n[c]\nd = { e = -3e20 }\n";
        let tidy = tidy_floats(text);
        assert_eq!(
            tidy,
            "a = 8.57e36\nb = [1e-5, 2.5, 1e300]\n[c]\nd = { e = -3e20 }\n"
        );
        let (a, b): (toml::Table, toml::Table) = (
            toml::from_str(text).unwrap(),
            toml::from_str(&tidy).unwrap(),
        );
        assert_eq!(a, b);
    }

    #[test]
    fn override_values_are_typed() {
        assert_eq!(
            Override::parse("image.width=256").unwrap().value,
            Some(toml::Value::Integer(256))
        );
        assert_eq!(
            Override::parse("a.b = 1e3").unwrap().value,
            Some(toml::Value::Float(1e3))
        );
        assert_eq!(
            Override::parse("image.png=out/x.png").unwrap().value,
            Some(toml::Value::String("out/x.png".into()))
        );
        assert!(matches!(
            Override::parse("camera.position=[1, 2, 3.5]")
                .unwrap()
                .value,
            Some(toml::Value::Array(_))
        ));
        assert!(Override::parse("image.width").is_err());
        assert!(Override::parse("image..width=3").is_err());
    }

    #[test]
    fn normalize_is_lexical() {
        assert_eq!(
            normalize(Path::new("/a/b/../c/./d.png")),
            PathBuf::from("/a/c/d.png")
        );
        assert_eq!(normalize(Path::new("../x")), PathBuf::from("../x"));
    }

    #[test]
    fn override_keys_are_normalised() {
        assert_eq!(
            Override::parse("image . png = x.png").unwrap().key,
            "image.png"
        );
    }

    #[test]
    fn override_into_scalar_is_an_error() {
        let mut t: toml::Table = toml::from_str("[image]\nwidth = 3\n").unwrap();
        let e = Override::parse("image.width.x=1")
            .unwrap()
            .apply(&mut t)
            .unwrap_err();
        assert!(
            e.to_string().contains("`image.width` is not a table"),
            "{e}"
        );
    }
}
