// Test harness only (src/gpu/ewa/tests.rs): evaluates the footprint
// lookups of ewa.wgsl on a list of inputs in `objects_data` (the count,
// then 16 words each: the kind, a point, its two derivatives and four
// wavelengths) into `film`, one vec4 per input.

fn probe_vec3(b: u32) -> vec3<f32> {
    return vec3<f32>(bitcast<f32>(objects_data[b]), bitcast<f32>(objects_data[b + 1u]), bitcast<f32>(objects_data[b + 2u]));
}

@compute @workgroup_size(64)
fn ewa_probe(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= objects_data[0] {
        return;
    }
    let b = 1u + 16u * id.x;
    let p = probe_vec3(b + 1u);
    let dx = probe_vec3(b + 4u);
    let dy = probe_vec3(b + 7u);
    let nm = vec4<f32>(probe_vec3(b + 10u), bitcast<f32>(objects_data[b + 13u]));
    switch objects_data[b] {
        case 0u: {
            film[id.x] = ewa_disk(p.xy, dx.xy, dy.xy);
        }
        case 1u: {
            film[id.x] = ewa_disk_set4(p.xy, dx.xy, dy.xy, nm);
        }
        case 2u: {
            film[id.x] = ewa_sky(p, dx, dy);
        }
        case 4u: {
            let f = ewa_equirect(p, dx, dy);
            film[id.x] = vec4<f32>(f.uv, f.dx.x, f.dy.y);
        }
        default: {
            let s = ewa_stars(p, dx, dy);
            film[id.x] = vec4<f32>(s.luminance, s.kelvin, s.milky_way, 0.0);
        }
    }
}
