//! Sample positions in a pixel, seeded from (image seed, pixel, sample
//! index) alone so that the image does not depend on the thread count or
//! the backend.

/// SplitMix64 finaliser: a well-mixed 64-bit hash.
#[inline]
pub fn mix(mut z: u64) -> u64 {
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

/// A nested uniform (Owen) scramble of the bits of `v`, keyed by `key`:
/// each bit is flipped according to the key and the bits above it, so a
/// stratified set of points stays stratified. The hash of Laine and Karras
/// (2011), in the form Burley (2020) gives, works on the reversed bits
/// (where multiplying by an even number only carries upwards).
fn owen_scramble(v: u32, key: u32) -> u32 {
    let mut x = v.reverse_bits();
    x = x.wrapping_add(key);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x.reverse_bits()
}

/// The first two dimensions of the Sobol sequence at index `i`, as 32-bit
/// fractions: the base-2 radical inverse, and the dimension whose
/// direction numbers come from the polynomial x + 1. Together a
/// (0, 2)-sequence: its first 2^k points put one point in each of the 2^k
/// cells of every grid of 2^a x 2^b cells with a + b = k.
fn sobol2(i: u32) -> (u32, u32) {
    let (mut y, mut v, mut k) = (0u32, 1u32 << 31, i);
    while k != 0 {
        if k & 1 != 0 {
            y ^= v;
        }
        k >>= 1;
        v ^= v >> 1;
    }
    (i.reverse_bits(), y)
}

/// Offset in [0, 1)^2 of a pixel's extra sample `j` (adaptive sampling):
/// point `j` of the pixel's own scrambled (0, 2)-sequence, so that any
/// first 4^k of them fill a 2^k x 2^k grid, one in each cell, whatever
/// count the refinement stops at. Seeded from (image seed, pixel) alone.
pub fn refine_offset(seed: u64, pixel: u64, j: u32) -> (f64, f64) {
    let h = mix(mix(seed ^ 0x5851_f42d_4c95_7f2d).wrapping_add(pixel));
    let (x, y) = sobol2(j);
    let (x, y) = (
        owen_scramble(x, h as u32),
        owen_scramble(y, (h >> 32) as u32),
    );
    // Centre of the 2^-32 cell: never exactly 0 or 1.
    let f = |v: u32| (v as f64 + 0.5) / 4_294_967_296.0;
    (f(x), f(y))
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

    #[test]
    fn refinement_points_are_stratified_at_every_power_of_two() {
        for pixel in [0u64, 7, 123_456] {
            for k in 0..=6u32 {
                let n = 1u32 << k;
                // Every grid of 2^a x 2^b cells with a + b = k: one point each.
                for a in 0..=k {
                    let (cols, rows) = (1usize << a, 1usize << (k - a));
                    let mut seen = vec![false; n as usize];
                    for j in 0..n {
                        let (x, y) = refine_offset(3, pixel, j);
                        assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                        let cell = (y * rows as f64) as usize * cols + (x * cols as f64) as usize;
                        assert!(!seen[cell], "pixel {pixel}, {n} points, {cols}x{rows} grid");
                        seen[cell] = true;
                    }
                }
            }
        }
        assert_ne!(refine_offset(3, 5, 0), refine_offset(3, 6, 0));
        assert_ne!(refine_offset(3, 5, 0), refine_offset(4, 5, 0));
    }
}
