//! Solid objects (planets, moons, asteroids, ships) with their surfaces, and
//! the lights that shade `lit` ones.
//!
//! Lighting is local and unlensed: a surface point sees each sun along the
//! sun's direction (shadowed by other objects and the hole along a straight
//! line), the disk as a set of glowing patches, and an ambient term. The
//! light leaving the surface then reaches the camera along the curved ray
//! that found it, with the frequency shift of a static emitter.

use crate::config::Filter;
use crate::disk::Disk;
use crate::shapes::{Hit, Shape};
use crate::spectral::SpectralContext;
use crate::spectrum::uplift::{RgbSpectrum, uplift};
use crate::spectrum::{blackbody_rgb, planck, sampled::luminance};
use crate::texture::{Footprint, Texture};
use glam::{DVec3, Vec3};
use std::ops::Range;

/// Most mirror reflections followed for one sample, on either backend.
pub const MAX_BOUNCES: usize = 8;

/// How a surface answers light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Finish {
    /// Glows with its colour.
    Color,
    /// Reflects rays, tinted by its colour.
    Mirror,
    /// Diffuse albedo (its colour) plus Phong highlights.
    Lit {
        /// Specular reflectance.
        specular: f32,
        /// Phong exponent.
        shininess: f32,
    },
}

/// A surface.
#[derive(Clone, Debug)]
pub struct Material {
    /// Kind.
    pub finish: Finish,
    /// Colour (linear sRGB).
    pub color: Vec3,
    /// Texture multiplying the colour.
    pub texture: Option<Texture>,
    /// How the texture is read.
    pub filter: Filter,
}

impl Material {
    /// Linear colour at texture coordinates `uv`, read at the point.
    #[inline]
    pub fn color_at(&self, uv: (f64, f64)) -> Vec3 {
        self.color_over(uv, None, true)
    }

    /// Linear colour at texture coordinates `uv`, over the footprint `fp`
    /// (derivatives of uv per pixel) where the filter is
    /// [`Filter::Footprint`] and one is known, else at the point (u wraps
    /// for a point: a mesh's tiled coordinates; a footprint's u wraps
    /// where `wrap_u`).
    #[inline]
    pub fn color_over(&self, uv: (f64, f64), fp: Option<&Footprint>, wrap_u: bool) -> Vec3 {
        let Some(t) = &self.texture else {
            return self.color;
        };
        let texel = match (self.filter, fp) {
            (Filter::Footprint, Some(fp)) => t.sample_footprint(uv.0, uv.1, fp, wrap_u),
            (filter, _) => t.sample(uv.0, uv.1, filter, true),
        };
        self.color * texel.truncate()
    }
}

/// An object: geometry and surface.
#[derive(Clone, Debug)]
pub struct Object {
    /// Geometry (r_s units).
    pub shape: Shape,
    /// Surface.
    pub material: Material,
}

impl Object {
    /// Linear colour of the surface at `hit`, over the sample's footprint
    /// `fp` in texture coordinates where the material filters by one (see
    /// [`Material::color_over`]): u wraps round a sphere and a mesh (its
    /// coordinates may tile), not off a rectangle's edge.
    #[inline]
    pub fn color(&self, hit: &Hit, fp: Option<&Footprint>) -> Vec3 {
        let wrap_u = !matches!(self.shape, Shape::Rectangle(_));
        self.material.color_over(hit.uv, fp, wrap_u)
    }
}

/// Spectrum of a light.
#[derive(Clone, Copy, Debug)]
pub enum LightSpectrum {
    /// A blackbody scaled to luminance 1.
    Blackbody(f64, f64),
    /// An uplifted RGB colour.
    Rgb(RgbSpectrum),
}

impl LightSpectrum {
    /// Spectral value at `nm` (luminance-1 normalisation).
    #[inline]
    pub fn at(&self, nm: f64) -> f64 {
        match self {
            LightSpectrum::Blackbody(kelvin, inv_y) => planck(nm, *kelvin) * inv_y,
            LightSpectrum::Rgb(s) => s.emission(nm),
        }
    }

    /// A blackbody at `kelvin`.
    pub fn blackbody(kelvin: f64) -> LightSpectrum {
        LightSpectrum::Blackbody(kelvin, 1.0 / luminance(kelvin))
    }
}

/// A distant star lighting the objects.
#[derive(Clone, Debug)]
pub struct Sun {
    /// Unit direction towards it.
    pub direction: DVec3,
    /// Irradiance on a facing surface, as linear sRGB.
    pub rgb: Vec3,
    /// Its spectrum (luminance 1) and irradiance scale.
    pub spectrum: LightSpectrum,
    /// Irradiance scale.
    pub intensity: f32,
}

/// A patch of the disk acting as a light.
#[derive(Clone, Copy, Debug)]
pub struct Glow {
    /// Centre of the patch.
    pub position: DVec3,
    /// Emitted radiance times the patch's area (linear sRGB).
    pub rgb_area: Vec3,
}

/// Everything that lights `lit` surfaces.
#[derive(Clone, Debug, Default)]
pub struct Lighting {
    /// Distant stars.
    pub suns: Vec<Sun>,
    /// Ambient light (linear sRGB).
    pub ambient: Vec3,
    /// Disk patches (already scaled by the disk light's intensity).
    pub glow: Vec<Glow>,
}

impl Lighting {
    /// Splits the disk into patches (6 rings x 24 sectors between its
    /// material radii), each with the texture's mean emission over it.
    pub fn disk_glow(
        disk: &Disk,
        rgb_texture: &Texture,
        (inner, outer): (f64, f64),
        intensity: f32,
    ) -> Vec<Glow> {
        const RINGS: usize = 6;
        const SECTORS: usize = 24;
        let mut sum = vec![Vec3::ZERO; RINGS * SECTORS];
        let mut count = vec![0u32; RINGS * SECTORS];
        let (w, h) = (rgb_texture.width, rgb_texture.height);
        let cell = |r: f64, phi: f64| {
            let ring = (((r - inner) / (outer - inner)) * RINGS as f64) as usize;
            let sector = ((phi.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU)
                * SECTORS as f64) as usize;
            (ring < RINGS).then(|| ring * SECTORS + sector.min(SECTORS - 1))
        };
        for y in 0..h {
            for x in 0..w {
                let (px, py) = disk.texel_centre(x, y, w, h);
                let r = px.hypot(py);
                if r < inner || r >= outer {
                    continue;
                }
                if let Some(c) = cell(r, py.atan2(px)) {
                    sum[c] += rgb_texture.texel(x, y).truncate();
                    count[c] += 1;
                }
            }
        }
        let mut glow = Vec::new();
        for ring in 0..RINGS {
            let (r0, r1) = (
                inner + (outer - inner) * ring as f64 / RINGS as f64,
                inner + (outer - inner) * (ring + 1) as f64 / RINGS as f64,
            );
            let area = std::f64::consts::PI * (r1 * r1 - r0 * r0) / SECTORS as f64;
            let rc = 0.5 * (r0 + r1);
            for sector in 0..SECTORS {
                let c = ring * SECTORS + sector;
                if count[c] == 0 {
                    continue;
                }
                let phi = (sector as f64 + 0.5) / SECTORS as f64 * std::f64::consts::TAU;
                let mean = sum[c] / count[c] as f32 * disk.intensity;
                glow.push(Glow {
                    // The texture is the disk's polar coordinates.
                    position: disk.spacetime.disk_plane_point(rc, phi),
                    rgb_area: mean * (area as f32) * intensity,
                });
            }
        }
        glow
    }

    /// Irradiance (linear sRGB) from the disk at `p` with normal `n`; the
    /// disk radiates from both faces, unshadowed.
    #[inline]
    fn disk_irradiance(&self, p: DVec3, n: DVec3) -> Vec3 {
        let mut e = Vec3::ZERO;
        for g in &self.glow {
            let d = g.position - p;
            let d2 = d.length_squared();
            let w = d / d2.sqrt();
            let cos_p = n.dot(w);
            if cos_p <= 0.0 {
                continue;
            }
            let cos_q = w.z.abs();
            e += g.rgb_area * (cos_p * cos_q / d2) as f32;
        }
        e
    }
}

/// Whether the straight ray from `p` along `dir` is blocked by an object or
/// the hole (r < r_s).
fn shadowed(p: DVec3, dir: DVec3, objects: &[Object]) -> bool {
    // The hole: closest approach of the half-line.
    let t = (-p.dot(dir)).max(0.0);
    if (p + dir * t).length_squared() < 1.0 {
        return true;
    }
    let far = p + dir * 1e7;
    objects.iter().any(|o| o.shape.intersect(p, far).is_some())
}

/// The shading geometry at a hit: unit normal facing the viewer, unit
/// direction to the viewer, and a start point just off the surface.
#[inline]
fn frame(hit: &Hit, towards_viewer: DVec3) -> (DVec3, DVec3, DVec3) {
    let v = towards_viewer.normalize();
    let n = if hit.normal.dot(v) < 0.0 {
        -hit.normal
    } else {
        hit.normal
    };
    let eps = 1e-9 * hit.point.length().max(1.0);
    (n, v, hit.point + n * eps)
}

/// Radiance (linear sRGB) leaving a `Color` or `Lit` surface towards the
/// viewer (`towards_viewer` points back along the ray), its texture read
/// over `fp` where the material filters by footprint ([`Object::color`]).
pub fn shade_rgb(
    obj: &Object,
    (hit, fp): (&Hit, Option<&Footprint>),
    towards_viewer: DVec3,
    lights: &Lighting,
    objects: &[Object],
) -> Vec3 {
    let albedo = obj.color(hit, fp);
    let Finish::Lit {
        specular,
        shininess,
    } = obj.material.finish
    else {
        return albedo;
    };
    let (n, v, p) = frame(hit, towards_viewer);
    let mut diffuse = lights.ambient + lights.disk_irradiance(p, n);
    let mut highlight = Vec3::ZERO;
    for s in &lights.suns {
        let cos = n.dot(s.direction);
        if cos <= 0.0 || shadowed(p, s.direction, objects) {
            continue;
        }
        diffuse += s.rgb * cos as f32;
        if specular > 0.0 {
            let r = n * (2.0 * cos) - s.direction;
            highlight += s.rgb * (r.dot(v).max(0.0) as f32).powf(shininess);
        }
    }
    albedo * diffuse + highlight * specular
}

/// Adds `k` times the spectrum leaving a `Color` or `Lit` surface, seen at
/// the camera wavelengths in `range` with frequency ratio `g` (the texture
/// read over `fp` as for [`shade_rgb`]).
#[allow(clippy::too_many_arguments)]
pub fn add_spectrum(
    obj: &Object,
    (hit, fp): (&Hit, Option<&Footprint>),
    towards_viewer: DVec3,
    lights: &Lighting,
    objects: &[Object],
    g: f64,
    ctx: &SpectralContext,
    k: f32,
    range: Range<usize>,
    out: &mut [f32],
) {
    let albedo = uplift(obj.color(hit, fp));
    let k = k * ctx.radiance_factor(g);
    let Finish::Lit {
        specular,
        shininess,
    } = obj.material.finish
    else {
        for i in range {
            let l = g * ctx.wavelengths.nm[i];
            out[i] += k * albedo.emission(l) as f32;
        }
        return;
    };
    let (n, v, p) = frame(hit, towards_viewer);
    // Diffuse sources without a spectrum of their own (ambient, disk) are
    // uplifted from their colour.
    let rest = uplift(lights.ambient + lights.disk_irradiance(p, n));
    let mut suns = Vec::with_capacity(lights.suns.len());
    for s in &lights.suns {
        let cos = n.dot(s.direction);
        if cos <= 0.0 || shadowed(p, s.direction, objects) {
            continue;
        }
        let r = n * (2.0 * cos) - s.direction;
        let spec = if specular > 0.0 {
            specular * (r.dot(v).max(0.0) as f32).powf(shininess)
        } else {
            0.0
        };
        suns.push((s, cos, spec));
    }
    for i in range {
        let l = g * ctx.wavelengths.nm[i];
        let a = albedo.reflectance(l);
        let mut e = a * rest.emission(l);
        for (s, cos, spec) in &suns {
            let sun = s.intensity as f64 * s.spectrum.at(l);
            e += sun * (a * cos + *spec as f64);
        }
        out[i] += k * e as f32;
    }
}

/// A sun from its settings.
pub fn sun(direction: DVec3, kelvin: Option<f64>, color: Option<Vec3>, intensity: f32) -> Sun {
    let (rgb, spectrum) = match (kelvin, color) {
        (Some(t), _) => (blackbody_rgb(t), LightSpectrum::blackbody(t)),
        (None, Some(c)) => (c, LightSpectrum::Rgb(uplift(c))),
        (None, None) => (Vec3::ONE, LightSpectrum::Rgb(uplift(Vec3::ONE))),
    };
    Sun {
        direction: direction.normalize(),
        rgb: rgb * intensity,
        spectrum,
        intensity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::Sphere;

    fn ball(center: DVec3, finish: Finish) -> Object {
        Object {
            shape: Shape::Sphere(Sphere {
                center,
                radius: 1.0,
                pole: DVec3::Z,
                meridian: DVec3::X,
            }),
            material: Material {
                finish,
                color: Vec3::splat(0.5),
                texture: None,
                filter: Filter::Bilinear,
            },
        }
    }

    #[test]
    fn lambert_and_shadow() {
        // Sun overhead (+z), ball at x = 100, seen from above.
        let obj = ball(
            DVec3::new(100.0, 0.0, 0.0),
            Finish::Lit {
                specular: 0.0,
                shininess: 1.0,
            },
        );
        let lights = Lighting {
            suns: vec![sun(DVec3::Z, None, Some(Vec3::ONE), 1.0)],
            ..Default::default()
        };
        let hit = obj
            .shape
            .intersect(DVec3::new(100.0, 0.0, 50.0), DVec3::new(100.0, 0.0, 0.0))
            .unwrap();
        let c = shade_rgb(
            &obj,
            (&hit, None),
            DVec3::Z,
            &lights,
            std::slice::from_ref(&obj),
        );
        assert!((c - Vec3::splat(0.5)).abs().max_element() < 1e-6, "{c}");
        // At 60 degrees from the sun: cos = 1/2.
        let p = DVec3::new(100.0 + 3f64.sqrt() / 2.0, 0.0, 0.5);
        let hit = obj
            .shape
            .intersect(p + DVec3::new(10.0, 0.0, 0.0), p)
            .unwrap();
        let c = shade_rgb(
            &obj,
            (&hit, None),
            DVec3::X,
            &lights,
            std::slice::from_ref(&obj),
        );
        assert!((c - Vec3::splat(0.25)).abs().max_element() < 1e-6, "{c}");
        // A second ball above the first shades it.
        let blocker = ball(DVec3::new(100.0, 0.0, 10.0), Finish::Color);
        let hit = obj
            .shape
            .intersect(DVec3::new(100.0, 0.0, 5.0), DVec3::new(100.0, 0.0, 0.0))
            .unwrap();
        let c = shade_rgb(
            &obj,
            (&hit, None),
            DVec3::Z,
            &lights,
            &[obj.clone(), blocker],
        );
        assert_eq!(c, Vec3::ZERO);
    }

    #[test]
    fn hole_casts_a_shadow() {
        let obj = ball(
            DVec3::new(10.0, 0.0, 0.0),
            Finish::Lit {
                specular: 0.0,
                shininess: 1.0,
            },
        );
        let lights = Lighting {
            suns: vec![sun(DVec3::new(-1.0, 0.0, 0.0), None, Some(Vec3::ONE), 1.0)],
            ..Default::default()
        };
        let hit = obj
            .shape
            .intersect(DVec3::new(5.0, 0.0, 0.0), DVec3::new(10.0, 0.0, 0.0))
            .unwrap();
        let c = shade_rgb(
            &obj,
            (&hit, None),
            DVec3::new(-1.0, 0.0, 0.0),
            &lights,
            std::slice::from_ref(&obj),
        );
        assert_eq!(c, Vec3::ZERO);
    }
}
