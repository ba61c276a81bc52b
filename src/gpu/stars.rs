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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{Override, SceneConfig};
    use crate::gpu::pack::Packed;
    use crate::stars::field::FIELD_MAGIC;

    fn spectral_side(sky_filter: &str) -> Scene {
        let sets = [
            "image.width=8".to_string(),
            "image.height=8".into(),
            format!("sky.filter=\"{sky_filter}\""),
        ];
        let overrides: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("configs/spectral_side.toml");
        Scene::build(SceneConfig::load(&path, &overrides).unwrap()).unwrap()
    }

    #[test]
    fn point_stars_are_packed_after_the_sky_and_only_with_the_footprint_filter() {
        let s = spectral_side("footprint");
        let Sky::Stars {
            points: Some(field),
            ..
        } = &s.sky
        else {
            panic!("spectral_side with the footprint filter has point stars");
        };
        let p = Packed::new(&s).unwrap();
        let at = p.params.stars_at as usize;
        // After the Milky Way and its mip levels, all of the field.
        assert!(at > 0 && at >= p.params.ewa_milky_way_mips as usize);
        assert_eq!(&p.sky[at..], field.gpu_words().as_slice());
        assert_eq!(p.sky[at], FIELD_MAGIC);
        let d = p.params.stars_densest as usize;
        let levels = (MAX_LEVEL + 1) as usize;
        for (k, t) in field.tiers().iter().enumerate() {
            for l in 0..=t.level() {
                assert_eq!(p.tables[d + k * levels + l as usize], t.densest(l) as f32);
            }
        }
        assert_eq!(p.params.stars_max, 64.0);
        // Splatted stars: none.
        let p = Packed::new(&spectral_side("bilinear")).unwrap();
        assert_eq!(p.params.stars_at, NONE);
    }
}
