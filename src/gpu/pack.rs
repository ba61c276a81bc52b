//! The scene as the shaders read it: [`Params`] (the layout of `Params` in
//! common.wgsl, field by field) and the flat buffers of tables, disk and
//! sky data. Everything is derived from the validated [`Scene`]; nothing is
//! re-read from files.

use super::GpuError;
use crate::colormap::DISPLAY_KELVIN;
use crate::config::{AlphaMode, Filter, Interpolation};
use crate::disk::DiskMaterial;
use crate::physics::kerr::Kerr;
use crate::physics::{Frame, Model, Spacetime};
use crate::scene::Scene;
use crate::sky::Sky;
use crate::spectrum::color::linear_srgb_to_xyz;
use crate::starmap::MILKY_WAY_KELVIN;
use crate::transfer::{Medium, Observe};
use crate::units::cgs::JANSKY;
use bytemuck::Zeroable;
use glam::DVec3;

pub(crate) use super::layout::{
    CLOUD_WORDS, GLOW_WORDS, MAX_GPU_CLOUDS, NONE, OBJECT_WORDS, Params, SUN_WORDS,
};
use super::layout::{
    DISK_RGB, DISK_SPECTRAL, FLAG_BANDS, FLAG_BEAMING, FLAG_DOPPLER, FLAG_KEEP_SPECTRA,
    FLAG_LIGHT_TRAVEL, FLAG_LINEAR, FLAG_OBSERVE_G, FLAG_SHIFT, MEDIUM_GOLD, MEDIUM_GRMHD,
    MEDIUM_NONE, MEDIUM_RIAF, MEDIUM_UNIFORM, MEDIUM_VOLUME, MODEL_GR, MODEL_SEED,
    PROFILE_NOVIKOV_THORNE, PROFILE_PAGE_THORNE, PROFILE_SHAKURA_SUNYAEV, ROTATION_KEPLERIAN,
    ROTATION_NONE, ROTATION_RIGID, SKY_BLACKBODY, SKY_COLOR, SKY_PANORAMA, SKY_STARS,
};

/// Smallest tolerance the f32 integrator honours: below it, rounding in
/// the error estimate (about 1e-7 of r) would shrink steps for nothing.
pub const MIN_GPU_TOLERANCE: f64 = 1e-6;

fn v4(v: DVec3) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, 0.0]
}

/// A scene packed for the GPU.
pub(crate) struct Packed {
    pub params: Params,
    pub tables: Vec<f32>,
    /// What the tables hold, for a refusal where they pass the adapter's
    /// buffer limit.
    pub tables_label: String,
    pub disk: Vec<u32>,
    pub sky: Vec<u32>,
    /// Objects, their meshes and textures, lights, the volumetric disk
    /// and the clouds (floats as bits).
    pub objects: Vec<u32>,
    /// Per-wavelength filters are needed (spectral mirrors or clouds).
    pub filters: bool,
    /// The scene has objects; it has gas (volume or clouds). Shaders
    /// without them leave their code out.
    pub objects_present: bool,
    pub gas: bool,
    /// Rays keep their light's travel time (Scene::timed: for light
    /// travel time or the time map).
    pub travel: bool,
    /// Rays may take the closed form (Scene::closed_form).
    pub closed: bool,
    /// The hole spins.
    pub kerr: bool,
    /// The scene asks for observables (`image.observables`).
    pub observe: bool,
    /// Samples carry footprints.
    pub footprint: bool,
    /// Object textures are read over footprints at object hits.
    pub object_footprint: bool,
    /// Wavelengths per sample (1 for RGB renders).
    pub n_wl: u32,
    pub spectral: bool,
    pub keep_spectra: bool,
    pub bands: bool,
    /// An observed scene (`[medium]` with `[observe]`).
    pub medium: bool,
    /// The medium is a GRMHD snapshot.
    pub grmhd: bool,
}

/// What the tables hold, for a refusal past the adapter's limit: a GRMHD
/// snapshot's cells named with its dump.
fn tables_label(medium: Option<&Medium>) -> String {
    match medium {
        Some(Medium::Grmhd(g)) => format!(
            "the GRMHD dump {} ({}x{}x{} cells, {} floats each, with the scene's tables)",
            g.path.display(),
            g.header.n[0],
            g.header.n[1],
            g.header.n[2],
            crate::transfer::grmhd::FIELDS
        ),
        _ => "the scene's tables".into(),
    }
}

/// Appends `values` to the table buffer and returns where they start.
fn push(tables: &mut Vec<f32>, values: impl IntoIterator<Item = f32>) -> u32 {
    let at = tables.len() as u32;
    tables.extend(values);
    at
}

impl Packed {
    pub fn new(scene: &Scene) -> Result<Packed, GpuError> {
        let cam = &scene.camera;
        let mut p = Params {
            width: cam.width,
            height: cam.height,
            samples: scene.samples,
            static_observer: cam.frame.is_some() as u32,
            seed_lo: scene.seed as u32,
            seed_hi: (scene.seed >> 32) as u32,
            pass_samples: scene.samples,
            ..Params::zeroed()
        };
        set_model(&mut p, scene);
        let mut tables: Vec<f32> = Vec::new();
        let spectral = scene.spectral.is_some();
        let keep_spectra = scene.keep_spectra;
        let bands = scene.bloom_bands;
        let mut flags = 0;
        let mut n_wl = 1;
        // sRGB decoding of 8-bit textures.
        p.at_srgb_decode = push(
            &mut tables,
            crate::texture::srgb_decode_table().iter().copied(),
        );
        let m = glam::DMat3::from_cols(
            linear_srgb_to_xyz(DVec3::X),
            linear_srgb_to_xyz(DVec3::Y),
            linear_srgb_to_xyz(DVec3::Z),
        );
        p.srgb_to_xyz = [v4(m.x_axis), v4(m.y_axis), v4(m.z_axis)];
        if let Some(ctx) = &scene.spectral {
            n_wl = ctx.wavelengths.len() as u32;
            flags |= pack_spectral(&mut p, &mut tables, ctx, keep_spectra, bands);
        }
        if let Some(o) = &scene.observe {
            n_wl = o.frequencies.len() as u32;
            flags |= FLAG_KEEP_SPECTRA;
            pack_medium(&mut p, &mut tables, scene, o);
        }
        let observe_g = scene.observables.contains(&crate::film::Observable::G);
        if observe_g {
            flags |= FLAG_OBSERVE_G;
            // An RGB render's g map takes the file's Doppler setting
            // (cpu::Shifts).
            if !spectral && scene.config.spectral.doppler {
                flags |= FLAG_DOPPLER;
            }
        }
        if scene.light_travel_time {
            flags |= FLAG_LIGHT_TRAVEL;
        }
        p.max_steps = scene.limits.max_steps;
        p.n_wavelengths = n_wl;
        p.flags = flags;
        let mut disk = match &scene.disk {
            Some(d) => pack_disk(&mut p, &mut tables, d),
            None => Vec::new(),
        };
        let mut sky = pack_sky(&mut p, &mut tables, &scene.sky);
        // Footprint filtering's mip levels and weights.
        super::ewa::pack(&mut p, &mut tables, &mut disk, &mut sky, scene);
        // Point stars' tiers after them.
        super::stars::pack(&mut p, &mut tables, &mut sky, scene);
        let (objects, filters) = pack_objects(scene, &mut p)?;
        set_frame(&mut p, scene);
        // Bindings may not be empty.
        for v in [&mut disk, &mut sky] {
            if v.is_empty() {
                v.push(0);
            }
        }
        if tables.is_empty() {
            tables.push(0.0);
        }
        let medium = scene.observe.as_ref().and_then(|o| o.medium.as_ref());
        let kerr = matches!(scene.model.spacetime(), Some(Spacetime::Kerr { .. }));
        Ok(Packed {
            params: p,
            tables,
            tables_label: tables_label(medium),
            disk,
            sky,
            objects,
            filters,
            travel: scene.timed,
            observe: !scene.observables.is_empty(),
            footprint: scene.footprints,
            object_footprint: scene.object_footprints,
            kerr,
            // Kerr's closed-form rays here carry no azimuth: a medium
            // that is not the same at every azimuth takes the integrator
            // (the CPU's carry it, KerrRay::azimuth_at).
            closed: scene.closed_form && (!kerr || medium.is_none_or(|m| m.axisymmetric())),
            objects_present: !scene.objects.is_empty(),
            gas: scene.volume.is_some() || !scene.clouds.is_empty(),
            n_wl,
            spectral,
            keep_spectra,
            bands,
            medium: scene.observe.is_some(),
            grmhd: matches!(medium, Some(Medium::Grmhd(_))),
        })
    }

    /// The shader variant this scene needs.
    pub fn variant(&self) -> super::layout::Variant {
        super::layout::Variant {
            n_wl: self.n_wl,
            spectral: self.spectral,
            spec_array: self.keep_spectra || self.bands,
            filters: self.filters,
            objects: self.objects_present,
            gas: self.gas,
            travel: self.travel,
            closed: self.closed,
            kerr: self.kerr,
            observe: self.observe,
            footprint: self.footprint,
            object_footprint: self.object_footprint,
            medium: self.medium,
            grmhd: self.grmhd,
        }
    }

    /// The shader specialised for this scene (the probes' tests append
    /// their entry points to it).
    #[cfg(test)]
    pub fn shader_source(&self) -> String {
        super::shader_source(&self.variant())
    }
}

/// A parameter block's words into its slot of Params.
fn put_block(into: &mut [[f32; 4]; 2], words: &[f32]) {
    bytemuck::cast_slice_mut::<_, f32>(into)[..words.len()].copy_from_slice(words);
}

/// An observed scene's medium (if any) and units (media.wgsl and
/// transfer.wgsl): its kind, the blocks it builds of itself, the
/// frequencies in the wavelengths' slots, and the synchrotron average's
/// table.
fn pack_medium(p: &mut Params, tables: &mut Vec<f32>, scene: &Scene, o: &Observe) {
    use crate::wgsl::Block;
    let spin = scene.model.spacetime().map_or(0.0, |st| st.spin());
    p.medium_horizon = Kerr::new(spin).horizon() as f32;
    p.medium_spin = spin as f32;
    // Without a medium (a thin disk alone) its extent is 0: no ray nears it.
    p.medium_extent = o.medium.as_ref().map_or(0.0, Medium::extent) as f32;
    match &o.medium {
        None => p.medium_kind = MEDIUM_NONE,
        Some(Medium::Grmhd(g)) => {
            // Its block, theta's inverse and its cells, in the tables.
            p.medium_kind = MEDIUM_GRMHD;
            p.at_medium_table = push(tables, g.gpu_tables());
        }
        Some(Medium::Gold2020(g)) => {
            p.medium_kind = MEDIUM_GOLD;
            put_block(&mut p.medium, g.gpu_block().words());
        }
        Some(Medium::Uniform(u)) => {
            p.medium_kind = MEDIUM_UNIFORM;
            put_block(&mut p.medium, u.gpu_block().words());
        }
        Some(Medium::Riaf(r)) => {
            p.medium_kind = MEDIUM_RIAF;
            put_block(&mut p.medium, r.gpu_block().words());
            put_block(&mut p.medium_motion, r.motion.gpu_block().words());
            p.at_medium_table = push(
                tables,
                crate::transfer::synchrotron::average_table()
                    .iter()
                    .map(|&v| v as f32),
            );
        }
        Some(Medium::Volume(v)) => {
            // Its density and motion are the visible-band volume's
            // (pack_objects packs them: the grid at P.at_volume).
            p.medium_kind = MEDIUM_VOLUME;
            put_block(&mut p.medium, v.gpu_block().words());
        }
    }
    for (slot, nu) in p.wl.iter_mut().zip(&o.frequencies) {
        *slot = [0.0, 0.0, 0.0, *nu as f32];
    }
    p.medium_cm_per_m = scene.cm_per_m() as f32;
    p.medium_jy = ((scene.camera_distance_cm() / o.distance_cm).powi(2) / JANSKY) as f32;
    let (c, k) = (crate::units::cgs::LIGHT, crate::units::cgs::BOLTZMANN);
    p.medium_kelvin = (c * c / (2.0 * k) / DISPLAY_KELVIN) as f32;
}

/// The spacetime's parameters: the model, its tolerance or step, the
/// spinning hole's constants and the early-exit bounds.
fn set_model(p: &mut Params, scene: &Scene) {
    let (model, tolerance, step) = match scene.model {
        Model::Gr {
            tolerance,
            spacetime,
        } => {
            // The shader's spacetime functions are this spacetime's:
            // spacetime.wgsl's, and with spin (the KERR variant)
            // kerr.wgsl's, in M units.
            if let Spacetime::Kerr { a } = spacetime {
                let k = Kerr::new(a);
                let horizon = k.horizon();
                // Kerr::ks_trace's ends.
                let inner = ((2.0 * scene.limits.inner).powi(2) - a * a).max(0.0).sqrt();
                let capture = inner.min(Kerr::new(a.abs()).photon_orbit());
                p.kerr_hole =
                    [a, horizon, 1.0 - (1.0 - a * a).sqrt(), k.photon_orbit()].map(|v| v as f32);
                // With a medium (limits.inner 0) rays go to 1e-5 of r_+,
                // as Kerr::trace_bounds.
                let margin = if scene.limits.inner > 0.0 { 1e-3 } else { 1e-4 };
                p.kerr_limits = [
                    horizon * (1.0 + margin),
                    capture,
                    next_up(2.0 * scene.limits.outer as f32) as f64,
                    0.0,
                ]
                .map(|v| v as f32);
            }
            (MODEL_GR, tolerance.max(MIN_GPU_TOLERANCE), 0.0)
        }
        Model::Seed { step } => (MODEL_SEED, 0.0, step),
    };
    p.tolerance = tolerance as f32;
    p.seed_step = step as f32;
    // The early-exit bounds only ever move exits outward: round them
    // that way.
    p.outer_limit = next_up(scene.limits.outer as f32);
    p.inner_limit = scene.limits.inner.min(f32::MAX as f64) as f32;
    p.model = model;
}

/// The spectral tables (Planck, D65, the uplift) and the wavelengths of
/// `ctx`; returns the spectral flags.
fn pack_spectral(
    p: &mut Params,
    tables: &mut Vec<f32>,
    ctx: &crate::spectral::SpectralContext,
    keep_spectra: bool,
    bands: bool,
) -> u32 {
    let mut flags = 0;
    for (on, f) in [
        (ctx.shift, FLAG_SHIFT),
        (ctx.doppler, FLAG_DOPPLER),
        (ctx.beaming, FLAG_BEAMING),
        (ctx.interpolation == Interpolation::Linear, FLAG_LINEAR),
        (keep_spectra, FLAG_KEEP_SPECTRA),
        (bands, FLAG_BANDS),
    ] {
        if on {
            flags |= f;
        }
    }
    let wl = &ctx.wavelengths;
    for (slot, (w, &l)) in p.wl.iter_mut().zip(wl.weights.iter().zip(&wl.nm)) {
        *slot = [w.x as f32, w.y as f32, w.z as f32, l as f32];
    }
    let (ln_t0, dln_t, rows, values, ln_y) = ctx.planck.gpu_parts();
    p.at_planck = push(tables, values.iter().copied());
    p.at_planck_ln_y = push(tables, ln_y.iter().map(|&v| v as f32));
    // Each row's XYZ: what a blackbody adds when only XYZ is wanted.
    let n = wl.len();
    let xyz: Vec<f32> = values
        .chunks_exact(n)
        .flat_map(|row| {
            let c: DVec3 = row
                .iter()
                .zip(&wl.weights)
                .map(|(&v, w)| *w * v as f64)
                .sum();
            [c.x as f32, c.y as f32, c.z as f32]
        })
        .collect();
    p.at_planck_xyz = push(tables, xyz);
    let (coeffs, d65_norm) = crate::spectrum::uplift::gpu_tables();
    p.planck_ln_t0 = ln_t0 as f32;
    p.planck_dln_t = dln_t as f32;
    p.planck_rows = rows as f32;
    p.d65_norm = d65_norm as f32;
    let d65 = &*crate::spectrum::D65;
    p.at_d65 = push(tables, d65.values.iter().map(|&v| v as f32));
    p.d65_nm0 = d65.start as f32;
    p.d65_dnm = d65.step as f32;
    p.d65_count = d65.values.len() as f32;
    p.at_uplift = push(tables, coeffs);
    flags
}

/// A filter as the shader's `disk_filter`/`sky_filter` take it: 0
/// nearest, 1 bilinear, 2 over the footprint (bilinear where a sample has
/// none, as Texture::sample_filtered).
fn filter_code(f: Filter) -> u32 {
    match f {
        Filter::Nearest => 0,
        Filter::Bilinear => 1,
        Filter::Footprint => 2,
    }
}

/// The disk's parameters and tables; returns its texture's words.
fn pack_disk(p: &mut Params, tables: &mut Vec<f32>, d: &crate::disk::Disk) -> Vec<u32> {
    let disk;
    let filter = filter_code(d.filter);
    let alpha = (d.alpha == AlphaMode::Blend) as u32;
    p.disk_inner = d.inner as f32;
    p.disk_material_inner = d.material_inner as f32;
    p.disk_outer = d.outer as f32;
    p.disk_intensity = d.intensity;
    p.disk_filter = filter;
    p.disk_alpha = alpha;
    if let Some(t) = &d.thin {
        p.thin_profile = match t.profile {
            crate::thin_disk::Profile::NovikovThorne => PROFILE_NOVIKOV_THORNE,
            crate::thin_disk::Profile::ShakuraSunyaev => PROFILE_SHAKURA_SUNYAEV,
        };
        p.thin_inner = t.inner as f32;
        p.thin_f_col = t.f_col as f32;
        p.thin_t0 = t.temperature_scale() as f32;
        if let Some((scale, roots, coef)) = t.gpu_page_thorne() {
            p.thin_profile = PROFILE_PAGE_THORNE;
            p.thin_t0 = scale as f32;
            p.thin_pt_roots = roots.map(|v| v as f32);
            p.thin_pt_coef = coef.map(|v| v as f32);
        }
        let (ln_lo, step, rows) = crate::thin_disk::gpu_table();
        p.at_thin_xyz = push(tables, rows.iter().flat_map(|r| r.map(|v| v as f32)));
        p.thin_ln_t0 = ln_lo as f32;
        p.thin_dln_t = step as f32;
        p.thin_rows = rows.len() as f32;
    }
    match &d.material {
        DiskMaterial::Rgb(t) => {
            let (fmt, words) = t.gpu_words();
            disk = words;
            p.disk_kind = DISK_RGB;
            p.disk_format = fmt;
            (p.disk_width, p.disk_height) = (t.width, t.height);
        }
        DiskMaterial::Spectral(s) => {
            let (words, uniform) = s.gpu_words();
            disk = words;
            p.disk_kind = DISK_SPECTRAL;
            (p.disk_width, p.disk_height) = (s.width, s.height);
            p.disk_set_len = s.nm.len() as u32;
            p.disk_set_uniform = uniform.is_some() as u32;
            let (nm0, dnm) = uniform.unwrap_or((s.nm[0], 0.0));
            (p.disk_nm0, p.disk_dnm) = (nm0 as f32, dnm as f32);
            p.at_set_nm = push(tables, s.nm.iter().map(|&l| l as f32));
        }
    }
    disk
}

/// The sky's parameters and tables; returns its texture's or map's words.
fn pack_sky(p: &mut Params, tables: &mut Vec<f32>, sky_of: &Sky) -> Vec<u32> {
    let mut sky = Vec::new();
    match sky_of {
        Sky::Uniform { rgb, spectrum } => {
            p.sky_kind = SKY_COLOR;
            p.sky_rgb = [rgb.x, rgb.y, rgb.z, 0.0];
            p.sky_intensity = 1.0;
            if let Some(s) = spectrum {
                p.sky_uplift = s.gpu_coefficients();
            }
        }
        Sky::Blackbody {
            kelvin,
            intensity,
            rgb,
        } => {
            p.sky_kind = SKY_BLACKBODY;
            p.sky_rgb = [rgb.x, rgb.y, rgb.z, 0.0];
            (p.sky_kelvin, p.sky_intensity) = (*kelvin as f32, *intensity);
        }
        Sky::Panorama {
            texture,
            filter,
            intensity,
        } => {
            let (fmt, words) = texture.gpu_words();
            sky = words;
            p.sky_kind = SKY_PANORAMA;
            p.sky_filter = filter_code(*filter);
            p.sky_format = fmt;
            (p.sky_width, p.sky_height) = (texture.width, texture.height);
            p.sky_intensity = *intensity;
        }
        Sky::Stars {
            map,
            filter,
            intensity,
            colours,
            ..
        } => {
            let (words, mw) = map.gpu_words();
            sky = words;
            p.sky_kind = SKY_STARS;
            p.sky_filter = filter_code(*filter);
            p.sky_milky_way = (mw > 0) as u32;
            (p.sky_width, p.sky_height) = (map.width, map.width / 2);
            (p.milky_way_width, p.milky_way_height) = (mw, mw / 2);
            p.sky_intensity = *intensity;
            let (min, step, colors) = colours.gpu_parts();
            p.at_bb = push(tables, colors.iter().flat_map(|c| c.to_array()));
            (p.bb_t0, p.bb_dt, p.bb_count) = (min as f32, step as f32, colors.len() as f32);
            p.milky_way_kelvin = MILKY_WAY_KELVIN as f32;
        }
    }
    sky
}

/// The next f32 above `x` (for bounds that must not round inward).
fn next_up(x: f32) -> f32 {
    if x.is_finite() && x >= 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        x
    }
}

/// Floats and words of the object data, with records written in place.
struct Words(Vec<u32>);

impl Words {
    fn at(&self) -> u32 {
        self.0.len() as u32
    }
    fn f(&mut self, v: f64) {
        self.0.push((v as f32).to_bits());
    }
    fn u(&mut self, v: u32) {
        self.0.push(v);
    }
    fn v3(&mut self, v: DVec3) {
        self.f(v.x);
        self.f(v.y);
        self.f(v.z);
    }
    fn rgb(&mut self, c: glam::Vec3) {
        self.f(c.x as f64);
        self.f(c.y as f64);
        self.f(c.z as f64);
    }
    /// Pads the record that started at `start` to `len` words.
    fn pad(&mut self, start: u32, len: u32) {
        assert!(self.at() - start <= len, "record overflows");
        while self.at() - start < len {
            self.0.push(0);
        }
    }
    fn grid(&mut self, g: &crate::volume::Grid3) {
        let (n, min, cell, data) = g.gpu_parts();
        for k in n {
            self.u(k as u32);
        }
        self.v3(min);
        self.v3(cell);
        let off = self.at() + 1;
        self.u(off);
        self.0.extend(data.iter().map(|v| v.to_bits()));
    }
}

/// Packs objects, lights, the volumetric disk and the clouds; returns
/// the data and whether per-wavelength filters are needed.
pub(crate) fn pack_objects(scene: &Scene, p: &mut Params) -> Result<(Vec<u32>, bool), GpuError> {
    if scene.clouds.len() > MAX_GPU_CLOUDS {
        return Err(GpuError::Unsupported {
            table: "[[cloud]]".into(),
            why: format!(
                "{} clouds; the GPU marches at most {MAX_GPU_CLOUDS}",
                scene.clouds.len()
            ),
        });
    }
    let mut w = Words(Vec::new());
    // Object records first, then what they point to.
    let n_obj = scene.objects.len() as u32;
    w.0.resize((n_obj * OBJECT_WORDS) as usize, 0);
    let mut any_mirror = false;
    for (i, o) in scene.objects.iter().enumerate() {
        let rec = i as u32 * OBJECT_WORDS;
        let r = object_record(&mut w, o, &mut any_mirror);
        w.0[rec as usize..(rec + OBJECT_WORDS) as usize].copy_from_slice(&r);
    }
    let light_at = pack_lighting(&mut w, &scene.lighting);
    let volume_at = scene
        .volume
        .as_ref()
        .map_or(NONE, |v| pack_volume(&mut w, v));
    let spectral = scene.spectral.is_some();
    let clouds_at = pack_clouds(&mut w, &scene.clouds, spectral);
    p.n_objects = n_obj;
    p.at_lighting = light_at;
    p.at_volume = volume_at;
    if let Some(v) = &scene.volume {
        // The volume's gas moves as its Motion in both bands (motion.wgsl).
        use crate::wgsl::Block;
        p.medium_spin = scene.model.spacetime().map_or(0.0, |st| st.spin()) as f32;
        put_block(&mut p.medium_motion, v.motion.gpu_block().words());
    }
    p.n_clouds = scene.clouds.len() as u32;
    let filters = spectral && (any_mirror || !scene.clouds.is_empty());
    p.at_clouds = clouds_at;
    p.any_mirror = any_mirror as u32;
    if w.0.is_empty() {
        w.0.push(0);
    }
    Ok((w.0, filters))
}

/// The record of object `o` (see objects.wgsl), with its texture and mesh
/// appended to `w`; sets `any_mirror` for a mirror.
fn object_record(
    w: &mut Words,
    o: &crate::objects::Object,
    any_mirror: &mut bool,
) -> [u32; OBJECT_WORDS as usize] {
    use crate::objects::Finish;
    use crate::shapes::Shape;
    let mut r = [0u32; OBJECT_WORDS as usize];
    let f = |v: f64| (v as f32).to_bits();
    let (kind, finish, specular, shininess) = match o.material.finish {
        Finish::Color => (0, 0, 0.0, 1.0),
        Finish::Mirror => {
            *any_mirror = true;
            (0, 1, 0.0, 1.0)
        }
        Finish::Lit {
            specular,
            shininess,
        } => (0, 2, specular, shininess),
    };
    let _ = kind;
    r[1] = finish;
    r[2] = specular.to_bits();
    r[3] = shininess.to_bits();
    let c = o.material.color;
    r[4] = c.x.to_bits();
    r[5] = c.y.to_bits();
    r[6] = c.z.to_bits();
    r[7] = NONE;
    r[28] = NONE;
    if let Some(t) = &o.material.texture {
        let (fmt, texels) = t.gpu_words();
        r[7] = w.at();
        r[8] = t.width;
        r[9] = t.height;
        r[10] = fmt;
        r[11] = filter_code(o.material.filter);
        w.0.extend(texels);
        // Read over footprints: the mip levels 1 and up, in level 0's
        // format (as ewa.rs appends the disk's).
        if o.material.filter == Filter::Footprint {
            r[28] = w.at();
            w.0.extend(t.gpu_mip_words());
        }
    }
    let put3 = |r: &mut [u32], at: usize, v: DVec3| {
        r[at] = f(v.x);
        r[at + 1] = f(v.y);
        r[at + 2] = f(v.z);
    };
    match &o.shape {
        Shape::Sphere(sp) => {
            r[0] = 0;
            put3(&mut r, 12, sp.center);
            r[15] = f(sp.radius);
            put3(&mut r, 16, sp.pole);
            put3(&mut r, 20, sp.meridian);
            put3(&mut r, 24, sp.center);
            r[27] = f(sp.radius * (1.0 + 1e-5));
        }
        Shape::Rectangle(re) => {
            r[0] = 1;
            put3(&mut r, 12, re.center);
            put3(&mut r, 16, re.normal);
            r[19] = f(re.half.0);
            put3(&mut r, 20, re.u_axis);
            r[23] = f(re.half.1);
            put3(&mut r, 24, re.center);
            r[27] = f(re.half.0.hypot(re.half.1) * (1.0 + 1e-5));
        }
        Shape::Mesh(m) => {
            r[0] = 2;
            mesh_record(&mut r, w, m);
        }
    }
    r
}

/// A mesh's part of its object record `r`: where its BVH, triangles,
/// positions, normals and texture coordinates start in `w` (appended),
/// and its bounding sphere.
fn mesh_record(r: &mut [u32], w: &mut Words, m: &crate::shapes::Mesh) {
    let f = |v: f64| (v as f32).to_bits();
    let put3 = |r: &mut [u32], at: usize, v: DVec3| {
        r[at] = f(v.x);
        r[at + 1] = f(v.y);
        r[at + 2] = f(v.z);
    };
    let (pos, nrm, uvs, tris, bvh) = m.gpu_parts();
    let (nodes, order) = bvh.gpu_parts();
    // Bounding sphere: the root box's.
    let lo = DVec3::from_array(
        [0, 1, 2].map(|k| pos.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min)),
    );
    let hi = DVec3::from_array(
        [0, 1, 2].map(|k| pos.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max)),
    );
    put3(r, 24, 0.5 * (lo + hi));
    r[27] = f(0.5 * (hi - lo).length() * (1.0 + 1e-5));
    r[12] = w.at();
    w.0.extend(nodes.iter().flatten());
    r[13] = w.at();
    w.0.extend_from_slice(order);
    r[14] = w.at();
    w.0.extend(tris.iter().flatten());
    r[15] = w.at();
    for q in pos {
        w.v3(*q);
    }
    r[16] = NONE;
    if let Some(n) = nrm {
        r[16] = w.at();
        for q in n {
            w.v3(*q);
        }
    }
    r[17] = NONE;
    if let Some(t) = uvs {
        r[17] = w.at();
        for (u, v) in t {
            w.f(*u);
            w.f(*v);
        }
    }
    r[18] = tris.len() as u32;
}

/// Lighting: counts, ambient, then suns and disk-glow patches; returns
/// where it starts.
fn pack_lighting(w: &mut Words, l: &crate::objects::Lighting) -> u32 {
    use crate::objects::LightSpectrum;
    let light_at = w.at();
    w.u(l.suns.len() as u32);
    w.u(l.glow.len() as u32);
    w.u(0);
    w.u(0);
    w.rgb(l.ambient);
    w.u(0);
    for sun in &l.suns {
        let start = w.at();
        w.v3(sun.direction);
        w.f(sun.intensity as f64);
        w.rgb(sun.rgb);
        match sun.spectrum {
            LightSpectrum::Blackbody(kelvin, inv_y) => {
                w.u(0);
                w.f(kelvin);
                // B_lambda with lambda in nm: C1 / pi * 1e45 nm^-5 / (...),
                // folded into the normalisation so f32 stays in range.
                w.f(inv_y * crate::units::RADIATION_C1 / std::f64::consts::PI * 1e45);
                w.u(0);
                w.u(0);
                w.pad(start, 12);
            }
            LightSpectrum::Rgb(s) => {
                w.u(1);
                w.u(0);
                w.u(0);
                w.u(0);
                w.u(0);
                w.pad(start, 12);
                for c in s.gpu_coefficients() {
                    w.f(c as f64);
                }
            }
        }
        w.pad(start, SUN_WORDS);
    }
    for g in &l.glow {
        let start = w.at();
        w.v3(g.position);
        w.rgb(g.rgb_area);
        w.pad(start, GLOW_WORDS);
    }
    light_at
}

/// The volumetric disk; returns where its record starts.
fn pack_volume(w: &mut Words, v: &crate::volume::VolumeDisk) -> u32 {
    let volume_at = w.at();
    for x in [
        v.inner,
        v.outer,
        v.thickness,
        v.kappa,
        v.emission as f64,
        v.peak_kelvin,
        v.step,
        v.zmax(),
    ] {
        w.f(x);
    }
    let (source, colours) = v.gpu_parts();
    let (min, step, colors) = colours.gpu_parts();
    w.u(source.len() as u32);
    let src_at = w.at() + 7;
    w.u(src_at);
    w.f(min);
    w.f(step);
    w.u(colors.len() as u32);
    let colors_at = src_at + 2 * source.len() as u32;
    w.u(colors_at);
    let grid_at = colors_at + 3 * colors.len() as u32;
    w.u(grid_at);
    w.u(0);
    assert_eq!(w.at(), src_at);
    for (k, lum) in source {
        w.f(*k);
        w.f(*lum as f64);
    }
    for c in colors {
        w.rgb(*c);
    }
    assert_eq!(w.at(), grid_at);
    w.grid(&v.density);
    volume_at
}

/// The clouds' records, each with its extinction table and grid
/// appended; returns where the records start.
fn pack_clouds(w: &mut Words, clouds: &[crate::volume::Cloud], spectral: bool) -> u32 {
    let clouds_at = w.at();
    w.0.resize((clouds_at + clouds.len() as u32 * CLOUD_WORDS) as usize, 0);
    for (i, c) in clouds.iter().enumerate() {
        let rec = clouds_at + i as u32 * CLOUD_WORDS;
        let mut r = Words(Vec::new());
        r.v3(c.center);
        r.f(c.radius);
        r.f(c.kappa0);
        r.f(c.beta);
        r.f(c.step);
        r.u(0);
        r.rgb(c.glow);
        r.u(0);
        match &c.glow_spectrum {
            Some(s) if spectral => {
                for x in s.gpu_coefficients() {
                    r.f(x as f64);
                }
            }
            _ => {
                for _ in 0..4 {
                    r.u(0);
                }
            }
        }
        // 16: the extinction table (per camera wavelength), 17: the grid.
        r.u(w.at());
        if spectral {
            for e in &c.extinction_table {
                w.f(*e);
            }
        }
        r.u(w.at());
        w.grid(c.gpu_grid());
        r.pad(0, CLOUD_WORDS);
        w.0[rec as usize..(rec + CLOUD_WORDS) as usize].copy_from_slice(&r.0);
    }
    clouds_at
}

/// The parameters that change from frame to frame of an animation: the
/// camera and the time.
pub(crate) fn set_frame(p: &mut Params, scene: &Scene) {
    use crate::animation::DiskRotation;
    let cam = &scene.camera;
    p.cam_pos = v4(cam.position);
    p.cam_fwd = v4(cam.forward);
    p.cam_right = v4(cam.right);
    p.cam_up = v4(cam.up);
    p.cam_half_height = cam.half_height as f32;
    p.cam_half_width = (cam.half_height * cam.width as f64 / cam.height as f64) as f32;
    p.cam_shift = cam.shift as f32;
    // In f64 here: the hole's direction against the camera's axes.
    let to_hole = -cam.position.normalize();
    let ahead = to_hole.dot(cam.forward);
    let hand = cam.forward.cross(cam.right).dot(cam.up).signum();
    p.cam_velocity = v4(cam.velocity);
    // The exact rays of far cameras come from image points, which a moving
    // camera's aberration moves: none then.
    let moving = cam.velocity != glam::DVec3::ZERO;
    let spin = match scene.model.spacetime() {
        Some(Spacetime::Kerr { a }) => Some(a),
        _ => None,
    };
    if let Some(a) = spin {
        // The camera's frame, in f64: the shader maps each direction with
        // it (Spacetime::camera_basis) and shifts light by its
        // observer term.
        let k = Kerr::new(a);
        let x = 2.0 * cam.position;
        let u = match cam.rest_frame {
            Frame::Zamo => k.ks_zamo_velocity(x),
            // Refused inside the ergosphere when the scene is built.
            Frame::Static => k.ks_static_velocity(x).unwrap_or([f64::NAN; 4]),
        };
        // (t, x, y, z) to the shader's (x, y, z, t).
        fn txyz(w: [f64; 4]) -> [f32; 4] {
            [w[1] as f32, w[2] as f32, w[3] as f32, w[0] as f32]
        }
        p.cam_u = txyz(u);
        let frame = k.ks_frame(x, u);
        p.cam_frame = frame.map(txyz);
        // The closed form's linear forms (see Params::kerr_rays).
        let along = |d: glam::DVec3| -> [f64; 4] {
            std::array::from_fn(|m| d.x * frame[0][m] + d.y * frame[1][m] + d.z * frame[2][m])
        };
        let forms =
            [u, along(cam.forward), along(cam.right), along(cam.up)].map(|w| k.ks_ray_forms(x, w));
        p.kerr_rays = std::array::from_fn(|q| std::array::from_fn(|i| forms[i][q] as f32));
        let s = k.spheroidal(x);
        let ct = x.z / s.r;
        p.kerr_start = [
            s.r as f32,
            ct as f32,
            s.phi as f32,
            (1.0 - ct * ct).max(0.0).sqrt() as f32,
        ];
        p.kerr_observer = match cam.rest_frame {
            Frame::Zamo => {
                let s = k.spheroidal(x);
                let z = k.zamo(s.r, s.th);
                [1.0, z.omega as f32, z.alpha as f32, 0.0]
            }
            Frame::Static => [0.0, 0.0, 0.0, (-0.5 * (1.0 - k.ks_f(x)).ln()) as f32],
        };
    }
    p.cam_hole = if ahead > 0.0 && !moving {
        [
            (to_hole.dot(cam.right) / ahead) as f32,
            (to_hole.dot(cam.up) / ahead) as f32,
            0.0,
            hand as f32,
        ]
    } else {
        [0.0; 4]
    };
    let (kind, omega) = match scene.rotation {
        DiskRotation::None => (ROTATION_NONE, 0.0),
        // unturn in physics.wgsl turns the spacetime's orbits.
        DiskRotation::Keplerian(_) => (ROTATION_KEPLERIAN, 0.0),
        DiskRotation::Rigid(w) => (ROTATION_RIGID, w),
    };
    p.time = scene.time as f32;
    p.rigid_omega = omega as f32;
    p.rotation = kind;
}
