//! Settings and tables of a spectral render.

use crate::config::{Interpolation, SpectralConfig};
use crate::spectrum::sampled::{PlanckTable, Wavelengths};

/// Everything the shading of one spectral sample needs.
#[derive(Clone, Debug)]
pub struct SpectralContext {
    /// Camera wavelengths and their CIE weights.
    pub wavelengths: Wavelengths,
    /// Blackbody spectra on those wavelengths.
    pub planck: PlanckTable,
    /// Apply the frequency shift.
    pub shift: bool,
    /// Radiance times g^5.
    pub beaming: bool,
    /// The disk's Keplerian Doppler shift.
    pub doppler: bool,
    /// Emitter lookup between tabulated wavelengths.
    pub interpolation: Interpolation,
    /// One traced ray per wavelength (reference path).
    pub per_wavelength: bool,
}

impl SpectralContext {
    /// Built from a validated `[spectral]` table.
    pub fn new(c: &SpectralConfig) -> SpectralContext {
        let wavelengths = Wavelengths::new(c.wavelengths as usize);
        SpectralContext {
            planck: PlanckTable::new(&wavelengths),
            wavelengths,
            shift: c.shift,
            beaming: c.beaming,
            doppler: c.doppler,
            interpolation: c.interpolation,
            per_wavelength: c.per_wavelength,
        }
    }

    /// Radiance factor for light arriving with frequency ratio `g`: g^5
    /// with beaming (I_nu / nu^3 is invariant, so per-wavelength radiance
    /// scales as g^5), else 1.
    #[inline]
    pub fn radiance_factor(&self, g: f64) -> f32 {
        if self.beaming { g.powi(5) as f32 } else { 1.0 }
    }
}
