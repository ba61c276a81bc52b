//! Derived quantities of a scene, for `blackhole info`.

use crate::physics::Model;
use crate::scene::Scene;
use std::fmt::Write;

/// A human-readable report of what a scene implies.
pub fn report(scene: &Scene) -> String {
    let r_s = scene.r_s;
    let cfg = &scene.config;
    let r_cam = scene.camera.position.length();
    let mut s = String::new();
    let mut line = |k: &str, v: String| {
        let _ = writeln!(s, "{k:<28} {v}");
    };
    line(
        "mass",
        format!(
            "{:.6e} kg ({:.4e} solar masses)",
            cfg.black_hole.mass,
            cfg.black_hole.mass / 1.98892e30
        ),
    );
    line("schwarzschild radius r_s", format!("{r_s:.6e} m"));
    line("photon sphere (1.5 r_s)", format!("{:.6e} m", 1.5 * r_s));
    line("ISCO (3 r_s)", format!("{:.6e} m", 3.0 * r_s));
    match &scene.disk {
        Some(d) => {
            line(
                "disk radii",
                format!(
                    "{:.4} to {:.4} r_s = {:.6e} to {:.6e} m",
                    d.inner,
                    d.outer,
                    d.inner * r_s,
                    d.outer * r_s
                ),
            );
            let (lo, hi) = (scene.limits.inner, scene.limits.outer);
            line(
                "disk material (from alpha)",
                format!(
                    "{lo:.4} to {hi:.4} r_s = {:.6e} to {:.6e} m",
                    lo * r_s,
                    hi * r_s
                ),
            );
        }
        None => line("disk", "none".into()),
    }
    line(
        "camera distance",
        format!("{r_cam:.4} r_s = {:.6e} m", r_cam * r_s),
    );
    let (model, detail) = match scene.model {
        Model::Gr { tolerance } => (
            "gr (exact Schwarzschild)",
            format!("tolerance {tolerance:e}"),
        ),
        Model::Seed { step } => ("seed (the assignment's)", format!("step {step} r/c")),
    };
    line("ray model", format!("{model}, {detail}"));
    line(
        "shadow angular radius",
        format!(
            "{:.6} deg (expected for this model at the camera)",
            scene.model.shadow_angle(r_cam).to_degrees()
        ),
    );
    let fov = cfg.camera.fov;
    let alpha = scene.model.shadow_angle(r_cam);
    if alpha < std::f64::consts::FRAC_PI_2 {
        let px = scene.camera.focal_pixels() * alpha.tan();
        line(
            "shadow radius in image",
            format!("{px:.1} px (fov {fov} deg, {} px high)", cfg.image.height),
        );
    } else {
        line(
            "shadow radius in image",
            "the shadow covers more than half the sky".into(),
        );
    }
    if let Model::Gr { .. } = scene.model {
        line(
            "sky light at camera",
            format!("blueshift g = {:.6}", 1.0 / (1.0 - 1.0 / r_cam).sqrt()),
        );
    }
    let img = &cfg.image;
    line(
        "image",
        format!(
            "{} x {} px, {} ray(s) per pixel",
            img.width, img.height, img.samples
        ),
    );
    line(
        "memory needed",
        format!("{:.1} MiB", scene.memory_bytes() as f64 / (1 << 20) as f64),
    );
    line("png", img.png.display().to_string());
    if let Some(e) = &img.exr {
        line("exr", e.display().to_string());
    }
    s
}
