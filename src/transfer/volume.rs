//! The volumetric disk (`[volume]`) as a medium in physical units, for
//! observed scenes: gas in local thermodynamic equilibrium, its source
//! function Planck's at the disk's temperature where it is (the
//! visible-band render's temperature field), its absorption grey and
//! proportional to its density (`volume.opacity` per r_s at density 1),
//! so j_nu = alpha B_nu(T) (Kirchhoff), moving as the visible-band disk's
//! gas does ([`VolumeDisk::motion`]: the one model of both bands).

use super::{Gas, Plasma};
use crate::physics::kerr::Kerr;
use crate::volume::VolumeDisk;
use glam::DVec3;

/// The volumetric disk's gas.
#[derive(Clone, Debug)]
pub struct VolumeGas {
    /// Its density, radii and temperature field (lengths in r_s).
    pub disk: VolumeDisk,
    /// alpha_nu (cm^-1) at density 1.
    pub alpha: f64,
}

crate::wgsl::gpu_block! {
    /// The volume's gas as the GPU reads it (media.wgsl's volume_gas_*):
    /// alpha_nu at density 1 (cm^-1), its structure's scale (M), the
    /// layer's half height and the inner radius (r_s), and T0 of the
    /// temperature T0 r^-3/4 (1 - sqrt(inner / r))^1/4; its density is
    /// the visible-band volume's grid, its motion its [`super::riaf::MotionBlock`].
    VolumeGasBlock {
        alpha,
        structure,
        zmax,
        inner,
        t0,
    }
}

impl VolumeGas {
    /// Its parameters for the GPU.
    pub fn gpu_block(&self) -> VolumeGasBlock {
        let d = &self.disk;
        let t0 =
            d.peak_kelvin / crate::assets::disk::temperature_shape(49.0 / 36.0 * d.inner, d.inner);
        VolumeGasBlock {
            alpha: self.alpha as f32,
            structure: self.structure() as f32,
            zmax: d.zmax() as f32,
            inner: d.inner as f32,
            t0: t0 as f32,
        }
    }

    /// The gas of `disk` about a hole whose r_s is `r_s_cm` cm.
    pub fn new(disk: VolumeDisk, r_s_cm: f64) -> VolumeGas {
        VolumeGas {
            alpha: disk.kappa / r_s_cm,
            disk,
        }
    }

    /// Beyond this radius (M) there is no gas.
    pub fn extent(&self) -> f64 {
        2.0 * self.disk.outer.hypot(self.disk.zmax())
    }

    /// The scale (M) of the gas's finest structure: the length of the
    /// visible band's pieces through it ([`VolumeDisk::scale`], two
    /// sampling steps in r_s), so that both bands take it at the same
    /// nodes, one each step.
    pub fn structure(&self) -> f64 {
        2.0 * self.disk.scale()
    }

    /// The length (M) over which the gas changes at `p` (M): its
    /// structure's, or, above and below its layer, the way to it.
    pub fn scale(&self, p: DVec3) -> f64 {
        let above = 0.5 * p.z.abs() - self.disk.zmax();
        self.structure().max(2.0 * above)
    }

    /// The gas at `p` (M; Boyer-Lindquist's r and cos th there), for a
    /// photon of angular momentum and radial momentum `photon`.
    #[inline]
    pub fn state(
        &self,
        kerr: Kerr,
        (r, cos_th): (f64, f64),
        p: DVec3,
        photon: (f64, f64),
    ) -> Option<Gas> {
        // The disk's fields are in the tracer's Cartesian r_s.
        let q = 0.5 * p;
        let rho = self.disk.density.sample(q) as f64;
        if rho <= 0.0 {
            return None;
        }
        let kelvin = self.disk.kelvin(q.x.hypot(q.y));
        if !(kelvin > 0.0) {
            return None;
        }
        Some(Gas {
            ratio: self.disk.motion.frequency_ratio(kerr, r, cos_th, photon)?,
            plasma: Plasma::Blackbody {
                alpha: self.alpha * rho,
                kelvin,
            },
        })
    }
}
