//! Pinhole camera.
//!
//! Rays start at the camera centre and pass through points of the image
//! plane: direction = forward + (u - 1/2) * right * w + (1/2 - v) * up * h,
//! with (u, v) the position in the image (0..1, v down) and w, h the plane's
//! size at unit distance from the vertical field of view and the aspect
//! ratio, so pixels are square.
//!
//! With the exact model the camera is a static observer: the pixel directions
//! are directions in its local orthonormal frame and are converted to the
//! coordinate directions the geodesic equation uses
//! ([`crate::physics::gr::static_to_coordinate`]). The seed model's space is
//! flat and its directions are used as they are.

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
    /// Convert local directions of a static observer (exact model).
    pub static_observer: bool,
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
        static_observer: bool,
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
            static_observer,
        })
    }

    /// Unit direction, in the camera's local frame, through image point
    /// (`px`, `py`) in pixels from the top-left corner (pixel centres at +0.5).
    pub fn local_direction(&self, px: f64, py: f64) -> DVec3 {
        let h = self.half_height;
        let w = h * self.width as f64 / self.height as f64;
        let sx = (2.0 * px / self.width as f64 - 1.0) * w;
        let sy = (1.0 - 2.0 * py / self.height as f64) * h;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Initial direction of the ray through (`px`, `py`) for the integrator.
    pub fn ray_direction(&self, px: f64, py: f64) -> DVec3 {
        let d = self.local_direction(px, py);
        if self.static_observer {
            crate::physics::gr::static_to_coordinate(self.position, d)
        } else {
            d
        }
    }

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
            false,
        )
        .unwrap()
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
    fn degenerate_bases_are_rejected() {
        let p = DVec3::new(0.0, -10.0, 0.0);
        assert_eq!(
            Camera::new(p, p, DVec3::Z, 50.0, 8, 8, false).unwrap_err(),
            CameraError::NoViewDirection
        );
        assert_eq!(
            Camera::new(p, DVec3::ZERO, DVec3::Y, 50.0, 8, 8, false).unwrap_err(),
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
        let c = crate::physics::gr::static_to_coordinate(x, local);
        let a_c = c.x.atan2(c.z);
        assert!((a_c.tan() - a_l.tan() / (0.75f64).sqrt()).abs() < 1e-12);
    }
}
