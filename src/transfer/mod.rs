//! Radiative transfer in physical units along the curved ray: unpolarised,
//! in invariant form. Along the affine parameter lambda of a photon of
//! unit energy at infinity (k_t = -1),
//!
//! d(I_nu / nu^3) / d lambda = j_nu / nu^2 - (nu alpha_nu) (I_nu / nu^3),
//!
//! with nu = -k.u the frequency the medium (four-velocity u) measures and
//! j_nu, alpha_nu its coefficients there. A ray is traced from the camera,
//! so the intensity is gathered front to back: each piece of constant
//! coefficients adds what it emits, dimmed by the optical depth between it
//! and the camera, I += T S (1 - e^-dtau) (just T j dl where it does not
//! absorb), and T *= e^-dtau: the exact solution I' = I e^-dtau +
//! S (1 - e^-dtau) of a constant piece, summed from the other end. All in
//! the camera's frame: a piece whose gas measures nu = x nu_cam adds
//! j(nu) dl / x^3, dl = x_inf dlambda its own path length.
//!
//! Pieces are as long as [`SCALE_FRACTION`] of the medium's scale where
//! they are ([`Medium::scale`]: its coefficients' e-folding length; half
//! the distance to the horizon at most), no thicker than [`MAX_DTAU`] at
//! any frequency, and end where the ray crosses a surface of the medium:
//! each takes the gas at its two Gauss-Legendre nodes. Where the
//! coefficients are constant the pieces are exact; where they vary the
//! error falls as the fourth power of the piece (a ray of Gold et al.'s
//! flow within 1e-7 of its integral by quadrature at 30 digits; the five
//! tests' fluxes move by under 4e-6 with pieces an eighth as long, Sgr
//! A*'s and M87*'s by under 5e-5).
//!
//! The pieces' loop ([`RayTransfer::run`]) walks any [`Path`]: an
//! integrator's segment or Schwarzschild's closed-form one
//! ([`RayTransfer::march`]), or a stretch of Kerr's closed-form ray
//! ([`closed`]).

pub mod closed;
pub mod gold;
pub mod grmhd;
pub mod pieces;
pub mod riaf;
pub mod sky;
pub mod synchrotron;
pub mod uniform;
pub mod volume;

use crate::physics::Segment;
use crate::physics::kerr::Kerr;
use glam::DVec3;
pub use gold::Gold;
pub use grmhd::dark::{Bounds, Census};
use pieces::{Cut, Pieces};
pub use riaf::{Riaf, RiafProfile};
pub use uniform::Uniform;
pub use volume::VolumeGas;

/// Most optical depth a piece takes at any frequency.
pub const MAX_DTAU: f64 = 0.1;

/// A piece's length as a fraction of the medium's scale there (measured:
/// REFERENCE.md section 19, and [`RayTransfer::run`]).
pub const SCALE_FRACTION: f64 = 1.0;

/// Below this transmittance nothing further along the ray is seen at a
/// frequency: it no longer limits the pieces, and where every frequency
/// is spent the ray ends.
pub const SPENT: f64 = 1e-12;

/// The two-point Gauss-Legendre nodes' distance from a piece's middle,
/// as a fraction of the piece: 1 / (2 sqrt 3).
pub const GAUSS_2: f64 = 0.288_675_134_594_812_9;

/// In a medium with a surface inside it ([`Medium::sharp`]) a piece
/// against the surface or near it ([`pieces::NEAR`]) whose nodes'
/// emission differs by more than this share of their sum (a ratio of 39)
/// is cut in two, down to [`SHARPEST`] of the medium's scale: the
/// brightest gas of a snapshot lies against its magnetisation cut, where
/// the electrons' temperature climbs steeply (ipole takes steps of about a
/// third of a cell there). On the generated torus with its funnel (40x40,
/// 60 degrees, 230 GHz, MKS and FMKS) the flux then comes within 6e-4 of
/// ipole's at a quarter of its default step, against 2.3% short refining
/// only the pieces against the surface, 36% short refining none;
/// SHARPEST 1/4 leaves it 5% short.
pub const CONTRAST: f64 = 0.95;
pub const SHARPEST: f64 = 1.0 / 16.0;

/// Most pieces one segment is cut into.
pub const MAX_PIECES: usize = 100_000;

/// Past this exponent a flow's Gaussian factor (Gold et al.'s density,
/// the RIAF's vertical profile) is taken as nil: e^-20 (2e-9) of its
/// scale, where what it would add to a flux is below 1e-8 of it.
pub const CUTOFF: f64 = 20.0;

/// The exact solution across a piece of constant coefficients and optical
/// depth `dtau`: I_out = I_in e^-dtau + S (1 - e^-dtau), S = j / alpha.
/// Summed from the camera's end, a piece seen through transmittance T
/// adds T S (1 - e^-dtau) and leaves T e^-dtau for all behind it. One
/// solver for every medium: the physical media here, and the visible
/// band's volumetric disk and clouds ([`crate::volume`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// Its optical depth.
    pub dtau: f64,
    /// e^-dtau: what it lets through.
    pub kept: f64,
    /// (1 - e^-dtau) / dtau: the share of its emission j dl that leaves
    /// it (1 where it does not absorb).
    shown: f64,
}

impl Piece {
    #[inline]
    pub fn new(dtau: f64) -> Piece {
        // One exponential for both; (1 - e^-x) / x by its series where
        // the division would lose digits.
        let less = (-dtau).exp_m1();
        let shown = if dtau < 1e-6 {
            1.0 - 0.5 * dtau
        } else {
            -less / dtau
        };
        Piece {
            dtau,
            kept: 1.0 + less,
            shown,
        }
    }

    /// What it sends on of an emission `j_dl` (j_nu times its length).
    #[inline]
    pub fn emission(&self, j_dl: f64) -> f64 {
        j_dl * self.shown
    }

    /// What it sends on where its source function is `source`: S (1 -
    /// e^-dtau).
    #[inline]
    pub fn source(&self, source: f64) -> f64 {
        source * self.dtau * self.shown
    }
}

/// An angle in micro-arcseconds.
pub fn micro_arcseconds(rad: f64) -> f64 {
    rad.to_degrees() * 3.6e9
}

/// A medium in physical units.
#[derive(Clone, Debug)]
pub enum Medium {
    /// Gold et al. 2020's analytic flow.
    Gold2020(Gold),
    /// A uniform shell of gas at rest.
    Uniform(Uniform),
    /// The radiatively inefficient accretion flow's thermal synchrotron
    /// (`kind = "synchrotron"`).
    Riaf(Riaf),
    /// The volumetric disk's gas, shining as a blackbody.
    Volume(Box<VolumeGas>),
    /// A GRMHD simulation's snapshot (`kind = "grmhd"`).
    Grmhd(Box<grmhd::Grmhd>),
}

/// What a medium is at a point of a ray: the frequency x_inf = nu_gas /
/// nu_inf its gas measures of a unit-energy photon, and what its
/// coefficients depend on there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gas {
    pub ratio: f64,
    pub plasma: Plasma,
}

/// What a medium's coefficients depend on at a point, found once for all
/// the frequencies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Plasma {
    /// Gold's flow at a density.
    Gold(Gold, f64),
    /// The uniform shell.
    Shell(Uniform),
    /// The flow's electrons.
    Thermal(synchrotron::Thermal),
    /// Electrons at one pitch angle to an ordered field.
    Pitched(synchrotron::Pitched),
    /// Gas in local thermodynamic equilibrium: absorption `alpha` (cm^-1,
    /// grey), source function Planck's at `kelvin`.
    Blackbody { alpha: f64, kelvin: f64 },
}

impl Plasma {
    /// (j_nu, alpha_nu) in cgs at gas-frame frequency `nu`.
    #[inline]
    fn coefficients(&self, nu: f64) -> (f64, f64) {
        match self {
            Plasma::Gold(g, n) => g.coefficients(*n, nu),
            Plasma::Shell(u) => u.coefficients(nu),
            Plasma::Thermal(t) => t.coefficients(nu),
            Plasma::Pitched(t) => t.coefficients(nu),
            Plasma::Blackbody { alpha, kelvin } => {
                (alpha * crate::spectrum::planck_nu(nu, *kelvin), *alpha)
            }
        }
    }
}

impl Medium {
    /// One line saying what it is, for `info`.
    pub fn describe(&self) -> String {
        use crate::config::quantity::frequency_text;
        match self {
            Medium::Gold2020(g) => format!(
                "gold2020 (Gold et al. 2020): A {}, alpha {}, h {:.6}, l0 {}, n0 {:e} cgs, nu_p {}",
                g.a_abs,
                g.alpha,
                g.h,
                g.l0,
                g.n0,
                frequency_text(g.nu_p)
            ),
            Medium::Uniform(u) => format!(
                "uniform shell at rest, r {} to {} M: j_nu {:e} cgs at {} (~ nu^-{}), alpha_nu {:e} cm^-1",
                u.inner,
                u.outer,
                u.j0,
                frequency_text(u.nu_p),
                u.alpha,
                u.k0
            ),
            Medium::Riaf(f) => {
                let p = &f.profile;
                format!(
                    "synchrotron (thermal, angle-averaged Leung et al. 2011) in a RIAF to {} M: n_e {:e} cm^-3 r^{}, T_e {:e} K r^{}, H {}, beta {}, Keplerian {}, infall {}",
                    p.outer,
                    p.density,
                    p.density_index,
                    p.temperature,
                    p.temperature_index,
                    p.thickness,
                    p.beta,
                    p.keplerian,
                    p.infall
                )
            }
            Medium::Volume(v) => format!(
                "the volumetric disk's gas as a blackbody, r {} to {} r_s: T {:.0} K at its hottest, alpha_nu {:e} cm^-1 at density 1 (grey), Keplerian",
                v.disk.inner, v.disk.outer, v.disk.peak_kelvin, v.alpha
            ),
            Medium::Grmhd(g) => g.describe(),
        }
    }

    /// Whether its emission can change sharply within its scale: a
    /// snapshot's magnetisation cut ends hot gas at a surface that is no
    /// radius ([`Medium::level`] tells it), and its brightest gas lies
    /// against it.
    pub fn sharp(&self) -> bool {
        matches!(self, Medium::Grmhd(g) if g.has_cut())
    }

    /// The level whose crossing of 1 is its inner surface, at (r, cos
    /// th), the point `p` (M): for a snapshot, its magnetisation over the
    /// cut.
    #[inline]
    fn level(&self, (r, cos_th): (f64, f64), p: DVec3) -> f64 {
        match self {
            Medium::Grmhd(g) => g.cut_level((r, cos_th), p),
            _ => 0.0,
        }
    }

    /// The GRMHD snapshot, if it is one.
    pub fn grmhd_mut(&mut self) -> Option<&mut grmhd::Grmhd> {
        match self {
            Medium::Grmhd(g) => Some(g),
            _ => None,
        }
    }

    /// What it holds within `b`, where it can tell: whether it is dark
    /// there, or smooth enough for longer pieces.
    fn census(&self, b: &Bounds) -> Option<Census> {
        match self {
            Medium::Grmhd(g) => Some(g.census(b)),
            _ => None,
        }
    }

    /// How many of its cells a stretch within `b` crosses, where it is a
    /// grid and can tell ([`grmhd::Grmhd::cells`]).
    fn cells(&self, b: &Bounds) -> Option<f64> {
        match self {
            Medium::Grmhd(g) => g.cells(b),
            _ => None,
        }
    }

    /// Whether nothing within `b` emits or absorbs (false where it cannot
    /// tell).
    pub fn dark(&self, b: &Bounds) -> bool {
        self.census(b) == Some(Census::Dark)
    }

    /// Whether it is the same at every azimuth (Kerr's closed-form rays
    /// then need no azimuth along the way; the GPU's, which carry none,
    /// take only such media).
    pub fn axisymmetric(&self) -> bool {
        match self {
            Medium::Volume(_) => false,
            Medium::Grmhd(g) => g.header.n[2] == 1,
            _ => true,
        }
    }

    /// Beyond this Boyer-Lindquist radius (M) the medium is empty.
    pub fn extent(&self) -> f64 {
        match self {
            Medium::Gold2020(g) => g.extent(),
            Medium::Uniform(u) => u.outer,
            Medium::Riaf(f) => f.profile.outer,
            Medium::Volume(v) => v.extent(),
            Medium::Grmhd(g) => g.extent(),
        }
    }

    /// The radii (M) where the medium ends abruptly.
    fn surfaces(&self) -> &[f64] {
        match self {
            Medium::Gold2020(_) => &[],
            Medium::Uniform(u) => &u.surfaces,
            Medium::Riaf(f) => &f.surfaces,
            Medium::Volume(_) => &[],
            Medium::Grmhd(g) => g.surfaces(),
        }
    }

    /// The length (M) over which its coefficients change by about e at
    /// (r, cos th), the point `p` (M).
    fn scale(&self, (r, cos_th): (f64, f64), p: DVec3) -> f64 {
        match self {
            Medium::Gold2020(g) => g.scale(r, cos_th),
            Medium::Uniform(u) => u.scale(r),
            Medium::Riaf(f) => f.scale(r, cos_th),
            Medium::Volume(v) => v.scale(p),
            Medium::Grmhd(g) => g.scale(r, cos_th),
        }
    }

    /// At (r, cos th), the point `p` (M), for a photon of unit energy at
    /// infinity, angular momentum `lz`, radial momentum `k_r` =
    /// dr/dlambda and polar rate `k_cos` = d(cos th)/dlambda (M units):
    /// the gas there, or None where nothing radiates or absorbs.
    #[inline]
    fn state(
        &self,
        kerr: Kerr,
        (r, cos_th): (f64, f64),
        p: DVec3,
        (lz, k_r, k_cos): (f64, f64, f64),
    ) -> Option<Gas> {
        match self {
            Medium::Grmhd(g) => g.state((r, cos_th), p, (lz, k_r, k_cos)),
            Medium::Volume(v) => v.state(kerr, (r, cos_th), p, (lz, k_r)),
            Medium::Gold2020(g) => {
                let n = g.density(r, cos_th);
                if n <= 0.0 {
                    return None;
                }
                Some(Gas {
                    ratio: g.frequency_ratio(kerr, r, cos_th, lz)?,
                    plasma: Plasma::Gold(*g, n),
                })
            }
            Medium::Uniform(u) => {
                if !u.contains(r) {
                    return None;
                }
                Some(Gas {
                    ratio: u.frequency_ratio(kerr, r, cos_th, lz)?,
                    plasma: Plasma::Shell(*u),
                })
            }
            Medium::Riaf(f) => {
                let (n, t, b) = f.plasma(r, cos_th)?;
                Some(Gas {
                    ratio: f.motion.frequency_ratio(kerr, r, cos_th, (lz, k_r))?,
                    plasma: Plasma::Thermal(synchrotron::Thermal::new(n, t, b)?),
                })
            }
        }
    }
}

/// How a scene is observed in physical units (`[observe]`), and its
/// medium (`[medium]`, or the volumetric disk's gas) if it has one; a
/// scene observed without one holds a thin disk or a blackbody sky.
#[derive(Clone, Debug)]
pub struct Observe {
    /// The gas that shines and absorbs, if any.
    pub medium: Option<Medium>,
    /// The source's distance (cm).
    pub distance_cm: f64,
    /// The frequencies observed at the camera (Hz).
    pub frequencies: Vec<f64>,
}

/// The hole and units a ray's transfer runs in.
#[derive(Clone, Copy, Debug)]
pub struct Transport<'a> {
    pub medium: &'a Medium,
    /// The hole (spin 0 for Schwarzschild).
    pub kerr: Kerr,
    /// Centimetres per M (G M / c^2).
    pub cm_per_m: f64,
}

/// One ray's transfer at every observed frequency: the camera-frame
/// intensity gathered so far (cgs) and the transmittance to the camera.
#[derive(Clone, Debug)]
pub struct RayTransfer {
    /// nu_cam / nu_inf of the photons this ray carries (the camera's own
    /// measure of a unit-energy photon).
    pub camera_ratio: f64,
    /// L_z / E of the photon (M units).
    pub lz: f64,
    /// I_nu at the camera per frequency (erg s^-1 cm^-2 Hz^-1 sr^-1).
    pub intensity: Vec<f64>,
    /// e^-tau from the camera per frequency.
    pub through: Vec<f64>,
    /// A piece's (j_nu, alpha_nu) per frequency (scratch).
    coeffs: Vec<(f64, f64)>,
}

impl RayTransfer {
    /// A ray carrying photons of angular momentum `lz` (M units) that the
    /// camera sees at nu_cam = `camera_ratio` nu_inf, at `n` frequencies.
    pub fn new(camera_ratio: f64, lz: f64, n: usize) -> RayTransfer {
        RayTransfer {
            camera_ratio,
            lz,
            intensity: vec![0.0; n],
            through: vec![1.0; n],
            coeffs: vec![(0.0, 0.0); n],
        }
    }

    /// Whether the medium ahead can no longer be seen at any frequency.
    pub fn spent(&self) -> bool {
        self.through.iter().all(|&t| t < SPENT)
    }

    /// An opaque surface ends the ray: each frequency gets, through the
    /// gas in front of it, what the surface emits (`emitted(nu)`, cgs, at
    /// its own frequency nu), seen at ln(nu_cam / nu_emit) = `ln_g` as
    /// I_nu(nu_cam) = g^3 I_nu,emit(nu_cam / g) (I_nu / nu^3 is invariant).
    pub fn surface(&mut self, ln_g: f64, nu_cam: &[f64], emitted: impl Fn(f64) -> f64) {
        let g = ln_g.exp();
        let g3 = g * g * g;
        for (k, &nu) in nu_cam.iter().enumerate() {
            if self.through[k] >= SPENT {
                self.intensity[k] += self.through[k] * g3 * emitted(nu / g);
            }
            self.through[k] = 0.0;
        }
    }

    /// Gathers the medium along `seg` (r_s, as the tracers give it) from
    /// fraction `s0` to `s1`, at the camera frequencies `nu_cam` (Hz).
    pub fn march(&mut self, t: &Transport, seg: &Segment, (s0, s1): (f64, f64), nu_cam: &[f64]) {
        if s1 <= s0 || seg.affine <= 0.0 {
            return;
        }
        // Lengths in M: the affine parameter's, in r_s, doubled (per unit
        // of the segment's fraction s).
        let m_per_s = 2.0 * seg.affine;
        let path = SegmentPath {
            seg,
            kerr: t.kerr,
            m_per_s,
            cm_per_s: m_per_s * t.cm_per_m,
        };
        self.run(t, &path, (s0, s1), nu_cam);
    }

    /// Gathers the medium along `path` from `s0` to `s1`: pieces of
    /// [`SCALE_FRACTION`] of the medium's scale, thinner where one is
    /// thicker than [`MAX_DTAU`], cut at the medium's surfaces.
    pub fn run(&mut self, t: &Transport, path: &impl Path, (s0, s1): (f64, f64), nu_cam: &[f64]) {
        if s1 <= s0 {
            return;
        }
        let extent = t.medium.extent();
        let at = |s: f64| path.at(s);
        let ends = [at(s0), at(0.5 * (s0 + s1)), at(s1)];
        // The stretch is a short piece of a smooth curve: beyond the
        // medium at its ends and middle, it is beyond it throughout while
        // the middle is no nearer than the ends (the curve's radius has no
        // minimum inside it).
        let r_min = ends.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
        if r_min > 1.2 * extent {
            return;
        }
        // A stretch wholly where the medium cannot shine is crossed
        // before its scale is found.
        let bounds = path.bounds(s0, s1);
        let census = bounds.and_then(|b| Some((b, t.medium.census(&b)?)));
        if census.is_some_and(|(_, c)| c == Census::Dark) {
            return;
        }
        // Near the horizon the gas's frequency runs away as 1 /
        // sqrt(r - r_+): pieces shrink with the distance to it.
        let horizon = t.kerr.horizon();
        let near = ends
            .iter()
            .map(|e| 0.5 * (e.0 - horizon).abs())
            .fold(f64::INFINITY, f64::min);
        let scale = ends
            .iter()
            .map(|&(r, c, p)| t.medium.scale((r, c), p))
            .fold(near, f64::min);
        let pieces = pieces::count(path.length(s0, s1), scale);
        let mut gas = MediumPieces {
            ray: self,
            t,
            path,
            nu_cam,
            edge: false,
        };
        let Some(first) = census else {
            pieces::walk(&mut gas, (s0, s1), pieces);
            return;
        };
        // Where it may shine, in pieces of the medium's scale or, where
        // it is smooth at level L, each crossing 2^L times as many cells.
        let spans = lit_spans(t.medium, path, (s0, s1), first, pieces);
        for &(a, b, smooth) in &spans.at[..spans.n] {
            let length = path.length(a, b);
            let scale = smooth.map_or(scale, |(level, cells)| {
                let crossed = grmhd::CELLS_PER_PIECE * f64::from(1u32 << level);
                near.min(length * crossed / cells)
            });
            pieces::walk(&mut gas, (a, b), pieces::count(length, scale));
        }
    }

    /// Adds a piece of the ray of length `dl_inf` (cm, in the affine
    /// parameter of a unit-energy photon) whose Gauss-Legendre nodes are
    /// at `nodes`: (r, cos th) and p (M), and the photon's dr/dlambda
    /// there; taken, it gives its greatest optical depth, unless that is
    /// above [`MAX_DTAU`] and it may be cut finer (not `finest`): then it
    /// adds nothing and asks to be cut thinner, giving the depth. Along the piece the gas
    /// emits, per unit of dl_inf, j_nu(x nu) x_inf / x^3 at the camera's
    /// frequency nu (it measures x nu over its own length x_inf dl_inf)
    /// and absorbs alpha_nu(x nu) x_inf: each averaged over the nodes, the
    /// piece then solved as one of constant source function.
    #[inline]
    fn piece(
        &mut self,
        t: &Transport,
        nodes: [Node; 2],
        dl_inf: f64,
        nu_cam: &[f64],
        (finest, sharp): (bool, bool),
    ) -> Cut {
        let mut lit = false;
        // Each node's emission, summed over the frequencies.
        let mut shown = [0.0; 2];
        for (i, ((r, c, p), (k_r, k_cos))) in nodes.into_iter().enumerate() {
            let gas = t.medium.state(t.kerr, (r, c), p, (self.lz, k_r, k_cos));
            for (k, &nu) in nu_cam.iter().enumerate() {
                let sum = if i == 0 { (0.0, 0.0) } else { self.coeffs[k] };
                self.coeffs[k] = match gas {
                    Some(gas) if self.through[k] >= SPENT => {
                        let x = gas.ratio / self.camera_ratio;
                        let (j, alpha) = gas.plasma.coefficients(x * nu);
                        let w = 0.5 * gas.ratio;
                        let j = w * j / (x * x * x);
                        shown[i] += j;
                        (sum.0 + j, sum.1 + w * alpha)
                    }
                    _ => sum,
                };
            }
            lit |= gas.is_some();
        }
        if !lit {
            return Cut::Taken(0.0);
        }
        if sharp && (shown[0] - shown[1]).abs() > CONTRAST * (shown[0] + shown[1]) {
            return Cut::Thinner(2.0 * MAX_DTAU);
        }
        let worst = self
            .coeffs
            .iter()
            .fold(0.0f64, |w, &(_, alpha)| w.max(alpha * dl_inf));
        if worst > MAX_DTAU && !finest {
            return Cut::Thinner(worst);
        }
        for (k, &(j, alpha)) in self.coeffs.iter().enumerate() {
            let piece = Piece::new(alpha * dl_inf);
            self.intensity[k] += self.through[k] * piece.emission(j * dl_inf);
            self.through[k] *= piece.kept;
        }
        Cut::Taken(worst)
    }
}

/// Most halvings of a stretch in finding where its medium cannot shine.
const DARK_DEPTH: usize = 6;

/// The parts of a stretch where its medium may shine, in order, each
/// with its smoothness level and the cells it crosses where it is smooth
/// (held in place: a stretch is found its parts inside the per-ray loop).
struct Spans {
    n: usize,
    at: [(f64, f64, Option<(u8, f64)>); 1 << DARK_DEPTH],
}

/// Where along `path` from s0 to s1 (walked in `pieces` pieces, within
/// bounds found not wholly dark: `first`) the medium may shine, in
/// order, each part where it is smooth with its level and the cells it
/// crosses: the stretch halved while a half is neither wholly dark nor
/// about two pieces long (of its own length where it is smooth), the
/// dark halves dropped, neighbours alike joined.
fn lit_spans(
    medium: &Medium,
    path: &impl Path,
    (s0, s1): (f64, f64),
    first: (Bounds, Census),
    pieces: f64,
) -> Spans {
    let depth = (0.5 * pieces).log2().ceil().clamp(0.0, DARK_DEPTH as f64) as usize;
    let mut spans = Spans {
        n: 0,
        at: [(0.0, 0.0, None); 1 << DARK_DEPTH],
    };
    // Depth first, the nearer half first: the spans come in order.
    let mut stack = [(0.0, 0.0, 0); DARK_DEPTH + 1];
    let mut top = 1;
    stack[0] = (s0, s1, 0);
    while top > 0 {
        top -= 1;
        let (a, b, level) = stack[top];
        let (bounds, census) = if level == 0 {
            first
        } else {
            match path.bounds(a, b) {
                Some(bounds) => (bounds, medium.census(&bounds).unwrap_or(Census::Rough)),
                None => (first.0, Census::Rough),
            }
        };
        let smooth = match census {
            Census::Dark => continue,
            Census::Smooth(level) => medium.cells(&bounds).map(|n| (level, n)),
            Census::Rough => None,
        };
        // A smooth half of about two of its longer pieces is not halved
        // further.
        let short =
            smooth.is_some_and(|(l, n)| n <= 2.0 * grmhd::CELLS_PER_PIECE * f64::from(1u32 << l));
        if level == depth || short {
            match spans.at[..spans.n].last_mut() {
                Some(last) if last.1 == a && last.2.map(|s| s.0) == smooth.map(|s| s.0) => {
                    last.1 = b;
                    last.2 = last.2.zip(smooth).map(|(x, y)| (x.0, x.1 + y.1));
                }
                _ => {
                    spans.at[spans.n] = (a, b, smooth);
                    spans.n += 1;
                }
            }
            continue;
        }
        let mid = 0.5 * (a + b);
        stack[top] = (mid, b, level + 1);
        stack[top + 1] = (a, mid, level + 1);
        top += 2;
    }
    spans
}

/// A node of a piece: (r, cos th, the Kerr-Schild point) and the photon's
/// (dr/dlambda, d(cos th)/dlambda) there.
type Node = ((f64, f64, DVec3), (f64, f64));

/// A stretch of a ray as the pieces' loop walks it, in a parameter s of
/// its own.
pub trait Path {
    /// (r, cos th) in Boyer-Lindquist's coordinates and the Kerr-Schild
    /// point, all in M, at s.
    fn at(&self, s: f64) -> (f64, f64, DVec3);
    /// The affine length (M, of a photon of unit energy at infinity) from
    /// s0 to s1.
    fn length(&self, s0: f64, s1: f64) -> f64;
    /// The same in cm.
    fn cm(&self, s0: f64, s1: f64) -> f64;
    /// The photon's dr/dlambda and d(cos th)/dlambda (M) at s. The photon
    /// runs from the camera's far side towards it, against the trace.
    fn k_at(&self, s: f64) -> (f64, f64);
    /// Where it lies from s0 to s1, for a medium that can tell where it
    /// cannot shine ([`Medium::dark`]); None where the path cannot say.
    fn bounds(&self, _s0: f64, _s1: f64) -> Option<Bounds> {
        None
    }
}

/// An integrator's (or Schwarzschild's closed form's) segment, in r_s:
/// its affine length runs evenly with its fraction s.
struct SegmentPath<'a> {
    seg: &'a Segment,
    kerr: Kerr,
    m_per_s: f64,
    cm_per_s: f64,
}

impl Path for SegmentPath<'_> {
    #[inline]
    fn at(&self, s: f64) -> (f64, f64, DVec3) {
        let p = self.seg.point(s) * 2.0;
        let r = self.kerr.ks_radius(p);
        (r, (p.z / r).clamp(-1.0, 1.0), p)
    }

    #[inline]
    fn length(&self, s0: f64, s1: f64) -> f64 {
        (s1 - s0) * self.m_per_s
    }

    #[inline]
    fn cm(&self, s0: f64, s1: f64) -> f64 {
        (s1 - s0) * self.cm_per_s
    }

    #[inline]
    fn k_at(&self, s: f64) -> (f64, f64) {
        segment_k(self.kerr, self.seg, s)
    }
}

/// The photon's dr/dlambda (M, unit energy at infinity) at fraction `s`
/// of `seg` (r_s, as the tracers give it) about the hole `kerr`: the
/// photon runs from the camera's far side towards it, against the trace.
#[inline]
pub fn segment_k_r(kerr: Kerr, seg: &Segment, s: f64) -> f64 {
    segment_k(kerr, seg, s).0
}

/// The photon's dr/dlambda and d(cos th)/dlambda (M, unit energy at
/// infinity) at fraction `s` of `seg`, as [`segment_k_r`].
#[inline]
pub fn segment_k(kerr: Kerr, seg: &Segment, s: f64) -> (f64, f64) {
    let p = seg.point(s) * 2.0;
    let dp = seg.tangent(s) * 2.0;
    let r = if kerr.a == 0.0 {
        p.length()
    } else {
        kerr.ks_radius(p)
    };
    let grad = if kerr.a == 0.0 {
        p / r
    } else {
        kerr.ks_radius_gradient(p, r)
    };
    let per = -1.0 / (2.0 * seg.affine);
    let dr = grad.dot(dp);
    // cos th = z / r.
    (dr * per, (dp.z - p.z / r * dr) / r * per)
}

/// A physical medium along a stretch, as the pieces' loop takes it.
struct MediumPieces<'a, 'b, P> {
    ray: &'a mut RayTransfer,
    t: &'a Transport<'b>,
    path: &'a P,
    nu_cam: &'a [f64],
    /// Whether the piece being taken touches a surface inside the medium.
    edge: bool,
}

impl<P: Path> Pieces for MediumPieces<'_, '_, P> {
    fn surfaces(&self) -> &[f64] {
        self.t.medium.surfaces()
    }

    #[inline]
    fn radius(&self, s: f64) -> f64 {
        self.path.at(s).0
    }

    #[inline]
    fn levelled(&self) -> bool {
        self.t.medium.sharp()
    }

    #[inline]
    fn level(&self, s: f64) -> f64 {
        let (r, c, p) = self.path.at(s);
        self.t.medium.level((r, c), p)
    }

    fn edge(&mut self, on: bool) {
        self.edge = on;
    }

    fn take(&mut self, piece: (f64, f64), finest: bool) -> Cut {
        let path = self.path;
        let nodes = pieces::nodes(piece).map(|n| (path.at(n), path.k_at(n)));
        let dl = path.cm(piece.0, piece.1);
        // Against a surface inside the medium, pieces are cut finer where
        // their nodes disagree, down to SHARPEST of its scale.
        let sharp = !finest
            && self.edge
            && path.length(piece.0, piece.1) > {
                let (r, c, p) = nodes[0].0;
                SHARPEST * self.t.medium.scale((r, c), p)
            };
        self.ray
            .piece(self.t, nodes, dl, self.nu_cam, (finest, sharp))
    }

    #[inline]
    fn spent(&self) -> bool {
        self.ray.spent()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A shell of gas at rest far out (r ~ 1e6 M: gravity's shift there is
    /// 1e-6), met along a straight chord that crosses `length` M of it.
    fn far_shell(k0: f64, length: f64) -> (Uniform, Segment) {
        let (inner, outer) = (1e6, 1e6 + length);
        let u = Uniform::new(inner, outer, (2.0, k0), 0.0, 1e11);
        // Radially through the shell, in r_s (half of M), from outside in
        // (the way a camera's ray goes).
        let seg = Segment::chord(
            DVec3::new(0.5 * (outer + 3.0), 0.0, 0.0),
            DVec3::new(0.5 * (inner - 3.0), 0.0, 0.0),
        );
        (u, seg)
    }

    /// The transfer through `far_shell(k0, length)` at 1e11 Hz, lengths
    /// in cm being M's (so tau = k0 L).
    fn through_far_shell(k0: f64, length: f64) -> (Uniform, RayTransfer) {
        let (u, seg) = far_shell(k0, length);
        let m = Medium::Uniform(u);
        let t = Transport {
            medium: &m,
            kerr: Kerr::new(0.0),
            cm_per_m: 1.0,
        };
        let mut ray = RayTransfer::new(1.0, 0.0, 1);
        ray.march(&t, &seg, (0.0, 1.0), &[1e11]);
        (u, ray)
    }

    #[test]
    fn pieces_add_up_to_the_closed_form_at_any_cut() {
        // A uniform medium of source function S and optical depth tau, cut
        // into n equal pieces summed from the camera's end, shows S (1 -
        // e^-tau) and lets e^-tau through, whatever n; a piece that does
        // not absorb sends on all it emits, and one across the series'
        // threshold agrees with the exact form on either side.
        let s = 2.5;
        for tau in [1e-9, 1e-4, 0.3, 7.0] {
            for n in [1, 3, 1000] {
                let p = Piece::new(tau / n as f64);
                let (mut light, mut through) = (0.0, 1.0);
                for _ in 0..n {
                    light += through * p.source(s);
                    through *= p.kept;
                }
                let want = -s * (-tau).exp_m1();
                assert!(
                    ((light - want) / want).abs() < 1e-12,
                    "tau {tau} n {n}: {light} {want}"
                );
                assert!((through - (-tau).exp()).abs() < 1e-12 * (-tau).exp().max(1e-3));
            }
        }
        assert_eq!(Piece::new(0.0).emission(3.0), 3.0);
        let (below, above) = (
            Piece::new(1e-6 * (1.0 - 1e-9)),
            Piece::new(1e-6 * (1.0 + 1e-9)),
        );
        assert!((below.emission(1.0) - above.emission(1.0)).abs() < 1e-12);
    }

    #[test]
    fn a_uniform_slab_shows_its_source_function_times_one_minus_e_tau() {
        // cm_per_m = 1: lengths in cm are M's, so tau = k0 L.
        let length = 10.0;
        for (k0, tol) in [(0.0, 1e-5), (0.05, 1e-5), (0.3, 1e-5), (5.0, 1e-5)] {
            let (u, ray) = through_far_shell(k0, length);
            let tau = k0 * length;
            let want = if k0 == 0.0 {
                u.j0 * length
            } else {
                u.j0 / k0 * (1.0 - (-tau).exp())
            };
            let got = ray.intensity[0];
            assert!(
                ((got - want) / want).abs() < tol,
                "k0 {k0}: {got} against {want}"
            );
            assert!((ray.through[0] - (-tau).exp()).abs() < 1e-5 * (-tau).exp().max(1e-3));
        }
    }

    #[test]
    fn thermal_synchrotron_gas_shows_the_planck_function_times_one_minus_e_tau() {
        // Gas of one density, temperature and (nearly: B ~ sqrt(n / r)
        // changes by 5e-6 across) field, at rest far out, met along L =
        // 10 M of a radial chord: I = B_nu(T) (1 - e^-tau), tau = alpha L,
        // from optically thin (I = j L) to thick (the Planck function),
        // lengths scaled by cm_per_m.
        let outer = 1e6;
        let mut p = RiafProfile::broderick_loeb(1e6, 1e11);
        (p.density_index, p.temperature_index, p.keplerian, p.outer) = (0.0, 0.0, 0.0, outer);
        let flow = Riaf::new(p, Kerr::new(0.0));
        let m = Medium::Riaf(flow);
        let length = 10.0;
        let seg = Segment::chord(
            DVec3::new(0.5 * (outer + 3.0), 0.0, 0.0),
            DVec3::new(0.5 * (outer - length), 0.0, 0.0),
        );
        let nu = 230e9;
        let (n, t, b) = flow.plasma(outer - 0.5 * length, 0.0).unwrap();
        let (j, alpha) = synchrotron::coefficients(n, t, b, nu);
        for tau in [1e-3, 0.5, 3.0, 40.0] {
            let cm_per_m = tau / (alpha * length);
            let tr = Transport {
                medium: &m,
                kerr: Kerr::new(0.0),
                cm_per_m,
            };
            let mut ray = RayTransfer::new(1.0, 0.0, 1);
            ray.march(&tr, &seg, (0.0, 1.0), &[nu]);
            let want = j / alpha * (1.0 - (-tau).exp());
            let got = ray.intensity[0];
            assert!(
                ((got - want) / want).abs() < 2e-5,
                "tau {tau}: {got:e} against {want:e}"
            );
        }
    }

    #[test]
    fn an_optically_thick_medium_shows_its_source_function() {
        // tau = 1e3 across: only the source function comes through.
        let (u, ray) = through_far_shell(100.0, 10.0);
        let s = u.j0 / u.k0;
        assert!(
            ((ray.intensity[0] - s) / s).abs() < 1e-5,
            "{}",
            ray.intensity[0]
        );
        assert!(ray.spent());
    }
}
