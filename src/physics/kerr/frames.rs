//! Observers at a point of Kerr-Schild space: static and ZAMO
//! 4-velocities, their orthonormal frames, the ray a camera sees along a
//! direction and the photon state it is traced back from, the velocity
//! of a moving body, and the reflection off a static mirror. The WGSL
//! twin is `src/gpu/kerr.wgsl`'s frames and mirror.

use super::Kerr;
use glam::DVec3;

impl Kerr {
    /// The reflection of the ray traced back along coordinate velocity `d`
    /// off a static mirror at `x` (outside the ergosphere) whose surface
    /// has the coordinate normal (gradient) `n`: the law of reflection in
    /// the mirror's local frame (the static observer's, closest to the
    /// axes), which keeps the photon's energy there and so its E.
    pub fn ks_reflect(self, x: DVec3, d: DVec3, n: DVec3) -> DVec3 {
        let f = self.ks_f(x);
        let u = [1.0 / (1.0 - f).sqrt(), 0.0, 0.0, 0.0];
        let frame = self.ks_frame(x, u);
        let (p, e) = self.ks_backward(x, d);
        let k = [self.ks_flow(x, p, e).dt, d.x, d.y, d.z];
        let kl = self.ks_lower(x, k);
        let dot4 = |a: &[f64; 4], b: &[f64; 4]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let energy = -dot4(&kl, &u);
        let local = DVec3::from_array(std::array::from_fn(|i| dot4(&kl, &frame[i])));
        // A covector's components in the frame are its values on it.
        let normal = DVec3::from_array(std::array::from_fn(|i| {
            n.x * frame[i][1] + n.y * frame[i][2] + n.z * frame[i][3]
        }))
        .normalize();
        let out = crate::physics::reflect(local, normal);
        DVec3::from_array(std::array::from_fn(|m| {
            energy * u[m + 1]
                + out.x * frame[0][m + 1]
                + out.y * frame[1][m + 1]
                + out.z * frame[2][m + 1]
        }))
    }

    /// A static observer's 4-velocity at `x`, d_t / sqrt(1 - f): only
    /// outside the ergosphere (None inside, where none exists).
    pub fn ks_static_velocity(self, x: DVec3) -> Option<[f64; 4]> {
        let f = self.ks_f(x);
        (f < 1.0).then(|| [1.0 / (1.0 - f).sqrt(), 0.0, 0.0, 0.0])
    }

    /// The velocity (units of c, in the frame [`Kerr::ks_frame`] of the
    /// observer `u` at `x`) of a body there moving with coordinate
    /// velocity `w` = d x / d t (Boyer-Lindquist's t): None where that is
    /// not slower than light.
    pub fn ks_relative_velocity(self, x: DVec3, u: [f64; 4], w: DVec3) -> Option<DVec3> {
        let (_, _, _, _, (r, dr)) = self.ks_fields::<true>(x);
        // Kerr-Schild's t runs 2 r / Delta dr ahead of Boyer-Lindquist's.
        let k = [1.0 + 2.0 * r / self.delta(r) * dr.dot(w), w.x, w.y, w.z];
        let dot = |a: &[f64; 4], b: &[f64; 4]| {
            let al = self.ks_lower(x, *a);
            al.iter().zip(b).map(|(p, q)| p * q).sum::<f64>()
        };
        let norm = -dot(&k, &k);
        if !(norm > 0.0) {
            return None;
        }
        let body = k.map(|c| c / norm.sqrt());
        let gamma = -dot(&body, &u);
        let e = self.ks_frame(x, u);
        Some(DVec3::from_array(std::array::from_fn(|i| {
            dot(&body, &e[i]) / gamma
        })))
    }

    /// The coordinate velocity d x / d t of the counter-clockwise circular
    /// orbit through `x`: about the spin axis in the equatorial plane
    /// (with spin only there), or without spin in the plane of x and
    /// z x x; None where no such orbit exists (inside the photon orbit,
    /// off the plane with spin, on the axis).
    pub fn ks_circular_velocity(self, x: DVec3) -> Option<DVec3> {
        let rho = x.x.hypot(x.y);
        if rho == 0.0 || (self.a != 0.0 && x.z.abs() > 1e-9 * rho) {
            return None;
        }
        let r = self.ks_radius(x);
        if !self.has_circular_orbit(r) {
            return None;
        }
        // Speed Omega times the orbit's radius along z x x (Kerr-Schild's
        // circles of radius r lie at rho).
        let radius = if self.a == 0.0 { x.length() } else { rho };
        Some(DVec3::new(-x.y, x.x, 0.0) / rho * (self.orbital_angular_velocity(r) * radius))
    }

    /// The ZAMO's 4-velocity at `x` (outside the horizon) in Kerr-Schild
    /// components: (d_t + omega d_phi) / alpha, d_phi = (-y, x, 0).
    pub fn ks_zamo_velocity(self, x: DVec3) -> [f64; 4] {
        let s = self.spheroidal(x);
        let z = self.zamo(s.r, s.th);
        [
            1.0 / z.alpha,
            -z.omega * x.y / z.alpha,
            z.omega * x.x / z.alpha,
            0.0,
        ]
    }

    /// The orthonormal spatial frame of the observer of 4-velocity `u` (the
    /// ZAMO's, a static observer's) at `x` closest to the coordinate axes: the axes projected orthogonally to its 4-velocity
    /// `u` and made orthonormal symmetrically (G^(-1/2), G their Gram
    /// matrix), so that no axis is preferred and the frame is regular on
    /// the spin axis. At a = 0 it is the static observer's frame of the
    /// Schwarzschild tracer (radial axis shortened by sqrt(1 - r_s/r)).
    /// Returns the three frame vectors (t, x, y, z components).
    pub fn ks_frame(self, x: DVec3, u: [f64; 4]) -> [[f64; 4]; 3] {
        let ul = self.ks_lower(x, u);
        // G_ij = g_ij + u_i u_j, the projected axes' Gram matrix.
        let cols: [DVec3; 3] = std::array::from_fn(|j| {
            let mut axis = [0.0; 4];
            axis[j + 1] = 1.0;
            let g = self.ks_lower(x, axis);
            DVec3::new(g[1], g[2], g[3]) + DVec3::new(ul[1], ul[2], ul[3]) * ul[j + 1]
        });
        let gram = glam::DMat3::from_cols(cols[0], cols[1], cols[2]);
        // G^(-1/2) by the Denman-Beavers iteration (G is symmetric and
        // positive definite).
        let (mut y, mut z) = (gram, glam::DMat3::IDENTITY);
        for _ in 0..60 {
            let (yn, zn) = ((y + z.inverse()) * 0.5, (z + y.inverse()) * 0.5);
            let done = (yn - y).abs_diff_eq(glam::DMat3::ZERO, 1e-15 * yn.x_axis.length());
            (y, z) = (yn, zn);
            if done {
                break;
            }
        }
        std::array::from_fn(|a| {
            let c = z.col(a);
            // e_a = sum_i c_i (d_i + u_i u).
            let uc = ul[1] * c.x + ul[2] * c.y + ul[3] * c.z;
            [uc * u[0], c.x + uc * u[1], c.y + uc * u[2], c.z + uc * u[3]]
        })
    }

    /// The ray a ZAMO camera at `x` (M units) sees along the unit
    /// direction `look` of its frame ([`Kerr::ks_frame`]), traced back
    /// from the camera: the spatial coordinate velocity of the
    /// past-directed null vector -(u + n), n = -look in the frame, the
    /// photon that reaches the camera from there with unit energy. (Its
    /// length matters inside the ergosphere, see [`Kerr::ks_backward`].)
    pub fn ks_camera_ray(self, x: DVec3, look: DVec3) -> DVec3 {
        self.ks_observer_ray(x, self.ks_zamo_velocity(x), look)
    }

    /// [`Kerr::ks_camera_ray`] for the observer of 4-velocity `u` at `x`
    /// (a static observer, or one moving).
    pub fn ks_observer_ray(self, x: DVec3, u: [f64; 4], look: DVec3) -> DVec3 {
        let e = self.ks_frame(x, u);
        let k: [f64; 4] =
            std::array::from_fn(|m| u[m] - look.x * e[0][m] - look.y * e[1][m] - look.z * e[2][m]);
        -DVec3::new(k[1], k[2], k[3])
    }

    /// The past-directed null covector (p, e = -p_t) at `x` (M units) whose
    /// spatial coordinate velocity is `v`: the state [`Kerr::ks_trace`]
    /// traces a ray back from a camera with. Outside the ergosphere one
    /// null vector has that velocity and runs back in time; inside, two
    /// do, and the one a ZAMO measures with energy closest to 1 is taken,
    /// as [`Kerr::ks_camera_ray`] makes it.
    pub fn ks_backward(self, x: DVec3, v: DVec3) -> (DVec3, f64) {
        self.ks_backward_in(x, self.ks_f_l(x), v)
    }

    /// The metric's f and l at `x` ([`Kerr::ks_fields`]), for
    /// [`Kerr::ks_backward_in`].
    pub fn ks_f_l(self, x: DVec3) -> (f64, DVec3) {
        let (f, l, _, _, _) = self.ks_fields::<false>(x);
        (f, l)
    }

    /// [`Kerr::ks_backward`] with the metric's `(f, l)` at `x` found
    /// before (a camera's rays share them).
    pub fn ks_backward_in(self, x: DVec3, fl: (f64, DVec3), v: DVec3) -> (DVec3, f64) {
        let t = self.ks_backward_t(x, fl, v);
        ks_null_lowered(fl, v, t)
    }

    /// [`Kerr::ks_backward_in`] and its rates along `dv`: k = (T, v) with
    /// T a root of g(k, k) = (f - 1) T^2 + 2 f lv T + |v|^2 + f lv^2, so
    /// dT = -(2 f (T + lv) l.dv + 2 v.dv) / (2 (f - 1) T + 2 f lv), and the
    /// lowered vector is linear in k.
    pub fn ks_backward_rates<const N: usize>(
        self,
        x: DVec3,
        (f, l): (f64, DVec3),
        v: DVec3,
        dv: [DVec3; N],
    ) -> ((DVec3, f64), [(DVec3, f64); N]) {
        let t = self.ks_backward_t(x, (f, l), v);
        let lv = l.dot(v);
        let slope = 2.0 * (f - 1.0) * t + 2.0 * f * lv;
        let rates = dv.map(|dv| {
            let dt = -(2.0 * f * (t + lv) * l.dot(dv) + 2.0 * v.dot(dv)) / slope;
            let dlk = dt + l.dot(dv);
            (dv + l * (f * dlk), dt - f * dlk)
        });
        (ks_null_lowered((f, l), v, t), rates)
    }

    /// The T of [`Kerr::ks_backward_in`]'s null vector (T, v).
    fn ks_backward_t(self, x: DVec3, (f, l): (f64, DVec3), v: DVec3) -> f64 {
        let lv = l.dot(v);
        // g(k, k) = 0 for k = (T, v): (f - 1) T^2 + 2 f lv T + |v|^2 + f lv^2.
        let (qa, qb, qc) = (f - 1.0, 2.0 * f * lv, v.length_squared() + f * lv * lv);
        let roots = if qa.abs() < 1e-14 {
            [-qc / qb, f64::NAN]
        } else {
            let d = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            // Without cancellation.
            let q = -0.5 * (qb + qb.signum() * d);
            [q / qa, qc / q]
        };
        let state = |t: f64| ks_null_lowered((f, l), v, t);
        if f < 1.0 {
            // Outside the ergosphere one root runs back in time: every
            // observer there measures its energy e = -k_t negative.
            let past = |t: f64| t.is_finite() && state(t).1 < 0.0;
            match (past(roots[0]), past(roots[1])) {
                (true, false) => return roots[0],
                (false, true) => return roots[1],
                _ => {}
            }
        }
        let u = self.ks_zamo_velocity(x);
        let measured = |t: f64| {
            // -k.u with k = (t, v): the ZAMO's energy of the vector (< 0
            // for one running back in time).
            let kl = self.ks_lower(x, [t, v.x, v.y, v.z]);
            -(kl[0] * u[0] + kl[1] * u[1] + kl[2] * u[2] + kl[3] * u[3])
        };
        let back: Vec<f64> = roots
            .into_iter()
            .filter(|t| t.is_finite() && measured(*t) < 0.0)
            .collect();
        match back.as_slice() {
            [t] => *t,
            [t0, t1] => {
                if (measured(*t0) + 1.0).abs() <= (measured(*t1) + 1.0).abs() {
                    *t0
                } else {
                    *t1
                }
            }
            _ => roots[0],
        }
    }

    /// The closed form's inputs for the null vector `w` (t, x, y, z; traced
    /// back from a camera) at `x`, each linear in `w`: its energy -p_t, L_z,
    /// Boyer-Lindquist p_theta, d r / d lambda and d cos theta / d lambda
    /// (the GPU sums them over the camera's frame vectors in f32, without
    /// a far camera's cancellation).
    pub fn ks_ray_forms(self, x: DVec3, w: [f64; 4]) -> [f64; 5] {
        let v = DVec3::new(w[1], w[2], w[3]);
        let r = self.ks_radius(x);
        self.ks_ray_terms(
            x,
            (r, self.ks_radius_gradient(x, r)),
            self.ks_lower(x, w),
            v,
        )
    }

    /// The spatial covariant momentum at `x` of a photon with energy
    /// `e`, L_z `lz` and Boyer-Lindquist p_r, p_th (as from
    /// [`Kerr::photon_from_zamo`]); None on the axis, where the azimuth
    /// is undefined.
    pub fn ks_momentum(self, x: DVec3, e: f64, lz: f64, p_r: f64, p_th: f64) -> Option<DVec3> {
        let s = self.spheroidal(x);
        let (st, ct) = s.th.sin_cos();
        if st.abs() < 1e-12 {
            return None;
        }
        let (sp, cp) = s.phi.sin_cos();
        let a = self.a;
        // Kerr-Schild's t and phi are Boyer-Lindquist's plus functions of
        // r (dt = 2r/Delta dr, dphi = a/Delta dr): p_r gains their terms.
        let delta = self.delta(s.r);
        let p_r_ks = p_r + (2.0 * s.r * e - a * lz) / delta;
        // Columns: d x / d r, d x / d th, d x / d phi.
        let j = glam::DMat3::from_cols(
            DVec3::new(st * cp, st * sp, ct),
            DVec3::new(
                ct * (s.r * cp - a * sp),
                ct * (s.r * sp + a * cp),
                -s.r * st,
            ),
            DVec3::new(-x.y, x.x, 0.0),
        );
        Some(j.transpose().inverse() * DVec3::new(p_r_ks, p_th, lz))
    }
}

/// The vector (T, v) lowered with the Kerr-Schild metric g = eta + f l l
/// (l_t = 1): its spatial part and its t component.
fn ks_null_lowered((f, l): (f64, DVec3), v: DVec3, t: f64) -> (DVec3, f64) {
    let lk = t + l.dot(v);
    (v + l * (f * lk), t - f * lk)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_zamo_cameras_frame_is_orthonormal_and_without_spin_the_static_one() {
        let g = |k: Kerr, x: DVec3, a: [f64; 4], b: [f64; 4]| {
            let al = k.ks_lower(x, a);
            al.iter().zip(b).map(|(p, q)| p * q).sum::<f64>()
        };
        for (a, x) in [
            (0.9, DVec3::new(3.0, 1.0, 0.5)),
            (0.9, DVec3::new(0.0, 0.0, 4.0)),
            (0.9, DVec3::new(1.7, 0.2, 0.05)),
            (-0.5, DVec3::new(-20.0, 5.0, 9.0)),
        ] {
            let k = Kerr::new(a);
            let u = k.ks_zamo_velocity(x);
            assert!((g(k, x, u, u) + 1.0).abs() < 1e-12, "{x}");
            // Zero angular momentum: u . d_phi = 0.
            assert!(g(k, x, u, [0.0, -x.y, x.x, 0.0]).abs() < 1e-12);
            let e = k.ks_frame(x, u);
            for i in 0..3 {
                assert!(g(k, x, u, e[i]).abs() < 1e-12);
                for j in 0..3 {
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((g(k, x, e[i], e[j]) - want).abs() < 1e-12, "{x} {i} {j}");
                }
            }
        }
        // a = 0: the camera's ray is the Schwarzschild camera's (its
        // coordinate direction, r_s = 2M), and a far camera sees straight.
        let k = Kerr::new(0.0);
        for (x, look) in [
            (DVec3::new(3.0, 1.0, -2.0), DVec3::new(-0.3, 0.9, 0.1)),
            (DVec3::new(0.0, -3.1, 0.0), DVec3::new(0.6, 0.8, 0.0)),
            (DVec3::new(40.0, 0.0, 10.0), DVec3::new(-1.0, 0.0, 0.0)),
        ] {
            let look = look.normalize();
            let v = k.ks_camera_ray(x, look);
            let want = crate::physics::Spacetime::Schwarzschild.camera_direction(x / 2.0, look);
            assert!(
                v.normalize().distance(want.normalize()) < 1e-12,
                "{x}: {v} vs {want}"
            );
        }
        let far = Kerr::new(0.9).ks_camera_ray(DVec3::new(0.0, -1e7, 0.0), DVec3::Y);
        assert!(far.normalize().distance(DVec3::Y) < 1e-6);
    }

    #[test]
    fn a_cameras_ray_is_traced_back_from_the_state_of_its_photon() {
        // The camera's ray gives back a null, past-directed state with
        // unit energy for the ZAMO, also inside the ergosphere (r 1.7 on
        // the equator of a = 0.9, where two null vectors share a velocity).
        for (a, x) in [
            (0.9, DVec3::new(1.7, 0.4, 0.05)),
            (0.9, DVec3::new(10.0, -3.0, 2.0)),
            (0.998, DVec3::new(0.0, 0.0, 3.0)),
        ] {
            let k = Kerr::new(a);
            for look in [DVec3::X, -DVec3::X, DVec3::Y, DVec3::new(0.3, -0.5, 0.8)] {
                let look = look.normalize();
                let v = k.ks_camera_ray(x, look);
                let (p, e) = k.ks_backward(x, v);
                assert!(
                    k.ks_hamiltonian(x, p, e).abs() < 1e-12 * (1.0 + e * e),
                    "{x} {look}"
                );
                // Its velocity is the one asked for.
                assert!(k.ks_flow(x, p, e).dx.distance(v) < 1e-12 * v.length());
                // The ZAMO measures energy 1 for the photon -(p, -e).
                let u = k.ks_zamo_velocity(x);
                let (lz, _) = k.ks_constants(x, p, e);
                let z = k.zamo(k.ks_radius(x), k.spheroidal(x).th);
                let zamo_energy = -(e - z.omega * lz) / z.alpha;
                assert!(
                    (zamo_energy - 1.0).abs() < 1e-10,
                    "{x} {look}: {zamo_energy} {u:?}"
                );
            }
        }
    }
}
