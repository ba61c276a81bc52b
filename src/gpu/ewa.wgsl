// Footprint filtering of textures: the elliptical Gaussian (EWA) filter
// over mip levels, in f32. Twin of src/texture/ewa.rs (plan, visit), the
// footprint lookups of src/texture/mod.rs (Texture::sample_footprint,
// sample_sky_footprint), src/texture/sphere.rs (equirect_footprint),
// src/spectral_texture.rs (footprint_texels, coverage, add_premultiplied)
// and src/starmap.rs (StarMap::sample_footprint).
//
// Level 0 is where shade.wgsl reads it; levels 1 and up follow in the
// same buffer from P.ewa_*_mips, level 1 first, each in level 0's format
// (src/gpu/ewa.rs packs them; an object's follow its texels in
// objects_data, from its record, as src/gpu/pack.rs packs them). The host writes EWA_MAX_ANISOTROPY,
// EWA_TABLE, EWA_COORD and EWA_REACH (texture::ewa::REACH) before this file; the weights are the CPU's
// table, in `tables` from P.at_ewa_weights.
//
// The lookups take explicit inputs (texture coordinates or a direction
// and their derivatives per pixel step) and read nothing of the ray.

// What a level's texels are read as (EwaSource::kind).
const EWA_DISK_RGBA: u32 = 0u;
const EWA_SKY_RGBA: u32 = 1u;
const EWA_SET_ALPHA: u32 = 2u;
const EWA_SET4: u32 = 3u;
// The star grid's level 0 (luminance and kelvin planes), its levels
// (pairs of mean luminance and luminance times kelvin), the Milky Way.
const EWA_STARS: u32 = 4u;
const EWA_STAR_PAIRS: u32 = 5u;
const EWA_MILKY_WAY: u32 = 6u;
// An object's texture (the record at ewa_rec): level 0 at its word 7,
// levels 1 and up at its word 28, in the format of its word 10.
const EWA_OBJECT_RGBA: u32 = 7u;

// The object record ewa_object reads (its source varies per object, not
// with P as the disk's and the sky's do).
var<private> ewa_rec: u32;

// One level's ellipse (ewa::LevelEllipse). The centre, in the level's
// texel units, is kept as its integer part and fraction, so that texel
// offsets from it are exact but for one rounding.
struct EwaLevel {
    level: u32,
    weight: f32,
    ci: vec2<f32>,
    cf: vec2<f32>,
    // r^2 = q.x dx^2 + q.y dx dy + q.z dy^2.
    q: vec3<f32>,
    // Half the bounding box (texels).
    extent: vec2<f32>,
}

// The one or two levels of a lookup.
struct EwaPlan {
    a: EwaLevel,
    b: EwaLevel,
    n: u32,
}

// Where a level's texels are and how to read them: words `base` (and
// `base2`: the set's alpha, the star grid's kelvin plane), the texel
// format, the set's fractional wavelength indices.
struct EwaSource {
    kind: u32,
    base: u32,
    base2: u32,
    fmt: u32,
    f: vec4<f32>,
}

// A footprint in texture coordinates: (u, v) and its derivatives per
// pixel step.
struct EwaFootprint {
    uv: vec2<f32>,
    dx: vec2<f32>,
    dy: vec2<f32>,
}

// ewa::level_dims
fn ewa_dims(w: u32, h: u32, k: u32) -> vec2<u32> {
    let s = min(k, 31u);
    return max(vec2<u32>(w >> s, h >> s), vec2<u32>(1u));
}

// ewa::level_count
fn ewa_level_count(w: u32, h: u32) -> u32 {
    return 32u - countLeadingZeros(max(max(w, h), 1u));
}

// Texels of levels 1 to k - 1: where level k starts among the levels.
fn ewa_level_offset(w: u32, h: u32, k: u32) -> u32 {
    var off = 0u;
    for (var j = 1u; j < k; j++) {
        let d = ewa_dims(w, h, j);
        off += d.x * d.y;
    }
    return off;
}

// v with its length unchanged up to rounding, found without squaring
// tiny or huge components.
fn ewa_unit(v: vec2<f32>) -> vec2<f32> {
    let s = max(abs(v.x), abs(v.y));
    let w = v / s;
    return w / length(w);
}

// ewa::axes of J J^T for J's columns a and b: (sigma1, sigma2, the major
// direction), the minor widened to sigma1 / EWA_MAX_ANISOTROPY, both at
// least `lo`. The smaller eigenvalue is det(J)^2 / l1, which f32 keeps
// where l1 - d would cancel.
fn ewa_axes(a: vec2<f32>, b: vec2<f32>, lo: f32) -> vec4<f32> {
    let m00 = a.x * a.x + b.x * b.x;
    let m01 = a.x * a.y + b.x * b.y;
    let m11 = a.y * a.y + b.y * b.y;
    let half = 0.5 * (m00 - m11);
    let d = sqrt(half * half + m01 * m01);
    let l1 = 0.5 * (m00 + m11) + d;
    let det = a.x * b.y - a.y * b.x;
    var l2 = 0.0;
    if l1 > 0.0 {
        l2 = det * (det / l1);
    }
    var e = vec2<f32>(1.0, 0.0);
    if m01 != 0.0 {
        // The larger eigenvalue's vector, from whichever row does not
        // cancel.
        if half >= 0.0 {
            e = ewa_unit(vec2<f32>(l1 - m11, m01));
        } else {
            e = ewa_unit(vec2<f32>(m01, l1 - m00));
        }
    } else if m00 < m11 {
        e = vec2<f32>(0.0, 1.0);
    }
    let s1 = max(sqrt(l1), lo);
    let s2 = max(max(sqrt(l2), s1 / EWA_MAX_ANISOTROPY), lo);
    return vec4<f32>(s1, s2, e);
}

// A derivative in level-0 texels, its larger component at most
// EWA_COORD (beyond it every footprint reads the coarsest level, as the
// CPU's larger cap does), scaled without overflowing f32.
fn ewa_cap(d: vec2<f32>, size: vec2<f32>) -> vec2<f32> {
    let m = max(abs(d.x), abs(d.y));
    if !(m > 0.0) {
        return vec2<f32>(0.0);
    }
    let v = (d / m) * size;
    let vm = max(abs(v.x), abs(v.y));
    if vm * m > EWA_COORD {
        return v * (EWA_COORD / vm);
    }
    return v * m;
}

// `e` centred at c (level texels).
fn ewa_centred(e_in: EwaLevel, c: vec2<f32>) -> EwaLevel {
    var e = e_in;
    e.ci = floor(c);
    e.cf = c - e.ci;
    return e;
}

// rem_euclid(x, n) of integers.
fn ewa_wrap(x: i32, n: i32) -> i32 {
    return ((x % n) + n) % n;
}

// ewa::level_ellipse: the ellipse on level k of a w0 x h0 pyramid for
// axes `ax` (ewa_axes) in level-0 texels.
fn ewa_level(k: u32, w0: u32, h0: u32, uv: vec2<f32>, ax: vec4<f32>) -> EwaLevel {
    let dims = ewa_dims(w0, h0, k);
    let s = vec2<f32>(f32(dims.x) / f32(w0), f32(dims.y) / f32(h0));
    var t1: f32;
    var t2: f32;
    var f1: vec2<f32>;
    if s.x == s.y {
        t1 = max(ax.x * s.x, 1.0);
        t2 = max(max(ax.y * s.x, t1 / EWA_MAX_ANISOTROPY), 1.0);
        f1 = ax.zw;
    } else {
        // The coarsest levels of a non-square image scale the axes unlike.
        let e2 = vec2<f32>(-ax.w, ax.z);
        let m = ewa_axes(s * ax.zw * ax.x, s * e2 * ax.y, 1.0);
        t1 = m.x;
        t2 = m.y;
        f1 = m.zw;
    }
    let cap = f32(max(dims.x, dims.y));
    t1 = min(t1, cap);
    t2 = min(t2, cap);
    let f2 = vec2<f32>(-f1.y, f1.x);
    let i1 = 1.0 / (t1 * t1);
    let i2 = 1.0 / (t2 * t2);
    let q00 = f1.x * f1.x * i1 + f2.x * f2.x * i2;
    let q01 = f1.x * f1.y * i1 + f2.x * f2.y * i2;
    let q11 = f1.y * f1.y * i1 + f2.y * f2.y * i2;
    let n00 = f1.x * f1.x * t1 * t1 + f2.x * f2.x * t2 * t2;
    let n11 = f1.y * f1.y * t1 * t1 + f2.y * f2.y * t2 * t2;
    let e = EwaLevel(k, 1.0, vec2<f32>(0.0), vec2<f32>(0.0), vec3<f32>(q00, 2.0 * q01, q11), sqrt(vec2<f32>(n00, n11)));
    return ewa_centred(e, uv * vec2<f32>(dims));
}

// ewa::plan: the level is log2 of the minor axis in level-0 texels (after
// the anisotropy cap), blended linearly between the two levels around it.
// Non-finite coordinates read 0; a non-finite footprint reads as a point.
// Coordinates are clamped to [-1, 2] (the textures span [0, 1]), which
// bounds the loops whatever comes in.
fn ewa_plan(uv_in: vec2<f32>, dx_in: vec2<f32>, dy_in: vec2<f32>, w0: u32, h0: u32) -> EwaPlan {
    let uv = clamp(
        vec2<f32>(select(0.0, uv_in.x, finite(uv_in.x)), select(0.0, uv_in.y, finite(uv_in.y))),
        vec2<f32>(-1.0),
        vec2<f32>(2.0)
    );
    var dx = dx_in;
    var dy = dy_in;
    if !(finite(dx.x) && finite(dx.y) && finite(dy.x) && finite(dy.y)) {
        dx = vec2<f32>(0.0);
        dy = vec2<f32>(0.0);
    }
    let size = vec2<f32>(f32(w0), f32(h0));
    let ax = ewa_axes(ewa_cap(dx * EWA_REACH, size), ewa_cap(dy * EWA_REACH, size), 0.0);
    var plan: EwaPlan;
    plan.n = 1u;
    if ax.x <= 1.0 {
        // Magnified: the one-texel circle on level 0.
        let e = EwaLevel(0u, 1.0, vec2<f32>(0.0), vec2<f32>(0.0), vec3<f32>(1.0, 0.0, 1.0), vec2<f32>(1.0));
        plan.a = ewa_centred(e, uv * size);
        return plan;
    }
    let last = ewa_level_count(w0, h0) - 1u;
    var lod = 0.0;
    if ax.y > 1.0 {
        lod = log2(ax.y);
    }
    // A whole level up to f32's rounding of log2 reads that level alone.
    if abs(lod - round(lod)) < 1e-6 {
        lod = round(lod);
    }
    if lod >= f32(last) {
        plan.a = ewa_level(last, w0, h0, uv, ax);
        return plan;
    }
    let k = u32(lod);
    let t = lod - f32(k);
    plan.a = ewa_level(k, w0, h0, uv, ax);
    if t == 0.0 {
        return plan;
    }
    plan.a.weight = 1.0 - t;
    plan.b = ewa_level(k + 1u, w0, h0, uv, ax);
    plan.b.weight = t;
    plan.n = 2u;
    return plan;
}

// ewa::weight: the table's weight at r^2 in [0, 1), interpolated.
fn ewa_weight(r2: f32) -> f32 {
    let f = r2 * f32(EWA_TABLE);
    let i = u32(f);
    let t = f - f32(i);
    let a = tables[P.at_ewa_weights + i];
    let b = tables[P.at_ewa_weights + i + 1u];
    return a + t * (b - a);
}

// Texel i (row-major in its level) as `s` reads it.
fn ewa_fetch(s: EwaSource, i: u32) -> vec4<f32> {
    switch s.kind {
        case EWA_DISK_RGBA: {
            return texel(TEX_DISK, s.base, i, 0u, 0u, s.fmt);
        }
        case EWA_SKY_RGBA: {
            return texel(TEX_SKY, s.base, i, 0u, 0u, s.fmt);
        }
        case EWA_OBJECT_RGBA: {
            return texel(TEX_OBJECT, s.base, i, 0u, 0u, s.fmt);
        }
        case EWA_SET_ALPHA: {
            return vec4<f32>(bitcast<f32>(disk_data[s.base2 + i]), 0.0, 0.0, 0.0);
        }
        case EWA_SET4: {
            let a = bitcast<f32>(disk_data[s.base2 + i]);
            let at = s.base + i * P.disk_set_len;
            return a * vec4<f32>(set_read(at, s.f.x), set_read(at, s.f.y), set_read(at, s.f.z), set_read(at, s.f.w));
        }
        case EWA_STARS: {
            let l = bitcast<f32>(sky_data[s.base + i]);
            return vec4<f32>(l, l * bitcast<f32>(sky_data[s.base2 + i]), 0.0, 0.0);
        }
        case EWA_STAR_PAIRS: {
            return vec4<f32>(bitcast<f32>(sky_data[s.base + 2u * i]), bitcast<f32>(sky_data[s.base + 2u * i + 1u]), 0.0, 0.0);
        }
        default: {
            return vec4<f32>(bitcast<f32>(sky_data[s.base + i]), 0.0, 0.0, 0.0);
        }
    }
}

// ewa::visit and the normalised mean after it: the Gaussian-weighted mean
// of the w x h level's texels under ellipse `e` (`wrap` makes columns
// periodic, else they clamp to the edge; rows always clamp, so an edge
// texel may count more than once, as on the CPU). One call of ewa_fetch:
// the driver inlines each call of a lookup whole.
fn ewa_mean(e: EwaLevel, w: u32, h: u32, wrap: bool, s: EwaSource) -> vec4<f32> {
    let qa = e.q.x;
    let qb = e.q.y;
    let qc = e.q.z;
    let wi = i32(w);
    let hi = i32(h);
    let cx = i32(e.ci.x);
    let cy = i32(e.ci.y);
    var acc = vec4<f32>(0.0);
    var sum = 0.0;
    let y0 = cy + i32(ceil(e.cf.y - e.extent.y - 0.5));
    let y1 = cy + i32(floor(e.cf.y + e.extent.y - 0.5));
    // The rows under the ellipse, then one more only where no texel was
    // under it (unreachable with both axes at least a texel; kept for
    // rounding at the limit, as on the CPU): the texel under the centre.
    for (var y = y0; y <= y1 + 1; y++) {
        let centre = y > y1;
        if centre && sum > 0.0 {
            break;
        }
        let dy = f32(y - cy) + 0.5 - e.cf.y;
        // Where qa dx^2 + qb dy dx + qc dy^2 < 1 along this row.
        let lin = qb * dy;
        var x0 = cx;
        var x1 = cx;
        var row = u32(clamp(cy, 0, hi - 1)) * w;
        if !centre {
            let con = qc * dy * dy - 1.0;
            let disc = lin * lin - 4.0 * qa * con;
            if disc <= 0.0 {
                continue;
            }
            let root = sqrt(disc);
            x0 = cx + i32(ceil(e.cf.x + (-lin - root) / (2.0 * qa) - 0.5));
            x1 = cx + i32(floor(e.cf.x + (-lin + root) / (2.0 * qa) - 0.5));
            row = u32(clamp(y, 0, hi - 1)) * w;
        }
        var col = x0;
        if wrap {
            col = ewa_wrap(x0, wi);
        }
        for (var x = x0; x <= x1; x++) {
            let dx = f32(x - cx) + 0.5 - e.cf.x;
            let r = (qa * dx + lin) * dx + qc * dy * dy;
            if centre || r < 1.0 {
                let wt = select(ewa_weight(max(r, 0.0)), 1.0, centre);
                let at = select(clamp(x, 0, wi - 1), col, wrap);
                acc += wt * ewa_fetch(s, row + u32(at));
                sum += wt;
            }
            col += 1;
            if wrap && col == wi {
                col = 0;
            }
        }
    }
    return acc / sum;
}

// Where level k of a w0 x h0 texture of `kind` lies and how it is read.
fn ewa_source(kind: u32, k: u32, w0: u32, h0: u32, f: vec4<f32>) -> EwaSource {
    let off = ewa_level_offset(w0, h0, k);
    let n0 = w0 * h0;
    switch kind {
        case EWA_DISK_RGBA: {
            let words = select(4u, 1u, P.disk_format == TEXELS_SRGB8);
            return EwaSource(kind, select(P.ewa_disk_mips + words * off, 0u, k == 0u), 0u, P.disk_format, f);
        }
        case EWA_SKY_RGBA: {
            let words = select(4u, 1u, P.sky_format == TEXELS_SRGB8);
            return EwaSource(kind, select(P.ewa_sky_mips + words * off, 0u, k == 0u), 0u, P.sky_format, f);
        }
        case EWA_OBJECT_RGBA: {
            let fmt = objects_data[ewa_rec + 10u];
            let words = select(4u, 1u, fmt == TEXELS_SRGB8);
            return EwaSource(kind, select(objects_data[ewa_rec + 28u] + words * off, objects_data[ewa_rec + 7u], k == 0u), 0u, fmt, f);
        }
        case EWA_SET_ALPHA, EWA_SET4: {
            let n = P.disk_set_len;
            if k == 0u {
                return EwaSource(kind, 0u, n0 * n, 0u, f);
            }
            return EwaSource(kind, P.ewa_disk_mips + off * n, P.ewa_disk_mip_alpha + off, 0u, f);
        }
        case EWA_STARS: {
            if k == 0u {
                return EwaSource(EWA_STARS, 0u, n0, 0u, f);
            }
            return EwaSource(EWA_STAR_PAIRS, P.ewa_sky_mips + 2u * off, 0u, 0u, f);
        }
        default: {
            return EwaSource(kind, select(P.ewa_milky_way_mips + off, P.ewa_milky_way_at, k == 0u), 0u, 0u, f);
        }
    }
}

// The elliptical Gaussian average of a w0 x h0 texture of `kind` over the
// footprint `fp`, both levels weighted (`f`: the set's wavelength indices
// for EWA_SET4).
fn ewa_filter(fp: EwaFootprint, w0: u32, h0: u32, wrap: bool, kind: u32, f: vec4<f32>) -> vec4<f32> {
    let plan = ewa_plan(fp.uv, fp.dx, fp.dy, w0, h0);
    var out = vec4<f32>(0.0);
    for (var j = 0u; j < plan.n; j++) {
        var e = plan.a;
        if j == 1u {
            e = plan.b;
        }
        let d = ewa_dims(w0, h0, e.level);
        out += e.weight * ewa_mean(e, d.x, d.y, wrap, ewa_source(kind, e.level, w0, h0, f));
    }
    return out;
}

// atan(t) for t >= 0 to a few f32 ulp (Cephes' atanf: reduced to |x| <=
// tan(pi/8), then its odd polynomial).
fn ewa_atan(t: f32) -> f32 {
    var x = t;
    var y0 = 0.0;
    if x > 2.414213562373095 {
        y0 = 0.5 * PI;
        x = -1.0 / x;
    } else if x > 0.4142135623730950 {
        y0 = 0.25 * PI;
        x = (x - 1.0) / (x + 1.0);
    }
    let z = x * x;
    return y0 + (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * x + x;
}

// atan2(y, x) to a few ulp, 0 for (0, 0) as on the CPU. The panorama's
// coordinates need it: GPUs' own may be coarser (llvmpipe's was off by
// 2e-6 rad, 1e-4 of a texel of a 512-texel-wide map, more than the rest
// of the lookup's error).
fn ewa_atan2(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let ay = abs(y);
    if ax == 0.0 && ay == 0.0 {
        return 0.0;
    }
    var a: f32;
    if ay <= ax {
        a = ewa_atan(ay / ax);
    } else {
        a = 0.5 * PI - ewa_atan(ax / ay);
    }
    if x < 0.0 {
        a = PI - a;
    }
    return select(a, -a, y < 0.0);
}

// texture::equirect_footprint: the panorama coordinates of unit direction
// `dir` and their derivatives for the direction's derivatives `ddx`, `ddy`
// per pixel step (their parts along `dir` ignored; u's those of the angle,
// free of the seam, scaled down where the footprint would span more than
// the whole row). The colatitude is atan2(rho, z), equal to the CPU's
// pi/2 - asin(z) for unit directions and free of f32's cancellation at
// the poles.
fn ewa_equirect(dir: vec3<f32>, ddx: vec3<f32>, ddy: vec3<f32>) -> EwaFootprint {
    let len = length(dir);
    var d = vec3<f32>(0.0);
    if len > 0.0 && finite(len) {
        d = dir / len;
    }
    let rho0 = length(d.xy);
    var ex = 0.0;
    var ey = 1.0;
    if rho0 > 0.0 {
        ex = d.x / rho0;
        ey = d.y / rho0;
    }
    let rho = max(rho0, 1e-12);
    // At a pole u is the CPU's atan2(0, 0), 0; no direction is the
    // equator's middle, as equirect_uv has it.
    var uv = vec2<f32>(rem_euclid(ewa_atan2(d.x, d.y), TAU) / TAU, ewa_atan2(rho0, d.z) / PI);
    if len == 0.0 {
        uv.y = 0.5;
    }
    let east = vec3<f32>(ey, -ex, 0.0);
    let north = vec3<f32>(-d.z * ex, -d.z * ey, rho);
    var t1 = select(vec3<f32>(0.0), ddx, finite3(ddx));
    var t2 = select(vec3<f32>(0.0), ddy, finite3(ddy));
    t1 -= d * dot(t1, d);
    t2 -= d * dot(t2, d);
    var a = vec2<f32>(dot(t1, east) / (rho * TAU), -dot(t1, north) / PI);
    var b = vec2<f32>(dot(t2, east) / (rho * TAU), -dot(t2, north) / PI);
    // The ellipse's u half-extent is |(a.u, b.u)|: at most half a turn.
    let extent = length(vec2<f32>(a.x, b.x));
    if extent > 0.5 {
        let k = 0.5 / extent;
        a.x *= k;
        b.x *= k;
    }
    return EwaFootprint(uv, a, b);
}

// ---- the lookups ----------------------------------------------------------------

// Texture::sample_footprint of the disk at (u, v) (wrap off) with the
// derivatives of (u, v) per pixel step: premultiplied linear RGBA of the
// RGBA texture, or of the spectral set its coverage in w (what disk_hit
// takes as alpha; the set's light is ewa_disk_set4's).
fn ewa_disk(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    let rgb = P.disk_kind == DISK_RGB;
    let kind = select(EWA_SET_ALPHA, EWA_DISK_RGBA, rgb);
    let c = ewa_filter(EwaFootprint(uv, duv_dx, duv_dy), P.disk_width, P.disk_height, false, kind, vec4<f32>(0.0));
    return select(vec4<f32>(0.0, 0.0, 0.0, c.x), c, rgb);
}

// Object::color's texture over a footprint (Texture::sample_footprint):
// the texture of the object record at word `rec` at (u, v) with the
// derivatives of (u, v) per pixel step; premultiplied linear RGBA. u wraps
// round a sphere and a mesh (taken modulo 1 first: a mesh's coordinates
// may tile, and the plan clamps coordinates to [-1, 2]), not off a
// rectangle's edges.
fn ewa_object(rec: u32, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    ewa_rec = rec;
    let wrap = objects_data[rec] != 1u;
    var p = uv;
    if wrap {
        p.x = fract(p.x);
    }
    return ewa_filter(EwaFootprint(p, duv_dx, duv_dy), objects_data[rec + 8u], objects_data[rec + 9u], wrap, EWA_OBJECT_RGBA, vec4<f32>(0.0));
}

// The spectral set over the footprint at four wavelengths `nm` (already
// shifted): the sum over texels of weight times alpha times value
// (SpectralTexture::footprint_texels then add_premultiplied), what
// shade_disk emits per unit intensity.
fn ewa_disk_set4(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>, nm: vec4<f32>) -> vec4<f32> {
    var f: vec4<f32>;
    for (var q = 0u; q < 4u; q++) {
        if P.disk_set_len == 1u {
            f[q] = select(-1.0, 0.0, nm[q] == P.disk_nm0);
        } else {
            f[q] = set_index(nm[q]);
        }
    }
    return ewa_filter(EwaFootprint(uv, duv_dx, duv_dy), P.disk_width, P.disk_height, false, EWA_SET4, f);
}

// Texture::sample_sky_footprint: the panorama over the footprint on the
// sky of unit direction `dir` with derivatives `ddir_dx`, `ddir_dy` per
// pixel step: premultiplied linear RGBA, before the sky's intensity.
fn ewa_sky(dir: vec3<f32>, ddir_dx: vec3<f32>, ddir_dy: vec3<f32>) -> vec4<f32> {
    return ewa_filter(ewa_equirect(dir, ddir_dx, ddir_dy), P.sky_width, P.sky_height, true, EWA_SKY_RGBA, vec4<f32>(0.0));
}

// StarMap::sample_footprint: the star grid (when the map has one; the
// temperature the luminance-weighted mean) and the Milky Way grid over
// the footprint on the sky of `dir`.
fn ewa_stars(dir: vec3<f32>, ddir_dx: vec3<f32>, ddir_dy: vec3<f32>) -> StarLight {
    let fp = ewa_equirect(dir, ddir_dx, ddir_dy);
    // The star grid (g = 0), then the Milky Way's.
    var got = array<vec4<f32>, 2>(vec4<f32>(0.0), vec4<f32>(0.0));
    for (var g = 0u; g < 2u; g++) {
        let stars = g == 0u;
        if select(P.sky_milky_way, P.ewa_star_grid, stars) == 0u {
            continue;
        }
        let size = select(vec2<u32>(P.milky_way_width, P.milky_way_height), vec2<u32>(P.sky_width, P.sky_height), stars);
        got[g] = ewa_filter(fp, size.x, size.y, true, select(EWA_MILKY_WAY, EWA_STARS, stars), vec4<f32>(0.0));
    }
    let l = got[0].x;
    return StarLight(l, select(0.0, got[0].y / l, l > 0.0), got[1].x);
}
