//! XYZ, linear sRGB (D65) and the sRGB transfer curve.

use glam::{DVec3, Vec3};

/// XYZ -> linear sRGB, the IEC 61966-2-1 matrix as published (4 decimals),
/// which is what colour-science uses.
pub fn xyz_to_linear_srgb(xyz: DVec3) -> DVec3 {
    DVec3::new(
        3.2406 * xyz.x - 1.5372 * xyz.y - 0.4986 * xyz.z,
        -0.9689 * xyz.x + 1.8758 * xyz.y + 0.0415 * xyz.z,
        0.0557 * xyz.x - 0.2040 * xyz.y + 1.0570 * xyz.z,
    )
}

/// Linear sRGB -> XYZ, the exact inverse of [`xyz_to_linear_srgb`].
pub fn linear_srgb_to_xyz(rgb: DVec3) -> DVec3 {
    *SRGB_TO_XYZ * rgb
}

/// The matrix of [`xyz_to_linear_srgb`] (for the GPU's display).
pub fn xyz_to_linear_srgb_matrix() -> glam::DMat3 {
    glam::DMat3::from_cols_array(&[
        3.2406, -0.9689, 0.0557, -1.5372, 1.8758, -0.2040, -0.4986, 0.0415, 1.0570,
    ])
}

static SRGB_TO_XYZ: std::sync::LazyLock<glam::DMat3> =
    std::sync::LazyLock::new(|| xyz_to_linear_srgb_matrix().inverse());

/// CIE 1976 L*a*b* of `xyz` relative to the white `white`.
pub fn xyz_to_lab(xyz: DVec3, white: DVec3) -> DVec3 {
    let f = lab_f;
    let (fx, fy, fz) = (f(xyz.x / white.x), f(xyz.y / white.y), f(xyz.z / white.z));
    DVec3::new(116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz))
}

/// CIE Lab's f(t) of a ratio to white: the cube root, with its linear toe
/// near black. L* = 116 f(Y / Y_white) - 16.
pub fn lab_f(t: f64) -> f64 {
    const D: f64 = 6.0 / 29.0;
    if t > D * D * D {
        t.cbrt()
    } else {
        t / (3.0 * D * D) + 4.0 / 29.0
    }
}

/// Luminance (Y) of a linear sRGB colour.
pub fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

/// The sRGB encoding curve (linear -> non-linear), piecewise as specified.
pub fn srgb_encode(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        // In f64: 1.055 - 0.055 is 0.99999994 in f32, and white must
        // encode to exactly 1.
        (1.055 * (x as f64).powf(1.0 / 2.4) - 0.055) as f32
    }
}

/// The sRGB decoding curve (non-linear -> linear).
pub fn srgb_decode(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Encodes a linear value in [0, 1] as an 8-bit sRGB code (rounded).
pub fn encode_u8(x: f32) -> u8 {
    (srgb_encode(x.clamp(0.0, 1.0)) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_encodes_to_one() {
        assert_eq!(srgb_encode(1.0), 1.0);
        assert_eq!(encode_u8(1.0), 255);
    }

    #[test]
    fn curve_round_trips_every_8bit_code() {
        for c in 0..=255u8 {
            let lin = srgb_decode(c as f32 / 255.0);
            assert_eq!(encode_u8(lin), c);
        }
    }

    #[test]
    fn curve_is_continuous_at_the_knee() {
        let below = srgb_encode(0.003_130_8);
        let above = 1.055 * 0.003_130_8f32.powf(1.0 / 2.4) - 0.055;
        assert!((below - above).abs() < 1e-5);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(srgb_encode(0.0), 0.0);
    }

    #[test]
    fn srgb_xyz_round_trip() {
        let c = DVec3::new(0.2, 0.5, 0.9);
        assert!(
            (xyz_to_linear_srgb(linear_srgb_to_xyz(c)) - c)
                .abs()
                .max_element()
                < 1e-14
        );
    }

    #[test]
    fn lab_of_white_and_grey() {
        let w = DVec3::new(0.95047, 1.0, 1.08883);
        assert!((xyz_to_lab(w, w) - DVec3::new(100.0, 0.0, 0.0)).length() < 1e-12);
        // 18% grey: L* = 49.496...
        let l = xyz_to_lab(w * 0.18, w).x;
        assert!((l - 49.4961).abs() < 1e-3, "{l}");
    }

    #[test]
    fn white_point_maps_to_equal_rgb() {
        // D65 white (x, y) = (0.3127, 0.3290) with Y = 1 gives R = G = B = 1
        // up to the matrix's 4-decimal rounding.
        let (x, y) = (0.3127, 0.3290);
        let xyz = DVec3::new(x / y, 1.0, (1.0 - x - y) / y);
        let rgb = xyz_to_linear_srgb(xyz);
        assert!((rgb - DVec3::ONE).abs().max_element() < 2e-3, "{rgb}");
    }
}
