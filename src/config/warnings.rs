//! Settings present in a scene file that change nothing in the scene at
//! hand, one warning line each.

use super::{ModelKind, SceneConfig};

/// Settings present in the document that change nothing in this scene,
/// one line each (for warnings).
pub(super) fn inert_settings(table: &toml::Table, c: &SceneConfig) -> Vec<String> {
    let has = |t: &str, k: &str| {
        table
            .get(t)
            .and_then(toml::Value::as_table)
            .is_some_and(|t| t.contains_key(k))
    };
    let mut out = Vec::new();
    let mut note = |key: &str, why: &str| out.push(format!("{key} does nothing: {why}"));
    match c.physics.model {
        ModelKind::Gr if has("physics", "step") => note(
            "physics.step",
            "it is the seed model's step; physics.model = \"gr\" uses physics.tolerance",
        ),
        ModelKind::Seed if has("physics", "tolerance") => note(
            "physics.tolerance",
            "it is the gr model's error control; physics.model = \"seed\" uses physics.step",
        ),
        _ => {}
    }
    if c.image.exr.is_none() {
        for k in ["exr_xyz", "exr_half"] {
            if has("image", k) {
                note(&format!("image.{k}"), "no image.exr is written");
            }
        }
        if has("spectral", "exr_layers") {
            note("spectral.exr_layers", "no image.exr is written");
        }
        if c.bloom.as_ref().is_some_and(|b| b.exr) {
            note("bloom.exr", "no image.exr is written");
        }
    }
    if c.observe.is_none() {
        for k in ["colormap", "scale", "decades", "colorbar"] {
            if has("image", k) {
                note(
                    &format!("image.{k}"),
                    "false colour is for observed scenes ([observe]); this one shows its light",
                );
            }
        }
    } else if has("image", "decades") && c.image.scale != super::ValueScale::Log {
        note("image.decades", "image.scale is not \"log\"");
    }
    if !c.spectral.enabled {
        for k in [
            "wavelengths",
            "shift",
            "beaming",
            "doppler",
            "interpolation",
            "per_wavelength",
            "exr_layers",
        ] {
            if has("spectral", k) {
                note(
                    &format!("spectral.{k}"),
                    "spectral.enabled is not true (an RGB render)",
                );
            }
        }
        if c.bloom.as_ref().is_some_and(|b| b.spectral) {
            note(
                "bloom.spectral",
                "spectral.enabled is not true (an RGB render)",
            );
        }
    }
    if c.sky.stars.is_none() {
        for k in ["milky_way", "resolution"] {
            if has("sky", k) {
                note(&format!("sky.{k}"), "it applies to sky.stars only");
            }
        }
    }
    if (c.sky.color.is_some() || c.sky.blackbody.is_some()) && has("sky", "filter") {
        note("sky.filter", "a uniform sky has nothing to filter");
    }
    let objects = table.get("object").and_then(toml::Value::as_array);
    for (i, o) in objects.into_iter().flatten().enumerate() {
        let material = o.get("material").and_then(toml::Value::as_table);
        if material.is_some_and(|m| m.contains_key("filter") && !m.contains_key("texture")) {
            note(
                &format!("object.{i}.material.filter"),
                "the material has no texture to filter",
            );
        }
    }
    let lights = table.get("light").and_then(toml::Value::as_array);
    for (i, light) in lights.into_iter().flatten().enumerate() {
        let kind = light.get("kind").and_then(toml::Value::as_str);
        if kind == Some("disk") && light.get("color").is_some() {
            note(
                &format!("light.{i}.color"),
                "a disk light shines in the disk's own colours",
            );
        }
    }
    out
}

/// Bare numbers of `[observe]` that read as another unit was meant (230
/// for 230 GHz, 8.178 for 8.178 kpc), one line each: a bare frequency is
/// in Hz and a bare distance in parsecs.
pub(super) fn implausible_units(c: &SceneConfig) -> Vec<String> {
    use super::quantity::{distance_text, frequency_text};
    let Some(o) = &c.observe else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for f in o.frequency.each() {
        if f.bare && f.hz > 0.0 && f.hz < 1e6 {
            out.push(format!(
                "observe.frequency = {}: a bare number is in Hz, and {} is below 1 MHz, where no telescope observes; write the unit (\"{} GHz\" if gigahertz were meant)",
                f.hz,
                frequency_text(f.hz),
                f.hz
            ));
        }
    }
    // The nearest supermassive hole (1e5 solar masses or more), Sgr A*,
    // is 8.2 kpc away: one within a kiloparsec is a unit slip.
    let suns = c.black_hole.mass / crate::units::SOLAR_MASS;
    if o.distance.bare && o.distance.pc > 0.0 && o.distance.pc < 1e3 && suns >= 1e5 {
        out.push(format!(
            "observe.distance = {}: a bare number is in parsecs, and {} is nearer than any hole of {:.3e} solar masses (the nearest supermassive one, Sgr A*, is 8.2 kpc away); write the unit (\"{} kpc\" if kiloparsecs were meant)",
            o.distance.pc,
            distance_text(o.distance.pc),
            suns,
            o.distance.pc
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disk_lights_colour_is_named_inert_and_an_ambient_ones_is_not() {
        let text = r#"
            [image]
            width = 8
            height = 8
            png = "out.png"
            [camera]
            position = [0.0, -1e11, 0.0]
            look_at = [0.0, 0.0, 0.0]
            fov = 50.0
            [black_hole]
            mass = 8.57e36
            [sky]
            color = [1.0, 1.0, 1.0]
            [[light]]
            kind = "ambient"
            color = [0.1, 0.1, 0.1]
            [[light]]
            kind = "disk"
            color = [1.0, 0.0, 0.0]
        "#;
        let table: toml::Table = toml::from_str(text).unwrap();
        let config: SceneConfig = toml::from_str(text).unwrap();
        assert_eq!(
            inert_settings(&table, &config),
            ["light.1.color does nothing: a disk light shines in the disk's own colours"]
        );
    }

    #[test]
    fn an_object_filter_without_a_texture_is_named_inert() {
        let text = r#"
            [image]
            width = 8
            height = 8
            png = "out.png"
            [camera]
            position = [0.0, -1e11, 0.0]
            look_at = [0.0, 0.0, 0.0]
            fov = 50.0
            [black_hole]
            mass = 8.57e36
            [sky]
            color = [1.0, 1.0, 1.0]
            [[object]]
            kind = "sphere"
            center = [0.0, 5e10, 0.0]
            radius = 1e10
            material = { kind = "color", filter = "footprint" }
            [[object]]
            kind = "sphere"
            center = [0.0, -5e10, 0.0]
            radius = 1e10
            material = { kind = "color", texture = "moon.png", filter = "footprint" }
        "#;
        let table: toml::Table = toml::from_str(text).unwrap();
        let config: SceneConfig = toml::from_str(text).unwrap();
        assert_eq!(
            inert_settings(&table, &config),
            ["object.0.material.filter does nothing: the material has no texture to filter"]
        );
    }
}
