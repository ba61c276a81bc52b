// Schwarzschild footprints from the closed form's own derivatives (the
// FOOTPRINT variants): the twin of Integrator::planar_footprint
// (src/cpu/footprint.rs) and of src/physics/closed/variation.rs, for a
// camera at rest whose rays start exactly from their image points
// (set_exact_ray). The pixel moves the ray's impact parameter and turns
// its plane about the camera's radial axis, both read off the image
// point's geometry; the orbit's derivatives in c = 1/b^2 are R_F's
// gradient (three R_D) along its roots'. No difference of neighbouring
// rays, so no f32 cancellation: what a GPU's transcendental functions err
// by stays relative to the derivative.

// R_F(x, y, z) and its gradient (-R_D with each argument distinguished,
// / 6: DLMF 19.18.1) from one duplication sequence, to f32 rounding.
// Zero arguments give huge (unused) slopes, never a division by zero.
fn carlson_rf_grad(x0: f32, y0: f32, z0: f32) -> vec4<f32> {
    let v0 = vec3<f32>(x0, y0, z0);
    var v = v0;
    let mean = (x0 + y0 + z0) / 3.0;
    let am0 = (vec3<f32>(x0 + y0 + z0) + 2.0 * v0) / 5.0;
    // The fifth-order series of both integrals hold to f32 rounding once
    // the spread is below 1/17.96 of the mean ((eps / 4)^(-1/6), R_J's
    // bound, the stricter; kc_carlson's).
    var spread = max(max(abs(mean - x0), abs(mean - y0)), abs(mean - z0));
    for (var i = 0u; i < 3u; i++) {
        spread = max(spread, max(max(abs(am0[i] - x0), abs(am0[i] - y0)), abs(am0[i] - z0)));
    }
    let q = 17.96 * spread;
    var af = mean;
    var am = am0;
    var scale = 1.0;
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < 32u && scale * q >= min(abs(af), min(min(abs(am.x), abs(am.y)), abs(am.z))); i++) {
        let s = sqrt(v);
        let lambda = s.x * s.y + s.x * s.z + s.y * s.z;
        sum += scale / max(s * (v + lambda), vec3<f32>(1e-30));
        v = 0.25 * (v + vec3<f32>(lambda));
        am = 0.25 * (am + vec3<f32>(lambda));
        af = 0.25 * (af + lambda);
        scale *= 0.25;
    }
    let rf = rf_series(mean, x0, y0, scale, af);
    var g: vec3<f32>;
    for (var i = 0u; i < 3u; i++) {
        // R_D is R_J with its distinguished argument as p.
        g[i] = -(rj_series(am0[i], v0, scale, am[i]) + 3.0 * sum[i]) / 6.0;
    }
    return vec4<f32>(rf, g);
}

// R_F of `v` and its derivative along `dv`.
fn rf_rate(v: vec3<f32>, dv: vec3<f32>) -> vec2<f32> {
    let g = carlson_rf_grad(v.x, v.y, v.z);
    return vec2<f32>(g.x, dot(g.yzw, dv));
}

// du/dc of a root u of u^3 - u^2 + c.
fn root_rate(u: f32) -> f32 {
    return -1.0 / (u * (3.0 * u - 2.0));
}

// Orbit::turn_rates: for 1/r = y <= u2, dG/dc and sqrt(P(y)) dG/dc of the
// angle G from y to the turning point.
fn turn_rates(r: vec3<f32>, y: f32, d: vec3<f32>) -> vec2<f32> {
    let v = vec3<f32>((y - r.x) * (r.z - r.y), (r.y - r.x) * (r.z - r.y), (r.z - y) * (r.y - r.x));
    let dv = vec3<f32>(
        -d.x * (r.z - r.y) + (y - r.x) * (d.z - d.y),
        (d.y - d.x) * (r.z - r.y) + (r.y - r.x) * (d.z - d.y),
        d.z * (r.y - r.x) + (r.z - y) * (d.y - d.x),
    );
    return angle_rates(v, dv, vec2<f32>(max(r.y - y, 0.0), d.y), (y - r.x) * (r.z - y));
}

// variation.rs's angle_rates: for an angle 2 sqrt(w) R_F(v) from a
// turning point at distance w whose rate in c is wd.y (wd = (w, dw)),
// R_F's arguments moving by dv: its rate and its rate times sqrt(w other).
fn angle_rates(v: vec3<f32>, dv: vec3<f32>, wd: vec2<f32>, other: f32) -> vec2<f32> {
    let f = rf_rate(v, dv);
    let core = wd.y * f.x + 2.0 * wd.x * f.y;
    return vec2<f32>(core / sqrt(wd.x), core * sqrt(max(other, 0.0)));
}

// Orbit::inner_rates: for 1/r = u >= u3, dH/dc and sqrt(P(u)) dH/dc of
// the angle H from the inner turning point to u.
fn inner_rates(r: vec3<f32>, u: f32, d: vec3<f32>) -> vec2<f32> {
    let v = vec3<f32>((r.z - r.x) * (r.z - r.y), (u - r.x) * (r.z - r.y), (u - r.y) * (r.z - r.x));
    let dv = vec3<f32>(
        (d.z - d.x) * (r.z - r.y) + (r.z - r.x) * (d.z - d.y),
        -d.x * (r.z - r.y) + (u - r.x) * (d.z - d.y),
        -d.y * (r.z - r.x) + (u - r.y) * (d.z - d.x),
    );
    return angle_rates(v, dv, vec2<f32>(max(u - r.z, 0.0), -d.z), (u - r.x) * (u - r.y));
}

// Plunge::rates: d/dc of the plunging orbit's root u1, A, m and K(m), for
// c = 1/b^2 (`cc`).
fn plunge_rates(c: Closed, cc: f32) -> vec4<f32> {
    let u1 = c.u.x;
    let a = c.u.y;
    let du1 = root_rate(u1);
    let p = 0.5 * (1.0 - u1);
    let dp = -0.5 * du1;
    let dq2 = -1.0 / u1 + cc * du1 / (u1 * u1) - 2.0 * p * dp;
    let da = ((p - u1) * (dp - du1) + 0.5 * dq2) / a;
    let dm = ((dp - du1) * a - (p - u1) * da) / (2.0 * a * a);
    // K = R_F(0, 1 - m, 1): its slope in the second argument.
    let dk = -carlson_rf_grad(0.0, c.k.w, 1.0).z * dm;
    return vec4<f32>(du1, da, dm, dk);
}

// Plunge::root_angle_rate: d/dc at fixed u of the angle from the root u1
// (plunge_from_root), with k = plunge_rates.
fn plunge_angle_rate(c: Closed, u: f32, k: vec4<f32>) -> f32 {
    let a = c.u.y;
    let x = u - c.u.x;
    let dx = -k.x;
    let cs = (a - x) / (a + x);
    let sn = 2.0 * sqrt(a * x) / (a + x);
    let dcs = 2.0 * (k.y * x - a * dx) / ((a + x) * (a + x));
    let dsn = sn * (0.5 * (k.y / a + dx / x) - (k.y + dx) / (a + x));
    // 1 - m sn^2 = cs^2 + m1 sn^2 (as plunge_from_root).
    let v = vec3<f32>(cs * cs, cs * cs + c.k.w * sn * sn, 1.0);
    let dv = vec3<f32>(2.0 * cs * dcs, -k.z * sn * sn - 2.0 * c.k.x * sn * dsn, 0.0);
    let rr = rf_rate(v, dv);
    var f = sn * rr.x;
    var df = dsn * rr.x + sn * rr.y;
    if cs < 0.0 {
        f = 2.0 * c.k.y - f;
        df = 2.0 * k.w - df;
    }
    return df / c.k.z - 0.5 * f * k.y / (a * c.k.z);
}

// ClosedRay::rates for the ray `c` from 1/r = u0 with impact parameter b:
// (d psi0/dc, d sweep/dc); and the plunging orbit's own rates.
struct ClosedRates {
    dpsi0: f32,
    dsweep: f32,
    droots: vec3<f32>,
    plunge: vec4<f32>,
}

fn closed_rates(c: Closed, u0: f32, b: f32) -> ClosedRates {
    var k: ClosedRates;
    k.dsweep = 0.0;
    k.plunge = vec4<f32>(0.0);
    if c.kind == PATH_PLUNGING {
        k.droots = vec3<f32>(0.0);
        k.plunge = plunge_rates(c, 1.0 / (b * b));
        k.dpsi0 = plunge_angle_rate(c, u0, k.plunge);
        if c.outbound {
            k.dsweep = k.dpsi0 - plunge_angle_rate(c, 0.0, k.plunge);
        }
        return k;
    }
    k.droots = vec3<f32>(root_rate(c.u.x), root_rate(c.u.y), root_rate(c.u.z));
    if c.kind == PATH_INNER {
        let h0 = inner_rates(c.u, u0, k.droots).x;
        k.dpsi0 = select(-h0, h0, c.psi0 > 0.0);
        return k;
    }
    let g0 = turn_rates(c.u, u0, k.droots).x;
    k.dpsi0 = select(g0, -g0, c.psi0 < 0.0);
    k.dsweep = turn_rates(c.u, 0.0, k.droots).x - k.dpsi0;
    return k;
}

// ClosedRay::orbit_at: du/dphi where 1/r is u after sweeping phi (its
// size from the orbit's equation, its sign from the branch).
fn closed_du(c: Closed, phi: f32, u: f32, b: f32) -> f32 {
    let rate = sqrt(max(u * u * (u - 1.0) + 1.0 / (b * b), 0.0));
    var rising: bool;
    if c.kind == PATH_TURNING {
        rising = c.psi0 + phi < 0.0;
    } else if c.kind == PATH_INNER {
        rising = c.psi0 + phi > 0.0;
    } else {
        rising = !c.outbound;
    }
    return select(-rate, rate, rising);
}

// ClosedRay::du_dc: du/dc at fixed angle where 1/r is u, du/dphi du.
fn closed_du_dc(c: Closed, k: ClosedRates, u: f32, du: f32) -> f32 {
    if c.kind == PATH_TURNING {
        return turn_rates(c.u, u, k.droots).y + du * k.dpsi0;
    }
    if c.kind == PATH_INNER {
        return du * k.dpsi0 - inner_rates(c.u, u, k.droots).y;
    }
    return abs(du) * (k.dpsi0 - plunge_angle_rate(c, u, k.plunge));
}

// Beyond this impact parameter (r_s) the derivatives in c = 1/b^2 leave
// f32's range (they grow as b^3): such rays, nearly straight, take their
// neighbours' differences.
const FP_CLOSED_MAX_B: f32 = 1e4;

// Integrator::planar_footprint of the sample at image point (px, py): fills fp
// and says true, or says false where it does not apply (no exact start,
// or b past FP_CLOSED_MAX_B) and leaves fp to the neighbours.
fn closed_footprint(px: f32, py: f32) -> bool {
    let s = image_point(px, py);
    set_exact_ray(s);
    if exact_b < 0.0 || exact_b > FP_CLOSED_MAX_B {
        return false;
    }
    let b = exact_b;
    let x = P.cam_pos.xyz;
    let c = closed_ray(x, camera_direction(px, py));
    if !c.ok {
        // Next to the critical curve: no footprint, as on the CPU.
        return true;
    }
    // The image point's geometry (camera axes: forward, right, up): the
    // ray's direction A and the hole's B, L = A x B without cancellation
    // (set_exact_ray). Per pixel A moves by dA; the angle between A and B
    // by dA . (A x L^) / |A|^2, and the plane turns about the radial axis
    // by dA . L^ |B| / |L| (signed by the axes' handedness).
    let hole = P.cam_hole.xy;
    let a = vec3<f32>(1.0, s.x, s.y);
    let bb = vec3<f32>(1.0, hole.x, hole.y);
    let l0 = vec3<f32>(s.x * hole.y - s.y * hole.x, s.y - hole.y, hole.x - s.x);
    let big = max(abs(l0.x), max(abs(l0.y), abs(l0.z)));
    let ln = normalize(l0 / big);
    let l_len = length(l0 / big) * big;
    let r = safe_length(x);
    let cos_a = dot(a, bb) / (length(a) * length(bb));
    // d b / d angle (camera_impact's slope).
    let db_dangle = r * cos_a / sqrt(1.0 - 1.0 / r);
    let across = cross(a, ln) / dot(a, a);
    let turn = ln * (length(bb) / l_len * P.cam_hole.w);
    var motion: array<vec2<f32>, 2>;
    let step = vec2<f32>(2.0 * P.cam_half_width / f32(P.width), -2.0 * P.cam_half_height / f32(P.height));
    let da_x = vec3<f32>(0.0, step.x, 0.0);
    let da_y = vec3<f32>(0.0, 0.0, step.y);
    motion[0] = vec2<f32>(dot(da_x, across) * db_dangle, dot(da_x, turn));
    motion[1] = vec2<f32>(dot(da_y, across) * db_dangle, dot(da_y, turn));
    fp.ok = true;
    fp.pixel_sr = pixel_solid_angle(px, py);
    let k = closed_rates(c, 1.0 / r, b);
    let dc_db = -2.0 / (b * b * b);
    let e1 = c.e1;
    let n = cross(c.e1, c.e2);
    if !c.captured {
        let d = c.e1 * cos(c.sweep) + c.e2 * sin(c.sweep);
        let by_b = cross(n, d) * (k.dsweep * dc_db);
        fp.sky_ok = true;
        fp.sky = d;
        fp.sky_dx = by_b * motion[0].x + cross(e1, d) * motion[0].y;
        fp.sky_dy = by_b * motion[1].x + cross(e1, d) * motion[1].y;
    }
    let first = closed_first_crossing(c);
    let eye = P.cam_pos.xyz;
    for (var i = 0u; P.disk_kind != DISK_NONE && first >= 0.0 && i < FP_CROSSINGS; i++) {
        let phi = first + f32(i) * PI;
        if phi >= c.sweep {
            break;
        }
        let u = closed_u(c, phi);
        let dir = c.e1 * cos(phi) + c.e2 * sin(phi);
        let p = dir / u;
        let rho = length(p.xy);
        if rho < P.disk_inner || rho > P.disk_outer {
            continue;
        }
        let du = closed_du(c, phi, u, b);
        let by_b = -p * (closed_du_dc(c, k, u, du) * dc_db / u);
        // The tangent, to slide back onto z = 0 after the plane turns.
        let t = (c.e2 * cos(phi) - c.e1 * sin(phi) - p * du) / u;
        var dq: array<vec2<f32>, 2>;
        for (var j = 0u; j < 2u; j++) {
            let m = motion[j];
            let moved = by_b * m.x + cross(e1, p) * m.y;
            let on = moved - t * (moved.z / t.z);
            dq[j] = on.xy;
            if P.rotation != ROTATION_NONE && P.time != 0.0 {
                // The disk's rotation turns rings by their own angles: its
                // derivative over a hundredth of the ring's radius.
                let h = 0.01 * rho / max(length(on.xy), 1e-30);
                dq[j] = (unturn_plane(p.xy + on.xy * h, P.time) - unturn_plane(p.xy - on.xy * h, P.time)) / (2.0 * h);
            }
        }
        let o = fp.n;
        fp.order[o] = i;
        fp.q[o] = unturn_plane(p.xy, P.time);
        fp.q_dx[o] = dq[0];
        fp.q_dy[o] = dq[1];
        fp.magnification[o] = fp_disk_magnification(fp.pixel_sr, p - eye, dq[0], dq[1]);
        fp.n = o + 1u;
    }
    return true;
}
