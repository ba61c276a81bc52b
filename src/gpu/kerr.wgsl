// The spinning hole (KERR): the WGSL twin of src/physics/kerr/ (the
// fields and flow of ks.rs, the integrator and tail of trace.rs, the
// frames and mirror of frames.rs, mod.rs's closed forms), in f32 and, as
// there, in units of M = r_s / 2 in Kerr-Schild Cartesian coordinates
// (g = eta + f l l, no pole or horizon singularity). A ray's state is its
// position x and spatial covariant momentum p, with p_t = -E conserved;
// segments are handed to the shading code in r_s.

// Kerr::ks_radius: the Boyer-Lindquist radius of x, the positive root of
// r^4 - (|x|^2 - a^2) r^2 - a^2 z^2 = 0, without cancellation near the ring
// and without overflow far out.
fn ks_radius(x: vec3<f32>) -> f32 {
    let a2 = P.kerr_hole.x * P.kerr_hole.x;
    let w = dot(x, x) - a2;
    if w > 0.0 {
        let q = a2 * (x.z / w) * (x.z / w);
        return sqrt(w * (0.5 + sqrt(0.25 + q)));
    }
    let root = sqrt(0.25 * w * w + a2 * x.z * x.z);
    return sqrt(a2 * x.z * x.z / max(root - 0.5 * w, 1e-30));
}

// The metric's f = 2 r^3 / (r^4 + a^2 z^2) at x of radius r.
fn ks_f(x: vec3<f32>, r: f32) -> f32 {
    let a = P.kerr_hole.x;
    let r2 = r * r;
    return 2.0 * r2 * r / (r2 * r2 + a * a * x.z * x.z);
}

// The null covector's spatial part l (l_t = 1) at x of radius r.
fn ks_l(x: vec3<f32>, r: f32) -> vec3<f32> {
    let a = P.kerr_hole.x;
    let inv_s = 1.0 / (r * r + a * a);
    return vec3<f32>((r * x.x + a * x.y) * inv_s, (r * x.y - a * x.x) * inv_s, x.z / r);
}

// Delta = r^2 - 2r + a^2 as (r - r_+)(r - r_-): no cancellation at the
// horizon, where Boyer-Lindquist's time rate divides by it.
fn ks_delta(r: f32) -> f32 {
    return (r - P.kerr_hole.y) * (r - P.kerr_hole.z);
}

// Hamilton's equations at (x, p) for a photon of energy e (Kerr::flow):
// d x / d lambda, d p / d lambda and, with TRAVEL, minus Boyer-Lindquist's
// d t / d lambda (the ray runs back in time: its travel time grows).
struct KRate {
    dx: vec3<f32>,
    dp: vec3<f32>,
    dt: f32,
}

fn ks_rate(x: vec3<f32>, p: vec3<f32>, e: f32) -> KRate {
    let a = P.kerr_hole.x;
    let a2 = a * a;
    let r = ks_radius(x);
    let r2 = r * r;
    let inv_r = 1.0 / r;
    let inv_s = 1.0 / (r2 + a2);
    let zz = x.z * x.z;
    let inv_q = 1.0 / (r2 * r2 + a2 * zz);
    let f = 2.0 * r2 * r * inv_q;
    let nx = r * x.x + a * x.y;
    let ny = r * x.y - a * x.x;
    let l = vec3<f32>(nx * inv_s, ny * inv_s, x.z * inv_r);
    // dr/dx_i = (x_i r^2 + a^2 z delta_iz) / (r Sigma), Sigma = r^2 + a^2
    // z^2 / r^2 (the CPU's 2r^2 - |x|^2 + a^2, which cancels in f32).
    let inv_den = inv_r / (r2 + a2 * zz * inv_r * inv_r);
    let dr = (x * r2 + vec3<f32>(0.0, 0.0, a2 * x.z)) * inv_den;
    let dq = dr * (4.0 * r2 * r) + vec3<f32>(0.0, 0.0, 2.0 * a2 * x.z);
    let df = (dr * (6.0 * r2) - dq * f) * inv_q;
    let ds = dr * (2.0 * r * inv_s);
    let dlx = (dr * x.x + vec3<f32>(r, a, 0.0) - ds * nx) * inv_s;
    let dly = (dr * x.y + vec3<f32>(-a, r, 0.0) - ds * ny) * inv_s;
    let dlz = (vec3<f32>(0.0, 0.0, r) - dr * x.z) * (inv_r * inv_r);
    let lp = e + dot(l, p);
    let dlp = dlx * p.x + dly * p.y + dlz * p.z;
    var k: KRate;
    k.dx = p - l * (f * lp);
    k.dp = df * (0.5 * lp * lp) + dlp * (f * lp);
    k.dt = 0.0;
    if TRAVEL {
        // Boyer-Lindquist's t is Kerr-Schild's less the integral of 2r /
        // Delta dr.
        k.dt = -(e + f * lp - 2.0 * r / ks_delta(r) * dot(dr, k.dx));
    }
    return k;
}

// The state (p, E) of the null vector (t, v) at x (Kerr::ks_lower's p_mu).
fn ks_momentum(x: vec3<f32>, v: vec3<f32>, t: f32) -> vec4<f32> {
    let r = ks_radius(x);
    let f = ks_f(x, r);
    let l = ks_l(x, r);
    let lw = t + dot(l, v);
    return vec4<f32>(v + l * (f * lw), t - f * lw);
}

// The time component of the past-directed null vector with spatial part v
// at x outside the ergosphere, where only one root of g(k, k) = 0 runs back
// in time (Kerr::ks_backward there).
fn ks_backward_t(x: vec3<f32>, v: vec3<f32>) -> f32 {
    let r = ks_radius(x);
    let f = ks_f(x, r);
    let lv = dot(ks_l(x, r), v);
    let qa = f - 1.0;
    let qb = 2.0 * f * lv;
    let qc = dot(v, v) + f * lv * lv;
    let d = sqrt(max(qb * qb - 4.0 * qa * qc, 0.0));
    let q = -0.5 * (qb + select(-d, d, qb >= 0.0));
    let t0 = q / qa;
    // A static observer measures energy t (1 - f) - f lv (times a
    // positive factor): negative for the vector running back in time.
    if t0 * (1.0 - f) - f * lv < 0.0 {
        return t0;
    }
    return qc / q;
}

// Kerr::ks_reflect: the ray traced back along v off a static mirror at x
// (outside the ergosphere) whose surface has the coordinate normal n, by
// the law of reflection in the static observer's frame closest to the axes.
// Returns the reflected null vector (xyz spatial, w time). That frame is
// G^(-1/2) of the projected axes' Gram matrix G = I + f / (1 - f) l l^T, a
// rank-one update whose root is closed: Z = I + beta l l^T / |l|^2.
fn ks_reflect(x: vec3<f32>, d: vec3<f32>, n: vec3<f32>) -> vec4<f32> {
    let r = ks_radius(x);
    let f = ks_f(x, r);
    let l = ks_l(x, r);
    let u0 = inverseSqrt(1.0 - f);
    let t = ks_backward_t(x, d);
    let lw = t + dot(l, d);
    let kl_t = -t + f * lw;
    let kl = d + l * (f * lw);
    let energy = -kl_t * u0;
    let l2 = dot(l, l);
    let beta = inverseSqrt(1.0 + f / (1.0 - f) * l2) - 1.0;
    let zl = l * (beta / l2);
    // Each frame vector's time component: f u0^2 (1 + beta) l_a.
    let et = l * (f * u0 * u0 * (1.0 + beta));
    let local = et * kl_t + kl + zl * dot(l, kl);
    let normal = normalize(n + zl * dot(l, n));
    let out = local - normal * (2.0 * dot(local, normal));
    return vec4<f32>(out + zl * dot(l, out), energy * u0 + dot(out, et));
}

// ---- the escape tail --------------------------------------------------------

// The polar motion over Mino time: (angle or cos, its rate, the azimuth's
// polar part); in theta near a pole (through it when L_z = 0), else in u =
// cos theta, whose equation is polynomial.
fn polar_rate(y: vec3<f32>, theta: bool, lz: f32, c1: f32, ae2: f32, ae: f32) -> vec3<f32> {
    if theta {
        let s = sin(y.x);
        let c = cos(y.x);
        var pole = 0.0;
        if lz != 0.0 {
            pole = lz / (s * s);
        }
        return vec3<f32>(y.y, -ae2 * c * s + pole * pole * c * s, pole - ae);
    }
    let u = y.x;
    return vec3<f32>(y.y, -c1 * u - 2.0 * ae2 * u * u * u, lz / (1.0 - u * u) - ae);
}

// integrate_mino: the polar state carried over Mino time `mino` by
// Dormand-Prince 5(4) with error control (f32: 1e-6 of the motion's scale).
fn polar_integrate(y0: vec3<f32>, mino: f32, theta: bool, lz: f32, c1: f32, ae2: f32, ae: f32, q: f32) -> vec3<f32> {
    var y = y0;
    var done = 0.0;
    var h = 0.25 * mino;
    let tol = 1e-6 * (1.0 + sqrt(abs(q) + ae2) * mino);
    var k1 = polar_rate(y, theta, lz, c1, ae2, ae);
    for (var i = 0u; i < 400u; i++) {
        let rest = mino - done;
        let last = h >= rest;
        h = min(h, rest);
        let k2 = polar_rate(y + k1 * (h * DP_A21), theta, lz, c1, ae2, ae);
        let k3 = polar_rate(y + (k1 * DP_A31 + k2 * DP_A32) * h, theta, lz, c1, ae2, ae);
        let k4 = polar_rate(y + (k1 * DP_A41 + k2 * DP_A42 + k3 * DP_A43) * h, theta, lz, c1, ae2, ae);
        let k5 = polar_rate(y + (k1 * DP_A51 + k2 * DP_A52 + k3 * DP_A53 + k4 * DP_A54) * h, theta, lz, c1, ae2, ae);
        let k6 = polar_rate(y + (k1 * DP_A61 + k2 * DP_A62 + k3 * DP_A63 + k4 * DP_A64 + k5 * DP_A65) * h, theta, lz, c1, ae2, ae);
        let yn = y + (k1 * DP_B1 + k3 * DP_B3 + k4 * DP_B4 + k5 * DP_B5 + k6 * DP_B6) * h;
        let k7 = polar_rate(yn, theta, lz, c1, ae2, ae);
        let ev = (k1 * DP_E1 + k3 * DP_E3 + k4 * DP_E4 + k5 * DP_E5 + k6 * DP_E6 + k7 * DP_E7) * h;
        let err = max(max(abs(ev.x), abs(ev.y)), abs(ev.z)) / tol;
        if err <= 1.0 {
            y = yn;
            k1 = k7;
            done += h;
            if last {
                break;
            }
        } else if !finite(err) {
            break;
        }
        h *= clamp(0.9 * pow(max(err, 1e-10), -0.2), 0.2, 5.0);
    }
    return y;
}

// Kerr::ks_escape_direction: the exact direction at infinity of the
// outbound photon at (x, p) of energy e, well past its last radial turning
// point: the rest of the path in Mino time, the radial part by
// Gauss-Legendre quadrature in u = 1/r, the polar part integrated.
fn ks_escape_direction(x: vec3<f32>, p: vec3<f32>, e: f32) -> vec3<f32> {
    let a = P.kerr_hole.x;
    let r = ks_radius(x);
    let ct = clamp(x.z / r, -1.0, 1.0);
    let th = acos(ct);
    // Off the axis by at least f32's resolution.
    let st = max(sin(th), 1e-7);
    let phi0 = atan2(x.y, x.x) - atan2(a, r);
    let lz = x.x * p.y - x.y * p.x;
    let p_th = ct / st * (x.x * p.x + x.y * p.y) - r * st * p.z;
    let q = p_th * p_th + ct * ct * (lz * lz / (st * st) - a * a * e * e);
    let k = q + (lz - a * e) * (lz - a * e);
    let u0 = 1.0 / r;
    var mino = 0.0;
    var phi_radial = 0.0;
    for (var i = 0u; i < GL_N; i++) {
        let u = u0 * GL_T[i];
        let energy = e * (1.0 + a * a * u * u) - a * lz * u * u;
        let du = 1.0 - 2.0 * u + a * a * u * u;
        let s = inverseSqrt(energy * energy - u * u * du * k);
        mino += GL_W[i] * s;
        phi_radial += GL_W[i] * (a * energy / du * s + a / du);
    }
    mino *= u0;
    phi_radial *= u0;
    // How close to the axis the polar motion swings: u^2 at its turn.
    let c1 = q + lz * lz - a * a * e * e;
    let ae2 = a * a * e * e;
    var u_turn2: f32;
    if ae2 > 0.0 {
        u_turn2 = (-c1 + sqrt(max(c1 * c1 + 4.0 * ae2 * q, 0.0))) / (2.0 * ae2);
    } else {
        u_turn2 = q / max(c1, 1e-30);
    }
    var th_end: f32;
    var phi_polar: f32;
    if u_turn2 > 0.9 {
        let y = polar_integrate(vec3<f32>(th, p_th, 0.0), mino, true, lz, c1, ae2, a * e, q);
        th_end = y.x;
        phi_polar = y.z;
    } else {
        let y = polar_integrate(vec3<f32>(ct, -st * p_th, 0.0), mino, false, lz, c1, ae2, a * e, q);
        th_end = acos(clamp(y.x, -1.0, 1.0));
        phi_polar = y.z;
    }
    let phi = phi0 + phi_radial + phi_polar;
    let s = sin(th_end);
    return vec3<f32>(s * cos(phi), s * sin(phi), cos(th_end));
}

// ---- tracing ----------------------------------------------------------------

struct KStep {
    x: vec3<f32>,
    p: vec3<f32>,
    t: f32,
    // The flow at the step's end (its last stage).
    k: KRate,
    ex: vec3<f32>,
    ep: vec3<f32>,
    et: f32,
}

// One Dormand-Prince 5(4) step of (x, p, travel time) from the flow k1 at
// its start.
fn ks_step(x: vec3<f32>, p: vec3<f32>, t: f32, k1: KRate, h: f32, e: f32) -> KStep {
    let k2 = ks_rate(x + k1.dx * (h * DP_A21), p + k1.dp * (h * DP_A21), e);
    let k3 = ks_rate(
        x + (k1.dx * DP_A31 + k2.dx * DP_A32) * h,
        p + (k1.dp * DP_A31 + k2.dp * DP_A32) * h,
        e,
    );
    let k4 = ks_rate(
        x + (k1.dx * DP_A41 + k2.dx * DP_A42 + k3.dx * DP_A43) * h,
        p + (k1.dp * DP_A41 + k2.dp * DP_A42 + k3.dp * DP_A43) * h,
        e,
    );
    let k5 = ks_rate(
        x + (k1.dx * DP_A51 + k2.dx * DP_A52 + k3.dx * DP_A53 + k4.dx * DP_A54) * h,
        p + (k1.dp * DP_A51 + k2.dp * DP_A52 + k3.dp * DP_A53 + k4.dp * DP_A54) * h,
        e,
    );
    let k6 = ks_rate(
        x + (k1.dx * DP_A61 + k2.dx * DP_A62 + k3.dx * DP_A63 + k4.dx * DP_A64 + k5.dx * DP_A65) * h,
        p + (k1.dp * DP_A61 + k2.dp * DP_A62 + k3.dp * DP_A63 + k4.dp * DP_A64 + k5.dp * DP_A65) * h,
        e,
    );
    var s: KStep;
    s.x = x + (k1.dx * DP_B1 + k3.dx * DP_B3 + k4.dx * DP_B4 + k5.dx * DP_B5 + k6.dx * DP_B6) * h;
    s.p = p + (k1.dp * DP_B1 + k3.dp * DP_B3 + k4.dp * DP_B4 + k5.dp * DP_B5 + k6.dp * DP_B6) * h;
    s.t = t + (k1.dt * DP_B1 + k3.dt * DP_B3 + k4.dt * DP_B4 + k5.dt * DP_B5 + k6.dt * DP_B6) * h;
    let k7 = ks_rate(s.x, s.p, e);
    s.k = k7;
    s.ex = (k1.dx * DP_E1 + k3.dx * DP_E3 + k4.dx * DP_E4 + k5.dx * DP_E5 + k6.dx * DP_E6 + k7.dx * DP_E7) * h;
    s.ep = (k1.dp * DP_E1 + k3.dp * DP_E3 + k4.dp * DP_E4 + k5.dp * DP_E5 + k6.dp * DP_E6 + k7.dp * DP_E7) * h;
    s.et = (k1.dt * DP_E1 + k3.dt * DP_E3 + k4.dt * DP_E4 + k5.dt * DP_E5 + k6.dt * DP_E6 + k7.dt * DP_E7) * h;
    return s;
}

// Outbound beyond the outer bound, 60 degrees or less from radial: the
// exact tail takes over.
fn ks_outbound(x: vec3<f32>, v: vec3<f32>, r: f32) -> bool {
    return r > P.kerr_limits.z && r > 4.0 && dot(x, v) >= 0.5 * length(x) * length(v);
}

// The ray from the camera or a mirror at `x` (r_s) along the null vector
// (t, v) traced back (M units, Kerr::ks_trace's start).
fn ks_ray_start(x_rs: vec3<f32>, v: vec3<f32>, t: f32) -> Ray {
    var ray: Ray;
    let x = 2.0 * x_rs;
    let pe = ks_momentum(x, v, t);
    ray.x = x;
    ray.p = pe.xyz;
    ray.e = pe.w;
    let k = ks_rate(x, ray.p, ray.e);
    ray.v = k.dx;
    ray.a = k.dp;
    ray.rate = k.dt;
    ray.r = ks_radius(x);
    ray.h = 0.05 * ray.r / length(k.dx);
    ray.steps = 0u;
    ray.pending = false;
    ray.err = 0.0;
    ray.time = 0.0;
    ray.sum = 0.0;
    ray.k = 0.0;
    return ray;
}

// Kerr::ks_trace: integrates until the next event (END_* or EV_VISIT),
// each step's segment in r_s.
fn advance_kerr(ray: ptr<function, Ray>) -> u32 {
    let tolerance = P.tolerance;
    if (*ray).steps == 0u && !(*ray).pending && ks_outbound((*ray).x, (*ray).v, (*ray).r) {
        return END_ESCAPED;
    }
    loop {
        if (*ray).pending {
            (*ray).pending = false;
            let x = (*ray).x;
            let v = (*ray).v;
            let r = (*ray).r;
            // Captured within 1e-3 of r_+ (rays traced back to the horizon
            // come from the past one), or inbound inside both the prograde
            // photon orbit and the scene's inner bound, or inside r_+.
            let inbound = dot(x, v) < 0.0;
            if ((r < P.kerr_limits.x || r < P.kerr_limits.y) && inbound) || r < P.kerr_hole.y {
                return END_CAPTURED;
            }
            if ks_outbound(x, v, r) {
                return END_ESCAPED;
            }
            (*ray).h *= step_growth((*ray).err);
        }
        if (*ray).steps >= P.max_steps {
            break;
        }
        let x = (*ray).x;
        let p = (*ray).p;
        let r = (*ray).r;
        let speed = length((*ray).v);
        let h = min((*ray).h, MAX_STEP_FRACTION * r / speed);
        let k1 = KRate((*ray).v, (*ray).a, (*ray).rate);
        let st = ks_step(x, p, (*ray).time, k1, h, (*ray).e);
        let rn = ks_radius(st.x);
        var ex = length(st.ex);
        if TRAVEL {
            ex = max(ex, abs(st.et));
        }
        let err = max(ex / (tolerance * max(r, rn)), length(st.ep) / (tolerance * length(p)));
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
        let v0 = (*ray).v;
        let t0 = (*ray).time;
        let rate0 = (*ray).rate;
        (*ray).x = st.x;
        (*ray).p = st.p;
        (*ray).v = st.k.dx;
        (*ray).a = st.k.dp;
        (*ray).rate = st.k.dt;
        (*ray).time = st.t;
        (*ray).r = rn;
        (*ray).pending = true;
        if needs_visit(0.5 * x, 0.5 * st.x) {
            (*ray).seg = Seg(0.5 * x, 0.5 * v0, 0.5 * st.x, 0.5 * st.k.dx, h, true, 0.0, 0.0,
                0.5 * t0, 0.5 * st.t, 0.5 * rate0 * h, 0.5 * st.k.dt * h);
            return EV_VISIT;
        }
    }
    // The steps spent: the loop's one break, which keeps this return
    // reachable (naga wants it; Tint warns of code after a loop that
    // cannot break).
    return END_ABANDONED;
}

// ---- shifts -----------------------------------------------------------------

// ln (nu / E) at the camera's frame for light of L_z / E = b (M units):
// (1 - omega b) / alpha for a ZAMO, 1 / sqrt(1 - f) for a static observer.
fn ks_observer_ln(b: f32) -> f32 {
    let o = P.kerr_observer;
    if o.x != 0.0 {
        return log((1.0 - o.y * b) / o.z);
    }
    return o.w;
}

// ln (nu_emitted / E) of the disk's material at x (M units) for light of
// L_z / E = b: on its circular orbit u^t (1 - Omega b) where one exists
// and `doppler`, else the ZAMO's (1 - omega b) / alpha there.
fn ks_emitter_ln(x: vec3<f32>, b: f32, doppler: bool) -> f32 {
    let a = P.kerr_hole.x;
    let r = ks_radius(x);
    let sr = sqrt(r);
    let r15 = r * sr;
    let root = r15 - 3.0 * sr + 2.0 * a;
    if doppler && r > P.kerr_hole.w && root > 0.0 {
        let ut = (r15 + a) / sqrt(r15 * root);
        return log(ut * (1.0 - b / (r15 + a)));
    }
    let a2 = a * a;
    let delta = ks_delta(r);
    let big_a = (r * r + a2) * (r * r + a2) - a2 * delta;
    let alpha = sqrt(r * r * delta / big_a);
    let omega = 2.0 * a * r / big_a;
    return log((1.0 - omega * b) / alpha);
}

// ln of a static emitter's clock at x (M units), sqrt(1 - f).
fn ks_static_ln(x: vec3<f32>) -> f32 {
    return 0.5 * log(1.0 - ks_f(x, ks_radius(x)));
}
