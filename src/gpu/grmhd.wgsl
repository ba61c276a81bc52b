// A GRMHD snapshot (MEDIUM_GRMHD), in f32: twin of src/transfer/grmhd/
// (mod.rs's Grmhd::state, scale and cut_level, coords.rs's Theta and
// Inverse, fluid.rs's four-vectors) and synchrotron.rs's Pitched. Its
// words are in the tables from P.at_medium_table: the GrmhdBlock
// (grmhd_block()), theta's inverse and the cells' values (GRMHD_FIELDS
// each: rho, Theta_e, |b|, sigma, U1-U3, B1-B3, X3 fastest).

// A word of the snapshot's, `k` from the block's start.
fn grmhd_word(k: u32) -> f32 {
    return tables[P.at_medium_table + k];
}

// Theta::at: (theta, d theta / d X1, d theta / d X2) at (X1, X2).
fn grmhd_theta(x1: f32, x2: f32) -> vec3<f32> {
    let g = grmhd_block();
    let kind = u32(g.theta_kind);
    if kind == 0u {
        return vec3<f32>(x2, 0.0, 1.0);
    }
    if kind == 2u {
        return vec3<f32>(x2 + 0.5 * g.hslope * sin(2.0 * x2), 0.0, 1.0 + g.hslope * cos(2.0 * x2));
    }
    let s = sin(2.0 * PI * x2);
    let c = cos(2.0 * PI * x2);
    let th_g = PI * x2 + 0.5 * (1.0 - g.hslope) * s;
    let dg = PI * (1.0 + (1.0 - g.hslope) * c);
    if kind == 1u {
        return vec3<f32>(th_g, 0.0, dg);
    }
    // FMKS: the polynomial's odd power keeps the sign of y.
    let y = 2.0 * x2 - 1.0;
    var p = pow(abs(y / g.poly_xt), g.poly_alpha);
    if y < 0.0 && (u32(g.poly_alpha) % 2u) == 1u {
        p = -p;
    }
    let th_j = g.poly_norm * y * (1.0 + p / (g.poly_alpha + 1.0)) + 0.5 * PI;
    let dj = 2.0 * g.poly_norm * (1.0 + p);
    let e = exp(g.mks_smooth * (g.start1 - x1));
    return vec3<f32>(th_g + e * (th_j - th_g), -g.mks_smooth * e * (th_j - th_g), dg + e * (dj - dg));
}

// Inverse::x2: (X2, d theta / d X1, d theta / d X2) of theta `th` at
// `x1`: the table's guess, then two Newton steps.
fn grmhd_x2(x1: f32, th: f32) -> vec3<f32> {
    let g = grmhd_block();
    let last = f32(GRMHD_THETAS - 1u);
    let u = clamp(th / PI * last, 0.0, last - 1e-3);
    let i = u32(u);
    let f = u - f32(i);
    let rows = u32(g.inverse_rows);
    let at = u32(g.inverse_at);
    var row = 0u;
    var w = 0.0;
    if rows > 1u {
        let v = clamp((x1 - g.inverse_x1) / g.inverse_step, 0.0, f32(rows - 1u) - 1e-3);
        row = u32(v);
        w = v - f32(row);
    }
    let a = at + row * GRMHD_THETAS + i;
    let lo = mix(grmhd_word(a), grmhd_word(a + 1u), f);
    var x = lo;
    if rows > 1u {
        let b = a + GRMHD_THETAS;
        x = mix(lo, mix(grmhd_word(b), grmhd_word(b + 1u), f), w);
    }
    var t = grmhd_theta(x1, x);
    for (var k = 0u; k < 2u; k++) {
        x -= (t.x - th) / t.z;
        t = grmhd_theta(x1, x);
    }
    return vec3<f32>(x, t.y, t.z);
}

// The first word of cell (i, j, k), the indices one beyond each edge
// allowed (Grmhd::ghost: the radial edges extended, a pole crossed to the
// cell half a turn round, or the mean of the two there for an odd n3 (the
// second index), the azimuth periodic).
fn grmhd_ghost(i_in: i32, j_in: i32, k_in: i32) -> vec2<u32> {
    let g = grmhd_block();
    let n1 = i32(g.n1);
    let n2 = i32(g.n2);
    let n3 = i32(g.n3);
    let i = clamp(i_in, 0, n1 - 1);
    var k = ((k_in % n3) + n3) % n3;
    var j = j_in;
    var k2 = k;
    if j < 0 || j >= n2 {
        j = clamp(j, 0, n2 - 1);
        if n3 % 2 == 0 {
            k = (k + n3 / 2) % n3;
            k2 = k;
        } else {
            k2 = (k + (n3 + 1) / 2) % n3;
            k = (k + (n3 - 1) / 2) % n3;
        }
    }
    let base = P.at_medium_table + u32(g.cells_at);
    let row = u32((i * n2 + j) * n3);
    return vec2<u32>(base + (row + u32(k)) * GRMHD_FIELDS, base + (row + u32(k2)) * GRMHD_FIELDS);
}

// The cell values interpolated at native x (Grmhd::interpolate), or the
// one value `only` of them where it is below GRMHD_FIELDS.
var<private> grmhd_v: array<f32, 10>;

fn grmhd_interpolate(x: vec3<f32>, only: u32) {
    let g = grmhd_block();
    let start = vec3<f32>(g.start1, g.start2, g.start3);
    let dx = vec3<f32>(g.dx1, g.dx2, g.dx3);
    let n = vec3<f32>(g.n1, g.n2, g.n3);
    let u = (x - start) / dx - 0.5;
    let at = clamp(floor(u), vec3<f32>(-1.0), n - 1.0);
    let del = clamp(u - at, vec3<f32>(0.0), vec3<f32>(1.0));
    for (var f = 0u; f < GRMHD_FIELDS; f++) {
        grmhd_v[f] = 0.0;
    }
    for (var corner = 0u; corner < 8u; corner++) {
        let o = vec3<u32>(corner & 1u, (corner >> 1u) & 1u, (corner >> 2u) & 1u);
        let wv = select(1.0 - del, del, o == vec3<u32>(1u));
        let w = wv.x * wv.y * wv.z;
        if w == 0.0 {
            continue;
        }
        let c = grmhd_ghost(i32(at.x) + i32(o.x), i32(at.y) + i32(o.y), i32(at.z) + i32(o.z));
        // Two cells only across a pole of an odd n3: one read otherwise.
        let two = c.x != c.y;
        var lo = 0u;
        var hi = GRMHD_FIELDS;
        if only < GRMHD_FIELDS {
            lo = only;
            hi = only + 1u;
        }
        for (var f = lo; f < hi; f++) {
            var v = tables[c.x + f];
            if two {
                v = 0.5 * (v + tables[c.y + f]);
            }
            grmhd_v[f] += w * v;
        }
    }
}

// Grmhd::native: (X1, X2, X3) of (r, theta) and the point p (r_s), with
// (d theta / d X1, d theta / d X2); w < 0 outside the grid.
struct GrmhdAt {
    x: vec3<f32>,
    d: vec2<f32>,
    inside: bool,
}

fn grmhd_native(r: f32, th: f32, p: vec3<f32>) -> GrmhdAt {
    let g = grmhd_block();
    let x1 = log(r);
    let t = grmhd_x2(x1, th);
    let phi = atan2(p.y, p.x) - atan2(P.medium_spin, r);
    let x3 = phi - 2.0 * PI * floor(phi / (2.0 * PI));
    let inside = x1 >= g.start1 && x1 < g.start1 + g.n1 * g.dx1 && t.x >= g.start2 && t.x < g.start2 + g.n2 * g.dx2;
    return GrmhdAt(vec3<f32>(x1, t.x, x3), t.yz, inside);
}

// Grmhd::cut_level: sigma over the cut at (r, cos theta), p; 0 outside.
fn grmhd_level(r: f32, c: f32, p: vec3<f32>) -> f32 {
    let n = grmhd_native(r, acos(clamp(c, -1.0, 1.0)), p);
    if !n.inside {
        return 0.0;
    }
    grmhd_interpolate(n.x, 3u);
    return grmhd_v[3] / grmhd_block().sigma_cut;
}

// Grmhd::scale: GRMHD_CELLS_PER_PIECE times the cell's narrowest width.
fn grmhd_scale(r: f32, c: f32) -> f32 {
    let g = grmhd_block();
    let x1 = log(max(r, 1e-3));
    let t = grmhd_x2(x1, acos(clamp(c, -1.0, 1.0)));
    let s = sqrt(max(1.0 - c * c, 0.0));
    return GRMHD_CELLS_PER_PIECE * min(r * g.dx1, min(r * t.z * g.dx2, r * max(s, 0.05) * g.dx3));
}

// The Kerr-Schild metric's (g_mu nu, g^t mu) at (r, sin, cos), M = 1
// (fluid.rs's KsMetric).
struct KsMetric {
    cov: mat4x4<f32>,
    con_t: vec4<f32>,
}

fn ks_metric(r: f32, s: f32, c: f32) -> KsMetric {
    let a = P.medium_spin;
    let sigma = r * r + a * a * c * c;
    let z = 2.0 * r / sigma;
    let s2 = s * s;
    let g03 = -z * a * s2;
    let g13 = -a * s2 * (1.0 + z);
    let cov = mat4x4<f32>(
        vec4<f32>(-(1.0 - z), z, 0.0, g03),
        vec4<f32>(z, 1.0 + z, 0.0, g13),
        vec4<f32>(0.0, 0.0, sigma, 0.0),
        vec4<f32>(g03, g13, 0.0, s2 * (sigma + a * a * s2 * (1.0 + z))),
    );
    return KsMetric(cov, vec4<f32>(-(1.0 + z), z, 0.0, 0.0));
}

// Kerr-Schild's contravariant components carried to Boyer-Lindquist's.
fn ks_to_bl(r: f32, v: vec4<f32>) -> vec4<f32> {
    let a = P.medium_spin;
    let delta = r * r - 2.0 * r + a * a;
    return vec4<f32>(v.x - 2.0 * r / delta * v.y, v.y, v.z, v.w - a / delta * v.y);
}

// Grmhd::state at (r, cos th), p (r_s) for a photon of L_z `lz`, dr /
// dlambda `k_r` and d(cos th)/dlambda `k_cos`: its ratio (<= 0 where
// nothing radiates or absorbs) and pitched_new's electrons.
fn grmhd_state(r: f32, c: f32, p: vec3<f32>, lz: f32, k_r: f32, k_cos: f32) -> Gas {
    var gas = Gas(-1.0, vec3<f32>(0.0));
    let g = grmhd_block();
    let th = acos(clamp(c, -1.0, 1.0));
    if !(r > g.r_min && r < g.r_max && th > g.polar_cut && th < PI - g.polar_cut) {
        return gas;
    }
    let n = grmhd_native(r, th, p);
    if !n.inside {
        return gas;
    }
    grmhd_interpolate(n.x, GRMHD_FIELDS);
    let ne = grmhd_v[0] * g.ne_unit;
    if grmhd_v[3] > g.sigma_cut || !(ne > 0.0) {
        return gas;
    }
    let s = sqrt(max(1.0 - c * c, 1e-24));
    let m = ks_metric(r, s, c);
    // Native vectors to Kerr-Schild: (r V1, th_1 V1 + th_2 V2, V3).
    let v = vec3<f32>(r * grmhd_v[4], n.d.x * grmhd_v[4] + n.d.y * grmhd_v[5], grmhd_v[6]);
    let bf = vec3<f32>(r * grmhd_v[7], n.d.x * grmhd_v[7] + n.d.y * grmhd_v[8], grmhd_v[9]);
    // fluid.rs's four_vectors.
    let gs = mat3x3<f32>(m.cov[1].yzw, m.cov[2].yzw, m.cov[3].yzw);
    let vv = dot(v, gs * v);
    let ga = sqrt(-(1.0 + abs(vv)) / m.con_t.x);
    let u = vec4<f32>(-ga * m.con_t.x, v - ga * m.con_t.yzw);
    let u_cov = m.cov * u;
    let bt = dot(bf, u_cov.yzw);
    let b = vec4<f32>(bt, (bf + u.yzw * bt) / u.x);
    let bsq = dot(b, m.cov * b);
    let ub = ks_to_bl(r, u);
    let bb = ks_to_bl(r, b);
    let a = P.medium_spin;
    let sigma = r * r + a * a * c * c;
    let delta = r * r - 2.0 * r + a * a;
    let k = vec4<f32>(-1.0, sigma / delta * k_r, -sigma * k_cos / s, lz);
    let ratio = -dot(k, ub);
    if !(ratio > 0.0) {
        return gas;
    }
    let b_len = sqrt(abs(bsq));
    var sin_pitch = 1.0;
    if b_len > 0.0 {
        let mu = clamp(dot(k, bb) / (ratio * b_len), -1.0, 1.0);
        sin_pitch = sqrt(max(1.0 - mu * mu, 0.0));
    }
    return Gas(ratio, pitched_new(ne, grmhd_v[1], grmhd_v[2] * g.b_unit, sin_pitch));
}

// Pitched::new: (ln of prefactor nu_s, nu_s, T_e) of electrons of density
// n, Theta_e theta, field B (G) at pitch angle sin_th; ln of 0 where they
// emit nothing: thermal_new's, its nu_s0 taken at the pitch angle.
fn pitched_new(n: f32, theta: f32, field: f32, sin_th: f32) -> vec3<f32> {
    let t = thermal_new(vec3<f32>(n, theta * ME_C2_OVER_K, field));
    let ln_norm = t.x + log(max(sin_th, 1e-37));
    return vec3<f32>(select(ln_norm, -3.4e38, t.x < -1e38 || sin_th <= 0.0), t.y * sin_th, t.z);
}

// ln j_nu at gas-frame frequency nu (-3.4e38 where nothing is emitted).
fn pitched_ln_emission(pl: vec3<f32>, nu: f32) -> f32 {
    let x = nu / pl.y;
    let c = pow(x, 1.0 / 3.0);
    let ln_j = pl.x + 2.0 * log(sqrt(x) + 1.8877486 * sqrt(c)) - c;
    return select(ln_j, -3.4e38, x > 1e12 || !(pl.y > 0.0));
}

// Pitched::coefficients: (j_nu, alpha_nu) at gas-frame frequency nu.
fn pitched_coefficients(pl: vec3<f32>, nu: f32) -> vec2<f32> {
    let ln_j = pitched_ln_emission(pl, nu);
    let j = select(exp(max(ln_j, -87.0)), 0.0, ln_j < -87.0);
    return vec2<f32>(j, select(j / planck_nu(nu, pl.z), 0.0, j == 0.0));
}
