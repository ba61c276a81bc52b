//! The exact model's integrator at each `physics.tolerance` against the
//! closed forms (Schwarzschild's, and Gralla and Lupsasca's with spin),
//! and what each tolerance costs. The table in validation/REFERENCE.md
//! (section 9) is `tolerance_table`'s output:
//!
//!   cargo test --release --test tolerance -- --ignored --nocapture
//!
//! The test that always runs holds the default tolerance to that table.

mod common;

use blackhole::config::PhysicsConfig;
use blackhole::physics::kerr::{Kerr, Spheroidal};
use blackhole::physics::spacetime::{Closed, ClosedStart};
use blackhole::physics::{End, Flow, Limits, Spacetime};
use glam::{DMat2, DVec2, DVec3};

/// Disk radii (r_s) whose crossings are compared: out to the shipped disks'
/// 10 r_s, in to 1.1 horizon radii (the integrator stops within 1e-3 of
/// the horizon).
fn disk(st: Spacetime) -> (f64, f64) {
    (1.1 * st.horizon(), 10.0)
}

/// The image orders compared: the direct image and the first ring.
const ORDERS: u32 = 2;

/// A crossing of the plane z = 0: its image order, point (r_s) and the
/// light's travel time from it to the camera (r_s / c).
#[derive(Clone, Copy, Debug)]
struct Crossing {
    order: u32,
    point: DVec3,
    time: f64,
}

/// A camera ray in closed form: how it ends, and its crossings of orders
/// below [`ORDERS`] within [`disk`], each with the inverse of the map from
/// image angles to the crossing's (x, y) (rad per r_s), where all four
/// neighbouring rays cross there at the same order.
struct Reference {
    captured: bool,
    escape: DVec3,
    /// The map from image angles to the escape direction, where the four
    /// neighbouring rays escape: its columns and the inverse of their
    /// Gram matrix (a least-squares inverse).
    sky: Option<([DVec3; 2], DMat2)>,
    crossings: Vec<(Crossing, Option<DMat2>)>,
}

impl Reference {
    /// The image shift (rad) that moves the escape direction by `d`.
    fn sky_shift(&self, d: DVec3) -> Option<f64> {
        let ([c1, c2], inverse) = self.sky?;
        Some((inverse * DVec2::new(c1.dot(d), c2.dot(d))).length())
    }
}

/// The rays a camera at Boyer-Lindquist radius `r` (M) sends, as offsets
/// (tangents) from the direction to the hole: an `n` x `n` grid within
/// `half` of it, and `ring[0]` x `ring[1]` rays round it in polar order at
/// impact parameters b = 2 to 9 M (angles about b / r), across the
/// shadow's edge where the rings of order 1 lie for every spin.
fn offsets(r: f64, half: f64, n: usize, ring: [usize; 2]) -> Vec<(f64, f64)> {
    // Off the grid's symmetric lines.
    let grid = (0..n * n).map(|k| {
        let at = |i: usize, o: f64| half * (2.0 * (i as f64 + o) / n as f64 - 1.0);
        (at(k / n, 0.37), at(k % n, 0.61))
    });
    let polar = (0..ring[0] * ring[1]).map(|k| {
        let chi = (((k % ring[0]) as f64 + 0.3) / ring[0] as f64) * std::f64::consts::TAU;
        let b = 2.0 + 7.0 * ((k / ring[0]) as f64 + 0.5) / ring[1] as f64;
        let rho = b / r;
        (rho * chi.cos(), rho * chi.sin())
    });
    grid.chain(polar).collect()
}

/// The camera at Boyer-Lindquist radius `r` (M) and inclination `incl`
/// (degrees) around a hole of spin `a`: its point (r_s), and for each
/// offset ([`offsets`]) the ray's unit direction in its frame with two
/// unit directions across it.
fn camera_rays(a: f64, r: f64, incl: f64, offsets: &[(f64, f64)]) -> (DVec3, Vec<[DVec3; 3]>) {
    let x = 0.5
        * Kerr::new(a).cartesian(Spheroidal {
            r,
            th: incl.to_radians(),
            phi: 0.0,
        });
    let inward = -x.normalize();
    let up = (DVec3::Z - inward * inward.z).normalize();
    let side = inward.cross(up);
    let rays = offsets
        .iter()
        .map(|&(u, w)| {
            let look = (inward + side * u + up * w).normalize();
            let e1 = (side - look * look.dot(side)).normalize();
            [look, e1, look.cross(e1)]
        })
        .collect();
    (x, rays)
}

/// The crossings of orders below [`ORDERS`] within [`disk`] of the ray
/// along `look` (the camera's frame) in closed form, or None where the
/// closed form leaves the ray to the integrator.
fn closed_crossings(
    st: Spacetime,
    start: &ClosedStart,
    x: DVec3,
    look: DVec3,
    timed: bool,
) -> Option<(Closed, Vec<Crossing>)> {
    let ray = st.closed_ray(start, st.camera_direction(x, look), timed)?;
    let mut found = Vec::new();
    ray.crossings(disk(st), |order, point, _plane, time, _| {
        if order < ORDERS {
            found.push(Crossing { order, point, time });
        }
        Flow::Continue
    });
    Some((ray, found))
}

/// The closed form's ray along `look` from `x`; `ray` holds the look
/// direction and two directions across it. Schwarzschild's closed form
/// keeps no time: its times come from Kerr's at a = 0 (the same ray, the
/// same coordinate time), whose radii must then agree.
fn reference(st: Spacetime, x: DVec3, ray: &[DVec3; 3]) -> Option<Reference> {
    let start = st.closed_start(x);
    let timed = st.closed_form_keeps_time();
    let (closed, mut crossings) = closed_crossings(st, &start, x, ray[0], timed)?;
    if !timed {
        let kerr = Spacetime::Kerr { a: 0.0 };
        let (_, times) = closed_crossings(kerr, &kerr.closed_start(x), x, ray[0], true)?;
        if times.len() != crossings.len() {
            return None;
        }
        for (c, t) in crossings.iter_mut().zip(times) {
            let (r, rt) = (c.point.length(), t.point.length());
            assert!(
                c.order == t.order && (r - rt).abs() < 1e-8 * r,
                "the Schwarzschild and a = 0 closed forms differ: {c:?} vs {t:?}"
            );
            c.time = t.time;
        }
    }
    // The image's map to the plane, by central differences over 1e-6 rad.
    let h = 1e-6;
    let near = |d: DVec3, order: u32| -> Option<DVec2> {
        let (_, cs) = closed_crossings(st, &start, x, (ray[0] + d * h).normalize(), false)?;
        let c = cs.iter().find(|c| c.order == order)?;
        Some(c.point.truncate())
    };
    let escape = |d: DVec3| -> Option<DVec3> {
        let ray = st.closed_ray(
            &start,
            st.camera_direction(x, (ray[0] + d * h).normalize()),
            false,
        )?;
        (!ray.captured()).then(|| ray.escape_direction())
    };
    let column = |e: DVec3| Some((escape(e)? - escape(-e)?) / (2.0 * h));
    let sky = column(ray[1]).zip(column(ray[2])).map(|(c1, c2)| {
        let gram = DMat2::from_cols(
            DVec2::new(c1.dot(c1), c1.dot(c2)),
            DVec2::new(c1.dot(c2), c2.dot(c2)),
        );
        ([c1, c2], gram.inverse())
    });
    let crossings = crossings
        .into_iter()
        .map(|c| {
            let column = |e: DVec3| Some((near(e, c.order)? - near(-e, c.order)?) / (2.0 * h));
            let map = column(ray[1]).zip(column(ray[2]));
            let inverse = map.map(|(c1, c2)| DMat2::from_cols(c1, c2).inverse());
            (c, inverse.filter(|m| m.is_finite()))
        })
        .collect();
    Some(Reference {
        captured: closed.captured(),
        escape: closed.escape_direction(),
        sky: sky.filter(|(_, m)| m.is_finite()),
        crossings,
    })
}

/// The integrator's ray from `x` along `look` at `tolerance`: how it
/// ended, its crossings of orders below [`ORDERS`] within [`disk`] (times
/// with `TIME`), and its steps. Scenes hand over to the exact tail beyond
/// their outermost material, here the disk's edge, and trace rays on to
/// the horizon when the disk reaches it.
fn traced<const TIME: bool>(
    st: Spacetime,
    x: DVec3,
    look: DVec3,
    tolerance: f64,
) -> (End, Vec<Crossing>, u32) {
    let (lo, hi) = disk(st);
    let limits = Limits {
        outer: hi,
        inner: 0.0,
        max_steps: 1_000_000,
    };
    let mut order = 0;
    let mut found = Vec::new();
    let t = st.trace::<TIME>(x, st.camera_direction(x, look), tolerance, &limits, |seg| {
        if let Some(s) = seg.crossing_z0() {
            let point = seg.point(s);
            let r = st.radius(point);
            if order < ORDERS && r >= lo && r <= hi {
                let time = if TIME { seg.time_at(s) } else { f64::NAN };
                found.push(Crossing { order, point, time });
            }
            order += 1;
        }
        Flow::Continue
    });
    (t.end, found, t.steps)
}

/// Errors of one set of rays at one tolerance (M and rad; the medians and
/// maxima are what the table prints).
#[derive(Default)]
struct Errors {
    /// Crossing radius, per image order (M).
    radius: [Vec<f64>; ORDERS as usize],
    /// The crossing point's error as a shift of the image (rad): where the
    /// pixel's colour really comes from.
    shift: [Vec<f64>; ORDERS as usize],
    /// The light's travel time from each crossing, timed traces (M).
    time: Vec<f64>,
    /// Escape direction (the chord, rad).
    direction: Vec<f64>,
    /// The escape direction's error as a shift of the image (rad): near
    /// the shadow's edge the sky's image is magnified without bound, and
    /// with it the direction's error, but not this.
    sky_shift: Vec<f64>,
    /// Rays the integrator ended otherwise than the closed form (captured
    /// against escaped, or with other crossings).
    disagree: usize,
    rays: usize,
}

impl Errors {
    /// Compares the integrator's ray at `tolerance` with the closed
    /// form's.
    fn add(&mut self, st: Spacetime, x: DVec3, ray: &[DVec3; 3], want: &Reference, tolerance: f64) {
        let (end, found, _) = traced::<false>(st, x, ray[0], tolerance);
        let (_, timed, _) = traced::<true>(st, x, ray[0], tolerance);
        self.rays += 1;
        let same_end = match end {
            End::Escaped(d) if !want.captured => {
                self.direction.push((d - want.escape).length());
                self.sky_shift.extend(want.sky_shift(d - want.escape));
                true
            }
            End::Captured => want.captured,
            _ => false,
        };
        let orders = |c: &[Crossing]| c.iter().map(|c| c.order).collect::<Vec<_>>();
        let want_orders: Vec<u32> = want.crossings.iter().map(|(c, _)| c.order).collect();
        if !same_end || orders(&found) != want_orders || orders(&timed) != want_orders {
            self.disagree += 1;
            return;
        }
        for (((c, inverse), f), t) in want.crossings.iter().zip(&found).zip(&timed) {
            let n = c.order as usize;
            let (rc, rf) = (st.radius(c.point), st.radius(f.point));
            // r_s to M.
            self.radius[n].push(2.0 * (rf - rc).abs());
            if let Some(m) = inverse {
                self.shift[n].push((*m * (f.point - c.point).truncate()).length());
            }
            self.time.push(2.0 * (t.time - c.time).abs());
        }
    }
}

/// The CPU time this process has used (s): unlike the wall clock, it
/// holds still while other work shares the cores.
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    t.tv_sec as f64 + 1e-9 * t.tv_nsec as f64
}

/// The least CPU time (s) of three runs of `f`, and its last result.
fn best_of_three<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..3 {
        let start = cpu_seconds();
        last = Some(f());
        best = best.min(cpu_seconds() - start);
    }
    (best, last.unwrap())
}

/// Tracing every ray of `set` at `tolerance`, untimed and timed: steps
/// and CPU time per ray (us).
fn ray_cost(st: Spacetime, set: &[(DVec3, [DVec3; 3], Reference)], tolerance: f64) -> [f64; 4] {
    let n = set.len() as f64;
    let all = |timed: bool| {
        set.iter()
            .map(|(x, ray, _)| {
                let (_, _, steps) = if timed {
                    traced::<true>(st, *x, ray[0], tolerance)
                } else {
                    traced::<false>(st, *x, ray[0], tolerance)
                };
                steps as f64
            })
            .sum::<f64>()
    };
    let (s, steps) = best_of_three(|| all(false));
    let (ts, timed_steps) = best_of_three(|| all(true));
    [steps / n, 1e6 * s / n, timed_steps / n, 1e6 * ts / n]
}

/// The median and the largest of `v`.
fn median_max(v: &[f64]) -> (f64, f64) {
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[v.len() - 1])
}

/// The rays the table measures for spacetime `st`: cameras at 40 M (the
/// shipped scenes' 20 r_s) and at 1000 M, at inclinations 30, 60 and 85
/// degrees, each with an `n` x `n` grid across the disk (out to 22 M)
/// and `ring` round the shadow ([`offsets`]), with their closed forms
/// (rays the closed form leaves to the integrator are left out).
fn ray_set(st: Spacetime, n: usize, ring: [usize; 2]) -> Vec<(DVec3, [DVec3; 3], Reference)> {
    let a = match st {
        Spacetime::Kerr { a } => a,
        Spacetime::Schwarzschild => 0.0,
    };
    let mut set = Vec::new();
    for (r, half) in [(40.0, 0.55), (1000.0, 0.022)] {
        for incl in [30.0, 60.0, 85.0] {
            let (x, rays) = camera_rays(a, r, incl, &offsets(r, half, n, ring));
            for ray in rays {
                if let Some(want) = reference(st, x, &ray) {
                    set.push((x, ray, want));
                }
            }
        }
    }
    set
}

/// Every ray of `set` at `tolerance`.
fn measure(st: Spacetime, set: &[(DVec3, [DVec3; 3], Reference)], tolerance: f64) -> Errors {
    let mut errors = Errors::default();
    for (x, ray, want) in set {
        errors.add(st, *x, ray, want, tolerance);
    }
    errors
}

/// The tolerances the table lists.
const TOLERANCES: [f64; 8] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-12];

/// The spacetimes measured: Schwarzschild and a = 0.9.
const SPACETIMES: [Spacetime; 2] = [Spacetime::Schwarzschild, Spacetime::Kerr { a: 0.9 }];

/// One row of the accuracy table, in markdown: median / max of each error.
fn row(tolerance: f64, e: &Errors) -> String {
    let mm = |v: &[f64]| {
        let (med, max) = median_max(v);
        format!("{med:.1e} / {max:.1e}")
    };
    format!(
        "| {tolerance:.0e} | {} | {} | {} | {} | {} | {} | {} | {} |",
        mm(&e.radius[0]),
        mm(&e.radius[1]),
        mm(&e.shift[0]),
        mm(&e.shift[1]),
        mm(&e.direction),
        mm(&e.sky_shift),
        mm(&e.time),
        e.disagree,
    )
}

/// The CPU time (best of three, s) and steps per sample of rendering the
/// shipped `name` at 640 x 360 and `tolerance`.
fn render_cost(name: &str, tolerance: f64) -> (f64, f64) {
    let set = format!("physics.tolerance={tolerance:e}");
    let scene = common::shipped(name, 640, 360, &[&set]);
    let (seconds, stats) = best_of_three(|| scene.render(&|_| {}).1);
    (seconds, stats.steps as f64 / stats.samples as f64)
}

#[test]
#[ignore = "the table of validation/REFERENCE.md: about 5 minutes on two cores"]
fn tolerance_table() {
    let mut cost = vec![Vec::new(); TOLERANCES.len()];
    for st in SPACETIMES {
        let set = ray_set(st, 12, [36, 8]);
        println!(
            "\n{st:?}: {} rays, the integrator against the closed form, median / max",
            set.len()
        );
        println!(
            "| tolerance | radius, order 0 (M) | radius, order 1 (M) | image shift, order 0 (rad) \
             | image shift, order 1 (rad) | escape direction (rad) | image shift, sky (rad) \
             | travel time (M) | rays ending otherwise |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
        for (i, tolerance) in TOLERANCES.into_iter().enumerate() {
            println!("{}", row(tolerance, &measure(st, &set, tolerance)));
            cost[i].push(ray_cost(st, &set, tolerance));
        }
    }
    println!(
        "\nCPU time, best of three: per ray (steps), untimed and timed, for Schwarzschild and a = 0.9; \
         renders at 640 x 360 (steps per sample)"
    );
    println!(
        "| tolerance | Schwarzschild | timed | a = 0.9 | timed | planets.toml | volumetric.toml |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (tolerance, c) in TOLERANCES.into_iter().zip(cost) {
        let ray = |c: [f64; 4]| {
            format!(
                "{:.1} us ({:.0}) | {:.1} us ({:.0})",
                c[1], c[0], c[3], c[2]
            )
        };
        let (p, ps) = render_cost("planets", tolerance);
        let (v, vs) = render_cost("volumetric", tolerance);
        println!(
            "| {tolerance:.0e} | {} | {} | {p:.2} s ({ps:.1}) | {v:.2} s ({vs:.1}) |",
            ray(c[0]),
            ray(c[1])
        );
    }
}

#[test]
fn the_default_tolerance_keeps_every_error_far_below_a_pixel() {
    // The default is the largest tolerance in the table whose every image
    // error is far below a pixel of a typical field (1024 pixels across
    // 60 degrees: 1e-3 rad). Measured on these rays (the table's cameras,
    // 8 x 8 and 24 x 6 rays each), Schwarzschild / a = 0.9, at 1e-7: the
    // image (disk and sky) within 1.8e-6 / 1.2e-5 rad, source radii of
    // orders 0 and 1 within 6.2e-5 / 2.3e-4 M, travel times within 6.9e-5
    // / 2.5e-4 M (rays next to the shadow's edge, which magnifies every
    // error). At 1e-6: 1.0e-5 / 6.2e-5 rad, 4.0e-4 / 2.3e-3 M and 2.9e-4 /
    // 2.4e-3 M. Limits: 3e-5 rad, 1e-3 M.
    let tolerance = PhysicsConfig::default().tolerance;
    for st in SPACETIMES {
        let set = ray_set(st, 8, [24, 6]);
        let e = measure(st, &set, tolerance);
        let max = |v: &[f64]| median_max(v).1;
        let radius = max(&e.radius[0]).max(max(&e.radius[1]));
        let image = max(&e.shift[0])
            .max(max(&e.shift[1]))
            .max(max(&e.sky_shift));
        let time = max(&e.time);
        eprintln!(
            "{st:?} at tolerance {tolerance:e}, {} rays: radius {radius:.1e} M, image {image:.1e} rad, \
             travel time {time:.1e} M; {} ending otherwise; {} and {} crossings of orders 0 and 1, \
             {} escaping",
            e.rays,
            e.disagree,
            e.radius[0].len(),
            e.radius[1].len(),
            e.sky_shift.len()
        );
        assert!(
            e.rays > 1000 && e.radius[1].len() > 100 && e.sky_shift.len() > 300,
            "{} rays",
            e.rays
        );
        assert_eq!(e.disagree, 0, "{st:?}");
        assert!(
            image < 3e-5 && radius < 1e-3 && time < 1e-3,
            "{st:?}: radius {radius:e} M, image {image:e} rad, time {time:e} M"
        );
    }
}
