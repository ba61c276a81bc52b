//! Sample positions in a pixel, seeded from (image seed, pixel, sample
//! index) alone so that the image does not depend on the thread count or
//! the backend.

/// SplitMix64 finaliser: a well-mixed 64-bit hash.
#[inline]
pub(crate) fn mix(mut z: u64) -> u64 {
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
