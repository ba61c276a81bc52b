//! Physical constants: one value for every use (the scene, the thin disk,
//! the spectra, the clock, `info`, radiative transfer, the GPU's shaders,
//! the tests). SI here; [`cgs`] holds the units radiative transfer is
//! written in.

/// Gravitational constant used throughout (m^3 kg^-1 s^-2).
pub const G: f64 = 6.674e-11;
/// Speed of light (m/s), exact SI value.
pub const C: f64 = 2.997_924_58e8;
/// The Sun's mass (kg): (1.98847 +- 0.00007) x 10^30 kg, CODATA 2018's G
/// with the IAU's nominal solar mass parameter.
pub const SOLAR_MASS: f64 = 1.988_47e30;
/// The Julian year (s), for rates per year.
pub const YEAR: f64 = 3.155_76e7;
/// Boltzmann's constant (J/K), exact SI value.
pub const BOLTZMANN: f64 = 1.380_649e-23;
/// Planck's constant (J s), exact SI value.
pub const PLANCK: f64 = 6.626_070_15e-34;
/// The proton's mass (kg), CODATA 2018.
pub const PROTON_MASS: f64 = 1.672_621_923_69e-27;
/// The Thomson cross-section (m^2), CODATA 2018.
pub const THOMSON: f64 = 6.652_458_732_1e-29;
/// The Stefan-Boltzmann constant (W m^-2 K^-4), CODATA 2018.
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;
/// Metres in a parsec (IAU 2015 Resolution B2: 648000 / pi au).
pub const PARSEC: f64 = 3.085_677_581_491_367e16;

/// The second radiation constant h c / k (m K) as CIE 15 prescribes for
/// Planckian radiators; colour-science uses the same value, which the
/// colour reference data rely on.
pub const RADIATION_C2: f64 = 1.4388e-2;
/// The first radiation constant 2 pi h c^2 (W m^2), as CIE 15 gives it.
pub const RADIATION_C1: f64 = 3.741771e-16;

/// The constants in cgs, radiative transfer's units (each the SI value
/// converted, or the literal where the conversion would round otherwise).
pub mod cgs {
    /// The speed of light (cm s^-1).
    pub const LIGHT: f64 = super::C * 1e2;
    /// Boltzmann's constant (erg K^-1).
    pub const BOLTZMANN: f64 = super::BOLTZMANN * 1e7;
    /// Planck's constant (erg s).
    pub const PLANCK: f64 = super::PLANCK * 1e7;
    /// The electron's charge (esu).
    pub const ELECTRON_CHARGE: f64 = 4.803_204_712_570_263e-10;
    /// The electron's mass (g).
    pub const ELECTRON_MASS: f64 = 9.109_383_701_5e-28;
    /// The proton's mass (g).
    pub const PROTON_MASS: f64 = super::PROTON_MASS * 1e3;
    /// Centimetres per parsec (IAU 2015).
    pub const PARSEC: f64 = 3.085_677_581_491_367e18;
    /// One jansky (erg s^-1 cm^-2 Hz^-1).
    pub const JANSKY: f64 = 1e-23;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cgs_is_si_converted() {
        // The conversions land on the literals radiative transfer was
        // validated with, bit for bit.
        assert_eq!(cgs::LIGHT, 2.997_924_58e10);
        assert_eq!(cgs::BOLTZMANN, 1.380_649e-16);
        assert_eq!(cgs::PLANCK, 6.626_070_15e-27);
        assert_eq!(cgs::PROTON_MASS, 1.672_621_923_69e-24);
        assert!((cgs::PARSEC / (PARSEC * 1e2) - 1.0).abs() < 1e-15);
    }
}
