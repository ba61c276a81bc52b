//! Shift on/off comparison: the per-pixel CIEDE2000 difference of the two
//! displayed images, a colour-coded map of it, and labelled side-by-side
//! composites.

use crate::spectrum::color::linear_srgb_to_xyz;
use glam::Vec3;
use palette::color_difference::Ciede2000;
use palette::white_point::D65;
use palette::{FromColor, Lab, Xyz};

pub use crate::canvas::Canvas;

/// CIEDE2000 difference of two linear sRGB colours in [0, 1] (as
/// displayed, after tone mapping), through CIE Lab relative to D65.
pub fn delta_e(a: Vec3, b: Vec3) -> f64 {
    let lab = |c: Vec3| {
        let xyz = linear_srgb_to_xyz(c.as_dvec3());
        Lab::<D65, f64>::from_color(Xyz::<D65, f64>::new(xyz.x, xyz.y, xyz.z))
    };
    lab(a).difference(lab(b))
}

/// Summary statistics of a difference map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeltaEStats {
    /// Mean over all pixels.
    pub mean: f64,
    /// 95th percentile.
    pub p95: f64,
    /// Largest.
    pub max: f64,
    /// Fraction of pixels above 2.3 (about one just-noticeable difference).
    pub noticeable: f64,
}

/// Statistics of per-pixel differences.
pub fn stats(de: &[f64]) -> DeltaEStats {
    let mut sorted = de.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len().max(1) as f64;
    DeltaEStats {
        mean: sorted.iter().sum::<f64>() / n,
        p95: sorted
            .get(((0.95 * n) as usize).min(sorted.len().saturating_sub(1)))
            .copied()
            .unwrap_or(0.0),
        max: sorted.last().copied().unwrap_or(0.0),
        noticeable: sorted.iter().filter(|&&d| d > 2.3).count() as f64 / n,
    }
}

/// Label height in pixels for an image of this width.
pub(crate) fn label_scale(width: usize) -> usize {
    (width / 320).clamp(1, 4)
}

/// Two images side by side under a black band carrying their labels.
pub fn side_by_side(w: usize, h: usize, left: &[u8], right: &[u8], labels: [&str; 2]) -> Canvas {
    let s = label_scale(w);
    let band = 8 * s + 8 * s / 2 + 4;
    let gap = 4 * s;
    let mut c = Canvas::new(2 * w + gap, h + band, [0, 0, 0]);
    c.paste(0, band, w, h, left);
    c.paste(w + gap, band, w, h, right);
    c.text(4 * s, 4 * s, s, labels[0], [255, 255, 255]);
    c.text(w + gap + 4 * s, 4 * s, s, labels[1], [255, 255, 255]);
    c
}

/// A colour-coded difference map (viridis from 0 to `top`) with a labelled
/// colour bar on the right.
pub fn delta_e_map(w: usize, h: usize, de: &[f64], top: f64) -> Canvas {
    let s = label_scale(w);
    let bar_w = 6 * s + 8;
    let margin = 8 * s * 6 + 16;
    let mut c = Canvas::new(w + bar_w + margin, h, [0, 0, 0]);
    let colour = |v: f64| {
        let k = colorous::VIRIDIS.eval_continuous((v / top).clamp(0.0, 1.0));
        [k.r, k.g, k.b]
    };
    for y in 0..h {
        for x in 0..w {
            c.set(x, y, colour(de[y * w + x]));
        }
    }
    let (bar_top, bar_bottom) = (24 * s, h.saturating_sub(8 * s));
    for y in bar_top..bar_bottom {
        let v = top * (bar_bottom - y) as f64 / (bar_bottom - bar_top).max(1) as f64;
        for x in w + 8..w + bar_w {
            c.set(x, y, colour(v));
        }
    }
    let tx = w + bar_w + 4;
    c.text(tx, bar_top, s, &format!("{top:.1}"), [255, 255, 255]);
    c.text(
        tx,
        (bar_top + bar_bottom) / 2 - 4 * s,
        s,
        &format!("{:.1}", top / 2.0),
        [255, 255, 255],
    );
    c.text(tx, bar_bottom - 8 * s, s, "0", [255, 255, 255]);
    c.text(w + 8, 4 * s, s, "dE00", [200, 200, 200]);
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ciede2000_matches_sharma_wu_dalal() {
        // Pairs 1, 2 and 17 of Sharma, Wu & Dalal (2005), given in Lab.
        let lab = |l, a, b| Lab::<D65, f64>::new(l, a, b);
        for (p, q, want) in [
            (
                lab(50.0, 2.6772, -79.7751),
                lab(50.0, 0.0, -82.7485),
                2.0425,
            ),
            (
                lab(50.0, 3.1571, -77.2803),
                lab(50.0, 0.0, -82.7485),
                2.8615,
            ),
            (lab(50.0, 2.5, 0.0), lab(73.0, 25.0, -18.0), 27.1492),
        ] {
            assert!((p.difference(q) - want).abs() < 1e-4);
        }
    }

    #[test]
    fn delta_e_of_identical_colours_is_zero_and_grows() {
        let a = Vec3::new(0.2, 0.4, 0.6);
        assert!(delta_e(a, a) < 1e-9);
        assert!(delta_e(a, a * 1.1) > 0.5);
        // White against black: L* 100 apart.
        assert!((delta_e(Vec3::ONE, Vec3::ZERO) - 100.0).abs() < 0.1);
    }

    #[test]
    fn statistics() {
        let s = stats(&[0.0, 1.0, 2.0, 3.0, 10.0]);
        assert_eq!(s.max, 10.0);
        assert!((s.mean - 3.2).abs() < 1e-12);
        assert!((s.noticeable - 0.4).abs() < 1e-12);
    }

    #[test]
    fn text_draws_inside_the_canvas() {
        let mut c = Canvas::new(40, 10, [0; 3]);
        c.text(0, 0, 1, "dE", [255; 3]);
        assert!(c.rgb.contains(&255));
        c.text(38, 8, 2, "clipped", [255; 3]);
    }
}
