//! Images used as textures: the disk's RGBA texture and the sky panorama.
//!
//! 8-bit images stay 8-bit in memory (4 bytes a texel, decoded to linear
//! through a table on lookup); 16-bit and float images (PNG16, EXR, HDR) are
//! kept as linear f32. Lookups return premultiplied linear RGBA so that
//! bilinear filtering across alpha edges does not bleed colour.
//!
//! Footprint lookups ([`Texture::sample_footprint`], [`ewa`]) read a mip
//! pyramid built on first use (a third of the texture's memory more, in
//! its own format), so scenes that never filter by footprint pay nothing.

pub mod ewa;
pub mod mip;
pub mod sphere;

pub use ewa::{Footprint, MAX_ANISOTROPY};
pub use sphere::{equirect_footprint, wrap_du};

use crate::config::Filter;
use crate::spectrum::color::{srgb_decode, srgb_encode};
use glam::{DVec3, Vec4};
use mip::Levels;
use std::path::Path;
use std::sync::{Arc, LazyLock, OnceLock};

static SRGB_TO_LINEAR: LazyLock<[f32; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| srgb_decode(i as f32 / 255.0)));

/// Shared, not copied, when a scene is cloned (a stereo pair's eyes).
#[derive(Clone, Debug)]
enum Texels {
    /// sRGB-encoded colour, linear alpha.
    Srgb8(Arc<Vec<[u8; 4]>>),
    /// Linear colour and alpha.
    Linear(Arc<Vec<[f32; 4]>>),
}

/// Whether an image `width` x `height` is an equirectangular panorama:
/// twice as wide as high, to 2% (a sky and `relens` take no other).
pub fn is_panorama(width: u32, height: u32) -> bool {
    (width as f64 / height as f64 / 2.0 - 1.0).abs() <= 0.02
}

/// What an image decoder may allocate: the memory available (the scene's
/// memory check has already weighed every asset), not the decoder's own
/// default of 512 MiB, which refused a 16-bit 16k panorama on a machine
/// with 22 GB free.
pub fn decode_limits() -> image::Limits {
    let mut limits = image::Limits::no_limits();
    limits.max_alloc = crate::memory::room::available().map(|a| a.bytes);
    limits
}

/// Channel values, four per texel, as texels (the same allocation where
/// its size allows).
fn texel_vec<T: bytemuck::Pod>(raw: Vec<T>) -> Vec<[T; 4]> {
    match bytemuck::allocation::try_cast_vec(raw) {
        Ok(v) => v,
        Err((_, raw)) => raw
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect(),
    }
}

/// Premultiplied linear RGBA of an sRGB8 texel (straight colour, linear
/// alpha).
#[inline]
fn srgb8_premultiplied([r, g, b, a]: [u8; 4]) -> Vec4 {
    let lut = &*SRGB_TO_LINEAR;
    let a = a as f32 / 255.0;
    Vec4::new(
        lut[r as usize] * a,
        lut[g as usize] * a,
        lut[b as usize] * a,
        a,
    )
}

/// Premultiplied RGBA of a linear texel (straight colour).
#[inline]
fn linear_premultiplied([r, g, b, a]: [f32; 4]) -> Vec4 {
    Vec4::new(r * a, g * a, b * a, a)
}

/// Straight colour of premultiplied RGBA (0 where transparent).
#[inline]
fn unpremultiply(p: &[f32]) -> [f32; 4] {
    let a = p[3];
    if a > 0.0 {
        [p[0] / a, p[1] / a, p[2] / a, a]
    } else {
        [0.0; 4]
    }
}

/// Mip levels 1 and up, in the format of level 0.
#[derive(Debug)]
enum MipTexels {
    Srgb8(Levels<[u8; 4]>),
    Linear(Levels<[f32; 4]>),
}

/// A decoded image.
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Whether the image had an alpha channel (else alpha is 1 everywhere).
    pub has_alpha: bool,
    texels: Texels,
    /// Built on the first footprint lookup that needs it; shared by clones
    /// (a stereo pair's eyes build it once).
    mips: Arc<OnceLock<MipTexels>>,
}

impl Texture {
    /// Loads an image file (PNG, JPEG, EXR or Radiance HDR). 8- and 16-bit
    /// colour is taken as sRGB-encoded, float formats as linear.
    pub fn load(path: &Path) -> Result<Texture, image::ImageError> {
        let mut reader = crate::inputs::image_reader(path)?;
        reader.limits(decode_limits());
        Ok(Texture::from_image(reader.decode()?))
    }

    /// Wraps a decoded image.
    pub fn from_image(img: image::DynamicImage) -> Texture {
        use image::DynamicImage as D;
        let (width, height) = (img.width(), img.height());
        let has_alpha = img.color().has_alpha();
        let texels = match img {
            // The decoded buffers become the texels without a copy (a 16k
            // panorama's texels are gigabytes).
            D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
                Texels::Srgb8(Arc::new(texel_vec(img.into_rgba8().into_raw())))
            }
            D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
                Texels::Linear(Arc::new(texel_vec(img.into_rgba32f().into_raw())))
            }
            other => {
                let mut raw = other.into_rgba32f().into_raw();
                for p in raw.chunks_exact_mut(4) {
                    for c in &mut p[..3] {
                        *c = srgb_decode(*c);
                    }
                }
                Texels::Linear(Arc::new(texel_vec(raw)))
            }
        };
        Texture {
            width,
            height,
            has_alpha,
            texels,
            mips: Arc::default(),
        }
    }

    /// One texel of linear `color` everywhere.
    pub fn uniform(color: glam::Vec4) -> Texture {
        Texture::linear(1, 1, vec![color.to_array()])
    }

    /// Linear RGBA texels, row by row.
    pub fn linear(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Texture {
        Texture {
            width,
            height,
            has_alpha: true,
            texels: Texels::Linear(Arc::new(texels)),
            mips: Arc::default(),
        }
    }

    /// Sets every texel's alpha to 1.
    pub fn make_opaque(&mut self) {
        match &mut self.texels {
            Texels::Srgb8(t) => Arc::make_mut(t).iter_mut().for_each(|p| p[3] = 255),
            Texels::Linear(t) => Arc::make_mut(t).iter_mut().for_each(|p| p[3] = 1.0),
        }
        // Levels built from the old alpha are stale.
        self.mips = Arc::default();
    }

    /// The texels as the GPU backend stores them: (0, one packed sRGB8
    /// RGBA word per texel) or (1, four f32 words of linear RGBA per texel).
    pub(crate) fn gpu_words(&self) -> (u32, Vec<u32>) {
        match &self.texels {
            Texels::Srgb8(t) => (0, t.iter().map(|p| u32::from_le_bytes(*p)).collect()),
            Texels::Linear(t) => (1, t.iter().flatten().map(|v| v.to_bits()).collect()),
        }
    }

    /// The mip levels (built now if not yet) as the GPU backend stores
    /// them: levels 1 and up one after another, each texel in the format
    /// of [`Texture::gpu_words`].
    pub(crate) fn gpu_mip_words(&self) -> Vec<u32> {
        match self.mips() {
            MipTexels::Srgb8(l) => l.data.iter().map(|p| u32::from_le_bytes(*p)).collect(),
            MipTexels::Linear(l) => l.data.iter().flatten().map(|v| v.to_bits()).collect(),
        }
    }

    /// Bytes held in memory: the texels, and the mip levels once a
    /// footprint lookup has built them ([`Texture::pyramid_bytes`]).
    pub fn memory_bytes(&self) -> usize {
        let base = self.width as usize * self.height as usize * self.texel_bytes();
        base + if self.mips.get().is_some() {
            self.pyramid_bytes()
        } else {
            0
        }
    }

    /// Bytes of one texel (4 for 8-bit images, 16 for linear f32).
    fn texel_bytes(&self) -> usize {
        match &self.texels {
            Texels::Srgb8(_) => 4,
            Texels::Linear(_) => 16,
        }
    }

    /// Bytes the mip levels take, built or not: at most a third of the
    /// texels' (what footprint filtering adds to a scene's memory).
    pub fn pyramid_bytes(&self) -> usize {
        mip::texel_count(self.width, self.height) * self.texel_bytes()
    }

    /// Builds the mip levels now rather than on the first footprint lookup
    /// that needs them (when a scene is built, say, so the render's time
    /// and memory hold no surprise).
    pub fn build_pyramid(&self) {
        self.mips();
    }

    /// The mip levels, built on first call: premultiplied area averages
    /// stored in the texels' format (8-bit sRGB colour with linear alpha,
    /// or linear f32), straight colour as level 0 keeps it.
    fn mips(&self) -> &MipTexels {
        self.mips.get_or_init(|| {
            let (w, h) = (self.width, self.height);
            let row = |y: usize, buf: &mut [f32]| {
                for (x, px) in buf.chunks_exact_mut(4).enumerate() {
                    px.copy_from_slice(&self.texel(x as u32, y as u32).to_array());
                }
            };
            match &self.texels {
                Texels::Srgb8(_) => MipTexels::Srgb8(Levels::build(4, (w, h), &row, |p| {
                    let [r, g, b, a] = unpremultiply(p);
                    let code = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
                    let enc = |c: f32| code(srgb_encode(c.clamp(0.0, 1.0)));
                    [enc(r), enc(g), enc(b), code(a)]
                })),
                Texels::Linear(_) => {
                    MipTexels::Linear(Levels::build(4, (w, h), &row, unpremultiply))
                }
            }
        })
    }

    /// Premultiplied linear RGBA of texel (x, y), row 0 at the top.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec4 {
        let i = y as usize * self.width as usize + x as usize;
        match &self.texels {
            Texels::Srgb8(t) => srgb8_premultiplied(t[i]),
            Texels::Linear(t) => linear_premultiplied(t[i]),
        }
    }

    /// Samples at texture coordinates (u, v) in [0, 1] (v down) over a
    /// pixel's footprint `fp` (the derivatives of (u, v) per pixel step):
    /// the elliptical Gaussian average of [`ewa`] on the mip levels.
    /// `wrap_u` makes u periodic (panoramas); otherwise coordinates clamp
    /// to the edge, as do rows always. Premultiplied linear RGBA.
    pub fn sample_footprint(&self, u: f64, v: f64, fp: &Footprint, wrap_u: bool) -> Vec4 {
        let (ellipses, n) = ewa::plan(u, v, fp, self.width, self.height);
        let mut out = Vec4::ZERO;
        for e in &ellipses[..n] {
            let (w, h) = ewa::level_dims(self.width, self.height, e.level);
            let mean = if e.level == 0 {
                match &self.texels {
                    Texels::Srgb8(t) => ewa_mean(t, srgb8_premultiplied, e, w, h, wrap_u),
                    Texels::Linear(t) => ewa_mean(t, linear_premultiplied, e, w, h, wrap_u),
                }
            } else {
                match self.mips() {
                    MipTexels::Srgb8(l) => {
                        ewa_mean(l.level(e.level), srgb8_premultiplied, e, w, h, wrap_u)
                    }
                    MipTexels::Linear(l) => {
                        ewa_mean(l.level(e.level), linear_premultiplied, e, w, h, wrap_u)
                    }
                }
            };
            out += e.weight * mean;
        }
        out
    }

    /// [`Texture::sample`] with `filter`, or, for [`Filter::Footprint`]
    /// given a footprint, [`Texture::sample_footprint`]: the one call a
    /// renderer makes whatever the scene's filter.
    #[inline]
    pub fn sample_filtered(
        &self,
        u: f64,
        v: f64,
        filter: Filter,
        footprint: Option<&Footprint>,
        wrap_u: bool,
    ) -> Vec4 {
        match (filter, footprint) {
            (Filter::Footprint, Some(fp)) => self.sample_footprint(u, v, fp, wrap_u),
            _ => self.sample(u, v, filter, wrap_u),
        }
    }

    /// A panorama (as [`equirect_uv`] maps it) along unit direction `dir`
    /// read with `filter`: over the footprint for [`Filter::Footprint`]
    /// given the direction's derivatives per pixel step `(ddx, ddy)`
    /// ([`Texture::sample_sky_footprint`]), else at the point.
    #[inline]
    pub fn sample_sky(
        &self,
        dir: DVec3,
        filter: Filter,
        derivatives: Option<(DVec3, DVec3)>,
    ) -> Vec4 {
        match (filter, derivatives) {
            (Filter::Footprint, Some((ddx, ddy))) => self.sample_sky_footprint(dir, ddx, ddy),
            _ => {
                let (u, v) = equirect_uv(dir);
                self.sample(u, v, filter, true)
            }
        }
    }

    /// A panorama (as [`equirect_uv`] maps it) over the footprint on the
    /// sky of a pixel whose unit escape direction is `dir`, with
    /// derivatives `ddx`, `ddy` per pixel step (scene axes; see
    /// [`equirect_footprint`]). Premultiplied linear RGBA.
    pub fn sample_sky_footprint(&self, dir: DVec3, ddx: DVec3, ddy: DVec3) -> Vec4 {
        let (u, v, fp) = equirect_footprint(dir, ddx, ddy);
        self.sample_footprint(u, v, &fp, true)
    }

    /// Samples at texture coordinates (u, v) in [0, 1] (v down). `wrap_u`
    /// makes u periodic (panoramas); otherwise coordinates clamp to the edge.
    #[inline]
    pub fn sample(&self, u: f64, v: f64, filter: Filter, wrap_u: bool) -> Vec4 {
        let (w, h) = (self.width as f64, self.height as f64);
        match filter {
            Filter::Nearest => {
                let x = (u * w).floor();
                let x = if wrap_u {
                    x.rem_euclid(w)
                } else {
                    x.clamp(0.0, w - 1.0)
                };
                let y = (v * h).floor().clamp(0.0, h - 1.0);
                self.texel(x as u32, y as u32)
            }
            // A lookup without a footprint is a point: the footprint
            // filter's reconstruction there is bilinear's (callers that have
            // a footprint use `sample_footprint`).
            Filter::Bilinear | Filter::Footprint => {
                let fx = u * w - 0.5;
                let fy = (v * h - 0.5).clamp(0.0, h - 1.0);
                let x0 = fx.floor();
                let y0 = fy.floor();
                let (tx, ty) = ((fx - x0) as f32, (fy - y0) as f32);
                let col = |x: f64| {
                    if wrap_u {
                        x.rem_euclid(w) as u32
                    } else {
                        x.clamp(0.0, w - 1.0) as u32
                    }
                };
                let (xa, xb) = (col(x0), col(x0 + 1.0));
                let ya = y0 as u32;
                let yb = (y0 + 1.0).min(h - 1.0) as u32;
                let top = self.texel(xa, ya).lerp(self.texel(xb, ya), tx);
                let bottom = self.texel(xa, yb).lerp(self.texel(xb, yb), tx);
                top.lerp(bottom, ty)
            }
        }
    }
}

/// The weighted mean of texels `t` (decoded by `decode`) under ellipse `e`
/// of a w x h level.
#[inline]
fn ewa_mean<T: Copy>(
    t: &[T],
    decode: impl Fn(T) -> Vec4,
    e: &ewa::LevelEllipse,
    w: u32,
    h: u32,
    wrap_u: bool,
) -> Vec4 {
    let mut acc = Vec4::ZERO;
    let sum = ewa::visit(e, w, h, wrap_u, |i, wt| acc += wt * decode(t[i]));
    acc / sum
}

/// The sRGB decoding table of 8-bit textures (code -> linear).
pub(crate) fn srgb_decode_table() -> &'static [f32; 256] {
    &SRGB_TO_LINEAR
}

/// Texture coordinates of a unit direction in an equirectangular panorama:
/// phi = atan2(x, y) in [0, 2 pi) across, theta = asin(z) from +90 degrees
/// (top row) to -90 degrees (bottom row).
#[inline]
pub fn equirect_uv(dir: DVec3) -> (f64, f64) {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let phi = dir.x.atan2(dir.y).rem_euclid(TAU);
    let theta = dir.z.clamp(-1.0, 1.0).asin();
    (phi / TAU, (FRAC_PI_2 - theta) / PI)
}

/// The unit direction at the centre of panorama texture coordinates (u, v);
/// inverse of [`equirect_uv`].
pub fn equirect_dir(u: f64, v: f64) -> DVec3 {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let phi = u * TAU;
    let theta = FRAC_PI_2 - v * PI;
    DVec3::new(
        theta.cos() * phi.sin(),
        theta.cos() * phi.cos(),
        theta.sin(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decoders_may_take_the_memory_that_is_free() {
        // Not the decoder's default 512 MiB: what the system has.
        let limit = decode_limits().max_alloc;
        if let Some(a) = crate::memory::room::available() {
            let l = limit.expect("a limit where the system tells");
            assert!(l as f64 > 0.5 * a.bytes as f64 && l as f64 <= 2.0 * a.bytes as f64);
        }
    }

    fn tex(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
        Texture::from_image(image::DynamicImage::ImageRgba8(img))
    }

    #[test]
    fn nearest_picks_the_texel_under_the_point() {
        let t = tex(4, 2, |x, y| [(x * 60) as u8, (y * 200) as u8, 0, 255]);
        let s = t.sample(0.30, 0.9, Filter::Nearest, false);
        assert_eq!(s, t.texel(1, 1));
        // Wrapping: u slightly below 0 lands in the last column.
        assert_eq!(t.sample(-0.01, 0.2, Filter::Nearest, true), t.texel(3, 0));
        assert_eq!(t.sample(1.0, 0.2, Filter::Nearest, false), t.texel(3, 0));
    }

    #[test]
    fn bilinear_interpolates_between_texel_centres() {
        let t = tex(2, 1, |x, _| {
            if x == 0 {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            }
        });
        // Halfway between the two texel centres (u = 0.25 and 0.75).
        let s = t.sample(0.5, 0.5, Filter::Bilinear, false);
        assert!((s.x - 0.5).abs() < 1e-6, "{s}");
        // At a texel centre it returns that texel.
        assert_eq!(t.sample(0.25, 0.5, Filter::Bilinear, false), t.texel(0, 0));
    }

    #[test]
    fn the_pyramid_is_built_on_first_need_and_counted() {
        let mut t = tex(64, 32, |x, y| [(x * 4) as u8, (y * 8) as u8, 7, 200]);
        assert_eq!(t.memory_bytes(), 64 * 32 * 4);
        // 32 x 16 + 16 x 8 + ... + 1 x 1 texels: under a third.
        let levels = 512 + 128 + 32 + 8 + 2 + 1;
        assert_eq!(t.pyramid_bytes(), 4 * levels);
        // Magnified: level 0 alone, nothing built.
        t.sample_footprint(
            0.3,
            0.3,
            &Footprint::new(0.2 / 64.0, 0.0, 0.0, 0.2 / 32.0),
            false,
        );
        assert_eq!(t.memory_bytes(), 64 * 32 * 4);
        let fp = Footprint::new(6.0 / 64.0, 0.0, 0.0, 6.0 / 32.0);
        let before = t.sample_footprint(0.3, 0.3, &fp, false);
        assert_eq!(t.memory_bytes(), 4 * (64 * 32 + levels));
        // A clone shares it; making the texture opaque drops it (its alpha
        // changed).
        assert_eq!(t.clone().memory_bytes(), t.memory_bytes());
        t.make_opaque();
        assert_eq!(t.memory_bytes(), 64 * 32 * 4);
        let after = t.sample_footprint(0.3, 0.3, &fp, false);
        assert!((before.w - 200.0 / 255.0).abs() < 2e-3 && after.w == 1.0);
    }

    #[test]
    fn first_lookups_from_many_rayon_workers_build_one_pyramid() {
        // Every worker's first lookup needs the levels at once; the build
        // must not hand its work to the workers waiting on it.
        use rayon::prelude::*;
        let t = tex(512, 256, |x, y| [(x % 256) as u8, (y % 256) as u8, 9, 255]);
        let fp = Footprint::new(5.0 / 512.0, 0.0, 0.0, 5.0 / 256.0);
        let sum: f32 = (0..20_000)
            .into_par_iter()
            .map(|i| t.sample_footprint((i % 97) as f64 / 97.0, 0.5, &fp, true).w)
            .sum();
        assert!((sum - 20_000.0).abs() < 1.0, "{sum}");
    }

    #[test]
    fn the_filter_decides_what_a_footprint_does() {
        let t = tex(64, 32, |x, y| {
            [(x * 4) as u8, (y * 8) as u8, (x ^ y) as u8, 255]
        });
        let fp = Footprint::new(3.0 / 64.0, 0.0, 0.0, 3.0 / 32.0);
        let (u, v) = (0.37, 0.61);
        let at = |f, fp| t.sample_filtered(u, v, f, fp, true);
        assert_eq!(
            at(Filter::Footprint, Some(&fp)),
            t.sample_footprint(u, v, &fp, true)
        );
        assert_eq!(at(Filter::Footprint, None), at(Filter::Bilinear, None));
        assert_eq!(at(Filter::Nearest, Some(&fp)), at(Filter::Nearest, None));
        assert_eq!(at(Filter::Bilinear, Some(&fp)), at(Filter::Bilinear, None));
        let d = equirect_dir(u, v);
        let (a, b) = (DVec3::X * 0.05, DVec3::Z * 0.05);
        assert_eq!(
            t.sample_sky(d, Filter::Footprint, Some((a, b))),
            t.sample_sky_footprint(d, a, b)
        );
        assert_eq!(
            t.sample_sky(d, Filter::Footprint, None),
            at(Filter::Bilinear, None)
        );
        assert_eq!(
            t.sample_sky(d, Filter::Nearest, Some((a, b))),
            at(Filter::Nearest, None)
        );
    }

    #[test]
    fn lookup_is_premultiplied_linear() {
        let t = tex(1, 1, |_, _| [255, 128, 0, 128]);
        let s = t.texel(0, 0);
        let a = 128.0 / 255.0;
        assert!((s.w - a).abs() < 1e-7);
        assert!((s.x - a).abs() < 1e-7);
        assert!((s.y - srgb_decode(128.0 / 255.0) * a).abs() < 1e-7);
    }

    #[test]
    fn equirect_round_trip_and_axes() {
        for &(u, v) in &[(0.1, 0.2), (0.6, 0.7), (0.99, 0.5)] {
            let (u2, v2) = equirect_uv(equirect_dir(u, v));
            assert!((u - u2).abs() < 1e-12 && (v - v2).abs() < 1e-12);
        }
        // +y is phi = 0 (left edge), +x is a quarter across, +z the top row.
        assert_eq!(equirect_uv(DVec3::Y), (0.0, 0.5));
        assert!((equirect_uv(DVec3::X).0 - 0.25).abs() < 1e-15);
        assert_eq!(equirect_uv(DVec3::Z).1, 0.0);
    }
}
