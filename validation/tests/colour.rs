//! The colour pipeline (spectrum -> XYZ -> linear sRGB -> encoded sRGB)
//! against colour-science, through reference data that
//! validation/colour_reference.py generates (blackbodies 1000-40000 K, the
//! 24 ColorChecker patches under D65, monochromatic lines, random spectra).
//! Target: XYZ relative error <= 1e-6 on the same grid.

use blackhole::spectrum::color::{srgb_encode, xyz_to_linear_srgb};
use blackhole::spectrum::sampled::Wavelengths;
use std::collections::HashMap;
use std::path::Path;

fn read(name: &str) -> (Vec<String>, HashMap<String, Vec<f64>>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("validation/reference")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            let mut f = l.split(',');
            let id = f.next().unwrap().to_string();
            (id, f.map(|v| v.parse().unwrap()).collect())
        })
        .collect();
    (header, rows)
}

#[test]
fn spectra_to_xyz_and_srgb_match_colour_science() {
    let (header, spectra) = read("spectra.csv");
    let (_, expected) = read("expected.csv");
    assert_eq!(header.len(), 82, "380-780 nm at 5 nm");
    assert_eq!(spectra.len(), 75);
    let wl = Wavelengths::new(81);
    let (mut worst_xyz, mut worst_rgb, mut worst_enc) = (0.0f64, 0.0f64, 0.0f64);
    for (id, s) in &spectra {
        let e = &expected[id];
        let v: Vec<f32> = s.iter().map(|&x| x as f32).collect();
        let xyz = wl.xyz(&v);
        let scale = e[..3].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let rel = (0..3)
            .map(|k| (xyz[k] - e[k]).abs() / scale)
            .fold(0.0, f64::max);
        worst_xyz = worst_xyz.max(rel);
        // sRGB from our XYZ; compared relative to the colour's largest
        // component (monochromatic lines are far out of gamut).
        let rgb = xyz_to_linear_srgb(xyz);
        let rgb_scale = e[3..6].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let rel_rgb = (0..3)
            .map(|k| (rgb[k] - e[3 + k]).abs() / rgb_scale)
            .fold(0.0, f64::max);
        worst_rgb = worst_rgb.max(rel_rgb);
        let enc = (0..3)
            .map(|k| (srgb_encode(rgb[k].clamp(0.0, 1.0) as f32) as f64 - e[6 + k]).abs())
            .fold(0.0, f64::max);
        worst_enc = worst_enc.max(enc);
        assert!(
            rel <= 1e-6,
            "{id}: XYZ {xyz} vs {:?}, relative error {rel:e}",
            &e[..3]
        );
        assert!(rel_rgb <= 1e-6, "{id}: sRGB {rgb} vs {:?}", &e[3..6]);
        assert!(enc <= 1e-6, "{id}: encoded sRGB error {enc:e}");
    }
    eprintln!(
        "worst relative XYZ error {worst_xyz:.2e}, linear sRGB {worst_rgb:.2e}, encoded sRGB {worst_enc:.2e}"
    );
}
