// The visible band's gas along a segment: twin of src/cpu/gas.rs, the
// volumetric disk and the clouds walked by pieces.wgsl's loop, each piece
// solved by common.wgsl's piece_shown and shaded by main.wgsl's
// shade_volume and shade_cloud.

// The visible gas of the stretch being walked (VisibleGas in
// src/cpu/gas.rs): which media it holds (bit 0 the volume, 1 + c cloud
// c) and the segment's chord (r_s), the media's lengths.
var<private> v_media: u32;
var<private> v_chord: f32;

// VisibleGas::take: the piece from s to e of `seg`, the volume's grey
// piece (its emission at each node, shifted as its gas moves) then
// each cloud's (its density averaged over the nodes), through
// transfer::Piece; its greatest optical depth, or minus it, adding
// nothing, where that is above MAX_DTAU and it may be cut (not `finest`).
fn v_take(seg: Seg, s: f32, e: f32, finest: bool) -> f32 {
    let dl = v_chord * (e - s);
    let mid = 0.5 * (s + e);
    let half = GAUSS_2 * (e - s);
    let n = vec2<f32>(mid - half, mid + half);
    let p0 = seg_point(seg, n.x);
    let p1 = seg_point(seg, n.y);
    var worst = 0.0;
    var rho = vec2<f32>(0.0);
    let v = P.at_volume;
    if (v_media & 1u) != 0u {
        rho = vec2<f32>(
            grid_sample(od(v + 14u), unturn(p0, emitted_at(seg, n.x))),
            grid_sample(od(v + 14u), unturn(p1, emitted_at(seg, n.y))),
        );
        worst = odf(v + 3u) * 0.5 * (rho.x + rho.y) * dl;
    }
    let volume_dtau = worst;
    // Each cloud's optical depth at 550 nm and ln g (a static emitter's,
    // the same for every cloud) at the piece's middle.
    var clouds: array<vec2<f32>, 16>;
    var static_ln = 0.0;
    var have_static_ln = false;
    let n_clouds = min(P.n_clouds, MAX_CLOUDS);
    for (var c = 0u; c < n_clouds; c++) {
        clouds[c] = vec2<f32>(0.0);
        if (v_media & (2u << c)) == 0u {
            continue;
        }
        let rec = P.at_clouds + c * CLOUD_WORDS;
        let kappa_dl = odf(rec + 4u) * 0.5 * (grid_sample(od(rec + 17u), p0) + grid_sample(od(rec + 17u), p1)) * dl;
        if kappa_dl <= 0.0 {
            continue;
        }
        if !have_static_ln {
            static_ln = light_ln(fixed_ln_shift(seg, mid, seg_point(seg, mid)));
            have_static_ln = true;
        }
        let ln_g = static_ln;
        // Thickest at the bluest wavelength the gas sees, 380 nm at the
        // camera.
        let beta = odf(rec + 5u);
        var depth = kappa_dl;
        if beta != 0.0 {
            depth *= pow(380.0 * exp(ln_g) / 550.0, -beta);
        }
        worst = max(worst, depth);
        clouds[c] = vec2<f32>(kappa_dl, ln_g);
    }
    if worst > MAX_DTAU && !finest {
        return -worst;
    }
    if volume_dtau > 0.0 {
        let kappa = odf(v + 3u);
        let dtau = volume_dtau;
        let shown = piece_shown(dtau);
        met_disk = true;
        for (var k = 0u; k < 2u; k++) {
            let r = rho[k];
            if r <= 0.0 {
                continue;
            }
            let at = n[k];
            let p = select(p0, p1, k == 1u);
            let axis = sqrt(p.x * p.x + p.y * p.y);
            // The source function: the blackbody of its radius, its
            // luminance `emission` times the peak temperature's; each
            // node emits half the piece's j dl.
            let src = volume_source(axis);
            // Gas where its motion is not timelike (inside the horizon)
            // shows nothing.
            let moved = moving_ln_shift(seg, at, p);
            if moved.y == 0.0 {
                continue;
            }
            let ln_g = moved.x;
            if OBSERVE {
                let order = crossings + select(0u, 1u, pending_cross >= 0.0 && at > pending_cross);
                probe_light(ln_g, axis, order, travel_time(seg, at), PROBE_RADIUS | PROBE_ORDER | timed_bit(), vec2<f32>(0.0));
            }
            let j_dl = 0.5 * kappa * r * dl * odf(v + 4u) * src.y;
            shade_volume(src.x, through * j_dl * shown, light_ln(ln_g));
        }
        through *= exp(-dtau);
    }
    for (var c = 0u; c < n_clouds; c++) {
        if clouds[c].x > 0.0 {
            shade_cloud(P.at_clouds + c * CLOUD_WORDS, clouds[c].x, through, clouds[c].y);
        }
    }
    return worst;
}

// Integrator::march: the visible gas along `seg` from s0 to s1, cut where
// each medium begins or ends, each stretch between walked by the pieces'
// loop in pieces of the finest scale there (two of a medium's steps).
// Returns whether the ray is spent.
fn march(seg: Seg, s0: f32, s1: f32) -> bool {
    if !(s0 < s1) {
        return false;
    }
    // Each medium's span on the segment (0: the volume; 1 + c: cloud c),
    // and the cuts between them.
    var spans: array<vec2<f32>, 16>;
    var cuts: array<f32, 32>;
    var n_cuts = 0u;
    let v = P.at_volume;
    let n_clouds = min(P.n_clouds, MAX_CLOUDS);
    for (var m = 0u; m <= n_clouds; m++) {
        var iv = vec2<f32>(1.0, 0.0);
        if m == 0u {
            if v != NONE {
                iv = slab(seg.x0.z, seg.x1.z, odf(v + 7u));
            }
        } else {
            let rec = P.at_clouds + (m - 1u) * CLOUD_WORDS;
            iv = ball(seg.x0, seg.x1, od3(rec), odf(rec + 3u));
        }
        let span = vec2<f32>(max(iv.x, s0), min(iv.y, s1));
        spans[m] = span;
        if span.x < span.y {
            // Kept in order as they come (insertion).
            for (var k = 0u; k < 2u; k++) {
                let c = span[k];
                var i = n_cuts;
                while i > 0u && cuts[i - 1u] > c {
                    cuts[i] = cuts[i - 1u];
                    i -= 1u;
                }
                cuts[i] = c;
                n_cuts += 1u;
            }
        }
    }
    v_chord = length(seg.x1 - seg.x0);
    for (var k = 0u; k + 1u < n_cuts; k++) {
        let a = cuts[k];
        let b = cuts[k + 1u];
        if !(a < b) {
            continue;
        }
        let mid = 0.5 * (a + b);
        v_media = 0u;
        var scale = 3.4e38;
        for (var m = 0u; m <= n_clouds; m++) {
            let span = spans[m];
            if span.x < span.y && span.x <= mid && mid <= span.y {
                v_media |= 1u << m;
                var step: f32;
                if m == 0u {
                    step = odf(v + 6u);
                } else {
                    step = odf(P.at_clouds + (m - 1u) * CLOUD_WORDS + 6u);
                }
                scale = min(scale, 2.0 * step);
            }
        }
        if v_media != 0u {
            pieces_walk(seg, a, b, pieces_count(v_chord * (b - a), scale));
            if through < SPENT {
                return true;
            }
        }
    }
    return false;
}
