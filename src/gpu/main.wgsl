// One invocation per pixel of a tile: its samples are traced and shaded as
// src/render/mod.rs does (Scene::trace_sample, Scene::render), the pixel's
// XYZ (and spectra or bloom bands when kept) written to the film, and the
// samples counted by class.

// The sample being shaded.
var<private> color: vec3<f32>;
var<private> spec: array<f32, SPEC_LEN>;
var<private> xyz_acc: vec3<f32>;
var<private> through: f32;
var<private> met_disk: bool;
var<private> g_min: f32;
var<private> g_max: f32;
// Frequency shifts of the current path (render::Shifts).
var<private> shift_on: bool;
var<private> doppler_on: bool;
var<private> r_cam: f32;
var<private> lz_over_e: f32;

var<workgroup> wg_counts: array<atomic<u32>, 6>;
var<workgroup> wg_steps: atomic<u32>;
var<workgroup> wg_g_min: atomic<u32>;
var<workgroup> wg_g_max: atomic<u32>;

// physics::shift::gr_disk_ln_shift and seed_disk_ln_shift, for the point
// at fraction s of `seg`.
fn disk_ln_shift(seg: Seg, s: f32, p: vec3<f32>) -> f32 {
    if !shift_on {
        return 0.0;
    }
    if P.model.x == 0u {
        let r_e = length(p);
        var emitter: f32;
        if doppler_on && r_e > 1.5 {
            let omega = sqrt(0.5 / (r_e * r_e * r_e));
            emitter = 0.5 * log(1.0 - 1.5 / r_e) - log(1.0 - omega * lz_over_e);
        } else {
            emitter = 0.5 * log(1.0 - 1.0 / r_e);
        }
        return emitter - 0.5 * log(1.0 - 1.0 / r_cam);
    }
    let gravity = seg_ln_shift(seg, s);
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

fn shade_disk(h: DiskHit, k: f32, ln_g: f32) {
    if !SPECTRAL {
        color += disk_rgba(h).xyz * P.disk_f.z * k;
        return;
    }
    let g = exp(ln_g);
    g_min = min(g_min, g);
    g_max = max(g_max, g);
    let kk = k * P.disk_f.z * radiance_factor(g);
    if P.disk_i.x == 1u {
        let px = disk_rgba(h);
        let c = uplift(px.xyz / px.w);
        let kw = kk * px.w;
        for (var j = 0u; j < N_WL; j++) {
            emit(j, kw * uplift_emission(c, g * nm_at(j)));
        }
        return;
    }
    let s = set_texels(h.u, h.v);
    for (var q = 0u; q < s.n; q++) {
        let kw = kk * s.w[q] * set_alpha(s.t[q]);
        for (var j = 0u; j < N_WL; j++) {
            emit(j, kw * set_value(s.t[q], g * nm_at(j)));
        }
    }
}

fn shade_sky(dir: vec3<f32>, k: f32, ln_g: f32) {
    if !SPECTRAL {
        color += sky_rgb(dir) * k;
        return;
    }
    sky_spectrum(dir, exp(ln_g), k);
}

struct Outcome {
    end: u32,
    steps: u32,
    disk: bool,
}

// Traces one camera sample, shading what it meets (Scene::trace_sample).
fn trace_sample(origin: vec3<f32>, dir: vec3<f32>) -> Outcome {
    through = 1.0;
    met_disk = false;
    r_cam = length(origin);
    lz_over_e = 0.0;
    if P.model.x == 0u && doppler_on {
        let l = cross(origin, dir);
        let v_inf = sqrt(dot(dir, dir) - dot(l, l) / (r_cam * r_cam * r_cam));
        lz_over_e = -l.z / v_inf;
    }
    var ray = ray_start(origin, dir);
    var end = END_ABANDONED;
    loop {
        let ev = advance(&ray);
        if ev != EV_CROSS {
            end = ev;
            break;
        }
        // A possible crossing of the disk's plane: an end exactly on the
        // plane is the next segment's start (as on the CPU).
        let seg = ray.seg;
        let s = seg_crossing_z0(seg);
        if !(s >= 0.0 && s < 1.0) {
            continue;
        }
        let p = seg_point(seg, s);
        let hit = disk_hit(p);
        if !(hit.alpha > 0.0) {
            continue;
        }
        met_disk = true;
        let ln_g = disk_ln_shift(seg, s, p);
        if P.disk_i.z == 0u {
            shade_disk(hit, through / hit.alpha, ln_g);
            end = END_STOPPED;
            break;
        }
        shade_disk(hit, through, ln_g);
        through *= 1.0 - hit.alpha;
        if through < 1e-4 {
            end = END_STOPPED;
            break;
        }
    }
    if end == END_ESCAPED {
        var d: vec3<f32>;
        var ln_g = 0.0;
        if P.model.x == 0u {
            d = gr_escape_direction(ray.x, ray.v);
            if shift_on {
                ln_g = -0.5 * log(1.0 - 1.0 / r_cam);
            }
        } else {
            let e = seed_escape(ray.x, ray.v);
            d = e.xyz;
            if shift_on {
                ln_g = -(ray.sum + e.w);
            }
        }
        shade_sky(d, through, ln_g);
    }
    return Outcome(end, ray.steps, met_disk);
}

fn class_of(o: Outcome) -> u32 {
    if o.end == END_ABANDONED {
        return STAT_ABANDONED;
    }
    if o.disk {
        return STAT_DISK;
    }
    if o.end == END_CAPTURED {
        return STAT_CAPTURED;
    }
    return STAT_SKY;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    if lid == 0u {
        for (var c = 0u; c < 6u; c++) {
            atomicStore(&wg_counts[c], 0u);
        }
        atomicStore(&wg_steps, 0u);
        atomicStore(&wg_g_min, 0x7f7fffffu);
        atomicStore(&wg_g_max, 0u);
    }
    workgroupBarrier();
    let width = P.image.x;
    let x = gid.x;
    let row = gid.y;
    if x < width && row < P.tile.w {
        let y = P.tile.z + row;
        let pixel = y * width + x;
        let tp = row * width + x;
        shift_on = SPECTRAL && has_flag(FLAG_SHIFT);
        doppler_on = shift_on && has_flag(FLAG_DOPPLER);
        // The range of g on the disk over the pixel's kept samples.
        var pg_min = 3.4e38;
        var pg_max = 0.0;
        let keep = SPECTRAL && has_flag(FLAG_KEEP_SPECTRA);
        let keep_bands = SPECTRAL && has_flag(FLAG_BANDS);
        if keep {
            for (var j = 0u; j < N_WL; j++) {
                spectra[tp * N_WL + j] = 0.0;
            }
        }
        if keep_bands {
            for (var b = 0u; b < 3u * BANDS; b++) {
                bands[tp * 3u * BANDS + b] = 0.0;
            }
        }
        let n = P.image.z;
        var sum = vec3<f32>(0.0);
        var kept = 0u;
        var counts = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 0u);
        var steps = 0u;
        for (var i = 0u; i < n; i++) {
            let off = sample_offset(pixel, i, n);
            let px = f32(x) + off.x;
            let py = f32(y) + off.y;
            color = vec3<f32>(0.0);
            g_min = 3.4e38;
            g_max = 0.0;
            xyz_acc = vec3<f32>(0.0);
            if SPEC_ARRAY {
                for (var j = 0u; j < N_WL; j++) {
                    spec[j] = 0.0;
                }
            }
            let o = trace_sample(P.cam_pos.xyz, camera_direction(px, py));
            var value: vec3<f32>;
            if SPEC_ARRAY {
                value = vec3<f32>(0.0);
                for (var j = 0u; j < N_WL; j++) {
                    value += P.wl[j].xyz * spec[j];
                }
            } else if SPECTRAL {
                value = xyz_acc;
            } else {
                value = color;
            }
            let ok = finite3(value);
            if ok {
                sum += value;
                kept += 1u;
                pg_min = min(pg_min, g_min);
                pg_max = max(pg_max, g_max);
                if keep {
                    for (var j = 0u; j < N_WL; j++) {
                        spectra[tp * N_WL + j] += spec[j];
                    }
                }
                if keep_bands {
                    for (var j = 0u; j < N_WL; j++) {
                        let b = tp * 3u * BANDS + 3u * (j * BANDS / N_WL);
                        let w = P.wl[j].xyz * spec[j];
                        bands[b] += w.x;
                        bands[b + 1u] += w.y;
                        bands[b + 2u] += w.z;
                    }
                }
            }
            let c = select(STAT_NON_FINITE, class_of(o), ok);
            counts[c] += 1u;
            steps += o.steps;
        }
        let k = 1.0 / f32(max(kept, 1u));
        var xyz = sum * k;
        if !SPECTRAL {
            let m = P.srgb_to_xyz;
            xyz = m[0].xyz * xyz.x + m[1].xyz * xyz.y + m[2].xyz * xyz.z;
        }
        film[tp] = vec4<f32>(xyz, 0.0);
        if keep {
            for (var j = 0u; j < N_WL; j++) {
                spectra[tp * N_WL + j] *= k;
            }
        }
        if keep_bands {
            for (var b = 0u; b < 3u * BANDS; b++) {
                bands[tp * 3u * BANDS + b] *= k;
            }
        }
        for (var c = 0u; c < 6u; c++) {
            if counts[c] > 0u {
                atomicAdd(&wg_counts[c], counts[c]);
            }
        }
        atomicAdd(&wg_steps, steps);
        if pg_max > 0.0 {
            atomicMin(&wg_g_min, bitcast<u32>(pg_min));
            atomicMax(&wg_g_max, bitcast<u32>(pg_max));
        }
    }
    workgroupBarrier();
    if lid == 0u {
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
        let s = atomicLoad(&wg_steps);
        let old = atomicAdd(&stats[STAT_STEPS_LO], s);
        if old + s < old {
            atomicAdd(&stats[STAT_STEPS_HI], 1u);
        }
    }
}
