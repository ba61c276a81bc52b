//! Derived quantities of a scene, for `blackhole info`.

use crate::animation::{CameraPath, DiskRotation, Timeline};
use crate::config::LightConfig;
use crate::objects::Finish;
use crate::physics::{Model, Spacetime};
use crate::scene::Scene;
use crate::shapes::Shape;
use std::fmt::Write;

/// A human-readable report of what a scene implies: [`facts`], one a
/// line.
pub fn report(scene: &Scene) -> String {
    let mut s = String::new();
    for (k, v) in facts(scene) {
        let _ = writeln!(s, "{k:<28} {v}");
    }
    s
}

/// What a scene implies, as (quantity, value with its units) in the
/// report's order.
pub fn facts(scene: &Scene) -> Vec<(String, String)> {
    let mut facts = Vec::new();
    let mut line = |k: &str, v: String| facts.push((k.to_string(), v));
    hole(scene, &mut line);
    disk(scene, &mut line);
    contents(scene, &mut line);
    view(scene, &mut line);
    image(scene, &mut line);
    outputs(scene, &mut line);
    if let Some(a) = &scene.animation {
        animation(scene, a, &mut line);
    }
    facts
}

/// The hole: its mass and radii.
fn hole(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let r_s = scene.r_s;
    let cfg = &scene.config;
    line(
        "mass",
        format!(
            "{:.6e} kg ({:.4e} solar masses)",
            cfg.black_hole.mass,
            cfg.black_hole.mass / crate::units::SOLAR_MASS
        ),
    );
    line("schwarzschild radius r_s", format!("{r_s:.6e} m"));
    // The hole's own radii, whichever model traces the light.
    let st = scene.model.spacetime().unwrap_or_default();
    match st {
        Spacetime::Schwarzschild => {
            let (sphere, isco) = (st.photon_sphere(), st.isco());
            line(
                &format!("photon sphere ({sphere} r_s)"),
                format!("{:.6e} m", sphere * r_s),
            );
            line(
                &format!("ISCO ({isco} r_s)"),
                format!("{:.6e} m", isco * r_s),
            );
        }
        Spacetime::Kerr { a } => kerr_lines(line, scene, a, r_s),
    }
}

/// The disk: radii, material and the physical disk's profile.
fn disk(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let r_s = scene.r_s;
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
            let (lo, hi) = d.material_radii();
            let material = if lo <= hi {
                format!(
                    "{lo:.4} to {hi:.4} r_s = {:.6e} to {:.6e} m",
                    lo * r_s,
                    hi * r_s
                )
            } else {
                "none (the texture is transparent everywhere)".into()
            };
            line("disk material (from alpha)", material);
            if let Some(t) = &d.thin {
                let (model, profile) = match t.profile {
                    crate::thin_disk::Profile::NovikovThorne => ("gr", "Novikov-Thorne"),
                    crate::thin_disk::Profile::ShakuraSunyaev => ("seed", "Shakura-Sunyaev"),
                };
                line(
                    "thin disk",
                    format!(
                        "{profile} ({model}), zero torque at {:.4} r_s, accretion rate {:.6e} kg/s ({:.4e} solar masses/year), f_col {}",
                        t.inner,
                        t.accretion_rate,
                        t.accretion_rate * crate::units::YEAR / crate::units::SOLAR_MASS,
                        t.f_col
                    ),
                );
                let (r_peak, t_peak) = t.peak();
                line(
                    "peak temperature",
                    format!(
                        "{t_peak:.6e} K at {r_peak:.4} r_s = {:.6e} m (T at the rim {:.4e} K)",
                        r_peak * r_s,
                        t.temperature(d.outer)
                    ),
                );
                line(
                    "luminosity",
                    format!(
                        "L = eta Mdot c^2 = {:.6e} W, eta = {:.6} ({})",
                        t.luminosity(),
                        t.efficiency(),
                        if model == "gr" {
                            "1 - E at the inner edge; 1 - sqrt(8/9) at the ISCO"
                        } else {
                            "Newtonian r_s / (4 r_in)"
                        }
                    ),
                );
                line(
                    "Eddington ratio",
                    format!(
                        "L / L_Edd = {:.4e} (L_Edd = {:.6e} W)",
                        t.luminosity() / t.eddington(),
                        t.eddington()
                    ),
                );
            }
        }
        None if scene.volume.is_none() => line("disk", "none".into()),
        None => {}
    }
}

/// What else is in the scene: gas, clouds, objects and lights.
fn contents(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let cfg = &scene.config;
    if let Some(v) = &scene.volume {
        line(
            "volumetric disk",
            format!(
                "{:.4} to {:.4} r_s, scale height {} r_s at the outer edge, peak {} K, opacity {} per r_s, sampled every {} r_s",
                v.inner, v.outer, v.thickness, v.peak_kelvin, v.kappa, v.step
            ),
        );
    }
    for (i, c) in scene.clouds.iter().enumerate() {
        line(
            &format!("cloud[{i}]"),
            format!(
                "centre {:.4} r_s from the hole, radius {:.4} r_s, optical depth {} at 550 nm, beta {}",
                c.center.length(),
                c.radius,
                cfg.clouds[i].depth,
                c.beta
            ),
        );
    }
    for (i, o) in scene.objects.iter().enumerate() {
        let kind = match &o.shape {
            Shape::Sphere(s) => format!("sphere of radius {:.4} r_s", s.radius),
            Shape::Rectangle(r) => format!(
                "rectangle {:.4} x {:.4} r_s",
                2.0 * r.half.0,
                2.0 * r.half.1
            ),
            Shape::Mesh(m) => format!("mesh of {} triangles", m.triangle_count()),
        };
        let finish = match o.material.finish {
            Finish::Color => "color",
            Finish::Mirror => "mirror",
            Finish::Lit { .. } => "lit",
        };
        let (near, far) = o.shape.radial_extent();
        line(
            &format!("object[{i}]"),
            format!("{kind}, {finish}, {near:.4} to {far:.4} r_s from the hole"),
        );
    }
    if !cfg.lights.is_empty() {
        let kinds: Vec<&str> = cfg
            .lights
            .iter()
            .map(|l| match l {
                LightConfig::Sun(_) => "sun",
                LightConfig::Disk(_) => "disk glow",
                LightConfig::Ambient(_) => "ambient",
            })
            .collect();
        line("lights", kinds.join(", "));
    }
}

/// The camera and the light it sees: the ray model, the shadow, the sky's shift.
fn view(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let r_s = scene.r_s;
    let cfg = &scene.config;
    let r_cam = scene.camera.position.length();
    line(
        "camera distance",
        format!("{r_cam:.4} r_s = {:.6e} m", r_cam * r_s),
    );
    let (model, detail) = match scene.model {
        Model::Gr {
            tolerance,
            spacetime,
        } => (
            format!("gr (exact {})", spacetime.name()),
            format!("tolerance {tolerance:e}"),
        ),
        Model::Seed { step } => ("seed (the assignment's)".into(), format!("step {step} r/c")),
    };
    line("ray model", format!("{model}, {detail}"));
    if let Some(alpha) = scene.model.shadow_angle(r_cam) {
        line(
            "shadow angular radius",
            format!(
                "{:.6} deg (expected for this model at the camera)",
                alpha.to_degrees()
            ),
        );
        let fov = cfg.camera.fov;
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
    }
    if let Some(st) = scene.model.spacetime() {
        // Light arriving with no angular momentum about the axis (with
        // spin the camera's frame drags the rest).
        let cam = scene.camera.position;
        line(
            "sky light at camera",
            format!(
                "blueshift g = {:.6}",
                st.static_ln_shift(
                    None,
                    crate::physics::Observer {
                        at: cam,
                        frame: scene.camera.rest_frame,
                        lz_over_e: 0.0,
                    }
                )
                .exp()
            ),
        );
    }
}

/// The image, its spectral settings and bloom.
fn image(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let cfg = &scene.config;
    let img = &cfg.image;
    let adaptive = if img.adaptive() {
        format!(
            ", adaptive up to {} where a pixel holds an edge",
            img.max_samples()
        )
    } else {
        String::new()
    };
    line(
        "image",
        format!(
            "{} x {} px, {} ray(s) per pixel{adaptive}",
            img.width, img.height, img.samples
        ),
    );
    match &scene.spectral {
        Some(ctx) => line(
            "spectral",
            format!(
                "{} wavelengths over 380-780 nm ({} nm apart), shift {}, Doppler {}, beaming {}{}",
                ctx.wavelengths.len(),
                ctx.wavelengths.step,
                on_off(ctx.shift),
                on_off(ctx.doppler),
                on_off(ctx.beaming),
                if ctx.per_wavelength {
                    ", one ray per wavelength"
                } else {
                    ""
                }
            ),
        ),
        None if scene.observe.is_some() => {
            line("spectral", "off (the observed frequencies instead)".into())
        }
        None => line("spectral", "off (an RGB render)".into()),
    }
    if let Some(o) = &scene.observe {
        if let Some(m) = &o.medium {
            line("medium", m.describe());
        }
        // The field as the distant observer sees it: the camera's angles
        // times the camera's distance over the source's.
        use crate::config::quantity::{distance_text, frequency_text};
        let uas = crate::transfer::micro_arcseconds;
        let shrink = scene.camera_distance_cm() / o.distance_cm;
        let pixel = scene
            .camera
            .pixel_solid_angle(0.5 * img.width as f64, 0.5 * img.height as f64)
            .sqrt();
        line(
            "observed",
            format!(
                "from {} at {}; a pixel {:.4} uas across, the field {:.2} uas high; fluxes in Jy per pixel",
                distance_text(o.distance_cm / crate::units::cgs::PARSEC),
                o.frequencies
                    .iter()
                    .map(|&f| frequency_text(f))
                    .collect::<Vec<_>>()
                    .join(", "),
                uas(pixel * shrink),
                uas(2.0 * scene.camera.half_height.atan() * shrink),
            ),
        );
        if let Some(look) = crate::colormap::RadioLook::of(cfg) {
            line(
                "picture",
                format!(
                    "{}{}",
                    look.describe(),
                    if look.bar {
                        "; a colour bar beside it"
                    } else {
                        ""
                    }
                ),
            );
        }
    }
    if let Some(b) = &cfg.bloom {
        line(
            "bloom",
            format!(
                "strength {}, sigma {} of the image height{}{}",
                b.strength,
                b.radius,
                match crate::post::bloom_terms(b).as_slice() {
                    terms @ [.., widest] if b.shape == crate::config::BloomShape::Halo => format!(
                        ", a halo of {} Gaussians to {} (light falling as 1/r^3)",
                        terms.len(),
                        widest.sigma
                    ),
                    _ => String::new(),
                },
                if b.spectral {
                    ", per wavelength band"
                } else {
                    ""
                }
            ),
        );
    }
}

/// The memory a render needs and the files it writes.
fn outputs(scene: &Scene, line: &mut impl FnMut(&str, String)) {
    let img = &scene.config.image;
    let r_s = scene.r_s;
    let cfg = &scene.config;
    let need = crate::memory::film(
        cfg,
        crate::memory::Job::render(cfg, false),
        crate::memory::assets(cfg),
    );
    let avail = crate::memory::available()
        .map(|a| {
            format!(
                "; {:.0} MiB available ({})",
                crate::memory::mib(a.bytes),
                a.limited_by
            )
        })
        .unwrap_or_default();
    line(
        "memory needed",
        format!(
            "{:.1} MiB to render on the CPU (largest: {}){avail}",
            crate::memory::mib(need.total()),
            need.largest(3)
        ),
    );
    line("png", img.png.display().to_string());
    if let Some(e) = &img.exr {
        line("exr", e.display().to_string());
    }
    if let Some(st) = &cfg.stereo {
        line(
            "stereo",
            format!(
                "eyes {:.6e} m apart ({:.4} r_s), zero parallax at {}",
                st.separation,
                st.separation / r_s,
                match st.convergence {
                    Some(c) => format!("{c:.6e} m"),
                    None => "camera.look_at".into(),
                }
            ),
        );
        let stem = img.png.with_extension("");
        for tag in ["left", "right", "side_by_side", "anaglyph"] {
            line(
                &format!("stereo {tag}"),
                format!("{}_{tag}.png", stem.display()),
            );
        }
    }
}

/// The `[animation]` lines: timing, how far the disk turns, the camera's
/// path and the files.
fn animation(scene: &Scene, a: &Timeline, line: &mut impl FnMut(&str, String)) {
    let r_s = scene.r_s;
    let unit = r_s / crate::units::C;
    let step = a.duration / a.frames as f64;
    if !a.timed {
        line(
            "animation",
            format!(
                "a still at t = {} s ({:.4} r_s/c): no frames, fps or duration, so nothing for animate",
                a.start,
                a.start / unit
            ),
        );
    } else {
        line(
            "animation",
            format!(
                "{} frames at {} fps ({:.2} s of video); t = {} to {} s, {:.6} s = {:.4} r_s/c per frame; light travel time {}",
                a.frames,
                a.fps,
                a.frames as f64 / a.fps,
                a.start,
                a.time(a.frames - 1),
                step,
                step / unit,
                on_off(a.light_travel_time)
            ),
        );
    }
    let radii = match (&scene.disk, &scene.volume) {
        (Some(d), _) => {
            let (lo, hi) = d.material_radii();
            (lo <= hi).then_some((lo.max(1.0), hi))
        }
        (None, Some(v)) => Some((v.inner, v.outer)),
        _ => None,
    };
    let per_frame = |r: f64| a.rotation.angle(r, step / unit).to_degrees();
    let whole = |r: f64| a.rotation.angle(r, a.duration / unit) / std::f64::consts::TAU;
    let law = match a.rotation {
        DiskRotation::Rigid(omega) => format!(
            "rigid, period {:.6} s",
            std::f64::consts::TAU / omega * unit
        ),
        _ => "Keplerian".into(),
    };
    line(
        "disk rotation",
        match radii {
            Some((lo, hi)) => format!(
                "{law}: per frame {:.3} deg at {lo:.3} r_s, {:.3} deg at {hi:.3} r_s; over the animation {:.3} and {:.3} turns",
                per_frame(lo),
                per_frame(hi),
                whole(lo),
                whole(hi)
            ),
            None => format!("{law} (no disk to turn)"),
        },
    );
    line(
        "camera path",
        match &a.camera {
            CameraPath::Fixed => "fixed ([camera])".into(),
            CameraPath::Orbit {
                azimuth,
                elevation,
                distance,
                ..
            } => format!(
                "orbit at {distance:.6e} m ({:.4} r_s), azimuth {:.2} to {:.2} deg, elevation {:.2} to {:.2} deg",
                distance / r_s,
                azimuth[0].to_degrees(),
                azimuth[1].to_degrees(),
                elevation[0].to_degrees(),
                elevation[1].to_degrees()
            ),
            CameraPath::Keyframes(k) => format!(
                "{} keyframe(s) from t = {} to {} s",
                k.len(),
                k[0].0,
                k[k.len() - 1].0
            ),
        },
    );
    let img = &scene.config.image;
    let stem = img.png.with_extension("");
    let last = a.frames - 1;
    line(
        "animate frames",
        format!("{0}_00000.png to {0}_{last:05}.png", stem.display()),
    );
    if img.exr.is_some() {
        line(
            "animate frames (exr)",
            format!("{0}_00000.exr to {0}_{last:05}.exr", stem.display()),
        );
    }
    if let Some(v) = &a.video {
        line("animate video", v.display().to_string());
    }
}

fn on_off(b: bool) -> &'static str {
    if b { "on" } else { "off" }
}

/// The spinning hole's radii (in r_s and m; Boyer-Lindquist's), its
/// camera's frame and the shadow a far camera at its inclination expects.
fn kerr_lines(line: &mut impl FnMut(&str, String), scene: &Scene, a: f64, r_s: f64) {
    use crate::physics::kerr::Kerr;
    let both = |r_m: f64| format!("{:.6} r_s = {:.6e} m", 0.5 * r_m, 0.5 * r_m * r_s);
    let k = Kerr::new(a);
    line("spin a = J c / (G M^2)", format!("{a}"));
    line("horizon r_+", both(k.horizon()));
    line(
        "ergosphere on the equator",
        both(k.ergosphere(std::f64::consts::FRAC_PI_2)),
    );
    let (pro, retro) = (Kerr::new(a.abs()), Kerr::new(-a.abs()));
    line(
        "ISCO prograde / retrograde",
        format!("{} / {}", both(pro.isco()), both(retro.isco())),
    );
    line(
        "photon orbits prograde / retrograde",
        format!(
            "{} / {}",
            both(pro.photon_orbit()),
            both(retro.photon_orbit())
        ),
    );
    line(
        "the disk's orbit",
        format!(
            "{} (ISCO {:.6} r_s, efficiency {:.6})",
            if a > 0.0 { "prograde" } else { "retrograde" },
            0.5 * k.isco(),
            k.efficiency()
        ),
    );
    let x = 2.0 * scene.camera.position;
    let s = k.spheroidal(x);
    let z = k.zamo(s.r, s.th);
    line(
        "camera frame",
        format!(
            "locally non-rotating (ZAMO) at r = {:.6} r_s: lapse alpha = {:.6}, frame dragging omega = {:.6e} c^3/(GM)",
            0.5 * s.r,
            z.alpha,
            z.omega
        ),
    );
    // Bardeen's curve at the camera's inclination, its angles at the
    // camera's distance (exact for a camera at infinity).
    let pts = k.shadow_curve(s.th.min(std::f64::consts::PI - s.th), 2000);
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let top = pts.iter().fold(0.0f64, |m, p| m.max(p.1));
    let deg = |m: f64| (m / s.r).atan().to_degrees();
    line(
        "shadow for a far camera here",
        format!(
            "from {:.6} to {:.6} deg across (the flat side first, where the hole turns towards the camera), {:.6} deg high each way (Bardeen's curve at inclination {:.2} deg)",
            deg(lo),
            deg(hi),
            deg(top),
            s.th.to_degrees()
        ),
    );
}
