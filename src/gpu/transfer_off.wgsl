// Scenes without a medium: transfer.wgsl's entry points, never called.
var<private> m_energy: f32;

fn medium_visit(seg: Seg) -> bool {
    return true;
}

fn medium_trace(camera: vec3<f32>, dir: vec3<f32>, px: f32, py: f32) -> Outcome {
    return Outcome(END_ABANDONED, 0u, false, false, false);
}
