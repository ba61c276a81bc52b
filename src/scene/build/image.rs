//! `[image]`, `[stereo]` and `[bloom]`: sizes, sampling and the outputs'
//! names, checked.

use super::super::{MAX_PIXELS, SceneError, check_output, invalid};
use crate::config::SceneConfig;

/// The config's warnings with the image's own.
pub(super) fn warnings(config: &SceneConfig) -> Vec<String> {
    let mut warnings = config.warnings.clone();
    if !config.image.adaptive()
        && let Some(n) = config.image.max_samples
    {
        warnings.push(format!(
            "image.max_samples = {n} does nothing without image.adaptive = true"
        ));
    }
    warnings
}

/// Checks the image's size, sampling, exposure and output names, the
/// stereo pair's distances and the bloom's strength and radius.
pub(super) fn check(config: &SceneConfig) -> Result<(), SceneError> {
    let img = &config.image;
    if img.width == 0 || img.width > 65_535 {
        return Err(invalid(
            "image.width",
            img.width,
            "expected 1 to 65535 pixels",
        ));
    }
    if img.height == 0 || img.height > 65_535 {
        return Err(invalid(
            "image.height",
            img.height,
            "expected 1 to 65535 pixels",
        ));
    }
    if img.samples == 0 || img.samples > 65_536 {
        return Err(invalid(
            "image.samples",
            img.samples,
            "expected 1 to 65536 rays per pixel",
        ));
    }
    if img.adaptive() {
        let max = img.max_samples();
        if max <= img.samples || max > 65_536 {
            return Err(invalid(
                "image.max_samples",
                max,
                &format!(
                    "expected more than image.samples ({}) and at most 65536 rays per pixel with image.adaptive on",
                    img.samples
                ),
            ));
        }
    }
    if !img.exposure.is_finite() {
        return Err(invalid(
            "image.exposure",
            img.exposure,
            "expected a finite number of stops",
        ));
    }
    if let Some(d) = img.decades
        && !(d.is_finite() && d > 0.0 && d <= 30.0)
    {
        return Err(invalid(
            "image.decades",
            d,
            "expected the log scale's span below white: more than 0 and at most 30 decades",
        ));
    }
    for (i, o) in img.observables.iter().enumerate() {
        if img.observables[..i].contains(o) {
            return Err(invalid(
                "image.observables",
                o.config_name(),
                "expected each observable once",
            ));
        }
    }
    check_output("image.png", &img.png, "png")?;
    if let Some(exr) = &img.exr {
        check_output("image.exr", exr, "exr")?;
    }
    if let Some(st) = &config.stereo {
        if !(st.separation.is_finite() && st.separation > 0.0) {
            return Err(invalid(
                "stereo.separation",
                st.separation,
                "expected a positive distance in metres",
            ));
        }
        if let Some(c) = st.convergence
            && !(c.is_finite() && c > 0.0)
        {
            return Err(invalid(
                "stereo.convergence",
                c,
                "expected a positive distance in metres",
            ));
        }
    }
    if let Some(b) = &config.bloom {
        if !(b.strength.is_finite() && (0.0..=1.0).contains(&b.strength)) {
            return Err(invalid("bloom.strength", b.strength, "expected 0 to 1"));
        }
        if !(b.radius.is_finite() && b.radius > 0.0 && b.radius <= 1.0) {
            return Err(invalid(
                "bloom.radius",
                b.radius,
                "expected 0 < radius <= 1 (fraction of the image height)",
            ));
        }
        if b.shape == crate::config::BloomShape::Halo && b.radius > crate::post::HALO_REACH {
            return Err(invalid(
                "bloom.radius",
                b.radius,
                &format!(
                    "expected at most {} with shape = \"halo\" (its innermost Gaussian; the widest is {} of the image height)",
                    crate::post::HALO_REACH,
                    crate::post::HALO_REACH
                ),
            ));
        }
    }
    let pixels = img.width as u64 * img.height as u64;
    if pixels > MAX_PIXELS {
        return Err(invalid(
            "image.width x image.height",
            (img.width, img.height),
            &format!("is {pixels} pixels; at most {MAX_PIXELS} (one gigapixel) are supported"),
        ));
    }
    Ok(())
}
