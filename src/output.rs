//! From the linear film to files: exposure, tone mapping, sRGB encoding, PNG
//! and EXR, each written atomically (a temporary file in the same folder,
//! renamed over the target only once complete).

use crate::config::ToneMap;
use crate::film::Film;
use crate::spectrum::color::{encode_u8, luminance};
use glam::Vec3;
use std::io::{BufWriter, Write};
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

/// Creates `path`'s folder if needed, lets `write` fill a temporary file
/// beside it, and renames that over `path` only if everything succeeded.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    use anyhow::Context;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create folder {}", dir.display()))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{name}.");
    builder.prefix(&prefix).suffix(".tmp");
    // tempfile creates 0600 files; an image is for everyone to read.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let tmp = builder
        .tempfile_in(dir)
        .with_context(|| format!("cannot create a temporary file in {}", dir.display()))?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        write(&mut w).with_context(|| format!("cannot write {}", path.display()))?;
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    tmp.as_file()
        .sync_all()
        .with_context(|| format!("cannot write {}", path.display()))?;
    tmp.persist(path)
        .with_context(|| format!("cannot replace {}", path.display()))?;
    Ok(())
}

/// Checks, before a long render, that `path` can be written: its folder
/// exists or can be made, and a file can be created in it (then removed).
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    use anyhow::Context;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).with_context(|| {
        format!(
            "cannot create folder {} for {}",
            dir.display(),
            path.display()
        )
    })?;
    tempfile::Builder::new()
        .prefix(".blackhole-probe.")
        .tempfile_in(dir)
        .with_context(|| {
            format!(
                "cannot write {}: folder {} is not writable",
                path.display(),
                dir.display()
            )
        })?;
    if path.is_dir() {
        anyhow::bail!("cannot write {}: it is a folder", path.display());
    }
    Ok(())
}

/// Writes an 8-bit RGB image as a PNG, atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> anyhow::Result<()> {
    write_png_as(
        path,
        width,
        height,
        rgb,
        image::ExtendedColorType::Rgb8,
        false,
    )
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

/// Name of a spectral channel in the layout of Fichet et al. (2021), "An
/// OpenEXR Layout for Spectral Images": Stokes S0 (emission), the
/// wavelength with a comma for the decimal point (a dot separates layers).
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

pub fn spectral_channel_name(nm: f64) -> String {
    format!("S0.{}nm", format!("{nm:.6}").replace('.', ","))
}

/// Writes the film as a scene-linear float EXR, atomically: R, G, B in
/// linear sRGB (Rec.709 primaries, D65 white, stated in the `chromaticities`
/// attribute); with `xyz` also X, Y, Z; and, when the film kept spectra, one
/// channel per wavelength in the spectral layout (`spectralLayoutVersion`,
/// `emissiveUnits`). Values are relative radiance: Y = 1 is the display
/// white before exposure. `half` stores 16-bit floats (about 3 significant
/// digits, a third of the size) instead of 32-bit.
pub fn write_exr(path: &Path, film: &Film, xyz: bool, half: bool) -> anyhow::Result<()> {
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
        let n = film.nm.len();
        for (k, &nm) in film.nm.iter().enumerate() {
            channels.push(AnyChannel::new(
                spectral_channel_name(nm).as_str(),
                plane(&|i| spectra[i * n + k]),
            ));
        }
    }
    // exr keeps extra attributes in hash maps, written in their (random)
    // order: one in the layer's and one in the image's keeps the bytes of
    // a file the same from run to run.
    let mut layer_attributes = LayerAttributes::default();
    if film.spectra.is_some() {
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
    if film.spectra.is_some() {
        image.attributes.other.insert(
            Text::from("spectralLayoutVersion"),
            AttributeValue::Text(Text::from("1.0")),
        );
    }
    write_atomic(path, |w| {
        // exr needs Seek; the BufWriter's file handle has it.
        image.write().non_parallel().to_buffered(w)?;
        Ok(())
    })
}

/// Writes a rendered film as the scene's outputs do: the PNG (bloom, then
/// exposure and tone curve), and the EXR (bloomed only with `bloom.exr`)
/// when `exr` is given.
pub fn write_film(
    scene: &crate::scene::Scene,
    film: &Film,
    png: &Path,
    exr: Option<&Path>,
) -> anyhow::Result<()> {
    write_film_of(&scene.config, film, png, exr)
}

/// The film as shown: bloomed when the scene's `[bloom]` asks.
pub fn displayed<'a>(
    cfg: &crate::config::SceneConfig,
    film: &'a Film,
) -> std::borrow::Cow<'a, [Vec3]> {
    match &cfg.bloom {
        Some(b) => {
            crate::post::bloom(film, b.strength as f32, b.radius * film.height as f64).into()
        }
        // The film itself, not a copy (the viewer shows one every frame).
        None => film.xyz.as_slice().into(),
    }
}

/// [`write_film`] from the scene's configuration alone (what `merge`
/// has): the image settings and bloom are all the outputs depend on.
pub fn write_film_of(
    cfg: &crate::config::SceneConfig,
    film: &Film,
    png: &Path,
    exr: Option<&Path>,
) -> anyhow::Result<()> {
    write_film_tagged(cfg, film, png, exr, &[])
}

/// [`write_film_of`] with `tags` as text chunks of the PNG (an animation
/// frame's scene hash and number).
pub fn write_film_tagged(
    cfg: &crate::config::SceneConfig,
    film: &Film,
    png: &Path,
    exr: Option<&Path>,
    tags: &[(&str, String)],
) -> anyhow::Result<()> {
    let img = &cfg.image;
    let shown = displayed(cfg, film);
    let rgb = xyz_to_srgb8(&shown, img.exposure, img.tonemap);
    if tags.is_empty() {
        write_png(png, film.width, film.height, &rgb)?;
    } else {
        write_atomic(png, |w| {
            let mut enc = png::Encoder::new(w, film.width, film.height);
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
        if cfg.bloom.as_ref().is_some_and(|b| b.exr) {
            let bloomed = Film {
                xyz: shown.into_owned(),
                ..film.clone()
            };
            write_exr(exr, &bloomed, img.exr_xyz, img.exr_half)?;
        } else {
            write_exr(exr, film, img.exr_xyz, img.exr_half)?;
        }
    }
    Ok(())
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
    fn spectral_channel_names_follow_the_layout() {
        assert_eq!(spectral_channel_name(550.0), "S0.550,000000nm");
        assert_eq!(spectral_channel_name(382.5), "S0.382,500000nm");
    }

    #[test]
    fn failed_write_leaves_no_file() {
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
