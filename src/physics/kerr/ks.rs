//! Kerr-Schild Cartesian coordinates of the Kerr hole: the Boyer-Lindquist
//! radius and angles of a point, the metric's fields f and l (and their
//! gradients), Hamilton's equations of a photon and its constants of
//! motion. The fields and flow's WGSL twin is `src/gpu/kerr.wgsl`.

use super::Kerr;
use glam::DVec3;

/// A point of Kerr-Schild Cartesian space: the Boyer-Lindquist radius and
/// polar angle, and the azimuth of Kerr-Schild coordinates there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spheroidal {
    pub r: f64,
    pub th: f64,
    /// The Kerr-Schild azimuth: x + i y = (r + i a) sin th e^(i phi).
    pub phi: f64,
}

/// The Hamiltonian flow of a photon in Kerr-Schild Cartesian coordinates
/// at a state (x, p): d x / d lambda, d p / d lambda, d t / d lambda.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flow {
    pub dx: DVec3,
    pub dp: DVec3,
    pub dt: f64,
    /// d t / d lambda of Boyer-Lindquist's time (Schwarzschild's at a =
    /// 0), the clock the disk's orbits and light travel times keep.
    pub dt_bl: f64,
}

/// Kerr-Schild Cartesian coordinates (the metric g = eta + f l l, with no
/// pole or horizon singularity; for a = 0 its space is the one the
/// Schwarzschild tracer integrates in, Schwarzschild r, th, ph read as
/// Cartesian): a photon's state is its position x and the spatial
/// covariant momentum p (p_t = -E, conserved).
impl Kerr {
    /// The Boyer-Lindquist radius of the point `x`: the positive root of
    /// r^4 - (|x|^2 - a^2) r^2 - a^2 z^2 = 0.
    #[inline]
    pub fn ks_radius(self, x: DVec3) -> f64 {
        self.ks_radius2(x).sqrt()
    }

    /// The square of [`Kerr::ks_radius`].
    #[inline(always)]
    fn ks_radius2(self, x: DVec3) -> f64 {
        let a2 = self.a * self.a;
        let w = x.length_squared() - a2;
        // The larger root without cancellation where w < 0 (near the
        // ring): r^2 = a^2 z^2 / (sqrt(w^2/4 + a^2 z^2) - w/2).
        let root = (0.25 * w * w + a2 * x.z * x.z).sqrt();
        if w >= 0.0 {
            0.5 * w + root
        } else {
            a2 * x.z * x.z / (root - 0.5 * w)
        }
    }

    /// The point's Boyer-Lindquist radius and polar angle and its
    /// Kerr-Schild azimuth.
    pub fn spheroidal(self, x: DVec3) -> Spheroidal {
        let r = self.ks_radius(x);
        Spheroidal {
            r,
            th: (x.z / r).clamp(-1.0, 1.0).acos(),
            phi: x.y.atan2(x.x) - self.a.atan2(r),
        }
    }

    /// The Cartesian point of (r, th, phi).
    pub fn cartesian(self, s: Spheroidal) -> DVec3 {
        let (st, ct) = s.th.sin_cos();
        let (sp, cp) = s.phi.sin_cos();
        DVec3::new(
            st * (s.r * cp - self.a * sp),
            st * (s.r * sp + self.a * cp),
            s.r * ct,
        )
    }

    /// f and the covariant null vector's spatial part l (l_t = 1) at `x`,
    /// their gradients when `GRAD`, and r with its gradient.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub(super) fn ks_fields<const GRAD: bool>(
        self,
        x: DVec3,
    ) -> (f64, DVec3, DVec3, [DVec3; 3], (f64, DVec3)) {
        let a = self.a;
        let a2 = a * a;
        // The flow is the integrator's whole cost, and a stage waits on
        // the last: every division needs r^2 only, so they run beside r's
        // square root rather than after it.
        let r2 = self.ks_radius2(x);
        let sigma = 2.0 * r2 - x.length_squared() + a2;
        let (inv_r2, inv_s) = (1.0 / r2, 1.0 / (r2 + a2));
        let q = r2 * r2 + a2 * x.z * x.z;
        let inv_q = 1.0 / q;
        let inv_r2_sigma = if GRAD { 1.0 / (r2 * sigma) } else { 0.0 };
        let r = r2.sqrt();
        let inv_r = r * inv_r2;
        let f = 2.0 * r2 * r * inv_q;
        let (nx, ny) = (r * x.x + a * x.y, r * x.y - a * x.x);
        let l = DVec3::new(nx * inv_s, ny * inv_s, x.z * inv_r);
        if !GRAD {
            return (f, l, DVec3::ZERO, [DVec3::ZERO; 3], (r, DVec3::ZERO));
        }
        // dr/dx_i = (x_i r^2 + a^2 z delta_iz) / (r (2 r^2 - |x|^2 + a^2)).
        let inv_den = r * inv_r2_sigma;
        let dr = (x * r2 + DVec3::new(0.0, 0.0, a2 * x.z)) * inv_den;
        let dq = dr * (4.0 * r2 * r) + DVec3::new(0.0, 0.0, 2.0 * a2 * x.z);
        let df = (dr * (6.0 * r2) - dq * f) * inv_q;
        let ds = dr * (2.0 * r * inv_s);
        // Gradients of l_x, l_y, l_z (each a vector over x, y, z).
        let dlx = (dr * x.x + DVec3::new(r, a, 0.0) - ds * nx) * inv_s;
        let dly = (dr * x.y + DVec3::new(-a, r, 0.0) - ds * ny) * inv_s;
        let dlz = (DVec3::Z * r - dr * x.z) * (inv_r * inv_r);
        (f, l, df, [dlx, dly, dlz], (r, dr))
    }

    /// The metric's f = 2 r^3 / (r^4 + a^2 z^2) at `x` (g_tt = -1 + f).
    pub fn ks_f(self, x: DVec3) -> f64 {
        self.ks_fields::<false>(x).0
    }
    /// The Hamiltonian H = (1/2) g^(mu nu) p_mu p_nu of the state (x, p)
    /// with p_t = -`e`: 0 for a photon.
    pub fn ks_hamiltonian(self, x: DVec3, p: DVec3, e: f64) -> f64 {
        let (f, l, _, _, _) = self.ks_fields::<false>(x);
        let lp = e + l.dot(p);
        0.5 * (p.length_squared() - e * e - f * lp * lp)
    }

    /// Hamilton's equations at (x, p) for a photon of energy `e`.
    #[inline(always)]
    pub fn ks_flow(self, x: DVec3, p: DVec3, e: f64) -> Flow {
        self.flow::<true>(x, p, e)
    }

    /// [`Kerr::ks_flow`], Boyer-Lindquist's time rate only with `BL`.
    #[inline(always)]
    pub(super) fn flow<const BL: bool>(self, x: DVec3, p: DVec3, e: f64) -> Flow {
        let (f, l, df, dl, (r, dr)) = self.ks_fields::<true>(x);
        // l^mu p_mu with l^t = -1, p_t = -e.
        let lp = e + l.dot(p);
        // Its gradient, sum over j of p_j grad l_j.
        let dlp = dl[0] * p.x + dl[1] * p.y + dl[2] * p.z;
        let dx = p - l * (f * lp);
        let dt = e + f * lp;
        Flow {
            dx,
            dp: df * (0.5 * lp * lp) + dlp * (f * lp),
            dt,
            // Boyer-Lindquist's t is Kerr-Schild's less the integral of
            // 2 r / Delta dr.
            dt_bl: if BL {
                dt - 2.0 * r / self.delta(r) * dr.dot(dx)
            } else {
                0.0
            },
        }
    }

    /// The photon's L_z and Carter's Q at the state (x, p) of energy `e`.
    pub fn ks_constants(self, x: DVec3, p: DVec3, e: f64) -> (f64, f64) {
        let lz = x.x * p.y - x.y * p.x;
        let s = self.spheroidal(x);
        let polar = s.th.sin_cos();
        let p_th = ks_p_theta(x, p, s.r, polar);
        (lz, self.carter_q(p_th, lz, e, polar))
    }

    /// Carter's Q of a photon of energy `e`, L_z `lz` and Boyer-Lindquist
    /// p_theta `p_th` where the polar angle's sine and cosine are `(st,
    /// ct)`.
    pub fn carter_q(self, p_th: f64, lz: f64, e: f64, (st, ct): (f64, f64)) -> f64 {
        p_th * p_th + ct * ct * (lz * lz / (st * st) - self.a * self.a * e * e)
    }

    /// The gradient of the Boyer-Lindquist radius `r` at `x`: (x r^2 + a^2
    /// z e_z) / (r (2 r^2 - |x|^2 + a^2)).
    pub fn ks_radius_gradient(self, x: DVec3, r: f64) -> DVec3 {
        let a2 = self.a * self.a;
        (x * (r * r) + DVec3::new(0.0, 0.0, a2 * x.z))
            / (r * (2.0 * r * r - x.length_squared() + a2))
    }

    /// The closed form's terms of a photon at `x` (Boyer-Lindquist radius
    /// `r` and its gradient) with covariant momentum `p` (t, x, y, z) and
    /// coordinate velocity `v`: its energy -p_t, L_z, Boyer-Lindquist
    /// p_theta, d r / d lambda and d cos theta / d lambda, each linear in
    /// (p, v).
    pub fn ks_ray_terms(
        self,
        x: DVec3,
        (r, grad_r): (f64, DVec3),
        p: [f64; 4],
        v: DVec3,
    ) -> [f64; 5] {
        let ct = x.z / r;
        let st = (1.0 - ct * ct).max(0.0).sqrt();
        let lz = x.x * p[2] - x.y * p[1];
        let p_th = ks_p_theta(x, DVec3::new(p[1], p[2], p[3]), r, (st, ct));
        let r_dot = grad_r.dot(v);
        [-p[0], lz, p_th, r_dot, (v.z - ct * r_dot) / r]
    }
    /// The 4-vector `w` (t, x, y, z) at `x` lowered with the Kerr-Schild
    /// metric g = eta + f l l.
    pub(super) fn ks_lower(self, x: DVec3, w: [f64; 4]) -> [f64; 4] {
        let (f, l, _, _, _) = self.ks_fields::<false>(x);
        let lw = w[0] + l.x * w[1] + l.y * w[2] + l.z * w[3];
        [
            -w[0] + f * lw,
            w[1] + f * l.x * lw,
            w[2] + f * l.y * lw,
            w[3] + f * l.z * lw,
        ]
    }
}

/// Boyer-Lindquist p_theta of the spatial momentum `p` at `x` (radius `r`,
/// polar angle's sine and cosine `(st, ct)`): its component along d x / d
/// theta at fixed r and phi.
pub(super) fn ks_p_theta(x: DVec3, p: DVec3, r: f64, (st, ct): (f64, f64)) -> f64 {
    ct / st * (x.x * p.x + x.y * p.y) - r * st * p.z
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::kerr::tests::rk4;
    use std::f64::consts::PI;

    #[test]
    fn kerr_schild_coordinates_round_trip() {
        let k = Kerr::new(0.9);
        for (r, th, phi) in [(1.5, 0.3, 1.0), (3.0, 1.55, -2.0), (40.0, 2.8, 3.0)] {
            let x = k.cartesian(Spheroidal { r, th, phi });
            let s = k.spheroidal(x);
            assert!((s.r - r).abs() < 1e-12 * r && (s.th - th).abs() < 1e-12);
            let dphi = (s.phi - phi).rem_euclid(2.0 * PI);
            assert!(dphi.min(2.0 * PI - dphi) < 1e-12);
        }
        // On the disk's plane the Boyer-Lindquist radius r lies at
        // cylindrical radius sqrt(r^2 + a^2).
        let x = DVec3::new((36.0f64 + 0.81).sqrt(), 0.0, 0.0);
        assert!((k.ks_radius(x) - 6.0).abs() < 1e-13);
    }

    #[test]
    fn hamiltons_equations_are_the_hamiltonians_gradients() {
        // Against central differences of H, at points near the hole, off
        // the plane, close to the ring's plane and far out.
        let k = Kerr::new(0.9);
        let e = 1.3;
        for (x, p) in [
            (DVec3::new(2.0, 0.5, 0.7), DVec3::new(-0.4, 0.9, 0.2)),
            (DVec3::new(-1.2, 1.1, 0.05), DVec3::new(0.3, -0.2, 1.0)),
            (DVec3::new(30.0, -20.0, 10.0), DVec3::new(-1.0, 0.5, 0.1)),
        ] {
            let flow = k.ks_flow(x, p, e);
            for i in 0..3 {
                let d = DVec3::from_array(std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }));
                let h = 1e-6 * x.length();
                let dh_dx = (k.ks_hamiltonian(x + d * h, p, e) - k.ks_hamiltonian(x - d * h, p, e))
                    / (2.0 * h);
                let dh_dp = (k.ks_hamiltonian(x, p + d * 1e-6, e)
                    - k.ks_hamiltonian(x, p - d * 1e-6, e))
                    / 2e-6;
                let scale = flow.dp.length().max(1e-3);
                assert!(
                    (flow.dp.to_array()[i] + dh_dx).abs() < 1e-7 * scale,
                    "{x} {i}: {} vs {}",
                    flow.dp.to_array()[i],
                    -dh_dx
                );
                assert!((flow.dx.to_array()[i] - dh_dp).abs() < 1e-7, "{x} {i}");
            }
            // dt / d lambda = dH / d p_t = -dH / dE.
            let dh_de =
                (k.ks_hamiltonian(x, p, e + 1e-6) - k.ks_hamiltonian(x, p, e - 1e-6)) / 2e-6;
            assert!((flow.dt + dh_de).abs() < 1e-7);
        }
    }

    #[test]
    fn without_spin_the_flow_is_the_schwarzschild_tracers_equation() {
        // a = 0: space is Schwarzschild r, th, ph read as Cartesian, and a
        // photon obeys x'' = -3 h^2 x / r^5 (M = 1), h = |x x x'|.
        let k = Kerr::new(0.0);
        let x = DVec3::new(7.0, -2.0, 3.0);
        let n = DVec3::new(-0.6, 0.7, 0.2).normalize();
        // A photon of unit energy for a static observer there (the ZAMO at
        // a = 0), its local direction n: radial and tangential parts.
        let s = k.spheroidal(x);
        let (er, eth) = (x / s.r, {
            let (st, ct) = s.th.sin_cos();
            let (sp, cp) = s.phi.sin_cos();
            DVec3::new(ct * cp, ct * sp, -st)
        });
        let eph = er.cross(eth);
        let local = [n.dot(er), n.dot(eth), n.dot(eph)];
        let c = k.photon_from_zamo(s.r, s.th, local);
        let p = k.ks_momentum(x, c.energy, c.lz, c.p_r, c.p_th).unwrap();
        assert!(k.ks_hamiltonian(x, p, c.energy).abs() < 1e-13);
        let eps = 1e-4;
        let (xa, pa) = rk4(k, x, p, c.energy, eps);
        let (xb, pb) = rk4(k, x, p, c.energy, -eps);
        let v = k.ks_flow(x, p, c.energy).dx;
        let acc = (k.ks_flow(xa, pa, c.energy).dx - k.ks_flow(xb, pb, c.energy).dx) / (2.0 * eps);
        let want = x * (-3.0 * x.cross(v).length_squared() / s.r.powi(5));
        assert!(acc.distance(want) < 1e-7 * want.length(), "{acc} vs {want}");
    }

    #[test]
    fn a_zamos_photon_in_kerr_schild_form_keeps_its_constants() {
        // The camera's photon mapped to Kerr-Schild momentum is null and
        // has the ZAMO's E, L_z and Q; along its path (through the
        // ergosphere, past the hole) H, L_z and Q stay put.
        let k = Kerr::new(0.9);
        for (r, th, phi, n) in [
            (30.0, 1.2, 0.3, [-0.995, 0.03, 0.0999]),
            (30.0, 0.5, 2.0, [-0.99, -0.1, -0.0995]),
            (8.0, PI / 2.0, -1.0, [-0.9, 0.0, 0.435889894]),
            (1.8, 1.4, 0.0, [0.6, 0.0, 0.8]),
        ] {
            let n = {
                let v = DVec3::from_array(n).normalize();
                [v.x, v.y, v.z]
            };
            let c = k.photon_from_zamo(r, th, n);
            let x = k.cartesian(Spheroidal { r, th, phi });
            let p = k.ks_momentum(x, c.energy, c.lz, c.p_r, c.p_th).unwrap();
            let e = c.energy;
            assert!(k.ks_hamiltonian(x, p, e).abs() < 1e-12 * e * e, "{r} {th}");
            let (lz, q) = k.ks_constants(x, p, e);
            assert!(
                (lz - c.lz).abs() < 1e-12 * (1.0 + c.lz.abs()),
                "{lz} vs {}",
                c.lz
            );
            assert!(
                (q - c.carter).abs() < 1e-10 * (1.0 + c.carter.abs()),
                "{q} vs {}",
                c.carter
            );
            let (mut xs, mut ps) = (x, p);
            let scale = 1.0 + c.carter.abs();
            for _ in 0..20_000 {
                (xs, ps) = rk4(k, xs, ps, e, 0.002 * k.ks_radius(xs).min(10.0));
                let rr = k.ks_radius(xs);
                if rr < 1.01 * k.horizon() || rr > 100.0 {
                    break;
                }
                let (l, qq) = k.ks_constants(xs, ps, e);
                assert!(
                    (l - c.lz).abs() < 1e-9 * (1.0 + c.lz.abs()),
                    "L_z {l} vs {}",
                    c.lz
                );
                assert!(
                    (qq - c.carter).abs() < 1e-9 * scale,
                    "Q {qq} vs {} at r {rr}",
                    c.carter
                );
                assert!(k.ks_hamiltonian(xs, ps, e).abs() < 1e-9 * e * e);
            }
        }
    }
}
