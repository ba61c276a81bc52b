//! A GRMHD simulation's snapshot as a medium (`kind = "grmhd"`): an
//! iharm3d-format dump's plasma in physical units, with the EHT's
//! conventions as ipole (`model/iharm`) has them.
//!
//! - Units from the hole's mass and `m_unit`, the simulation's mass unit:
//!   L = G M / c^2, rho_unit = m_unit / L^3, B_unit = c sqrt(4 pi
//!   rho_unit), n_e = rho rho_unit / (m_p + m_e).
//! - Electrons by the R-high/R-low prescription (Moscibrodzka, Falcke and
//!   Shiokawa 2016): T_i/T_e = R = (R_high b^2 + R_low) / (1 + b^2), b =
//!   beta / beta_crit, beta = p_gas / p_mag; or the dump's own electron
//!   entropy. Theta_e is found per cell and floored at 1e-3 (unmagnetised
//!   cells take the floor, as ipole's do).
//! - Cuts: nothing emits or absorbs where sigma = b^2 / rho > `sigma_cut`
//!   (found along the ray), within `polar_cut` of the axis, beyond `r_max`
//!   (or the grid) or inside max(1, r_in).
//! - Cell-centred values (rho, Theta_e, |b|, sigma and the primitives'
//!   velocity and field) are interpolated trilinearly in the native
//!   coordinates, across the poles and the azimuth's seam as ipole's ghost
//!   cells do; the four-vectors are built from the interpolated
//!   primitives at each point.
//! - Thermal synchrotron at the pitch angle between the photon and the
//!   field in the fluid's frame (Leung et al. 2011, ipole's unpolarised
//!   fit), absorbed by Kirchhoff's law.

pub mod coords;
pub mod dark;
pub mod dump;
pub mod fit;
pub mod fluid;
pub mod torus;

use super::synchrotron::Pitched;
use super::{Gas, Plasma};
use crate::units::cgs::{ELECTRON_MASS, LIGHT, PROTON_MASS};
use dark::Bounds;
use dump::{B1, Dump, DumpError, Header, KEL, RHO, U1, UU};
use fluid::{KsMetric, four_vectors, ks_to_bl, native_four_vectors, to_ks};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::PathBuf;
use std::sync::Arc;

/// The least magnetisation, as ipole floors it.
const SIGMA_FLOOR: f64 = 1e-40;

/// The coldest electrons (Theta_e), as ipole floors them.
pub const THETA_E_FLOOR: f64 = 1e-3;

/// How many cells a piece spans. Between cell centres the values are
/// trilinear, and a piece's two Gauss-Legendre nodes follow them closely:
/// on the torus (80x80, 230 GHz) pieces of two cells move the image by a
/// normalised mean squared error of 8e-7 and the flux by 6e-5 from pieces
/// of one, four cells by 3e-6 and 2e-4, at 1.5 and 1.9 times the speed.
pub const CELLS_PER_PIECE: f64 = 2.0;

/// The values kept per cell, interpolated between cell centres.
pub const FIELDS: usize = 10;
/// A cell's values, in single precision: half the memory and the memory
/// traffic of doubles, the interpolation still in double (a value's
/// relative round-off 6e-8, far below the images' tolerances).
pub type Cell = [f32; FIELDS];
const F_RHO: usize = 0;
const F_THETA_E: usize = 1;
const F_B: usize = 2;
const F_SIGMA: usize = 3;
const F_U: usize = 4;
const F_B1: usize = 7;

/// How the electrons' temperature is found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Electrons {
    /// T_i / T_e from the plasma beta (Moscibrodzka et al. 2016).
    RHigh {
        r_high: f64,
        r_low: f64,
        beta_crit: f64,
    },
    /// The dump's own electron entropy (column KEL): Theta_e = (m_p /
    /// m_e) KEL rho^(gam_e - 1).
    Dump,
}

/// The physical settings of a dump's plasma (`[medium]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The simulation's mass unit (g).
    pub m_unit: f64,
    pub electrons: Electrons,
    /// Above this magnetisation b^2 / rho the plasma is empty.
    pub sigma_cut: f64,
    /// No emission beyond this radius (M).
    pub r_max: f64,
    /// No emission within this angle (rad) of the axis.
    pub polar_cut: f64,
    /// The total flux density (Jy, at the first observed frequency) to
    /// fit `m_unit` to before rendering, if any.
    pub flux: Option<f64>,
}

/// A dump's plasma, ready to be sampled along rays.
#[derive(Clone)]
pub struct Grmhd {
    pub path: PathBuf,
    pub header: Header,
    pub settings: Settings,
    /// FIELDS values per cell, X3 fastest; shared by copies that differ
    /// only in m_unit.
    cells: Arc<Vec<Cell>>,
    /// Centimetres per M.
    cm_per_m: f64,
    /// n_e per unit of code density (cm^-3), and Gauss per code field.
    ne_unit: f64,
    b_unit: f64,
    /// The accretion rate in code units (ipole's dMact, positive inward).
    code_mdot: f64,
    /// Where the plasma may emit: radii (M) and the polar cut.
    radii: [f64; 2],
    /// theta's inverse.
    inverse: Arc<coords::Inverse>,
    /// The largest magnetisation of any cell.
    max_sigma: f64,
    /// Where nothing can shine ([`dark::Darkness`]).
    darkness: Arc<dark::Darkness>,
}

impl std::fmt::Debug for Grmhd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Grmhd")
            .field("path", &self.path)
            .field("header", &self.header)
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

/// The grid's cells' coordinates.
#[inline]
fn centre(h: &Header, i: usize, j: usize, k: usize) -> [f64; 3] {
    [
        h.start[0] + (i as f64 + 0.5) * h.dx[0],
        h.start[1] + (j as f64 + 0.5) * h.dx[1],
        h.start[2] + (k as f64 + 0.5) * h.dx[2],
    ]
}

impl Grmhd {
    /// The plasma of `dump` about a hole of `cm_per_m` cm per M; a dump
    /// whose cells are refused ([`Dump::rows`]) gives the reason.
    pub fn new(dump: &Dump, settings: Settings, cm_per_m: f64) -> Result<Grmhd, DumpError> {
        let h = &dump.header;
        let [n1, n2, n3] = h.n;
        let mut cells = vec![[0.0f32; FIELDS]; n1 * n2 * n3];
        let mut code_mdot = 0.0;
        // ipole's rate: rho u^1 sqrt(-g) over the shells of the 21
        // innermost radial cells, averaged.
        let shells = n1.min(21);
        dump.rows(|i, row| {
            for j in 0..n2 {
                let [x1, x2, _] = centre(h, i, j, 0);
                let r = x1.exp();
                let (th, d1, d2) = h.theta.at(x1, x2);
                let (sin, cos) = th.sin_cos();
                let gdet = (r * r + h.a * h.a * cos * cos) * sin.abs() * r * d2;
                let metric = KsMetric::new(h.a, r, (sin, cos));
                let ks = |v: &[f64]| to_ks(r, (d1, d2), [v[0], v[1], v[2]]);
                for k in 0..n3 {
                    let p = &row[(j * n3 + k) * h.n_prim..][..h.n_prim];
                    let (u, _, bsq) = four_vectors(&metric, ks(&p[U1..]), ks(&p[B1..]));
                    let mut c = [0.0; FIELDS];
                    c[F_RHO] = p[RHO];
                    c[F_THETA_E] = theta_e(h, &settings.electrons, p, bsq);
                    c[F_B] = bsq.max(0.0).sqrt();
                    c[F_SIGMA] = (bsq / p[RHO]).max(0.0);
                    c[F_U..F_U + 3].copy_from_slice(&p[U1..U1 + 3]);
                    c[F_B1..F_B1 + 3].copy_from_slice(&p[B1..B1 + 3]);
                    cells[(i * n2 + j) * n3 + k] = c.map(|x| x as f32);
                    if i < shells {
                        code_mdot -= gdet * p[RHO] * u[1] / r;
                    }
                }
            }
        })?;
        code_mdot *= h.dx[1] * h.dx[2] / shells as f64;
        let max_sigma = cells
            .iter()
            .map(|c| f64::from(c[F_SIGMA]))
            .fold(0.0, f64::max);
        let radii = [h.r_in.max(1.0), settings.r_max.min(h.r_out)];
        let darkness = Arc::new(dark::Darkness::new(h, &cells, settings.sigma_cut, radii));
        let mut g = Grmhd {
            path: dump.path.clone(),
            header: h.clone(),
            settings,
            cells: Arc::new(cells),
            cm_per_m,
            ne_unit: 0.0,
            b_unit: 0.0,
            code_mdot,
            radii,
            max_sigma,
            darkness,
            inverse: Arc::new(coords::Inverse::new(
                h.theta,
                (h.start[0], h.start[0] + n1 as f64 * h.dx[0]),
            )),
        };
        g.set_m_unit(settings.m_unit);
        Ok(g)
    }

    /// The same plasma at another mass unit (g): n_e ~ m_unit, B ~
    /// m_unit^1/2, Theta_e unchanged.
    pub fn set_m_unit(&mut self, m_unit: f64) {
        self.settings.m_unit = m_unit;
        let rho_unit = m_unit / self.cm_per_m.powi(3);
        self.ne_unit = rho_unit / (PROTON_MASS + ELECTRON_MASS);
        self.b_unit = LIGHT * (4.0 * PI * rho_unit).sqrt();
    }

    /// The accretion rate through the inner grid (g/s), as ipole reports
    /// it: rho u^r over the 21 innermost radial shells, averaged.
    pub fn accretion_rate(&self) -> f64 {
        self.code_mdot * self.settings.m_unit / (self.cm_per_m / LIGHT)
    }

    /// The radii (M) between which the plasma may emit.
    pub fn radii(&self) -> (f64, f64) {
        (self.radii[0], self.radii[1])
    }

    /// Beyond this radius (M) nothing shines: the emitting radii's outer
    /// one, or nearer where the cells that can shine end sooner (a torus
    /// whose field ends inside it; [`dark::Darkness`]).
    pub fn extent(&self) -> f64 {
        self.radii[1].min(self.darkness.outer)
    }

    /// Where the plasma ends abruptly: the emitting region's radii.
    pub fn surfaces(&self) -> &[f64] {
        &self.radii
    }

    /// One line for `info`.
    pub fn describe(&self) -> String {
        let h = &self.header;
        let s = &self.settings;
        let electrons = match s.electrons {
            Electrons::RHigh {
                r_high,
                r_low,
                beta_crit,
            } => format!("R_high {r_high}, R_low {r_low}, beta_crit {beta_crit}"),
            Electrons::Dump => "electrons from the dump's entropy".into(),
        };
        let fit = s
            .flux
            .map_or(String::new(), |f| format!(" (to be fitted to {f} Jy)"));
        format!(
            "grmhd {} ({} {}x{}x{}, a {}, t {} M): m_unit {:e} g{fit}, {electrons}, sigma_cut {}, emitting r {:.4} to {} M beyond {:.2} deg of the axis; thermal synchrotron at the pitch angle (Leung et al. 2011); accretion rate {:.4e} solar masses a year",
            self.path.display(),
            h.metric,
            h.n[0],
            h.n[1],
            h.n[2],
            h.a,
            h.t,
            s.m_unit,
            s.sigma_cut,
            self.radii[0],
            self.radii[1],
            s.polar_cut.to_degrees(),
            self.accretion_rate() / (crate::units::SOLAR_MASS * 1e3) * crate::units::YEAR
        )
    }

    /// The native coordinates of (r, theta) and the Kerr-Schild point
    /// `p`, with d theta / d X1 and d theta / d X2 there, or None outside
    /// the grid (as ipole's `X_in_domain`).
    #[inline]
    fn native(&self, r: f64, th: f64, p: DVec3) -> Option<([f64; 3], (f64, f64))> {
        let h = &self.header;
        let x1 = r.ln();
        let ends = |k: usize, x: f64| x >= h.start[k] && x < h.start[k] + h.n[k] as f64 * h.dx[k];
        if !ends(0, x1) {
            return None;
        }
        let (x2, d1, d2) = self.inverse.x2(x1, th);
        if !ends(1, x2) {
            return None;
        }
        // Within (-2 pi, pi]: into [0, 2 pi) as rem_euclid would, without
        // its division.
        let phi = p.y.atan2(p.x) - h.a.atan2(r);
        let phi = if phi < 0.0 { phi + TAU } else { phi };
        Some(([x1, x2, phi], (d1, d2)))
    }

    /// The cell values interpolated at native `x`, trilinearly between
    /// the cell centres about it (ipole's `interp_scalar` with its ghost
    /// cells: the radial edges extended, the poles crossed to the
    /// opposite azimuth, the azimuth periodic).
    #[inline]
    fn interpolate(&self, x: [f64; 3]) -> [f64; FIELDS] {
        let (at, del) = self.corner(x);
        let mut out = [0.0; FIELDS];
        let [n1, n2, n3] = self.header.n;
        if at[0] >= 0 && at[0] + 1 < n1 as i64 && at[1] >= 0 && at[1] + 1 < n2 as i64 {
            // Inside the grid (all but the ghost cells): the eight cells'
            // indices directly, the azimuth wrapped once.
            let k0 = at[2].rem_euclid(n3 as i64) as usize;
            let ks = [k0, if k0 + 1 == n3 { 0 } else { k0 + 1 }];
            let base = [at[0] as usize * n2, at[1] as usize];
            let w = [
                [1.0 - del[0], del[0]],
                [1.0 - del[1], del[1]],
                [1.0 - del[2], del[2]],
            ];
            for corner in 0..8 {
                let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
                let weight = w[0][o[0]] * w[1][o[1]] * w[2][o[2]];
                if weight == 0.0 {
                    continue;
                }
                let v = &self.cells[(base[0] + o[0] * n2 + base[1] + o[1]) * n3 + ks[o[2]]];
                for f in 0..FIELDS {
                    out[f] += weight * f64::from(v[f]);
                }
            }
            return out;
        }
        for corner in 0..8 {
            let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
            let w = (0..3)
                .map(|d| if o[d] == 1 { del[d] } else { 1.0 - del[d] })
                .product::<f64>();
            if w == 0.0 {
                continue;
            }
            let v = self.ghost(
                at[0] + o[0] as i64,
                at[1] + o[1] as i64,
                at[2] + o[2] as i64,
            );
            for f in 0..FIELDS {
                out[f] += w * v[f];
            }
        }
        out
    }

    /// One of the cell values (`field`) interpolated at native `x`, as
    /// [`Grmhd::interpolate`].
    #[inline]
    fn interpolate_one(&self, x: [f64; 3], field: usize) -> f64 {
        let (at, del) = self.corner(x);
        let mut out = 0.0;
        for corner in 0..8 {
            let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
            let w = (0..3)
                .map(|d| if o[d] == 1 { del[d] } else { 1.0 - del[d] })
                .product::<f64>();
            if w != 0.0 {
                out += w * self.ghost(
                    at[0] + o[0] as i64,
                    at[1] + o[1] as i64,
                    at[2] + o[2] as i64,
                )[field];
            }
        }
        out
    }

    /// The cell centre below native `x` (ghost indices from -1) and the
    /// offset from it in cells, each within [0, 1] (ipole's
    /// `Xtoijk_ghost`).
    #[inline]
    fn corner(&self, x: [f64; 3]) -> ([i64; 3], [f64; 3]) {
        let h = &self.header;
        let mut at = [0i64; 3];
        let mut del = [0.0; 3];
        for d in 0..3 {
            let u = (x[d] - h.start[d]) / h.dx[d] - 0.5;
            let i = (u.floor() as i64).clamp(-1, h.n[d] as i64 - 1);
            at[d] = i;
            del[d] = (u - i as f64).clamp(0.0, 1.0);
        }
        (at, del)
    }

    /// A cell by index, the indices allowed one beyond each edge (ipole's
    /// ghost cells).
    #[inline]
    fn ghost(&self, i: i64, j: i64, k: i64) -> [f64; FIELDS] {
        let [n1, n2, n3] = self.header.n.map(|n| n as i64);
        let i = i.clamp(0, n1 - 1);
        let k = k.rem_euclid(n3);
        let cell = |j: i64, k: i64| self.cells[((i * n2 + j) * n3 + k) as usize].map(f64::from);
        if (0..n2).contains(&j) {
            return cell(j, k);
        }
        // Across a pole: the cell on the other side, half a turn round.
        let j = j.clamp(0, n2 - 1);
        if n3 % 2 == 0 {
            cell(j, (k + n3 / 2) % n3)
        } else {
            let (a, b) = (
                cell(j, (k + (n3 - 1) / 2) % n3),
                cell(j, (k + (n3 + 1) / 2) % n3),
            );
            std::array::from_fn(|f| 0.5 * (a[f] + b[f]))
        }
    }

    /// Whether any of its cells is cut for its magnetisation.
    pub fn has_cut(&self) -> bool {
        self.max_sigma > self.settings.sigma_cut
    }

    /// The magnetisation at (r, cos theta), the point `p`, over
    /// `sigma_cut`: the plasma is cut where it is above 1 (0 outside the
    /// grid).
    #[inline]
    pub fn cut_level(&self, (r, cos): (f64, f64), p: DVec3) -> f64 {
        let th = cos.clamp(-1.0, 1.0).acos();
        match self.native(r, th, p) {
            Some((x, _)) => self.interpolate_one(x, F_SIGMA) / self.settings.sigma_cut,
            None => 0.0,
        }
    }

    /// The plasma as the renderer sees it at Boyer-Lindquist (r, theta)
    /// and Kerr-Schild azimuth `phi`, before the cuts: None outside the
    /// grid.
    pub fn probe(&self, r: f64, th: f64, phi: f64) -> Option<Probe> {
        let a = self.header.a;
        let p = crate::physics::kerr::Kerr::new(a).cartesian(crate::physics::kerr::Spheroidal {
            r,
            th,
            phi,
        });
        let (x, d) = self.native(r, th, p)?;
        let v = self.interpolate(x);
        let (s, c) = th.sin_cos();
        let (u, b, _) = native_four_vectors(a, r, (s.max(1e-24), c), d, primitives(&v));
        Some(Probe {
            native: x,
            n_e: v[F_RHO] * self.ne_unit,
            theta_e: v[F_THETA_E],
            b_gauss: v[F_B] * self.b_unit,
            // ipole's floor (its cells', here the interpolated value's:
            // the same within the floor).
            sigma: v[F_SIGMA].max(SIGMA_FLOOR),
            u,
            b: b.map(|x| x * self.b_unit),
        })
    }

    /// Centimetres per M: the length unit.
    pub fn cm_per_m(&self) -> f64 {
        self.cm_per_m
    }

    /// The pieces' scale (M) at (r, cos theta): [`CELLS_PER_PIECE`] times
    /// the narrowest width of the cell there.
    pub fn scale(&self, r: f64, cos: f64) -> f64 {
        let h = &self.header;
        let x1 = r.max(1e-3).ln();
        let d2 = self.inverse.slope(x1, cos.clamp(-1.0, 1.0).acos());
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let widths = [r * h.dx[0], r * d2 * h.dx[1], r * sin.max(0.05) * h.dx[2]];
        CELLS_PER_PIECE * widths.into_iter().fold(f64::INFINITY, f64::min)
    }

    /// How many cells a stretch within `b` crosses along the index it
    /// crosses most; None where its azimuth is not known and the grid has
    /// more than one cell in it.
    pub fn cells(&self, b: &Bounds) -> Option<f64> {
        let h = &self.header;
        if b.phi.is_none() && h.n[2] > 1 {
            return None;
        }
        let [r, th, phi] = b.travel;
        let (r0, r1) = (b.r.0.max(1e-3), b.r.1.max(1e-3));
        // The cells are narrowest in theta where d theta / d X2 is least:
        // at the range's ends or, where it holds it, the midplane's.
        let mut slope = f64::INFINITY;
        for x1 in [r0.ln(), r1.ln()] {
            for t in [b.theta.0, b.theta.1, FRAC_PI_2] {
                if t >= b.theta.0 && t <= b.theta.1 {
                    slope = slope.min(self.inverse.slope(x1, t));
                }
            }
        }
        Some(
            (r / (r0 * h.dx[0]))
                .max(th / (slope * h.dx[1]))
                .max(phi / h.dx[2]),
        )
    }

    /// The plasma at (r, cos theta), the Kerr-Schild point `p` (M), seen
    /// by a photon of unit energy at infinity with angular momentum `lz`,
    /// dr/dlambda `k_r` and d(cos theta)/dlambda `k_cos`; None where
    /// nothing emits or absorbs.
    pub fn state(
        &self,
        (r, cos): (f64, f64),
        p: DVec3,
        (lz, k_r, k_cos): (f64, f64, f64),
    ) -> Option<Gas> {
        let s = &self.settings;
        if !(r > self.radii[0] && r < self.radii[1]) {
            return None;
        }
        let th = cos.clamp(-1.0, 1.0).acos();
        if !(th > s.polar_cut && th < PI - s.polar_cut) {
            return None;
        }
        let (x, d) = self.native(r, th, p)?;
        let c = self.interpolate(x);
        if c[F_SIGMA] > s.sigma_cut {
            return None;
        }
        let ne = c[F_RHO] * self.ne_unit;
        if !(ne > 0.0) {
            return None;
        }
        let h = &self.header;
        let sin = (1.0 - cos * cos).max(1e-24).sqrt();
        let (u, b, bsq) = native_four_vectors(h.a, r, (sin, cos), d, primitives(&c));
        let (u, b) = (ks_to_bl(h.a, r, u), ks_to_bl(h.a, r, b));
        // The photon's covariant Boyer-Lindquist momentum: k_t = -1, k_r
        // = Sigma / Delta dr/dlambda, k_theta = Sigma dtheta/dlambda.
        let sigma = r * r + h.a * h.a * cos * cos;
        let delta = r * r - 2.0 * r + h.a * h.a;
        let k = [-1.0, sigma / delta * k_r, -sigma * k_cos / sin, lz];
        let dot = |v: [f64; 4]| k[0] * v[0] + k[1] * v[1] + k[2] * v[2] + k[3] * v[3];
        let ratio = -dot(u);
        if !(ratio > 0.0) {
            return None;
        }
        let b_len = bsq.abs().sqrt();
        let sin_pitch = if b_len == 0.0 {
            1.0
        } else {
            let mu = (dot(b) / (ratio * b_len)).clamp(-1.0, 1.0);
            (1.0 - mu * mu).sqrt()
        };
        Some(Gas {
            ratio,
            plasma: Plasma::Pitched(Pitched::new(
                ne,
                c[F_THETA_E],
                c[F_B] * self.b_unit,
                sin_pitch,
            )?),
        })
    }
}

crate::wgsl::gpu_block! {
    /// A snapshot for the GPU (grmhd.wgsl): at the head of its words in
    /// the tables, then theta's inverse (`inverse_at`, rows of
    /// coords::THETAS from X1 `inverse_x1` by `inverse_step`) and the
    /// cells (`cells_at`, FIELDS each, X3 fastest); indices relative to
    /// the block, counts and indices exact in f32 (below 2^24).
    GrmhdBlock {
        n1,
        n2,
        n3,
        start1,
        start2,
        start3,
        dx1,
        dx2,
        dx3,
        /// 0 EKS, 1 MKS, 2 BHAC_MKS, 3 FMKS.
        theta_kind,
        hslope,
        poly_xt,
        poly_alpha,
        mks_smooth,
        poly_norm,
        r_min,
        r_max,
        polar_cut,
        sigma_cut,
        ne_unit,
        b_unit,
        inverse_rows,
        inverse_x1,
        inverse_step,
        inverse_at,
        cells_at,
        /// 1 where some cell is cut for its magnetisation.
        sharp,
    }
}

impl Grmhd {
    /// Its words for the GPU's tables: the block, theta's inverse and the
    /// cells, in f32.
    pub fn gpu_tables(&self) -> Vec<f32> {
        use crate::wgsl::Block;
        let h = &self.header;
        let ((x1, step, rows), inverse) = self.inverse.table();
        let head = GrmhdBlock::FIELDS.len();
        let (theta_kind, hslope, poly) = match h.theta {
            coords::Theta::Exponential => (0.0, 0.0, (0.0, 0.0, 0.0, 0.0)),
            coords::Theta::Modified { hslope } => (1.0, hslope, (0.0, 0.0, 0.0, 0.0)),
            coords::Theta::Bhac { hslope } => (2.0, hslope, (0.0, 0.0, 0.0, 0.0)),
            coords::Theta::Funky {
                hslope,
                poly_xt,
                poly_alpha,
                mks_smooth,
                poly_norm,
                ..
            } => (
                3.0,
                hslope,
                (poly_xt, poly_alpha as f64, mks_smooth, poly_norm),
            ),
        };
        let f = |x: f64| x as f32;
        let block = GrmhdBlock {
            n1: h.n[0] as f32,
            n2: h.n[1] as f32,
            n3: h.n[2] as f32,
            start1: f(h.start[0]),
            start2: f(h.start[1]),
            start3: f(h.start[2]),
            dx1: f(h.dx[0]),
            dx2: f(h.dx[1]),
            dx3: f(h.dx[2]),
            theta_kind,
            hslope: f(hslope),
            poly_xt: f(poly.0),
            poly_alpha: f(poly.1),
            mks_smooth: f(poly.2),
            poly_norm: f(poly.3),
            r_min: f(self.radii[0]),
            r_max: f(self.radii[1]),
            polar_cut: f(self.settings.polar_cut),
            sigma_cut: f(self.settings.sigma_cut),
            ne_unit: f(self.ne_unit),
            b_unit: f(self.b_unit),
            inverse_rows: rows as f32,
            inverse_x1: f(x1),
            inverse_step: f(step),
            inverse_at: head as f32,
            cells_at: (head + inverse.len()) as f32,
            sharp: if self.has_cut() { 1.0 } else { 0.0 },
        };
        let mut words = Vec::with_capacity(head + inverse.len() + self.cells.len() * FIELDS);
        words.extend_from_slice(block.words());
        words.extend(inverse.iter().map(|&x| x as f32));
        words.extend(self.cells.iter().flatten());
        words
    }
}

/// The plasma at a point ([`Grmhd::probe`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// The native coordinates X1, X2, X3.
    pub native: [f64; 3],
    /// Electron density (cm^-3), Theta_e, |b| (G) and sigma = b^2 / rho,
    /// interpolated from the cells' values.
    pub n_e: f64,
    pub theta_e: f64,
    pub b_gauss: f64,
    pub sigma: f64,
    /// u^mu and b^mu (G), Kerr-Schild (t, r, theta, phi), built from the
    /// interpolated primitives.
    pub u: [f64; 4],
    pub b: [f64; 4],
}

/// The velocity and field primitives among interpolated values.
#[inline]
fn primitives(v: &[f64; FIELDS]) -> ([f64; 3], [f64; 3]) {
    (
        [v[F_U], v[F_U + 1], v[F_U + 2]],
        [v[F_B1], v[F_B1 + 1], v[F_B1 + 2]],
    )
}

/// A cell's electron temperature (Theta_e), floored at [`THETA_E_FLOOR`].
fn theta_e(h: &Header, electrons: &Electrons, p: &[f64], bsq: f64) -> f64 {
    let mass_ratio = PROTON_MASS / ELECTRON_MASS;
    let t = match *electrons {
        Electrons::RHigh {
            r_high,
            r_low,
            beta_crit,
        } => {
            // beta = p_gas / p_mag = u (gam - 1) / (b^2 / 2). An
            // unmagnetised cell (no synchrotron light either way) takes
            // the floor, as ipole's does: its R of infinite beta is
            // inf / inf there, NaN, which its fmax floors.
            if !(bsq > 0.0) {
                return THETA_E_FLOOR;
            }
            let beta = p[UU] * (h.gam - 1.0) / (0.5 * bsq) / beta_crit;
            let b2 = beta * beta;
            let ratio = if b2.is_finite() {
                (r_high * b2 + r_low) / (1.0 + b2)
            } else {
                r_high
            };
            let (ge, gp) = (h.gam_e - 1.0, h.gam_p - 1.0);
            mass_ratio * ge * gp / (gp + ge * ratio) * p[UU] / p[RHO]
        }
        Electrons::Dump => mass_ratio * p[KEL] * p[RHO].powf(h.gam_e - 1.0),
    };
    if t.is_finite() {
        t.max(THETA_E_FLOOR)
    } else {
        THETA_E_FLOOR
    }
}
