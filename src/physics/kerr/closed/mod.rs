//! Kerr light rays in closed form (Gralla and Lupsasca, "Null geodesics
//! of the Kerr exterior", PRD 101, 044032, 2020), in units of M: the
//! radial potential's roots and their cases, from which the Mino time
//! between radii, and so each equatorial crossing and the escape, are
//! elliptic integrals (`super::elliptic`).
//!
//! A photon of energy-rescaled angular momentum lambda = L_z / E and
//! Carter constant eta = Q / E^2 moves in r under the quartic
//! R(r) = (r^2 + a^2 - a lambda)^2 - Delta (eta + (lambda - a)^2)
//!      = r^4 + A r^2 + B r + C,
//! A = a^2 - eta - lambda^2, B = 2 (eta + (lambda - a)^2), C = -a^2 eta.
//!
//! The module's files (the WGSL twin of them all is
//! `src/gpu/kerr_closed.wgsl`, with `src/gpu/closed.wgsl`'s elliptic
//! integrals):
//! - `roots.rs`: the radial potential's roots and their cases;
//! - `radial.rs`: the radial motion in Jacobi's functions, its Mino time
//!   and the azimuth's radial integrals;
//! - `times.rs`: the coordinate time's radial integrals and a crossing's
//!   time;
//! - `polar.rs`: the polar motion, ordinary and vortical;
//! - `ray.rs`: the ray from a camera, its equatorial crossings and its
//!   direction at infinity.

mod polar;
mod radial;
mod ray;
mod roots;
mod times;

pub use polar::PolarMotion;
pub(crate) use ray::ks_azimuth_term;
#[cfg(test)]
pub(crate) use ray::test_rays::sample_rays;
pub use ray::{Crossing, CrossingPoint, KerrRay, KsStart, State};
pub use roots::{RadialRoots, RootCase};
