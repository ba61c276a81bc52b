//! A Kerr light ray in closed form from a camera: where it starts, its
//! equatorial crossings in order and its direction at infinity.

use super::polar::{Polar, PolarMotion};
use super::radial::{Amp, Complete, Ints, Radial};
use super::roots::{RadialRoots, RootCase};
use super::times;
use crate::physics::dual::{D2, Real};
use crate::physics::elliptic::jacobi_sn_cn_dn;
use crate::physics::kerr::Kerr;
use glam::DVec3;

/// A Kerr light ray in closed form from a start outside the horizon (in
/// M): its equatorial crossings in order, then the sky in its direction at
/// infinity or the hole. The ray runs in Mino time s from the start; r, cos
/// theta and the azimuth are Jacobi functions and elliptic integrals of s.
/// Written in [`Real`]: a `KerrRay<D2>` carries every quantity's rates
/// along the pixel's two axes ([`KerrRay::rated`]), from which a footprint
/// is read; the coordinate time is kept as values.
#[derive(Clone, Copy, Debug)]
pub struct KerrRay<T = f64> {
    a: f64,
    lambda: T,
    eta: T,
    /// The sign of the photon's energy along the ray's direction (-1 for a
    /// ray traced back from a camera): the azimuth runs with it.
    energy_sign: f64,
    radial: Radial<T>,
    /// The radial motion's parameter and scale; its complete integrals.
    k: T,
    kappa: T,
    complete: Complete<T>,
    /// U at the start and its direction (U = U0 + dir kappa s).
    u0: T,
    dir: f64,
    /// The Mino time to the end.
    s_end: T,
    /// The partial fractions of a (2 r - a lambda) / Delta = sum of coef /
    /// (r - r_+-), over kappa; their pole integrals at the start.
    coef: [T; 2],
    pole0: [T; 2],
    /// And at infinity (an escaping ray).
    pole_end: [T; 2],
    polar: Polar<T>,
    /// r_+ and r_-.
    horizons: [f64; 2],
    /// The Kerr-Schild azimuth at the start, less its radial term at r0.
    phi0: f64,
    /// It ends in the hole rather than at infinity.
    pub captured: bool,
    /// The sign of dr/ds: before and after the Mino time it turns in r
    /// (the same, and the turn at infinity, where it does not).
    radial_signs: (f64, f64, f64),
    /// The least radius along the ray.
    min_r: f64,
    /// Whether it keeps the coordinate time: then kappa times the radial
    /// part of its integral at the start (signed as `pole0`) and the
    /// partial fractions of ((8 - 2 a lambda) r - 4 a^2) / Delta.
    timed: bool,
    time0: f64,
    tcoef: [f64; 2],
}

/// Where a ray is at a Mino time ([`KerrRay::state_at`]): its
/// Boyer-Lindquist radius and cos theta (M), and their rates dr/ds and
/// d cos theta / ds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    pub r: f64,
    pub r_dot: f64,
    pub cos: f64,
    pub cos_dot: f64,
}

/// An equatorial crossing of a [`KerrRay`]: its Boyer-Lindquist radius and
/// where it lies along the ray.
#[derive(Clone, Copy, Debug)]
pub struct Crossing<T = f64> {
    pub r: f64,
    /// Its Mino time from the start.
    pub s: f64,
    /// The radial motion's argument U there, and its Jacobi functions.
    u: T,
    sn: f64,
    cn: f64,
    dn: f64,
    /// The number of half swings of the polar motion to it.
    j: f64,
}

/// Where a [`KerrRay`] crosses the equatorial plane (M).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrossingPoint {
    /// The Kerr-Schild Cartesian point.
    pub x: DVec3,
    /// Its Boyer-Lindquist azimuth, which the closed form finds first
    /// (Kerr-Schild's adds the radial term of [`ks_azimuth_term`]).
    pub phi: f64,
    /// The Boyer-Lindquist coordinate time the light takes from it to the
    /// start (NaN for a ray not made `timed`).
    pub t: f64,
}

/// Where a camera's rays start (M): the Kerr-Schild point, its
/// Boyer-Lindquist r and cos theta, and what every ray from there shares
/// (found once per camera, not per ray).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KsStart {
    pub x: DVec3,
    pub r: f64,
    pub cos: f64,
    sin: f64,
    /// The Kerr-Schild azimuth less its radial term at r.
    phi_rest: f64,
    /// r_+ and r_-.
    horizons: [f64; 2],
    /// The metric's f and l there, and the gradient of r.
    fields: (f64, DVec3),
    grad_r: DVec3,
}

impl KsStart {
    /// The start at Kerr-Schild point `x` (M), outside the ring.
    pub fn new(kerr: Kerr, x: DVec3) -> KsStart {
        let r = kerr.ks_radius(x);
        let cos = x.z / r;
        let r_plus = kerr.horizon();
        let horizons = [r_plus, kerr.a * kerr.a / r_plus];
        // The Kerr-Schild azimuth (Kerr::spheroidal).
        let phi = x.y.atan2(x.x) - kerr.a.atan2(r);
        KsStart {
            x,
            r,
            cos,
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
            phi_rest: phi - ks_azimuth_term(kerr.a, horizons, r),
            horizons,
            fields: kerr.ks_f_l(x),
            grad_r: kerr.ks_radius_gradient(x, r),
        }
    }
}

impl<T: Real> KerrRay<T> {
    /// The ray of the photon at `start` with lambda, eta, energy sign and
    /// the signs of d r / d s and d cos theta / d s; None where the closed form
    /// does not apply (the integrator takes the ray): eta = 0 (in the
    /// plane), a ray that passes within ~1e-5 rad of the axis, or anything
    /// not finite (exactly critical). A `timed` ray also gives each
    /// crossing's coordinate time ([`KerrRay::crossing_point_time`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        a: f64,
        (lambda, eta): (T, T),
        energy_sign: f64,
        start: &KsStart,
        (r_out, u_up): (bool, bool),
        timed: bool,
    ) -> Option<KerrRay<T>> {
        let (r0, cos0) = (start.r, start.cos);
        let polar = match PolarMotion::new(a, lambda, eta) {
            Some(pm) if pm.u_plus.re() < 1.0 - 1e-10 => Polar::ordinary(pm, cos0, u_up, timed),
            Some(_) => return None,
            None => Polar::vortical(a, lambda, eta, cos0, u_up)?,
        };
        let [r_plus, r_minus] = start.horizons;
        if !(r0 > r_plus) {
            return None;
        }
        let poles = [r_plus, r_minus];
        let roots = RadialRoots::new(a, lambda, eta);
        let [r1, r2, r3, r4] = roots.re;
        let case = roots.case(r_plus);
        let turning = case == RootCase::OuterTurning;
        // Between r+ and r3 (a camera near the hole): the photon turns at
        // r3, if at all, and falls in. The same forms hold with the roots
        // relabelled (r1, r2, r3, r4) -> (r2, r1, r4, r3): U = 0 at r3 and
        // r = r+ before r2.
        let inner = turning && r0 < r4.re() * (1.0 - 1e-12);
        if inner && !(r0 <= r3.re() && r2.re() < r_plus) {
            // Between r3 and r4 only by rounding.
            return None;
        }
        // Without spin r_- = 0 may be a root: the time's pole there has
        // no weight, r_+ stands in for it.
        let spin = a != 0.0;
        let at_poles = if spin { poles } else { [r_plus; 2] };
        let (radial, k, kappa) = match case {
            RootCase::OuterTurning if inner => Radial::outer([r2, r1, r4, r3], at_poles),
            RootCase::OuterTurning | RootCase::InnerReal => Radial::outer(roots.re, at_poles),
            RootCase::OnePair => Radial::pair(r1, r2, (roots.re[2], roots.im[2]), at_poles),
            RootCase::TwoPairs => Radial::quad(&roots, at_poles)?,
        };
        // Only rays that cross the plane need their time (two complex
        // pairs are vortical).
        let timed = timed && polar.vortical.is_none();
        if timed && matches!(radial, Radial::Quad { .. }) {
            return None;
        }
        let poles_on = spin || timed;
        let complete = radial.complete(k, timed, poles_on);
        // U = U0 + dir kappa s: through the turning point (U = 0) when the
        // photon turns, towards the end otherwise.
        let amp0 = radial.sn_cn(r0);
        let (sign0, dir) = if turning {
            (if r_out == inner { -1.0 } else { 1.0 }, 1.0)
        } else {
            (1.0, if r_out == radial.rising() { 1.0 } else { -1.0 })
        };
        let captured = inner || !turning && !r_out;
        let amp_end = if captured {
            radial.sn_cn(r_plus)
        } else {
            radial.sn_cn_at_infinity()
        };
        // An escaping ray's azimuth needs the pole integrals at infinity.
        let poles_end = spin && !captured;
        let (u0, pole0, radial_time0) = if timed {
            radial.at::<true>(amp0, k, &complete, true)
        } else {
            radial.at::<false>(amp0, k, &complete, spin)
        };
        let (u_end, pole_end, _) = radial.at::<false>(amp_end, k, &complete, poles_end);
        let dr = r_plus - r_minus;
        let (tcoef, time0) = if timed {
            let pole0 = pole0.map(T::re);
            times::time_start(a, lambda.re(), poles, sign0, radial_time0, pole0)
        } else {
            ([0.0; 2], 0.0)
        };
        let (u0, pole0) = (u0 * sign0, pole0.map(|p| p * sign0));
        let s_end = (u_end - u0) * dir / kappa;
        let coef = [
            (T::c(2.0 * r_plus) - lambda * a) * a / (kappa * dr),
            -((T::c(2.0 * r_minus) - lambda * a) * a) / (kappa * dr),
        ];
        let turn = (-u0 / (kappa * dir)).re();
        let radial_signs = radial_signs(turning, inner, captured, turn);
        let ray = KerrRay {
            radial_signs,
            a,
            lambda,
            eta,
            energy_sign,
            radial,
            k,
            kappa,
            complete,
            u0,
            dir,
            s_end,
            coef,
            pole0,
            pole_end,
            polar,
            horizons: poles,
            phi0: start.phi_rest,
            captured,
            min_r: if captured {
                r_plus
            } else if turning {
                r4.re()
            } else {
                r0
            },
            timed,
            time0,
            tcoef,
        };
        ray.is_finite().then_some(ray)
    }

    /// Whether everything the ray's points are found from is finite (not
    /// so for an exactly critical ray).
    fn is_finite(&self) -> bool {
        let (polar, complete) = (&self.polar, &self.complete);
        self.s_end.re().is_finite()
            && self.s_end.re() >= 0.0
            && self
                .pole0
                .iter()
                .chain(&self.pole_end)
                .all(|p| p.re().is_finite())
            && polar.psi0.re().is_finite()
            && polar.pi0.re().is_finite()
            && polar.pi_c.re().is_finite()
            && self.time0.is_finite()
            && polar.d0.is_finite()
            && complete.k.re().is_finite()
            && complete.pi.iter().all(|p| p.re().is_finite())
    }

    /// A bound below the radius (M) all along the ray: its turning point,
    /// or the nearer end.
    pub fn min_radius(&self) -> f64 {
        self.min_r
    }

    /// The photon's equatorial crossings in order (the image order n = 0,
    /// 1, 2, ...), before it ends.
    pub fn crossings(&self) -> impl Iterator<Item = Crossing<T>> + '_ {
        let p = &self.polar;
        let half = p.big_k * 2.0;
        // A start on the plane is not a crossing.
        let first = (p.psi0.re() / half.re() + 1e-12).floor() + 1.0;
        (0..)
            .map(move |i| {
                let j = first + i as f64;
                (j, (half * j - p.psi0) / p.scale)
            })
            // Vortical motion stays in one hemisphere.
            .take_while(move |&(_, s)| s.re() < self.s_end.re() && p.vortical.is_none())
            .map(move |(j, s)| {
                // |U| stays below K outside a complex pair, below 2K with
                // one, where sn >= 0 (two pairs are vortical: no crossings).
                // Its rates wait for the crossing's integrals
                // (KerrRay::crossing_rated).
                let u = self.u0 + self.kappa * self.dir * s;
                let (sn, cn, dn) = jacobi_sn_cn_dn(u.re(), self.k.re());
                Crossing {
                    r: self.radial.radius(T::c(sn), T::c(cn)).re(),
                    s: s.re(),
                    u,
                    sn,
                    cn,
                    dn,
                    j,
                }
            })
    }

    /// The Boyer-Lindquist azimuth where the radial pole integrals are
    /// `pole` and the polar integral of 1 / sin^2 theta from the start is
    /// `g_phi` (Kerr-Schild's at radius r adds [`ks_azimuth_term`]).
    fn bl_azimuth(&self, pole: [T; 2], g_phi: T) -> T {
        let radial = (self.coef[0] * (pole[0] - self.pole0[0])
            + self.coef[1] * (pole[1] - self.pole0[1]))
            * self.dir;
        (radial + self.lambda * g_phi) * self.energy_sign + self.phi0
    }

    /// The Kerr-Schild Cartesian point (x, y; z = 0) and Boyer-Lindquist
    /// azimuth of the `j`-th node at radius `r`, with the radial pole
    /// integrals `pole` there.
    fn point_of(&self, r: T, j: f64, pole: [T; 2]) -> ([T; 2], T) {
        let p = &self.polar;
        // At the j-th node am = j pi exactly.
        let g_phi = (p.pi_c * (2.0 * j) - p.pi0) * p.g_scale;
        let bl = self.bl_azimuth(pole, g_phi);
        let phi = bl + ks_azimuth_term(self.a, self.horizons, r);
        let (s, co) = phi.sin_cos();
        ([r * co - s * self.a, r * s + co * self.a], bl)
    }

    /// The polar motion at Mino time `s`: cos theta and its rate d cos
    /// theta / ds.
    fn polar_at(&self, s: T) -> (T, T) {
        let (j, psi_r) = self.polar_phase(s);
        let (sn, cn, dn) = T::jacobi_sn_cn_dn(psi_r, self.polar.m);
        self.polar_cos(j, sn, cn, dn)
    }

    /// The polar motion's half swings j at Mino time `s` and the rest of
    /// its Jacobi argument (psi = 2 K j + psi_r, |psi_r| <= K).
    fn polar_phase(&self, s: T) -> (f64, T) {
        let p = &self.polar;
        let psi = p.psi0 + p.scale * s;
        let j = (psi.re() / (2.0 * p.big_k.re())).round();
        (j, psi - p.big_k * (2.0 * j))
    }

    /// cos theta and d cos theta / ds after `j` half swings and the rest's
    /// Jacobi functions (am = j pi + am(psi_r)).
    fn polar_cos(&self, j: f64, sn: T, cn: T, dn: T) -> (T, T) {
        let p = &self.polar;
        // d sn / d psi = cn dn.
        let swing = p.scale * cn * dn;
        match p.vortical {
            None => {
                let sign = if j % 2.0 == 0.0 { 1.0 } else { -1.0 };
                let root = p.u_plus.sqrt() * sign;
                (root * sn, root * swing)
            }
            Some((u_minus, hemisphere)) => {
                let spread = p.u_plus - u_minus;
                let c = (p.u_plus - spread * sn * sn).max(0.0).sqrt() * hemisphere;
                let rate = if c.re() == 0.0 {
                    T::c(0.0)
                } else {
                    -(spread * sn * swing) / c
                };
                (c, rate)
            }
        }
    }

    /// The direction at infinity of an escaping ray (unit, Cartesian).
    fn escape_components(&self) -> [T; 3] {
        let p = &self.polar;
        let (j, psi_r) = self.polar_phase(self.s_end);
        let jac = jacobi_sn_cn_dn(psi_r.re(), p.m.re());
        let ((sn, cn, dn), (f, [jr])) = T::jacobi_legendre(psi_r, p.m, jac, [p.n]);
        let (cos_th, _) = self.polar_cos(j, sn, cn, dn);
        let pi_r = f + p.n * jr;
        let g_phi = (p.pi_c * (2.0 * j) + pi_r - p.pi0) * p.g_scale;
        // Kerr-Schild's azimuth is Boyer-Lindquist's at infinity.
        let phi = self.bl_azimuth(self.pole_end, g_phi);
        let sin_th = (T::c(1.0) - cos_th * cos_th).max(0.0).sqrt();
        let (s, c) = phi.sin_cos();
        [sin_th * c, sin_th * s, cos_th]
    }
}

impl KerrRay {
    /// The ray traced from the Kerr-Schild point `x` (M) along coordinate
    /// velocity `v`, back in time as from a camera ([`Kerr::ks_backward`]).
    pub fn from_ks(kerr: Kerr, x: DVec3, v: DVec3, timed: bool) -> Option<KerrRay> {
        KerrRay::from_start(kerr, &KsStart::new(kerr, x), v, timed)
    }

    /// [`KerrRay::from_ks`] from a start found before.
    pub fn from_start(kerr: Kerr, start: &KsStart, v: DVec3, timed: bool) -> Option<KerrRay> {
        let x = start.x;
        let (p, e) = kerr.ks_backward_in(x, start.fields, v);
        let [_, lz, p_th, r_dot, cos_dot] =
            kerr.ks_ray_terms(x, (start.r, start.grad_r), [-e, p.x, p.y, p.z], v);
        let q = kerr.carter_q(p_th, lz, e, (start.sin, start.cos));
        KerrRay::new(
            kerr.a,
            (lz / e, q / (e * e)),
            e.signum(),
            start,
            (r_dot > 0.0, cos_dot > 0.0),
            timed,
        )
    }

    /// The Kerr-Schild Cartesian point (M) of a crossing.
    pub fn crossing_point(&self, c: &Crossing) -> DVec3 {
        self.untimed_point(c).0
    }

    /// [`KerrRay::point`] without the time's integrals.
    fn untimed_point(&self, c: &Crossing) -> (DVec3, f64) {
        let pole = if self.a == 0.0 {
            [0.0; 2]
        } else {
            self.radial
                .at::<false>(Amp::new(c.sn, c.cn), self.k, &self.complete, true)
                .1
        };
        self.point(c, pole)
    }

    /// The Kerr-Schild Cartesian point (M) of a crossing, its
    /// Boyer-Lindquist azimuth and the Boyer-Lindquist coordinate time (M)
    /// the light takes from it to the start, of a ray made `timed` (NaN
    /// otherwise). With M = 1, dt/ds =
    /// E (r^2 + 2 r + 4 + ((8 - 2 a lambda) r - 4 a^2) / Delta + a^2 cos^2
    /// theta): the radial part is the integrals of r and r^2 and the time's
    /// horizon poles at the crossing's amplitude, the polar part D at the
    /// j-th node, 2 j D(m).
    pub fn crossing_point_time(&self, c: &Crossing) -> CrossingPoint {
        if !self.timed {
            let (x, phi) = self.untimed_point(c);
            return CrossingPoint {
                x,
                phi,
                t: f64::NAN,
            };
        }
        let (_, pole, radial_time) =
            self.radial
                .at::<true>(Amp::new(c.sn, c.cn), self.k, &self.complete, true);
        let radial = self.dir
            * (radial_time + self.tcoef[0] * pole[0] + self.tcoef[1] * pole[1] - self.time0)
            / self.kappa;
        let p = &self.polar;
        let polar = self.a * self.a * p.u_plus / p.scale * (2.0 * c.j * p.d_c - p.d0);
        let (x, phi) = self.point(c, pole);
        CrossingPoint {
            x,
            phi,
            t: -self.energy_sign * (radial + polar),
        }
    }

    /// A crossing's Kerr-Schild Cartesian point and Boyer-Lindquist
    /// azimuth, with its radial pole integrals `pole`.
    fn point(&self, c: &Crossing, pole: [f64; 2]) -> (DVec3, f64) {
        let ([x, y], bl) = self.point_of(c.r, c.j, pole);
        (DVec3::new(x, y, 0.0), bl)
    }

    /// The ray's Boyer-Lindquist radius and cos theta (M) at Mino time `s`
    /// from the start (0 to [`KerrRay::mino_to_end`]), with their rates.
    #[inline]
    pub fn state_at(&self, s: f64) -> State {
        let u = self.u0 + self.dir * self.kappa * s;
        let (sn, cn, _) = jacobi_sn_cn_dn(u, self.k);
        let r = self.radial.radius(sn, cn);
        let (before, after, turn) = self.radial_signs;
        let sign = if s < turn { before } else { after };
        let r_dot = sign * self.radial_potential(r).max(0.0).sqrt();
        let (cos, cos_dot) = self.polar_at(s);
        State {
            r,
            r_dot,
            cos,
            cos_dot,
        }
    }

    /// The outer horizon's radius r_+ (M).
    pub fn horizon(&self) -> f64 {
        self.horizons[0]
    }

    /// The least and greatest cos theta along the ray: the polar turning
    /// points, +-sqrt(u_+) of an ordinary swing, between sqrt(u_-) and
    /// sqrt(u_+) in one hemisphere of a vortical one. A ray with angular
    /// momentum never reaches the axis; what interpolates its points must
    /// not either.
    pub fn cos_range(&self) -> (f64, f64) {
        let p = &self.polar;
        let top = p.u_plus.sqrt();
        match p.vortical {
            None => (-top, top),
            Some((u_minus, h)) if h < 0.0 => (-top, -u_minus.sqrt()),
            Some((u_minus, _)) => (u_minus.sqrt(), top),
        }
    }

    /// How fast the polar motion's Jacobi argument runs with Mino time.
    pub fn polar_rate(&self) -> f64 {
        self.polar.scale
    }

    /// The radial potential R(r): (dr/ds)^2 in Mino time (M = 1).
    #[inline]
    pub fn radial_potential(&self, r: f64) -> f64 {
        let (a, l) = (self.a, self.lambda);
        let w = r * r + a * a - a * l;
        w * w - (r * r - 2.0 * r + a * a) * (self.eta + (l - a) * (l - a))
    }

    /// The Mino time at which a captured ray, on its last fall, reaches
    /// radius `r` (between its last turning point, or the start, and the
    /// horizon).
    pub fn mino_at_fall(&self, r: f64) -> f64 {
        let (u, _, _) =
            self.radial
                .at::<false>(self.radial.sn_cn(r), self.k, &self.complete, false);
        ((u - self.u0) * self.dir / self.kappa).clamp(0.0, self.s_end)
    }

    /// The Mino time at which the ray, coming in from its start, first
    /// reaches radius `r` (below the start's, above its least): before
    /// its turn U has the sign it starts with.
    pub fn mino_at_approach(&self, r: f64) -> f64 {
        let (u, _, _) =
            self.radial
                .at::<false>(self.radial.sn_cn(r), self.k, &self.complete, false);
        let u = if self.radial_signs.2.is_finite() {
            u.abs().copysign(self.u0)
        } else {
            u
        };
        ((u - self.u0) * self.dir / self.kappa).clamp(0.0, self.s_end)
    }

    /// The direction at infinity of an escaping ray (unit, Cartesian).
    pub fn escape_direction(&self) -> DVec3 {
        DVec3::from_array(self.escape_components())
    }

    /// The photon's lambda = L_z / E.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The Mino time from the start to the end (infinity or the horizon).
    pub fn mino_to_end(&self) -> f64 {
        self.s_end
    }

    /// The ray's Kerr-Schild azimuth at Mino time `s` (unwrapped: it runs
    /// on continuously from the start's) and its rate d phi / ds, for a
    /// medium that is not the same at every azimuth. As at a crossing
    /// ([`KerrRay::crossing_point`]): the radial pole integrals at the
    /// radial motion's amplitude there and the polar integral of 1 /
    /// sin^2 theta, Pi at its phase; the rate is the geodesic's, d phi_BL
    /// / ds = a (2 r - a lambda) / Delta + lambda / sin^2 theta, plus the
    /// Kerr-Schild term's a / Delta dr/ds (signed with the photon's energy
    /// as the azimuth is).
    pub fn azimuth_at(&self, s: f64, here: &State) -> (f64, f64) {
        let u = self.u0 + self.dir * self.kappa * s;
        let pole = if self.a == 0.0 {
            [0.0; 2]
        } else {
            // Two complex pairs' amplitude runs on past a half turn (as
            // whole half turns and a rest); the others' stays within one.
            let amp = if matches!(self.radial, Radial::Quad { .. }) {
                let j = (u / (2.0 * self.complete.k)).round();
                let (sn, cn, _) = jacobi_sn_cn_dn(u - 2.0 * j * self.complete.k, self.k);
                Amp { sn, cn, j }
            } else {
                let (sn, cn, _) = jacobi_sn_cn_dn(u, self.k);
                Amp::new(sn, cn)
            };
            self.radial.at::<false>(amp, self.k, &self.complete, true).1
        };
        let p = &self.polar;
        let (j, psi_r) = self.polar_phase(s);
        let jac = jacobi_sn_cn_dn(psi_r, p.m);
        let (_, (f, [jr])) = f64::jacobi_legendre(psi_r, p.m, jac, [p.n]);
        let g_phi = (p.pi_c * (2.0 * j) + f + p.n * jr - p.pi0) * p.g_scale;
        let phi = self.bl_azimuth(pole, g_phi) + ks_azimuth_term(self.a, self.horizons, here.r);
        (phi, self.azimuth_rate(here))
    }

    /// The ray's d phi / ds (Kerr-Schild) at `here`, as
    /// [`KerrRay::azimuth_at`] gives it.
    #[inline]
    pub fn azimuth_rate(&self, here: &State) -> f64 {
        let State { r, r_dot, cos, .. } = *here;
        let (a, l) = (self.a, self.lambda);
        let delta = r * r - 2.0 * r + a * a;
        let sin2 = (1.0 - cos * cos).max(1e-300);
        self.energy_sign * (a * (2.0 * r - a * l) / delta + l / sin2) + a / delta * r_dot
    }
}

impl KerrRay<D2> {
    /// [`KerrRay::from_start`] along `v` with every quantity's rates along
    /// `dv` (the camera direction's derivatives along the pixel's axes):
    /// lambda and eta move with the photon's momentum, which is linear in
    /// the null vector ([`Kerr::ks_backward_rates`]), and Carter's Q is
    /// quadratic in it.
    pub fn rated(
        kerr: Kerr,
        start: &KsStart,
        v: DVec3,
        dv: [DVec3; 2],
        timed: bool,
    ) -> Option<KerrRay<D2>> {
        let x = start.x;
        let grad = (start.r, start.grad_r);
        let ((p, e), d) = kerr.ks_backward_rates(x, start.fields, v, dv);
        let [_, lz, p_th, r_dot, cos_dot] = kerr.ks_ray_terms(x, grad, [-e, p.x, p.y, p.z], v);
        let q = kerr.carter_q(p_th, lz, e, (start.sin, start.cos));
        let (lambda, eta) = (lz / e, q / (e * e));
        let (st, ct) = (start.sin, start.cos);
        let a2 = kerr.a * kerr.a;
        let mut rates = [[0.0; 2]; 2];
        for k in 0..2 {
            let (dp, de) = d[k];
            // L_z and p_theta are linear in the momentum.
            let [_, dlz, dp_th, _, _] = kerr.ks_ray_terms(x, grad, [-de, dp.x, dp.y, dp.z], dv[k]);
            let dq =
                2.0 * p_th * dp_th + ct * ct * (2.0 * lz * dlz / (st * st) - 2.0 * a2 * e * de);
            rates[0][k] = (dlz - lambda * de) / e;
            rates[1][k] = (dq - 2.0 * eta * e * de) / (e * e);
        }
        KerrRay::new(
            kerr.a,
            (D2::with(lambda, rates[0]), D2::with(eta, rates[1])),
            e.signum(),
            start,
            (r_dot > 0.0, cos_dot > 0.0),
            timed,
        )
    }

    /// A crossing's Boyer-Lindquist radius and azimuth (M) with their
    /// rates, and its Kerr-Schild Cartesian point (M; z = 0): the radius's
    /// rates and the azimuth's radial integrals from one duplication
    /// sequence at the crossing's amplitude.
    pub fn crossing_rated(&self, c: &Crossing<D2>) -> (D2, D2, DVec3) {
        let jac = (c.sn, c.cn, c.dn);
        let (r, pole) = if self.a == 0.0 {
            let ((sn, cn, _), _) = D2::jacobi_legendre(c.u, self.k, jac, []);
            (self.radial.radius(sn, cn), [D2::c(0.0); 2])
        } else {
            let n = self.radial.n();
            let ((sn, cn, _), (f, j)) = D2::jacobi_legendre(c.u, self.k, jac, n);
            let ints = Ints {
                f,
                j,
                d: 0.0,
                jn: 0.0,
            };
            let amp = Amp::new(sn, cn);
            let pole = self
                .radial
                .at_ints::<false>(amp, self.k, &self.complete, true, ints)
                .1;
            (self.radial.radius(sn, cn), pole)
        };
        let ([x, y], bl) = self.point_of(r, c.j, pole);
        (r, bl, DVec3::new(x.v, y.v, 0.0))
    }

    /// The direction at infinity of an escaping ray and its rates.
    pub fn escape_rated(&self) -> (DVec3, [DVec3; 2]) {
        let [x, y, z] = self.escape_components();
        let rate = |k: usize| DVec3::new(x.d[k], y.d[k], z.d[k]);
        (DVec3::new(x.v, y.v, z.v), [rate(0), rate(1)])
    }

    /// The ray without its rates: what the trace walks.
    pub fn value(&self) -> KerrRay {
        KerrRay {
            a: self.a,
            lambda: self.lambda.v,
            eta: self.eta.v,
            energy_sign: self.energy_sign,
            radial: self.radial.value(),
            k: self.k.v,
            kappa: self.kappa.v,
            complete: self.complete.value(),
            u0: self.u0.v,
            dir: self.dir,
            s_end: self.s_end.v,
            coef: self.coef.map(|x| x.v),
            pole0: self.pole0.map(|x| x.v),
            pole_end: self.pole_end.map(|x| x.v),
            polar: self.polar.value(),
            horizons: self.horizons,
            phi0: self.phi0,
            captured: self.captured,
            radial_signs: self.radial_signs,
            min_r: self.min_r,
            timed: self.timed,
            time0: self.time0,
            tcoef: self.tcoef,
        }
    }
}

/// [`KerrRay`]'s signs of dr/ds before and after its turn in r, and the
/// Mino time `turn` of it: a turning ray passes U = 0 there, inward then
/// outward (the other way between r_+ and r3, `inner`); any other runs
/// one way, in if `captured`.
fn radial_signs(turning: bool, inner: bool, captured: bool, turn: f64) -> (f64, f64, f64) {
    if turning {
        let sign = if inner { -1.0 } else { 1.0 };
        (-sign, sign, turn)
    } else {
        let sign = if captured { -1.0 } else { 1.0 };
        (sign, sign, f64::INFINITY)
    }
}

/// The Kerr-Schild azimuth's radial term, the integral of a / Delta dr
/// (its difference between two radii; 0 at infinity): phi_KS = phi_BL +
/// this at r (M), outside the outer horizon `r_plus`.
pub(crate) fn ks_azimuth_term<T: Real>(a: f64, [r_plus, r_minus]: [f64; 2], r: T) -> T {
    if a == 0.0 || r.re().is_infinite() {
        return T::c(0.0);
    }
    ((r - r_plus) / (r - r_minus)).ln() * (a / (r_plus - r_minus))
}

/// Rays for the tests here and of the transfer along them.
#[cfg(test)]
pub(crate) mod test_rays {
    use super::*;

    /// Rays traced back from 50 M towards the hole, missing it by about
    /// 0.5, 3 and 9 M (captured, and turning at different depths), at
    /// spins 0 and 0.9; each with the Mino time it is followed to (to
    /// 1.01 r_+, or where it is 500 M out again).
    pub fn sample_rays() -> Vec<(Kerr, KerrRay, f64)> {
        let mut out = Vec::new();
        for a in [0.0, 0.9] {
            let kerr = Kerr::new(a);
            for miss in [0.5, 3.0, 9.0] {
                let x = DVec3::new(0.0, -50.0, 8.0);
                let v = (-x).normalize() + DVec3::new(miss, 0.0, 0.3 * miss) / 50.0;
                let ray = KerrRay::from_ks(kerr, x, v.normalize(), false).expect("closed form");
                let end = if ray.captured {
                    ray.mino_at_fall(1.01 * kerr.horizon())
                } else {
                    // Past the turn (the way out beyond 50 M is short in
                    // Mino time), where r = 500.
                    let (mut lo, mut hi) = (0.5 * ray.mino_to_end(), ray.mino_to_end());
                    for _ in 0..100 {
                        let mid = 0.5 * (lo + hi);
                        if ray.state_at(mid).r > 500.0 {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    lo
                };
                out.push((kerr, ray, end));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::test_rays::sample_rays as rays;
    use super::*;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn the_rates_are_the_derivatives_of_the_points() {
        // dr/ds = +-sqrt(R) signed by the turn, d cos theta / ds from the
        // polar Jacobi functions: against central differences of the
        // closed form's points (step 1e-6 of the way).
        for (kerr, ray, end) in rays() {
            for i in 1..40 {
                let s = end * i as f64 / 40.0;
                let h = 1e-6 * end;
                let at = ray.state_at(s);
                let (r, r_dot, c_dot) = (at.r, at.r_dot, at.cos_dot);
                let (p, m) = (ray.state_at(s + h), ray.state_at(s - h));
                let (dr, dc) = ((p.r - m.r) / (2.0 * h), (p.cos - m.cos) / (2.0 * h));
                assert!(
                    (dr - r_dot).abs() < 1e-5 * r * r,
                    "a {} s {s}: dr/ds {r_dot} against {dr}",
                    kerr.a
                );
                assert!(
                    (dc - c_dot).abs() < 1e-5 * (1.0 + c_dot.abs()),
                    "a {} s {s}: dcos/ds {c_dot} against {dc}",
                    kerr.a
                );
            }
        }
    }

    #[test]
    fn the_azimuth_is_the_geodesics_from_the_start() {
        // The closed form's azimuth is the integral of the geodesic's d
        // phi / ds from the start: it starts at the start's Kerr-Schild
        // azimuth, its central differences (step 1e-6 of the way: 1e-5 of
        // round-off and curvature) are the geodesic's rate, and at each equatorial crossing it puts the
        // point where the crossings' own closed form does. Rays passing
        // near the axis (lambda 0.02) and vortical ones among them.
        let mut rays: Vec<_> = rays()
            .into_iter()
            .map(|(k, ray, end)| (k, ray, end, DVec3::new(0.0, -50.0, 8.0)))
            .collect();
        let kerr = Kerr::new(0.9);
        for (x, v) in [
            (DVec3::new(0.0, -50.0, 8.0), DVec3::new(0.0, 1.0, -0.16)),
            (DVec3::new(1.0, 2.0, 40.0), DVec3::new(-0.02, -0.05, -1.0)),
            (DVec3::new(2.0, 0.0, 3.0), DVec3::new(0.1, 0.3, 1.0)),
        ] {
            let ray = KerrRay::from_ks(kerr, x, v.normalize(), false).expect("closed form");
            let end = if ray.captured {
                ray.mino_at_fall(1.01 * kerr.horizon())
            } else {
                0.9 * ray.mino_to_end()
            };
            rays.push((kerr, ray, end, x));
        }
        let wrap = |d: f64| (d + PI).rem_euclid(TAU) - PI;
        let mut crossings = 0;
        let mut vortical = 0;
        for (kerr, ray, end, x) in rays {
            vortical += ray.polar.vortical.is_some() as u32;
            let start = ray.state_at(0.0);
            let (phi0, _) = ray.azimuth_at(0.0, &start);
            let s0 = kerr.spheroidal(x);
            assert!(
                wrap(phi0 - s0.phi).abs() < 1e-12,
                "{phi0} against {}",
                s0.phi
            );
            for i in 1..80 {
                let s = end * i as f64 / 80.0;
                let h = 1e-6 * end;
                let (_, rate) = ray.azimuth_at(s, &ray.state_at(s));
                let (p, m) = (s + h, s - h);
                let dphi = (ray.azimuth_at(p, &ray.state_at(p)).0
                    - ray.azimuth_at(m, &ray.state_at(m)).0)
                    / (2.0 * h);
                assert!(
                    (dphi - rate).abs() < 1e-5 * (1.0 + rate.abs()),
                    "a {} lambda {} s {s}: d phi/ds {rate} against {dphi}",
                    kerr.a,
                    ray.lambda
                );
            }
            for c in ray.crossings().take_while(|c| c.s < end) {
                let at = ray.state_at(c.s);
                let (phi, _) = ray.azimuth_at(c.s, &at);
                let x = kerr.cartesian(crate::physics::kerr::Spheroidal {
                    r: at.r,
                    th: 0.5 * PI,
                    phi,
                });
                let want = ray.crossing_point(&c);
                assert!((x - want).length() < 1e-9 * at.r, "{x} against {want}");
                crossings += 1;
            }
        }
        assert!(crossings >= 2 && vortical >= 1, "{crossings} {vortical}");
    }

    #[test]
    fn a_rated_rays_values_are_the_rays_with_their_times() {
        // The trace walks a rated ray's values: its crossings' points,
        // azimuths and light travel times are the plain ray's, to the
        // rounding of the extra term in the duplication sequence.
        let kerr = Kerr::new(0.9);
        let start = KsStart::new(kerr, DVec3::new(0.0, -30.0, 6.0));
        let mut n = 0;
        for i in 0..100 {
            let v = DVec3::new(-0.25 + 0.005 * i as f64, 1.0, -0.25 + 0.003 * i as f64);
            let dv = [DVec3::X, DVec3::Z];
            let (Some(rated), Some(plain)) = (
                KerrRay::rated(kerr, &start, v, dv, true),
                KerrRay::from_start(kerr, &start, v, true),
            ) else {
                continue;
            };
            let value = rated.value();
            for (a, b) in value.crossings().zip(plain.crossings()) {
                let (p, q) = (value.crossing_point_time(&a), plain.crossing_point_time(&b));
                let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * y.abs().max(1.0);
                assert!(
                    (p.x - q.x).length() <= 1e-12 * q.x.length()
                        && close(p.phi, q.phi)
                        && close(p.t, q.t),
                    "{p:?} {q:?}"
                );
                n += 1;
            }
        }
        assert!(n > 30, "{n} crossings");
    }

    /// What a footprint reads of a ray: the escape direction, or each
    /// crossing's Boyer-Lindquist radius and azimuth.
    #[derive(Debug, PartialEq)]
    enum Kind {
        Escape,
        Captured,
    }

    fn kind(captured: bool) -> Kind {
        if captured {
            Kind::Captured
        } else {
            Kind::Escape
        }
    }

    #[test]
    fn a_rated_ray_carries_the_closed_forms_derivatives() {
        // Rays from cameras near and far, on and off the axis, in every
        // direction of a coarse sphere, against central differences of the
        // closed form in the direction (step 1e-6 of it). Which radial
        // case each ray took is counted: every one must be exercised.
        let mut cases = [0usize; 5];
        let mut worst: f64 = 0.0;
        let (mut tested, mut skipped) = (0usize, 0usize);
        for (a, x) in [
            (0.9, DVec3::new(30.0, 0.0, 8.0)),
            (0.998, DVec3::new(0.3, 0.2, 12.0)),
            (-0.6, DVec3::new(-5.0, 3.0, -1.0)),
            (0.5, DVec3::new(2.2, 0.0, 0.4)),
        ] {
            let kerr = Kerr::new(a);
            let start = KsStart::new(kerr, x);
            // A coarse sphere of directions, and near-radial ones (a
            // camera near the axis sees vortical rays along them).
            let out = x.normalize();
            let (e1, e2) = (
                out.cross(DVec3::X).normalize(),
                out.cross(DVec3::Y).normalize(),
            );
            let sphere = (0..24).flat_map(|i| {
                (1..12).map(move |j| {
                    let (th, ph) = (j as f64 * 0.26, i as f64 * 0.2618 + 0.1);
                    DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
                })
            });
            let radial = [-1.0, 1.0].into_iter().flat_map(|sign| {
                [0.0, 0.003, 0.01, 0.03, 0.1]
                    .into_iter()
                    .flat_map(move |t| [e1, e2, -e1].map(|e| (out * sign + e * t).normalize()))
            });
            for v in sphere.chain(radial) {
                {
                    let dv = [v.cross(DVec3::Z).normalize(), DVec3::new(0.3, -0.2, 0.5)];
                    let Some(rated) = KerrRay::rated(kerr, &start, v, dv, false) else {
                        continue;
                    };
                    let plain = KerrRay::from_start(kerr, &start, v, false).unwrap();
                    let value = rated.value();
                    assert_eq!(value.captured, plain.captured);
                    // The rated ray's values are the ray's (to the
                    // duplication's rounding).
                    assert!((value.s_end - plain.s_end).abs() <= 1e-13 * plain.s_end.abs());
                    cases[match rated.radial {
                        Radial::Outer { .. } if rated.min_r > rated.horizons[0] => 0,
                        Radial::Outer { .. } => 1,
                        Radial::Pair { .. } => 2,
                        Radial::Quad { .. } => 3,
                    }] += 1;
                    if rated.polar.vortical.is_some() {
                        cases[4] += 1;
                    }
                    let near_axis = rated.polar.u_plus.v > 1.0 - 1e-6;
                    for k in 0..2 {
                        // The fourth-order central difference (rays at -2h,
                        // -h, h, 2h) at two steps: where they agree to 1e-6
                        // the difference has converged and is the reference
                        // (a ray near the axis carries ~1e-9 of rounding in
                        // eta, so the steps are not small).
                        let fans: Vec<Vec<KerrRay>> = [4e-4, 1e-4]
                            .iter()
                            .map(|&h| {
                                [-2.0, -1.0, 1.0, 2.0]
                                    .iter()
                                    .filter_map(|&t| {
                                        KerrRay::from_start(
                                            kerr,
                                            &start,
                                            v + dv[k] * (t * h),
                                            false,
                                        )
                                    })
                                    .filter(|r| kind(r.captured) == kind(plain.captured))
                                    .collect()
                            })
                            .collect();
                        if fans.iter().any(|f| f.len() < 4) {
                            continue;
                        }
                        let diff = |f: &dyn Fn(&KerrRay) -> Option<f64>| -> Option<f64> {
                            let mut d = [0.0; 2];
                            for (i, (rays, h)) in fans.iter().zip([4e-4, 1e-4]).enumerate() {
                                let [a, b, c, e] =
                                    [f(&rays[0])?, f(&rays[1])?, f(&rays[2])?, f(&rays[3])?];
                                d[i] = (8.0 * (c - b) - (e - a)) / (12.0 * h);
                            }
                            ((d[0] - d[1]).abs() <= 1e-6 * d[1].abs().max(1.0)).then_some(d[1])
                        };
                        let mut check = |got: f64, want: Option<f64>, what: &str| {
                            let Some(want) = want else {
                                skipped += 1;
                                return;
                            };
                            tested += 1;
                            let err = (got - want).abs() / want.abs().max(1.0);
                            // Within 1e-3 rad of the axis (u_+ > 1 - 1e-6)
                            // the polar characteristic runs past -1e6 and
                            // its Pi's rates cancel to about 1e-4.
                            let tol = if near_axis { 1e-3 } else { 1e-5 };
                            assert!(
                                err < tol,
                                "a {a} x {x} v {v} axis {k} {what}: {got} against {want}"
                            );
                            if !near_axis {
                                worst = worst.max(err);
                            }
                        };
                        if !plain.captured {
                            let (_, d) = rated.escape_rated();
                            for (c, got) in d[k].to_array().into_iter().enumerate() {
                                check(got, diff(&|r| Some(r.escape_direction()[c])), "escape");
                            }
                        }
                        for (n, c) in rated.crossings().enumerate() {
                            let at = |r: &KerrRay| r.crossings().nth(n);
                            let (r, phi, _) = rated.crossing_rated(&c);
                            check(r.d[k], diff(&|ray| Some(at(ray)?.r)), "crossing radius");
                            let azimuth =
                                |ray: &KerrRay| Some(ray.crossing_point_time(&at(ray)?).phi);
                            check(phi.d[k], diff(&azimuth), "crossing azimuth");
                        }
                    }
                }
            }
        }
        eprintln!(
            "cases {cases:?}, {tested} rates tested ({skipped} where the differences had not \
             converged), worst relative difference {worst:.2e}"
        );
        assert!(cases.iter().all(|&n| n > 0), "cases {cases:?}");
        assert!(
            skipped * 20 < tested,
            "{skipped} of {tested} rates untested"
        );
    }
}
