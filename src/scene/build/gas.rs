//! `[volume]` and `[[cloud]]`: the volumetric disk and the absorbing gas
//! clouds, checked and built.

use super::super::{SceneError, colour, finite_vec, invalid};
use crate::config::SceneConfig;
use crate::spectral::SpectralContext;
use crate::volume::{Cloud, VolumeDisk};

/// The volumetric disk, if any (`has_disk`: the scene has a flat one,
/// which it would replace).
pub(super) fn volume(
    config: &SceneConfig,
    has_disk: bool,
    spacetime: crate::physics::Spacetime,
) -> Result<Option<VolumeDisk>, SceneError> {
    Ok(match &config.volume {
        None => None,
        Some(v) => {
            if has_disk {
                return Err(invalid(
                    "volume",
                    "[volume] and [disk]",
                    "choose one: the volumetric disk replaces the flat one",
                ));
            }
            let pos = |k: &str, x: f64| {
                if x.is_finite() && x > 0.0 {
                    Ok(x)
                } else {
                    Err(invalid(
                        &format!("volume.{k}"),
                        x,
                        "expected a positive number",
                    ))
                }
            };
            let inner = pos("inner", v.inner)?;
            let outer = pos("outer", v.outer)?;
            if !(inner >= 1.0) {
                return Err(invalid(
                    "volume.inner",
                    inner,
                    "expected at least 1 (r_s): no gas inside the horizon",
                ));
            }
            if !(outer > inner) {
                return Err(invalid(
                    "volume.inner",
                    inner,
                    &format!("expected volume.inner < volume.outer = {outer} (r_s)"),
                ));
            }
            let step = pos("step", v.step)?;
            if step > 0.5 * pos("thickness", v.thickness)? {
                return Err(invalid(
                    "volume.step",
                    step,
                    "must be at most half the thickness, or the gas is skipped over",
                ));
            }
            for (key, x) in [
                ("volume.opacity", v.opacity),
                ("volume.emission", v.emission.unwrap_or(1.0)),
            ] {
                if !(x.is_finite() && x >= 0.0) {
                    return Err(invalid(key, x, "expected a finite number >= 0"));
                }
            }
            if !(v.peak_kelvin.is_finite() && (500.0..=1e6).contains(&v.peak_kelvin)) {
                return Err(invalid(
                    "volume.peak_kelvin",
                    v.peak_kelvin,
                    "expected 500 to 1e6 K",
                ));
            }
            Some(VolumeDisk::new(
                inner,
                outer,
                v.thickness,
                v.opacity,
                v.emission.unwrap_or(1.0) as f32,
                v.peak_kelvin,
                step,
                v.seed,
                crate::physics::kerr::Kerr::new(spacetime.spin()),
            ))
        }
    })
}

/// The clouds (lengths in r_s), with per-wavelength tables for a spectral
/// render's `spectral` context.
pub(super) fn clouds(
    config: &SceneConfig,
    r_s: f64,
    spectral: Option<&SpectralContext>,
) -> Result<Vec<Cloud>, SceneError> {
    config
        .clouds
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let key = |k: &str| format!("cloud[{i}].{k}");
            let center = finite_vec(&key("center"), c.center)? / r_s;
            if !(c.radius.is_finite() && c.radius > 0.0) {
                return Err(invalid(
                    &key("radius"),
                    c.radius,
                    "expected a positive radius in metres",
                ));
            }
            if !(c.depth.is_finite() && (0.0..=3.0).contains(&c.depth)) {
                return Err(invalid(
                    &key("depth"),
                    c.depth,
                    "expected 0 to 3: a cloud may dim the hole, never hide it",
                ));
            }
            if !(c.beta.is_finite() && (0.0..=4.0).contains(&c.beta)) {
                return Err(invalid(&key("beta"), c.beta, "expected 0 to 4"));
            }
            let radius = c.radius / r_s;
            if center.length() < radius + 1.0 {
                return Err(invalid(
                    &key("radius"),
                    c.radius,
                    "the cloud must not reach the hole",
                ));
            }
            let cloud = Cloud::new(
                center,
                radius,
                c.depth,
                c.beta,
                colour(&key("color"), c.color)?,
                c.seed,
            );
            // Spectral renders read per-wavelength extinction and the
            // glow's spectrum; without them a cloud would do nothing.
            Ok(match spectral {
                Some(ctx) => cloud.for_wavelengths(&ctx.wavelengths.nm),
                None => cloud,
            })
        })
        .collect()
}
