//! The elliptical weighted average (EWA) filter over a mip pyramid
//! (Heckbert 1989; the Gaussian form of Greene and Heckbert 1986): one
//! pixel's footprint in texture space is an ellipse, and a lookup is the
//! Gaussian-weighted mean of the texels under it, on the pyramid level
//! where the ellipse's minor axis spans one to two texels.
//!
//! The ellipse is the image of the unit disc under the footprint's
//! Jacobian: a texel at offset p from the lookup has r^2 = p^T (J J^T)^-1 p,
//! and weight `exp(-2 r^2) - exp(-2)` where r < 1 (zero beyond), a Gaussian
//! of standard deviation half a pixel spacing along each of the pixel's
//! axes, truncated where the neighbouring pixels' lookups are centred.
//! Weights are normalised per level, so a constant texture stays constant.
//!
//! Three guards keep a lookup bounded and never a point:
//! - each axis is at least one texel of the level read (the reconstruction
//!   filter where the texture is magnified: a tent two texels wide, like
//!   bilinear's);
//! - the ratio of the axes is at most [`MAX_ANISOTROPY`]; beyond it the
//!   minor axis widens (blur across the stretch rather than alias along it);
//! - two levels are blended by the fractional level (trilinear in level), so
//!   the result changes smoothly as a footprint grows (no popping in
//!   animations).

use glam::DVec2;

/// The highest ratio of the ellipse's axes. Lensing stretches footprints
/// without limit near the critical curve; a lookup reads about
/// `pi * MAX_ANISOTROPY * 2` texels at most on its finer level (minor axis
/// one to two texels, major at most 16 times that), a bounded cost. 16 is
/// the common hardware cap: one octave of minor-axis blur per doubling
/// beyond it.
pub const MAX_ANISOTROPY: f64 = 16.0;

/// The Gaussian's falloff: weight `exp(-ALPHA r^2) - exp(-ALPHA)`.
const ALPHA: f32 = 2.0;

/// The filter's reach (r = 1) in pixel steps. At one step its weight's
/// deviation along each axis is 0.369 pixel; at 0.78 it is the one-pixel
/// box's, 0.289: the lookup is then the mean of the texture over the
/// pixel, as many point samples would give it, rather than a wider blur
/// of it. On `quick.toml` with adaptive sampling, against 256 point-read
/// samples a pixel: mean CIEDE2000 0.135 and 99th percentile 2.22 at a
/// reach of one step, 0.098 and 1.79 at 0.78 (validation/PERFORMANCE.md).
pub const REACH: f64 = 0.78;

/// A pixel's footprint in texture space: how the texture coordinates
/// (u, v), in [0, 1] texture units (v down), change per pixel step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// (du/dx, dv/dx): one pixel step across the image.
    pub dx: DVec2,
    /// (du/dy, dv/dy): one pixel step down the image.
    pub dy: DVec2,
}

impl Footprint {
    /// From the four derivatives.
    pub fn new(du_dx: f64, dv_dx: f64, du_dy: f64, dv_dy: f64) -> Footprint {
        Footprint {
            dx: DVec2::new(du_dx, dv_dx),
            dy: DVec2::new(du_dy, dv_dy),
        }
    }

    /// No extent: the lookup is the one-texel reconstruction filter.
    pub const POINT: Footprint = Footprint {
        dx: DVec2::ZERO,
        dy: DVec2::ZERO,
    };

    /// Whether every derivative is finite.
    pub fn is_finite(&self) -> bool {
        self.dx.is_finite() && self.dy.is_finite()
    }
}

/// Number of levels of a w x h pyramid, level 0 the image itself, down to
/// 1 x 1.
#[inline]
pub fn level_count(w: u32, h: u32) -> usize {
    (32 - w.max(h).max(1).leading_zeros()) as usize
}

/// Size of level `k` of a w x h pyramid: each side halved (rounded down)
/// `k` times, at least 1.
#[inline]
pub fn level_dims(w: u32, h: u32, k: usize) -> (u32, u32) {
    let k = k.min(31) as u32;
    ((w >> k).max(1), (h >> k).max(1))
}

/// The ellipse read on one level of a lookup.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LevelEllipse {
    /// The pyramid level.
    pub level: usize,
    /// Its share of the lookup (the two levels' sum to 1).
    pub weight: f32,
    /// The centre in the level's texel units (texel x's centre at x + 0.5).
    centre: DVec2,
    /// r^2 = a dx^2 + b dx dy + c dy^2.
    q: [f64; 3],
    /// Half the bounding box (texels).
    extent: DVec2,
}

/// Eigen-decomposition of the symmetric [[m00, m01], [m01, m11]]: the
/// larger and smaller eigenvalues and the larger's unit eigenvector.
fn eigen(m00: f64, m01: f64, m11: f64) -> (f64, f64, DVec2) {
    let mean = 0.5 * (m00 + m11);
    let d = (0.25 * (m00 - m11) * (m00 - m11) + m01 * m01).sqrt();
    let (l1, l2) = (mean + d, (mean - d).max(0.0));
    let e = if m01.abs() > 1e-300 {
        DVec2::new(l1 - m11, m01).normalize()
    } else if m00 >= m11 {
        DVec2::X
    } else {
        DVec2::Y
    };
    (l1, l2, e)
}

/// The ellipse's axes (lengths sigma1 >= sigma2 and the major direction)
/// from J J^T = [[m00, m01], [m01, m11]], the minor widened to
/// sigma1 / MAX_ANISOTROPY and both to at least `min`.
fn axes(m00: f64, m01: f64, m11: f64, min: f64) -> (f64, f64, DVec2) {
    let (l1, l2, e) = eigen(m00, m01, m11);
    let s1 = l1.sqrt().max(min);
    let s2 = l2.sqrt().max(s1 / MAX_ANISOTROPY).max(min);
    (s1, s2, e)
}

/// The ellipse on level `k` of a w0 x h0 pyramid for axes given in level-0
/// texels, each axis at least one texel of that level and at most the
/// level's larger side (the coarsest levels: a few texels, not many turns
/// around a wrapped row).
fn level_ellipse(
    k: usize,
    (w0, h0): (u32, u32),
    uv: DVec2,
    (s1, s2, e1): (f64, f64, DVec2),
) -> LevelEllipse {
    let (w, h) = level_dims(w0, h0, k);
    // Level texels per level-0 texel, per axis (not always equal: the
    // coarsest levels of a non-square image).
    let s = DVec2::new(w as f64 / w0 as f64, h as f64 / h0 as f64);
    let (t1, t2, f1) = if s.x == s.y {
        // The usual case: the axes scale alike.
        let t1 = (s1 * s.x).max(1.0);
        (t1, (s2 * s.x).max(t1 / MAX_ANISOTROPY).max(1.0), e1)
    } else {
        let e2 = e1.perp();
        let (p1, p2) = (s * e1 * s1, s * e2 * s2);
        let m00 = p1.x * p1.x + p2.x * p2.x;
        let m01 = p1.x * p1.y + p2.x * p2.y;
        let m11 = p1.y * p1.y + p2.y * p2.y;
        axes(m00, m01, m11, 1.0)
    };
    let cap = w.max(h) as f64;
    let (t1, t2) = (t1.min(cap), t2.min(cap));
    let f2 = f1.perp();
    // Q = (J J^T)^-1 = f1 f1^T / t1^2 + f2 f2^T / t2^2.
    let (i1, i2) = (1.0 / (t1 * t1), 1.0 / (t2 * t2));
    let q00 = f1.x * f1.x * i1 + f2.x * f2.x * i2;
    let q01 = f1.x * f1.y * i1 + f2.x * f2.y * i2;
    let q11 = f1.y * f1.y * i1 + f2.y * f2.y * i2;
    // The bounding box: sqrt of the diagonal of J J^T.
    let n00 = f1.x * f1.x * t1 * t1 + f2.x * f2.x * t2 * t2;
    let n11 = f1.y * f1.y * t1 * t1 + f2.y * f2.y * t2 * t2;
    LevelEllipse {
        level: k,
        weight: 1.0,
        centre: DVec2::new(uv.x * w as f64, uv.y * h as f64),
        q: [q00, 2.0 * q01, q11],
        extent: DVec2::new(n00.sqrt(), n11.sqrt()),
    }
}

/// The one or two level ellipses of a lookup at (u, v) with footprint `fp`
/// in a w0 x h0 texture: the level is log2 of the minor axis in level-0
/// texels (after the anisotropy cap), blended linearly between the two
/// levels around it. Non-finite coordinates read (0, 0); a non-finite
/// footprint reads as a point.
pub(crate) fn plan(u: f64, v: f64, fp: &Footprint, w0: u32, h0: u32) -> ([LevelEllipse; 2], usize) {
    let uv = DVec2::new(
        if u.is_finite() { u } else { 0.0 },
        if v.is_finite() { v } else { 0.0 },
    );
    let fp = if fp.is_finite() {
        *fp
    } else {
        Footprint::POINT
    };
    let size = DVec2::new(w0 as f64, h0 as f64);
    // Beyond 1e12 texels every footprint reads the coarsest level; the cap
    // keeps the squares below finite.
    let cap = |v: DVec2| {
        let m = v.abs().max_element();
        if m > 1e12 { v * (1e12 / m) } else { v }
    };
    let (a, b) = (cap(fp.dx * size * REACH), cap(fp.dy * size * REACH));
    let m00 = a.x * a.x + b.x * b.x;
    let m01 = a.x * a.y + b.x * b.y;
    let m11 = a.y * a.y + b.y * b.y;
    let ax = axes(m00, m01, m11, 0.0);
    let mut out = [LevelEllipse::default(); 2];
    if ax.0 <= 1.0 {
        // Magnified: the one-texel circle on level 0.
        out[0] = LevelEllipse {
            level: 0,
            weight: 1.0,
            centre: uv * size,
            q: [1.0, 0.0, 1.0],
            extent: DVec2::ONE,
        };
        return (out, 1);
    }
    let last = level_count(w0, h0) - 1;
    let lod = if ax.1 > 1.0 { ax.1.log2() } else { 0.0 };
    // A whole level up to rounding reads that level alone (not a blend
    // with a weight of 1e-16 at twice the cost).
    let lod = if (lod - lod.round()).abs() < 1e-9 {
        lod.round()
    } else {
        lod
    };
    let one = |k| level_ellipse(k, (w0, h0), uv, ax);
    if lod >= last as f64 {
        out[0] = one(last);
        return (out, 1);
    }
    let k = lod.floor() as usize;
    let t = (lod - k as f64) as f32;
    out[0] = one(k);
    if t == 0.0 {
        return (out, 1);
    }
    out[0].weight = 1.0 - t;
    out[1] = LevelEllipse {
        weight: t,
        ..one(k + 1)
    };
    (out, 2)
}

/// Entries of the weight table over r^2 in [0, 1].
pub(crate) const TABLE: usize = 256;

/// The weight `exp(-ALPHA r^2) - exp(-ALPHA)` at r^2 = i / TABLE (one
/// entry past the end for interpolation): a table lookup costs a few
/// cycles where `exp` costs tens, and linear interpolation keeps it within
/// 8e-6 of the exact weight (the error is at most (1 / TABLE)^2 / 8 times
/// the second derivative, at most ALPHA^2 = 4).
static WEIGHTS: std::sync::LazyLock<[f32; TABLE + 2]> = std::sync::LazyLock::new(|| {
    let floor = (-(ALPHA as f64)).exp();
    std::array::from_fn(|i| {
        let r2 = (i as f64 / TABLE as f64).min(1.0);
        ((-(ALPHA as f64) * r2).exp() - floor) as f32
    })
});

/// The weight table (the GPU backend reads the same one).
pub(crate) fn weight_table() -> &'static [f32; TABLE + 2] {
    &WEIGHTS
}

/// The weight at r^2 in [0, 1), interpolated in [`WEIGHTS`].
#[inline]
fn weight(table: &[f32; TABLE + 2], r2: f32) -> f32 {
    let f = r2 * TABLE as f32;
    let i = f as usize;
    let t = f - i as f32;
    table[i] + t * (table[i + 1] - table[i])
}

/// floor(x) as an integer, without a call to the C library (x86-64's
/// baseline has no rounding instruction). |x| below 2^53.
#[inline]
fn floor_i(x: f64) -> i64 {
    let t = x as i64;
    t - ((t as f64) > x) as i64
}

/// ceil(x) as an integer (see [`floor_i`]).
#[inline]
fn ceil_i(x: f64) -> i64 {
    let t = x as i64;
    t + ((t as f64) < x) as i64
}

/// Visits the texels of a w x h level under ellipse `e` (their index in
/// the level, row-major, and unnormalised weight; `wrap_u` makes columns
/// periodic, else they clamp to the edge; rows always clamp) and returns
/// the sum of the weights. Texels past a clamped edge read the edge texel,
/// so it may be visited more than once.
#[inline]
pub(crate) fn visit(
    e: &LevelEllipse,
    w: u32,
    h: u32,
    wrap_u: bool,
    mut f: impl FnMut(usize, f32),
) -> f32 {
    let table = &*WEIGHTS;
    let [qa, qb, qc] = e.q;
    let c = e.centre;
    let (wi, hi) = (w as i64, h as i64);
    let mut sum = 0.0f32;
    let y0 = ceil_i(c.y - e.extent.y - 0.5);
    let y1 = floor_i(c.y + e.extent.y - 0.5);
    for y in y0..=y1 {
        let dy = y as f64 + 0.5 - c.y;
        // Where qa dx^2 + qb dy dx + qc dy^2 < 1 along this row.
        let (lin, con) = (qb * dy, qc * dy * dy - 1.0);
        let disc = lin * lin - 4.0 * qa * con;
        if disc <= 0.0 {
            continue;
        }
        let root = disc.sqrt();
        let x0 = ceil_i(c.x + (-lin - root) / (2.0 * qa) - 0.5);
        let x1 = floor_i(c.x + (-lin + root) / (2.0 * qa) - 0.5);
        let row = y.clamp(0, hi - 1) as usize * w as usize;
        // r^2 at x0, stepped along the row: r^2(dx + 1) - r^2(dx) =
        // qa (2 dx + 1) + lin.
        let dx0 = x0 as f64 + 0.5 - c.x;
        let mut r2 = qa * dx0 * dx0 + lin * dx0 + con + 1.0;
        let mut step = qa * (2.0 * dx0 + 1.0) + lin;
        let mut col = if wrap_u { x0.rem_euclid(wi) } else { x0 };
        for _ in x0..=x1 {
            let r = r2 as f32;
            if r < 1.0 {
                let wt = weight(table, r.max(0.0));
                let at = if wrap_u { col } else { col.clamp(0, wi - 1) };
                f(row + at as usize, wt);
                sum += wt;
            }
            r2 += step;
            step += 2.0 * qa;
            col += 1;
            if wrap_u && col == wi {
                col = 0;
            }
        }
    }
    if sum <= 0.0 {
        // Unreachable with both axes at least a texel (the unit disc about
        // any point holds a texel centre); kept for rounding at the limit.
        let x = c.x.floor() as i64;
        let col = if wrap_u {
            x.rem_euclid(wi)
        } else {
            x.clamp(0, wi - 1)
        };
        let row = (c.y.floor() as i64).clamp(0, hi - 1) as usize * w as usize;
        f(row + col as usize, 1.0);
        return 1.0;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_down_to_one_texel() {
        assert_eq!(level_count(4096, 2048), 13);
        assert_eq!(level_dims(4096, 2048, 11), (2, 1));
        assert_eq!(level_dims(4096, 2048, 12), (1, 1));
        assert_eq!(level_count(1, 1), 1);
        assert_eq!(level_count(5, 3), 3);
        assert_eq!(level_dims(5, 3, 1), (2, 1));
    }

    /// The footprint whose filter reaches the given derivatives' ellipse
    /// (texture units per pixel step over [`REACH`]).
    fn reaching(du_dx: f64, dv_dx: f64, du_dy: f64, dv_dy: f64) -> Footprint {
        let k = 1.0 / REACH;
        Footprint::new(du_dx * k, dv_dx * k, du_dy * k, dv_dy * k)
    }

    #[test]
    fn level_follows_the_minor_axis() {
        // Minor axis 4 texels, major 32: level 2, no blend.
        let (w, h) = (256, 256);
        let fp = reaching(32.0 / w as f64, 0.0, 0.0, 4.0 / h as f64);
        let (e, n) = plan(0.5, 0.5, &fp, w, h);
        assert_eq!((n, e[0].level), (1, 2));
        // Axes 8 and 1 level-2 texels: extents.
        assert!((e[0].extent.x - 8.0).abs() < 1e-9 && (e[0].extent.y - 1.0).abs() < 1e-9);
        // Minor 6 texels: between levels 2 and 3, log2(6) - 2 = 0.585.
        let fp = reaching(0.0, 6.0 / h as f64, 6.0 / w as f64, 0.0);
        let (e, n) = plan(0.5, 0.5, &fp, w, h);
        assert_eq!((n, e[0].level, e[1].level), (2, 2, 3));
        assert!((e[1].weight - (6f32.log2() - 2.0)).abs() < 1e-6);
        // Magnified: level 0, axes one texel.
        let (e, n) = plan(0.5, 0.5, &Footprint::POINT, w, h);
        assert_eq!((n, e[0].level), (1, 0));
        assert!((e[0].extent - DVec2::ONE).length() < 1e-12);
    }

    #[test]
    fn anisotropy_is_capped() {
        // 100 : 0.01 texels: the minor widens to 100 / 16.
        let (w, h) = (1024, 1024);
        let fp = reaching(100.0 / w as f64, 0.0, 0.0, 0.01 / h as f64);
        let (e, n) = plan(0.5, 0.5, &fp, w, h);
        let lod = (100.0 / MAX_ANISOTROPY).log2();
        assert_eq!((n, e[0].level), (2, lod.floor() as usize));
        let k = e[0].level as i32;
        let s = 2f64.powi(-k);
        assert!((e[0].extent.x - 100.0 * s).abs() < 1e-9);
        assert!((e[0].extent.y - 100.0 / 16.0 * s).abs() < 1e-9);
    }

    #[test]
    fn weights_are_the_truncated_gaussian() {
        // A rotated 3 x 1 texel ellipse (level 0) off a texel centre: every
        // texel's weight against r^2 = |J^-1 p|^2, found by brute force.
        let (th, n) = (0.6f64, 64.0);
        let a = DVec2::new(th.cos(), th.sin()) * 3.0;
        let b = DVec2::new(-th.sin(), th.cos());
        let fp = Footprint {
            dx: a / n / REACH,
            dy: b / n / REACH,
        };
        let c = DVec2::new(20.3, 17.8);
        let (e, k) = plan(c.x / n, c.y / n, &fp, 64, 64);
        assert_eq!((k, e[0].level), (1, 0));
        let mut seen = std::collections::HashMap::new();
        let sum = visit(&e[0], 64, 64, false, |i, w| {
            assert!(seen.insert(i, w).is_none(), "visited twice");
        });
        let det = a.x * b.y - a.y * b.x;
        let mut expect = 0.0;
        for i in 0..64 * 64 {
            let p = DVec2::new((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5) - c;
            let s = DVec2::new(b.y * p.x - b.x * p.y, -a.y * p.x + a.x * p.y) / det;
            let r2 = s.length_squared() as f32;
            let want = if r2 < 1.0 {
                (-2.0 * r2).exp() - (-2.0f32).exp()
            } else {
                0.0
            };
            expect += want;
            let got = seen.get(&i).copied().unwrap_or(0.0);
            assert!((got - want).abs() < 1e-5, "texel {i}: {got} vs {want}");
        }
        assert!(seen.len() > 8, "{}", seen.len());
        assert!((sum - expect).abs() < 1e-4, "{sum} vs {expect}");
    }

    #[test]
    fn wraps_columns_and_clamps_rows() {
        let fp = Footprint::new(4.0 / 16.0, 0.0, 0.0, 4.0 / 16.0);
        let (e, _) = plan(0.0, 0.0, &fp, 16, 16);
        let mut cols = std::collections::BTreeSet::new();
        let mut rows = std::collections::BTreeSet::new();
        let (w, h) = level_dims(16, 16, e[0].level);
        visit(&e[0], w, h, true, |i, _| {
            cols.insert(i % w as usize);
            rows.insert(i / w as usize);
        });
        assert!(cols.contains(&(w as usize - 1)) && cols.contains(&0));
        assert_eq!(*rows.iter().next().unwrap(), 0);
    }

    #[test]
    fn huge_footprints_read_the_coarsest_level() {
        let fp = Footprint::new(1e200, 3e199, 0.0, 1e200);
        let (e, n) = plan(0.3, 0.5, &fp, 64, 32);
        assert_eq!((n, e[0].level), (1, level_count(64, 32) - 1));
        assert!(e[0].extent.is_finite() && e[0].extent.x <= 2.0);
    }

    #[test]
    fn bad_footprints_read_as_points() {
        let fp = Footprint::new(f64::NAN, 0.0, f64::INFINITY, 1.0);
        let (e, n) = plan(f64::NAN, 0.5, &fp, 8, 8);
        assert_eq!((n, e[0].level), (1, 0));
        assert!(e[0].centre.is_finite());
    }
}
