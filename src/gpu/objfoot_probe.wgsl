// Test harness only (src/gpu/objfoot_tests.rs): the footprint at the first
// object hit of the camera ray through each image point, as a render finds
// it (objfp_trace for the sample's own hit, then object_footprint). film
// holds the count (bits) in film[0].x and the points in film[1 + k].xy;
// each answer is two vec4s from film[1 + count + 2k]: (object, or -1 for
// none; 1 where it has a footprint; u, v) and (du/dx, dv/dx, du/dy,
// dv/dy).

@compute @workgroup_size(64)
fn objfp_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = bitcast<u32>(film[0].x);
    if id.x >= n {
        return;
    }
    let at = film[1u + id.x].xy;
    let o = 1u + n + 2u * id.x;
    objfp_begin(at.x, at.y);
    let hit = objfp_trace(at.x, at.y);
    if !hit.ok {
        film[o] = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
        film[o + 1u] = vec4<f32>(0.0);
        return;
    }
    obj_plane = hit.plane;
    object_footprint(hit.obj, hit.seg, hit.hit);
    film[o] = vec4<f32>(f32(hit.obj), select(0.0, 1.0, obj_fp.ok), hit.hit.uv);
    film[o + 1u] = vec4<f32>(obj_fp.dx, obj_fp.dy);
}
