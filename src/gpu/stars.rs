//! Point stars on the GPU, the host's side: the catalogue's tiers
//! ([`StarField::gpu_words`]) appended to the sky's words, each tier's
//! densest cell per level to `tables`, and the constants `stars.wgsl`
//! (the f32 twin of [`crate::sky`]'s point stars and [`crate::stars`])
//! shares with the host.

use super::layout::{NONE, Params};
use crate::scene::Scene;
use crate::sky::Sky;
use crate::stars::index::{MAX_BOX_CELLS, MAX_LEVEL};
use crate::stars::{StarField, SumRule};

/// Slack (radians) added to a footprint's reach when choosing the cells
/// it reads: the face coordinates of the cap's box are f32 (a few 1e-7
/// rad off), where the CPU's 1e-9 would not keep a star near a cell's
/// edge in the box. The stars themselves are tested exactly.
const BOX_MARGIN: f64 = 1e-5;

/// `stars.wgsl` with the constants it shares with the host before it.
pub(crate) fn wgsl() -> String {
    format!(
        "const STARS_MAG0: f32 = {:?};\nconst STARS_REFINE_MARGIN: f32 = {:?};\n\
         const STARS_MAX_BOX_CELLS: u32 = {}u;\nconst STARS_LEVELS: u32 = {}u;\n\
         const STARS_CELL_PER_RADIUS: f32 = {:?};\nconst STARS_BOX_MARGIN: f32 = {:?};\n{}",
        crate::sky::MAG0_FLUX as f32,
        crate::sky::REFINE_MARGIN as f32,
        MAX_BOX_CELLS,
        MAX_LEVEL + 1,
        crate::stars::density::CELL_PER_RADIUS as f32,
        BOX_MARGIN as f32,
        include_str!("stars.wgsl")
    )
}

/// The point stars of `scene`'s sky, if any: their words appended to
/// `sky`, their densest cells to `tables`, and where in `p`. Without
/// point stars `p.stars_at` is NONE.
pub(crate) fn pack(p: &mut Params, tables: &mut Vec<f32>, sky: &mut Vec<u32>, scene: &Scene) {
    p.stars_at = NONE;
    let Sky::Stars {
        points: Some(field),
        ..
    } = &scene.sky
    else {
        return;
    };
    p.stars_at = sky.len() as u32;
    sky.extend(field.gpu_words());
    p.stars_densest = tables.len() as u32;
    tables.extend(densest(field));
    p.stars_max = SumRule::default().max_stars as f32;
}

/// Each tier's most stars per steradian in a cell of each level
/// ([`crate::stars::StarIndex::densest`]), `MAX_LEVEL + 1` a tier (0
/// past its leaf level).
fn densest(field: &StarField) -> Vec<f32> {
    field
        .tiers()
        .iter()
        .flat_map(|t| {
            (0..=MAX_LEVEL).map(move |l| {
                if l <= t.level() {
                    t.densest(l) as f32
                } else {
                    0.0
                }
            })
        })
        .collect()
}
