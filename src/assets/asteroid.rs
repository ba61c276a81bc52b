//! Procedural asteroids: icospheres displaced by fractal Perlin noise,
//! written as OBJ with smooth vertex normals.

use glam::DVec3;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use std::collections::HashMap;
use std::fmt::Write;

/// A unit icosphere: the icosahedron subdivided `level` times
/// (20 * 4^level triangles), counter-clockwise seen from outside.
pub fn icosphere(level: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                (v.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(f.len() * 4);
        for [a, b, c] in f {
            let ab = midpoint(a, b, &mut v);
            let bc = midpoint(b, c, &mut v);
            let ca = midpoint(c, a, &mut v);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = next;
    }
    (v, f)
}

/// An asteroid of mean radius 1: an icosphere at `level`, squashed along
/// two axes and displaced radially by fractal noise of relative amplitude
/// `roughness`.
pub fn asteroid(seed: u32, level: u32, roughness: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (mut v, f) = icosphere(level);
    let shape = Fbm::<Perlin>::new(seed).set_octaves(7).set_frequency(1.1);
    // An elongated body: scale factors from the seed, within [0.6, 1.0].
    let k = |i: u32| {
        0.6 + 0.4 * ((seed.wrapping_mul(2654435761).wrapping_add(i * 40503) >> 8) % 1000) as f64
            / 999.0
    };
    let stretch = DVec3::new(1.0, k(1), k(2));
    for p in v.iter_mut() {
        let n = shape.get((*p * 1.3).to_array());
        *p = *p * stretch * (1.0 + roughness * n);
    }
    (v, f)
}

/// Wavefront OBJ text with smooth vertex normals (area-weighted face
/// normals), fixed formatting for reproducible files.
pub fn to_obj(v: &[DVec3], f: &[[u32; 3]], header: &str) -> String {
    let mut n = vec![DVec3::ZERO; v.len()];
    for &[a, b, c] in f {
        let face = (v[b as usize] - v[a as usize]).cross(v[c as usize] - v[a as usize]);
        for i in [a, b, c] {
            n[i as usize] += face;
        }
    }
    let mut s = String::with_capacity(v.len() * 64 + f.len() * 32);
    let _ = writeln!(s, "# {header}: {} vertices, {} triangles", v.len(), f.len());
    for p in v {
        let _ = writeln!(s, "v {:.6} {:.6} {:.6}", p.x, p.y, p.z);
    }
    for q in &n {
        let q = q.normalize_or_zero();
        let _ = writeln!(s, "vn {:.5} {:.5} {:.5}", q.x, q.y, q.z);
    }
    for &[a, b, c] in f {
        let _ = writeln!(s, "f {0}//{0} {1}//{1} {2}//{2}", a + 1, b + 1, c + 1);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed_and_unit() {
        for level in 0..4 {
            let (v, f) = icosphere(level);
            assert_eq!(f.len(), 20 * 4usize.pow(level));
            // Euler: V - E + F = 2 with E = 3F/2.
            assert_eq!(v.len() as i64 - 3 * f.len() as i64 / 2 + f.len() as i64, 2);
            assert!(v.iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
            // Outward winding.
            for &[a, b, c] in &f {
                let (pa, pb, pc) = (v[a as usize], v[b as usize], v[c as usize]);
                assert!((pb - pa).cross(pc - pa).dot(pa + pb + pc) > 0.0);
            }
        }
    }

    #[test]
    fn asteroids_are_lumpy_and_deterministic() {
        let (a, _) = asteroid(3, 3, 0.3);
        let (b, _) = asteroid(3, 3, 0.3);
        assert_eq!(a, b);
        let r: Vec<f64> = a.iter().map(|p| p.length()).collect();
        let (lo, hi) = r
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(hi - lo > 0.2 && hi < 1.6 && lo > 0.3, "{lo} {hi}");
        let obj = to_obj(&a, &icosphere(3).1, "test");
        assert!(obj.starts_with("# test") && obj.contains("\nvn ") && obj.contains("//"));
    }
}
