//! `[[object]]` and `[[light]]`: the solid objects (spheres, rectangles,
//! meshes) with their materials, and what lights them.

use super::super::{SceneError, colour, finite_vec, invalid, load_texture, spectral_to_rgb};
use crate::config::{LightConfig, MaterialConfig, ObjectConfig, SceneConfig};
use crate::disk::{Disk, DiskMaterial};
use crate::objects::{self, Finish, Lighting, Material, Object};
use crate::shapes::{Mesh, Rectangle, Shape, Sphere};
use glam::{DAffine3, DQuat, DVec3, EulerRot};

/// Builds object `i` (lengths to r_s).
pub(super) fn object(i: usize, o: &ObjectConfig, r_s: f64) -> Result<Object, SceneError> {
    let key = |k: &str| format!("object[{i}].{k}");
    let positive = |k: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(invalid(&key(k), v, "expected a positive length in metres"))
        }
    };
    let unit = |k: &str, v: [f64; 3]| {
        finite_vec(&key(k), v)?
            .try_normalize()
            .ok_or_else(|| invalid(&key(k), v, "expected a non-zero direction"))
    };
    let (shape, mat) = match o {
        ObjectConfig::Sphere(s) => {
            let pole = unit("pole", s.pole)?;
            let meridian = pole.any_orthonormal_vector();
            let shape = Shape::Sphere(Sphere {
                center: finite_vec(&key("center"), s.center)? / r_s,
                radius: positive("radius", s.radius)? / r_s,
                pole,
                meridian,
            });
            (shape, &s.material)
        }
        ObjectConfig::Rectangle(r) => {
            let normal = unit("normal", r.normal)?;
            let u_axis = match r.width_axis {
                Some(w) => {
                    let w = unit("width_axis", w)?;
                    (w - normal * w.dot(normal))
                        .try_normalize()
                        .ok_or_else(|| {
                            invalid(&key("width_axis"), w, "must not be along the normal")
                        })?
                }
                None => normal.any_orthonormal_vector(),
            };
            let shape = Shape::Rectangle(Rectangle {
                center: finite_vec(&key("center"), r.center)? / r_s,
                normal,
                u_axis,
                half: (
                    0.5 * positive("size", r.size[0])? / r_s,
                    0.5 * positive("size", r.size[1])? / r_s,
                ),
            });
            (shape, &r.material)
        }
        ObjectConfig::Mesh(m) => {
            let scale = positive("scale", m.scale)? / r_s;
            let rot = finite_vec(&key("rotation"), m.rotation)?;
            let q = DQuat::from_euler(
                EulerRot::ZYX,
                rot.z.to_radians(),
                rot.y.to_radians(),
                rot.x.to_radians(),
            );
            let t = DAffine3::from_scale_rotation_translation(
                DVec3::splat(scale),
                q,
                finite_vec(&key("position"), m.position)? / r_s,
            );
            let mesh = Mesh::load_obj(&m.file, t, m.smooth)
                .map_err(|e| invalid(&key("file"), &m.file, &format!("cannot load: {e}")))?;
            (Shape::Mesh(std::sync::Arc::new(mesh)), &m.material)
        }
    };
    Ok(Object {
        shape,
        material: material(&key, mat)?,
    })
}

/// An object's material: its finish, colour and texture, checked (`key`
/// names the object's keys).
fn material(key: &dyn Fn(&str) -> String, mat: &MaterialConfig) -> Result<Material, SceneError> {
    let (finish, surface) = match mat {
        MaterialConfig::Color(s) => (Finish::Color, s),
        MaterialConfig::Mirror(s) => (Finish::Mirror, s),
        MaterialConfig::Lit(s) => {
            if !(s.specular.is_finite() && (0.0..=1.0).contains(&s.specular)) {
                return Err(invalid(
                    &key("material.specular"),
                    s.specular,
                    "expected 0 to 1",
                ));
            }
            if !(s.shininess.is_finite() && s.shininess >= 1.0) {
                return Err(invalid(
                    &key("material.shininess"),
                    s.shininess,
                    "expected a Phong exponent >= 1",
                ));
            }
            (
                Finish::Lit {
                    specular: s.specular as f32,
                    shininess: s.shininess as f32,
                },
                s,
            )
        }
    };
    let texture = match &surface.texture {
        Some(p) => Some(load_texture(&key("material.texture"), p)?),
        None => None,
    };
    Ok(Material {
        finish,
        color: colour(&key("material.color"), surface.color)?,
        texture,
        filter: surface.filter,
    })
}

/// The lights of `lit` objects: suns, ambient light, and the disk's glow
/// (from `disk`, which a disk light needs).
pub(super) fn lights(config: &SceneConfig, disk: Option<&Disk>) -> Result<Lighting, SceneError> {
    let mut lighting = Lighting::default();
    for (i, l) in config.lights.iter().enumerate() {
        let key = |k: &str| format!("light[{i}].{k}");
        let check_intensity = |v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(v as f32)
            } else {
                Err(invalid(
                    &key("intensity"),
                    v,
                    "expected a finite number >= 0",
                ))
            }
        };
        match l {
            LightConfig::Sun(s) => {
                let d = finite_vec(&key("direction"), s.direction)?;
                if d.length() == 0.0 {
                    return Err(invalid(
                        &key("direction"),
                        s.direction,
                        "expected a non-zero direction towards the star",
                    ));
                }
                let color = match (s.kelvin, s.color) {
                    (Some(_), Some(_)) => {
                        return Err(invalid(
                            &key("kelvin"),
                            s.kelvin,
                            "give kelvin or color, not both",
                        ));
                    }
                    (Some(t), None) if !(t.is_finite() && (100.0..=1e6).contains(&t)) => {
                        return Err(invalid(
                            &key("kelvin"),
                            t,
                            "expected a temperature of 100 to 1e6 K",
                        ));
                    }
                    (_, Some(c)) => Some(colour(&key("color"), c)?),
                    _ => None,
                };
                lighting.suns.push(objects::sun(
                    d,
                    s.kelvin,
                    color,
                    check_intensity(s.intensity)?,
                ));
            }
            LightConfig::Ambient(a) => {
                lighting.ambient += colour(&key("color"), a.color)? * check_intensity(a.intensity)?;
            }
            LightConfig::Disk(g) => {
                let Some(d) = disk else {
                    return Err(invalid(&key("kind"), "disk", "a disk light needs a [disk]"));
                };
                let k = check_intensity(g.intensity)?;
                let rgb_texture = match &d.material {
                    // The thin disk's light sampled like a texture.
                    _ if d.thin.is_some() => d.thin_texture(256),
                    DiskMaterial::Rgb(t) => t.clone(),
                    DiskMaterial::Spectral(s) => spectral_to_rgb(s),
                };
                lighting.glow = Lighting::disk_glow(d, &rgb_texture, d.material_radii(), k);
            }
        }
    }
    Ok(lighting)
}

/// With spin, every object outside the ergosphere, where a mirror or a lit
/// surface can stay at rest (static frames exist only there).
pub(super) fn outside_ergosphere(
    objects: &[Object],
    spacetime: crate::physics::Spacetime,
) -> Result<(), SceneError> {
    let crate::physics::Spacetime::Kerr { a } = spacetime else {
        return Ok(());
    };
    // The ergosphere reaches r = 2M = 1 r_s on the equator, which
    // Kerr-Schild space puts sqrt(1 + a^2 / 4) r_s from the centre.
    let ergo = (1.0 + 0.25 * a * a).sqrt();
    for (i, o) in objects.iter().enumerate() {
        let (near, _) = o.shape.radial_extent();
        if near <= ergo {
            return Err(invalid(
                &format!("object.{i}"),
                format!("{near:.4} r_s from the hole"),
                &format!(
                    "to lie outside the ergosphere of black_hole.spin = {a} (beyond {ergo:.4} r_s), where nothing can stay at rest"
                ),
            ));
        }
    }
    Ok(())
}
