//! Where a snapshot cannot shine, so that rays cross it without sampling.
//!
//! The plasma at a point is interpolated between the eight cell centres
//! about it ([`super::Grmhd::interpolate`]): a box between eight centres
//! (a dual cell) emits and absorbs nothing anywhere inside it when all
//! eight are above the magnetisation cut (the interpolated sigma is then
//! above it too), or all hold no gas, or all no field (|b| and n_e are
//! interpolated as they are), or it lies beyond the emitting radii. Each
//! dual cell is marked dark or lit, and a table of their running counts
//! answers in eight reads whether any box of them holds a lit one. This
//! is exact, not a threshold: skipping the dark ones changes no emission.
//! Beside each count the table keeps those of the lit ones whose plasma
//! is not smooth at each of [`SMOOTH_LEVELS`] levels, so that pieces may
//! be longer where a box holds none ([`Grmhd::census`]).

use super::coords::Theta;
use super::dump::Header;
use super::{Cell, F_B, F_RHO, F_SIGMA, Grmhd};
use std::f64::consts::{PI, TAU};

/// Where a stretch of a ray lies: Boyer-Lindquist r (M) and theta, and
/// the Kerr-Schild azimuth unwrapped (None: any), each a closed range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub r: (f64, f64),
    pub theta: (f64, f64),
    pub phi: Option<(f64, f64)>,
    /// How far the stretch goes in r (M), theta and the azimuth (rad; 0
    /// where it is not known), a way back after a turn counted again.
    pub travel: [f64; 3],
}

/// The dual cells' lit counts, summed from the first in each index: dual
/// cell (i, j, k) spans the centres i - 1 and i (ghost index -1 is the
/// edge's), j - 1 and j (across the poles as the ghost cells go), and k
/// and k + 1 (mod n3).
#[derive(Clone, Debug)]
pub struct Darkness {
    /// Dual cells along each index: n1 + 1, n2 + 1, n3.
    dims: [usize; 3],
    /// Running counts, (dims + 1) along each index, k fastest: of the
    /// lit dual cells, and of those lit that are not smooth at each
    /// level (a corner's plasma unlike its neighbours': [`SMOOTH`]), side
    /// by side so that a query reads them all from the same memory.
    sums: Vec<[u32; 1 + SMOOTH_LEVELS]>,
    /// The same as bits of blocks of [`BLOCK`]^3 dual cells (bit 0: some
    /// lit; bit L: some lit not smooth at level L), small enough to stay
    /// in the processor's cache: most boxes are answered from it.
    blocks: Vec<u8>,
    /// Blocks along each index.
    block_dims: [usize; 3],
    /// How many are lit.
    pub lit: u64,
    /// The greatest radius (M) a lit one reaches (0 where none is).
    pub outer: f64,
    /// theta of the cell centres along X2 as [`Theta::parts`], and the
    /// map.
    centres: Vec<(f64, f64)>,
    theta: Theta,
}

/// Dual cells along each index of a block ([`Darkness::blocks`]).
const BLOCK: usize = 4;
/// Past this many blocks a box is answered by the counts alone (eight
/// reads).
const MOST_BLOCKS: usize = 64;

/// The three ways a cell fails to shine, as bits.
const HIGH_SIGMA: u8 = 1;
const NO_GAS: u8 = 2;
const NO_FIELD: u8 = 4;
/// How smooth the plasma is about a cell, in levels: at level L its n_e,
/// Theta_e and |b| are each within SMOOTH_RATIO^(1 / 2^(L - 1)) of its
/// six neighbours', well below the magnetisation cut, and pieces may
/// cross 2^L times as many cells ([`Census::Smooth`]): over each piece
/// the plasma then changes by the same factor at most, 1.25^4 = 2.4 (a
/// two-node Gauss-Legendre rule's error on an exponential of that span is
/// 3e-4 of it).
pub const SMOOTH_LEVELS: usize = 3;
const SMOOTH_RATIO: f64 = 1.25;
/// The first level's bit; level L's is SMOOTH << (L - 1).
const SMOOTH: u8 = 8;

/// Each cell's bits: the ways it fails to shine, and its smoothness
/// levels ([`SMOOTH_LEVELS`]; the edges' own values beyond the grid,
/// sigma below a tenth of the cut `cut`).
fn cell_bits(h: &Header, cells: &[Cell], cut: f64) -> Vec<u8> {
    let [n1, n2, n3] = h.n;
    let mut dead: Vec<u8> = cells
        .iter()
        .map(|c| {
            let mut bits = 0;
            if f64::from(c[F_SIGMA]) > cut {
                bits |= HIGH_SIGMA;
            }
            if !(c[F_RHO] > 0.0) {
                bits |= NO_GAS;
            }
            if !(c[F_B] > 0.0) {
                bits |= NO_FIELD;
            }
            bits
        })
        .collect();
    let index = |i: usize, j: usize, k: usize| (i * n2 + j) * n3 + k;
    for i in 0..n1 {
        for j in 0..n2 {
            for k in 0..n3 {
                let (at, c) = (index(i, j, k), &cells[index(i, j, k)]);
                // A cell that cannot shine is not smooth either.
                if dead[at] != 0 || f64::from(c[F_SIGMA]) > 0.1 * cut {
                    continue;
                }
                let near = [
                    index(i.saturating_sub(1), j, k),
                    index((i + 1).min(n1 - 1), j, k),
                    index(i, j.saturating_sub(1), k),
                    index(i, (j + 1).min(n2 - 1), k),
                    index(i, j, (k + n3 - 1) % n3),
                    index(i, j, (k + 1) % n3),
                ];
                // The greatest ratio to a neighbour's value: of the
                // greatest to the cell's and the cell's to the least.
                let mut ratio = 1.0f64;
                for f in [F_RHO, super::F_THETA_E, F_B] {
                    let a = c[f];
                    let (lo, hi) = near.iter().fold((a, a), |(lo, hi), &n| {
                        (lo.min(cells[n][f]), hi.max(cells[n][f]))
                    });
                    ratio = if lo > 0.0 {
                        ratio.max(f64::from((hi / a).max(a / lo)))
                    } else {
                        f64::INFINITY
                    };
                }
                let mut bound = SMOOTH_RATIO;
                for level in 0..SMOOTH_LEVELS {
                    if ratio <= bound {
                        dead[at] |= SMOOTH << level;
                    }
                    bound = bound.sqrt();
                }
            }
        }
    }
    dead
}

impl Darkness {
    /// The dual cells of the grid `h` holding `cells`, with the
    /// magnetisation cut `cut` and the emitting radii `radii` (M).
    pub fn new(h: &Header, cells: &[Cell], cut: f64, radii: [f64; 2]) -> Darkness {
        let [n1, n2, n3] = h.n;
        let dead = cell_bits(h, cells, cut);
        // A ghost cell's bits: across a pole of an odd n3 the mean of two
        // cells, which fails a way only where both do.
        let ghost = |i: i64, j: i64, k: i64| -> u8 {
            let i = i.clamp(0, n1 as i64 - 1) as usize;
            let cell = |j: usize, k: usize| dead[(i * n2 + j) * n3 + k];
            let k = k.rem_euclid(n3 as i64) as usize;
            if (0..n2 as i64).contains(&j) {
                return cell(j as usize, k);
            }
            let j = j.clamp(0, n2 as i64 - 1) as usize;
            if n3 % 2 == 0 {
                cell(j, (k + n3 / 2) % n3)
            } else {
                cell(j, (k + (n3 - 1) / 2) % n3) & cell(j, (k + (n3 + 1) / 2) % n3)
            }
        };
        // The bits with a ghost row beyond each pole (rows -1 to n2), then
        // each row's AND over a dual cell's two rows and two azimuths: a
        // dual cell is then the AND of two of these along X1.
        let rows = n2 + 2;
        let mut ext = vec![0u8; n1 * rows * n3];
        for i in 0..n1 {
            for row in 0..rows {
                for k in 0..n3 {
                    ext[(i * rows + row) * n3 + k] = ghost(i as i64, row as i64 - 1, k as i64);
                }
            }
        }
        let mut pairs = vec![0u8; n1 * (n2 + 1) * n3];
        for i in 0..n1 {
            for j in 0..=n2 {
                let e = |row: usize, k: usize| ext[(i * rows + row) * n3 + k];
                for k in 0..n3 {
                    let k1 = if k + 1 == n3 { 0 } else { k + 1 };
                    pairs[(i * (n2 + 1) + j) * n3 + k] =
                        e(j, k) & e(j, k1) & e(j + 1, k) & e(j + 1, k1);
                }
            }
        }
        let (ln_in, ln_out) = (radii[0].ln(), radii[1].ln());
        let dims = [n1 + 1, n2 + 1, n3];
        let stride = [(dims[1] + 1) * (dims[2] + 1), dims[2] + 1];
        let mut sums = vec![[0u32; 1 + SMOOTH_LEVELS]; (dims[0] + 1) * stride[0]];
        let block_dims = dims.map(|n| n.div_ceil(BLOCK));
        let mut blocks = vec![0u8; block_dims.iter().product()];
        let (mut lit, mut outer) = (0, 0.0f64);
        for i in 0..dims[0] {
            // The centres it spans in X1 (ln r).
            let x1 = h.start[0] + (i as f64 - 0.5) * h.dx[0];
            let beyond = x1 + h.dx[0] <= ln_in || x1 >= ln_out;
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    // The centres i - 1 and i, the edge's beyond the grid.
                    let pair = |i: usize| pairs[(i * (n2 + 1) + j) * n3 + k];
                    let all = pair(i.saturating_sub(1)) & pair(i.min(n1 - 1));
                    let smooth_bits = ((1u8 << SMOOTH_LEVELS) - 1) * SMOOTH;
                    let here = u32::from(all & !smooth_bits == 0 && !beyond);
                    let mut values = [here; 1 + SMOOTH_LEVELS];
                    for (level, v) in values[1..].iter_mut().enumerate() {
                        *v &= u32::from(all & (SMOOTH << level) == 0);
                    }
                    lit += here as u64;
                    if here == 1 {
                        outer = outer.max((x1 + h.dx[0]).exp());
                    }
                    sums[(i + 1) * stride[0] + (j + 1) * stride[1] + k + 1] = values;
                    let block =
                        ((i / BLOCK) * block_dims[1] + j / BLOCK) * block_dims[2] + k / BLOCK;
                    for (bit, v) in values.into_iter().enumerate() {
                        blocks[block] |= (v as u8) << bit;
                    }
                }
            }
        }
        // Summed along k, then j, then i: [i+1][j+1][k+1] counts those at
        // or below (i, j, k).
        let add = |sums: &mut [[u32; 1 + SMOOTH_LEVELS]], from: usize, to: usize| {
            let below = sums[from];
            for (s, b) in sums[to].iter_mut().zip(below) {
                *s += b;
            }
        };
        for at in 1..sums.len() {
            if at % stride[1] != 0 {
                add(&mut sums, at - 1, at);
            }
        }
        for at in stride[1]..sums.len() {
            if at % stride[0] >= stride[1] {
                add(&mut sums, at - stride[1], at);
            }
        }
        for at in stride[0]..sums.len() {
            add(&mut sums, at - stride[0], at);
        }
        let centres = (0..n2)
            .map(|j| h.theta.parts(h.start[1] + (j as f64 + 0.5) * h.dx[1]))
            .collect();
        Darkness {
            dims,
            sums,
            blocks,
            block_dims,
            lit,
            outer,
            centres,
            theta: h.theta,
        }
    }

    /// How many dual cells with indices within the inclusive ranges are
    /// lit, and how many of those are not smooth at each level.
    fn count(
        &self,
        [(i0, i1), (j0, j1), (k0, k1)]: [(usize, usize); 3],
    ) -> [i64; 1 + SMOOTH_LEVELS] {
        let stride = [(self.dims[1] + 1) * (self.dims[2] + 1), self.dims[2] + 1];
        let (i1, j1, k1) = (i1 + 1, j1 + 1, k1 + 1);
        let mut n = [0i64; 1 + SMOOTH_LEVELS];
        for (a, b, c, sign) in [
            (i1, j1, k1, 1),
            (i0, j1, k1, -1),
            (i1, j0, k1, -1),
            (i1, j1, k0, -1),
            (i0, j0, k1, 1),
            (i0, j1, k0, 1),
            (i1, j0, k0, 1),
            (i0, j0, k0, -1),
        ] {
            let v = self.sums[a * stride[0] + b * stride[1] + c];
            for (n, v) in n.iter_mut().zip(v) {
                *n += sign * v as i64;
            }
        }
        n
    }

    /// The blocks' bits ORed over those about the dual cells within the
    /// inclusive ranges (in X3 one or two), or None past [`MOST_BLOCKS`].
    fn block_bits(
        &self,
        i: (usize, usize),
        j: (usize, usize),
        ks: [Option<(usize, usize)>; 2],
    ) -> Option<u8> {
        let [bi, bj] = [i, j].map(|(a, b)| (a / BLOCK, b / BLOCK));
        let ks = ks
            .into_iter()
            .flatten()
            .map(|(k0, k1)| (k0 / BLOCK, k1 / BLOCK));
        let along_k: usize = ks.clone().map(|(k0, k1)| k1 - k0 + 1).sum();
        if (bi.1 - bi.0 + 1) * (bj.1 - bj.0 + 1) * along_k > MOST_BLOCKS {
            return None;
        }
        let mut bits = 0;
        for (k0, k1) in ks {
            for a in bi.0..=bi.1 {
                for b in bj.0..=bj.1 {
                    let row = (a * self.block_dims[1] + b) * self.block_dims[2];
                    bits = self.blocks[row + k0..=row + k1]
                        .iter()
                        .fold(bits, |x, &y| x | y);
                }
            }
        }
        Some(bits)
    }

    /// The bytes it keeps a cell of the dump (its running counts; the
    /// blocks' bits are 1/64 of a byte).
    pub const BYTES_PER_CELL: usize = 4 * (1 + SMOOTH_LEVELS);

    /// How many cell centres along X2 lie at theta `th` or below at X1
    /// `x1`: the dual cell there as [`super::Grmhd::corner`] finds it
    /// (from -1), plus 1.
    fn row(&self, x1: f64, th: f64) -> usize {
        let w = self.theta.weight(x1);
        self.centres.partition_point(|&(g, d)| g + w * d <= th)
    }
}

/// What a box holds ([`Grmhd::census`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Census {
    /// Nothing inside it emits or absorbs: every point there is outside
    /// the grid, the emitting radii or the polar cut, or inside dark dual
    /// cells only.
    Dark,
    /// Lit dual cells, each smooth at this level or above
    /// ([`SMOOTH_LEVELS`]).
    Smooth(u8),
    /// Lit dual cells, some not smooth.
    Rough,
}

impl Grmhd {
    /// What the dual cells within `b` hold.
    pub fn census(&self, b: &Bounds) -> Census {
        let Some((i, j, ks)) = self.boxes(b) else {
            return Census::Dark;
        };
        // The blocks about the box first: none lit, or every lit one
        // smooth at the last level, answers it as the counts would (the
        // counts might yet find the box dark where the blocks hold lit
        // cells beside it: those rare boxes are walked, their dark
        // nodes found so).
        if let Some(bits) = self.darkness.block_bits(i, j, ks) {
            if bits & 1 == 0 {
                return Census::Dark;
            }
            if bits >> SMOOTH_LEVELS == 0 {
                return Census::Smooth(SMOOTH_LEVELS as u8);
            }
        }
        let mut n = [0; 1 + SMOOTH_LEVELS];
        for k in ks.into_iter().flatten() {
            for (n, c) in n.iter_mut().zip(self.darkness.count([i, j, k])) {
                *n += c;
            }
        }
        if n[0] == 0 {
            return Census::Dark;
        }
        match n[1..].iter().rposition(|&rough| rough == 0) {
            Some(level) => Census::Smooth(level as u8 + 1),
            None => Census::Rough,
        }
    }

    /// The dual cells within `b` as index ranges (in X3 one or two), or
    /// None where it lies outside the grid, the emitting radii or the
    /// polar cut.
    #[allow(clippy::type_complexity)]
    fn boxes(
        &self,
        b: &Bounds,
    ) -> Option<((usize, usize), (usize, usize), [Option<(usize, usize)>; 2])> {
        let h = &self.header;
        let s = &self.settings;
        let ((r0, r1), (th0, th1)) = (b.r, b.theta);
        if r1 <= self.radii[0] || r0 >= self.radii[1] {
            return None;
        }
        if th1 <= s.polar_cut || th0 >= PI - s.polar_cut {
            return None;
        }
        let (x1_lo, x1_hi) = (r0.max(1e-300).ln(), r1.ln());
        let end = |d: usize| h.start[d] + h.n[d] as f64 * h.dx[d];
        if x1_hi < h.start[0] || x1_lo >= end(0) {
            return None;
        }
        // The dual cells, as Grmhd::corner finds them (floor of the
        // offset from the first centre, from -1), shifted to start at 0;
        // margins of 1e-9 of a cell, and of 1e-12 rad, for round-off
        // between these bounds and the points' own coordinates.
        let index = |x: f64, up: bool| {
            let u = (x - h.start[0]) / h.dx[0] - 0.5 + if up { 1e-9 } else { -1e-9 };
            (u.floor() as i64).clamp(-1, h.n[0] as i64 - 1) + 1
        };
        let i = (index(x1_lo, false) as usize, index(x1_hi, true) as usize);
        // theta rises with X2 and, at a given X2, lies between its values
        // at the ends of an X1 range (FMKS blends two maps by a weight
        // monotone in X1): the rows at the range's two ends bound it.
        let d = &self.darkness;
        let (th0, th1) = (th0 - 1e-12, th1 + 1e-12);
        let j = (
            d.row(x1_lo, th0).min(d.row(x1_hi, th0)),
            d.row(x1_lo, th1).max(d.row(x1_hi, th1)),
        );
        let n3 = h.n[2];
        let all = (0, n3 - 1);
        let ks = match b.phi {
            Some((p0, p1)) if p1 - p0 < TAU => {
                let u0 = (p0.rem_euclid(TAU) - h.start[2]) / h.dx[2] - 0.5;
                let f0 = (u0 - 1e-9).floor() as i64;
                let f1 = (u0 + (p1 - p0) / h.dx[2] + 1e-9).floor() as i64;
                if f1 - f0 + 1 >= n3 as i64 {
                    [Some(all), None]
                } else {
                    let (k0, k1) = (
                        f0.rem_euclid(n3 as i64) as usize,
                        f1.rem_euclid(n3 as i64) as usize,
                    );
                    if k0 <= k1 {
                        [Some((k0, k1)), None]
                    } else {
                        [Some((k0, n3 - 1)), Some((0, k1))]
                    }
                }
            }
            _ => [Some(all), None],
        };
        Some((i, j, ks))
    }
}

#[cfg(test)]
mod tests {
    use super::super::torus::{Metric, TorusOptions, torus_dump};
    use super::super::{Electrons, Settings};
    use super::*;
    use crate::physics::kerr::{Kerr, Spheroidal};
    use crate::sampling::mix;

    /// The FMKS torus with its magnetised funnel, 64 x 32 x `n3`.
    fn funnel_torus(n3: usize) -> super::super::dump::Dump {
        let n = [64, 32, n3];
        torus_dump(
            &TorusOptions {
                metric: Metric::Fmks,
                n,
                funnel: true,
            },
            "test",
        )
    }

    /// `dump`'s plasma at T_i = T_e, cut at sigma 1 and beyond 40 M, about
    /// M87*'s mass.
    fn plasma(dump: &super::super::dump::Dump) -> Grmhd {
        let settings = Settings {
            m_unit: 1e29,
            electrons: Electrons::RHigh {
                r_high: 1.0,
                r_low: 1.0,
                beta_crit: 1.0,
            },
            sigma_cut: 1.0,
            r_max: 40.0,
            polar_cut: 1f64.to_radians(),
            flux: None,
        };
        Grmhd::new(dump, settings, 9.157_655e14).unwrap()
    }

    #[test]
    fn nothing_shines_in_a_box_called_dark() {
        // The FMKS torus with its magnetised funnel (cut at sigma 1),
        // lopsided in density and with a third of its azimuths' field
        // zeroed: boxes of every size about random points, and in each box
        // found dark, 24 random points at which the plasma gives no gas
        // (Grmhd::state None, for photons of several directions): their
        // centres even in the native coordinates, half of them within a
        // cell's size, so that the edges of the cut are met often. Both
        // answers common enough to matter; the lit dual cells a fraction.
        let mut dump = funnel_torus(6);
        let h = dump.header.clone();
        let np = h.n_prim;
        let super::super::dump::Prims::Memory(prims) = &mut dump.prims else {
            unreachable!("the torus is built in memory")
        };
        for (c, cell) in prims.chunks_mut(np).enumerate() {
            let k = c % h.n[2];
            cell[0] *= 1.0 + 0.5 * (k as f64).cos();
            if k < 2 {
                cell[5..8].fill(0.0);
            }
        }
        let g = plasma(&dump);
        let total = (h.n[0] + 1) * (h.n[1] + 1) * h.n[2];
        assert!(
            g.darkness.lit > 0 && (g.darkness.lit as usize) < total * 9 / 10,
            "{} of {total}",
            g.darkness.lit
        );
        let mut state = 1u64;
        let mut next = || {
            state += 1;
            (mix(state) >> 11) as f64 / (1u64 << 53) as f64
        };
        let kerr = Kerr::new(h.a);
        let (mut dark, mut lit) = (0, 0);
        for n in 0..40_000 {
            // Centres even in the native coordinates (where the cells
            // are), out to 50 M; half the boxes within a cell's size.
            let x1 = h.start[0] + 50f64.ln() * next();
            let x2 = h.start[1] + h.n[1] as f64 * h.dx[1] * next();
            let (r, th, phi) = (x1.exp(), h.theta.at(x1, x2).0, TAU * next());
            let size = if n % 2 == 0 { 1.0 } else { 8.0 };
            let (dr, dth, dphi) = (
                r * h.dx[0] * size * next(),
                0.05 * size * next(),
                h.dx[2] * size * next(),
            );
            let b = Bounds {
                r: (r, r + dr),
                theta: (th, (th + dth).min(std::f64::consts::PI)),
                phi: Some((phi, phi + dphi)),
                travel: [dr, dth, dphi],
            };
            let inside = |next: &mut dyn FnMut() -> f64| Spheroidal {
                r: b.r.0 + dr * next(),
                th: b.theta.0 + (b.theta.1 - b.theta.0) * next(),
                phi: phi + dphi * next(),
            };
            if g.census(&b) != Census::Dark {
                lit += 1;
                continue;
            }
            dark += 1;
            for _ in 0..24 {
                let p = inside(&mut next);
                let x = kerr.cartesian(p);
                let cos = p.th.cos();
                for k in [(0.0, -1.0, 0.0), (2.0, 0.5, 0.1), (-3.0, 0.2, -0.3)] {
                    let gas = g.state((p.r, cos), x, k);
                    assert!(gas.is_none(), "{p:?} in {b:?}: {gas:?}");
                }
            }
        }
        assert!(dark > 5000 && lit > 5000, "{dark} dark, {lit} lit");
    }

    #[test]
    fn smooth_boxes_lie_well_below_the_cut() {
        // The FMKS torus with its funnel as generated: in boxes called
        // smooth (longer pieces there), every point where the
        // plasma shines has all the cells about it below a tenth of the
        // magnetisation cut; smooth boxes are common, and rarer than lit
        // ones (the funnel's edge, the torus's surface are rough).
        let dump = funnel_torus(4);
        let h = dump.header.clone();
        let g = plasma(&dump);
        let kerr = Kerr::new(h.a);
        let mut state = 7u64;
        let mut next = || {
            state += 1;
            (mix(state) >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut lit, mut smooth, mut shining) = (0, 0, 0);
        for _ in 0..20_000 {
            let x1 = h.start[0] + 40f64.ln() * next();
            let x2 = h.start[1] + h.n[1] as f64 * h.dx[1] * next();
            let (r, th, phi) = (x1.exp(), h.theta.at(x1, x2).0, TAU * next());
            let (dr, dth, dphi) = (r * h.dx[0] * 2.0 * next(), 0.1 * next(), h.dx[2] * next());
            let b = Bounds {
                r: (r, r + dr),
                theta: (th, (th + dth).min(std::f64::consts::PI)),
                phi: Some((phi, phi + dphi)),
                travel: [dr, dth, dphi],
            };
            let census = g.census(&b);
            if census == Census::Dark {
                continue;
            }
            lit += 1;
            if census == Census::Rough {
                continue;
            }
            smooth += 1;
            for _ in 0..8 {
                let p = Spheroidal {
                    r: r + dr * next(),
                    th: b.theta.0 + (b.theta.1 - b.theta.0) * next(),
                    phi: phi + dphi * next(),
                };
                let (x, cos) = (kerr.cartesian(p), p.th.cos());
                if g.state((p.r, cos), x, (0.0, -1.0, 0.0)).is_some() {
                    shining += 1;
                    let level = g.cut_level((p.r, cos), x);
                    assert!(level <= 0.1 + 1e-12, "{p:?} in {b:?}: {level}");
                }
            }
        }
        assert!(
            smooth > 500 && smooth < lit && shining > 1000,
            "{smooth} smooth of {lit} lit, {shining} points shining"
        );
    }
}
