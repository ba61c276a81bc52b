//! Per-sample integrator and the parallel driver.
//!
//! A pixel sample flows: seed from (image seed, pixel, sample index) ->
//! position in the pixel -> camera ray -> trace -> radiance, averaged with a
//! box filter. Seeding from the pixel makes the image independent of thread
//! count and scheduling.

use crate::config::AlphaMode;
use crate::physics::{End, Flow, Segment};
use crate::scene::Scene;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Scene-linear RGB (sRGB primaries, D65) per pixel, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Film {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels.
    pub pixels: Vec<Vec3>,
}

/// Counts gathered while rendering.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stats {
    /// Rays traced.
    pub rays: u64,
    /// Accepted integration steps over all rays.
    pub steps: u64,
    /// Rays that fell into the hole.
    pub captured: u64,
    /// Rays that ended on the disk.
    pub disk: u64,
    /// Rays that reached the sky.
    pub sky: u64,
    /// Rays abandoned (step limit or non-finite state), drawn black.
    pub abandoned: u64,
}

impl std::ops::Add for Stats {
    type Output = Stats;
    fn add(self, o: Stats) -> Stats {
        Stats {
            rays: self.rays + o.rays,
            steps: self.steps + o.steps,
            captured: self.captured + o.captured,
            disk: self.disk + o.disk,
            sky: self.sky + o.sky,
            abandoned: self.abandoned + o.abandoned,
        }
    }
}

/// SplitMix64 finaliser: a well-mixed 64-bit hash.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Deterministic uniform numbers for one (pixel, sample).
struct Rng(u64);

impl Rng {
    fn new(seed: u64, pixel: u64, sample: u64) -> Rng {
        Rng(mix(mix(seed ^ 0x9e37_79b9_7f4a_7c15).wrapping_add(pixel)).wrapping_add(mix(sample)))
    }
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        (mix(self.0) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Kensler's hash-based permutation of 0..len (no allocation), keyed by `key`.
fn permute(mut i: u32, len: u32, key: u32) -> u32 {
    let mut w = len - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= key;
        i = i.wrapping_mul(0xe170_893d);
        i ^= key >> 16;
        i ^= (i & w) >> 4;
        i ^= key >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= key >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | key >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < len {
            return (i.wrapping_add(key)) % len;
        }
    }
}

/// Offset in [0, 1)^2 of sample `i` of `n` in a pixel: the centre for one
/// sample, a jittered grid when n is a square, else Latin-hypercube strata
/// with a per-pixel permutation.
pub fn sample_offset(seed: u64, pixel: u64, i: u32, n: u32) -> (f64, f64) {
    if n == 1 {
        return (0.5, 0.5);
    }
    let mut rng = Rng::new(seed, pixel, i as u64);
    let (jx, jy) = (rng.next_f64(), rng.next_f64());
    let k = (n as f64).sqrt().round() as u32;
    if k * k == n {
        let (cx, cy) = (i % k, i / k);
        ((cx as f64 + jx) / k as f64, (cy as f64 + jy) / k as f64)
    } else {
        let key = mix(seed ^ pixel.wrapping_mul(0x2545_f491_4f6c_dd1d)) as u32;
        let row = permute(i, n, key);
        ((i as f64 + jx) / n as f64, (row as f64 + jy) / n as f64)
    }
}

impl Scene {
    /// Radiance arriving at the camera along image point (`px`, `py`), and
    /// how its ray ended.
    pub fn radiance(&self, px: f64, py: f64) -> (Vec3, End, u32) {
        let dir = self.camera.ray_direction(px, py);
        self.trace_from(self.camera.position, dir)
    }

    /// Radiance arriving at `origin` from coordinate direction `dir`.
    pub fn trace_from(&self, origin: DVec3, dir: DVec3) -> (Vec3, End, u32) {
        let mut color = Vec3::ZERO;
        let mut through = 1.0f32;
        let disk = self.disk.as_ref();
        let visit = |seg: &Segment| {
            let Some(disk) = disk else {
                return Flow::Continue;
            };
            let Some(s) = seg.crossing_z0() else {
                return Flow::Continue;
            };
            let Some(t) = disk.sample(seg.point(s)) else {
                return Flow::Continue;
            };
            match disk.alpha {
                AlphaMode::Cutout => {
                    color += through * t.truncate() / t.w;
                    Flow::Stop
                }
                AlphaMode::Blend => {
                    color += through * t.truncate();
                    through *= 1.0 - t.w;
                    if through < 1e-4 {
                        Flow::Stop
                    } else {
                        Flow::Continue
                    }
                }
            }
        };
        let trace = self.model.trace(origin, dir, &self.limits, visit);
        if let End::Escaped(d) = trace.end {
            color += through * self.sky.radiance(d);
        }
        (color, trace.end, trace.steps)
    }

    /// Renders the whole image; `progress` is called with the number of rows
    /// finished since its last call.
    pub fn render(&self, progress: &(dyn Fn(u64) + Sync)) -> (Film, Stats) {
        let (w, h) = (self.camera.width, self.camera.height);
        let n = self.config.image.samples;
        let seed = self.config.image.seed;
        let mut pixels = vec![Vec3::ZERO; w as usize * h as usize];
        let stats = pixels
            .par_chunks_mut(w as usize)
            .enumerate()
            .map(|(y, row)| {
                let mut st = Stats::default();
                for (x, out) in row.iter_mut().enumerate() {
                    let pixel = y as u64 * w as u64 + x as u64;
                    let mut sum = Vec3::ZERO;
                    for i in 0..n {
                        let (ox, oy) = sample_offset(seed, pixel, i, n);
                        let (c, end, steps) = self.radiance(x as f64 + ox, y as f64 + oy);
                        // A non-finite sample is dropped rather than
                        // poisoning the pixel; it is counted as abandoned.
                        let ok = c.is_finite();
                        sum += if ok { c } else { Vec3::ZERO };
                        st.rays += 1;
                        st.steps += steps as u64;
                        match end {
                            _ if !ok => st.abandoned += 1,
                            End::Captured => st.captured += 1,
                            End::Escaped(_) => st.sky += 1,
                            End::Stopped => st.disk += 1,
                            End::Abandoned => st.abandoned += 1,
                        }
                    }
                    *out = sum / n as f32;
                }
                progress(1);
                st
            })
            .reduce(Stats::default, |a, b| a + b);
        (
            Film {
                width: w,
                height: h,
                pixels,
            },
            stats,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_counts_fill_every_cell_once() {
        let n = 16;
        let mut seen = [false; 16];
        for i in 0..n {
            let (x, y) = sample_offset(7, 42, i, n);
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            let cell = (y * 4.0) as usize * 4 + (x * 4.0) as usize;
            assert!(!seen[cell]);
            seen[cell] = true;
        }
    }

    #[test]
    fn other_counts_are_latin_hypercube_strata() {
        for n in [2u32, 3, 5, 7, 12] {
            let mut rows = vec![false; n as usize];
            let mut cols = vec![false; n as usize];
            for i in 0..n {
                let (x, y) = sample_offset(1, 99, i, n);
                let (cx, cy) = ((x * n as f64) as usize, (y * n as f64) as usize);
                assert!(!cols[cx] && !rows[cy], "n={n}");
                cols[cx] = true;
                rows[cy] = true;
            }
        }
    }

    #[test]
    fn offsets_depend_only_on_seed_pixel_and_index() {
        assert_eq!(sample_offset(3, 10, 2, 4), sample_offset(3, 10, 2, 4));
        assert_ne!(sample_offset(3, 10, 2, 4), sample_offset(3, 11, 2, 4));
        assert_eq!(sample_offset(3, 10, 0, 1), (0.5, 0.5));
    }
}
