//! How an observed scene's pictures show its brightness temperature, as
//! radio astronomers read such images: in false colour (the Event Horizon
//! Telescope's afmhot by default; inferno, magma, viridis or grey), on a
//! linear or logarithmic scale up to the temperature at white, with a
//! labelled colour bar beside the PNG where the scene asks for one.
//!
//! Each pixel's value is its luminance Y (the film holds T_b /
//! [`DISPLAY_KELVIN`] as Y) times 2^exposure, or on the log scale 1 +
//! log10 of it over `image.decades`, clamped to [0, 1] and looked up in a
//! table of 256 sRGB colours: the nearest entry, in f32, as the GPU's
//! display does it (display.wgsl's `encode_pixel`), so that the viewer
//! shows what the PNG holds.

use crate::canvas::Canvas;
use crate::config::{ColorMapName, SceneConfig, ValueScale};
use glam::Vec3;

/// The brightness temperature (K) an observed scene's picture shows as
/// white before exposure.
pub const DISPLAY_KELVIN: f64 = 1e10;

/// The log scale's default span below white (decades).
pub const DEFAULT_DECADES: f64 = 3.0;

/// An observed picture's look.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadioLook {
    pub map: ColorMapName,
    /// Decades below white that the log scale spans; None: linear.
    pub log: Option<f64>,
    /// `image.exposure` (stops).
    pub exposure: f64,
    /// A colour bar beside the PNG.
    pub bar: bool,
}

impl RadioLook {
    /// The look of an observed scene's pictures (None for others, whose
    /// colour is the light's).
    pub fn of(cfg: &SceneConfig) -> Option<RadioLook> {
        cfg.observe.as_ref()?;
        let img = &cfg.image;
        Some(RadioLook {
            map: img.colormap.unwrap_or(ColorMapName::Afmhot),
            log: match img.scale {
                ValueScale::Linear => None,
                ValueScale::Log => Some(img.decades.unwrap_or(DEFAULT_DECADES)),
            },
            exposure: img.exposure,
            bar: img.colorbar,
        })
    }

    /// The brightness temperature shown as white (K).
    pub fn white_kelvin(&self) -> f64 {
        DISPLAY_KELVIN / self.exposure.exp2()
    }

    /// One line saying how the picture is read, for `info` and the viewer.
    pub fn describe(&self) -> String {
        let scale = match self.log {
            None => "linear from 0".to_string(),
            Some(d) => format!("logarithmic over {d} decades"),
        };
        format!(
            "brightness temperature in {}, {scale}, white at {:.3e} K",
            self.map.name(),
            self.white_kelvin()
        )
    }

    /// The table entry of a pixel of luminance `y` (T_b / DISPLAY_KELVIN).
    #[inline]
    pub fn index(&self, y: f32) -> usize {
        let mut v = y * self.exposure.exp2() as f32;
        if let Some(d) = self.log {
            v = if v > 0.0 {
                1.0 + v.ln() / (d as f32 * std::f32::consts::LN_10)
            } else {
                0.0
            };
        }
        // NaN and negatives to 0.
        let v = if v > 0.0 { v.min(1.0) } else { 0.0 };
        (v * 255.0 + 0.5).floor() as usize
    }

    /// The 256 sRGB colours, black (or the map's dark end) to white (its
    /// bright end).
    pub fn table(&self) -> [[u8; 3]; 256] {
        std::array::from_fn(|i| self.map.colour(i as f64 / 255.0))
    }

    /// The 8-bit sRGB picture of `shown` (XYZ, T_b / DISPLAY_KELVIN as
    /// Y), each pixel on its own, so that the bytes do not depend on the
    /// thread count.
    pub fn encode(&self, shown: &[Vec3]) -> Vec<u8> {
        use rayon::prelude::*;
        let table = self.table();
        let mut out = vec![0u8; 3 * shown.len()];
        out.par_chunks_mut(3 * 8192)
            .zip(shown.par_chunks(8192))
            .for_each(|(bytes, px)| {
                for (b, c) in bytes.chunks_exact_mut(3).zip(px) {
                    b.copy_from_slice(&table[self.index(c.y)]);
                }
            });
        out
    }

    /// The picture `rgb` (`w` x `h`) with its colour bar on the right: the
    /// table from the bright end (top) to the dark one, labelled in K.
    pub fn with_bar(&self, w: usize, h: usize, rgb: &[u8]) -> Canvas {
        let s = crate::compare::label_scale(w.max(2 * h));
        let bar_w = 6 * s + 8;
        let label_w = 8 * s * 8 + 12;
        let mut c = Canvas::new(w + bar_w + label_w, h, [0, 0, 0]);
        c.paste(0, 0, w, h, rgb);
        let table = self.table();
        let (top, bottom) = (20 * s, h.saturating_sub(6 * s).max(20 * s + 2));
        let span = (bottom - top).max(1) as f64;
        for y in top..bottom.min(h) {
            let v = (bottom - y) as f64 / span;
            let colour = table[(v * 255.0).round() as usize];
            for x in w + 8..w + bar_w {
                c.set(x, y, colour);
            }
        }
        let white = [255, 255, 255];
        c.text(w + 8, 4 * s, s, "Tb (K)", [200, 200, 200]);
        let tx = w + bar_w + 4;
        let t_white = self.white_kelvin();
        // Ticks at fractions of the bar: linear at 1, 1/2, 0; log at each
        // decade.
        let ticks: Vec<(f64, f64)> = match self.log {
            None => vec![(1.0, t_white), (0.5, 0.5 * t_white), (0.0, 0.0)],
            Some(d) => {
                let n = d.floor().max(1.0) as usize;
                (0..=n)
                    .map(|k| (1.0 - k as f64 / d, t_white / 10f64.powi(k as i32)))
                    .collect()
            }
        };
        for (at, kelvin) in ticks {
            let y = bottom as f64 - at * span;
            let y = (y as usize)
                .saturating_sub(4 * s)
                .min(h.saturating_sub(8 * s));
            let text = if kelvin == 0.0 {
                "0".to_string()
            } else {
                format!("{kelvin:.1e}")
            };
            c.text(tx, y, s, &text, white);
        }
        c
    }
}

impl ColorMapName {
    /// Its name in the scene file.
    pub fn name(self) -> &'static str {
        match self {
            ColorMapName::Afmhot => "afmhot",
            ColorMapName::Inferno => "inferno",
            ColorMapName::Magma => "magma",
            ColorMapName::Viridis => "viridis",
            ColorMapName::Grey => "grey",
        }
    }

    /// Its sRGB colour at `t` in [0, 1]: matplotlib's afmhot (gnuplot's
    /// 2t, 2t - 1/2, 2t - 1, each clamped) and gray, and the viridis family
    /// (colorous's tables of matplotlib's).
    pub fn colour(self, t: f64) -> [u8; 3] {
        let byte = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let from = |g: colorous::Gradient| {
            let c = g.eval_continuous(t.clamp(0.0, 1.0));
            [c.r, c.g, c.b]
        };
        match self {
            ColorMapName::Afmhot => [byte(2.0 * t), byte(2.0 * t - 0.5), byte(2.0 * t - 1.0)],
            ColorMapName::Grey => [byte(t); 3],
            ColorMapName::Inferno => from(colorous::INFERNO),
            ColorMapName::Magma => from(colorous::MAGMA),
            ColorMapName::Viridis => from(colorous::VIRIDIS),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn look(map: ColorMapName, log: Option<f64>) -> RadioLook {
        RadioLook {
            map,
            log,
            exposure: 0.0,
            bar: false,
        }
    }

    #[test]
    fn afmhot_is_gnuplots_ramps_and_the_ends_are_black_and_white() {
        let t = look(ColorMapName::Afmhot, None).table();
        assert_eq!(t[0], [0, 0, 0]);
        assert_eq!(t[255], [255, 255, 255]);
        // 2t, 2t - 1/2, 2t - 1 at t = 0.5: (1, 0.5, 0).
        assert_eq!(t[128], [255, 129, 1]);
        // matplotlib 3.11's afmhot(0.25): (0.5, 0, 0).
        assert_eq!(ColorMapName::Afmhot.colour(0.25), [128, 0, 0]);
        // Its viridis(0) and (1): #440154 and #fde725.
        assert_eq!(ColorMapName::Viridis.colour(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(ColorMapName::Viridis.colour(1.0), [0xfd, 0xe7, 0x25]);
    }

    #[test]
    fn the_scale_puts_white_at_the_exposed_temperature() {
        // Linear: T_b / (1e10 K / 2^exposure); log: each decade 1/decades.
        let mut l = look(ColorMapName::Grey, None);
        l.exposure = 1.0;
        assert_eq!(l.white_kelvin(), 5e9);
        assert_eq!(l.index(0.5), 255);
        assert_eq!(l.index(0.25), 128);
        assert_eq!(l.index(f32::NAN), 0);
        assert_eq!(l.index(-1.0), 0);
        let g = look(ColorMapName::Grey, Some(3.0));
        assert_eq!(g.index(1.0), 255);
        assert_eq!(g.index(0.1), 170);
        assert_eq!(g.index(1e-3), 0);
        assert_eq!(g.index(1e-5), 0);
    }

    #[test]
    fn the_bar_stands_beside_the_picture() {
        let l = look(ColorMapName::Afmhot, Some(2.0));
        let rgb = vec![7u8; 3 * 64 * 48];
        let c = l.with_bar(64, 48, &rgb);
        assert!(c.width > 64 && c.height == 48);
        assert_eq!(&c.rgb[..3], &[7, 7, 7]);
    }
}
