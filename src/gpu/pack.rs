//! The scene as the shaders read it: [`Params`] (the layout of `Params` in
//! common.wgsl, field by field) and the flat buffers of tables, disk and
//! sky data. Everything is derived from the validated [`Scene`]; nothing is
//! re-read from files.

use super::GpuError;
use crate::config::{AlphaMode, Filter, Interpolation};
use crate::disk::DiskMaterial;
use crate::physics::Model;
use crate::scene::Scene;
use crate::sky::Sky;
use crate::spectrum::color::linear_srgb_to_xyz;
use crate::starmap::MILKY_WAY_KELVIN;
use bytemuck::{Pod, Zeroable};
use glam::DVec3;

/// Scene parameters (see common.wgsl for each field's meaning).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct Params {
    pub cam_pos: [f32; 4],
    pub cam_fwd: [f32; 4],
    pub cam_right: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam: [f32; 4],
    pub image: [u32; 4],
    pub tile: [u32; 4],
    pub model: [u32; 4],
    pub physics: [f32; 4],
    pub disk_i: [u32; 4],
    pub disk_dims: [u32; 4],
    pub disk_f: [f32; 4],
    pub disk_nm: [f32; 4],
    pub sky_i: [u32; 4],
    pub sky_dims: [u32; 4],
    pub sky_rgb: [f32; 4],
    pub sky_f: [f32; 4],
    pub sky_uplift: [f32; 4],
    pub off_a: [u32; 4],
    pub off_b: [u32; 4],
    pub off_c: [u32; 4],
    pub planck: [f32; 4],
    pub d65: [f32; 4],
    pub bb: [f32; 4],
    pub srgb_to_xyz: [[f32; 4]; 3],
    pub wl: [[f32; 4]; 512],
}

const FLAG_SHIFT: u32 = 1;
const FLAG_DOPPLER: u32 = 2;
const FLAG_BEAMING: u32 = 4;
const FLAG_LINEAR: u32 = 8;
const FLAG_KEEP_SPECTRA: u32 = 16;
const FLAG_BANDS: u32 = 32;

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
    pub disk: Vec<u32>,
    pub sky: Vec<u32>,
    /// Wavelengths per sample (1 for RGB renders).
    pub n_wl: u32,
    pub spectral: bool,
    pub keep_spectra: bool,
    pub bands: bool,
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
        let img = &scene.config.image;
        let mut p = Params {
            cam_pos: v4(cam.position),
            cam_fwd: v4(cam.forward),
            cam_right: v4(cam.right),
            cam_up: v4(cam.up),
            cam: [
                cam.half_height as f32,
                (cam.half_height * cam.width as f64 / cam.height as f64) as f32,
                cam.shift as f32,
                0.0,
            ],
            image: [
                cam.width,
                cam.height,
                img.samples,
                cam.static_observer as u32,
            ],
            tile: [img.seed as u32, (img.seed >> 32) as u32, 0, 0],
            ..Params::zeroed()
        };
        let (model, tolerance, step) = match scene.model {
            Model::Gr { tolerance } => (0, tolerance.max(MIN_GPU_TOLERANCE), 0.0),
            Model::Seed { step } => (1, 0.0, step),
        };
        p.physics = [
            tolerance as f32,
            step as f32,
            // The early-exit bounds only ever move exits outward: round
            // them that way.
            next_up(scene.limits.outer as f32),
            scene.limits.inner.min(f32::MAX as f64) as f32,
        ];
        let mut tables: Vec<f32> = Vec::new();
        let spectral = scene.spectral.is_some();
        let keep_spectra = spectral && scene.config.spectral.exr_layers;
        let bands = spectral && scene.config.bloom.as_ref().is_some_and(|b| b.spectral);
        let mut flags = 0;
        let mut n_wl = 1;
        // sRGB decoding of 8-bit textures.
        p.off_b[3] = push(
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
            p.off_a[2] = push(&mut tables, values.iter().copied());
            p.off_a[3] = push(&mut tables, ln_y.iter().map(|&v| v as f32));
            let (coeffs, scale, d65_norm) = crate::spectrum::uplift::gpu_tables();
            p.planck = [ln_t0 as f32, dln_t as f32, rows as f32, d65_norm as f32];
            let d65 = &*crate::spectrum::D65;
            p.off_b[0] = push(&mut tables, d65.values.iter().map(|&v| v as f32));
            p.d65 = [
                d65.start as f32,
                d65.step as f32,
                d65.values.len() as f32,
                0.0,
            ];
            p.off_b[1] = push(&mut tables, coeffs);
            p.off_b[2] = push(&mut tables, scale);
        }
        p.model = [model, scene.limits.max_steps, n_wl, flags];

        // The disk.
        let mut disk = Vec::new();
        if let Some(d) = &scene.disk {
            let filter = (d.filter == Filter::Bilinear) as u32;
            let alpha = (d.alpha == AlphaMode::Blend) as u32;
            p.disk_f = [d.inner as f32, d.outer as f32, d.intensity, 0.0];
            match &d.material {
                DiskMaterial::Rgb(t) => {
                    let (fmt, words) = t.gpu_words();
                    disk = words;
                    p.disk_i = [1, filter, alpha, fmt];
                    p.disk_dims = [t.width, t.height, 0, 0];
                }
                DiskMaterial::Spectral(s) => {
                    let (words, uniform) = s.gpu_words();
                    disk = words;
                    p.disk_i = [2, filter, alpha, 0];
                    p.disk_dims = [
                        s.width,
                        s.height,
                        s.nm.len() as u32,
                        uniform.is_some() as u32,
                    ];
                    let (nm0, dnm) = uniform.unwrap_or((s.nm[0], 0.0));
                    p.disk_nm = [nm0 as f32, dnm as f32, 0.0, 0.0];
                    p.off_c[1] = push(&mut tables, s.nm.iter().map(|&l| l as f32));
                }
            }
        }

        // The sky.
        let mut sky = Vec::new();
        match &scene.sky {
            Sky::Uniform { rgb, spectrum } => {
                p.sky_i = [0, 0, 0, 0];
                p.sky_rgb = [rgb.x, rgb.y, rgb.z, 0.0];
                p.sky_f = [0.0, 1.0, 0.0, 0.0];
                if let Some(s) = spectrum {
                    p.sky_uplift = s.gpu_coefficients();
                }
            }
            Sky::Blackbody {
                kelvin,
                intensity,
                rgb,
            } => {
                p.sky_i = [1, 0, 0, 0];
                p.sky_rgb = [rgb.x, rgb.y, rgb.z, 0.0];
                p.sky_f = [*kelvin as f32, *intensity, 0.0, 0.0];
            }
            Sky::Panorama {
                texture,
                filter,
                intensity,
            } => {
                let (fmt, words) = texture.gpu_words();
                sky = words;
                p.sky_i = [2, (*filter == Filter::Bilinear) as u32, fmt, 0];
                p.sky_dims = [texture.width, texture.height, 0, 0];
                p.sky_f = [0.0, *intensity, 0.0, 0.0];
            }
            Sky::Stars {
                map,
                filter,
                intensity,
                colours,
            } => {
                let (words, mw) = map.gpu_words();
                sky = words;
                p.sky_i = [3, (*filter == Filter::Bilinear) as u32, 0, (mw > 0) as u32];
                p.sky_dims = [map.width, map.width / 2, mw, mw / 2];
                p.sky_f = [0.0, *intensity, 0.0, 0.0];
                let (min, step, colors) = colours.gpu_parts();
                p.off_c[0] = push(&mut tables, colors.iter().flat_map(|c| c.to_array()));
                p.bb = [
                    min as f32,
                    step as f32,
                    colors.len() as f32,
                    MILKY_WAY_KELVIN as f32,
                ];
            }
        }
        // Bindings may not be empty.
        for v in [&mut disk, &mut sky] {
            if v.is_empty() {
                v.push(0);
            }
        }
        if tables.is_empty() {
            tables.push(0.0);
        }
        Ok(Packed {
            params: p,
            tables,
            disk,
            sky,
            n_wl,
            spectral,
            keep_spectra,
            bands,
        })
    }

    /// The constants the shader text is specialised with.
    pub fn shader_header(&self) -> String {
        let (t, w) = crate::physics::tail::gauss_legendre();
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{:e}", *x as f32))
                .collect::<Vec<_>>()
                .join(", ")
        };
        format!(
            "const N_WL: u32 = {}u;\nconst SPECTRAL: bool = {};\nconst SPEC_ARRAY: bool = {};\n\
             const SPEC_LEN: u32 = {}u;\nconst GL_N: u32 = {}u;\n\
             var<private> GL_T: array<f32, {}> = array<f32, {}>({});\n\
             var<private> GL_W: array<f32, {}> = array<f32, {}>({});\n",
            self.n_wl,
            self.spectral,
            self.keep_spectra || self.bands,
            if self.keep_spectra || self.bands {
                self.n_wl
            } else {
                1
            },
            t.len(),
            t.len(),
            t.len(),
            list(t),
            w.len(),
            w.len(),
            list(w)
        )
    }
}

/// The next f32 above `x` (for bounds that must not round inward).
fn next_up(x: f32) -> f32 {
    if x.is_finite() && x >= 0.0 {
        f32::from_bits(x.to_bits() + 1)
    } else {
        x
    }
}
