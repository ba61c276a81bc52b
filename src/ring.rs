//! The ring of an image of a hole's surroundings, measured as the Event
//! Horizon Telescope's image-domain feature extraction does (the "REx"
//! ring extractor of Chael et al. 2019 and the EHT's M87* paper IV): from
//! a trial centre, the brightness's peak along rays at evenly spaced
//! position angles; the centre is the one about which those peaks lie
//! closest to a circle, and the diameter twice their mean distance.

/// A ring found in an image, in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ring {
    /// Its centre (x right, y down, pixel centres at whole numbers + 0.5).
    pub center: (f64, f64),
    /// Twice the mean distance of the peaks from the centre.
    pub diameter: f64,
    /// The peaks' spread about that circle (standard deviation of their
    /// distances).
    pub spread: f64,
}

/// Position angles the peaks are sought along.
const ANGLES: usize = 72;
/// Steps along each ray, per pixel.
const PER_PIXEL: f64 = 4.0;

/// The ring of the row-major image `values` (`width` x `height`), or None
/// where it has no brightness or no peak away from every trial centre.
pub fn find(values: &[f32], width: usize, height: usize) -> Option<Ring> {
    let total: f64 = values.iter().map(|&v| v.max(0.0) as f64).sum();
    if !(total > 0.0) {
        return None;
    }
    // The brightness's centroid starts the search.
    let (mut cx, mut cy) = (0.0, 0.0);
    for (i, &v) in values.iter().enumerate() {
        let v = v.max(0.0) as f64;
        cx += v * ((i % width) as f64 + 0.5);
        cy += v * ((i / width) as f64 + 0.5);
    }
    let mut best = ring_about(values, width, height, (cx / total, cy / total))?;
    // A coarse grid about it, then finer ones about the best.
    let reach = 0.15 * width.min(height) as f64;
    for (span, step) in [(reach, 1.0), (1.5, 0.25), (0.4, 0.05)] {
        let c0 = best.center;
        let n = (span / step).round() as i32;
        for i in -n..=n {
            for j in -n..=n {
                let c = (c0.0 + i as f64 * step, c0.1 + j as f64 * step);
                if let Some(r) = ring_about(values, width, height, c)
                    && r.spread < best.spread
                {
                    best = r;
                }
            }
        }
    }
    Some(best)
}

/// The peaks about `center` and the circle they make.
fn ring_about(values: &[f32], width: usize, height: usize, center: (f64, f64)) -> Option<Ring> {
    let reach = 0.5 * width.min(height) as f64;
    let steps = (reach * PER_PIXEL) as usize;
    let mut radii = [0.0f64; ANGLES];
    for (k, radius) in radii.iter_mut().enumerate() {
        let a = std::f64::consts::TAU * k as f64 / ANGLES as f64;
        let (dx, dy) = (a.cos() / PER_PIXEL, a.sin() / PER_PIXEL);
        let at = |i: usize| {
            bilinear(
                values,
                width,
                height,
                center.0 + dx * i as f64,
                center.1 + dy * i as f64,
            )
        };
        let (mut peak, mut value) = (0, f64::NEG_INFINITY);
        for i in 1..steps {
            let v = at(i);
            if v > value {
                (peak, value) = (i, v);
            }
        }
        if peak < 2 || peak + 1 >= steps {
            return None;
        }
        // The parabola through the peak and its neighbours.
        let (l, m, r) = (at(peak - 1), value, at(peak + 1));
        let curve = l - 2.0 * m + r;
        let shift = if curve < 0.0 {
            0.5 * (l - r) / curve
        } else {
            0.0
        };
        *radius = (peak as f64 + shift) / PER_PIXEL;
    }
    let mean = radii.iter().sum::<f64>() / ANGLES as f64;
    let var = radii.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / ANGLES as f64;
    Some(Ring {
        center,
        diameter: 2.0 * mean,
        spread: var.sqrt(),
    })
}

/// The image at (x, y) (pixel centres at whole numbers + 0.5), nil
/// outside it.
fn bilinear(values: &[f32], width: usize, height: usize, x: f64, y: f64) -> f64 {
    let (u, v) = (x - 0.5, y - 0.5);
    let (i, j) = (u.floor(), v.floor());
    let (fu, fv) = (u - i, v - j);
    let get = |a: f64, b: f64| -> f64 {
        if a < 0.0 || b < 0.0 || a >= width as f64 || b >= height as f64 {
            0.0
        } else {
            values[b as usize * width + a as usize] as f64
        }
    };
    (1.0 - fv) * ((1.0 - fu) * get(i, j) + fu * get(i + 1.0, j))
        + fv * ((1.0 - fu) * get(i, j + 1.0) + fu * get(i + 1.0, j + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Gaussian ring of radius `r` and width `sigma` about `c`, its
    /// brightness varying with position angle as 1 + `lopsided` cos.
    fn ring_image(
        w: usize,
        h: usize,
        c: (f64, f64),
        r: f64,
        sigma: f64,
        lopsided: f64,
    ) -> Vec<f32> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 + 0.5 - c.0, (i / w) as f64 + 0.5 - c.1);
                let d = (x * x + y * y).sqrt();
                let a = y.atan2(x);
                ((1.0 + lopsided * a.cos()) * (-0.5 * ((d - r) / sigma).powi(2)).exp()) as f32
            })
            .collect()
    }

    #[test]
    fn finds_a_ring_off_centre_and_lopsided() {
        // A crescent (bright on one side, as Doppler boosting makes it) off
        // the image's centre: its centre within 0.1 px, diameter within
        // 0.1 px.
        let (c, r, sigma) = ((33.3, 30.7), 14.0, 2.0);
        let img = ring_image(64, 64, c, r, sigma, 0.7);
        let ring = find(&img, 64, 64).unwrap();
        let want = 2.0 * r;
        assert!(
            (ring.center.0 - c.0).abs() < 0.1 && (ring.center.1 - c.1).abs() < 0.1,
            "{ring:?}"
        );
        assert!(
            (ring.diameter - want).abs() < 0.1,
            "{ring:?} against {want}"
        );
        assert!(find(&vec![0.0; 64 * 64], 64, 64).is_none());
    }
}
