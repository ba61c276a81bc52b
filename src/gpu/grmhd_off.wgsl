// Media other than a GRMHD snapshot: grmhd.wgsl's entry points, never
// called (media.wgsl calls them only for MEDIUM_GRMHD).
fn grmhd_state(r: f32, c: f32, p: vec3<f32>, lz: f32, k_r: f32, k_cos: f32) -> Gas {
    return Gas(-1.0, vec3<f32>(0.0));
}

fn grmhd_scale(r: f32, c: f32) -> f32 {
    return r;
}

fn grmhd_level(r: f32, c: f32, p: vec3<f32>) -> f32 {
    return 0.0;
}

fn pitched_coefficients(pl: vec3<f32>, nu: f32) -> vec2<f32> {
    return vec2<f32>(0.0);
}

fn pitched_ln_emission(pl: vec3<f32>, nu: f32) -> f32 {
    return -3.4e38;
}
