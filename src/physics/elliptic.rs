//! Elliptic integrals and functions for the closed-form rays: Carlson's
//! symmetric integrals R_F, R_C, R_D and R_J by the duplication theorem to
//! full double precision (Carlson 1995, "Numerical computation of real or
//! complex elliptic integrals"; DLMF 19.36), Legendre's incomplete
//! integrals written with them (DLMF 19.25), and the Jacobi amplitude and
//! sn by the arithmetic-geometric mean (DLMF 22.20).

/// Carlson's symmetric elliptic integral of the first kind,
/// R_F(x, y, z) = 1/2 int_0^inf dt / sqrt((t + x)(t + y)(t + z)), by the
/// duplication theorem (DLMF 19.36.1), to full double precision; at most
/// one argument may be 0.
pub fn carlson_rf(x: f64, y: f64, z: f64) -> f64 {
    let (x0, y0, z0) = (x, y, z);
    let (mut x, mut y, mut z) = (x, y, z);
    let a0 = (x0 + y0 + z0) / 3.0;
    // (3 eps)^(-1/8): the seventh-order series is then exact to rounding.
    const DUPLICATE_TO: f64 = RF_BOUND;
    let q = DUPLICATE_TO * (a0 - x0).abs().max((a0 - y0).abs()).max((a0 - z0).abs());
    let mut a = a0;
    let mut scale = 1.0;
    // Each round shrinks the spread fourfold: 60 cover any spread up to
    // 1e33 of the mean; past them the integral diverges (two arguments
    // 0), NaN.
    for _ in 0..=60 {
        if scale * q < a.abs() {
            break;
        }
        let (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        a = 0.25 * (a + lambda);
        scale *= 0.25;
    }
    if scale * q >= a.abs() {
        return f64::NAN;
    }
    rf_tail(a0, (x0, y0, z0), scale, a)
}

/// R_F(x, y, z) and R_D(x, y, z) from one duplication sequence (R_D adds
/// a division a round and its series); z > 0. [`carlson_fj`] with p = z
/// gives the same, but its general p's work cost a Schwarzschild
/// footprint 5% more.
pub fn carlson_rf_rd(x: f64, y: f64, z: f64) -> (f64, f64) {
    let (mut vx, mut vy, mut vz) = (x, y, z);
    let mean = (x + y + z) / 3.0;
    let a0d = (x + y + 3.0 * z) / 5.0;
    let spread = |a: f64| (a - x).abs().max((a - y).abs()).max((a - z).abs());
    let q = (RF_BOUND * spread(mean)).max(RJ_BOUND * spread(a0d));
    let (mut af, mut ad) = (mean, a0d);
    let mut scale = 1.0;
    let mut sum = 0.0;
    for _ in 0..=60 {
        if scale * q < af.abs().min(ad.abs()) {
            break;
        }
        let (sx, sy, sz) = (vx.sqrt(), vy.sqrt(), vz.sqrt());
        let lambda = sx * sy + sx * sz + sy * sz;
        sum += scale / (sz * (vz + lambda));
        vx = 0.25 * (vx + lambda);
        vy = 0.25 * (vy + lambda);
        vz = 0.25 * (vz + lambda);
        af = 0.25 * (af + lambda);
        ad = 0.25 * (ad + lambda);
        scale *= 0.25;
    }
    if scale * q >= af.abs().min(ad.abs()) {
        return (f64::NAN, f64::NAN);
    }
    (
        rf_tail(mean, (x, y, z), scale, af),
        rj_tail(a0d, (x, y, z), scale, ad) + 3.0 * sum,
    )
}

/// R_F at `v` and its derivative along `dv` (dR_F/dv_i = -R_D with v_i
/// distinguished / 6, DLMF 19.18.1), from R_F and one R_D: the three R_D
/// sum to 3 / sqrt(xyz) and, weighted by x, y, z, to 3 R_F (DLMF 19.21.9
/// and 19.21.10), so `dv` split into (1, 1, 1), v itself and the one
/// computed R_D's axis needs no other. That axis is the middle argument's,
/// whose complement's spread divides; where all three agree to 1e-3, the
/// three R_D are computed. All arguments > 0.
pub fn carlson_rf_rate(v: [f64; 3], dv: [f64; 3]) -> (f64, f64) {
    let mut idx = [0, 1, 2];
    idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let [k, j, l] = idx;
    if v[l] - v[k] <= 1e-3 * v[l] {
        let (r, g) = carlson_rf_grad(v[0], v[1], v[2]);
        return (r, g[0] * dv[0] + g[1] * dv[1] + g[2] * dv[2]);
    }
    let (r, dj) = carlson_rf_rd(v[k], v[l], v[j]);
    // dv = alpha (1, 1, 1) + beta v + gamma e_j.
    let beta = (dv[l] - dv[k]) / (v[l] - v[k]);
    let alpha = dv[k] - beta * v[k];
    let gamma = dv[j] - alpha - beta * v[j];
    let s = 3.0 / (v[0] * v[1] * v[2]).sqrt();
    (r, -(alpha * s + 3.0 * beta * r + gamma * dj) / 6.0)
}

/// R_F(x, y, z) and its gradient: dR_F/dx = -R_D(y, z, x) / 6 and so on
/// (DLMF 19.18.1), the three R_D from the one duplication sequence R_F
/// takes. An entry is infinite where its argument is 0 (R_F's slope there
/// is).
pub fn carlson_rf_grad(x: f64, y: f64, z: f64) -> (f64, [f64; 3]) {
    let v0 = [x, y, z];
    let mut v = v0;
    let mean = (x + y + z) / 3.0;
    let spread = (mean - x).abs().max((mean - y).abs()).max((mean - z).abs());
    // R_D's means (the distinguished argument counted three times) and the
    // worse of both integrals' bounds.
    let a0d: [f64; 3] = std::array::from_fn(|i| (x + y + z + 2.0 * v0[i]) / 5.0);
    let mut q = RF_BOUND * spread;
    for a in a0d {
        q = q.max(
            RJ_BOUND
                * spread
                    .max((a - x).abs())
                    .max((a - y).abs())
                    .max((a - z).abs()),
        );
    }
    let (mut af, mut ad) = (mean, a0d);
    let mut scale = 1.0;
    let mut sum = [0.0; 3];
    for _ in 0..=60 {
        if scale * q < af.abs().min(ad[0].abs()).min(ad[1].abs()).min(ad[2].abs()) {
            break;
        }
        let s = [v[0].sqrt(), v[1].sqrt(), v[2].sqrt()];
        let lambda = s[0] * s[1] + s[0] * s[2] + s[1] * s[2];
        for i in 0..3 {
            sum[i] += scale / (s[i] * (v[i] + lambda));
            v[i] = 0.25 * (v[i] + lambda);
            ad[i] = 0.25 * (ad[i] + lambda);
        }
        af = 0.25 * (af + lambda);
        scale *= 0.25;
    }
    if scale * q >= af.abs() {
        return (f64::NAN, [f64::NAN; 3]);
    }
    let rf = rf_tail(mean, (x, y, z), scale, af);
    let grad =
        std::array::from_fn(|i| -(rj_tail(a0d[i], (x, y, z), scale, ad[i]) + 3.0 * sum[i]) / 6.0);
    (rf, grad)
}

/// The duplications' targets for the seventh-order series (the error's
/// next term is of the eighth): R_F (3 eps)^(-1/8), R_J (eps / 4)^(-1/8).
const RF_BOUND: f64 = 78.895_969_078_640_8;
const RJ_BOUND: f64 = 107.634_741_152_475_46;

/// R_F's series once the duplications have shrunk the arguments' spread
/// about their mean `a` by `scale` (DLMF 19.36.1).
#[inline]
fn rf_tail(a0: f64, (x0, y0, _): (f64, f64, f64), scale: f64, a: f64) -> f64 {
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = -(xx + yy);
    let e2 = xx * yy - zz * zz;
    let e3 = xx * yy * zz;
    // Through the seventh order (DLMF 19.36.1): the duplications stop a
    // round earlier than with the fifth.
    (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0
        - 3.0 * e2 * e3 / 44.0
        - 5.0 * e2 * e2 * e2 / 208.0
        + 3.0 * e3 * e3 / 104.0
        + e2 * e2 * e3 / 16.0)
        / a.sqrt()
}

/// R_J's series term, likewise (Carlson 1995, eq. 2.19), without the
/// duplications' R_C sum.
#[inline]
fn rj_tail(a0: f64, (x0, y0, z0): (f64, f64, f64), scale: f64, a: f64) -> f64 {
    let xx = (a0 - x0) * scale / a;
    let yy = (a0 - y0) * scale / a;
    let zz = (a0 - z0) * scale / a;
    let pp = -0.5 * (xx + yy + zz);
    let e2 = xx * yy + xx * zz + yy * zz - 3.0 * pp * pp;
    let e3 = xx * yy * zz + 2.0 * e2 * pp + 4.0 * pp * pp * pp;
    let e4 = (2.0 * xx * yy * zz + e2 * pp + 3.0 * pp * pp * pp) * pp;
    let e5 = xx * yy * zz * pp * pp;
    // Through the seventh order (DLMF 19.36.2), as R_F's.
    let series = 1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0
        - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0
        + 3.0 * e5 / 26.0
        - e2 * e2 * e2 / 16.0
        + 3.0 * e3 * e3 / 40.0
        + 3.0 * e2 * e4 / 20.0
        + 45.0 * e2 * e2 * e3 / 272.0
        - 9.0 * (e3 * e4 + e2 * e5) / 68.0;
    scale * series / (a * a.sqrt())
}

/// Carlson's R_C(x, y) = R_F(x, y, y), x >= 0, y != 0; for y < 0 the
/// Cauchy principal value (DLMF 19.2.20).
pub fn carlson_rc(x: f64, y: f64) -> f64 {
    if y < 0.0 {
        // DLMF 19.2.20: R_C(x, y) = sqrt(x / (x - y)) R_C(x - y, -y).
        return (x / (x - y)).sqrt() * carlson_rc(x - y, -y);
    }
    let (x0, y0) = (x, y);
    let (mut x, mut y) = (x, y);
    let a0 = (x0 + 2.0 * y0) / 3.0;
    // (3 eps)^(-1/8): the series to s^7 is then exact to rounding.
    const DUPLICATE_TO: f64 = 78.895_969_078_640_8;
    let q = DUPLICATE_TO * (a0 - x0).abs();
    let mut a = a0;
    let mut scale = 1.0;
    // Each round shrinks the spread fourfold: 60 cover any spread up to
    // 1e33 of the mean; past them the integral diverges (two arguments
    // 0), NaN.
    for _ in 0..=60 {
        if scale * q < a.abs() {
            break;
        }
        let lambda = 2.0 * x.sqrt() * y.sqrt() + y;
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        a = 0.25 * (a + lambda);
        scale *= 0.25;
    }
    if scale * q >= a.abs() {
        return f64::NAN;
    }
    let s = (y0 - a0) * scale / a;
    let s2 = s * s;
    (1.0 + s2
        * (0.3
            + s * (1.0 / 7.0
                + s * (0.375 + s * (9.0 / 22.0 + s * (159.0 / 208.0 + s * (9.0 / 8.0)))))))
        / a.sqrt()
}

/// Carlson's symmetric integral of the third kind,
/// R_J(x, y, z, p) = 3/2 int_0^inf dt / ((t + p) sqrt((t + x)(t + y)(t + z))),
/// x, y, z >= 0 with at most one 0, p != 0; for p < 0 the Cauchy
/// principal value (Carlson 1995, eq. 2.22); by [`carlson_fj`]'s
/// duplication.
pub fn carlson_rj(x: f64, y: f64, z: f64, p: f64) -> f64 {
    carlson_fj(x, y, z, [p]).1[0]
}

/// R_C(1, 1 + e), e > -1, in closed form (DLMF 19.2.19-20): atan(sqrt e) /
/// sqrt e, atanh(sqrt(-e)) / sqrt(-e), by its series near 0.
#[inline]
fn rc_one(e: f64) -> f64 {
    // e shrinks 64-fold each duplication: most calls take the short series.
    if e.abs() < 1e-5 {
        // 1 - e/3 + e^2/5 - e^3/7: the next term is below 1e-21.
        1.0 + e * (-1.0 / 3.0 + e * (0.2 - e / 7.0))
    } else if e.abs() < 1e-3 {
        // ... - e^5/11: the next term is below 1e-19.
        1.0 + e * (-1.0 / 3.0 + e * (0.2 + e * (-1.0 / 7.0 + e * (1.0 / 9.0 - e / 11.0))))
    } else if e > 0.0 {
        let s = e.sqrt();
        s.atan() / s
    } else {
        let s = (-e).sqrt();
        s.atanh() / s
    }
}

/// R_F(x, y, z) and R_J(x, y, z, p_i) for several p_i at once (one
/// duplication sequence of x, y, z serves them all); x, y, z >= 0 with at
/// most one 0, p_i != 0 (the principal value for p_i < 0, as
/// [`carlson_rj`]).
#[inline]
pub fn carlson_fj<const N: usize>(x: f64, y: f64, z: f64, p: [f64; N]) -> (f64, [f64; N]) {
    let (rf, _, rj) = carlson_fj_rooted::<N, false>((x, y, z), (x.sqrt(), y.sqrt(), z.sqrt()), p);
    (rf, rj)
}

/// [`carlson_fj`] with the square roots of x, y and z known (the
/// duplication's first round takes them), and with `D` R_D(x, y, z) too
/// (R_J at p = z, for a division a round where a general p takes an R_C).
fn carlson_fj_rooted<const N: usize, const D: bool>(
    (x, y, z): (f64, f64, f64),
    roots: (f64, f64, f64),
    p: [f64; N],
) -> (f64, f64, [f64; N]) {
    // A negative p by Carlson's transformation to q > 0 (as carlson_rj).
    let (lo, hi) = (x.min(y).min(z), x.max(y).max(z));
    let mid = x + y + z - lo - hi;
    let q: [f64; N] = std::array::from_fn(|i| {
        if p[i] < 0.0 {
            mid + (hi - mid) * (mid - lo) / (mid - p[i])
        } else {
            p[i]
        }
    });
    let (x0, y0, z0) = (x, y, z);
    let (mut x, mut y, mut z) = (x, y, z);
    let mut pp = q;
    let a0f = (x0 + y0 + z0) / 3.0;
    let a0j: [f64; N] = std::array::from_fn(|i| (x0 + y0 + z0 + 2.0 * q[i]) / 5.0);
    let delta: [f64; N] = std::array::from_fn(|i| (q[i] - x0) * (q[i] - y0) * (q[i] - z0));
    // Both integrals' bounds (see carlson_rf and carlson_rj): duplicate
    // until the worse is met.
    let spread = |a: f64, extra: f64| {
        (a - x0)
            .abs()
            .max((a - y0).abs())
            .max((a - z0).abs())
            .max(extra)
    };
    let qf = RF_BOUND * spread(a0f, 0.0);
    let a0d = (x0 + y0 + 3.0 * z0) / 5.0;
    let qd = RJ_BOUND * spread(a0d, 0.0);
    let (mut ad, mut sum_d) = (a0d, 0.0);
    let mut qj = [0.0; N];
    for i in 0..N {
        qj[i] = RJ_BOUND * spread(a0j[i], (a0j[i] - q[i]).abs());
    }
    let (mut af, mut aj) = (a0f, a0j);
    let mut scale = 1.0;
    let mut sum = [0.0; N];
    // As carlson_rf: NaN where the integrals diverge.
    let (mut sx, mut sy, mut sz) = roots;
    for round in 0..=61 {
        let mut more = scale * qf >= af.abs() || D && scale * qd >= ad.abs();
        for i in 0..N {
            more |= scale * qj[i] >= aj[i].abs();
        }
        if !more {
            break;
        }
        if round == 61 {
            return (f64::NAN, f64::NAN, [f64::NAN; N]);
        }
        if round > 0 {
            (sx, sy, sz) = (x.sqrt(), y.sqrt(), z.sqrt());
        }
        let lambda = sx * sy + sx * sz + sy * sz;
        if D {
            sum_d += scale / (sz * (z + lambda));
            ad = 0.25 * (ad + lambda);
        }
        for i in 0..N {
            let sp = pp[i].sqrt();
            let inv_d = 1.0 / ((sp + sx) * (sp + sy) * (sp + sz));
            let e = delta[i] * scale * scale * scale * inv_d * inv_d;
            sum[i] += scale * rc_one(e) * inv_d;
            pp[i] = 0.25 * (pp[i] + lambda);
            aj[i] = 0.25 * (aj[i] + lambda);
        }
        x = 0.25 * (x + lambda);
        y = 0.25 * (y + lambda);
        z = 0.25 * (z + lambda);
        af = 0.25 * (af + lambda);
        scale *= 0.25;
    }
    let rf = rf_tail(a0f, (x0, y0, z0), scale, af);
    let rj: [f64; N] = std::array::from_fn(|i| {
        let rj_q = rj_tail(a0j[i], (x0, y0, z0), scale, aj[i]) + 6.0 * sum[i];
        if p[i] < 0.0 {
            let b = q[i] - mid;
            (b * rj_q - 3.0 * rf + 3.0 * carlson_rc(lo * hi / mid, p[i] * q[i] / mid))
                / (mid - p[i])
        } else {
            rj_q
        }
    });
    let rd = if D {
        rj_tail(a0d, (x0, y0, z0), scale, ad) + 3.0 * sum_d
    } else {
        0.0
    };
    (rf, rd, rj)
}

/// Bulirsch's general complete elliptic integral cel(kc, p, a, b) = int_0^(pi
/// / 2) (a cos^2 t + b sin^2 t) / ((cos^2 t + p sin^2 t) sqrt(cos^2 t + kc^2
/// sin^2 t)) dt, kc != 0 (the principal value for p < 0), by its
/// quadratically convergent Gauss transformation (Bulirsch 1969): K(m) =
/// cel(sqrt(1 - m), 1, 1, 1), Pi(n | m) = cel(sqrt(1 - m), 1 - n, 1, 1).
/// NaN for arguments that are not finite.
#[inline]
pub fn bulirsch_cel(kc: f64, p: f64, a: f64, b: f64) -> f64 {
    bulirsch_cel_many(kc, [(p, a, b)])[0]
}

/// [`bulirsch_cel`] of one kc for several (p, a, b): the Gauss
/// transformation's kc and means do not depend on them, so one sequence
/// serves all.
pub fn bulirsch_cel_many<const N: usize>(kc: f64, pab: [(f64, f64, f64); N]) -> [f64; N] {
    let mut kc = kc.abs();
    let mut e = kc;
    let mut mu = 1.0;
    let mut state = pab.map(|(p, a, b)| {
        if p > 0.0 {
            let p = p.sqrt();
            (p, a, b / p)
        } else {
            // p < 0: to a positive p by the transformation of the third
            // kind.
            let k2 = kc * kc;
            let f = k2 - p;
            let g = 1.0 - p;
            let q = (1.0 - k2) * (b - a * p);
            let p = (f / g).sqrt();
            let a = (a - b) / g;
            (p, a, -q / (g * g * p) + a * p)
        }
    });
    // Quadratic convergence: 12 rounds reach any kc in (1e-300, 1e300);
    // the bound keeps a NaN from looping.
    for _ in 0..64 {
        for (p, a, b) in &mut state {
            let f = *a;
            *a += *b / *p;
            let g = e / *p;
            *b = 2.0 * (*b + f * g);
            *p += g;
        }
        let mu_last = mu;
        mu += kc;
        // The error is the square of the means' gap: 1e-8 gives 1e-16.
        if (mu_last - kc).abs() <= 1e-8 * mu_last {
            break;
        }
        kc = 2.0 * e.sqrt();
        e = kc * mu;
    }
    state.map(|(p, a, b)| std::f64::consts::FRAC_PI_2 * (b + a * mu) / (mu * (mu + p)))
}

/// Legendre's F(phi | m) and Pi(n_i; phi | m) for several n_i at once, at
/// the amplitude of sine `s` and cosine `c` >= 0 (|phi| <= pi / 2; DLMF
/// 19.25.5, 19.25.14; the principal value where n_i sin^2 phi > 1).
pub fn legendre_f_pi<const N: usize>(s: f64, c: f64, m: f64, n: [f64; N]) -> (f64, [f64; N]) {
    let (f, j) = legendre_f_j(s, c, m, n);
    (f, std::array::from_fn(|i| f + n[i] * j[i]))
}

/// Legendre's F(phi | m) and J_i = (Pi(n_i; phi | m) - F) / n_i =
/// sin^3 phi R_J(cos^2 phi, 1 - m sin^2 phi, 1, 1 - n_i sin^2 phi) / 3 at
/// the amplitude of sine `s` and cosine `c` >= 0, from one duplication
/// sequence: J at n = 0 is D(phi | m) = int_0^phi sin^2 t / sqrt(1 - m
/// sin^2 t) dt = (F - E) / m without the cancellation (DLMF 19.25.13).
pub fn legendre_f_j<const N: usize>(s: f64, c: f64, m: f64, n: [f64; N]) -> (f64, [f64; N]) {
    let (f, _, j) = legendre_f_d_j_as::<N, false>(s, c, m, n);
    (f, j)
}

/// [`legendre_f_j`] with D(phi | m) beside (J at n = 0) from the same
/// duplication sequence, at the cost of R_D's term rather than a general
/// characteristic's.
pub fn legendre_f_d_j<const N: usize>(s: f64, c: f64, m: f64, n: [f64; N]) -> (f64, f64, [f64; N]) {
    legendre_f_d_j_as::<N, true>(s, c, m, n)
}

/// [`legendre_f_d_j`], D only with `D` (0 otherwise).
#[inline]
fn legendre_f_d_j_as<const N: usize, const D: bool>(
    s: f64,
    c: f64,
    m: f64,
    n: [f64; N],
) -> (f64, f64, [f64; N]) {
    let (c2, d2) = (c * c, 1.0 - m * s * s);
    let s3 = s * s * s / 3.0;
    // sqrt(cos^2) and sqrt(1) are known.
    let (rf, rd, rj) = carlson_fj_rooted::<N, D>(
        (c2, d2, 1.0),
        (c, d2.sqrt(), 1.0),
        n.map(|n| 1.0 - n * s * s),
    );
    (s * rf, s3 * rd, rj.map(|j| s3 * j))
}

/// Jacobi's sn, cn and dn of (u | m), m < 1, by the descending Landen
/// transformation with a single sine and cosine (Bulirsch 1965; m < 0
/// through the same means from sqrt(1 - m) > 1).
pub fn jacobi_sn_cn_dn(u: f64, m: f64) -> (f64, f64, f64) {
    if m.abs() < 1e-18 {
        let (s, c) = u.sin_cos();
        return (s, c, 1.0);
    }
    let mut em = [0.0f64; 16];
    let mut en = [0.0f64; 16];
    let mut emc = 1.0 - m;
    let mut a = 1.0;
    let mut c = 1.0;
    let mut l = 0;
    for i in 0..16 {
        l = i;
        em[i] = a;
        emc = emc.sqrt();
        en[i] = emc;
        c = 0.5 * (a + emc);
        if (a - emc).abs() <= 1e-9 * a {
            // Quadratic convergence: the next mean is exact to 1e-18.
            break;
        }
        emc *= a;
        a = c;
    }
    let (sn, cn) = (u * c).sin_cos();
    let mut dn = 1.0;
    if sn == 0.0 {
        return (sn, cn, dn);
    }
    let mut a = cn / sn;
    let mut c = c * a;
    for i in (0..=l).rev() {
        let b = em[i];
        a *= c;
        c *= dn;
        dn = (en[i] + a) / (b + a);
        a = c / b;
    }
    let a = 1.0 / (c * c + 1.0).sqrt();
    let sn = if sn >= 0.0 { a } else { -a };
    (sn, c * sn, dn)
}

/// Carlson's R_D(x, y, z) = R_J(x, y, z, z), the integral of the second
/// kind; z > 0.
pub fn carlson_rd(x: f64, y: f64, z: f64) -> f64 {
    carlson_rj(x, y, z, z)
}

/// Legendre's F(phi | m) = int_0^phi dt / sqrt(1 - m sin^2 t) for
/// |phi| <= pi / 2, m sin^2 phi <= 1 (DLMF 19.25.5).
pub fn legendre_f(phi: f64, m: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s * carlson_rf(c * c, 1.0 - m * s * s, 1.0)
}

/// Legendre's E(phi | m) = int_0^phi sqrt(1 - m sin^2 t) dt for |phi| <=
/// pi / 2 (DLMF 19.25.9).
pub fn legendre_e(phi: f64, m: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let (c2, d2) = (c * c, 1.0 - m * s * s);
    s * carlson_rf(c2, d2, 1.0) - m * s * s * s * carlson_rd(c2, d2, 1.0) / 3.0
}

/// Legendre's Pi(n; phi | m) = int_0^phi dt / ((1 - n sin^2 t) sqrt(1 - m
/// sin^2 t)) for |phi| <= pi / 2, the principal value where n sin^2 phi > 1
/// (DLMF 19.25.14).
pub fn legendre_pi(n: f64, phi: f64, m: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let (c2, d2) = (c * c, 1.0 - m * s * s);
    s * carlson_rf(c2, d2, 1.0) + n * s * s * s * carlson_rj(c2, d2, 1.0, 1.0 - n * s * s) / 3.0
}

/// Jacobi sn(u | m), m <= 1.
pub fn jacobi_sn(u: f64, m: f64) -> f64 {
    if m >= 1.0 {
        return u.tanh();
    }
    jacobi_am(u, m).sin()
}

/// The Jacobi amplitude am(u | m), m < 1 (sn = sin am, cn = cos am), by
/// the arithmetic-geometric mean (descending Landen; DLMF 22.20; for m < 0
/// the means start from b = sqrt(1 - m) > 1 and the same recursion holds).
pub fn jacobi_am(u: f64, m: f64) -> f64 {
    if m.abs() < 1e-18 {
        return u;
    }
    let mut a = [1.0f64; 16];
    let mut c = [0.0f64; 16];
    let mut b = (1.0 - m).sqrt();
    // Only its size matters (it starts the loop).
    c[0] = m.abs().sqrt();
    let mut n = 0;
    while c[n].abs() > f64::EPSILON * a[n] && n < 15 {
        let an = a[n];
        a[n + 1] = 0.5 * (an + b);
        c[n + 1] = 0.5 * (an - b);
        b = (an * b).sqrt();
        n += 1;
    }
    let mut phi = (1u64 << n) as f64 * a[n] * u;
    for k in (1..=n).rev() {
        phi = 0.5 * (phi + (c[k] / a[k] * phi.sin()).asin());
    }
    phi
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Legendre's F(phi | m) for any real phi (m < 1): F(phi + j pi) =
    /// F(phi) + 2 j K(m).
    fn legendre_f_any(phi: f64, m: f64) -> f64 {
        let j = (phi / std::f64::consts::PI).round();
        legendre_f(phi - j * std::f64::consts::PI, m) + 2.0 * j * carlson_rf(0.0, 1.0 - m, 1.0)
    }

    /// The complete Pi(n | m) by Carlson's integrals (the principal value
    /// for n > 1), to check Bulirsch's.
    fn complete_pi(n: f64, m: f64) -> f64 {
        carlson_rf(0.0, 1.0 - m, 1.0) + n * carlson_rj(0.0, 1.0 - m, 1.0, 1.0 - n) / 3.0
    }

    fn close(got: f64, want: f64, rel: f64) -> bool {
        (got - want).abs() <= rel * want.abs().max(1e-300)
    }

    #[test]
    fn the_duplication_bounds_are_the_precision_targets() {
        // R_F and R_C: (3 eps)^(-1/8); R_J: (eps / 4)^(-1/8) (seventh-order
        // series).
        let eps = f64::EPSILON;
        assert!(close((3.0 * eps).powf(-1.0 / 8.0), RF_BOUND, 1e-15));
        assert!(close((0.25 * eps).powf(-1.0 / 8.0), RJ_BOUND, 1e-15));
    }

    #[test]
    fn carlson_rf_matches_dlmf_values() {
        // DLMF 19.20: R_F(0, 1, 2) = 1.31102 87771 46059 905...; R_F(x,x,x) = x^-1/2;
        // R_F(0, 1, 1) = pi / 2.
        assert!((carlson_rf(0.0, 1.0, 2.0) - 1.311_028_777_146_059_9).abs() < 1e-15);
        assert!((carlson_rf(4.0, 4.0, 4.0) - 0.5).abs() < 1e-15);
        assert!((carlson_rf(0.0, 1.0, 1.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        // R_F(1, 2, 3) = 0.72694 59354 68908 2 (mpmath).
        assert!((carlson_rf(1.0, 2.0, 3.0) - 0.726_945_935_468_908_2).abs() < 1e-15);
    }

    #[test]
    fn carlson_rc_rd_rj_match_reference_values() {
        // Carlson (1995) table 1 where it has them, the rest mpmath 1.3
        // (elliprc, elliprd, elliprj; the real part where p < 0 or y < 0),
        // to 30 digits, rounded.
        for (x, y, want) in [
            (0.0, 0.25, std::f64::consts::PI),
            (2.25, 2.0, std::f64::consts::LN_2),
            (0.25, -2.0, 0.231_049_060_186_648_45),
            (1.0, 1.0, 1.0),
            (0.3, 1e-6, 12.778_233_784_659_48),
            (1e-8, 2.0, 1.110_670_737_316_226_8),
            (5.0, 0.2, 1.046_347_114_131_571_7),
        ] {
            let got = carlson_rc(x, y);
            assert!(
                close(got, want, 4e-16),
                "R_C({x}, {y}) = {got:e}, want {want:e}"
            );
        }
        for ((x, y, z, p), want) in [
            ((0.0, 1.0, 2.0, 3.0), 0.776_886_237_785_823_3),
            ((2.0, 3.0, 4.0, 5.0), 0.142_975_796_671_567_54),
            ((2.0, 3.0, 4.0, -0.5), 0.247_238_197_030_515_64),
            ((2.0, 3.0, 4.0, -5.0), -0.127_112_300_429_639_1),
            ((1e-8, 1.0, 2.0, 0.5), 2.936_247_063_179_825_6),
            ((0.5, 1.5, 3.5, 1e-3), 5.960_364_834_634_205_5),
            ((1.0, 1.0, 1.0, 1.0), 1.0),
            ((0.2, 0.4, 9.0, 100.0), 0.020_482_753_253_322_83),
            ((3.0, 1.0, 2.0, -1e-3), 4.177_944_887_618_635),
        ] {
            let got = carlson_rj(x, y, z, p);
            assert!(
                close(got, want, 1e-15),
                "R_J({x}, {y}, {z}, {p}) = {got:e}, want {want:e}"
            );
        }
        for ((x, y, z), want) in [
            ((0.0, 2.0, 1.0), 1.797_210_352_103_388_4),
            ((2.0, 3.0, 4.0), 0.165_105_272_942_610_54),
            ((1e-8, 1.0, 3.0), 0.664_853_324_568_665_7),
            ((1.0, 1.0, 1.0), 1.0),
            ((0.5, 2.0, 0.1), 5.988_220_971_017_105),
        ] {
            let got = carlson_rd(x, y, z);
            assert!(
                close(got, want, 1e-15),
                "R_D({x}, {y}, {z}) = {got:e}, want {want:e}"
            );
        }
    }

    #[test]
    fn legendres_integrals_match_reference_values() {
        // mpmath 1.3: ellipe(phi, m), ellippi(n, phi, m).
        assert!(close(legendre_e(1.0, 0.5), 0.927_329_883_624_44, 1e-15));
        assert!(close(legendre_e(1.4, 0.99), 0.992_647_332_853_851_1, 1e-15));
        for (n, phi, m, want) in [
            (0.3, 1.0, 0.5, 1.192_325_436_934_558_2),
            (-0.7, 1.2, 0.9, 1.237_332_354_491_279_8),
            (1.5, 0.4, 0.3, 0.439_801_149_988_648_67),
            (0.9, 1.5, 0.99, 13.821_106_013_751_473),
        ] {
            let got = legendre_pi(n, phi, m);
            assert!(
                close(got, want, 1e-14),
                "Pi({n}; {phi} | {m}) = {got:e}, want {want:e}"
            );
        }
    }

    #[test]
    fn jacobi_sn_inverts_the_first_integral() {
        // sn(F(phi | m) | m) = sin phi.
        for m in [0.0, 0.1, 0.5, 0.9, 0.999_999] {
            for phi in [0.1, 0.7, 1.2, 1.5] {
                let f = legendre_f(phi, m);
                assert!(
                    (jacobi_sn(f, m) - phi.sin()).abs() < 1e-14,
                    "m {m} phi {phi}"
                );
            }
        }
    }

    #[test]
    fn jacobi_functions_and_the_amplitude_agree_beyond_a_period() {
        // am(F(phi | m) | m) = phi for phi over several half periods and
        // negative parameters (the polar motion's), and Bulirsch's sn, cn,
        // dn are sin am, cos am and sqrt(1 - m sn^2).
        for m in [-20.0, -3.0, -0.3, 0.0, 0.5, 0.99, 0.999_999] {
            for phi in [-4.0, -1.2, 0.3, 1.5, 2.0, 3.1, 7.7, 12.0] {
                let u = legendre_f_any(phi, m);
                let am = jacobi_am(u, m);
                assert!(
                    (am - phi).abs() < 1e-13 * phi.abs().max(1.0),
                    "m {m} phi {phi}: am {am}"
                );
                let (sn, cn, dn) = jacobi_sn_cn_dn(u, m);
                let (s, c) = phi.sin_cos();
                assert!(
                    (sn - s).abs() < 1e-14 && (cn - c).abs() < 1e-14,
                    "m {m} phi {phi}: sn {sn} cn {cn}"
                );
                assert!(
                    close(dn, (1.0 - m * s * s).sqrt(), 1e-14),
                    "m {m} phi {phi}: dn {dn} want {}",
                    (1.0 - m * s * s).sqrt()
                );
            }
        }
    }

    #[test]
    fn the_shared_duplication_gives_each_integral() {
        // R_F and several R_J (principal values too) from one sequence of
        // x, y, z: R_F against its own routine, each R_J as when asked
        // alone (carlson_rj, checked against Carlson's table).
        for (x, y, z) in [
            (0.0, 0.4, 1.0),
            (0.3, 0.9, 1.0),
            (1e-3, 2.0, 1.0),
            (0.9, 1.0, 1.0),
        ] {
            let p = [0.7, 2.5, -0.4, 1e-3];
            let (rf, rj) = carlson_fj(x, y, z, p);
            assert!(close(rf, carlson_rf(x, y, z), 4e-16), "{x} {y} {z}");
            for (i, &pi) in p.iter().enumerate() {
                let want = carlson_rj(x, y, z, pi);
                assert!(
                    close(rj[i], want, 1e-14),
                    "{x} {y} {z} {pi}: {} {want}",
                    rj[i]
                );
            }
        }
        for (phi, m) in [(0.3, 0.5), (1.2, -2.0), (-1.0, 0.99)] {
            let n = [0.3, -1.5, 0.9];
            let (f, pi) = legendre_f_pi(f64::sin(phi), f64::cos(phi), m, n);
            assert!(close(f, legendre_f(phi, m), 1e-15));
            for i in 0..3 {
                assert!(close(pi[i], legendre_pi(n[i], phi, m), 1e-14));
            }
        }
    }

    #[test]
    fn r_fs_gradient_is_the_three_r_d() {
        // Against R_D asked alone (checked against Carlson's table) and
        // against central differences of R_F.
        for (x, y, z) in [
            (0.2, 0.4, 1.0),
            (1e-3, 2.0, 1.0),
            (3.0, 3.0, 3.0),
            (1e-9, 0.5, 70.0),
        ] {
            let (rf, g) = carlson_rf_grad(x, y, z);
            assert!(close(rf, carlson_rf(x, y, z), 4e-16), "{x} {y} {z}");
            let want = [
                carlson_rd(y, z, x),
                carlson_rd(z, x, y),
                carlson_rd(x, y, z),
            ];
            for i in 0..3 {
                assert!(
                    close(g[i], -want[i] / 6.0, 1e-14),
                    "{x} {y} {z} [{i}]: {}",
                    g[i]
                );
            }
            let (r, d) = carlson_rf_rd(x, y, z);
            assert!(
                close(r, rf, 4e-16) && close(d, want[2], 1e-14),
                "{x} {y} {z}"
            );
            let h = 1e-4 * x.min(y).min(z);
            let fd = (carlson_rf(x + h, y, z) - carlson_rf(x - h, y, z)) / (2.0 * h);
            assert!(close(g[0], fd, 1e-6), "{x} {y} {z}: {} {fd}", g[0]);
        }
    }

    #[test]
    fn legendres_d_beside_f_and_j_is_j_at_n_zero() {
        // D from R_D's own term of the duplication sequence against J at n
        // = 0 (a general characteristic's term) and against its definition
        // (F - E) / m; F and J as asked alone.
        for (phi, m, n) in [
            (0.3, 0.5, 0.2),
            (1.4, -3.0, 0.9),
            (1.0, 0.99, -4.0),
            (0.05, 0.2, 0.5),
        ] {
            let (s, c) = f64::sin_cos(phi);
            let (f, d, [j]) = legendre_f_d_j(s, c, m, [n]);
            let (f0, [j0, d0]) = legendre_f_j(s, c, m, [n, 0.0]);
            let by_e = (legendre_f(phi, m) - legendre_e(phi, m)) / m;
            assert!(
                close(f, f0, 1e-15) && close(j, j0, 1e-14) && close(d, d0, 1e-14),
                "{phi} {m} {n}: {f} {f0} {j} {j0} {d} {d0}"
            );
            assert!(close(d, by_e, 1e-12), "{phi} {m}: {d} {by_e}");
        }
    }

    #[test]
    fn r_fs_rate_from_one_r_d_is_the_gradients() {
        // Spread arguments, two near each other, all three within 2e-3
        // (the closest that takes one R_D), 1e-5 and 1e-7 (the gradient's
        // own path): along several directions.
        for v in [
            [0.2, 0.4, 1.0],
            [1e-3, 2.0, 1.0],
            [0.5, 0.5 + 1e-9, 3.0],
            [1.0, 1.0 + 1e-3, 1.0 - 1e-3],
            [1.0, 1.0 + 1e-5, 1.0 - 1e-5],
            [2.0, 2.0 + 1e-7, 2.0 - 2e-7],
            [7e-9, 3e-4, 0.2],
        ] {
            let (r, g) = carlson_rf_grad(v[0], v[1], v[2]);
            for dv in [
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.3, -2.0, 0.7],
            ] {
                let want = g[0] * dv[0] + g[1] * dv[1] + g[2] * dv[2];
                let (rr, got) = carlson_rf_rate(v, dv);
                let scale = g[0].abs().max(g[1].abs()).max(g[2].abs());
                assert!(close(rr, r, 4e-16), "{v:?}");
                assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "{v:?} {dv:?}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn bulirschs_complete_integrals_are_carlsons() {
        for m in [-30.0f64, -2.0, -0.1, 0.0, 0.3, 0.9, 0.999_999] {
            let kc = (1.0 - m).sqrt();
            let k = carlson_rf(0.0, 1.0 - m, 1.0);
            assert!(close(bulirsch_cel(kc, 1.0, 1.0, 1.0), k, 2e-15), "K({m})");
            for n in [-5.0, -0.5, 0.2, 0.95, 1.5, 7.0] {
                // Carlson's principal value loses digits as m -> 1 (to
                // 1e-11 at 1 - 1e-6) and where its terms cancel (to 1e-14
                // at 7 | -0.1); mpmath's real part there.
                let want = match (n, m) {
                    (1.5, 0.999_999) => -13.780_438_422_408_798,
                    (7.0, 0.999_999) => -1.206_979_566_474_593_2,
                    (7.0, -0.1) => 0.010_709_588_150_784_717,
                    _ => complete_pi(n, m),
                };
                let got = bulirsch_cel(kc, 1.0 - n, 1.0, 1.0);
                assert!(close(got, want, 1e-14), "Pi({n} | {m}): {got} vs {want}");
            }
        }
    }
}
