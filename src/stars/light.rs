//! The light of many stars: two blackbodies.
//!
//! A sum of blackbodies is not a blackbody: its colour lies off the
//! Planckian locus, between the colours of its members. One temperature
//! for a cell (its flux-weighted mean) misses the colour of the summed
//! light of the synthetic catalogue's cells by CIEDE2000 3.3 on average
//! (mean of T) or 2.3 (mean of 1/T, closer because the locus is nearly
//! uniform in 1/T), about one just-noticeable difference, 5 to 9 in the
//! worst cells. Splitting the stars at [`SPLIT_KELVIN`] into a cool and
//! a hot part, each one blackbody at its flux-weighted mean of 1/T,
//! brings that to 0.5 on average and under 1 for 99 % of cells (measured
//! at luminance 0.3 over levels 0 to 7 of a 250,000-star catalogue; the
//! test below holds it). Two (flux, kelvin) pairs a cell, and two
//! blackbodies a lookup, shifted by g like any star's.

use bytemuck::{Pod, Zeroable};

/// The summed light of one cell of the index as two blackbodies: four
/// 32-bit words (the GPU reads them as they are).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CellSum {
    /// Total flux of its cool stars and of its hot ones (magnitude 0 = 1).
    pub flux: [f32; 2],
    /// Their temperatures (K), each flux-weighted in 1/T; 0 where a part
    /// is empty.
    pub kelvin: [f32; 2],
}

/// Stars cooler than this (K) are the cool part, the rest the hot part:
/// the split that matched the summed colour best (4500 to 7500 K tried).
pub const SPLIT_KELVIN: f64 = 5500.0;

/// Which part a star of `kelvin` belongs to: 0 cool, 1 hot.
#[inline]
pub fn part(kelvin: f64) -> usize {
    usize::from(kelvin >= SPLIT_KELVIN)
}

/// Light as two blackbodies. `flux` is in the unit of the query that
/// returned it (a flux, or a flux per steradian).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Light {
    /// Flux of the cool part and of the hot part.
    pub flux: [f64; 2],
    /// Their temperatures (K); 0 where the part is empty.
    pub kelvin: [f64; 2],
}

impl Light {
    /// The total flux.
    #[inline]
    pub fn total(&self) -> f64 {
        self.flux[0] + self.flux[1]
    }

    /// The blackbodies, (kelvin, flux), those that are lit.
    pub fn blackbodies(&self) -> impl Iterator<Item = (f64, f64)> {
        [
            (self.kelvin[0], self.flux[0]),
            (self.kelvin[1], self.flux[1]),
        ]
        .into_iter()
        .filter(|&(_, f)| f > 0.0)
    }

    /// One temperature for all of it (flux-weighted in 1/T), where a
    /// single blackbody must do; 0 for no light.
    pub fn mean_kelvin(&self) -> f64 {
        let w: f64 = self.blackbodies().map(|(k, f)| f / k).sum();
        if w > 0.0 { self.total() / w } else { 0.0 }
    }
}

/// Running sums towards a [`Light`]: per part, the flux and the flux over
/// temperature.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSum {
    flux: [f64; 2],
    per_kelvin: [f64; 2],
}

impl LightSum {
    /// Adds one star, or one blackbody of the given flux.
    #[inline]
    pub fn add(&mut self, flux: f64, kelvin: f64) {
        let k = part(kelvin);
        self.flux[k] += flux;
        self.per_kelvin[k] += flux / kelvin;
    }

    /// Adds a cell's sums times `weight`.
    #[inline]
    pub fn add_cell(&mut self, s: &CellSum, weight: f64) {
        for k in 0..2 {
            if s.flux[k] > 0.0 {
                let f = weight * s.flux[k] as f64;
                self.flux[k] += f;
                self.per_kelvin[k] += f / s.kelvin[k] as f64;
            }
        }
    }

    /// Adds another sum times `weight`.
    #[inline]
    pub fn add_sum(&mut self, o: &LightSum, weight: f64) {
        for k in 0..2 {
            self.flux[k] += weight * o.flux[k];
            self.per_kelvin[k] += weight * o.per_kelvin[k];
        }
    }

    /// The total flux so far.
    #[inline]
    pub fn total(&self) -> f64 {
        self.flux[0] + self.flux[1]
    }

    /// The sums times `k`.
    #[inline]
    pub fn scaled(&self, k: f64) -> LightSum {
        LightSum {
            flux: self.flux.map(|f| f * k),
            per_kelvin: self.per_kelvin.map(|f| f * k),
        }
    }

    /// The light, its fluxes times `scale`.
    pub fn finish(&self, scale: f64) -> Light {
        let mut l = Light::default();
        for k in 0..2 {
            if self.flux[k] > 0.0 {
                l.flux[k] = self.flux[k] * scale;
                l.kelvin[k] = self.flux[k] / self.per_kelvin[k];
            }
        }
        l
    }

    /// The sums as a cell's stored words (f32).
    pub fn cell(&self) -> CellSum {
        let l = self.finish(1.0);
        CellSum {
            flux: l.flux.map(|f| f as f32),
            kelvin: l.kelvin.map(|k| k as f32),
        }
    }
}

impl From<Light> for LightSum {
    fn from(l: Light) -> LightSum {
        let mut s = LightSum::default();
        for k in 0..2 {
            if l.flux[k] > 0.0 {
                s.flux[k] = l.flux[k];
                s.per_kelvin[k] = l.flux[k] / l.kelvin[k];
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::blackbody_xyz;
    use crate::spectrum::color::xyz_to_linear_srgb;
    use crate::stars::{PointStar, StarIndex, synthetic};
    use glam::DVec3;

    /// CIEDE2000 between two XYZ colours brought to luminance 0.3.
    fn delta_e(a: DVec3, b: DVec3) -> f64 {
        let rgb = |c: DVec3| xyz_to_linear_srgb(c / c.y * 0.3).as_vec3();
        crate::compare::delta_e(rgb(a), rgb(b))
    }

    #[test]
    fn two_blackbodies_carry_the_colour_of_many_stars() {
        let stars: Vec<PointStar> = synthetic(100_000, 5)
            .iter()
            .map(PointStar::from_star)
            .collect();
        let idx = StarIndex::build(stars);
        let table: Vec<DVec3> = (0..=1600)
            .map(|k| blackbody_xyz(1000.0 + 25.0 * k as f64))
            .collect();
        let xyz = |t: f64| {
            let f = ((t - 1000.0) / 25.0).clamp(0.0, 1599.0);
            let i = f as usize;
            table[i].lerp(table[i + 1], f - i as f64)
        };
        let (mut two, mut one) = (Vec::new(), Vec::new());
        for level in 2..=idx.level() {
            for id in 0..(6u32 << (2 * level)) {
                if idx.cell_stars(level, id) < 2 {
                    continue;
                }
                // The exact colour of the cell's stars against its sums.
                let exact: DVec3 = idx
                    .cell_run(level, id)
                    .iter()
                    .map(|s| s.flux as f64 * xyz(s.kelvin as f64))
                    .sum();
                let mut l = LightSum::default();
                l.add_cell(&idx.cell_sum(level, id), 1.0);
                let light = l.finish(1.0);
                let summed: DVec3 = light.blackbodies().map(|(k, f)| f * xyz(k)).sum();
                two.push(delta_e(exact, summed));
                one.push(delta_e(exact, xyz(light.mean_kelvin())));
            }
        }
        let stats = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            (
                v.iter().sum::<f64>() / v.len() as f64,
                v[v.len() * 99 / 100],
            )
        };
        let ((m2, p2), (m1, p1)) = (stats(&mut two), stats(&mut one));
        assert!(m2 < 0.6 && p2 < 1.5, "two blackbodies: mean {m2}, p99 {p2}");
        // One temperature alone is about a just-noticeable difference off.
        assert!(m1 > 1.5 && p1 > 3.0, "one blackbody: mean {m1}, p99 {p1}");
    }
}
