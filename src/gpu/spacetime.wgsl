// The spacetime the exact model's light moves in: the WGSL twin of
// src/physics/spacetime.rs, in f32 and in units of r_s. Everything here
// depends on the metric; the rest of the shader asks these functions.
// Schwarzschild's are below; a spinning hole's (KERR) are in kerr.wgsl and
// chosen here or where a ray starts and steps.

// Spacetime::camera_direction: a static observer's local direction -> the
// coordinate direction.
fn static_to_coordinate(x: vec3<f32>, local: vec3<f32>) -> vec3<f32> {
    let r = length(x);
    let n = x / r;
    let radial = dot(local, n);
    return local + n * (radial * (sqrt(1.0 - 1.0 / r) - 1.0));
}

// The impact parameter of the ray a static camera at r sends at angle
// alpha (sin_local) from the hole's direction: b = r sin(alpha) /
// sqrt(1 - r_s/r).
fn camera_impact(r: f32, sin_local: f32) -> f32 {
    return r * sin_local / sqrt(1.0 - 1.0 / r);
}

// Spacetime::acceleration: x'' = -k x / |x|^5, k = (3/2) h^2.
fn accel(x: vec3<f32>, k: f32) -> vec3<f32> {
    let r2 = dot(x, x);
    let r = sqrt(r2);
    return x * (-k / (r2 * r2 * r));
}

// Spacetime::time_rate: dt/dlambda = E / (1 - r_s/r)
fn time_rate(x: vec3<f32>, e: f32) -> f32 {
    return e / (1.0 - 1.0 / length(x));
}

// Spacetime::reflect: the law of reflection in the static frame.
fn reflect_static(x: vec3<f32>, dir: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let r = length(x);
    let e = x / r;
    let s = sqrt(1.0 - 1.0 / r);
    let local = dir + e * (dot(dir, e) * (1.0 / s - 1.0));
    let normal = normalize(n + e * (dot(n, e) * (s - 1.0)));
    let out = local - normal * (2.0 * dot(local, normal));
    return out + e * (dot(out, e) * (s - 1.0));
}

// Spacetime::photon_lz_over_e: the L_z/E of a photon leaving `x` along `v`
// (coordinate velocity), for the disk's Doppler shift.
fn photon_lz_over_e(x: vec3<f32>, v: vec3<f32>) -> f32 {
    let l = cross(x, v);
    let r = length(x);
    let v_inf = sqrt(dot(v, v) - dot(l, l) / (r * r * r));
    return -l.z / v_inf;
}

// Spacetime::static_ln_shift: ln g of a static emitter at r_e seen by the
// static camera at r_o.
fn static_ln_shift(r_e: f32, r_o: f32) -> f32 {
    return 0.5 * log((1.0 - 1.0 / r_e) / (1.0 - 1.0 / r_o));
}

// Spacetime::static_ln_shift of sky light (r_e infinite) at r_o.
fn sky_ln_shift(r_o: f32) -> f32 {
    return -0.5 * log(1.0 - 1.0 / r_o);
}

// The emitter's part of Spacetime::disk_ln_shift: the disk's material at
// r_e, on its circular orbit with `doppler` (outside the photon sphere,
// where orbits exist), static without.
fn disk_emitter_ln_shift(r_e: f32, lz: f32, doppler: bool) -> f32 {
    if doppler && r_e > 1.5 {
        let omega = sqrt(0.5 / (r_e * r_e * r_e));
        return 0.5 * log(1.0 - 1.5 / r_e) - log(1.0 - omega * lz);
    }
    return 0.5 * log(1.0 - 1.0 / r_e);
}

// Spacetime::ring_radius: the radius of the equatorial ring at distance
// rho from the axis (Kerr-Schild's circles of radius r lie at sqrt(r^2 +
// a^2)).
fn ring_radius(rho: f32) -> f32 {
    if KERR {
        let a = 0.5 * P.kerr_hole.x;
        return sqrt(max(rho * rho - a * a, 0.0));
    }
    return rho;
}

// Spacetime::disk_plane: the plane point `p` in the disk's polar
// coordinates (r cos phi, r sin phi), Boyer-Lindquist's with spin (x + i y
// = (r + i a) e^(i phi_KS), phi_KS = phi + kc_ks_term(r)); inside the
// horizon the origin.
fn disk_plane(p: vec3<f32>) -> vec2<f32> {
    if KERR {
        let r = ring_radius(sqrt(p.x * p.x + p.y * p.y));
        if !(2.0 * r > P.kerr_hole.y) {
            return vec2<f32>(0.0);
        }
        let a = 0.5 * P.kerr_hole.x;
        let e_ks = vec2<f32>(p.x * r + p.y * a, p.y * r - p.x * a) / (r * r + a * a);
        let t = -kc_ks_term(2.0 * r);
        let c = cos(t);
        let s = sin(t);
        return r * vec2<f32>(c * e_ks.x - s * e_ks.y, s * e_ks.x + c * e_ks.y);
    }
    return p.xy;
}

// Spacetime::orbital_angular_velocity of the disk's circular orbit at ring
// radius r (per r_s/c): sqrt(1 / (2 r^3)), with spin 1 / (r^1.5 + a) in M.
fn orbit_omega(r: f32) -> f32 {
    if KERR {
        let m = 2.0 * r;
        return 2.0 / (m * sqrt(m) + P.kerr_hole.x);
    }
    return sqrt(0.5 / (r * r * r));
}
