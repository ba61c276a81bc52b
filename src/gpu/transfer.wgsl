// Radiative transfer in physical units (the MEDIUM variant): twin of
// src/transfer/mod.rs (RayTransfer's march and pieces) and the jansky
// shade (src/cpu/jansky.rs), in f32, through the media of media.wgsl.
// Lengths in M, positions from the segments' r_s; coefficients in cgs;
// P.wl[k].w the observed frequencies (Hz).

// The pieces are walked by pieces.wgsl's loop; its constants come from
// the header (SCALE_FRACTION, MAX_PIECES, SPENT, GAUSS_2, MAX_DTAU:
// transfer/mod.rs's).

// Each observed frequency's camera-frame intensity (cgs), transmittance
// and a piece's emission and absorption per unit of its unit-energy
// affine length (cgs); the photon's camera ratio and L_z / E (M).
var<private> m_int: array<f32, N_WL>;
var<private> m_through: array<f32, N_WL>;
var<private> m_coef: array<vec2<f32>, N_WL>;
var<private> m_camera_ratio: f32;
var<private> m_lz: f32;

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
        let gas = medium_state(at.x, at.y, seg_point(seg, n), m_lz, segment_k_r(seg, n, m_per_s));
        if gas.ratio > 0.0 {
            lit = true;
            let x = gas.ratio / m_camera_ratio;
            let w = 0.5 * gas.ratio;
            let g3 = w / (x * x * x);
            for (var k = 0u; k < N_WL; k++) {
                if m_through[k] >= SPENT {
                    let c = medium_coefficients(gas, x * P.wl[k].w);
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
        alive = alive || m_through[k] >= SPENT;
    }
    m_alive = alive;
    return worst;
}

// The segment being walked: M and cm per unit of its fraction.
var<private> walk_m_per_s: f32;
var<private> walk_cm_per_s: f32;

// The piece from s to e (MediumPieces::take): m_piece at its nodes.
fn m_take(seg: Seg, s: f32, e: f32, finest: bool) -> f32 {
    let mid = 0.5 * (s + e);
    let half = GAUSS_2 * (e - s);
    return m_piece(seg, mid - half, mid + half, walk_m_per_s, (e - s) * walk_cm_per_s, finest);
}

// A piece from s to e starting at radius r_start ends where the ray
// crosses a surface of the medium: (its end, the radius there). A
// crossing within half the finest piece of its start is the one just
// ended (f32 may see it again): that piece is taken whole.
fn m_cut(seg: Seg, s: f32, e_in: f32, r_start: f32, min_ds: f32) -> vec2<f32> {
    var e = e_in;
    var r_e = m_at(seg, e).x;
    for (var i = 0u; i < 2u; i++) {
        let b = medium_surface(i);
        if b > 0.0 && (r_start > b) != (r_e > b) {
            let c = m_crossing(seg, s, e, b);
            if c - s > 0.5 * min_ds {
                e = c;
                r_e = m_at(seg, e).x;
            }
        }
    }
    return vec2<f32>(e, r_e);
}

// Gathers the medium along a segment of unit-energy affine length
// `affine` (r_s, as the segments are) from fraction s0 to s1
// (RayTransfer::march and run).
fn m_march(seg: Seg, affine: f32, s0: f32, s1: f32) {
    if P.medium_kind == MEDIUM_NONE || !(s1 > s0) {
        return;
    }
    let e0 = m_at(seg, s0);
    let em = m_at(seg, 0.5 * (s0 + s1));
    let e1 = m_at(seg, s1);
    if !(affine > 0.0 && min(e0.x, min(em.x, e1.x)) <= 1.2 * medium_extent()) {
        return;
    }
    let horizon = P.medium_horizon;
    let scale = min(
        min(min(medium_scale(e0), 0.5 * abs(e0.x - horizon)), min(medium_scale(em), 0.5 * abs(em.x - horizon))),
        min(medium_scale(e1), 0.5 * abs(e1.x - horizon)),
    );
    // Lengths in M per unit of the fraction: the affine parameter's, in
    // r_s, doubled.
    walk_m_per_s = 2.0 * affine;
    walk_cm_per_s = walk_m_per_s * P.medium_cm_per_m;
    pieces_walk(seg, s0, s1, pieces_count(walk_m_per_s * (s1 - s0), scale));
}

// RayTransfer::surface of a blackbody: an opaque surface ends the ray,
// each frequency getting through the gas in front of it k B_nu(T) seen at
// g = nu_cam / nu_emit as g^3 k B_nu(nu_cam / g; T).
fn m_opaque(g: f32, kelvin: f32, k_scale: f32) {
    let g3 = g * g * g;
    for (var k = 0u; k < N_WL; k++) {
        if m_through[k] >= SPENT {
            m_int[k] += m_through[k] * g3 * k_scale * planck_nu(P.wl[k].w / g, kelvin);
        }
        m_through[k] = 0.0;
    }
    m_alive = false;
}

// A camera sample of an observed scene (JanskyShade in src/cpu/jansky.rs): each
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
