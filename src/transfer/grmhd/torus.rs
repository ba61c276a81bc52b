//! The standard initial state of GRMHD runs as a dump (`blackhole torus`):
//! Fishbone and Moncrief's (1976) torus in hydrostatic equilibrium about a
//! Kerr hole, threaded by a single poloidal loop of field, with the EHT
//! GRMHD code comparison's parameters (Porth et al. 2019: a = 0.9375,
//! r_in = 6, r_max = 12, gam = 5/3, kappa = 1e-3, beta_min = 100, MKS
//! hslope 0.3, outer radius 50), in iharm3d's format, as iharm3d's
//! `prob/torus` sets it up at t = 0, without its random jitter.
//!
//! Outside the torus the gas sits at iharm3d's geometric floors, at rest
//! to the normal observer. The optional funnel adds a vertical field
//! along the axis with hot, tenuous gas (sigma = b^2 / rho up to 10, u /
//! rho = (sigma / 10)^2): what the EHT's sigma cut is for.

use super::coords::Theta;
use super::dump::{Header, write};
use super::fluid::{KsMetric, bl_to_ks, native_four_vectors, relative_velocity};
use std::path::Path;

/// The comparison's torus.
pub const SPIN: f64 = 0.9375;
const R_IN: f64 = 6.0;
const R_MAX: f64 = 12.0;
const GAM: f64 = 5.0 / 3.0;
const KAPPA: f64 = 1e-3;
const BETA: f64 = 100.0;
const HSLOPE: f64 = 0.3;
const R_OUT: f64 = 50.0;
/// Magnetisation of the funnel's gas.
const FUNNEL_SIGMA: f64 = 10.0;
/// The funnel's field strength on the axis (code units).
const FUNNEL_FIELD: f64 = 0.01;

/// Which native coordinates to write.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Metric {
    Mks,
    Fmks,
}

/// What `blackhole torus` writes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TorusOptions {
    pub metric: Metric,
    pub n: [usize; 3],
    pub funnel: bool,
}

/// The Fishbone-Moncrief specific angular momentum u_t u^phi of the
/// torus's pressure maximum at `r` (their equation 3.8, in a form that
/// holds for either sense of spin).
fn angular_momentum(a: f64, r: f64) -> f64 {
    let sr = r.sqrt();
    let w = a * a - 2.0 * a * sr + r * r;
    let root = (2.0 * a * sr + (r - 3.0) * r).sqrt();
    let first = -2.0 * a * r * w / root;
    let second = (a + (r - 2.0) * sr) * (r.powi(3) + a * a * (2.0 + r))
        / (1.0 + 2.0 * a / r.powf(1.5) - 3.0 / r).sqrt();
    w * (first + second) / (r.powi(3) * root * (a * a + (r - 2.0) * r))
}

/// ln h, the log of the specific enthalpy (less its value at the inner
/// edge) of the torus of angular momentum `l` at (r, theta), and u^phi
/// (Boyer-Lindquist) of its gas there.
fn enthalpy(a: f64, l: f64, r: f64, th: f64) -> (f64, f64) {
    let part = |r: f64, th: f64| {
        let (s, c) = th.sin_cos();
        let delta = r * r - 2.0 * r + a * a;
        let big_a = (r * r + a * a).powi(2) - delta * a * a * s * s;
        let sigma = r * r + a * a * c * c;
        let e2chi = sigma * sigma * delta / (big_a * big_a * s * s);
        let root = (1.0 + 4.0 * l * l * e2chi).sqrt();
        let ln_h = 0.5 * ((1.0 + root) / (sigma * delta / big_a)).ln()
            - 0.5 * root
            - 2.0 * a * r * l / big_a;
        let up1 = ((root - 1.0) / 2.0).sqrt();
        let u_phi = 2.0 * a * r * (1.0 + up1 * up1).sqrt() / (big_a * sigma * delta).sqrt()
            + (sigma / big_a).sqrt() * up1 / s;
        (ln_h, u_phi)
    };
    let (h, u_phi) = part(r, th);
    (h - part(R_IN, 0.5 * std::f64::consts::PI).0, u_phi)
}

/// The Boyer-Lindquist u^t of gas turning at `u_phi` (u^r = u^theta = 0).
fn bl_ut(a: f64, r: f64, th: f64, u_phi: f64) -> f64 {
    let (s, c) = th.sin_cos();
    let sigma = r * r + a * a * c * c;
    let g_tt = -(1.0 - 2.0 * r / sigma);
    let g_tp = -2.0 * a * r * s * s / sigma;
    let g_pp =
        ((r * r + a * a).powi(2) - (r * r - 2.0 * r + a * a) * a * a * s * s) * s * s / sigma;
    let (qa, qb, qc) = (g_tt, 2.0 * g_tp * u_phi, g_pp * u_phi * u_phi + 1.0);
    (-qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa)
}

/// iharm3d's geometric floors on density and internal energy at `r`.
fn floors(r: f64) -> (f64, f64) {
    let scale = r.powi(-2) / (1.0 + r / 10.0);
    (1e-6 * scale, 1e-8 * scale.powf(GAM))
}

/// The torus's header and primitives.
pub fn torus(o: &TorusOptions) -> (Header, Vec<f64>) {
    let [n1, n2, n3] = o.n;
    let a = SPIN;
    let horizon = 1.0 + (1.0 - a * a).sqrt();
    // iharm3d's inner edge: 5.5 cells inside the horizon.
    let r_in = ((n1 as f64 * horizon.ln() / 5.5 - R_OUT.ln()) / (n1 as f64 / 5.5 - 1.0)).exp();
    let start = [r_in.ln(), 0.0, 0.0];
    let dx = [
        (R_OUT.ln() - r_in.ln()) / n1 as f64,
        1.0 / n2 as f64,
        std::f64::consts::TAU / n3 as f64,
    ];
    let theta = match o.metric {
        Metric::Mks => Theta::Modified { hslope: HSLOPE },
        Metric::Fmks => Theta::funky(HSLOPE, 0.82, 14, 0.5, start[0]),
    };
    let header = Header {
        metric: match o.metric {
            Metric::Mks => "MKS",
            Metric::Fmks => "FMKS",
        }
        .into(),
        n: o.n,
        gam: GAM,
        gam_e: 4.0 / 3.0,
        gam_p: 5.0 / 3.0,
        n_prim: 8,
        start,
        dx,
        a,
        r_in,
        r_out: R_OUT,
        theta,
        t: 0.0,
        dump_cadence: 5.0,
        has_electrons: false,
    };
    let plane = axisymmetric(&header, o.funnel);
    let mut prims = Vec::with_capacity(n1 * n2 * n3 * 8);
    for cell in &plane {
        for _ in 0..n3 {
            prims.extend_from_slice(cell);
        }
    }
    (header, prims)
}

/// Where a cell centre (i, j) lies: r, theta, d theta / d X1, d theta /
/// d X2 and sqrt(-g) of the native coordinates.
struct Place {
    r: f64,
    th: f64,
    d: (f64, f64),
    gdet: f64,
}

fn place(h: &Header, x1: f64, x2: f64) -> Place {
    let r = x1.exp();
    let (th, d1, d2) = h.theta.at(x1, x2);
    let sigma = r * r + h.a * h.a * th.cos().powi(2);
    Place {
        r,
        th,
        d: (d1, d2),
        gdet: sigma * th.sin().abs() * r * d2,
    }
}

/// The primitives of one azimuthal plane, cell (i, j) at i n2 + j.
fn axisymmetric(h: &Header, funnel: bool) -> Vec<[f64; 8]> {
    let [n1, n2, _] = h.n;
    let a = h.a;
    let l = angular_momentum(a, R_MAX);
    let places: Vec<Place> = (0..n1 * n2)
        .map(|c| {
            let (i, j) = (c / n2, c % n2);
            place(
                h,
                h.start[0] + (i as f64 + 0.5) * h.dx[0],
                h.start[1] + (j as f64 + 0.5) * h.dx[1],
            )
        })
        .collect();
    let mut cells = vec![[0.0; 8]; n1 * n2];
    let mut inside = vec![false; n1 * n2];
    for (c, p) in places.iter().enumerate() {
        let (ln_h, u_phi) = enthalpy(a, l, p.r, p.th);
        if p.r < R_IN || !(ln_h >= 0.0) {
            continue;
        }
        inside[c] = true;
        let hm1 = ln_h.exp() - 1.0;
        let rho = (hm1 * (GAM - 1.0) / (KAPPA * GAM)).powf(1.0 / (GAM - 1.0));
        let u = KAPPA * rho.powf(GAM) / (GAM - 1.0);
        let u_bl = [bl_ut(a, p.r, p.th, u_phi), 0.0, 0.0, u_phi];
        let g = KsMetric::new(a, p.r, p.th.sin_cos());
        let v = relative_velocity(&g, bl_to_ks(a, p.r, u_bl));
        let v1 = v[0] / p.r;
        cells[c][..5].copy_from_slice(&[rho, u, v1, (v[1] - p.d.0 * v1) / p.d.1, v[2]]);
    }
    // Density in units of its peak; the floors outside.
    let rho_max = cells.iter().map(|c| c[0]).fold(0.0, f64::max);
    for (c, p) in cells.iter_mut().zip(&places) {
        c[0] /= rho_max;
        c[1] /= rho_max;
        let (rho_f, u_f) = floors(p.r);
        c[0] = c[0].max(rho_f);
        c[1] = c[1].max(u_f);
    }
    // The loop: A_phi = max(rho / rho_max - 0.2, 0) at the cell corners,
    // rho averaged over the four cells about each.
    let at = |i: isize, j: isize| {
        let (i, j) = (
            i.clamp(0, n1 as isize - 1) as usize,
            j.clamp(0, n2 as isize - 1) as usize,
        );
        cells[i * n2 + j][0]
    };
    let corners = |f: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
        (0..(n1 + 1) * (n2 + 1))
            .map(|c| f(c / (n2 + 1), c % (n2 + 1)))
            .collect()
    };
    let torus_a = corners(&|i, j| {
        let (i, j) = (i as isize, j as isize);
        let rho = 0.25 * (at(i, j) + at(i - 1, j) + at(i, j - 1) + at(i - 1, j - 1));
        (rho - 0.2).max(0.0)
    });
    let mut field = curl(h, &places, &torus_a);
    // Normalised so that beta = p_gas / p_mag is BETA at the peaks of
    // gas and magnetic pressure (iharm3d's normalisation).
    let (mut u_max, mut bsq_max) = (0.0f64, 0.0f64);
    for (c, p) in places.iter().enumerate() {
        let bsq = field_squared(h, p, &cells[c], field[c]);
        bsq_max = bsq_max.max(bsq);
        if inside[c] {
            u_max = u_max.max(cells[c][1]);
        }
    }
    let norm = ((GAM - 1.0) * u_max / (0.5 * bsq_max) / BETA).sqrt();
    for f in field.iter_mut() {
        f[0] *= norm;
        f[1] *= norm;
    }
    if funnel {
        // A vertical field, A_phi = B0 (r sin theta)^2 / 2, gathered to
        // the axis by cos^8 theta; the gas there at sigma = 10, u = rho.
        let funnel_a = corners(&|i, j| {
            let x1 = h.start[0] + i as f64 * h.dx[0];
            let (th, _, _) = h.theta.at(x1, h.start[1] + j as f64 * h.dx[1]);
            let rho = x1.exp() * th.sin();
            0.5 * FUNNEL_FIELD * rho * rho * th.cos().powi(8)
        });
        let extra = curl(h, &places, &funnel_a);
        for (c, p) in places.iter().enumerate() {
            field[c][0] += extra[c][0];
            field[c][1] += extra[c][1];
            if !inside[c] {
                // At most FUNNEL_SIGMA, and the hotter the more it is
                // magnetised: u / rho = (sigma / FUNNEL_SIGMA)^2, smooth
                // from cell to cell (the cut then leaves a surface, not
                // slivers of hot gas between a hot cell and a cold one).
                let bsq = field_squared(h, p, &cells[c], field[c]);
                let rho = cells[c][0].max(bsq / FUNNEL_SIGMA);
                let heat = bsq / rho / FUNNEL_SIGMA;
                cells[c][0] = rho;
                cells[c][1] = cells[c][1].max(rho * heat * heat);
            }
        }
    }
    for (c, f) in cells.iter_mut().zip(&field) {
        c[5] = f[0];
        c[6] = f[1];
    }
    cells
}

/// B^1 and B^2 per cell from A_phi at the corners (iharm3d's flux-CT
/// stencil: B^1 = -d A / d X2, B^2 = d A / d X1, over sqrt(-g)).
fn curl(h: &Header, places: &[Place], a: &[f64]) -> Vec<[f64; 2]> {
    let n2 = h.n[1];
    let at = |i: usize, j: usize| a[i * (n2 + 1) + j];
    places
        .iter()
        .enumerate()
        .map(|(c, p)| {
            let (i, j) = (c / n2, c % n2);
            let (a00, a01, a10, a11) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            [
                -(a00 - a01 + a10 - a11) / (2.0 * h.dx[1] * p.gdet),
                (a00 + a01 - a10 - a11) / (2.0 * h.dx[0] * p.gdet),
            ]
        })
        .collect()
}

/// b.b of a cell's gas in the field (B^1, B^2, 0).
fn field_squared(h: &Header, p: &Place, cell: &[f64; 8], f: [f64; 2]) -> f64 {
    native_four_vectors(
        h.a,
        p.r,
        p.th.sin_cos(),
        p.d,
        ([cell[2], cell[3], cell[4]], [f[0], f[1], 0.0]),
    )
    .2
}

impl TorusOptions {
    /// From the names `blackhole torus` and `medium.torus` take: the
    /// metric ("mks" or "fmks") and the grid ("N1xN2xN3").
    pub fn parse(metric: &str, grid: &str, funnel: bool) -> Result<TorusOptions, String> {
        let metric = match metric {
            "mks" => Metric::Mks,
            "fmks" => Metric::Fmks,
            other => return Err(format!("metric {other:?}: expected \"mks\" or \"fmks\"")),
        };
        let parts: Vec<Option<usize>> = grid.split('x').map(|p| p.trim().parse().ok()).collect();
        let n = match parts.as_slice() {
            [Some(a), Some(b), Some(c)]
                if *a >= 8 && *b >= 4 && *c >= 1 && a * b * c <= 1 << 28 =>
            {
                [*a, *b, *c]
            }
            _ => {
                return Err(format!(
                    "grid {grid:?}: expected N1xN2xN3, cell counts along the radius (at least 8), the polar angle (at least 4) and the azimuth (at least 1), at most 2^28 in all, such as 128x64x4"
                ));
            }
        };
        Ok(TorusOptions { metric, n, funnel })
    }
}

/// The torus of `o` as a dump held in memory (named `name`).
pub fn torus_dump(o: &TorusOptions, name: &str) -> super::dump::Dump {
    let (header, prims) = torus(o);
    super::dump::Dump {
        path: name.into(),
        header,
        prims: super::dump::Prims::Memory(prims),
    }
}

/// Writes the torus dump of `o` at `path`.
pub fn write_torus(path: &Path, o: &TorusOptions) -> anyhow::Result<Header> {
    let (h, prims) = torus(o);
    write(path, &h, &prims)?;
    Ok(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_torus_peaks_at_r_max_in_the_midplane_with_its_inner_edge_at_r_in() {
        // ln h = 0 at the inner edge and rises to its peak at r_max.
        let l = angular_momentum(SPIN, R_MAX);
        let half = 0.5 * std::f64::consts::PI;
        assert!(enthalpy(SPIN, l, R_IN, half).0.abs() < 1e-14);
        let h = |r: f64| enthalpy(SPIN, l, r, half).0;
        let d = 1e-4;
        let slope = (h(R_MAX + d) - h(R_MAX - d)) / (2.0 * d);
        assert!(slope.abs() < 1e-7, "d ln h / dr at r_max: {slope}");
        assert!(h(R_MAX) > h(R_MAX - 1.0) && h(R_MAX) > h(R_MAX + 1.0));
        // The gas orbits at Fishbone and Moncrief's angular momentum, l =
        // u^t u_phi.
        let (_, u_phi) = enthalpy(SPIN, l, 9.0, half);
        let ut = bl_ut(SPIN, 9.0, half, u_phi);
        let sigma = 81.0;
        let g_tt = -(1.0 - 18.0 / sigma);
        let g_tp = -2.0 * SPIN * 9.0 / sigma;
        let g_pp =
            ((81.0 + SPIN * SPIN).powi(2) - (81.0 - 18.0 + SPIN * SPIN) * SPIN * SPIN) / sigma;
        let u_p = g_tp * ut + g_pp * u_phi;
        assert!((ut * u_p - l).abs() < 1e-10, "{} {l}", ut * u_p);
        // And is a unit timelike vector.
        let norm = g_tt * ut * ut + 2.0 * g_tp * ut * u_phi + g_pp * u_phi * u_phi;
        assert!((norm + 1.0).abs() < 1e-12);
    }
}
