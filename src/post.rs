//! Post-processing on the linear film: bloom, and stereo composites.

use crate::config::{BloomConfig, BloomShape};
use crate::film::Film;
use glam::Vec3;
use rayon::prelude::*;

/// Normalised Gaussian weights for offsets -r..=r.
pub(crate) fn kernel(sigma: f64) -> Vec<f32> {
    let r = (3.0 * sigma).ceil().max(1.0) as i64;
    let w: Vec<f64> = (-r..=r)
        .map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp())
        .collect();
    let sum: f64 = w.iter().sum();
    w.iter().map(|x| (x / sum) as f32).collect()
}

/// For each position of a line of `n` pixels, the part of the kernel `k`
/// that lands inside the line.
pub(crate) fn inside(n: usize, k: &[f32]) -> Vec<f32> {
    let r = (k.len() / 2) as i64;
    (0..n as i64)
        .map(|i| {
            (-r..=r)
                .filter(|d| (0..n as i64).contains(&(i + d)))
                .map(|d| k[(d + r) as usize])
                .sum()
        })
        .collect()
}

/// One separable pass along rows (`transpose` = false) or columns. Each
/// source pixel is divided by the part of the kernel that lands inside the
/// image, so its whole light stays in the image: the pass keeps the total.
fn pass(src: &[Vec3], w: usize, h: usize, k: &[f32], along_columns: bool) -> Vec<Vec3> {
    let r = (k.len() / 2) as i64;
    let (n, lines) = if along_columns { (h, w) } else { (w, h) };
    let idx = |line: usize, i: usize| {
        if along_columns {
            i * w + line
        } else {
            line * w + i
        }
    };
    let inside = inside(n, k);
    let spread = |line: usize, out: &mut [Vec3]| {
        for i in 0..n {
            let v = src[idx(line, i)] / inside[i];
            if v == Vec3::ZERO {
                continue;
            }
            let lo = (i as i64 - r).max(0);
            let hi = (i as i64 + r).min(n as i64 - 1);
            for j in lo..=hi {
                out[j as usize] += v * k[(j - i as i64 + r) as usize];
            }
        }
    };
    let mut dst = vec![Vec3::ZERO; w * h];
    if along_columns {
        // Columns are strided: each is spread into its own buffer, then
        // copied into place.
        let out_lines: Vec<Vec<Vec3>> = (0..lines)
            .into_par_iter()
            .map(|line| {
                let mut out = vec![Vec3::ZERO; n];
                spread(line, &mut out);
                out
            })
            .collect();
        for (line, vals) in out_lines.into_iter().enumerate() {
            for (i, v) in vals.into_iter().enumerate() {
                dst[idx(line, i)] = v;
            }
        }
    } else {
        dst.par_chunks_mut(w)
            .enumerate()
            .for_each(|(line, out)| spread(line, out));
    }
    dst
}

/// Gaussian blur with standard deviation `sigma` pixels, keeping the total.
/// From [`COARSE_SIGMA`] pixels on it runs on the image shrunk by a power
/// of two ([`coarse_blur`]): a halo's widest Gaussians at 1080 rows (108
/// pixels) cost 650 taps a pixel at full size.
pub fn blur(img: &[Vec3], w: usize, h: usize, sigma: f64) -> Vec<Vec3> {
    if sigma <= 0.0 {
        return img.to_vec();
    }
    if sigma >= COARSE_SIGMA {
        return coarse_blur(img, w, h, sigma);
    }
    let k = kernel(sigma);
    let rows = pass(img, w, h, &k, false);
    pass(&rows, w, h, &k, true)
}

/// Sigma (pixels) from which [`blur`] works on a shrunk image.
pub const COARSE_SIGMA: f64 = 32.0;

/// [`blur`] of a wide Gaussian: the image summed in blocks of f x f (f a
/// power of two, sigma / f in 16..32), blurred there, and spread back by
/// bilinear interpolation of the blocks' light per pixel. The blocks' box
/// (variance f^2 / 12 an axis) and the interpolation's tent (f^2 / 6) widen
/// the kernel, and the coarse sigma leaves them room; a point moves to its
/// block's centre, up to f / 2, which the Gaussian of `sigma` hardly
/// notices (within 2% of its peak, 3.3% by the image's edges, where each
/// level renormalises the kernel inside the image). The total is kept
/// exactly (a last scale per channel).
fn coarse_blur(img: &[Vec3], w: usize, h: usize, sigma: f64) -> Vec<Vec3> {
    let f = 2usize.pow((sigma / 16.0).log2().floor().max(0.0) as u32);
    let (cw, ch) = (w.div_ceil(f), h.div_ceil(f));
    let mut coarse = vec![Vec3::ZERO; cw * ch];
    for y in 0..h {
        for x in 0..w {
            coarse[(y / f) * cw + x / f] += img[y * w + x];
        }
    }
    let fine = f as f64;
    let sigma_c = (sigma * sigma - fine * fine / 4.0).sqrt() / fine;
    let k = kernel(sigma_c);
    let rows = pass(&coarse, cw, ch, &k, false);
    let spread = pass(&rows, cw, ch, &k, true);
    // Each block's light per fine pixel, interpolated at the pixel's
    // centre in block coordinates.
    let at = |cx: isize, cy: isize| -> Vec3 {
        let cx = cx.clamp(0, cw as isize - 1) as usize;
        let cy = cy.clamp(0, ch as isize - 1) as usize;
        spread[cy * cw + cx]
    };
    let area = (f * f) as f32;
    let mut out = vec![Vec3::ZERO; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let v = (y as f64 + 0.5) / fine - 0.5;
        let (y0, ty) = (v.floor() as isize, (v - v.floor()) as f32);
        for (x, o) in row.iter_mut().enumerate() {
            let u = (x as f64 + 0.5) / fine - 0.5;
            let (x0, tx) = (u.floor() as isize, (u - u.floor()) as f32);
            let top = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
            let bottom = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
            *o = (top * (1.0 - ty) + bottom * ty) / area;
        }
    });
    let before: glam::DVec3 = img.iter().map(|v| v.as_dvec3()).sum();
    let after: glam::DVec3 = out.iter().map(|v| v.as_dvec3()).sum();
    let scale = Vec3::from_array([0, 1, 2].map(|i| {
        if after[i] != 0.0 {
            (before[i] / after[i]) as f32
        } else {
            1.0
        }
    }));
    for o in &mut out {
        *o *= scale;
    }
    out
}

/// The widest Gaussian of a halo ([`BloomShape::Halo`]), a fraction of the
/// image's height: its wings reach about three times that.
pub const HALO_REACH: f64 = 0.1;

/// One Gaussian of bloom: each plane adds `keep` x itself + `weight` x
/// itself blurred by `sigma` (a fraction of the image's height, at 550
/// nm). A bloom's terms keep the light: their `keep` and `weight` sum to 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BloomTerm {
    pub keep: f32,
    pub weight: f32,
    pub sigma: f64,
}

/// The Gaussians of `[bloom]`: one for [`BloomShape::Gaussian`]; for
/// [`BloomShape::Halo`] sigma = radius x 2^k up to [`HALO_REACH`], weights
/// halving with k (a sum over octaves of Gaussians whose weight goes as
/// 1 / sigma falls as r^-3 between the first and the last: the scale
/// mixture of sigma^-3 exp(-r^2 / 2 sigma^2) per log sigma).
pub fn bloom_terms(b: &BloomConfig) -> Vec<BloomTerm> {
    let spread = b.strength as f32;
    // Octaves from the radius while within the reach (at least one).
    let n = match b.shape {
        BloomShape::Gaussian => 1,
        BloomShape::Halo => {
            1 + (HALO_REACH * (1.0 + 1e-9) / b.radius)
                .log2()
                .floor()
                .max(0.0) as usize
        }
    };
    let sigmas: Vec<f64> = (0..n).map(|k| b.radius * 2f64.powi(k as i32)).collect();
    let raw: Vec<f64> = (0..sigmas.len()).map(|k| 0.5f64.powi(k as i32)).collect();
    let sum: f64 = raw.iter().sum();
    sigmas
        .iter()
        .zip(&raw)
        .enumerate()
        .map(|(k, (&sigma, &r))| BloomTerm {
            keep: if k == 0 { 1.0 - spread } else { 0.0 },
            weight: spread * (r / sum) as f32,
            sigma,
        })
        .collect()
}

/// `plane` bloomed by `terms`: each sigma a fraction of the height `h`,
/// scaled by the band's centre (nm) over 550 nm for a band.
fn bloom_plane(
    plane: &[Vec3],
    (w, h): (usize, usize),
    terms: &[BloomTerm],
    centre: Option<f64>,
) -> Vec<Vec3> {
    let mut mine: Option<Vec<Vec3>> = None;
    for t in terms {
        let sigma = t.sigma * h as f64;
        let sigma = centre.map_or(sigma, |c| sigma * c / 550.0);
        let mut spread = blur(plane, w, h, sigma);
        for (b, a) in spread.iter_mut().zip(plane) {
            *b = *a * t.keep + *b * t.weight;
        }
        mine = Some(match mine {
            None => spread,
            Some(mut m) => {
                for (m, b) in m.iter_mut().zip(spread) {
                    *m += b;
                }
                m
            }
        });
    }
    mine.unwrap_or_else(|| plane.to_vec())
}

/// Bloom on linear XYZ: each term's share of the image kept and of it
/// blurred ([`bloom_terms`]: `(1 - strength)` x image + `strength` x the
/// blurred image for one Gaussian). With per-band XYZ (spectral bloom)
/// each wavelength band is spread with sigmas proportional to its
/// wavelength (as given at 550 nm), as the width of a diffraction pattern
/// grows with wavelength.
pub fn bloom(film: &Film, terms: &[BloomTerm]) -> Vec<Vec3> {
    let (w, h) = (film.width as usize, film.height as usize);
    match &film.bands {
        Some(bands) => {
            let mut total = vec![Vec3::ZERO; w * h];
            for (centre, plane) in bands {
                let mine = bloom_plane(plane, (w, h), terms, Some(*centre));
                for (t, m) in total.iter_mut().zip(mine) {
                    *t += m;
                }
            }
            total
        }
        None => bloom_plane(&film.xyz, (w, h), terms, None),
    }
}

/// Red-cyan anaglyph of two 8-bit sRGB images: red from the left eye,
/// green and blue from the right.
pub fn anaglyph(left: &[u8], right: &[u8]) -> Vec<u8> {
    left.chunks_exact(3)
        .zip(right.chunks_exact(3))
        .flat_map(|(l, r)| [l[0], r[1], r[2]])
        .collect()
}

/// Two 8-bit RGB images side by side (left image on the left).
pub fn side_by_side(w: usize, h: usize, left: &[u8], right: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(w * h * 6);
    for y in 0..h {
        out.extend_from_slice(&left[y * w * 3..(y + 1) * w * 3]);
        out.extend_from_slice(&right[y * w * 3..(y + 1) * w * 3]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_keeps_the_total_even_at_the_edges() {
        let (w, h) = (40, 30);
        let mut img = vec![Vec3::ZERO; w * h];
        img[0] = Vec3::new(10.0, 5.0, 1.0); // a corner
        img[15 * w + 20] = Vec3::splat(3.0);
        img[29 * w + 39] = Vec3::ONE;
        let before: Vec3 = img.iter().copied().sum();
        let after: Vec3 = blur(&img, w, h, 4.0).iter().copied().sum();
        assert!(
            ((after - before) / before).abs().max_element() < 1e-5,
            "{before} {after}"
        );
    }

    #[test]
    fn a_wide_blur_on_the_shrunk_image_is_the_gaussian() {
        // Sigma 32 to 200 pixels: the shrunk image's blur against the
        // separable Gaussian at full size, for a point (on and off the
        // blocks' grid) and near an edge: within 2% of the peak (4% by the
        // edge; measured 1.8% and 3.3%), the total kept.
        let (w, h) = (500, 460);
        for sigma in [32.0, 45.0, 64.0, 200.0] {
            for at in [(250, 230), (251, 233), (5, 450)] {
                let mut img = vec![Vec3::ZERO; w * h];
                img[at.1 * w + at.0] = Vec3::new(1.0, 2.0, 3.0);
                let k = kernel(sigma);
                let exact = pass(&pass(&img, w, h, &k, false), w, h, &k, true);
                let fast = blur(&img, w, h, sigma);
                let peak = exact.iter().map(|v| v.z).fold(0.0, f32::max);
                let worst = exact
                    .iter()
                    .zip(&fast)
                    .map(|(a, b)| (a.z - b.z).abs())
                    .fold(0.0, f32::max);
                let total: Vec3 = fast.iter().copied().sum();
                eprintln!(
                    "sigma {sigma} at {at:?}: worst {:.4} of the peak",
                    worst / peak
                );
                assert!(
                    worst < if at.0 < 10 { 0.04 } else { 0.02 } * peak,
                    "sigma {sigma} at {at:?}: {worst} of {peak}"
                );
                assert!((total - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-4);
            }
        }
    }

    #[test]
    fn blur_spreads_a_point_into_a_gaussian() {
        let (w, h) = (61, 61);
        let mut img = vec![Vec3::ZERO; w * h];
        img[30 * w + 30] = Vec3::ONE;
        let b = blur(&img, w, h, 3.0);
        // Second moment along x equals sigma^2.
        let m2: f32 = (0..w)
            .map(|x| b[30 * w + x].x * ((x as f32 - 30.0).powi(2)))
            .sum::<f32>()
            / (0..w).map(|x| b[30 * w + x].x).sum::<f32>();
        // The kernel is cut at 3 sigma, which trims the variance by ~2%.
        let k = kernel(3.0);
        let r = (k.len() / 2) as f32;
        let want: f32 = k
            .iter()
            .enumerate()
            .map(|(i, w)| w * (i as f32 - r).powi(2))
            .sum();
        assert!((m2 - want).abs() < 1e-3, "{m2} vs {want}");
        assert!((want - 9.0).abs() < 0.3);
    }

    #[test]
    fn bloom_keeps_the_total_within_one_percent() {
        let (w, h) = (64, 48);
        let mut xyz = vec![Vec3::splat(0.01); w * h];
        for i in (0..w * h).step_by(97) {
            xyz[i] = Vec3::new(20.0, 25.0, 30.0);
        }
        let film = film(w, h, xyz.clone());
        let before: Vec3 = xyz.iter().copied().sum();
        for shape in [BloomShape::Gaussian, BloomShape::Halo] {
            let terms = bloom_terms(&config(0.3, 5.0 / 48.0 / 4.0, shape));
            let out = bloom(&film, &terms);
            let after: Vec3 = out.iter().copied().sum();
            assert!(
                ((after - before) / before).abs().max_element() < 1e-4,
                "{shape:?}"
            );
            // And it does spread: the peak drops.
            assert!(out[0].y < 25.0);
        }
    }

    fn config(strength: f64, radius: f64, shape: BloomShape) -> BloomConfig {
        BloomConfig {
            strength,
            radius,
            shape,
            spectral: false,
            exr: false,
        }
    }

    /// A film `w` x `h` of XYZ values `xyz`.
    fn film(w: usize, h: usize, xyz: Vec<Vec3>) -> Film {
        Film {
            width: w as u32,
            height: h as u32,
            xyz,
            nm: vec![],
            frequencies: vec![],
            spectra: None,
            bands: None,
            bloomed: None,
            observables: Vec::new(),
        }
    }

    /// A film `w` x `h` of black with one point of `flux` at its centre.
    fn point(w: usize, h: usize, flux: f32) -> Film {
        let mut xyz = vec![Vec3::ZERO; w * h];
        xyz[(h / 2) * w + w / 2] = Vec3::splat(flux);
        film(w, h, xyz)
    }

    #[test]
    fn a_halo_is_octaves_of_gaussians_halving_in_weight() {
        let t = bloom_terms(&config(0.2, 0.01, BloomShape::Halo));
        let sigmas: Vec<f64> = t.iter().map(|t| t.sigma).collect();
        assert_eq!(sigmas, [0.01, 0.02, 0.04, 0.08]);
        let total: f32 = t.iter().map(|t| t.keep + t.weight).sum();
        assert!((total - 1.0).abs() < 1e-6);
        assert_eq!(t[0].keep, 0.8);
        for p in t.windows(2) {
            assert!((p[1].weight / p[0].weight - 0.5).abs() < 1e-6);
        }
        // The Gaussian: one term, as bloom always was.
        let g = bloom_terms(&config(0.2, 0.03, BloomShape::Gaussian));
        assert_eq!(
            g,
            [BloomTerm {
                keep: 0.8,
                weight: 0.2,
                sigma: 0.03
            }]
        );
    }

    #[test]
    fn a_halo_falls_as_the_cube_of_the_distance() {
        // Sigmas of 1, 2 ... 32 pixels: between about 3 and 40 pixels the
        // halo's light goes as r^-3 (the scale mixture of Gaussians of
        // weight 1 / sigma), with a ripple of the octaves' spacing. The
        // profile against the closed form of the mixture, and its slope.
        let (w, h) = (257, 400);
        let terms = bloom_terms(&config(1.0, 1.0 / h as f64, BloomShape::Halo));
        assert_eq!(terms.len(), 6);
        let out = bloom(&point(w, h, 1.0), &terms);
        let row = &out[(h / 2) * w..(h / 2 + 1) * w];
        let exact = |r: f64| -> f64 {
            terms
                .iter()
                .map(|t| {
                    let s = t.sigma * h as f64;
                    t.weight as f64 / (2.0 * std::f64::consts::PI * s * s)
                        * (-r * r / (2.0 * s * s)).exp()
                })
                .sum()
        };
        for r in [3usize, 5, 8, 12, 20, 30] {
            let got = row[w / 2 + r].y as f64;
            eprintln!(
                "halo at {r} px: {:+.4} of the mixture's closed form",
                got / exact(r as f64) - 1.0
            );
            assert!(
                (got / exact(r as f64) - 1.0).abs() < 0.03,
                "r = {r}: {got} vs {}",
                exact(r as f64)
            );
        }
        // Over a factor 8 in distance, the light falls by 8^3 within 15%.
        let fall = row[w / 2 + 4].y as f64 / row[w / 2 + 32].y as f64;
        eprintln!("halo: light at 4 px over 32 px {fall:.1} (8^3 = 512)");
        assert!((fall / 512.0 - 1.0).abs() < 0.15, "{fall}");
    }

    #[test]
    fn with_a_halo_a_brighter_star_looks_bigger_as_the_cube_root_of_its_flux() {
        // The radius where a point's bloomed light falls below a level:
        // with the halo, ten times the flux reaches 10^(1/3) = 2.15 times
        // as far (the r^-3 wings); with one Gaussian of the same inner
        // sigma hardly further (sqrt of the log of the flux).
        let (w, h) = (401, 400);
        let reach = |shape: BloomShape, flux: f32| -> usize {
            let terms = bloom_terms(&config(0.5, 1.0 / h as f64, shape));
            let out = bloom(&point(w, h, flux), &terms);
            let row = &out[(h / 2) * w..(h / 2 + 1) * w];
            (0..w / 2)
                .rev()
                .find(|&r| row[w / 2 + r].y >= 1e-4)
                .unwrap_or(0)
        };
        let (near, far) = (reach(BloomShape::Halo, 1.0), reach(BloomShape::Halo, 10.0));
        let ratio = far as f64 / near as f64;
        let (gn, gf) = (
            reach(BloomShape::Gaussian, 1.0),
            reach(BloomShape::Gaussian, 10.0),
        );
        eprintln!("reach of flux 1 and 10: halo {near} and {far} px, Gaussian {gn} and {gf} px");
        assert!(
            near >= 4 && (ratio - 10f64.cbrt()).abs() < 0.2,
            "{near} {far}"
        );
        assert!(gf as f64 / (gn as f64) < 1.4, "{gn} {gf}");
    }

    #[test]
    fn anaglyph_takes_red_from_the_left_eye() {
        assert_eq!(anaglyph(&[10, 20, 30], &[40, 50, 60]), vec![10, 50, 60]);
        assert_eq!(
            side_by_side(1, 1, &[1, 2, 3], &[4, 5, 6]),
            vec![1, 2, 3, 4, 5, 6]
        );
    }
}
