//! The panorama at infinity, looked up by the escape direction alone.

use crate::config::Filter;
use crate::texture::{Texture, equirect_uv};
use glam::{DVec3, Vec3};

/// What an escaping ray sees.
#[derive(Clone, Debug)]
pub enum Sky {
    /// The same linear colour in every direction.
    Uniform(Vec3),
    /// An equirectangular panorama ([`equirect_uv`] gives its orientation).
    Panorama {
        /// The image.
        texture: Texture,
        /// Lookup filter.
        filter: Filter,
        /// Linear multiplier.
        intensity: f32,
    },
}

impl Sky {
    /// Linear colour seen along unit direction `dir`.
    #[inline]
    pub fn radiance(&self, dir: DVec3) -> Vec3 {
        match self {
            Sky::Uniform(c) => *c,
            Sky::Panorama {
                texture,
                filter,
                intensity,
            } => {
                let (u, v) = equirect_uv(dir);
                texture.sample(u, v, *filter, true).truncate() * *intensity
            }
        }
    }
}
