//! Adaptive sampling (`image.adaptive`) on the GPU: the host drives the
//! rounds of `cpu::adaptive` with the CPU's own decisions, and the GPU
//! traces only the samples they ask for.
//!
//! The base pass is an ordinary pass whose `resolve` also writes each
//! pixel's lightness sums and class mask (FLAG_ADAPTIVE, the last vec4 of
//! its observables' words); the host adds them to each pixel's
//! `adaptive::Pixel` in f64 and decides each round's extra samples with
//! `adaptive::round_targets`. A round is dispatched as groups of rows, each
//! with a list of the pixels refined in it (its band pixel, its first
//! sample in the group, its samples, its first extra sample's index):
//! `main` traces the group's samples one per invocation (at the pixel's
//! `refine_offset` points), `resolve` sums each listed pixel's, and the
//! result is added to the film like a pass. Rows are sampled `MARGIN`
//! beyond the rows asked for, as on the CPU, so that tiles merge byte for
//! byte.
//!
//! A pixel's samples of a round are summed in pieces of at most `slots`
//! times the width, cut at the same places whatever the rows rendered, so
//! a pixel's value does not depend on how its rows are grouped.

use super::bands::{Readout, stats_of};
use super::films::Pass;
use super::layout::{OBSERVED_VEC4S, STATS, Stat};
use super::traced::{Traced, Want};
use super::{GpuError, Prepared, WORKGROUP};
use crate::adaptive::{self, MARGIN, MAX_ROUNDS, Pixel};
use crate::film::{Film, PixelProbe, Stats};
use std::ops::Range;

/// A prepared scene's adaptive sampling.
#[derive(Clone, Copy, Debug)]
pub(super) struct Adaptive {
    /// Most extra samples a pixel takes.
    pub(super) room: u32,
    /// `Scene::refine_contrast`.
    pub(super) contrast: f64,
}

/// One dispatch of a round: rows `first_row..first_row + rows` and an
/// entry per pixel refined in them, (band pixel, first sample, samples,
/// first extra sample), ordered by first sample.
struct Group {
    first_row: u32,
    rows: u32,
    entries: Vec<[u32; 4]>,
    samples: u32,
}

/// What a film pass reads back for adaptive sampling.
const WANT: Want = Want {
    film: true,
    bands: true,
    show: None,
};

impl Prepared<'_> {
    /// [`Prepared::render_rows`], also giving the samples each pixel
    /// took (row-major; more than `image.samples` where adaptive sampling
    /// refined it), as `Scene::render_rows_counted` does.
    pub fn render_rows_counted(
        &self,
        rows: Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats, Vec<u32>), GpuError> {
        match self.adaptive {
            Some(a) if !rows.is_empty() && rows.end <= self.height => {
                self.render_adaptive(a, rows, progress)
            }
            _ => {
                let n = rows.len() * self.width as usize;
                let (film, stats) = self.render_rows(rows, progress)?;
                Ok((film, stats, vec![self.samples; n]))
            }
        }
    }

    /// Renders rows `rows` with adaptive sampling: the base pass, then the
    /// rounds, over the rows and `MARGIN` rows around them.
    pub(super) fn render_adaptive(
        &self,
        a: Adaptive,
        rows: Range<u32>,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(Film, Stats, Vec<u32>), GpuError> {
        let band = rows.start.saturating_sub(MARGIN)..(rows.end + MARGIN).min(self.height);
        let w = self.width as usize;
        // The rows around are rendered apart, so that the counts are the
        // kept rows'.
        let parts: Vec<Range<u32>> = [band.start..rows.start, rows.clone(), rows.end..band.end]
            .into_iter()
            .filter(|r| !r.is_empty())
            .collect();
        let mut px = vec![vec![Pixel::default(); w]; band.len()];
        let mut kept: Option<Pass> = None;
        self.start_device_time();
        for part in &parts {
            let at = (part.start - band.start) as usize;
            let mut first = 0;
            while first < self.samples {
                let count = self.slots.min(self.samples - first);
                self.check_stop()?;
                let shown: &(dyn Fn(u64) + Sync) = if *part == rows { progress } else { &|_| {} };
                let mut t = self.pass(first, count, 1, part.clone(), shown, WANT)?;
                add_sums(&mut px[at..], &t, None);
                if *part == rows {
                    t.adaptive.clear();
                    let pass = self.to_pass(t);
                    match kept.as_mut() {
                        None => kept = Some(pass),
                        Some(k) => k.merge_rows(pass, 0),
                    }
                }
                first += count;
            }
        }
        let mut kept = kept.expect("the rows asked for");
        adaptive::set_near(&mut px);
        for round in 0..MAX_ROUNDS {
            self.check_stop()?;
            let Some(targets) = adaptive::round_targets(round, &px, a.room, a.contrast) else {
                break;
            };
            for part in &parts {
                for g in self.groups(part.clone(), band.start, &px, &targets) {
                    let t = self.refine_group(&g)?;
                    add_sums(&mut px[(g.first_row - band.start) as usize..], &t, Some(&g));
                    if *part == rows {
                        kept.merge_rows(self.to_pass(t), g.first_row - rows.start);
                    }
                }
            }
            for (row, t) in px.iter_mut().zip(&targets) {
                for (p, &t) in row.iter_mut().zip(t) {
                    p.extra = t;
                }
            }
        }
        let at = (rows.start - band.start) as usize;
        let mut counts = Vec::with_capacity(rows.len() * w);
        for row in &px[at..at + rows.len()] {
            let (n, extra) = adaptive::refined(row);
            kept.stats.refined += n;
            kept.stats.extra += extra;
            counts.extend(row.iter().map(|p| self.samples + p.extra));
        }
        Ok((kept.film, kept.stats, counts))
    }

    /// The groups of a round's samples over rows `part` (`px` and
    /// `targets` from row `first` on): runs of rows with refined pixels,
    /// each within a band's rows and sample slots, a pixel's samples in
    /// pieces of at most `slots` times the width, one piece of a pixel in
    /// a group.
    fn groups(
        &self,
        part: Range<u32>,
        first: u32,
        px: &[Vec<Pixel>],
        targets: &[Vec<u32>],
    ) -> Vec<Group> {
        let w = self.width;
        let piece = self.slots as u64 * w as u64;
        // The dispatch's rows of the list stay within 65535 workgroups.
        let capacity =
            (piece * self.rows_per_tile as u64).min(w as u64 * WORKGROUP as u64 * 65_535);
        let mut groups: Vec<Group> = Vec::new();
        let mut open = false;
        for y in part {
            let r = (y - first) as usize;
            let mut any = false;
            for (x, (p, &t)) in px[r].iter().zip(&targets[r]).enumerate() {
                let mut j = p.extra;
                let mut pieces = 0;
                while j < t {
                    let count = (t - j).min(piece as u32);
                    let full = |g: &Group| {
                        g.samples as u64 + count as u64 > capacity
                            || y - g.first_row >= self.rows_per_tile
                    };
                    if !open || pieces > 0 || groups.last().is_some_and(full) {
                        groups.push(Group {
                            first_row: y,
                            rows: 1,
                            entries: Vec::new(),
                            samples: 0,
                        });
                        open = true;
                    }
                    let g = groups.last_mut().expect("open");
                    g.rows = y - g.first_row + 1;
                    let tp = (y - g.first_row) * w + x as u32;
                    g.entries.push([tp, g.samples, count, j]);
                    g.samples += count;
                    j += count;
                    pieces += 1;
                    any = true;
                }
            }
            // A row without refinement ends the group: rows are read back.
            open &= any;
        }
        groups
    }

    /// Traces and resolves group `g`'s samples, and reads back its rows:
    /// the pixels not listed in it kept no sample.
    fn refine_group(&self, g: &Group) -> Result<Traced, GpuError> {
        let gpu = self.gpu;
        let w = self.width;
        let mut params = self.pack.params;
        params.tile_first_row = g.first_row;
        params.tile_rows = g.rows;
        params.pass_first = 0;
        params.pass_samples = 0;
        params.refine_samples = g.samples;
        params.refine_pixels = g.entries.len() as u32;
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let list =
            params.at_observed as u64 + OBSERVED_VEC4S as u64 * params.slots_per_sample as u64;
        gpu.queue
            .write_buffer(&self.film, 16 * list, bytemuck::cast_slice(&g.entries));
        let mut stats_init = [0u32; STATS];
        stats_init[Stat::GMin.slot()] = f32::MAX.to_bits();
        gpu.queue
            .write_buffer(&self.stats, 0, bytemuck::cast_slice(&stats_init));
        let mut enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("refine"),
                timestamp_writes: self.stamps(0),
            });
            pass.set_bind_group(0, &self.bind, &[]);
            // The list as rows of the image's width (see main.wgsl).
            let rows_of = |n: u32| n.div_ceil(w).div_ceil(WORKGROUP);
            pass.set_pipeline(&self.pipelines.trace);
            pass.dispatch_workgroups(w.div_ceil(WORKGROUP), rows_of(g.samples), 1);
            pass.set_pipeline(&self.pipelines.resolve);
            pass.dispatch_workgroups(w.div_ceil(WORKGROUP), rows_of(g.entries.len() as u32), 1);
        }
        self.resolve_stamps(&mut enc, 0);
        let npx = g.rows as u64 * w as u64;
        let mut out = Readout::new(self, WANT, npx as usize);
        out.copy(self, &mut enc, npx);
        gpu.queue.submit([enc.finish()]);
        out.read(self, npx)?;
        let enc = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        let s = self.read_stats(enc, WANT, &stats_init)?;
        if self.timer.is_some() {
            let t = self.read_times(1)?;
            self.add_device_time(t);
        }
        let mut t = out.traced(w, g.rows, stats_of(&s, g.samples as u64));
        // The rows' other pixels hold what an earlier dispatch left.
        let mut listed = vec![false; npx as usize];
        for e in &g.entries {
            listed[e[0] as usize] = true;
        }
        for (i, _) in listed.iter().enumerate().filter(|(_, l)| !**l) {
            t.kept[i] = 0.0;
            if let Some(o) = t.observed.get_mut(i) {
                *o = PixelProbe::default();
            }
            t.adaptive[i] = [0; 4];
        }
        Ok(t)
    }
}

/// Adds the adaptive sums of a pass `t` over rows of `px` from its first
/// on (where `g` is given, only its listed pixels).
fn add_sums(px: &mut [Vec<Pixel>], t: &Traced, g: Option<&Group>) {
    let w = t.width as usize;
    let add = |px: &mut [Vec<Pixel>], i: usize| {
        let [v_sum, v_sq, lo, hi] = t.adaptive[i];
        px[i / w][i % w].add_sums(
            f32::from_bits(v_sum) as f64,
            f32::from_bits(v_sq) as f64,
            t.kept[i] as u32,
            (hi as u64) << 32 | lo as u64,
        );
    };
    match g {
        Some(g) => g.entries.iter().for_each(|e| add(px, e[0] as usize)),
        None => (0..t.adaptive.len()).for_each(|i| add(px, i)),
    }
}
