#!/usr/bin/env python3
"""Reference spectra and their colours from colour-science.

Writes validation/reference/spectra.csv (the input spectra on the renderer's
default grid, 380-780 nm at 5 nm) and validation/reference/expected.csv (their
XYZ, linear sRGB and encoded sRGB computed by colour-science). The Rust test
suite (validation/tests/colour.rs) runs the renderer's pipeline on the same
spectra and compares; check_colour.py does the same live through
`blackhole colour`.

Spectra:
  bb_<T>    Planck blackbodies, 1000-40000 K, scaled to Y = 1
  cc_<i>    the 24 ColorChecker patches (N Ohta) under D65, Y_white = 1
  mono_<nm> monochromatic lines on the grid (out of the sRGB gamut)
  rnd_<i>   random spectra (numpy default_rng(2026), uniform in [0, 1])

XYZ is colour-science's 'Integration' method on the same grid with k = 1 and
an all-ones illuminant, times 100 (colour scales that case to 0-100): that is
sum(S * cmf) * 5 nm. Linear sRGB uses colour's XYZ_to_RGB('sRGB') (the IEC 61966-2-1
matrix); encoded sRGB is eotf_inverse_sRGB of the values clipped to [0, 1]:
our PNG policy for out-of-gamut colours is per-channel clipping.
"""

import argparse
import csv
import os
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
import numpy as np  # noqa: E402

SHAPE = colour.SpectralShape(380, 780, 5)
HERE = os.path.dirname(os.path.abspath(__file__))


def cmfs():
    return colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(SHAPE)


def spectra():
    """(id, values on SHAPE) of every reference spectrum."""
    wl = SHAPE.wavelengths
    out = []
    cm = cmfs()
    ybar = cm.values[:, 1]
    for t in [1000, 1500, 2000, 3000, 4000, 5000, 5800, 6504, 8000, 10000, 15000, 20000, 30000, 40000]:
        sd = colour.sd_blackbody(t, SHAPE)
        v = sd.values / (np.sum(sd.values * ybar) * 5.0)
        out.append((f"bb_{t}", v))
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE).values
    k = 1.0 / (np.sum(d65 * ybar) * 5.0)
    patches = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    for i, (name, sd) in enumerate(patches.items()):
        r = sd.copy().align(SHAPE).values
        out.append((f"cc_{i + 1:02d}", r * d65 * k))
    for nm in range(380, 781, 20):
        v = np.zeros(len(wl))
        v[(nm - 380) // 5] = 1.0
        out.append((f"mono_{nm}", v))
    rng = np.random.default_rng(2026)
    for i in range(16):
        out.append((f"rnd_{i:02d}", rng.uniform(0.0, 1.0, len(wl))))
    return out


def colours(values):
    """XYZ, linear sRGB and encoded sRGB of one spectrum, by colour-science."""
    sd = colour.SpectralDistribution(dict(zip(SHAPE.wavelengths, values)))
    ones = colour.SpectralDistribution(dict(zip(SHAPE.wavelengths, np.ones(len(values)))))
    # colour returns the sum scaled by 1/100 (its 0-100 XYZ convention for
    # k = 1); undo that so Y = 1 means luminance 1.
    xyz = 100.0 * colour.colorimetry.sd_to_XYZ_integration(sd, cmfs(), ones, k=1)
    rgb = colour.XYZ_to_RGB(xyz, "sRGB", apply_cctf_encoding=False)
    enc = colour.models.eotf_inverse_sRGB(np.clip(rgb, 0.0, 1.0))
    return xyz, rgb, enc


def write(folder):
    os.makedirs(folder, exist_ok=True)
    rows = spectra()
    with open(os.path.join(folder, "spectra.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["id"] + [str(int(x)) for x in SHAPE.wavelengths])
        for name, v in rows:
            w.writerow([name] + [repr(float(x)) for x in v])
    with open(os.path.join(folder, "expected.csv"), "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["id", "X", "Y", "Z", "R", "G", "B", "sR", "sG", "sB"])
        for name, v in rows:
            xyz, rgb, enc = colours(v)
            w.writerow([name] + [repr(float(x)) for x in (*xyz, *rgb, *enc)])
    with open(os.path.join(folder, "README.md"), "w") as f:
        f.write(
            "# Colour reference data\n\n"
            f"Made by `validation/colour_reference.py` with colour-science {colour.__version__}, "
            f"numpy {np.__version__}. Do not edit: regenerate with\n"
            "`python3 validation/colour_reference.py`.\n\n"
            "- `spectra.csv`: input spectra, 380-780 nm at 5 nm.\n"
            "- `expected.csv`: their XYZ (Integration, same grid, k = 1), linear sRGB\n"
            "  (IEC 61966-2-1 matrix) and encoded sRGB of the values clipped to [0, 1].\n"
        )
    return len(rows)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(HERE, "reference"))
    a = ap.parse_args()
    n = write(a.out)
    print(f"wrote {n} reference spectra to {a.out}")
