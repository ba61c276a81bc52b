//! The radii within which anything of the scene lies, where rays may stop
//! being stepped and leave on their exact tail.

use crate::config::Filter;
use crate::disk::Disk;
use crate::objects::Object;
use crate::physics::Limits;
use crate::volume::{Cloud, VolumeDisk};

/// The innermost radius (r_s) a footprint-filtered disk lights for the
/// tracer's early capture.
const FOOTPRINT_INNER: f64 = 1.05;

/// The inner and outer radius (r_s) of the disk's material, the objects,
/// the gas and the clouds, and the step budget.
pub(super) fn limits(
    disk: Option<&Disk>,
    objects: &[Object],
    volume: Option<&VolumeDisk>,
    clouds: &[Cloud],
    max_steps: u32,
) -> Limits {
    // A footprint reads texels as far off as lensing stretches it: near
    // the shadow the material's edge lights hits well inside the material
    // (the closed form sees them, down to 1.1 r_s on the shipped disk), so
    // the whole annulus counts, down to FOOTPRINT_INNER: a ray still
    // inbound there is captured (any nearer, the integrator's steps shrink
    // without end as it nears the horizon).
    let (inner, outer) = disk.map_or((f64::INFINITY, 0.0), |d| match d.filter {
        Filter::Footprint => (d.inner.max(FOOTPRINT_INNER), d.outer),
        _ => d.material_radii(),
    });
    let (inner, outer) = objects.iter().fold((inner, outer), |(lo, hi), o| {
        let (near, far) = o.shape.radial_extent();
        (lo.min(near), hi.max(far))
    });
    let (inner, outer) = match volume {
        // The gas starts just inside `inner` (smooth edge) and reaches
        // 3 scale heights above the plane.
        Some(v) => (inner.min(0.9 * v.inner), outer.max(v.outer.hypot(v.zmax()))),
        None => (inner, outer),
    };
    let (inner, outer) = clouds.iter().fold((inner, outer), |(lo, hi), c| {
        let d = c.center.length();
        (lo.min(d - c.radius), hi.max(d + c.radius))
    });
    Limits {
        outer,
        inner,
        max_steps,
    }
}
