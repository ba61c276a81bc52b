//! The camera's motion: the frame it is at rest in (static, or the locally
//! non-rotating one) and its velocity relative to that frame at each
//! instant: fixed (`camera.velocity`), the circular orbit through its
//! position (`camera.orbit = "circular"`), or its animation path's
//! (`animation.camera_motion = "path"`).

use super::{SceneError, invalid};
use crate::camera::Camera;
use crate::config::{CameraFrame, CameraMotion as PathMotion, SceneConfig};
use crate::physics::{Frame, Spacetime};
use glam::DVec3;

/// How the camera's velocity is found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// A fixed velocity relative to the frame (units of c; zero at rest).
    Velocity(DVec3),
    /// The counter-clockwise circular orbit through the camera's position.
    Circular,
    /// The camera path's velocity at the instant rendered.
    Path,
}

/// The camera's frame and motion, checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMotion {
    /// The frame it is at rest in.
    pub frame: Frame,
    /// How it moves relative to it.
    pub motion: Motion,
}

impl CameraMotion {
    /// The `[camera]` and `[animation]` keys of motion, checked.
    pub(crate) fn of(config: &SceneConfig) -> Result<CameraMotion, SceneError> {
        let cam = &config.camera;
        let frame = match cam.frame {
            CameraFrame::Static => Frame::Static,
            CameraFrame::Zamo => Frame::Zamo,
        };
        let path = config
            .animation
            .as_ref()
            .is_some_and(|a| a.camera_motion == PathMotion::Path);
        let motion = match (cam.velocity, cam.orbit, path) {
            (Some(v), None, false) => {
                let v = DVec3::from_array(v);
                if !(v.is_finite() && v.length() < 1.0) {
                    return Err(invalid(
                        "camera.velocity",
                        cam.velocity.expect("set").to_vec(),
                        "a velocity [x, y, z] in units of c, slower than light (|v| < 1)",
                    ));
                }
                Motion::Velocity(v)
            }
            (None, Some(_), false) => Motion::Circular,
            (None, None, true) => {
                let a = config.animation.as_ref().expect("an animation");
                if a.orbit.is_none() && a.keyframes.is_none() {
                    return Err(invalid(
                        "animation.camera_motion",
                        "path",
                        "a camera path to move along ([animation.orbit] or [[animation.keyframe]])",
                    ));
                }
                Motion::Path
            }
            (None, None, false) => Motion::Velocity(DVec3::ZERO),
            _ => {
                return Err(invalid(
                    "camera.velocity",
                    "set with camera.orbit or animation.camera_motion = \"path\"",
                    "one of camera.velocity, camera.orbit and animation.camera_motion = \"path\"",
                ));
            }
        };
        Ok(CameraMotion { frame, motion })
    }

    /// Whether the camera moves relative to its frame, or is at rest in a
    /// static frame of a spinning hole (what the GPU does not render yet).
    pub fn moves(&self) -> bool {
        self.motion != Motion::Velocity(DVec3::ZERO)
    }

    /// Sets `camera` (at its position, in r_s, around `spacetime`, None:
    /// the seed model's flat space) at rest in the frame and moving as
    /// asked at time `t` (s, for messages): `path_velocity` gives the
    /// camera path's coordinate velocity (units of c) there.
    pub(crate) fn apply(
        &self,
        camera: &mut Camera,
        spacetime: Option<Spacetime>,
        path_velocity: impl FnOnce() -> DVec3,
        t: f64,
    ) -> Result<(), SceneError> {
        let x = camera.position;
        camera.rest_frame = self.frame;
        if let Some(st) = spacetime
            && st.observer_velocity(x, self.frame).is_none()
        {
            return Err(invalid(
                "camera.frame",
                "static",
                &format!(
                    "a camera outside the ergosphere (it is at r = {:.4} r_s): inside it nothing stays at rest, use \"zamo\"",
                    st.radius(x)
                ),
            ));
        }
        let relative = |w: DVec3, key: &str, what: &str| match spacetime {
            Some(st) => st.relative_velocity(x, self.frame, w).ok_or_else(|| {
                invalid(
                    key,
                    what,
                    &format!("a motion slower than light (at t = {t} s it is not)"),
                )
            }),
            // Flat space: the coordinate velocity is the velocity.
            None if w.length() < 1.0 => Ok(w),
            None => Err(invalid(
                key,
                what,
                &format!("a motion slower than light (at t = {t} s it is not)"),
            )),
        };
        camera.velocity = match self.motion {
            Motion::Velocity(v) => v,
            Motion::Circular => {
                let w = match spacetime {
                    Some(st) => st.circular_velocity(x),
                    // The seed model's Newtonian orbit, sqrt(GM / r).
                    None => {
                        let axis = DVec3::Z.cross(x);
                        (axis.length() > 0.0).then(|| axis.normalize() * (0.5 / x.length()).sqrt())
                    }
                };
                let Some(w) = w else {
                    return Err(invalid(
                        "camera.orbit",
                        "circular",
                        &format!(
                            "a camera where a circular orbit about the +z axis exists (outside the photon orbit, off the axis, and with spin in the disk's plane z = 0); it is at r = {:.4} r_s, z = {:.4} r_s",
                            spacetime.map_or(x.length(), |st| st.radius(x)),
                            x.z
                        ),
                    ));
                };
                relative(w, "camera.orbit", "circular")?
            }
            Motion::Path => relative(path_velocity(), "animation.camera_motion", "path")?,
        };
        Ok(())
    }
}
