//! Mip pyramids: each level the area average of the one before, in
//! premultiplied channels (so transparent texels lend no colour).
//!
//! Level k is w >> k by h >> k texels (at least 1): for even sides each
//! texel averages a 2 x 2 block; otherwise each averages the area its
//! rectangle covers, partial texels by their covered fraction, so every
//! level keeps the image's mean exactly. Built in f32 one level from the
//! next; the callers store each level in their own format.

use super::ewa::{level_count, level_dims};

/// For each of `n_out` cells spanning `n_in` input cells, the inputs it
/// covers and the fraction of it each covers (summing to 1).
fn taps(n_in: u32, n_out: u32) -> Vec<Vec<(usize, f32)>> {
    let s = n_in as f64 / n_out as f64;
    (0..n_out)
        .map(|i| {
            let (a, b) = (i as f64 * s, (i + 1) as f64 * s);
            let first = a.floor() as usize;
            let last = (b.ceil() as usize).min(n_in as usize);
            (first..last)
                .map(|k| {
                    let cover = (b.min(k as f64 + 1.0) - a.max(k as f64)) / s;
                    (k, cover as f32)
                })
                .filter(|&(_, c)| c > 0.0)
                .collect()
        })
        .collect()
}

/// Runs `f(j, row)` for each `len`-value row of `out`, on scoped threads
/// rather than rayon's pool: a pyramid is built inside a `OnceLock` on the
/// first lookup that needs it, often from a rayon worker, and a worker
/// waiting on rayon work may steal another pixel's task, whose lookup would
/// then wait on the same `OnceLock` held by its own thread (a deadlock).
/// Plain threads only wait.
fn rows_in_parallel(out: &mut [f32], len: usize, f: &(dyn Fn(usize, &mut [f32]) + Sync)) {
    let rows = out.len() / len.max(1);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    // Small levels on the calling thread (a thread costs tens of
    // microseconds).
    if threads == 1 || out.len() < 1 << 16 {
        for (j, row) in out.chunks_mut(len).enumerate() {
            f(j, row);
        }
        return;
    }
    let per = rows.div_ceil(threads);
    std::thread::scope(|scope| {
        for (k, block) in out.chunks_mut(per * len).enumerate() {
            scope.spawn(move || {
                for (j, row) in block.chunks_mut(len).enumerate() {
                    f(k * per + j, row);
                }
            });
        }
    });
}

/// Area-averages a w x h image of `c` interleaved channels, whose row y
/// `row(y, buf)` writes into `buf` (w * c values), to nw x nh.
fn downsample(
    c: usize,
    (w, h): (u32, u32),
    (nw, nh): (u32, u32),
    row: &(dyn Fn(usize, &mut [f32]) + Sync),
) -> Vec<f32> {
    let (tx, ty) = (taps(w, nw), taps(h, nh));
    let mut out = vec![0.0f32; nw as usize * nh as usize * c];
    rows_in_parallel(&mut out, nw as usize * c, &|j, orow| {
        let mut buf = vec![0.0f32; w as usize * c];
        for &(y, wy) in &ty[j] {
            row(y, &mut buf);
            for (o, xs) in orow.chunks_exact_mut(c).zip(&tx) {
                for &(x, wx) in xs {
                    let k = wx * wy;
                    for (o, v) in o.iter_mut().zip(&buf[x * c..(x + 1) * c]) {
                        *o += k * v;
                    }
                }
            }
        }
    });
    out
}

/// Builds levels 1 and up of a w x h image of `c` premultiplied channels
/// (level 0's row y written by `base(y, buf)`), handing each to
/// `store(level, (width, height), channels)` from the finest down.
pub(crate) fn build(
    c: usize,
    (w, h): (u32, u32),
    base: &(dyn Fn(usize, &mut [f32]) + Sync),
    mut store: impl FnMut(usize, (u32, u32), &[f32]),
) {
    let n = level_count(w, h);
    let mut prev: Option<Vec<f32>> = None;
    for k in 1..n {
        let from = level_dims(w, h, k - 1);
        let to = level_dims(w, h, k);
        let level = match &prev {
            None => downsample(c, from, to, base),
            Some(p) => {
                let stride = from.0 as usize * c;
                let row = |y: usize, buf: &mut [f32]| {
                    buf.copy_from_slice(&p[y * stride..(y + 1) * stride])
                };
                downsample(c, from, to, &row)
            }
        };
        store(k, to, &level);
        prev = Some(level);
    }
}

/// Texels (of any stored type) of levels 1 and up, one after another, and
/// where each level starts.
#[derive(Debug)]
pub(crate) struct Levels<T> {
    /// Every level's texels, level 1 first.
    pub data: Vec<T>,
    /// Index in `data` of level k's first texel (entry 0 unused).
    pub offsets: Vec<usize>,
}

impl<T> Levels<T> {
    /// Levels 1 and up of a w x h image of `c` premultiplied channels,
    /// each texel stored as `encode` makes it of its channels.
    pub fn build(
        c: usize,
        (w, h): (u32, u32),
        base: &(dyn Fn(usize, &mut [f32]) + Sync),
        encode: impl Fn(&[f32]) -> T,
    ) -> Levels<T> {
        let n = level_count(w, h);
        let total: usize = (1..n)
            .map(|k| {
                let (a, b) = level_dims(w, h, k);
                a as usize * b as usize
            })
            .sum();
        let mut data = Vec::with_capacity(total);
        let mut offsets = vec![0; n];
        build(c, (w, h), base, |k, _, level| {
            offsets[k] = data.len();
            data.extend(level.chunks_exact(c).map(&encode));
        });
        Levels { data, offsets }
    }

    /// The texels of level k (k >= 1).
    #[inline]
    pub fn level(&self, k: usize) -> &[T] {
        let end = self.offsets.get(k + 1).copied().unwrap_or(self.data.len());
        &self.data[self.offsets[k]..end]
    }
}

/// Texels in levels 1 and up of a w x h image: a third of level 0's at
/// most (a quarter, a sixteenth, ...).
pub fn texel_count(w: u32, h: u32) -> usize {
    (1..level_count(w, h))
        .map(|k| {
            let (a, b) = level_dims(w, h, k);
            a as usize * b as usize
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_cover_each_input_once() {
        for (n_in, n_out) in [(8, 4), (5, 2), (7, 3), (2, 1), (1, 1), (3, 1)] {
            let t = taps(n_in, n_out);
            let mut per_input = vec![0.0f32; n_in as usize];
            for cell in &t {
                let s: f32 = cell.iter().map(|c| c.1).sum();
                assert!((s - 1.0).abs() < 1e-6, "{n_in}->{n_out}: {s}");
                for &(k, c) in cell {
                    per_input[k] += c;
                }
            }
            // Each input's total share is n_out / n_in: the mean is kept.
            for p in per_input {
                assert!((p - n_out as f32 / n_in as f32).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn levels_average_two_by_two_blocks_and_keep_the_mean() {
        let (w, h) = (8u32, 4u32);
        let img: Vec<f32> = (0..w * h).map(|i| (i * i % 13) as f32).collect();
        let base = |y: usize, buf: &mut [f32]| {
            buf.copy_from_slice(&img[y * w as usize..(y + 1) * w as usize])
        };
        let l = Levels::build(1, (w, h), &base, |c| c[0]);
        assert_eq!(l.offsets.len(), 4);
        let l1 = l.level(1);
        assert_eq!(l1.len(), 8);
        let want = (img[0] + img[1] + img[8] + img[9]) / 4.0;
        assert!((l1[0] - want).abs() < 1e-6);
        let mean = img.iter().sum::<f32>() / img.len() as f32;
        for k in 1..4 {
            let lv = l.level(k);
            let m = lv.iter().sum::<f32>() / lv.len() as f32;
            assert!((m - mean).abs() < 1e-4, "level {k}: {m} vs {mean}");
        }
        assert_eq!(l.level(3).len(), 1);
        assert_eq!(texel_count(w, h), l.data.len());
        // Odd sides keep the mean too.
        let (w, h) = (5u32, 3u32);
        let img: Vec<f32> = (0..w * h).map(|i| (i % 4) as f32).collect();
        let base = |y: usize, buf: &mut [f32]| {
            buf.copy_from_slice(&img[y * w as usize..(y + 1) * w as usize])
        };
        let l = Levels::build(1, (w, h), &base, |c| c[0]);
        let mean = img.iter().sum::<f32>() / img.len() as f32;
        for k in 1..3 {
            let lv = l.level(k);
            let m = lv.iter().sum::<f32>() / lv.len() as f32;
            assert!((m - mean).abs() < 1e-5, "level {k}: {m} vs {mean}");
        }
    }
}
