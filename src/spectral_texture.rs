//! Spectral texture sets: one greyscale image per wavelength plus an alpha
//! image, described by a TOML manifest.
//!
//! ```toml
//! units = "relative spectral radiance per nm; luminance 1 = ..."
//! alpha = "alpha.png"
//! [[wavelength]]
//! nm = 400.0
//! file = "disk_0400nm.png"
//! scale = 2.5e-3      # value = code / max_code * scale (PNG); value * scale (EXR)
//! ```
//!
//! Images may be 8- or 16-bit greyscale PNG (codes scaled to [0, 1], then by
//! `scale`) or EXR (values times `scale`). Wavelengths must increase
//! strictly; every image must have the alpha image's size. In memory the
//! spectra are interleaved per texel, so one lookup touches one texel's
//! values for every wavelength.

use crate::config::{Filter, Interpolation};
use crate::texture::{Footprint, ewa, mip};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use thiserror::Error;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    units: String,
    alpha: PathBuf,
    #[serde(rename = "wavelength")]
    wavelengths: Vec<Entry>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    nm: f64,
    file: PathBuf,
    #[serde(default = "one")]
    scale: f64,
}

fn one() -> f64 {
    1.0
}

/// Why a spectral texture set cannot be loaded.
#[derive(Debug, Error)]
pub enum SpectralTextureError {
    /// The manifest cannot be read.
    #[error("cannot read {path}: {cause}")]
    Read {
        /// The manifest.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// The manifest is not valid TOML or misses keys.
    #[error("{path}: {cause}")]
    Parse {
        /// The manifest.
        path: PathBuf,
        /// What and where.
        cause: toml::de::Error,
    },
    /// An image cannot be decoded.
    #[error("{path}: cannot load image: {cause}")]
    Image {
        /// The image.
        path: PathBuf,
        /// Why.
        cause: image::ImageError,
    },
    /// The content is inconsistent.
    #[error("{path}: {message}")]
    Invalid {
        /// The file at fault.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// A loaded spectral texture set.
#[derive(Clone, Debug)]
pub struct SpectralTexture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Tabulated wavelengths (nm), strictly increasing.
    pub nm: Vec<f64>,
    /// The manifest's statement of units.
    pub units: String,
    /// Values, texel-major: texel t's spectrum is `values[t * n..(t + 1) * n]`.
    values: std::sync::Arc<Vec<f32>>,
    alpha: std::sync::Arc<Vec<f32>>,
    /// (first, spacing) when the wavelengths are evenly spaced.
    uniform: Option<(f64, f64)>,
    /// Mip levels, built by the first footprint lookup that needs them;
    /// shared by clones.
    mips: Arc<OnceLock<SpectralMips>>,
}

/// Levels 1 and up of a spectral set, texel after texel as level 0 keeps
/// them: straight spectra (the alpha-weighted mean of the texels each
/// covers) and alpha (their mean).
#[derive(Debug)]
struct SpectralMips {
    values: Vec<f32>,
    alpha: Vec<f32>,
    /// Texel index (among the levels' texels) where level k starts.
    offsets: Vec<usize>,
}

/// Decodes a greyscale image to values in [0, 1] (PNG) or as stored (EXR).
fn load_grey(path: &Path) -> Result<(u32, u32, Vec<f32>), SpectralTextureError> {
    use image::DynamicImage as D;
    let mut img = crate::inputs::image_reader(path).map_err(|e| SpectralTextureError::Image {
        path: path.to_path_buf(),
        cause: e.into(),
    })?;
    img.limits(crate::texture::decode_limits());
    let img = img.decode().map_err(|cause| SpectralTextureError::Image {
        path: path.to_path_buf(),
        cause,
    })?;
    let (w, h) = (img.width(), img.height());
    let v: Vec<f32> = match img {
        D::ImageLuma8(i) => i.pixels().map(|p| p.0[0] as f32 / 255.0).collect(),
        D::ImageLumaA8(i) => i.pixels().map(|p| p.0[0] as f32 / 255.0).collect(),
        D::ImageLuma16(i) => i.pixels().map(|p| p.0[0] as f32 / 65535.0).collect(),
        D::ImageLumaA16(i) => i.pixels().map(|p| p.0[0] as f32 / 65535.0).collect(),
        D::ImageRgb32F(i) => i.pixels().map(|p| p.0[0]).collect(),
        D::ImageRgba32F(i) => i.pixels().map(|p| p.0[0]).collect(),
        _ => {
            return Err(SpectralTextureError::Invalid {
                path: path.to_path_buf(),
                message: "expected a greyscale PNG (8 or 16 bit) or an EXR".into(),
            });
        }
    };
    Ok((w, h, v))
}

impl SpectralTexture {
    /// Loads the set a manifest describes; its files are relative to the
    /// manifest's folder.
    pub fn load(manifest: &Path) -> Result<SpectralTexture, SpectralTextureError> {
        let text = crate::inputs::read_to_string(manifest).map_err(|cause| {
            SpectralTextureError::Read {
                path: manifest.to_path_buf(),
                cause,
            }
        })?;
        let m: Manifest = toml::from_str(&text).map_err(|cause| SpectralTextureError::Parse {
            path: manifest.to_path_buf(),
            cause,
        })?;
        let invalid = |message: String| SpectralTextureError::Invalid {
            path: manifest.to_path_buf(),
            message,
        };
        if m.wavelengths.is_empty() {
            return Err(invalid("lists no [[wavelength]] entries".into()));
        }
        for (i, e) in m.wavelengths.iter().enumerate() {
            if !(e.nm.is_finite() && e.nm > 0.0) {
                return Err(invalid(format!(
                    "wavelength {}: nm = {} is not a positive number",
                    i + 1,
                    e.nm
                )));
            }
            if !(e.scale.is_finite() && e.scale >= 0.0) {
                return Err(invalid(format!(
                    "wavelength {} nm: scale = {} must be finite and >= 0",
                    e.nm, e.scale
                )));
            }
            if i > 0 {
                let prev = m.wavelengths[i - 1].nm;
                if e.nm == prev {
                    return Err(invalid(format!("wavelength {} nm is listed twice", e.nm)));
                }
                if e.nm < prev {
                    return Err(invalid(format!(
                        "wavelengths must increase: {} nm comes after {} nm",
                        e.nm, prev
                    )));
                }
            }
        }
        let dir = manifest.parent().unwrap_or(Path::new(""));
        let (width, height, alpha) = load_grey(&dir.join(&m.alpha))?;
        let n = m.wavelengths.len();
        let texels = width as usize * height as usize;
        let mut values = vec![0.0f32; texels * n];
        for (k, e) in m.wavelengths.iter().enumerate() {
            let path = dir.join(&e.file);
            let (w, h, v) = load_grey(&path)?;
            if (w, h) != (width, height) {
                return Err(SpectralTextureError::Invalid {
                    path,
                    message: format!(
                        "is {w} x {h}, but the alpha image {} is {width} x {height}",
                        m.alpha.display()
                    ),
                });
            }
            let s = e.scale as f32;
            for (t, x) in v.into_iter().enumerate() {
                values[t * n + k] = x * s;
            }
        }
        let nm: Vec<f64> = m.wavelengths.iter().map(|e| e.nm).collect();
        let uniform = (n > 1).then(|| (nm[0], nm[1] - nm[0])).filter(|&(a, d)| {
            nm.iter()
                .enumerate()
                .all(|(i, &l)| (l - (a + i as f64 * d)).abs() < 1e-9 * d)
        });
        Ok(SpectralTexture {
            width,
            height,
            nm,
            units: m.units,
            values: values.into(),
            alpha: alpha.into(),
            uniform,
            mips: Arc::default(),
        })
    }

    /// Bytes held in memory: the planes, and their mip levels once a
    /// footprint lookup has built them.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.values.len() + self.alpha.len())
            + if self.mips.get().is_some() {
                self.pyramid_bytes()
            } else {
                0
            }
    }

    /// Bytes the mip levels of every plane and alpha take, built or not:
    /// at most a third of the planes'.
    pub fn pyramid_bytes(&self) -> usize {
        4 * (self.nm.len() + 1) * mip::texel_count(self.width, self.height)
    }

    /// Texels of level 0.
    #[inline]
    fn base_texels(&self) -> usize {
        self.alpha.len()
    }

    /// Builds the mip levels now rather than on the first footprint lookup
    /// that needs them.
    pub fn build_pyramid(&self) {
        self.mips();
    }

    /// The mip levels, built on first call (the planes premultiplied by
    /// alpha, area-averaged, stored straight).
    fn mips(&self) -> &SpectralMips {
        self.mips.get_or_init(|| {
            let n = self.nm.len();
            let (w, h) = (self.width, self.height);
            let row = |y: usize, buf: &mut [f32]| {
                for (x, px) in buf.chunks_exact_mut(n + 1).enumerate() {
                    let t = y * w as usize + x;
                    let a = self.alpha[t];
                    for (p, v) in px.iter_mut().zip(&self.values[t * n..(t + 1) * n]) {
                        *p = v * a;
                    }
                    px[n] = a;
                }
            };
            let count = mip::texel_count(w, h);
            let mut m = SpectralMips {
                values: Vec::with_capacity(count * n),
                alpha: Vec::with_capacity(count),
                offsets: vec![0; ewa::level_count(w, h)],
            };
            mip::build(n + 1, (w, h), &row, |k, _, level| {
                m.offsets[k] = m.alpha.len();
                for px in level.chunks_exact(n + 1) {
                    let a = px[n];
                    let inv = if a > 0.0 { 1.0 / a } else { 0.0 };
                    m.values.extend(px[..n].iter().map(|v| v * inv));
                    m.alpha.push(a);
                }
            });
            m
        })
    }

    /// Texel `t`'s spectrum (`t` from [`SpectralTexture::texels`] or
    /// [`SpectralTexture::footprint_texels`]: past level 0's texels, a mip
    /// level's).
    #[inline]
    fn spectrum(&self, t: usize) -> &[f32] {
        let n = self.nm.len();
        let base = self.base_texels();
        if t < base {
            &self.values[t * n..(t + 1) * n]
        } else {
            let m = self
                .mips
                .get()
                .expect("a mip texel comes from a footprint lookup");
            &m.values[(t - base) * n..(t - base + 1) * n]
        }
    }

    /// The texels under a pixel's footprint `fp` at (u, v) (clamped to the
    /// edge): the elliptical Gaussian average of [`ewa`], as (texel,
    /// weight) pairs whose weights sum to 1, written to `out` (cleared
    /// first; keep one per thread, a lookup reads from a few to a few
    /// hundred texels). The texels may lie in mip levels: their indices
    /// serve [`SpectralTexture::alpha`], [`SpectralTexture::value`],
    /// [`SpectralTexture::value_at`] and the blends as level 0's do.
    pub fn footprint_texels(&self, u: f64, v: f64, fp: &Footprint, out: &mut Vec<(usize, f32)>) {
        out.clear();
        let (ellipses, k) = ewa::plan(u, v, fp, self.width, self.height);
        for e in &ellipses[..k] {
            let (w, h) = ewa::level_dims(self.width, self.height, e.level);
            let offset = match e.level {
                0 => 0,
                l => self.base_texels() + self.mips().offsets[l],
            };
            let start = out.len();
            let sum = ewa::visit(e, w, h, false, |i, wt| out.push((offset + i, wt)));
            let scale = e.weight / sum;
            for p in &mut out[start..] {
                p.1 *= scale;
            }
        }
    }

    /// The texels a lookup with `filter` reads, into `out` (cleared
    /// first): [`SpectralTexture::footprint_texels`] for
    /// [`Filter::Footprint`] given a footprint, else
    /// [`SpectralTexture::texels`]'s.
    pub fn texels_into(
        &self,
        u: f64,
        v: f64,
        filter: Filter,
        footprint: Option<&Footprint>,
        out: &mut Vec<(usize, f32)>,
    ) {
        match (filter, footprint) {
            (Filter::Footprint, Some(fp)) => self.footprint_texels(u, v, fp, out),
            _ => {
                let (t, n) = self.texels(u, v, filter);
                out.clear();
                out.extend_from_slice(&t[..n]);
            }
        }
    }

    /// The coverage of weighted texels: the sum of weight times alpha.
    #[inline]
    pub fn coverage(&self, texels: &[(usize, f32)]) -> f32 {
        texels.iter().map(|&(t, w)| w * self.alpha(t)).sum()
    }

    /// Texel indices and weights for texture coordinates (u, v) (v down,
    /// clamped to the edge).
    #[inline]
    pub fn texels(&self, u: f64, v: f64, filter: Filter) -> ([(usize, f32); 4], usize) {
        let (w, h) = (self.width as usize, self.height as usize);
        let clamp = |x: f64, n: usize| (x.max(0.0) as usize).min(n - 1);
        match filter {
            Filter::Nearest => {
                let t = clamp(v * h as f64, h) * w + clamp(u * w as f64, w);
                ([(t, 1.0), (0, 0.0), (0, 0.0), (0, 0.0)], 1)
            }
            // A lookup without a footprint is a point: the footprint
            // filter's reconstruction there is bilinear's (callers that have
            // a footprint use `footprint_texels`).
            Filter::Bilinear | Filter::Footprint => {
                let fx = (u * w as f64 - 0.5).clamp(0.0, (w - 1) as f64);
                let fy = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
                let (x0, y0) = (fx as usize, fy as usize);
                let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
                let (tx, ty) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
                (
                    [
                        (y0 * w + x0, (1.0 - tx) * (1.0 - ty)),
                        (y0 * w + x1, tx * (1.0 - ty)),
                        (y1 * w + x0, (1.0 - tx) * ty),
                        (y1 * w + x1, tx * ty),
                    ],
                    4,
                )
            }
        }
    }

    /// The GPU backend's copy: every texel's values (interleaved by
    /// wavelength), then every texel's alpha, as f32 bits; and the uniform
    /// spacing (first nm, step) when the wavelengths have one.
    pub(crate) fn gpu_words(&self) -> (Vec<u32>, Option<(f64, f64)>) {
        let words = self
            .values
            .iter()
            .chain(self.alpha.iter())
            .map(|v| v.to_bits())
            .collect();
        (words, self.uniform)
    }

    /// The mip levels (built now if not yet) as the GPU backend stores
    /// them: every level's values (levels 1 and up, interleaved by
    /// wavelength as [`SpectralTexture::gpu_words`]), then their alpha.
    pub(crate) fn gpu_mip_words(&self) -> Vec<u32> {
        let m = self.mips();
        m.values
            .iter()
            .chain(&m.alpha)
            .map(|v| v.to_bits())
            .collect()
    }

    /// Alpha of a texel.
    #[inline]
    pub fn alpha(&self, texel: usize) -> f32 {
        match self.alpha.get(texel) {
            Some(&a) => a,
            None => {
                let m = self
                    .mips
                    .get()
                    .expect("a mip texel comes from a footprint lookup");
                m.alpha[texel - self.base_texels()]
            }
        }
    }

    /// Value of texel `t` at wavelength `nm`, read as `interp` says; 0 outside
    /// the tabulated range (half a spacing beyond the ends for nearest).
    #[inline]
    pub fn value(&self, t: usize, nm: f64, interp: Interpolation) -> f32 {
        match self.lookup(nm, interp) {
            Some(at) => self.value_at(t, at),
            None => 0.0,
        }
    }

    /// Where wavelength `nm` falls in the table, the same for every texel
    /// (found once per hit for all its texels): the entry and the weight
    /// of the next one; none outside the tabulated range.
    #[inline]
    pub fn lookup(&self, nm: f64, interp: Interpolation) -> Option<(usize, f32)> {
        let n = self.nm.len();
        if n == 1 {
            return (nm == self.nm[0]).then_some((0, 0.0));
        }
        // Fractional index of nm in the table.
        let f = match self.uniform {
            Some((a, d)) => (nm - a) / d,
            None => {
                let i = self.nm.partition_point(|&l| l <= nm);
                if i == 0 {
                    (nm - self.nm[0]) / (self.nm[1] - self.nm[0])
                } else if i == n {
                    (n - 1) as f64 + (nm - self.nm[n - 1]) / (self.nm[n - 1] - self.nm[n - 2])
                } else {
                    (i - 1) as f64 + (nm - self.nm[i - 1]) / (self.nm[i] - self.nm[i - 1])
                }
            }
        };
        match interp {
            Interpolation::Nearest => {
                let r = f.round();
                (r >= 0.0 && r <= (n - 1) as f64).then_some((r as usize, 0.0))
            }
            Interpolation::Linear => {
                if !(f >= 0.0 && f <= (n - 1) as f64) {
                    return None;
                }
                let i = (f as usize).min(n - 2);
                Some((i, (f - i as f64) as f32))
            }
        }
    }

    /// Adds to `out[i]`, for i in `range`, the texels' spectra weighted by
    /// `k` (each texel's weight times its scale) read at g times camera
    /// wavelength i: what
    /// summing [`SpectralTexture::value`] over the texels gives, with the
    /// texels blended once per table entry rather than once per camera
    /// wavelength (the same sum in another order).
    pub fn add_blend(
        &self,
        texels: &[(usize, f32)],
        k: &[f32],
        g: f64,
        ctx: &crate::spectral::SpectralContext,
        range: std::ops::Range<usize>,
        out: &mut [f32],
    ) {
        self.add_blend_by(texels, |q, _| k[q], g, ctx, range, out)
    }

    /// [`SpectralTexture::add_blend`] of texels weighted `k` times their
    /// weight times their alpha (premultiplied, as a disk hit blends them):
    /// for the texels of [`SpectralTexture::footprint_texels`], however
    /// many.
    pub fn add_premultiplied(
        &self,
        texels: &[(usize, f32)],
        k: f32,
        g: f64,
        ctx: &crate::spectral::SpectralContext,
        range: std::ops::Range<usize>,
        out: &mut [f32],
    ) {
        self.add_blend_by(
            texels,
            |_, (t, w)| k * w * self.alpha(t),
            g,
            ctx,
            range,
            out,
        )
    }

    /// [`SpectralTexture::add_blend`] with texel q's factor `kw(q, texel)`.
    fn add_blend_by(
        &self,
        texels: &[(usize, f32)],
        kw: impl Fn(usize, (usize, f32)) -> f32,
        g: f64,
        ctx: &crate::spectral::SpectralContext,
        range: std::ops::Range<usize>,
        out: &mut [f32],
    ) {
        let (nm, interp) = (&ctx.wavelengths.nm, ctx.interpolation);
        let n = self.nm.len();
        // The table entries the shifted wavelengths can reach.
        let first = range.clone().find_map(|i| self.lookup(g * nm[i], interp));
        let last = range
            .clone()
            .rev()
            .find_map(|i| self.lookup(g * nm[i], interp));
        let (Some((lo, _)), Some((hi, _))) = (first, last) else {
            return;
        };
        // Linear reads take the entry after each one found.
        let hi = (hi + 1).min(n - 1);
        // On the stack for sets of usual size (no allocation per hit).
        let mut stack = [0.0f32; 128];
        let mut heap = Vec::new();
        let blend: &mut [f32] = if hi + 1 - lo <= stack.len() {
            &mut stack[..hi + 1 - lo]
        } else {
            heap.resize(hi + 1 - lo, 0.0);
            &mut heap
        };
        for (q, &texel) in texels.iter().enumerate() {
            let kw = kw(q, texel);
            let s = &self.spectrum(texel.0)[lo..hi + 1];
            for (b, v) in blend.iter_mut().zip(s) {
                *b += kw * v;
            }
        }
        for i in range {
            if let Some((j, w)) = self.lookup(g * nm[i], interp) {
                let j = j - lo;
                out[i] += if w == 0.0 {
                    blend[j]
                } else {
                    blend[j] * (1.0 - w) + blend[j + 1] * w
                };
            }
        }
    }

    /// Value of texel `t` at a [`SpectralTexture::lookup`].
    #[inline]
    pub fn value_at(&self, t: usize, (i, w): (usize, f32)) -> f32 {
        let s = self.spectrum(t);
        if w == 0.0 {
            s[i]
        } else {
            s[i] * (1.0 - w) + s[i + 1] * w
        }
    }
}

/// The images a spectral set's manifest names (alpha and wavelengths),
/// for checks that look at every input file.
pub fn manifest_files(manifest: &Path) -> anyhow::Result<Vec<std::path::PathBuf>> {
    use anyhow::Context;
    let text = crate::inputs::read_to_string(manifest)
        .with_context(|| format!("cannot read {}", manifest.display()))?;
    let table: toml::Table =
        toml::from_str(&text).with_context(|| format!("cannot parse {}", manifest.display()))?;
    let dir = manifest.parent().unwrap_or(Path::new(""));
    let mut files = Vec::new();
    if let Some(a) = table.get("alpha").and_then(|v| v.as_str()) {
        files.push(dir.join(a));
    }
    for w in table
        .get("wavelength")
        .and_then(|v| v.as_array())
        .into_iter()
        .flatten()
    {
        if let Some(f) = w.get("file").and_then(|v| v.as_str()) {
            files.push(dir.join(f));
        }
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_set(dir: &Path, entries: &[(f64, &str, u16)], manifest_extra: &str) -> PathBuf {
        image::GrayImage::from_pixel(2, 2, image::Luma([255]))
            .save(dir.join("alpha.png"))
            .unwrap();
        let mut m = format!("units = \"test\"\nalpha = \"alpha.png\"\n{manifest_extra}\n");
        for &(nm, file, code) in entries {
            if !file.is_empty() {
                image::ImageBuffer::<image::Luma<u16>, _>::from_pixel(2, 2, image::Luma([code]))
                    .save(dir.join(file))
                    .unwrap();
            }
            m += &format!(
                "[[wavelength]]\nnm = {nm}\nfile = \"{}\"\nscale = 2.0\n",
                if file.is_empty() { "missing.png" } else { file }
            );
        }
        let p = dir.join("manifest.toml");
        std::fs::write(&p, m).unwrap();
        p
    }

    #[test]
    fn loads_and_interpolates() {
        let d = tempfile::tempdir().unwrap();
        let p = write_set(
            d.path(),
            &[
                (400.0, "a.png", 0),
                (500.0, "b.png", 65535),
                (600.0, "c.png", 32768),
            ],
            "",
        );
        let t = SpectralTexture::load(&p).unwrap();
        assert_eq!((t.width, t.height, t.nm.len()), (2, 2, 3));
        assert_eq!(t.value(0, 500.0, Interpolation::Nearest), 2.0);
        assert_eq!(t.value(0, 540.0, Interpolation::Nearest), 2.0);
        assert_eq!(t.value(0, 450.0, Interpolation::Linear), 1.0);
        assert_eq!(t.value(0, 300.0, Interpolation::Nearest), 0.0);
        assert_eq!(t.value(0, 640.0, Interpolation::Linear), 0.0);
        assert!((t.value(0, 649.0, Interpolation::Nearest) - 2.0 * 32768.0 / 65535.0).abs() < 1e-6);
        assert_eq!(t.alpha(3), 1.0);
    }

    #[test]
    fn blending_texels_first_is_the_sum_of_their_values() {
        // The shipped set (51 wavelengths, 4 distinct texels of a bilinear
        // lookup), on 81 camera wavelengths shifted by g both ways.
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let t = SpectralTexture::load(&root.join("spectral_assets/disk_spectral/manifest.toml"))
            .unwrap();
        let (texels, n) = t.texels(0.31, 0.62, Filter::Bilinear);
        assert_eq!(n, 4);
        let k = [0.7f32, 1.3, 0.2, 2.1];
        for interpolation in [Interpolation::Linear, Interpolation::Nearest] {
            let ctx = crate::spectral::SpectralContext::new(&crate::config::SpectralConfig {
                enabled: true,
                wavelengths: 81,
                interpolation,
                ..Default::default()
            });
            for g in [0.45, 0.9, 1.0, 1.37, 2.2] {
                let mut blended = vec![0.0f32; 81];
                t.add_blend(&texels, &k, g, &ctx, 0..81, &mut blended);
                for (i, &b) in blended.iter().enumerate() {
                    let nm = g * ctx.wavelengths.nm[i];
                    let sum: f32 = texels
                        .iter()
                        .zip(&k)
                        .map(|(&(tx, _), &kw)| kw * t.value(tx, nm, interpolation))
                        .sum();
                    assert!(
                        (b - sum).abs() <= 1e-6 * sum.abs().max(1e-3),
                        "g {g}, {nm} nm: {b} vs {sum}"
                    );
                }
            }
        }
    }

    #[test]
    fn footprint_texels_are_normalised_and_serve_the_blends() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let t = SpectralTexture::load(&root.join("spectral_assets/disk_spectral/manifest.toml"))
            .unwrap();
        let base = t.memory_bytes();
        let ctx = crate::spectral::SpectralContext::new(&crate::config::SpectralConfig {
            enabled: true,
            wavelengths: 41,
            ..Default::default()
        });
        let mut texels = Vec::new();
        let mut levels_seen = false;
        for (major, minor, angle) in [
            (0.3, 0.3, 0.0),
            (2.0, 1.0, 0.4),
            (7.0, 3.0, 1.1),
            (90.0, 9.0, 2.0),
        ] {
            let (c, s) = (f64::cos(angle), f64::sin(angle));
            let n = t.width as f64;
            let fp = Footprint::new(c * major / n, s * major / n, -s * minor / n, c * minor / n);
            t.footprint_texels(0.31, 0.62, &fp, &mut texels);
            let sum: f32 = texels.iter().map(|p| p.1).sum();
            assert!((sum - 1.0).abs() < 1e-5, "{major}: {sum}");
            levels_seen |= texels.iter().any(|p| p.0 >= t.base_texels());
            // The premultiplied blend is add_blend with weight x alpha.
            let kw: Vec<f32> = texels.iter().map(|&(x, w)| 0.7 * w * t.alpha(x)).collect();
            let (mut a, mut b) = (vec![0.0f32; 41], vec![0.0f32; 41]);
            t.add_premultiplied(&texels, 0.7, 1.1, &ctx, 0..41, &mut a);
            t.add_blend(&texels, &kw, 1.1, &ctx, 0..41, &mut b);
            assert_eq!(a, b);
            assert!((t.coverage(&texels) - kw.iter().sum::<f32>() / 0.7).abs() < 1e-5);
        }
        assert!(levels_seen, "minified lookups read mip levels");
        // The filter decides: a footprint only for "footprint", bilinear
        // where none is given.
        let fp = Footprint::new(0.01, 0.0, 0.0, 0.01);
        let mut via = Vec::new();
        t.texels_into(0.31, 0.62, Filter::Footprint, Some(&fp), &mut via);
        t.footprint_texels(0.31, 0.62, &fp, &mut texels);
        assert_eq!(via, texels);
        let (bl, n) = t.texels(0.31, 0.62, Filter::Bilinear);
        t.texels_into(0.31, 0.62, Filter::Footprint, None, &mut via);
        assert_eq!(via, bl[..n]);
        t.texels_into(0.31, 0.62, Filter::Nearest, Some(&fp), &mut via);
        assert_eq!(via.len(), 1);
        assert_eq!(t.memory_bytes(), base + t.pyramid_bytes());
        assert!(t.pyramid_bytes() * 3 <= base + 4 * (t.nm.len() + 1));
    }

    #[test]
    fn a_constant_set_stays_constant_on_every_level() {
        let d = tempfile::tempdir().unwrap();
        let p = write_set(
            d.path(),
            &[(400.0, "a.png", 30000), (500.0, "b.png", 500)],
            "",
        );
        let t = SpectralTexture::load(&p).unwrap();
        let want = t.value(0, 500.0, Interpolation::Nearest);
        let mut texels = Vec::new();
        for size in [0.1, 1.0, 1.5, 2.0, 50.0] {
            let fp = Footprint::new(size / 2.0, 0.0, 0.0, size / 2.0);
            t.footprint_texels(0.4, 0.7, &fp, &mut texels);
            let v: f32 = texels
                .iter()
                .map(|&(x, w)| w * t.value(x, 500.0, Interpolation::Nearest))
                .sum();
            assert!((v - want).abs() < 1e-6 * want, "{size}: {v} vs {want}");
            assert!((t.coverage(&texels) - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn bad_manifests_are_explained() {
        let d = tempfile::tempdir().unwrap();
        let err = |entries: &[(f64, &str, u16)], extra: &str| {
            let p = write_set(d.path(), entries, extra);
            SpectralTexture::load(&p).unwrap_err().to_string()
        };
        let e = err(&[(500.0, "a.png", 1), (400.0, "b.png", 1)], "");
        assert!(e.contains("must increase") && e.contains("400 nm"), "{e}");
        let e = err(&[(500.0, "a.png", 1), (500.0, "b.png", 1)], "");
        assert!(e.contains("listed twice"), "{e}");
        let e = err(&[(500.0, "", 1)], "");
        assert!(e.contains("missing.png"), "{e}");
        let e = err(&[(500.0, "a.png", 1)], "colour = 3");
        assert!(e.contains("unknown field `colour`"), "{e}");
        // A size mismatch names the file.
        image::GrayImage::new(3, 3)
            .save(d.path().join("big.png"))
            .unwrap();
        let p = d.path().join("m2.toml");
        std::fs::write(
            &p,
            "units = \"x\"\nalpha = \"alpha.png\"\n[[wavelength]]\nnm = 500\nfile = \"big.png\"\n",
        )
        .unwrap();
        let e = SpectralTexture::load(&p).unwrap_err().to_string();
        assert!(
            e.contains("big.png") && e.contains("3 x 3") && e.contains("2 x 2"),
            "{e}"
        );
    }
}
