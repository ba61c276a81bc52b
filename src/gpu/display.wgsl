// The display on the GPU: the tracer's passes of samples added up over
// frames, bloom, exposure, the tone curve and the sRGB encoding, so that
// the viewer shows a frame without reading the film back (and `render`
// blooms without reading the bloom bands back).
//
// Twins: `Pass::merged` in src/gpu/mod.rs (adding passes), `bloom` and
// `blur` in src/post.rs, `tone_map` and `xyz_to_srgb8` in src/output.rs,
// `RadioLook` in src/colormap.rs (an observed scene's false colour),
// `encode_u8` in src/spectrum/color.rs. A change to one side is a change
// to both.
//
// The host prepends a header (src/gpu/layout.rs, `display_header`): the
// `DisplayParams` struct, BANDS and the TONE_* and COLORMAP_* codes.

@group(0) @binding(0) var<uniform> D: DisplayParams;
// The tracer's band of rows: each pixel's mean over the pass's kept
// samples (w: their number), and its bloom bands (3 BANDS floats a pixel).
@group(0) @binding(1) var<storage, read> film: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> bands: array<f32>;
// The whole image: the view's mean so far (w: samples kept), its bands.
@group(0) @binding(3) var<storage, read_write> acc: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> acc_bands: array<f32>;
// A plane blurred along rows; the bloomed image.
@group(0) @binding(5) var<storage, read_write> scratch: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read_write> shown: array<vec4<f32>>;
// Per plane: its Gaussian's weights, and the weight inside the image of a
// source at each column and at each row (see `post::pass`).
@group(0) @binding(7) var<storage, read> kern: array<f32>;
// The 8-bit sRGB image the window shows.
@group(0) @binding(8) var image: texture_storage_2d<rgba8unorm, write>;

// How `accumulate` is specialised (pipeline constants, so that each
// pipeline is free of branches: CPU devices run every branch of a pass):
// the band starts the image again, the bloom bands are kept too, the pixels
// are encoded as they are added (the viewer without bloom).
override RESTART: bool = false;
override KEEP_BANDS: bool = false;
override ENCODE: bool = false;

// Adds the tracer's band of rows to the view's image (or starts it): each
// pixel the mean over both passes' kept samples, as `Pass::merged`. Each
// invocation takes PIXELS pixels of its row a span apart (neighbouring
// invocations take neighbouring pixels): CPU devices pay for every
// invocation.
@compute @workgroup_size(GROUP_X, GROUP_Y, 1)
fn accumulate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let span = (D.width + PIXELS - 1u) / PIXELS;
    let row = gid.y;
    if gid.x >= span || row >= D.rows {
        return;
    }
    for (var k = 0u; k < PIXELS; k++) {
        let x = gid.x + k * span;
        if x < D.width {
            accumulate_pixel(x, row);
        }
    }
}

fn accumulate_pixel(x: u32, row: u32) {
    let tp = row * D.width + x;
    let y = D.first_row + row;
    let i = y * D.width + x;
    let band = film[tp];
    let nb = 3u * BANDS;
    var now = band;
    if RESTART {
        acc[i] = band;
        if KEEP_BANDS {
            for (var b = 0u; b < nb; b++) {
                acc_bands[i * nb + b] = bands[tp * nb + b];
            }
        }
    } else {
        let old = acc[i];
        now = old;
        let n = old.w + band.w;
        if n > 0.0 {
            now = vec4<f32>((old.xyz * old.w + band.xyz * band.w) / n, n);
            acc[i] = now;
            if KEEP_BANDS {
                for (var b = 0u; b < nb; b++) {
                    let j = i * nb + b;
                    acc_bands[j] = (acc_bands[j] * old.w + bands[tp * nb + b] * band.w) / n;
                }
            }
        }
    }
    if ENCODE {
        encode_pixel(x, y, now.xyz);
    }
}

// Plane 0 is the image's XYZ, plane 1 + b its bloom band b.
fn plane_value(p: u32, i: u32) -> vec3<f32> {
    if p == 0u {
        return acc[i].xyz;
    }
    let at = i * 3u * BANDS + 3u * (p - 1u);
    return vec3<f32>(acc_bands[at], acc_bands[at + 1u], acc_bands[at + 2u]);
}

// One plane blurred along its rows, each source divided by the part of the
// kernel inside the image so that the blur keeps the total.
@compute @workgroup_size(GROUP_X, GROUP_Y, 1)
fn blur_rows(@builtin(global_invocation_id) gid: vec3<u32>) {
    let x = i32(gid.x);
    let y = gid.y;
    if gid.x >= D.width || y >= D.height {
        return;
    }
    let r = i32(D.k_radius);
    let lo = max(x - r, 0);
    let hi = min(x + r, i32(D.width) - 1);
    var sum = vec3<f32>(0.0);
    for (var i = lo; i <= hi; i++) {
        let v = plane_value(D.plane, y * D.width + u32(i)) / kern[D.at_inside_rows + u32(i)];
        sum += v * kern[D.at_kernel + u32(x - i + r)];
    }
    scratch[y * D.width + gid.x] = vec4<f32>(sum, 0.0);
}

// The same along columns, then mixed with the plane (keep x the plane +
// strength x its blur: one of bloom's Gaussians, post::BloomTerm) and added
// to the bloomed image.
@compute @workgroup_size(GROUP_X, GROUP_Y, 1)
fn blur_columns(@builtin(global_invocation_id) gid: vec3<u32>) {
    let x = gid.x;
    let y = i32(gid.y);
    if x >= D.width || gid.y >= D.height {
        return;
    }
    let r = i32(D.k_radius);
    let lo = max(y - r, 0);
    let hi = min(y + r, i32(D.height) - 1);
    var sum = vec3<f32>(0.0);
    for (var j = lo; j <= hi; j++) {
        let v = scratch[u32(j) * D.width + x].xyz / kern[D.at_inside_columns + u32(j)];
        sum += v * kern[D.at_kernel + u32(y - j + r)];
    }
    let i = gid.y * D.width + x;
    let mixed = plane_value(D.plane, i) * D.keep + sum * D.strength;
    if D.first_plane != 0u {
        shown[i] = vec4<f32>(mixed, 0.0);
    } else {
        shown[i] = vec4<f32>(shown[i].xyz + mixed, 0.0);
    }
}

fn luminance(c: vec3<f32>) -> f32 {
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

// Exposure and the tone curve (output::tone_map): linear, in [0, 1].
fn tone_map(rgb: vec3<f32>) -> vec3<f32> {
    let c = max(rgb * D.exposure_scale, vec3<f32>(0.0));
    if D.tonemap == TONE_REINHARD {
        let l = luminance(c);
        if l <= 0.0 {
            return vec3<f32>(0.0);
        }
        return min(c * (1.0 / (1.0 + l)), vec3<f32>(1.0));
    }
    if D.tonemap == TONE_ACES {
        // Narkowicz 2015 fit of the ACES RRT+ODT, per channel.
        return clamp((c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return min(c, vec3<f32>(1.0));
}

// The 8-bit sRGB code of a linear value (encode_u8), as a unit float that
// the rgba8unorm store turns back into that very code.
fn encode(v: f32) -> f32 {
    let x = clamp(v, 0.0, 1.0);
    var s = 12.92 * x;
    if x > 0.0031308 {
        s = 1.055 * pow(x, 1.0 / 2.4) - 0.055;
    }
    return floor(clamp(s, 0.0, 1.0) * 255.0 + 0.5) / 255.0;
}

// The image (bloomed or not) to linear sRGB, exposed, tone-mapped and
// encoded into the window's texture (PIXELS pixels an invocation, as in
// `accumulate`).
@compute @workgroup_size(GROUP_X, GROUP_Y, 1)
fn tonemap(@builtin(global_invocation_id) gid: vec3<u32>) {
    let span = (D.width + PIXELS - 1u) / PIXELS;
    let y = gid.y;
    if gid.x >= span || y >= D.height {
        return;
    }
    for (var k = 0u; k < PIXELS; k++) {
        let x = gid.x + k * span;
        if x >= D.width {
            return;
        }
        let i = y * D.width + x;
        var xyz = acc[i].xyz;
        if D.bloom != 0u {
            xyz = shown[i].xyz;
        }
        encode_pixel(x, y, xyz);
    }
}

fn encode_pixel(x: u32, y: u32, xyz: vec3<f32>) {
    if D.colormap != COLORMAP_NONE {
        // An observed scene's false colour (colormap::RadioLook::index):
        // Y is T_b / DISPLAY_KELVIN; the nearest of the table's 256 sRGB
        // colours at the start of `kern`, each the number r + 256 g +
        // 65536 b.
        var v = xyz.y * D.exposure_scale;
        if D.colormap == COLORMAP_LOG {
            v = select(0.0, 1.0 + log(v) / (D.decades * 2.3025851), v > 0.0);
        }
        v = select(0.0, min(v, 1.0), v > 0.0);
        let c = u32(kern[u32(floor(v * 255.0 + 0.5))]);
        let rgb = vec3<f32>(f32(c & 255u), f32((c >> 8u) & 255u), f32((c >> 16u) & 255u)) / 255.0;
        textureStore(image, vec2<u32>(x, y), vec4<f32>(rgb, 1.0));
        return;
    }
    let m = D.xyz_to_srgb;
    let rgb = m[0].xyz * xyz.x + m[1].xyz * xyz.y + m[2].xyz * xyz.z;
    let t = tone_map(rgb);
    textureStore(image, vec2<u32>(x, y), vec4<f32>(encode(t.x), encode(t.y), encode(t.z), 1.0));
}
