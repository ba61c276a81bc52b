//! Closed-form results of the Kerr (spinning) hole: horizon, ergosphere,
//! the locally non-rotating (ZAMO) frame and a photon's constants of
//! motion from it, equatorial circular orbits (angular velocity, energy,
//! innermost stable orbit, efficiency), the photon orbits, the frequency
//! shift of an orbiting emitter, Page and Thorne's flux of a thin disk and
//! Bardeen's shadow curve. What the spinning spacetime's renderer, its
//! `info` and its tests are built on.
//!
//! Boyer-Lindquist coordinates in geometric units of the hole's mass
//! (G = c = M = 1: lengths in GM/c^2 = r_s / 2), the spin `a` = J c /
//! (G M^2) along +z. Circular orbits here are counter-clockwise seen from
//! +z, as the disk turns: prograde for a > 0, retrograde for a < 0 (a
//! retrograde orbit of a hole of spin a is the counter-clockwise orbit of
//! spin -a, mirrored).

use glam::DVec3;
use std::f64::consts::PI;

/// A Kerr hole of mass 1 and spin `a` (|a| < 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kerr {
    /// J c / (G M^2), along +z.
    pub a: f64,
}

/// The locally non-rotating observer's frame at a point: lapse, frame
/// dragging and the circumferential radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Zamo {
    /// alpha = sqrt(Sigma Delta / A): its proper time per coordinate time.
    pub alpha: f64,
    /// omega = 2 a r / A: the angular velocity it turns at.
    pub omega: f64,
    /// varpi = sqrt(A / Sigma) sin th.
    pub varpi: f64,
    /// sqrt(Delta / Sigma) and sqrt(Sigma), the radial and polar scales
    /// of its tetrad.
    pub radial: f64,
    pub polar: f64,
}

/// A photon's constants of motion and its momentum's components.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonConstants {
    /// Energy at infinity E = -p_t.
    pub energy: f64,
    /// Angular momentum about the spin axis L_z = p_ph.
    pub lz: f64,
    /// Carter's constant Q.
    pub carter: f64,
    /// p_r and p_th (covariant).
    pub p_r: f64,
    pub p_th: f64,
}

impl Kerr {
    /// The hole of spin `a`.
    pub fn new(a: f64) -> Kerr {
        Kerr { a }
    }

    /// Sigma = r^2 + a^2 cos^2 th.
    #[inline]
    pub fn sigma(self, r: f64, th: f64) -> f64 {
        r * r + self.a * self.a * th.cos().powi(2)
    }

    /// Delta = r^2 - 2 r + a^2.
    #[inline]
    pub fn delta(self, r: f64) -> f64 {
        r * r - 2.0 * r + self.a * self.a
    }

    /// A = (r^2 + a^2)^2 - a^2 Delta sin^2 th.
    #[inline]
    pub fn big_a(self, r: f64, th: f64) -> f64 {
        let a2 = self.a * self.a;
        (r * r + a2).powi(2) - a2 * self.delta(r) * th.sin().powi(2)
    }

    /// The outer horizon r_+ = 1 + sqrt(1 - a^2).
    pub fn horizon(self) -> f64 {
        1.0 + (1.0 - self.a * self.a).sqrt()
    }

    /// The ergosphere's radius at polar angle `th`, 1 + sqrt(1 - a^2
    /// cos^2 th) (2 on the equator): static observers exist only outside.
    pub fn ergosphere(self, th: f64) -> f64 {
        1.0 + (1.0 - (self.a * th.cos()).powi(2)).sqrt()
    }

    /// The ZAMO's frame at (r, th), outside the horizon.
    pub fn zamo(self, r: f64, th: f64) -> Zamo {
        let (sigma, delta, big_a) = (self.sigma(r, th), self.delta(r), self.big_a(r, th));
        Zamo {
            alpha: (sigma * delta / big_a).sqrt(),
            omega: 2.0 * self.a * r / big_a,
            varpi: (big_a / sigma).sqrt() * th.sin(),
            radial: (delta / sigma).sqrt(),
            polar: sigma.sqrt(),
        }
    }

    /// The constants of a photon of unit energy in the ZAMO's frame at
    /// (r, th) moving along the unit direction `n` = (n_r, n_th, n_ph) of
    /// that frame (n_r outward, n_th towards larger th, n_ph along the
    /// orbit's direction).
    pub fn photon_from_zamo(self, r: f64, th: f64, n: [f64; 3]) -> PhotonConstants {
        let z = self.zamo(r, th);
        let lz = z.varpi * n[2];
        let energy = z.alpha + z.omega * lz;
        let p_th = z.polar * n[1];
        let (s, c) = th.sin_cos();
        PhotonConstants {
            energy,
            lz,
            carter: p_th * p_th + c * c * (lz * lz / (s * s) - self.a * self.a * energy * energy),
            p_r: n[0] / z.radial,
            p_th,
        }
    }

    /// g = nu_observed / nu_infinity of light from infinity reaching the
    /// ZAMO at (r, th) with L_z / E = `b`: (1 - omega b) / alpha.
    pub fn zamo_sky_shift(self, r: f64, th: f64, b: f64) -> f64 {
        let z = self.zamo(r, th);
        (1.0 - z.omega * b) / z.alpha
    }

    /// r^1.5 - 3 r^0.5 + 2a, whose root bounds circular orbits.
    #[inline]
    fn orbit_root(self, r: f64) -> f64 {
        r.powf(1.5) - 3.0 * r.sqrt() + 2.0 * self.a
    }

    /// Whether a counter-clockwise circular orbit exists at `r` (outside
    /// the photon orbit; it is stable from the ISCO out).
    pub fn has_circular_orbit(self, r: f64) -> bool {
        r > self.photon_orbit() && self.orbit_root(r) > 0.0
    }

    /// The angular velocity dph/dt of the counter-clockwise circular orbit
    /// at `r`: 1 / (r^1.5 + a).
    pub fn orbital_angular_velocity(self, r: f64) -> f64 {
        1.0 / (r.powf(1.5) + self.a)
    }

    /// Energy per unit mass of the circular orbit at `r`:
    /// (r^1.5 - 2 r^0.5 + a) / (r^0.75 sqrt(r^1.5 - 3 r^0.5 + 2a)).
    pub fn orbit_energy(self, r: f64) -> f64 {
        (r.powf(1.5) - 2.0 * r.sqrt() + self.a) / (r.powf(0.75) * self.orbit_root(r).sqrt())
    }

    /// Angular momentum per unit mass of the circular orbit at `r`:
    /// (r^2 - 2 a r^0.5 + a^2) / (r^0.75 sqrt(r^1.5 - 3 r^0.5 + 2a)).
    pub fn orbit_angular_momentum(self, r: f64) -> f64 {
        let a = self.a;
        (r * r - 2.0 * a * r.sqrt() + a * a) / (r.powf(0.75) * self.orbit_root(r).sqrt())
    }

    /// u^t of the circular orbit at `r`: (r^1.5 + a) / (r^0.75
    /// sqrt(r^1.5 - 3 r^0.5 + 2a)).
    pub fn orbit_ut(self, r: f64) -> f64 {
        (r.powf(1.5) + self.a) / (r.powf(0.75) * self.orbit_root(r).sqrt())
    }

    /// The innermost stable circular orbit (Bardeen, Press & Teukolsky
    /// 1972) of the counter-clockwise orbit.
    pub fn isco(self) -> f64 {
        let a = self.a;
        let z1 = 1.0 + (1.0 - a * a).cbrt() * ((1.0 + a).cbrt() + (1.0 - a).cbrt());
        let z2 = (3.0 * a * a + z1 * z1).sqrt();
        let root = ((3.0 - z1) * (3.0 + z1 + 2.0 * z2)).max(0.0).sqrt();
        if a >= 0.0 {
            3.0 + z2 - root
        } else {
            3.0 + z2 + root
        }
    }

    /// The radiative efficiency of a thin disk ending at the ISCO, 1 -
    /// E(r_isco).
    pub fn efficiency(self) -> f64 {
        1.0 - self.orbit_energy(self.isco())
    }

    /// The circular photon orbit turning counter-clockwise:
    /// 2 (1 + cos((2/3) acos(-a))).
    pub fn photon_orbit(self) -> f64 {
        2.0 * (1.0 + ((2.0 / 3.0) * (-self.a).acos()).cos())
    }

    /// g = nu_infinity / nu_emitted of light leaving the circular orbit at
    /// `r` with L_z / E = `b` for infinity: 1 / (u^t (1 - Omega b)).
    pub fn orbit_shift(self, r: f64, b: f64) -> f64 {
        1.0 / (self.orbit_ut(r) * (1.0 - self.orbital_angular_velocity(r) * b))
    }

    /// Page and Thorne's (1974) flux per face of a thin disk in the gas's
    /// frame at `r`, for an accretion rate of 1 (geometric units), the
    /// torque vanishing at its inner edge `r_in` (the ISCO, or further
    /// out); 0 inside it.
    pub fn page_thorne_flux(self, r: f64, r_in: f64) -> f64 {
        self.page_thorne().flux(r, r_in)
    }

    /// The spin's constants of Page and Thorne's flux, found once for a
    /// disk's every hit.
    pub fn page_thorne(self) -> PageThorne {
        let a = self.a;
        let t = a.acos() / 3.0;
        let roots = [
            2.0 * (t - PI / 3.0).cos(),
            2.0 * (t + PI / 3.0).cos(),
            -2.0 * t.cos(),
        ];
        let coef = std::array::from_fn(|i| {
            let xi = roots[i];
            let prod: f64 = (0..3).filter(|&j| j != i).map(|j| xi - roots[j]).product();
            3.0 * (xi - a).powi(2) / (xi * prod)
        });
        PageThorne { a, roots, coef }
    }

    /// Bardeen's (1973) shadow curve for a camera at infinity at
    /// inclination `incl` (radians from the spin axis), sampled at `n`
    /// spherical photon orbits: the upper half's screen points (alpha,
    /// beta >= 0) in units of M (angles times the camera's distance),
    /// alpha = -xi / sin(incl) along the screen's horizontal axis, so that
    /// photons turning with the hole (xi > 0 for a > 0) lie at negative
    /// alpha: the side where the rotation comes towards the camera, which
    /// holds the flat side of the "D". Orbits this camera does not see
    /// (beta^2 < 0) are left out.
    pub fn shadow_curve(self, incl: f64, n: usize) -> Vec<(f64, f64)> {
        let a = self.a;
        let (s, c) = incl.sin_cos();
        let point = |r: f64| {
            let (xi, eta) = self.spherical_photon_orbit(r);
            (-xi / s, eta + a * a * c * c - xi * xi * (c / s).powi(2))
        };
        // The orbits seen lie between the two circular ones, where beta^2
        // >= 0: its ends found on a grid, then by bisection.
        let (pro, retro) = (
            Kerr::new(a.abs()).photon_orbit(),
            Kerr::new(-a.abs()).photon_orbit(),
        );
        let grid = 4096;
        let at = |k: usize| pro + (retro - pro) * k as f64 / grid as f64;
        let seen: Vec<usize> = (0..=grid).filter(|&k| point(at(k)).1 >= 0.0).collect();
        let (Some(&first), Some(&last)) = (seen.first(), seen.last()) else {
            return Vec::new();
        };
        let edge = |inside: f64, outside: f64| {
            let (mut lo, mut hi) = (inside, outside);
            for _ in 0..100 {
                let mid = 0.5 * (lo + hi);
                if point(mid).1 >= 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        let r0 = if first == 0 {
            pro
        } else {
            edge(at(first), at(first - 1))
        };
        let r1 = if last == grid {
            retro
        } else {
            edge(at(last), at(last + 1))
        };
        (0..n)
            .map(|k| {
                // Chebyshev-spaced with both ends, to resolve where the
                // curve turns.
                let u = 0.5 - 0.5 * (PI * k as f64 / (n - 1).max(1) as f64).cos();
                let (alpha, b2) = point(r0 + (r1 - r0) * u);
                (alpha, b2.max(0.0).sqrt())
            })
            .collect()
    }

    /// The constants (xi = L_z / E, eta = Q / E^2) of the spherical photon
    /// orbit of radius `r` (between the two circular photon orbits).
    pub fn spherical_photon_orbit(self, r: f64) -> (f64, f64) {
        let a = self.a;
        let xi = -(r * r * r - 3.0 * r * r + a * a * r + a * a) / (a * (r - 1.0));
        let eta =
            r * r * r * (4.0 * self.delta(r) - r * (r - 1.0).powi(2)) / (a * a * (r - 1.0).powi(2));
        (xi, eta)
    }
}

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
    fn ks_fields<const GRAD: bool>(
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
        let out = super::reflect(local, normal);
        DVec3::from_array(std::array::from_fn(|m| {
            energy * u[m + 1]
                + out.x * frame[0][m + 1]
                + out.y * frame[1][m + 1]
                + out.z * frame[2][m + 1]
        }))
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
    fn flow<const BL: bool>(self, x: DVec3, p: DVec3, e: f64) -> Flow {
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

    /// The exact direction at infinity of the outbound photon at the state
    /// (x, p) of energy `e`, well past its last radial turning point (its
    /// direction within 60 degrees of the outward radial, as for the
    /// Schwarzschild tail). The rest of the path in Mino time (d lambda_M
    /// = d lambda / Sigma, in which Carter's equations separate): the time
    /// to infinity G = integral of dr / sqrt(R) and the radial part of the
    /// azimuth's advance by Gauss-Legendre quadrature in u = 1/r, the
    /// polar motion theta'' = Theta'(theta) / 2 over G with error control
    /// (through a pole if L_z = 0), and the Kerr-Schild azimuth's own term,
    /// the integral of a / Delta dr.
    pub fn ks_escape_direction(self, x: DVec3, p: DVec3, e: f64) -> DVec3 {
        use super::tail::quad;
        let a = self.a;
        let sph = self.spheroidal(x);
        let (st, ct) = sph.th.sin_cos();
        let lz = x.x * p.y - x.y * p.x;
        // d theta / d lambda_M = p_th.
        let p_th = ks_p_theta(x, p, sph.r, (st, ct));
        let q = self.carter_q(p_th, lz, e, (st, ct));
        let k = q + (lz - a * e).powi(2);
        let u0 = 1.0 / sph.r;
        let energy_term = |u: f64| e * (1.0 + a * a * u * u) - a * lz * u * u;
        let delta_u = |u: f64| 1.0 - 2.0 * u + a * a * u * u;
        // R(r) / r^4 in u: the radial potential, smooth down to u = 0.
        let radial = |u: f64| energy_term(u).powi(2) - u * u * delta_u(u) * k;
        let mino = u0 * quad(|t| 1.0 / radial(u0 * t).sqrt());
        let phi_radial = u0
            * quad(|t| {
                let u = u0 * t;
                a * energy_term(u) / (delta_u(u) * radial(u).sqrt()) + a / delta_u(u)
            });
        // The polar motion and its part of the azimuth over Mino time.
        // How close to the axis the polar motion swings: u = cos theta
        // turns where Q - c1 u^2 - a^2 E^2 u^4 = 0.
        let c1 = q + lz * lz - a * a * e * e;
        let ae2 = a * a * e * e;
        let u_turn2 = if ae2 > 0.0 {
            (-c1 + (c1 * c1 + 4.0 * ae2 * q).max(0.0).sqrt()) / (2.0 * ae2)
        } else {
            q / c1.max(1e-300)
        };
        let (th, phi_polar) = if u_turn2 > 0.9 {
            // Near a pole, in theta (through it if L_z = 0: theta < 0 is
            // the other side): theta'' = Theta'(theta) / 2.
            let f = |y: &DVec3| {
                let (s, c) = y.x.sin_cos();
                let pole = if lz == 0.0 { 0.0 } else { lz / (s * s) };
                DVec3::new(y.y, -ae2 * c * s + pole * pole * c * s, pole - a * e)
            };
            let y = integrate_mino(f, DVec3::new(sph.th, p_th, 0.0), mino, q, a * e);
            (y.x, y.z)
        } else {
            // Elsewhere in u = cos theta, whose equation is polynomial (no
            // trigonometry in the loop): u'' = -c1 u - 2 a^2 E^2 u^3.
            let f = |y: &DVec3| {
                let u = y.x;
                DVec3::new(
                    y.y,
                    -c1 * u - 2.0 * ae2 * u * u * u,
                    lz / (1.0 - u * u) - a * e,
                )
            };
            let y = integrate_mino(f, DVec3::new(ct, -st * p_th, 0.0), mino, q, a * e);
            (y.x.clamp(-1.0, 1.0).acos(), y.z)
        };
        let phi = sph.phi + phi_radial + phi_polar;
        let (s, c) = th.sin_cos();
        DVec3::new(s * phi.cos(), s * phi.sin(), c)
    }

    /// Traces the photon at the Kerr-Schild state (x, p) of energy `e`
    /// (M units) with Dormand-Prince 5(4) on Hamilton's equations, local
    /// error `tolerance` relative to r and |p|; each accepted step is
    /// handed to `visit` as a [`Segment`] in r_s (the scene's units, half
    /// of M's: the cubic Hermite curve through the ends' positions and
    /// d x / d lambda), and the state's momentum at its end. It ends
    /// captured inside the horizon, or inbound inside both the prograde
    /// photon orbit (inside which no photon turns back out) and
    /// `limits.inner`; escaped with the exact tail once outbound beyond
    /// `limits.outer` and 60 degrees from radial; stopped by `visit`; or
    /// abandoned after `limits.max_steps`. With `TIME` each segment
    /// carries the light's travel time from its ends to the start (r_s/c;
    /// the ray runs back in time), its error held to the tolerance too.
    pub fn ks_trace<const TIME: bool>(
        self,
        x: DVec3,
        p: DVec3,
        e: f64,
        tolerance: f64,
        limits: &super::Limits,
        mut visit: impl FnMut(&super::Segment, DVec3) -> super::Flow,
    ) -> super::Trace {
        use super::{End, Segment, Trace};
        let done = |end, steps| Trace {
            end,
            steps,
            ln_shift: 0.0,
        };
        let (mut x, mut p) = (x, p);
        // A ray traced back towards the horizon comes from the past one
        // (an eternal hole's white hole), which Kerr-Schild's ingoing
        // chart reaches only as its azimuth winds without end: it is
        // captured (black, as from a collapsed star) once it is within
        // 1e-3 of r_+, a few turns of winding in.
        let horizon = self.horizon() * (1.0 + 1e-3);
        // Every object lies beyond limits.inner (r_s) from the centre, so
        // beyond Boyer-Lindquist's sqrt(inner^2 - a^2) (in M).
        let inner = ((2.0 * limits.inner).powi(2) - self.a * self.a)
            .max(0.0)
            .sqrt();
        let capture = inner.min(Kerr::new(self.a.abs()).photon_orbit());
        // In M: limits are in r_s.
        let outer = 2.0 * limits.outer;
        let outbound = |x: DVec3, v: DVec3, r: f64| {
            r > outer && r > 4.0 && x.dot(v) >= 0.5 * x.length() * v.length()
        };
        let mut r = self.ks_radius(x);
        let mut v = self.ks_flow(x, p, e).dx;
        if outbound(x, v, r) {
            return done(End::Escaped(self.ks_escape_direction(x, p, e)), 0);
        }
        // The state and minus Boyer-Lindquist's time (the travel time back
        // from the start, in M).
        let f = |y: &KsState| {
            let fl = self.flow::<TIME>(y.x, y.p, e);
            KsState {
                x: fl.dx,
                p: fl.dp,
                t: -fl.dt_bl,
            }
        };
        let mut time = 0.0;
        let first = self.ks_flow(x, p, e);
        let mut rate = -first.dt_bl;
        let mut k = KsState {
            x: first.dx,
            p: first.dp,
            t: rate,
        };
        let mut h = 0.05 * r / v.length();
        let mut steps = 0;
        while steps < limits.max_steps {
            let speed = v.length();
            h = h.min(0.5 * r / speed);
            let y = KsState { x, p, t: time };
            let (yn, err, kn) = super::gr::dp45(f, &y, &k, h);
            let (xn, pn) = (yn.x, yn.p);
            let (ex, ep) = (err.x.length(), err.p.length());
            let rn = self.ks_radius(xn);
            let et = if TIME { err.t.abs() } else { 0.0 };
            let err = (ex.max(et) / (tolerance * r.max(rn))).max(ep / (tolerance * p.length()));
            if !(err <= 1.0) {
                if !err.is_finite() || h < 1e-12 * r / speed {
                    return done(End::Abandoned, steps);
                }
                h *= (0.9 * step_factor(err)).max(0.2);
                continue;
            }
            steps += 1;
            // The step's last stage is the flow at its end.
            let vn = kn.x;
            let (tn, rate_n) = (yn.t, kn.t);
            k = kn;
            let seg = Segment {
                x0: x * 0.5,
                v0: v * 0.5,
                x1: xn * 0.5,
                v1: vn * 0.5,
                h,
                curved: true,
                ln_shift: [0.0; 2],
                time: if TIME {
                    [0.5 * time, 0.5 * tn]
                } else {
                    [0.0; 2]
                },
                time_rate: if TIME {
                    super::TimeRate::Ends([0.5 * rate * h, 0.5 * rate_n * h])
                } else {
                    super::TimeRate::Untimed
                },
            };
            (time, rate) = (tn, rate_n);
            if visit(&seg, pn) == super::Flow::Stop {
                return done(End::Stopped, steps);
            }
            (x, p, v, r) = (xn, pn, vn, rn);
            if (r < horizon || r < capture) && x.dot(v) < 0.0 || r < self.horizon() {
                return done(End::Captured, steps);
            }
            if outbound(x, v, r) {
                return done(End::Escaped(self.ks_escape_direction(x, p, e)), steps);
            }
            h *= if err > 0.0 {
                (0.9 * step_factor(err)).min(5.0)
            } else {
                5.0
            };
        }
        done(End::Abandoned, steps)
    }

    /// The 4-vector `w` (t, x, y, z) at `x` lowered with the Kerr-Schild
    /// metric g = eta + f l l.
    fn ks_lower(self, x: DVec3, w: [f64; 4]) -> [f64; 4] {
        let (f, l, _, _, _) = self.ks_fields::<false>(x);
        let lw = w[0] + l.x * w[1] + l.y * w[2] + l.z * w[3];
        [
            -w[0] + f * lw,
            w[1] + f * l.x * lw,
            w[2] + f * l.y * lw,
            w[3] + f * l.z * lw,
        ]
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
    pub fn ks_backward_in(self, x: DVec3, (f, l): (f64, DVec3), v: DVec3) -> (DVec3, f64) {
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
        let state = |t: f64| {
            let lk = t + lv;
            (v + l * (f * lk), t - f * lk)
        };
        if f < 1.0 {
            // Outside the ergosphere one root runs back in time: every
            // observer there measures its energy e = -k_t negative.
            let past = |t: f64| t.is_finite() && state(t).1 < 0.0;
            match (past(roots[0]), past(roots[1])) {
                (true, false) => return state(roots[0]),
                (false, true) => return state(roots[1]),
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
        let t = match back.as_slice() {
            [t] => *t,
            [t0, t1] => {
                if (measured(*t0) + 1.0).abs() <= (measured(*t1) + 1.0).abs() {
                    *t0
                } else {
                    *t1
                }
            }
            _ => roots[0],
        };
        state(t)
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

/// Boyer-Lindquist p_theta of the spatial momentum `p` at `x` (radius `r`,
/// polar angle's sine and cosine `(st, ct)`): its component along d x / d
/// theta at fixed r and phi.
fn ks_p_theta(x: DVec3, p: DVec3, r: f64, (st, ct): (f64, f64)) -> f64 {
    ct / st * (x.x * p.x + x.y * p.y) - r * st * p.z
}

/// Page and Thorne's flux for one spin: the roots x_i of x^3 - 3x + 2a and
/// their coefficients 3 (x_i - a)^2 / (x_i prod_(j != i) (x_i - x_j))
/// (also the GPU's constants).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PageThorne {
    pub a: f64,
    pub roots: [f64; 3],
    pub coef: [f64; 3],
}

impl PageThorne {
    /// [`Kerr::page_thorne_flux`] at `r` for the inner edge `r_in` (M).
    pub fn flux(&self, r: f64, r_in: f64) -> f64 {
        let a = self.a;
        if r <= r_in {
            return 0.0;
        }
        let (x, x0) = (r.sqrt(), r_in.sqrt());
        let sum: f64 = (0..3)
            .map(|i| self.coef[i] * ((x - self.roots[i]) / (x0 - self.roots[i])).ln())
            .sum();
        let bracket = x - x0 - 1.5 * a * (x / x0).ln() - sum;
        3.0 / (8.0 * PI * x.powi(4) * (x * x * x - 3.0 * x + 2.0 * a)) * bracket
    }
}

/// The tracer's state: position, spatial momentum and (last) minus
/// Boyer-Lindquist's time, or their rates.
#[derive(Clone, Copy)]
struct KsState {
    x: DVec3,
    p: DVec3,
    t: f64,
}

impl std::ops::Add for KsState {
    type Output = KsState;
    #[inline(always)]
    fn add(self, o: KsState) -> KsState {
        KsState {
            x: self.x + o.x,
            p: self.p + o.p,
            t: self.t + o.t,
        }
    }
}

impl std::ops::Mul<f64> for KsState {
    type Output = KsState;
    #[inline(always)]
    fn mul(self, c: f64) -> KsState {
        KsState {
            x: self.x * c,
            p: self.p * c,
            t: self.t * c,
        }
    }
}

/// err^(-1/5), the step's growth for an error `err` of the tolerance, to
/// 0.3%: an exponent-halving guess from the float's bits and two Newton
/// steps on y^-5 = err (a factor needs no more; libm's powf, even in f32,
/// cost a tenth of the tracer's time). For err in 1e-30 to 1e30.
#[inline]
fn step_factor(err: f64) -> f64 {
    const ONE: u64 = 0x3ff0_0000_0000_0000;
    // bits(y) = bits(1) - (bits(err) - bits(1)) / 5: y's exponent is
    // -1/5 of err's, its mantissa linear between.
    let bits = err.to_bits();
    let mut y = f64::from_bits(if bits >= ONE {
        ONE - (bits - ONE) / 5
    } else {
        ONE + (ONE - bits) / 5
    });
    for _ in 0..2 {
        let y2 = y * y;
        y *= 0.2 * (6.0 - err * y2 * y2 * y);
    }
    y
}

/// The polar motion's state y = (angle or cos, its rate, the azimuth's
/// polar part) carried over Mino time `mino` by Dormand-Prince 5(4) with
/// error control, 1e-10 of the motion's scale (which a photon of Carter's
/// `q` and a E `ae` sets): directions to 1e-11 rad, far below any pixel
/// (1e-12 cost 40% more of the tail's time for nothing seen).
fn integrate_mino(
    f: impl Fn(&DVec3) -> DVec3 + Copy,
    mut y: DVec3,
    mino: f64,
    q: f64,
    ae: f64,
) -> DVec3 {
    let (mut done, mut h) = (0.0, mino / 4.0);
    let scale = 1.0 + (q.abs() + ae * ae).sqrt() * mino;
    let mut tries = 0;
    let mut k = f(&y);
    while done < mino && tries < 100_000 {
        tries += 1;
        h = h.min(mino - done);
        let (yn, err, kn) = super::gr::dp45(f, &y, &k, h);
        let err = err.abs().max_element() / (1e-10 * scale);
        if err <= 1.0 {
            (y, k) = (yn, kn);
            done += h;
        }
        h *= (0.9 * step_factor(err.max(1e-10))).clamp(0.2, 5.0);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1e-300)
    }

    #[test]
    fn the_step_factor_is_the_fifth_root_to_three_per_mille() {
        let mut worst = 0.0f64;
        for i in -600..=600 {
            let err = 10f64.powf(i as f64 / 50.0);
            let want = err.powf(-0.2);
            worst = worst.max((step_factor(err) / want - 1.0).abs());
        }
        eprintln!("worst {worst:e}");
        assert!(worst < 3e-3, "{worst}");
    }

    #[test]
    fn horizons_orbits_and_efficiencies_match_the_reference_table() {
        // PHYSICS.md section 7: a, r_+, r_isco pro/retro, eta pro/retro,
        // r_ph pro/retro.
        let table = [
            (0.0, 2.0, 6.0, 6.0, 0.057190958, 0.057190958, 3.0, 3.0),
            (
                0.5,
                1.866025404,
                4.233002530,
                7.554584715,
                0.082117993,
                0.045142227,
                2.347296355,
                3.532088886,
            ),
            (
                0.9,
                1.435889894,
                2.320883042,
                8.717352280,
                0.155752992,
                0.038998346,
                1.557854627,
                3.910267939,
            ),
            (
                0.998,
                1.063213923,
                1.236970655,
                8.994374455,
                0.320994166,
                0.037773625,
                1.073909258,
                3.998221893,
            ),
        ];
        for (a, r_plus, isco_p, isco_r, eta_p, eta_r, ph_p, ph_r) in table {
            let (pro, retro) = (Kerr::new(a), Kerr::new(-a));
            assert!(close(pro.horizon(), r_plus, 1e-9), "{a}");
            assert!(close(pro.isco(), isco_p, 1e-9), "{a}: {}", pro.isco());
            assert!(close(retro.isco(), isco_r, 1e-9), "{a}: {}", retro.isco());
            assert!(
                close(pro.efficiency(), eta_p, 1e-8),
                "{a}: {}",
                pro.efficiency()
            );
            assert!(close(retro.efficiency(), eta_r, 1e-8), "{a}");
            assert!(close(pro.photon_orbit(), ph_p, 1e-9), "{a}");
            assert!(close(retro.photon_orbit(), ph_r, 1e-9), "{a}");
            // The ergosphere touches the horizon at the poles, is 2 on the
            // equator.
            assert!(close(pro.ergosphere(0.0), pro.horizon(), 1e-15));
            assert!(close(pro.ergosphere(PI / 2.0), 2.0, 1e-12));
        }
    }

    #[test]
    fn the_isco_is_where_the_orbit_energy_is_least() {
        // dE/dr = 0 at the ISCO, for either direction of orbit.
        for a in [-0.9, -0.3, 0.0, 0.5, 0.9, 0.998] {
            let k = Kerr::new(a);
            let r = k.isco();
            let h = 1e-6 * r;
            let slope = (k.orbit_energy(r + h) - k.orbit_energy(r - h)) / (2.0 * h);
            assert!(slope.abs() < 1e-7, "a = {a}: dE/dr = {slope}");
            assert!(k.has_circular_orbit(r));
        }
    }

    #[test]
    fn an_orbiting_emitter_seen_from_the_axis() {
        // L_z = 0: g = 1 / u^t. PHYSICS.md section 7, a = 0.9; and a = 0
        // gives sqrt(1 - 3M/r).
        let k = Kerr::new(0.9);
        for (r, g) in [
            (k.isco(), 0.370867944),
            (6.0, 0.743444059),
            (10.0, 0.845936299),
            (20.0, 0.923512041),
        ] {
            assert!(close(k.orbit_shift(r, 0.0), g, 1e-8), "r = {r}");
        }
        for r in [6.0, 10.0, 40.0] {
            let g = Kerr::new(0.0).orbit_shift(r, 0.0);
            assert!(close(g, (1.0 - 3.0 / r).sqrt(), 1e-12));
        }
    }

    #[test]
    fn the_zamo_tetrad_is_orthonormal_and_its_photons_are_null() {
        // The Kerr metric in Boyer-Lindquist form, and the photon's
        // covariant momentum from the ZAMO's frame, for directions all
        // round, at points near and far.
        let k = Kerr::new(0.9);
        for (r, th) in [(1.6, 0.4), (3.0, 1.2), (10.0, PI / 2.0), (50.0, 2.9)] {
            let (sigma, delta, big_a) = (k.sigma(r, th), k.delta(r), k.big_a(r, th));
            let s2 = th.sin().powi(2);
            // Inverse metric components.
            let g_tt = -big_a / (sigma * delta);
            let g_tph = -2.0 * k.a * r / (sigma * delta);
            let g_phph = (delta - k.a * k.a * s2) / (sigma * delta * s2);
            let (g_rr, g_thth) = (delta / sigma, 1.0 / sigma);
            for n in [
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -1.0],
                [0.48, -0.6, 0.64],
            ] {
                let p = k.photon_from_zamo(r, th, n);
                let (pt, pph) = (-p.energy, p.lz);
                let norm = g_tt * pt * pt
                    + 2.0 * g_tph * pt * pph
                    + g_phph * pph * pph
                    + g_rr * p.p_r * p.p_r
                    + g_thth * p.p_th * p.p_th;
                assert!(
                    norm.abs() < 1e-12 * p.energy.powi(2),
                    "{r} {th} {n:?}: {norm}"
                );
                // The ZAMO measures unit energy: -p.u with u its 4-velocity
                // (1, 0, 0, omega) / alpha.
                let z = k.zamo(r, th);
                let measured = (p.energy - z.omega * p.lz) / z.alpha;
                assert!((measured - 1.0).abs() < 1e-12);
            }
        }
        // a = 0: the ZAMO is the static observer.
        let z = Kerr::new(0.0).zamo(3.0, 1.0);
        assert!(z.omega == 0.0 && close(z.alpha, (1.0f64 / 3.0).sqrt(), 1e-14));
        assert!(close(
            Kerr::new(0.0).zamo_sky_shift(3.0, 1.0, 2.0),
            3.0f64.sqrt(),
            1e-14
        ));
    }

    #[test]
    fn page_thorne_flux_matches_the_reference_values_and_carries_eta() {
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        let k0 = Kerr::new(0.0);
        assert!(rel(k0.page_thorne_flux(10.0, 6.0), 1.356875464e-05) < 1e-8);
        let k = Kerr::new(0.9);
        for (r, f) in [
            (3.0, 2.973582367e-04),
            (5.0, 2.233358651e-04),
            (10.0, 4.804168669e-05),
        ] {
            assert!(rel(k.page_thorne_flux(r, k.isco()), f) < 1e-8, "r = {r}");
        }
        assert_eq!(k.page_thorne_flux(k.isco(), k.isco()), 0.0);
        // The energy reaching infinity, both faces, each carrying E(r):
        // eta x the accretion rate (in u = ln r, Simpson).
        for a in [0.0, 0.5, 0.9, 0.998] {
            let k = Kerr::new(a);
            let (u0, u1) = (k.isco().ln(), (1e7f64).ln());
            let n = 200_000;
            let h = (u1 - u0) / n as f64;
            let f = |u: f64| {
                let r = u.exp();
                2.0 * k.page_thorne_flux(r, k.isco()) * k.orbit_energy(r) * 2.0 * PI * r * r
            };
            let mut sum = f(u0) + f(u1);
            for i in 1..n {
                sum += f(u0 + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            let l = sum * h / 3.0;
            assert!(
                rel(l, k.efficiency()) < 1e-5,
                "a = {a}: {l} vs {}",
                k.efficiency()
            );
        }
    }

    #[test]
    fn bardeen_shadow_extents_match_the_reference_values() {
        // PHYSICS.md section 7: alpha's extent and the largest beta (its
        // inclined values come from a sampled curve and sit up to 7.1e-5
        // inside the exact ends).
        let cases = [
            (0.9, 90.0, -2.844421, 6.832319, Some(5.196152)),
            (0.998, 90.0, -2.110888, 6.996666, None),
            (0.9, 60.0, -3.095901, 6.589377, Some(5.135468)),
            (0.9, 17.0, -4.303139, 5.503551, None),
        ];
        let extent = |a: f64, incl: f64| {
            let pts = Kerr::new(a).shadow_curve(f64::to_radians(incl), 20_000);
            let min = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
            let max = pts.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
            let beta = pts.iter().map(|p| p.1).fold(0.0, f64::max);
            (min, max, beta)
        };
        for (a, incl, lo, hi, top) in cases {
            let (min, max, beta) = extent(a, incl);
            assert!((min - lo).abs() < 1e-4, "a {a} i {incl}: {min}");
            assert!((max - hi).abs() < 1e-4, "a {a} i {incl}: {max}");
            if let Some(t) = top {
                assert!((beta - t).abs() < 1e-4, "a {a} i {incl}: {beta}");
            }
        }
        // The inclined ends, where beta^2 = 0, solved to 30 digits
        // (mpmath): at 60 degrees r = 1.6224613871954 and 3.7322183544536,
        // at 17 degrees r = 2.1751779756344 and 2.9576275067596.
        for (incl, lo, hi) in [
            (60.0, -3.095907971152445, 6.589408976122013),
            (17.0, -4.303167601884889, 5.503621726121442),
        ] {
            let (min, max, _) = extent(0.9, incl);
            assert!((min - lo).abs() < 1e-9, "{incl}: {min}");
            assert!((max - hi).abs() < 1e-9, "{incl}: {max}");
        }
    }

    /// The angle between two directions, precise when small (acos of
    /// their dot product loses it below ~2e-8 rad).
    fn angle(a: DVec3, b: DVec3) -> f64 {
        a.cross(b).length().atan2(a.dot(b))
    }

    /// One classical Runge-Kutta step of Hamilton's equations.
    fn rk4(k: Kerr, x: DVec3, p: DVec3, e: f64, h: f64) -> (DVec3, DVec3) {
        let f1 = k.ks_flow(x, p, e);
        let f2 = k.ks_flow(x + f1.dx * (0.5 * h), p + f1.dp * (0.5 * h), e);
        let f3 = k.ks_flow(x + f2.dx * (0.5 * h), p + f2.dp * (0.5 * h), e);
        let f4 = k.ks_flow(x + f3.dx * h, p + f3.dp * h, e);
        (
            x + (f1.dx + (f2.dx + f3.dx) * 2.0 + f4.dx) * (h / 6.0),
            p + (f1.dp + (f2.dp + f3.dp) * 2.0 + f4.dp) * (h / 6.0),
        )
    }

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

    /// A photon from a ZAMO's frame at (r, th, phi) along `n`, in
    /// Kerr-Schild form: (x, p, E).
    fn zamo_photon(k: Kerr, r: f64, th: f64, phi: f64, n: [f64; 3]) -> (DVec3, DVec3, f64) {
        let v = DVec3::from_array(n).normalize();
        let c = k.photon_from_zamo(r, th, [v.x, v.y, v.z]);
        let x = k.cartesian(Spheroidal { r, th, phi });
        let p = k.ks_momentum(x, c.energy, c.lz, c.p_r, c.p_th).unwrap();
        (x, p, c.energy)
    }

    #[test]
    fn the_escape_tail_agrees_with_integrating_on() {
        // From a state at r ~ 20 the tail's direction equals integrating
        // Hamilton's equations on to r ~ 400 and taking the tail there; and
        // without spin it is the Schwarzschild tail's.
        for (a, r, th, n) in [
            (0.9, 20.0, 1.2, [0.8, 0.3, 0.5]),
            (0.9, 20.0, 0.4, [0.7, -0.6, -0.3]),
            (-0.7, 25.0, 2.5, [0.9, 0.2, -0.4]),
            (0.998, 30.0, 1.5, [0.95, 0.0, 0.3]),
            (0.9, 20.0, 0.3, [0.8, -0.6, 0.0]),
        ] {
            let k = Kerr::new(a);
            // Forward, and traced back (the photon arriving along -n:
            // momentum and energy negated), as camera rays are.
            for back in [false, true] {
                let (x0, p0, e0) = zamo_photon(k, r, th, 0.7, n.map(|c| if back { -c } else { c }));
                let (mut x, mut p, e) = if back { (x0, -p0, -e0) } else { (x0, p0, e0) };
                let near = k.ks_escape_direction(x, p, e);
                while k.ks_radius(x) < 400.0 {
                    (x, p) = rk4(k, x, p, e, 0.002 * k.ks_radius(x));
                }
                let far = k.ks_escape_direction(x, p, e);
                assert!(
                    angle(near, far) < 1e-9,
                    "a {a} th {th} back {back}: {}",
                    angle(near, far)
                );
            }
        }
        let k = Kerr::new(0.0);
        let (x, p, e) = zamo_photon(k, 12.0, 1.0, 0.3, [0.7, 0.5, 0.4]);
        let v = k.ks_flow(x, p, e).dx;
        // Schwarzschild's tail works in r_s = 2M.
        let schwarzschild = super::super::tail::gr_escape_direction(x / 2.0, v);
        assert!(angle(k.ks_escape_direction(x, p, e), schwarzschild) < 1e-11);
    }

    #[test]
    fn a_traced_ray_keeps_its_constants_to_1e9_at_tolerance_1e10() {
        // E is exact (p_t is not integrated); L_z and Q relative to their
        // scale at every accepted step, for rays that pass close by,
        // through the ergosphere, over a pole, and that fall in.
        let limits = super::super::Limits {
            outer: 30.0,
            inner: 0.0,
            max_steps: 100_000,
        };
        for (a, r, th, n, end) in [
            (0.9, 60.0, 1.3, [-0.99, 0.02, 0.1], "escaped"),
            (0.998, 60.0, 1.5, [-0.996, 0.0, 0.09], "any"),
            (0.9, 60.0, 0.2, [-0.995, 0.1, 0.0], "escaped"),
            (-0.9, 60.0, 1.0, [-1.0, 0.01, -0.02], "captured"),
            (0.9, 3.0, 1.5, [0.3, 0.1, 0.9], "any"),
        ] {
            let k = Kerr::new(a);
            let (x, p, e) = zamo_photon(k, r, th, 0.4, n);
            let (lz0, q0) = k.ks_constants(x, p, e);
            let scale_l = 1.0 + lz0.abs();
            let scale_q = 1.0 + q0.abs();
            let mut worst: f64 = 0.0;
            let t = k.ks_trace::<false>(x, p, e, 1e-10, &limits, |seg, pn| {
                let (l, q) = k.ks_constants(seg.x1 * 2.0, pn, e);
                worst = worst
                    .max((l - lz0).abs() / scale_l)
                    .max((q - q0).abs() / scale_q);
                super::super::Flow::Continue
            });
            assert!(worst < 1e-9, "a {a} th {th}: drift {worst:e} ({:?})", t.end);
            match end {
                "escaped" => assert!(
                    matches!(t.end, super::super::End::Escaped(_)),
                    "{:?}",
                    t.end
                ),
                "captured" => assert_eq!(t.end, super::super::End::Captured),
                _ => assert_ne!(t.end, super::super::End::Abandoned),
            }
        }
    }

    #[test]
    fn without_spin_the_trace_is_the_schwarzschild_tracers() {
        // The same camera ray traced both ways: the same escape direction
        // and the same path (the disk plane's crossing).
        let k = Kerr::new(0.0);
        let limits = super::super::Limits {
            outer: 20.0,
            inner: 0.0,
            max_steps: 100_000,
        };
        let mut crossed = 0;
        for n in [
            [-0.99, 0.05, 0.12],
            [-0.98, -0.1, 0.17],
            [-0.995, 0.0, 0.0995],
        ] {
            let (x, p, e) = zamo_photon(k, 40.0, 1.45, 0.2, n);
            let v = k.ks_flow(x, p, e).dx;
            let mut kerr_cross = None;
            let kt = k.ks_trace::<false>(x, p, e, 1e-10, &limits, |seg, _| {
                if kerr_cross.is_none() {
                    kerr_cross = seg.crossing_z0().map(|s| seg.point(s));
                }
                super::super::Flow::Continue
            });
            let mut gr_cross = None;
            let gt = super::super::gr::trace::<false>(x / 2.0, v, 1e-10, &limits, |seg| {
                if gr_cross.is_none() {
                    gr_cross = seg.crossing_z0().map(|s| seg.point(s));
                }
                super::super::Flow::Continue
            });
            match (kt.end, gt.end) {
                (super::super::End::Escaped(a), super::super::End::Escaped(b)) => {
                    assert!(angle(a, b) < 1e-8, "{n:?}: {}", angle(a, b))
                }
                (a, b) => assert_eq!(a, b, "{n:?}"),
            }
            if let (Some(a), Some(b)) = (kerr_cross, gr_cross) {
                assert!(a.distance(b) < 1e-7 * a.length(), "{a} vs {b}");
                crossed += 1;
            } else {
                assert_eq!(kerr_cross.is_some(), gr_cross.is_some());
            }
        }
        assert!(crossed >= 2, "{crossed} rays crossed the plane");
    }

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
            let want = super::super::Spacetime::Schwarzschild.camera_direction(x / 2.0, look);
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
