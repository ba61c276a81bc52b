//! From the linear film to files: exposure, tone mapping, sRGB encoding, PNG
//! and EXR, each written atomically (a temporary file in the same folder,
//! renamed over the target only once complete).

use crate::config::ToneMap;
use crate::files::Batch;
use crate::film::Film;
use crate::spectrum::color::{encode_u8, luminance};
use glam::Vec3;
use std::io::BufWriter;
use std::path::Path;

/// Applies exposure (stops) and a tone curve to a linear colour; the result
/// is linear in [0, 1] per channel, ready for the sRGB curve.
#[inline]
pub fn tone_map(c: Vec3, exposure: f32, op: ToneMap) -> Vec3 {
    let c = (c * exposure.exp2()).max(Vec3::ZERO);
    match op {
        ToneMap::Clip => c.min(Vec3::ONE),
        ToneMap::Reinhard => {
            let l = luminance(c);
            if l <= 0.0 {
                return Vec3::ZERO;
            }
            (c * (1.0 / (1.0 + l))).min(Vec3::ONE)
        }
        ToneMap::Aces => {
            // Narkowicz 2015 fit of the ACES RRT+ODT, per channel.
            let f =
                |x: f32| ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
            Vec3::new(f(c.x), f(c.y), f(c.z))
        }
    }
}

/// 8-bit sRGB RGB bytes of linear XYZ pixels.
pub fn xyz_to_srgb8(xyz: &[Vec3], exposure: f64, op: ToneMap) -> Vec<u8> {
    use rayon::prelude::*;
    let e = exposure as f32;
    // In blocks over the threads (the viewer converts every frame); each
    // pixel on its own, so the bytes do not depend on the thread count.
    const BLOCK: usize = 8192;
    let mut out = vec![0u8; 3 * xyz.len()];
    out.par_chunks_mut(3 * BLOCK)
        .zip(xyz.par_chunks(BLOCK))
        .for_each(|(bytes, px)| {
            for (b, c) in bytes.chunks_exact_mut(3).zip(px) {
                let c = crate::spectrum::color::xyz_to_linear_srgb(c.as_dvec3()).as_vec3();
                let t = tone_map(c, e, op);
                b.copy_from_slice(&[encode_u8(t.x), encode_u8(t.y), encode_u8(t.z)]);
            }
        });
    out
}

/// Writes one file atomically: `write` fills a temporary beside `path`
/// (its folder made if needed), renamed over `path` only if everything
/// succeeded (see [`crate::files::Batch`] for several files at once).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let mut batch = Batch::new();
    batch.write(path, write)?;
    batch.commit()
}

/// Writes an 8-bit RGB image as a PNG, atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> anyhow::Result<()> {
    let mut batch = Batch::new();
    stage_png(&mut batch, path, width, height, rgb)?;
    batch.commit()
}

/// Writes an 8-bit RGB PNG into `batch`.
pub fn stage_png(
    batch: &mut Batch,
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
) -> anyhow::Result<()> {
    batch.write(path, |w| {
        use image::ImageEncoder;
        use image::codecs::png::{CompressionType, FilterType, PngEncoder};
        PngEncoder::new_with_quality(w, CompressionType::Default, FilterType::Adaptive)
            .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)?;
        Ok(())
    })
}

/// Writes raw pixel bytes (in the layout `color` names, 16-bit samples in
/// native byte order) as a PNG, atomically; `smallest` spends more time
/// for the smallest file (for shipped assets).
pub fn write_png_as(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
    color: image::ExtendedColorType,
    smallest: bool,
) -> anyhow::Result<()> {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let (c, f) = if smallest {
        (CompressionType::Best, FilterType::Adaptive)
    } else {
        (CompressionType::Default, FilterType::Adaptive)
    };
    write_atomic(path, |w| {
        PngEncoder::new_with_quality(w, c, f).write_image(bytes, width, height, color)?;
        Ok(())
    })
}

/// The text chunk `key` of a PNG (none when absent).
pub fn png_text(path: &Path, key: &str) -> anyhow::Result<Option<String>> {
    use anyhow::Context;
    let file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .with_context(|| format!("cannot read {}", path.display()))?;
    let info = reader.info();
    Ok(info
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == key)
        .map(|t| t.text.clone()))
}

/// Writes the film as a scene-linear float EXR, atomically: R, G, B in
/// linear sRGB (Rec.709 primaries, D65 white, stated in the `chromaticities`
/// attribute); with `xyz` also X, Y, Z; and, when the film kept spectra, one
/// channel per wavelength in the spectral layout (`spectralLayoutVersion`,
/// `emissiveUnits`). Values are relative radiance: Y = 1 is the display
/// white before exposure. `half` stores 16-bit floats (about 3 significant
/// digits, a third of the size) instead of 32-bit. The film's observables
/// follow as 32-bit channels `obs.NAME` (one layer `obs`, as compositors
/// list their AOVs).
pub fn write_exr(path: &Path, film: &Film, xyz: bool, half: bool) -> anyhow::Result<()> {
    let mut batch = Batch::new();
    stage_exr(&mut batch, path, film, xyz, half)?;
    batch.commit()
}

/// [`write_exr`] into `batch`.
pub fn stage_exr(
    batch: &mut Batch,
    path: &Path,
    film: &Film,
    xyz: bool,
    half: bool,
) -> anyhow::Result<()> {
    stage_exr_tagged(batch, path, film, xyz, half, &[])
}

/// The text [`stage_exr_tagged`] writes in the EXR's `comments` for `tags`.
fn exr_comment(tags: &[(&str, String)]) -> String {
    tags.iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The value of `key` among the tags of an EXR written with
/// [`stage_exr_tagged`] (none when absent); reads the header only.
pub fn exr_tag(path: &Path, key: &str) -> anyhow::Result<Option<String>> {
    use anyhow::Context;
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok(meta.headers.iter().find_map(|h| {
        let text = h.own_attributes.comments.as_ref()?.to_string();
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix('='))
            .map(str::to_string)
    }))
}

/// [`stage_exr`] with `tags` (an animation frame's scene hash and number)
/// in the layer's `comments` attribute, one `key=value` a line: a standard
/// attribute, so the file's bytes stay the same from run to run.
fn stage_exr_tagged(
    batch: &mut Batch,
    path: &Path,
    film: &Film,
    xyz: bool,
    half: bool,
    tags: &[(&str, String)],
) -> anyhow::Result<()> {
    use exr::meta::attribute::{AttributeValue, Chromaticities, Text};
    use exr::prelude::*;
    let rgb = film.linear_srgb();
    let plane = |f: &dyn Fn(usize) -> f32| {
        if half {
            FlatSamples::F16((0..rgb.len()).map(|i| f16::from_f32(f(i))).collect())
        } else {
            FlatSamples::F32((0..rgb.len()).map(f).collect())
        }
    };
    let mut channels: Vec<AnyChannel<FlatSamples>> = vec![
        AnyChannel::new("R", plane(&|i| rgb[i].x)),
        AnyChannel::new("G", plane(&|i| rgb[i].y)),
        AnyChannel::new("B", plane(&|i| rgb[i].z)),
    ];
    if xyz {
        channels.push(AnyChannel::new("X", plane(&|i| film.xyz[i].x)));
        channels.push(AnyChannel::new("Y", plane(&|i| film.xyz[i].y)));
        channels.push(AnyChannel::new("Z", plane(&|i| film.xyz[i].z)));
    }
    if let Some(spectra) = &film.spectra {
        let names = film.channel_names();
        let n = names.len();
        for (k, name) in names.iter().enumerate() {
            // Janskys in full precision: a flux map's range is wide.
            channels.push(AnyChannel::new(
                name.as_str(),
                if film.frequencies.is_empty() {
                    plane(&|i| spectra[i * n + k])
                } else {
                    FlatSamples::F32((0..rgb.len()).map(|i| spectra[i * n + k]).collect())
                },
            ));
        }
    }
    // The observables in full precision whatever `half` says: a radius or
    // a time in 16 bits keeps three digits.
    for (o, values) in &film.observables {
        channels.push(AnyChannel::new(
            o.channel().as_str(),
            FlatSamples::F32(values.clone()),
        ));
    }
    // exr keeps extra attributes in hash maps, written in their (random)
    // order: one in the layer's and one in the image's keeps the bytes of
    // a file the same from run to run.
    let mut layer_attributes = LayerAttributes::default();
    if !tags.is_empty() {
        layer_attributes.comments = Some(Text::from(exr_comment(tags).as_str()));
    }
    if film.spectra.is_some() && film.frequencies.is_empty() {
        layer_attributes.other.insert(
            Text::from("emissiveUnits"),
            AttributeValue::Text(Text::from("W.m^-2.sr^-1")),
        );
    }
    let layer = Layer::new(
        (film.width as usize, film.height as usize),
        layer_attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut image = Image::from_layer(layer);
    image.attributes.chromaticities = Some(Chromaticities {
        red: Vec2(0.64, 0.33),
        green: Vec2(0.30, 0.60),
        blue: Vec2(0.15, 0.06),
        white: Vec2(0.3127, 0.3290),
    });
    if film.spectra.is_some() && film.frequencies.is_empty() {
        image.attributes.other.insert(
            Text::from("spectralLayoutVersion"),
            AttributeValue::Text(Text::from("1.0")),
        );
    }
    batch.write(path, |w| {
        // exr needs Seek; the BufWriter's file handle has it.
        image.write().non_parallel().to_buffered(w)?;
        Ok(())
    })
}

/// The film as shown: bloomed when the scene's `[bloom]` asks (by the
/// device that rendered it, where it did).
pub fn displayed<'a>(
    cfg: &crate::config::SceneConfig,
    film: &'a Film,
) -> std::borrow::Cow<'a, [Vec3]> {
    match &cfg.bloom {
        Some(_) if film.bloomed.is_some() => film.bloomed.as_deref().expect("bloomed").into(),
        Some(b) => crate::post::bloom(film, &crate::post::bloom_terms(b)).into(),
        // The film itself, not a copy (the viewer shows one every frame).
        None => film.xyz.as_slice().into(),
    }
}

/// The 8-bit sRGB picture of `shown` as the scene shows it: false colour
/// for an observed scene, else its light exposed, tone-mapped and encoded.
pub fn picture(cfg: &crate::config::SceneConfig, shown: &[Vec3]) -> Vec<u8> {
    match crate::colormap::RadioLook::of(cfg) {
        Some(look) => look.encode(shown),
        None => xyz_to_srgb8(shown, cfg.image.exposure, cfg.image.tonemap),
    }
}

/// Writes a rendered film as the scene's outputs do, both files or
/// neither: the PNG (bloom, then exposure and tone curve) and, when `exr`
/// is given, the EXR (bloomed only with `bloom.exr`).
pub fn write_film(
    cfg: &crate::config::SceneConfig,
    film: &Film,
    png: &Path,
    exr: Option<&Path>,
) -> anyhow::Result<()> {
    let mut batch = Batch::new();
    stage_film(&mut batch, cfg, film, png, exr, &[])?;
    batch.commit()
}

/// [`write_film`] into `batch`, with `tags` (an animation frame's scene
/// hash and number) as text chunks of the PNG and in the EXR's comments.
pub fn stage_film(
    batch: &mut Batch,
    cfg: &crate::config::SceneConfig,
    film: &Film,
    png: &Path,
    exr: Option<&Path>,
    tags: &[(&str, String)],
) -> anyhow::Result<()> {
    let shown = displayed(cfg, film);
    let rgb = picture(cfg, &shown);
    stage_shown(batch, cfg, film, &shown, &rgb, png, exr, tags)
}

/// The PNG's pixels of a picture `rgb` (`w` x `h`): an observed scene's
/// with its colour bar beside it where the scene asks for one.
pub fn png_canvas<'a>(
    cfg: &crate::config::SceneConfig,
    w: u32,
    h: u32,
    rgb: &'a [u8],
) -> (u32, u32, std::borrow::Cow<'a, [u8]>) {
    match crate::colormap::RadioLook::of(cfg).filter(|look| look.bar) {
        Some(look) => {
            let c = look.with_bar(w as usize, h as usize, rgb);
            (c.width as u32, c.height as u32, c.rgb.into())
        }
        None => (w, h, rgb.into()),
    }
}

/// [`stage_film`] of a film already shown (`shown`, bloomed if the scene
/// asks) and encoded (`rgb`, its 8-bit sRGB bytes): for `compare`, which
/// keeps both.
#[allow(clippy::too_many_arguments)]
pub fn stage_shown(
    batch: &mut Batch,
    cfg: &crate::config::SceneConfig,
    film: &Film,
    shown: &[Vec3],
    rgb: &[u8],
    png: &Path,
    exr: Option<&Path>,
    tags: &[(&str, String)],
) -> anyhow::Result<()> {
    let (width, height, rgb) = png_canvas(cfg, film.width, film.height, rgb);
    if tags.is_empty() {
        stage_png(batch, png, width, height, &rgb)?;
    } else {
        batch.write(png, |w| {
            let mut enc = png::Encoder::new(w, width, height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_filter(png::Filter::Adaptive);
            for (k, v) in tags {
                enc.add_text_chunk(k.to_string(), v.clone())?;
            }
            enc.write_header()?.write_image_data(&rgb)?;
            Ok(())
        })?;
    }
    if let Some(exr) = exr {
        stage_scene_exr(batch, exr, cfg, (film, shown), tags)?;
    }
    Ok(())
}

/// The EXR of `film` as the scene `cfg` asks (`image.exr_xyz`,
/// `exr_half`, bloomed with `bloom.exr`), with `tags` and, for an observed
/// scene, where it lies on the sky ([`SkyFrame::exr_tags`]) in its
/// comments.
///
/// [`SkyFrame::exr_tags`]: crate::transfer::sky::SkyFrame::exr_tags
pub fn stage_scene_exr(
    batch: &mut Batch,
    path: &Path,
    cfg: &crate::config::SceneConfig,
    (film, shown): (&Film, &[Vec3]),
    tags: &[(&str, String)],
) -> anyhow::Result<()> {
    let img = &cfg.image;
    let film = exr_film(cfg, film, shown);
    let mut tags = tags.to_vec();
    if let Some(sky) = crate::transfer::sky::SkyFrame::of(cfg) {
        tags.extend(sky.exr_tags());
    }
    if let Some(crate::config::MediumConfig::Grmhd(g)) = &cfg.medium {
        // The mass unit rendered with (fitted, where medium.flux asked).
        tags.push((
            "medium.dump",
            match (&g.dump, &g.torus) {
                (Some(p), _) => p.display().to_string(),
                (None, Some(t)) => format!(
                    "torus {} {}{}",
                    t.metric,
                    t.grid,
                    if t.funnel { " funnel" } else { "" }
                ),
                _ => String::new(),
            },
        ));
        tags.push(("medium.m_unit", format!("{:e}", g.m_unit)));
    }
    stage_exr_tagged(batch, path, &film, img.exr_xyz, img.exr_half, &tags)
}

/// The film the EXR holds: bloomed (`shown`) with `bloom.exr`, else the
/// film itself.
pub fn exr_film<'a>(
    cfg: &crate::config::SceneConfig,
    film: &'a Film,
    shown: &[Vec3],
) -> std::borrow::Cow<'a, Film> {
    if cfg.bloom.as_ref().is_some_and(|b| b.exr) {
        std::borrow::Cow::Owned(Film {
            xyz: shown.to_vec(),
            bloomed: None,
            ..film.clone()
        })
    } else {
        std::borrow::Cow::Borrowed(film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_keeps_in_range_values() {
        let c = Vec3::new(0.2, 0.5, 0.9);
        assert_eq!(tone_map(c, 0.0, ToneMap::Clip), c);
        assert_eq!(tone_map(Vec3::splat(3.0), 0.0, ToneMap::Clip), Vec3::ONE);
        assert_eq!(tone_map(c, 1.0, ToneMap::Clip), (c * 2.0).min(Vec3::ONE));
    }

    #[test]
    fn reinhard_keeps_hue_and_compresses() {
        let c = Vec3::new(0.4, 0.2, 0.1);
        let t = tone_map(c, 0.0, ToneMap::Reinhard);
        let l = luminance(c);
        assert!((t - c / (1.0 + l)).length() < 1e-7);
        assert!((t.x / t.y - 2.0).abs() < 1e-6);
    }

    #[test]
    fn aces_is_monotonic_and_bounded() {
        let mut last = -1.0;
        for i in 0..100 {
            let x = i as f32 * 0.2;
            let y = tone_map(Vec3::splat(x), 0.0, ToneMap::Aces).x;
            assert!(y >= last && y <= 1.0);
            last = y;
        }
    }

    #[test]
    fn flux_channel_names_give_the_frequency_in_ghz() {
        assert_eq!(crate::film::flux_channel_name(230e9), "jy.230GHz");
        assert_eq!(crate::film::flux_channel_name(345.5e9), "jy.345,5GHz");
        assert_eq!(crate::film::flux_channel_name(86e9), "jy.86GHz");
    }

    #[test]
    fn spectral_channel_names_follow_the_layout() {
        assert_eq!(crate::film::spectral_channel_name(550.0), "S0.550,000000nm");
        assert_eq!(crate::film::spectral_channel_name(382.5), "S0.382,500000nm");
    }

    #[test]
    fn failed_write_leaves_no_file() {
        use std::io::Write;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.png");
        let r = write_atomic(&target, |w| {
            w.write_all(b"partial")?;
            anyhow::bail!("interrupted")
        });
        assert!(r.is_err());
        assert!(!target.exists());
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "temporary removed"
        );
    }
}
