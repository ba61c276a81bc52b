//! `[sky]`: one of a panorama, a uniform colour, a blackbody or the star
//! catalogue, checked and loaded.

use super::super::{SceneError, invalid, load_texture};
use crate::config::{Filter, SceneConfig, SkyConfig};
use crate::sky::Sky;
use crate::spectrum::uplift::uplift;
use crate::spectrum::{BlackbodyTable, blackbody_rgb};
use crate::starmap::{StarMap, parse_catalogue};
use crate::stars::{PointStar, StarField};
use glam::Vec3;
use std::path::Path;

/// The sky; `spectral` when the render is spectral (a uniform colour is
/// then uplifted).
pub(super) fn sky(config: &SceneConfig, spectral: bool) -> Result<Sky, SceneError> {
    let s = &config.sky;
    if !(s.intensity.is_finite() && s.intensity >= 0.0) {
        return Err(invalid(
            "sky.intensity",
            s.intensity,
            "expected a finite number >= 0",
        ));
    }
    let k = s.intensity as f32;
    Ok(match (&s.texture, s.color, s.blackbody, &s.stars) {
        (Some(path), None, None, None) => {
            let mut texture = load_texture("sky.texture", path)?;
            // The sky has nothing behind it: alpha means nothing there.
            texture.make_opaque();
            if !crate::texture::is_panorama(texture.width, texture.height) {
                return Err(invalid(
                    "sky.texture",
                    path,
                    &format!(
                        "is {} x {}; an equirectangular panorama must be twice as wide as high (to 2%)",
                        texture.width, texture.height
                    ),
                ));
            }
            Sky::Panorama {
                texture,
                filter: s.filter,
                intensity: k,
            }
        }
        (None, Some(c), None, None) => {
            if !c.iter().all(|x| x.is_finite() && *x >= 0.0) {
                return Err(invalid(
                    "sky.color",
                    c,
                    "expected three finite linear values >= 0",
                ));
            }
            let rgb = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * k;
            Sky::Uniform {
                rgb,
                spectrum: spectral.then(|| uplift(rgb)),
            }
        }
        // Observed in physical units any temperature shines (the cosmic
        // microwave background's 2.7255 K); a visible-band render's colour
        // table spans 100 K to 1e6 K.
        (None, None, Some(t), None) if config.observe.is_some() => {
            if !(t.is_finite() && t > 0.0) {
                return Err(invalid("sky.blackbody", t, "a temperature > 0 (K)"));
            }
            Sky::Blackbody {
                kelvin: t,
                intensity: k,
                rgb: Vec3::ZERO,
            }
        }
        (None, None, Some(t), None) => {
            if !(t.is_finite() && (100.0..=1e6).contains(&t)) {
                return Err(invalid(
                    "sky.blackbody",
                    t,
                    "expected a temperature of 100 to 1e6 K",
                ));
            }
            Sky::Blackbody {
                kelvin: t,
                intensity: k,
                rgb: blackbody_rgb(t) * k,
            }
        }
        (None, None, None, Some(path)) => stars(s, path, k)?,
        _ => {
            let set: Vec<&str> = [
                s.texture.as_ref().map(|_| "texture"),
                s.color.map(|_| "color"),
                s.blackbody.map(|_| "blackbody"),
                s.stars.as_ref().map(|_| "stars"),
            ]
            .into_iter()
            .flatten()
            .collect();
            let keys: Vec<String> = set.iter().map(|k| format!("sky.{k}")).collect();
            return Err(SceneError::Keys(if keys.is_empty() {
                "[sky] gives no sky: give exactly one of sky.texture, sky.color, sky.blackbody, sky.stars".into()
            } else {
                format!(
                    "[sky] gives {}: give exactly one of sky.texture, sky.color, sky.blackbody, sky.stars",
                    keys.join(" and ")
                )
            }));
        }
    })
}

/// The star catalogue's sky, its map built at `sky.resolution`.
fn stars(s: &SkyConfig, path: &Path, k: f32) -> Result<Sky, SceneError> {
    if !(2..=65_536).contains(&s.resolution) || !s.resolution.is_multiple_of(2) {
        return Err(invalid(
            "sky.resolution",
            s.resolution,
            "expected an even width of 2 to 65536 texels",
        ));
    }
    let text = crate::inputs::read_to_string(path).map_err(|e| {
        invalid(
            "sky.stars",
            path,
            &format!("cannot read the star catalogue: {e}"),
        )
    })?;
    let stars = parse_catalogue(&text).map_err(|e| invalid("sky.stars", path, &e))?;
    // The footprint filter draws the stars as points: the map keeps the
    // Milky Way alone.
    let points = (s.filter == Filter::Footprint).then(|| {
        let field = StarField::build(stars.iter().map(PointStar::from_star).collect());
        std::sync::Arc::new(field)
    });
    let splatted: &[_] = if points.is_some() { &[] } else { &stars };
    Ok(Sky::Stars {
        map: StarMap::build(splatted, s.resolution, s.milky_way),
        points,
        filter: s.filter,
        intensity: k,
        colours: BlackbodyTable::new(500.0, 60000.0),
    })
}
