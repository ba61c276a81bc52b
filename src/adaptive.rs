//! Adaptive sampling's per-pixel state and policy (`image.adaptive`;
//! src/cpu/adaptive.rs tells the whole method): each pixel's sample
//! classes and lightness sums, where a round refines and how much. Neutral
//! ground for both backends: the CPU's rows and rounds (src/cpu/) and
//! the GPU's (src/gpu/refine.rs) decide alike.

use crate::film::SampleClass;
use rayon::prelude::*;

/// Most rounds of refinement: how far a thin feature is followed from
/// where the base pass saw an edge, and (plus one) the rows a band of rows
/// needs around it.
pub const MAX_ROUNDS: usize = 8;

/// Rows sampled above and below a band of rows (see the module's notes).
pub const MARGIN: u32 = MAX_ROUNDS as u32 + 1;

/// Extra samples of a pixel's first round (a 2 x 2 grid).
const FIRST: u32 = 4;

/// Lightness difference (CIE L* units) between neighbours that makes both
/// refine: about two just-noticeable differences (Delta E 2.3 each).
/// Chosen by measurement on `quick.toml` (see REFERENCE.md): 10 refines a
/// quarter fewer pixels for a mean error an eighth larger.
pub const CONTRAST: f64 = 5.0;

/// Standard error of a pixel's mean lightness (L* units) at which its
/// refinement stops: about one just-noticeable difference.
pub const TOLERANCE: f64 = 2.0;

/// Extra samples a pixel takes before it may stop while a neighbour holds
/// a class that none of its own samples has: 16 points of its stratified
/// sequence miss an edge only where it covers about 1/32 of the pixel or
/// less, where 4 miss one covering up to about 1/8.
pub const UNSEEN: u32 = 16;

/// A pixel's samples as adaptive sampling sees them.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pixel {
    /// Sum and sum of squares of its finite samples' lightness.
    v_sum: f64,
    v_sq: f64,
    /// Its finite samples.
    n_v: u32,
    /// The classes ([`class_bit`]) its samples ended in.
    mask: u64,
    /// The classes of the base samples of its 3x3 neighbourhood.
    near: u64,
    /// Samples taken beyond the base pass.
    pub extra: u32,
}

impl Pixel {
    /// Adds a sample of class bit `bit` and lightness `v` (None when its
    /// light is not finite).
    #[inline]
    pub fn add(&mut self, bit: u64, v: Option<f64>) {
        self.mask |= bit;
        if let Some(v) = v {
            self.v_sum += v;
            self.v_sq += v * v;
            self.n_v += 1;
        }
    }

    /// Adds samples as sums: `n_v` finite ones of lightness sum `v_sum`
    /// and sum of squares `v_sq`, of the classes `mask` (the GPU's sums
    /// of a pass over the pixel's samples).
    pub fn add_sums(&mut self, v_sum: f64, v_sq: f64, n_v: u32, mask: u64) {
        self.mask |= mask;
        self.v_sum += v_sum;
        self.v_sq += v_sq;
        self.n_v += n_v;
    }

    /// Mean lightness (NaN without a finite sample).
    fn mean(&self) -> f64 {
        self.v_sum / self.n_v as f64
    }

    /// The standard error of the mean lightness is within [`TOLERANCE`].
    fn converged(&self) -> bool {
        if self.n_v < 2 {
            return false;
        }
        let n = self.n_v as f64;
        let var = ((self.v_sq - self.v_sum * self.v_sum / n) / (n - 1.0)).max(0.0);
        var / n <= TOLERANCE * TOLERANCE
    }

    /// Classes its refinement found that no base sample around it had.
    fn discovered(&self) -> u64 {
        self.mask & !self.near
    }
}

/// The class of a sample as adaptive sampling tells classes apart: the
/// disk by image order (0 to 11, higher orders together) and objects by
/// index (modulo 48).
pub fn class_bit(class: SampleClass, order: f64, object: Option<u32>) -> u64 {
    let bit = match class {
        SampleClass::Sky => 0,
        SampleClass::Captured => 1,
        SampleClass::Abandoned => 2,
        SampleClass::NonFinite => 3,
        SampleClass::Disk => {
            4 + if order.is_finite() {
                order.clamp(0.0, 11.0) as u32
            } else {
                0
            }
        }
        SampleClass::Objects => 16 + object.unwrap_or(0) % 48,
    };
    1 << bit
}

/// Lightness of luminance `y` shown with white at `white`: CIE L* up to
/// white, and beyond it 100 + (116 / 3) ln(y / white), which continues L*
/// smoothly (about 27 units a stop) so that edges in light brighter than
/// white count too.
pub fn lightness(y: f64, white: f64) -> f64 {
    let t = (y / white).max(0.0);
    if t > 1.0 {
        100.0 + 116.0 / 3.0 * t.ln()
    } else {
        116.0 * crate::spectrum::color::lab_f(t) - 16.0
    }
}

/// The extra samples after `extra`, at most `room`.
fn next(extra: u32, room: u32) -> u32 {
    if extra == 0 {
        FIRST.min(room)
    } else {
        (2 * extra).min(room)
    }
}

/// Pixel `x`'s extra samples after round `round`'s decision, from its row
/// (`rows[1]`) and the rows above and below (None outside the band).
fn decide(round: usize, rows: [Option<&[Pixel]>; 3], x: usize, room: u32, contrast: f64) -> u32 {
    let row = rows[1].expect("the pixel's own row");
    let p = row[x];
    if p.extra >= room {
        return p.extra;
    }
    let lo = x.saturating_sub(1);
    let hi = (x + 1).min(row.len() - 1);
    let neighbours = || {
        rows.iter().enumerate().flat_map(move |(r, pixels)| {
            pixels
                .iter()
                .flat_map(move |px| (lo..=hi).filter(move |&i| r != 1 || i != x).map(|i| px[i]))
        })
    };
    let edge = round == 0
        && (p.mask.count_ones() > 1
            || neighbours().any(|q| q.mask != p.mask || (q.mean() - p.mean()).abs() > contrast));
    let unseen = || neighbours().any(|q| q.mask & !p.mask != 0);
    let unsettled = p.extra > 0 && (!p.converged() || (p.extra < UNSEEN && unseen()));
    let follows = neighbours().any(|q| q.discovered() & !p.mask != 0);
    if edge || unsettled || follows {
        next(p.extra, room)
    } else {
        p.extra
    }
}

/// Sets each pixel's classes of the base samples of its 3x3 neighbourhood
/// (after the base pass, before the first round).
pub fn set_near<R: AsRef<[Pixel]> + AsMut<[Pixel]> + Sync>(rows: &mut [R]) {
    let n = rows.len();
    let near: Vec<Vec<u64>> = (0..n)
        .into_par_iter()
        .map(|r| {
            let w = rows[r].as_ref().len();
            (0..w)
                .map(|x| {
                    let (lo, hi) = (x.saturating_sub(1), (x + 1).min(w - 1));
                    rows[r.saturating_sub(1)..(r + 2).min(n)]
                        .iter()
                        .flat_map(|row| row.as_ref()[lo..=hi].iter().map(|p| p.mask))
                        .fold(0, |a, b| a | b)
                })
                .collect()
        })
        .collect();
    for (row, near) in rows.iter_mut().zip(near) {
        for (p, n) in row.as_mut().iter_mut().zip(near) {
            p.near = n;
        }
    }
}

/// Each pixel's extra samples after round `round`'s decision (at most
/// `room`; neighbours' lightness differing by `contrast` refine them),
/// row by row; None where no pixel takes more. Both backends decide with
/// it, so they refine the same pixels from the same states.
pub fn round_targets<R: AsRef<[Pixel]> + Sync>(
    round: usize,
    rows: &[R],
    room: u32,
    contrast: f64,
) -> Option<Vec<Vec<u32>>> {
    let targets: Vec<Vec<u32>> = (0..rows.len())
        .into_par_iter()
        .map(|r| {
            let at = |k: Option<usize>| k.and_then(|k| rows.get(k)).map(|row| row.as_ref());
            let around = [at(r.checked_sub(1)), at(Some(r)), at(Some(r + 1))];
            let w = rows[r].as_ref().len();
            (0..w)
                .map(|x| decide(round, around, x, room, contrast))
                .collect()
        })
        .collect();
    let more = rows
        .iter()
        .zip(&targets)
        .any(|(row, t)| row.as_ref().iter().zip(t).any(|(p, &t)| t > p.extra));
    more.then_some(targets)
}

/// The pixels of `px` refined and their extra samples, for the counts.
pub fn refined(px: &[Pixel]) -> (u64, u64) {
    let n = px.iter().filter(|p| p.extra > 0).count() as u64;
    (n, px.iter().map(|p| p.extra as u64).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lightness_is_cie_lstar_up_to_white_and_smooth_beyond() {
        assert!((lightness(1.0, 1.0) - 100.0).abs() < 1e-12);
        assert!((lightness(0.18, 1.0) - 49.496).abs() < 1e-2);
        assert!((lightness(0.5, 0.5) - 100.0).abs() < 1e-12);
        assert_eq!(lightness(0.0, 1.0), 0.0);
        // The slope matches on both sides of white.
        let e = 1e-6;
        let below = (lightness(1.0, 1.0) - lightness(1.0 - e, 1.0)) / e;
        let above = (lightness(1.0 + e, 1.0) - lightness(1.0, 1.0)) / e;
        assert!((below - above).abs() < 1e-3, "{below} {above}");
    }

    #[test]
    fn the_state_is_the_size_the_memory_check_counts() {
        // crate::memory counts 40 bytes a pixel for it.
        assert_eq!(std::mem::size_of::<Pixel>(), 40);
    }

    #[test]
    fn a_lone_pixel_converges_only_when_its_samples_agree() {
        let mut p = Pixel::default();
        for _ in 0..5 {
            p.add(1, Some(50.0));
        }
        assert!(p.converged());
        p.add(1, Some(0.0));
        assert!(!p.converged());
        // Spreads of +-2.7 and +-5.5 over 5 samples: standard errors 1.2
        // and 2.5, either side of TOLERANCE.
        let spread = |d: f64| {
            let mut p = Pixel::default();
            for v in [50.0 - d, 50.0 + d, 50.0 - d, 50.0 + d, 50.0] {
                p.add(1, Some(v));
            }
            p.converged()
        };
        assert!(spread(2.7) && !spread(5.5));
    }

    #[test]
    fn class_changes_refine_both_sides_and_uniform_pixels_none() {
        let px = |bit: u64, v: f64| {
            let mut p = Pixel::default();
            p.add(bit, Some(v));
            p
        };
        let sky = [px(1, 100.0); 3];
        let mixed = [px(1, 100.0), px(1, 100.0), px(2, 0.0)];
        let room = 63;
        // The pixel next to the other class and the other pixel itself.
        assert_eq!(
            decide(0, [None, Some(&mixed), None], 1, room, CONTRAST),
            FIRST
        );
        assert_eq!(
            decide(0, [None, Some(&mixed), None], 2, room, CONTRAST),
            FIRST
        );
        // Two away: nothing.
        assert_eq!(decide(0, [None, Some(&mixed), None], 0, room, CONTRAST), 0);
        assert_eq!(
            decide(0, [Some(&sky), Some(&sky), Some(&sky)], 1, room, CONTRAST),
            0
        );
        // Contrast alone.
        let step = [px(1, 100.0), px(1, 100.0), px(1, 94.0)];
        assert_eq!(
            decide(0, [None, Some(&step), None], 1, room, CONTRAST),
            FIRST
        );
        let soft = [px(1, 100.0), px(1, 100.0), px(1, 96.0)];
        assert_eq!(decide(0, [None, Some(&soft), None], 1, room, CONTRAST), 0);
        // Where the light is filtered, contrast alone refines nothing.
        let far = f64::INFINITY;
        assert_eq!(decide(0, [None, Some(&step), None], 1, room, far), 0);
        assert_eq!(decide(0, [None, Some(&mixed), None], 1, room, far), FIRST);
        // Not after the first round, unless a neighbour found a class
        // that no base sample near it had.
        let mut mixed = mixed;
        for p in &mut mixed {
            p.near = 1 | 2;
        }
        assert_eq!(decide(1, [None, Some(&mixed), None], 1, room, CONTRAST), 0);
        let mut found = mixed;
        found[2].extra = 4;
        found[2].add(1 << 5, Some(0.0));
        assert_eq!(
            decide(1, [None, Some(&found), None], 1, room, CONTRAST),
            FIRST
        );
    }
}
