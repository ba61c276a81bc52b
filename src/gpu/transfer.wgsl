// Radiative transfer in physical units (the MEDIUM variant): twin of
// src/transfer/ (mod.rs's march and pieces, gold.rs, uniform.rs, riaf.rs,
// synchrotron.rs) and the jansky shade (src/render/jansky.rs), in f32.
// Lengths in M, positions from the segments' r_s; coefficients in cgs.
// P.medium holds the medium's parameters by kind (see pack.rs,
// pack_medium), P.wl[k].w the observed frequencies (Hz).

// A piece's length as a fraction of the medium's scale, most pieces a
// segment is cut into, the transmittance below which nothing further is
// seen, the pieces' nodes and the most optical depth a piece takes come
// from the header (M_SCALE_FRACTION, M_MAX_PIECES, M_SPENT, M_GAUSS_2,
// MAX_DTAU: transfer/mod.rs's).

// Each observed frequency's camera-frame intensity (cgs), transmittance
// and a piece's emission and absorption per unit of its unit-energy
// affine length (cgs); the photon's camera ratio and L_z / E (M).
var<private> m_int: array<f32, N_WL>;
var<private> m_through: array<f32, N_WL>;
var<private> m_coef: array<vec2<f32>, N_WL>;
var<private> m_camera_ratio: f32;
var<private> m_lz: f32;

// spectrum::planck_nu: B_nu(T) = 2 h nu^3 / c^2 / (e^x - 1), x = h nu /
// k T, in cgs; 2 h / c^2 = 1.4745e-47 is out of f32's range: nu in THz.
// Where x passes 80, e^x is held at e^80; 0 without a temperature.
fn m_planck(nu: f32, kelvin: f32) -> f32 {
    if !(kelvin > 0.0) {
        return 0.0;
    }
    let x = H_OVER_K * nu / kelvin;
    let em1 = select(x * (1.0 + x * (0.5 + x / 6.0)), exp(min(x, 80.0)) - 1.0, x > 1e-3);
    let t = nu * 1e-12;
    return TWO_H_OVER_C2_THZ * t * t * t / em1;
}

struct MZamo {
    alpha: f32,
    omega: f32,
    varpi: f32,
}

// Kerr::zamo_at (NaN inside the horizon).
fn m_zamo(r: f32, c: f32, s: f32) -> MZamo {
    let a = P.medium[3].y;
    let a2 = a * a;
    let sigma = r * r + a2 * c * c;
    let delta = r * r - 2.0 * r + a2;
    let big_a = (r * r + a2) * (r * r + a2) - a2 * delta * s * s;
    return MZamo(sqrt(sigma * delta / big_a), 2.0 * a * r / big_a, sqrt(big_a / sigma) * s);
}

// ---- Gold et al. 2020 (gold.rs): medium[0] = (A, alpha, h, l0),
// medium[1] = (n0, nu_p, extent, 0).

// (M_CUTOFF, transfer::CUTOFF, from the header.)

fn gold_density(r: f32, c: f32) -> f32 {
    let h = P.medium[0].z;
    let e = 0.5 * ((r / 10.0) * (r / 10.0) + (h * c) * (h * c));
    return select(0.0, P.medium[1].x * exp(-e), e < M_CUTOFF);
}

fn gold_scale(r: f32, c: f32) -> f32 {
    let h = P.medium[0].z;
    let radial = 100.0 / max(r, 1.0);
    let edge_e = sqrt(2.0 * M_CUTOFF);
    let s = sqrt(max(1.0 - c * c, 0.0));
    let vertical = r / max(h * h * abs(c * s) + h, 1e-30);
    let outside = min(min(radial, 0.5 * r), max(r * (abs(c) - edge_e / max(h, 1e-30)), vertical));
    return select(min(min(radial, vertical), 0.5 * r), outside, h * abs(c) > edge_e);
}

// Gold::frequency_ratio; negative where the flow is not timelike.
fn gold_ratio(r: f32, c: f32, lz: f32) -> f32 {
    let s = sqrt(max(1.0 - c * c, 1e-30));
    let big_r = r * s;
    let l = P.medium[0].w * big_r * sqrt(big_r) / (1.0 + big_r);
    let z = m_zamo(r, c, s);
    let a2 = z.alpha * z.alpha;
    let w2 = z.varpi * z.varpi;
    let drag = 1.0 - z.omega * l;
    let inv = drag * drag / a2 - l * l / w2;
    let ratio = (drag * (1.0 - lz * z.omega) / a2 - lz * l / w2) / sqrt(max(inv, 1e-30));
    return select(-1.0, ratio, inv > 0.0);
}

fn gold_coefficients(n: f32, nu: f32) -> vec2<f32> {
    let x = nu / P.medium[1].y;
    let alpha = P.medium[0].y;
    let j = n * pow(x, -alpha);
    let k = select(P.medium[0].x * n * pow(x, -(alpha + 2.5)), 0.0, P.medium[0].x == 0.0);
    return vec2<f32>(j, k);
}

// ---- the uniform shell (uniform.rs): medium[0] = (inner, outer, j0, k0),
// medium[1] = (alpha, nu_p, 0, 0).

fn shell_scale(r: f32) -> f32 {
    let m = P.medium[0];
    let thickness = m.y - m.x;
    return select(max(thickness, max(r - m.y, m.x - r)), thickness, r >= m.x && r <= m.y);
}

// ---- the RIAF (riaf.rs): medium[0] = (n_e, T_e at 1 M, their indices),
// medium[1] = (H, beta, kappa, f), medium[2] = (outer, r_isco, E, L).

// (n_e, T_e, B), or n_e = 0 where there is no gas.
fn riaf_plasma(r: f32, c: f32) -> vec3<f32> {
    let m = P.medium[0];
    let h = P.medium[1].x;
    let sin2 = max(1.0 - c * c, 0.0);
    let e = c * c / (2.0 * h * h * max(sin2, 1e-30));
    let gas = r <= P.medium[2].x && e < M_CUTOFF;
    let n = m.x * pow(r, m.z) * exp(-min(e, M_CUTOFF));
    let t = m.y * pow(r, m.w);
    // B = sqrt(8 pi n m_p c^2 / (6 beta r)).
    let b = RIAF_FIELD * sqrt(n / (P.medium[1].y * r));
    return select(vec3<f32>(0.0), vec3<f32>(n, t, b), gas);
}

fn riaf_scale(r: f32, c: f32) -> f32 {
    let h = P.medium[1].x;
    let s = sqrt(max(1.0 - c * c, 0.0));
    let radial = 0.125 * r;
    let cot_edge = h * sqrt(2.0 * M_CUTOFF);
    let edge = atan(1.0 / cot_edge);
    let th = atan2(s, abs(c));
    let axis = max(min(radial, r * (edge - th)), r / 32.0);
    let vertical = r / (abs(c) / (h * h * max(s * s * s, 1e-30)) + 1.0 / h);
    return select(min(radial, max(vertical, r / 32.0)), axis, abs(c) >= cot_edge * s);
}

// Riaf::frequency_ratio; negative where the motion is not timelike.
fn riaf_ratio(r: f32, c: f32, lz: f32, k_r: f32) -> f32 {
    let s = sqrt(max(1.0 - c * c, 1e-30));
    let z = m_zamo(r, c, s);
    let a = P.medium[3].y;
    let a2 = z.alpha * z.alpha;
    let w2 = z.varpi * z.varpi;
    let sigma = r * r + a * a * c * c;
    let delta = r * r - 2.0 * r + a * a;
    let g_rr_up = delta / sigma;
    let isco = P.medium[2];
    var omega_k = 1.0 / (r * sqrt(r) + a);
    var ur_k = 0.0;
    if r < isco.y {
        let ut = (isco.z - z.omega * isco.w) / a2;
        let uph = z.omega * ut + isco.w / w2;
        let d = isco.z - z.omega * isco.w;
        let ur2 = g_rr_up * (d * d / a2 - isco.w * isco.w / w2 - 1.0);
        omega_k = uph / ut;
        ur_k = -sqrt(max(ur2, 0.0));
    }
    let omega = omega_k + (1.0 - P.medium[1].z) * (z.omega - omega_k);
    let ur_ff = -sqrt(max((1.0 / a2 - 1.0) * g_rr_up, 0.0));
    let ur = ur_k + P.medium[1].w * (ur_ff - ur_k);
    let k = -a2 + w2 * (omega - z.omega) * (omega - z.omega);
    let ut2 = -(1.0 + ur * ur / g_rr_up) / k;
    let ratio = sqrt(max(ut2, 0.0)) * (1.0 - lz * omega) - k_r / g_rr_up * ur;
    return select(-1.0, ratio, z.alpha > 0.0 && k < 0.0 && ut2 > 0.0);
}

// ---- thermal synchrotron (synchrotron.rs), in logarithms where f32
// would underflow: K_2(1/Theta_e) ~ e^(-1/Theta_e).

// ln K_2(x), Abramowitz and Stegun 9.8.1-9.8.8.
fn ln_bessel_k2(x: f32) -> f32 {
    var result: f32;
    if x <= 2.0 {
        let t = (x / 3.75) * (x / 3.75);
        let i0 = 1.0 + t * (3.5156229 + t * (3.0899424 + t * (1.2067492 + t * (0.2659732 + t * (0.0360768 + t * 0.0045813)))));
        let i1 = x * (0.5 + t * (0.87890594 + t * (0.51498869 + t * (0.15084934 + t * (0.02658733 + t * (0.00301532 + t * 0.00032411))))));
        let q = 0.25 * x * x;
        let ln = log(0.5 * x);
        let k0 = -ln * i0 + (-0.57721566 + q * (0.42278420 + q * (0.23069756 + q * (0.03488590 + q * (0.00262698 + q * (0.00010750 + q * 0.0000074))))));
        let k1 = (x * ln * i1 + (1.0 + q * (0.15443144 + q * (-0.67278579 + q * (-0.18156897 + q * (-0.01919402 + q * (-0.00110404 + q * -0.00004686))))))) / x;
        result = log(k0 + 2.0 / x * k1);
    } else {
    let t = 2.0 / x;
    let p0 = 1.25331414 + t * (-0.07832358 + t * (0.02189568 + t * (-0.01062446 + t * (0.00587872 + t * (-0.00251540 + t * 0.00053208)))));
    let p1 = 1.25331414 + t * (0.23498619 + t * (-0.03655620 + t * (0.01504268 + t * (-0.00780353 + t * (0.00325614 + t * -0.00068245)))));
    result = -x - 0.5 * log(x) + log(p0 + t * p1);
    }
    return result;
}

// The pitch-angle average's table (Average in synchrotron.rs): ln G +
// y^1/3 at SYNC_TABLE points of ln y from SYNC_LN_Y_LOW to SYNC_LN_Y_HIGH.
fn ln_average(y: f32) -> f32 {
    let last = f32(SYNC_TABLE - 1u);
    let step = (SYNC_LN_Y_HIGH - SYNC_LN_Y_LOW) / last;
    let u = (log(y) - SYNC_LN_Y_LOW) / step;
    let at = P.at_medium_table;
    let i = u32(clamp(u, 0.0, last - 1.0));
    let f = clamp(u, 0.0, last) - f32(i);
    let inside = mix(tables[at + i], tables[at + i + 1u], f) - pow(y, 1.0 / 3.0);
    let below = tables[at] - exp(SYNC_LN_Y_LOW / 3.0) + u * step / 3.0;
    return select(select(-3.4e38, inside, u < last), below, u < 0.0);
}

// Thermal::new: what the coefficients of electrons (n_e, T_e, B) share at
// every frequency, (ln of prefactor nu_s0, nu_s0, T_e); ln of 0 where they
// emit nothing.
fn synchrotron_thermal(pl: vec3<f32>) -> vec3<f32> {
    let n = pl.x;
    // Theta_e = k T / (m_e c^2).
    let theta = max(pl.y / ME_C2_OVER_K, SYNC_COLDEST);
    let none = pl.y / ME_C2_OVER_K < SYNC_COLDEST || n <= 0.0 || pl.z <= 0.0;
    // (2/9) nu_c Theta^2, nu_c = e B / (2 pi m_e c).
    let nu_s0 = 2.0 / 9.0 * CYCLOTRON_PER_GAUSS * pl.z * theta * theta;
    // n sqrt(2) pi e^2 / (3 c).
    let ln_norm = log(max(n * SYNC_NORM * nu_s0, 1e-37)) - ln_bessel_k2(1.0 / theta);
    return vec3<f32>(select(ln_norm, -3.4e38, none), nu_s0, pl.y);
}

// (j_nu, alpha_nu) of thermal synchrotron at gas-frame frequency nu, of
// electrons as synchrotron_thermal gives them.
fn synchrotron_coefficients(th: vec3<f32>, nu: f32) -> vec2<f32> {
    let ln_j = th.x + ln_average(nu / th.y);
    let j = select(exp(max(ln_j, -87.0)), 0.0, ln_j < -87.0);
    return vec2<f32>(j, select(j / m_planck(nu, th.z), 0.0, j == 0.0));
}

// ---- the medium by kind (Medium in transfer/mod.rs).

fn m_extent() -> f32 {
    return P.medium[3].z;
}

// At (r, cos th, z), z the point's height (M).
fn m_scale(at: vec3<f32>) -> f32 {
    let r = at.x;
    let c = at.y;
    var scale: f32;
    if P.medium_kind == MEDIUM_GOLD {
        scale = gold_scale(r, c);
    } else if P.medium_kind == MEDIUM_UNIFORM {
        scale = shell_scale(r);
    } else if P.medium_kind == MEDIUM_VOLUME {
        scale = volume_gas_scale(at.z);
    } else {
        scale = riaf_scale(r, c);
    }
    return scale;
}

struct MGas {
    ratio: f32,
    // Gold's density, the shell's 1, the flow's synchrotron_thermal.
    plasma: vec3<f32>,
}

// Medium::state at (r, cos th), the point p (r_s): ratio <= 0 where
// nothing radiates or absorbs.
fn m_state(r: f32, c: f32, p: vec3<f32>, k_r: f32) -> MGas {
    var gas = MGas(-1.0, vec3<f32>(0.0));
    if P.medium_kind == MEDIUM_VOLUME {
        let g = volume_gas(p);
        if g.x > 0.0 {
            gas = MGas(riaf_ratio(r, c, m_lz, k_r), vec3<f32>(g, 0.0));
        }
    } else if P.medium_kind == MEDIUM_GOLD {
        let n = gold_density(r, c);
        if n > 0.0 {
            gas = MGas(gold_ratio(r, c, m_lz), vec3<f32>(n, 0.0, 0.0));
        }
    } else if P.medium_kind == MEDIUM_UNIFORM {
        if r >= P.medium[0].x && r <= P.medium[0].y {
            let s = sqrt(max(1.0 - c * c, 0.0));
            let z = m_zamo(r, c, s);
            if z.alpha > 0.0 {
                gas = MGas((1.0 - z.omega * m_lz) / z.alpha, vec3<f32>(1.0, 0.0, 0.0));
            }
        }
    } else {
        let pl = riaf_plasma(r, c);
        if pl.x > 0.0 {
            gas = MGas(riaf_ratio(r, c, m_lz, k_r), synchrotron_thermal(pl));
        }
    }
    return gas;
}

fn m_coefficients(gas: MGas, nu: f32) -> vec2<f32> {
    var c: vec2<f32>;
    if P.medium_kind == MEDIUM_GOLD {
        c = gold_coefficients(gas.plasma.x, nu);
    } else if P.medium_kind == MEDIUM_UNIFORM {
        let m = P.medium[0];
        c = vec2<f32>(m.z * pow(nu / P.medium[1].y, -P.medium[1].x), m.w);
    } else if P.medium_kind == MEDIUM_VOLUME {
        c = vec2<f32>(gas.plasma.x * m_planck(nu, gas.plasma.y), gas.plasma.x);
    } else {
        c = synchrotron_coefficients(gas.plasma, nu);
    }
    return c;
}

// ---- the volumetric disk's gas (volume.rs): medium[0] = (alpha_nu at
// density 1 (cm^-1), its structure's scale (M), the layer's half height
// (r_s), the inner radius (r_s)), medium[1] = (T0, 0, keplerian, infall),
// medium[2] = (0, the ISCO's r, E, L) as the flow's; its density is the
// visible-band volume's grid at P.at_volume.

// VolumeGas::scale at height z (M).
fn volume_gas_scale(z: f32) -> f32 {
    return max(P.medium[0].y, 2.0 * (0.5 * abs(z) - P.medium[0].z));
}

// VolumeGas::state's plasma at p (r_s): (alpha_nu (cm^-1), kelvin),
// alpha 0 where there is no gas.
fn volume_gas(p: vec3<f32>) -> vec2<f32> {
    let rho = grid_sample(od(P.at_volume + 14u), p);
    let r = length(p.xy);
    let inner = P.medium[0].w;
    if !(rho > 0.0 && r > inner) {
        return vec2<f32>(0.0);
    }
    let kelvin = P.medium[1].x * pow(r, -0.75) * pow(1.0 - sqrt(inner / r), 0.25);
    return vec2<f32>(P.medium[0].x * rho, kelvin);
}

// The surfaces where the medium ends abruptly (none: negative).
fn m_surface(i: u32) -> f32 {
    var b = -1.0;
    if P.medium_kind == MEDIUM_UNIFORM {
        b = select(P.medium[0].y, P.medium[0].x, i == 0u);
    } else if P.medium_kind == MEDIUM_SYNCHROTRON && i == 0u {
        b = P.medium[2].x;
    }
    return b;
}

// ---- the march along a segment (RayTransfer::march and piece).

// (r, cos th, z) in M of the segment's point at s.
fn m_at(seg: Seg, s: f32) -> vec3<f32> {
    let p = seg_point(seg, s) * 2.0;
    var r = length(p);
    if KERR {
        r = ks_radius(p);
    }
    return vec3<f32>(r, clamp(p.z / r, -1.0, 1.0), p.z);
}

// Whether the medium ahead can still be seen at some frequency (kept by
// m_piece as it dims the ray).
var<private> m_alive: bool;

// Where between fractions a and b the radius crosses `b_r` (bisection).
fn m_crossing(seg: Seg, a: f32, b: f32, b_r: f32) -> f32 {
    var lo = a;
    var hi = b;
    let lo_side = m_at(seg, lo).x > b_r;
    for (var i = 0u; i < 30u; i++) {
        let mid = 0.5 * (lo + hi);
        if (m_at(seg, mid).x > b_r) == lo_side {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return hi;
}

// The photon's dr/dlambda (M) at fraction s of a segment of m_per_s M
// per unit of s (Path::k_r_at): the photon runs against the trace.
fn m_k_r(seg: Seg, s: f32, m_per_s: f32) -> f32 {
    let p = seg_point(seg, s) * 2.0;
    let dp = seg_tangent(seg, s) * 2.0;
    var grad = p / length(p);
    if KERR {
        // Kerr::ks_radius_gradient.
        let a2 = P.kerr_hole.x * P.kerr_hole.x;
        let r = ks_radius(p);
        grad = (p * (r * r) + vec3<f32>(0.0, 0.0, a2 * p.z)) / (r * (2.0 * r * r - dot(p, p) + a2));
    }
    return -dot(grad, dp) / m_per_s;
}

// Adds a piece of length dl_inf (cm, unit-energy affine parameter) whose
// two Gauss-Legendre nodes are at fractions n0 and n1 of the segment
// (RayTransfer::piece): the gas's emission j x_inf / x^3 and absorption
// alpha x_inf per unit of dl_inf averaged over them, the piece solved as
// one of constant source function. Returns its greatest optical depth;
// unless that passes MAX_DTAU and it may be cut finer: then returns minus
// that depth.
fn m_piece(seg: Seg, n0: f32, n1: f32, m_per_s: f32, dl_inf: f32, finest: bool) -> f32 {
    var lit = false;
    for (var k = 0u; k < N_WL; k++) {
        m_coef[k] = vec2<f32>(0.0);
    }
    for (var i = 0u; i < 2u; i++) {
        var n = n0;
        if i == 1u {
            n = n1;
        }
        let at = m_at(seg, n);
        let gas = m_state(at.x, at.y, seg_point(seg, n), m_k_r(seg, n, m_per_s));
        if gas.ratio > 0.0 {
            lit = true;
            let x = gas.ratio / m_camera_ratio;
            let w = 0.5 * gas.ratio;
            let g3 = w / (x * x * x);
            for (var k = 0u; k < N_WL; k++) {
                if m_through[k] >= M_SPENT {
                    let c = m_coefficients(gas, x * P.wl[k].w);
                    m_coef[k] += vec2<f32>(c.x * g3, c.y * w);
                }
            }
        }
    }
    if !lit {
        return 0.0;
    }
    var worst = 0.0;
    for (var k = 0u; k < N_WL; k++) {
        worst = max(worst, m_coef[k].y * dl_inf);
    }
    if worst > MAX_DTAU && !finest {
        return -worst;
    }
    var alive = false;
    for (var k = 0u; k < N_WL; k++) {
        let c = m_coef[k];
        let dtau = c.y * dl_inf;
        let tr = m_through[k];
        m_int[k] += tr * c.x * dl_inf * piece_shown(dtau);
        m_through[k] = tr * exp(-dtau);
        alive = alive || m_through[k] >= M_SPENT;
    }
    m_alive = alive;
    return worst;
}

// Gathers the medium along a segment of unit-energy affine length
// `affine` (r_s, as the segments are) from fraction s0 to s1.
fn m_march(seg: Seg, affine: f32, s0: f32, s1: f32) {
    if P.medium_kind == MEDIUM_NONE || !(s1 > s0) {
        return;
    }
    let e0 = m_at(seg, s0);
    let em = m_at(seg, 0.5 * (s0 + s1));
    let e1 = m_at(seg, s1);
    let near = affine > 0.0 && min(e0.x, min(em.x, e1.x)) <= 1.2 * m_extent();
    let horizon = P.medium[3].x;
    let scale = min(
        min(min(m_scale(e0), 0.5 * abs(e0.x - horizon)), min(m_scale(em), 0.5 * abs(em.x - horizon))),
        min(m_scale(e1), 0.5 * abs(e1.x - horizon)),
    );
    // Lengths in M per unit of the fraction: the affine parameter's, in
    // r_s, doubled.
    let m_per_s = 2.0 * affine;
    let pieces = clamp(ceil(m_per_s * (s1 - s0) / (M_SCALE_FRACTION * scale)), 1.0, M_MAX_PIECES);
    let base_ds = (s1 - s0) / pieces;
    var ds = base_ds;
    let min_ds = (s1 - s0) / M_MAX_PIECES;
    let cm_per_s = m_per_s * P.medium_cm_per_m;
    var s = s0;
    var r_s = e0.x;
    var guard = 0u;
    while near && s < s1 && m_alive && guard < 4000000u {
        guard += 1u;
        var e = min(s + ds, s1);
        var r_e = m_at(seg, e).x;
        // A piece ends where the ray crosses a surface of the medium;
        // a crossing within half the finest piece of its start is the one
        // just ended (f32 may see it again): that piece is taken whole.
        for (var i = 0u; i < 2u; i++) {
            let b = m_surface(i);
            if b > 0.0 && (r_s > b) != (r_e > b) {
                let c = m_crossing(seg, s, e, b);
                if c - s > 0.5 * min_ds {
                    e = c;
                    r_e = m_at(seg, e).x;
                }
            }
        }
        let finest = ds <= min_ds;
        let dl = (e - s) * cm_per_s;
        let mid = 0.5 * (s + e);
        let half = M_GAUSS_2 * (e - s);
        let depth = m_piece(seg, mid - half, mid + half, m_per_s, dl, finest);
        if depth < 0.0 {
            ds = min(max(ds * MAX_DTAU / -depth, min_ds), 0.5 * ds);
        } else {
            s = e;
            r_s = r_e;
            var grow = 2.0;
            if depth > 0.0 {
                grow = clamp(0.8 * MAX_DTAU / depth, 1.0, 2.0);
            }
            ds = min(ds * grow, base_ds);
        }
    }
}

// The photon's energy in the tracer's units (the segments' affine length
// is |e h|, halved for Kerr's M): set where trace_paths starts its ray.
var<private> m_energy: f32;

// RayTransfer::surface of a blackbody: an opaque surface ends the ray,
// each frequency getting through the gas in front of it k B_nu(T) seen at
// g = nu_cam / nu_emit as g^3 k B_nu(nu_cam / g; T).
fn m_opaque(g: f32, kelvin: f32, k_scale: f32) {
    let g3 = g * g * g;
    for (var k = 0u; k < N_WL; k++) {
        if m_through[k] >= M_SPENT {
            m_int[k] += m_through[k] * g3 * k_scale * m_planck(P.wl[k].w / g, kelvin);
        }
        m_through[k] = 0.0;
    }
    m_alive = false;
}

// visit's part with a medium: the segment's gas gathered, up to the thin
// disk where it meets it; whether the ray goes on.
fn medium_visit(seg: Seg) -> bool {
    var affine = abs(m_energy * seg.h);
    if KERR {
        affine *= 0.5;
    }
    // The thin disk where the segment meets it (JanskyShade::disk in
    // src/render/jansky.rs): its blackbody light B_nu(f_col T) / f_col^4
    // ends the ray there.
    var s_disk = 2.0;
    var kelvin = 0.0;
    var p = vec3<f32>(0.0);
    if P.disk_kind != DISK_NONE && may_cross(seg.x0.z, seg.x1.z) {
        let s = seg_crossing_z0(seg);
        if s >= 0.0 {
            p = seg_point(seg, s);
            let hit = disk_hit(unturn_plane(disk_plane(p), emitted_at(seg, s)), 0u);
            if hit.alpha > 0.0 {
                s_disk = s;
                kelvin = P.thin_f_col * thin_temperature(disk_hit_radius(hit));
            }
        }
    }
    m_march(seg, affine, 0.0, min(s_disk, 1.0));
    if s_disk <= 1.0 {
        let f2 = P.thin_f_col * P.thin_f_col;
        m_opaque(exp(gr_disk_ln_shift(p)), kelvin, 1.0 / (f2 * f2));
    }
    return m_alive;
}

// A camera sample of an observed scene (JanskyShade in src/render/jansky.rs): each
// frequency's flux density (Jy) into the sample's spectrum, the
// brightness temperature at the first over DISPLAY_KELVIN as its grey
// light. The ray is traced by trace_paths, whose visits gather the gas.
fn medium_trace(camera: vec3<f32>, dir: vec3<f32>, px: f32, py: f32) -> Outcome {
    let r_c = length(camera);
    var ln_sky: f32;
    if KERR {
        let ray = ray_start(camera, dir);
        m_lz = (ray.x.x * ray.p.y - ray.x.y * ray.p.x) / ray.e;
        ln_sky = ks_observer_ln(m_lz) + cam_ln_d;
    } else {
        m_lz = 2.0 * photon_lz_over_e(camera, dir);
        ln_sky = sky_ln_shift(r_c) + cam_ln_d;
    }
    m_camera_ratio = exp(ln_sky);
    for (var k = 0u; k < N_WL; k++) {
        m_int[k] = 0.0;
        m_through[k] = 1.0;
    }
    m_alive = true;
    var o = trace_paths(camera, dir);
    if o.end == END_ESCAPED && P.sky_kind == SKY_BLACKBODY {
        // A blackbody sky at infinity, where the photon's frequency is
        // nu_cam / m_camera_ratio, behind whatever the ray crossed.
        m_opaque(m_camera_ratio, P.sky_kelvin, 1.0);
    }
    if o.end == END_STOPPED {
        // Stopped at the thin disk, or where the gas hides all behind it.
        o.disk = true;
    } else if o.end != END_CAPTURED && o.end != END_ESCAPED {
        // A ray cut short (lavapipe ends every loop of a group of
        // invocations after 65535 iterations in all): counted as
        // abandoned, which the closing line reports.
        o.end = END_ABANDONED;
    }
    // The pixel's solid angle as the distant observer sees it
    // (Camera::pixel_solid_angle times (r_cam / D)^2), in Jy per cgs.
    let sr = pixel_solid_angle(px, py) * P.medium_jy;
    var finite_all = true;
    for (var k = 0u; k < N_WL; k++) {
        spectra[spec_row + k] = m_int[k] * sr;
        finite_all = finite_all && finite(m_int[k]);
    }
    // Rayleigh-Jeans: T_b = I c^2 / (2 k nu^2), over DISPLAY_KELVIN.
    let nu0 = P.wl[0].w;
    let y = m_int[0] * P.medium_kelvin / (nu0 * nu0);
    color = vec3<f32>(select(bitcast<f32>(0x7fc00000u), y, finite_all));
    return o;
}
