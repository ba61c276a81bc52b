//! Re-lensing: any equirectangular panorama seen through a rendered lens
//! map, the EXR channels `obs.sky.x`, `obs.sky.y`, `obs.sky.z` (each
//! pixel's unit escape direction, scene axes, NaN where the ray did not
//! escape) and `obs.magnification` (its signed lensing magnification).
//!
//! Each pixel reads the panorama over its footprint on the sky (the
//! elliptical filter of [`crate::texture::ewa`]), the footprint from the
//! neighbouring pixels' directions: central differences where both
//! neighbours along an axis are usable, else the one usable side, and
//! never a neighbour across a discontinuity of the map:
//! - a neighbour whose ray did not escape (NaN),
//! - a neighbour whose magnification has the other sign (another image of
//!   the sky: the critical curve lies between),
//! - the larger of two steps when it is more than [`STEP_RATIO`] times the
//!   smaller (a jump between images or across a disk's edge; a smooth
//!   map's step changes little from one pixel to the next).
//!
//! Where neither neighbour along an axis is usable, the footprint is
//! isotropic with the other axis's size; where neither axis has one, a
//! point (the filter's one-texel reconstruction).

use crate::texture::Texture;
use anyhow::{Context, Result, anyhow, bail};
use glam::{DVec3, Vec4};
use rayon::prelude::*;
use std::path::Path;

/// The largest ratio of the steps to a pixel's two neighbours along an
/// axis that still counts as one smooth map (see the module docs).
pub const STEP_RATIO: f64 = 4.0;

/// The EXR channels of a lens map.
pub const SKY_CHANNELS: [&str; 3] = ["obs.sky.x", "obs.sky.y", "obs.sky.z"];

/// The EXR channel of the signed magnification.
pub const MAGNIFICATION_CHANNEL: &str = "obs.magnification";

/// A rendered lens map.
#[derive(Clone, Debug)]
pub struct LensMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Each pixel's unit escape direction (scene axes), row 0 at the top;
    /// NaN where the ray did not escape.
    pub sky: Vec<DVec3>,
    /// Each pixel's signed magnification, where the map has it.
    pub magnification: Option<Vec<f32>>,
}

/// The four bytes every OpenEXR file starts with.
const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

impl LensMap {
    /// Reads the lens map of a rendered EXR, refusing (by name) a file
    /// that is not an EXR or lacks the `obs.sky` channels;
    /// `obs.magnification` is read where present.
    pub fn read_exr(path: &Path) -> Result<LensMap> {
        use exr::prelude::*;
        let mut head = [0u8; 4];
        {
            use std::io::Read;
            let mut f = std::fs::File::open(path)
                .with_context(|| format!("cannot read lens map {}", path.display()))?;
            if f.read_exact(&mut head).is_err() || head != EXR_MAGIC {
                bail!(
                    "{}: not an OpenEXR file; relens reads the EXR of a render whose image.observables include \"sky\"",
                    path.display()
                );
            }
        }
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
            .map_err(|e| anyhow!("{}: cannot read the EXR: {e}", path.display()))?;
        // Channels by full name: a named layer's channels as `layer.name`.
        let mut found: std::collections::HashMap<String, (Vec<f32>, (usize, usize))> =
            Default::default();
        for layer in &image.layer_data {
            let prefix = layer
                .attributes
                .layer_name
                .as_ref()
                .map(|n| format!("{n}."))
                .unwrap_or_default();
            for ch in &layer.channel_data.list {
                let name = format!("{prefix}{}", ch.name);
                // Directions and magnifications are floats: an integer
                // channel is some other file's.
                let wanted = SKY_CHANNELS.contains(&name.as_str()) || name == MAGNIFICATION_CHANNEL;
                if wanted && matches!(ch.sample_data, FlatSamples::U32(_)) {
                    bail!(
                        "{}: channel {name} holds unsigned integers; a lens map's directions and magnification are floats (as render writes them)",
                        path.display()
                    );
                }
                let values: Vec<f32> = ch.sample_data.values_as_f32().collect();
                found.insert(name, (values, (layer.size.0, layer.size.1)));
            }
        }
        let mut take = |name: &str| found.remove(name);
        let mut planes = Vec::new();
        for name in SKY_CHANNELS {
            planes.push(take(name).ok_or_else(|| {
                anyhow!(
                    "{}: has no channel {name}: relens needs the lens map obs.sky.x, obs.sky.y, obs.sky.z (render with image.observables including \"sky\" and an EXR)",
                    path.display()
                )
            })?);
        }
        let size = planes[0].1;
        let magnification = take(MAGNIFICATION_CHANNEL);
        if planes.iter().chain(&magnification).any(|p| p.1 != size) {
            bail!(
                "{}: the obs.sky and obs.magnification channels differ in size",
                path.display()
            );
        }
        let (w, h) = size;
        if w == 0 || h == 0 {
            bail!("{}: the image is empty", path.display());
        }
        let sky = (0..w * h)
            .map(|i| {
                let d = DVec3::new(
                    planes[0].0[i] as f64,
                    planes[1].0[i] as f64,
                    planes[2].0[i] as f64,
                );
                // Unit length in f64 (the channels are f32).
                if d.is_finite() && d.length_squared() > 0.0 {
                    d.normalize()
                } else {
                    DVec3::NAN
                }
            })
            .collect();
        Ok(LensMap {
            width: w as u32,
            height: h as u32,
            sky,
            magnification: magnification.map(|m| m.0),
        })
    }

    /// Whether pixel `n` may serve pixel `p`'s footprint: its ray escaped
    /// and its magnification has p's sign (where both are known).
    fn usable(&self, p: usize, n: usize) -> bool {
        if !self.sky[n].is_finite() {
            return false;
        }
        match &self.magnification {
            Some(m) => {
                let (a, b) = (m[p], m[n]);
                !(a.is_finite() && b.is_finite() && (a > 0.0) != (b > 0.0))
            }
            None => true,
        }
    }

    /// The derivative of pixel `p`'s direction along one axis, from its
    /// neighbours `minus` and `plus` (None past the image's edge).
    fn derivative(&self, p: usize, minus: Option<usize>, plus: Option<usize>) -> Option<DVec3> {
        let d = self.sky[p];
        let m = minus
            .filter(|&n| self.usable(p, n))
            .map(|n| d - self.sky[n]);
        let q = plus.filter(|&n| self.usable(p, n)).map(|n| self.sky[n] - d);
        match (m, q) {
            (Some(m), Some(q)) => {
                let (sm, sq) = (m.length(), q.length());
                if sm > STEP_RATIO * sq {
                    Some(q)
                } else if sq > STEP_RATIO * sm {
                    Some(m)
                } else {
                    Some(0.5 * (m + q))
                }
            }
            (one, other) => one.or(other),
        }
    }

    /// Pixel (x, y)'s escape direction and its derivatives per pixel step
    /// across and down (see the module docs); None where it did not escape.
    pub fn footprint(&self, x: u32, y: u32) -> Option<(DVec3, DVec3, DVec3)> {
        let (w, h) = (self.width as usize, self.height as usize);
        let (x, y) = (x as usize, y as usize);
        let p = y * w + x;
        let d = self.sky[p];
        if !d.is_finite() {
            return None;
        }
        let tangent = |v: DVec3| v - d * v.dot(d);
        let ddx = self
            .derivative(p, (x > 0).then(|| p - 1), (x + 1 < w).then(|| p + 1))
            .map(tangent);
        let ddy = self
            .derivative(p, (y > 0).then(|| p - w), (y + 1 < h).then(|| p + w))
            .map(tangent);
        // Isotropic with the other axis's size: turned a quarter about d.
        let turn = |v: DVec3| d.cross(v);
        let (ddx, ddy) = match (ddx, ddy) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, turn(a)),
            (None, Some(b)) => (turn(b), b),
            (None, None) => (DVec3::ZERO, DVec3::ZERO),
        };
        Some((d, ddx, ddy))
    }
}

/// The panorama seen through the lens map: each pixel's premultiplied
/// linear RGBA over its footprint on the sky (0 where the ray did not
/// escape), row by row.
pub fn relens(map: &LensMap, panorama: &Texture) -> Vec<Vec4> {
    let w = map.width;
    (0..map.width as usize * map.height as usize)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            match map.footprint(x, y) {
                Some((d, ddx, ddy)) => panorama.sample_sky_footprint(d, ddx, ddy),
                None => Vec4::ZERO,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A w x h map of directions `f(x, y)`, magnification `m(x, y)`.
    fn map(w: u32, h: u32, f: impl Fn(u32, u32) -> DVec3, m: impl Fn(u32, u32) -> f32) -> LensMap {
        let (mut sky, mut mag) = (Vec::new(), Vec::new());
        for y in 0..h {
            for x in 0..w {
                sky.push(f(x, y));
                mag.push(m(x, y));
            }
        }
        LensMap {
            width: w,
            height: h,
            sky,
            magnification: Some(mag),
        }
    }

    /// Directions one milliradian apart across and 2 down, about +y.
    fn smooth(x: u32, y: u32) -> DVec3 {
        DVec3::new(1e-3 * x as f64, 1.0, -2e-3 * y as f64).normalize()
    }

    #[test]
    fn central_differences_inside_one_sided_at_edges() {
        let m = map(5, 4, smooth, |_, _| 1.0);
        let (d, ddx, ddy) = m.footprint(2, 1).unwrap();
        let cx = 0.5 * (smooth(3, 1) - smooth(1, 1));
        assert!((ddx - (cx - d * cx.dot(d))).length() < 1e-15);
        assert!((ddy.length() - 2e-3).abs() < 1e-5);
        // Left edge: the step to the right.
        let (d, ddx, _) = m.footprint(0, 1).unwrap();
        let r = smooth(1, 1) - smooth(0, 1);
        assert!((ddx - (r - d * r.dot(d))).length() < 1e-15);
    }

    #[test]
    fn footprints_never_reach_across_a_discontinuity() {
        // Columns 0-2 see one image, columns 3-5 another (a jump of 0.5
        // rad, magnification negative); column 6 did not escape.
        let f = |x: u32, y: u32| match x {
            0..=2 => smooth(x, y),
            3..=5 => DVec3::new(0.5 + 1e-3 * x as f64, 1.0, -2e-3 * y as f64).normalize(),
            _ => DVec3::NAN,
        };
        let sign = |x: u32, _| if x >= 3 { -2.0 } else { 1.0 };
        let m = map(7, 3, f, sign);
        let step = |a: DVec3, b: DVec3, d: DVec3| {
            let s = b - a;
            s - d * s.dot(d)
        };
        // Column 2: its right neighbour changes sign; the left step only.
        let (d, ddx, _) = m.footprint(2, 1).unwrap();
        assert!((ddx - step(f(1, 1), f(2, 1), d)).length() < 1e-15);
        // Column 3: the left neighbour changes sign; the right step only.
        let (d, ddx, _) = m.footprint(3, 1).unwrap();
        assert!((ddx - step(f(3, 1), f(4, 1), d)).length() < 1e-15);
        // Column 5: the right neighbour is NaN.
        let (d, ddx, _) = m.footprint(5, 1).unwrap();
        assert!((ddx - step(f(4, 1), f(5, 1), d)).length() < 1e-15);
        assert!(m.footprint(6, 1).is_none());
        // Without the magnification, the step ratio alone finds the jump.
        let m = LensMap {
            magnification: None,
            ..m
        };
        let (d, ddx, _) = m.footprint(2, 1).unwrap();
        assert!((ddx - step(f(1, 1), f(2, 1), d)).length() < 1e-15);
        let (d, ddx, _) = m.footprint(3, 1).unwrap();
        assert!((ddx - step(f(3, 1), f(4, 1), d)).length() < 1e-15);
    }

    #[test]
    fn an_isolated_row_takes_the_other_axis_size() {
        // One row between NaN rows: dy from dx, turned, of its length.
        let f = |x: u32, y: u32| if y == 1 { smooth(x, 0) } else { DVec3::NAN };
        let m = map(4, 3, f, |_, _| 1.0);
        let (d, ddx, ddy) = m.footprint(1, 1).unwrap();
        assert!((ddy.length() - ddx.length()).abs() < 1e-15);
        assert!(ddy.dot(ddx).abs() < 1e-15 && ddy.dot(d).abs() < 1e-15);
        // A lone pixel: a point.
        let f = |x: u32, y: u32| {
            if (x, y) == (1, 1) {
                smooth(0, 0)
            } else {
                DVec3::NAN
            }
        };
        let m = map(3, 3, f, |_, _| 1.0);
        let (_, ddx, ddy) = m.footprint(1, 1).unwrap();
        assert_eq!((ddx, ddy), (DVec3::ZERO, DVec3::ZERO));
    }
}
