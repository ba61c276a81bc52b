//! The spacetime the exact model's light moves in: everything that depends
//! on the metric, behind one type chosen when the scene is built.
//!
//! The geodesic equation (as the integrator's right-hand side) and its
//! conserved quantities, the local frame of a camera, the frequency shift
//! of an emitter or of sky light, the disk's orbital angular velocity and
//! its innermost stable orbit, the shadow's size, the exact tail and the
//! closed-form tracer: the renderer asks a [`Spacetime`] for each, so a
//! second spacetime (a spinning hole) is a second variant here, not
//! conditions scattered through the code. An enum and `match`, resolved at
//! compile time per call, not a trait object per ray. Lengths in r_s, times
//! in r_s/c.

use super::closed::ClosedRay;
use glam::DVec3;

/// A spacetime of the exact model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Spacetime {
    /// A non-rotating hole: Schwarzschild coordinates read as Cartesian,
    /// x = r (sin th cos ph, sin th sin ph, cos th).
    #[default]
    Schwarzschild,
}

impl Spacetime {
    /// Its name, as reports give it.
    pub fn name(self) -> &'static str {
        match self {
            Spacetime::Schwarzschild => "Schwarzschild",
        }
    }

    /// The horizon's radius.
    #[inline]
    pub fn horizon(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => 1.0,
        }
    }

    /// The photon sphere's radius: inside it an inbound ray cannot come
    /// back out.
    #[inline]
    pub fn photon_sphere(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => super::PHOTON_SPHERE,
        }
    }

    /// The innermost stable circular orbit (of a prograde orbit).
    #[inline]
    pub fn isco(self) -> f64 {
        match self {
            Spacetime::Schwarzschild => 3.0,
        }
    }

    /// A direction measured by the camera at `x` (a static observer's
    /// orthonormal frame aligned with the coordinate axes) as the
    /// coordinate direction the geodesic equation integrates: the radial
    /// component shrinks by sqrt(1 - r_s/r).
    #[inline]
    pub fn camera_direction(self, x: DVec3, local: DVec3) -> DVec3 {
        match self {
            Spacetime::Schwarzschild => {
                let r = x.length();
                let n = x / r;
                let radial = local.dot(n);
                local + n * (radial * ((1.0 - 1.0 / r).sqrt() - 1.0))
            }
        }
    }

    /// The reflection of the photon direction `d` (coordinate) off a static
    /// mirror at `p` with coordinate-space normal `n`, by the law of
    /// reflection in the mirror's local static frame.
    pub fn reflect(self, p: DVec3, d: DVec3, n: DVec3) -> DVec3 {
        match self {
            Spacetime::Schwarzschild => schwarzschild_reflect(p, d, n),
        }
    }

    /// The photon's L_z / E of the state (x, v), for the disk's Doppler
    /// shift.
    #[inline]
    pub fn photon_lz_over_e(self, x: DVec3, v: DVec3) -> f64 {
        match self {
            Spacetime::Schwarzschild => super::shift::gr_photon_lz_over_e(x, v),
        }
    }

    /// ln g of light from the disk's material at radius `r_e` (on its
    /// circular orbit, or static without `doppler`) reaching the camera at
    /// `r_o`, for a photon of `lz_over_e`.
    #[inline]
    pub fn disk_ln_shift(self, r_e: f64, lz_over_e: f64, r_o: f64, doppler: bool) -> f64 {
        match self {
            Spacetime::Schwarzschild => {
                super::shift::gr_disk_ln_shift(r_e, lz_over_e, r_o, doppler)
            }
        }
    }

    /// ln g of light from a static emitter at radius `r_e` reaching the
    /// camera at `r_o` (r_e infinite: sky light).
    #[inline]
    pub fn static_ln_shift(self, r_e: f64, r_o: f64) -> f64 {
        match self {
            Spacetime::Schwarzschild if r_e.is_infinite() => -0.5 * (1.0 - 1.0 / r_o).ln(),
            Spacetime::Schwarzschild => 0.5 * ((1.0 - 1.0 / r_e) / (1.0 - 1.0 / r_o)).ln(),
        }
    }

    /// The angular velocity (per r_s/c of coordinate time) of a circular
    /// orbit at radius `r`: sqrt(GM / r^3).
    #[inline]
    pub fn orbital_angular_velocity(self, r: f64) -> f64 {
        match self {
            Spacetime::Schwarzschild => (0.5 / (r * r * r)).sqrt(),
        }
    }

    /// The shadow edge's angle from the direction to the hole (radians) for
    /// a camera at radius `r`.
    pub fn shadow_angle(self, r: f64) -> f64 {
        match self {
            Spacetime::Schwarzschild => {
                // At the photon sphere the product is 1 up to rounding (1 +
                // 1 ulp at r = 1.5): clamp so asin stays defined.
                let a = (super::B_CRIT_GR / r * (1.0 - 1.0 / r).sqrt())
                    .min(1.0)
                    .asin();
                // Inside the photon sphere the shadow covers more than half
                // the sky: the escape cone points outward.
                if r <= self.photon_sphere() {
                    std::f64::consts::PI - a
                } else {
                    a
                }
            }
        }
    }

    /// Traces the ray from `x` along coordinate direction `v` (the
    /// camera's, [`Spacetime::camera_direction`]) with this spacetime's
    /// integrator at `tolerance`; with `TIME` each segment carries the
    /// light's coordinate travel time.
    pub fn trace<const TIME: bool>(
        self,
        x: DVec3,
        v: DVec3,
        tolerance: f64,
        limits: &super::Limits,
        visit: impl FnMut(&super::Segment) -> super::Flow,
    ) -> super::Trace {
        match self {
            Spacetime::Schwarzschild => super::gr::trace::<TIME>(x, v, tolerance, limits, visit),
        }
    }

    /// Whether rays of this spacetime have the closed form.
    #[inline]
    pub fn has_closed_form(self) -> bool {
        match self {
            Spacetime::Schwarzschild => true,
        }
    }

    /// The ray from `x` along coordinate direction `v` in closed form, where
    /// it applies (see [`super::closed`]).
    #[inline]
    pub fn closed_ray(self, x: DVec3, v: DVec3) -> Option<ClosedRay> {
        match self {
            Spacetime::Schwarzschild => ClosedRay::new(x, v),
        }
    }
}

/// The exact model's reflection off a static mirror at `x` (r_s) for a
/// photon of coordinate velocity `dir` and a surface whose coordinate
/// normal is `n` (the gradient of its defining function, either
/// orientation). The law of reflection holds in the mirror's local static
/// frame, where space is measured with the Schwarzschild metric: there a
/// vector's radial component is its coordinate one divided by
/// sqrt(1 - r_s/r), while a normal (a gradient) has its radial component
/// multiplied by it. The direction is reflected there and mapped back; its
/// local length, the photon's energy in that frame, is kept.
#[inline]
fn schwarzschild_reflect(x: DVec3, dir: DVec3, n: DVec3) -> DVec3 {
    let r = x.length();
    let e = x / r;
    let s = (1.0 - 1.0 / r).sqrt();
    let local = dir + e * (dir.dot(e) * (1.0 / s - 1.0));
    let normal = (n + e * (n.dot(e) * (s - 1.0))).normalize();
    let out = super::reflect(local, normal);
    out + e * (out.dot(e) * (s - 1.0))
}

#[cfg(test)]
mod tests {
    use super::super::reflect;
    use super::*;

    #[test]
    fn static_frame_reflection_limits() {
        let d = DVec3::new(0.3, 1.0, -0.2);
        let n = DVec3::new(1.0, -1.0, 0.5).normalize();
        // Far from the hole it is the flat law.
        let far = DVec3::new(1e9, 0.0, 0.0);
        assert!(
            Spacetime::Schwarzschild
                .reflect(far, d, n)
                .distance(reflect(d, n))
                < 1e-8
        );
        // A radial normal: only the radial part flips, in any frame.
        let x = DVec3::new(0.0, 2.0, 0.0);
        let r = Spacetime::Schwarzschild.reflect(x, d, DVec3::Y);
        assert!(r.distance(DVec3::new(0.3, -1.0, -0.2)) < 1e-12, "{r}");
        // Near the hole a slanted mirror differs from the flat law, and
        // the local length (the photon's energy there) is kept.
        let x = DVec3::new(3.0, 0.0, 0.0);
        let n = DVec3::new(1.0, -1.0, 0.0).normalize();
        let d = DVec3::Y;
        let r = Spacetime::Schwarzschild.reflect(x, d, n);
        assert!(r.angle_between(reflect(d, n)) > 0.1);
        let local = |v: DVec3| {
            let s = (1.0 - 1.0 / 3.0f64).sqrt();
            DVec3::new(v.x / s, v.y, v.z).length()
        };
        assert!((local(r) - local(d)).abs() < 1e-12);
    }
}
