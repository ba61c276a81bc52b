//! `[disk]`: the flat disk's radii, its texture or spectral set (or the
//! physical thin disk's light), checked and loaded.

use super::super::{SceneError, invalid, load_texture, spectral_to_rgb};
use crate::config::{DiskEmission, SceneConfig};
use crate::disk::{Disk, DiskMaterial};
use crate::physics::Spacetime;
use crate::spectral_texture::SpectralTexture;
use crate::texture::Texture;
use glam::Vec4;
use std::path::PathBuf;

/// The flat disk, if the scene has one, around the hole of `spacetime`
/// (its radii count that spacetime's rings); `spectral` when the render is
/// spectral (the spectral set is then used as such); warnings (a texture
/// without alpha) go to `warnings`.
pub(super) fn disk(
    config: &SceneConfig,
    spectral: bool,
    spacetime: Spacetime,
    warnings: &mut Vec<String>,
) -> Result<Option<Disk>, SceneError> {
    let horizon = spacetime.horizon();
    Ok(match &config.disk {
        None => None,
        Some(d) => {
            if !(d.radius.is_finite() && d.radius > 1.0) {
                return Err(invalid(
                    "disk.radius",
                    d.radius,
                    "expected an outer radius > 1 (in r_s)",
                ));
            }
            if !(d.inner_radius >= 0.0 && d.inner_radius < d.radius) {
                return Err(invalid(
                    "disk.inner_radius",
                    d.inner_radius,
                    &format!("expected 0 <= inner_radius < radius = {}", d.radius),
                ));
            }
            if !(d.intensity.is_finite() && d.intensity >= 0.0) {
                return Err(invalid(
                    "disk.intensity",
                    d.intensity,
                    "expected a finite number >= 0",
                ));
            }
            let load_set = |path: &PathBuf| {
                SpectralTexture::load(path).map_err(|e| SceneError::Invalid {
                    key: "disk.spectrum".into(),
                    value: format!("{:?}", path),
                    expected: e.to_string(),
                })
            };
            let thin = match d.emission {
                DiskEmission::Texture => {
                    for (key, set) in [
                        ("disk.accretion_rate", d.accretion_rate.is_some()),
                        ("disk.peak_temperature", d.peak_temperature.is_some()),
                    ] {
                        if set {
                            return Err(invalid(key, "set", "only with disk.emission = \"thin\""));
                        }
                    }
                    None
                }
                DiskEmission::Thin => Some(thin_disk(d, config, spacetime)?),
            };
            let material = match (&d.texture, &d.spectrum, spectral) {
                // The thin disk's own light; a texture only modulates it.
                _ if thin.is_some() => match &d.texture {
                    Some(tex) => DiskMaterial::Rgb(load_texture("disk.texture", tex)?),
                    None => DiskMaterial::Rgb(Texture::uniform(Vec4::ONE)),
                },
                (None, None, _) => {
                    return Err(invalid(
                        "disk",
                        "no texture",
                        "expected disk.texture (RGBA image) and/or disk.spectrum (spectral set manifest)",
                    ));
                }
                (_, Some(set), true) => DiskMaterial::Spectral(load_set(set)?),
                (Some(tex), _, _) => DiskMaterial::Rgb(load_texture("disk.texture", tex)?),
                (None, Some(set), false) => DiskMaterial::Rgb(spectral_to_rgb(&load_set(set)?)),
            };
            if let (DiskMaterial::Rgb(t), Some(path)) = (&material, &d.texture)
                && !t.has_alpha
            {
                warnings.push(format!(
                    "disk.texture {} has no alpha channel: the disk is opaque everywhere from r = {} r_s ({}) to disk.radius = {} r_s",
                    path.display(),
                    short(d.inner_radius.max(horizon)),
                    if d.inner_radius > horizon {
                        "disk.inner_radius".to_string()
                    } else {
                        format!(
                            "the horizon; set disk.inner_radius, e.g. {} for the ISCO",
                            short(spacetime.isco())
                        )
                    },
                    d.radius
                ));
            }
            let mut disk = Disk {
                // Nothing is seen inside the horizon; a thin disk
                // begins at its inner edge.
                inner: thin
                    .as_ref()
                    .map_or(d.inner_radius.max(horizon), |t| t.inner),
                spacetime,
                thin,
                outer: d.radius,
                material,
                filter: d.filter,
                alpha: d.alpha,
                intensity: d.intensity as f32,
                material_inner: 0.0,
            };
            disk.material_inner = disk.material_radii().0;
            Some(disk)
        }
    })
}

/// The thin disk `[disk]` describes (`emission = "thin"`), its keys checked.
fn thin_disk(
    d: &crate::config::DiskConfig,
    config: &SceneConfig,
    spacetime: Spacetime,
) -> Result<crate::thin_disk::ThinDisk, SceneError> {
    use crate::thin_disk::{Profile, ThinDisk};
    let profile = match config.physics.model {
        crate::config::ModelKind::Gr => Profile::NovikovThorne,
        crate::config::ModelKind::Seed => Profile::ShakuraSunyaev,
    };
    if d.spectrum.is_some() {
        return Err(invalid(
            "disk.spectrum",
            "set",
            "nothing with disk.emission = \"thin\", whose light is a blackbody (a disk.texture may modulate it)",
        ));
    }
    let isco = spacetime.isco();
    let inner = if d.inner_radius == 0.0 {
        isco
    } else {
        d.inner_radius
    };
    if !(inner > spacetime.horizon()) {
        return Err(invalid(
            "disk.inner_radius",
            d.inner_radius,
            &format!(
                "an inner edge outside the horizon, > {} r_s (or 0 for the ISCO, {isco} r_s)",
                spacetime.horizon()
            ),
        ));
    }
    if profile == Profile::NovikovThorne && inner < isco {
        return Err(invalid(
            "disk.inner_radius",
            d.inner_radius,
            &format!(
                "at least {isco} r_s (the ISCO) for a thin disk under physics.model = \"gr\": its gas has no stable circular orbits further in (0 means the ISCO)"
            ),
        ));
    }
    let spin = spacetime.spin();
    if !(d.f_col.is_finite() && d.f_col >= 1.0) {
        return Err(invalid(
            "disk.f_col",
            d.f_col,
            "a colour-correction factor >= 1 (1: a pure blackbody)",
        ));
    }
    let mass = config.black_hole.mass;
    let rate = match (d.accretion_rate, d.peak_temperature) {
        (Some(m), None) if m.is_finite() && m > 0.0 => m,
        (Some(m), None) => {
            return Err(invalid("disk.accretion_rate", m, "a rate > 0, in kg/s"));
        }
        (None, Some(t)) if t.is_finite() && t > 0.0 => {
            ThinDisk::rate_for_peak(profile, mass, inner, spin, t)
        }
        (None, Some(t)) => {
            return Err(invalid(
                "disk.peak_temperature",
                t,
                "a temperature > 0, in kelvin",
            ));
        }
        (Some(_), Some(_)) => {
            return Err(invalid(
                "disk.peak_temperature",
                "set",
                "one of disk.accretion_rate (kg/s) and disk.peak_temperature (K), not both",
            ));
        }
        (None, None) => {
            return Err(invalid(
                "disk.emission",
                "thin",
                "disk.accretion_rate (kg/s) or disk.peak_temperature (K) with it",
            ));
        }
    };
    Ok(ThinDisk::new(profile, mass, rate, inner, d.f_col).with_spin(spin))
}

/// A radius to four decimals, without trailing zeros (3, 0.7272).
fn short(r: f64) -> f64 {
    (r * 1e4).round() / 1e4
}
