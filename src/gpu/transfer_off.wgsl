// Scenes without a medium: transfer.wgsl's entry points, never called.
var<private> m_alive: bool;
var<private> m_lz: f32;
var<private> m_camera_ratio: f32;

fn m_march(seg: Seg, affine: f32, s0: f32, s1: f32) {
}

fn m_at(seg: Seg, s: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}

fn m_cut(seg: Seg, s: f32, e: f32, r_start: f32, min_ds: f32) -> vec2<f32> {
    return vec2<f32>(e, r_start);
}

fn m_take(seg: Seg, s: f32, e: f32, finest: bool) -> f32 {
    return 0.0;
}

fn m_opaque(g: f32, kelvin: f32, k_scale: f32) {
}

fn m_along_kerr(c: KerrClosed, s_start: f32, s_stop: f32) -> u32 {
    return 0u;
}

fn medium_trace(camera: vec3<f32>, dir: vec3<f32>, px: f32, py: f32) -> Outcome {
    return Outcome(END_ABANDONED, 0u, false, false, false);
}

var<private> m_edge: bool;

fn medium_sharp() -> bool {
    return false;
}

fn m_level(seg: Seg, s: f32) -> f32 {
    return 0.0;
}

fn m_level_change(seg: Seg, a: f32, b: f32, above: bool) -> f32 {
    return b;
}
