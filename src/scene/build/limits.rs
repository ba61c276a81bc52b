//! The radii within which anything of the scene lies, where rays may stop
//! being stepped and leave on their exact tail.

use crate::disk::Disk;
use crate::objects::Object;
use crate::physics::Limits;
use crate::transfer::Medium;
use crate::volume::{Cloud, VolumeDisk};

/// The inner and outer radius (r_s) of the disk's material, the objects,
/// the gas and the clouds, and the step budget.
pub(super) fn limits(
    disk: Option<&Disk>,
    objects: &[Object],
    (volume, medium): (Option<&VolumeDisk>, Option<&Medium>),
    clouds: &[Cloud],
    max_steps: u32,
) -> Limits {
    // A footprint stops at the material's inner edge (Disk::hit_footprint),
    // so every filter lights hits within the material's radii alone.
    let (inner, outer) = disk.map_or((f64::INFINITY, 0.0), Disk::material_radii);
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
    // A medium reaches down to the horizon: rays are followed until they
    // cross it, out to where the medium ends (its extent is in M).
    let (inner, outer) = match medium {
        Some(m) => (0.0, outer.max(0.5 * m.extent())),
        None => (inner, outer),
    };
    Limits {
        outer,
        inner,
        max_steps,
    }
}
