// What the tracer reads of footprints in every variant: the sample's
// footprint (footprint.wgsl fills it), its image point (for stars.wgsl),
// the state of footprints at object hits (objfoot.wgsl) and the cheap
// lookups the probes make. The heavy parts are included only in the
// variants that use them (src/gpu/mod.rs's shader_source); the others get
// inert stand-ins (the *_off.wgsl files).

// Most plane crossings a footprint follows.
const FP_CROSSINGS: u32 = 6u;

// A sample's footprint (footprint::Footprint); ok is false where its own
// ray has no closed form (next to the critical curve) or after a mirror.
struct Footprint {
    ok: bool,
    // The pixel's solid angle (sr) at the sample, in the camera's frame.
    pixel_sr: f32,
    sky_ok: bool,
    sky: vec3<f32>,
    sky_dx: vec3<f32>,
    sky_dy: vec3<f32>,
    n: u32,
    order: array<u32, FP_CROSSINGS>,
    q: array<vec2<f32>, FP_CROSSINGS>,
    q_dx: array<vec2<f32>, FP_CROSSINGS>,
    q_dy: array<vec2<f32>, FP_CROSSINGS>,
    magnification: array<f32, FP_CROSSINGS>,
}

var<private> fp: Footprint;

// The sample's image point (pixels from the top-left corner), set by main.
var<private> stars_px: vec2<f32>;

// The footprint of the object hit being shaded (object_color reads it):
// the derivatives of (u, v) per pixel along x and y.
struct ObjFootprint {
    ok: bool,
    dx: vec2<f32>,
    dy: vec2<f32>,
}

var<private> obj_fp: ObjFootprint;
// The sample's image point; whether its ray still follows the camera's
// geodesic (Probing::object_at); the crossings of the plane z = 0 so far
// (Probing::plane), and z where the last visited step ended.
var<private> obj_at: vec2<f32>;
var<private> obj_fp_on: bool;
var<private> obj_plane: u32;
var<private> obj_last_z: f32;

// A sample at image point (px, py) begins.
fn objfp_begin(px: f32, py: f32) {
    obj_at = vec2<f32>(px, py);
    obj_fp_on = true;
    obj_plane = 0u;
    obj_last_z = P.cam_pos.z;
    obj_fp.ok = false;
}

// Footprint::sky_magnification, as (value, 1), or zeros where not known.
fn fp_sky_magnification() -> vec2<f32> {
    if !FOOTPRINT || !fp.ok || !fp.sky_ok {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(fp.pixel_sr / dot(cross(fp.sky_dx, fp.sky_dy), fp.sky), 1.0);
}

// The index into fp's crossings of plane-crossing order `order`, or
// FP_CROSSINGS where it has none.
fn fp_disk(order: u32) -> u32 {
    if FOOTPRINT && fp.ok {
        for (var i = 0u; i < fp.n; i++) {
            if fp.order[i] == order {
                return i;
            }
        }
    }
    return FP_CROSSINGS;
}

// DiskFootprint::magnification at plane crossing `order`, as
// fp_sky_magnification.
fn fp_disk_magnification_at(order: u32) -> vec2<f32> {
    let i = fp_disk(order);
    if i == FP_CROSSINGS {
        return vec2<f32>(0.0);
    }
    return vec2<f32>(fp.magnification[i], 1.0);
}
