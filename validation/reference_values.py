#!/usr/bin/env python3
"""Print colour-science reference values for the renderer's colour tests.

Run after ``python3 -m pip install -r validation/requirements.txt``::

    python3 validation/reference_values.py

Prints (writes no files):

1. xy chromaticity and linear sRGB (Y normalised to 1) of a 5800 K blackbody
   on 380-780 nm at 5 nm, computed two ways:
   a. ``colour.sd_to_XYZ(..., method='Integration')`` with the CIE 1931 2 deg
      CMFs aligned to the same 380-780 nm / 5 nm grid;
   b. a plain numpy sum of Planck x CMF on that grid (no weights, no
      interpolation);
   plus, for contrast, what ``sd_to_XYZ`` gives when handed the full
   360-830 nm / 1 nm CMFs (it then *extends* the 380-780 nm spectrum to
   360-830 nm by constant extrapolation, so the numbers differ).
2. XYZ of a flat 0.5 reflectance under D65 on 380-780 nm at 5 nm
   (Y of the perfect diffuser = 100).
3. The Planck formula and constants colour-science uses.
"""

from __future__ import annotations

import os
import warnings

os.environ.setdefault("COLOUR_SCIENCE__FILTER_USAGE_WARNINGS", "True")
warnings.filterwarnings("ignore", module="colour")

import numpy as np  # noqa: E402

import colour  # noqa: E402
from colour import SpectralShape  # noqa: E402
from colour.colorimetry import blackbody  # noqa: E402

CMFS_NAME = "CIE 1931 2 Degree Standard Observer"
SHAPE = SpectralShape(380, 780, 5)
TEMPERATURE = 5800.0

# Values from the project's physics notes.
EXPECTED_XY = (0.3260002553, 0.3353569896)
EXPECTED_RGB = (1.1094994198, 0.9758397116, 0.9175022141)
EXPECTED_XYZ_REFL = (47.5214834701, 50.0, 54.4400273515)


def f10(values) -> str:
    return "(" + ", ".join(f"{float(v):.10f}" for v in np.ravel(values)) + ")"


def f17(values) -> str:
    return "(" + ", ".join(repr(float(v)) for v in np.ravel(values)) + ")"


def check(name: str, got, expected, tol: float = 5e-10) -> bool:
    got = np.asarray(got, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    err = float(np.max(np.abs(got - expected)))
    ok = err <= tol
    print(f"    {name}: {'MATCH' if ok else 'MISMATCH'} vs notes (max |diff| = {err:.3g})")
    return ok


def xy_and_rgb(XYZ):
    XYZ = np.asarray(XYZ, dtype=np.float64)
    XYZ_n = XYZ / XYZ[1]  # Y normalised to 1
    xy = colour.XYZ_to_xy(XYZ_n)
    # Linear sRGB: no CCTF encoding; source whitepoint = sRGB's own D65, so
    # no chromatic adaptation is applied.
    rgb = colour.XYZ_to_RGB(XYZ_n, "sRGB", apply_cctf_encoding=False)
    return XYZ_n, xy, rgb


def main() -> int:
    print(f"colour-science {colour.__version__}, numpy {np.__version__}")
    cmfs_full = colour.MSDS_CMFS[CMFS_NAME]
    cmfs = cmfs_full.copy().align(SHAPE)  # 380..780 @ 5 nm (values at the knots)
    w = SHAPE.wavelengths
    cmf_grid = np.asarray(cmfs_full.values)[
        np.isin(cmfs_full.wavelengths, w)
    ]  # the same values, straight from the 1 nm table
    print(
        "  CMFs aligned to 380-780/5 vs rows of the 1 nm table: "
        f"max |diff| = {float(np.max(np.abs(cmfs.values - cmf_grid))):.3g}"
    )
    all_ok = True

    # ---- 3. Planck -------------------------------------------------------
    c1, c2, n = blackbody.CONSTANT_C1, blackbody.CONSTANT_C2, blackbody.CONSTANT_N
    h = colour.constants.CONSTANT_PLANCK
    c = colour.constants.CONSTANT_LIGHT_SPEED
    k = colour.constants.CONSTANT_BOLTZMANN
    print("\n[Planck law as colour.colorimetry.planck_law / sd_blackbody]")
    print("  L(lambda, T) = c1 / (pi * n**2 * lambda**5) / expm1(c2 / (n * lambda * T))")
    print("  lambda in metres; sd_blackbody(T, shape) = planck_law(nm * 1e-9, T) * 1e-9  [W sr-1 m-2 nm-1]")
    print(f"  c1 = {c1!r} W m^2   (hard-coded; comment says 2*pi*h*c**2)")
    print(f"  c2 = {c2!r} m K     (hard-coded ITS-90 / CIE value, NOT h*c/k)")
    print(f"  n  = {n!r}")
    print(f"  colour.constants: h = {h!r}, c = {c!r}, k = {k!r} (not used by planck_law)")
    print(f"    h*c/k        = {h * c / k!r}  (relative to c2: {(h * c / k) / c2 - 1:+.3e})")
    print(f"    2*pi*h*c**2  = {2 * np.pi * h * c * c!r}")

    # ---- 1. 5800 K blackbody ---------------------------------------------
    sd_bb = colour.sd_blackbody(TEMPERATURE, SHAPE)
    P = blackbody.planck_law(w * 1e-9, TEMPERATURE) * 1e-9
    assert np.array_equal(P, sd_bb.values)

    print(f"\n[1] {TEMPERATURE:g} K blackbody, 380-780 nm @ 5 nm, Y normalised to 1")
    XYZ_int = colour.sd_to_XYZ(sd_bb, cmfs, method="Integration")
    XYZ_n, xy, rgb = xy_and_rgb(XYZ_int)
    print("  a) sd_to_XYZ(sd_blackbody(5800, 380-780/5), cmfs aligned to 380-780/5, method='Integration')")
    print(f"     XYZ (Y=1)   = {f17(XYZ_n)}")
    print(f"     xy          = {f10(xy)}   full: {f17(xy)}")
    print(f"     linear sRGB = {f10(rgb)}   full: {f17(rgb)}")
    all_ok &= check("xy", xy, EXPECTED_XY)
    all_ok &= check("sRGB", rgb, EXPECTED_RGB)

    XYZ_sum = (P[:, None] * cmf_grid).sum(axis=0)
    XYZ_n2, xy2, rgb2 = xy_and_rgb(XYZ_sum)
    print("  b) numpy: XYZ = sum_i planck_law(lambda_i) * cmf(lambda_i), lambda_i = 380, 385, ..., 780")
    print(f"     XYZ (Y=1)   = {f17(XYZ_n2)}")
    print(f"     xy          = {f10(xy2)}   full: {f17(xy2)}")
    print(f"     linear sRGB = {f10(rgb2)}   full: {f17(rgb2)}")
    all_ok &= check("xy", xy2, EXPECTED_XY)
    all_ok &= check("sRGB", rgb2, EXPECTED_RGB)
    print(f"     a) vs b): max |diff| xy = {float(np.max(np.abs(xy - xy2))):.3g}, "
          f"sRGB = {float(np.max(np.abs(rgb - rgb2))):.3g}")

    P_hck = blackbody.planck_law(w * 1e-9, TEMPERATURE, c2=h * c / k)
    _, xy3, rgb3 = xy_and_rgb((P_hck[:, None] * cmf_grid).sum(axis=0))
    print(f"  (b with c2 = h*c/k instead: xy = {f10(xy3)}, sRGB = {f10(rgb3)})")

    _, xy4, rgb4 = xy_and_rgb(colour.sd_to_XYZ(sd_bb, cmfs_full, method="Integration"))
    print("  (for contrast, sd_to_XYZ with the full 360-830/1 CMFs, method='Integration':"
          f" xy = {f10(xy4)}, sRGB = {f10(rgb4)} -- spectrum extrapolated to 360-830)")

    srgb = colour.RGB_COLOURSPACES["sRGB"]
    M = np.asarray(srgb.matrix_XYZ_to_RGB)
    print("  sRGB matrix_XYZ_to_RGB used by colour.XYZ_to_RGB (the rounded 4-decimal"
          " IEC 61966-2-1 matrix,\n  use_derived_matrix_XYZ_to_RGB ="
          f" {srgb.use_derived_matrix_XYZ_to_RGB}; NOT the inverse of matrix_RGB_to_XYZ"
          " nor derived from the primaries):")
    for row in M:
        print("    " + f17(row))
    M_derived = np.linalg.inv(np.asarray(srgb.matrix_RGB_to_XYZ))
    print(f"  (inverse of matrix_RGB_to_XYZ would give sRGB = {f10(M_derived @ XYZ_n)})")
    rgb_plain = M @ XYZ_n
    print(f"  plain M @ XYZ(Y=1) = {f17(rgb_plain)}; vs XYZ_to_RGB max |diff| ="
          f" {float(np.max(np.abs(rgb_plain - rgb))):.3g} (no chromatic adaptation applied)")

    # ---- 2. flat 0.5 reflectance under D65 -------------------------------
    print("\n[2] flat 0.5 reflectance under D65, 380-780 nm @ 5 nm (perfect diffuser Y = 100)")
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE)
    refl = colour.sd_constant(0.5, SHAPE)
    XYZ_r = colour.sd_to_XYZ(refl, cmfs, d65, method="Integration")
    print("  a) sd_to_XYZ(sd_constant(0.5), cmfs aligned, D65 aligned, method='Integration')")
    print(f"     XYZ = {f10(XYZ_r)}   full: {f17(XYZ_r)}")
    all_ok &= check("XYZ", XYZ_r, EXPECTED_XYZ_REFL)
    S = d65.values
    k_norm = 100.0 / np.sum(S * cmf_grid[:, 1])
    XYZ_r2 = k_norm * np.sum((0.5 * S)[:, None] * cmf_grid, axis=0)
    print("  b) numpy: k = 100 / sum(S*y_bar); XYZ = k * sum(0.5 * S * cmf)")
    print(f"     XYZ = {f10(XYZ_r2)}   full: {f17(XYZ_r2)}")
    all_ok &= check("XYZ", XYZ_r2, EXPECTED_XYZ_REFL)
    XYZ_r3 = colour.sd_to_XYZ(refl, cmfs_full, colour.SDS_ILLUMINANTS["D65"], method="Integration")
    print(f"  (for contrast, with full 360-830/1 CMFs: XYZ = {f10(XYZ_r3)})")

    print(f"\nall reference values reproduced: {'YES' if all_ok else 'NO'}")
    return 0 if all_ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
