//! The sky from a star catalogue: every star a blackbody.
//!
//! Stars come from a CSV extract of a catalogue (`hip,ra_deg,dec_deg,vmag,bv`;
//! the shipped one is `spectral_assets/stars/hipparcos_mag8.csv`, from the
//! Hipparcos-based data of d3-celestial). The map is in galactic
//! coordinates: the galactic centre (l = 0, b = 0) lies along +y, l = 90 deg
//! along -x (so the sky is seen unmirrored from inside), the north galactic
//! pole along +z; the Milky Way's plane is the panorama's equator.
//!
//! Each texel holds the luminance and temperature of the starlight on it
//! (stars are Gaussian spots in angle on the sphere, so they stay round near
//! the poles and survive nearest-neighbour sampling; where spots overlap the
//! temperature is the luminance-weighted mean), plus a faint Milky Way band
//! on a coarser grid, a blackbody at [`MILKY_WAY_KELVIN`]. RGB renders take
//! each blackbody's colour; spectral renders its true spectrum, shifted.

use crate::config::Filter;
use crate::texture::mip::{self, Levels};
use crate::texture::{equirect_dir, equirect_footprint, equirect_uv, ewa};
use glam::DVec3;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;
use std::sync::{Arc, OnceLock};

// The catalogue's rows and axes live in `crate::stars`; kept here for the
// star map's callers.
pub use crate::stars::catalogue::{
    DEFAULT_BV, Star, equatorial_to_galactic, galactic_to_world, parse_catalogue, star_kelvin,
};

/// Colour temperature of the Milky Way's diffuse light (K).
pub const MILKY_WAY_KELVIN: f64 = 4800.0;

/// Width of the Milky Way grid relative to the star grid: the band is
/// smooth, and its noise is the costly part of building the map.
const MILKY_WAY_DIVISOR: u32 = 4;

/// Noise seed of the Milky Way's structure.
const MILKY_WAY_SEED: u32 = 11;

/// Angular Gaussian width (texel heights) and peak linear brightness of a
/// star of visual magnitude `m`: faint stars are sharp and dim, bright ones
/// saturate and grow, as on a photograph.
fn star_spot(m: f64) -> (f64, f32) {
    let sigma = 0.6 + 0.3 * (5.0 - m).max(0.0);
    let peak = 0.05 * 10f64.powf(0.3 * (8.0 - m));
    (sigma, peak as f32)
}

fn milky_way_luminance(dir: DVec3, dust: &Fbm<Perlin>, clouds: &Fbm<Perlin>) -> f32 {
    // Galactic latitude b and longitude l of the scene direction.
    let g = DVec3::new(dir.y, -dir.x, dir.z);
    let b = g.z.clamp(-1.0, 1.0).asin().to_degrees();
    let l = g.y.atan2(g.x).to_degrees();
    // Brighter towards the centre than the anticentre.
    let band =
        (-0.5 * (b / 6.0).powi(2)).exp() * (0.35 + 0.65 * (0.5 * l.to_radians()).cos().powi(2));
    let bulge = 1.6 * (-0.5 * ((l / 20.0).powi(2) + (b / 9.0).powi(2))).exp();
    // Far from the plane the band is below a ten-thousandth of its peak
    // (and the lanes nil): its mean structure there differs from the noisy
    // one by under 1e-6 in luminance, and skips two thirds of the noise,
    // the costly part of a star scene's setup.
    if band + bulge < 1e-4 {
        return ((band + bulge) * 0.55) as f32 * 0.018;
    }
    let structure = 0.55 + 0.45 * clouds.get((dir * 5.0).to_array());
    // Dark lanes hug the plane (the Great Rift).
    let lane = (-0.5 * (b / 2.5).powi(2)).exp()
        * (0.5 + 0.5 * dust.get((dir * 9.0).to_array())).clamp(0.0, 1.0);
    ((band + bulge) * structure * (1.0 - 0.85 * lane)).max(0.0) as f32 * 0.018
}

/// Starlight on the sphere.
#[derive(Clone, Debug)]
pub struct StarMap {
    /// Width of the star grid (texels); the height is half.
    pub width: u32,
    /// Luminance of the starlight per texel.
    luminance: std::sync::Arc<Vec<f32>>,
    /// Its temperature (K), where the luminance is non-zero.
    kelvin: std::sync::Arc<Vec<f32>>,
    /// Milky Way luminance on a grid [`MILKY_WAY_DIVISOR`] times coarser.
    milky_way: Option<(u32, std::sync::Arc<Vec<f32>>)>,
    /// Mip levels for footprint lookups, built on first use; shared by
    /// clones.
    mips: Arc<StarMips>,
}

/// Levels 1 and up of the star grid (means of luminance and of luminance
/// times temperature, so a level's temperature is the luminance-weighted
/// mean) and of the Milky Way grid.
#[derive(Debug, Default)]
struct StarMips {
    stars: OnceLock<Levels<[f32; 2]>>,
    milky_way: OnceLock<Levels<f32>>,
}

/// What one direction of a [`StarMap`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StarLight {
    /// Luminance of the stars.
    pub luminance: f32,
    /// Their temperature (K).
    pub kelvin: f32,
    /// Luminance of the Milky Way (temperature [`MILKY_WAY_KELVIN`]).
    pub milky_way: f32,
}

impl StarLight {
    /// The blackbodies seen: (temperature in K, luminance) of the stars
    /// and of the Milky Way, those that are lit.
    pub fn blackbodies(&self) -> impl Iterator<Item = (f64, f32)> {
        [
            (self.kelvin as f64, self.luminance),
            (MILKY_WAY_KELVIN, self.milky_way),
        ]
        .into_iter()
        .filter(|&(_, l)| l > 0.0)
    }
}

impl StarMap {
    /// Splats the catalogue onto a `width` x `width / 2` grid. Without
    /// stars (point stars are drawn elsewhere) the map holds the Milky Way
    /// alone, and no star grid.
    pub fn build(stars: &[Star], width: u32, milky_way: bool) -> StarMap {
        let (w, h) = (width as usize, width as usize / 2);
        let texel = std::f64::consts::PI / h as f64;
        let texels = if stars.is_empty() { 0 } else { w * h };
        let mut lum = vec![0.0f32; texels];
        let mut lum_t = vec![0.0f32; texels];
        for s in stars {
            let dir = galactic_to_world(equatorial_to_galactic(s.ra, s.dec));
            let kelvin = star_kelvin(s.bv) as f32;
            let (sigma_px, peak) = star_spot(s.vmag);
            let sigma = sigma_px * texel;
            let reach = 3.5 * sigma;
            let (u, v) = equirect_uv(dir);
            let (ci, cj) = (u * w as f64, v * h as f64);
            let rows = (reach / texel).ceil() as isize + 1;
            let cos_lat = (1.0 - dir.z * dir.z).max(0.0).sqrt();
            // Near a pole one texel spans little angle: widen the column
            // range, up to the whole row.
            let cols = if cos_lat * (w as f64) < 4.0 * (reach / texel) {
                w as isize / 2
            } else {
                ((reach / texel) / cos_lat).ceil() as isize + 1
            };
            for dj in -rows..=rows {
                let j = cj.floor() as isize + dj;
                if j < 0 || j >= h as isize {
                    continue;
                }
                // At most one full row: -w/2 ..= w/2 would reach one column twice.
                let cols_hi = if 2 * cols >= w as isize {
                    w as isize - cols - 1
                } else {
                    cols
                };
                for di in -cols..=cols_hi {
                    let i = (ci.floor() as isize + di).rem_euclid(w as isize) as usize;
                    let d = equirect_dir((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                    // Angle between directions, stable for small angles.
                    let ang = 2.0 * ((d - dir).length() * 0.5).asin();
                    if ang > reach {
                        continue;
                    }
                    let l = peak * (-0.5 * (ang / sigma).powi(2)).exp() as f32;
                    lum[j as usize * w + i] += l;
                    lum_t[j as usize * w + i] += l * kelvin;
                }
            }
        }
        let kelvin: Vec<f32> = lum
            .iter()
            .zip(&lum_t)
            .map(|(&l, &lt)| if l > 0.0 { lt / l } else { 0.0 })
            .collect();
        let milky_way = milky_way.then(|| {
            let mw = (width / MILKY_WAY_DIVISOR).max(2);
            let (mw_w, mw_h) = (mw as usize, mw as usize / 2);
            let dust = Fbm::<Perlin>::new(MILKY_WAY_SEED).set_octaves(6);
            let clouds = Fbm::<Perlin>::new(MILKY_WAY_SEED + 1).set_octaves(6);
            let mut grid = vec![0.0f32; mw_w * mw_h];
            grid.par_chunks_mut(mw_w).enumerate().for_each(|(j, row)| {
                for (i, px) in row.iter_mut().enumerate() {
                    let d = equirect_dir(
                        (i as f64 + 0.5) / mw_w as f64,
                        (j as f64 + 0.5) / mw_h as f64,
                    );
                    *px = milky_way_luminance(d, &dust, &clouds);
                }
            });
            (mw, grid.into())
        });
        StarMap {
            width,
            luminance: lum.into(),
            kelvin: kelvin.into(),
            milky_way,
            mips: Arc::default(),
        }
    }

    /// The GPU backend's copy: luminance, then kelvin per texel, then the
    /// Milky Way grid, as f32 bits; and the Milky Way grid's width (0 for
    /// none).
    pub(crate) fn gpu_words(&self) -> (Vec<u32>, u32) {
        let mw: &[f32] = self.milky_way.as_ref().map_or(&[], |m| &m.1);
        let words = self
            .luminance
            .iter()
            .chain(self.kelvin.iter())
            .chain(mw)
            .map(|v| v.to_bits())
            .collect();
        (words, self.milky_way.as_ref().map_or(0, |m| m.0))
    }

    /// The mip levels (built now if not yet) as the GPU backend stores
    /// them: the star grid's levels 1 and up (two words a texel: the mean
    /// luminance and luminance times kelvin; none without a star grid)
    /// and the Milky Way grid's (none without it), as f32 bits.
    pub(crate) fn gpu_mip_words(&self) -> (Vec<u32>, Vec<u32>) {
        let stars = if self.luminance.is_empty() {
            Vec::new()
        } else {
            self.star_mips()
                .data
                .iter()
                .flatten()
                .map(|v| v.to_bits())
                .collect()
        };
        let mw = self.milky_way.as_ref().map_or(Vec::new(), |(mw, grid)| {
            self.milky_way_mips(*mw, grid)
                .data
                .iter()
                .map(|v| v.to_bits())
                .collect()
        });
        (stars, mw)
    }

    /// Whether the map has a star grid (without one, point stars are drawn
    /// elsewhere and the map holds the Milky Way alone).
    pub(crate) fn has_star_grid(&self) -> bool {
        !self.luminance.is_empty()
    }

    /// Bytes held in memory: the grids, and their mip levels once footprint
    /// lookups have built them.
    pub fn memory_bytes(&self) -> usize {
        let stars = self.mips.stars.get().map_or(0, |l| 8 * l.data.len());
        let mw = self.mips.milky_way.get().map_or(0, |l| 4 * l.data.len());
        8 * self.luminance.len() + self.milky_way.as_ref().map_or(0, |m| 4 * m.1.len()) + stars + mw
    }

    /// Bytes the mip levels of both grids take, built or not: at most a
    /// third of the grids'.
    pub fn pyramid_bytes(&self) -> usize {
        let mw = self
            .milky_way
            .as_ref()
            .map_or(0, |(m, _)| 4 * mip::texel_count(*m, *m / 2));
        8 * mip::texel_count(self.width, self.width / 2) + mw
    }

    /// Builds both grids' mip levels now rather than on the first footprint
    /// lookups that need them.
    pub fn build_pyramids(&self) {
        if !self.luminance.is_empty() {
            self.star_mips();
        }
        if let Some((mw, grid)) = &self.milky_way {
            self.milky_way_mips(*mw, grid);
        }
    }

    /// The star grid's levels, built on first call.
    fn star_mips(&self) -> &Levels<[f32; 2]> {
        self.mips.stars.get_or_init(|| {
            let w = self.width as usize;
            let row = |y: usize, buf: &mut [f32]| {
                for (x, p) in buf.chunks_exact_mut(2).enumerate() {
                    let (l, k) = (self.luminance[y * w + x], self.kelvin[y * w + x]);
                    p.copy_from_slice(&[l, l * k]);
                }
            };
            Levels::build(2, (self.width, self.width / 2), &row, |p| [p[0], p[1]])
        })
    }

    /// The Milky Way grid's levels (of a grid `mw` texels wide), built on
    /// first call.
    fn milky_way_mips(&self, mw: u32, grid: &[f32]) -> &Levels<f32> {
        self.mips.milky_way.get_or_init(|| {
            let w = mw as usize;
            let row = |y: usize, buf: &mut [f32]| buf.copy_from_slice(&grid[y * w..(y + 1) * w]);
            Levels::build(1, (mw, mw / 2), &row, |p| p[0])
        })
    }

    /// [`StarMap::sample`] with `filter`, or, for [`Filter::Footprint`]
    /// given the direction's derivatives per pixel step `(ddx, ddy)`,
    /// [`StarMap::sample_footprint`].
    #[inline]
    pub fn sample_filtered(
        &self,
        dir: DVec3,
        filter: Filter,
        derivatives: Option<(DVec3, DVec3)>,
    ) -> StarLight {
        match (filter, derivatives) {
            (Filter::Footprint, Some((ddx, ddy))) => self.sample_footprint(dir, ddx, ddy),
            _ => self.sample(dir, filter),
        }
    }

    /// The starlight over a pixel's footprint on the sky: `dir` the unit
    /// escape direction and `ddx`, `ddy` its derivatives per pixel step
    /// (scene axes), both grids read through the elliptical Gaussian filter
    /// of [`ewa`] (the stars' temperature the luminance-weighted mean).
    pub fn sample_footprint(&self, dir: DVec3, ddx: DVec3, ddy: DVec3) -> StarLight {
        let (u, v, fp) = equirect_footprint(dir, ddx, ddy);
        let (w, h) = (self.width, self.width / 2);
        let (ellipses, n) = if self.luminance.is_empty() {
            Default::default()
        } else {
            ewa::plan(u, v, &fp, w, h)
        };
        let (mut l, mut lt) = (0.0f32, 0.0f32);
        for e in &ellipses[..n] {
            let (lw, lh) = ewa::level_dims(w, h, e.level);
            let (mut a, mut b) = (0.0f32, 0.0f32);
            let sum = if e.level == 0 {
                ewa::visit(e, lw, lh, true, |i, wt| {
                    a += wt * self.luminance[i];
                    b += wt * self.luminance[i] * self.kelvin[i];
                })
            } else {
                let t = self.star_mips().level(e.level);
                ewa::visit(e, lw, lh, true, |i, wt| {
                    a += wt * t[i][0];
                    b += wt * t[i][1];
                })
            };
            l += e.weight * a / sum;
            lt += e.weight * b / sum;
        }
        let milky_way = self.milky_way.as_ref().map_or(0.0, |(mw, grid)| {
            let (mw_w, mw_h) = (*mw, *mw / 2);
            let (ellipses, n) = ewa::plan(u, v, &fp, mw_w, mw_h);
            let mut m = 0.0f32;
            for e in &ellipses[..n] {
                let (lw, lh) = ewa::level_dims(mw_w, mw_h, e.level);
                let t: &[f32] = match e.level {
                    0 => grid,
                    k => self.milky_way_mips(*mw, grid).level(k),
                };
                let mut a = 0.0f32;
                let sum = ewa::visit(e, lw, lh, true, |i, wt| a += wt * t[i]);
                m += e.weight * a / sum;
            }
            m
        });
        StarLight {
            luminance: l,
            kelvin: if l > 0.0 { lt / l } else { 0.0 },
            milky_way,
        }
    }

    /// The starlight along unit direction `dir`.
    #[inline]
    pub fn sample(&self, dir: DVec3, filter: Filter) -> StarLight {
        let (u, v) = equirect_uv(dir);
        let (w, h) = (self.width as usize, self.width as usize / 2);
        let (luminance, kelvin) = match filter {
            _ if self.luminance.is_empty() => (0.0, 0.0),
            Filter::Nearest => {
                let i = ((u * w as f64) as usize).min(w - 1);
                let j = ((v * h as f64) as usize).min(h - 1);
                (self.luminance[j * w + i], self.kelvin[j * w + i])
            }
            // A lookup without a footprint is a point: the footprint
            // filter's reconstruction there is bilinear's (callers that have
            // a footprint use `sample_footprint`).
            Filter::Bilinear | Filter::Footprint => {
                let (mut l, mut lt) = (0.0, 0.0);
                for (k, wt) in bilinear(u, v, w, h) {
                    l += wt * self.luminance[k];
                    lt += wt * self.luminance[k] * self.kelvin[k];
                }
                (l, if l > 0.0 { lt / l } else { 0.0 })
            }
        };
        let milky_way = self.milky_way.as_ref().map_or(0.0, |(mw, grid)| {
            let (mw_w, mw_h) = (*mw as usize, *mw as usize / 2);
            bilinear(u, v, mw_w, mw_h)
                .iter()
                .map(|&(k, wt)| wt * grid[k])
                .sum()
        });
        StarLight {
            luminance,
            kelvin,
            milky_way,
        }
    }
}

/// Texel indices and weights of a bilinear lookup at (u, v) in a w x h
/// panorama (wrapping across, clamped at the poles).
#[inline]
fn bilinear(u: f64, v: f64, w: usize, h: usize) -> [(usize, f32); 4] {
    let fx = u * w as f64 - 0.5;
    let fy = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = ((fx - x0) as f32, (fy - y0) as f32);
    let xa = (x0 as isize).rem_euclid(w as isize) as usize;
    let xb = (xa + 1) % w;
    let ya = y0 as usize;
    let yb = (ya + 1).min(h - 1);
    [
        (ya * w + xa, (1.0 - tx) * (1.0 - ty)),
        (ya * w + xb, tx * (1.0 - ty)),
        (yb * w + xa, (1.0 - tx) * ty),
        (yb * w + xb, tx * ty),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::bv_to_kelvin;

    #[test]
    fn a_star_lands_where_its_direction_points() {
        let sirius = Star {
            hip: 32349,
            ra: 101.2872,
            dec: -16.7161,
            vmag: -1.44,
            bv: Some(0.01),
        };
        let map = StarMap::build(&[sirius], 512, false);
        let dir = galactic_to_world(equatorial_to_galactic(sirius.ra, sirius.dec));
        let at = map.sample(dir, Filter::Nearest);
        assert!(at.luminance > 1.0, "{at:?}");
        assert!((at.kelvin as f64 - bv_to_kelvin(0.01)).abs() < 1e-2);
        // Far away the sky is black.
        assert_eq!(map.sample(-dir, Filter::Bilinear).luminance, 0.0);
    }

    #[test]
    fn overlapping_stars_mix_temperature_by_luminance() {
        let star = |bv| Star {
            hip: 1,
            ra: 10.0,
            dec: 20.0,
            vmag: 3.0,
            bv: Some(bv),
        };
        let map = StarMap::build(&[star(0.0), star(1.0)], 256, false);
        let dir = galactic_to_world(equatorial_to_galactic(10.0, 20.0));
        let at = map.sample(dir, Filter::Nearest);
        let mean = 0.5 * (bv_to_kelvin(0.0) + bv_to_kelvin(1.0));
        assert!(
            (at.kelvin as f64 - mean).abs() < 1.0,
            "{} vs {mean}",
            at.kelvin
        );
    }

    #[test]
    fn footprint_lookups_average_the_grids() {
        // One star: its temperature is the same however wide the
        // footprint (each level's temperature is luminance-weighted), and
        // its light spreads as the footprint grows.
        let star = Star {
            hip: 1,
            ra: 10.0,
            dec: 20.0,
            vmag: 2.0,
            bv: Some(0.3),
        };
        let map = StarMap::build(&[star], 512, true);
        let dir = galactic_to_world(equatorial_to_galactic(10.0, 20.0));
        let a = dir.any_orthonormal_vector();
        let b = dir.cross(a);
        let kelvin = bv_to_kelvin(0.3) as f32;
        let mut previous = f32::INFINITY;
        for size in [1e-4, 0.02, 0.05, 0.2] {
            let s = map.sample_footprint(dir, a * size, b * size);
            assert!((s.kelvin - kelvin).abs() < 1e-2 * kelvin, "{size}: {s:?}");
            assert!(s.luminance > 0.0 && s.luminance < previous, "{size}: {s:?}");
            previous = s.luminance;
            assert!(s.milky_way > 0.0);
        }
        assert_eq!(
            map.sample_filtered(dir, Filter::Footprint, Some((a * 0.01, b * 0.01))),
            map.sample_footprint(dir, a * 0.01, b * 0.01)
        );
        assert_eq!(
            map.sample_filtered(dir, Filter::Footprint, None),
            map.sample(dir, Filter::Bilinear)
        );
        // Magnified, it reads about as bilinear does.
        let s = map.sample_footprint(dir, a * 1e-5, b * 1e-5);
        let bl = map.sample(dir, Filter::Bilinear);
        assert!(
            (s.luminance - bl.luminance).abs() < 0.3 * bl.luminance,
            "{s:?} {bl:?}"
        );
        assert!(map.memory_bytes() > 8 * 512 * 256);
        assert_eq!(
            map.memory_bytes(),
            8 * 512 * 256 + 4 * 128 * 64 + map.pyramid_bytes()
        );
    }

    #[test]
    fn milky_way_is_brightest_towards_the_galactic_centre() {
        let map = StarMap::build(&[], 512, true);
        let centre = map.sample(DVec3::Y, Filter::Nearest).milky_way;
        let pole = map.sample(DVec3::Z, Filter::Nearest).milky_way;
        let anticentre = map.sample(-DVec3::Y, Filter::Nearest).milky_way;
        assert!(
            centre > anticentre && anticentre > pole,
            "{centre} {anticentre} {pole}"
        );
    }
}
