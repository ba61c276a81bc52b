//! `relens`: any equirectangular panorama through a rendered lens map
//! (`blackhole::relens`).

use crate::RelensArgs;
use anyhow::{Result, bail};
use blackhole::files::{Batch, Plan};
use blackhole::relens::{LensMap, relens as relens_map};
use blackhole::texture::Texture;
use glam::Vec4;
use std::path::Path;
use std::time::Instant;

/// The output's format, from its extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Png,
    Exr,
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("exr") => Ok(Format::Exr),
        _ => bail!(
            "{}: expected an output file name ending in .png or .exr",
            path.display()
        ),
    }
}

/// The panorama as the renderer's sky reads it: opaque, twice as wide as
/// high.
fn load_panorama(path: &Path) -> Result<Texture> {
    let mut t = Texture::load(path)
        .map_err(|e| anyhow::anyhow!("cannot read panorama {}: {e}", path.display()))?;
    if !blackhole::texture::is_panorama(t.width, t.height) {
        bail!(
            "panorama {} is {} x {}; an equirectangular panorama must be twice as wide as high (to 2%)",
            path.display(),
            t.width,
            t.height
        );
    }
    t.make_opaque();
    Ok(t)
}

/// Checks the files, reads both inputs, filters and writes OUT atomically.
pub fn relens(args: &RelensArgs) -> Result<()> {
    let start = Instant::now();
    let format = format_of(&args.out)?;
    let mut plan = Plan::new();
    plan.input("lens map", &args.exr);
    plan.input("panorama", &args.panorama);
    plan.output("output", &args.out);
    plan.check()?;
    // Before anything is read: a 16k panorama decodes into gigabytes.
    blackhole::memory::relens(&args.exr, &args.panorama, format == Format::Exr)
        .check("relens")
        .map_err(anyhow::Error::msg)?;
    let map = LensMap::read_exr(&args.exr)?;
    let panorama = load_panorama(&args.panorama)?;
    let pixels = relens_map(&map, &panorama);
    let (w, h) = (map.width, map.height);
    let mut batch = Batch::new();
    match format {
        Format::Png => {
            // Over black, as a render's PNG before its exposure and tone
            // curve (the panorama's linear values, encoded to sRGB).
            let rgb: Vec<u8> = pixels
                .iter()
                .flat_map(|p| {
                    let e = blackhole::spectrum::color::encode_u8;
                    [e(p.x), e(p.y), e(p.z)]
                })
                .collect();
            blackhole::output::stage_png(&mut batch, &args.out, w, h, &rgb)?;
        }
        Format::Exr => stage_rgba_exr(&mut batch, &args.out, w, h, &pixels)?,
    }
    batch.commit()?;
    if !args.quiet {
        let escaped = map.sky.iter().filter(|d| d.is_finite()).count();
        eprintln!(
            "relensed {} through {} ({w} x {h}, {escaped} pixels on the sky) in {:.2} s; wrote {}",
            args.panorama.display(),
            args.exr.display(),
            start.elapsed().as_secs_f64(),
            args.out.display()
        );
    }
    Ok(())
}

/// Premultiplied linear RGBA as a 32-bit float EXR (alpha 0 where the ray
/// did not escape: the relensed sky composites under a render).
fn stage_rgba_exr(batch: &mut Batch, path: &Path, w: u32, h: u32, px: &[Vec4]) -> Result<()> {
    use exr::prelude::*;
    let plane = |c: usize| FlatSamples::F32(px.iter().map(|p| p[c]).collect());
    let channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B", "A"]
        .iter()
        .enumerate()
        .map(|(c, name)| AnyChannel::new(*name, plane(c)))
        .collect();
    let layer = Layer::new(
        (w as usize, h as usize),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    batch.write(path, |out| {
        image.write().non_parallel().to_buffered(out)?;
        Ok(())
    })
}
