//! Stars as point sources: the catalogue, its spatial index and summed
//! levels, brightness tiers, and synthetic catalogues.
//!
//! - [`catalogue`]: the CSV (`hip,ra_deg,dec_deg,vmag,bv`) parsed in
//!   parallel; each star a [`PointStar`]: unit direction in scene axes,
//!   flux 10^(-0.4 V) (magnitude 0 = 1) and blackbody temperature from B-V.
//! - [`cube`]: equi-angular cube-map cells (6 faces of 2^l x 2^l, Morton
//!   order within a face).
//! - [`index`]: [`StarIndex`], the stars sorted by leaf cell with CSR
//!   offsets; every star within an angle of a direction, exactly once
//!   ([`StarIndex::for_each_within`]); exact cap sums from whole cells'
//!   sums and the rim's stars ([`StarIndex::cap_sum`]).
//! - [`light`]: the summed light of many stars as two blackbodies (one
//!   temperature misses their colour by about one just-noticeable
//!   difference).
//! - [`density`]: flux per steradian from the summed levels in constant
//!   time ([`StarIndex::smooth_density`]) and the crossover [`SumRule`].
//! - [`field`]: [`StarField`], the catalogue in brightness tiers, each
//!   summed or resolved on its own ([`StarField::footprint`]): what a
//!   renderer asks for a footprint.
//! - [`synthetic`]: catalogues of any size with a real one's statistics.
//!
//! # GPU layout
//!
//! [`StarIndex::gpu_words`] is one array of 32-bit words (f32 as their
//! bits) for a storage buffer; `L` is the leaf level, `N` the star count,
//! `C = 6 * 4^L` the leaf cells:
//!
//! | words | what |
//! |---|---|
//! | 0 .. 8 | header: magic `"STR1"`, L, N, then where the four arrays start (S, O, U, I) and the total |
//! | S .. S + 5N | stars, 5 words each: direction x, y, z (f32, scene axes), flux (f32), kelvin (f32) |
//! | O .. O + C + 1 | CSR offsets (u32): the stars of leaf cell k are stars offsets[k] .. offsets[k+1] |
//! | U .. U + 4 * 2(4^(L+1) - 1) | summed levels, level 0 first, level l from cell 2(4^l - 1): per cell cool flux, hot flux, cool kelvin, hot kelvin (f32) |
//! | I .. I + (4^(L+1) - 1) / 3 | 1 / solid angle (sr) of one face's cells, level l from (4^l - 1) / 3, Morton order (the same on all six faces) |
//!
//! A direction's cell at level l: its face `f` (largest component, see
//! [`cube`]), face coordinates `x = atan2(pu, pa) / (pi/4)` and likewise
//! `y`, `i = floor((x + 1) / 2 * 2^l)` (clamped to 2^l - 1), the same for
//! `j`; cell id `f * 4^l + morton(i, j)` (i in the even bits). A cell `k`
//! of level l covers leaf cells `k * 4^(L-l) .. (k+1) * 4^(L-l)`, so its
//! stars are `offsets[k << 2(L-l)] .. offsets[(k+1) << 2(L-l)]`: star
//! counts of any cell come from the offsets. At 2.5 million stars (L = 8)
//! the words are 57.5 MiB; storage buffers are commonly limited to 128
//! MiB (wgpu's default `max_storage_buffer_binding_size`), about 5.5
//! million stars.
//!
//! [`StarField::gpu_words`] puts the tiers in one array: magic `"STF1"`,
//! the tier count T, T words giving where each tier's block starts, then
//! the blocks, each laid out as above with offsets from its own start.
//! The GPU backend draws point stars from these words (`src/gpu/stars.rs`
//! uploads them, `src/gpu/stars.wgsl` reads them).

pub mod catalogue;
pub mod cube;
pub mod density;
pub mod field;
pub mod index;
pub mod light;
pub mod synthetic;

pub use catalogue::{
    DEFAULT_BV, PointStar, Star, equatorial_to_galactic, galactic_to_world, parse_catalogue,
    parse_point_stars, star_kelvin,
};
pub use density::{Density, SumRule, cap_solid_angle};
pub use field::StarField;
pub use index::{CapSum, StarIndex};
pub use light::{CellSum, Light, LightSum};
pub use synthetic::{synthetic, to_csv};
