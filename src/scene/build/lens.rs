//! `[black_hole]`, `[camera]` and `[physics]`: the lens, the camera (and
//! the stereo eyes) outside its horizon, and the ray model.

use super::super::{SceneError, finite_vec, invalid, schwarzschild_radius};
use crate::camera::{Camera, CameraError};
use crate::config::{ModelKind, PhysicsConfig, SceneConfig};
use crate::physics::{Model, Spacetime};
use glam::DVec3;

/// The hole's Schwarzschild radius (m), its mass checked.
pub(super) fn schwarzschild(config: &SceneConfig) -> Result<f64, SceneError> {
    let mass = config.black_hole.mass;
    if !(mass.is_finite() && mass > 0.0) {
        return Err(invalid(
            "black_hole.mass",
            mass,
            "expected a positive mass in kg",
        ));
    }
    let r_s = schwarzschild_radius(mass);
    if !(r_s.is_finite() && r_s > 0.0) {
        return Err(invalid(
            "black_hole.mass",
            mass,
            "gives no finite Schwarzschild radius",
        ));
    }
    Ok(r_s)
}

/// The hole's spacetime under the exact model: Schwarzschild, or Kerr
/// for a spin; the spin checked (the seed model has none).
pub(super) fn spacetime(config: &SceneConfig) -> Result<Spacetime, SceneError> {
    let a = config.black_hole.spin;
    if !(a.is_finite() && a.abs() <= MAX_SPIN) {
        return Err(invalid(
            "black_hole.spin",
            a,
            &format!("expected a spin J c / (G M^2) from -{MAX_SPIN} to {MAX_SPIN}"),
        ));
    }
    if a == 0.0 {
        return Ok(Spacetime::Schwarzschild);
    }
    if config.physics.model == ModelKind::Seed {
        return Err(invalid(
            "black_hole.spin",
            a,
            "0 under physics.model = \"seed\": the assignment's model has no spin (use physics.model = \"gr\")",
        ));
    }
    Ok(Spacetime::Kerr { a })
}

/// The largest spin: closer to 1 the horizon and the prograde orbits
/// crowd together at r = M.
pub const MAX_SPIN: f64 = 0.9999;

/// The ray model and its accuracy, checked.
pub(super) fn model(phys: &PhysicsConfig, spacetime: Spacetime) -> Result<Model, SceneError> {
    let model = match phys.model {
        ModelKind::Gr => {
            if !(phys.tolerance > 0.0 && phys.tolerance <= 1e-2) {
                return Err(invalid(
                    "physics.tolerance",
                    phys.tolerance,
                    "expected 0 < tolerance <= 1e-2",
                ));
            }
            Model::Gr {
                tolerance: phys.tolerance,
                spacetime,
            }
        }
        ModelKind::Seed => {
            if !(phys.step > 0.0 && phys.step <= 0.1) {
                return Err(invalid(
                    "physics.step",
                    phys.step,
                    "expected 0 < step <= 0.1 (fraction of r/c)",
                ));
            }
            Model::Seed { step: phys.step }
        }
    };
    if phys.max_steps == 0 {
        return Err(invalid(
            "physics.max_steps",
            phys.max_steps,
            "expected at least 1",
        ));
    }
    Ok(model)
}

/// The camera's position, the point it looks at (both in r_s) and its up
/// direction, checked: finite, in range, the camera outside the horizon
/// of `spacetime`.
pub(super) fn pose(
    config: &SceneConfig,
    r_s: f64,
    spacetime: Spacetime,
) -> Result<(DVec3, DVec3, DVec3), SceneError> {
    let cam = &config.camera;
    let position = finite_vec("camera.position", cam.position)? / r_s;
    let look_at = finite_vec("camera.look_at", cam.look_at)? / r_s;
    let up = finite_vec("camera.up", cam.up)?;
    if !(cam.fov > 0.0 && cam.fov < 180.0) {
        return Err(invalid(
            "camera.fov",
            cam.fov,
            "expected degrees between 0 and 180 (exclusive)",
        ));
    }
    for (key, v, raw) in [
        ("camera.position", position, cam.position),
        ("camera.look_at", look_at, cam.look_at),
    ] {
        if !v.is_finite() {
            return Err(invalid(
                key,
                raw,
                &format!(
                    "is out of range in units of r_s = {r_s:.6e} m (black_hole.mass too small?)"
                ),
            ));
        }
    }
    let r_cam = spacetime.radius(position);
    let horizon = spacetime.horizon();
    if !(r_cam > horizon) {
        return Err(invalid(
            "camera.position",
            cam.position,
            &format!(
                "is at r = {:.4} r_s, inside the horizon at {horizon:.4} r_s (r_s = {r_s:.6e} m); the camera must be outside",
                r_cam
            ),
        ));
    }
    Ok((position, look_at, up))
}

/// The camera at `position` looking at `look_at` with `up` (r_s), with a
/// well-defined view, and a stereo pair's eyes outside the horizon too.
pub(super) fn camera(
    config: &SceneConfig,
    r_s: f64,
    (position, look_at, up): (DVec3, DVec3, DVec3),
    spacetime: Spacetime,
) -> Result<Camera, SceneError> {
    let (img, cam, phys) = (&config.image, &config.camera, &config.physics);
    let camera = Camera::new(
        position,
        look_at,
        up,
        cam.fov,
        img.width,
        img.height,
        (phys.model == ModelKind::Gr).then_some(spacetime),
    )
    .map_err(|e| match e {
        CameraError::NoViewDirection => invalid(
            "camera.look_at",
            cam.look_at,
            "must differ from camera.position",
        ),
        CameraError::UpAlongView => invalid(
            "camera.up",
            cam.up,
            "must be non-zero and not parallel to the view direction (look_at - position)",
        ),
    })?;

    // Both stereo eyes must be outside the horizon, like the camera.
    if let Some(st) = &config.stereo {
        let conv = st
            .convergence
            .unwrap_or_else(|| (look_at - position).length() * r_s);
        let (l, r) = camera.stereo_pair(st.separation / r_s, conv / r_s);
        for (eye, side) in [(l, "left"), (r, "right")] {
            let r_eye = spacetime.radius(eye.position);
            if !(r_eye > spacetime.horizon()) {
                return Err(invalid(
                    "stereo.separation",
                    st.separation,
                    &format!(
                        "puts the {side} eye at r = {r_eye:.4} r_s, inside the horizon at {:.4} r_s (r_s = {r_s:.6e} m); both eyes must be outside",
                        spacetime.horizon()
                    ),
                ));
            }
        }
    }
    Ok(camera)
}
