//! Physical constants in SI units: one value for every use (the scene, the
//! thin disk, the clock, `info`, the tests).

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
