// What a ray finds: the disk's texture or spectral set, the sky kinds, and
// the spectral machinery (RGB uplift, D65, Planck rows, frequency shifts):
// the WGSL twin of src/disk.rs, src/sky.rs, src/starmap.rs, src/texture/,
// src/spectral_texture.rs, src/spectrum/ and the shading in src/cpu/.

// ---- textures (premultiplied linear RGBA) -----------------------------------

const TEX_DISK: u32 = 0u;
const TEX_SKY: u32 = 1u;
// An object's texture, from word `base` of the object data.
const TEX_OBJECT: u32 = 2u;

fn tex_word(which: u32, i: u32) -> u32 {
    if which == TEX_DISK {
        return disk_data[i];
    }
    if which == TEX_SKY {
        return sky_data[i];
    }
    return objects_data[i];
}

fn texel(which: u32, base: u32, x: u32, y: u32, w: u32, fmt: u32) -> vec4<f32> {
    let i = y * w + x;
    if fmt == 0u {
        let p = tex_word(which, base + i);
        let a = f32(p >> 24u) / 255.0;
        let lut = P.at_srgb_decode;
        return vec4<f32>(
            tables[lut + (p & 0xffu)] * a,
            tables[lut + ((p >> 8u) & 0xffu)] * a,
            tables[lut + ((p >> 16u) & 0xffu)] * a,
            a
        );
    }
    let c = vec4<f32>(
        bitcast<f32>(tex_word(which, base + 4u * i)),
        bitcast<f32>(tex_word(which, base + 4u * i + 1u)),
        bitcast<f32>(tex_word(which, base + 4u * i + 2u)),
        bitcast<f32>(tex_word(which, base + 4u * i + 3u))
    );
    return vec4<f32>(c.xyz * c.w, c.w);
}

fn rem_euclid(x: f32, n: f32) -> f32 {
    let r = x - n * floor(x / n);
    // Rounding can land exactly on n.
    return select(r, 0.0, r >= n);
}

fn tex_col(x: f32, w: f32, wrap: bool) -> u32 {
    if wrap {
        return u32(rem_euclid(x, w));
    }
    return u32(clamp(x, 0.0, w - 1.0));
}

// texture::Texture::sample
fn tex_sample(which: u32, base: u32, u: f32, v: f32, bilinear: bool, wrap: bool, wi: u32, hi: u32, fmt: u32) -> vec4<f32> {
    let w = f32(wi);
    let h = f32(hi);
    if !bilinear {
        let x = tex_col(floor(u * w), w, wrap);
        let y = u32(clamp(floor(v * h), 0.0, h - 1.0));
        return texel(which, base, x, y, wi, fmt);
    }
    let fx = u * w - 0.5;
    let fy = clamp(v * h - 0.5, 0.0, h - 1.0);
    let x0 = floor(fx);
    let y0 = floor(fy);
    let tx = fx - x0;
    let ty = fy - y0;
    let xa = tex_col(x0, w, wrap);
    let xb = tex_col(x0 + 1.0, w, wrap);
    let ya = u32(y0);
    let yb = u32(min(y0 + 1.0, h - 1.0));
    let top = mix(texel(which, base, xa, ya, wi, fmt), texel(which, base, xb, ya, wi, fmt), tx);
    let bottom = mix(texel(which, base, xa, yb, wi, fmt), texel(which, base, xb, yb, wi, fmt), tx);
    return mix(top, bottom, ty);
}

// texture::equirect_uv
fn equirect_uv(dir: vec3<f32>) -> vec2<f32> {
    let phi = rem_euclid(atan2(dir.x, dir.y), TAU);
    let theta = asin(clamp(dir.z, -1.0, 1.0));
    return vec2<f32>(phi / TAU, (0.5 * PI - theta) / PI);
}

// ---- spectra -----------------------------------------------------------------

// ---- camera wavelengths, four at a time -----------------------------------------
//
// Loops over wavelengths take four per iteration: llvmpipe (software
// Vulkan) ends every loop of an invocation after 65535 iterations in all,
// which per-wavelength loops in the gas would otherwise spend. Lanes past
// the last wavelength are masked.

fn nm4(j0: u32) -> vec4<f32> {
    return vec4<f32>(P.wl[j0].w, P.wl[j0 + 1u].w, P.wl[j0 + 2u].w, P.wl[j0 + 3u].w);
}

fn live4(j0: u32) -> vec4<bool> {
    return vec4<u32>(j0, j0 + 1u, j0 + 2u, j0 + 3u) < vec4<u32>(N_WL);
}

// The index of lane k of the chunk at j0, kept inside the wavelengths.
fn lane(j0: u32, k: u32) -> u32 {
    return min(j0 + k, N_WL - 1u);
}

// The per-wavelength filter of the mirrors and clouds met so far.
fn filter4(j0: u32) -> vec4<f32> {
    return vec4<f32>(
        wl_filter[lane(j0, 0u)],
        wl_filter[lane(j0, 1u)],
        wl_filter[lane(j0, 2u)],
        wl_filter[lane(j0, 3u)]
    );
}

fn scale_filter4(j0: u32, f: vec4<f32>) {
    let live = live4(j0);
    wl_filter[j0] *= f.x;
    if live.y {
        wl_filter[j0 + 1u] *= f.y;
    }
    if live.z {
        wl_filter[j0 + 2u] *= f.z;
    }
    if live.w {
        wl_filter[j0 + 3u] *= f.w;
    }
}

// Light of camera wavelengths j0..j0+3, through the filter: into the
// sample's XYZ, and its spectrum when kept.
fn emit4(j0: u32, v_in: vec4<f32>) {
    let live = live4(j0);
    var v = select(vec4<f32>(0.0), v_in, live);
    if FILTERS {
        v *= filter4(j0);
    }
    xyz_acc += P.wl[j0].xyz * v.x + P.wl[j0 + 1u].xyz * v.y + P.wl[j0 + 2u].xyz * v.z
        + P.wl[j0 + 3u].xyz * v.w;
    if SPEC_ARRAY {
        let row = spec_row + j0;
        spectra[row] += v.x;
        if live.y {
            spectra[row + 1u] += v.y;
        }
        if live.z {
            spectra[row + 2u] += v.z;
        }
        if live.w {
            spectra[row + 3u] += v.w;
        }
    }
}

fn radiance_factor(g: f32) -> f32 {
    if has_flag(FLAG_BEAMING) {
        return pow(g, 5.0);
    }
    return 1.0;
}

// spectrum::d65: the table, continued by a 6504 K blackbody beyond its ends.
fn d65(nm: f32) -> f32 {
    let start = P.d65_nm0;
    let step = P.d65_dnm;
    let n = u32(P.d65_count);
    let f = (nm - start) / step;
    let base = P.at_d65;
    if f >= 0.0 && f <= f32(n - 1u) {
        let i = min(u32(f), n - 2u);
        let t = f - f32(i);
        return tables[base + i] * (1.0 - t) + tables[base + i + 1u] * t;
    }
    var edge = start + f32(n - 1u) * step;
    var at = tables[base + n - 1u];
    if nm < start {
        edge = start;
        at = tables[base];
    }
    let c = 1.4388e7 / 6504.0;
    let ratio = pow(edge / nm, 5.0) * (exp(c / edge) - 1.0) / (exp(c / nm) - 1.0);
    return at * ratio;
}

fn d65_4(nm: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(d65(nm.x), d65(nm.y), d65(nm.z), d65(nm.w));
}

fn sigmoid4(p: vec4<f32>) -> vec4<f32> {
    let s = 0.5 + p / (2.0 * sqrt(1.0 + p * p));
    return select(s, select(vec4<f32>(0.0), vec4<f32>(1.0), p > vec4<f32>(0.0)), abs(p) > vec4<f32>(1e18));
}

// An uplifted spectrum (c0, c1, c2, scale) as reflectance at `nm`.
fn uplift_reflectance4(c: vec4<f32>, nm: vec4<f32>) -> vec4<f32> {
    let x = (nm - 380.0) / 400.0;
    return c.w * sigmoid4((c.x * x + c.y) * x + c.z);
}

// ... and as emission (times D65, white of luminance 1).
fn uplift_emission4(c: vec4<f32>, nm: vec4<f32>) -> vec4<f32> {
    return uplift_reflectance4(c, nm) * d65_4(nm) * P.d65_norm;
}

// spectrum::uplift::uplift: the colour over its largest component,
// looked up bilinearly on the table's face, scaled back.
fn uplift(rgb_in: vec3<f32>) -> vec4<f32> {
    let rgb0 = max(rgb_in, vec3<f32>(0.0));
    let m = max(rgb0.x, max(rgb0.y, rgb0.z));
    if !(m > 0.0) || !finite(m) {
        return vec4<f32>(0.0);
    }
    let rgb = rgb0 / m;
    var l = 2u;
    if rgb.x >= rgb.y && rgb.x >= rgb.z {
        l = 0u;
    } else if rgb.y >= rgb.z {
        l = 1u;
    }
    let v = array<f32, 3>(rgb.x, rgb.y, rgb.z);
    let top = f32(UPLIFT_RES - 1u);
    let k = top / v[l];
    let xf = clamp(v[(l + 1u) % 3u] * k, 0.0, top);
    let yf = clamp(v[(l + 2u) % 3u] * k, 0.0, top);
    let xi = min(u32(xf), UPLIFT_RES - 2u);
    let yi = min(u32(yf), UPLIFT_RES - 2u);
    let tx = xf - f32(xi);
    let ty = yf - f32(yi);
    var out = vec3<f32>(0.0);
    for (var dy = 0u; dy < 2u; dy++) {
        let wy = select(1.0 - ty, ty, dy == 1u);
        for (var dx = 0u; dx < 2u; dx++) {
            let wx = select(1.0 - tx, tx, dx == 1u);
            let at = P.at_uplift + 3u * ((l * UPLIFT_RES + yi + dy) * UPLIFT_RES + xi + dx);
            out += vec3<f32>(tables[at], tables[at + 1u], tables[at + 2u]) * (wy * wx);
        }
    }
    return vec4<f32>(out, m / UPLIFT_FACE);
}

fn planck_row(t: f32) -> vec2<f32> {
    let rows = P.planck_rows;
    let f = clamp((log(t) - P.planck_ln_t0) / P.planck_dln_t, 0.0, rows - 1.0);
    let i = min(floor(f), rows - 2.0);
    return vec2<f32>(i, f - i);
}

// spectrum::sampled::PlanckTable::add: a blackbody at `kelvin` seen with
// frequency ratio g, luminance `scale` before the shift.
fn planck_add(kelvin: f32, g: f32, scale: f32) {
    let a = planck_row(kelvin * g);
    let b = planck_row(kelvin);
    let ly = P.at_planck_ln_y;
    let ia = u32(a.x);
    let ib = u32(b.x);
    let ln_a = tables[ly + ia] * (1.0 - a.y) + tables[ly + ia + 1u] * a.y;
    let ln_b = tables[ly + ib] * (1.0 - b.y) + tables[ly + ib + 1u] * b.y;
    var k = scale * exp(ln_a - ln_b);
    if !has_flag(FLAG_BEAMING) {
        k *= pow(g, -5.0);
    }
    let k0 = k * (1.0 - a.y);
    let k1 = k * a.y;
    if !SPEC_ARRAY && !FILTERS {
        // Only the XYZ is wanted: the rows' own XYZ (sum against the CMFs).
        let x = P.at_planck_xyz + 3u * ia;
        xyz_acc += vec3<f32>(tables[x], tables[x + 1u], tables[x + 2u]) * k0
            + vec3<f32>(tables[x + 3u], tables[x + 4u], tables[x + 5u]) * k1;
        return;
    }
    let row0 = P.at_planck + ia * N_WL;
    let row1 = row0 + N_WL;
    for (var j = 0u; j < N_WL; j += 4u) {
        let a0 = vec4<f32>(tables[row0 + lane(j, 0u)], tables[row0 + lane(j, 1u)], tables[row0 + lane(j, 2u)], tables[row0 + lane(j, 3u)]);
        let a1 = vec4<f32>(tables[row1 + lane(j, 0u)], tables[row1 + lane(j, 1u)], tables[row1 + lane(j, 2u)], tables[row1 + lane(j, 3u)]);
        emit4(j, k0 * a0 + k1 * a1);
    }
}

fn uplift_add(c: vec4<f32>, g: f32, k: f32) {
    let kk = k * radiance_factor(g);
    for (var j = 0u; j < N_WL; j += 4u) {
        emit4(j, kk * uplift_emission4(c, g * nm4(j)));
    }
}

fn blackbody_rgb(kelvin: f32) -> vec3<f32> {
    let n = P.bb_count;
    let f = clamp((kelvin - P.bb_t0) / P.bb_dt, 0.0, n - 1.0);
    let i = min(floor(f), n - 2.0);
    let t = f - i;
    let at = P.at_bb + 3u * u32(i);
    let a = vec3<f32>(tables[at], tables[at + 1u], tables[at + 2u]);
    let b = vec3<f32>(tables[at + 3u], tables[at + 4u], tables[at + 5u]);
    return mix(a, b, t);
}

// ---- the disk ----------------------------------------------------------------

struct DiskHit {
    u: f32,
    v: f32,
    alpha: f32,
    // FOOTPRINT: the derivatives of (u, v) per pixel along x (xy) and y
    // (zw), where the filter reads over the footprint and the sample has
    // one at this crossing.
    fp: bool,
    duv: vec4<f32>,
    // An RGB texture's premultiplied linear RGBA there (over the
    // footprint or at the point), read once for the hit's alpha and its
    // light; a spectral set's is white with its coverage as alpha (a thin
    // disk's pattern is then 1, as on the CPU).
    rgba: vec4<f32>,
}

// Texels (index, weight) of the spectral set under (u, v), and how many.
struct SetTexels {
    t: array<u32, 4>,
    w: array<f32, 4>,
    n: u32,
}

fn set_texels(u: f32, v: f32) -> SetTexels {
    let wi = P.disk_width;
    let hi = P.disk_height;
    let w = f32(wi);
    let h = f32(hi);
    if P.disk_filter == 0u {
        let x = min(u32(max(u * w, 0.0)), wi - 1u);
        let y = min(u32(max(v * h, 0.0)), hi - 1u);
        return SetTexels(array<u32, 4>(y * wi + x, 0u, 0u, 0u), array<f32, 4>(1.0, 0.0, 0.0, 0.0), 1u);
    }
    let fx = clamp(u * w - 0.5, 0.0, w - 1.0);
    let fy = clamp(v * h - 0.5, 0.0, h - 1.0);
    let x0 = u32(fx);
    let y0 = u32(fy);
    let x1 = min(x0 + 1u, wi - 1u);
    let y1 = min(y0 + 1u, hi - 1u);
    let tx = fx - f32(x0);
    let ty = fy - f32(y0);
    return SetTexels(
        array<u32, 4>(y0 * wi + x0, y0 * wi + x1, y1 * wi + x0, y1 * wi + x1),
        array<f32, 4>((1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty),
        4u
    );
}

fn set_alpha(t: u32) -> f32 {
    let n = P.disk_width * P.disk_height * P.disk_set_len;
    return bitcast<f32>(disk_data[n + t]);
}

// spectral_texture::SpectralTexture::value
fn set_value(t: u32, nm: f32) -> f32 {
    let n = P.disk_set_len;
    if n == 1u {
        return set_read(t, select(-1.0, 0.0, nm == P.disk_nm0));
    }
    return set_read(t * n, set_index(nm));
}

// The fractional index of `nm` among the spectral set's wavelengths (two
// or more): SpectralTexture::lookup's, before it rounds or splits it.
fn set_index(nm: f32) -> f32 {
    let n = P.disk_set_len;
    let nm0 = P.disk_nm0;
    if P.disk_set_uniform != 0u {
        return (nm - nm0) / P.disk_dnm;
    }
    // partition_point(l <= nm) over the set's wavelengths.
    let tab = P.at_set_nm;
    var lo = 0u;
    var hi = n;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if tables[tab + mid] <= nm {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let i = lo;
    if i == 0u {
        return (nm - tables[tab]) / (tables[tab + 1u] - tables[tab]);
    }
    if i == n {
        return f32(n - 1u) + (nm - tables[tab + n - 1u]) / (tables[tab + n - 1u] - tables[tab + n - 2u]);
    }
    return f32(i - 1u) + (nm - tables[tab + i - 1u]) / (tables[tab + i] - tables[tab + i - 1u]);
}

// SpectralTexture::value_at of the spectrum starting at word `base` of
// the disk data, at fractional index `f` (set_index; a set of one
// wavelength: 0 at it, else -1), read as the interpolation says; 0
// outside the table.
fn set_read(base: u32, f: f32) -> f32 {
    let n = P.disk_set_len;
    if n == 1u {
        return select(0.0, bitcast<f32>(disk_data[base]), f == 0.0);
    }
    if !has_flag(FLAG_LINEAR) {
        // Rust's round: half away from zero (f < 0 reads 0 either way).
        let r = floor(f + 0.5);
        if r < 0.0 || r > f32(n - 1u) {
            return 0.0;
        }
        return bitcast<f32>(disk_data[base + u32(r)]);
    }
    if !(f >= 0.0 && f <= f32(n - 1u)) {
        return 0.0;
    }
    let i = min(u32(f), n - 2u);
    let frac = f - f32(i);
    return bitcast<f32>(disk_data[base + i]) * (1.0 - frac) + bitcast<f32>(disk_data[base + i + 1u]) * frac;
}

// disk::Disk::hit_footprint at the point `q` of the disk's polar
// coordinates (disk_plane), the ray's plane crossing `order` (whose
// footprint the filter reads over): alpha 0 means no hit.
fn disk_hit(q: vec2<f32>, order: u32) -> DiskHit {
    let inner = P.disk_inner;
    let outer = P.disk_outer;
    let r2 = q.x * q.x + q.y * q.y;
    if r2 > outer * outer || r2 < inner * inner {
        return DiskHit(0.0, 0.0, 0.0, false, vec4<f32>(0.0), vec4<f32>(0.0));
    }
    let side = 2.0 * outer;
    let u = (q.x + outer) / side;
    let v = (outer - q.y) / side;
    // Disk::hit_footprint: the footprint's crossing, where the filter
    // reads over one.
    var i = FP_CROSSINGS;
    if FOOTPRINT && P.disk_filter == 2u {
        i = fp_disk(order);
    }
    let blend = P.disk_alpha != 0u;
    // The point's lookup: the hit without a footprint, and where a cutout
    // read over one stops the ray (a point without material is passed
    // before any filtering).
    var point = DiskHit(u, v, 0.0, false, vec4<f32>(0.0), vec4<f32>(0.0));
    if !(i < FP_CROSSINGS && blend) {
        if P.disk_kind == DISK_RGB {
            let t = tex_sample(TEX_DISK, 0u, u, v, P.disk_filter != 0u, false, P.disk_width, P.disk_height, P.disk_format);
            point = DiskHit(u, v, t.w, false, vec4<f32>(0.0), t);
        } else {
            var alpha = 0.0;
            let s = set_texels(u, v);
            for (var q = 0u; q < s.n; q++) {
                alpha += s.w[q] * set_alpha(s.t[q]);
            }
            point = DiskHit(u, v, alpha, false, vec4<f32>(0.0), vec4<f32>(1.0, 1.0, 1.0, alpha));
        }
    }
    if i < FP_CROSSINGS && (blend || point.alpha > 0.0) {
        // Disk::short_of_the_hole: the footprint stops at the material's
        // inner edge.
        let r = sqrt(r2);
        let n = q / max(r, 1e-30);
        let reach = length(vec2<f32>(dot(n, fp.q_dx[i]), dot(n, fp.q_dy[i])));
        let room = max(r - P.disk_material_inner, 0.0);
        let k = select(1.0, room / reach, reach > room);
        let duv = k * vec4<f32>(fp.q_dx[i].x, -fp.q_dx[i].y, fp.q_dy[i].x, -fp.q_dy[i].y) / side;
        let c = ewa_disk(vec2<f32>(u, v), duv.xy, duv.zw);
        // Blended alpha is the footprint's; a cutout's colour is, where
        // its alpha does not round to nothing.
        if blend || c.w > 0.0 {
            return DiskHit(u, v, c.w, true, duv, select(vec4<f32>(1.0, 1.0, 1.0, c.w), c, P.disk_kind == DISK_RGB));
        }
    }
    return point;
}

// thin_disk::ThinDisk::temperature: T0 (f(r) / r^3)^(1/4).
fn thin_temperature(r: f32) -> f32 {
    let inner = P.thin_inner;
    if !(r > inner) {
        return 0.0;
    }
    var f: f32;
    if P.thin_profile == PROFILE_PAGE_THORNE {
        // Kerr::page_thorne_flux (its scale in thin_t0), x = sqrt(r / M).
        let x = sqrt(2.0 * r);
        let x0 = P.thin_pt_roots.w;
        let xi = P.thin_pt_roots.xyz;
        let c = P.thin_pt_coef;
        let logs = log((vec3<f32>(x) - xi) / (vec3<f32>(x0) - xi));
        let bracket = x - x0 - c.w * log(x / x0) - dot(c.xyz, logs);
        let a = P.kerr_hole.x;
        let flux = 3.0 / (8.0 * PI * x * x * x * x * (x * x * x - 3.0 * x + 2.0 * a)) * bracket;
        return P.thin_t0 * pow(max(flux, 0.0), 0.25);
    }
    if P.thin_profile == PROFILE_SHAKURA_SUNYAEV {
        f = 1.0 - sqrt(inner / r);
    } else {
        let x = sqrt(2.0 * r);
        let x0 = sqrt(2.0 * inner);
        let s3 = sqrt(3.0);
        let b = x - x0 - 0.5 * s3 * log((x - s3) * (x0 + s3) / ((x0 - s3) * (x + s3)));
        f = x * b / (x * x - 3.0);
    }
    return P.thin_t0 * pow(max(f, 0.0) / (r * r * r), 0.25);
}

// The ring radius (Boyer-Lindquist r with spin) of a hit, from its
// texture coordinates (the disk's polar coordinates).
fn disk_hit_radius(h: DiskHit) -> f32 {
    let outer = P.disk_outer;
    return length(vec2<f32>(h.u * 2.0 * outer - outer, outer - h.v * 2.0 * outer));
}

// thin_disk::blackbody_xyz_absolute: the table of ln XYZ over ln T.
fn thin_xyz(kelvin: f32) -> vec3<f32> {
    let n = u32(P.thin_rows);
    let f = (log(kelvin) - P.thin_ln_t0) / P.thin_dln_t;
    if !(f >= 0.0) {
        return vec3<f32>(0.0);
    }
    let i = min(u32(f), n - 2u);
    let t = f - f32(i);
    let base = P.at_thin_xyz + 3u * i;
    let a = vec3<f32>(tables[base], tables[base + 1u], tables[base + 2u]);
    let b = vec3<f32>(tables[base + 3u], tables[base + 4u], tables[base + 5u]);
    return exp(a + (b - a) * t);
}

// Planck's B_lambda(T) in W m^-2 sr^-1 nm^-1, wavelengths in nm.
fn planck_nm4(nm: vec4<f32>, kelvin: f32) -> vec4<f32> {
    let x = 1.438776877e7 / (nm * kelvin);
    let e = select(exp(x) - 1.0, x * (1.0 + 0.5 * x), x < vec4<f32>(1e-3));
    let nm2 = nm * nm;
    return 1.1910429724e20 / (nm2 * nm2 * nm) / e;
}

// The thin disk's pattern: the texture's linear luminance (premultiplied).
fn thin_modulation(h: DiskHit) -> f32 {
    return dot(h.rgba.xyz, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// ---- the sky -----------------------------------------------------------------

struct StarLight {
    luminance: f32,
    kelvin: f32,
    milky_way: f32,
}

struct Bilinear {
    k: array<u32, 4>,
    w: array<f32, 4>,
}

// starmap::bilinear
fn star_bilinear(uv: vec2<f32>, wi: u32, hi: u32) -> Bilinear {
    let w = f32(wi);
    let h = f32(hi);
    let fx = uv.x * w - 0.5;
    let fy = clamp(uv.y * h - 0.5, 0.0, h - 1.0);
    let x0 = floor(fx);
    let y0 = floor(fy);
    let tx = fx - x0;
    let ty = fy - y0;
    let xa = u32(rem_euclid(x0, w));
    let xb = (xa + 1u) % wi;
    let ya = u32(y0);
    let yb = min(ya + 1u, hi - 1u);
    return Bilinear(
        array<u32, 4>(ya * wi + xa, ya * wi + xb, yb * wi + xa, yb * wi + xb),
        array<f32, 4>((1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty)
    );
}

fn star_sample(dir: vec3<f32>) -> StarLight {
    let uv = equirect_uv(dir);
    let wi = P.sky_width;
    let hi = P.sky_height;
    let n = wi * hi;
    var lum = 0.0;
    var kelvin = 0.0;
    if P.ewa_star_grid == 0u {
        // A map of the Milky Way alone (its stars are points).
    } else if P.sky_filter == 0u {
        let i = min(u32(uv.x * f32(wi)), wi - 1u);
        let j = min(u32(uv.y * f32(hi)), hi - 1u);
        lum = bitcast<f32>(sky_data[j * wi + i]);
        kelvin = bitcast<f32>(sky_data[n + j * wi + i]);
    } else {
        let b = star_bilinear(uv, wi, hi);
        var lt = 0.0;
        for (var q = 0u; q < 4u; q++) {
            let l = bitcast<f32>(sky_data[b.k[q]]);
            lum += b.w[q] * l;
            lt += b.w[q] * l * bitcast<f32>(sky_data[n + b.k[q]]);
        }
        if lum > 0.0 {
            kelvin = lt / lum;
        }
    }
    var mw = 0.0;
    if P.sky_milky_way != 0u {
        let b = star_bilinear(uv, P.milky_way_width, P.milky_way_height);
        for (var q = 0u; q < 4u; q++) {
            mw += b.w[q] * bitcast<f32>(sky_data[P.ewa_milky_way_at + b.k[q]]);
        }
    }
    return StarLight(lum, kelvin, mw);
}

// StarMap::sample_filtered: over the sample's footprint where the filter
// says so and the sample has one on the sky, else at the point.
fn star_lookup(dir: vec3<f32>) -> StarLight {
    if FOOTPRINT && P.sky_filter == 2u && fp.ok && fp.sky_ok {
        return ewa_stars(dir, fp.sky_dx, fp.sky_dy);
    }
    return star_sample(dir);
}

fn panorama(dir: vec3<f32>) -> vec3<f32> {
    if FOOTPRINT && P.sky_filter == 2u && fp.ok && fp.sky_ok {
        return ewa_sky(dir, fp.sky_dx, fp.sky_dy).xyz * P.sky_intensity;
    }
    let uv = equirect_uv(dir);
    return tex_sample(TEX_SKY, 0u, uv.x, uv.y, P.sky_filter != 0u, true, P.sky_width, P.sky_height, P.sky_format).xyz
        * P.sky_intensity;
}

// sky::Sky::radiance
fn sky_rgb(dir: vec3<f32>) -> vec3<f32> {
    switch P.sky_kind {
        case SKY_COLOR, SKY_BLACKBODY: {
            return P.sky_rgb.xyz;
        }
        case SKY_PANORAMA: {
            return panorama(dir);
        }
        default: {
            let s = star_lookup(dir);
            var c = vec3<f32>(0.0);
            if s.luminance > 0.0 {
                c += blackbody_rgb(s.kelvin) * s.luminance;
            }
            if s.milky_way > 0.0 {
                c += blackbody_rgb(P.milky_way_kelvin) * s.milky_way;
            }
            if point_stars_on() {
                c += point_stars(1.0, 1.0);
            }
            return c * P.sky_intensity;
        }
    }
}

// sky::Sky::add_spectrum
fn sky_spectrum(dir: vec3<f32>, g: f32, k: f32) {
    switch P.sky_kind {
        case SKY_COLOR: {
            uplift_add(P.sky_uplift, g, k);
        }
        case SKY_BLACKBODY: {
            planck_add(P.sky_kelvin, g, k * P.sky_intensity);
        }
        case SKY_PANORAMA: {
            uplift_add(uplift(panorama(dir)), g, k);
        }
        default: {
            let s = star_lookup(dir);
            if s.luminance > 0.0 {
                planck_add(s.kelvin, g, k * P.sky_intensity * s.luminance);
            }
            if s.milky_way > 0.0 {
                planck_add(P.milky_way_kelvin, g, k * P.sky_intensity * s.milky_way);
            }
            if point_stars_on() {
                _ = point_stars(g, k);
            }
        }
    }
}
