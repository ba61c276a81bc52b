//! The visible band's gas along a ray: the volumetric disk's glow and the
//! clouds' absorption and glow, through the transfer's exact pieces
//! ([`crate::transfer::Piece`]), the solver of the physical media. Each
//! medium is sampled every `step` of its own (the scale its density
//! changes over); a sample thicker than [`MAX_DTAU`] at some wavelength
//! is taken again in as many thinner pieces as that needs, each at its
//! own midpoint, as the physical transfer does.

use super::{Probing, Shade, Shifts};
use crate::cpu::Integrator;
use crate::physics::Segment;
use crate::transfer::{MAX_DTAU, Piece};
use crate::volume::samples;

/// Most pieces one sample is cut into.
const MAX_SPLIT: f64 = 64.0;

/// Below this transmittance the gas hides all behind it.
const SPENT: f32 = 1e-4;

/// Which medium a sample belongs to.
#[derive(Clone, Copy)]
enum Gas {
    Volume,
    Cloud(usize),
}

impl Integrator<'_> {
    /// Integrates the gas along `seg` from fraction `s_start` to `s_end`:
    /// the volumetric disk's emission and the clouds' glow, each piece's
    /// light seen through the transmittance so far, which it then reduces.
    /// Returns whether the ray is spent (transmittance below 1e-4).
    pub(super) fn march<S: Shade>(
        &self,
        seg: &Segment,
        (s_start, s_end): (f64, f64),
        shade: &mut S,
        through: &mut f32,
        shifts: &Shifts,
        (glowed, probing): (&mut bool, &mut Probing),
    ) -> bool {
        if s_start >= s_end {
            return false;
        }
        // Samples of every medium the segment crosses, in order along it:
        // (midpoint, width, length, medium).
        let mut todo: Vec<(f64, f64, f64, Gas)> = Vec::new();
        let clip = |(lo, hi): (f64, f64)| {
            let (lo, hi) = (lo.max(s_start), hi.min(s_end));
            (lo < hi).then_some((lo, hi))
        };
        if let Some(v) = &self.volume
            && let Some((lo, hi)) = v.interval(seg).and_then(clip)
        {
            todo.extend(samples(seg, lo, hi, v.step).map(|(s, ds, dl)| (s, ds, dl, Gas::Volume)));
        }
        for (i, c) in self.clouds.iter().enumerate() {
            if let Some((lo, hi)) = c.interval(seg).and_then(clip) {
                todo.extend(
                    samples(seg, lo, hi, c.step).map(|(s, ds, dl)| (s, ds, dl, Gas::Cloud(i))),
                );
            }
        }
        if todo.is_empty() {
            return false;
        }
        todo.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut gas = GasState {
            shade,
            through,
            shifts,
            glowed,
            probing,
        };
        for (s, ds, dl, medium) in todo {
            let spent = match self.gas_piece(&mut gas, seg, medium, (s, dl), false) {
                Offered::Taken { spent } => spent,
                // Too thick: taken again in pieces of MAX_DTAU at most.
                Offered::Thinner(depth) => {
                    let n = (depth / MAX_DTAU).ceil().min(MAX_SPLIT);
                    let (piece_ds, piece_dl) = (ds / n, dl / n);
                    let first = s - 0.5 * ds + 0.5 * piece_ds;
                    (0..n as usize).any(|k| {
                        let at = (first + k as f64 * piece_ds, piece_dl);
                        self.gas_piece(&mut gas, seg, medium, at, true)
                            == Offered::Taken { spent: true }
                    })
                }
            };
            if spent {
                return true;
            }
        }
        false
    }

    /// One piece of `medium` about fraction `s` of `seg`, `dl` long: its
    /// light and absorption, then whether the ray is spent; unless it is
    /// thicker than [`MAX_DTAU`] at some wavelength and may be cut (not
    /// `finest`): then it adds nothing and asks to be cut thinner.
    fn gas_piece<S: Shade>(
        &self,
        gas: &mut GasState<'_, S>,
        seg: &Segment,
        medium: Gas,
        (s, dl): (f64, f64),
        finest: bool,
    ) -> Offered {
        let p = seg.point(s);
        let shifts = gas.shifts;
        match medium {
            Gas::Volume => {
                let v = self.volume.as_ref().expect("volume samples need a volume");
                let tau = shifts.emitted_at(seg, s);
                let rho = v.density.sample(self.rotation.unturn(p, tau)) as f64;
                if rho <= 0.0 {
                    return Offered::Taken { spent: false };
                }
                // Grey: one depth at every wavelength.
                let piece = Piece::new(v.kappa * rho * dl);
                if piece.dtau > MAX_DTAU && !finest {
                    return Offered::Thinner(piece.dtau);
                }
                *gas.glowed = true;
                let axis = (p.x * p.x + p.y * p.y).sqrt();
                // The source function: the blackbody of its radius, its
                // luminance `emission` times the peak temperature's.
                let (kelvin, lum) = v.source(axis);
                let ln_g = shifts.disk(seg, s, p);
                let probing = &mut *gas.probing;
                probing.light(ln_g, axis, probing.order_at(s), shifts.travel_time(seg, s));
                let light = piece.source(*gas.through as f64 * (v.emission * lum) as f64);
                gas.shade
                    .volume(self, kelvin, light as f32, shifts.light(ln_g));
                *gas.through *= piece.kept as f32;
                Offered::Taken {
                    spent: *gas.through < SPENT,
                }
            }
            Gas::Cloud(i) => {
                let c = &self.clouds[i];
                let rho = c.density(p);
                if rho <= 0.0 {
                    return Offered::Taken { spent: false };
                }
                let ln_g = shifts.light(shifts.fixed(seg, s, p));
                let kappa_dl = c.kappa0 * rho * dl;
                // Thickest at the bluest wavelength the gas sees (beta >=
                // 0), 380 nm at the camera.
                let depth = kappa_dl * c.extinction(380.0 * ln_g.exp());
                if depth > MAX_DTAU && !finest {
                    return Offered::Thinner(depth);
                }
                gas.shade.cloud(self, c, kappa_dl, *gas.through, ln_g);
                Offered::Taken { spent: false }
            }
        }
    }
}

/// What became of a gas sample offered to [`Integrator::gas_piece`]: taken
/// (and whether the ray is spent after it), or too thick to be taken whole
/// (its greatest optical depth given) and to be cut thinner.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Offered {
    Taken { spent: bool },
    Thinner(f64),
}

/// What the pieces of one march share.
struct GasState<'a, S> {
    shade: &'a mut S,
    through: &'a mut f32,
    shifts: &'a Shifts,
    glowed: &'a mut bool,
    probing: &'a mut Probing,
}
