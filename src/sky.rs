//! The panorama at infinity, looked up by the escape direction alone.

use crate::config::Filter;
use crate::footprint::Footprint;
use crate::spectral::SpectralContext;
use crate::spectrum::BlackbodyTable;
use crate::spectrum::uplift::{RgbSpectrum, uplift};
use crate::starmap::StarMap;
use crate::stars::{StarField, SumRule};
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
        /// The splatted catalogue, or with point stars the Milky Way
        /// alone.
        map: StarMap,
        /// The catalogue as point sources (`filter = "footprint"`): each
        /// star's flux through the pixel filter, over the sample's
        /// footprint.
        points: Option<std::sync::Arc<StarField>>,
        /// Lookup filter.
        filter: Filter,
        /// Linear multiplier.
        intensity: f32,
        /// Blackbody colours for RGB renders.
        colours: BlackbodyTable,
    },
}

impl Sky {
    /// The filter its lookups take, for a sky read from a map.
    pub fn filter(&self) -> Option<Filter> {
        match self {
            Sky::Panorama { filter, .. } | Sky::Stars { filter, .. } => Some(*filter),
            _ => None,
        }
    }

    /// Linear sRGB seen along unit direction `dir`.
    #[inline]
    pub fn radiance(&self, dir: DVec3, fp: Option<SkyView>) -> Vec3 {
        match self {
            Sky::Uniform { rgb, .. } | Sky::Blackbody { rgb, .. } => *rgb,
            Sky::Panorama {
                texture,
                filter,
                intensity,
            } => {
                texture
                    .sample_sky(dir, *filter, sky_derivatives(fp))
                    .truncate()
                    * *intensity
            }
            Sky::Stars {
                map,
                points,
                filter,
                intensity,
                colours,
            } => {
                let mut c = Vec3::ZERO;
                for (t, l) in map
                    .sample_filtered(dir, *filter, sky_derivatives(fp))
                    .blackbodies()
                {
                    c += colours.get(t) * l;
                }
                if let (Some(field), Some(view)) = (points, fp) {
                    point_stars(field, view, |t, l| c += colours.get(t) * l as f32);
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
        fp: Option<SkyView>,
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
                let rgb = texture
                    .sample_sky(dir, *filter, sky_derivatives(fp))
                    .truncate()
                    * *intensity;
                add_rgb(uplift(rgb), k, out);
            }
            Sky::Stars {
                map,
                points,
                filter,
                intensity,
                ..
            } => {
                for (t, l) in map
                    .sample_filtered(dir, *filter, sky_derivatives(fp))
                    .blackbodies()
                {
                    let k = k * intensity * l;
                    ctx.planck.add(t, g, beaming, k, range.clone(), out);
                }
                if let (Some(field), Some(view)) = (points, fp) {
                    point_stars(field, view, |t, l| {
                        let k = k * intensity * l as f32;
                        ctx.planck.add(t, g, beaming, k, range.clone(), out);
                    });
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
        fp: Option<SkyView>,
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
                points,
                filter,
                intensity,
                ..
            } => {
                let mut xyz = DVec3::ZERO;
                for (t, l) in map
                    .sample_filtered(dir, *filter, sky_derivatives(fp))
                    .blackbodies()
                {
                    xyz += ctx.planck.xyz(t.ln(), ln_g, beaming, k * intensity * l);
                }
                if let (Some(field), Some(view)) = (points, fp) {
                    point_stars(field, view, |t, l| {
                        xyz += ctx
                            .planck
                            .xyz(t.ln(), ln_g, beaming, k * intensity * l as f32);
                    });
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
            Sky::Stars { map, points, .. } => {
                map.memory_bytes() + points.as_ref().map_or(0, |p| p.memory_bytes())
            }
            _ => 0,
        }
    }
}

/// A sample's footprint as the sky reads it, with the lens itself: where
/// the ray through another image point escapes (None where it does not),
/// to place a star's image exactly.
#[derive(Clone, Copy)]
pub struct SkyView<'a> {
    /// The sample's footprint.
    pub footprint: &'a Footprint,
    /// The escape direction of the ray through an image point.
    pub lens: &'a dyn Fn(glam::DVec2) -> Option<DVec3>,
}

/// The escape direction's derivatives per pixel of a sample's footprint,
/// where it has them.
#[inline]
fn sky_derivatives(fp: Option<SkyView>) -> Option<(DVec3, DVec3)> {
    fp.and_then(|f| f.footprint.sky)
        .map(|(_, [dx, dy])| (dx, dy))
}

/// How far past the tent's reach (pixels) a first estimate of a star's
/// image is still refined.
pub(crate) const REFINE_MARGIN: f64 = 0.5;

/// The flux (the luminance a source of one steradian would have) of a
/// star of visual magnitude 0: the shipped catalogue's faint stars keep
/// the light their splatted spots gave them at the default resolution.
pub const MAG0_FLUX: f64 = 4.2e-4;

/// The point stars a sample sees: each star whose image falls within the
/// pixel filter's reach of the sample's pixel, as `visit(kelvin,
/// radiance)`. A star's image is where the footprint's linear map puts
/// it, and its radiance its flux through a tent filter one pixel wide
/// about the pixel's centre (normalised: its weights over the pixels
/// about an image sum to 1, so the image's pixels hold its flux times its
/// magnification), over the sky's solid angle a pixel spans there. Where
/// the footprint holds too many stars to count, the summed levels give
/// the light per steradian, which a lens keeps.
fn point_stars(field: &StarField, view: SkyView, mut visit: impl FnMut(f64, f64)) {
    let fp = view.footprint;
    let Some((d, [dx, dy])) = fp.sky else {
        return;
    };
    let sr = dx.cross(dy).dot(d).abs();
    if !(sr > 0.0) {
        return;
    }
    // Image-plane offsets e of a sky point near d: least squares of
    // dx e.x + dy e.y = the point's offset in the tangent plane at d.
    let (a, b, c) = (dx.dot(dx), dx.dot(dy), dy.dot(dy));
    let det = a * c - b * b;
    // The tent reaches one pixel from the centre, the sample is within
    // half a pixel of it.
    let reach = 1.5 * (dx.length() + dy.length());
    let offset = fp.offset();
    let density = field.footprint(d, reach, SumRule::default(), |star, weight| {
        let s = star.direction();
        let along = s.dot(d);
        if along <= 0.0 {
            return;
        }
        // The image-plane offset of a tangent-plane offset at d.
        let solve = |off: DVec3| {
            let (p, q) = (dx.dot(off), dy.dot(off));
            glam::DVec2::new(c * p - b * q, a * q - b * p) / det
        };
        let mut e = solve(s / along - d);
        // One Newton step through the lens itself: each pixel around the
        // image then places it alike (by its own linear map alone they
        // disagree where the map curves, and the tent's weights no longer
        // add up to one).
        if (offset + e).abs().max_element() < 1.0 + REFINE_MARGIN
            && let Some(d1) = (view.lens)(fp.at + e)
            && s.dot(d1) > 0.0
        {
            e += solve(s / s.dot(d1) - d1);
        }
        let t = offset + e;
        let tent = (1.0 - t.x.abs()).max(0.0) * (1.0 - t.y.abs()).max(0.0);
        if tent > 0.0 {
            visit(
                star.kelvin as f64,
                MAG0_FLUX * star.flux as f64 * weight * tent / sr,
            );
        }
    });
    for (t, flux) in density.light.blackbodies() {
        visit(t, MAG0_FLUX * flux);
    }
}
