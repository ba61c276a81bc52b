//! `assets`: the shipped assets regenerated from their fixed seeds, every
//! input and the memory checked before anything is written.

use crate::{Asset, AssetArgs};
use anyhow::{Context, Result, bail};
use blackhole::assets;
use blackhole::output::write_png_as;
use std::path::{Path, PathBuf};

/// The shipped star catalogue: in the current folder's checkout, else in
/// the one this binary was built from.
fn shipped_catalogue() -> PathBuf {
    let rel = Path::new("spectral_assets/stars/hipparcos_mag8.csv");
    if rel.is_file() {
        return rel.to_path_buf();
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

pub fn generate_assets(a: AssetArgs) -> Result<()> {
    let out = a.out.as_path();
    let want = |x: Asset| a.only.is_none_or(|o| o == x);
    let (stars, nm) = checked_inputs(&a)?;
    let params = assets::disk::DiskParams {
        size: a.disk_size,
        outer: a.disk_radius,
        peak_kelvin: a.disk_kelvin,
        ..Default::default()
    };
    if want(Asset::Disk) {
        let img = assets::disk::generate(&params);
        let path = out.join("disk_rgba.png");
        write_png_as(
            &path,
            img.width(),
            img.height(),
            img.as_raw(),
            image::ExtendedColorType::Rgba8,
            true,
        )?;
        eprintln!("wrote {}", path.display());
    }
    if want(Asset::Spectral) {
        write_spectral(out, &params, a.spectral_size, &nm)?;
    }
    if want(Asset::Meshes) {
        write_meshes(out)?;
    }
    if let Some(stars) = stars {
        let p = assets::sky::SkyParams {
            width: a.sky_width,
            milky_way: !a.no_milky_way,
        };
        let img = assets::sky::generate(&stars, &p);
        let path = out.join("sky.png");
        write_png_as(
            &path,
            img.width(),
            img.height(),
            img.as_raw(),
            image::ExtendedColorType::Rgb8,
            true,
        )?;
        eprintln!("wrote {} ({} stars)", path.display(), stars.len());
    }
    Ok(())
}

/// Every input and the memory the wanted assets take checked, before
/// anything is written: the star catalogue (when the sky is wanted) and
/// the wavelengths (when the spectral disk is).
fn checked_inputs(a: &AssetArgs) -> Result<(Option<Vec<blackhole::starmap::Star>>, Vec<f64>)> {
    let want = |x: Asset| a.only.is_none_or(|o| o == x);
    if !(a.disk_radius > 3.0 && a.disk_radius.is_finite()) {
        bail!(
            "--disk-radius {}: expected a finite radius beyond 3 r_s (the ISCO)",
            a.disk_radius
        );
    }
    if !(a.disk_kelvin > 0.0 && a.disk_kelvin.is_finite()) {
        bail!(
            "--disk-kelvin {}: expected a finite temperature > 0",
            a.disk_kelvin
        );
    }
    // Sizes a texture can have, and the memory their making takes, before
    // anything is written.
    for (flag, n, most) in [
        ("--disk-size", a.disk_size, 65_536),
        ("--spectral-size", a.spectral_size, 65_536),
        ("--sky-width", a.sky_width, 65_536),
    ] {
        if n > most {
            bail!("{flag} {n}: expected at most {most} texels");
        }
    }
    // Check every input before writing anything.
    let stars = if want(Asset::Sky) {
        if a.sky_width < 2 || !a.sky_width.is_multiple_of(2) {
            bail!("--sky-width {}: expected an even number >= 2", a.sky_width);
        }
        let cat = a.catalogue.clone().unwrap_or_else(shipped_catalogue);
        let text = std::fs::read_to_string(&cat).with_context(|| {
            format!(
                "cannot read the star catalogue {} (name one with --catalogue CSV)",
                cat.display()
            )
        })?;
        Some(
            blackhole::starmap::parse_catalogue(&text)
                .map_err(|e| anyhow::anyhow!("--catalogue {}: {e}", cat.display()))?,
        )
    } else {
        None
    };
    let nm = if want(Asset::Spectral) {
        if a.spectral_size == 0 {
            bail!("--spectral-size must be >= 1");
        }
        parse_range(&a.spectral_nm)?
    } else {
        Vec::new()
    };
    if want(Asset::Disk) && a.disk_size == 0 {
        bail!("--disk-size must be >= 1");
    }
    let mut need = blackhole::memory::Need::default();
    let sq = |n: u32| n as u64 * n as u64;
    if want(Asset::Disk) {
        // The disk's texels (density, temperature, alpha) and the image.
        need.parts
            .push(("--disk-size".into(), 16 * sq(a.disk_size)));
    }
    if want(Asset::Spectral) {
        // The texels, the alpha and every wavelength's 16-bit image.
        let bytes = (13 + 2 * nm.len() as u64) * sq(a.spectral_size);
        need.parts.push(("--spectral-size".into(), bytes));
    }
    if want(Asset::Sky) {
        // The star map while it is built, and the 8-bit panorama.
        let texels = a.sky_width as u64 * (a.sky_width as u64 / 2);
        need.parts.push(("--sky-width".into(), 15 * texels));
    }
    need.check("making the assets")
        .map_err(anyhow::Error::msg)?;
    Ok((stars, nm))
}

/// The spectral disk: a 16-bit image per wavelength and their manifest.
fn write_spectral(
    out: &Path,
    params: &assets::disk::DiskParams,
    size: u32,
    nm: &[f64],
) -> Result<()> {
    let (files, manifest) = assets::disk::generate_spectral(params, size, nm);
    let dir = out.join("disk_spectral");
    for (name, img) in &files {
        let color = img.color().into();
        write_png_as(
            &dir.join(name),
            img.width(),
            img.height(),
            img.as_bytes(),
            color,
            true,
        )?;
    }
    blackhole::output::write_atomic(&dir.join("manifest.toml"), |w| {
        std::io::Write::write_all(w, manifest.as_bytes())?;
        Ok(())
    })?;
    eprintln!(
        "wrote {} ({} wavelengths)",
        dir.join("manifest.toml").display(),
        nm.len()
    );
    Ok(())
}

/// The asteroid meshes, from their fixed seeds.
fn write_meshes(out: &Path) -> Result<()> {
    let dir = out.join("meshes");
    for seed in 0..3u32 {
        let (v, f) = assets::asteroid::asteroid(seed, 4, 0.28);
        let name = format!("asteroid_{seed}.obj");
        let header =
            format!("blackhole assets: asteroid, seed {seed}, icosphere level 4, roughness 0.28");
        let text = assets::asteroid::to_obj(&v, &f, &header);
        blackhole::output::write_atomic(&dir.join(&name), |w| {
            std::io::Write::write_all(w, text.as_bytes())?;
            Ok(())
        })?;
        eprintln!(
            "wrote {} ({} triangles)",
            dir.join(&name).display(),
            f.len()
        );
    }
    Ok(())
}

/// Parses "first,last,step" (nm) into the wavelengths it spans.
fn parse_range(text: &str) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--spectral-nm {text}: expected first,last,step in nm"))?;
    match v[..] {
        [a, b, d] if a > 0.0 && b >= a && d > 0.0 && ((b - a) / d) < 10_000.0 => {
            Ok((0..=((b - a) / d + 1e-9) as usize)
                .map(|i| a + i as f64 * d)
                .collect())
        }
        _ => bail!(
            "--spectral-nm {text}: expected first,last,step with 0 < first <= last and step > 0"
        ),
    }
}
