//! Footprints on the celestial sphere in an equirectangular panorama: from
//! a direction and its derivatives per pixel to the texture coordinates of
//! [`super::equirect_uv`] and theirs.

use super::ewa::Footprint;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// The shortest signed difference of two u (panorama) coordinates, in
/// [-0.5, 0.5): a step across the seam at u = 0 is the short way round,
/// not nearly a whole turn back.
#[inline]
pub fn wrap_du(du: f64) -> f64 {
    (du + 0.5).rem_euclid(1.0) - 0.5
}

/// The largest |u| extent of a footprint: half a turn each way, the whole
/// row. Towards a pole a fixed angle spans ever more of a row (the row's
/// circumference shrinks as cos(latitude)); beyond a whole row the filter
/// would only read the row again.
const MAX_U_EXTENT: f64 = 0.5;

/// Texture coordinates (u, v) in an equirectangular panorama of unit
/// direction `dir` (as [`super::equirect_uv`]) and their derivatives given
/// the direction's derivatives `ddx`, `ddy` per pixel step (scene axes;
/// their components along `dir` do not move the point on the sphere and
/// are ignored). The u derivatives are those of the angle, free of the
/// seam; towards the poles they grow as 1 / cos(latitude), and are scaled
/// down where the footprint would span more than the whole row.
pub fn equirect_footprint(dir: DVec3, ddx: DVec3, ddy: DVec3) -> (f64, f64, Footprint) {
    let (u, v) = super::equirect_uv(dir);
    let d = dir.normalize_or_zero();
    // Distance from the polar axis; its floor keeps a pole's 1/rho finite
    // (the cap below then holds the footprint to the row).
    let rho = d.x.hypot(d.y);
    let (ex, ey) = if rho > 0.0 {
        (d.x / rho, d.y / rho)
    } else {
        (0.0, 1.0)
    };
    let rho = rho.max(1e-12);
    // u = atan2(x, y) / 2 pi: du = (y dx - x dy) / (x^2 + y^2) / 2 pi,
    // along the local east (ey, -ex, 0) over the row's radius.
    // v = (pi/2 - latitude) / pi: dv = -dlat / pi, dlat along the local
    // north (-z ex, -z ey, rho).
    let east = DVec3::new(ey, -ex, 0.0);
    let north = DVec3::new(-d.z * ex, -d.z * ey, rho);
    let uv = |t: DVec3| {
        let t = if t.is_finite() { t } else { DVec3::ZERO };
        let t = t - d * t.dot(d);
        DVec2::new(t.dot(east) / (rho * TAU), -t.dot(north) / PI)
    };
    let (mut a, mut b) = (uv(ddx), uv(ddy));
    // The ellipse's u half-extent is sqrt(a.u^2 + b.u^2).
    let extent = a.x.hypot(b.x);
    if extent > MAX_U_EXTENT {
        let k = MAX_U_EXTENT / extent;
        a.x *= k;
        b.x *= k;
    }
    (u, v, Footprint { dx: a, dy: b })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::{equirect_dir, equirect_uv};

    /// A unit tangent frame at `dir` (any rotation about it).
    fn frame(dir: DVec3) -> (DVec3, DVec3) {
        let t = dir.any_orthonormal_vector();
        (t, dir.cross(t))
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-6;
        for &(u, v) in &[(0.1, 0.3), (0.62, 0.55), (0.93, 0.8), (0.3, 0.07)] {
            let d = equirect_dir(u, v);
            let (t1, t2) = frame(d);
            let (ddx, ddy) = (t1 * 1e-3 + t2 * 4e-4, t2 * -7e-4);
            let (u0, v0, fp) = equirect_footprint(d, ddx, ddy);
            assert!((u0 - u).abs() < 1e-12 && (v0 - v).abs() < 1e-12);
            for (dd, want) in [(ddx, fp.dx), (ddy, fp.dy)] {
                let step = |s: f64| equirect_uv((d + dd * s).normalize());
                let (p, m) = (step(h), step(-h));
                let fd = DVec2::new(wrap_du(p.0 - m.0), p.1 - m.1) / (2.0 * h);
                assert!(
                    (fd - want).length() < 1e-6 * want.length().max(1e-3),
                    "({u}, {v}): {fd} vs {want}"
                );
            }
        }
    }

    #[test]
    fn the_seam_is_crossed_the_short_way() {
        // At phi = 0 (u = 0, the +y direction) the derivative is the
        // angle's, the same as a quarter turn away, not a jump of 1.
        let d = DVec3::Y;
        let east = DVec3::new(1.0, 0.0, 0.0);
        let (u, _, fp) = equirect_footprint(d, east * 1e-3, DVec3::Z * 1e-3);
        assert_eq!(u, 0.0);
        assert!((fp.dx.x - 1e-3 / TAU).abs() < 1e-15, "{}", fp.dx.x);
        assert!((fp.dy.y + 1e-3 / PI).abs() < 1e-15, "{}", fp.dy.y);
        let (_, _, fq) = equirect_footprint(DVec3::X, DVec3::new(0.0, -1e-3, 0.0), DVec3::Z * 1e-3);
        assert!((fq.dx - fp.dx).length() < 1e-15);
        assert!((wrap_du(0.999 - 0.001) + 0.002).abs() < 1e-15);
        assert!((wrap_du(0.001 - 0.999) - 0.002).abs() < 1e-15);
    }

    #[test]
    fn at_the_poles_the_footprint_spans_at_most_the_row() {
        for d in [DVec3::Z, -DVec3::Z, DVec3::new(1e-9, 0.0, 1.0).normalize()] {
            let (t1, t2) = frame(d);
            let (_, v, fp) = equirect_footprint(d, t1 * 0.01, t2 * 0.01);
            assert!(fp.is_finite());
            assert!(fp.dx.x.hypot(fp.dy.x) <= MAX_U_EXTENT * (1.0 + 1e-12));
            // The v derivative stays the angle's: 0.01 rad over pi.
            assert!(fp.dx.y.hypot(fp.dy.y) <= 0.01 / PI * (1.0 + 1e-9));
            assert!(v == 0.0 || v == 1.0 || v < 1e-6);
        }
        // Near, not at, a pole: u derivatives grow as 1 / cos(latitude).
        let lat: f64 = 89.0f64.to_radians();
        let d = DVec3::new(0.0, lat.cos(), lat.sin());
        let (_, _, fp) = equirect_footprint(d, DVec3::X * 1e-4, DVec3::ZERO);
        assert!((fp.dx.x - 1e-4 / (TAU * lat.cos())).abs() < 1e-12);
    }
}
