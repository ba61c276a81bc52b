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

// The path the pieces walk (transfer/mod.rs's Path): an integrator's or
// Schwarzschild's closed-form segment, a stretch of Kerr's closed-form
// ray (transfer::closed::Stretch: r and cos theta at its ends and their
// rates per unit of its parameter, as (f0, f1, d0, d1), within the ray's
// range of cos theta), or its straight way out far from the hole
// (Straight: walk_r.x the radius at its start, walk_r.y its length,
// walk_cos.x cos theta).
const PATH_SEGMENT: u32 = 0u;
const PATH_STRETCH: u32 = 1u;
const PATH_STRAIGHT: u32 = 2u;
var<private> walk_path: u32;
var<private> walk_r: vec4<f32>;
var<private> walk_cos: vec4<f32>;
var<private> walk_cos_range: vec2<f32>;

// The cubic through values (f.x, f.y) with rates (f.z, f.w) at 0 and 1,
// at t; and its rate.
fn hermite4(f: vec4<f32>, t: f32) -> f32 {
    let t2 = t * t;
    let t3 = t2 * t;
    return f.x * (2.0 * t3 - 3.0 * t2 + 1.0) + f.y * (3.0 * t2 - 2.0 * t3) + f.z * (t3 - 2.0 * t2 + t) + f.w * (t3 - t2);
}

fn hermite4_rate(f: vec4<f32>, t: f32) -> f32 {
    let t2 = t * t;
    return f.x * (6.0 * t2 - 6.0 * t) + f.y * (6.0 * t - 6.0 * t2) + f.z * (3.0 * t2 - 4.0 * t + 1.0) + f.w * (3.0 * t2 - 2.0 * t);
}

// (r, cos th, z) in M of the path's point at s (Path::at).
fn m_at(seg: Seg, s: f32) -> vec3<f32> {
    if walk_path == PATH_STRETCH {
        let r = hermite4(walk_r, s);
        let c = clamp(hermite4(walk_cos, s), walk_cos_range.x, walk_cos_range.y);
        return vec3<f32>(r, c, r * c);
    }
    if walk_path == PATH_STRAIGHT {
        let r = walk_r.x + s * walk_r.y;
        return vec3<f32>(r, walk_cos.x, r * walk_cos.x);
    }
    let p = seg_point(seg, s) * 2.0;
    var r = length(p);
    if KERR {
        r = ks_radius(p);
    }
    return vec3<f32>(r, clamp(p.z / r, -1.0, 1.0), p.z);
}

// The path's point in the segments' r_s: a stretch's at azimuth 0 (the
// media along closed-form rays are axisymmetric).
fn m_point(seg: Seg, s: f32, at: vec3<f32>) -> vec3<f32> {
    if walk_path == PATH_SEGMENT {
        return seg_point(seg, s);
    }
    return 0.5 * vec3<f32>(at.x * sqrt(max(1.0 - at.y * at.y, 0.0)), 0.0, at.z);
}

// The photon's (dr/dlambda, d(cos th)/dlambda) (M) at s (Path::k_at):
// against the trace.
fn m_k(seg: Seg, s: f32, m_per_s: f32) -> vec2<f32> {
    if walk_path == PATH_STRETCH {
        return vec2<f32>(-hermite4_rate(walk_r, s), -hermite4_rate(walk_cos, s)) / m_per_s;
    }
    if walk_path == PATH_STRAIGHT {
        return vec2<f32>(-1.0, 0.0);
    }
    return segment_k(seg, s, m_per_s);
}

// The level of the medium's inner surface at s (MediumPieces::level).
fn m_level(seg: Seg, s: f32) -> f32 {
    let at = m_at(seg, s);
    return medium_level(at.x, at.y, m_point(seg, s, at));
}

// Where between a and b the level first crosses 1 from `above` (or
// below): pieces::side_change.
fn m_level_change(seg: Seg, a: f32, b: f32, above: bool) -> f32 {
    var lo = a;
    var hi = b;
    for (var i = 0u; i < 30u; i++) {
        let mid = 0.5 * (lo + hi);
        if (m_level(seg, mid) > 1.0) == above {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return hi;
}

// Whether the piece being taken touches the medium's inner surface or
// comes near it (MediumPieces::edge).
var<private> m_edge: bool;

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
    // Each node's brightest emission (ln; -3.4e38 where it has none).
    var shown = vec2<f32>(-3.4e38);
    var scale = 0.0;
    for (var k = 0u; k < N_WL; k++) {
        m_coef[k] = vec2<f32>(0.0);
    }
    for (var i = 0u; i < 2u; i++) {
        var n = n0;
        if i == 1u {
            n = n1;
        }
        let at = m_at(seg, n);
        let kk = m_k(seg, n, m_per_s);
        let gas = medium_state(at.x, at.y, m_point(seg, n, at), m_lz, kk.x, kk.y);
        if i == 0u && m_edge {
            scale = medium_scale(at);
        }
        if gas.ratio > 0.0 {
            lit = true;
            let x = gas.ratio / m_camera_ratio;
            let w = 0.5 * gas.ratio;
            let g3 = w / (x * x * x);
            // The node's brightest emission in logarithms: f32 would lose
            // the faint side of a contrast to underflow.
            var node = -3.4e38;
            for (var k = 0u; k < N_WL; k++) {
                if m_through[k] >= SPENT {
                    let c = medium_coefficients(gas, x * P.wl[k].w);
                    m_coef[k] += vec2<f32>(c.x * g3, c.y * w);
                    if m_edge {
                        node = max(node, medium_ln_emission(gas, x * P.wl[k].w) + log(g3));
                    }
                }
            }
            shown = select(vec2<f32>(shown.x, node), vec2<f32>(node, shown.y), i == 0u);
        }
    }
    if !lit {
        return 0.0;
    }
    // Against a surface inside the medium, thinner where the nodes
    // disagree, down to SHARPEST of its scale (RayTransfer::piece).
    let sharp = m_edge && !finest && (n1 - n0) / (2.0 * GAUSS_2) * m_per_s > SHARPEST * scale;
    // |a - b| > CONTRAST (a + b): a ratio above (1 + CONTRAST) / (1 -
    // CONTRAST).
    if sharp && abs(shown.x - shown.y) > log((1.0 + CONTRAST) / (1.0 - CONTRAST)) {
        return -2.0 * MAX_DTAU;
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
// (RayTransfer::march).
fn m_march(seg: Seg, affine: f32, s0: f32, s1: f32) {
    walk_path = PATH_SEGMENT;
    // Lengths in M per unit of the fraction: the affine parameter's, in
    // r_s, doubled.
    m_run(seg, s0, s1, 2.0 * affine);
}

// RayTransfer::run: the medium along the path being walked from s0 to s1,
// `m_per_s` M of it per unit of s.
fn m_run(seg: Seg, s0: f32, s1: f32, m_per_s: f32) {
    if P.medium_kind == MEDIUM_NONE || !(s1 > s0) {
        return;
    }
    let e0 = m_at(seg, s0);
    let em = m_at(seg, 0.5 * (s0 + s1));
    let e1 = m_at(seg, s1);
    if !(m_per_s > 0.0 && min(e0.x, min(em.x, e1.x)) <= 1.2 * medium_extent()) {
        return;
    }
    let horizon = P.medium_horizon;
    let scale = min(
        min(min(medium_scale(e0), 0.5 * abs(e0.x - horizon)), min(medium_scale(em), 0.5 * abs(em.x - horizon))),
        min(medium_scale(e1), 0.5 * abs(e1.x - horizon)),
    );
    walk_m_per_s = m_per_s;
    walk_cm_per_s = m_per_s * P.medium_cm_per_m;
    pieces_walk(seg, s0, s1, pieces_count(m_per_s * (s1 - s0), scale));
}

// The stretch of `c` from state a to state b (kc_state_at), ds of Mino
// time apart (transfer::closed::Stretch::new), made the path walked: its
// affine length (M) by three-point Gauss-Legendre on the cubic Hermite
// curves of 1/r and cos theta in s, its points cubic Hermite curves in
// the affine parameter.
fn m_stretch(a: vec4<f32>, b: vec4<f32>, ds: f32, range: vec2<f32>) -> f32 {
    let a2 = P.kerr_hole.x * P.kerr_hole.x;
    let inv = vec4<f32>(1.0 / a.x, 1.0 / b.x, -a.y / (a.x * a.x) * ds, -b.y / (b.x * b.x) * ds);
    let cos_s = vec4<f32>(a.z, b.z, a.w * ds, b.w * ds);
    var sig = vec3<f32>(0.0);
    let node = 0.5 * 0.7745966692;
    let ts = vec3<f32>(0.5 - node, 0.5, 0.5 + node);
    for (var i = 0u; i < 3u; i++) {
        let r = 1.0 / hermite4(inv, ts[i]);
        let c = hermite4(cos_s, ts[i]);
        sig[i] = r * r + a2 * c * c;
    }
    let length = 0.5 * ds * (8.0 / 9.0 * sig.y + 5.0 / 9.0 * (sig.x + sig.z));
    let per_a = length / (a.x * a.x + a2 * a.z * a.z);
    let per_b = length / (b.x * b.x + a2 * b.z * b.z);
    walk_path = PATH_STRETCH;
    walk_r = vec4<f32>(a.x, b.x, a.y * per_a, b.y * per_b);
    walk_cos = vec4<f32>(a.z, b.z, a.w * per_a, b.w * per_b);
    walk_cos_range = range;
    return length;
}

// transfer::closed::along_kerr_ray: the medium along Kerr's closed-form
// ray `c` from Mino time s_start to s_stop, in stretches of at most
// KERR_STRETCH of their radius, KERR_SWING of polar phase and half the
// way to the horizon, each walked by the pieces; past KERR_FAR going out,
// straight to the medium's end. Gives the stretches walked.
fn m_along_kerr(c: KerrClosed, s_start: f32, s_stop: f32) -> u32 {
    if P.medium_kind == MEDIUM_NONE {
        return 0u;
    }
    let seg = Seg(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), 0.0, false, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let beyond = 1.2 * medium_extent();
    let horizon = P.medium_horizon;
    let a2 = P.kerr_hole.x * P.kerr_hole.x;
    let range = kc_cos_range(c);
    var s = s_start;
    var here = kc_state_at(c, s);
    var stretches = 0u;
    while s < s_stop && m_alive && stretches < 100000u {
        let r = here.x;
        if r > KERR_FAR && here.y > 0.0 {
            if r < beyond {
                walk_path = PATH_STRAIGHT;
                walk_r = vec4<f32>(r, beyond - r, 0.0, 0.0);
                walk_cos = vec4<f32>(here.z, 0.0, 0.0, 0.0);
                m_run(seg, 0.0, 1.0, beyond - r);
                stretches += 1u;
            }
            break;
        }
        let sigma = r * r + a2 * here.z * here.z;
        let fall = 0.5 * (r - horizon) / max(abs(here.y), 1e-30);
        var ds = min(min(KERR_STRETCH * r / sigma, KERR_SWING / c.pscale), fall);
        var e = s;
        var there = here;
        for (var k = 0u; k < 60u; k++) {
            e = min(s + ds, s_stop);
            there = kc_state_at(c, e);
            if e == s_stop || there.x - horizon > 0.4 * (r - horizon) {
                break;
            }
            ds *= 0.5;
        }
        if !(e > s) || (there.x > r && r > beyond) {
            break;
        }
        let length = m_stretch(here, there, e - s, range);
        m_run(seg, 0.0, 1.0, length);
        s = e;
        here = there;
        stretches += 1u;
    }
    walk_path = PATH_SEGMENT;
    return stretches;
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
