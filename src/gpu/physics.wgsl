// Both ray models, the camera and the exact escape tail: the WGSL twin of
// src/camera.rs and src/physics/ (gr.rs, seed.rs, tail.rs, mod.rs), in f32
// and in units of r_s.

const END_CAPTURED: u32 = 0u;
const END_ESCAPED: u32 = 1u;
const END_STOPPED: u32 = 2u;
const END_ABANDONED: u32 = 3u;

const PHOTON_SPHERE: f32 = 1.5;
const MAX_STEP_FRACTION: f32 = 0.5;
const SEED_REMAINING_BEND: f32 = 2e-3;

struct Seg {
    x0: vec3<f32>,
    v0: vec3<f32>,
    x1: vec3<f32>,
    v1: vec3<f32>,
    h: f32,
    curved: bool,
    // seed model: ln g of light emitted at each end (running sum)
    ln0: f32,
    ln1: f32,
    // light's travel time from each end to the trace's origin, and (exact
    // model) its rate per unit of the segment parameter at each end
    t0: f32,
    t1: f32,
    rate0: f32,
    rate1: f32,
}

// ---- camera ----------------------------------------------------------------

// |x| without f32's overflow of its squares past about 1.8e19 (a camera
// that far out, whose length() is infinite): scaled by its largest
// component first.
fn safe_length(x: vec3<f32>) -> f32 {
    let m = max(abs(x.x), max(abs(x.y), abs(x.z)));
    if !(m > 0.0) {
        return 0.0;
    }
    return m * length(x / m);
}

// The pixel point's place on the image plane at unit forward distance.
fn image_point(px: f32, py: f32) -> vec2<f32> {
    let h = P.cam_half_height;
    let w = P.cam_half_width;
    let sx = (2.0 * px / f32(P.width) - 1.0) * w + P.cam_shift;
    let sy = (1.0 - 2.0 * py / f32(P.height)) * h;
    return vec2<f32>(sx, sy);
}

// Camera::pixel_solid_angle: the solid angle (sr) of the pixel about
// image point (px, py), in the camera's frame.
fn pixel_solid_angle(px: f32, py: f32) -> f32 {
    let s = image_point(px, py);
    let side = 2.0 * P.cam_half_height / f32(P.height);
    return side * side / pow(1.0 + dot(s, s), 1.5);
}

// The Doppler factor's ln of the camera's motion for the ray just made by
// camera_direction (camera::aberrate).
var<private> cam_ln_d: f32;
// KERR: the time component of the null vector the next ray starts along
// (the camera's, then each mirror's), its spatial part being the direction.
var<private> start_t: f32;

fn camera_direction(px: f32, py: f32) -> vec3<f32> {
    let s = image_point(px, py);
    var d = normalize(P.cam_fwd.xyz + P.cam_right.xyz * s.x + P.cam_up.xyz * s.y);
    cam_ln_d = 0.0;
    let v = P.cam_velocity.xyz;
    let beta = length(v);
    if beta > 0.0 {
        // camera::aberrate: the photon's direction -d boosted to the rest
        // frame, and D = 1 / (gamma (1 + beta . n')).
        let gamma = 1.0 / sqrt((1.0 - beta) * (1.0 + beta));
        let b = v / beta;
        let n1 = -d;
        let c = dot(n1, b);
        let n = (n1 + b * ((gamma - 1.0) * c + gamma * beta)) / (gamma * (1.0 + beta * c));
        d = -normalize(n);
        cam_ln_d = -log(gamma * (1.0 + beta * c));
    }
    if KERR {
        // At rest straight from the image point: the dot products lose a
        // far camera's small offsets to f32's rounding of d.
        if beta > 0.0 {
            cam_local = vec3<f32>(dot(d, P.cam_fwd.xyz), dot(d, P.cam_right.xyz), dot(d, P.cam_up.xyz));
        } else {
            cam_local = vec3<f32>(1.0, s.x, s.y) / length(vec3<f32>(1.0, s.x, s.y));
        }
        // Spacetime::camera_basis: the past-directed null vector
        // -(u - d . e) of the camera's frame, traced back.
        let f = P.cam_frame;
        let k = -(P.cam_u - f[0] * d.x - f[1] * d.y - f[2] * d.z);
        start_t = k.w;
        return k.xyz;
    }
    if P.static_observer != 0u {
        return static_to_coordinate(P.cam_pos.xyz, d);
    }
    return d;
}


// ---- segments --------------------------------------------------------------

fn seg_point(s: Seg, t: f32) -> vec3<f32> {
    if !s.curved {
        return s.x0 + (s.x1 - s.x0) * t;
    }
    let t2 = t * t;
    let t3 = t2 * t;
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    return s.x0 * h00 + s.v0 * (h10 * s.h) + s.x1 * h01 + s.v1 * (h11 * s.h);
}

fn seg_tangent(s: Seg, t: f32) -> vec3<f32> {
    if !s.curved {
        return s.x1 - s.x0;
    }
    let t2 = t * t;
    let d00 = 6.0 * t2 - 6.0 * t;
    let d10 = 3.0 * t2 - 4.0 * t + 1.0;
    let d01 = -6.0 * t2 + 6.0 * t;
    let d11 = 3.0 * t2 - 2.0 * t;
    return s.x0 * d00 + s.v0 * (d10 * s.h) + s.x1 * d01 + s.v1 * (d11 * s.h);
}

fn seg_ln_shift(s: Seg, t: f32) -> f32 {
    return s.ln0 + (s.ln1 - s.ln0) * t;
}

// physics::Segment::time_at
fn seg_time(s: Seg, t: f32) -> f32 {
    if !s.curved {
        return s.t0 + (s.t1 - s.t0) * t;
    }
    let t2 = t * t;
    let t3 = t2 * t;
    return s.t0 * (2.0 * t3 - 3.0 * t2 + 1.0) + s.rate0 * (t3 - 2.0 * t2 + t)
        + s.t1 * (-2.0 * t3 + 3.0 * t2) + s.rate1 * (t3 - t2);
}

// The disk's rotation (animation::DiskRotation::unturn): the point of the
// material's own frame that lies at `p` at time `tau`.
fn unturn(p: vec3<f32>, tau: f32) -> vec3<f32> {
    if P.rotation == ROTATION_NONE || tau == 0.0 {
        return p;
    }
    var a: f32;
    if P.rotation == ROTATION_KEPLERIAN {
        a = orbit_omega(ring_radius(sqrt(p.x * p.x + p.y * p.y))) * tau;
    } else {
        a = P.rigid_omega * tau;
    }
    let s = sin(-a);
    let c = cos(-a);
    return vec3<f32>(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
}

// DiskRotation::unturn_plane: unturn of a point of the disk's plane in its
// polar coordinates (disk_plane), whose length is its ring's radius.
fn unturn_plane(q: vec2<f32>, tau: f32) -> vec2<f32> {
    if P.rotation == ROTATION_NONE || tau == 0.0 {
        return q;
    }
    var a: f32;
    if P.rotation == ROTATION_KEPLERIAN {
        a = orbit_omega(sqrt(q.x * q.x + q.y * q.y)) * tau;
    } else {
        a = P.rigid_omega * tau;
    }
    let s = sin(-a);
    let c = cos(-a);
    return vec2<f32>(c * q.x - s * q.y, s * q.x + c * q.y);
}

// Fraction in (0, 1] where the segment crosses z = 0, or -1.
fn seg_crossing_z0(s: Seg) -> f32 {
    let z0 = s.x0.z;
    let z1 = s.x1.z;
    if z0 == 0.0 || ((z0 > 0.0) == (z1 > 0.0) && z1 != 0.0) {
        return -1.0;
    }
    let lin = z0 / (z0 - z1);
    if !s.curved {
        return lin;
    }
    // Illinois false position on the Hermite cubic.
    var a = 0.0;
    var b = 1.0;
    var fa = z0;
    var fb = z1;
    var t = lin;
    var side = 0;
    for (var it = 0; it < 40; it++) {
        let ft = seg_point(s, t).z;
        if ft == 0.0 {
            return t;
        }
        if (ft > 0.0) == (fa > 0.0) {
            a = t;
            fa = ft;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = t;
            fb = ft;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
        if b - a < 1e-7 {
            break;
        }
        t = (a * fb - b * fa) / (fb - fa);
    }
    return t;
}

// ---- exact tail --------------------------------------------------------------

fn rotate_in_plane(x: vec3<f32>, v: vec3<f32>, dphi: f32) -> vec3<f32> {
    let e1 = normalize(x);
    let perp = v - e1 * dot(v, e1);
    let len = length(perp);
    if !(len > 1e-30) || !finite(len) {
        return e1;
    }
    let e2 = perp / len;
    return e1 * cos(dphi) + e2 * sin(dphi);
}

// The angle an inbound ray of impact parameter b sweeps from infinity
// down to 1/u0 (no turning point in between): b u0 times the quadrature.
fn escape_sweep(b: f32, u0: f32) -> f32 {
    let k2 = b * b * u0 * u0;
    var q = 0.0;
    for (var i = 0u; i < GL_N; i++) {
        let t = GL_T[i];
        q += GL_W[i] / sqrt(1.0 - k2 * t * t * (1.0 - u0 * t));
    }
    return b * u0 * q;
}

fn gr_escape_direction(x: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    let r = length(x);
    let u0 = 1.0 / r;
    let c = cross(x, v);
    let h2 = dot(c, c);
    let vinf2 = dot(v, v) - h2 * u0 * u0 * u0;
    let b2 = h2 / vinf2;
    let k2 = b2 * u0 * u0;
    var q = 0.0;
    for (var i = 0u; i < GL_N; i++) {
        let t = GL_T[i];
        q += GL_W[i] / sqrt(1.0 - k2 * t * t * (1.0 - u0 * t));
    }
    return rotate_in_plane(x, v, sqrt(b2) * u0 * q);
}

// Seed model: direction, and the rest of the running sum (-1/(2r)).
fn seed_escape(x: vec3<f32>, v: vec3<f32>) -> vec4<f32> {
    let r = length(x);
    let u0 = 1.0 / r;
    let n = exp(0.5 * u0);
    let sin_psi = length(cross(x, v)) / (r * length(v));
    let b = n * r * sin_psi;
    let k2 = b * b * u0 * u0;
    var q = 0.0;
    for (var i = 0u; i < GL_N; i++) {
        let t = GL_T[i];
        q += GL_W[i] / sqrt(exp(u0 * t) - k2 * t * t);
    }
    return vec4<f32>(rotate_in_plane(x, v, b * u0 * q), -0.5 * u0);
}

fn may_escape(x: vec3<f32>, v: vec3<f32>, r: f32) -> bool {
    return r > P.outer_limit && r > 2.0 && dot(x, v) >= 0.5 * r * length(v);
}

fn may_escape_seed(x: vec3<f32>, v: vec3<f32>, r: f32) -> bool {
    if !may_escape(x, v, r) {
        return false;
    }
    let len = length(v);
    let c = dot(x, v) / (r * len);
    let b = exp(0.5 / r) * length(cross(x, v)) / len;
    return 1.0 - c <= 2.0 * b * SEED_REMAINING_BEND;
}

// ---- exact model: Dormand-Prince 5(4) ---------------------------------------


struct DpStep {
    x: vec3<f32>,
    v: vec3<f32>,
    a: vec3<f32>,
    ex: vec3<f32>,
    ev: vec3<f32>,
    // with TRAVEL: the coordinate time the step takes
    dt: f32,
}


fn dp_step(x: vec3<f32>, v: vec3<f32>, a1: vec3<f32>, h: f32, k: f32, e: f32) -> DpStep {
    let v1 = v;
    let x2 = x + v1 * (h * DP_A21);
    let v2 = v + a1 * (h * DP_A21);
    let a2 = accel(x2, k);
    let x3 = x + (v1 * DP_A31 + v2 * DP_A32) * h;
    let v3 = v + (a1 * DP_A31 + a2 * DP_A32) * h;
    let a3 = accel(x3, k);
    let x4 = x + (v1 * DP_A41 + v2 * DP_A42 + v3 * DP_A43) * h;
    let v4 = v + (a1 * DP_A41 + a2 * DP_A42 + a3 * DP_A43) * h;
    let a4 = accel(x4, k);
    let x5 = x + (v1 * DP_A51 + v2 * DP_A52 + v3 * DP_A53
        + v4 * DP_A54) * h;
    let v5 = v + (a1 * DP_A51 + a2 * DP_A52 + a3 * DP_A53
        + a4 * DP_A54) * h;
    let a5 = accel(x5, k);
    let x6 = x + (v1 * DP_A61 + v2 * DP_A62 + v3 * DP_A63
        + v4 * DP_A64 + v5 * DP_A65) * h;
    let v6 = v + (a1 * DP_A61 + a2 * DP_A62 + a3 * DP_A63
        + a4 * DP_A64 + a5 * DP_A65) * h;
    let a6 = accel(x6, k);
    let xn = x + (v1 * DP_B1 + v3 * DP_B3 + v4 * DP_B4
        + v5 * DP_B5 + v6 * DP_B6) * h;
    let vn = v + (a1 * DP_B1 + a3 * DP_B3 + a4 * DP_B4
        + a5 * DP_B5 + a6 * DP_B6) * h;
    let an = accel(xn, k);
    let ex = (v1 * DP_E1 + v3 * DP_E3 + v4 * DP_E4
        + v5 * DP_E5 + v6 * DP_E6 + vn * DP_E7) * h;
    let ev = (a1 * DP_E1 + a3 * DP_E3 + a4 * DP_E4
        + a5 * DP_E5 + a6 * DP_E6 + an * DP_E7) * h;
    var dt = 0.0;
    if TRAVEL {
        dt = h * (DP_B1 * time_rate(x, e) + DP_B3 * time_rate(x3, e)
            + DP_B4 * time_rate(x4, e) + DP_B5 * time_rate(x5, e)
            + DP_B6 * time_rate(x6, e));
    }
    return DpStep(xn, vn, an, ex, ev, dt);
}

// ---- resumable tracing ---------------------------------------------------------
//
// The integration loops below stop at every event (a step that may meet
// the disk, an object or gas, capture, escape, running out of steps) and
// hand it to the caller, which shades and resumes: shading code stays out
// of the hot loop, which keeps it small for the shader compiler.

const EV_VISIT: u32 = 4u;

struct Ray {
    x: vec3<f32>,
    v: vec3<f32>,
    a: vec3<f32>,
    h: f32,
    err: f32,
    r: f32,
    // exact model: (3/2) h^2; seed model: the running sum
    k: f32,
    sum: f32,
    // exact model: the photon's energy; both: the light's travel time so far
    e: f32,
    time: f32,
    // KERR (M units): x, v = dx/dlambda and a = dp/dlambda as above, the
    // covariant momentum p, and the travel time's rate
    p: vec3<f32>,
    rate: f32,
    steps: u32,
    // a step was reported: its end checks are still to run
    pending: bool,
    // the segment of the last reported step
    seg: Seg,
}

fn ray_start(x: vec3<f32>, v: vec3<f32>) -> Ray {
    if KERR {
        return ks_ray_start(x, v, start_t);
    }
    let r = length(x);
    var ray: Ray;
    ray.x = x;
    ray.r = r;
    ray.steps = 0u;
    ray.pending = false;
    ray.sum = 0.0;
    ray.err = 0.0;
    ray.time = 0.0;
    ray.e = 0.0;
    if P.model == MODEL_GR {
        ray.v = v;
        ray.k = 1.5 * dot(cross(x, v), cross(x, v));
        ray.e = sqrt(dot(v, v) - (2.0 / 3.0) * ray.k / (r * r * r));
        ray.a = accel(x, ray.k);
        ray.h = 0.05 * r / length(v);
    } else {
        ray.v = normalize(v);
    }
    return ray;
}

// Whether a segment from z0 to z1 may cross the disk's plane.
fn may_cross(z0: f32, z1: f32) -> bool {
    return P.disk_kind != DISK_NONE && !(z0 == 0.0 || ((z0 > 0.0) == (z1 > 0.0) && z1 != 0.0));
}

// The step controller's factors after a step with error `err` of the
// tolerance: the next step's growth once accepted (at most 5x), the retry's
// shrinking once rejected (at least 0.2x).
fn step_growth(err: f32) -> f32 {
    if err > 0.0 {
        return min(0.9 * pow(err, -0.2), 5.0);
    }
    return 5.0;
}

fn step_shrink(err: f32) -> f32 {
    return max(0.9 * pow(err, -0.2), 0.2);
}

// Exact model: integrates until the next event (END_* or EV_VISIT).
fn advance_gr(ray: ptr<function, Ray>) -> u32 {
    let tolerance = P.tolerance;
    let capture_radius = min(P.inner_limit, PHOTON_SPHERE);
    if (*ray).steps == 0u && !(*ray).pending && may_escape((*ray).x, (*ray).v, (*ray).r) {
        return END_ESCAPED;
    }
    loop {
        if (*ray).pending {
            (*ray).pending = false;
            let x = (*ray).x;
            let v = (*ray).v;
            let r = (*ray).r;
            if r < 1.0 || (r < capture_radius && dot(x, v) < 0.0) {
                return END_CAPTURED;
            }
            if may_escape(x, v, r) {
                return END_ESCAPED;
            }
            (*ray).h *= step_growth((*ray).err);
        }
        if (*ray).steps >= P.max_steps {
            break;
        }
        let x = (*ray).x;
        let v = (*ray).v;
        let r = (*ray).r;
        let speed = length(v);
        let h = min((*ray).h, MAX_STEP_FRACTION * r / speed);
        let st = dp_step(x, v, (*ray).a, h, (*ray).k, (*ray).e);
        let rn = length(st.x);
        let err = max(length(st.ex) / (tolerance * max(r, rn)), length(st.ev) / (tolerance * speed));
        if !(err <= 1.0) {
            // f32: a step below 1e-6 of r cannot move the ray.
            if !finite(err) || h < 1e-6 * r / speed {
                return END_ABANDONED;
            }
            (*ray).h = h * step_shrink(err);
            continue;
        }
        (*ray).steps += 1u;
        (*ray).h = h;
        (*ray).err = err;
        (*ray).x = st.x;
        (*ray).v = st.v;
        (*ray).a = st.a;
        (*ray).r = rn;
        (*ray).pending = true;
        let t0 = (*ray).time;
        (*ray).time += st.dt;
        if needs_visit(x, st.x) {
            var rates = vec2<f32>(0.0);
            if TRAVEL {
                rates = vec2<f32>(time_rate(x, (*ray).e), time_rate(st.x, (*ray).e)) * h;
            }
            (*ray).seg = Seg(x, v, st.x, st.v, h, true, 0.0, 0.0, t0, (*ray).time, rates.x, rates.y);
            return EV_VISIT;
        }
    }
    // The steps spent: the loop's one break, which keeps this return
    // reachable (naga wants it; Tint warns of code after a loop that
    // cannot break).
    return END_ABANDONED;
}

// The assignment's model: steps until the next event.
fn advance_seed(ray: ptr<function, Ray>) -> u32 {
    let step = P.seed_step;
    if (*ray).steps == 0u && !(*ray).pending && may_escape_seed((*ray).x, (*ray).v, (*ray).r) {
        return END_ESCAPED;
    }
    loop {
        if (*ray).pending {
            (*ray).pending = false;
            let r = (*ray).r;
            if !finite(r) {
                return END_ABANDONED;
            }
            if r < 1.0 {
                return END_CAPTURED;
            }
            if may_escape_seed((*ray).x, (*ray).v, r) {
                return END_ESCAPED;
            }
        }
        if (*ray).steps >= P.max_steps {
            break;
        }
        let x = (*ray).x;
        let v = (*ray).v;
        let r = (*ray).r;
        let dt = step * r;
        let a = x * (-0.5 / (r * r * r));
        let xn = x + v * dt + a * (0.5 * dt * dt);
        let vn = normalize(v + a * dt);
        let sum0 = (*ray).sum;
        let rn = length(xn);
        let an = xn * (-0.5 / (rn * rn * rn));
        let sum = sum0 + 0.5 * (dot(a, v) + dot(an, vn)) * dt;
        (*ray).sum = sum;
        (*ray).steps += 1u;
        (*ray).x = xn;
        (*ray).v = vn;
        (*ray).r = rn;
        (*ray).pending = true;
        let t0 = (*ray).time;
        if TRAVEL {
            // Optical path: length times the index exp(1/(2r)).
            (*ray).time += length(xn - x) * 0.5 * (exp(0.5 / r) + exp(0.5 / rn));
        }
        if needs_visit(x, xn) {
            (*ray).seg = Seg(x, v * dt, xn, vn * dt, 1.0, false, -sum0, -sum, t0, (*ray).time, 0.0, 0.0);
            return EV_VISIT;
        }
    }
    // The steps spent: the loop's one break, which keeps this return
    // reachable (naga wants it; Tint warns of code after a loop that
    // cannot break).
    return END_ABANDONED;
}

fn advance(ray: ptr<function, Ray>) -> u32 {
    if KERR {
        return advance_kerr(ray);
    }
    if P.model == MODEL_GR {
        return advance_gr(ray);
    }
    return advance_seed(ray);
}
