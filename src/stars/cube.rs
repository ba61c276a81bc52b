//! Equi-angular cube-map cells on the unit sphere.
//!
//! Face `f = 2 a + s` looks along axis `a` (0 = x, 1 = y, 2 = z), towards
//! +a for `s = 0` and -a for `s = 1`. On it a direction p has components
//! `pu = p[(a + 1) % 3]`, `pv = p[(a + 2) % 3]` and `pa = ±p[a]`, and face
//! coordinates `x = atan2(pu, pa) / (pi/4)`, `y = atan2(pv, pa) / (pi/4)`,
//! both in [-1, 1]. Equal steps of x and y are equal angles around the
//! face's v and u axes, so cells vary in solid angle by a factor of about
//! 1.4 across a face (a plain cube map's gnomonic cells: 5.2), and every
//! cell edge is a great-circle arc.
//!
//! At level l a face has n = 2^l cells a side; cell (i, j) holds
//! x in [2i/n - 1, 2(i+1)/n - 1) and likewise j for y. Cells are numbered
//! face by face, in Morton (Z) order within a face:
//! `id = f * 4^l + morton(i, j)`, so the four children of cell k of level
//! l are cells 4k .. 4k+3 of level l + 1, and a cell's descendants at any
//! finer level are one contiguous run of ids.

use glam::DVec3;
use std::f64::consts::FRAC_PI_4;

/// The face a direction falls on and its face coordinates (x, y) in
/// [-1, 1]; `p` need not be unit length.
#[inline]
pub fn face_coords(p: DVec3) -> (u32, f64, f64) {
    let (ax, ay, az) = (p.x.abs(), p.y.abs(), p.z.abs());
    let a = if ax >= ay && ax >= az {
        0
    } else if ay >= az {
        1
    } else {
        2
    };
    let f = 2 * a + u32::from(p[a as usize] < 0.0);
    let (pu, pv, pa) = components(p, f);
    (f, pu.atan2(pa) / FRAC_PI_4, pv.atan2(pa) / FRAC_PI_4)
}

/// A direction's (u, v, a) components in face `f`'s frame.
#[inline]
fn components(p: DVec3, f: u32) -> (f64, f64, f64) {
    let a = (f / 2) as usize;
    let pa = if f.is_multiple_of(2) { p[a] } else { -p[a] };
    (p[(a + 1) % 3], p[(a + 2) % 3], pa)
}

/// The unit direction at face coordinates (x, y) of face `f`; x and y may
/// reach a little past [-1, 1] (up to |x| < 2), onto the neighbouring face.
#[inline]
pub fn face_dir(f: u32, x: f64, y: f64) -> DVec3 {
    let a = (f / 2) as usize;
    let mut p = DVec3::ZERO;
    p[a] = if f.is_multiple_of(2) { 1.0 } else { -1.0 };
    p[(a + 1) % 3] = (x * FRAC_PI_4).tan();
    p[(a + 2) % 3] = (y * FRAC_PI_4).tan();
    p.normalize()
}

/// The cell index (0 .. n) of face coordinate `x` at `n` cells a side.
#[inline]
pub fn cell_of(x: f64, n: u32) -> u32 {
    (((x + 1.0) * 0.5 * n as f64).floor().max(0.0) as u32).min(n - 1)
}

/// The id of the cell of level `level` holding direction `p`.
#[inline]
pub fn cell_id(p: DVec3, level: u32) -> u32 {
    let (f, x, y) = face_coords(p);
    let n = 1 << level;
    (f << (2 * level)) | morton(cell_of(x, n), cell_of(y, n))
}

/// Interleaves the bits of i (even bits) and j (odd bits), each < 2^16.
#[inline]
pub fn morton(i: u32, j: u32) -> u32 {
    fn spread(mut v: u32) -> u32 {
        v &= 0xffff;
        v = (v | (v << 8)) & 0x00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    }
    spread(i) | (spread(j) << 1)
}

/// The inverse of [`morton`].
#[inline]
pub fn unmorton(m: u32) -> (u32, u32) {
    fn squeeze(mut v: u32) -> u32 {
        v &= 0x5555_5555;
        v = (v | (v >> 1)) & 0x3333_3333;
        v = (v | (v >> 2)) & 0x0f0f_0f0f;
        v = (v | (v >> 4)) & 0x00ff_00ff;
        (v | (v >> 8)) & 0xffff
    }
    (squeeze(m), squeeze(m >> 1))
}

/// Face, i, j of cell `id` of level `level`.
#[inline]
pub fn cell_parts(id: u32, level: u32) -> (u32, u32, u32) {
    let (i, j) = unmorton(id & ((1 << (2 * level)) - 1));
    (id >> (2 * level), i, j)
}

/// The face coordinates of a cell's edges: (x0, x1, y0, y1).
#[inline]
pub fn cell_bounds(i: u32, j: u32, level: u32) -> (f64, f64, f64, f64) {
    let h = 2.0 / (1u32 << level) as f64;
    (
        i as f64 * h - 1.0,
        (i + 1) as f64 * h - 1.0,
        j as f64 * h - 1.0,
        (j + 1) as f64 * h - 1.0,
    )
}

/// Solid angle (sr) of cell (i, j) of level `level` on any face.
pub fn cell_solid_angle(i: u32, j: u32, level: u32) -> f64 {
    let (x0, x1, y0, y1) = cell_bounds(i, j, level);
    let t = |x: f64| (x * FRAC_PI_4).tan();
    // The solid angle of the gnomonic rectangle [0, u] x [0, v] is
    // atan(uv / sqrt(1 + u^2 + v^2)); a rectangle is four of them, signed.
    let g = |u: f64, v: f64| (u * v / (1.0 + u * u + v * v).sqrt()).atan();
    let (u0, u1, v0, v1) = (t(x0), t(x1), t(y0), t(y1));
    g(u1, v1) - g(u0, v1) - g(u1, v0) + g(u0, v0)
}

/// The four corner directions of cell (i, j) of level `level` on face `f`.
pub fn cell_corners(f: u32, i: u32, j: u32, level: u32) -> [DVec3; 4] {
    let (x0, x1, y0, y1) = cell_bounds(i, j, level);
    [
        face_dir(f, x0, y0),
        face_dir(f, x1, y0),
        face_dir(f, x0, y1),
        face_dir(f, x1, y1),
    ]
}

/// The range of one face coordinate (in [-1, 1]) that a cap reaches:
/// `cu`, `ca` are the cap centre's components along the coordinate's own
/// axis and the face's axis, `sin_r` the sine of its radius (< pi/2). The
/// coordinate is a longitude around the third axis; a cap whose centre is
/// at polar angle theta from that axis spans longitudes within
/// asin(sin r / sin theta) of its centre's, unless it holds the axis.
#[inline]
fn coordinate_range(cu: f64, ca: f64, sin_r: f64) -> Option<(f64, f64)> {
    let rho = cu.hypot(ca);
    if rho <= sin_r {
        return Some((-1.0, 1.0));
    }
    let mid = cu.atan2(ca);
    let half = (sin_r / rho).min(1.0).asin();
    // mid is in [-pi, pi] and half <= pi/2: the interval never wraps onto
    // the face from the other side of the circle.
    let (lo, hi) = (mid - half, mid + half);
    (hi >= -FRAC_PI_4 && lo <= FRAC_PI_4)
        .then(|| ((lo / FRAC_PI_4).max(-1.0), (hi / FRAC_PI_4).min(1.0)))
}

/// The face coordinates a cap can reach, face by face: computed once
/// for a query and read at any level.
#[derive(Clone, Copy, Debug)]
pub struct CapFaces {
    /// Per face, the box (x0, x1, y0, y1) of face coordinates holding
    /// every point of the cap on that face; None where the cap misses it.
    pub ranges: [Option<[f64; 4]>; 6],
}

impl CapFaces {
    /// The faces a cap of angular radius `r` around unit `c` reaches: a
    /// conservative box per face (every point of the cap on the face is in
    /// it). A cap of radius pi/2 or more takes every face it reaches whole.
    pub fn new(c: DVec3, r: f64) -> CapFaces {
        // Every point of a face is within acos(1/sqrt 3) of its axis (the
        // corners): a cap farther than that plus its radius misses the face.
        const CORNER: f64 = 0.955_316_618_124_509_3;
        let near = if r + CORNER < std::f64::consts::PI {
            (r + CORNER).cos() - 1e-12
        } else {
            -1.0
        };
        let sin_r = r.sin();
        let mut ranges = [None; 6];
        for (f, range) in ranges.iter_mut().enumerate() {
            let (cu, cv, ca) = components(c, f as u32);
            if ca < near {
                continue;
            }
            *range = if r >= std::f64::consts::FRAC_PI_2 {
                Some([-1.0, 1.0, -1.0, 1.0])
            } else {
                match (
                    coordinate_range(cu, ca, sin_r),
                    coordinate_range(cv, ca, sin_r),
                ) {
                    (Some((x0, x1)), Some((y0, y1))) => Some([x0, x1, y0, y1]),
                    _ => None,
                }
            };
        }
        CapFaces { ranges }
    }

    /// The cells (i0, i1, j0, j1), inclusive, of face `f` at `n` cells a
    /// side that the cap can touch.
    #[inline]
    pub fn cells(&self, f: u32, n: u32) -> Option<(u32, u32, u32, u32)> {
        self.ranges[f as usize].map(|[x0, x1, y0, y1]| {
            (
                cell_of(x0, n),
                cell_of(x1, n),
                cell_of(y0, n),
                cell_of(y1, n),
            )
        })
    }
}

/// The cells (i0, i1, j0, j1), inclusive, of face `f` at `n` cells a side
/// that a cap of angular radius `r` around unit `c` can touch (see
/// [`CapFaces`]).
pub fn cap_box(c: DVec3, r: f64, f: u32, n: u32) -> Option<(u32, u32, u32, u32)> {
    CapFaces::new(c, r).cells(f, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn random_dirs(n: usize, seed: u64) -> Vec<DVec3> {
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_add(0x9e37_79b9_7f4a_7c15);
            (crate::sampling::mix(s) >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let z = 2.0 * next() - 1.0;
                let phi = 2.0 * PI * next();
                let r = (1.0 - z * z).sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn coordinates_round_trip_and_morton_inverts() {
        for p in random_dirs(1000, 1) {
            let (f, x, y) = face_coords(p);
            assert!(x.abs() <= 1.0 && y.abs() <= 1.0);
            assert!((face_dir(f, x, y) - p).length() < 1e-14, "{p}");
        }
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1023, 77), (65535, 65535)] {
            assert_eq!(unmorton(morton(i, j)), (i, j));
        }
        // Children of cell k are 4k .. 4k+3.
        let p = DVec3::new(0.3, -0.8, 0.2).normalize();
        for l in 0..10 {
            assert_eq!(cell_id(p, l + 1) / 4, cell_id(p, l));
        }
    }

    #[test]
    fn cells_tile_the_sphere_in_solid_angle() {
        for level in [0, 1, 3, 6] {
            let n = 1u32 << level;
            let total: f64 = (0..n)
                .flat_map(|i| (0..n).map(move |j| cell_solid_angle(i, j, level)))
                .sum();
            assert!((6.0 * total - 4.0 * PI).abs() < 1e-12, "{level}: {total}");
        }
        // Equi-angular: the largest cell is about 1.4 times the smallest.
        let (a, b) = (cell_solid_angle(0, 0, 6), cell_solid_angle(31, 31, 6));
        assert!((1.2..1.5).contains(&(b / a)), "{}", b / a);
    }

    #[test]
    fn cap_box_holds_every_point_of_the_cap() {
        // Points on the cap's rim (the farthest a cap reaches) fall in the
        // box of their face.
        let n = 64;
        for (k, c) in random_dirs(300, 2).into_iter().enumerate() {
            let r: f64 = [1e-5, 0.01, 0.2, 0.7, 1.4][k % 5];
            let e1 = c.any_orthonormal_vector();
            let e2 = c.cross(e1);
            for t in 0..256 {
                let a = 2.0 * PI * t as f64 / 256.0;
                let p = c * r.cos() + (e1 * a.cos() + e2 * a.sin()) * r.sin() * (1.0 - 1e-12);
                let (f, x, y) = face_coords(p);
                let (i0, i1, j0, j1) = cap_box(c, r, f, n).expect("face missed");
                let (i, j) = (cell_of(x, n), cell_of(y, n));
                assert!((i0..=i1).contains(&i) && (j0..=j1).contains(&j), "{c} {r}");
            }
        }
    }
}
