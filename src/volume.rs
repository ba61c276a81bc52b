//! Participating media: the volumetric accretion disk (glowing gas of finite
//! thickness) and absorbing gas clouds, integrated along the curved ray.
//!
//! Along each step's segment the gas is walked by the pieces' loop of every
//! band ([`crate::transfer::pieces`]), in pieces two `step`s long taken at
//! two nodes each; each piece adds its emission times the transmittance so
//! far and then multiplies the transmittance by exp(-kappa dl)
//! ([`crate::transfer::Piece`]: exact for gas constant over a piece).

use crate::physics::Segment;
use glam::DVec3;
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use rayon::prelude::*;

/// Rows of the radial source table.
const SOURCE_ROWS: usize = 2048;

/// A scalar field on a regular 3D grid, trilinear between nodes, 0 outside.
#[derive(Clone, Debug)]
pub struct Grid3 {
    n: [usize; 3],
    min: DVec3,
    cell: DVec3,
    data: std::sync::Arc<Vec<f32>>,
}

impl Grid3 {
    /// Samples `f` at the nodes of an n[0] x n[1] x n[2] grid spanning
    /// [min, max].
    pub fn build(n: [usize; 3], min: DVec3, max: DVec3, f: impl Fn(DVec3) -> f32 + Sync) -> Grid3 {
        let cell =
            (max - min) / DVec3::new((n[0] - 1) as f64, (n[1] - 1) as f64, (n[2] - 1) as f64);
        let data: Vec<f32> = (0..n[0] * n[1] * n[2])
            .into_par_iter()
            .map(|i| {
                let (x, y, z) = (i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1]));
                f(min + cell * DVec3::new(x as f64, y as f64, z as f64))
            })
            .collect();
        Grid3 {
            n,
            min,
            cell,
            data: data.into(),
        }
    }

    /// Trilinear value at `p` (0 outside the grid).
    #[inline]
    pub fn sample(&self, p: DVec3) -> f32 {
        let f = (p - self.min) / self.cell;
        if f.x < 0.0 || f.y < 0.0 || f.z < 0.0 {
            return 0.0;
        }
        let (i, j, k) = (f.x as usize, f.y as usize, f.z as usize);
        if i + 1 >= self.n[0] || j + 1 >= self.n[1] || k + 1 >= self.n[2] {
            return 0.0;
        }
        let (tx, ty, tz) = (
            (f.x - i as f64) as f32,
            (f.y - j as f64) as f32,
            (f.z - k as f64) as f32,
        );
        let at = |a: usize, b: usize, c: usize| self.data[(c * self.n[1] + b) * self.n[0] + a];
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(at(i, j, k), at(i + 1, j, k), tx);
        let x10 = lerp(at(i, j + 1, k), at(i + 1, j + 1, k), tx);
        let x01 = lerp(at(i, j, k + 1), at(i + 1, j, k + 1), tx);
        let x11 = lerp(at(i, j + 1, k + 1), at(i + 1, j + 1, k + 1), tx);
        lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz)
    }

    /// (nodes per axis, the first node, the spacing, the values), for the
    /// GPU backend.
    pub(crate) fn gpu_parts(&self) -> ([usize; 3], DVec3, DVec3, &[f32]) {
        (self.n, self.min, self.cell, &self.data)
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        4 * self.data.len()
    }
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The volumetric disk: gas between `inner` and `outer` (r_s) with a
/// Gaussian vertical profile of scale height `height(r)`, its density
/// modulated by sheared fractal Perlin noise, glowing as a blackbody at the
/// thin-disk temperature of its radius, turning as [`VolumeDisk::motion`].
/// One model for both bands: an observed scene's medium
/// ([`crate::transfer::VolumeGas`]) is this disk in physical units.
#[derive(Clone, Debug)]
pub struct VolumeDisk {
    /// Inner radius.
    pub inner: f64,
    /// Outer radius.
    pub outer: f64,
    /// Scale height at the outer edge.
    pub thickness: f64,
    /// Absorption coefficient (per r_s) at density 1.
    pub kappa: f64,
    /// Emission: luminance per r_s of path at density 1 and the peak
    /// temperature.
    pub emission: f32,
    /// Peak temperature (K).
    pub peak_kelvin: f64,
    /// Sampling step along the ray (r_s).
    pub step: f64,
    /// Density (0..~1.5), precomputed on a grid.
    pub density: Grid3,
    /// How its gas moves about the hole (Keplerian, plunging inside the
    /// ISCO), in both bands: the visible light's shift and an observed
    /// scene's transfer.
    pub motion: crate::transfer::riaf::Motion,
    /// Temperature and luminance relative to the peak temperature's, per
    /// radius from `inner` to `outer` (the source function's radial part).
    source: Vec<(f64, f32)>,
    colours: crate::spectrum::BlackbodyTable,
}

impl VolumeDisk {
    /// The radial source table (kelvin, relative luminance per row from
    /// `inner` to `outer`) and the blackbody colours, for the GPU backend.
    pub(crate) fn gpu_parts(&self) -> (&[(f64, f32)], &crate::spectrum::BlackbodyTable) {
        (&self.source, &self.colours)
    }

    /// Scale height at cylindrical radius r: the disk flares outward.
    pub fn height(&self, r: f64) -> f64 {
        self.thickness * (0.4 + 0.6 * r / self.outer)
    }

    /// Builds the density grid.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        inner: f64,
        outer: f64,
        thickness: f64,
        kappa: f64,
        emission: f32,
        peak_kelvin: f64,
        step: f64,
        seed: u32,
        kerr: crate::physics::kerr::Kerr,
    ) -> VolumeDisk {
        let zmax = 3.0 * thickness;
        let turbulence = Fbm::<Perlin>::new(seed).set_octaves(5);
        let mut disk = VolumeDisk {
            inner,
            outer,
            thickness,
            kappa,
            emission,
            peak_kelvin,
            step,
            motion: crate::transfer::riaf::Motion::new(1.0, 0.0, kerr),
            density: Grid3 {
                n: [2, 2, 2],
                min: DVec3::ZERO,
                cell: DVec3::ONE,
                data: vec![0.0; 8].into(),
            },
            source: Vec::new(),
            colours: crate::spectrum::BlackbodyTable::new(100.0, peak_kelvin + 100.0),
        };
        let y_peak = crate::spectrum::sampled::luminance(peak_kelvin);
        disk.source = (0..SOURCE_ROWS)
            .map(|i| {
                let r = inner + (outer - inner) * i as f64 / (SOURCE_ROWS - 1) as f64;
                let t = disk.kelvin(r).max(100.0);
                (t, (crate::spectrum::sampled::luminance(t) / y_peak) as f32)
            })
            .collect();
        let n_xy = 320;
        let n_z = 33;
        let h = |r: f64| thickness * (0.4 + 0.6 * r / outer);
        disk.density = Grid3::build(
            [n_xy, n_xy, n_z],
            DVec3::new(-outer, -outer, -zmax),
            DVec3::new(outer, outer, zmax),
            |p| {
                let r = (p.x * p.x + p.y * p.y).sqrt();
                if r < inner * 0.9 || r > outer {
                    return 0.0;
                }
                let radial =
                    smoothstep(inner, inner * 1.15, r) * (1.0 - smoothstep(outer * 0.75, outer, r));
                let vertical = (-0.5 * (p.z / h(r)).powi(2)).exp();
                let phi = p.y.atan2(p.x) + 2.5 * r.ln();
                let n = turbulence.get([
                    1.8 * phi.cos(),
                    1.8 * phi.sin(),
                    10.0 * r.ln() + 0.8 * p.z / h(r),
                ]);
                let clumps = (0.55 + 0.65 * n).clamp(0.05, 1.5);
                (radial * vertical * clumps) as f32
            },
        );
        disk
    }

    /// The length (r_s) of the pieces its gas is taken in: two sampling
    /// steps, one between the nodes of each ([`crate::transfer::pieces`]).
    pub fn scale(&self) -> f64 {
        2.0 * self.step
    }

    /// Largest height where there is gas.
    pub fn zmax(&self) -> f64 {
        3.0 * self.thickness
    }

    /// The segment's parameter interval inside the disk's slab, if any.
    pub fn interval(&self, seg: &Segment) -> Option<(f64, f64)> {
        slab(seg.x0.z, seg.x1.z, self.zmax())
    }

    /// Temperature (K) and luminance relative to the peak temperature's of
    /// the gas at cylindrical radius r.
    #[inline]
    pub fn source(&self, r: f64) -> (f64, f32) {
        let f = ((r - self.inner) / (self.outer - self.inner) * (SOURCE_ROWS - 1) as f64)
            .clamp(0.0, (SOURCE_ROWS - 1) as f64);
        self.source[f.round() as usize]
    }

    /// Linear sRGB of a blackbody at `kelvin`, luminance 1.
    #[inline]
    pub fn rgb(&self, kelvin: f64) -> glam::Vec3 {
        self.colours.get(kelvin)
    }

    /// Temperature at cylindrical radius r.
    pub fn kelvin(&self, r: f64) -> f64 {
        self.peak_kelvin * crate::assets::disk::temperature_profile(r, self.inner)
    }
}

/// Parameter interval of a straight segment from height z0 to z1 within
/// |z| <= h.
fn slab(z0: f64, z1: f64, h: f64) -> Option<(f64, f64)> {
    if z0 == z1 {
        return (z0.abs() <= h).then_some((0.0, 1.0));
    }
    let (a, b) = ((-h - z0) / (z1 - z0), (h - z0) / (z1 - z0));
    let (lo, hi) = (a.min(b).max(0.0), a.max(b).min(1.0));
    (lo < hi).then_some((lo, hi))
}

/// An absorbing gas cloud: a ball whose density falls as 1 - (d/R)^2,
/// lumpy with noise, of optical depth `depth` through its centre at
/// 550 nm, extinction ~ (lambda / 550 nm)^-beta, glowing with the light it
/// scatters (`glow`, linear sRGB) so it is never simply black.
#[derive(Clone, Debug)]
pub struct Cloud {
    /// Centre (r_s).
    pub center: DVec3,
    /// Radius (r_s).
    pub radius: f64,
    /// Absorption coefficient at the centre (per r_s, 550 nm).
    pub kappa0: f64,
    /// Extinction exponent.
    pub beta: f64,
    /// Radiance the cloud shows where it is opaque.
    pub glow: glam::Vec3,
    /// Sampling step (r_s).
    pub step: f64,
    /// Relative density (lumpy 1 - (d/R)^2) on a grid over the ball.
    grid: Grid3,
    /// (lambda / 550 nm)^-beta at each camera wavelength (spectral renders).
    pub extinction_table: Vec<f64>,
    /// The glow's spectrum (spectral renders).
    pub glow_spectrum: Option<crate::spectrum::uplift::RgbSpectrum>,
}

impl Cloud {
    /// A cloud of optical depth `depth` through its centre.
    pub fn new(
        center: DVec3,
        radius: f64,
        depth: f64,
        beta: f64,
        glow: glam::Vec3,
        seed: u32,
    ) -> Cloud {
        let noise = Fbm::<Perlin>::new(seed).set_octaves(4);
        let grid = Grid3::build(
            [48, 48, 48],
            center - DVec3::splat(radius),
            center + DVec3::splat(radius),
            |p| {
                let d2 = (p - center).length_squared() / (radius * radius);
                if d2 >= 1.0 {
                    return 0.0;
                }
                let lumps = 1.0 + 0.5 * noise.get(((p - center) / radius * 2.5).to_array());
                ((1.0 - d2) * lumps) as f32
            },
        );
        Cloud {
            center,
            radius,
            // The integral of 1 - (x/R)^2 across the diameter is 4R/3.
            kappa0: depth * 3.0 / (4.0 * radius),
            beta,
            glow,
            step: radius / 16.0,
            grid,
            extinction_table: Vec::new(),
            glow_spectrum: None,
        }
    }

    /// Prepares the per-wavelength tables of a spectral render.
    pub fn for_wavelengths(mut self, nm: &[f64]) -> Cloud {
        self.extinction_table = nm.iter().map(|&l| self.extinction(l)).collect();
        self.glow_spectrum = Some(crate::spectrum::uplift::uplift(self.glow));
        self
    }

    /// The density grid, for the GPU backend.
    pub(crate) fn gpu_grid(&self) -> &Grid3 {
        &self.grid
    }

    /// Relative density at `p` (0 outside the ball).
    #[inline]
    pub fn density(&self, p: DVec3) -> f64 {
        self.grid.sample(p) as f64
    }

    /// The length (r_s) of the pieces its gas is taken in: two sampling
    /// steps, as the volume's ([`VolumeDisk::scale`]).
    pub fn scale(&self) -> f64 {
        2.0 * self.step
    }

    /// Extinction relative to 550 nm at wavelength `nm`.
    #[inline]
    pub fn extinction(&self, nm: f64) -> f64 {
        if self.beta == 0.0 {
            1.0
        } else {
            (nm / 550.0).powf(-self.beta)
        }
    }

    /// The segment's parameter interval inside the ball, if any.
    pub fn interval(&self, seg: &Segment) -> Option<(f64, f64)> {
        let d = seg.x1 - seg.x0;
        let m = seg.x0 - self.center;
        let (a, b, c) = (
            d.length_squared(),
            m.dot(d),
            m.length_squared() - self.radius * self.radius,
        );
        let disc = b * b - a * c;
        if a == 0.0 || disc <= 0.0 {
            return None;
        }
        let r = disc.sqrt();
        let (lo, hi) = (((-b - r) / a).max(0.0), ((-b + r) / a).min(1.0));
        (lo < hi).then_some((lo, hi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_and_ball_intervals() {
        assert_eq!(slab(-2.0, 2.0, 1.0), Some((0.25, 0.75)));
        assert_eq!(slab(2.0, 3.0, 1.0), None);
        let c = Cloud::new(
            DVec3::new(0.0, 10.0, 0.0),
            2.0,
            1.0,
            0.0,
            glam::Vec3::ZERO,
            1,
        );
        let seg = Segment::chord(DVec3::ZERO, DVec3::new(0.0, 20.0, 0.0));
        let (lo, hi) = c.interval(&seg).unwrap();
        assert!((lo - 0.4).abs() < 1e-12 && (hi - 0.6).abs() < 1e-12);
        assert!(
            c.interval(&Segment::chord(
                DVec3::new(3.0, 0.0, 0.0),
                DVec3::new(3.0, 20.0, 0.0)
            ))
            .is_none()
        );
    }

    #[test]
    fn cloud_depth_is_the_optical_depth_through_its_centre() {
        // Without its lumps, the density 1 - (d/R)^2 integrates to `depth`
        // along the diameter.
        let c = Cloud::new(DVec3::ZERO, 3.0, 1.7, 0.0, glam::Vec3::ZERO, 1);
        let n = 100_000;
        let tau: f64 = (0..n)
            .map(|i| {
                let x = -3.0 + 6.0 * (i as f64 + 0.5) / n as f64;
                c.kappa0 * (1.0 - (x / 3.0) * (x / 3.0)) * 6.0 / n as f64
            })
            .sum();
        assert!((tau - 1.7).abs() < 1e-6);
        assert!((c.extinction(450.0) - 1.0).abs() < 1e-15);
        let blue = Cloud::new(DVec3::ZERO, 3.0, 1.7, 1.3, glam::Vec3::ZERO, 1);
        assert!(blue.extinction(450.0) > 1.0 && blue.extinction(650.0) < 1.0);
    }

    #[test]
    fn grid_interpolates_linear_fields_exactly() {
        let g = Grid3::build([5, 5, 5], DVec3::splat(-1.0), DVec3::splat(1.0), |p| {
            (p.x + 2.0 * p.y - p.z) as f32
        });
        let p = DVec3::new(0.3, -0.2, 0.45);
        assert!((g.sample(p) - (0.3 - 0.4 - 0.45) as f32).abs() < 1e-6);
        assert_eq!(g.sample(DVec3::splat(2.0)), 0.0);
    }
}
