//! An exact oracle for lensing by a Schwarzschild hole: a source at
//! infinity seen by a static camera at radius r_o (PHYSICS.md section 9).
//!
//! **Units: lengths in Schwarzschild radii (r_s = 1, so M = 1/2)**, angles
//! in radians. PHYSICS.md section 9 writes its formulas with M = 1 (r_s =
//! 2): its u = 1/r and 1/b^2 - u^2 + 2u^3 become, in r_s = 1 units,
//! 1/b^2 - u^2 + u^3, and its sqrt(1 - 2/r_O) becomes sqrt(1 - 1/r_o).
//!
//! Independent of the renderer's closed forms (Carlson elliptic integrals
//! in `src/physics/closed.rs`): every angle here is adaptive Gauss-Legendre
//! quadrature of the orbit equation (du/dphi)^2 = G(u) = 1/b^2 - u^2 + u^3,
//! u = 1/r, and every derivative is the same quadrature of the integrand
//! differentiated under the integral sign (no finite differences).
//!
//! Geometry. The camera is static at r_o > 1.5 (outside the photon
//! sphere). A pixel's direction makes the angle `theta` with the direction
//! to the hole, measured in the camera's own frame (0: straight at the
//! hole, pi: straight away). The ray's plane holds the hole, the camera
//! and the pixel's direction; in it the ray's position angle about the
//! hole, counted from the camera's position, grows along the ray. A ray
//! that escapes ends at infinity at position angle `Phi` (the swept
//! angle), which is also its direction there. The far side of the axis
//! (from the camera through the hole, continued) is Phi = pi; a source at
//! infinity at the angle `beta` from it, on the pixel's side, sits at
//! Phi = pi - beta (mod 2 pi), on the other side at Phi = pi + beta.
//!
//! The turning point. A ray with b > b_c has a periapsis u_p, a root of
//! G, and G(u) = (u_p - u) Q(u) with Q > 0 on [0, u_p]. The substitution
//! u = u_p - s^2 turns du / sqrt(G) into 2 ds / sqrt(Q), smooth, with
//! Q = k + m s^2 - s^4, k = u_p (2 - 3 u_p), m = 3 u_p - 1. Near the
//! critical ray k -> 0 and the integrand peaks like 2 / sqrt(k + s^2) at
//! s = 0 (the logarithmic winding); the adaptive rule refines there.
//!
//! Accuracy (measured against 45-digit mpmath quadrature,
//! validation/lens_reference.py, and Darwin's deflections): where theta
//! determines the ray well, Phi to 1.5e-15 relative, dPhi/dtheta to
//! 3e-15 and mu to 5e-15; the infinity-to-infinity deflection to 5e-13
//! rad (the reference's own digits). The quadrature is converged to
//! rounding (a tolerance 1000 times looser moves Phi by 2e-16 at most).
//! What remains is the conditioning of theta as an f64: an error of
//! eps theta |dPhi/dtheta| in Phi, which near the shadow's edge is about
//! 1e-16 / (b/b_c - 1) (1e-10 rad at 1e-6 of the edge, where dPhi/dtheta
//! and mu are good to 2e-10 and 1e-9). The image of order n has b/b_c - 1
//! of about e^(-(n + 1) pi) x 15: its mu is good to 1e-10 at order 4,
//! 3e-8 at order 6.

use std::f64::consts::PI;
use std::sync::OnceLock;

/// The critical impact parameter (r_s = 1): 3 sqrt(3) / 2. Rays with
/// b <= B_CRIT that move inwards fall in.
pub const B_CRIT: f64 = 2.598_076_211_353_316;

/// Relative tolerance of each adaptive quadrature, against the integral
/// of the integrand's absolute value.
const TOLERANCE: f64 = 1e-14;

/// The impact parameter (r_s = 1) of the ray that a static camera at r_o
/// (r_s = 1) sends at the angle theta (radians, camera frame) from the
/// hole: b = r_o sin(theta) / sqrt(1 - 1/r_o).
pub fn impact(r_o: f64, theta: f64) -> f64 {
    r_o * theta.sin() / (1.0 - 1.0 / r_o).sqrt()
}

/// The shadow's angular radius (radians, camera frame) for a static camera
/// at r_o (r_s = 1): sin(alpha) = (b_c / r_o) sqrt(1 - 1/r_o). Pixels with
/// theta <= this are captured.
pub fn shadow(r_o: f64) -> f64 {
    (B_CRIT * (1.0 - 1.0 / r_o).sqrt() / r_o).asin()
}

/// The deflection (radians) of a ray from infinity to infinity at impact
/// parameter b (r_s = 1): 2 int_0^{u_p} du / sqrt(G) - pi; None where
/// b <= b_c (captured).
pub fn deflection(b: f64) -> Option<f64> {
    (b > B_CRIT).then(|| {
        let orbit = Periapsis::new(b);
        integrate(|s| orbit.integrand(s), 0.0, orbit.p.sqrt())[0] * 2.0 - PI
    })
}

/// The angle Phi (radians, >= 0) that the ray through a pixel at the angle
/// theta (radians, camera frame, 0 at the hole) sweeps about the hole from
/// the camera at r_o (r_s = 1) to infinity, where it leaves in the
/// direction at position angle Phi (the far side of the axis is pi). None
/// where the ray falls in (theta <= the shadow's radius). For theta < pi/2
/// the ray moves inwards first and turns at its periapsis; for
/// theta > pi/2 it moves outwards all the way.
pub fn swept(r_o: f64, theta: f64) -> Option<f64> {
    swept_rate(r_o, theta).map(|(phi, _)| phi)
}

/// (Phi, dPhi/dtheta) of `swept` (r_s = 1, radians): the derivative
/// exactly, by differentiating under the integral sign. dPhi/dtheta < 0
/// wherever the ray escapes (a pixel further from the hole sweeps less).
pub fn swept_rate(r_o: f64, theta: f64) -> Option<(f64, f64)> {
    assert!(
        r_o > 1.5 && r_o.is_finite(),
        "lens oracle: camera radius {r_o} r_s must be finite and outside the photon sphere (> 1.5)"
    );
    assert!(
        (0.0..=PI).contains(&theta),
        "lens oracle: pixel angle {theta} rad must be within [0, pi]"
    );
    let u_o = 1.0 / r_o;
    let b = impact(r_o, theta);
    let (sin, cos) = theta.sin_cos();
    if b <= B_CRIT {
        if cos > 0.0 {
            return None;
        }
        // Outwards with no turning point: G > 0 on [0, u_o]. Phi =
        // int_0^{u_o} b / sqrt(1 - b^2 w) du, w = u^2 (1 - u), and
        // dPhi/db = int_0^{u_o} (1 - b^2 w)^(-3/2) du.
        let [phi, dphi_db] = integrate(
            |u| {
                let r = 1.0 / (1.0 - b * b * u * u * (1.0 - u)).sqrt();
                [b * r, r * r * r]
            },
            0.0,
            u_o,
        );
        return Some((phi, dphi_db * b * cos / sin));
    }
    let orbit = Periapsis::new(b);
    let (p, k) = (orbit.p, orbit.k);
    // s at the camera: s_o^2 = p - u_o, from G(u_o) = (p - u_o) Q(u_o) =
    // u_o^2 (1 - u_o) cot^2(theta), free of the cancellation in p - u_o
    // when theta is near pi/2.
    let q_o = (1.0 - p) * (p + u_o) - u_o * u_o;
    let s_o = u_o * (cos / sin).abs() * ((1.0 - u_o) / q_o).sqrt();
    let s_p = p.sqrt();
    let f = |s: f64| orbit.integrand(s);
    // Phi and dPhi/dp without the end-point terms.
    let [phi, dphi_dp] = if cos > 0.0 {
        // Inwards to the periapsis (s from s_o to 0), then out to
        // infinity (s from 0 to s_p).
        let [a, da] = integrate(f, 0.0, s_p);
        let [c, dc] = integrate(f, 0.0, s_o);
        [a + c, da + dc]
    } else {
        integrate(f, s_o, s_p)
    };
    // c = 1/b^2 = p^2 (1 - p): dc/dp = k, dc/dtheta = -2 cot(theta) / b^2.
    let dp_dtheta = -2.0 * cos / (b * b * k * sin);
    // The end point s_p = sqrt(p) moves with p: f(s_p) ds_p/dp =
    // 1 / (p sqrt(1 - p)). The camera's end s_o moves too; its term,
    // (+-) f(s_o) ds_o/dp dp/dtheta, is -2 / (b k sin(theta)) on both
    // sides of pi/2 (finite where s_o = 0).
    let end = 1.0 / (p * (1.0 - p).sqrt());
    let rate = (dphi_dp + end) * dp_dtheta - 2.0 / (b * k * sin);
    Some((phi, rate))
}

/// The signed lensing magnification of the ray through a pixel at the
/// angle theta (radians, camera frame) for a static camera at r_o (r_s =
/// 1): the pixel's solid angle at the camera over its footprint's on the
/// celestial sphere, mu = -sin(theta) / (sin(Phi) dPhi/dtheta), whose size
/// is sin(theta) / (sin(beta) |dPhi/dtheta|) (beta: the escape direction's
/// angle from the far side of the axis). The sign is the parity of the map
/// from image to sky, against the unlensed map (the identity): + where the
/// ray ends on the pixel's side of the axis (sin Phi > 0: primary and other
/// even-order images, and every ray looking away from the hole), - on the
/// other side (secondary and odd orders: mirrored). NaN where the ray is
/// captured; infinite on the axis's caustic (an Einstein ring, sin Phi = 0).
pub fn magnification(r_o: f64, theta: f64) -> f64 {
    match swept_rate(r_o, theta) {
        None => f64::NAN,
        Some((phi, rate)) => -theta.sin() / (phi.sin() * rate),
    }
}

/// The swept angle Phi of the image of order `order` (0, 1, 2, ...) of a
/// source at infinity at the angle beta (radians) from the far side of the
/// axis: even orders on the source's side, Phi = (order + 1) pi - beta;
/// odd orders on the other side, Phi = order pi + beta.
pub fn image_sweep(beta: f64, order: usize) -> f64 {
    if order.is_multiple_of(2) {
        (order + 1) as f64 * PI - beta
    } else {
        order as f64 * PI + beta
    }
}

/// The first n images of a point source at infinity at the angle beta
/// (radians, 0 < beta < pi) from the far side of the axis, seen by a static
/// camera at r_o (r_s = 1), in order 0, 1, 2, ... (see `image_sweep`): each
/// as (theta, mu), theta the image's angle from the hole's direction
/// (radians, camera frame, measured on the image's own side: even orders on
/// the source's side, odd orders opposite) and mu its signed magnification
/// (`magnification`: + for even orders, - for odd). The image's flux is
/// |mu| times the source's.
pub fn images(r_o: f64, beta: f64, n: usize) -> Vec<(f64, f64)> {
    assert!(
        beta > 0.0 && beta < PI,
        "lens oracle: source angle {beta} rad must be within (0, pi)"
    );
    (0..n)
        .map(|order| {
            let theta = aim(r_o, image_sweep(beta, order));
            (theta, magnification(r_o, theta))
        })
        .collect()
}

/// The pixel angle theta (radians, camera frame) whose ray, from a static
/// camera at r_o (r_s = 1), sweeps `target` (radians, > 0) on its way to
/// infinity. Phi falls monotonically from +infinity at the shadow's edge
/// to 0 at theta = pi, so the root is bracketed and found by Newton steps
/// with the exact derivative, safeguarded by bisection.
pub fn aim(r_o: f64, target: f64) -> f64 {
    assert!(
        target > 0.0,
        "lens oracle: swept angle {target} rad must be > 0"
    );
    let edge = shadow(r_o);
    // Bracket: Phi(hi) < target < Phi(lo), lo approaching the edge.
    let (mut lo, mut hi) = (edge, PI);
    for j in 1..=1100 {
        let x = edge + (PI - edge) * 0.5f64.powi(j);
        if x <= edge {
            break;
        }
        match swept(r_o, x) {
            Some(phi) if phi < target => hi = x,
            _ => {
                lo = x;
                break;
            }
        }
    }
    assert!(
        lo > edge,
        "lens oracle: the ray sweeping {target} rad lies closer to the shadow's edge than an f64 resolves"
    );
    let mut x = lo;
    for _ in 0..300 {
        let next = match swept_rate(r_o, x) {
            // Within rounding of the edge: treat as infinite sweep.
            None => {
                lo = x;
                0.5 * (lo + hi)
            }
            Some((phi, rate)) => {
                let g = phi - target;
                if g == 0.0 {
                    return x;
                }
                if g > 0.0 {
                    lo = x;
                } else {
                    hi = x;
                }
                let newton = x - g / rate;
                if newton > lo && newton < hi {
                    newton
                } else {
                    0.5 * (lo + hi)
                }
            }
        };
        if (next - x).abs() <= 2.0 * f64::EPSILON * x || hi - lo <= 2.0 * f64::EPSILON * hi {
            return next;
        }
        x = next;
    }
    x
}

/// A ray with b > b_c (r_s = 1) and its periapsis u_p = p.
struct Periapsis {
    p: f64,
    /// Q at the periapsis: p (2 - 3p), also dc/dp for c = 1/b^2.
    k: f64,
    m: f64,
}

impl Periapsis {
    fn new(b: f64) -> Periapsis {
        let p = periapsis(b);
        Periapsis {
            p,
            k: p * (2.0 - 3.0 * p),
            m: 3.0 * p - 1.0,
        }
    }

    /// [2 / sqrt(Q), d/dp of it] at s (u = p - s^2), with
    /// dQ/dp = (2 - 6p) + 3 s^2.
    fn integrand(&self, s: f64) -> [f64; 2] {
        let s2 = s * s;
        let q = self.k + s2 * (self.m - s2);
        let f = 2.0 / q.sqrt();
        [f, -(2.0 - 6.0 * self.p + 3.0 * s2) * f / (2.0 * q)]
    }
}

/// The periapsis u_p = 1/r_p (r_s = 1) of a ray at b > b_c: the root of
/// c - u^2 (1 - u) = 0, c = 1/b^2, in (0, 2/3) (the left side falls
/// monotonically there). Started from the cubic's trigonometric root and
/// polished by Newton steps kept inside the bracket.
fn periapsis(b: f64) -> f64 {
    let c = 1.0 / (b * b);
    let angle = (1.0 - 13.5 * c).clamp(-1.0, 1.0).acos();
    let mut u = 1.0 / 3.0 + 2.0 / 3.0 * (angle / 3.0 - 2.0 * PI / 3.0).cos();
    let (mut lo, mut hi) = (0.0, 2.0 / 3.0);
    if !(u > lo && u < hi) {
        u = c.sqrt();
    }
    for _ in 0..200 {
        let h = c - u * u * (1.0 - u);
        if h == 0.0 {
            return u;
        }
        if h > 0.0 {
            lo = u;
        } else {
            hi = u;
        }
        // dh/du = -u (2 - 3u).
        let newton = u + h / (u * (2.0 - 3.0 * u));
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - u).abs() <= f64::EPSILON * u {
            return next;
        }
        u = next;
    }
    u
}

/// The 12-point Gauss-Legendre rule on [-1, 1]: (node, weight), the nodes
/// found by Newton's method on the Legendre polynomial.
fn rule() -> &'static [(f64, f64)] {
    static RULE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    RULE.get_or_init(|| {
        const N: usize = 12;
        (0..N)
            .map(|i| {
                let mut x = (PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
                for _ in 0..100 {
                    let (p, d) = legendre(N, x);
                    let dx = p / d;
                    x -= dx;
                    if dx.abs() < 1e-16 {
                        break;
                    }
                }
                let (_, d) = legendre(N, x);
                (x, 2.0 / ((1.0 - x * x) * d * d))
            })
            .collect()
    })
}

/// (P_n(x), P_n'(x)) by the three-term recurrence.
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for j in 2..=n {
        let j = j as f64;
        let p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
        p0 = p1;
        p1 = p2;
    }
    (p1, n as f64 * (x * p1 - p0) / (x * x - 1.0))
}

/// The integral over [a, b] of a two-component integrand by adaptive
/// Gauss-Legendre: a panel is split until its two halves agree with the
/// whole to TOLERANCE (relative to the integral of |f|, shared out by
/// width). The accepted halves are far more accurate than that difference.
fn integrate(f: impl Fn(f64) -> [f64; 2], a: f64, b: f64) -> [f64; 2] {
    if b <= a {
        return [0.0; 2];
    }
    let panel = |lo: f64, hi: f64| {
        let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let (mut v, mut av) = ([0.0; 2], [0.0; 2]);
        for &(x, w) in rule() {
            let y = f(mid + half * x);
            for i in 0..2 {
                v[i] += w * half * y[i];
                av[i] += w * half * y[i].abs();
            }
        }
        (v, av)
    };
    const START: usize = 8;
    let mut stack = Vec::new();
    let mut scale = [0.0; 2];
    for i in 0..START {
        let lo = a + (b - a) * i as f64 / START as f64;
        let hi = a + (b - a) * (i + 1) as f64 / START as f64;
        let (v, av) = panel(lo, hi);
        scale = [scale[0] + av[0], scale[1] + av[1]];
        stack.push((lo, hi, v, av));
    }
    let tol = scale.map(|s| TOLERANCE * s);
    let mut total = [0.0; 2];
    while let Some((lo, hi, whole, size)) = stack.pop() {
        let mid = 0.5 * (lo + hi);
        let (l, al) = panel(lo, mid);
        let (r, ar) = panel(mid, hi);
        let share = (hi - lo) / (b - a);
        // Settled at the tolerance's share, or at the panel's own rounding
        // (where a steep peak holds most of the integral).
        let settled = (0..2).all(|i| {
            let diff = (l[i] + r[i] - whole[i]).abs();
            assert!(
                diff.is_finite(),
                "lens oracle: the integrand is not finite in [{lo}, {hi}]"
            );
            diff <= tol[i] * share || diff <= 64.0 * f64::EPSILON * size[i]
        });
        if settled || share < 1e-15 {
            total = [total[0] + l[0] + r[0], total[1] + l[1] + r[1]];
        } else {
            stack.push((lo, mid, l, al));
            stack.push((mid, hi, r, ar));
        }
    }
    total
}
