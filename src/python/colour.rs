//! The colour pipeline and the closed forms the tests use, on numpy
//! arrays: the renderer's own functions, for notebooks that compare them
//! with colour-science or plot them.

use super::BlackholeError;
use crate::physics::Spacetime;
use crate::spectrum::color::{srgb_encode, xyz_to_linear_srgb};
use crate::spectrum::sampled::{MAX_WAVELENGTHS, Wavelengths};
use glam::{DVec3, Vec3};
use numpy::ndarray::{Array, ArrayD, Axis, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayDyn, PyArrayLikeDyn, PyReadonlyArrayDyn};

/// Any array-like of numbers, as float64.
type Numbers<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;
use pyo3::prelude::*;

/// `a`'s last axis, which must hold `n` values (`what` names them).
fn last_axis(a: &PyReadonlyArrayDyn<'_, f64>, n: Option<usize>, what: &str) -> PyResult<usize> {
    let shape = a.as_array().shape().to_vec();
    let last = shape.last().copied().unwrap_or(0);
    match n {
        Some(n) if last != n => Err(BlackholeError::new_err(format!(
            "an array of shape {shape:?}: expected {what} along its last axis ({n} values)"
        ))),
        _ => Ok(last),
    }
}

/// `f` of each row along the last axis of `a`, each giving `out` values:
/// shape (..., out).
fn map_rows<'py>(
    py: Python<'py>,
    a: &PyReadonlyArrayDyn<'_, f64>,
    out: usize,
    f: impl Fn(&[f64]) -> Vec<f64>,
) -> Bound<'py, PyArrayDyn<f64>> {
    let view = a.as_array();
    let mut shape = view.shape().to_vec();
    let n = shape.pop().unwrap_or(0);
    let rows: Vec<f64> = view
        .to_shape((view.len() / n.max(1), n))
        .expect("a reshape of a standard layout")
        .axis_iter(Axis(0))
        .flat_map(|r| f(&r.to_vec()))
        .collect();
    shape.push(out);
    ArrayD::from_shape_vec(IxDyn(&shape), rows)
        .expect("the rows fill the shape")
        .into_pyarray(py)
}

/// The wavelengths (nm) of a spectral render of `n` samples: evenly
/// spaced from 380 to 780 nm.
#[pyfunction]
fn wavelengths(py: Python<'_>, n: i64) -> PyResult<Bound<'_, PyArrayDyn<f64>>> {
    if !(2..=MAX_WAVELENGTHS as i64).contains(&n) {
        return Err(BlackholeError::new_err(format!(
            "{n} wavelengths: expected 2 to {MAX_WAVELENGTHS}"
        )));
    }
    let n = n as usize;
    Ok(Array::from_vec(Wavelengths::new(n).nm)
        .into_dyn()
        .into_pyarray(py))
}

/// CIE 1931 XYZ of spectra (..., N) sampled at `wavelengths(N)`: the
/// renderer's quadrature of the 1 nm colour-matching functions.
#[pyfunction]
fn spectrum_to_xyz<'py>(
    py: Python<'py>,
    spectra: Numbers<'py>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let n = last_axis(&spectra, None, "spectra")?;
    if !(2..=MAX_WAVELENGTHS).contains(&n) {
        return Err(BlackholeError::new_err(format!(
            "spectra of {n} samples: expected 2 to {MAX_WAVELENGTHS} wavelengths from 380 to 780 nm along the last axis"
        )));
    }
    let wl = Wavelengths::new(n);
    Ok(map_rows(py, &spectra, 3, |s| {
        let s: Vec<f32> = s.iter().map(|&v| v as f32).collect();
        wl.xyz(&s).to_array().to_vec()
    }))
}

/// Linear sRGB (..., 3) of CIE XYZ (..., 3).
#[pyfunction]
fn xyz_to_srgb<'py>(py: Python<'py>, xyz: Numbers<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    last_axis(&xyz, Some(3), "X, Y, Z")?;
    Ok(map_rows(py, &xyz, 3, |c| {
        xyz_to_linear_srgb(DVec3::new(c[0], c[1], c[2]))
            .to_array()
            .to_vec()
    }))
}

/// The sRGB transfer curve of linear values clipped to [0, 1], any shape.
#[pyfunction]
fn srgb_encode_values<'py>(py: Python<'py>, linear: Numbers<'py>) -> Bound<'py, PyArrayDyn<f64>> {
    linear
        .as_array()
        .mapv(|x| srgb_encode(x.clamp(0.0, 1.0) as f32) as f64)
        .into_pyarray(py)
}

/// Smooth spectra (..., len(wavelengths)) of linear sRGB colours (..., 3),
/// as the renderer uplifts RGB textures: `kind` "reflectance" (a surface,
/// 1 at white) or "emission" (light: times D65, white of luminance 1).
#[pyfunction]
#[pyo3(signature = (rgb, wavelengths, kind="emission"))]
fn rgb_to_spectrum<'py>(
    py: Python<'py>,
    rgb: Numbers<'py>,
    wavelengths: Vec<f64>,
    kind: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    last_axis(&rgb, Some(3), "R, G, B")?;
    let emission = match kind {
        "emission" => true,
        "reflectance" => false,
        _ => {
            return Err(BlackholeError::new_err(format!(
                "kind {kind:?}: expected \"emission\" or \"reflectance\""
            )));
        }
    };
    if let Some(nm) = wavelengths.iter().find(|nm| !nm.is_finite() || **nm <= 0.0) {
        return Err(BlackholeError::new_err(format!(
            "wavelength {nm}: expected positive nanometres"
        )));
    }
    crate::spectrum::uplift::prepare();
    Ok(map_rows(py, &rgb, wavelengths.len(), |c| {
        let s = crate::spectrum::uplift::uplift(Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32));
        wavelengths
            .iter()
            .map(|&nm| {
                if emission {
                    s.emission(nm)
                } else {
                    s.reflectance(nm)
                }
            })
            .collect()
    }))
}

/// The spacetime of spin `a` (|a| < 1).
fn spacetime(spin: f64) -> PyResult<Spacetime> {
    if !(spin.abs() < 1.0) {
        return Err(BlackholeError::new_err(format!(
            "spin {spin}: expected -1 < a < 1"
        )));
    }
    Ok(if spin == 0.0 {
        Spacetime::Schwarzschild
    } else {
        Spacetime::Kerr { a: spin }
    })
}

/// The angular radius (degrees) of the shadow of a Schwarzschild hole seen
/// by a static camera at radius `r` (r_s).
#[pyfunction]
fn shadow_angle(r: f64) -> PyResult<f64> {
    if !(r > 1.0) || !r.is_finite() {
        return Err(BlackholeError::new_err(format!(
            "r = {r}: expected a finite radius outside the horizon (> 1 r_s)"
        )));
    }
    Ok(Spacetime::Schwarzschild
        .shadow_angle(r)
        .expect("Schwarzschild's shadow is round")
        .to_degrees())
}

/// Bardeen's shadow curve of a hole of spin `spin` seen from inclination
/// `inclination` (degrees from the spin axis) by a far camera: `n` points
/// (alpha, beta) in r_s on the image plane. Below |a| = 1e-5, where
/// Bardeen's parametrisation loses its digits (it divides by a), the
/// curve is Schwarzschild's circle of radius 3 sqrt(3) M (the spin moves
/// it by less than that); within 0.01 degrees of the axis, the circle of
/// the spherical photon orbit with L_z = 0 that an observer on the axis
/// sees.
#[pyfunction]
#[pyo3(signature = (spin, inclination, n=512))]
fn shadow_curve(spin: f64, inclination: f64, n: usize) -> PyResult<Vec<(f64, f64)>> {
    spacetime(spin)?;
    if !(0.0..=180.0).contains(&inclination) || !(8..=1_000_000).contains(&n) {
        return Err(BlackholeError::new_err(format!(
            "inclination {inclination} deg, n {n}: expected 0 to 180 degrees and 8 to 1000000 points"
        )));
    }
    let circle = |radius_m: f64| -> Vec<(f64, f64)> {
        (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                (0.5 * radius_m * t.cos(), 0.5 * radius_m * t.sin())
            })
            .collect()
    };
    if spin.abs() < 1e-5 {
        return Ok(circle(3.0 * 3f64.sqrt()));
    }
    let k = crate::physics::kerr::Kerr::new(spin);
    let i = inclination.to_radians();
    let i = i.min(std::f64::consts::PI - i);
    if i < 0.01f64.to_radians() {
        // The orbit with xi = L_z / E = 0, between the two circular ones;
        // the axis observer sees it at radius sqrt(eta + a^2).
        let (pro, retro) = (
            crate::physics::kerr::Kerr::new(spin.abs()).photon_orbit(),
            crate::physics::kerr::Kerr::new(-spin.abs()).photon_orbit(),
        );
        let xi = |r: f64| k.spherical_photon_orbit(r).0;
        let (mut lo, mut hi) = (pro, retro);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (xi(mid) > 0.0) == (xi(lo) > 0.0) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let eta = k.spherical_photon_orbit(0.5 * (lo + hi)).1;
        return Ok(circle((eta + spin * spin).sqrt()));
    }
    Ok(k.shadow_curve(i, n)
        .into_iter()
        .map(|(a, b)| (0.5 * a, 0.5 * b))
        .collect())
}

/// The total deflection (degrees) of light of impact parameter `b` (r_s)
/// passing a Schwarzschild hole from infinity to infinity (b above the
/// critical 3 sqrt(3) / 2). From b = 1e4 r_s on, where the elliptic
/// form's digits run out, the weak-field series to (M/b)^4 (its next term
/// is below 1e-16 of the sum there).
#[pyfunction]
fn deflection(b: f64) -> PyResult<f64> {
    if !(b > crate::physics::B_CRIT_GR) || !b.is_finite() {
        return Err(BlackholeError::new_err(format!(
            "b = {b}: expected a finite impact parameter above the critical {} r_s (below it the light is captured)",
            crate::physics::B_CRIT_GR
        )));
    }
    if b >= 1e4 {
        // 4M/b + 15 pi/4 (M/b)^2 + 128/3 (M/b)^3 + 3465 pi/64 (M/b)^4,
        // M = 1/2 in r_s.
        let x = 0.5 / b;
        let pi = std::f64::consts::PI;
        let rad = x * (4.0 + x * (15.0 * pi / 4.0 + x * (128.0 / 3.0 + x * 3465.0 * pi / 64.0)));
        return Ok(rad.to_degrees());
    }
    Ok(crate::physics::closed::Orbit::new(b)
        .deflection()
        .to_degrees())
}

/// The frequency ratio g = nu_observed / nu_emitted of light from the
/// thin disk's gas orbiting at radius `r` (r_s; Boyer-Lindquist with
/// spin) that reaches a static observer at `observer` (r_s; None: far
/// away) with angular momentum `lz_over_e` (r_s; 0: seen face on).
/// Without `doppler` the gas is at rest (static, or with spin the
/// locally non-rotating observer).
#[pyfunction]
#[pyo3(signature = (r, spin=0.0, lz_over_e=0.0, observer=None, doppler=true))]
fn disk_shift(
    r: f64,
    spin: f64,
    lz_over_e: f64,
    observer: Option<f64>,
    doppler: bool,
) -> PyResult<f64> {
    let st = spacetime(spin)?;
    if !(r > st.horizon()) || !r.is_finite() || !lz_over_e.is_finite() {
        return Err(BlackholeError::new_err(format!(
            "r = {r}, lz_over_e = {lz_over_e}: expected a finite radius outside the horizon ({} r_s)",
            st.horizon()
        )));
    }
    let r_o = observer.unwrap_or(f64::INFINITY);
    if !(r_o > st.horizon()) {
        return Err(BlackholeError::new_err(format!(
            "observer at {r_o}: expected a radius outside the horizon"
        )));
    }
    Ok(match st {
        Spacetime::Schwarzschild => {
            crate::physics::shift::gr_disk_ln_shift(r, lz_over_e, r_o, doppler).exp()
        }
        Spacetime::Kerr { a } => {
            if observer.is_some() {
                return Err(BlackholeError::new_err(
                    "observer: with spin the shift is for a far observer (leave observer None)",
                ));
            }
            // M units: r and L_z / E twice their r_s values.
            let k = crate::physics::kerr::Kerr::new(a);
            (-crate::physics::spacetime::kerr_emitter_ln(k, 2.0 * r, 2.0 * lz_over_e, doppler))
                .exp()
        }
    })
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(wavelengths, m)?)?;
    m.add_function(wrap_pyfunction!(spectrum_to_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(xyz_to_srgb, m)?)?;
    m.add_function(wrap_pyfunction!(srgb_encode_values, m)?)?;
    m.add_function(wrap_pyfunction!(rgb_to_spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(shadow_angle, m)?)?;
    m.add_function(wrap_pyfunction!(shadow_curve, m)?)?;
    m.add_function(wrap_pyfunction!(deflection, m)?)?;
    m.add_function(wrap_pyfunction!(disk_shift, m)?)?;
    Ok(())
}
