// Stand-ins for ewa.wgsl in a variant without footprints (FOOTPRINT and
// OBJECT_FOOTPRINT off): its lookups stand behind those switches and are
// never made (see footprint_off.wgsl).

fn ewa_disk(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn ewa_object(rec: u32, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn ewa_disk_set4(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>, nm: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn ewa_sky(dir: vec3<f32>, ddir_dx: vec3<f32>, ddir_dy: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}

fn ewa_stars(dir: vec3<f32>, ddir_dx: vec3<f32>, ddir_dy: vec3<f32>) -> StarLight {
    return StarLight(0.0, 0.0, 0.0);
}
