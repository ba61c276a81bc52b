//! Flux per steradian over a footprint, from the summed levels.
//!
//! A footprint that holds few stars is summed star by star (the renderer
//! visits them with [`StarIndex::for_each_within`] and weighs each through
//! its pixel filter). One that holds many reads the summed levels instead,
//! in constant time: the flux density of the cells (each cell's flux over
//! its solid angle), bilinear across the four cells around the direction
//! (across cube edges too) and linear between the two levels whose cell
//! width brackets [`CELL_PER_RADIUS`] times the footprint's radius, like a
//! trilinear mip lookup. [`SumRule`] is the crossover.
//!
//! Against the exact star sum over random caps (2.5 million synthetic
//! stars, 400 caps), the smooth density's total over the cap errs by a
//! median 15 %, 8.4 %, 5.0 % and 3.5 % at 1, 3, 10 and 30 degrees
//! (its star count by 4.5 %, 1.5 %, 0.8 %, 2.1 %): the flux's error is
//! the brightest stars near the rim, which [`super::StarField`]'s tiers
//! keep as points. A cell width of 1 footprint radius matched best (0.5,
//! 0.75, 1.25, 1.5 and 2 tried).

use super::cube::{cell_of, face_coords, face_dir, morton};
use super::index::StarIndex;
use super::light::{Light, LightSum};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Width of the cells a smooth lookup reads, in footprint radii (the
/// width of a cell at the middle of a face, (pi/2) / 2^level).
pub const CELL_PER_RADIUS: f64 = 1.0;

/// When the summed levels answer for a footprint rather than its stars.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SumRule {
    /// Stars a footprint may hold (by the estimate of
    /// [`StarIndex::estimated_count`]) and still be summed star by star.
    /// From `max_stars` to twice that the two answers are blended, so
    /// that a footprint growing across the crossover changes smoothly;
    /// beyond it the summed levels alone answer.
    pub max_stars: f64,
}

impl SumRule {
    /// The share of a footprint holding about `stars` stars that the
    /// summed levels answer: 0 up to `max_stars`, rising linearly to 1 at
    /// twice that.
    #[inline]
    pub fn summed_share(&self, stars: f64) -> f64 {
        if self.max_stars > 0.0 {
            ((stars - self.max_stars) / self.max_stars).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }
}

impl Default for SumRule {
    /// 64 stars: a one-pixel footprint of a 2.5-million-star sky holds
    /// about 2 to 10, so ordinary pixels see every star; a footprint near
    /// the photon ring, tens of degrees across, holds thousands.
    fn default() -> Self {
        SumRule { max_stars: 64.0 }
    }
}

/// The light of a footprint, per steradian.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Density {
    /// Flux per steradian (magnitude 0 = 1), as two blackbodies.
    pub light: Light,
    /// Stars per steradian.
    pub stars_per_sr: f64,
    /// The share of the answer from the exact star sum: 1 below the
    /// crossover, 0 above it, between in the blend.
    pub exact: f64,
}

/// Solid angle (sr) of a cap of angular radius `r`.
#[inline]
pub fn cap_solid_angle(r: f64) -> f64 {
    let h = (0.5 * r.clamp(0.0, PI)).sin();
    4.0 * PI * h * h
}

impl StarIndex {
    /// The (fractional) level whose cells a smooth lookup of a footprint
    /// of angular radius `radius` reads, from 1 (0 for an index of one
    /// level) to the leaf level.
    pub fn density_level(&self, radius: f64) -> f64 {
        let l = (FRAC_PI_2 / (CELL_PER_RADIUS * radius)).log2();
        if l.is_nan() {
            return self.level() as f64;
        }
        l.clamp(self.level().min(1) as f64, self.level() as f64)
    }

    /// The smooth flux density around `dir` at the scale of a footprint of
    /// angular radius `radius` (radians), in constant time: 8 cells read.
    pub fn smooth_density(&self, dir: DVec3, radius: f64) -> Density {
        let c = dir.normalize();
        let mut sum = LightSum::default();
        let mut stars = 0.0;
        if c.is_finite() {
            let lf = self.density_level(radius);
            let l0 = lf.floor() as u32;
            let t = lf - l0 as f64;
            self.bilinear(c, l0, 1.0 - t, &mut sum, &mut stars);
            if t > 0.0 {
                self.bilinear(c, l0 + 1, t, &mut sum, &mut stars);
            }
        }
        Density {
            light: sum.finish(1.0),
            stars_per_sr: stars,
            exact: 0.0,
        }
    }

    /// About how many stars lie within `radius` of `dir` (the smooth
    /// star density times the cap's solid angle): the quantity
    /// [`SumRule`] compares.
    pub fn estimated_count(&self, dir: DVec3, radius: f64) -> f64 {
        self.smooth_density(dir, radius).stars_per_sr * cap_solid_angle(radius)
    }

    /// An upper bound of [`Self::estimated_count`] for any direction, from
    /// the densest cells of the levels it reads: where it is within
    /// [`SumRule::max_stars`], the footprint is resolved star by star
    /// without a lookup.
    pub fn most_stars(&self, radius: f64) -> f64 {
        let lf = self.density_level(radius);
        let l0 = lf.floor() as u32;
        let l1 = (l0 + 1).min(self.level());
        self.densest(l0).max(self.densest(l1)) * cap_solid_angle(radius)
    }

    /// The flux per steradian over the cap of angular radius `radius`
    /// around `dir`: the exact mean of its stars ([`Self::cap_sum`] over
    /// the cap's solid angle) while it holds up to `rule.max_stars`, the
    /// smooth density of the summed levels ([`Self::smooth_density`])
    /// beyond twice that, blended between.
    pub fn flux_density(&self, dir: DVec3, radius: f64, rule: SumRule) -> Density {
        let smooth = self.smooth_density(dir, radius);
        let omega = cap_solid_angle(radius);
        let n = smooth.stars_per_sr * omega;
        let w = rule.summed_share(n);
        if w >= 1.0 || omega <= 0.0 {
            return smooth;
        }
        let exact = self.cap_sum(dir, radius);
        let mut sum = LightSum::from(exact.light);
        sum = sum.scaled((1.0 - w) / omega);
        sum.add_sum(&LightSum::from(smooth.light), w);
        Density {
            light: sum.finish(1.0),
            stars_per_sr: (1.0 - w) * exact.stars as f64 / omega + w * smooth.stars_per_sr,
            exact: 1.0 - w,
        }
    }

    /// Adds `weight` times the bilinear flux and star densities of `level`
    /// at unit `c`.
    fn bilinear(&self, c: DVec3, level: u32, weight: f64, sum: &mut LightSum, stars: &mut f64) {
        let n = 1u32 << level;
        let (f, x, y) = face_coords(c);
        // A lone level-0 cell would hold the whole face.
        if level == 0 {
            // One cell a face: nothing to interpolate towards.
            return self.add_cell(level, f, 0, 0, weight, sum, stars);
        }
        let sx = (x + 1.0) * 0.5 * n as f64 - 0.5;
        let sy = (y + 1.0) * 0.5 * n as f64 - 0.5;
        let (fx, fy) = (sx.floor(), sy.floor());
        let (tx, ty) = (sx - fx, sy - fy);
        let h = 2.0 / n as f64;
        for (di, dj, w) in [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ] {
            if w <= 0.0 {
                continue;
            }
            let (i, j) = (fx as i64 + di, fy as i64 + dj);
            let (face, i, j) = if (0..n as i64).contains(&i) && (0..n as i64).contains(&j) {
                (f, i as u32, j as u32)
            } else {
                // Past the face's edge: the cell the tap's centre falls in
                // on the neighbouring face.
                let d = face_dir(f, (i as f64 + 0.5) * h - 1.0, (j as f64 + 0.5) * h - 1.0);
                let (f2, x2, y2) = face_coords(d);
                (f2, cell_of(x2, n), cell_of(y2, n))
            };
            self.add_cell(level, face, i, j, weight * w, sum, stars);
        }
    }

    /// Adds `weight` times cell (face, i, j)'s densities.
    #[allow(clippy::too_many_arguments)]
    fn add_cell(
        &self,
        level: u32,
        face: u32,
        i: u32,
        j: u32,
        weight: f64,
        sum: &mut LightSum,
        stars: &mut f64,
    ) {
        let id = (face << (2 * level)) | morton(i, j);
        let w = weight * self.cell_inv_solid_angle(level, id);
        sum.add_cell(&self.cell_sum(level, id), w);
        *stars += w * self.cell_stars(level, id) as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stars::{PointStar, StarIndex, synthetic};

    #[test]
    fn a_uniform_sky_reads_its_density_everywhere() {
        // Stars on a fine grid of directions, equal flux: the smooth
        // density is the flux over 4 pi, wherever and at whatever scale.
        let mut stars = Vec::new();
        let m = 400;
        for a in 0..m {
            let z = 1.0 - 2.0 * (a as f64 + 0.5) / m as f64;
            for b in 0..2 * m {
                let phi = (b as f64 + 0.5 * (a % 2) as f64) * PI / m as f64;
                let r = (1.0 - z * z).sqrt();
                let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                stars.push(PointStar {
                    dir: d.as_vec3().to_array(),
                    flux: 1.0,
                    kelvin: 6000.0,
                });
            }
        }
        let n = stars.len() as f64;
        let idx = StarIndex::with_level(stars, 5);
        for (k, d) in [
            DVec3::X,
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(0.3, -0.2, 0.9),
        ]
        .into_iter()
        .enumerate()
        {
            for r in [0.05, 0.1, 0.3] {
                let rho = idx.smooth_density(d, r);
                let expect = n / (4.0 * PI);
                assert!(
                    (rho.light.total() / expect - 1.0).abs() < 0.03,
                    "{k} {r}: {} {expect}",
                    rho.light.total()
                );
                assert!((rho.light.kelvin[1] - 6000.0).abs() < 1e-2);
                assert!((rho.stars_per_sr / expect - 1.0).abs() < 0.03);
            }
        }
    }

    #[test]
    fn flux_density_is_exact_below_the_crossover_and_smooth_above() {
        let stars: Vec<PointStar> = synthetic(20_000, 9)
            .iter()
            .map(PointStar::from_star)
            .collect();
        let idx = StarIndex::build(stars);
        let rule = SumRule::default();
        let d = DVec3::new(0.2, 0.9, -0.1);
        // Small: the exact mean of the stars in the cap.
        let r = 0.05;
        let omega = cap_solid_angle(r);
        let exact = idx.cap_sum(d, r);
        let got = idx.flux_density(d, r, rule);
        assert_eq!(got.exact, 1.0);
        assert!(
            (got.light.total() * omega - exact.light.total()).abs()
                < 1e-9 * exact.light.total().max(1e-30)
        );
        // Large: the smooth density.
        let r = 0.5;
        assert!(idx.estimated_count(d, r) > 2.0 * rule.max_stars);
        assert_eq!(idx.flux_density(d, r, rule), idx.smooth_density(d, r));
    }
}
