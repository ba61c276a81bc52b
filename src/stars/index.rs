//! The spatial index of a star catalogue: stars sorted by cube-map cell
//! (CSR offsets), with the summed flux and colour of every cell of every
//! coarser level.

use super::catalogue::PointStar;
use super::cube::{
    CapFaces, cell_corners, cell_parts, cell_solid_angle, face_dir, morton, unmorton,
};
use super::light::{CellSum, Light, LightSum};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The finest level the index builds (6 x 4^11 = 25 million leaf cells).
pub const MAX_LEVEL: u32 = 11;

/// Mean stars per leaf cell the automatic level aims at, at most.
pub const STARS_PER_CELL: usize = 8;

/// Slack (radians) added to a query's reach when choosing cells, so that
/// rounding in the cell geometry never drops a star on the rim; the
/// stars themselves are tested exactly.
pub const MARGIN: f64 = 1e-9;

/// A box of more leaf cells than this is walked at a coarser level, where
/// each cell's stars are still one contiguous run.
pub(crate) const MAX_BOX_CELLS: u32 = 64;

/// A partial cell with this many stars or fewer is summed star by star
/// rather than split.
const SPLIT_MIN_STARS: u32 = 16;

/// The catalogue, indexed.
#[derive(Clone, Debug)]
pub struct StarIndex {
    level: u32,
    stars: Vec<PointStar>,
    offsets: Vec<u32>,
    sums: Vec<CellSum>,
    inv_solid_angle: Vec<f32>,
    densest: Vec<f64>,
    total_flux: f64,
}

/// The exact light of the stars within a cap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CapSum {
    /// Their light; flux relative to magnitude 0.
    pub light: Light,
    /// How many stars.
    pub stars: u64,
    /// How many stars were tested one by one (the query's cost, with the
    /// cells it visited).
    pub tested: u64,
    /// How many cells were classified or summed.
    pub cells: u64,
}

/// The number of leaf cells at `level`.
#[inline]
pub fn cell_count(level: u32) -> usize {
    6 << (2 * level)
}

/// Index in [`StarIndex::sums`] of the first cell of `level`: levels are
/// stored coarsest first, 6 x 4^l cells each.
#[inline]
pub fn level_base(level: u32) -> usize {
    2 * ((1 << (2 * level)) - 1)
}

/// Index in [`StarIndex::inv_solid_angles`] of the first cell of
/// `level`: one face's cells (the same on every face), coarsest level
/// first, 4^l each.
#[inline]
pub fn face_level_base(level: u32) -> usize {
    ((1 << (2 * level)) - 1) / 3
}

/// The squared chord of an angle: a direction d is within angle r of c
/// when |d - c|^2 <= chord2(r), exact for small angles where the cosine
/// is not.
#[inline]
pub fn chord2(r: f64) -> f64 {
    let h = (0.5 * r.clamp(0.0, PI)).sin();
    4.0 * h * h
}

/// Whether `star` lies within the cap of centre `c` (unit) and squared
/// chord `chord2`: the test every query applies.
#[inline]
pub fn within(star: &PointStar, c: DVec3, chord2: f64) -> bool {
    (star.direction() - c).length_squared() <= chord2
}

/// Angle between unit vectors, accurate at small angles.
#[inline]
fn angle(a: DVec3, b: DVec3) -> f64 {
    2.0 * (0.5 * (a - b).length()).min(1.0).asin()
}

impl StarIndex {
    /// The level of leaf cells for `n` stars: the coarsest whose cells
    /// hold at most [`STARS_PER_CELL`] stars on average.
    pub fn auto_level(n: usize) -> u32 {
        (0..MAX_LEVEL)
            .find(|&l| cell_count(l) * STARS_PER_CELL >= n)
            .unwrap_or(MAX_LEVEL)
    }

    /// Indexes `stars` at the automatic level.
    pub fn build(stars: Vec<PointStar>) -> StarIndex {
        let level = Self::auto_level(stars.len());
        Self::with_level(stars, level)
    }

    /// Indexes `stars` with leaf cells of `level` (at most [`MAX_LEVEL`]).
    pub fn with_level(stars: Vec<PointStar>, level: u32) -> StarIndex {
        assert!(level <= MAX_LEVEL, "level {level} > {MAX_LEVEL}");
        assert!(stars.len() < u32::MAX as usize, "too many stars");
        let cells = cell_count(level);
        let ids: Vec<u32> = stars
            .par_iter()
            .map(|s| super::cube::cell_id(s.direction(), level))
            .collect();
        // Counting sort by cell, stable: each cell's stars keep the
        // catalogue's order.
        let mut offsets = vec![0u32; cells + 1];
        for &id in &ids {
            offsets[id as usize + 1] += 1;
        }
        for k in 0..cells {
            offsets[k + 1] += offsets[k];
        }
        let mut next = offsets.clone();
        let mut sorted = vec![PointStar::default(); stars.len()];
        for (s, &id) in stars.iter().zip(&ids) {
            let slot = &mut next[id as usize];
            sorted[*slot as usize] = *s;
            *slot += 1;
        }
        drop((stars, ids, next));
        let (sums, total_flux) = summed_levels(&sorted, &offsets, level);
        let inv_solid_angle = (0..=level)
            .flat_map(|l| (0..1u32 << (2 * l)).map(move |m| (l, m)))
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&(l, m)| {
                let (i, j) = unmorton(m);
                (1.0 / cell_solid_angle(i, j, l)) as f32
            })
            .collect();
        let mut index = StarIndex {
            level,
            stars: sorted,
            offsets,
            sums,
            inv_solid_angle,
            densest: Vec::new(),
            total_flux,
        };
        index.densest = (0..=level)
            .map(|l| {
                (0..cell_count(l) as u32)
                    .map(|id| index.cell_stars(l, id) as f64 * index.cell_inv_solid_angle(l, id))
                    .fold(0.0, f64::max)
            })
            .collect();
        index
    }

    /// The level of the leaf cells.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The stars, sorted by leaf cell.
    pub fn stars(&self) -> &[PointStar] {
        &self.stars
    }

    /// CSR offsets: the stars of leaf cell k are `stars[offsets[k] ..
    /// offsets[k + 1]]`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// The summed levels, level 0 first (see [`level_base`]).
    pub fn sums(&self) -> &[CellSum] {
        &self.sums
    }

    /// 1 / solid angle (sr) of the cells of one face, level by level (see
    /// [`face_level_base`]), in Morton order: cell `id` of level `l` is
    /// entry `face_level_base(l) + id % 4^l`.
    pub fn inv_solid_angles(&self) -> &[f32] {
        &self.inv_solid_angle
    }

    /// 1 / solid angle (sr) of cell `id` of `level`.
    #[inline]
    pub fn cell_inv_solid_angle(&self, level: u32, id: u32) -> f64 {
        self.inv_solid_angle[face_level_base(level) + (id & ((1 << (2 * level)) - 1)) as usize]
            as f64
    }

    /// The most stars per steradian of any cell of `level`.
    #[inline]
    pub fn densest(&self, level: u32) -> f64 {
        self.densest[level as usize]
    }

    /// The catalogue's total flux (summed in f64).
    pub fn total_flux(&self) -> f64 {
        self.total_flux
    }

    /// Bytes the index holds.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(self.stars.as_slice())
            + std::mem::size_of_val(self.offsets.as_slice())
            + std::mem::size_of_val(self.sums.as_slice())
            + std::mem::size_of_val(self.inv_solid_angle.as_slice())
    }

    /// Number of stars in cell `id` of `level`.
    #[inline]
    pub fn cell_stars(&self, level: u32, id: u32) -> u32 {
        let shift = 2 * (self.level - level);
        self.offsets[((id + 1) as usize) << shift] - self.offsets[(id as usize) << shift]
    }

    /// The stars of cell `id` of `level`: one contiguous run.
    #[inline]
    pub fn cell_run(&self, level: u32, id: u32) -> &[PointStar] {
        let shift = 2 * (self.level - level);
        let a = self.offsets[(id as usize) << shift] as usize;
        let b = self.offsets[((id + 1) as usize) << shift] as usize;
        &self.stars[a..b]
    }

    /// The summed light of cell `id` of `level`.
    #[inline]
    pub fn cell_sum(&self, level: u32, id: u32) -> CellSum {
        self.sums[level_base(level) + id as usize]
    }

    /// Visits every star within angle `radius` (radians) of direction
    /// `dir` (need not be unit), each exactly once, in no promised order;
    /// returns how many stars were tested (the query's cost). A star is
    /// within when [`within`] says so.
    pub fn for_each_within(&self, dir: DVec3, radius: f64, visit: impl FnMut(&PointStar)) -> usize {
        let c = dir.normalize();
        if !c.is_finite() || radius.is_nan() || radius < 0.0 {
            return 0;
        }
        self.for_each_in(&CapFaces::new(c, radius + MARGIN), c, radius, visit)
    }

    /// [`Self::for_each_within`] for unit `c` with the cap's faces already
    /// found (`faces` of radius `radius` + 1e-9 or more): one `CapFaces`
    /// serves every tier of a [`super::StarField`].
    pub fn for_each_in(
        &self,
        faces: &CapFaces,
        c: DVec3,
        radius: f64,
        mut visit: impl FnMut(&PointStar),
    ) -> usize {
        let c2 = chord2(radius);
        let n = 1u32 << self.level;
        let mut tested = 0;
        for f in 0..6 {
            let Some(b) = faces.cells(f, n) else {
                continue;
            };
            let (level, (i0, i1, j0, j1)) = coarsened(b, self.level, MAX_BOX_CELLS);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let run = self.cell_run(level, (f << (2 * level)) | morton(i, j));
                    tested += run.len();
                    for s in run {
                        if within(s, c, c2) {
                            visit(s);
                        }
                    }
                }
            }
        }
        tested
    }

    /// The exact flux and colour of the stars within angle `radius` of
    /// `dir`: whole cells' sums where a cell lies inside the cap, stars one
    /// by one only in cells on its rim. Equal to summing what
    /// [`Self::for_each_within`] visits (to f32 rounding of the sums);
    /// the cost grows with the rim, not the area.
    pub fn cap_sum(&self, dir: DVec3, radius: f64) -> CapSum {
        let mut out = CapSum::default();
        let c = dir.normalize();
        if !c.is_finite() || radius.is_nan() || radius < 0.0 {
            return out;
        }
        let c2 = chord2(radius);
        let mut sum = LightSum::default();
        let mut stack = self.start_cells(c, radius);
        while let Some((level, id)) = stack.pop() {
            out.cells += 1;
            let count = self.cell_stars(level, id);
            if count == 0 {
                continue;
            }
            match classify(c, radius, level, id) {
                Place::Outside => {}
                Place::Inside => {
                    sum.add_cell(&self.cell_sum(level, id), 1.0);
                    out.stars += count as u64;
                }
                Place::Partial if level == self.level || count <= SPLIT_MIN_STARS => {
                    for s in self.cell_run(level, id) {
                        out.tested += 1;
                        if within(s, c, c2) {
                            sum.add(s.flux as f64, s.kelvin as f64);
                            out.stars += 1;
                        }
                    }
                }
                Place::Partial => stack.extend((0..4).map(|k| (level + 1, 4 * id + k))),
            }
        }
        out.light = sum.finish(1.0);
        out
    }

    /// The cells a hierarchical query starts from: per face, the cap's
    /// box of leaf cells, coarsened until it holds at most 16 cells.
    fn start_cells(&self, c: DVec3, radius: f64) -> Vec<(u32, u32)> {
        let mut cells = Vec::new();
        let faces = CapFaces::new(c, radius + MARGIN);
        for f in 0..6 {
            let Some(b) = faces.cells(f, 1 << self.level) else {
                continue;
            };
            let (level, (i0, i1, j0, j1)) = coarsened(b, self.level, 16);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    cells.push((level, (f << (2 * level)) | morton(i, j)));
                }
            }
        }
        cells
    }

    /// The index as 32-bit words for a GPU storage buffer (layout in the
    /// module docs of [`crate::stars`]).
    pub fn gpu_words(&self) -> Vec<u32> {
        let star_words: &[u32] = bytemuck::cast_slice(&self.stars);
        let sum_words: &[u32] = bytemuck::cast_slice(&self.sums);
        let stars_at = GPU_HEADER_WORDS;
        let offsets_at = stars_at + star_words.len();
        let sums_at = offsets_at + self.offsets.len();
        let inv_at = sums_at + sum_words.len();
        let total = inv_at + self.inv_solid_angle.len();
        let header = [
            GPU_MAGIC,
            self.level,
            self.stars.len() as u32,
            stars_at as u32,
            offsets_at as u32,
            sums_at as u32,
            inv_at as u32,
            total as u32,
        ];
        let mut words = Vec::with_capacity(total);
        words.extend_from_slice(&header);
        words.extend_from_slice(star_words);
        words.extend_from_slice(&self.offsets);
        words.extend_from_slice(sum_words);
        words.extend(self.inv_solid_angle.iter().map(|v| v.to_bits()));
        words
    }
}

/// A box of cells (i0, i1, j0, j1) of `level`, halved until it holds at
/// most `max` cells: (its level, the box).
fn coarsened(b: (u32, u32, u32, u32), mut level: u32, max: u32) -> (u32, (u32, u32, u32, u32)) {
    let (mut i0, mut i1, mut j0, mut j1) = b;
    while level > 0 && (i1 - i0 + 1) * (j1 - j0 + 1) > max {
        (i0, i1, j0, j1) = (i0 >> 1, i1 >> 1, j0 >> 1, j1 >> 1);
        level -= 1;
    }
    (level, (i0, i1, j0, j1))
}

/// Words before the arrays in [`StarIndex::gpu_words`].
pub const GPU_HEADER_WORDS: usize = 8;

/// The first word of [`StarIndex::gpu_words`]: "STR1" little-endian.
pub const GPU_MAGIC: u32 = u32::from_le_bytes(*b"STR1");

/// Where a cell lies against a cap.
enum Place {
    Inside,
    Outside,
    Partial,
}

/// A cell against the cap of centre `c` (unit) and radius `r`,
/// conservatively: Inside and Outside are certain, Partial may be either.
fn classify(c: DVec3, r: f64, level: u32, id: u32) -> Place {
    let (f, i, j) = cell_parts(id, level);
    let corners = cell_corners(f, i, j, level);
    let h = 1.0 / (1u32 << level) as f64;
    let centre = face_dir(
        f,
        (2 * i + 1) as f64 * h - 1.0,
        (2 * j + 1) as f64 * h - 1.0,
    );
    // Distance from a point is convex over the cell (within 55 degrees of
    // its centre): its farthest point is a corner.
    let reach = corners
        .iter()
        .map(|&k| angle(centre, k))
        .fold(0.0, f64::max);
    if angle(c, centre) > r + reach + MARGIN {
        return Place::Outside;
    }
    let inside = if r <= 0.5 * PI {
        // A convex cell with its corners in a convex cap lies in it.
        corners.iter().all(|&k| angle(c, k) < r - MARGIN)
    } else {
        // Clear of the (convex) complement.
        angle(-c, centre) > (PI - r) + reach + MARGIN
    };
    if inside {
        Place::Inside
    } else {
        Place::Partial
    }
}

/// The summed levels of stars sorted by cell (f64 sums, stored f32), and
/// the total flux.
fn summed_levels(stars: &[PointStar], offsets: &[u32], leaf: u32) -> (Vec<CellSum>, f64) {
    let mut acc: Vec<LightSum> = offsets
        .par_windows(2)
        .map(|w| {
            let mut l = LightSum::default();
            for s in &stars[w[0] as usize..w[1] as usize] {
                l.add(s.flux as f64, s.kelvin as f64);
            }
            l
        })
        .collect();
    let mut sums = vec![CellSum::default(); level_base(leaf + 1)];
    for level in (0..=leaf).rev() {
        let base = level_base(level);
        for (k, a) in acc.iter().enumerate() {
            sums[base + k] = a.cell();
        }
        if level > 0 {
            acc = acc
                .chunks_exact(4)
                .map(|q| {
                    let mut l = LightSum::default();
                    q.iter().for_each(|c| l.add_sum(c, 1.0));
                    l
                })
                .collect();
        }
    }
    let total = acc.iter().map(LightSum::total).sum();
    (sums, total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stars::{synthetic, to_csv};

    /// Directions on the cube's seams: face centres (the poles among
    /// them), edge midpoints, corners, and points just either side.
    pub(crate) fn seams() -> Vec<DVec3> {
        let mut v = Vec::new();
        for a in [-1.0, 0.0, 1.0] {
            for b in [-1.0, 0.0, 1.0] {
                for c in [-1.0, 0.0, 1.0] {
                    let d = DVec3::new(a, b, c);
                    if d != DVec3::ZERO {
                        v.push(d.normalize());
                        v.push((d + DVec3::new(1e-7, -2e-7, 3e-7)).normalize());
                    }
                }
            }
        }
        v
    }

    /// A synthetic catalogue plus stars exactly on the seams.
    fn catalogue(n: usize) -> Vec<PointStar> {
        let mut s: Vec<PointStar> = synthetic(n, 11).iter().map(PointStar::from_star).collect();
        for d in seams() {
            s.push(PointStar {
                dir: d.as_vec3().to_array(),
                flux: 2.0,
                kelvin: 4000.0,
            });
        }
        s
    }

    #[test]
    fn queries_find_exactly_the_brute_force_set() {
        let idx = StarIndex::build(catalogue(30_000));
        assert_eq!(idx.level(), 5);
        let stars = idx.stars();
        let mut centres = seams();
        // Random directions and stars' own (offset a little).
        let mut rng = 1u64;
        let mut next = || {
            rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
            (crate::sampling::mix(rng) >> 11) as f64 / (1u64 << 53) as f64
        };
        for k in 0..40 {
            let z = 2.0 * next() - 1.0;
            let phi = 2.0 * PI * next();
            let s = (1.0 - z * z).sqrt();
            centres.push(DVec3::new(s * phi.cos(), s * phi.sin(), z));
            let p = stars[(k * 733) % stars.len()].direction();
            centres.push((p + 1e-6 * DVec3::new(next(), next(), next())).normalize());
        }
        let arcsec = (1.0f64 / 3600.0).to_radians();
        let degree = 1f64.to_radians();
        let radii = [
            arcsec,
            60.0 * arcsec,
            0.1 * degree,
            degree,
            10.0 * degree,
            60.0 * degree,
        ];
        let mut found = 0;
        for (k, &c) in centres.iter().enumerate() {
            let c = c.normalize();
            // Each star's angle from c by an independent formula.
            let angles: Vec<f64> = stars
                .iter()
                .map(|s| {
                    let p = s.direction();
                    p.cross(c).length().atan2(p.dot(c))
                })
                .collect();
            for &r in &radii {
                let mut got = Vec::new();
                idx.for_each_within(c, r, |s| {
                    got.push((s as *const PointStar as usize - stars.as_ptr() as usize) / 20)
                });
                got.sort();
                // Each star once, and exactly those the shared test passes ...
                let c2 = chord2(r);
                let want: Vec<usize> = (0..stars.len())
                    .filter(|&i| within(&stars[i], c, c2))
                    .collect();
                assert_eq!(got, want, "query {k} at {c}, radius {r}");
                // ... which are those the independent formula finds, up to
                // ties on the rim (seam stars at exactly 60 degrees from
                // seam directions).
                let mut hit = vec![false; stars.len()];
                got.iter().for_each(|&i| hit[i] = true);
                for (i, &a) in angles.iter().enumerate() {
                    assert!(
                        hit[i] || a > r - 1e-12,
                        "query {k} at {c}, radius {r}: {i} missed"
                    );
                    assert!(
                        !hit[i] || a <= r + 1e-12,
                        "query {k} at {c}, radius {r}: {i} extra"
                    );
                }
                found += got.len();
                // The hierarchical sum counts the same stars, same flux.
                let sum = idx.cap_sum(c, r);
                assert_eq!(sum.stars, want.len() as u64, "{k} {r}");
                let flux: f64 = want.iter().map(|&i| stars[i].flux as f64).sum();
                let err = (sum.light.total() - flux).abs();
                assert!(err <= 1e-6 * flux, "{k} {r}: {} {flux}", sum.light.total());
            }
        }
        assert!(found > 100_000, "{found}");
    }

    #[test]
    fn small_queries_are_cheap_and_large_sums_read_cells() {
        let idx = StarIndex::build(catalogue(30_000));
        let c = DVec3::new(0.3, 0.5, -0.8).normalize();
        let tested = idx.for_each_within(c, 0.1f64.to_radians(), |_| {});
        assert!(tested < 60, "{tested}");
        let all = idx.cap_sum(c, 60f64.to_radians());
        assert!(all.stars > 5000 && all.tested < all.stars / 4, "{all:?}");
    }

    #[test]
    fn summed_levels_hold_the_catalogue_total() {
        let stars = catalogue(20_000);
        let total: f64 = stars.iter().map(|s| s.flux as f64).sum();
        let idx = StarIndex::build(stars);
        assert!((idx.total_flux() - total).abs() < 1e-12 * total);
        for level in 0..=idx.level() {
            let sum: f64 = (0..cell_count(level) as u32)
                .map(|id| {
                    let s = idx.cell_sum(level, id);
                    (s.flux[0] + s.flux[1]) as f64
                })
                .sum();
            assert!(
                (sum - total).abs() < 1e-6 * total,
                "level {level}: {sum} {total}"
            );
        }
        // The whole sphere, from any direction.
        let s = idx.cap_sum(DVec3::new(0.1, -0.4, 0.2), PI);
        assert_eq!(s.stars, 20_000 + seams().len() as u64);
        assert!((s.light.total() - total).abs() < 1e-6 * total);
    }

    #[test]
    fn gpu_words_follow_the_documented_layout() {
        let text = to_csv(&synthetic(1000, 2));
        let idx = StarIndex::build(crate::stars::parse_point_stars(&text).unwrap());
        let w = idx.gpu_words();
        assert_eq!(w[0], GPU_MAGIC);
        assert_eq!(w[1], idx.level());
        assert_eq!(w[2], 1000);
        let (sa, oa, ua, ia) = (w[3] as usize, w[4] as usize, w[5] as usize, w[6] as usize);
        let total = w[7] as usize;
        assert_eq!((sa, total), (GPU_HEADER_WORDS, w.len()));
        assert_eq!(oa, sa + 5 * 1000);
        assert_eq!(ua, oa + cell_count(idx.level()) + 1);
        assert_eq!(ia, ua + 4 * level_base(idx.level() + 1));
        assert_eq!(total, ia + face_level_base(idx.level() + 1));
        // Star k of leaf cell id: words sa + 5 (offsets[id] + k) ...
        let id = 17;
        let k = w[oa + id] as usize;
        let star = idx.stars()[k];
        assert_eq!(f32::from_bits(w[sa + 5 * k + 3]), star.flux);
        // ... and cell id of level l: words ua + 4 (2 (4^l - 1) + id).
        let s = idx.cell_sum(1, 5);
        assert_eq!(
            f32::from_bits(w[ua + 4 * (level_base(1) + 5) + 1]),
            s.flux[1]
        );
        assert_eq!(
            f32::from_bits(w[ua + 4 * (level_base(1) + 5) + 2]),
            s.kelvin[0]
        );
    }
}
