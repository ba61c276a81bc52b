// Point stars over a sample's footprint (FOOTPRINT, a star catalogue sky
// with filter = "footprint"): the f32 twin of sky::point_stars and what it
// reads of src/stars/ (cube.rs: face coordinates and Morton cells;
// index.rs: for_each_in; density.rs: smooth_density, most_stars,
// SumRule; field.rs: StarField::footprint; light.rs: the two
// blackbodies). The catalogue is StarField::gpu_words in `sky_data` from
// word P.stars_at (layout in src/stars/mod.rs); each tier's densest cell
// per level (StarIndex::densest) is in `tables` from P.stars_densest,
// STARS_LEVELS a tier. The constants STARS_* before this file come from
// the host (src/gpu/stars.rs).
//
// What f32 changes: the cap's box of cells is found for a radius
// STARS_BOX_MARGIN wider (the CPU's 1e-9 is below f32's rounding of the
// face coordinates), so no star within the cap is missed; the stars
// themselves are tested exactly as on the CPU (squared chord).

// The light of the tiers summed (LightSum): per part (cool, hot) the flux
// and the flux over kelvin.
struct StarSum {
    flux: vec2<f32>,
    per_kelvin: vec2<f32>,
    stars: f32,
}

fn sw(i: u32) -> u32 {
    return sky_data[P.stars_at + i];
}

fn sf(i: u32) -> f32 {
    return bitcast<f32>(sky_data[P.stars_at + i]);
}

// A tier's block: where it starts (words from P.stars_at) and its header.
struct StarTier {
    at: u32,
    level: u32,
    stars: u32,
    offsets: u32,
    sums: u32,
    inv: u32,
}

fn star_tier(t: u32) -> StarTier {
    let at = sw(2u + t);
    return StarTier(at, sw(at + 1u), at + sw(at + 3u), at + sw(at + 4u), at + sw(at + 5u), at + sw(at + 6u));
}

// ---- cube.rs ----------------------------------------------------------------

// A direction's (u, v, a) components in face f's frame.
fn cube_components(p: vec3<f32>, f: u32) -> vec3<f32> {
    let a = f / 2u;
    var q = p;
    if a == 1u {
        q = p.yzx;
    } else if a == 2u {
        q = p.zxy;
    }
    // q = (p[a], p[a + 1], p[a + 2]).
    return vec3<f32>(q.y, q.z, select(q.x, -q.x, (f & 1u) == 1u));
}

// face_coords: (face, x, y) with x, y in [-1, 1].
fn cube_face_coords(p: vec3<f32>) -> vec3<f32> {
    let m = abs(p);
    var a = 2u;
    if m.x >= m.y && m.x >= m.z {
        a = 0u;
    } else if m.y >= m.z {
        a = 1u;
    }
    var axis = p.z;
    if a == 0u {
        axis = p.x;
    } else if a == 1u {
        axis = p.y;
    }
    let f = 2u * a + select(0u, 1u, axis < 0.0);
    let c = cube_components(p, f);
    return vec3<f32>(f32(f), ewa_atan2(c.x, c.z) / (0.25 * PI), ewa_atan2(c.y, c.z) / (0.25 * PI));
}

// face_dir: the unit direction at face coordinates (x, y) of face f.
fn cube_face_dir(f: u32, x: f32, y: f32) -> vec3<f32> {
    // (p[a], p[a + 1], p[a + 2]), rotated back into place.
    let q = vec3<f32>(select(1.0, -1.0, (f & 1u) == 1u), tan(x * 0.25 * PI), tan(y * 0.25 * PI));
    let a = f / 2u;
    var p = q;
    if a == 1u {
        p = q.zxy;
    } else if a == 2u {
        p = q.yzx;
    }
    return normalize(p);
}

fn cube_cell_of(x: f32, n: u32) -> u32 {
    return min(u32(max(floor((x + 1.0) * 0.5 * f32(n)), 0.0)), n - 1u);
}

fn cube_spread(v_in: u32) -> u32 {
    var v = v_in & 0xffffu;
    v = (v | (v << 8u)) & 0x00ff00ffu;
    v = (v | (v << 4u)) & 0x0f0f0f0fu;
    v = (v | (v << 2u)) & 0x33333333u;
    return (v | (v << 1u)) & 0x55555555u;
}

fn cube_morton(i: u32, j: u32) -> u32 {
    return cube_spread(i) | (cube_spread(j) << 1u);
}

// coordinate_range: the range (x0, x1) of one face coordinate a cap
// reaches, z 1 where it reaches the face at all.
fn cube_range(cu: f32, ca: f32, sin_r: f32) -> vec3<f32> {
    let rho = length(vec2<f32>(cu, ca));
    if rho <= sin_r {
        return vec3<f32>(-1.0, 1.0, 1.0);
    }
    let mid = ewa_atan2(cu, ca);
    let half = asin(min(sin_r / rho, 1.0));
    let lo = mid - half;
    let hi = mid + half;
    if hi >= -0.25 * PI && lo <= 0.25 * PI {
        return vec3<f32>(max(lo / (0.25 * PI), -1.0), min(hi / (0.25 * PI), 1.0), 1.0);
    }
    return vec3<f32>(0.0);
}

// CapFaces::new for face f: the box (x0, x1, y0, y1) of face coordinates
// holding every point of the cap of radius r around unit c on the face;
// x0 > x1 where the cap misses it.
fn cube_cap_face(c: vec3<f32>, r: f32, f: u32) -> vec4<f32> {
    let miss = vec4<f32>(1.0, -1.0, 1.0, -1.0);
    // Every point of a face is within acos(1/sqrt 3) of its axis.
    let corner = 0.9553166181245093;
    var near = -1.0;
    if r + corner < PI {
        near = cos(r + corner) - STARS_BOX_MARGIN;
    }
    let k = cube_components(c, f);
    if k.z < near {
        return miss;
    }
    if r >= 0.5 * PI {
        return vec4<f32>(-1.0, 1.0, -1.0, 1.0);
    }
    let sin_r = sin(r);
    let x = cube_range(k.x, k.z, sin_r);
    let y = cube_range(k.y, k.z, sin_r);
    if x.z == 0.0 || y.z == 0.0 {
        return miss;
    }
    return vec4<f32>(x.xy, y.xy);
}

// ---- index.rs: the stars within a cap ----------------------------------------

// index::chord2: the squared chord of an angle.
fn star_chord2(r: f32) -> f32 {
    let h = sin(0.5 * clamp(r, 0.0, PI));
    return 4.0 * h * h;
}

// density::cap_solid_angle.
fn star_cap_sr(r: f32) -> f32 {
    let h = sin(0.5 * clamp(r, 0.0, PI));
    return 4.0 * PI * h * h;
}

// The first star of cell `id` of `level` in tier `t` (offsets[id << 2(L - l)]).
fn star_run_start(t: StarTier, level: u32, id: u32) -> u32 {
    return sw(t.offsets + (id << (2u * (t.level - level))));
}

// StarIndex::for_each_in: every star of tier `t` within angle `radius` of
// unit `c`, each once, through star_visit with `weight`.
fn star_tier_visit(t: StarTier, c: vec3<f32>, radius: f32, weight: f32, v: StarView) {
    let c2 = star_chord2(radius);
    let n = 1u << t.level;
    for (var f = 0u; f < 6u; f++) {
        let b = cube_cap_face(c, radius + STARS_BOX_MARGIN, f);
        if b.x > b.y {
            continue;
        }
        var level = t.level;
        var i0 = cube_cell_of(b.x, n);
        var i1 = cube_cell_of(b.y, n);
        var j0 = cube_cell_of(b.z, n);
        var j1 = cube_cell_of(b.w, n);
        // index::coarsened: a big box is walked at a coarser level.
        while level > 0u && (i1 - i0 + 1u) * (j1 - j0 + 1u) > STARS_MAX_BOX_CELLS {
            i0 = i0 >> 1u;
            i1 = i1 >> 1u;
            j0 = j0 >> 1u;
            j1 = j1 >> 1u;
            level -= 1u;
        }
        for (var j = j0; j <= j1; j++) {
            for (var i = i0; i <= i1; i++) {
                let id = (f << (2u * level)) | cube_morton(i, j);
                let a = star_run_start(t, level, id);
                let e = star_run_start(t, level, id + 1u);
                for (var k = a; k < e; k++) {
                    let w = t.at + 8u + 5u * k;
                    // PointStar::direction: renormalised.
                    let s = normalize(vec3<f32>(sf(w), sf(w + 1u), sf(w + 2u)));
                    let d = s - c;
                    if dot(d, d) <= c2 {
                        star_visit(v, s, sf(w + 3u), sf(w + 4u), weight);
                    }
                }
            }
        }
    }
}

// ---- density.rs: the summed levels ----------------------------------------------

// StarIndex::density_level.
fn star_density_level(t: StarTier, radius: f32) -> f32 {
    let l = log2(0.5 * PI / (STARS_CELL_PER_RADIUS * radius));
    // NaN by its bits (compilers may fold l != l away).
    if (bitcast<u32>(l) & 0x7fffffffu) > 0x7f800000u {
        return f32(t.level);
    }
    return clamp(l, f32(min(t.level, 1u)), f32(t.level));
}

// StarIndex::add_cell: `weight` times cell (face, i, j) of `level`.
fn star_add_cell(t: StarTier, level: u32, face: u32, i: u32, j: u32, weight: f32, sum: ptr<function, StarSum>) {
    let m = cube_morton(i, j);
    let id = (face << (2u * level)) | m;
    // face_level_base(level) + id % 4^level.
    let inv = sf(t.inv + ((1u << (2u * level)) - 1u) / 3u + m);
    let w = weight * inv;
    // level_base(level) = 2 (4^level - 1).
    let at = t.sums + 4u * (2u * ((1u << (2u * level)) - 1u) + id);
    let flux = vec2<f32>(sf(at), sf(at + 1u));
    let kelvin = vec2<f32>(sf(at + 2u), sf(at + 3u));
    let lit = flux > vec2<f32>(0.0);
    let fw = select(vec2<f32>(0.0), w * flux, lit);
    (*sum).flux += fw;
    (*sum).per_kelvin += select(vec2<f32>(0.0), fw / kelvin, lit);
    let count = star_run_start(t, level, id + 1u) - star_run_start(t, level, id);
    (*sum).stars += w * f32(count);
}

// StarIndex::bilinear: `weight` times the bilinear densities of `level`
// at unit c.
fn star_bilinear_level(t: StarTier, c: vec3<f32>, level: u32, weight: f32, sum: ptr<function, StarSum>) {
    let n = 1u << level;
    let fc = cube_face_coords(c);
    let f = u32(fc.x);
    if level == 0u {
        star_add_cell(t, level, f, 0u, 0u, weight, sum);
        return;
    }
    let sx = (fc.y + 1.0) * 0.5 * f32(n) - 0.5;
    let sy = (fc.z + 1.0) * 0.5 * f32(n) - 0.5;
    let fx = floor(sx);
    let fy = floor(sy);
    let tx = sx - fx;
    let ty = sy - fy;
    let h = 2.0 / f32(n);
    for (var q = 0u; q < 4u; q++) {
        let di = q & 1u;
        let dj = q >> 1u;
        let w = select(1.0 - tx, tx, di == 1u) * select(1.0 - ty, ty, dj == 1u);
        if w <= 0.0 {
            continue;
        }
        let i = i32(fx) + i32(di);
        let j = i32(fy) + i32(dj);
        if i >= 0 && j >= 0 && i < i32(n) && j < i32(n) {
            star_add_cell(t, level, f, u32(i), u32(j), weight * w, sum);
        } else {
            // Past the face's edge: the cell the tap's centre falls in on
            // the neighbouring face.
            let d = cube_face_dir(f, (f32(i) + 0.5) * h - 1.0, (f32(j) + 0.5) * h - 1.0);
            let g = cube_face_coords(d);
            star_add_cell(t, level, u32(g.x), cube_cell_of(g.y, n), cube_cell_of(g.z, n), weight * w, sum);
        }
    }
}

// StarIndex::smooth_density: flux and stars per steradian, as sums.
fn star_smooth(t: StarTier, c: vec3<f32>, radius: f32) -> StarSum {
    var sum = StarSum(vec2<f32>(0.0), vec2<f32>(0.0), 0.0);
    let lf = star_density_level(t, radius);
    let l0 = u32(floor(lf));
    let tt = lf - f32(l0);
    star_bilinear_level(t, c, l0, 1.0 - tt, &sum);
    if tt > 0.0 {
        star_bilinear_level(t, c, l0 + 1u, tt, &sum);
    }
    return sum;
}

// StarIndex::most_stars: an upper bound of the stars any cap of `radius`
// holds by the smooth estimate, from each level's densest cell.
fn star_most(ti: u32, t: StarTier, radius: f32) -> f32 {
    let lf = star_density_level(t, radius);
    let l0 = u32(floor(lf));
    let l1 = min(l0 + 1u, t.level);
    let at = P.stars_densest + ti * STARS_LEVELS;
    return max(tables[at + l0], tables[at + l1]) * star_cap_sr(radius);
}

// ---- sky::point_stars ------------------------------------------------------------

// What a star's image is placed with: the footprint's sky direction and
// its derivatives, the least-squares solve's terms, the sample's offset
// from its pixel's centre, and the pixel's sky solid angle.
struct StarView {
    d: vec3<f32>,
    dx: vec3<f32>,
    dy: vec3<f32>,
    abc: vec3<f32>,
    det: f32,
    offset: vec2<f32>,
    sr: f32,
    g: f32,
    k: f32,
}

// Light of a blackbody at `kelvin` of radiance `l` (before the sky's
// intensity): into `point_rgb` (RGB renders) or the sample's spectrum.
var<private> point_rgb: vec3<f32>;

fn star_emit(v: StarView, kelvin: f32, l: f32) {
    if SPECTRAL {
        planck_add(kelvin, v.g, v.k * l);
    } else {
        point_rgb += blackbody_rgb(kelvin) * l;
    }
}

// The image-plane offset (pixels) of a tangent-plane offset at d.
fn star_solve(v: StarView, off: vec3<f32>) -> vec2<f32> {
    let p = dot(v.dx, off);
    let q = dot(v.dy, off);
    return vec2<f32>(v.abc.z * p - v.abc.y * q, v.abc.x * q - v.abc.y * p) / v.det;
}

// One star (unit direction s, flux, kelvin) through the tent filter, its
// image placed by the footprint's linear map and one Newton step through
// the lens (fp_ends).
fn star_visit(v: StarView, s: vec3<f32>, flux: f32, kelvin: f32, weight: f32) {
    let along = dot(s, v.d);
    if along <= 0.0 {
        return;
    }
    var e = star_solve(v, s / along - v.d);
    let o = v.offset + e;
    if max(abs(o.x), abs(o.y)) < 1.0 + STARS_REFINE_MARGIN {
        let l = fp_ends(stars_px.x + e.x, stars_px.y + e.y);
        if l.ok && l.escaped {
            let sd = dot(s, l.dir);
            if sd > 0.0 {
                e += star_solve(v, s / sd - l.dir);
            }
        }
    }
    let t = v.offset + e;
    let tent = max(1.0 - abs(t.x), 0.0) * max(1.0 - abs(t.y), 0.0);
    if tent > 0.0 {
        star_emit(v, kelvin, STARS_MAG0 * flux * weight * tent / v.sr);
    }
}

// sky::point_stars for the sample's footprint (fp; its sky part known):
// RGB renders get the light back (before the sky's intensity), spectral
// ones add it (times k and the intensity, with frequency ratio g).
fn point_stars(g: f32, k: f32) -> vec3<f32> {
    point_rgb = vec3<f32>(0.0);
    let d = fp.sky;
    let dx = fp.sky_dx;
    let dy = fp.sky_dy;
    let sr = abs(dot(cross(dx, dy), d));
    if !(sr > 0.0) || !finite(sr) {
        return point_rgb;
    }
    let abc = vec3<f32>(dot(dx, dx), dot(dx, dy), dot(dy, dy));
    let offset = stars_px - floor(stars_px) - vec2<f32>(0.5);
    let v = StarView(d, dx, dy, abc, abc.x * abc.z - abc.y * abc.y, offset, sr, g, k * P.sky_intensity);
    // The Newton steps' rays set the camera's per-ray state: kept for the
    // rest of the sample.
    let keep_b = exact_b;
    let keep_l = exact_l;
    let keep_local = cam_local;
    let keep_ln_d = cam_ln_d;
    let keep_t = start_t;
    // The tent reaches one pixel from the centre, the sample is within
    // half a pixel of it.
    let reach = 1.5 * (length(dx) + length(dy));
    let c = normalize(d);
    var sum = StarSum(vec2<f32>(0.0), vec2<f32>(0.0), 0.0);
    let tiers = sw(1u);
    for (var ti = 0u; ti < tiers; ti++) {
        let t = star_tier(ti);
        // StarField::footprint: resolved for certain, without a lookup.
        if star_most(ti, t, reach) <= P.stars_max {
            star_tier_visit(t, c, reach, 1.0, v);
            continue;
        }
        let sm = star_smooth(t, c, reach);
        let n = sm.stars * star_cap_sr(reach);
        // SumRule::summed_share.
        var w = 1.0;
        if P.stars_max > 0.0 {
            w = clamp((n - P.stars_max) / P.stars_max, 0.0, 1.0);
        }
        if w < 1.0 {
            star_tier_visit(t, c, reach, 1.0 - w, v);
        }
        if w > 0.0 {
            sum.flux += w * sm.flux;
            sum.per_kelvin += w * sm.per_kelvin;
        }
    }
    exact_b = keep_b;
    exact_l = keep_l;
    cam_local = keep_local;
    cam_ln_d = keep_ln_d;
    start_t = keep_t;
    // The summed tiers' light per steradian, as two blackbodies.
    for (var q = 0u; q < 2u; q++) {
        if sum.flux[q] > 0.0 {
            star_emit(v, sum.flux[q] / sum.per_kelvin[q], STARS_MAG0 * sum.flux[q]);
        }
    }
    return point_rgb;
}

// Whether the sample draws point stars: the sky has them and the sample's
// footprint reaches the sky (else, as on the CPU, the map alone).
fn point_stars_on() -> bool {
    return FOOTPRINT && P.stars_at != NONE && fp.ok && fp.sky_ok;
}
