// Kerr rays in closed form: the WGSL twin of src/physics/kerr/closed/
// (roots.rs, radial.rs, times.rs, polar.rs, ray.rs) in f32 (M = 1). The
// camera's constants come from its image point through the host's f64
// linear forms (Params.kerr_rays), not from an f32 state, which a far
// camera's cancellation would spoil; see those files for the formulas.


// R_C(1, 1 + e) in closed form (its series near 0).
fn kc_rc_one(e: f32) -> f32 {
    if abs(e) < 1e-2 {
        // The next term, e^4 / 9, is below f32's rounding.
        return 1.0 + e * (-1.0 / 3.0 + e * (0.2 - e / 7.0));
    }
    if e > 0.0 {
        let s = sqrt(e);
        return atan(s) / s;
    }
    let s = sqrt(-e);
    return atanh(s) / s;
}

// R_F(x, y, z) and R_J(x, y, z, p_i) for two p_i from one duplication
// sequence (elliptic::carlson_fj), p_i < 0 by Carlson's transformation to
// a positive q; NaN where they diverge. Bounds (3 eps)^(-1/6) = 11.87 and
// (eps / 4)^(-1/6) = 17.96 for f32.
fn kc_carlson(x0: f32, y0: f32, z0: f32, p: vec2<f32>) -> vec3<f32> {
    let lo = min(min(x0, y0), z0);
    let hi = max(max(x0, y0), z0);
    let mid = x0 + y0 + z0 - lo - hi;
    var q = p;
    for (var i = 0; i < 2; i++) {
        if p[i] < 0.0 {
            q[i] = mid + (hi - mid) * (mid - lo) / (mid - p[i]);
        }
    }
    var x = x0;
    var y = y0;
    var z = z0;
    var pp = q;
    let a0f = (x0 + y0 + z0) / 3.0;
    let a0j = (vec2<f32>(x0 + y0 + z0) + 2.0 * q) / 5.0;
    let delta = (q - x0) * (q - y0) * (q - z0);
    let qf = 11.87 * max(max(abs(a0f - x0), abs(a0f - y0)), abs(a0f - z0));
    var qj: vec2<f32>;
    for (var i = 0; i < 2; i++) {
        qj[i] = 17.96 * max(max(max(abs(a0j[i] - x0), abs(a0j[i] - y0)), abs(a0j[i] - z0)), abs(a0j[i] - q[i]));
    }
    var af = a0f;
    var aj = a0j;
    var scale = 1.0;
    var sum = vec2<f32>(0.0);
    var done = false;
    // Each round shrinks the spread fourfold: 16 cover 4e9.
    for (var round = 0; round < 16; round++) {
        if scale * qf < abs(af) && scale * qj.x < abs(aj.x) && scale * qj.y < abs(aj.y) {
            done = true;
            break;
        }
        let sx = sqrt(x);
        let sy = sqrt(y);
        let sz = sqrt(z);
        let lambda = sx * sy + sx * sz + sy * sz;
        for (var i = 0; i < 2; i++) {
            let sp = sqrt(pp[i]);
            let d = (sp + sx) * (sp + sy) * (sp + sz);
            let e = delta[i] * scale * scale * scale / (d * d);
            sum[i] += scale * kc_rc_one(e) / d;
        }
        pp = 0.25 * (pp + lambda);
        aj = 0.25 * (aj + lambda);
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        af = 0.25 * (af + lambda);
        scale *= 0.25;
    }
    if !done {
        // Diverged (two arguments 0): a value the ray's checks refuse.
        return vec3<f32>(3.4e38);
    }
    let rf = rf_series(a0f, x0, y0, scale, af);
    var out = vec3<f32>(rf, 0.0, 0.0);
    for (var i = 0; i < 2; i++) {
        var rj = rj_series(a0j[i], vec3<f32>(x0, y0, z0), scale, aj[i]) + 6.0 * sum[i];
        if p[i] < 0.0 {
            // (mid - p) R_J(p) = (q - mid) R_J(q) - 3 R_F + 3 R_C(lo hi / mid, p q / mid).
            let cx = lo * hi / mid;
            let cy = p[i] * q[i] / mid;
            // R_C(x, y) for y < 0: sqrt(x / (x - y)) R_C(x - y, -y), and
            // R_C(x, y) = atan(sqrt((x - y) / y)) / sqrt(x - y) for x < y,
            // atanh(sqrt((x - y) / x)) / sqrt(x - y) for x > y.
            let u = cx - cy;
            let v = -cy;
            var rc: f32;
            if u < v {
                rc = atan(sqrt((v - u) / u)) / sqrt(v - u);
            } else if u > v {
                rc = atanh(sqrt((u - v) / u)) / sqrt(u - v);
            } else {
                rc = 1.0 / sqrt(u);
            }
            rc *= sqrt(cx / u);
            rj = ((q[i] - mid) * rj - 3.0 * rf + 3.0 * rc) / (mid - p[i]);
        }
        out[i + 1] = rj;
    }
    return out;
}

// Legendre's F(phi | m) and Pi(n_i; phi | m) at the amplitude of sine s and
// cosine c >= 0.
fn kc_f_pi(s: f32, c: f32, m: f32, n: vec2<f32>) -> vec3<f32> {
    let r = kc_f_j(s, c, m, n);
    return vec3<f32>(r.x, r.x + n * r.yz);
}

// F and J_i = (Pi(n_i) - F) / n_i (legendre_f_j): J at n = 0 is D.
fn kc_f_j(s: f32, c: f32, m: f32, n: vec2<f32>) -> vec3<f32> {
    let r = kc_carlson(c * c, 1.0 - m * s * s, 1.0, vec2<f32>(1.0) - n * s * s);
    let s3 = s * s * s / 3.0;
    return vec3<f32>(s * r.x, s3 * r.yz);
}

// Bulirsch's cel(kc, p, 1, 1): K(m) at p = 1, Pi(n | m) at p = 1 - n (the
// principal value for p < 0).
fn kc_cel(kc0: f32, p0: f32) -> f32 {
    return kc_cel_ab(kc0, p0, 1.0, 1.0);
}

// Bulirsch's cel(kc, p, a, b) (D(m) at p = 1, a = 0, b = 1).
fn kc_cel_ab(kc0: f32, p0: f32, a0: f32, b0: f32) -> f32 {
    var kc = abs(kc0);
    var a = a0;
    var b = b0;
    var p = p0;
    var e = kc;
    var mu = 1.0;
    if p > 0.0 {
        p = sqrt(p);
        b /= p;
    } else {
        let k2 = kc * kc;
        let f = k2 - p;
        let g = 1.0 - p;
        let q = (1.0 - k2) * (b - a * p);
        p = sqrt(f / g);
        a = (a - b) / g;
        b = -q / (g * g * p) + a * p;
    }
    for (var i = 0; i < 10; i++) {
        let f = a;
        a += b / p;
        let g = e / p;
        b = 2.0 * (b + f * g);
        p += g;
        let mu_last = mu;
        mu += kc;
        if abs(mu_last - kc) <= 3e-4 * mu_last {
            break;
        }
        kc = 2.0 * sqrt(e);
        e = kc * mu;
    }
    return 0.5 * PI * (b + a * mu) / (mu * (mu + p));
}

// Newton's method on R = r^4 + A r^2 + B r + C from a real estimate.
fn kc_polish(c: vec3<f32>, x0: f32) -> f32 {
    var x = x0;
    var f = ((x * x + c.x) * x + c.y) * x + c.z;
    for (var i = 0; i < 4; i++) {
        let df = (4.0 * x * x + 2.0 * c.x) * x + c.y;
        let nx = x - f / df;
        let nf = ((nx * nx + c.x) * nx + c.y) * nx + c.z;
        if !(abs(nf) < abs(f)) {
            break;
        }
        x = nx;
        f = nf;
    }
    return x;
}

// A Kerr ray in closed form (physics::kerr_closed::KerrRay).
const KC_OUTER: u32 = 0u;
const KC_PAIR: u32 = 1u;
// Two complex pairs: roots = (s1, s2, sqrt c1, sqrt d1); per pole linear,
// third, alpha, cc, dd hold Radial::Quad's lin, pi, odd, sqrt G, sqrt H.
const KC_QUAD: u32 = 2u;

struct KerrClosed {
    ok: bool,
    captured: bool,
    kind: u32,
    // Outer: r3, r4, r31, r41; pair: r1, r2, A, B.
    roots: vec4<f32>,
    // Per pole (r_+, r_-): n, linear, third; pair also alpha, c, d.
    n: vec2<f32>,
    linear: vec2<f32>,
    third: vec2<f32>,
    alpha: vec2<f32>,
    cc: vec2<f32>,
    dd: vec2<f32>,
    // k, kappa, K(k), and the pair's complete Pi at its two n.
    k: f32,
    kappa: f32,
    big_k: f32,
    pi_c: vec2<f32>,
    // KC_QUAD: theta at infinity, and the odd part's log at theta = 0.
    theta_inf: f32,
    l1: vec2<f32>,
    u0: f32,
    dir: f32,
    s_end: f32,
    coef: vec2<f32>,
    pole0: vec2<f32>,
    pole_end: vec2<f32>,
    // Polar: u_+, m, its Pi's characteristic, scale, psi0, K(m), Pi(n | m),
    // Pi at psi0, the factor of the 1/sin^2 integral; vortical motion:
    // u_- (< 0 for ordinary motion) and the hemisphere.
    u_plus: f32,
    pm: f32,
    pn: f32,
    g_scale: f32,
    u_minus: f32,
    hemisphere: f32,
    pscale: f32,
    psi0: f32,
    pk: f32,
    ppi_c: f32,
    ppi0: f32,
    phi0: f32,
    lambda: f32,
    energy_sign: f32,
    // With TRAVEL (KerrRay's time): the pole at infinity, (N, r4 - r3) for
    // four real roots, (n, alpha, c, d) for one pair; the pair's r = r0 +
    // r1 / (1 + alpha cn) as (r0, r1) and its complete D and Pi there; the
    // time's horizon-pole coefficients; kappa times its radial integral at
    // the start; the polar D(m) and D(am psi0).
    t_inf: vec4<f32>,
    t_lin: vec2<f32>,
    t_c: vec2<f32>,
    tcoef: vec2<f32>,
    time0: f32,
    pd: vec2<f32>,
    // A camera ray's L_z / E (kerr_camera_ray).
    lz_over_e: f32,
    // Carter's eta, and the sign of dr/ds before and after Mino time
    // `turn` (KerrRay's radial_signs): the ray's state at any time.
    eta: f32,
    r_signs: vec2<f32>,
    turn: f32,
}

// An amplitude as (sn, cn, whole half turns before it) (Amp).
fn kc_angle(theta: f32) -> vec3<f32> {
    let j = round(theta / PI);
    let t = theta - j * PI;
    return vec3<f32>(sin(t), cos(t), j);
}

fn kc_sn_cn(c: KerrClosed, r: f32) -> vec3<f32> {
    let g = c.roots;
    if c.kind == KC_OUTER {
        let s2 = clamp((r - g.y) * g.z / ((r - g.x) * g.w), 0.0, 1.0);
        return vec3<f32>(sqrt(s2), sqrt(1.0 - s2), 0.0);
    }
    if c.kind == KC_QUAD {
        // On the branch through theta at infinity.
        let raw = atan2((r - g.x) * g.z, (r - g.y) * g.w);
        var d = raw - c.theta_inf + PI;
        d = d - TAU * floor(d / TAU) - PI;
        return kc_angle(c.theta_inf + d);
    }
    let p = g.z * (r - g.x);
    let q = g.w * (r - g.y);
    let cn = clamp((p - q) / (p + q), -1.0, 1.0);
    return vec3<f32>(sqrt(1.0 - cn * cn), cn, 0.0);
}

fn kc_sn_cn_inf(c: KerrClosed) -> vec3<f32> {
    let g = c.roots;
    if c.kind == KC_OUTER {
        return vec3<f32>(sqrt(g.z / g.w), sqrt((g.w - g.z) / g.w), 0.0);
    }
    if c.kind == KC_QUAD {
        return kc_angle(c.theta_inf);
    }
    let cn = (g.z - g.w) / (g.z + g.w);
    return vec3<f32>(sqrt(1.0 - cn * cn), cn, 0.0);
}

fn kc_radius(c: KerrClosed, sc: vec3<f32>) -> f32 {
    let g = c.roots;
    if c.kind == KC_OUTER {
        let s2 = sc.x * sc.x;
        return (g.y * g.z - g.x * g.w * s2) / (g.z - g.w * s2);
    }
    if c.kind == KC_QUAD {
        return (g.x * sc.y * g.z - g.y * sc.x * g.w) / (sc.y * g.z - sc.x * g.w);
    }
    return ((g.w * g.y - g.z * g.x) + (g.w * g.y + g.z * g.x) * sc.y)
        / ((g.w - g.z) + (g.w + g.z) * sc.y);
}

// The one-pair form's odd part: the integral of dw / (c + d w^2) in w = sn
// / dn (minus atanh, its principal value past the pole, for c < 0).
fn kc_odd(w: f32, cc: f32, dd: f32) -> f32 {
    if cc > 0.0 {
        return atan(w * sqrt(dd / cc)) / sqrt(cc * dd);
    }
    let z = w * sqrt(dd / -cc);
    return -0.5 * log(abs((1.0 + z) / (1.0 - z))) / sqrt(-cc * dd);
}

// U at the amplitude (sn, cn) and the two pole integrals (Radial::at).
fn kc_at(c: KerrClosed, sc: vec3<f32>, poles: bool) -> vec3<f32> {
    if c.kind == KC_QUAD {
        let f = kc_f_pi(sc.x, sc.y, c.k, c.n);
        let u = f.x + 2.0 * sc.z * c.big_k;
        if !poles {
            return vec3<f32>(u, 0.0, 0.0);
        }
        let dn = sqrt(1.0 - c.k * sc.x * sc.x);
        let big_pi = f.yz + 2.0 * sc.z * c.pi_c;
        let lg = log(abs((c.cc * dn - c.dd) / (c.cc * dn + c.dd)));
        return vec3<f32>(u, c.linear * u + c.third * big_pi + c.alpha * (lg - c.l1));
    }
    if c.kind == KC_OUTER {
        let f = kc_f_pi(sc.x, sc.y, c.k, c.n);
        if !poles {
            return vec3<f32>(f.x, 0.0, 0.0);
        }
        return vec3<f32>(f.x, f.x * c.linear + c.third * f.yz);
    }
    var f = kc_f_pi(sc.x, abs(sc.y), c.k, c.n);
    if sc.y < 0.0 {
        f = vec3<f32>(2.0 * c.big_k, 2.0 * c.pi_c) - f;
    }
    if !poles {
        return vec3<f32>(f.x, 0.0, 0.0);
    }
    let w = sc.x / sqrt(1.0 - c.k * sc.x * sc.x);
    var out = vec3<f32>(f.x, 0.0, 0.0);
    for (var i = 0; i < 2; i++) {
        let odd = kc_odd(w, c.cc[i], c.dd[i]);
        out[i + 1] = c.linear[i] * f.x + c.third[i] * (f[i + 1] / c.cc[i] - c.alpha[i] * odd);
    }
    return out;
}

// The Kerr-Schild azimuth's radial term a ln((r - r_+) / (r - r_-)) / (r_+ -
// r_-).
fn kc_ks_term(r: f32) -> f32 {
    let h = P.kerr_hole;
    if h.x == 0.0 {
        return 0.0;
    }
    return h.x / (h.y - h.z) * log((r - h.y) / (r - h.z));
}

// PolarMotion::new with Polar's scales: u_+, u_-, m, n, the Mino time's
// scale and the 1/sin^2 integral's factor (false where no motion is).
fn kc_polar_motion(c: ptr<function, KerrClosed>, a: f32, lambda: f32, eta: f32, cos0: f32) -> bool {
    let half = 0.5 * (a * a - eta - lambda * lambda);
    let disc = half * half + eta * a * a;
    if eta > 0.0 {
        let a2_um = half - sqrt(disc);
        (*c).u_plus = -eta / a2_um;
        (*c).pm = (*c).u_plus * a * a / a2_um;
        (*c).pn = (*c).u_plus;
        (*c).pscale = sqrt(-a2_um);
        (*c).g_scale = 1.0 / (*c).pscale;
        (*c).u_minus = -1.0;
    } else {
        if !(half > 0.0 && disc >= 0.0) {
            return false;
        }
        let a2_up = half + sqrt(disc);
        (*c).u_plus = a2_up / (a * a);
        (*c).u_minus = -eta / a2_up;
        (*c).pm = 1.0 - (*c).u_minus / (*c).u_plus;
        (*c).pn = -((*c).u_plus - (*c).u_minus) / (1.0 - (*c).u_plus);
        (*c).pscale = sqrt(a2_up);
        (*c).g_scale = 1.0 / ((*c).pscale * (1.0 - (*c).u_plus));
        (*c).hemisphere = sign(cos0);
    }
    return true;
}

// Radial::quad: two complex pairs -z +- i b1, z +- i b2 (false where the
// pencil has no two distinct squares in f32).
fn kc_radial_quad(c: ptr<function, KerrClosed>, z: f32, s12: f32, s34: f32, poles: vec2<f32>) -> bool {
    let a1 = -z;
    let a2 = z;
    let b1 = sqrt(-s12);
    let b2 = sqrt(-s34);
    let ssum = (a1 - a2) * (a1 - a2) + b1 * b1 + b2 * b2;
    let disc = max(ssum * ssum - 4.0 * b1 * b1 * b2 * b2, 0.0);
    let l2 = (ssum + sqrt(disc)) / (2.0 * b2 * b2);
    let l1 = b1 * b1 / (b2 * b2 * l2);
    if !(l1 < 1.0 - 1e-6 && l2 > 1.0 + 1e-6) {
        return false;
    }
    let s1 = (a1 - l1 * a2) / (1.0 - l1);
    let s2 = (a1 - l2 * a2) / (1.0 - l2);
    let span = l2 - l1;
    let c1 = l2 * (1.0 - l1) / span;
    let d1 = l1 * (l2 - 1.0) / span;
    let d2 = (l2 - 1.0) / span;
    (*c).kind = KC_QUAD;
    (*c).k = 1.0 - l1 / l2;
    (*c).kappa = sqrt(c1 * d2) * abs(s1 - s2);
    (*c).roots = vec4<f32>(s1, s2, sqrt(c1), sqrt(d1));
    (*c).theta_inf = atan2(sqrt(c1), sqrt(d1));
    let t = sqrt(d1 / c1);
    let alpha = s1 - poles;
    let gamma = (s2 - poles) * t;
    let g = alpha * alpha + gamma * gamma;
    let sg = sqrt(g);
    let sh = sqrt(g - (*c).k * alpha * alpha);
    (*c).n = g / (alpha * alpha);
    (*c).linear = (alpha + t * gamma) / g;
    (*c).third = 1.0 / alpha - (alpha + t * gamma) / g;
    (*c).alpha = -(gamma - t * alpha) / (2.0 * sg * sh);
    (*c).cc = sg;
    (*c).dd = sh;
    (*c).l1 = log(abs((sg - sh) / (sg + sh)));
    let kc = sqrt(1.0 - (*c).k);
    (*c).big_k = kc_cel(kc, 1.0);
    (*c).pi_c = vec2<f32>(kc_cel(kc, 1.0 - (*c).n.x), kc_cel(kc, 1.0 - (*c).n.y));
    return true;
}

// What kc_radial_outer says of the photon: no closed form, it turns, it
// turns inside (between r_+ and r3).
const KC_FAIL: u32 = 4u;
const KC_TURNS: u32 = 1u;
const KC_INNER: u32 = 2u;

// Radial::outer: four real roots, relabelled between r_+ and r3 (a start
// inside r3). KC_FAIL, or whether the photon turns (KC_TURNS) and does so
// inside (KC_INNER).
fn kc_radial_outer(c: ptr<function, KerrClosed>, coefs: vec3<f32>, z: f32, s12: f32, s34: f32, r0: f32, poles: vec2<f32>) -> u32 {
    let r_plus = poles.x;
    let r1 = kc_polish(coefs, -z - sqrt(s12));
    let r2 = kc_polish(coefs, -z + sqrt(s12));
    let r3 = kc_polish(coefs, z - sqrt(s34));
    let r4 = kc_polish(coefs, z + sqrt(s34));
    let turning = r4 > r_plus;
    let inner = turning && r0 < r4;
    var g = vec4<f32>(r1, r2, r3, r4);
    if inner {
        if !(r0 <= r3 && r2 < r_plus) {
            return KC_FAIL;
        }
        g = vec4<f32>(r2, r1, r4, r3);
    }
    let r31 = g.z - g.x;
    let r41 = g.w - g.x;
    let r32 = g.z - g.y;
    let r42 = g.w - g.y;
    (*c).kind = KC_OUTER;
    (*c).roots = vec4<f32>(g.z, g.w, r31, r41);
    (*c).k = r32 * r41 / (r31 * r42);
    (*c).kappa = 0.5 * sqrt(r31 * r42);
    (*c).n = (g.z - poles) * r41 / ((g.w - poles) * r31);
    (*c).linear = 1.0 / (g.z - poles);
    (*c).third = (g.z - g.w) / ((g.w - poles) * (g.z - poles));
    (*c).t_inf = vec4<f32>(r41 / r31, g.w - g.z, 0.0, 0.0);
    return select(0u, KC_TURNS, turning) | select(0u, KC_INNER, inner);
}

// Radial::pair: r1 < r2 real, one complex pair z -+ i sqrt(-s34).
fn kc_radial_pair(c: ptr<function, KerrClosed>, coefs: vec3<f32>, z: f32, s12: f32, s34: f32, poles: vec2<f32>) {
    let r1 = kc_polish(coefs, -z - sqrt(s12));
    let r2 = kc_polish(coefs, -z + sqrt(s12));
    let im = sqrt(-s34);
    let big_a2 = length(vec2<f32>(z - r2, im));
    let big_b2 = length(vec2<f32>(z - r1, im));
    let r21 = r2 - r1;
    (*c).kind = KC_PAIR;
    (*c).roots = vec4<f32>(r1, r2, big_a2, big_b2);
    (*c).k = ((big_a2 + big_b2) * (big_a2 + big_b2) - r21 * r21) / (4.0 * big_a2 * big_b2);
    (*c).kappa = sqrt(big_a2 * big_b2);
    let d0 = big_b2 * (r2 - poles) - big_a2 * (r1 - poles);
    let d1 = big_b2 * (r2 - poles) + big_a2 * (r1 - poles);
    (*c).alpha = d1 / d0;
    (*c).n = (*c).alpha * (*c).alpha / ((*c).alpha * (*c).alpha - 1.0);
    (*c).linear = (big_a2 + big_b2) / d1;
    (*c).third = -2.0 * big_a2 * big_b2 * r21 / (d0 * d1);
    (*c).cc = 1.0 - (*c).alpha * (*c).alpha;
    (*c).dd = (*c).k + (1.0 - (*c).k) * (*c).alpha * (*c).alpha;
    let kc = sqrt(1.0 - (*c).k);
    (*c).big_k = kc_cel(kc, 1.0);
    (*c).pi_c = vec2<f32>(kc_cel(kc, 1.0 - (*c).n.x), kc_cel(kc, 1.0 - (*c).n.y));
    if TRAVEL {
        let al = (big_b2 + big_a2) / (big_b2 - big_a2);
        let n_inf = al * al / (al * al - 1.0);
        (*c).t_inf = vec4<f32>(n_inf, al, 1.0 - al * al, (*c).k + (1.0 - (*c).k) * al * al);
        (*c).t_lin = vec2<f32>(
            (big_b2 * r2 + big_a2 * r1) / (big_b2 + big_a2),
            2.0 * big_a2 * big_b2 * r21 / ((big_b2 + big_a2) * (big_b2 - big_a2)),
        );
        (*c).t_c = vec2<f32>(kc_cel_ab(kc, 1.0, 0.0, 1.0), kc_cel(kc, 1.0 - n_inf));
    }
}

// Polar::ordinary and Polar::vortical's phase at the start: psi0, K(m),
// Pi(n | m), Pi at psi0 and, for the time, D.
fn kc_polar_phase(c: ptr<function, KerrClosed>, cos0: f32, u_up: bool) {
    let pkc = sqrt(1.0 - (*c).pm);
    (*c).pk = kc_cel(pkc, 1.0);
    (*c).ppi_c = kc_cel(pkc, 1.0 - (*c).pn);
    if (*c).u_minus < 0.0 {
        let sn_th = clamp(cos0 / sqrt((*c).u_plus), -1.0, 1.0);
        let cn_th = sqrt(1.0 - sn_th * sn_th);
        // F, J of u_+ and D (J at n = 0).
        let fj = kc_f_j(sn_th, cn_th, (*c).pm, vec2<f32>((*c).pn, 0.0));
        let f0 = vec2<f32>(fj.x, fj.x + (*c).pn * fj.y);
        if TRAVEL {
            (*c).pd = vec2<f32>(kc_cel_ab(pkc, 1.0, 0.0, 1.0), fj.z);
        }
        if u_up {
            (*c).psi0 = f0.x;
            (*c).ppi0 = f0.y;
        } else {
            (*c).psi0 = 2.0 * (*c).pk - f0.x;
            (*c).ppi0 = 2.0 * (*c).ppi_c - f0.y;
            (*c).pd.y = 2.0 * (*c).pd.x - (*c).pd.y;
        }
    } else {
        let s2 = clamp(((*c).u_plus - cos0 * cos0) / ((*c).u_plus - (*c).u_minus), 0.0, 1.0);
        let f0 = kc_f_pi(sqrt(s2), sqrt(1.0 - s2), (*c).pm, vec2<f32>((*c).pn, 0.0));
        // Towards the pole psi runs up to 0.
        let sgn = select(1.0, -1.0, u_up == (cos0 > 0.0));
        (*c).psi0 = sgn * f0.x;
        (*c).ppi0 = sgn * f0.y;
    }
}

// KerrRay::new: lambda, eta, the energy's sign, the start (r0, cos theta0,
// Kerr-Schild phi0) and the signs of d r and d cos theta.
fn kerr_closed_ray(lambda: f32, eta: f32, energy_sign: f32, start: vec3<f32>, r_out: bool, u_up: bool) -> KerrClosed {
    var c: KerrClosed;
    c.ok = false;
    let a = P.kerr_hole.x;
    let r_plus = P.kerr_hole.y;
    let r_minus = P.kerr_hole.z;
    let r0 = start.x;
    if !(r0 > r_plus) || eta == 0.0 {
        return c;
    }
    if !kc_polar_motion(&c, a, lambda, eta, start.y) {
        return c;
    }
    // Rays passing within ~0.03 rad (1.8 degrees) of the axis integrate:
    // there cos theta's start amplitude asin(cos theta0 / sqrt(u_+)) is
    // ill-conditioned in f32 (the CPU's margin is 1e-10).
    if !(c.u_plus < 1.0 - 1e-3) {
        return c;
    }
    // RadialRoots::new: the resolvent cubic, then Newton on R.
    let big_a = a * a - eta - lambda * lambda;
    let big_b = 2.0 * (eta + (lambda - a) * (lambda - a));
    let big_c = -a * a * eta;
    let z = kc_resolvent_z(big_a, big_b, big_c);
    let base = -0.5 * big_a - z * z;
    let bz = select(0.0, big_b / (4.0 * z), z > 0.0);
    let s12 = base + bz;
    let s34 = base - bz;
    let coefs = vec3<f32>(big_a, big_b, big_c);
    let poles = vec2<f32>(r_plus, r_minus);
    var turning = false;
    var inner = false;
    if !(s12 >= 0.0) {
        // Two complex pairs -z +- i b1, z +- i b2 (Radial::quad).
        if !(s34 < 0.0) {
            return c;
        }
        if !kc_radial_quad(&c, z, s12, s34, poles) {
            return c;
        }
    } else if s34 >= 0.0 {
        let cut = kc_radial_outer(&c, coefs, z, s12, s34, r0, poles);
        if cut == KC_FAIL {
            return c;
        }
        turning = (cut & KC_TURNS) != 0u;
        inner = (cut & KC_INNER) != 0u;
    } else {
        // One complex pair z -+ i sqrt(-s34).
        kc_radial_pair(&c, coefs, z, s12, s34, poles);
    }
    let sc0 = kc_sn_cn(c, r0);
    var sign0 = 1.0;
    c.dir = 1.0;
    if turning {
        sign0 = select(1.0, -1.0, r_out == inner);
    } else {
        // U grows with r but for two pairs with s1 < s2.
        let rising = c.kind != KC_QUAD || c.roots.x > c.roots.y;
        c.dir = select(-1.0, 1.0, r_out == rising);
    }
    let at0 = kc_at(c, sc0, a != 0.0 || TRAVEL);
    c.u0 = sign0 * at0.x;
    c.pole0 = sign0 * at0.yz;
    // Only rays that cross the plane need their time (two complex pairs
    // are vortical; one with ordinary polar motion would integrate).
    if TRAVEL && c.u_minus < 0.0 {
        if c.kind == KC_QUAD {
            return c;
        }
        let slope = 8.0 - 2.0 * a * lambda;
        c.tcoef = vec2<f32>(slope * r_plus - 4.0 * a * a, -(slope * r_minus - 4.0 * a * a)) / (r_plus - r_minus);
        c.time0 = sign0 * kc_time(c, sc0, at0);
    }
    c.captured = inner || (!turning && !r_out);
    var sc_end: vec3<f32>;
    if c.captured {
        sc_end = kc_sn_cn(c, r_plus);
    } else {
        sc_end = kc_sn_cn_inf(c);
    }
    let at_end = kc_at(c, sc_end, a != 0.0 && !c.captured);
    c.pole_end = at_end.yz;
    c.s_end = (at_end.x - c.u0) * c.dir / c.kappa;
    let dr = r_plus - r_minus;
    c.coef = vec2<f32>(a * (2.0 * r_plus - a * lambda), -a * (2.0 * r_minus - a * lambda)) / (dr * c.kappa);
    kc_polar_phase(&c, start.y, u_up);
    c.phi0 = start.z - kc_ks_term(r0);
    c.lambda = lambda;
    c.eta = eta;
    // radial_signs: outwards after a turning point (inwards after an
    // inner one), else one sign throughout.
    if turning {
        let sign = select(1.0, -1.0, inner);
        c.r_signs = vec2<f32>(-sign, sign);
        c.turn = -c.u0 / (c.kappa * c.dir);
    } else {
        let sign = select(1.0, -1.0, c.captured);
        c.r_signs = vec2<f32>(sign, sign);
        c.turn = 3.4e38;
    }
    c.energy_sign = energy_sign;
    c.ok = kc_finite(c);
    return c;
}

// RadialRoots::new's resolvent cubic of R = r^4 + A r^2 + B r + C: z, the
// roots being -z +- sqrt(s12) and z +- sqrt(s34).
fn kc_resolvent_z(big_a: f32, big_b: f32, big_c: f32) -> f32 {
    let pp = -big_a * big_a / 12.0 - big_c;
    let qq = -big_a / 3.0 * ((big_a / 6.0) * (big_a / 6.0) - big_c) - big_b * big_b / 8.0;
    let dq = (pp / 3.0) * (pp / 3.0) * (pp / 3.0) + 0.25 * qq * qq;
    var sum: f32;
    if dq >= 0.0 {
        let u = -0.5 * qq + select(sqrt(dq), -sqrt(dq), qq > 0.0);
        let w = sign(u) * pow(abs(u), 1.0 / 3.0);
        sum = select(0.0, w - pp / (3.0 * w), w != 0.0);
    } else {
        let rho = sqrt(-(pp / 3.0) * (pp / 3.0) * (pp / 3.0));
        let theta = atan2(sqrt(-dq), -0.5 * qq);
        sum = 2.0 * pow(rho, 1.0 / 3.0) * cos(theta / 3.0);
    }
    return sqrt(max(0.5 * sum - big_a / 6.0, 0.0));
}

// Whether every constant of the ray came out finite in f32 (else the
// integrator takes it).
fn kc_finite(c: KerrClosed) -> bool {
    return c.s_end >= 0.0 && c.s_end < 3e38 && abs(c.pole0.x) < 3e38 && abs(c.pole0.y) < 3e38
        && abs(c.pole_end.x) < 3e38 && abs(c.pole_end.y) < 3e38 && abs(c.psi0) < 3e38
        && abs(c.ppi0) < 3e38 && abs(c.ppi_c) < 3e38 && abs(c.pi_c.x) < 3e38 && abs(c.pi_c.y) < 3e38
        && abs(c.big_k) < 3e38 && c.pk > 0.0 && abs(c.time0) < 3e38 && abs(c.pd.y) < 3e38;
}

fn kc_azimuth(c: KerrClosed, pole: vec2<f32>, r_term: f32, g_phi: f32) -> f32 {
    let radial = dot(c.coef, pole - c.pole0) * c.dir;
    return c.phi0 + c.energy_sign * (radial + c.lambda * g_phi) + r_term;
}

// A crossing: its Kerr-Schild point and Boyer-Lindquist radius (M; r < 0
// past the ray's end), with TRAVEL the time (M) its light takes to the
// start, and the point in the disk's polar coordinates (M; disk_plane).
struct KcCrossing {
    p: vec3<f32>,
    r: f32,
    t: f32,
    plane: vec2<f32>,
}

// The crossing after j half swings of the polar motion (KerrRay::crossings
// and crossing_point_time).
fn kc_crossing(c: KerrClosed, j: f32) -> KcCrossing {
    let s = (2.0 * j * c.pk - c.psi0) / c.pscale;
    // Vortical motion stays in one hemisphere.
    if !(s < c.s_end) || c.u_minus >= 0.0 {
        return KcCrossing(vec3<f32>(0.0), -1.0, 0.0, vec2<f32>(0.0));
    }
    let u = c.u0 + c.dir * c.kappa * s;
    let sc = vec3<f32>(jacobi_sncn(u, 1.0 - c.k), 0.0);
    let r = kc_radius(c, sc);
    let a = P.kerr_hole.x;
    let at = kc_at(c, sc, a != 0.0 || TRAVEL);
    var t = 0.0;
    if TRAVEL {
        let radial = c.dir * (kc_time(c, sc, at) - c.time0) / c.kappa;
        let polar = a * a * c.u_plus / c.pscale * (2.0 * j * c.pd.x - c.pd.y);
        t = -c.energy_sign * (radial + polar);
    }
    let g_phi = (2.0 * j * c.ppi_c - c.ppi0) * c.g_scale;
    // Boyer-Lindquist's azimuth first: the disk's coordinates without a
    // round trip through the Kerr-Schild point.
    let bl = kc_azimuth(c, at.yz, 0.0, g_phi);
    let phi = bl + kc_ks_term(r);
    let p = vec3<f32>(r * cos(phi) - a * sin(phi), r * sin(phi) + a * cos(phi), 0.0);
    return KcCrossing(p, r, t, r * vec2<f32>(cos(bl), sin(bl)));
}

// kappa times the radial integral of the coordinate time's rate at the
// amplitude (sn, cn) whose kc_at (with poles) is `at` (Radial::at's TIME
// plus the horizon poles, M = 1): r^2 + 2 r + 4 by Pi and the squared pole
// of the pole at infinity.
fn kc_time(c: KerrClosed, sc: vec3<f32>, at: vec3<f32>) -> f32 {
    let u = at.x;
    let s = sc.x;
    let cn = sc.y;
    let k = c.k;
    let s2 = s * s;
    let nn = c.t_inf.x;
    // D and J of the pole at infinity from one duplication (R_D = R_J at
    // p = z = 1).
    let fj = kc_f_j(s, abs(cn), k, vec2<f32>(0.0, nn));
    var d = fj.y;
    var pn = fj.x + nn * fj.z;
    let dn = sqrt(1.0 - k * s2);
    var poly: f32;
    if c.kind == KC_OUTER {
        let r3 = c.roots.x;
        let r43 = c.t_inf.y;
        let g = 1.0 / (1.0 - nn * s2);
        let v2 = (k * u - k * nn * d + (2.0 * k * nn - 3.0 * k - nn * nn + 2.0 * nn) * pn
            - nn * nn * s * cn * dn * g) / (2.0 * (k - nn) * (nn - 1.0));
        let i1 = r3 * u + r43 * pn;
        let i2 = r3 * r3 * u + 2.0 * r3 * r43 * pn + r43 * r43 * v2;
        poly = i2 + 2.0 * i1 + 4.0 * u;
    } else {
        if cn < 0.0 {
            d = 2.0 * c.t_c.x - d;
            pn = 2.0 * c.t_c.y - pn;
        }
        let al = c.t_inf.y;
        let cc = c.t_inf.z;
        let dd = c.t_inf.w;
        let r1 = pn / cc - al * kc_odd(s / dn, cc, dd);
        let a2 = al * al;
        let r2 = (k * a2 * (u - d) - k * u - (2.0 * a2 * k - a2 - 2.0 * k) * r1
            - a2 * al * s * dn / (1.0 + al * cn)) / ((a2 - 1.0) * (a2 * k - a2 - k));
        let r0 = c.t_lin.x;
        let rc = c.t_lin.y;
        let i1 = r0 * u + rc * r1;
        let i2 = r0 * r0 * u + 2.0 * r0 * rc * r1 + rc * rc * r2;
        poly = i2 + 2.0 * i1 + 4.0 * u;
    }
    return poly + dot(c.tcoef, at.yz);
}

// The first crossing's index (later ones follow one by one).
fn kc_first(c: KerrClosed) -> f32 {
    return floor(c.psi0 / (2.0 * c.pk) + 1e-6) + 1.0;
}

// KerrRay::escape_direction.
fn kc_escape(c: KerrClosed) -> vec3<f32> {
    let psi = c.psi0 + c.pscale * c.s_end;
    let j = round(psi / (2.0 * c.pk));
    let sc = jacobi_sncn(psi - 2.0 * j * c.pk, 1.0 - c.pm);
    let f = kc_f_pi(sc.x, sc.y, c.pm, vec2<f32>(c.pn, 0.0));
    var cos_th: f32;
    if c.u_minus < 0.0 {
        let sgn = select(-1.0, 1.0, j - 2.0 * floor(0.5 * j) == 0.0);
        cos_th = sqrt(c.u_plus) * sc.x * sgn;
    } else {
        cos_th = c.hemisphere * sqrt(max(c.u_plus - (c.u_plus - c.u_minus) * sc.x * sc.x, 0.0));
    }
    let g_phi = (2.0 * j * c.ppi_c + f.y - c.ppi0) * c.g_scale;
    let phi = kc_azimuth(c, c.pole_end, 0.0, g_phi);
    let sin_th = sqrt(max(1.0 - cos_th * cos_th, 0.0));
    return vec3<f32>(sin_th * cos(phi), sin_th * sin(phi), cos_th);
}

// KerrRay::state_at: (r, dr/ds, cos theta, d cos theta / ds) at Mino time
// s (M = 1): r from the radial motion's Jacobi form, its rate from the
// radial potential signed by the branch, cos theta from the polar
// motion's (reduced to within K of a half swing, as polar_phase does).
fn kc_state_at(c: KerrClosed, s: f32) -> vec4<f32> {
    let u = c.u0 + c.dir * c.kappa * s;
    let r = kc_radius(c, vec3<f32>(jacobi_sncn(u, 1.0 - c.k), 0.0));
    let a = P.kerr_hole.x;
    let w = r * r + a * a - a * c.lambda;
    let big_r = w * w - (r * r - 2.0 * r + a * a) * (c.eta + (c.lambda - a) * (c.lambda - a));
    let r_dot = select(c.r_signs.y, c.r_signs.x, s < c.turn) * sqrt(max(big_r, 0.0));
    let psi = c.psi0 + c.pscale * s;
    let j = round(psi / (2.0 * c.pk));
    let snc = jacobi_sncn(psi - 2.0 * c.pk * j, 1.0 - c.pm);
    let dn = sqrt(max(1.0 - c.pm * snc.x * snc.x, 0.0));
    let swing = c.pscale * snc.y * dn;
    if c.u_minus < 0.0 {
        let root = sqrt(c.u_plus) * select(1.0, -1.0, j - 2.0 * floor(0.5 * j) != 0.0);
        return vec4<f32>(r, r_dot, root * snc.x, root * swing);
    }
    let spread = c.u_plus - c.u_minus;
    let cos = sqrt(max(c.u_plus - spread * snc.x * snc.x, 0.0)) * c.hemisphere;
    var rate = 0.0;
    if cos != 0.0 {
        rate = -(spread * snc.x * swing) / cos;
    }
    return vec4<f32>(r, r_dot, cos, rate);
}

// KerrRay::cos_range: the least and greatest cos theta along the ray.
fn kc_cos_range(c: KerrClosed) -> vec2<f32> {
    let top = sqrt(c.u_plus);
    if c.u_minus < 0.0 {
        return vec2<f32>(-top, top);
    }
    if c.hemisphere < 0.0 {
        return vec2<f32>(-top, -sqrt(c.u_minus));
    }
    return vec2<f32>(sqrt(c.u_minus), top);
}

// KerrRay::mino_at_fall: the Mino time at which a captured ray, on its
// last fall, reaches radius r.
fn kc_mino_at_fall(c: KerrClosed, r: f32) -> f32 {
    let u = kc_at(c, kc_sn_cn(c, r), false).x;
    return clamp((u - c.u0) * c.dir / c.kappa, 0.0, c.s_end);
}
