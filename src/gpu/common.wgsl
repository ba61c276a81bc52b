// Bindings and helpers shared by the GPU tracer.
//
// The host prepends a header (src/gpu/layout.rs, the one source of both
// sides): the variant's constants N_WL (wavelengths, 1 for RGB renders),
// SPECTRAL, SPEC_ARRAY (each sample's spectrum kept, for EXR layers or
// bloom bands; light always goes straight into XYZ too), FILTERS (mirrors
// or clouds filter light per wavelength), FILTER_LEN, OBJECTS and GAS (the
// scene has objects, gas: code for what it lacks is left out), TRAVEL
// (rays keep their light's travel time) and CLOSED; the `Params` struct,
// which the host fills from the validated scene (src/gpu/pack.rs); the
// flags, kind codes, counters (STAT_*), record sizes, the integrator's
// tableau and the tail's quadrature nodes. Lengths are in r_s, as on the
// CPU.

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> tables: array<f32>;
@group(0) @binding(2) var<storage, read> disk_data: array<u32>;
@group(0) @binding(3) var<storage, read> sky_data: array<u32>;
@group(0) @binding(4) var<storage, read_write> film: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> spectra: array<f32>;
@group(0) @binding(6) var<storage, read_write> bands: array<f32>;
@group(0) @binding(7) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read> objects_data: array<u32>;

fn has_flag(f: u32) -> bool {
    return (P.flags & f) != 0u;
}

// Finite by the bits: shader compilers may assume no NaN or infinity and
// fold `x != x` away.
fn finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

fn finite3(v: vec3<f32>) -> bool {
    return finite(v.x) && finite(v.y) && finite(v.z);
}

// ---- 64-bit integers as (low, high) words, for the CPU's sampler --------

fn mul32_wide(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = (p00 >> 16u) + (p01 & 0xffffu) + (p10 & 0xffffu);
    return vec2<u32>((p00 & 0xffffu) | (mid << 16u), p11 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u));
}

fn mul64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = mul32_wide(a.x, b.x);
    return vec2<u32>(lo.x, lo.y + a.x * b.y + a.y * b.x);
}

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

// Right shift by 0 < n < 32.
fn shr64(a: vec2<u32>, n: u32) -> vec2<u32> {
    return vec2<u32>((a.x >> n) | (a.y << (32u - n)), a.y >> n);
}

fn u64_of(x: u32) -> vec2<u32> {
    return vec2<u32>(x, 0u);
}

// SplitMix64 finaliser (sampling::mix).
fn mix64(z0: vec2<u32>) -> vec2<u32> {
    var z = mul64(z0 ^ shr64(z0, 30u), vec2<u32>(0x1ce4e5b9u, 0xbf58476du));
    z = mul64(z ^ shr64(z, 27u), vec2<u32>(0x133111ebu, 0x94d049bbu));
    return z ^ shr64(z, 31u);
}

const GOLDEN: vec2<u32> = vec2<u32>(0x7f4a7c15u, 0x9e3779b9u);

// The next uniform number of the sequence in `state`, in [0, 1).
fn next_uniform(state: ptr<function, vec2<u32>>) -> f32 {
    *state = add64(*state, GOLDEN);
    let m = shr64(mix64(*state), 11u);
    return f32(m.y) * 4.76837158203125e-7 + f32(m.x) * 1.1102230246251565e-16;
}

// Kensler's permutation of 0..len keyed by `key` (sampling::permute).
fn permute(i0: u32, len: u32, key: u32) -> u32 {
    var w = len - 1u;
    w = w | (w >> 1u);
    w = w | (w >> 2u);
    w = w | (w >> 4u);
    w = w | (w >> 8u);
    w = w | (w >> 16u);
    var i = i0;
    // Cycle-walking ends within a few rounds (w < 2 len).
    for (var round = 0u; round < 64u; round++) {
        i = i ^ key;
        i = i * 0xe170893du;
        i = i ^ (key >> 16u);
        i = i ^ ((i & w) >> 4u);
        i = i ^ (key >> 8u);
        i = i * 0x0929eb3fu;
        i = i ^ (key >> 23u);
        i = i ^ ((i & w) >> 1u);
        i = i * (1u | (key >> 27u));
        i = i * 0x6935fa69u;
        i = i ^ ((i & w) >> 11u);
        i = i * 0x74dcb303u;
        i = i ^ ((i & w) >> 2u);
        i = i * 0x9e501cc3u;
        i = i ^ ((i & w) >> 2u);
        i = i * 0xc860a3dfu;
        i = i & w;
        i = i ^ (i >> 5u);
        if i < len {
            return (i + key) % len;
        }
    }
    return (i0 + key) % len;
}

// Offset in [0, 1)^2 of sample `i` of `n` in pixel `pixel`
// (sampling::sample_offset, to f32 precision).
fn sample_offset(pixel: u32, i: u32, n: u32) -> vec2<f32> {
    if n == 1u {
        return vec2<f32>(0.5, 0.5);
    }
    let seed = vec2<u32>(P.seed_lo, P.seed_hi);
    var state = add64(mix64(add64(mix64(seed ^ GOLDEN), u64_of(pixel))), mix64(u64_of(i)));
    let jx = next_uniform(&state);
    let jy = next_uniform(&state);
    let k = u32(round(sqrt(f32(n))));
    if k * k == n {
        return vec2<f32>((f32(i % k) + jx) / f32(k), (f32(i / k) + jy) / f32(k));
    }
    let key = mix64(seed ^ mul64(u64_of(pixel), vec2<u32>(0x4f6cdd1du, 0x2545f491u))).x;
    let row = permute(i, n, key);
    return vec2<f32>((f32(i) + jx) / f32(n), (f32(row) + jy) / f32(n));
}

// Owen scramble of `v`'s bits keyed by `key` (sampling::owen_scramble).
fn owen_scramble(v: u32, key: u32) -> u32 {
    var x = reverseBits(v);
    x = x + key;
    x = x ^ (x * 0x6c50b47cu);
    x = x ^ (x * 0xb82f1e52u);
    x = x ^ (x * 0xc7afe638u);
    x = x ^ (x * 0x8d22f6e6u);
    return reverseBits(x);
}

// A 32-bit fraction's cell centre in [0, 1) as f32 (never 1 after rounding).
fn fraction32(v: u32) -> f32 {
    let f = f32(v >> 8u) * 5.9604644775390625e-8 + (f32(v & 0xffu) + 0.5) * 2.3283064365386963e-10;
    return min(f, 0.99999994);
}

// Offset of pixel `pixel`'s extra sample `j` (adaptive sampling): point j
// of its scrambled (0, 2)-sequence (sampling::refine_offset).
fn refine_offset(pixel: u32, j: u32) -> vec2<f32> {
    let seed = vec2<u32>(P.seed_lo, P.seed_hi);
    let h = mix64(add64(mix64(seed ^ vec2<u32>(0x4c957f2du, 0x5851f42du)), u64_of(pixel)));
    // sobol2: the radical inverse, and the dimension of x + 1.
    var y = 0u;
    var v = 0x80000000u;
    for (var k = j; k != 0u; k = k >> 1u) {
        if (k & 1u) != 0u {
            y = y ^ v;
        }
        v = v ^ (v >> 1u);
    }
    return vec2<f32>(fraction32(owen_scramble(reverseBits(j), h.x)), fraction32(owen_scramble(y, h.y)));
}

// transfer::Piece, the exact solution across a piece of optical depth
// dtau: (1 - e^-dtau) / dtau, the share of its emission j dl that leaves
// it (by the series where f32 would cancel); it lets e^-dtau through.
// One solver for the physical media (transfer.wgsl) and the visible
// band's gas (main.wgsl's march).
fn piece_shown(dtau: f32) -> f32 {
    if dtau < 1e-4 {
        return 1.0 - dtau * (0.5 - dtau / 6.0);
    }
    return (1.0 - exp(-dtau)) / dtau;
}
