// The media of observed scenes (the MEDIUM variant), in f32: the WGSL
// twin of src/transfer/gold.rs, uniform.rs, riaf.rs, synchrotron.rs,
// volume.rs and the dispatch by kind of src/transfer/mod.rs (Medium;
// the GRMHD snapshot's own in grmhd.wgsl),
// each function named after its Rust twin (Gold::density: gold_density).
// Lengths in M, coefficients in cgs. Each medium's parameters are the
// block it builds of itself (Gold::gpu_block...), read through the
// header's generated readers (gold_block()...): no parameter travels by
// position. transfer.wgsl walks them.

// spectrum::planck_nu: B_nu(T) = 2 h nu^3 / c^2 / (e^x - 1), x = h nu /
// k T, in cgs; 2 h / c^2 = 1.4745e-47 is out of f32's range: nu in THz.
// Where x passes 80, e^x is held at e^80; 0 without a temperature.
fn planck_nu(nu: f32, kelvin: f32) -> f32 {
    if !(kelvin > 0.0) {
        return 0.0;
    }
    let x = H_OVER_K * nu / kelvin;
    let em1 = select(x * (1.0 + x * (0.5 + x / 6.0)), exp(min(x, 80.0)) - 1.0, x > 1e-3);
    let t = nu * 1e-12;
    return TWO_H_OVER_C2_THZ * t * t * t / em1;
}

// ---- Gold et al. 2020 (gold.rs; GoldBlock). The cut-off is the
// header's M_CUTOFF (transfer::CUTOFF).

fn gold_density(r: f32, c: f32) -> f32 {
    let g = gold_block();
    let e = 0.5 * ((r / 10.0) * (r / 10.0) + (g.h * c) * (g.h * c));
    return select(0.0, g.n0 * exp(-e), e < M_CUTOFF);
}

fn gold_scale(r: f32, c: f32) -> f32 {
    let h = gold_block().h;
    let radial = 100.0 / max(r, 1.0);
    let edge_e = sqrt(2.0 * M_CUTOFF);
    let s = sqrt(max(1.0 - c * c, 0.0));
    let vertical = r / max(h * h * abs(c * s) + h, 1e-30);
    let outside = min(min(radial, 0.5 * r), max(r * (abs(c) - edge_e / max(h, 1e-30)), vertical));
    return select(min(min(radial, vertical), 0.5 * r), outside, h * abs(c) > edge_e);
}

// Gold::frequency_ratio; negative where the flow is not timelike.
fn gold_frequency_ratio(r: f32, c: f32, lz: f32) -> f32 {
    let s = sqrt(max(1.0 - c * c, 1e-30));
    let big_r = r * s;
    let l = gold_block().l0 * big_r * sqrt(big_r) / (1.0 + big_r);
    let z = kerr_zamo_at(r, c, s);
    let a2 = z.alpha * z.alpha;
    let w2 = z.varpi * z.varpi;
    let drag = 1.0 - z.omega * l;
    let inv = drag * drag / a2 - l * l / w2;
    let ratio = (drag * (1.0 - lz * z.omega) / a2 - lz * l / w2) / sqrt(max(inv, 1e-30));
    return select(-1.0, ratio, inv > 0.0);
}

fn gold_coefficients(n: f32, nu: f32) -> vec2<f32> {
    let g = gold_block();
    let x = nu / g.nu_p;
    let j = n * pow(x, -g.alpha);
    let k = select(g.a_abs * n * pow(x, -(g.alpha + 2.5)), 0.0, g.a_abs == 0.0);
    return vec2<f32>(j, k);
}

// ---- the uniform shell (uniform.rs; UniformBlock).

fn uniform_scale(r: f32) -> f32 {
    let u = uniform_block();
    let thickness = u.outer - u.inner;
    return select(max(thickness, max(r - u.outer, u.inner - r)), thickness, r >= u.inner && r <= u.outer);
}

// Uniform::contains and frequency_ratio (the gas at rest in the frame's
// rotation); negative outside the shell or the horizon.
fn uniform_frequency_ratio(r: f32, c: f32, lz: f32) -> f32 {
    let u = uniform_block();
    var ratio = -1.0;
    if r >= u.inner && r <= u.outer {
        let z = kerr_zamo_at(r, c, sqrt(max(1.0 - c * c, 0.0)));
        if z.alpha > 0.0 {
            ratio = (1.0 - z.omega * lz) / z.alpha;
        }
    }
    return ratio;
}

fn uniform_coefficients(nu: f32) -> vec2<f32> {
    let u = uniform_block();
    return vec2<f32>(u.j0 * pow(nu / u.nu_p, -u.alpha), u.k0);
}

// ---- the RIAF (riaf.rs; RiafBlock, its motion MotionBlock).

// Riaf::plasma: (n_e, T_e, B), or n_e = 0 where there is no gas.
fn riaf_plasma(r: f32, c: f32) -> vec3<f32> {
    let f = riaf_block();
    let sin2 = max(1.0 - c * c, 0.0);
    let e = c * c / (2.0 * f.thickness * f.thickness * max(sin2, 1e-30));
    let gas = r <= f.outer && e < M_CUTOFF;
    let n = f.density * pow(r, f.density_index) * exp(-min(e, M_CUTOFF));
    let t = f.temperature * pow(r, f.temperature_index);
    // B = sqrt(8 pi n m_p c^2 / (6 beta r)).
    let b = RIAF_FIELD * sqrt(n / (f.beta * r));
    return select(vec3<f32>(0.0), vec3<f32>(n, t, b), gas);
}

fn riaf_scale(r: f32, c: f32) -> f32 {
    let h = riaf_block().thickness;
    let s = sqrt(max(1.0 - c * c, 0.0));
    let radial = 0.125 * r;
    let cot_edge = h * sqrt(2.0 * M_CUTOFF);
    let edge = atan(1.0 / cot_edge);
    let th = atan2(s, abs(c));
    let axis = max(min(radial, r * (edge - th)), r / 32.0);
    let vertical = r / (abs(c) / (h * h * max(s * s * s, 1e-30)) + 1.0 / h);
    return select(min(radial, max(vertical, r / 32.0)), axis, abs(c) >= cot_edge * s);
}

// ---- thermal synchrotron (synchrotron.rs), in logarithms where f32
// would underflow: K_2(1/Theta_e) ~ e^(-1/Theta_e).

// ln K_2(x), Abramowitz and Stegun 9.8.1-9.8.8.
fn ln_bessel_k2(x: f32) -> f32 {
    var result: f32;
    if x <= 2.0 {
        let t = (x / 3.75) * (x / 3.75);
        let i0 = 1.0 + t * (3.5156229 + t * (3.0899424 + t * (1.2067492 + t * (0.2659732 + t * (0.0360768 + t * 0.0045813)))));
        let i1 = x * (0.5 + t * (0.87890594 + t * (0.51498869 + t * (0.15084934 + t * (0.02658733 + t * (0.00301532 + t * 0.00032411))))));
        let q = 0.25 * x * x;
        let ln = log(0.5 * x);
        let k0 = -ln * i0 + (-0.57721566 + q * (0.42278420 + q * (0.23069756 + q * (0.03488590 + q * (0.00262698 + q * (0.00010750 + q * 0.0000074))))));
        let k1 = (x * ln * i1 + (1.0 + q * (0.15443144 + q * (-0.67278579 + q * (-0.18156897 + q * (-0.01919402 + q * (-0.00110404 + q * -0.00004686))))))) / x;
        result = log(k0 + 2.0 / x * k1);
    } else {
    let t = 2.0 / x;
    let p0 = 1.25331414 + t * (-0.07832358 + t * (0.02189568 + t * (-0.01062446 + t * (0.00587872 + t * (-0.00251540 + t * 0.00053208)))));
    let p1 = 1.25331414 + t * (0.23498619 + t * (-0.03655620 + t * (0.01504268 + t * (-0.00780353 + t * (0.00325614 + t * -0.00068245)))));
    result = -x - 0.5 * log(x) + log(p0 + t * p1);
    }
    return result;
}

// The pitch-angle average's table (Average in synchrotron.rs): ln G +
// y^1/3 at SYNC_TABLE points of ln y from SYNC_LN_Y_LOW to SYNC_LN_Y_HIGH.
fn ln_average(y: f32) -> f32 {
    let last = f32(SYNC_TABLE - 1u);
    let step = (SYNC_LN_Y_HIGH - SYNC_LN_Y_LOW) / last;
    let u = (log(y) - SYNC_LN_Y_LOW) / step;
    let at = P.at_medium_table;
    let i = u32(clamp(u, 0.0, last - 1.0));
    let f = clamp(u, 0.0, last) - f32(i);
    let inside = mix(tables[at + i], tables[at + i + 1u], f) - pow(y, 1.0 / 3.0);
    let below = tables[at] - exp(SYNC_LN_Y_LOW / 3.0) + u * step / 3.0;
    return select(select(-3.4e38, inside, u < last), below, u < 0.0);
}

// Thermal::new: what the coefficients of electrons (n_e, T_e, B) share at

// Thermal::new: what the coefficients of electrons (n_e, T_e, B) share at
// every frequency, (ln of prefactor nu_s0, nu_s0, T_e); ln of 0 where they
// emit nothing.
fn thermal_new(pl: vec3<f32>) -> vec3<f32> {
    let n = pl.x;
    // Theta_e = k T / (m_e c^2).
    let theta = max(pl.y / ME_C2_OVER_K, SYNC_COLDEST);
    let none = pl.y / ME_C2_OVER_K < SYNC_COLDEST || n <= 0.0 || pl.z <= 0.0;
    // (2/9) nu_c Theta^2, nu_c = e B / (2 pi m_e c).
    let nu_s0 = 2.0 / 9.0 * CYCLOTRON_PER_GAUSS * pl.z * theta * theta;
    // n sqrt(2) pi e^2 / (3 c).
    let ln_norm = log(max(n * SYNC_NORM * nu_s0, 1e-37)) - ln_bessel_k2(1.0 / theta);
    return vec3<f32>(select(ln_norm, -3.4e38, none), nu_s0, pl.y);
}

// Thermal::coefficients: (j_nu, alpha_nu) of thermal synchrotron at
// gas-frame frequency nu, of electrons as thermal_new gives them.
fn thermal_coefficients(th: vec3<f32>, nu: f32) -> vec2<f32> {
    let ln_j = th.x + ln_average(nu / th.y);
    let j = select(exp(max(ln_j, -87.0)), 0.0, ln_j < -87.0);
    return vec2<f32>(j, select(j / planck_nu(nu, th.z), 0.0, j == 0.0));
}

// ---- the volumetric disk's gas (volume.rs; VolumeGasBlock): its density
// is the visible-band volume's grid at P.at_volume, its motion the
// MotionBlock.

// VolumeGas::scale at height z (M).
fn volume_gas_scale(z: f32) -> f32 {
    let v = volume_gas_block();
    return max(v.structure, 2.0 * (0.5 * abs(z) - v.zmax));
}

// VolumeGas::state's plasma at p (r_s): (alpha_nu (cm^-1), kelvin),
// alpha 0 where there is no gas.
fn volume_gas_state(p: vec3<f32>) -> vec2<f32> {
    let v = volume_gas_block();
    let rho = grid_sample(od(P.at_volume + 14u), p);
    let r = length(p.xy);
    if !(rho > 0.0 && r > v.inner) {
        return vec2<f32>(0.0);
    }
    let kelvin = v.t0 * pow(r, -0.75) * pow(1.0 - sqrt(v.inner / r), 0.25);
    return vec2<f32>(v.alpha * rho, kelvin);
}

// ---- the medium by kind (Medium in transfer/mod.rs).

fn medium_extent() -> f32 {
    return P.medium_extent;
}

// Medium::scale at (r, cos th, z), z the point's height (M).
fn medium_scale(at: vec3<f32>) -> f32 {
    let r = at.x;
    let c = at.y;
    var scale: f32;
    if P.medium_kind == MEDIUM_GOLD {
        scale = gold_scale(r, c);
    } else if P.medium_kind == MEDIUM_UNIFORM {
        scale = uniform_scale(r);
    } else if P.medium_kind == MEDIUM_VOLUME {
        scale = volume_gas_scale(at.z);
    } else if GRMHD {
        scale = grmhd_scale(r, c);
    } else {
        scale = riaf_scale(r, c);
    }
    return scale;
}

// Medium::surfaces: the radii where the medium ends abruptly (none:
// negative).
fn medium_surface(i: u32) -> f32 {
    var b = -1.0;
    if P.medium_kind == MEDIUM_UNIFORM {
        let u = uniform_block();
        b = select(u.outer, u.inner, i == 0u);
    } else if P.medium_kind == MEDIUM_RIAF && i == 0u {
        b = riaf_block().outer;
    } else if GRMHD {
        let g = grmhd_block();
        b = select(g.r_max, g.r_min, i == 0u);
    }
    return b;
}

// Medium::sharp: whether a surface inside the medium (a snapshot's
// magnetisation cut) ends pieces; Medium::level its level there.
fn medium_sharp() -> bool {
    return GRMHD && grmhd_block().sharp > 0.0;
}

fn medium_level(r: f32, c: f32, p: vec3<f32>) -> f32 {
    return grmhd_level(r, c, p);
}

// The gas at a point (transfer::Gas): the frequency it measures for a
// unit-energy photon, ratio <= 0 where nothing radiates or absorbs, and
// its plasma (Gold's density, the shell's 1, thermal_new's electrons, the
// volume's (alpha, kelvin)).
struct Gas {
    ratio: f32,
    plasma: vec3<f32>,
}

// Medium::state at (r, cos th), the point p (r_s), for a photon of
// L_z / E `lz`, dr/dlambda `k_r` and d(cos th)/dlambda `k_cos` (M).
fn medium_state(r: f32, c: f32, p: vec3<f32>, lz: f32, k_r: f32, k_cos: f32) -> Gas {
    var gas = Gas(-1.0, vec3<f32>(0.0));
    if GRMHD {
        gas = grmhd_state(r, c, p, lz, k_r, k_cos);
    } else if P.medium_kind == MEDIUM_VOLUME {
        let g = volume_gas_state(p);
        if g.x > 0.0 {
            gas = Gas(motion_frequency_ratio(r, c, lz, k_r), vec3<f32>(g, 0.0));
        }
    } else if P.medium_kind == MEDIUM_GOLD {
        let n = gold_density(r, c);
        if n > 0.0 {
            gas = Gas(gold_frequency_ratio(r, c, lz), vec3<f32>(n, 0.0, 0.0));
        }
    } else if P.medium_kind == MEDIUM_UNIFORM {
        gas = Gas(uniform_frequency_ratio(r, c, lz), vec3<f32>(1.0, 0.0, 0.0));
    } else {
        let pl = riaf_plasma(r, c);
        if pl.x > 0.0 {
            gas = Gas(motion_frequency_ratio(r, c, lz, k_r), thermal_new(pl));
        }
    }
    return gas;
}

// ln j_nu of the gas at its own frequency nu, where f32 would underflow
// j_nu (pieces against a snapshot's cut compare it).
fn medium_ln_emission(gas: Gas, nu: f32) -> f32 {
    if GRMHD {
        return pitched_ln_emission(gas.plasma, nu);
    }
    return log(max(medium_coefficients(gas, nu).x, 1e-38));
}

// Plasma::coefficients: (j_nu, alpha_nu) of the gas at its own frequency
// nu (cgs).
fn medium_coefficients(gas: Gas, nu: f32) -> vec2<f32> {
    var c: vec2<f32>;
    if P.medium_kind == MEDIUM_GOLD {
        c = gold_coefficients(gas.plasma.x, nu);
    } else if P.medium_kind == MEDIUM_UNIFORM {
        c = uniform_coefficients(nu);
    } else if P.medium_kind == MEDIUM_VOLUME {
        c = vec2<f32>(gas.plasma.x * planck_nu(nu, gas.plasma.y), gas.plasma.x);
    } else if GRMHD {
        c = pitched_coefficients(gas.plasma, nu);
    } else {
        c = thermal_coefficients(gas.plasma, nu);
    }
    return c;
}
