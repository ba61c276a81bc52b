//! The star panorama from a real catalogue.
//!
//! Stars come from `spectral_assets/stars/hipparcos_mag8.csv` (an extract of
//! the Hipparcos-based catalogue shipped with d3-celestial). The panorama is
//! in galactic coordinates: the galactic centre (l = 0, b = 0) lies along +y,
//! l = 90 deg along -x (so the sky is seen unmirrored from inside), the north
//! galactic pole along +z; the Milky Way's plane is the panorama's equator.
//! Each star is a Gaussian spot in angle on the sphere (not in pixels, so it
//! stays round near the poles), coloured by its blackbody temperature from
//! B-V and scaled by its magnitude.

use super::{BlackbodyTable, dither, quantise};
use crate::spectrum::bv_to_kelvin;
use crate::texture::{equirect_dir, equirect_uv};
use glam::{DVec3, Vec3};
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;

/// B-V used for the few catalogue stars without one (roughly solar).
pub const DEFAULT_BV: f64 = 0.65;

/// One catalogue star.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Star {
    /// Hipparcos number.
    pub hip: u32,
    /// Right ascension (degrees, J2000).
    pub ra: f64,
    /// Declination (degrees, J2000).
    pub dec: f64,
    /// Visual magnitude.
    pub vmag: f64,
    /// B-V colour index, if known.
    pub bv: Option<f64>,
}

/// Parses the catalogue CSV (`hip,ra_deg,dec_deg,vmag,bv`).
pub fn parse_catalogue(csv: &str) -> Result<Vec<Star>, String> {
    let mut lines = csv.lines();
    let header = lines.next().ok_or("empty catalogue")?;
    if header.trim() != "hip,ra_deg,dec_deg,vmag,bv" {
        return Err(format!(
            "unexpected header {header:?}, expected hip,ra_deg,dec_deg,vmag,bv"
        ));
    }
    lines
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let f: Vec<&str> = l.split(',').collect();
            let bad = || {
                format!(
                    "line {}: expected 5 fields hip,ra,dec,vmag,bv: {l:?}",
                    i + 2
                )
            };
            if f.len() != 5 {
                return Err(bad());
            }
            let num = |s: &str| s.trim().parse::<f64>().map_err(|_| bad());
            Ok(Star {
                hip: f[0].trim().parse().map_err(|_| bad())?,
                ra: num(f[1])?,
                dec: num(f[2])?,
                vmag: num(f[3])?,
                bv: if f[4].trim().is_empty() {
                    None
                } else {
                    Some(num(f[4])?)
                },
            })
        })
        .collect()
}

/// Equatorial (J2000) unit vector -> galactic unit vector (x to the
/// galactic centre, y to l = 90 deg, z to the north galactic pole).
pub fn equatorial_to_galactic(ra_deg: f64, dec_deg: f64) -> DVec3 {
    let (ra, dec) = (ra_deg.to_radians(), dec_deg.to_radians());
    let e = DVec3::new(dec.cos() * ra.cos(), dec.cos() * ra.sin(), dec.sin());
    DVec3::new(
        -0.054_875_560_4 * e.x - 0.873_437_090_2 * e.y - 0.483_835_015_5 * e.z,
        0.494_109_427_9 * e.x - 0.444_829_630_0 * e.y + 0.746_982_244_5 * e.z,
        -0.867_666_149_0 * e.x - 0.198_076_373_4 * e.y + 0.455_983_776_2 * e.z,
    )
}

/// Galactic unit vector -> scene direction (see the module docs).
pub fn galactic_to_world(g: DVec3) -> DVec3 {
    DVec3::new(-g.y, g.x, g.z)
}

/// Parameters of the panorama.
#[derive(Clone, Debug)]
pub struct SkyParams {
    /// Width (texels); the height is half.
    pub width: u32,
    /// Faint Milky Way band.
    pub milky_way: bool,
    /// Noise seed for the Milky Way.
    pub seed: u32,
}

impl Default for SkyParams {
    fn default() -> Self {
        SkyParams {
            width: 4096,
            milky_way: true,
            seed: 11,
        }
    }
}

/// Angular Gaussian width (texel heights) and peak linear brightness of a
/// star of visual magnitude `m`: faint stars are sharp and dim, bright ones
/// saturate and grow, as on a photograph.
fn star_spot(m: f64) -> (f64, f32) {
    let sigma = 0.6 + 0.3 * (5.0 - m).max(0.0);
    let peak = 0.05 * 10f64.powf(0.3 * (8.0 - m));
    (sigma, peak as f32)
}

fn milky_way(dir: DVec3, dust: &Fbm<Perlin>, clouds: &Fbm<Perlin>) -> f32 {
    // Galactic latitude b and longitude l of the scene direction.
    let g = DVec3::new(dir.y, -dir.x, dir.z);
    let b = g.z.clamp(-1.0, 1.0).asin().to_degrees();
    let l = g.y.atan2(g.x).to_degrees();
    // Brighter towards the centre than the anticentre.
    let band =
        (-0.5 * (b / 6.0).powi(2)).exp() * (0.35 + 0.65 * (0.5 * l.to_radians()).cos().powi(2));
    let bulge = 1.6 * (-0.5 * ((l / 20.0).powi(2) + (b / 9.0).powi(2))).exp();
    let structure = 0.55 + 0.45 * clouds.get((dir * 5.0).to_array());
    // Dark lanes hug the plane (the Great Rift).
    let lane = (-0.5 * (b / 2.5).powi(2)).exp()
        * (0.5 + 0.5 * dust.get((dir * 9.0).to_array())).clamp(0.0, 1.0);
    ((band + bulge) * structure * (1.0 - 0.85 * lane)).max(0.0) as f32 * 0.018
}

/// Generates the panorama (RGB, 8-bit sRGB).
pub fn generate(stars: &[Star], p: &SkyParams) -> image::RgbImage {
    let (w, h) = (p.width as usize, p.width as usize / 2);
    let texel = std::f64::consts::PI / h as f64;
    let mut linear = vec![Vec3::ZERO; w * h];
    if p.milky_way {
        let dust = Fbm::<Perlin>::new(p.seed).set_octaves(6);
        let clouds = Fbm::<Perlin>::new(p.seed + 1).set_octaves(6);
        let warm = super::blackbody_rgb(4800.0);
        linear.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            for (i, px) in row.iter_mut().enumerate() {
                let d = equirect_dir((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                *px = warm * milky_way(d, &dust, &clouds);
            }
        });
    }
    let table = BlackbodyTable::new(1500.0, 40000.0);
    for s in stars {
        let dir = galactic_to_world(equatorial_to_galactic(s.ra, s.dec));
        let kelvin = bv_to_kelvin(s.bv.unwrap_or(DEFAULT_BV).clamp(-0.4, 2.0));
        let color = table.get(kelvin);
        let (sigma_px, peak) = star_spot(s.vmag);
        let sigma = sigma_px * texel;
        let reach = 3.5 * sigma;
        let (u, v) = equirect_uv(dir);
        let (ci, cj) = (u * w as f64, v * h as f64);
        let rows = (reach / texel).ceil() as isize + 1;
        let cos_lat = (1.0 - dir.z * dir.z).max(0.0).sqrt();
        // Near a pole one texel spans little angle: widen the column range,
        // up to the whole row.
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
            for di in -cols..=cols {
                let i = (ci.floor() as isize + di).rem_euclid(w as isize) as usize;
                let d = equirect_dir((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
                // Angle between directions, stable for small angles.
                let ang = 2.0 * ((d - dir).length() * 0.5).asin();
                if ang > reach {
                    continue;
                }
                let wgt = (-0.5 * (ang / sigma).powi(2)).exp() as f32;
                linear[j as usize * w + i] += color * (peak * wgt);
            }
        }
    }
    let mut data = vec![0u8; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(j, row)| {
        for i in 0..w {
            let k = (j * w + i) as u64;
            let c = linear[k as usize];
            row[i * 3] = quantise(c.x, dither(k, 0));
            row[i * 3 + 1] = quantise(c.y, dither(k, 1));
            row[i * 3 + 2] = quantise(c.z, dither(k, 2));
        }
    });
    image::RgbImage::from_raw(w as u32, h as u32, data).expect("buffer sized to the image")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn galactic_centre_and_pole() {
        // Sgr A*: RA 266.405, Dec -28.936 -> l = 0, b = 0.
        let g = equatorial_to_galactic(266.405, -28.936);
        assert!((g - DVec3::X).length() < 2e-3, "{g}");
        // North galactic pole: RA 192.859, Dec 27.128.
        let g = equatorial_to_galactic(192.859, 27.128);
        assert!((g - DVec3::Z).length() < 2e-3, "{g}");
        assert_eq!(galactic_to_world(DVec3::X), DVec3::Y);
    }

    #[test]
    fn catalogue_parses_and_rejects_garbage() {
        let s = parse_catalogue(
            "hip,ra_deg,dec_deg,vmag,bv\n32349,101.2872,-16.7161,-1.44,0.01\n1,2,3,4,\n",
        )
        .unwrap();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].bv, Some(0.01));
        assert_eq!(s[1].bv, None);
        assert!(parse_catalogue("hip,ra\n").is_err());
        assert!(parse_catalogue("hip,ra_deg,dec_deg,vmag,bv\n1,2,x,4,5\n").is_err());
    }

    #[test]
    fn a_star_lands_where_its_direction_points() {
        let sirius = Star {
            hip: 32349,
            ra: 101.2872,
            dec: -16.7161,
            vmag: -1.44,
            bv: Some(0.01),
        };
        let p = SkyParams {
            width: 512,
            milky_way: false,
            seed: 0,
        };
        let img = generate(&[sirius], &p);
        let (u, v) = equirect_uv(galactic_to_world(equatorial_to_galactic(
            sirius.ra, sirius.dec,
        )));
        let px = img.get_pixel((u * 512.0) as u32, (v * 256.0) as u32);
        assert!(px.0.iter().all(|&c| c > 200), "{px:?}");
        // Far away the sky is black.
        let far = img.get_pixel(((u * 512.0) as u32 + 256) % 512, 128);
        assert_eq!(far.0, [0, 0, 0]);
    }
}
