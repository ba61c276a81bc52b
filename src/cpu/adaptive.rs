//! Adaptive sampling (`image.adaptive`): after the base pass of
//! `image.samples` rays a pixel, rounds of extra samples where a pixel
//! holds an edge, until its mean converges or it reaches
//! `image.max_samples`.
//!
//! - **Where**: after the base pass, a pixel is refined if its samples
//!   ended in more than one class, or its class set differs from one of
//!   its 8 neighbours', or its mean lightness differs from a neighbour's
//!   by more than [`CONTRAST`] (in a scene whose light is all read over
//!   footprints, [`Scene::refine_contrast`], classes alone: a filtered
//!   texture's or a point star's pixel is its converged value already,
//!   and more samples would only pay for what the footprint gave). The
//!   classes tell apart sky, hole, out of
//!   steps, non-finite, each image order of the disk and each object, so
//!   a shadow's edge, the disk's edges, a change of image order and a
//!   silhouette are found whatever their colours; both sides of a class
//!   change are refined, the test being symmetric.
//! - **Thin features**: a class that a refined pixel finds which no base
//!   sample of its 3x3 neighbourhood had (a ring thinner than the pixel
//!   spacing, a tip between the base samples) makes every neighbour that
//!   has not seen it refine too, round after round: the refinement follows
//!   the feature along.
//! - **How much**: a refined pixel's extra samples go 4, 8, 16, ... (each
//!   round doubles them) up to the cap. They are points of the pixel's own
//!   scrambled (0, 2)-sequence ([`crate::sampling::refine_offset`]), so
//!   every count of 4^k is a stratified grid. A pixel stops when the
//!   standard error of its mean lightness, s / sqrt(n) over all its
//!   samples, is at most [`TOLERANCE`](crate::adaptive::TOLERANCE); this treats the samples as
//!   independent, which overstates the error of stratified ones, so a
//!   pixel across a strong edge runs to the cap and only pixels whose
//!   samples agree stop early. Samples that agree by chance, missing an
//!   edge that clips the pixel, are guarded against: while a neighbour
//!   holds a class that none of the pixel's samples has, it takes at
//!   least [`UNSEEN`](crate::adaptive::UNSEEN) extra samples.
//! - **Tiles and threads**: a pixel's samples are seeded by its place in
//!   the image and its sample index, and every decision reads only its
//!   own and its neighbours' state, so after k rounds a pixel depends on
//!   the base samples within k + 1 rows of it. A band of rows is rendered
//!   with [`MARGIN`](crate::adaptive::MARGIN) rows more above and below (sampled, refined, not
//!   kept), which makes each row exactly what a whole render gives it.

use super::pixels::{Layout, Row, Sample};
use crate::adaptive::{MAX_ROUNDS, refined, round_targets, set_near};
use crate::cpu::Integrator;
use crate::sampling::refine_offset;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

impl Integrator<'_> {
    /// Refines the rows `rows` (the base pass done) in rounds; gives up
    /// between pixels once `stop` is set.
    pub(super) fn refine(
        &self,
        rows: &mut [Row],
        layout: &Layout,
        direct: bool,
        stop: &AtomicBool,
    ) {
        let w = layout.width;
        let room = self.max_samples.saturating_sub(self.samples);
        set_near(rows);
        for round in 0..MAX_ROUNDS {
            if stop.load(Ordering::Relaxed) {
                return;
            }
            let Some(targets) = round_targets(round, rows, room, self.refine_contrast()) else {
                break;
            };
            rows.par_iter_mut().zip(targets).for_each(|(row, targets)| {
                let mut spec = vec![0.0f32; layout.n_wl];
                for (x, &target) in targets.iter().enumerate() {
                    if stop.load(Ordering::Relaxed) {
                        return;
                    }
                    let pixel = (row.y * w + x) as u64;
                    while row.px[x].extra < target {
                        let (ox, oy) = refine_offset(self.seed, pixel, row.px[x].extra);
                        let (px, py) = (x as f64 + ox, row.y as f64 + oy);
                        let s: Sample = self.camera_sample(px, py, direct, &mut spec);
                        row.add(layout, x, &s, &spec);
                        row.px[x].extra += 1;
                    }
                }
            });
        }
        // The counts of the kept rows' refinement.
        for row in rows.iter_mut().filter(|r| r.kept()) {
            let (n, extra) = refined(&row.px);
            row.stats.refined += n;
            row.stats.extra += extra;
        }
    }
}
