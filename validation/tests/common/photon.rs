//! Closed-form photon paths of both ray models as radial quadratures (r_s
//! units, c = 1), for checking traced and rendered rays.
//!
//! A ray in a plane through the hole keeps its impact parameter b, and
//! along it
//! - `gr`: dphi/dr = b / (r^2 sqrt(Q)), dt/dr = 1 / ((1 - 1/r) sqrt(Q)),
//!   Q = 1 - b^2 (1 - 1/r) / r^2 (t: Schwarzschild coordinate time);
//! - `seed` (a medium of index n = exp(1/(2r))): dphi/dr = b / (r sqrt(Q)),
//!   dt/dr = n^2 r / sqrt(Q), Q = n^2 r^2 - b^2 (t: optical path length).
//!
//! Both have an integrable 1/sqrt singularity where Q = 0 (a turning
//! point); the quadrature substitutes r = lo + u^2, which removes it.

use std::f64::consts::FRAC_PI_2;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lens {
    Gr,
    Seed,
}

impl Lens {
    fn index(r: f64) -> f64 {
        (0.5 / r).exp()
    }

    /// Q(r): positive where the ray can be.
    pub fn q(self, b: f64, r: f64) -> f64 {
        match self {
            Lens::Gr => 1.0 - b * b * (1.0 - 1.0 / r) / (r * r),
            Lens::Seed => {
                let nr = Lens::index(r) * r;
                nr * nr - b * b
            }
        }
    }

    /// (dphi/dr, dt/dr) at r.
    pub fn rates(self, b: f64, r: f64) -> (f64, f64) {
        let s = self.q(b, r).max(0.0).sqrt();
        match self {
            Lens::Gr => (b / (r * r * s), 1.0 / ((1.0 - 1.0 / r) * s)),
            Lens::Seed => {
                let n = Lens::index(r);
                (b / (r * s), n * n * r / s)
            }
        }
    }

    /// The turning point (largest root of Q) of a ray at b that reaches
    /// `r_hi`, or None if the ray has none (it falls in).
    pub fn turning(self, b: f64, r_hi: f64) -> Option<f64> {
        // Below these radii Q only falls: the photon sphere (gr), the
        // minimum of n r (seed).
        let floor = match self {
            Lens::Gr => 1.5,
            Lens::Seed => 0.5,
        };
        if self.q(b, floor) > 0.0 {
            return None;
        }
        let (mut lo, mut hi) = (floor, r_hi);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if self.q(b, m) > 0.0 {
                hi = m;
            } else {
                lo = m;
            }
        }
        Some(hi)
    }

    /// (swept angle, time) from radius `lo` out to `hi` along a ray at b
    /// that moves outward all the way (`lo` may be its turning point).
    pub fn integrals(self, b: f64, lo: f64, hi: f64) -> (f64, f64) {
        // r = lo + u^2 with u graded quadratically towards u = 0, where a
        // turning point puts the steep part; 5-point Gauss-Legendre on
        // each piece.
        const X: [f64; 5] = [
            0.0,
            -0.538_469_310_105_683_1,
            0.538_469_310_105_683_1,
            -0.906_179_845_938_664,
            0.906_179_845_938_664,
        ];
        const W: [f64; 5] = [
            0.568_888_888_888_888_9,
            0.478_628_670_499_366_5,
            0.478_628_670_499_366_5,
            0.236_926_885_056_189_1,
            0.236_926_885_056_189_1,
        ];
        let top = (hi - lo).sqrt();
        let n = 4000;
        let (mut phi, mut t) = (0.0, 0.0);
        for k in 0..n {
            let a = top * (k as f64 / n as f64).powi(2);
            let c = top * ((k + 1) as f64 / n as f64).powi(2);
            let (mid, half) = (0.5 * (a + c), 0.5 * (c - a));
            for (x, w) in X.iter().zip(W) {
                let u = mid + half * x;
                let (dp, dt) = self.rates(b, lo + u * u);
                phi += w * half * 2.0 * u * dp;
                t += w * half * 2.0 * u * dt;
            }
        }
        (phi, t)
    }

    /// (swept angle, time) from radius `from` to `to` > `from`, through
    /// the turning point first when `inward` (the ray leaves `from`
    /// moving inwards).
    pub fn path(self, b: f64, from: f64, to: f64, inward: bool) -> (f64, f64) {
        if !inward {
            return self.integrals(b, from, to);
        }
        let rmin = self.turning(b, from).expect("the ray turns");
        let (p1, t1) = self.integrals(b, rmin, from);
        let (p2, t2) = self.integrals(b, rmin, to);
        (p1 + p2, t1 + t2)
    }

    /// The impact parameter at which b = h at radius r with the ray
    /// tangential there (Q(r) = 0).
    fn tangent_b(self, r: f64) -> f64 {
        match self {
            Lens::Gr => r / (1.0 - 1.0 / r).sqrt(),
            Lens::Seed => Lens::index(r) * r,
        }
    }

    /// The ray from radius `from` (< `to`) to radius `to` that sweeps the
    /// angle `sweep` on the way: (b, time).
    pub fn connect(self, from: f64, to: f64, sweep: f64) -> (f64, f64) {
        // Outward rays sweep more as b grows to tangency at `from`;
        // inward-first rays sweep more still as b shrinks from there.
        let b_tan = self.tangent_b(from) * (1.0 - 1e-15);
        let outward = self.path(b_tan, from, to, false).0 >= sweep;
        let (mut lo, mut hi) = if outward {
            (0.0, b_tan)
        } else {
            // b above which the ray turns before the hole.
            let b_min = match self {
                Lens::Gr => 1.5 * 3f64.sqrt(),
                Lens::Seed => Lens::index(0.5) * 0.5,
            };
            (b_min * (1.0 + 1e-9), b_tan)
        };
        for _ in 0..100 {
            let m = 0.5 * (lo + hi);
            let swept = self.path(m, from, to, !outward).0;
            // Outward: sweep grows with b; inward: it shrinks with b.
            if (swept < sweep) == outward {
                lo = m;
            } else {
                hi = m;
            }
        }
        let b = 0.5 * (lo + hi);
        (b, self.path(b, from, to, !outward).1)
    }

    /// Angle from the direction to the hole at which a static observer at
    /// radius r sees a ray of impact parameter b.
    pub fn sight_angle(self, b: f64, r: f64) -> f64 {
        match self {
            Lens::Gr => (b * (1.0 - 1.0 / r).sqrt() / r).asin(),
            Lens::Seed => (b / (Lens::index(r) * r)).asin(),
        }
    }

    /// The ray between a point of the disk plane at radius `r` and a
    /// camera at distance `d` on the axis (a quarter turn apart):
    /// (angle at which the camera sees it, light travel time).
    pub fn face_on(self, r: f64, d: f64) -> (f64, f64) {
        let (b, t) = self.connect(r, d, FRAC_PI_2);
        (self.sight_angle(b, d), t)
    }
}
