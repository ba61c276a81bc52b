// Closed-form rays of the exact model: the WGSL twin of
// src/physics/closed.rs in f32 (r_s = 1). A ray's plane, impact parameter
// and orbit give its disk-plane crossings and its direction at infinity
// without integration; see that file for the formulas.


// Carlson's R_F by duplication, to f32 rounding: (3 eps)^(-1/6) = 11.87.
fn carlson_rf(x0: f32, y0: f32, z0: f32) -> f32 {
    var x = x0;
    var y = y0;
    var z = z0;
    let a0 = (x0 + y0 + z0) / 3.0;
    let q = 11.87 * max(max(abs(a0 - x0), abs(a0 - y0)), abs(a0 - z0));
    var a = a0;
    var scale = 1.0;
    // Each round shrinks the spread fourfold: 32 rounds cover q / a < 1e19.
    for (var i = 0u; i < 32u && scale * q >= abs(a); i++) {
        let sx = sqrt(x);
        let sy = sqrt(y);
        let sz = sqrt(z);
        let lambda = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        a = 0.25 * (a + lambda);
        scale *= 0.25;
    }
    return rf_series(a0, x0, y0, scale, a);
}

// R_F's series through the fifth order (DLMF 19.36.1) once the
// duplications have shrunk the arguments' spread about their mean `a` by
// `scale` (a0: their first mean; x0, y0: two of the first arguments).
fn rf_series(a0: f32, x0: f32, y0: f32, scale: f32, a: f32) -> f32 {
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = -(xx + yy);
    let e2 = xx * yy - zz * zz;
    let e3 = xx * yy * zz;
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / sqrt(a);
}

// R_J's series term likewise (DLMF 19.36.2 through the fifth order; a0
// and a: the means with p counted twice, v0: the first x, y, z), without
// the duplications' sum; R_D's with p its distinguished argument.
fn rj_series(a0: f32, v0: vec3<f32>, scale: f32, a: f32) -> f32 {
    let d = (vec3<f32>(a0) - v0) * scale / a;
    let pq = -0.5 * (d.x + d.y + d.z);
    let xyz = d.x * d.y * d.z;
    let e2 = d.x * d.y + d.x * d.z + d.y * d.z - 3.0 * pq * pq;
    let e3 = xyz + 2.0 * e2 * pq + 4.0 * pq * pq * pq;
    let e4 = (2.0 * xyz + e2 * pq + 3.0 * pq * pq * pq) * pq;
    let e5 = xyz * pq * pq;
    let series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0;
    return scale * series / (a * sqrt(a));
}

// Jacobi (sn, cn)(u | m) for m < 1 (m < 0 too, where the means start
// from sqrt(m1) > 1), given m1 = 1 - m (known better than 1 - m next to m
// = 1), by the AGM and the descending Landen recurrence on cn / sn. One sin and one cos: GPU asin is too coarse
// for the AGM's usual backward sweep of amplitudes (lavapipe's cost
// 1e-3 in radius).
fn jacobi_sncn(u: f32, m1: f32) -> vec2<f32> {
    if m1 == 1.0 {
        return vec2<f32>(sin(u), cos(u));
    }
    // A fixed number of AGM rounds (no early exit) keeps the loops
    // unrollable and the arrays in registers: 7 reach f32 rounding for
    // 1 - m down to 1e-12 (the error is about the square of the
    // previous round's relative gap), and rounds past convergence change
    // nothing.
    var em: array<f32, 7>;
    var en: array<f32, 7>;
    var a = 1.0;
    var dn = 1.0;
    var e = m1;
    var c = 1.0;
    for (var i = 0u; i < 7u; i++) {
        em[i] = a;
        e = sqrt(e);
        en[i] = e;
        c = 0.5 * (a + e);
        e *= a;
        a = c;
    }
    let w = u * c;
    var sn = sin(w);
    var cn = cos(w);
    if sn != 0.0 {
        var r = cn / sn;
        c *= r;
        for (var k = 6; k >= 0; k--) {
            let b = em[k];
            r *= c;
            c *= dn;
            dn = (en[k] + r) / (b + r);
            r = c / b;
        }
        let s = inverseSqrt(c * c + 1.0);
        sn = select(-s, s, sn >= 0.0);
        cn = c * sn;
    }
    return vec2<f32>(sn, cn);
}

// physics::closed::roots: u1 < u2 <= u3 of u^3 - u^2 + 1/b^2, b > b_c.
fn orbit_roots(b: f32) -> vec3<f32> {
    let c = 1.0 / (b * b);
    var r: vec3<f32>;
    if c < 1e-3 {
        // Far rays: the small roots are +-sqrt(c / (1 - u)); each round
        // gains a factor sqrt(c) / 2 < 0.016.
        var u1 = -sqrt(c);
        var u2 = sqrt(c);
        for (var i = 0u; i < 6u; i++) {
            u1 = -sqrt(c / (1.0 - u1));
            u2 = sqrt(c / (1.0 - u2));
        }
        r = vec3<f32>(u1, u2, 1.0 - u1 - u2);
    } else {
        let theta = acos(clamp(1.0 - 13.5 * c, -1.0, 1.0)) / 3.0;
        let t = 1.0 / 3.0;
        // theta in [0, pi/3]: these come out in increasing order.
        let lo = t + 2.0 * t * cos(theta + TAU / 3.0);
        let hi = t + 2.0 * t * cos(theta);
        r = vec3<f32>(lo, -c / (lo * hi), hi);
    }
    for (var k = 0u; k < 3u; k++) {
        var u = r[k];
        for (var i = 0u; i < 2u; i++) {
            let f = u * u * (u - 1.0) + c;
            let df = u * (3.0 * u - 2.0);
            if abs(df) > 1e-6 {
                u -= f / df;
            }
        }
        r[k] = u;
    }
    return r;
}

// A ray in closed form (physics::closed::ClosedRay).
const PATH_TURNING: u32 = 0u;
const PATH_INNER: u32 = 1u;
const PATH_PLUNGING: u32 = 2u;

struct Closed {
    ok: bool,
    // PATH_TURNING (b > b_c outside the photon sphere), PATH_INNER (b > b_c
    // inside it), PATH_PLUNGING (b < b_c; `outbound` ones escape).
    kind: u32,
    outbound: bool,
    // Turning, inner: the roots; plunging: (u1, A, 0).
    u: vec3<f32>,
    // Turning, inner: m, K(m), sqrt(u3 - u1) / 2, 1 - m; plunging: m,
    // K(m), sqrt(A), 1 - m.
    k: vec4<f32>,
    // Angle from the turning point (or the root u1) at the start.
    psi0: f32,
    sweep: f32,
    captured: bool,
    e1: vec3<f32>,
    e2: vec3<f32>,
    // The impact parameter.
    b: f32,
}

// Orbit::sweep: the angle between 1/r = y and 1/r = x, y < x <= u2.
fn orbit_sweep(r: vec3<f32>, y: f32, x: f32) -> f32 {
    if x <= y {
        return 0.0;
    }
    let x1 = sqrt(x - r.x);
    let y1 = sqrt(y - r.x);
    let x2 = sqrt(max(r.y - x, 0.0));
    let y2 = sqrt(r.y - y);
    let x3 = sqrt(r.z - x);
    let y3 = sqrt(r.z - y);
    let d = x - y;
    let u12 = (x1 * x2 * y3 + y1 * y2 * x3) / d;
    let u13 = (x1 * x3 * y2 + y1 * y3 * x2) / d;
    let u23 = (x2 * x3 * y1 + y2 * y3 * x1) / d;
    return 2.0 * carlson_rf(u12 * u12, u13 * u13, u23 * u23);
}

// Orbit::inner_sweep: the angle from the inner turning point u3 to u >= u3.
fn inner_sweep(r: vec3<f32>, u: f32) -> f32 {
    if u <= r.z {
        return 0.0;
    }
    let x1 = sqrt(u - r.x);
    let x2 = sqrt(u - r.y);
    let x3 = sqrt(u - r.z);
    let y1 = sqrt(r.z - r.x);
    let y2 = sqrt(r.z - r.y);
    let d = u - r.z;
    let u12 = y1 * y2 * x3 / d;
    let u13 = x1 * x3 * y2 / d;
    let u23 = x2 * x3 * y1 / d;
    return 2.0 * carlson_rf(u12 * u12, u13 * u13, u23 * u23);
}

// Plunge::from_root: the angle from the root u1 to 1/r = u.
fn plunge_from_root(c: Closed, u: f32) -> f32 {
    let a = c.u.y;
    let x = u - c.u.x;
    let cs = (a - x) / (a + x);
    let sn = 2.0 * sqrt(a * x) / (a + x);
    // 1 - m sn^2 = cs^2 + m1 sn^2, exact where m is next to 1.
    let f = sn * carlson_rf(cs * cs, cs * cs + c.k.w * sn * sn, 1.0);
    return select(2.0 * c.k.y - f, f, cs >= 0.0) / c.k.z;
}

// 1/r after sweeping `phi` from the start.
fn closed_u(c: Closed, phi: f32) -> f32 {
    if c.kind == PATH_TURNING {
        let w = jacobi_sncn(c.k.y - abs(c.psi0 + phi) * c.k.z, c.k.w).x;
        return c.u.x + (c.u.y - c.u.x) * w * w;
    }
    if c.kind == PATH_INNER {
        let s = jacobi_sncn(abs(c.psi0 + phi) * c.k.z, c.k.w).x;
        return (c.u.z - c.u.y * s * s) / (1.0 - s * s);
    }
    let psi = select(c.psi0 + phi, c.psi0 - phi, c.outbound);
    let cn = jacobi_sncn(psi * c.k.z, c.k.w).y;
    return c.u.x + c.u.y * (1.0 - cn) / (1.0 + cn);
}

fn closed_point(c: Closed, phi: f32) -> vec3<f32> {
    return (c.e1 * cos(phi) + c.e2 * sin(phi)) / closed_u(c, phi);
}

// ClosedRay::rate: |du/dphi| at 1/r = u, from the orbit's equation
// (du/dphi)^2 = 1/b^2 - u^2 (1 - u).
fn closed_rate(c: Closed, u: f32) -> f32 {
    return sqrt(max(u * u * (u - 1.0) + 1.0 / (c.b * c.b), 0.0));
}

// ClosedRay::tangent: dx/dphi after sweeping `phi` (not unit), du/dphi =
// +-sqrt(u^3 - u^2 + 1/b^2) signed by the orbit's branch
// (ClosedRay::orbit_at).
fn closed_tangent(c: Closed, phi: f32) -> vec3<f32> {
    let u = closed_u(c, phi);
    var rising = !c.outbound;
    if c.kind == PATH_TURNING {
        // u falls away from the turning point either way.
        rising = c.psi0 + phi < 0.0;
    } else if c.kind == PATH_INNER {
        // u grows away from the inner turning point.
        rising = c.psi0 + phi > 0.0;
    }
    let rate = closed_rate(c, u);
    let du = select(-rate, rate, rising);
    let p = c.e1 * cos(phi) + c.e2 * sin(phi);
    let d = c.e2 * cos(phi) - c.e1 * sin(phi);
    return (d - p * (du / u)) / u;
}

// ClosedRay::segments: where a captured ray's segments end, just outside
// the horizon (HORIZON_MARGIN of r_s), as a medium's integrated rays do.
fn closed_segments_end(c: Closed) -> f32 {
    let u_end = 1.0 / (1.0 + HORIZON_MARGIN);
    var end = c.sweep;
    if c.captured && c.kind == PATH_INNER {
        end = inner_sweep(c.u, u_end) - c.psi0;
    } else if c.captured && c.kind == PATH_PLUNGING {
        end = plunge_from_root(c, u_end) - c.psi0;
    }
    return min(end, c.sweep);
}

// ClosedRay::new from the start `x` and coordinate velocity `v`; ok is
// false where the integrator must take the ray (b next to b_c).
fn closed_ray(x: vec3<f32>, v: vec3<f32>) -> Closed {
    var c: Closed;
    c.ok = false;
    let r = safe_length(x);
    let h2 = dot(cross(x, v), cross(x, v));
    let v_inf2 = dot(v, v) - h2 / (r * r * r);
    if !(h2 > 0.0 && v_inf2 > 0.0 && r > 1.0) {
        return c;
    }
    // A camera ray's b from its image point (set by main), else from the
    // state, whose cross product loses it far away.
    var b = exact_b;
    if b < 0.0 {
        b = sqrt(h2 / v_inf2);
    }
    let u = 1.0 / r;
    let inbound = dot(x, v) < 0.0;
    // Next to b_c the split between the two forms is left to the
    // integrator, as on the CPU (f32 needs the wider margin).
    if b > B_CRIT * (1.0 + 1e-5) {
        let roots = orbit_roots(b);
        let m = (roots.y - roots.x) / (roots.z - roots.x);
        let m1 = (roots.z - roots.y) / (roots.z - roots.x);
        c.u = roots;
        c.k = vec4<f32>(m, carlson_rf(0.0, m1, 1.0), 0.5 * sqrt(roots.z - roots.x), m1);
        if u >= roots.z {
            // Inside the photon sphere: into the hole, after turning at
            // 1/u3 if it starts outbound.
            let from_turn = inner_sweep(roots, u);
            c.kind = PATH_INNER;
            c.psi0 = select(-from_turn, from_turn, inbound);
            c.sweep = inner_sweep(roots, 1.0) - c.psi0;
            c.captured = true;
        } else if !(u <= roots.y) {
            return c;
        } else {
            c.kind = PATH_TURNING;
            let to_turn = orbit_sweep(roots, u, roots.y);
            if inbound {
                c.psi0 = -to_turn;
                c.sweep = to_turn + orbit_sweep(roots, 0.0, roots.y);
            } else {
                c.psi0 = to_turn;
                c.sweep = orbit_sweep(roots, 0.0, u);
            }
            c.captured = false;
        }
    } else if b < B_CRIT * (1.0 - 1e-5) {
        let cc = 1.0 / (b * b);
        let q = cc - 2.0 / 27.0;
        let d = sqrt(max(0.25 * q * q - 1.0 / 729.0, 0.0));
        // Real cube roots of signed values.
        let s1 = -0.5 * q + d;
        let s2 = -0.5 * q - d;
        var u1 = sign(s1) * pow(abs(s1), 1.0 / 3.0) + sign(s2) * pow(abs(s2), 1.0 / 3.0) + 1.0 / 3.0;
        for (var i = 0u; i < 3u; i++) {
            let f = u1 * u1 * (u1 - 1.0) + cc;
            let df = u1 * (3.0 * u1 - 2.0);
            if abs(df) > 1e-6 {
                u1 -= f / df;
            }
        }
        let p = 0.5 * (1.0 - u1);
        let q2 = max(-cc / u1 - p * p, 0.0);
        let a = sqrt((p - u1) * (p - u1) + q2);
        // 1 - m = (A - (p - u1)) / 2A without the cancellation.
        let m1 = max(q2 / (a + p - u1) / (2.0 * a), 1e-30);
        let m = (a + p - u1) / (2.0 * a);
        c.kind = PATH_PLUNGING;
        c.outbound = !inbound;
        c.u = vec3<f32>(u1, a, 0.0);
        c.k = vec4<f32>(m, carlson_rf(0.0, m1, 1.0), sqrt(a), m1);
        c.psi0 = plunge_from_root(c, u);
        if inbound {
            c.sweep = plunge_from_root(c, 1.0) - c.psi0;
        } else {
            c.sweep = c.psi0 - plunge_from_root(c, 0.0);
        }
        c.captured = inbound;
    } else {
        return c;
    }
    c.b = b;
    c.e1 = x / r;
    if exact_b >= 0.0 {
        // The camera's ray: its plane from the exact angular momentum.
        c.e2 = normalize(cross(exact_l, c.e1));
    } else {
        c.e2 = normalize(v - c.e1 * dot(v, c.e1));
    }
    c.ok = true;
    return c;
}

// The angle of the ray's first crossing of z = 0 after its start (later
// ones follow every pi), or a negative value when it lies in that plane.
fn closed_first_crossing(c: Closed) -> f32 {
    let a = c.e1.z;
    let s = c.e2.z;
    if abs(a) < 1e-30 && abs(s) < 1e-30 {
        return -1.0;
    }
    let t = atan2(-a, s);
    var first = t - PI * floor(t / PI);
    // A start on the plane is not a crossing.
    if first <= 1e-6 {
        first += PI;
    }
    return first;
}
