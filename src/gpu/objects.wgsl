// Objects, their surfaces and the lights on them, and the gas (volumetric
// disk and clouds): the WGSL twin of src/shapes/, src/objects.rs and
// src/volume.rs. Records live in `objects_data` (layout in src/gpu/pack.rs;
// words 7 to 11 the texture: where its texels start, width, height,
// format, filter code; word 28 where its mip levels start, NONE unless it
// is read over footprints).


fn od(i: u32) -> u32 {
    return objects_data[i];
}

fn odf(i: u32) -> f32 {
    return bitcast<f32>(objects_data[i]);
}

fn od3(i: u32) -> vec3<f32> {
    return vec3<f32>(odf(i), odf(i + 1u), odf(i + 2u));
}

struct ObjHit {
    ok: bool,
    s: f32,
    point: vec3<f32>,
    normal: vec3<f32>,
    uv: vec2<f32>,
    // Hit::part: a mesh's triangle, else 0.
    part: u32,
}

fn no_hit() -> ObjHit {
    return ObjHit(false, 2.0, vec3<f32>(0.0), vec3<f32>(0.0), vec2<f32>(0.0), 0u);
}

// shapes::Sphere::intersect, with hits beyond `s_min` of the chord.
fn sphere_hit(rec: u32, a: vec3<f32>, b: vec3<f32>, s_min: f32) -> ObjHit {
    let center = od3(rec + 12u);
    let radius = odf(rec + 15u);
    let d = b - a;
    let m = a - center;
    let qa = dot(d, d);
    let qb = dot(m, d);
    let qc = dot(m, m) - radius * radius;
    let disc = qb * qb - qa * qc;
    if qa == 0.0 || disc < 0.0 {
        return no_hit();
    }
    let root = sqrt(disc);
    let q = -(qb + select(-root, root, qb >= 0.0));
    let x = q / qa;
    var y = 3.4e38;
    if q != 0.0 {
        y = qc / q;
    }
    let t0 = min(x, y);
    let t1 = max(x, y);
    var s: f32;
    if t0 > s_min && t0 <= 1.0 {
        s = t0;
    } else if t1 > s_min && t1 <= 1.0 {
        s = t1;
    } else {
        return no_hit();
    }
    let point = a + d * s;
    let normal = (point - center) / radius;
    let pole = od3(rec + 16u);
    let meridian = od3(rec + 20u);
    let east = cross(pole, meridian);
    let u = rem_euclid(atan2(dot(normal, east), dot(normal, meridian)), TAU) / TAU;
    let v = acos(clamp(dot(normal, pole), -1.0, 1.0)) / PI;
    return ObjHit(true, s, point, normal, vec2<f32>(u, v), 0u);
}

// shapes::Rectangle::intersect
fn rectangle_hit(rec: u32, a: vec3<f32>, b: vec3<f32>, s_min: f32) -> ObjHit {
    let center = od3(rec + 12u);
    let normal = od3(rec + 16u);
    let da = dot(a - center, normal);
    let db = dot(b - center, normal);
    if da == db || ((da > 0.0) == (db > 0.0) && db != 0.0) {
        return no_hit();
    }
    let s = da / (da - db);
    if !(s > s_min && s <= 1.0) {
        return no_hit();
    }
    let point = a + (b - a) * s;
    let u_axis = od3(rec + 20u);
    let v_axis = cross(normal, u_axis);
    let r = point - center;
    let x = dot(r, u_axis);
    let y = dot(r, v_axis);
    let h0 = odf(rec + 19u);
    let h1 = odf(rec + 23u);
    if abs(x) > h0 || abs(y) > h1 {
        return no_hit();
    }
    return ObjHit(true, s, point, normal, vec2<f32>(0.5 + 0.5 * x / h0, 0.5 - 0.5 * y / h1), 0u);
}

fn mesh_vertex(rec: u32, i: u32) -> vec3<f32> {
    return od3(od(rec + 15u) + 3u * i);
}

// Moeller-Trumbore on triangle t: (t, u, v), t < 0 for none.
fn triangle_hit(rec: u32, t: u32, a: vec3<f32>, d: vec3<f32>, t_max: f32, s_min: f32) -> vec3<f32> {
    let tri = od(rec + 14u) + 3u * t;
    let p0 = mesh_vertex(rec, od(tri));
    let p1 = mesh_vertex(rec, od(tri + 1u));
    let p2 = mesh_vertex(rec, od(tri + 2u));
    let e1 = p1 - p0;
    let e2 = p2 - p0;
    let pv = cross(d, e2);
    let det = dot(e1, pv);
    if abs(det) < 1e-30 {
        return vec3<f32>(-1.0);
    }
    let inv = 1.0 / det;
    let tv = a - p0;
    let u = dot(tv, pv) * inv;
    if u < 0.0 || u > 1.0 {
        return vec3<f32>(-1.0);
    }
    let qv = cross(tv, e1);
    let v = dot(d, qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return vec3<f32>(-1.0);
    }
    let tt = dot(e2, qv) * inv;
    if tt > s_min && tt <= t_max {
        return vec3<f32>(tt, u, v);
    }
    return vec3<f32>(-1.0);
}

// shapes::bvh::Aabb::hit: entry parameter, or -1.
fn box_hit(node: u32, a: vec3<f32>, inv: vec3<f32>, t_max: f32) -> f32 {
    let t0 = (od3(node) - a) * inv;
    let t1 = (od3(node + 4u) - a) * inv;
    let lo = min(t0, t1);
    let hi = max(t0, t1);
    let near = max(max(max(lo.x, lo.y), lo.z), 0.0);
    let far = min(min(min(hi.x, hi.y), hi.z), t_max);
    return select(-1.0, near, near <= far);
}

// shapes::Mesh::intersect: the nearest triangle through the BVH.
fn mesh_hit(rec: u32, a: vec3<f32>, b: vec3<f32>, s_min: f32) -> ObjHit {
    let d = b - a;
    let inv = 1.0 / d;
    let nodes = od(rec + 12u);
    let order = od(rec + 13u);
    var t_max = 1.0;
    var best = NONE;
    var stack: array<u32, 64>;
    stack[0] = 0u;
    var top = 1u;
    while top > 0u {
        top -= 1u;
        let idx = stack[top];
        let node = nodes + 8u * idx;
        if box_hit(node, a, inv, t_max) < 0.0 {
            continue;
        }
        let count = od(node + 7u);
        let start = od(node + 3u);
        if count > 0u {
            for (var k = 0u; k < count; k++) {
                let t = od(order + start + k);
                let h = triangle_hit(rec, t, a, d, t_max, s_min);
                if h.x >= 0.0 && h.x < t_max {
                    t_max = h.x;
                    best = t;
                }
            }
            continue;
        }
        let first = idx + 1u;
        let second = start;
        let dl = box_hit(nodes + 8u * first, a, inv, t_max);
        let dr = box_hit(nodes + 8u * second, a, inv, t_max);
        // The farther child first, so the nearer is visited first.
        if dl >= 0.0 && dr >= 0.0 {
            if dl <= dr {
                stack[top] = second;
                stack[top + 1u] = first;
            } else {
                stack[top] = first;
                stack[top + 1u] = second;
            }
            top = min(top + 2u, 62u);
        } else if dl >= 0.0 {
            stack[top] = first;
            top += 1u;
        } else if dr >= 0.0 {
            stack[top] = second;
            top += 1u;
        }
    }
    if best == NONE {
        return no_hit();
    }
    let h = triangle_hit(rec, best, a, d, 1.0, s_min);
    let tri = od(rec + 14u) + 3u * best;
    let i0 = od(tri);
    let i1 = od(tri + 1u);
    let i2 = od(tri + 2u);
    let u = h.y;
    let v = h.z;
    let w = 1.0 - u - v;
    var normal = vec3<f32>(0.0);
    let nrm = od(rec + 16u);
    if nrm != NONE {
        let n = od3(nrm + 3u * i0) * w + od3(nrm + 3u * i1) * u + od3(nrm + 3u * i2) * v;
        if dot(n, n) > 0.0 {
            normal = normalize(n);
        }
    }
    if dot(normal, normal) == 0.0 {
        let p0 = mesh_vertex(rec, i0);
        normal = normalize(cross(mesh_vertex(rec, i1) - p0, mesh_vertex(rec, i2) - p0));
    }
    var uv = vec2<f32>(u, v);
    let uvs = od(rec + 17u);
    if uvs != NONE {
        let a0 = vec2<f32>(odf(uvs + 2u * i0), odf(uvs + 2u * i0 + 1u));
        let a1 = vec2<f32>(odf(uvs + 2u * i1), odf(uvs + 2u * i1 + 1u));
        let a2 = vec2<f32>(odf(uvs + 2u * i2), odf(uvs + 2u * i2 + 1u));
        uv = a0 * w + a1 * u + a2 * v;
    }
    return ObjHit(true, h.x, a + d * h.x, normal, uv, best);
}

fn object_hit(i: u32, a: vec3<f32>, b: vec3<f32>, s_min: f32) -> ObjHit {
    let rec = i * OBJECT_WORDS;
    switch od(rec) {
        case 0u: {
            return sphere_hit(rec, a, b, s_min);
        }
        case 1u: {
            return rectangle_hit(rec, a, b, s_min);
        }
        default: {
            return mesh_hit(rec, a, b, s_min);
        }
    }
}

// The nearest object on the chord a -> b outside the horizon (a chord may
// cut into the horizon; the light cannot come back out): its index (NONE
// for none) and hit (Scene::nearest_object).
struct NearObject {
    obj: u32,
    hit: ObjHit,
}

fn nearest_object(a: vec3<f32>, b: vec3<f32>) -> NearObject {
    var near = NearObject(NONE, no_hit());
    for (var i = 0u; OBJECTS && i < P.n_objects; i++) {
        let h = object_hit(i, a, b, 1e-6);
        if h.ok && dot(h.point, h.point) > 1.0 && h.s < near.hit.s {
            near = NearObject(i, h);
        }
    }
    return near;
}

// Whether the chord a -> b comes within radius of a bounding sphere.
fn chord_near(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, radius: f32) -> bool {
    let d = b - a;
    let len2 = dot(d, d);
    var t = 0.0;
    if len2 > 0.0 {
        t = clamp(dot(c - a, d) / len2, 0.0, 1.0);
    }
    let q = a + d * t - c;
    return dot(q, q) <= radius * radius;
}

// Parameter interval of the chord inside |z| <= h (volume::slab), or
// (1, 0) for none.
fn slab(z0: f32, z1: f32, h: f32) -> vec2<f32> {
    if z0 == z1 {
        return select(vec2<f32>(1.0, 0.0), vec2<f32>(0.0, 1.0), abs(z0) <= h);
    }
    let a = (-h - z0) / (z1 - z0);
    let b = (h - z0) / (z1 - z0);
    return vec2<f32>(max(min(a, b), 0.0), min(max(a, b), 1.0));
}

// volume::Cloud::interval: the chord inside a ball, or (1, 0).
fn ball(x0: vec3<f32>, x1: vec3<f32>, center: vec3<f32>, radius: f32) -> vec2<f32> {
    let d = x1 - x0;
    let m = x0 - center;
    let a = dot(d, d);
    let b = dot(m, d);
    let c = dot(m, m) - radius * radius;
    let disc = b * b - a * c;
    if a == 0.0 || disc <= 0.0 {
        return vec2<f32>(1.0, 0.0);
    }
    let r = sqrt(disc);
    return vec2<f32>(max((-b - r) / a, 0.0), min((-b + r) / a, 1.0));
}

// Whether a step from x0 to x1 needs the full visit (a possible disk
// crossing, an object or gas near its chord): the hot loop's only test.
fn needs_visit(x0: vec3<f32>, x1: vec3<f32>) -> bool {
    if MEDIUM || may_cross(x0.z, x1.z) {
        return true;
    }
    if !OBJECTS && !GAS {
        return false;
    }
    for (var i = 0u; OBJECTS && i < P.n_objects; i++) {
        let rec = i * OBJECT_WORDS;
        if chord_near(x0, x1, od3(rec + 24u), odf(rec + 27u)) {
            return true;
        }
    }
    if GAS && P.at_volume != NONE {
        let iv = slab(x0.z, x1.z, odf(P.at_volume + 7u));
        if iv.x < iv.y {
            return true;
        }
    }
    for (var c = 0u; GAS && c < P.n_clouds; c++) {
        let rec = P.at_clouds + c * CLOUD_WORDS;
        if chord_near(x0, x1, od3(rec), odf(rec + 3u)) {
            return true;
        }
    }
    return false;
}

// ---- surfaces and lights --------------------------------------------------------

// objects::Object::color: the colour times the texture, over the
// footprint of the hit being shaded where there is one (OBJECT_FOOTPRINT:
// obj_fp, objfoot.wgsl), else at the point (nearest, or bilinear for the
// other filters, wrapping in u).
fn object_color(rec: u32, uv: vec2<f32>) -> vec3<f32> {
    let color = od3(rec + 4u);
    if od(rec + 7u) == NONE {
        return color;
    }
    if OBJECT_FOOTPRINT && obj_fp.ok {
        return color * ewa_object(rec, uv, obj_fp.dx, obj_fp.dy).xyz;
    }
    return color * tex_sample(TEX_OBJECT, od(rec + 7u), uv.x, uv.y, od(rec + 11u) != 0u, true, od(rec + 8u), od(rec + 9u), od(rec + 10u)).xyz;
}

// objects::shadowed: the hole or any object on the straight half-line.
fn shadowed(p: vec3<f32>, dir: vec3<f32>) -> bool {
    let t = max(-dot(p, dir), 0.0);
    let q = p + dir * t;
    if dot(q, q) < 1.0 {
        return true;
    }
    // Every object lies within limits.outer of the hole.
    let far = p + dir * (2.0 * (P.outer_limit + length(p)) + 1.0);
    for (var i = 0u; i < P.n_objects; i++) {
        if object_hit(i, p, far, 1e-6).ok {
            return true;
        }
    }
    return false;
}

// objects::Lighting::disk_irradiance
fn disk_irradiance(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let l = P.at_lighting;
    let n_suns = od(l);
    let n_glow = od(l + 1u);
    let base = l + 8u + n_suns * SUN_WORDS;
    var e = vec3<f32>(0.0);
    for (var i = 0u; i < n_glow; i++) {
        let g = base + i * GLOW_WORDS;
        let d = od3(g) - p;
        let d2 = dot(d, d);
        let w = d / sqrt(d2);
        let cos_p = dot(n, w);
        if cos_p <= 0.0 {
            continue;
        }
        e += od3(g + 3u) * (cos_p * abs(w.z) / d2);
    }
    return e;
}

// The sun's spectrum at nm (luminance 1), times its intensity.
fn sun_spectrum4(sun: u32, nm: vec4<f32>) -> vec4<f32> {
    let k = odf(sun + 3u);
    if od(sun + 7u) == 0u {
        let t = odf(sun + 8u);
        return k * odf(sun + 9u) * pow(nm, vec4<f32>(-5.0)) / (exp(1.4388e7 / (nm * t)) - 1.0);
    }
    let c = vec4<f32>(odf(sun + 12u), odf(sun + 13u), odf(sun + 14u), odf(sun + 15u));
    return k * uplift_emission4(c, nm);
}

// The lit frame at a hit: (n towards the viewer, v, the point lifted off
// the surface); f32 needs a larger lift than the CPU's 1e-9.
struct Frame {
    n: vec3<f32>,
    v: vec3<f32>,
    p: vec3<f32>,
}

fn lit_frame(h: ObjHit, towards_viewer: vec3<f32>) -> Frame {
    let v = normalize(towards_viewer);
    var n = h.normal;
    if dot(n, v) < 0.0 {
        n = -n;
    }
    let eps = 1e-5 * max(length(h.point), 1.0);
    return Frame(n, v, h.point + n * eps);
}

// objects::shade_rgb
fn object_rgb(i: u32, h: ObjHit, towards_viewer: vec3<f32>) -> vec3<f32> {
    let rec = i * OBJECT_WORDS;
    let albedo = object_color(rec, h.uv);
    if od(rec + 1u) != 2u {
        return albedo;
    }
    let specular = odf(rec + 2u);
    let shininess = odf(rec + 3u);
    let f = lit_frame(h, towards_viewer);
    let l = P.at_lighting;
    var diffuse = od3(l + 4u) + disk_irradiance(f.p, f.n);
    var highlight = vec3<f32>(0.0);
    for (var s = 0u; s < od(l); s++) {
        let sun = l + 8u + s * SUN_WORDS;
        let dir = od3(sun);
        let c = dot(f.n, dir);
        if c <= 0.0 || shadowed(f.p, dir) {
            continue;
        }
        diffuse += od3(sun + 4u) * c;
        if specular > 0.0 {
            let r = f.n * (2.0 * c) - dir;
            highlight += od3(sun + 4u) * pow(max(dot(r, f.v), 0.0), shininess);
        }
    }
    return albedo * diffuse + highlight * specular;
}

// objects::add_spectrum, through the filter.
fn object_spectrum(i: u32, h: ObjHit, towards_viewer: vec3<f32>, g: f32, k0: f32) {
    let rec = i * OBJECT_WORDS;
    let albedo = uplift(object_color(rec, h.uv));
    let k = k0 * radiance_factor(g);
    if od(rec + 1u) != 2u {
        for (var j = 0u; j < N_WL; j += 4u) {
            emit4(j, k * uplift_emission4(albedo, g * nm4(j)));
        }
        return;
    }
    let specular = odf(rec + 2u);
    let shininess = odf(rec + 3u);
    let f = lit_frame(h, towards_viewer);
    let l = P.at_lighting;
    let rest = uplift(od3(l + 4u) + disk_irradiance(f.p, f.n));
    // Up to 8 suns reach a point (a scene's suns beyond that are rare).
    var cos_s: array<f32, 8>;
    var spec_s: array<f32, 8>;
    let n_suns = min(od(l), 8u);
    for (var s = 0u; s < n_suns; s++) {
        let sun = l + 8u + s * SUN_WORDS;
        let dir = od3(sun);
        let c = dot(f.n, dir);
        cos_s[s] = 0.0;
        spec_s[s] = 0.0;
        if c <= 0.0 || shadowed(f.p, dir) {
            continue;
        }
        cos_s[s] = c;
        if specular > 0.0 {
            let r = f.n * (2.0 * c) - dir;
            spec_s[s] = specular * pow(max(dot(r, f.v), 0.0), shininess);
        }
    }
    for (var j = 0u; j < N_WL; j += 4u) {
        let lambda = g * nm4(j);
        let a = uplift_reflectance4(albedo, lambda);
        var e = a * uplift_emission4(rest, lambda);
        for (var s = 0u; s < n_suns; s++) {
            if cos_s[s] > 0.0 {
                let sun = l + 8u + s * SUN_WORDS;
                e += sun_spectrum4(sun, lambda) * (a * cos_s[s] + spec_s[s]);
            }
        }
        emit4(j, k * e);
    }
}

// ---- gas ----------------------------------------------------------------------

// volume::Grid3::sample at `p` of the grid whose record starts at `g`.
fn grid_sample(g: u32, p: vec3<f32>) -> f32 {
    let n = vec3<u32>(od(g), od(g + 1u), od(g + 2u));
    let f = (p - od3(g + 3u)) / od3(g + 6u);
    if f.x < 0.0 || f.y < 0.0 || f.z < 0.0 {
        return 0.0;
    }
    let i = u32(f.x);
    let j = u32(f.y);
    let k = u32(f.z);
    if i + 1u >= n.x || j + 1u >= n.y || k + 1u >= n.z {
        return 0.0;
    }
    let t = f - vec3<f32>(f32(i), f32(j), f32(k));
    let data = od(g + 9u);
    let row = n.x;
    let plane = n.x * n.y;
    let at0 = data + k * plane + j * row + i;
    let x00 = mix(odf(at0), odf(at0 + 1u), t.x);
    let x10 = mix(odf(at0 + row), odf(at0 + row + 1u), t.x);
    let x01 = mix(odf(at0 + plane), odf(at0 + plane + 1u), t.x);
    let x11 = mix(odf(at0 + plane + row), odf(at0 + plane + row + 1u), t.x);
    return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

// The volume's radial source: (kelvin, luminance relative to the peak's).
fn volume_source(r: f32) -> vec2<f32> {
    let v = P.at_volume;
    let rows = od(v + 8u);
    let inner = odf(v);
    let outer = odf(v + 1u);
    let f = clamp((r - inner) / (outer - inner) * f32(rows - 1u), 0.0, f32(rows - 1u));
    let at = od(v + 9u) + 2u * u32(floor(f + 0.5));
    return vec2<f32>(odf(at), odf(at + 1u));
}

// The volume's blackbody colour table (RGB renders).
fn volume_rgb(kelvin: f32) -> vec3<f32> {
    let v = P.at_volume;
    let n = f32(od(v + 12u));
    let f = clamp((kelvin - odf(v + 10u)) / odf(v + 11u), 0.0, n - 1.0);
    let i = min(floor(f), n - 2.0);
    let at = od(v + 13u) + 3u * u32(i);
    return mix(od3(at), od3(at + 3u), f - i);
}
