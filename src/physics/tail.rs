//! Exact remaining bending of an outbound ray, from its current state to
//! infinity.
//!
//! Both models are central and planar, so beyond the last step the rest of the
//! path is fixed by the impact parameter b alone. With u = 1/r the swept polar
//! angle from u0 out to u = 0 is
//!
//! * exact model: dphi/du = 1 / sqrt(1/b^2 - u^2 + u^3),
//! * seed model (optics in the index n = exp(1/(2r))): dphi/du = b / sqrt(e^u - b^2 u^2),
//!
//! and the ray leaves along the polar direction it reaches. With u = u0 t both
//! become smooth integrals over t in [0, 1] as long as the ray is well past
//! periapsis (cos of its angle to the radial >= 1/2, see `may_escape`), which
//! Gauss-Legendre quadrature evaluates to ~1e-12 rad. Integrating the rays out
//! to huge radii instead is where naive tracers spend most of their time.

use glam::DVec3;
use std::sync::LazyLock;

const NODES: usize = 20;

/// Gauss-Legendre nodes and weights on [0, 1].
static GAUSS: LazyLock<([f64; NODES], [f64; NODES])> = LazyLock::new(|| {
    let mut t = [0.0; NODES];
    let mut w = [0.0; NODES];
    let n = NODES as f64;
    for i in 0..NODES {
        // Newton on P_n from the Chebyshev-like initial guess.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=NODES {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        t[i] = 0.5 * (1.0 - x);
        w[i] = 1.0 / ((1.0 - x * x) * dp * dp);
    }
    (t, w)
});

/// The quadrature's nodes and weights on [0, 1] (for the GPU backend).
pub(crate) fn gauss_legendre() -> (&'static [f64; NODES], &'static [f64; NODES]) {
    let (t, w) = &*GAUSS;
    (t, w)
}

/// The integral of `f` over [0, 1] by the quadrature.
pub(crate) fn quad(f: impl Fn(f64) -> f64) -> f64 {
    let (t, w) = &*GAUSS;
    t.iter().zip(w).map(|(&t, &w)| w * f(t)).sum()
}

/// Rotates the radial direction of `x` by `dphi` towards the motion `v`
/// within the ray's plane.
fn rotate_in_plane(x: DVec3, v: DVec3, dphi: f64) -> DVec3 {
    let e1 = x.normalize();
    let perp = v - e1 * v.dot(e1);
    let len = perp.length();
    if len <= 1e-300 || !len.is_finite() {
        return e1;
    }
    let e2 = perp / len;
    e1 * dphi.cos() + e2 * dphi.sin()
}

/// Exact model: asymptotic direction of the outbound ray at `x` with
/// coordinate velocity `v` (any scale).
pub fn gr_escape_direction(x: DVec3, v: DVec3) -> DVec3 {
    let r = x.length();
    let u0 = 1.0 / r;
    let h2 = x.cross(v).length_squared();
    // v_inf^2 = |v|^2 - r_s h^2 / r^3 is conserved along the 3D form.
    let vinf2 = v.length_squared() - h2 * u0 * u0 * u0;
    let b2 = h2 / vinf2;
    let k2 = b2 * u0 * u0;
    let dphi = (b2.sqrt() * u0) * quad(|t| 1.0 / (1.0 - k2 * t * t * (1.0 - u0 * t)).sqrt());
    rotate_in_plane(x, v, dphi)
}

/// Seed model: asymptotic direction of the outbound ray at `x` moving along
/// `v`, and the remaining change of the running frequency sum
/// (a.v dt / c^2 from here to infinity, exactly -GM/(c^2 r) = -1/(2r)).
pub fn seed_escape(x: DVec3, v: DVec3) -> (DVec3, f64) {
    let r = x.length();
    let u0 = 1.0 / r;
    let n = (0.5 * u0).exp();
    // Optical invariant b = n r sin(psi).
    let sin_psi = x.cross(v).length() / (r * v.length());
    let b = n * r * sin_psi;
    let k2 = b * b * u0 * u0;
    let dphi = (b * u0) * quad(|t| 1.0 / ((u0 * t).exp() - k2 * t * t).sqrt());
    (rotate_in_plane(x, v, dphi), -0.5 * u0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        // Degree 2n-1 is exact: check degree 39 and a non-polynomial.
        let p = quad(|t| 40.0 * t.powi(39));
        assert!((p - 1.0).abs() < 1e-13, "{p}");
        let e = quad(f64::exp);
        assert!((e - (std::f64::consts::E - 1.0)).abs() < 1e-14, "{e}");
    }

    #[test]
    fn weak_field_limit_matches_first_order_bending() {
        // A ray with huge b moving along +y at x = b, 45 degrees past
        // periapsis. Integrating each model's transverse acceleration along
        // the straight line gives the remaining bending to first order:
        // exact model (a_perp = 1.5 b^3 / r^5): (1/b)(1 - 1.5 c + 0.5 c^3);
        // seed model (a_perp = b / (2 r^3)): (1/(2b))(1 - c), c = cos(psi).
        let b = 1e5;
        let x = DVec3::new(b, b, 0.0);
        let c = std::f64::consts::FRAC_1_SQRT_2;
        // Angle from +y; bending towards the hole turns it towards -x.
        let bend = |d: DVec3| d.x.atan2(d.y);
        let gr = bend(gr_escape_direction(x, DVec3::Y));
        let want = (1.0 - 1.5 * c + 0.5 * c * c * c) / b;
        assert!((gr + want).abs() < 1e-4 * want, "{gr} vs {want}");
        let (d, rest) = seed_escape(x, DVec3::Y);
        let want = (1.0 - c) / (2.0 * b);
        assert!(
            (bend(d) + want).abs() < 1e-4 * want,
            "{} vs {want}",
            bend(d)
        );
        assert_eq!(rest, -0.5 / x.length());
    }
}
