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

use super::Scene;
use super::pixels::{Layout, Row, Sample};
use crate::adaptive::{CONTRAST, MAX_ROUNDS, refined, round_targets, set_near};
use crate::config::Filter;
use crate::objects::Finish;
use crate::sampling::refine_offset;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

impl Scene {
    /// The lightness difference between neighbouring pixels that makes
    /// both refine: [`CONTRAST`], or none (infinite) where every light the
    /// scene holds is read over the samples' footprints (the sky's
    /// panorama or point stars, the disk's texture, objects that glow with
    /// their textures) or is uniform. There a pixel's samples differ only
    /// across an edge between classes, which the classes find; a mirror,
    /// a lit surface (its highlights and shadows), gas, clouds or any
    /// texture read at the point keep the contrast test.
    pub fn refine_contrast(&self) -> f64 {
        let footprint = |f: Filter| f == Filter::Footprint;
        let sky = self.sky.filter().is_none_or(footprint);
        let disk = self.disk.as_ref().is_none_or(|d| footprint(d.filter));
        let objects = self.objects.iter().all(|o| {
            let m = &o.material;
            m.finish == Finish::Color && (m.texture.is_none() || footprint(m.filter))
        });
        let gas = self.volume.is_some() || !self.clouds.is_empty();
        if sky && disk && objects && !gas {
            f64::INFINITY
        } else {
            CONTRAST
        }
    }

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
