//! The panorama at infinity, looked up by the escape direction alone.

use crate::config::Filter;
use crate::render::Footprint;
use crate::spectral::SpectralContext;
use crate::spectrum::BlackbodyTable;
use crate::spectrum::uplift::{RgbSpectrum, uplift};
use crate::starmap::StarMap;
use crate::texture::Texture;
use glam::{DVec3, Vec3};
use std::ops::Range;

/// What an escaping ray sees.
#[derive(Clone, Debug)]
pub enum Sky {
    /// The same linear colour in every direction.
    Uniform {
        /// Linear sRGB.
        rgb: Vec3,
        /// Its uplifted spectrum (spectral renders only).
        spectrum: Option<RgbSpectrum>,
    },
    /// A uniform blackbody of luminance `intensity`.
    Blackbody {
        /// Temperature (K).
        kelvin: f64,
        /// Luminance.
        intensity: f32,
        /// Its linear sRGB.
        rgb: Vec3,
    },
    /// An equirectangular panorama ([`equirect_uv`] gives its orientation).
    Panorama {
        /// The image.
        texture: Texture,
        /// Lookup filter.
        filter: Filter,
        /// Linear multiplier.
        intensity: f32,
    },
    /// Stars of a catalogue, each a blackbody.
    Stars {
        /// The splatted catalogue.
        map: StarMap,
        /// Lookup filter.
        filter: Filter,
        /// Linear multiplier.
        intensity: f32,
        /// Blackbody colours for RGB renders.
        colours: BlackbodyTable,
    },
}

impl Sky {
    /// Linear sRGB seen along unit direction `dir`.
    #[inline]
    pub fn radiance(&self, dir: DVec3, fp: Option<&Footprint>) -> Vec3 {
        match self {
            Sky::Uniform { rgb, .. } | Sky::Blackbody { rgb, .. } => *rgb,
            Sky::Panorama {
                texture,
                filter,
                intensity,
            } => {
                texture.sample_sky(dir, *filter, sky_derivatives(fp)).truncate() * *intensity
            }
            Sky::Stars {
                map,
                filter,
                intensity,
                colours,
            } => {
                let mut c = Vec3::ZERO;
                for (t, l) in map.sample_filtered(dir, *filter, sky_derivatives(fp)).blackbodies() {
                    c += colours.get(t) * l;
                }
                c * *intensity
            }
        }
    }

    /// Adds `k` times the spectrum seen along `dir` at the camera
    /// wavelengths in `range`, for light arriving with frequency ratio `g`.
    #[allow(clippy::too_many_arguments)]
    pub fn add_spectrum(
        &self,
        dir: DVec3,
        fp: Option<&Footprint>,
        g: f64,
        ctx: &SpectralContext,
        k: f32,
        range: Range<usize>,
        out: &mut [f32],
    ) {
        let beaming = ctx.beaming;
        let add_rgb = |spec: RgbSpectrum, k: f32, out: &mut [f32]| {
            let k = k * ctx.radiance_factor(g);
            for i in range.clone() {
                out[i] += k * spec.emission(g * ctx.wavelengths.nm[i]) as f32;
            }
        };
        match self {
            Sky::Uniform { spectrum, .. } => {
                if let Some(spec) = spectrum {
                    add_rgb(*spec, k, out);
                }
            }
            Sky::Blackbody {
                kelvin, intensity, ..
            } => {
                ctx.planck
                    .add(*kelvin, g, beaming, k * intensity, range, out);
            }
            Sky::Panorama {
                texture,
                filter,
                intensity,
            } => {
                let rgb =
                    texture.sample_sky(dir, *filter, sky_derivatives(fp)).truncate() * *intensity;
                add_rgb(uplift(rgb), k, out);
            }
            Sky::Stars {
                map,
                filter,
                intensity,
                ..
            } => {
                for (t, l) in map.sample_filtered(dir, *filter, sky_derivatives(fp)).blackbodies() {
                    let k = k * intensity * l;
                    ctx.planck.add(t, g, beaming, k, range.clone(), out);
                }
            }
        }
    }

    /// The XYZ of what [`Sky::add_spectrum`] adds over all the wavelengths,
    /// for skies of blackbody light (none for the others), for light
    /// arriving with frequency ratio exp(`ln_g`).
    #[inline]
    pub fn xyz(
        &self,
        dir: DVec3,
        fp: Option<&Footprint>,
        ln_g: f64,
        ctx: &SpectralContext,
        k: f32,
    ) -> Option<DVec3> {
        let beaming = ctx.beaming;
        match self {
            Sky::Blackbody {
                kelvin, intensity, ..
            } => Some(ctx.planck.xyz(kelvin.ln(), ln_g, beaming, k * intensity)),
            Sky::Stars {
                map,
                filter,
                intensity,
                ..
            } => {
                let mut xyz = DVec3::ZERO;
                for (t, l) in map.sample_filtered(dir, *filter, sky_derivatives(fp)).blackbodies() {
                    xyz += ctx.planck.xyz(t.ln(), ln_g, beaming, k * intensity * l);
                }
                Some(xyz)
            }
            _ => None,
        }
    }

    /// Bytes held in memory.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Sky::Panorama { texture, .. } => texture.memory_bytes(),
            Sky::Stars { map, .. } => map.memory_bytes(),
            _ => 0,
        }
    }
}

/// The escape direction's derivatives per pixel of a sample's footprint,
/// where it has them.
#[inline]
fn sky_derivatives(fp: Option<&Footprint>) -> Option<(DVec3, DVec3)> {
    fp.and_then(|f| f.sky).map(|(_, [dx, dy])| (dx, dy))
}
