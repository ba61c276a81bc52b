#!/usr/bin/env python3
"""High-precision reference values for the Schwarzschild lens oracle
(validation/tests/common/lens.rs, checked in validation/tests/lens_oracle.rs).

Units r_s = 1. A static camera at r_o sees, at the angle theta from the
hole, the ray of impact parameter b = r_o sin(theta) / sqrt(1 - 1/r_o); it
sweeps Phi = int du / sqrt(G(u)), G = 1/b^2 - u^2 + u^3, to infinity
(inwards through the periapsis when theta < pi/2). Computed with mpmath at
45 digits: tanh-sinh quadrature, the turning point removed by u = u_p - s^2
with G(u_p - s^2) / s^2 evaluated as is (no algebra shared with the Rust
oracle), dPhi/dtheta by Richardson-extrapolated central differences.

    python3 -m pip install mpmath
    python3 validation/lens_reference.py
"""

import mpmath as mp

mp.mp.dps = 45


def swept(r_o, theta):
    r_o, theta = mp.mpf(r_o), mp.mpf(theta)
    u_o = 1 / r_o
    b = r_o * mp.sin(theta) / mp.sqrt(1 - u_o)
    c = 1 / b**2
    g = lambda u: c - u**2 + u**3
    if b <= 3 * mp.sqrt(3) / 2:
        assert mp.cos(theta) < 0, "captured"
        return mp.quad(lambda u: 1 / mp.sqrt(g(u)), [0, u_o])
    lo, hi = mp.mpf(0), mp.mpf(2) / 3  # g falls on [0, 2/3]
    for _ in range(300):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if g(mid) > 0 else (lo, mid)
    p = (lo + hi) / 2
    f = lambda s: 2 / mp.sqrt(g(p - s * s) / (s * s))
    # Break points graded towards s = 0, where a nearly critical ray peaks.
    width = mp.sqrt(abs(2 * p - 3 * p * p))
    def integral(a, z):
        inner = [width * 10**j for j in range(12) if a < width * 10**j < z]
        return mp.re(mp.quad(f, [a] + inner + [z]))
    s_p, s_o = mp.sqrt(p), mp.sqrt(max(p - u_o, 0))
    if mp.cos(theta) > 0:
        return integral(0, s_p) + integral(0, s_o)
    return integral(s_o, s_p)


def rate(r_o, theta):
    theta = mp.mpf(theta)
    h = mp.mpf(10) ** -7 * min(theta, mp.pi - theta)
    central = lambda h: (swept(r_o, theta + h) - swept(r_o, theta - h)) / (2 * h)
    return (4 * central(h) - central(2 * h)) / 3


CASES = [(10, "0.26"), (10, "0.9"), (10, "1.5707963267948966"), (10, "2.0"), (10, "3.0"),
         (3, "0.8"), (1e6, "3e-6"), (1e6, "1.0")]

if __name__ == "__main__":
    print("(r_o, theta, Phi, dPhi/dtheta)")
    for r_o, theta in CASES:
        t = mp.mpf(float(theta))  # the f64 the tests pass
        # Rounded to the nearest f64, printed as the shortest literal that
        # reads back as it.
        print(f"({float(r_o)!r}, {theta}, {float(swept(r_o, t))!r}, {float(rate(r_o, t))!r}),")
