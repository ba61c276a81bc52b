// Footprints (FOOTPRINT): twin of src/cpu/footprint.rs. Each sample's
// derivatives per pixel of its direction at infinity and of the disk-plane
// points its texture reads. Schwarzschild's come from its closed form's
// own derivatives where a camera at rest starts its rays exactly
// (footprint_closed.wgsl: the CPU's within 6.6e-5 at the 99th percentile
// on `quick`). Every other (Kerr, the seed model, moving cameras) from
// neighbouring rays a sixteenth of a pixel away on each axis, in closed
// form whatever the scene traces with (the same geodesic; the
// integrator's adaptive steps would put their own jumps into a
// difference). A neighbour counts only where it ends the same way (it
// escapes too; it crosses the disk at the same crossing of the plane),
// else the other side's; where neither does, that part has no footprint.
// f32 differences over 1/16 px hold the derivatives to about 1e-3
// (measured against the CPU's f64 in validation/tests/gpu.rs).
//
// The seed model has no closed form: its rays are traced with its fixed
// step sequence, which is smooth in the direction (fp_traced).

// Neighbour step (pixels): a power of two, so that px +- FP_STEP is exact.
const FP_STEP: f32 = 0.0625;

// Where one ray ends, as much as a footprint compares (footprint::Ends).
struct FpEnds {
    ok: bool,
    escaped: bool,
    dir: vec3<f32>,
    n: u32,
    order: array<u32, FP_CROSSINGS>,
    // The crossing (scene coordinates, r_s) and the disk-plane point the
    // texture reads (turned back by the disk's rotation).
    p: array<vec3<f32>, FP_CROSSINGS>,
    q: array<vec2<f32>, FP_CROSSINGS>,
}

fn fp_push(e: ptr<function, FpEnds>, order: u32, p: vec3<f32>, plane: vec2<f32>) {
    let rho = length(plane);
    if (*e).n < FP_CROSSINGS && rho >= P.disk_inner && rho <= P.disk_outer {
        let i = (*e).n;
        (*e).order[i] = order;
        (*e).p[i] = p;
        (*e).q[i] = unturn_plane(plane, P.time);
        (*e).n = i + 1u;
    }
}

// Scene::ends: where the camera ray through image point (px, py) ends, in
// closed form. Sets the camera's per-ray state (exact_b, cam_local, ...):
// the sample's own ray is made again after its footprint.
fn fp_ends(px: f32, py: f32) -> FpEnds {
    var e: FpEnds;
    e.ok = false;
    e.escaped = false;
    e.n = 0u;
    set_exact_ray(image_point(px, py));
    let d = camera_direction(px, py);
    let disk = P.disk_kind != DISK_NONE;
    if KERR {
        let c = kerr_camera_ray();
        if !c.ok {
            return e;
        }
        let first = kc_first(c);
        for (var i = 0u; disk && i < 64u && e.n < FP_CROSSINGS; i++) {
            let q = kc_crossing(c, first + f32(i));
            if q.r < 0.0 {
                break;
            }
            fp_push(&e, i, 0.5 * q.p, 0.5 * q.plane);
        }
        e.escaped = !c.captured;
        if e.escaped {
            e.dir = kc_escape(c);
        }
    } else {
        if P.model != MODEL_GR {
            return fp_traced(d);
        }
        let c = closed_ray(P.cam_pos.xyz, d);
        if !c.ok {
            return e;
        }
        let first = closed_first_crossing(c);
        for (var i = 0u; disk && first >= 0.0 && i < 64u && e.n < FP_CROSSINGS; i++) {
            let phi = first + f32(i) * PI;
            if phi >= c.sweep {
                break;
            }
            let p = closed_point(c, phi);
            fp_push(&e, i, p, p.xy);
        }
        e.escaped = !c.captured;
        if e.escaped {
            e.dir = c.e1 * cos(c.sweep) + c.e2 * sin(c.sweep);
        }
    }
    e.ok = true;
    return e;
}

// The seed model's ray from the camera along `d`, traced with its fixed
// step sequence (smooth in the direction): its ends, as fp_ends.
fn fp_traced(d: vec3<f32>) -> FpEnds {
    var e: FpEnds;
    e.ok = false;
    e.escaped = false;
    e.n = 0u;
    var ray = ray_start(P.cam_pos.xyz, d);
    var order = 0u;
    var end = END_ABANDONED;
    loop {
        // The seed model's own step (fp_ends takes no other here): the
        // integrators' code is not inlined again.
        let ev = advance_seed(&ray);
        if ev != EV_VISIT {
            end = ev;
            break;
        }
        let seg = ray.seg;
        if may_cross(seg.x0.z, seg.x1.z) {
            let s = seg_crossing_z0(seg);
            if s >= 0.0 {
                let p = seg_point(seg, s);
                fp_push(&e, order, p, disk_plane(p));
                order += 1u;
            }
        }
    }
    if end == END_ESCAPED {
        e.escaped = true;
        e.dir = seed_escape(ray.x, ray.v).xyz;
    } else if end != END_CAPTURED {
        return e;
    }
    e.ok = true;
    return e;
}

// A derivative from the neighbours that end alike (after at +h, before at
// -h; `ok` says which do): central where both do, else one-sided; w is 0
// where neither does.
fn fp_derive(ok: vec2<bool>, a: vec3<f32>, b: vec3<f32>, here: vec3<f32>) -> vec4<f32> {
    let h = FP_STEP;
    if ok.x && ok.y {
        return vec4<f32>((a - b) / (2.0 * h), 1.0);
    }
    if ok.x {
        return vec4<f32>((a - here) / h, 1.0);
    }
    if ok.y {
        return vec4<f32>((here - b) / h, 1.0);
    }
    return vec4<f32>(0.0);
}

// The disk-plane point of `e`'s crossing of plane-crossing order `order`
// (z is 1 where it has one).
fn fp_crossing(ends: FpEnds, order: u32) -> vec3<f32> {
    // A variable: arrays are indexed at run time through references.
    var e = ends;
    if e.ok {
        for (var i = 0u; i < e.n; i++) {
            if e.order[i] == order {
                return vec3<f32>(e.q[i], 1.0);
            }
        }
    }
    return vec3<f32>(0.0);
}

fn fp_escaped(e: FpEnds) -> bool {
    return e.ok && e.escaped;
}

// fp_derive of the disk-plane point of crossing `order` over the
// neighbours a (+h) and b (-h).
fn fp_derive_crossing(order: u32, a: FpEnds, b: FpEnds, here: vec3<f32>) -> vec4<f32> {
    let ca = fp_crossing(a, order);
    let cb = fp_crossing(b, order);
    let flat = vec3<f32>(1.0, 1.0, 0.0);
    return fp_derive(vec2<bool>(ca.z > 0.0, cb.z > 0.0), ca * flat, cb * flat, here);
}

// Scene::neighbour_footprint of the sample at image point (px, py): fills
// fp.
fn sample_footprint(px: f32, py: f32) {
    fp.ok = false;
    fp.sky_ok = false;
    fp.n = 0u;
    // Schwarzschild's closed form gives its derivatives itself
    // (footprint_closed.wgsl) where the camera's rays start exactly.
    if !KERR && P.model == MODEL_GR && closed_footprint(px, py) {
        return;
    }
    // The sample and its neighbours at +-h on each axis, from one call
    // site: a shader compiler that inlines every call (llvmpipe does)
    // would otherwise compile the closed forms five times over.
    let h = FP_STEP;
    var at = array<vec2<f32>, 5>(vec2<f32>(0.0), vec2<f32>(h, 0.0), vec2<f32>(-h, 0.0), vec2<f32>(0.0, h), vec2<f32>(0.0, -h));
    var ends: array<FpEnds, 5>;
    for (var k = 0u; k < 5u; k++) {
        ends[k] = fp_ends(px + at[k].x, py + at[k].y);
        if k == 0u && !ends[0].ok {
            return;
        }
    }
    var here = ends[0];
    let xa = ends[1];
    let xb = ends[2];
    let ya = ends[3];
    let yb = ends[4];
    fp.ok = true;
    fp.pixel_sr = pixel_solid_angle(px, py);
    if here.escaped {
        let d = here.dir;
        let dx = fp_derive(vec2<bool>(fp_escaped(xa), fp_escaped(xb)), xa.dir, xb.dir, d);
        let dy = fp_derive(vec2<bool>(fp_escaped(ya), fp_escaped(yb)), ya.dir, yb.dir, d);
        if dx.w > 0.0 && dy.w > 0.0 {
            fp.sky_ok = true;
            fp.sky = d;
            fp.sky_dx = dx.xyz;
            fp.sky_dy = dy.xyz;
        }
    }
    let eye = P.cam_pos.xyz;
    for (var i = 0u; i < here.n; i++) {
        let order = here.order[i];
        let q = vec3<f32>(here.q[i], 0.0);
        let dx = fp_derive_crossing(order, xa, xb, q);
        let dy = fp_derive_crossing(order, ya, yb, q);
        if dx.w > 0.0 && dy.w > 0.0 {
            let k = fp.n;
            fp.order[k] = order;
            fp.q[k] = q.xy;
            fp.q_dx[k] = dx.xy;
            fp.q_dy[k] = dy.xy;
            fp.magnification[k] = fp_disk_magnification(fp.pixel_sr, here.p[i] - eye, dx.xy, dy.xy);
            fp.n = k + 1u;
        }
    }
}

// footprint::disk_magnification: the pixel's solid angle over the solid
// angle its footprint on the plane (derivatives dx, dy) would subtend seen
// straight from the camera along `to`, signed by the image's parity.
fn fp_disk_magnification(pixel_sr: f32, to: vec3<f32>, dx: vec2<f32>, dy: vec2<f32>) -> f32 {
    let rho2 = dot(to, to);
    let e_z = to.z / sqrt(rho2);
    return pixel_sr * rho2 / ((dx.x * dy.y - dx.y * dy.x) * e_z);
}
