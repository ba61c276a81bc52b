//! Footprint filtering on the GPU, the host's side: the mip levels the CPU
//! builds (`Scene::build_filters`) appended to the disk's and the sky's
//! data after level 0, the CPU's weight table, and the constants of
//! `ewa.wgsl` (the f32 twin of [`crate::texture::ewa`]; see the README's
//! "Filtered textures").

use super::layout::Params;
use crate::config::Filter;
use crate::disk::DiskMaterial;
use crate::scene::Scene;
use crate::sky::Sky;
use crate::texture::{MAX_ANISOTROPY, ewa, mip};

/// The largest derivative, in level-0 texels, a lookup takes as given:
/// beyond it the footprint's minor axis after the anisotropy cap is over
/// 6e7 texels, and every such footprint reads the coarsest level as a
/// circle there, whatever its shape (the CPU caps at 1e12 in f64; f32
/// squares 1e9 twice without overflowing).
const EWA_COORD: f64 = 1e9;

/// `ewa.wgsl` with the constants it shares with the host before it.
pub(crate) fn wgsl() -> String {
    format!(
        "const EWA_MAX_ANISOTROPY: f32 = {:?};\nconst EWA_TABLE: u32 = {}u;\n\
         const EWA_COORD: f32 = {:?};\nconst EWA_REACH: f32 = {:?};\n{}",
        MAX_ANISOTROPY as f32,
        ewa::TABLE,
        EWA_COORD as f32,
        ewa::REACH as f32,
        include_str!("ewa.wgsl")
    )
}

/// Appends the mip levels of what `scene` filters by footprint to the
/// disk's and the sky's words (after level 0, which they hold), the
/// weight table to `tables`, and says where in `p`. The star map's
/// layout (whether it has a star grid, where its Milky Way grid starts)
/// is set for every star sky.
pub(crate) fn pack(
    p: &mut Params,
    tables: &mut Vec<f32>,
    disk: &mut Vec<u32>,
    sky: &mut Vec<u32>,
    scene: &Scene,
) {
    if let Sky::Stars { map, .. } = &scene.sky {
        let grid = map.has_star_grid();
        p.ewa_star_grid = grid as u32;
        p.ewa_milky_way_at = if grid {
            2 * map.width * (map.width / 2)
        } else {
            0
        };
    }
    let footprint_disk = scene
        .disk
        .as_ref()
        .filter(|d| d.filter == Filter::Footprint);
    let footprint_sky = scene.sky.filter() == Some(Filter::Footprint);
    // Object textures' levels go with their texels (pack.rs's object
    // records); they need the weights too.
    if footprint_disk.is_none() && !footprint_sky && !scene.object_footprints {
        return;
    }
    p.at_ewa_weights = tables.len() as u32;
    tables.extend_from_slice(ewa::weight_table());
    if let Some(d) = footprint_disk {
        p.ewa_disk_mips = disk.len() as u32;
        match &d.material {
            DiskMaterial::Rgb(t) => disk.extend(t.gpu_mip_words()),
            DiskMaterial::Spectral(s) => {
                let values = mip::texel_count(s.width, s.height) * s.nm.len();
                p.ewa_disk_mip_alpha = p.ewa_disk_mips + values as u32;
                disk.extend(s.gpu_mip_words());
            }
        }
    }
    if footprint_sky {
        match &scene.sky {
            Sky::Panorama { texture, .. } => {
                p.ewa_sky_mips = sky.len() as u32;
                sky.extend(texture.gpu_mip_words());
            }
            Sky::Stars { map, .. } => {
                let (stars, milky_way) = map.gpu_mip_words();
                p.ewa_sky_mips = sky.len() as u32;
                sky.extend(stars);
                p.ewa_milky_way_mips = sky.len() as u32;
                sky.extend(milky_way);
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests;
