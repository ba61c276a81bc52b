//! The visible band's gas along a ray: the volumetric disk's glow and the
//! clouds' absorption and glow, walked by the pieces' loop of the
//! physical media ([`crate::transfer::pieces`]) and solved by its exact
//! pieces ([`crate::transfer::Piece`]). The segment is cut where a medium
//! begins or ends; each stretch between is walked in pieces of the
//! finest scale among the media there (two of the volume's or a cloud's
//! `step`, a node each step), each taking every medium there at its two
//! nodes: the volume first, then the clouds in order.

use super::{Probing, Shade, Shifts};
use crate::cpu::Integrator;
use crate::physics::Segment;
use crate::transfer::pieces::{self, Cut, Pieces};
use crate::transfer::{MAX_DTAU, Piece, SPENT};

/// Most media one stretch holds: the volume and the clouds (the scene
/// refuses more than 15).
const MEDIA: usize = 16;

impl Integrator<'_> {
    /// Integrates the gas along `seg` from fraction `s_start` to `s_end`:
    /// the volumetric disk's emission and the clouds' glow, each piece's
    /// light seen through the transmittance so far, which it then reduces.
    /// Returns whether the ray is spent (transmittance below
    /// [`SPENT`]).
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
        // Where each medium the segment crosses begins and ends on it:
        // medium 0 the volume, 1 + i cloud i.
        let clip = |(lo, hi): (f64, f64)| {
            let (lo, hi) = (lo.max(s_start), hi.min(s_end));
            (lo < hi).then_some((lo, hi))
        };
        let mut spans: Vec<(usize, (f64, f64))> = Vec::new();
        if let Some(v) = &self.volume
            && let Some(span) = v.interval(seg).and_then(clip)
        {
            spans.push((0, span));
        }
        for (i, c) in self.clouds.iter().enumerate().take(MEDIA - 1) {
            if let Some(span) = c.interval(seg).and_then(clip) {
                spans.push((1 + i, span));
            }
        }
        if spans.is_empty() {
            return false;
        }
        let mut cuts: Vec<f64> = spans.iter().flat_map(|(_, (lo, hi))| [*lo, *hi]).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let chord = (seg.x1 - seg.x0).length();
        let mut gas = VisibleGas {
            it: self,
            seg,
            chord,
            media: [false; MEDIA],
            shade,
            through,
            shifts,
            glowed,
            probing,
        };
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let mid = 0.5 * (a + b);
            let mut scale = f64::INFINITY;
            for (m, (lo, hi)) in &spans {
                let here = *lo <= mid && mid <= *hi;
                gas.media[*m] = here;
                if here {
                    scale = scale.min(match m {
                        0 => self.volume.as_ref().map_or(f64::INFINITY, |v| v.scale()),
                        i => self.clouds[i - 1].scale(),
                    });
                }
            }
            if scale.is_finite() {
                pieces::walk(&mut gas, (a, b), pieces::count(chord * (b - a), scale));
                if gas.spent() {
                    return true;
                }
            }
        }
        false
    }
}

/// The visible gas of one segment as the pieces' loop takes it: the
/// media present on the stretch walked, what the pieces share.
struct VisibleGas<'a, 'b, S> {
    it: &'a Integrator<'b>,
    seg: &'a Segment,
    /// The segment's chord (r_s): the visible media's lengths.
    chord: f64,
    /// Which media the stretch holds: 0 the volume, 1 + i cloud i.
    media: [bool; MEDIA],
    shade: &'a mut S,
    through: &'a mut f32,
    shifts: &'a Shifts,
    glowed: &'a mut bool,
    probing: &'a mut Probing,
}

impl<S: Shade> Pieces for VisibleGas<'_, '_, S> {
    /// The volume's grey piece (its emission at each node, a blackbody of
    /// its radius shifted as its gas moves: [`Shifts::moving`]), then each
    /// cloud's (its density averaged over the nodes); the piece asks to be
    /// cut thinner where any of them is thicker than [`MAX_DTAU`] at some
    /// wavelength.
    fn take(&mut self, (s, e): (f64, f64), finest: bool) -> Cut {
        let (it, seg, shifts) = (self.it, self.seg, self.shifts);
        let dl = self.chord * (e - s);
        let at = pieces::nodes((s, e)).map(|n| (n, seg.point(n)));
        let mut worst = 0.0f64;
        // The volume's density at each node.
        let mut rho = [0.0f64; 2];
        if self.media[0]
            && let Some(v) = &it.volume
        {
            for (k, &(n, p)) in at.iter().enumerate() {
                rho[k] = v
                    .density
                    .sample(it.rotation.unturn(p, shifts.emitted_at(seg, n)))
                    as f64;
            }
            worst = v.kappa * 0.5 * (rho[0] + rho[1]) * dl;
        }
        let volume_dtau = worst;
        // Each cloud's optical depth at 550 nm and ln g (a static
        // emitter's, the same for every cloud) at the piece's middle.
        let mut clouds = [(0.0f64, 0.0f64); MEDIA];
        let mut static_ln_g = None;
        for (i, c) in it.clouds.iter().enumerate().take(MEDIA - 1) {
            if !self.media[1 + i] {
                continue;
            }
            let kappa_dl = c.kappa0 * 0.5 * (c.density(at[0].1) + c.density(at[1].1)) * dl;
            if kappa_dl <= 0.0 {
                continue;
            }
            let ln_g = *static_ln_g.get_or_insert_with(|| {
                let mid = 0.5 * (s + e);
                shifts.light(shifts.fixed(seg, mid, seg.point(mid)))
            });
            // Thickest at the bluest wavelength the gas sees (beta >= 0),
            // 380 nm at the camera.
            worst = worst.max(kappa_dl * c.extinction(380.0 * ln_g.exp()));
            clouds[1 + i] = (kappa_dl, ln_g);
        }
        if worst > MAX_DTAU && !finest {
            return Cut::Thinner(worst);
        }
        if let Some(v) = it.volume.as_ref().filter(|_| volume_dtau > 0.0) {
            let piece = Piece::new(volume_dtau);
            *self.glowed = true;
            for (&(n, p), &rho) in at.iter().zip(&rho) {
                if rho <= 0.0 {
                    continue;
                }
                let axis = (p.x * p.x + p.y * p.y).sqrt();
                // The source function: the blackbody of its radius, its
                // luminance `emission` times the peak temperature's; each
                // node emits half the piece's j dl.
                let (kelvin, lum) = v.source(axis);
                // Gas where its motion is not timelike (inside the
                // horizon) shows nothing.
                let Some(ln_g) = shifts.moving(seg, n, p, &v.motion) else {
                    continue;
                };
                let probing = &mut *self.probing;
                probing.light(ln_g, axis, probing.order_at(n), shifts.travel_time(seg, n));
                let j_dl = 0.5 * v.kappa * rho * dl * (v.emission * lum) as f64;
                let light = piece.emission(*self.through as f64 * j_dl);
                self.shade
                    .volume(it, kelvin, light as f32, shifts.light(ln_g));
            }
            *self.through *= piece.kept as f32;
        }
        for (i, c) in it.clouds.iter().enumerate().take(MEDIA - 1) {
            let (kappa_dl, ln_g) = clouds[1 + i];
            if kappa_dl > 0.0 {
                self.shade.cloud(it, c, kappa_dl, *self.through, ln_g);
            }
        }
        Cut::Taken(worst)
    }

    fn spent(&self) -> bool {
        (*self.through as f64) < SPENT
    }
}
