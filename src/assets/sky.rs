//! The RGB star panorama `sky.png`: the [`StarMap`] of the catalogue,
//! each blackbody at its colour, encoded as 8-bit sRGB.

use super::{BlackbodyTable, dither, quantise};
use crate::config::Filter;
use crate::starmap::{MILKY_WAY_KELVIN, Star, StarMap};
use crate::texture::equirect_dir;
use rayon::prelude::*;

/// Parameters of the panorama.
#[derive(Clone, Debug)]
pub struct SkyParams {
    /// Width (texels); the height is half.
    pub width: u32,
    /// Faint Milky Way band.
    pub milky_way: bool,
}

impl Default for SkyParams {
    fn default() -> Self {
        SkyParams {
            width: 4096,
            milky_way: true,
        }
    }
}

/// Generates the panorama (RGB, 8-bit sRGB).
pub fn generate(stars: &[Star], p: &SkyParams) -> image::RgbImage {
    let map = StarMap::build(stars, p.width, p.milky_way);
    let (w, h) = (p.width as usize, p.width as usize / 2);
    let table = BlackbodyTable::new(1500.0, 40000.0);
    let mw = table.get(MILKY_WAY_KELVIN);
    let mut data = vec![0u8; w * h * 3];
    data.par_chunks_mut(w * 3).enumerate().for_each(|(j, row)| {
        for i in 0..w {
            let d = equirect_dir((i as f64 + 0.5) / w as f64, (j as f64 + 0.5) / h as f64);
            let s = map.sample(d, Filter::Nearest);
            let c = table.get(s.kelvin as f64) * s.luminance + mw * s.milky_way;
            let k = (j * w + i) as u64;
            row[i * 3] = quantise(c.x, dither(k, 0));
            row[i * 3 + 1] = quantise(c.y, dither(k, 1));
            row[i * 3 + 2] = quantise(c.z, dither(k, 2));
        }
    });
    image::RgbImage::from_raw(w as u32, h as u32, data).expect("buffer sized to the image")
}
