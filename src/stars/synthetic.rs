//! Synthetic star catalogues for tests and benchmarks: any size,
//! deterministic from a seed, with the statistics of a real one.
//!
//! - Magnitudes follow the count law of the shipped Hipparcos extract:
//!   log10 N(<V) = 0.6 + 0.5 V to V = 7, then rising 0.45 a magnitude (so
//!   2.5 million stars, Tycho-2's size, reach V = 12.1; 10,000 reach 6.8).
//!   The brightest star is about V = -1.2.
//! - Positions: isotropic, plus a disk population concentrated towards the
//!   galactic plane (sin b Laplace-distributed, scale 0.25) whose share
//!   grows from 10 % at V = 0 to 52 % at V = 12, as faint stars crowd the
//!   Milky Way (plane to pole density 1.3 at V = 0, about 5 at V = 12).
//!   Galactic longitude is uniform (no bulge).
//! - B-V follows the quantiles of the shipped catalogue (median 0.57,
//!   5 % to 95 % from -0.07 to 1.59); 0.2 % of stars have none.
//!
//! Values are rounded to the CSV's decimals (6 for angles, 3 for V and
//! B-V), so [`to_csv`] and parsing round-trip exactly.

use super::catalogue::{HEADER, Star, galactic_to_equatorial};
use crate::sampling::mix;
use glam::DVec3;
use rayon::prelude::*;
use std::fmt::Write;

/// log10 of the number of stars brighter than V over the whole sky, by
/// the count law (a catalogue of n stars holds those up to
/// [`faintest_magnitude`]).
pub fn log_count(v: f64) -> f64 {
    if v <= 7.0 {
        0.6 + 0.5 * v
    } else {
        4.1 + 0.45 * (v - 7.0)
    }
}

/// The magnitude brighter than which `log10 N` stars lie (inverse of
/// [`log_count`]).
fn magnitude_at(log_n: f64) -> f64 {
    if log_n <= 4.1 {
        (log_n - 0.6) / 0.5
    } else {
        7.0 + (log_n - 4.1) / 0.45
    }
}

/// The faintest magnitude of a synthetic catalogue of `n` stars.
pub fn faintest_magnitude(n: usize) -> f64 {
    magnitude_at((n.max(1) as f64).log10())
}

/// B-V quantiles of the shipped catalogue (1 % to 99 %), with the ends
/// set where stellar colours stop.
const BV_QUANTILES: [(f64, f64); 11] = [
    (0.0, -0.30),
    (0.01, -0.15),
    (0.05, -0.07),
    (0.10, -0.01),
    (0.25, 0.19),
    (0.50, 0.57),
    (0.75, 1.11),
    (0.90, 1.47),
    (0.95, 1.59),
    (0.99, 1.73),
    (1.0, 2.0),
];

fn bv_at(q: f64) -> f64 {
    let k = BV_QUANTILES
        .windows(2)
        .position(|w| q <= w[1].0)
        .unwrap_or(BV_QUANTILES.len() - 2);
    let ((q0, b0), (q1, b1)) = (BV_QUANTILES[k], BV_QUANTILES[k + 1]);
    b0 + (b1 - b0) * (q - q0) / (q1 - q0)
}

/// Uniform numbers in [0, 1) for star `i` of the catalogue of `seed`.
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        (mix(self.0) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

fn round(v: f64, decimals: i32) -> f64 {
    let k = 10f64.powi(decimals);
    (v * k).round() / k
}

/// Star `i` of the synthetic catalogue of `n` stars of `seed`.
fn star(i: usize, n: usize, seed: u64) -> Star {
    let mut r = Stream(mix(mix(seed ^ 0x5eed_5ea7_0000_0001).wrapping_add(i as u64)));
    // Rank by brightness 1 .. n, drawn uniformly: the count law.
    let rank = 1.0 + r.next() * (n.max(1) - 1) as f64;
    let vmag = magnitude_at(rank.log10());
    let disk = (0.1 + 0.035 * vmag).clamp(0.05, 0.6);
    let sin_b = if r.next() < disk {
        // Laplace, scale 0.25, folded back into [-1, 1].
        let u = r.next();
        let s = -0.25 * (1.0 - u * (1.0 - (-4.0f64).exp())).ln();
        if r.next() < 0.5 { s } else { -s }
    } else {
        2.0 * r.next() - 1.0
    };
    let l = 2.0 * std::f64::consts::PI * r.next();
    let cos_b = (1.0 - sin_b * sin_b).max(0.0).sqrt();
    let (ra, dec) = galactic_to_equatorial(DVec3::new(cos_b * l.cos(), cos_b * l.sin(), sin_b));
    let bv = (r.next() >= 0.002).then(|| round(bv_at(r.next()), 3));
    let ra = round(ra, 6);
    Star {
        hip: i as u32 + 1,
        ra: if ra >= 360.0 { 0.0 } else { ra },
        dec: round(dec, 6),
        vmag: round(vmag, 3),
        bv,
    }
}

/// A synthetic catalogue of `n` stars, the same for the same `seed` on
/// every machine and thread count.
pub fn synthetic(n: usize, seed: u64) -> Vec<Star> {
    (0..n).into_par_iter().map(|i| star(i, n, seed)).collect()
}

/// Writes `v` with `decimals` decimals through integers (float
/// formatting was most of the writing time); the same text as
/// `{:.decimals$}` for the values [`synthetic`] makes.
fn fixed(s: &mut String, v: f64, decimals: u32) {
    let k = 10i64.pow(decimals);
    let q = (v.abs() * k as f64).round() as i64;
    let sign = if v < 0.0 && q != 0 { "-" } else { "" };
    let _ = write!(s, "{sign}{}.{:0w$}", q / k, q % k, w = decimals as usize);
}

/// The catalogue as CSV text in the format [`super::parse_catalogue`]
/// reads.
pub fn to_csv(stars: &[Star]) -> String {
    let rows: Vec<String> = stars
        .par_chunks(4096)
        .map(|chunk| {
            let mut s = String::with_capacity(48 * chunk.len());
            for st in chunk {
                let _ = write!(s, "{},", st.hip);
                fixed(&mut s, st.ra, 6);
                s.push(',');
                fixed(&mut s, st.dec, 6);
                s.push(',');
                fixed(&mut s, st.vmag, 3);
                s.push(',');
                if let Some(bv) = st.bv {
                    fixed(&mut s, bv, 3);
                }
                s.push('\n');
            }
            s
        })
        .collect();
    let mut out =
        String::with_capacity(HEADER.len() + 1 + rows.iter().map(String::len).sum::<usize>());
    out.push_str(HEADER);
    out.push('\n');
    for r in rows {
        out.push_str(&r);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stars::catalogue::{equatorial_to_galactic, parse_catalogue};

    #[test]
    fn deterministic_and_round_trips_through_csv() {
        let a = synthetic(5000, 7);
        assert_eq!(a, synthetic(5000, 7));
        assert_ne!(a, synthetic(5000, 8));
        assert_eq!(parse_catalogue(&to_csv(&a)).unwrap(), a);
        for (v, d) in [
            (-0.0004, 3),
            (-0.0006, 3),
            (12.5, 3),
            (359.999_999, 6),
            (-16.716_1, 6),
        ] {
            let mut s = String::new();
            fixed(&mut s, round(v, d), d as u32);
            assert_eq!(s.parse::<f64>().unwrap(), round(v, d), "{v}: {s}");
            assert_eq!(s.split('.').nth(1).unwrap().len(), d as usize, "{v}: {s}");
        }
    }

    #[test]
    fn statistics_of_a_real_catalogue() {
        let n = 200_000;
        let s = synthetic(n, 3);
        let count = |v: f64| s.iter().filter(|x| x.vmag < v).count() as f64;
        // The count law: about 0.45 to 0.5 dex a magnitude.
        let slope = (count(9.0).log10() - count(5.0).log10()) / 4.0;
        assert!((0.44..0.51).contains(&slope), "{slope}");
        for v in [4.0, 7.0, 9.5] {
            let expected = 10f64.powf(log_count(v) - log_count(faintest_magnitude(n))) * n as f64;
            assert!(
                (count(v) / expected - 1.0).abs() < 0.05,
                "{v}: {} {expected}",
                count(v)
            );
        }
        let faintest = s.iter().map(|x| x.vmag).fold(f64::MIN, f64::max);
        let brightest = s.iter().map(|x| x.vmag).fold(f64::MAX, f64::min);
        assert!(
            (faintest - faintest_magnitude(n)).abs() < 0.01,
            "{faintest}"
        );
        assert!((-1.3..1.0).contains(&brightest), "{brightest}");
        // More stars near the galactic plane than near its poles, per
        // steradian: |b| < 10 deg against |b| > 60 deg.
        let sin_b: Vec<f64> = s
            .iter()
            .map(|x| equatorial_to_galactic(x.ra, x.dec).z)
            .collect();
        let plane = sin_b
            .iter()
            .filter(|z| z.abs() < 10f64.to_radians().sin())
            .count() as f64
            / 10f64.to_radians().sin();
        let poles = sin_b
            .iter()
            .filter(|z| z.abs() > 60f64.to_radians().sin())
            .count() as f64
            / (1.0 - 60f64.to_radians().sin());
        assert!((2.0..6.0).contains(&(plane / poles)), "{}", plane / poles);
        // B-V: median about 0.57, most stars from -0.1 to 1.6.
        let mut bv: Vec<f64> = s.iter().filter_map(|x| x.bv).collect();
        bv.sort_by(f64::total_cmp);
        let q = |p: f64| bv[(p * bv.len() as f64) as usize];
        assert!((q(0.5) - 0.57).abs() < 0.02 && (q(0.05) + 0.07).abs() < 0.02);
        assert!((q(0.95) - 1.59).abs() < 0.02);
        let missing = n - bv.len();
        assert!((200..600).contains(&missing), "{missing}");
    }
}
