// How gas moves about the hole and what a photon's frequency is to it:
// twin of src/transfer/riaf.rs's Motion (the RIAF's and the volumetric
// disk's gas, in both bands: VolumeDisk::motion), with the segments'
// affine lengths and the photon's radial momentum (transfer::
// segment_k_r). In f32, lengths in M; its parameters are the Motion's
// block (motion_block()), the spin P.medium_spin.

// The photon's energy in the tracer's units (the segments' affine length
// is |e h|, halved for Kerr's M): set where trace_paths starts its ray.
var<private> m_energy: f32;

// A segment's unit-energy affine length (r_s): |e h|, halved for
// Kerr's M.
fn m_affine(seg: Seg) -> f32 {
    var affine = abs(m_energy * seg.h);
    if KERR {
        affine *= 0.5;
    }
    return affine;
}

struct Zamo {
    alpha: f32,
    omega: f32,
    varpi: f32,
}

// Kerr::zamo_at (NaN inside the horizon).
fn kerr_zamo_at(r: f32, c: f32, s: f32) -> Zamo {
    let a = P.medium_spin;
    let a2 = a * a;
    let sigma = r * r + a2 * c * c;
    let delta = r * r - 2.0 * r + a2;
    let big_a = (r * r + a2) * (r * r + a2) - a2 * delta * s * s;
    return Zamo(sqrt(sigma * delta / big_a), 2.0 * a * r / big_a, sqrt(big_a / sigma) * s);
}

// Motion::frequency_ratio (the RIAF's and the volume's gas); negative
// where the motion is not timelike.
fn motion_frequency_ratio(r: f32, c: f32, lz: f32, k_r: f32) -> f32 {
    let s = sqrt(max(1.0 - c * c, 1e-30));
    let z = kerr_zamo_at(r, c, s);
    let m = motion_block();
    let a = P.medium_spin;
    let a2 = z.alpha * z.alpha;
    let w2 = z.varpi * z.varpi;
    let sigma = r * r + a * a * c * c;
    let delta = r * r - 2.0 * r + a * a;
    let g_rr_up = delta / sigma;
    var omega_k = 1.0 / (r * sqrt(r) + a);
    var ur_k = 0.0;
    if r < m.r_isco {
        let ut = (m.e_isco - z.omega * m.l_isco) / a2;
        let uph = z.omega * ut + m.l_isco / w2;
        let d = m.e_isco - z.omega * m.l_isco;
        let ur2 = g_rr_up * (d * d / a2 - m.l_isco * m.l_isco / w2 - 1.0);
        omega_k = uph / ut;
        ur_k = -sqrt(max(ur2, 0.0));
    }
    let omega = omega_k + (1.0 - m.keplerian) * (z.omega - omega_k);
    let ur_ff = -sqrt(max((1.0 / a2 - 1.0) * g_rr_up, 0.0));
    let ur = ur_k + m.infall * (ur_ff - ur_k);
    let k = -a2 + w2 * (omega - z.omega) * (omega - z.omega);
    let ut2 = -(1.0 + ur * ur / g_rr_up) / k;
    let ratio = sqrt(max(ut2, 0.0)) * (1.0 - lz * omega) - k_r / g_rr_up * ur;
    return select(-1.0, ratio, z.alpha > 0.0 && k < 0.0 && ut2 > 0.0);
}

// transfer::segment_k_r: the photon's dr/dlambda (M) at fraction s of a
// segment of m_per_s M per unit of s: the photon runs against the trace.
fn segment_k_r(seg: Seg, s: f32, m_per_s: f32) -> f32 {
    return segment_k(seg, s, m_per_s).x;
}

// transfer::segment_k: (dr/dlambda, d(cos th)/dlambda) (M) at s.
fn segment_k(seg: Seg, s: f32, m_per_s: f32) -> vec2<f32> {
    let p = seg_point(seg, s) * 2.0;
    let dp = seg_tangent(seg, s) * 2.0;
    var r = length(p);
    var grad = p / r;
    if KERR {
        // Kerr::ks_radius_gradient.
        let a2 = P.kerr_hole.x * P.kerr_hole.x;
        r = ks_radius(p);
        grad = (p * (r * r) + vec3<f32>(0.0, 0.0, a2 * p.z)) / (r * (2.0 * r * r - dot(p, p) + a2));
    }
    let dr = dot(grad, dp);
    // cos th = z / r.
    return vec2<f32>(-dr, -(dp.z - p.z / r * dr) / r) / m_per_s;
}
