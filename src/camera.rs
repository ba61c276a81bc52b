//! Pinhole camera.
//!
//! Rays start at the camera centre and pass through points of the image
//! plane: direction = forward + (u - 1/2) * right * w + (1/2 - v) * up * h,
//! with (u, v) the position in the image (0..1, v down) and w, h the plane's
//! size at unit distance from the vertical field of view and the aspect
//! ratio, so pixels are square.
//!
//! With the exact model the camera is an observer at rest in a frame (the
//! static one, or with spin the locally non-rotating one): the pixel
//! directions are directions in its local orthonormal frame and are
//! converted to the coordinate directions the integrator uses
//! ([`crate::physics::Spacetime::camera_direction`]). The seed model's space is
//! flat and its directions are used as they are. A camera may also move
//! relative to that frame: each direction is then aberrated and its light's
//! frequency multiplied by the Doppler factor D = 1 / (gamma (1 - beta cos
//! th')), th' the angle between the look direction and the velocity.

use crate::physics::spacetime::ClosedStart;
use glam::DVec3;

/// A pinhole camera in Schwarzschild units (r_s = 1).
#[derive(Clone, Debug)]
pub struct Camera {
    /// Centre of projection.
    pub position: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit vector to the right in the image.
    pub right: DVec3,
    /// Unit vector up in the image.
    pub up: DVec3,
    /// Half-height of the image plane at unit distance, tan(fov / 2).
    pub half_height: f64,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The spacetime whose static observer the camera is (the exact
    /// model): its local directions are converted to the coordinate ones
    /// the geodesic equation integrates. None: flat (the seed model).
    pub frame: Option<crate::physics::Spacetime>,
    /// Horizontal offset of the image window, in image-plane units at unit
    /// distance (0 for a symmetric frustum; stereo eyes shift it).
    pub shift: f64,
    /// The frame the camera is at rest in, before its own velocity.
    pub rest_frame: crate::physics::Frame,
    /// Its velocity relative to that frame (units of c, along the scene's
    /// axes as its frame has them; |v| < 1).
    pub velocity: DVec3,
    /// The spinning hole's conversion of local directions to coordinate
    /// ones, an affine map found once for the position and frame it was
    /// found at (the frame's vectors cost more than the rest of a ray in
    /// closed form).
    basis: std::sync::OnceLock<Option<Basis>>,
    /// Where its rays in closed form start, likewise found once (for the
    /// spacetime and position it was found at).
    closed_start: std::sync::OnceLock<(crate::physics::Spacetime, ClosedStart)>,
}

/// A camera's affine map from local to coordinate directions at `at` in
/// `frame`.
#[derive(Clone, Copy, Debug)]
struct Basis {
    at: DVec3,
    frame: crate::physics::Frame,
    map: glam::DMat3,
    offset: DVec3,
}

/// Why a camera cannot be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraError {
    /// `look_at` coincides with `position`.
    NoViewDirection,
    /// `up` is zero or parallel to the view direction.
    UpAlongView,
}

impl Camera {
    /// Builds the camera basis; `fov` is the vertical field of view in degrees.
    pub fn new(
        position: DVec3,
        look_at: DVec3,
        up: DVec3,
        fov: f64,
        width: u32,
        height: u32,
        frame: Option<crate::physics::Spacetime>,
    ) -> Result<Camera, CameraError> {
        let forward = (look_at - position)
            .try_normalize()
            .ok_or(CameraError::NoViewDirection)?;
        let side = forward.cross(up);
        if !(side.length() > 1e-9 * up.length()) {
            return Err(CameraError::UpAlongView);
        }
        let right = side.normalize();
        let up = right.cross(forward);
        Ok(Camera {
            position,
            forward,
            right,
            up,
            half_height: (fov.to_radians() * 0.5).tan(),
            width,
            height,
            frame,
            shift: 0.0,
            rest_frame: crate::physics::Frame::default(),
            velocity: DVec3::ZERO,
            basis: std::sync::OnceLock::new(),
            closed_start: std::sync::OnceLock::new(),
        })
    }

    /// Unit direction, in the camera's local frame, through image point
    /// (`px`, `py`) in pixels from the top-left corner (pixel centres at +0.5).
    pub fn local_direction(&self, px: f64, py: f64) -> DVec3 {
        let (sx, sy) = self.plane_point(px, py);
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// The image plane's point (right, up) at unit distance through image
    /// point (`px`, `py`).
    fn plane_point(&self, px: f64, py: f64) -> (f64, f64) {
        let h = self.half_height;
        let w = h * self.width as f64 / self.height as f64;
        let sx = (2.0 * px / self.width as f64 - 1.0) * w + self.shift;
        let sy = (1.0 - 2.0 * py / self.height as f64) * h;
        (sx, sy)
    }

    /// The solid angle (sr) one pixel spans in the camera's own frame at
    /// image point (`px`, `py`): the image plane's pixel area at unit
    /// distance, (2 h / height)^2, foreshortened by 1 / |s|^3 with s the
    /// plane point (forward + right sx + up sy).
    pub fn pixel_solid_angle(&self, px: f64, py: f64) -> f64 {
        let (sx, sy) = self.plane_point(px, py);
        let side = 2.0 * self.half_height / self.height as f64;
        side * side / (1.0 + sx * sx + sy * sy).powf(1.5)
    }

    /// Image point (pixels) where a point in front of the camera projects
    /// along a straight line: the inverse of [`Camera::local_direction`].
    pub fn project(&self, point: DVec3) -> Option<(f64, f64)> {
        let d = point - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let h = self.half_height;
        let w = h * self.width as f64 / self.height as f64;
        let (sx, sy) = (d.dot(self.right) / z - self.shift, d.dot(self.up) / z);
        Some((
            (sx / w + 1.0) * 0.5 * self.width as f64,
            (1.0 - sy / h) * 0.5 * self.height as f64,
        ))
    }

    /// The left and right eyes of an off-axis stereo pair: each moved half
    /// the `separation` along `right`, both looking along `forward`, their
    /// image windows shifted so they coincide on the plane at `convergence`
    /// (zero parallax there; nearer points pop out, farther ones recede).
    pub fn stereo_pair(&self, separation: f64, convergence: f64) -> (Camera, Camera) {
        let eye = |sign: f64| Camera {
            position: self.position + self.right * (sign * 0.5 * separation),
            shift: self.shift - sign * 0.5 * separation / convergence,
            basis: std::sync::OnceLock::new(),
            closed_start: std::sync::OnceLock::new(),
            ..self.clone()
        };
        (eye(-1.0), eye(1.0))
    }

    /// What the closed-form rays of spacetime `st` from `at` share: found
    /// once for the camera's own position.
    pub fn closed_start(&self, st: crate::physics::Spacetime, at: DVec3) -> ClosedStart {
        let (found_st, start) = self
            .closed_start
            .get_or_init(|| (st, st.closed_start(self.position)));
        if *found_st == st && start.point() == at {
            *start
        } else {
            st.closed_start(at)
        }
    }

    /// Initial direction of the ray through (`px`, `py`) for the integrator.
    pub fn ray_direction(&self, px: f64, py: f64) -> DVec3 {
        self.ray(px, py).0
    }

    /// The ray through (`px`, `py`): its initial direction for the
    /// integrator and ln D, the Doppler factor of the camera's motion for
    /// all light arriving along it (0 at rest).
    pub fn ray(&self, px: f64, py: f64) -> (DVec3, f64) {
        let look = self.local_direction(px, py);
        let (d, ln_doppler) = aberrate(look, self.velocity);
        let dir = match (self.frame, self.linear_map()) {
            (_, Some(b)) => b.map * d + b.offset,
            (Some(st), None) => st.camera_direction_in(self.position, d, self.rest_frame),
            (None, None) => d,
        };
        (dir, ln_doppler)
    }

    /// The frame's map of local directions to coordinate ones where it is
    /// linear (built once).
    fn linear_map(&self) -> Option<&Basis> {
        let st = self.frame?;
        let basis = self.basis.get_or_init(|| {
            st.camera_basis(self.position, self.rest_frame)
                .map(|(map, offset)| Basis {
                    at: self.position,
                    frame: self.rest_frame,
                    map,
                    offset,
                })
        });
        basis
            .as_ref()
            .filter(|b| b.at == self.position && b.frame == self.rest_frame)
    }

    /// The ray's coordinate direction through (`px`, `py`) ([`Camera::ray`])
    /// and its derivatives per pixel along x and y: exact for a camera at
    /// rest whose frame maps directions linearly (flat space, Schwarzschild's
    /// static frame, a Kerr frame's basis: the image plane's normalised
    /// point, mapped), else central differences over 1e-4 px.
    pub fn ray_rates(&self, px: f64, py: f64) -> (DVec3, [DVec3; 2]) {
        use crate::physics::Spacetime;
        let (v, _) = self.ray(px, py);
        let exact = match (self.frame, self.linear_map()) {
            _ if self.velocity != DVec3::ZERO => None,
            (_, Some(b)) => Some(b.map),
            (None, None) => Some(glam::DMat3::IDENTITY),
            // Its radial component scaled by sqrt(1 - r_s / r).
            (Some(st @ Spacetime::Schwarzschild), None) => Some(glam::DMat3::from_cols(
                st.camera_direction(self.position, DVec3::X),
                st.camera_direction(self.position, DVec3::Y),
                st.camera_direction(self.position, DVec3::Z),
            )),
            (Some(Spacetime::Kerr { .. }), None) => None,
        };
        if let Some(map) = exact {
            let h = self.half_height;
            let w = h * self.width as f64 / self.height as f64;
            let (sx, sy) = self.plane_point(px, py);
            let s = self.forward + self.right * sx + self.up * sy;
            let len = s.length();
            let d = s / len;
            // d(s / |s|) = (ds - d (d . ds)) / |s|.
            let along = |ds: DVec3| map * ((ds - d * d.dot(ds)) / len);
            let per_px = [
                self.right * (2.0 * w / self.width as f64),
                self.up * (-2.0 * h / self.height as f64),
            ];
            return (v, per_px.map(along));
        }
        const H: f64 = 1e-4;
        let diff = |(ax, ay): (f64, f64)| {
            (self.ray(px + ax * H, py + ay * H).0 - self.ray(px - ax * H, py - ay * H).0)
                / (2.0 * H)
        };
        (v, [diff((1.0, 0.0)), diff((0.0, 1.0))])
    }
}

/// The direction in the rest frame of a look direction `look` of an
/// observer moving at `velocity` (units of c), and ln D: light arriving
/// along -look is aberrated forward (cos th = (cos th' - beta) / (1 - beta
/// cos th'), th' from the velocity) and its frequency multiplied by D = 1
/// / (gamma (1 - beta cos th')).
pub fn aberrate(look: DVec3, velocity: DVec3) -> (DVec3, f64) {
    let beta = velocity.length();
    if beta == 0.0 {
        return (look, 0.0);
    }
    let gamma = 1.0 / ((1.0 - beta) * (1.0 + beta)).sqrt();
    let b = velocity / beta;
    // The photon travels along n' = -look in the moving frame; in the
    // rest frame along n, by the boost.
    let n1 = -look;
    let c = n1.dot(b);
    let n = (n1 + b * ((gamma - 1.0) * c + gamma * beta)) / (gamma * (1.0 + beta * c));
    (-n.normalize(), -(gamma * (1.0 + beta * c)).ln())
}

impl Camera {
    /// Focal length in pixels: a direction at angle a from the axis lands
    /// f * tan(a) pixels from the image centre.
    pub fn focal_pixels(&self) -> f64 {
        self.height as f64 * 0.5 / self.half_height
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(w: u32, h: u32) -> Camera {
        Camera::new(
            DVec3::new(0.0, -10.0, 0.0),
            DVec3::ZERO,
            DVec3::Z,
            60.0,
            w,
            h,
            None,
        )
        .unwrap()
    }

    #[test]
    fn the_rays_rates_are_the_direction_maps_derivatives() {
        // Exact (flat, and a Schwarzschild and a Kerr frame at rest, whose
        // maps are linear) and by differences (a moving camera), against
        // central differences of Camera::ray over 1e-4 px (truncation
        // ~1e-9 of the pixel scale).
        let spaces = [
            None,
            Some(crate::physics::Spacetime::Schwarzschild),
            Some(crate::physics::Spacetime::Kerr { a: 0.9 }),
        ];
        for (k, frame) in spaces.into_iter().chain([None]).enumerate() {
            let mut c = Camera::new(
                DVec3::new(1.0, -6.0, 2.0),
                DVec3::ZERO,
                DVec3::Z,
                70.0,
                64,
                48,
                frame,
            )
            .unwrap();
            c.shift = 0.1;
            if k == 3 {
                c.velocity = DVec3::new(0.3, 0.2, 0.0);
            }
            for (px, py) in [(0.5, 0.5), (31.7, 20.2), (63.0, 47.5)] {
                let (v, [dx, dy]) = c.ray_rates(px, py);
                assert_eq!(v, c.ray(px, py).0);
                let h = 1e-4;
                let fx = (c.ray(px + h, py).0 - c.ray(px - h, py).0) / (2.0 * h);
                let fy = (c.ray(px, py + h).0 - c.ray(px, py - h).0) / (2.0 * h);
                for (got, want) in [(dx, fx), (dy, fy)] {
                    let e = (got - want).length() / want.length();
                    assert!(e < 1e-7, "{frame:?} {k} at {px} {py}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn centre_pixel_looks_at_target_and_edges_span_fov() {
        let c = cam(101, 101);
        let d = c.local_direction(50.5, 50.5);
        assert!((d - DVec3::Y).length() < 1e-12);
        let top = c.local_direction(50.5, 0.0);
        assert!((top.angle_between(DVec3::Y).to_degrees() - 30.0).abs() < 1e-9);
        assert!(top.z > 0.0, "row 0 is at the top");
        let right = c.local_direction(101.0, 50.5);
        assert!(right.x > 0.0, "last column is on the right");
    }

    #[test]
    fn pixels_are_square() {
        let c = cam(200, 100);
        let f = c.focal_pixels();
        let dx = c.local_direction(100.0 + 10.0, 50.0);
        let dy = c.local_direction(100.0, 50.0 - 10.0);
        let ax = (dx.x / dx.y * f, dy.z / dy.y * f);
        assert!(
            (ax.0 - 10.0).abs() < 1e-9 && (ax.1 - 10.0).abs() < 1e-9,
            "{ax:?}"
        );
    }

    #[test]
    fn pixel_solid_angles_add_up_to_the_frustum() {
        // A rectangular pyramid of half-angles a, b spans 4 asin(sin a sin b).
        let c = cam(120, 80);
        let (hh, hw) = (c.half_height, c.half_height * 1.5);
        let exact = 4.0 * (hw.atan().sin() * hh.atan().sin()).asin();
        // Midpoint rule on a 4 x 4 grid within each pixel.
        let mut sum = 0.0;
        for y in 0..80 * 4 {
            for x in 0..120 * 4 {
                sum += c.pixel_solid_angle((x as f64 + 0.5) / 4.0, (y as f64 + 0.5) / 4.0) / 16.0;
            }
        }
        // The midpoint rule is good to ~1e-6 here; a wrong foreshortening
        // is off by percent.
        assert!((sum / exact - 1.0).abs() < 1e-5, "{sum} vs {exact}");
    }

    #[test]
    fn stereo_frusta_agree_on_the_convergence_plane() {
        let c = Camera::new(
            DVec3::new(0.0, -20.0, 3.0),
            DVec3::ZERO,
            DVec3::Z,
            45.0,
            640,
            360,
            None,
        )
        .unwrap();
        let (conv, sep) = (18.0, 1.5);
        let (l, r) = c.stereo_pair(sep, conv);
        assert!(((l.position - r.position).length() - sep).abs() < 1e-12);
        // Points on the convergence plane project to the same pixel.
        for (a, b) in [(0.0, 0.0), (3.0, -1.0), (-5.0, 2.5), (6.0, 3.0)] {
            let p = c.position + c.forward * conv + c.right * a + c.up * b;
            let (pl, pr) = (l.project(p).unwrap(), r.project(p).unwrap());
            assert!(
                (pl.0 - pr.0).abs() < 1e-9 && (pl.1 - pr.1).abs() < 1e-9,
                "{pl:?} {pr:?}"
            );
            // Round trip through the pixel direction.
            let d = l.local_direction(pl.0, pl.1);
            assert!(d.cross((p - l.position).normalize()).length() < 1e-12);
        }
        // Nearer points have crossed parallax (left eye sees them more to
        // the right), farther ones uncrossed.
        let near = c.position + c.forward * (0.5 * conv);
        let far = c.position + c.forward * (3.0 * conv);
        assert!(l.project(near).unwrap().0 > r.project(near).unwrap().0);
        assert!(l.project(far).unwrap().0 < r.project(far).unwrap().0);
    }

    #[test]
    fn degenerate_bases_are_rejected() {
        let p = DVec3::new(0.0, -10.0, 0.0);
        assert_eq!(
            Camera::new(p, p, DVec3::Z, 50.0, 8, 8, None).unwrap_err(),
            CameraError::NoViewDirection
        );
        assert_eq!(
            Camera::new(p, DVec3::ZERO, DVec3::Y, 50.0, 8, 8, None).unwrap_err(),
            CameraError::UpAlongView
        );
    }

    #[test]
    fn static_observer_shrinks_the_radial_component() {
        // tan(alpha_c) = tan(alpha_L) / sqrt(1 - 1/r) for a direction at
        // alpha_L from the outward radial.
        let x = DVec3::new(0.0, 0.0, 4.0);
        let a_l: f64 = 0.7;
        let local = DVec3::new(a_l.sin(), 0.0, a_l.cos());
        let c = crate::physics::Spacetime::Schwarzschild.camera_direction(x, local);
        let a_c = c.x.atan2(c.z);
        assert!((a_c.tan() - a_l.tan() / (0.75f64).sqrt()).abs() < 1e-12);
    }
}
