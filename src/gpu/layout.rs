//! The one source of the GPU's layout: the parameter block, the counters,
//! flags and kind codes, the integrator's tableau and the other constants
//! the shaders share with the host, all defined here in Rust and written
//! into the WGSL header ([`header`]), so that the two cannot drift apart.

use bytemuck::{Pod, Zeroable};

/// A value's type in WGSL (for the generated `Params` struct).
pub(crate) trait WgslType {
    /// Its WGSL spelling.
    fn wgsl() -> String;
}

impl WgslType for f32 {
    fn wgsl() -> String {
        "f32".into()
    }
}

impl WgslType for u32 {
    fn wgsl() -> String {
        "u32".into()
    }
}

impl WgslType for [f32; 4] {
    fn wgsl() -> String {
        "vec4<f32>".into()
    }
}

impl<const N: usize> WgslType for [[f32; 4]; N] {
    fn wgsl() -> String {
        format!("array<vec4<f32>, {N}>")
    }
}

/// Defines a `#[repr(C)]` struct and its WGSL twin (`WGSL`, the struct's
/// declaration) and the byte offset of every field (`OFFSETS`, for the test
/// that checks WGSL lays it out alike). Fields must be ordered so that
/// vectors start on 16 bytes (scalars come in fours).
macro_rules! gpu_struct {
    ($(#[$m:meta])* $name:ident { $($(#[$fm:meta])* $field:ident : $ty:ty,)* }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Pod, Zeroable)]
        pub(crate) struct $name {
            $($(#[$fm])* pub $field: $ty,)*
        }

        impl $name {
            /// The struct's declaration in WGSL.
            pub fn wgsl() -> String {
                let mut s = format!("struct {} {{\n", stringify!($name));
                $(s += &format!("    {}: {},\n", stringify!($field), <$ty as WgslType>::wgsl());)*
                s + "}\n"
            }

            /// Every field's name and byte offset.
            #[cfg(test)]
            pub fn offsets() -> Vec<(&'static str, usize)> {
                vec![$((stringify!($field), std::mem::offset_of!($name, $field)),)*]
            }
        }
    };
}

gpu_struct! {
    /// The scene's parameters, one uniform block (see src/gpu/pack.rs for
    /// how each is filled). Lengths in r_s; offsets index `tables`.
    Params {
        cam_pos: [f32; 4],
        cam_fwd: [f32; 4],
        cam_right: [f32; 4],
        cam_up: [f32; 4],
        /// The hole's direction as a point of the image plane at unit
        /// forward distance (right, up), and in w its handedness (the sign
        /// of (forward x right) . up) where it lies ahead, else 0: from it
        /// each pixel's impact parameter without f32's cancellation.
        cam_hole: [f32; 4],
        /// The camera's velocity relative to its frame (units of c, along
        /// the scene's axes; zero at rest).
        cam_velocity: [f32; 4],
        /// With spin (KERR): the 4-velocity of the frame the camera is at
        /// rest in (Kerr-Schild components, in M units; xyz spatial, w
        /// time) and its frame's three unit vectors closest to the axes
        /// (Kerr::ks_frame), made in f64 on the host.
        cam_u: [f32; 4],
        cam_frame: [[f32; 4]; 3],
        /// With spin, for the closed form (Kerr::ks_ray_forms): the energy,
        /// L_z, p_theta, d r and d cos theta of the camera's ray as linear
        /// forms (minus the frame's own, then the frame vectors along
        /// forward, right and up; the ray's are those three weighted by
        /// its local direction, less the first), and its start: r, cos
        /// theta, the Kerr-Schild azimuth (M) and sin theta.
        kerr_rays: [[f32; 4]; 5],
        kerr_start: [f32; 4],
        /// The camera frame's part of every shift (Spacetime's
        /// kerr_observer): 1 for a ZAMO (then its omega and alpha), 0 for
        /// a static observer (then ln of its 1 / sqrt(1 - f) in w).
        kerr_observer: [f32; 4],
        /// The hole in M units: a, r_+, r_-, the counter-clockwise
        /// circular photon orbit (inside it the disk has no orbits).
        kerr_hole: [f32; 4],
        /// Where rays end (M): captured within 1e-3 of r_+, or inbound
        /// inside both the prograde photon orbit and the scene's inner
        /// bound; the outer bound.
        kerr_limits: [f32; 4],
        /// Page and Thorne's flux (PROFILE_PAGE_THORNE): the three roots
        /// of x^3 - 3x + 2a and x_0 = sqrt(r_in / M); the roots' log
        /// coefficients and 1.5 a.
        thin_pt_roots: [f32; 4],
        thin_pt_coef: [f32; 4],
        /// tan(fov / 2), and times the aspect ratio.
        cam_half_height: f32,
        cam_half_width: f32,
        /// The stereo eye's off-axis shift of the image window.
        cam_shift: f32,
        _pad_cam: f32,
        width: u32,
        height: u32,
        samples: u32,
        /// 1: a static observer's frame (gr).
        static_observer: u32,
        seed_lo: u32,
        seed_hi: u32,
        tile_first_row: u32,
        tile_rows: u32,
        /// MODEL_GR or MODEL_SEED.
        model: u32,
        max_steps: u32,
        n_wavelengths: u32,
        /// FLAG_* bits.
        flags: u32,
        tolerance: f32,
        seed_step: f32,
        outer_limit: f32,
        inner_limit: f32,
        /// DISK_NONE, DISK_RGB or DISK_SPECTRAL.
        disk_kind: u32,
        /// 1: bilinear.
        disk_filter: u32,
        /// 1: blended alpha.
        disk_alpha: u32,
        /// TEXELS_SRGB8 or TEXELS_LINEAR.
        disk_format: u32,
        disk_width: u32,
        disk_height: u32,
        /// The spectral set's wavelengths, and 1 when evenly spaced.
        disk_set_len: u32,
        disk_set_uniform: u32,
        disk_inner: f32,
        disk_outer: f32,
        disk_intensity: f32,
        _pad_disk: f32,
        /// The spectral set's first wavelength and spacing (nm).
        disk_nm0: f32,
        disk_dnm: f32,
        _pad_disk_nm0: f32,
        _pad_disk_nm1: f32,
        /// PROFILE_NONE, PROFILE_NOVIKOV_THORNE, PROFILE_SHAKURA_SUNYAEV or
        /// PROFILE_PAGE_THORNE.
        thin_profile: f32,
        thin_inner: f32,
        thin_f_col: f32,
        thin_t0: f32,
        /// The thin disk's ln XYZ table: ln of its first kelvin, step, rows.
        thin_ln_t0: f32,
        thin_dln_t: f32,
        thin_rows: f32,
        _pad_thin: f32,
        /// SKY_COLOR, SKY_BLACKBODY, SKY_PANORAMA or SKY_STARS.
        sky_kind: u32,
        sky_filter: u32,
        sky_format: u32,
        sky_milky_way: u32,
        sky_width: u32,
        sky_height: u32,
        milky_way_width: u32,
        milky_way_height: u32,
        /// A uniform or blackbody sky's linear sRGB times its intensity.
        sky_rgb: [f32; 4],
        sky_kelvin: f32,
        sky_intensity: f32,
        _pad_sky0: f32,
        _pad_sky1: f32,
        /// A uniform sky's uplifted spectrum: c0, c1, c2, scale.
        sky_uplift: [f32; 4],
        _pad_at0: u32,
        _pad_at1: u32,
        at_planck: u32,
        at_planck_ln_y: u32,
        at_d65: u32,
        at_uplift: u32,
        _pad_at2: u32,
        at_srgb_decode: u32,
        at_bb: u32,
        at_set_nm: u32,
        at_planck_xyz: u32,
        at_thin_xyz: u32,
        /// The Planck table: ln of its first kelvin, step, rows; and 1 / Y
        /// of D65.
        planck_ln_t0: f32,
        planck_dln_t: f32,
        planck_rows: f32,
        d65_norm: f32,
        /// The D65 table: first nm, spacing, count.
        d65_nm0: f32,
        d65_dnm: f32,
        d65_count: f32,
        _pad_d65: f32,
        /// The blackbody colour table: first kelvin, spacing, count; and
        /// the Milky Way's kelvin.
        bb_t0: f32,
        bb_dt: f32,
        bb_count: f32,
        milky_way_kelvin: f32,
        /// Linear sRGB to XYZ, by columns.
        srgb_to_xyz: [[f32; 4]; 3],
        n_objects: u32,
        /// Where the lighting and the volume (NONE: none) begin in the
        /// object data.
        at_lighting: u32,
        at_volume: u32,
        n_clouds: u32,
        /// The frame's time (r_s/c) and a rigid rotation's angular velocity.
        time: f32,
        rigid_omega: f32,
        _pad_anim0: f32,
        _pad_anim1: f32,
        /// ROTATION_NONE, ROTATION_KEPLERIAN or ROTATION_RIGID.
        rotation: u32,
        _pad_anim2: u32,
        _pad_anim3: u32,
        _pad_anim4: u32,
        /// Where the first cloud begins in the object data; 1 when a
        /// mirror is in the scene.
        at_clouds: u32,
        any_mirror: u32,
        /// Sample slots per sample index (the tile's pixels; the slots
        /// follow the pixels in `film`), where the samples' spectra start.
        slots_per_sample: u32,
        at_spectra: u32,
        /// A pass of samples: the first sample's index, samples in it.
        pass_first: u32,
        pass_samples: u32,
        /// OBSERVE: where the samples' probes and the pixels' observables
        /// start in `film` (vec4s; see [`PROBE_G`] and [`OBSERVED_VEC4S`]).
        at_probes: u32,
        at_observed: u32,
        /// Adaptive sampling (FLAG_ADAPTIVE): the displayed white's
        /// luminance (2^-exposure) for the samples' lightness; in a
        /// round's dispatch, its samples and pixels (0 in other passes;
        /// see `REFINE` in main.wgsl).
        white: f32,
        refine_samples: u32,
        refine_pixels: u32,
        _pad_refine: u32,
        /// Per camera wavelength: its CIE weights (x, y, z) and nm (w).
        wl: [[f32; 4]; 512],
        /// Footprint filtering (ewa.wgsl, filled by src/gpu/ewa.rs): where
        /// the mip levels 1 and up start in `disk_data` (the RGBA texels,
        /// or the spectral set's values) and the set's levels' alpha; in
        /// `sky_data` the panorama's or the star grid's levels and the
        /// Milky Way grid's.
        ewa_disk_mips: u32,
        ewa_disk_mip_alpha: u32,
        ewa_sky_mips: u32,
        ewa_milky_way_mips: u32,
        /// The weight table in `tables`; 1 when a star map has its star
        /// grid; where the Milky Way grid's level 0 starts in `sky_data`.
        at_ewa_weights: u32,
        ewa_star_grid: u32,
        ewa_milky_way_at: u32,
        /// The radius (r_s) inside which the disk's texture holds no
        /// material: a footprint stops there (Disk::hit_footprint).
        disk_material_inner: f32,
        /// Point stars (stars.wgsl, filled by src/gpu/stars.rs): where
        /// `StarField::gpu_words` start in `sky_data` (NONE: the sky has
        /// no point stars); where each tier's densest cell per level
        /// (`STARS_LEVELS` a tier) starts in `tables`; `SumRule::max_stars`.
        stars_at: u32,
        stars_densest: u32,
        stars_max: f32,
        _pad_stars: u32,
        /// A medium (MEDIUM; transfer.wgsl, filled by pack.rs's
        /// `pack_medium`): MEDIUM_*, where the synchrotron average's table
        /// starts in `tables`, centimetres per M, and the pixel solid
        /// angle's factor to janskys per cgs intensity ((r_cam / D)^2 /
        /// 1 Jy).
        medium_kind: u32,
        at_medium_table: u32,
        medium_cm_per_m: f32,
        medium_jy: f32,
        /// c^2 / (2 k) over the display's white brightness temperature.
        medium_kelvin: f32,
        /// The horizon (M), the spin, and the medium's extent (M;
        /// `Medium::extent`, 0 without one).
        medium_horizon: f32,
        medium_spin: f32,
        medium_extent: f32,
        /// The medium's own block, as the medium builds it (`gpu_block`:
        /// `GoldBlock`, `UniformBlock`, `RiafBlock`, `VolumeGasBlock`),
        /// read in the shader by the header's generated readers
        /// (`gold_block()`...), and the gas's motion (`MotionBlock`,
        /// `motion_block()`) where it has one.
        medium: [[f32; 4]; 2],
        medium_motion: [[f32; 4]; 2],
    }
}

/// Most frequencies an observed scene takes on the GPU (the slots of
/// `Params::wl`).
pub const MAX_GPU_FREQUENCIES: usize = 512;

/// `Params::medium_kind`.
pub(crate) const MEDIUM_GOLD: u32 = 0;
pub(crate) const MEDIUM_UNIFORM: u32 = 1;
pub(crate) const MEDIUM_RIAF: u32 = 2;
/// An observed scene without a medium (a thin disk alone).
pub(crate) const MEDIUM_NONE: u32 = 3;
/// The volumetric disk's gas as a blackbody.
pub(crate) const MEDIUM_VOLUME: u32 = 4;
/// A GRMHD snapshot (its grid in the tables at `at_medium_table`).
pub(crate) const MEDIUM_GRMHD: u32 = 5;

gpu_struct! {
    /// The display's parameters (display.wgsl), one uniform block per
    /// plane of the image that bloom blurs, at offsets a multiple of the
    /// device's uniform alignment.
    DisplayParams {
        /// The image shown (a preview's smaller size while moving).
        width: u32,
        height: u32,
        /// The tracer's band of rows being added: its first row and rows.
        first_row: u32,
        rows: u32,
        /// The plane a bloom pass blurs (0: the XYZ, 1 + b: bloom band
        /// b), and 1 for the first one added.
        plane: u32,
        first_plane: u32,
        /// The plane's Gaussian: its radius and where its weights, and
        /// the weights inside the image per column and per row, start in
        /// `kern`.
        k_radius: u32,
        at_kernel: u32,
        at_inside_rows: u32,
        at_inside_columns: u32,
        /// TONE_*, and 1 when the image shown is bloomed.
        tonemap: u32,
        bloom: u32,
        /// The share of the plane a bloom pass adds as it is, and of its
        /// blur (`post::BloomTerm`'s keep and weight); 2^exposure.
        strength: f32,
        exposure_scale: f32,
        /// An observed scene's false colour (COLORMAP_*; its table is
        /// the first 256 words of `kern`) and its log scale's decades.
        colormap: u32,
        decades: f32,
        keep: f32,
        _pad_keep0: u32,
        _pad_keep1: u32,
        _pad_keep2: u32,
        /// XYZ to linear sRGB, by columns.
        xyz_to_srgb: [[f32; 4]; 3],
    }
}

/// `DisplayParams::colormap`: the light's tone curve, or an observed
/// scene's false colour on a linear or a log scale.
pub(crate) const COLORMAP_NONE: u32 = 0;
pub(crate) const COLORMAP_LINEAR: u32 = 1;
pub(crate) const COLORMAP_LOG: u32 = 2;

/// Tone curves of `DisplayParams::tonemap`.
pub(crate) const TONE_CLIP: u32 = 0;
pub(crate) const TONE_REINHARD: u32 = 1;
pub(crate) const TONE_ACES: u32 = 2;

/// The display passes' workgroup (256 invocations, the most WebGPU
/// allows), and the pixels of a row each invocation of `accumulate` and
/// `tonemap` takes: on CPU devices every invocation costs (llvmpipe: a
/// pass over 1080p of one pixel an invocation took 130 ms, of 8 pixels
/// 40 ms), on GPUs the pixels a span apart keep neighbouring invocations
/// on neighbouring memory.
pub(crate) const DISPLAY_GROUP: (u32, u32) = (32, 8);
pub(crate) const DISPLAY_PIXELS: u32 = 8;

/// The display shader's header: its parameter block and constants.
pub(crate) fn display_header() -> String {
    let mut s = DisplayParams::wgsl();
    for (name, value) in [
        ("BANDS", crate::film::BANDS as u32),
        ("TONE_CLIP", TONE_CLIP),
        ("TONE_REINHARD", TONE_REINHARD),
        ("TONE_ACES", TONE_ACES),
        ("COLORMAP_NONE", COLORMAP_NONE),
        ("COLORMAP_LINEAR", COLORMAP_LINEAR),
        ("COLORMAP_LOG", COLORMAP_LOG),
        ("GROUP_X", DISPLAY_GROUP.0),
        ("GROUP_Y", DISPLAY_GROUP.1),
        ("PIXELS", DISPLAY_PIXELS),
    ] {
        s += &format!("const {name}: u32 = {value}u;\n");
    }
    s
}

/// Bits of `Params::flags`.
pub(crate) const FLAG_SHIFT: u32 = 1;
pub(crate) const FLAG_DOPPLER: u32 = 2;
pub(crate) const FLAG_BEAMING: u32 = 4;
pub(crate) const FLAG_LINEAR: u32 = 8;
pub(crate) const FLAG_KEEP_SPECTRA: u32 = 16;
pub(crate) const FLAG_BANDS: u32 = 32;
/// OBSERVE: shifts are computed for the g map (cpu::Shifts::on), even
/// where the light does not take them.
pub(crate) const FLAG_OBSERVE_G: u32 = 64;
/// OBSERVE: the disk is seen as it was when its light left it
/// (`light_travel_time`); without OBSERVE that is what TRAVEL means, with
/// it TRAVEL may be for the time map alone (Scene::timed).
pub(crate) const FLAG_LIGHT_TRAVEL: u32 = 128;
/// Adaptive sampling (with OBSERVE): each sample's class as adaptive
/// sampling tells them apart, and each pixel's lightness sums and classes
/// (the last of its `OBSERVED_VEC4S`).
pub(crate) const FLAG_ADAPTIVE: u32 = 256;

/// What a sample's probe holds (OBSERVE; cpu::Probing), PROBE_VEC4S
/// vec4s per sample slot from `Params::at_probes`: g, ring radius, travel
/// time, and as the bits of its w word which of them it has (PROBE_G,
/// PROBE_RADIUS, PROBE_TIME, PROBE_MAG, PROBE_SKY: set and finite) and its
/// image order (PROBE_ORDER, the order itself shifted by
/// PROBE_ORDER_SHIFT); then the magnification and the direction at
/// infinity.
pub(crate) const PROBE_G: u32 = 1;
pub(crate) const PROBE_RADIUS: u32 = 2;
pub(crate) const PROBE_TIME: u32 = 4;
pub(crate) const PROBE_ORDER: u32 = 8;
pub(crate) const PROBE_MAG: u32 = 16;
pub(crate) const PROBE_SKY: u32 = 32;
pub(crate) const PROBE_ORDER_SHIFT: u32 = 8;
pub(crate) const PROBE_VEC4S: u32 = 2;

/// vec4s per pixel of the observables that `resolve` sums over a pass of
/// samples (film::PixelProbe's reduction, finished on the host), from
/// `Params::at_observed`: the sums of g, ring radius and time and, as
/// bits, the least order plus one (0: none); the three counts and a zero;
/// the samples per class, by `Stat` slot (six words, two zeros); the sums
/// of the magnification and the sky direction's x, y, z; their two counts
/// and two zeros; with FLAG_ADAPTIVE the sum and sum of squares of its
/// finite samples' lightness and, as bits, the low and high words of its
/// class mask (adaptive::class_bit).
pub(crate) const OBSERVED_VEC4S: u32 = 7;

/// Kind codes of `Params`.
pub(crate) const MODEL_GR: u32 = 0;
pub(crate) const MODEL_SEED: u32 = 1;
pub(crate) const DISK_NONE: u32 = 0;
pub(crate) const DISK_RGB: u32 = 1;
pub(crate) const DISK_SPECTRAL: u32 = 2;
pub(crate) const TEXELS_SRGB8: u32 = 0;
pub(crate) const TEXELS_LINEAR: u32 = 1;
pub(crate) const SKY_COLOR: u32 = 0;
pub(crate) const SKY_BLACKBODY: u32 = 1;
pub(crate) const SKY_PANORAMA: u32 = 2;
pub(crate) const SKY_STARS: u32 = 3;
pub(crate) const PROFILE_NONE: f32 = 0.0;
pub(crate) const PROFILE_NOVIKOV_THORNE: f32 = 1.0;
pub(crate) const PROFILE_SHAKURA_SUNYAEV: f32 = 2.0;
/// Novikov and Thorne's profile around a spinning hole: Page and Thorne's
/// flux.
pub(crate) const PROFILE_PAGE_THORNE: f32 = 3.0;
pub(crate) const ROTATION_NONE: u32 = 0;
pub(crate) const ROTATION_KEPLERIAN: u32 = 1;
pub(crate) const ROTATION_RIGID: u32 = 2;

/// The counters the shader adds up, in `stats`, by name: one class per
/// sample, the steps as two words, the range of g as the bits of positive
/// floats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stat {
    Disk,
    Objects,
    Sky,
    Captured,
    Abandoned,
    NonFinite,
    StepsLo,
    StepsHi,
    GMin,
    GMax,
    Closed,
}

impl Stat {
    /// Every counter, in its slot's order.
    pub const ALL: [Stat; 11] = [
        Stat::Disk,
        Stat::Objects,
        Stat::Sky,
        Stat::Captured,
        Stat::Abandoned,
        Stat::NonFinite,
        Stat::StepsLo,
        Stat::StepsHi,
        Stat::GMin,
        Stat::GMax,
        Stat::Closed,
    ];

    /// Its WGSL constant's name.
    fn name(self) -> &'static str {
        match self {
            Stat::Disk => "STAT_DISK",
            Stat::Objects => "STAT_OBJECTS",
            Stat::Sky => "STAT_SKY",
            Stat::Captured => "STAT_CAPTURED",
            Stat::Abandoned => "STAT_ABANDONED",
            Stat::NonFinite => "STAT_NON_FINITE",
            Stat::StepsLo => "STAT_STEPS_LO",
            Stat::StepsHi => "STAT_STEPS_HI",
            Stat::GMin => "STAT_G_MIN",
            Stat::GMax => "STAT_G_MAX",
            Stat::Closed => "STAT_CLOSED",
        }
    }

    /// Its slot.
    pub fn slot(self) -> usize {
        self as usize
    }
}

/// Counters per workgroup in `stats`.
pub(crate) const STATS: usize = Stat::ALL.len();

/// "None" for offsets into the object data.
pub(crate) const NONE: u32 = u32::MAX;
/// Words of an object record (see objects.wgsl).
pub(crate) const OBJECT_WORDS: u32 = 32;
/// Words of a sun record.
pub(crate) const SUN_WORDS: u32 = 16;
/// Words of a disk-glow patch.
pub(crate) const GLOW_WORDS: u32 = 8;
/// Words of a cloud record.
pub(crate) const CLOUD_WORDS: u32 = 32;
/// Most clouds the GPU marches at once.
pub const MAX_GPU_CLOUDS: usize = 15;

/// What a shader variant is specialised for (constants of its header): the
/// scene's wavelength count and what it holds, so that code for what it
/// lacks is left out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Variant {
    /// Wavelengths per sample (1 for RGB renders).
    pub n_wl: u32,
    pub spectral: bool,
    /// Each sample's spectrum is kept (EXR layers or bloom bands).
    pub spec_array: bool,
    /// Mirrors or clouds filter light per wavelength.
    pub filters: bool,
    pub objects: bool,
    pub gas: bool,
    /// Rays keep their light's travel time.
    pub travel: bool,
    /// Rays may take the closed form.
    pub closed: bool,
    /// The hole spins: Kerr's rays, frames and shifts (kerr.wgsl).
    pub kerr: bool,
    /// The scene asks for observables: each sample's probe and each
    /// pixel's sums are kept.
    pub observe: bool,
    /// Samples carry their footprints (footprint.wgsl; Scene::footprints).
    pub footprint: bool,
    /// An object's texture is read over footprints at object hits
    /// (objfoot.wgsl; Scene::object_footprints).
    pub object_footprint: bool,
    /// An observed scene: radiative transfer through a medium at `n_wl`
    /// frequencies (media.wgsl and transfer.wgsl).
    pub medium: bool,
    /// The medium is a GRMHD snapshot (grmhd.wgsl): other media's shaders
    /// leave its code out.
    pub grmhd: bool,
}

/// Writes `name: f32 = value` as WGSL, with the shortest digits that read
/// back as the same f32.
fn f32_const(name: &str, v: f64) -> String {
    format!("const {name}: f32 = {:?};\n", v as f32)
}

/// The WGSL header of a shader variant: its specialisation constants, the
/// layout and constants above, the integrator's tableau and the
/// quadrature nodes of the escape tail.
pub(crate) fn header(v: &Variant) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let b = |x: bool| if x { "true" } else { "false" };
    let _ = write!(
        s,
        "const N_WL: u32 = {}u;\nconst SPECTRAL: bool = {};\nconst SPEC_ARRAY: bool = {};\n\
         const FILTERS: bool = {};\nconst FILTER_LEN: u32 = {}u;\n\
         const OBJECTS: bool = {};\nconst GAS: bool = {};\nconst TRAVEL: bool = {};\nconst CLOSED: bool = {};\n\
         const KERR: bool = {};\nconst OBSERVE: bool = {};\nconst FOOTPRINT: bool = {};\n\
         const OBJECT_FOOTPRINT: bool = {};\nconst MEDIUM: bool = {};\nconst GRMHD: bool = {};\n",
        v.n_wl,
        b(v.spectral),
        b(v.spec_array),
        b(v.filters),
        if v.filters { v.n_wl } else { 1 },
        b(v.objects),
        b(v.gas),
        b(v.travel),
        b(v.closed),
        b(v.kerr),
        b(v.observe),
        b(v.footprint),
        b(v.object_footprint),
        b(v.medium),
        b(v.grmhd),
    );
    s += &Params::wgsl();
    for (name, value) in u32_constants() {
        let _ = writeln!(s, "const {name}: u32 = {value}u;");
    }
    for stat in Stat::ALL {
        let _ = writeln!(s, "const {}: u32 = {}u;", stat.name(), stat.slot());
    }
    for (name, value) in [
        ("PROFILE_NONE", PROFILE_NONE),
        ("PROFILE_NOVIKOV_THORNE", PROFILE_NOVIKOV_THORNE),
        ("PROFILE_SHAKURA_SUNYAEV", PROFILE_SHAKURA_SUNYAEV),
        ("PROFILE_PAGE_THORNE", PROFILE_PAGE_THORNE),
    ] {
        s += &f32_const(name, value as f64);
    }
    s += &f32_const("UPLIFT_FACE", crate::spectrum::uplift::FACE);
    s += &f32_const("B_CRIT", crate::physics::closed::B_CRIT);
    // Schwarzschild's closed-form rays as segments (main.wgsl's
    // trace_closed_segments, for the gas along them): physics::closed's.
    s += &f32_const("SEGMENT_SWEEP", crate::physics::closed::SEGMENT_SWEEP);
    s += &f32_const("SEGMENT_SPAN", crate::physics::closed::SEGMENT_SPAN);
    s += &f32_const("CLOSED_FAR", crate::physics::closed::FAR);
    s += &f32_const("HORIZON_MARGIN", crate::physics::closed::HORIZON_MARGIN);
    // Kerr's closed-form rays in stretches, for the gas along them
    // (transfer.wgsl's m_along_kerr): transfer::closed's.
    s += &f32_const("KERR_STRETCH", crate::transfer::closed::STRETCH);
    s += &f32_const("KERR_SWING", crate::transfer::closed::SWING);
    s += &f32_const("KERR_FAR", crate::transfer::closed::FAR);
    // The pieces' loop of every band's gas (pieces.wgsl): a piece's
    // thickest optical depth and length, most pieces to a stretch, the
    // transmittance past which nothing is seen and the pieces'
    // Gauss-Legendre nodes.
    s += &f32_const("MAX_DTAU", crate::transfer::MAX_DTAU);
    s += &f32_const("SCALE_FRACTION", crate::transfer::SCALE_FRACTION);
    s += &f32_const("MAX_PIECES", crate::transfer::MAX_PIECES as f64);
    s += &f32_const("SPENT", crate::transfer::SPENT);
    s += &f32_const("GAUSS_2", crate::transfer::GAUSS_2);
    // cgs constants of the media (transfer.wgsl), from src/units.rs and the
    // media's own: the flows' cut-off, Planck's B_nu (h / k, and 2 h / c^2
    // for nu in THz, which f32 holds), thermal synchrotron's Theta_e scale
    // m_e c^2 / k, its coldest Theta_e, the cyclotron frequency of 1 G,
    // sqrt(2) pi e^2 / (3 c) and the RIAF's field sqrt(8 pi m_p c^2 / 6).
    {
        use crate::transfer::synchrotron;
        use crate::units::cgs::{
            BOLTZMANN, ELECTRON_CHARGE, ELECTRON_MASS, LIGHT, PLANCK, PROTON_MASS,
        };
        use std::f64::consts::PI;
        for (name, value) in [
            ("M_CUTOFF", crate::transfer::CUTOFF),
            ("H_OVER_K", PLANCK / BOLTZMANN),
            ("TWO_H_OVER_C2_THZ", 2.0 * PLANCK / (LIGHT * LIGHT) * 1e36),
            ("ME_C2_OVER_K", ELECTRON_MASS * LIGHT * LIGHT / BOLTZMANN),
            ("SYNC_COLDEST", synchrotron::COLDEST),
            ("CYCLOTRON_PER_GAUSS", synchrotron::cyclotron(1.0)),
            (
                "SYNC_NORM",
                2f64.sqrt() * PI * ELECTRON_CHARGE * ELECTRON_CHARGE / (3.0 * LIGHT),
            ),
            (
                "RIAF_FIELD",
                (8.0 * PI * PROTON_MASS * LIGHT * LIGHT / 6.0).sqrt(),
            ),
        ] {
            s += &f32_const(name, value);
        }
    }
    // The media's parameter blocks: each one's struct and the reader of its
    // words in Params (media.wgsl).
    {
        use crate::transfer::{gold, riaf, uniform, volume};
        use crate::wgsl::Block;
        s += &gold::GoldBlock::wgsl("gold_block", "P.medium");
        s += &uniform::UniformBlock::wgsl("uniform_block", "P.medium");
        s += &riaf::RiafBlock::wgsl("riaf_block", "P.medium");
        s += &volume::VolumeGasBlock::wgsl("volume_gas_block", "P.medium");
        s += &riaf::MotionBlock::wgsl("motion_block", "P.medium_motion");
        s += &crate::transfer::grmhd::GrmhdBlock::wgsl_in_table(
            "grmhd_block",
            "tables",
            "P.at_medium_table",
        );
    }
    // A GRMHD snapshot (grmhd.wgsl): theta's inverse's points a row, the
    // values a cell, cells a piece, and the refinement against the
    // magnetisation cut (transfer::CONTRAST, SHARPEST, pieces::NEAR).
    s += &format!(
        "const GRMHD_THETAS: u32 = {}u;\nconst GRMHD_FIELDS: u32 = {}u;\n",
        crate::transfer::grmhd::coords::THETAS,
        crate::transfer::grmhd::FIELDS
    );
    s += &f32_const(
        "GRMHD_CELLS_PER_PIECE",
        crate::transfer::grmhd::CELLS_PER_PIECE,
    );
    s += &f32_const("CONTRAST", crate::transfer::CONTRAST);
    s += &f32_const("SHARPEST", crate::transfer::SHARPEST);
    s += &f32_const("NEAR", crate::transfer::pieces::NEAR);
    // The synchrotron average's table (transfer.wgsl's ln_average).
    let (lo, hi) = crate::transfer::synchrotron::AVERAGE_RANGE;
    s += &f32_const("SYNC_LN_Y_LOW", lo.ln());
    s += &f32_const("SYNC_LN_Y_HIGH", hi.ln());
    s += &format!(
        "const SYNC_TABLE: u32 = {}u;\n",
        crate::transfer::synchrotron::AVERAGE_POINTS
    );
    for (name, value) in crate::physics::gr::DORMAND_PRINCE {
        s += &f32_const(name, value);
    }
    s += &quadrature();
    s
}

/// The header's u32 constants: flags, kinds, record sizes and counts
/// shared with the host.
fn u32_constants() -> [(&'static str, u32); 49] {
    [
        ("FLAG_SHIFT", FLAG_SHIFT),
        ("FLAG_DOPPLER", FLAG_DOPPLER),
        ("FLAG_BEAMING", FLAG_BEAMING),
        ("FLAG_LINEAR", FLAG_LINEAR),
        ("FLAG_KEEP_SPECTRA", FLAG_KEEP_SPECTRA),
        ("MEDIUM_GOLD", MEDIUM_GOLD),
        ("MEDIUM_UNIFORM", MEDIUM_UNIFORM),
        ("MEDIUM_RIAF", MEDIUM_RIAF),
        ("MEDIUM_NONE", MEDIUM_NONE),
        ("MEDIUM_VOLUME", MEDIUM_VOLUME),
        ("MEDIUM_GRMHD", MEDIUM_GRMHD),
        ("FLAG_BANDS", FLAG_BANDS),
        ("FLAG_OBSERVE_G", FLAG_OBSERVE_G),
        ("FLAG_LIGHT_TRAVEL", FLAG_LIGHT_TRAVEL),
        ("FLAG_ADAPTIVE", FLAG_ADAPTIVE),
        ("PROBE_G", PROBE_G),
        ("PROBE_RADIUS", PROBE_RADIUS),
        ("PROBE_TIME", PROBE_TIME),
        ("PROBE_ORDER", PROBE_ORDER),
        ("PROBE_MAG", PROBE_MAG),
        ("PROBE_SKY", PROBE_SKY),
        ("PROBE_ORDER_SHIFT", PROBE_ORDER_SHIFT),
        ("PROBE_VEC4S", PROBE_VEC4S),
        ("OBSERVED_VEC4S", OBSERVED_VEC4S),
        ("MODEL_GR", MODEL_GR),
        ("MODEL_SEED", MODEL_SEED),
        ("DISK_NONE", DISK_NONE),
        ("DISK_RGB", DISK_RGB),
        ("DISK_SPECTRAL", DISK_SPECTRAL),
        ("TEXELS_SRGB8", TEXELS_SRGB8),
        ("TEXELS_LINEAR", TEXELS_LINEAR),
        ("SKY_COLOR", SKY_COLOR),
        ("SKY_BLACKBODY", SKY_BLACKBODY),
        ("SKY_PANORAMA", SKY_PANORAMA),
        ("SKY_STARS", SKY_STARS),
        ("ROTATION_NONE", ROTATION_NONE),
        ("ROTATION_KEPLERIAN", ROTATION_KEPLERIAN),
        ("ROTATION_RIGID", ROTATION_RIGID),
        ("STATS", STATS as u32),
        ("BANDS", crate::film::BANDS as u32),
        ("NONE", NONE),
        ("OBJECT_WORDS", OBJECT_WORDS),
        ("SUN_WORDS", SUN_WORDS),
        ("GLOW_WORDS", GLOW_WORDS),
        ("CLOUD_WORDS", CLOUD_WORDS),
        ("MAX_CLOUDS", MAX_GPU_CLOUDS as u32),
        ("MAX_BOUNCES", crate::objects::MAX_BOUNCES as u32),
        ("UPLIFT_RES", crate::spectrum::uplift::RES as u32),
        (
            "GL_N",
            crate::physics::tail::gauss_legendre().0.len() as u32,
        ),
    ]
}

/// The escape tail's Gauss-Legendre nodes and weights as WGSL arrays.
fn quadrature() -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let (t, w) = crate::physics::tail::gauss_legendre();
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{:e}", *x as f32))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let _ = writeln!(
        s,
        "var<private> GL_T: array<f32, {n}> = array<f32, {n}>({});",
        list(t),
        n = t.len()
    );
    let _ = writeln!(
        s,
        "var<private> GL_W: array<f32, {n}> = array<f32, {n}>({});",
        list(w),
        n = w.len()
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_medium_block_fits_its_slot_and_has_its_reader() {
        // The blocks the media build of themselves are packed into
        // Params::medium (8 words) and Params::medium_motion, and read in
        // the shader by the header's readers: each block's own generated
        // struct and reader, of its slot, are in the header.
        use crate::transfer::{gold, riaf, uniform, volume};
        use crate::wgsl::Block;
        let header = header(&Variant {
            n_wl: 1,
            spectral: false,
            spec_array: false,
            filters: false,
            objects: false,
            gas: false,
            travel: false,
            closed: false,
            kerr: true,
            observe: false,
            footprint: false,
            object_footprint: false,
            medium: true,
            grmhd: false,
        });
        let p: Params = bytemuck::Zeroable::zeroed();
        let medium = (std::mem::size_of_val(&p.medium) / 4, "P.medium");
        let motion = (
            std::mem::size_of_val(&p.medium_motion) / 4,
            "P.medium_motion",
        );
        fn check<B: Block>(header: &str, reader: &str, (words, slot): (usize, &str)) {
            assert!(
                B::FIELDS.len() <= words,
                "{}: {} words",
                B::NAME,
                B::FIELDS.len()
            );
            assert!(header.contains(&B::wgsl(reader, slot)), "{}", B::NAME);
        }
        check::<gold::GoldBlock>(&header, "gold_block", medium);
        check::<uniform::UniformBlock>(&header, "uniform_block", medium);
        check::<riaf::RiafBlock>(&header, "riaf_block", medium);
        check::<volume::VolumeGasBlock>(&header, "volume_gas_block", medium);
        check::<riaf::MotionBlock>(&header, "motion_block", motion);
    }

    #[test]
    fn every_rust_file_a_shader_names_exists() {
        // A shader's header names the Rust it is the twin of ("twin of
        // src/physics/closed.rs"), and its comments the Rust they follow:
        // each such path (a file, or a folder ending in /) is in the tree,
        // and every shader that is a twin names one.
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut shaders = Vec::new();
        let mut folders = vec![root.join("src/gpu")];
        while let Some(dir) = folders.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    folders.push(path);
                } else if path.extension().is_some_and(|e| e == "wgsl") {
                    shaders.push(path);
                }
            }
        }
        assert!(shaders.len() > 20, "{} shaders", shaders.len());
        let mut named = 0;
        for shader in &shaders {
            let text = std::fs::read_to_string(shader).unwrap();
            let header: String = text
                .lines()
                .take_while(|l| l.starts_with("//"))
                .collect::<Vec<_>>()
                .join(" ");
            let comments = text
                .lines()
                .filter_map(|l| l.split_once("//").map(|(_, c)| c));
            for comment in comments {
                for word in comment.split(|c: char| c.is_whitespace() || "(),;:".contains(c)) {
                    let Some(at) = word.find("src/") else {
                        continue;
                    };
                    let path = &word[at..];
                    let path = path.strip_suffix("'s").unwrap_or(path);
                    let path = path.trim_end_matches(['.', '\'', '`']);
                    assert!(
                        root.join(path).exists() && (path.ends_with(".rs") || path.ends_with('/')),
                        "{}: names {path}, which is not a Rust file or folder of the tree",
                        shader.display()
                    );
                    named += 1;
                }
            }
            if header.to_lowercase().contains("twin of") {
                assert!(
                    header.contains("src/"),
                    "{}: a twin whose header names no Rust file",
                    shader.display()
                );
            }
        }
        assert!(named > 30, "{named} paths named");
    }

    /// Every variant: each switch on and off, RGB and 81 wavelengths
    /// (object footprints only with objects).
    fn variants() -> Vec<Variant> {
        let mut out = Vec::new();
        for bits in 0..2048u32 {
            if bits & (1 << 10) != 0 && bits & (1 << 3) == 0 {
                continue;
            }
            let on = |k: u32| bits & (1 << k) != 0;
            let spectral = on(0);
            out.push(Variant {
                n_wl: if spectral { 81 } else { 1 },
                spectral,
                spec_array: spectral && on(1),
                filters: on(2),
                objects: on(3),
                gas: on(4),
                travel: on(5),
                closed: on(6),
                kerr: on(7),
                observe: on(8),
                footprint: on(9),
                object_footprint: on(10),
                medium: false,
                grmhd: false,
            });
        }
        // Observed scenes: a medium alone, at one or several frequencies,
        // kept per pixel, around either hole.
        for (n_wl, kerr, grmhd) in [
            (1, false, false),
            (1, true, false),
            (3, false, false),
            (3, true, false),
            (1, true, true),
            (3, true, true),
        ] {
            out.push(Variant {
                n_wl,
                spectral: false,
                spec_array: true,
                filters: false,
                objects: false,
                gas: false,
                travel: false,
                closed: false,
                kerr,
                observe: false,
                footprint: false,
                object_footprint: false,
                medium: true,
                grmhd,
            });
        }
        out.dedup();
        out
    }

    fn parse(v: &Variant) -> naga::Module {
        let source = crate::gpu::shader_source(v);
        naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| {
            panic!("{v:?}: {}", e.emit_to_string(&source));
        })
    }

    #[test]
    fn every_shader_variant_compiles_and_validates() {
        // What a GPU driver would refuse, found without one (the browser
        // gets the text; native drivers the module specialised). Over the
        // threads: 128 variants took half a minute one after another.
        use rayon::prelude::*;
        variants().par_iter().for_each(|v| {
            let v = *v;
            let module = parse(&v);
            let mut validator = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::empty(),
            );
            if let Err(e) = validator.validate(&module) {
                let source = crate::gpu::shader_source(&v);
                panic!("{v:?}: {}", e.emit_to_string(&source));
            }
            // What native drivers get: the module without what the
            // variant's switches turn off.
            let mut lean = module.clone();
            crate::gpu::specialise::specialise(&mut lean);
            if let Err(e) = validator.validate(&lean) {
                panic!("{v:?} specialised: {e:?}");
            }
            for entry in ["main", "resolve"] {
                assert!(
                    module.entry_points.iter().any(|e| e.name == entry),
                    "{v:?}: no entry point {entry}"
                );
            }
        });
    }

    fn validate(module: &naga::Module, source: &str) {
        let mut validator = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        );
        if let Err(e) = validator.validate(module) {
            panic!("{}", e.emit_to_string(source));
        }
    }

    #[test]
    fn the_display_shader_compiles_and_validates() {
        let source = crate::gpu::display_source();
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&source)));
        validate(&module, &source);
        for entry in ["accumulate", "blur_rows", "blur_columns", "tonemap"] {
            assert!(
                module.entry_points.iter().any(|e| e.name == entry),
                "no entry point {entry}"
            );
        }
        assert_laid_out_alike(
            &module,
            "DisplayParams",
            &DisplayParams::offsets(),
            std::mem::size_of::<DisplayParams>(),
        );
    }

    /// The WGSL struct `name` in `module` has the Rust struct's member
    /// names, offsets and size.
    fn assert_laid_out_alike(
        module: &naga::Module,
        name: &str,
        rust: &[(&'static str, usize)],
        size: usize,
    ) {
        let (members, span) = module
            .types
            .iter()
            .find_map(|(_, t)| match (&t.name, &t.inner) {
                (Some(n), naga::TypeInner::Struct { members, span }) if n == name => {
                    Some((members.clone(), *span))
                }
                _ => None,
            })
            .unwrap_or_else(|| panic!("no struct {name}"));
        assert_eq!(members.len(), rust.len());
        for (m, (field, offset)) in members.iter().zip(rust) {
            assert_eq!(m.name.as_deref(), Some(*field));
            assert_eq!(m.offset as usize, *offset, "{name}.{field}");
        }
        assert_eq!(span as usize, size);
    }

    #[test]
    fn the_wgsl_params_are_laid_out_as_the_rust_struct() {
        let module = parse(&variants()[0]);
        assert_laid_out_alike(
            &module,
            "Params",
            &Params::offsets(),
            std::mem::size_of::<Params>(),
        );
    }
}
