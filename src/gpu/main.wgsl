// Two passes, as src/cpu/mod.rs renders (Integrator::trace_sample,
// Scene::render): `main` traces and shades one sample of one pixel per
// invocation and stores it in its slot; `resolve` sums each pixel's
// samples in order into the film (XYZ, spectra or bloom bands when kept)
// and counts them by class. One invocation per sample keeps every
// invocation's loops short (llvmpipe ends an invocation's loops after
// 65535 iterations in all) and spreads many samples over the GPU.

// The sample being shaded.
var<private> color: vec3<f32>;
var<private> xyz_acc: vec3<f32>;
// Where the sample's spectrum goes in `spectra`, when kept.
var<private> spec_row: u32;
var<private> through: f32;
var<private> met_disk: bool;
var<private> met_object: bool;
// The first object met (NONE: none), for adaptive sampling's classes.
var<private> first_obj: u32;
// Transmittance of the mirrors and clouds met so far (RGB; per wavelength).
var<private> rgb_filter: vec3<f32>;
var<private> wl_filter: array<f32, FILTER_LEN>;
// Seed model: the running sum from the camera to this path's start.
var<private> ln_offset: f32;
// The light's travel time from this path's start back to the camera.
var<private> time_offset: f32;
var<private> g_min: f32;
var<private> g_max: f32;
// Frequency shifts of the current path (cpu::Shifts): computed
// (shift_on: a spectral render with the shift on, or the g map) and
// applied to the light (shift_render: the former alone).
var<private> shift_on: bool;
var<private> shift_render: bool;
var<private> doppler_on: bool;
var<private> r_cam: f32;
var<private> lz_over_e: f32;
// KERR: ln (nu / E) at the camera's frame for the light it receives (the
// camera path's L_z / E decides it), cpu::Shifts::observer.
var<private> obs_ln: f32;
// The camera ray's impact parameter and the direction of its angular
// momentum x cross v, from its image point without f32's cancellation
// (a camera at 1e6 r_s would lose b to 2% in the cross product); b < 0
// where not known.
var<private> exact_b: f32;
var<private> exact_l: vec3<f32>;
// KERR: the camera ray's local direction along its forward, right and up
// axes, for the closed form's linear forms (Params::kerr_rays).
var<private> cam_local: vec3<f32>;
// OBSERVE (cpu::Probing): the first light met (g, ring radius, travel
// time), its image order, which of them it has (PROBE_* bits; 0 until
// light is met), and the crossings of the plane z = 0 so far.
var<private> probe: vec3<f32>;
var<private> probe_order: u32;
var<private> probe_bits: u32;
var<private> crossings: u32;
// The crossings are counted where a probe or a footprint needs the image
// order (a disk hit reads the footprint of its own crossing: fp_disk).
const COUNT_CROSSINGS: bool = OBSERVE || FOOTPRINT;
// OBSERVE: the first light's magnification (with PROBE_MAG), and the
// ray's direction at infinity where it escapes.
var<private> probe_mu: f32;
var<private> probe_sky: vec3<f32>;
var<private> probe_has_sky: bool;
// Where (fraction of the step) the step being marched crosses the plane
// off the disk, not yet counted (Probing::pending; negative: none).
var<private> pending_cross: f32;

// Probing::light: light of ln g `ln_g` from ring radius `radius`, `order`
// crossings in, `time` from the camera, noted if it is the first; `has`:
// which of radius, order and time it has (PROBE_* bits).
// `mu`: its magnification and 1, or zeros where not known (FOOTPRINT).
fn probe_light(ln_g: f32, radius: f32, order: u32, time: f32, has: u32, mu: vec2<f32>) {
    if !OBSERVE || probe_bits != 0u {
        return;
    }
    probe = vec3<f32>(exp(ln_g), radius, time);
    probe_order = order;
    probe_bits = PROBE_G | has | select(0u, PROBE_MAG, mu.y > 0.0);
    probe_mu = mu.x;
}

// Probing::escaped: where the ray went at infinity.
fn probe_escaped(d: vec3<f32>) {
    if OBSERVE {
        probe_sky = d;
        probe_has_sky = true;
    }
}

// The sample's probe as its slot holds it (PROBE_VEC4S vec4s from `at`):
// the values it has and is a finite number for, the rest zero (Probe's
// NaN; PixelProbe::add adds finite values only).
fn probe_write(at: u32) {
    var bits = probe_bits & PROBE_ORDER;
    var v = vec3<f32>(0.0);
    if (probe_bits & PROBE_G) != 0u && finite(probe.x) {
        bits |= PROBE_G;
        v.x = probe.x;
    }
    if (probe_bits & PROBE_RADIUS) != 0u && finite(probe.y) {
        bits |= PROBE_RADIUS;
        v.y = probe.y;
    }
    if (probe_bits & PROBE_TIME) != 0u && finite(probe.z) {
        bits |= PROBE_TIME;
        v.z = probe.z;
    }
    var w = vec4<f32>(0.0);
    if (probe_bits & PROBE_MAG) != 0u && finite(probe_mu) {
        bits |= PROBE_MAG;
        w.x = probe_mu;
    }
    if probe_has_sky && finite3(probe_sky) {
        bits |= PROBE_SKY;
        w = vec4<f32>(w.x, probe_sky);
    }
    if (bits & PROBE_ORDER) != 0u {
        bits |= probe_order << PROBE_ORDER_SHIFT;
    }
    film[at] = vec4<f32>(v, bitcast<f32>(bits));
    film[at + 1u] = w;
}

// Shifts::travel_time: the light's travel time from fraction s of `seg` to
// the camera where the trace keeps it (TRAVEL; its PROBE_TIME bit is
// timed_bit()).
fn travel_time(seg: Seg, s: f32) -> f32 {
    if TRAVEL {
        return time_offset + seg_time(seg, s);
    }
    return 0.0;
}

fn timed_bit() -> u32 {
    return select(0u, PROBE_TIME, TRAVEL);
}

// Shifts::light: the shift the light gets (none where only the g map sees
// it).
fn light_ln(ln_g: f32) -> f32 {
    if OBSERVE && !shift_render {
        return 0.0;
    }
    return ln_g;
}

// Shifts::travel: the disk is seen as it was when its light left it. With
// OBSERVE the timed trace (TRAVEL) may be for the time map alone.
fn seen_late() -> bool {
    return TRAVEL && (!OBSERVE || has_flag(FLAG_LIGHT_TRAVEL));
}

struct Start {
    ok: bool,
    x: vec3<f32>,
    v: vec3<f32>,
}

// The exact model's far camera: its ray's state where it first reaches a
// radius at which f32 holds it (beyond everything in the scene), from the
// exact b and plane and the swept angle of the way in between (that of the
// escape tail from there less that from the camera); ok is false where the
// camera is near enough, or the ray turns before it gets there.
fn exact_start(r: f32) -> Start {
    var s: Start;
    s.ok = false;
    // With spin the start lies farther out, at 5000 r_s (1e4 M): there the
    // ingoing Kerr-Schild chart's azimuth differs from Boyer-Lindquist's by
    // a M^2 / r^2 = 1e-8 rad and spin bends light by less, where at 100 r_s
    // the 1e-5 rad of it, magnified by the lensing near the hole, moved
    // the sky by up to 2e-4 rad; and f32 at 1e4 M still places a ray to
    // 1e-3 M.
    var to = max(2.0 * P.outer_limit, 100.0);
    if KERR {
        to = max(2.0 * P.outer_limit, 5000.0);
    }
    let b = exact_b;
    // A ray that passes far from the hole starts farther out (4 b), where
    // it is as straight: from a camera 1e21 r_s out, the integrator in
    // f32 cannot take it the whole way.
    to = max(to, 4.0 * b);
    if !(r > 4.0 * to && b < 0.5 * to) {
        return s;
    }
    let e1 = P.cam_pos.xyz / r;
    let e2 = normalize(cross(exact_l, e1));
    let swept = escape_sweep(b, 1.0 / to) - escape_sweep(b, 1.0 / r);
    let er = e1 * cos(swept) + e2 * sin(swept);
    let ephi = e2 * cos(swept) - e1 * sin(swept);
    // v_inf = 1: h = b, |v|^2 = 1 + b^2 / r^3; inbound.
    let vt = b / to;
    let vr = -sqrt(max(1.0 + b * b / (to * to * to) - vt * vt, 0.0));
    s.x = er * to;
    s.v = er * vr + ephi * vt;
    s.ok = true;
    return s;
}

// Sets exact_b and exact_l for the camera's ray through image point `s`
// (gr's static camera at r_cam with the hole ahead).
fn set_exact_ray(s: vec2<f32>) {
    exact_b = -1.0;
    if P.static_observer == 0u || P.cam_hole.w == 0.0 {
        return;
    }
    // A = (1, sx, sy) and B = (1, hx, hy) in (forward, right, up): the
    // ray's and the hole's directions; A x B without cancellation.
    let hole = P.cam_hole.xy;
    let c0 = vec3<f32>(s.x * hole.y - s.y * hole.x, s.y - hole.y, hole.x - s.x);
    // Scaled to its largest component before its length: from a camera
    // 1e19 r_s out the image's offsets are 1e-19, whose squares f32
    // flushes to zero (and the ray then had no exact start).
    let big = max(abs(c0.x), max(abs(c0.y), abs(c0.z)));
    if !(big > 0.0) {
        return;
    }
    let c = c0 / big;
    let len = length(c) * big;
    let a = vec3<f32>(1.0, s.x, s.y);
    let b = vec3<f32>(1.0, hole.x, hole.y);
    let r = safe_length(P.cam_pos.xyz);
    exact_b = camera_impact(r, len / (length(a) * length(b)));
    let world = P.cam_fwd.xyz * c.x + P.cam_right.xyz * c.y + P.cam_up.xyz * c.z;
    exact_l = normalize(world) * P.cam_hole.w;
}

var<workgroup> wg_counts: array<atomic<u32>, 6>;
var<workgroup> wg_steps: atomic<u32>;
var<workgroup> wg_closed: atomic<u32>;
var<workgroup> wg_g_min: atomic<u32>;
var<workgroup> wg_g_max: atomic<u32>;

// physics::shift::gr_disk_ln_shift and seed_disk_ln_shift, for the point
// at fraction s of `seg` (cpu::Shifts::disk).
fn disk_ln_shift(seg: Seg, s: f32, p: vec3<f32>) -> f32 {
    if !shift_on {
        return 0.0;
    }
    if P.model == MODEL_GR {
        return gr_disk_ln_shift(p);
    }
    let gravity = ln_offset + seg_ln_shift(seg, s) + cam_ln_d;
    if !doppler_on {
        return gravity;
    }
    let r = sqrt(p.x * p.x + p.y * p.y);
    let speed = sqrt(0.5 / r);
    let u = vec3<f32>(-p.y, p.x, 0.0) / r * speed;
    let n = -normalize(seg_tangent(seg, s));
    let gamma = 1.0 / sqrt(1.0 - speed * speed);
    return gravity - log(gamma * (1.0 - dot(u, n)));
}

// Scene::shade_disk_hit: a crossing of the disk's material seen through
// `through`; cutout alpha ends the ray, blended alpha lets the light behind
// through until almost nothing gets through. True where the ray stops.
fn shade_disk_hit(hit: DiskHit, ln_g: f32) -> bool {
    met_disk = true;
    // One call of shade_disk: the driver inlines each call whole.
    let cut = P.disk_alpha == 0u;
    shade_disk(hit, select(through, through / hit.alpha, cut), ln_g);
    if cut {
        return true;
    }
    through *= 1.0 - hit.alpha;
    return through < 1e-4;
}

// Shifts::sky for the exact model: sky light at the static camera, whatever
// the path.
fn gr_sky_ln_shift() -> f32 {
    if !shift_on {
        return 0.0;
    }
    if KERR {
        return obs_ln + cam_ln_d;
    }
    return sky_ln_shift(r_cam) + cam_ln_d;
}

// Shifts::gr_disk: the exact model's disk light at `p`, from the point and
// the photon's conserved L_z/E alone (shift_on checked by the caller).
fn gr_disk_ln_shift(p: vec3<f32>) -> f32 {
    if KERR {
        return obs_ln - ks_emitter_ln(2.0 * p, lz_over_e, doppler_on) + cam_ln_d;
    }
    return disk_emitter_ln_shift(length(p), lz_over_e, doppler_on) - 0.5 * log(1.0 - 1.0 / r_cam) + cam_ln_d;
}

// cpu::Shifts::emitted_at: when the light left fraction s of `seg`.
fn emitted_at(seg: Seg, s: f32) -> f32 {
    if seen_late() {
        return P.time - (time_offset + seg_time(seg, s));
    }
    return P.time;
}

// cpu::Shifts::fixed: light from a static emitter at `p`.
fn fixed_ln_shift(seg: Seg, s: f32, p: vec3<f32>) -> f32 {
    if !shift_on {
        return 0.0;
    }
    if KERR {
        return obs_ln + ks_static_ln(2.0 * p) + cam_ln_d;
    }
    if P.model == MODEL_GR {
        return static_ln_shift(length(p), r_cam) + cam_ln_d;
    }
    return ln_offset + seg_ln_shift(seg, s) + cam_ln_d;
}

// cpu::Shifts::moving: light from the volume's gas at `p`, moving as its
// motion (motion.wgsl) against the camera's measure of the photon; a
// static emitter's without the Doppler shift, the seed model's disk's in
// its flat space. (ln g, 1), or (_, 0) where the motion is not timelike.
fn moving_ln_shift(seg: Seg, s: f32, p: vec3<f32>) -> vec2<f32> {
    if P.model != MODEL_GR {
        return vec2<f32>(disk_ln_shift(seg, s, p), 1.0);
    }
    if !(shift_on && doppler_on) {
        return vec2<f32>(fixed_ln_shift(seg, s, p), 1.0);
    }
    let q = 2.0 * p;
    var r = length(q);
    // Spacetime::photon_lz_over_e is in r_s without spin.
    var lz = 2.0 * lz_over_e;
    if KERR {
        r = ks_radius(q);
        lz = lz_over_e;
    }
    let ratio = motion_frequency_ratio(r, clamp(q.z / r, -1.0, 1.0), lz, segment_k_r(seg, s, 2.0 * m_affine(seg)));
    return vec2<f32>(gr_sky_ln_shift() - log(ratio), select(0.0, 1.0, ratio > 0.0));
}

fn shade_disk(h: DiskHit, k: f32, ln_g: f32) {
    let thin = P.thin_profile != PROFILE_NONE;
    let f_col = P.thin_f_col;
    if !SPECTRAL {
        if thin {
            let c = thin_xyz(f_col * thin_temperature(disk_hit_radius(h))) / pow(f_col, 4.0);
            let rgb = vec3<f32>(
                3.2406 * c.x - 1.5372 * c.y - 0.4986 * c.z,
                -0.9689 * c.x + 1.8758 * c.y + 0.0415 * c.z,
                0.0557 * c.x - 0.2040 * c.y + 1.0570 * c.z,
            );
            color += rgb * thin_modulation(h) * P.disk_intensity * rgb_filter * k;
            return;
        }
        color += h.rgba.xyz * P.disk_intensity * rgb_filter * k;
        return;
    }
    let g = exp(ln_g);
    g_min = min(g_min, g);
    g_max = max(g_max, g);
    let kk = k * P.disk_intensity * radiance_factor(g);
    if thin {
        // With beaming, g^5 B_lambda(g lambda; T) = B_lambda(lambda; g T).
        let t = f_col * thin_temperature(disk_hit_radius(h));
        let kw = kk * thin_modulation(h) / pow(f_col, 4.0);
        if t > 0.0 {
            for (var j = 0u; j < N_WL; j += 4u) {
                emit4(j, kw * planck_nm4(g * nm4(j), t));
            }
        }
        return;
    }
    if P.disk_kind == DISK_RGB {
        let px = h.rgba;
        let c = uplift(px.xyz / px.w);
        let kw = kk * px.w;
        for (var j = 0u; j < N_WL; j += 4u) {
            emit4(j, kw * uplift_emission4(c, g * nm4(j)));
        }
        return;
    }
    if FOOTPRINT && h.fp {
        for (var j = 0u; j < N_WL; j += 4u) {
            emit4(j, kk * ewa_disk_set4(vec2<f32>(h.u, h.v), h.duv.xy, h.duv.zw, g * nm4(j)));
        }
        return;
    }
    let s = set_texels(h.u, h.v);
    for (var q = 0u; q < s.n; q++) {
        let t = s.t[q];
        let kw = kk * s.w[q] * set_alpha(t);
        for (var j = 0u; j < N_WL; j += 4u) {
            let nm = g * nm4(j);
            emit4(j, kw * vec4<f32>(set_value(t, nm.x), set_value(t, nm.y), set_value(t, nm.z), set_value(t, nm.w)));
        }
    }
}

fn shade_sky(dir: vec3<f32>, k: f32, ln_g: f32) {
    if !SPECTRAL {
        color += sky_rgb(dir) * rgb_filter * k;
        return;
    }
    sky_spectrum(dir, exp(ln_g), k);
}

// A mirror of colour `rgb` met with frequency ratio g filters what follows.
fn shade_tint(rgb: vec3<f32>, g: f32) {
    if !SPECTRAL {
        rgb_filter *= rgb;
        return;
    }
    if FILTERS {
        let c = uplift(rgb);
        for (var j = 0u; j < N_WL; j += 4u) {
            scale_filter4(j, uplift_reflectance4(c, g * nm4(j)));
        }
    }
}

// Gas of the volumetric disk at `kelvin`, weight k.
fn shade_volume(kelvin: f32, k: f32, ln_g: f32) {
    if !SPECTRAL {
        color += volume_rgb(kelvin) * rgb_filter * k;
        return;
    }
    let g = exp(ln_g);
    g_min = min(g_min, g);
    g_max = max(g_max, g);
    planck_add(kelvin, g, k);
}

// A cloud sample of optical depth kappa_dl (550 nm): its glow, then its
// absorption of everything behind it.
fn shade_cloud(rec: u32, kappa_dl: f32, k: f32, ln_g: f32) {
    let beta = odf(rec + 5u);
    if !SPECTRAL {
        let l = vec3<f32>(610.0, 550.0, 465.0);
        var ext = vec3<f32>(1.0);
        if beta != 0.0 {
            ext = pow(l / 550.0, vec3<f32>(-beta));
        }
        let dtau = kappa_dl * ext;
        let shown = vec3<f32>(piece_shown(dtau.x), piece_shown(dtau.y), piece_shown(dtau.z));
        color += od3(rec + 8u) * dtau * shown * rgb_filter * k;
        rgb_filter *= exp(-dtau);
        return;
    }
    let g = exp(ln_g);
    let kk = k * radiance_factor(g);
    var g_beta = 1.0;
    if beta != 0.0 {
        g_beta = pow(g, -beta);
    }
    let c = vec4<f32>(odf(rec + 12u), odf(rec + 13u), odf(rec + 14u), odf(rec + 15u));
    let ext = od(rec + 16u);
    for (var j = 0u; j < N_WL; j += 4u) {
        let e = vec4<f32>(odf(ext + lane(j, 0u)), odf(ext + lane(j, 1u)), odf(ext + lane(j, 2u)), odf(ext + lane(j, 3u)));
        // The glow is the source function: S (1 - e^-dtau).
        let dtau = kappa_dl * g_beta * e;
        let shown = vec4<f32>(piece_shown(dtau.x), piece_shown(dtau.y), piece_shown(dtau.z), piece_shown(dtau.w));
        emit4(j, kk * dtau * shown * uplift_emission4(c, g * nm4(j)));
        if FILTERS {
            scale_filter4(j, exp(-dtau));
        }
    }
}

const VISIT_CONTINUE: u32 = 0u;
const VISIT_STOP: u32 = 1u;
const VISIT_BOUNCE: u32 = 2u;

// A mirror's reflection, to be traced next.
var<private> bounce_origin: vec3<f32>;
var<private> bounce_dir: vec3<f32>;
// KERR: the reflected null vector's time component.
var<private> bounce_t: f32;
var<private> bounce_tint: vec3<f32>;
var<private> bounce_ln_g: f32;
var<private> bounce_time: f32;

// Shade::gas: the gas along `seg` from s0 to s1, the visible band's
// (march) or an observed scene's medium (m_march); whether the ray is
// spent.
fn gas_march(seg: Seg, s0: f32, s1: f32) -> bool {
    if MEDIUM {
        m_march(seg, m_affine(seg), s0, s1);
        return !m_alive;
    }
    return march(seg, s0, s1);
}

// The visitor of src/cpu/mod.rs (Integrator::trace_sample): the nearest
// object on the chord, the disk if met before it, gas in order along the
// segment, then the object's surface or mirror.
fn visit(seg: Seg) -> u32 {
    let near = nearest_object(seg.x0, seg.x1);
    let obj = near.obj;
    let h = near.hit;
    var s_object = 1.0;
    if obj != NONE {
        s_object = h.s;
    }
    // An observed scene's gas is its medium (whose volume's grid the GAS
    // variant may hold too), transferred in janskys (transfer.wgsl).
    let gas = select(GAS && (P.at_volume != NONE || P.n_clouds > 0u), P.medium_kind != MEDIUM_NONE, MEDIUM);
    var s_gas = 0.0;
    // OBSERVE: the image order counts every crossing before any object, on
    // the disk or not; one that missed the disk is counted after this
    // step's gas, the gas beyond it one order later.
    var missed = false;
    var s_cross = -1.0;
    if may_cross(seg.x0.z, seg.x1.z) {
        let s = seg_crossing_z0(seg);
        if s >= 0.0 && s < s_object {
            missed = true;
            s_cross = s;
            let p = seg_point(seg, s);
            let hit = disk_hit(unturn_plane(disk_plane(p), emitted_at(seg, s)), crossings);
            if hit.alpha > 0.0 {
                if gas && gas_march(seg, 0.0, s) {
                    return VISIT_STOP;
                }
                let ln_g = disk_ln_shift(seg, s, p);
                if OBSERVE {
                    probe_light(ln_g, ring_radius(length(p.xy)), crossings, travel_time(seg, s), PROBE_RADIUS | PROBE_ORDER | timed_bit(), fp_disk_magnification_at(crossings));
                }
                if COUNT_CROSSINGS {
                    crossings += 1u;
                }
                if MEDIUM {
                    thin_disk_janskys(hit, ln_g);
                    return VISIT_STOP;
                }
                if shade_disk_hit(hit, light_ln(ln_g)) {
                    return VISIT_STOP;
                }
                s_gas = s;
                missed = false;
            }
        }
    } else if OBSERVE && gas && P.disk_kind == DISK_NONE {
        // No disk: the gas's order still counts the crossings.
        let s = seg_crossing_z0(seg);
        missed = s >= 0.0 && s < s_object;
        s_cross = s;
    }
    pending_cross = select(-1.0, s_cross, OBSERVE && missed);
    if gas && gas_march(seg, s_gas, s_object) {
        return VISIT_STOP;
    }
    pending_cross = -1.0;
    if COUNT_CROSSINGS && missed {
        crossings += 1u;
    }
    if OBJECT_FOOTPRINT && obj_fp_on {
        obj_plane += objfp_crossings(seg, s_object, obj_last_z);
        obj_last_z = seg.x1.z;
    }
    if !OBJECTS || obj == NONE {
        return VISIT_CONTINUE;
    }
    met_object = true;
    if first_obj == NONE {
        first_obj = obj;
    }
    let incoming = seg_tangent(seg, h.s);
    let ln_g = fixed_ln_shift(seg, h.s, h.point);
    let rec = obj * OBJECT_WORDS;
    if OBJECT_FOOTPRINT {
        // The hit's footprint where its texture is read over one and the
        // ray still follows the camera's geodesic (object_color reads it).
        obj_fp.ok = false;
        if obj_fp_on && od(rec + 28u) != NONE {
            object_footprint(obj, seg, h);
        }
    }
    if od(rec + 1u) == 1u {
        var n = h.normal;
        if dot(n, -incoming) < 0.0 {
            n = -n;
        }
        bounce_origin = h.point + n * (1e-5 * max(length(h.point), 1.0));
        if KERR {
            let k = ks_reflect(2.0 * h.point, incoming, n);
            bounce_dir = k.xyz;
            bounce_t = k.w;
        } else if P.model == MODEL_GR {
            bounce_dir = reflect_static(h.point, incoming, n);
        } else {
            bounce_dir = incoming - n * (2.0 * dot(incoming, n));
        }
        bounce_tint = object_color(rec, h.uv);
        bounce_ln_g = ln_g;
        bounce_time = seg_time(seg, h.s);
        return VISIT_BOUNCE;
    }
    if OBSERVE {
        probe_light(ln_g, 0.0, 0u, travel_time(seg, h.s), timed_bit(), vec2<f32>(0.0));
    }
    if SPECTRAL {
        object_spectrum(obj, h, -incoming, exp(light_ln(ln_g)), through);
    } else {
        color += object_rgb(obj, h, -incoming) * rgb_filter * through;
    }
    return VISIT_STOP;
}


struct Outcome {
    end: u32,
    steps: u32,
    disk: bool,
    object: bool,
    // Traced in closed form.
    closed: bool,
}


// Integrator::trace_closed: a ray of a disk-and-sky scene in closed form, its
// disk-plane crossings in order, then the sky or the hole.
fn trace_closed(c: Closed) -> Outcome {
    let first = closed_first_crossing(c);
    // A crossing every pi up to the sweep; 64 cover any b outside the
    // margin round b_c.
    for (var i = 0u; first >= 0.0 && i < 64u; i++) {
        let phi = first + f32(i) * PI;
        if phi >= c.sweep {
            break;
        }
        // Schwarzschild's closed form keeps no time (timed scenes
        // integrate).
        let p = closed_point(c, phi);
        let hit = disk_hit(unturn_plane(p.xy, P.time), i);
        if hit.alpha > 0.0 && shade_closed_crossing(hit, p, i, 0.0, 0u) {
            return Outcome(END_STOPPED, 0u, true, false, true);
        }
    }
    return closed_end(c.captured, c.e1 * cos(c.sweep) + c.e2 * sin(c.sweep));
}

// ClosedRay::segments for an observed scene's medium: Schwarzschild's
// closed-form ray as segments visited in order (cubic Hermite curves
// through exact points and tangents, each sweeping at most SEGMENT_SWEEP
// and changing 1/r by at most SEGMENT_SPAN of itself, towards the horizon
// half the way to it; their unit-energy affine lengths r^2 dphi / b by
// Simpson's rule), the disk and the gas met as on integrated rays; past
// CLOSED_FAR, going out, one straight chord to the outer limit.
fn trace_closed_segments(c: Closed) -> Outcome {
    let end = closed_segments_end(c);
    let outer = P.outer_limit;
    // The segments' parameter is their affine length itself.
    m_energy = 1.0;
    var phi = 0.0;
    var x0 = closed_point(c, 0.0);
    var t0 = closed_tangent(c, 0.0);
    var steps = 0u;
    while phi < end && steps < 100000u {
        let r0 = length(x0);
        let out = dot(x0, t0) > 0.0;
        if !c.captured && r0 > outer && out {
            break;
        }
        if !c.captured && r0 > CLOSED_FAR && out {
            let d = normalize(t0);
            let along = dot(x0, d);
            let reach = -along + sqrt(max(along * along - r0 * r0 + outer * outer, 0.0));
            let x1 = x0 + d * reach * (1.0 + 1e-6);
            let v = x1 - x0;
            steps += 1u;
            if visit(Seg(x0, v, x1, v, length(v), false, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)) == VISIT_STOP {
                return Outcome(END_STOPPED, steps, true, false, true);
            }
            break;
        }
        let u = 1.0 / r0;
        let rate = max(closed_rate(c, u), 1e-30);
        let next = min(phi + min(SEGMENT_SWEEP, min(SEGMENT_SPAN, 0.5 * (1.0 - u)) * u / rate), end);
        if next == c.sweep && !c.captured {
            // Infinity itself is no point.
            break;
        }
        let dphi = next - phi;
        let x1 = closed_point(c, next);
        let t1 = closed_tangent(c, next);
        let rm = length(closed_point(c, phi + 0.5 * dphi));
        let affine = dphi / 6.0 * (r0 * r0 + 4.0 * rm * rm + dot(x1, x1)) / c.b;
        let seg = Seg(x0, t0 * (c.b / (r0 * r0)), x1, t1 * (c.b / dot(x1, x1)), affine, true, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        steps += 1u;
        if visit(seg) == VISIT_STOP {
            return Outcome(END_STOPPED, steps, true, false, true);
        }
        phi = next;
        x0 = x1;
        t0 = t1;
    }
    var o = closed_end(c.captured, c.e1 * cos(c.sweep) + c.e2 * sin(c.sweep));
    o.steps = steps;
    return o;
}

// A closed-form ray's crossing of the disk's material (`hit`, alpha > 0)
// at `p`, the ray's `order`-th, its light `time` from the camera
// (`timed`: PROBE_TIME when kept): the disk's light there; true where it
// stops the ray.
fn shade_closed_crossing(hit: DiskHit, p: vec3<f32>, order: u32, time: f32, timed: u32) -> bool {
    var ln_g = 0.0;
    if shift_on {
        ln_g = gr_disk_ln_shift(p);
    }
    if OBSERVE {
        probe_light(ln_g, ring_radius(length(p.xy)), order, time, PROBE_RADIUS | PROBE_ORDER | timed, fp_disk_magnification_at(order));
    }
    if MEDIUM {
        thin_disk_janskys(hit, ln_g);
        return true;
    }
    return shade_disk_hit(hit, light_ln(ln_g));
}

// The thin disk met by an observed scene's ray (JanskyShade::disk): its
// blackbody B_nu(f_col T) / f_col^4 at ln g, opaque.
fn thin_disk_janskys(hit: DiskHit, ln_g: f32) {
    met_disk = true;
    let f2 = P.thin_f_col * P.thin_f_col;
    let kelvin = P.thin_f_col * thin_temperature(disk_hit_radius(hit));
    m_opaque(exp(ln_g), kelvin, 1.0 / (f2 * f2));
}

// A closed-form ray's end: the hole, or the sky along `dir`.
fn closed_end(captured: bool, dir: vec3<f32>) -> Outcome {
    if captured {
        return Outcome(END_CAPTURED, 0u, met_disk, false, true);
    }
    let ln_g = gr_sky_ln_shift();
    if OBSERVE {
        probe_escaped(dir);
        probe_light(ln_g, 0.0, 0u, 0.0, 0u, fp_sky_magnification());
    }
    // An observed scene's sky is medium_trace's.
    if !MEDIUM {
        sky_later(dir, light_ln(ln_g));
    }
    return Outcome(END_ESCAPED, 0u, met_disk, false, true);
}

// Integrator::trace_closed for a spinning hole's ray in closed form: an
// observed scene's medium is walked between the crossings that meet the
// disk (m_along_kerr), from the camera to the ray's end.
fn trace_closed_kerr(c: KerrClosed) -> Outcome {
    let first = kc_first(c);
    var gas_from = 0.0;
    var steps = 0u;
    // Crossings in order up to the ray's end (64 cover any ray outside
    // the critical curve's f32 margin).
    for (var i = 0u; i < 64u; i++) {
        let q = kc_crossing(c, first + f32(i));
        if q.r < 0.0 {
            break;
        }
        // The scene's units, r_s; with TRAVEL the light's travel time,
        // and the disk as the light left it.
        var emitted = P.time;
        var time = 0.0;
        if TRAVEL {
            time = time_offset + 0.5 * q.t;
        }
        if seen_late() {
            emitted = P.time - time;
        }
        let hit = disk_hit(unturn_plane(0.5 * q.plane, emitted), i);
        if !(hit.alpha > 0.0) {
            continue;
        }
        if MEDIUM {
            // The gas in front of the disk, to the crossing's Mino time.
            let at = (2.0 * (first + f32(i)) * c.pk - c.psi0) / c.pscale;
            steps += m_along_kerr(c, gas_from, at);
            gas_from = at;
            if !m_alive {
                return Outcome(END_STOPPED, steps, true, false, true);
            }
        }
        if shade_closed_crossing(hit, 0.5 * q.p, i, time, timed_bit()) {
            return Outcome(END_STOPPED, steps, true, false, true);
        }
    }
    if MEDIUM {
        // To the ray's end: out of the medium, or just outside the
        // horizon for a captured ray.
        var end = c.s_end;
        if c.captured {
            end = kc_mino_at_fall(c, P.medium_horizon * (1.0 + HORIZON_MARGIN));
        }
        steps += m_along_kerr(c, gas_from, end);
        if !m_alive {
            return Outcome(END_STOPPED, steps, met_disk, false, true);
        }
    }
    var o: Outcome;
    if c.captured {
        o = closed_end(true, vec3<f32>(0.0));
    } else {
        o = closed_end(false, kc_escape(c));
    }
    o.steps = steps;
    return o;
}

// The spinning hole's closed form of the camera's ray made last by
// camera_direction: its constants from the frame's f64 linear forms.
fn kerr_camera_ray() -> KerrClosed {
    let w = vec4<f32>(-1.0, cam_local);
    let kr = P.kerr_rays;
    let e = dot(kr[0], w);
    let lz = dot(kr[1], w);
    let p_th = dot(kr[2], w);
    let ct = P.kerr_start.y;
    let st = P.kerr_start.w;
    let a = P.kerr_hole.x;
    let q = p_th * p_th + ct * ct * (lz * lz / (st * st) - a * a * e * e);
    var c = kerr_closed_ray(lz / e, q / (e * e), sign(e), P.kerr_start.xyz, dot(kr[3], w) > 0.0, dot(kr[4], w) > 0.0);
    c.lz_over_e = lz / e;
    return c;
}

// The sky a ray escaped to, shaded after its trace: each path of the
// trace ends there, and one call of shade_sky (the driver inlines each
// call whole, the point stars' neighbouring rays with it) serves them all.
var<private> sky_pending: bool;
var<private> sky_dir: vec3<f32>;
var<private> sky_k: f32;
var<private> sky_ln: f32;

// The ray escaped along `dir` with light's ln g `ln_g`.
fn sky_later(dir: vec3<f32>, ln_g: f32) {
    sky_pending = true;
    sky_dir = dir;
    sky_k = through;
    sky_ln = ln_g;
}

// Traces one camera sample through its mirror reflections, shading what
// it meets (Integrator::trace_sample).
fn trace_sample(camera: vec3<f32>, camera_dir: vec3<f32>) -> Outcome {
    sky_pending = false;
    let o = trace_paths(camera, camera_dir);
    if sky_pending {
        shade_sky(sky_dir, sky_k, sky_ln);
    }
    return o;
}

// trace_sample's paths: closed forms where they hold, else integrated.
// The per-sample state a trace starts from (the camera's ray, before any
// bounce).
fn start_paths(camera: vec3<f32>) {
    through = 1.0;
    met_disk = false;
    met_object = false;
    first_obj = NONE;
    rgb_filter = vec3<f32>(1.0);
    if FILTERS {
        for (var j = 0u; j < N_WL; j++) {
            wl_filter[j] = 1.0;
        }
    }
    r_cam = safe_length(camera);
    ln_offset = 0.0;
    time_offset = 0.0;
    pending_cross = -1.0;
    crossings = 0u;
    if OBSERVE {
        probe_bits = 0u;
        probe_has_sky = false;
    }
}

// The camera's ray in closed form where the spacetime has one for it
// (Kerr's or Schwarzschild's), traced to its end; `closed` false where it
// has none (the integrator takes it).
fn trace_camera_closed(camera: vec3<f32>, camera_dir: vec3<f32>) -> Outcome {
    if CLOSED && KERR {
        let c = kerr_camera_ray();
        if c.ok {
            lz_over_e = c.lz_over_e;
            if shift_on {
                obs_ln = ks_observer_ln(lz_over_e);
            }
            if MEDIUM {
                // The transfer's photon is the closed form's (its L_z / E
                // from the host's f64 forms, not the f32 state's).
                m_lz = lz_over_e;
                m_camera_ratio = exp(obs_ln + cam_ln_d);
            }
            return trace_closed_kerr(c);
        }
    } else if CLOSED {
        let c = closed_ray(camera, camera_dir);
        if c.ok {
            lz_over_e = 0.0;
            if doppler_on && exact_b >= 0.0 {
                // L_z / E = -b (l . z) with l the unit x cross v.
                lz_over_e = -exact_b * exact_l.z;
            } else if doppler_on {
                lz_over_e = photon_lz_over_e(camera, camera_dir);
            }
            if MEDIUM {
                return trace_closed_segments(c);
            }
            return trace_closed(c);
        }
    }
    return Outcome(END_ABANDONED, 0u, false, false, false);
}

// The sky's light along the escape direction of the traced `ray`.
fn escaped_sky(ray: Ray) {
    var d: vec3<f32>;
    var ln_g = 0.0;
    if KERR {
        d = ks_escape_direction(ray.x, ray.p, ray.e);
        ln_g = gr_sky_ln_shift();
    } else if P.model == MODEL_GR {
        d = gr_escape_direction(ray.x, ray.v);
        ln_g = gr_sky_ln_shift();
    } else {
        let e = seed_escape(ray.x, ray.v);
        d = e.xyz;
        if shift_on {
            ln_g = ln_offset - (ray.sum + e.w) + cam_ln_d;
        }
    }
    if OBSERVE {
        probe_escaped(d);
        probe_light(ln_g, 0.0, 0u, 0.0, 0u, fp_sky_magnification());
    }
    // An observed scene's sky is its janskys' (medium_trace).
    if !MEDIUM {
        sky_later(d, light_ln(ln_g));
    }
}

fn trace_paths(camera: vec3<f32>, camera_dir: vec3<f32>) -> Outcome {
    start_paths(camera);
    var origin = camera;
    var dir = camera_dir;
    var steps = 0u;
    // Runs out of bounces unless a trace ends without a mirror.
    var outcome_end = END_ABANDONED;
    if CLOSED {
        let closed = trace_camera_closed(camera, camera_dir);
        if closed.closed {
            return closed;
        }
    }
    if P.model == MODEL_GR && !TRAVEL && exact_b >= 0.0 {
        let start = exact_start(r_cam);
        if start.ok {
            origin = start.x;
            dir = start.v;
            if KERR {
                start_t = ks_backward_t(2.0 * origin, dir);
            }
            // The image order counts a crossing of the plane on the
            // straight stretch skipped on the way in.
            let z0 = camera.z;
            let z1 = origin.z;
            if COUNT_CROSSINGS && !(z0 == 0.0 || ((z0 > 0.0) == (z1 > 0.0) && z1 != 0.0)) {
                crossings = 1u;
            }
        }
    }
    for (var b = 0u; b <= MAX_BOUNCES; b++) {
        lz_over_e = 0.0;
        if P.model == MODEL_GR && !KERR && doppler_on {
            lz_over_e = photon_lz_over_e(origin, dir);
        }
        var ray = ray_start(origin, dir);
        m_energy = ray.e;
        if KERR && shift_on {
            // Spacetime::photon_lz_over_e, M units.
            lz_over_e = (ray.x.x * ray.p.y - ray.x.y * ray.p.x) / ray.e;
            if b == 0u {
                obs_ln = ks_observer_ln(lz_over_e);
            }
        }
        var end = END_ABANDONED;
        var bounced = false;
        loop {
            let ev = advance(&ray);
            if ev != EV_VISIT {
                end = ev;
                break;
            }
            let r = visit(ray.seg);
            if r == VISIT_STOP {
                end = END_STOPPED;
                break;
            }
            if r == VISIT_BOUNCE {
                bounced = true;
                break;
            }
        }
        steps += ray.steps;
        if bounced {
            shade_tint(bounce_tint, exp(light_ln(bounce_ln_g)));
            origin = bounce_origin;
            // The ray left the camera's geodesic: its footprint no longer
            // describes it (Probing::bounced).
            fp.ok = false;
            obj_fp_on = false;
            dir = bounce_dir;
            start_t = bounce_t;
            time_offset += bounce_time;
            if P.model == MODEL_SEED {
                // The camera's Doppler factor is added once, at the end.
                ln_offset = bounce_ln_g - cam_ln_d;
            }
        } else {
            // An observed scene needs its escape direction only for the
            // observables.
            if end == END_ESCAPED && (!MEDIUM || OBSERVE) {
                escaped_sky(ray);
            }
            outcome_end = end;
            break;
        }
    }
    return Outcome(outcome_end, steps, met_disk, met_object, false);
}

fn class_of(o: Outcome) -> u32 {
    if o.end == END_ABANDONED {
        return STAT_ABANDONED;
    }
    if o.disk {
        return STAT_DISK;
    }
    if o.object {
        return STAT_OBJECTS;
    }
    if o.end == END_CAPTURED {
        return STAT_CAPTURED;
    }
    return STAT_SKY;
}

// FLAG_ADAPTIVE: the sample's class as adaptive sampling tells them apart
// (adaptive::class_bit's bit): sky 0, captured 1, out of steps 2,
// not finite 3, the disk 4 + its image order (to 11), objects 16 + index
// modulo 48.
fn adaptive_class(cls: u32) -> u32 {
    if !OBSERVE || !has_flag(FLAG_ADAPTIVE) {
        return 0u;
    }
    switch cls {
        case STAT_CAPTURED: { return 1u; }
        case STAT_ABANDONED: { return 2u; }
        case STAT_NON_FINITE: { return 3u; }
        case STAT_DISK: { return 4u + select(0u, min(probe_order, 11u), (probe_bits & PROBE_ORDER) != 0u); }
        case STAT_OBJECTS: { return 16u + select(first_obj, 0u, first_obj == NONE) % 48u; }
        default: { return 0u; }
    }
}

// adaptive::lightness in f32: CIE L* of luminance `y` at white
// P.white, continued as 100 + (116 / 3) ln(y / white) above it.
fn lightness(y: f32) -> f32 {
    let t = max(y / P.white, 0.0);
    if t > 1.0 {
        return 100.0 + 116.0 / 3.0 * log(t);
    }
    if t > 0.008856452 {
        return 116.0 * pow(t, 1.0 / 3.0) - 16.0;
    }
    return 116.0 * (t * 7.787037 + 4.0 / 29.0) - 16.0;
}

// A round of adaptive sampling (REFINE: Params::refine_samples > 0) traces
// a list of samples, not the band's pixels' samples i: film holds, from
// refine_at(), one entry per pixel refined (its band pixel, its first
// sample in the list, its samples, its first extra sample's index),
// ordered by the list.
fn refining() -> bool {
    return OBSERVE && P.refine_samples > 0u;
}

fn refine_at() -> u32 {
    return P.at_observed + OBSERVED_VEC4S * P.slots_per_sample;
}

fn refine_entry(e: u32) -> vec4<u32> {
    return bitcast<vec4<u32>>(film[refine_at() + e]);
}

// The entry of the round's sample k: the last whose first sample is at
// most k.
fn refine_entry_of(k: u32) -> vec4<u32> {
    var lo = 0u;
    var hi = P.refine_pixels;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if refine_entry(mid).y <= k {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return refine_entry(lo);
}

// The first word of sample `i`'s slot for tile pixel `tp`.
fn slot(tp: u32, i: u32) -> u32 {
    return i * P.slots_per_sample + tp;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let width = P.width;
    var x = gid.x;
    var row = gid.y;
    // Sample i of the pixel's image.z, in slot gid.z of this pass; in a
    // round of adaptive sampling, the list's sample k in slot k.
    var sl = gid.z;
    var extra = NONE;
    if refining() {
        sl = gid.y * width + gid.x;
        if gid.x >= width || sl >= P.refine_samples {
            return;
        }
        let e = refine_entry_of(sl);
        x = e.x % width;
        row = e.x / width;
        extra = e.w + sl - e.y;
    } else if x >= width || row >= P.tile_rows {
        return;
    }
    let y = P.tile_first_row + row;
    let pixel = y * width + x;
    let tp = row * width + x;
    if extra == NONE {
        sl = slot(tp, gid.z);
    }
    shift_on = SPECTRAL && has_flag(FLAG_SHIFT);
    shift_render = shift_on;
    if OBSERVE && has_flag(FLAG_OBSERVE_G) {
        shift_on = true;
    }
    // An observed scene's light is always shifted (its thin disk's
    // Doppler shift included).
    shift_on = shift_on || MEDIUM;
    doppler_on = (shift_on && has_flag(FLAG_DOPPLER)) || MEDIUM;
    spec_row = P.at_spectra + sl * N_WL;
    if SPEC_ARRAY {
        for (var j = 0u; j < N_WL; j++) {
            spectra[spec_row + j] = 0.0;
        }
    }
    color = vec3<f32>(0.0);
    xyz_acc = vec3<f32>(0.0);
    g_min = 3.4e38;
    g_max = 0.0;
    var off: vec2<f32>;
    if extra == NONE {
        off = sample_offset(pixel, P.pass_first + gid.z, P.samples);
    } else {
        off = refine_offset(pixel, extra);
    }
    let px = f32(x) + off.x;
    let py = f32(y) + off.y;
    if FOOTPRINT {
        // Its neighbours' rays first: they set the camera's per-ray state.
        sample_footprint(px, py);
        stars_px = vec2<f32>(px, py);
    }
    if OBJECT_FOOTPRINT {
        objfp_begin(px, py);
    }
    set_exact_ray(image_point(px, py));
    let dir = camera_direction(px, py);
    // An observed scene's light is always shifted, the moving camera's
    // Doppler factor included.
    if !shift_on && !MEDIUM {
        cam_ln_d = 0.0;
    }
    var o: Outcome;
    if MEDIUM {
        o = medium_trace(P.cam_pos.xyz, dir, px, py);
    } else {
        o = trace_sample(P.cam_pos.xyz, dir);
    }
    var value = color;
    if SPECTRAL {
        value = xyz_acc;
    }
    let ok = finite3(value);
    let cls = select(STAT_NON_FINITE, class_of(o), ok);
    // The slot: (XYZ or linear sRGB, class), (range of g, steps, closed
    // plus twice adaptive sampling's class).
    let rec = P.slots_per_sample + 2u * sl;
    film[rec] = vec4<f32>(value, bitcast<f32>(cls));
    let closed_class = select(0u, 1u, o.closed) + 2u * adaptive_class(cls);
    film[rec + 1u] = vec4<f32>(g_min, g_max, bitcast<f32>(o.steps), f32(closed_class));
    if OBSERVE {
        probe_write(P.at_probes + PROBE_VEC4S * sl);
    }
}

// What resolve gathers of a pixel's samples for the observables (OBSERVE):
// the sums of g, radius and time over the samples that have one, their
// counts, the least order (NONE: none); the sums of the magnification and
// the sky direction and their counts; with FLAG_ADAPTIVE the lightness
// sums and the class mask's words.
struct Observed {
    sum: vec3<f32>,
    n: vec3<u32>,
    order: u32,
    fp: vec4<f32>,
    fp_n: vec2<u32>,
    l_sum: vec2<f32>,
    mask: vec2<u32>,
}

// Adds slot `sl`'s sample (its light `a`, class `cls`, closed-form flag
// and refinement class `closed_class`) to `o`: every sample, its light a
// number or not (PixelProbe::add).
fn observe_sample(o: ptr<function, Observed>, sl: u32, a: vec4<f32>, cls: u32, closed_class: u32) {
    if has_flag(FLAG_ADAPTIVE) {
        let c = closed_class >> 1u;
        (*o).mask |= select(vec2<u32>(0u, 1u << (c & 31u)), vec2<u32>(1u << (c & 31u), 0u), c < 32u);
        if cls != STAT_NON_FINITE {
            var lum = a.y;
            if !SPECTRAL {
                lum = dot(a.xyz, vec3<f32>(0.2126, 0.7152, 0.0722));
            }
            let v = lightness(lum);
            (*o).l_sum += vec2<f32>(v, v * v);
        }
    }
    let pr = film[P.at_probes + PROBE_VEC4S * sl];
    let bits = bitcast<u32>(pr.w);
    let has = vec3<bool>((bits & PROBE_G) != 0u, (bits & PROBE_RADIUS) != 0u, (bits & PROBE_TIME) != 0u);
    (*o).sum += select(vec3<f32>(0.0), pr.xyz, has);
    (*o).n += select(vec3<u32>(0u), vec3<u32>(1u), has);
    let pw = film[P.at_probes + PROBE_VEC4S * sl + 1u];
    let has_mu = (bits & PROBE_MAG) != 0u;
    let has_sky = (bits & PROBE_SKY) != 0u;
    (*o).fp += vec4<f32>(select(0.0, pw.x, has_mu), select(vec3<f32>(0.0), pw.yzw, has_sky));
    (*o).fp_n += vec2<u32>(select(0u, 1u, has_mu), select(0u, 1u, has_sky));
    if (bits & PROBE_ORDER) != 0u {
        (*o).order = min((*o).order, bits >> PROBE_ORDER_SHIFT);
    }
}

// Writes pixel `tp`'s observables and its samples' class `counts`: small
// words as bits (order plus one: 0 is none), never a NaN's pattern.
fn write_observed(o: Observed, tp: u32, counts: array<u32, 6>) {
    let at = P.at_observed + OBSERVED_VEC4S * tp;
    film[at] = vec4<f32>(o.sum, bitcast<f32>(select(o.order + 1u, 0u, o.order == NONE)));
    film[at + 1u] = vec4<f32>(bitcast<vec3<f32>>(o.n), 0.0);
    film[at + 2u] = bitcast<vec4<f32>>(vec4<u32>(counts[0], counts[1], counts[2], counts[3]));
    film[at + 3u] = bitcast<vec4<f32>>(vec4<u32>(counts[4], counts[5], 0u, 0u));
    film[at + 4u] = o.fp;
    film[at + 5u] = bitcast<vec4<f32>>(vec4<u32>(o.fp_n, 0u, 0u));
    film[at + 6u] = vec4<f32>(o.l_sum, bitcast<vec2<f32>>(o.mask));
}

// Pixel `tp`'s kept spectra and bands (`keep`, `keep_bands`) scaled by
// `k` (1 / kept, after the sum), or with `clear` set to 0 (before it; not
// scaled by 0, which keeps a NaN left there).
fn scale_kept_spectra(tp: u32, keep: bool, keep_bands: bool, k: f32, clear: bool) {
    if keep {
        for (var j = 0u; j < N_WL; j++) {
            spectra[tp * N_WL + j] = select(spectra[tp * N_WL + j] * k, 0.0, clear);
        }
    }
    if keep_bands {
        for (var b = 0u; b < 3u * BANDS; b++) {
            bands[tp * 3u * BANDS + b] = select(bands[tp * 3u * BANDS + b] * k, 0.0, clear);
        }
    }
}

// Adds slot `sl`'s spectrum (and its bands) to pixel `tp`'s kept ones.
fn add_kept_spectrum(tp: u32, sl: u32, keep: bool, keep_bands: bool) {
    let row_i = P.at_spectra + sl * N_WL;
    if keep {
        for (var j = 0u; j < N_WL; j++) {
            spectra[tp * N_WL + j] += spectra[row_i + j];
        }
    }
    if keep_bands {
        for (var j = 0u; j < N_WL; j++) {
            let bi = tp * 3u * BANDS + 3u * (j * BANDS / N_WL);
            let w = P.wl[j].xyz * spectra[row_i + j];
            bands[bi] += w.x;
            bands[bi + 1u] += w.y;
            bands[bi + 2u] += w.z;
        }
    }
}

// The workgroup's tallies into the frame's stats (by its first
// invocation, after the barrier).
fn flush_workgroup_stats() {
    for (var c = 0u; c < 6u; c++) {
        let v = atomicLoad(&wg_counts[c]);
        if v > 0u {
            atomicAdd(&stats[c], v);
        }
    }
    let g_lo = atomicLoad(&wg_g_min);
    let g_hi = atomicLoad(&wg_g_max);
    if g_hi > 0u {
        atomicMin(&stats[STAT_G_MIN], g_lo);
        atomicMax(&stats[STAT_G_MAX], g_hi);
    }
    let n_closed = atomicLoad(&wg_closed);
    if n_closed > 0u {
        atomicAdd(&stats[STAT_CLOSED], n_closed);
    }
    let s = atomicLoad(&wg_steps);
    let old = atomicAdd(&stats[STAT_STEPS_LO], s);
    if old + s < old {
        atomicAdd(&stats[STAT_STEPS_HI], 1u);
    }
}

@compute @workgroup_size(8, 8, 1)
fn resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    if lid == 0u {
        for (var c = 0u; c < 6u; c++) {
            atomicStore(&wg_counts[c], 0u);
        }
        atomicStore(&wg_steps, 0u);
        atomicStore(&wg_closed, 0u);
        atomicStore(&wg_g_min, 0x7f7fffffu);
        atomicStore(&wg_g_max, 0u);
    }
    workgroupBarrier();
    let width = P.width;
    let x = gid.x;
    let row = gid.y;
    // The pixel's samples: slots slot(tp, i), i < P.pass_samples; in a
    // round of adaptive sampling, entry e's samples in the list.
    var tp = row * width + x;
    var n = P.pass_samples;
    var listed = NONE;
    var valid = x < width && row < P.tile_rows;
    if refining() {
        let e = row * width + x;
        valid = x < width && e < P.refine_pixels;
        if valid {
            let entry = refine_entry(e);
            tp = entry.x;
            listed = entry.y;
            n = entry.z;
        }
    }
    if valid {
        let keep = (SPECTRAL || MEDIUM) && has_flag(FLAG_KEEP_SPECTRA);
        let keep_bands = SPECTRAL && has_flag(FLAG_BANDS);
        scale_kept_spectra(tp, keep, keep_bands, 0.0, true);
        // The range of g on the disk over the pixel's kept samples.
        var pg_min = 3.4e38;
        var pg_max = 0.0;
        var sum = vec3<f32>(0.0);
        var kept = 0u;
        var counts = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 0u);
        var steps = 0u;
        var closed = 0u;
        var o: Observed;
        o.order = NONE;
        for (var i = 0u; i < n; i++) {
            var sl = slot(tp, i);
            if listed != NONE {
                sl = listed + i;
            }
            let rec = P.slots_per_sample + 2u * sl;
            let a = film[rec];
            let b = film[rec + 1u];
            let cls = bitcast<u32>(a.w);
            counts[cls] += 1u;
            steps += bitcast<u32>(b.z);
            let closed_class = u32(b.w);
            closed += closed_class & 1u;
            if OBSERVE {
                observe_sample(&o, sl, a, cls, closed_class);
            }
            if cls == STAT_NON_FINITE {
                // Light that is no number is left out of the pixel.
                continue;
            }
            sum += a.xyz;
            kept += 1u;
            pg_min = min(pg_min, b.x);
            pg_max = max(pg_max, b.y);
            add_kept_spectrum(tp, sl, keep, keep_bands);
        }
        let k = 1.0 / f32(max(kept, 1u));
        var xyz = sum * k;
        if !SPECTRAL {
            let m = P.srgb_to_xyz;
            xyz = m[0].xyz * xyz.x + m[1].xyz * xyz.y + m[2].xyz * xyz.z;
        }
        // w: the samples kept, for adding passes together.
        film[tp] = vec4<f32>(xyz, f32(kept));
        if OBSERVE {
            write_observed(o, tp, counts);
        }
        scale_kept_spectra(tp, keep, keep_bands, k, false);
        for (var c = 0u; c < 6u; c++) {
            if counts[c] > 0u {
                atomicAdd(&wg_counts[c], counts[c]);
            }
        }
        atomicAdd(&wg_steps, steps);
        atomicAdd(&wg_closed, closed);
        if pg_max > 0.0 {
            atomicMin(&wg_g_min, bitcast<u32>(pg_min));
            atomicMax(&wg_g_max, bitcast<u32>(pg_max));
        }
    }
    workgroupBarrier();
    if lid == 0u {
        flush_workgroup_stats();
    }
}
