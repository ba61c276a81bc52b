//! Post-processing on the linear film: bloom, and stereo composites.

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
pub fn blur(img: &[Vec3], w: usize, h: usize, sigma: f64) -> Vec<Vec3> {
    if sigma <= 0.0 {
        return img.to_vec();
    }
    let k = kernel(sigma);
    let rows = pass(img, w, h, &k, false);
    pass(&rows, w, h, &k, true)
}

/// Bloom: (1 - strength) x image + strength x blurred image, on linear XYZ.
/// With per-band XYZ (spectral bloom) each wavelength band is spread with a
/// sigma proportional to its wavelength (`sigma` at 550 nm), as the width of
/// a diffraction pattern grows with wavelength.
pub fn bloom(film: &Film, strength: f32, sigma: f64) -> Vec<Vec3> {
    let (w, h) = (film.width as usize, film.height as usize);
    let mix = |a: Vec3, b: Vec3| a * (1.0 - strength) + b * strength;
    match &film.bands {
        Some(bands) => {
            let mut total = vec![Vec3::ZERO; w * h];
            for (centre, plane) in bands {
                let spread = blur(plane, w, h, sigma * centre / 550.0);
                for ((t, a), b) in total.iter_mut().zip(plane).zip(spread) {
                    *t += mix(*a, b);
                }
            }
            total
        }
        None => {
            let mut out = blur(&film.xyz, w, h, sigma);
            for (b, a) in out.iter_mut().zip(&film.xyz) {
                *b = mix(*a, *b);
            }
            out
        }
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
        let film = Film {
            width: w as u32,
            height: h as u32,
            xyz: xyz.clone(),
            nm: vec![],
            frequencies: vec![],
            spectra: None,
            bands: None,
            bloomed: None,
            observables: Vec::new(),
        };
        let before: Vec3 = xyz.iter().copied().sum();
        let after: Vec3 = bloom(&film, 0.3, 5.0).iter().copied().sum();
        assert!(((after - before) / before).abs().max_element() < 0.01);
        // And it does spread: the peak drops.
        assert!(bloom(&film, 0.3, 5.0)[0].y < 25.0);
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
