//! Stars as point sources: the catalogue, its spatial index and summed
//! levels, and synthetic catalogues.

pub mod catalogue;
pub mod cube;
pub mod density;
pub mod index;
pub mod light;
pub mod synthetic;

pub use catalogue::{
    DEFAULT_BV, PointStar, Star, equatorial_to_galactic, galactic_to_world, parse_catalogue,
    parse_point_stars, star_kelvin,
};
pub use density::{Density, SumRule, cap_solid_angle};
pub use index::{CapSum, CellSum, StarIndex};
pub use light::{Light, LightSum};
pub use synthetic::{synthetic, to_csv};
