//! `colour`: sampled spectra through the renderer's colour pipeline (for
//! checking it against colour-science).

use anyhow::{Context, Result, bail};
use std::path::Path;

pub fn colour(path: &Path) -> Result<()> {
    use blackhole::spectrum::color::{srgb_encode, xyz_to_linear_srgb};
    use blackhole::spectrum::sampled::{MAX_WAVELENGTHS, Wavelengths};
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines
        .next()
        .with_context(|| format!("{}: empty file", path.display()))?;
    let nm: Vec<f64> = header
        .split(',')
        .skip(1)
        .map(|h| h.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{}: header must be id,<nm>,<nm>,...", path.display()))?;
    let n = nm.len();
    if !(2..=MAX_WAVELENGTHS).contains(&n) {
        bail!(
            "{}: expected 2 to {MAX_WAVELENGTHS} wavelengths, found {n}",
            path.display()
        );
    }
    let wl = Wavelengths::new(n);
    if nm.iter().zip(&wl.nm).any(|(a, b)| (a - b).abs() > 1e-9) {
        bail!(
            "{}: the wavelengths must be {n} evenly spaced samples from 380 to 780 nm ({} nm apart)",
            path.display(),
            wl.step
        );
    }
    let mut out = String::from("id,X,Y,Z,R,G,B,sR,sG,sB\n");
    for (i, line) in lines {
        let mut f = line.split(',');
        let id = f.next().unwrap_or_default().trim();
        let v: Vec<f32> = f
            .map(|x| x.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .with_context(|| format!("{} line {}: expected numbers", path.display(), i + 1))?;
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            bail!(
                "{} line {}: the value at {} nm is {}: expected finite numbers",
                path.display(),
                i + 1,
                nm.get(k).copied().unwrap_or(f64::NAN),
                v[k]
            );
        }
        if v.len() != n {
            bail!(
                "{} line {}: {} values for {n} wavelengths",
                path.display(),
                i + 1,
                v.len()
            );
        }
        let xyz = wl.xyz(&v);
        let rgb = xyz_to_linear_srgb(xyz);
        let enc = rgb
            .to_array()
            .map(|c| srgb_encode(c.clamp(0.0, 1.0) as f32));
        out += &format!(
            "{id},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.9},{:.9},{:.9}\n",
            xyz.x, xyz.y, xyz.z, rgb.x, rgb.y, rgb.z, enc[0], enc[1], enc[2]
        );
    }
    print!("{out}");
    Ok(())
}
