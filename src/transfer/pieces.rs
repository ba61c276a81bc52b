//! The pieces' loop: how a stretch of a ray is cut into pieces of gas,
//! one loop for every band. The visible band's volumetric disk and clouds
//! ([`crate::cpu`]'s march) and the physical media ([`super::RayTransfer`])
//! each say what a piece holds ([`Pieces::take`]); where the pieces fall,
//! how they thin where the gas is thick and when the ray is spent is this
//! loop's alone (its GPU twin: `src/gpu/transfer.wgsl`'s `pieces_walk`).
//!
//! A stretch is cut into pieces of [`SCALE_FRACTION`] of the gas's scale,
//! each taking the gas at its two Gauss-Legendre nodes ([`nodes`]). A
//! piece thicker than [`MAX_DTAU`] at some wavelength or frequency is
//! taken again thinner, the next ones growing back towards the scale's
//! length by at most a factor 2 each; a piece ends where the ray crosses
//! one of the gas's surfaces; the walk ends where the gas has spent the
//! ray (its transmittance below [`SPENT`] everywhere).

use super::{GAUSS_2, MAX_DTAU, MAX_PIECES, SCALE_FRACTION};

/// Pieces reaching above this [`Pieces::level`] are near its surface
/// (for a snapshot, where the magnetisation is above a tenth of its cut:
/// the hot sheath against the cut's surface).
pub const NEAR: f64 = 0.1;

/// What became of a piece offered to the gas: taken, with its greatest
/// optical depth, or to be cut thinner, its depth (over [`MAX_DTAU`])
/// given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cut {
    Taken(f64),
    Thinner(f64),
}

/// A band's gas along one stretch, in the stretch's own parameter s.
pub trait Pieces {
    /// Radii (M) where the gas ends abruptly: no piece straddles one.
    fn surfaces(&self) -> &[f64] {
        &[]
    }
    /// The radius (M) at s; asked only where there are surfaces.
    fn radius(&self, _s: f64) -> f64 {
        f64::NAN
    }
    /// Whether [`Pieces::level`] tells a surface inside the medium.
    fn levelled(&self) -> bool {
        false
    }
    /// A level inside the medium at `s` (a snapshot's magnetisation over
    /// its cut): pieces end where it crosses 1, a surface that is no
    /// radius, and are told ([`Pieces::edge`]) when they touch it or
    /// reach above [`NEAR`] of it.
    fn level(&self, _s: f64) -> f64 {
        0.0
    }
    /// Told before each piece whether it touches the level's surface or
    /// comes near it.
    fn edge(&mut self, _on: bool) {}
    /// Takes the piece from s to e (its light, then its absorption),
    /// unless it is thicker than [`MAX_DTAU`] and may be cut finer (not
    /// `finest`): then it adds nothing and asks to be cut thinner.
    fn take(&mut self, piece: (f64, f64), finest: bool) -> Cut;
    /// Nothing further along can be seen any more.
    fn spent(&self) -> bool;
}

/// The two-point Gauss-Legendre nodes of the piece from s to e: exact for
/// coefficients cubic along it, where the midpoint's rule is exact only
/// for linear ones.
#[inline]
pub fn nodes((s, e): (f64, f64)) -> [f64; 2] {
    let (mid, half) = (0.5 * (s + e), GAUSS_2 * (e - s));
    [mid - half, mid + half]
}

/// How many pieces a stretch `length` long gets where its gas changes
/// over `scale` (the same unit).
#[inline]
pub fn count(length: f64, scale: f64) -> f64 {
    (length / (SCALE_FRACTION * scale))
        .ceil()
        .clamp(1.0, MAX_PIECES as f64)
}

/// Walks `gas` from s0 to s1 in `pieces` pieces ([`count`]), thinner
/// where it is thick, until it is spent.
pub fn walk(gas: &mut impl Pieces, (s0, s1): (f64, f64), pieces: f64) {
    if s1 <= s0 {
        return;
    }
    let base_ds = (s1 - s0) / pieces;
    let mut ds = base_ds;
    let min_ds = (s1 - s0) / MAX_PIECES as f64;
    let mut s = s0;
    let cuts = !gas.surfaces().is_empty();
    // The radius at the piece's start.
    let mut r_start = if cuts { gas.radius(s0) } else { f64::NAN };
    let levelled = gas.levelled();
    let mut level_start = if levelled { gas.level(s0) } else { 0.0 };
    let mut starts_at_edge = false;
    while s < s1 && !gas.spent() {
        let mut e = (s + ds).min(s1);
        let mut r_e = r_start;
        if cuts {
            r_e = gas.radius(e);
            for i in 0..gas.surfaces().len() {
                let b = gas.surfaces()[i];
                if (r_start > b) != (r_e > b) {
                    e = crossing(gas, (s, e), b, r_start > b);
                    r_e = gas.radius(e);
                }
            }
        }
        let mut level_e = level_start;
        if levelled {
            level_e = gas.level(e);
            let ends_at_edge = (level_e > 1.0) != (level_start > 1.0);
            if ends_at_edge {
                e = side_change(gas, (s, e), level_start > 1.0);
                level_e = gas.level(e);
                if cuts {
                    r_e = gas.radius(e);
                }
            }
            gas.edge(ends_at_edge || starts_at_edge || level_start.max(level_e) > NEAR);
        }
        match gas.take((s, e), ds <= min_ds) {
            // Too thick somewhere: taken again thinner.
            Cut::Thinner(worst) => ds = (ds * MAX_DTAU / worst).max(min_ds).min(0.5 * ds),
            // Taken: the next piece grows back towards the scale's length,
            // at most doubling, as thin as this one allows.
            Cut::Taken(depth) => {
                s = e;
                r_start = r_e;
                if levelled {
                    starts_at_edge = (level_e > 1.0) != (level_start > 1.0);
                    level_start = level_e;
                }
                let grow = if depth > 0.0 {
                    (0.8 * MAX_DTAU / depth).clamp(1.0, 2.0)
                } else {
                    2.0
                };
                ds = (ds * grow).min(base_ds);
            }
        }
    }
}

/// Where between `a` and `b`, whose radii lie on either side of
/// `surface` (M; outside it at `a` where `outside`), the gas's radius
/// crosses it (bisection to 1e-12 of the interval).
fn crossing(gas: &impl Pieces, (a, b): (f64, f64), surface: f64, outside: bool) -> f64 {
    bisect((a, b), 40, |s| (gas.radius(s) > surface) == outside)
}

/// Where along (a, b) the level first crosses 1 from above (`start`) or
/// below, by bisection to 2^-30 of the piece: the end of the piece before
/// it (a hair past, so the next piece starts on the other side).
fn side_change(gas: &impl Pieces, (a, b): (f64, f64), start: bool) -> f64 {
    bisect((a, b), 30, |s| (gas.level(s) > 1.0) == start)
}

/// The end of (a, b) past which `on_start_side` turns false, to 2^-n of
/// the interval: the first point found on the far side.
fn bisect((a, b): (f64, f64), n: u32, on_start_side: impl Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (a, b);
    for _ in 0..n {
        let mid = 0.5 * (lo + hi);
        if on_start_side(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::Piece;

    /// A uniform grey slab from 0 to `length` (coefficient `alpha` per
    /// unit of s, source function 1), with a surface at radius 0.5 where
    /// the radius is s.
    struct Slab {
        alpha: f64,
        light: f64,
        through: f64,
        pieces: Vec<(f64, f64)>,
        surfaces: Vec<f64>,
    }

    impl Pieces for Slab {
        fn surfaces(&self) -> &[f64] {
            &self.surfaces
        }
        fn radius(&self, s: f64) -> f64 {
            s
        }
        fn take(&mut self, (s, e): (f64, f64), finest: bool) -> Cut {
            let p = Piece::new(self.alpha * (e - s));
            if p.dtau > MAX_DTAU && !finest {
                return Cut::Thinner(p.dtau);
            }
            self.pieces.push((s, e));
            self.light += self.through * p.source(1.0);
            self.through *= p.kept;
            Cut::Taken(p.dtau)
        }
        fn spent(&self) -> bool {
            self.through < super::super::SPENT
        }
    }

    #[test]
    fn pieces_cover_the_stretch_thin_where_thick_and_stop_at_surfaces_and_when_spent() {
        for alpha in [0.0, 0.05, 3.0, 400.0] {
            let mut slab = Slab {
                alpha,
                light: 0.0,
                through: 1.0,
                pieces: Vec::new(),
                surfaces: vec![0.5],
            };
            walk(&mut slab, (0.0, 1.0), 10.0);
            let tau = alpha;
            // S (1 - e^-tau) whatever the cut, to the ray's spending.
            let want = -(-tau).exp_m1();
            assert!(
                (slab.light - want).abs() < 1e-12,
                "alpha {alpha}: {} {want}",
                slab.light
            );
            let end = slab.pieces.last().unwrap().1;
            if alpha < 20.0 {
                // Contiguous from 0 to 1, one piece ending at the surface.
                assert_eq!(slab.pieces[0].0, 0.0);
                assert_eq!(end, 1.0);
                assert!(slab.pieces.windows(2).all(|w| w[0].1 == w[1].0));
                assert!(slab.pieces.iter().any(|p| (p.1 - 0.5).abs() < 1e-12));
            } else {
                // Spent before the end: -ln(1e-12) / 400 = 0.069.
                assert!(end < 0.08 && slab.through < super::super::SPENT, "{end}");
            }
            // No piece thicker than MAX_DTAU, none longer than a tenth.
            for &(s, e) in &slab.pieces {
                assert!(alpha * (e - s) <= MAX_DTAU * (1.0 + 1e-12) && e - s <= 0.1 + 1e-12);
            }
        }
    }

    /// Gas whose level falls through 1 at s = 0.37 (and is near it, above
    /// NEAR, from 0.3 on): the pieces it is walked in, and whether each
    /// was told it touches or nears the surface.
    struct Levelled {
        pieces: Vec<((f64, f64), bool)>,
        edge: bool,
    }

    impl Pieces for Levelled {
        fn levelled(&self) -> bool {
            true
        }
        fn level(&self, s: f64) -> f64 {
            if s < 0.3 {
                0.0
            } else {
                1.0 + (s - 0.37) * 10.0
            }
        }
        fn edge(&mut self, on: bool) {
            self.edge = on;
        }
        fn take(&mut self, piece: (f64, f64), _finest: bool) -> Cut {
            self.pieces.push((piece, self.edge));
            Cut::Taken(0.0)
        }
        fn spent(&self) -> bool {
            false
        }
    }

    #[test]
    fn pieces_end_where_the_level_crosses_one_and_are_told_near_it() {
        let mut gas = Levelled {
            pieces: Vec::new(),
            edge: false,
        };
        walk(&mut gas, (0.0, 1.0), 10.0);
        let p = &gas.pieces;
        assert!(p.windows(2).all(|w| w[0].0.1 == w[1].0.0));
        assert_eq!((p[0].0.0, p.last().unwrap().0.1), (0.0, 1.0));
        // One piece ends at the crossing (to 2^-30 of its piece), the next
        // starts there; both are told, as is every piece reaching above
        // NEAR, and none wholly below it.
        let at = p
            .iter()
            .position(|q| (q.0.1 - 0.37).abs() < 1e-9)
            .expect("a piece ends at 0.37");
        assert!(p[at].1 && p[at + 1].1);
        for &((s, e), told) in p {
            let near = gas.level(s).max(gas.level(e)) > NEAR;
            assert_eq!(
                told,
                near || (s - 0.37).abs() < 1e-9 || (e - 0.37).abs() < 1e-9,
                "{s} {e}"
            );
        }
    }

    #[test]
    fn gauss_nodes_integrate_cubics_exactly() {
        let f = |x: f64| 3.0 * x * x * x - x * x + 2.0;
        let (s, e) = (0.3, 1.7);
        let [a, b] = nodes((s, e));
        let quad = 0.5 * (e - s) * (f(a) + f(b));
        let exact = |x: f64| 0.75 * x.powi(4) - x.powi(3) / 3.0 + 2.0 * x;
        assert!((quad - (exact(e) - exact(s))).abs() < 1e-12);
    }
}
