// Footprints at object hits (OBJECT_FOOTPRINT): twin of
// src/cpu/footprint/objects.rs. Where a sample's ray meets an object
// whose texture is read over footprints, four neighbouring rays OBJ_STEP
// pixels away are traced as the sample's ray is (ray_start and advance,
// the same nearest_object) to their first object hit, each moved onto its
// step's curve; the derivatives of (u, v) per pixel are their differences
// (a sphere's u the short way across its seam). A neighbour counts only on
// the same object, on the same smooth piece of it (a mesh's same triangle
// or one sharing a vertex), after as many crossings of the plane z = 0;
// else the other side's one-sided difference is taken, else the hit has
// no footprint and its texture is read at the point. After a mirror there
// is none. The footprint is found lazily, at the hit: the neighbours'
// traces overwrite the camera's per-ray state, which is restored after.

// Neighbour step (pixels): a power of two, so that px +- OBJ_STEP is exact.
// f32 rounds a hit to about 1e-7 of its distance from the hole, which a
// difference divides by the step's size there (the error grows as 1/step),
// and a lensed footprint changes over the step (as step^2, one-sided at a
// limb as step): against the CPU's f64 footprints (src/gpu/objfoot_tests.rs)
// steps of 1/256, 1/128, 1/64, 1/32 and 1/16 px were off by at worst 7.8e-3,
// 2.6e-3, 1.3e-2, 1.0e-1 and 2.5e-1 on a lensed sphere and 5.8e-3, 2.1e-3,
// 1.1e-3, 7.0e-4 and 2.4e-4 on a flat rectangle (seed: 1.5e-2 to 8.1e-4).
// 1/128 px, next to the CPU's 1/100, holds every case within 1e-2.
const OBJ_STEP: f32 = 0.0078125;
// The largest u extent of a sphere's footprint (half a turn each way).
const OBJ_MAX_U_EXTENT: f32 = 0.5;

// Whether the way from z0 to z1 crosses z = 0 (Segment::crossing_z0's
// test).
fn z_crosses(z0: f32, z1: f32) -> bool {
    return !(z0 == 0.0 || ((z0 > 0.0) == (z1 > 0.0) && z1 != 0.0));
}

// footprint::plane_crossings: the crossings of z = 0 up to fraction s of
// `seg` (1: the whole step), and since `last_z`, where the last visited
// step ended: without a disk a step that crosses the plane far from any
// object needs no visit, so a change of side between visits counts one.
fn objfp_crossings(seg: Seg, s: f32, last_z: f32) -> u32 {
    var n = select(0u, 1u, z_crosses(last_z, seg.x0.z));
    if z_crosses(seg.x0.z, seg.x1.z) && (s >= 1.0 || seg_crossing_z0(seg) <= s) {
        n += 1u;
    }
    return n;
}

// footprint::on_curve: a hit on a curved step's chord moved onto the curve
// by chords a fifth as long each time about it; where one misses (at the
// surface's edge) the last hit stands.
fn objfp_on_curve(i: u32, seg: Seg, hit: ObjHit) -> ObjHit {
    if !seg.curved {
        return hit;
    }
    var best = hit;
    var s = hit.s;
    var half = 0.25;
    for (var k = 0u; k < 6u; k++) {
        let a = max(s - half, 0.0);
        let b = min(s + half, 1.0);
        let h = object_hit(i, seg_point(seg, a), seg_point(seg, b), 1e-6);
        if !h.ok {
            break;
        }
        s = a + (b - a) * h.s;
        best = h;
        best.s = s;
        half *= 0.2;
    }
    return best;
}

// A ray's first object hit on its step's chord, that step, and the
// crossings of the plane before it; ok is false where it meets none.
struct ObjNeighbour {
    ok: bool,
    obj: u32,
    plane: u32,
    hit: ObjHit,
    seg: Seg,
}

// Scene::object_hit: the camera ray through image point (px, py) traced
// as trace_sample traces a sample's (the far camera's start included), the
// geodesic alone, to its first object. Sets the camera's per-ray state
// (set_exact_ray, camera_direction): object_footprint restores it.
fn objfp_trace(px: f32, py: f32) -> ObjNeighbour {
    var out: ObjNeighbour;
    out.ok = false;
    out.plane = 0u;
    set_exact_ray(image_point(px, py));
    let camera = P.cam_pos.xyz;
    var origin = camera;
    var dir = camera_direction(px, py);
    if P.model == MODEL_GR && !TRAVEL && exact_b >= 0.0 {
        let start = exact_start(length(camera));
        if start.ok {
            origin = start.x;
            dir = start.v;
            if KERR {
                start_t = ks_backward_t(2.0 * origin, dir);
            }
        }
    }
    var ray = ray_start(origin, dir);
    var last_z = camera.z;
    loop {
        if advance(&ray) != EV_VISIT {
            break;
        }
        let seg = ray.seg;
        let near = nearest_object(seg.x0, seg.x1);
        out.plane += objfp_crossings(seg, select(1.0, near.hit.s, near.obj != NONE), last_z);
        last_z = seg.x1.z;
        if near.obj != NONE {
            out.ok = true;
            out.obj = near.obj;
            out.hit = near.hit;
            out.seg = seg;
            break;
        }
    }
    return out;
}

// Shape::continuous: a sphere's and a rectangle's hits always; a mesh's on
// the same triangle or two sharing a vertex.
fn objfp_continuous(i: u32, a: u32, b: u32) -> bool {
    let rec = i * OBJECT_WORDS;
    if od(rec) != 2u || a == b {
        return true;
    }
    let ta = od(rec + 14u) + 3u * a;
    let tb = od(rec + 14u) + 3u * b;
    for (var k = 0u; k < 3u; k++) {
        let v = od(ta + k);
        if v == od(tb) || v == od(tb + 1u) || v == od(tb + 2u) {
            return true;
        }
    }
    return false;
}

// a - b in uv, a sphere's u the short way across its seam (wrap_du).
fn objfp_diff(sphere: bool, a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    var d = a - b;
    if sphere {
        d.x -= floor(d.x + 0.5);
    }
    return d;
}

// One axis's derivative from the neighbours after (a) and before (b):
// central where both are alike, else one-sided from `here`; z = 0 where
// neither is.
fn objfp_axis(sphere: bool, a: vec3<f32>, b: vec3<f32>, here: vec2<f32>) -> vec3<f32> {
    let h = OBJ_STEP;
    if a.z > 0.0 && b.z > 0.0 {
        return vec3<f32>(objfp_diff(sphere, a.xy, b.xy) / (2.0 * h), 1.0);
    }
    if a.z > 0.0 {
        return vec3<f32>(objfp_diff(sphere, a.xy, here) / h, 1.0);
    }
    if b.z > 0.0 {
        return vec3<f32>(objfp_diff(sphere, here, b.xy) / h, 1.0);
    }
    return vec3<f32>(0.0);
}

// Scene::object_footprint of the sample's hit `hit` on object i on the
// chord of `seg`: sets obj_fp. The neighbours' traces set the camera's
// per-ray state, which the sample's own shading still reads (its shifts):
// it is put back.
fn object_footprint(i: u32, seg: Seg, hit: ObjHit) {
    let b = exact_b;
    let l = exact_l;
    let ln_d = cam_ln_d;
    let local = cam_local;
    let t = start_t;
    // The sample itself, then its neighbours right, left, down and up,
    // each hit moved onto its curve: one call site each, so that the
    // compiler inlines the trace and the chords once (on llvmpipe four
    // sites took four times as long to compile).
    var n: array<vec3<f32>, 4>;
    var here = hit;
    for (var k = 0u; k < 5u; k++) {
        var nb = ObjNeighbour(true, i, obj_plane, hit, seg);
        if k > 0u {
            let s = select(-OBJ_STEP, OBJ_STEP, (k & 1u) == 1u);
            let d = select(vec2<f32>(0.0, s), vec2<f32>(s, 0.0), k < 3u);
            nb = objfp_trace(obj_at.x + d.x, obj_at.y + d.y);
        }
        var uv = vec3<f32>(0.0);
        if nb.ok && nb.obj == i && nb.plane == obj_plane {
            let h = objfp_on_curve(i, nb.seg, nb.hit);
            if k == 0u {
                here = h;
            } else if objfp_continuous(i, here.part, h.part) {
                uv = vec3<f32>(h.uv, 1.0);
            }
        }
        if k > 0u {
            n[k - 1u] = uv;
        }
    }
    exact_b = b;
    exact_l = l;
    cam_ln_d = ln_d;
    cam_local = local;
    start_t = t;
    let sphere = od(i * OBJECT_WORDS) == 0u;
    let dx = objfp_axis(sphere, n[0], n[1], here.uv);
    let dy = objfp_axis(sphere, n[2], n[3], here.uv);
    obj_fp.ok = dx.z > 0.0 && dy.z > 0.0;
    obj_fp.dx = dx.xy;
    obj_fp.dy = dy.xy;
    let extent = length(vec2<f32>(dx.x, dy.x));
    if sphere && extent > OBJ_MAX_U_EXTENT {
        obj_fp.dx.x *= OBJ_MAX_U_EXTENT / extent;
        obj_fp.dy.x *= OBJ_MAX_U_EXTENT / extent;
    }
}
