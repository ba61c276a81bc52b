//! Frequency shift g = nu_obs / nu_emit of light from the disk
//! (validation/REFERENCE.md section 3), in r_s = c = 1 units (M = GM/c^2 = 1/2).
//!
//! Sky light: 1 / sqrt(1 - r_s / r_o) at a static camera (exact model), or
//! the trace's running sum ([`super::Trace::ln_shift`], seed model).

use super::Segment;
#[cfg(test)]
use super::TimeRate;
use glam::DVec3;

/// The photon's conserved L_z / E for the exact model, from the traced
/// ray's initial state: L = x x x' is conserved by the 3D form and
/// E = v_inf with v_inf^2 = |x'|^2 - h^2/r^3. The light travels opposite to
/// the traced direction, hence the sign.
pub fn gr_photon_lz_over_e(x0: DVec3, v0: DVec3) -> f64 {
    let l = x0.cross(v0);
    let r = x0.length();
    let v_inf = (v0.length_squared() - l.length_squared() / (r * r * r)).sqrt();
    -l.z / v_inf
}

/// ln g for light emitted at radius `r_e` in the disk plane and received by
/// a static observer at `r_o`, exact model. With `doppler` the emitter
/// follows a circular Keplerian orbit (counter-clockwise seen from +z,
/// angular velocity Omega = sqrt(GM/r^3)): g = sqrt(1 - 3M/r) / (1 - Omega
/// L_z/E); such orbits exist only outside the photon sphere, and inside it
/// (where only unphysical textures reach) the emitter is taken as static:
/// g = sqrt(1 - r_s/r_e). Both are divided by sqrt(1 - r_s/r_o) for the
/// observer.
pub fn gr_disk_ln_shift(r_e: f64, lz_over_e: f64, r_o: f64, doppler: bool) -> f64 {
    let emitter = if doppler && r_e > 1.5 {
        let omega = (0.5 / (r_e * r_e * r_e)).sqrt();
        0.5 * (1.0 - 1.5 / r_e).ln() - (1.0 - omega * lz_over_e).ln()
    } else {
        0.5 * (1.0 - 1.0 / r_e).ln()
    };
    emitter - 0.5 * (1.0 - 1.0 / r_o).ln()
}

/// ln g at fraction `s` of a seed-model segment: the running sum of the
/// photon's energy change, plus with `doppler` the special-relativistic
/// Doppler factor 1 / (gamma (1 - u . n)) of a Keplerian emitter moving at
/// u = sqrt(GM/r) counter-clockwise, n the light's direction. The seed
/// model's space is flat, so that is the whole of the rotation's effect.
pub fn seed_disk_ln_shift(seg: &Segment, s: f64, doppler: bool) -> f64 {
    let gravity = seg.ln_shift_at(s);
    if !doppler {
        return gravity;
    }
    let p = seg.point(s);
    let r = (p.x * p.x + p.y * p.y).sqrt();
    let speed = (0.5 / r).sqrt();
    let u = DVec3::new(-p.y, p.x, 0.0) / r * speed;
    let n = -seg.tangent(s).normalize();
    let gamma = 1.0 / (1.0 - speed * speed).sqrt();
    gravity - (gamma * (1.0 - u.dot(n))).ln()
}

#[cfg(test)]
// Reference values from validation/REFERENCE.md, some of which are close to sqrt(2).
#[allow(clippy::approx_constant)]
mod tests {
    use super::*;

    #[test]
    fn face_on_keplerian_redshift() {
        // L_z = 0: g = sqrt(1 - 3M/r) at r = 6M, 10M, 20M (r_s = 3, 5, 10).
        for (r, want) in [(3.0, 0.707106781), (5.0, 0.836660027), (10.0, 0.921954446)] {
            let g = gr_disk_ln_shift(r, 0.0, f64::INFINITY, true).exp();
            assert!((g - want).abs() < 1e-9, "{g}");
        }
    }

    #[test]
    fn edge_on_extremes_at_isco() {
        // Emission along the orbit's tangent at r = 6M towards a distant
        // observer: |L_z/E| = b = r / sqrt(1 - r_s/r). validation/REFERENCE.md: g =
        // 1.414213562 (approaching) and 0.471404521 (receding).
        let r: f64 = 3.0;
        let b = r / (1.0 - 1.0 / r).sqrt();
        let up = gr_disk_ln_shift(r, b, f64::INFINITY, true).exp();
        let down = gr_disk_ln_shift(r, -b, f64::INFINITY, true).exp();
        assert!((up - 1.414213562).abs() < 1e-8, "{up}");
        assert!((down - 0.471404521).abs() < 1e-8, "{down}");
    }

    #[test]
    fn static_emitter_and_observer() {
        // r_e = 3 r_s, r_o = 100 r_s: 0.820609940.
        let g = gr_disk_ln_shift(3.0, 1.0, 100.0, false).exp();
        assert!((g - 0.820609940).abs() < 1e-9, "{g}");
    }

    #[test]
    fn photon_angular_momentum_sign() {
        // A ray traced from a camera on -y towards +y passing at x > 0: the
        // light travels towards -y at x > 0, so L_z = x p_y - y p_x < 0.
        let l = gr_photon_lz_over_e(DVec3::new(3.0, -1000.0, 0.0), DVec3::Y);
        assert!(l < 0.0);
        // |L_z/E| is the impact parameter for a ray in the plane.
        let b = crate::physics::gr::impact_parameter(DVec3::new(3.0, -1000.0, 0.0), DVec3::Y);
        assert!((l.abs() - b).abs() < 1e-12);
    }

    #[test]
    fn seed_doppler_matches_special_relativity() {
        // Light leaving an emitter at r = 5 (flat, running sum 0) straight
        // along its velocity: g = sqrt((1 + u) / (1 - u)).
        let r = 5.0;
        let u = (0.5f64 / r).sqrt();
        // Traced direction is opposite to the light: light along +y at (r, 0).
        let seg = Segment {
            x0: DVec3::new(r, 1.0, 0.0),
            v0: DVec3::ZERO,
            x1: DVec3::new(r, -1.0, 0.0),
            v1: DVec3::ZERO,
            h: 1.0,
            affine: 2.0,
            curved: false,
            ln_shift: [0.0, 0.0],
            time: [0.0; 2],
            time_rate: TimeRate::Untimed,
        };
        let g = seed_disk_ln_shift(&seg, 0.5, true).exp();
        assert!((g - ((1.0 + u) / (1.0 - u)).sqrt()).abs() < 1e-12, "{g}");
    }
}
