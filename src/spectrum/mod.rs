//! Spectra and colour: CIE 1931 colour-matching functions, Planck's law,
//! XYZ and sRGB.
//!
//! The CMF tables are the CSV files in `cie_data/` (generated from
//! colour-science by `validation/generate_cie_data.py`), embedded at build
//! time so the binary needs no data files.

pub mod color;
pub mod sampled;
pub mod uplift;

use glam::{DVec3, Vec3};
use std::sync::LazyLock;

/// Shortest wavelength of the visible range the renderer samples (nm).
pub const LAMBDA_MIN: f64 = 380.0;
/// Longest wavelength of the visible range the renderer samples (nm).
pub const LAMBDA_MAX: f64 = 780.0;

/// A table of values on a regular wavelength grid, read from `cie_data/`.
#[derive(Debug)]
pub struct Table<T> {
    /// First wavelength (nm).
    pub start: f64,
    /// Grid spacing (nm).
    pub step: f64,
    /// One entry per wavelength.
    pub values: Vec<T>,
}

fn parse_rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split(',')
                .map(|v| v.trim().parse().expect("cie_data is numeric"))
                .collect()
        })
        .collect()
}

impl<T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>> Table<T> {
    fn from_rows(rows: Vec<Vec<f64>>, value: impl Fn(&[f64]) -> T) -> Table<T> {
        Table {
            start: rows[0][0],
            step: rows[1][0] - rows[0][0],
            values: rows.iter().map(|r| value(&r[1..])).collect(),
        }
    }

    /// Last wavelength (nm).
    pub fn end(&self) -> f64 {
        self.start + (self.values.len() - 1) as f64 * self.step
    }

    /// Value at a grid wavelength `nm`.
    pub fn at(&self, nm: f64) -> T {
        self.values[((nm - self.start) / self.step).round() as usize]
    }

    /// Value at any wavelength, linear between grid points; `None` outside
    /// the table.
    pub fn lerp(&self, nm: f64) -> Option<T> {
        let f = (nm - self.start) / self.step;
        if !(f >= 0.0 && f <= (self.values.len() - 1) as f64) {
            return None;
        }
        let i = (f as usize).min(self.values.len() - 2);
        let t = f - i as f64;
        Some(self.values[i] * (1.0 - t) + self.values[i + 1] * t)
    }
}

/// Colour-matching functions x-bar, y-bar, z-bar.
pub type Cmf = Table<DVec3>;

impl Cmf {
    /// XYZ of a spectrum given as a function of wavelength (nm), by the plain
    /// sum over the grid points in [`LAMBDA_MIN`, `LAMBDA_MAX`] times the
    /// spacing.
    pub fn integrate(&self, spectrum: impl Fn(f64) -> f64) -> DVec3 {
        let n = ((LAMBDA_MAX - LAMBDA_MIN) / self.step).round() as usize;
        (0..=n)
            .map(|i| {
                let nm = LAMBDA_MIN + i as f64 * self.step;
                self.at(nm) * spectrum(nm)
            })
            .sum::<DVec3>()
            * self.step
    }
}

/// CIE 1931 2-degree observer at 1 nm (360-830 nm).
pub static CIE_1NM: LazyLock<Cmf> = LazyLock::new(|| {
    Table::from_rows(
        parse_rows(include_str!("../../cie_data/cie1931_2deg_1nm.csv")),
        |r| DVec3::new(r[0], r[1], r[2]),
    )
});
/// CIE 1931 2-degree observer at 5 nm (360-830 nm).
pub static CIE_5NM: LazyLock<Cmf> = LazyLock::new(|| {
    Table::from_rows(
        parse_rows(include_str!("../../cie_data/cie1931_2deg_5nm.csv")),
        |r| DVec3::new(r[0], r[1], r[2]),
    )
});
/// CIE standard illuminant D65 at 5 nm (300-780 nm, 100 at 560 nm).
pub static D65: LazyLock<Table<f64>> = LazyLock::new(|| {
    Table::from_rows(
        parse_rows(include_str!("../../cie_data/d65_5nm.csv")),
        |r| r[0],
    )
});

/// D65 at any wavelength: the table, linear between its points, continued
/// beyond its ends by a 6504 K blackbody matched at the end (D65's own
/// envelope), so shifted lookups outside 300-780 nm stay smooth and positive.
pub fn d65(nm: f64) -> f64 {
    if let Some(v) = D65.lerp(nm) {
        return v;
    }
    let edge = if nm < D65.start { D65.start } else { D65.end() };
    D65.at(edge) * planck(nm, 6504.0) / planck(edge, 6504.0)
}

/// Planck spectral radiance B_lambda(T) in W / (m^2 sr m), wavelength in nm:
/// the visible band's blackbodies, with CIE 15's radiation constants.
pub fn planck(nm: f64, kelvin: f64) -> f64 {
    use crate::units::{RADIATION_C1, RADIATION_C2};
    let l = nm * 1e-9;
    RADIATION_C1 / (std::f64::consts::PI * l.powi(5)) / (RADIATION_C2 / (l * kelvin)).exp_m1()
}

/// Planck's B_nu(T) in cgs (erg s^-1 cm^-2 Hz^-1 sr^-1), frequency in Hz:
/// the source function of gas in thermal equilibrium, and the light of
/// the thin disk and of a blackbody sky in physical units.
pub fn planck_nu(nu: f64, kelvin: f64) -> f64 {
    use crate::units::cgs::{BOLTZMANN, LIGHT, PLANCK};
    2.0 * PLANCK * nu * nu * nu / (LIGHT * LIGHT) / (PLANCK * nu / (BOLTZMANN * kelvin)).exp_m1()
}

/// XYZ of a blackbody at `kelvin`, scaled to luminance Y = 1 (1 nm grid).
pub fn blackbody_xyz(kelvin: f64) -> DVec3 {
    let xyz = CIE_1NM.integrate(|nm| planck(nm, kelvin));
    xyz / xyz.y
}

/// Linear sRGB of a blackbody at `kelvin`, luminance 1 (negative channels,
/// outside the sRGB gamut, clipped to 0).
pub fn blackbody_rgb(kelvin: f64) -> Vec3 {
    color::xyz_to_linear_srgb(blackbody_xyz(kelvin))
        .as_vec3()
        .max(Vec3::ZERO)
}

/// Blackbody colours tabulated in 25 K steps: per-texel Planck integrals
/// would dominate the generators' run time.
#[derive(Clone, Debug)]
pub struct BlackbodyTable {
    min: f64,
    colors: Vec<Vec3>,
}

impl BlackbodyTable {
    const STEP: f64 = 25.0;

    /// Table over [min, max] kelvin.
    pub fn new(min: f64, max: f64) -> BlackbodyTable {
        let n = ((max - min) / Self::STEP).ceil() as usize + 1;
        BlackbodyTable {
            min,
            colors: (0..n)
                .map(|i| blackbody_rgb(min + i as f64 * Self::STEP))
                .collect(),
        }
    }

    /// The GPU backend's copy: (first kelvin, spacing, colours).
    pub(crate) fn gpu_parts(&self) -> (f64, f64, &[Vec3]) {
        (self.min, Self::STEP, &self.colors)
    }

    /// Colour at `kelvin`, linearly interpolated, clamped to the table.
    pub fn get(&self, kelvin: f64) -> Vec3 {
        let f = ((kelvin - self.min) / Self::STEP).clamp(0.0, (self.colors.len() - 1) as f64);
        let i = (f as usize).min(self.colors.len() - 2);
        self.colors[i].lerp(self.colors[i + 1], (f - i as f64) as f32)
    }
}

/// Effective temperature (K) of a star from its B-V colour index
/// (Ballesteros 2012).
pub fn bv_to_kelvin(bv: f64) -> f64 {
    4600.0 * (1.0 / (0.92 * bv + 1.7) + 1.0 / (0.92 * bv + 0.62))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d65_table_and_extension() {
        assert_eq!(d65(560.0), 100.0);
        assert!((d65(562.5) - 0.5 * (D65.at(560.0) + D65.at(565.0))).abs() < 1e-12);
        // Continuous at the table's end and beyond it.
        assert!((d65(780.0 + 1e-9) - d65(780.0)).abs() < 1e-6);
        assert!(d65(900.0) > 0.0 && d65(900.0) < d65(780.0));
        assert!(d65(250.0) > 0.0);
    }

    #[test]
    fn tables_load_with_expected_shape() {
        assert_eq!(CIE_1NM.values.len(), 471);
        assert_eq!(CIE_5NM.values.len(), 95);
        // y-bar peaks at exactly 1 at 555 nm.
        assert_eq!(CIE_1NM.at(555.0).y, 1.0);
        assert_eq!(CIE_5NM.at(555.0), CIE_1NM.at(555.0));
    }

    #[test]
    fn blackbody_5800k_matches_colour_science() {
        // validation/REFERENCE.md section 5: 380-780 nm at 5 nm, plain sum, Y = 1.
        let xyz = CIE_5NM.integrate(|nm| planck(nm, 5800.0));
        let xyz = xyz / xyz.y;
        let s = xyz.x + xyz.y + xyz.z;
        assert!((xyz.x / s - 0.3260002553).abs() < 1e-9, "x {}", xyz.x / s);
        assert!((xyz.y / s - 0.3353569896).abs() < 1e-9, "y {}", xyz.y / s);
        let rgb = color::xyz_to_linear_srgb(xyz);
        let want = DVec3::new(1.1094994198, 0.9758397116, 0.9175022141);
        assert!((rgb - want).abs().max_element() < 1e-9, "{rgb}");
    }

    #[test]
    fn planck_peak_follows_wien() {
        // Wien's displacement: lambda_max T = c2 / 4.965114231744276.
        let t = 5000.0;
        let peak = (300..3000)
            .map(|i| i as f64)
            .max_by(|a, b| planck(*a, t).total_cmp(&planck(*b, t)))
            .unwrap();
        let wien = crate::units::RADIATION_C2 / 4.965114231744276 / t * 1e9;
        assert!((peak - wien).abs() <= 1.0, "{peak} vs {wien}");
    }

    #[test]
    fn table_matches_direct_integration() {
        let t = BlackbodyTable::new(1000.0, 20000.0);
        for k in [1500.0, 4321.0, 5800.0, 12000.0] {
            let d = (t.get(k) - blackbody_rgb(k)).abs().max_element();
            assert!(d < 2e-3, "{k}: {d}");
        }
    }

    #[test]
    fn hot_is_blue_cool_is_red() {
        let cool = blackbody_rgb(3000.0);
        let hot = blackbody_rgb(15000.0);
        assert!(cool.x > cool.z && hot.z > hot.x);
    }

    #[test]
    fn ballesteros_formula() {
        // The Sun, B-V = 0.65, comes out near 5800 K; hotter for bluer stars.
        assert!((bv_to_kelvin(0.65) - 5800.0).abs() < 150.0);
        assert!(bv_to_kelvin(0.0) > bv_to_kelvin(1.0));
        let t = 4600.0 * (1.0 / 1.7 + 1.0 / 0.62);
        assert!((bv_to_kelvin(0.0) - t).abs() < 1e-9);
    }
}
