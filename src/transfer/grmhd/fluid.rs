//! The fluid's four-vectors in Kerr-Schild coordinates (t, r, theta,
//! phi; M = 1) from a dump's primitives, as ipole's `model/iharm` builds
//! them: the velocity from its part relative to the normal observer, the
//! field four-vector b^mu from B^i = b^i u^t - b^t u^i.

/// The Kerr-Schild metric at (r, theta): g_mu nu, and the row g^t mu of
/// its inverse.
#[derive(Clone, Copy, Debug)]
pub struct KsMetric {
    pub cov: [[f64; 4]; 4],
    pub con_t: [f64; 4],
}

impl KsMetric {
    #[inline]
    pub fn new(a: f64, r: f64, (sin, cos): (f64, f64)) -> KsMetric {
        let sigma = r * r + a * a * cos * cos;
        let z = 2.0 * r / sigma;
        let s2 = sin * sin;
        let mut g = [[0.0; 4]; 4];
        g[0][0] = -(1.0 - z);
        g[0][1] = z;
        g[0][3] = -z * a * s2;
        g[1][1] = 1.0 + z;
        g[1][3] = -a * s2 * (1.0 + z);
        g[2][2] = sigma;
        g[3][3] = s2 * (sigma + a * a * s2 * (1.0 + z));
        g[1][0] = g[0][1];
        g[3][0] = g[0][3];
        g[3][1] = g[1][3];
        KsMetric {
            cov: g,
            con_t: [-(1.0 + z), z, 0.0, 0.0],
        }
    }

    #[inline]
    pub fn lower(&self, v: [f64; 4]) -> [f64; 4] {
        let mut out = [0.0; 4];
        for (mu, o) in out.iter_mut().enumerate() {
            *o = (0..4).map(|nu| self.cov[mu][nu] * v[nu]).sum();
        }
        out
    }
}

/// u^mu and b^mu (contravariant, Kerr-Schild) and b.b, from the velocity
/// relative to the normal observer `v` and the field `field` (both
/// spatial, Kerr-Schild components), as ipole does it (with |v.v| where
/// round-off could make it negative).
#[inline]
pub fn four_vectors(g: &KsMetric, v: [f64; 3], field: [f64; 3]) -> ([f64; 4], [f64; 4], f64) {
    let mut vv = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            vv += g.cov[i + 1][j + 1] * v[i] * v[j];
        }
    }
    let gamma_alpha = (-(1.0 + vv.abs()) / g.con_t[0]).sqrt();
    let u = [
        -gamma_alpha * g.con_t[0],
        v[0] - gamma_alpha * g.con_t[1],
        v[1] - gamma_alpha * g.con_t[2],
        v[2] - gamma_alpha * g.con_t[3],
    ];
    let u_cov = g.lower(u);
    let bt = field[0] * u_cov[1] + field[1] * u_cov[2] + field[2] * u_cov[3];
    let b = [
        bt,
        (field[0] + u[1] * bt) / u[0],
        (field[1] + u[2] * bt) / u[0],
        (field[2] + u[3] * bt) / u[0],
    ];
    let b_cov = g.lower(b);
    let bsq = (0..4).map(|m| b[m] * b_cov[m]).sum();
    (u, b, bsq)
}

/// A native vector's Kerr-Schild components at radius `r` where theta's
/// derivatives are (d theta / d X1, d theta / d X2): (r V1, th_1 V1 +
/// th_2 V2, V3).
#[inline]
pub fn to_ks(r: f64, (d1, d2): (f64, f64), v: [f64; 3]) -> [f64; 3] {
    [r * v[0], d1 * v[0] + d2 * v[1], v[2]]
}

/// [`four_vectors`] of the velocity `v` and field `field` given in native
/// components at radius `r`, theta's derivatives `d`, spin `a` and
/// (sin, cos) of theta.
#[inline]
pub fn native_four_vectors(
    a: f64,
    r: f64,
    (sin, cos): (f64, f64),
    d: (f64, f64),
    (v, field): ([f64; 3], [f64; 3]),
) -> ([f64; 4], [f64; 4], f64) {
    let g = KsMetric::new(a, r, (sin, cos));
    four_vectors(&g, to_ks(r, d, v), to_ks(r, d, field))
}

/// A Kerr-Schild contravariant vector's Boyer-Lindquist components (t and
/// phi shift with r: dt_KS = dt_BL + 2r/Delta dr, dphi_KS = dphi_BL +
/// a/Delta dr).
#[inline]
pub fn ks_to_bl(a: f64, r: f64, v: [f64; 4]) -> [f64; 4] {
    let delta = r * r - 2.0 * r + a * a;
    [
        v[0] - 2.0 * r / delta * v[1],
        v[1],
        v[2],
        v[3] - a / delta * v[1],
    ]
}

/// The inverse of [`ks_to_bl`].
#[inline]
pub fn bl_to_ks(a: f64, r: f64, v: [f64; 4]) -> [f64; 4] {
    let delta = r * r - 2.0 * r + a * a;
    [
        v[0] + 2.0 * r / delta * v[1],
        v[1],
        v[2],
        v[3] + a / delta * v[1],
    ]
}

/// The part of a Kerr-Schild four-velocity `u` relative to the normal
/// observer: u^i - u^t g^ti / g^tt (the primitive iharm3d stores).
#[inline]
pub fn relative_velocity(g: &KsMetric, u: [f64; 4]) -> [f64; 3] {
    let f = u[0] / g.con_t[0];
    [
        u[1] - f * g.con_t[1],
        u[2] - f * g.con_t[2],
        u[3] - f * g.con_t[3],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_velocity_is_a_unit_timelike_vector_and_b_is_orthogonal_to_it() {
        // For any relative velocity and field: u.u = -1, u.b = 0, and the
        // relative velocity read back from u is the one given.
        let a = 0.9375;
        for (r, th) in [(2.5, 0.4), (6.0, 1.5), (40.0, 2.9)] {
            let g = KsMetric::new(a, r, f64::sin_cos(th));
            let v = [0.05, -0.01, 0.03];
            let field = [0.2, 0.01, -0.05];
            let (u, b, bsq) = four_vectors(&g, v, field);
            let u_cov = g.lower(u);
            let uu: f64 = (0..4).map(|m| u[m] * u_cov[m]).sum();
            let ub: f64 = (0..4).map(|m| b[m] * u_cov[m]).sum();
            assert!((uu + 1.0).abs() < 1e-12, "u.u {uu}");
            assert!(ub.abs() < 1e-12 * bsq.sqrt(), "u.b {ub}");
            assert!(bsq > 0.0);
            let back = relative_velocity(&g, u);
            for i in 0..3 {
                assert!((back[i] - v[i]).abs() < 1e-13);
            }
            // B^i = b^i u^t - b^t u^i.
            for i in 0..3 {
                let bi = b[i + 1] * u[0] - b[0] * u[i + 1];
                assert!((bi - field[i]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn the_metric_is_kerr_schilds() {
        // g^t mu g_mu nu = delta^t_nu, and det g = -Sigma^2 sin^2 theta.
        let a = 0.7;
        let (r, th) = (3.3_f64, 1.1_f64);
        let g = KsMetric::new(a, r, th.sin_cos());
        for nu in 0..4 {
            let s: f64 = (0..4).map(|m| g.con_t[m] * g.cov[m][nu]).sum();
            assert!(
                (s - if nu == 0 { 1.0 } else { 0.0 }).abs() < 1e-13,
                "{nu}: {s}"
            );
        }
        let sigma = r * r + a * a * th.cos().powi(2);
        let m = g.cov;
        // Laplace expansion of the 4x4 determinant.
        let det3 = |a: [[f64; 3]; 3]| {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        };
        let mut det = 0.0;
        for c in 0..4 {
            let mut minor = [[0.0; 3]; 3];
            for (ri, row) in (1..4).enumerate() {
                for (ci, col) in (0..4).filter(|&x| x != c).enumerate() {
                    minor[ri][ci] = m[row][col];
                }
            }
            det += if c % 2 == 0 { 1.0 } else { -1.0 } * m[0][c] * det3(minor);
        }
        let want = -(sigma * th.sin()).powi(2);
        assert!(((det - want) / want).abs() < 1e-12, "{det} {want}");
    }
}
