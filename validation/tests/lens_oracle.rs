//! The exact Schwarzschild lens oracle (common/lens.rs) against known
//! physics: Darwin's deflections, the far-camera limit, the shadow's
//! edge, the weak-field point lens, the e^(2 pi) ratio of successive
//! images and its derivative against finite differences. Units r_s = 1.

mod common;

use common::lens::{
    B_CRIT, aim, deflection, image_sweep, images, impact, magnification, shadow, swept, swept_rate,
};
use std::f64::consts::{FRAC_PI_2, PI};

/// How finely Phi can be aimed at with theta an f64: two ulps of theta
/// times dPhi/dtheta (near the shadow's edge this dominates).
fn resolution(theta: f64, rate: f64) -> f64 {
    2.0 * f64::EPSILON * theta * rate.abs()
}

/// Infinity-to-infinity deflections (PHYSICS.md section 2, Darwin 1959,
/// given to 12 significant figures).
#[test]
fn deflection_matches_darwin() {
    let darwin = [
        (2.7, 2.91939633961),
        (3.0, 1.71938831023),
        (5.0, 0.590395787606),
        (10.0, 0.236135995388),
        (50.0, 0.0412225397493),
        (100.0, 0.0202999662395),
    ];
    for (b, want) in darwin {
        let got = deflection(b).unwrap();
        // The reference's last digit: 5e-12 at most.
        assert!((got - want).abs() < 6e-12, "b = {b}: {got} vs {want}");
    }
    // The same values at the project's other landmarks (section 2).
    let pi_at = deflection(2.678479).unwrap();
    assert!((pi_at - PI).abs() < 2e-5, "{pi_at}");
    let half_pi_at = deflection(3.083783).unwrap();
    assert!((half_pi_at - FRAC_PI_2).abs() < 2e-6, "{half_pi_at}");
    assert!(deflection(2.59).is_none());
    assert!(deflection(2.61).is_some());
}

/// Phi and dPhi/dtheta against 45-digit mpmath quadrature
/// (validation/lens_reference.py): inwards, strongly and weakly bent,
/// across pi/2, outwards with and without a turning point continuation.
/// The measured agreement at these well-conditioned points is 1e-15
/// (Phi) and 3e-15 (dPhi/dtheta); mu inherits both.
#[test]
fn matches_high_precision_quadrature() {
    let reference = [
        (10.0, 0.26, 5.70110760523048, -85.34606810942297),
        (10.0, 0.9, 2.4869803779079542, -1.361935611179705),
        (10.0, FRAC_PI_2, 1.681734378964349, -1.1160979977064869),
        (10.0, 2.0, 1.2118173548320832, -1.0788453027166558),
        (10.0, 3.0, 0.14926564535625655, -1.0543871441510575),
        (3.0, 0.8, 6.015443386444866, -67.2115004764092),
        (1e6, 3e-6, 4.8609749824860495, -1987557.0314233736),
        (1e6, 1.0, 2.1415944840800374, -1.0000021753478514),
    ];
    for (r_o, theta, phi, rate) in reference {
        let (got, got_rate) = swept_rate(r_o, theta).unwrap();
        assert!(
            (got / phi - 1.0).abs() < 4e-15,
            "{r_o} {theta}: {got} vs {phi}"
        );
        assert!(
            (got_rate / rate - 1.0).abs() < 1e-14,
            "{r_o} {theta}: {got_rate} vs {rate}"
        );
    }
}

/// A far camera: the ray at impact parameter b sweeps pi + deflection(b)
/// less the part of the path from infinity to the camera it does not
/// travel, int_0^{1/r_o} b du / sqrt(1 - b^2 u^2 (1 - u)) =
/// b / r_o + b^3 / (6 r_o^3) - b^3 / (8 r_o^4) + ...
#[test]
fn far_camera_sweeps_pi_plus_deflection() {
    for b in [3.0, 5.0, 10.0] {
        let full = PI + deflection(b).unwrap();
        for r_o in [1e4, 1e6, 1e12f64] {
            let theta = (b * (1.0 - 1.0 / r_o).sqrt() / r_o).asin();
            assert!((impact(r_o, theta) / b - 1.0).abs() < 1e-14);
            let missing = full - swept(r_o, theta).unwrap();
            let series = b / r_o + b.powi(3) / (6.0 * r_o.powi(3));
            // The next term, and the swept angles' own rounding.
            let off = missing - series;
            let tol = b.powi(3) / r_o.powi(4) + 2e-15;
            assert!(off.abs() < tol, "b {b} r_o {r_o}: {missing} ({off:e})");
        }
    }
}

/// The capture edge found from the oracle, against PHYSICS.md section 2's
/// shadow angles; beyond it Phi diverges like -ln(theta - edge) (one
/// radian for each e-fold of b - b_c, exactly, for Schwarzschild). Between
/// 1e-7 and 1e-8 of the edge the decade sweeps ln 10 to 5e-7: the next
/// order (delta ln delta) and theta's rounding (1e-8 rad of Phi there).
#[test]
fn shadow_edge_and_logarithmic_winding() {
    for (r_o, degrees) in [(10.0, 14.269027), (100.0, 1.481291)] {
        let (mut lo, mut hi) = (0.0, FRAC_PI_2);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if swept(r_o, mid).is_none() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!(
            (hi.to_degrees() - degrees).abs() < 6e-7,
            "{r_o}: {}",
            hi.to_degrees()
        );
        assert!((shadow(r_o) - hi).abs() < 1e-15);
        let edge = shadow(r_o);
        let at = |d: f64| swept(r_o, edge * (1.0 + d)).unwrap();
        let decade = at(1e-8) - at(1e-7);
        assert!((decade - 10f64.ln()).abs() < 1e-6, "{r_o}: {decade}");
    }
}

/// The weak-field limit: a camera at r_o = 1e6 r_s and a source at
/// infinity. The point lens has beta = theta - theta_E^2 / theta with
/// theta_E^2 = 2 r_s / r_o (the deflection 2 r_s / b, b = r_o theta, and
/// the distance ratio D_LS / D_S = 1 for a source at infinity), whose
/// images at u = beta / theta_E have |mu| = [(u^2+2)/(u sqrt(u^2+4)) +- 1] / 2
/// at theta = theta_E (sqrt(u^2+4) +- u) / 2. Its next order (15 pi / 16)
/// (r_s / b)^2 is (15 pi / 32) r_s / b = 2e-3 of the deflection at b =
/// 707 r_s (the secondary at u = 1.5), the size of the point lens's
/// measured error; with the deflection's series to (r_s / b)^3 the oracle
/// agrees to 1.1e-6, the 1/r_o of the camera's own frame (below).
#[test]
fn weak_field_point_lens() {
    let r_o: f64 = 1e6;
    let einstein = (2.0 / r_o).sqrt();
    // The deflection's series (r_s = 1) and its derivative.
    let alpha = |b: f64| 2.0 / b + 15.0 * PI / 16.0 / (b * b) + 16.0 / 3.0 / (b * b * b);
    let dalpha = |b: f64| -2.0 / (b * b) - 15.0 * PI / 8.0 / (b * b * b) - 16.0 / (b * b * b * b);
    for u in [0.2, 0.7, 1.5] {
        let beta = u * einstein;
        let got = images(r_o, beta, 2);
        let root = (u * u + 4.0).sqrt();
        let point = (u * u + 2.0) / (u * root);
        let lens = [
            (einstein * (root + u) / 2.0, (point + 1.0) / 2.0),
            (einstein * (root - u) / 2.0, -(point - 1.0) / 2.0),
        ];
        for (k, ((theta, mu), (theta_pl, mu_pl))) in got.iter().zip(lens).enumerate() {
            assert!(
                (theta / theta_pl - 1.0).abs() < 3e-3,
                "u {u} image {k}: theta {theta} vs {theta_pl}"
            );
            assert!(
                (mu / mu_pl - 1.0).abs() < 3e-3,
                "u {u} image {k}: mu {mu} vs {mu_pl}"
            );
            // The series lens: g(t) = t - alpha(r_o t) = +-beta, mu = t / (g g').
            let side = if k == 0 { 1.0 } else { -1.0 };
            let mut t = theta_pl;
            for _ in 0..50 {
                let g = t - alpha(r_o * t) - side * beta;
                t -= g / (1.0 - r_o * dalpha(r_o * t));
            }
            let series = t / (side * beta * (1.0 - r_o * dalpha(r_o * t)));
            assert!(
                (theta / t - 1.0).abs() < 3e-6,
                "u {u} image {k}: theta {theta} vs {t}"
            );
            assert!(
                (mu / series - 1.0).abs() < 3e-6,
                "u {u} image {k}: mu {mu} vs {series}"
            );
        }
    }
    // Far from the hole: b = r_o sin(theta) / sqrt(1 - r_s/r_o) stretches
    // every footprint by 1 / sqrt(1 - r_s/r_o) both ways, so mu =
    // 1 - r_s/r_o, and the point lens adds 2 / u^4 (1e-12 at pi/2).
    for theta in [FRAC_PI_2, 3.0] {
        let mu = magnification(r_o, theta);
        assert!((mu - (1.0 - 1.0 / r_o)).abs() < 1e-11, "{theta}: {mu}");
    }
}

/// Images of orders 0 to 6: on alternating sides with alternating parity,
/// each sweeping its target and approaching the shadow's edge. The
/// relativistic images (order 2 on: deflected by 2 pi or more) of orders
/// n and n+2 on the same side differ in |mu| by e^(2 pi) (PHYSICS.md
/// section 9) in the strong-deflection limit, measured here to 6% (orders
/// 2 and 4), 1% (3 and 5) and 2e-4 (4 and 6), approaching it as the order
/// grows. (Orders 0 and 1 are the weak-field pair for a far camera: no
/// such ratio.)
#[test]
fn image_orders_parity_and_exponential_dimming() {
    for r_o in [10.0, 100.0] {
        let edge = shadow(r_o);
        for beta in [0.05, 0.5, 2.0] {
            let found = images(r_o, beta, 7);
            for (k, &(theta, mu)) in found.iter().enumerate() {
                let (phi, rate) = swept_rate(r_o, theta).unwrap();
                let target = image_sweep(beta, k);
                let tol = 1e-13 * target + resolution(theta, rate);
                assert!((phi - target).abs() < tol, "order {k}: {phi} vs {target}");
                assert_eq!(
                    mu > 0.0,
                    k % 2 == 0,
                    "r_o {r_o} beta {beta} order {k}: mu {mu}"
                );
                assert!(theta > edge);
                if k >= 2 {
                    assert!(
                        theta < found[k - 2].0,
                        "order {k} lies inside order {}",
                        k - 2
                    );
                }
            }
            let rel = |k: usize| found[k].1 / found[k + 2].1 / (2.0 * PI).exp() - 1.0;
            for (k, tol) in [(2, 0.06), (3, 0.01), (4, 2e-4)] {
                assert!(
                    rel(k).abs() < tol,
                    "r_o {r_o} beta {beta}: mu{k}/mu{} ({:e})",
                    k + 2,
                    rel(k)
                );
            }
            assert!(rel(4).abs() < rel(2).abs());
        }
    }
}

/// dPhi/dtheta from the differentiated quadrature against central finite
/// differences, inwards, across pi/2, outwards with and without a turning
/// point continuation (b < b_c), near the shadow's edge and near pi.
#[test]
fn derivative_matches_finite_differences() {
    for r_o in [3.0, 10.0, 1e3] {
        let edge = shadow(r_o);
        let mut thetas = vec![
            edge * (1.0 + 1e-6),
            edge * 1.01,
            0.5 * (edge + FRAC_PI_2),
            FRAC_PI_2 - 1e-3,
            FRAC_PI_2,
            FRAC_PI_2 + 1e-3,
            2.5,
            PI - 1e-3,
        ];
        // An outward ray with b < b_c.
        let below = PI - (B_CRIT * (1.0 - 1.0 / r_o).sqrt() / r_o).asin() + 1e-3;
        thetas.push(below.min(PI - 1e-4));
        for theta in thetas {
            let (_, rate) = swept_rate(r_o, theta).unwrap();
            // Central differences at h and 2h, Richardson-extrapolated
            // (error h^4), with h a hundredth of the distance to the
            // nearest end (where Phi ~ -ln(theta - edge) varies fastest).
            let h = 1e-2 * (theta - edge).min(PI - theta).min(0.1) / 2.0;
            let central = |h: f64| {
                (swept(r_o, theta + h).unwrap() - swept(r_o, theta - h).unwrap()) / (2.0 * h)
            };
            let fd = (4.0 * central(h) - central(2.0 * h)) / 3.0;
            assert!(rate < 0.0);
            assert!(
                (rate / fd - 1.0).abs() < 1e-7,
                "r_o {r_o} theta {theta}: {rate} vs {fd}"
            );
        }
    }
}

/// The root finder returns the ray that sweeps the asked angle, for
/// sweeps from nearly 0 (looking away) to 5 pi (near the edge).
#[test]
fn aim_inverts_swept() {
    for r_o in [2.0, 10.0, 1e5] {
        for target in [1e-3, 1.0, PI, 2.0 * PI, 5.0 * PI] {
            let theta = aim(r_o, target);
            let (phi, rate) = swept_rate(r_o, theta).unwrap();
            let tol = 1e-13 * target.max(1.0) + resolution(theta, rate);
            assert!((phi - target).abs() < tol, "{r_o} {target}: {phi}");
        }
    }
}
