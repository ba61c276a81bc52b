//! A radiatively inefficient accretion flow (RIAF): the hot, thick,
//! thermal plasma about Sgr A* and M87*, as Broderick and Loeb 2006 (ApJ
//! 636, L109) and Pu et al. 2016 (ApJ 820, 105) model it, in
//! Boyer-Lindquist coordinates of a hole of mass M = 1:
//!
//! - electron density n_e = n0 r^a exp(-z^2 / (2 (H rho)^2)), z = r cos
//!   th, rho = r sin th (a = -1.1, H = 1 in Broderick and Loeb's fits);
//! - electron temperature T_e = T0 r^b (b = -0.84), the same off the plane;
//! - a tangled field in equipartition with the ions' gravity: B^2 / 8 pi
//!   = n_e m_p c^2 / (6 beta r) (beta = 10);
//! - the gas turns at Omega_K + (1 - kappa) (omega - Omega_K), between the
//!   Keplerian Omega_K (inside the ISCO the plunging orbit's, with the
//!   ISCO's energy and angular momentum) and the frame's own omega, and
//!   falls in at u^r = u^r_K + f (u^r_ff - u^r_K), between the Keplerian
//!   (nil outside the ISCO) and free fall from rest at infinity (the
//!   sub-Keplerian shearing inflow of Pu et al. 2016's follow-ups);
//! - thermal synchrotron emission, angle-averaged ([`super::synchrotron`]).

use super::CUTOFF;
use crate::physics::kerr::Kerr;
use crate::units::cgs;
use std::f64::consts::PI;

/// The flow's parameters, as a user gives them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RiafProfile {
    /// n_e at r = 1 M (cm^-3).
    pub density: f64,
    /// T_e at r = 1 M (K).
    pub temperature: f64,
    /// n_e ~ r^density_index.
    pub density_index: f64,
    /// T_e ~ r^temperature_index.
    pub temperature_index: f64,
    /// H: the vertical Gaussian's width over the cylindrical radius.
    pub thickness: f64,
    /// Gas over magnetic pressure.
    pub beta: f64,
    /// kappa: 1 Keplerian, 0 turning with the frame.
    pub keplerian: f64,
    /// f: 0 no infall (outside the ISCO), 1 free fall.
    pub infall: f64,
    /// Beyond this radius (M) there is no gas.
    pub outer: f64,
}

impl RiafProfile {
    /// Broderick and Loeb's power laws and field, Keplerian without
    /// infall, out to 1000 M, at the given density and temperature scales.
    pub fn broderick_loeb(density: f64, temperature: f64) -> RiafProfile {
        RiafProfile {
            density,
            temperature,
            density_index: -1.1,
            temperature_index: -0.84,
            thickness: 1.0,
            beta: 10.0,
            keplerian: 1.0,
            infall: 0.0,
            outer: 1000.0,
        }
    }
}

/// The flow about a given hole.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Riaf {
    pub profile: RiafProfile,
    /// Where the gas ends abruptly (its outer radius).
    pub surfaces: [f64; 1],
    /// How its gas moves.
    pub motion: Motion,
}

/// Gas turning between the Keplerian rate (the plunging orbit's inside
/// the ISCO) and the frame's, and falling between the Keplerian motion's
/// and free fall from rest at infinity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// 1 Keplerian, 0 turning with the frame.
    pub keplerian: f64,
    /// 0 the Keplerian motion's fall (none outside the ISCO), 1 free fall.
    pub infall: f64,
    /// The ISCO's radius and its circular orbit's energy and angular
    /// momentum per unit mass, which the plunge inside it keeps.
    isco: (f64, f64, f64),
}

crate::wgsl::gpu_block! {
    /// The flow's profile as the GPU reads it (media.wgsl's riaf_*): the
    /// fields of [`RiafProfile`] that shape the gas (its motion is its
    /// [`MotionBlock`]).
    RiafBlock {
        density,
        temperature,
        density_index,
        temperature_index,
        thickness,
        beta,
        outer,
    }
}

crate::wgsl::gpu_block! {
    /// A [`Motion`] as the GPU reads it (media.wgsl's motion_*): its
    /// mixes and the ISCO's radius, energy and angular momentum.
    MotionBlock {
        keplerian,
        infall,
        r_isco,
        e_isco,
        l_isco,
    }
}

impl Riaf {
    /// Its profile for the GPU.
    pub fn gpu_block(&self) -> RiafBlock {
        let (p, f) = (&self.profile, |x: f64| x as f32);
        RiafBlock {
            density: f(p.density),
            temperature: f(p.temperature),
            density_index: f(p.density_index),
            temperature_index: f(p.temperature_index),
            thickness: f(p.thickness),
            beta: f(p.beta),
            outer: f(p.outer),
        }
    }

    pub fn new(profile: RiafProfile, kerr: Kerr) -> Riaf {
        Riaf {
            profile,
            surfaces: [profile.outer],
            motion: Motion::new(profile.keplerian, profile.infall, kerr),
        }
    }

    /// (n_e cm^-3, T_e K, B G) at (r, cos th), or None where there is
    /// no gas.
    #[inline]
    pub fn plasma(&self, r: f64, cos_th: f64) -> Option<(f64, f64, f64)> {
        let p = &self.profile;
        if r > p.outer {
            return None;
        }
        let sin2 = (1.0 - cos_th * cos_th).max(0.0);
        // z^2 / (2 H^2 rho^2) = cot^2 th / (2 H^2).
        let e = cos_th * cos_th / (2.0 * p.thickness * p.thickness * sin2);
        if !(e < CUTOFF) {
            return None;
        }
        let n = p.density * r.powf(p.density_index) * (-e).exp();
        let t = p.temperature * r.powf(p.temperature_index);
        let b = (8.0 * PI * n * cgs::PROTON_MASS * cgs::LIGHT.powi(2) / (6.0 * p.beta * r)).sqrt();
        Some((n, t, b))
    }

    /// The length (M) over which the plasma changes by about e at (r, cos
    /// th): a fraction of r for the power laws (the emission at a fixed
    /// frequency is steeper in r than the density or temperature), the
    /// vertical Gaussian's width and its steepening off the plane (no
    /// finer than 1/32 of r: where it is steeper the gas is below e^-5 of
    /// the plane's), and about the axis, where there is no gas, the way
    /// to the cone where it starts.
    #[inline]
    pub fn scale(&self, r: f64, cos_th: f64) -> f64 {
        let h = self.profile.thickness;
        let sin = (1.0 - cos_th * cos_th).max(0.0).sqrt();
        let radial = 0.125 * r;
        // The cone's cot th = H sqrt(2 CUTOFF).
        let cot_edge = h * (2.0 * CUTOFF).sqrt();
        if cos_th.abs() >= cot_edge * sin {
            let edge = (1.0 / cot_edge).atan();
            let th = sin.atan2(cos_th.abs());
            return radial.min(r * (edge - th)).max(r / 32.0);
        }
        // d/dth of cot^2 th / (2 H^2) is cot th / (H^2 sin^2 th).
        let vertical = r / (cos_th.abs() / (h * h * sin * sin * sin) + 1.0 / h);
        radial.min(vertical.max(r / 32.0))
    }
}

impl Motion {
    /// The motion about the hole `kerr`.
    pub fn new(keplerian: f64, infall: f64, kerr: Kerr) -> Motion {
        let r = kerr.isco();
        Motion {
            keplerian,
            infall,
            isco: (r, kerr.orbit_energy(r), kerr.orbit_angular_momentum(r)),
        }
    }

    /// The motion for the GPU.
    pub fn gpu_block(&self) -> MotionBlock {
        let (r, e, l) = self.isco;
        MotionBlock {
            keplerian: self.keplerian as f32,
            infall: self.infall as f32,
            r_isco: r as f32,
            e_isco: e as f32,
            l_isco: l as f32,
        }
    }

    /// The frequency the gas at (r, th) measures for a photon of unit
    /// energy at infinity, angular momentum `lz` and radial momentum
    /// `k^r` = dr/dlambda (M units) about the hole `kerr`: -k.u = u^t -
    /// lz u^ph - g_rr k^r u^r. None where the prescribed motion is not
    /// timelike, or inside the horizon.
    #[inline]
    pub fn frequency_ratio(
        &self,
        kerr: Kerr,
        r: f64,
        cos_th: f64,
        (lz, k_r): (f64, f64),
    ) -> Option<f64> {
        let sin = (1.0 - cos_th * cos_th).max(1e-300).sqrt();
        let z = kerr.zamo_at(r, cos_th, sin);
        if !(z.alpha > 0.0) {
            return None;
        }
        let a2 = z.alpha * z.alpha;
        let w2 = z.varpi * z.varpi;
        let sigma = r * r + kerr.a * kerr.a * cos_th * cos_th;
        let delta = kerr.delta(r);
        // g^rr = Delta / Sigma; g^tt = -1 / alpha^2.
        let g_rr_up = delta / sigma;
        let (r_isco, e, l) = self.isco;
        let (omega_k, ur_k) = if r >= r_isco {
            (kerr.orbital_angular_velocity(r), 0.0)
        } else {
            // The plunge keeps u_t = -E, u_ph = L: u^t = (E - omega L) /
            // alpha^2, u^ph = omega u^t + L / varpi^2, and u^r from the
            // norm, inwards.
            let ut = (e - z.omega * l) / a2;
            let uph = z.omega * ut + l / w2;
            let ur2 = g_rr_up * ((e - z.omega * l).powi(2) / a2 - l * l / w2 - 1.0);
            (uph / ut, -ur2.max(0.0).sqrt())
        };
        let omega = omega_k + (1.0 - self.keplerian) * (z.omega - omega_k);
        // Free fall from rest at infinity: u_t = -1, u_ph = 0.
        let ur_ff = -((1.0 / a2 - 1.0) * g_rr_up).max(0.0).sqrt();
        let ur = ur_k + self.infall * (ur_ff - ur_k);
        // -1 = (u^t)^2 (g_tt + 2 Omega g_tph + Omega^2 g_phph) + g_rr
        // (u^r)^2, the bracket -alpha^2 + varpi^2 (Omega - omega)^2.
        let k = -a2 + w2 * (omega - z.omega).powi(2);
        let ut2 = -(1.0 + ur * ur / g_rr_up) / k;
        if !(k < 0.0 && ut2 > 0.0) {
            return None;
        }
        let ut = ut2.sqrt();
        Some(ut * (1.0 - lz * omega) - k_r / g_rr_up * ur)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn riaf(spin: f64, keplerian: f64, infall: f64) -> Riaf {
        let mut p = RiafProfile::broderick_loeb(1e6, 1e11);
        p.keplerian = keplerian;
        p.infall = infall;
        Riaf::new(p, Kerr::new(spin))
    }

    #[test]
    fn keplerian_gas_shifts_as_the_circular_orbit() {
        // Outside the ISCO in the plane, without infall: the circular
        // orbit's 1 / (u^t (1 - Omega lz)) (Kerr::orbit_shift).
        for spin in [0.0, 0.5, 0.9] {
            let kerr = Kerr::new(spin);
            let f = riaf(spin, 1.0, 0.0);
            for (r, lz) in [(8.0, -3.0), (12.0, 0.0), (30.0, 4.5)] {
                let got = f.motion.frequency_ratio(kerr, r, 0.0, (lz, 0.7)).unwrap();
                let want = 1.0 / kerr.orbit_shift(r, lz);
                assert!(
                    (got - want).abs() < 1e-12 * want,
                    "{spin} {r}: {got} {want}"
                );
            }
        }
    }

    #[test]
    fn the_plunge_and_free_fall_are_unit_timelike_geodesics() {
        // Inside the ISCO the Keplerian gas plunges with the ISCO's E and
        // L: for a photon of lz = 0 moving radially with k^r, -k.u = E -
        // k_r u^r... check through the conserved u_t: at lz = 0 and k^r =
        // 0, -k.u = u^t, and u_t = g_tt u^t + g_tph u^ph = -E.
        let kerr = Kerr::new(0.0);
        let f = riaf(0.0, 1.0, 0.0);
        let r: f64 = 4.5;
        let ut = f.motion.frequency_ratio(kerr, r, 0.0, (0.0, 0.0)).unwrap();
        // Schwarzschild: u_t = -(1 - 2/r) u^t.
        let e = kerr.orbit_energy(6.0);
        assert!(((1.0 - 2.0 / r) * ut - e).abs() < 1e-12, "{ut}");
        // Free fall from rest at infinity (kappa 0, f 1) at spin 0:
        // u^t = 1 / (1 - 2/r), u^r = -sqrt(2/r); a photon going out
        // radially (k^r = 1, k_r = 1 / (1 - 2/r)) meets it at -k.u =
        // (1 + sqrt(2/r)) / (1 - 2/r) = 1 / (1 - sqrt(2/r)).
        let ff = riaf(0.0, 0.0, 1.0);
        for r in [3.0f64, 10.0, 100.0] {
            let got = ff.motion.frequency_ratio(kerr, r, 0.3, (0.0, 1.0)).unwrap();
            let want = 1.0 / (1.0 - (2.0 / r).sqrt());
            assert!((got - want).abs() < 1e-12 * want, "{r}: {got} {want}");
        }
    }

    #[test]
    fn the_plasma_follows_its_power_laws() {
        let f = riaf(0.0, 1.0, 0.0);
        let (n1, t1, b1) = f.plasma(10.0, 0.0).unwrap();
        let (n2, t2, b2) = f.plasma(20.0, 0.0).unwrap();
        assert!((n2 / n1 - 2f64.powf(-1.1)).abs() < 1e-12);
        assert!((t2 / t1 - 2f64.powf(-0.84)).abs() < 1e-12);
        // B^2 ~ n / r.
        assert!(((b2 / b1).powi(2) - 2f64.powf(-2.1)).abs() < 1e-12);
        // At z = rho (th = 45 degrees) the Gaussian is e^-1/2.
        let c = 0.5f64.sqrt();
        let (n3, _, _) = f.plasma(10.0, c).unwrap();
        assert!((n3 / n1 - (-0.5f64).exp()).abs() < 1e-12);
        assert!(f.plasma(1001.0, 0.0).is_none());
    }
}
