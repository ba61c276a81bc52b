//! A camera sample's footprint: how where its ray ends moves as the
//! sample moves on the image (the derivatives per pixel of its direction
//! at infinity and of its disk crossings), what the sky, the disk's
//! filters and the lensing magnification read. The renderer makes them
//! (cpu/footprint.rs); this is what they are.

use glam::{DVec2, DVec3};

/// Most disk crossings a footprint follows (higher orders are
/// exponentially thinner than a pixel).
pub const MAX_CROSSINGS: usize = 6;

/// A disk crossing's footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DiskFootprint {
    /// The plane crossing's order (0: the direct image).
    pub order: u32,
    /// The disk-plane point the texture reads, and its derivatives per
    /// pixel along x and y (r_s per pixel).
    pub q: DVec2,
    pub dq: [DVec2; 2],
    /// The lensing magnification of the disk there: the solid angle the
    /// pixel sees over the solid angle its footprint on the disk would
    /// subtend seen straight from the camera, signed by the image's
    /// parity (1 in flat space).
    pub magnification: f64,
}

/// A camera sample's footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// The solid angle (sr) of one pixel at the sample, in the camera's
    /// own frame.
    pub pixel_sr: f64,
    /// The sample's image point (pixels from the top-left corner).
    pub at: DVec2,
    /// Where the ray escapes: its direction at infinity and that
    /// direction's derivatives per pixel along x and y (rad per pixel).
    pub sky: Option<(DVec3, [DVec3; 2])>,
    /// The footprints of its disk crossings, in order.
    pub(crate) disk: [DiskFootprint; MAX_CROSSINGS],
    pub(crate) n: usize,
}

impl Footprint {
    /// The signed lensing magnification of the sky seen along the ray: the
    /// pixel's solid angle over its footprint's on the celestial sphere,
    /// negative for an image of odd parity; None where the ray does not
    /// escape or the footprint is not known.
    pub fn sky_magnification(&self) -> Option<f64> {
        let (d, [dx, dy]) = self.sky?;
        Some(self.pixel_sr / dx.cross(dy).dot(d))
    }

    /// Where the sample lies relative to its pixel's centre (pixels).
    pub fn offset(&self) -> DVec2 {
        self.at - self.at.floor() - DVec2::splat(0.5)
    }

    /// The footprint of the disk crossing of plane-crossing order `order`.
    pub fn disk(&self, order: u32) -> Option<&DiskFootprint> {
        self.disk[..self.n].iter().find(|d| d.order == order)
    }
}
