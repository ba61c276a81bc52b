#!/usr/bin/env python3
"""Live check of blackhole's colour pipeline against colour-science.

Run from the repository root after `cargo build --release`:

    python3 validation/check_colour.py [--blackhole target/release/blackhole]

1. cie_data/ equals colour-science's CIE 1931 2-degree CMFs and D65.
2. `blackhole colour` turns the reference spectra (blackbodies 1000-40000 K,
   the 24 ColorChecker patches under D65, monochromatic lines, random
   spectra) into XYZ and sRGB; compared with colour-science on the same grid.
   Target: XYZ relative error <= 1e-6.
3. Rendered EXRs: a uniform blackbody sky with the shift off has the
   blackbody's chromaticity; with the camera at 3 r_s, shift and beaming on,
   the sky is B(g T) with g = 1/sqrt(1 - 1/3). Target: chromaticity error
   <= 1e-4. The spectral layers integrate to the XYZ layer.

Prints a table of the largest errors and exits non-zero if a target is missed.
"""

import argparse
import csv
import io
import os
import subprocess
import sys
import tempfile
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
import numpy as np  # noqa: E402
import OpenEXR  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import colour_reference as ref  # noqa: E402

RESULTS = []  # (check, worst error, target, passed)


def record(check, worst, target):
    RESULTS.append((check, worst, target, worst <= target))


def check_cie_data():
    cm = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    ours = np.loadtxt(os.path.join(ROOT, "cie_data/cie1931_2deg_1nm.csv"), delimiter=",", skiprows=1)
    theirs = cm.values[np.searchsorted(cm.wavelengths, ours[:, 0])]
    record("cie_data CMF 1 nm vs colour (abs)", float(np.max(np.abs(ours[:, 1:] - theirs))), 0.0)
    d65 = colour.SDS_ILLUMINANTS["D65"]
    ours = np.loadtxt(os.path.join(ROOT, "cie_data/d65_5nm.csv"), delimiter=",", skiprows=1)
    theirs = np.array([d65[w] for w in ours[:, 0]])
    record("cie_data D65 5 nm vs colour (abs)", float(np.max(np.abs(ours[:, 1] - theirs))), 0.0)


def check_pipeline(exe, tmp):
    rows = ref.spectra()
    path = os.path.join(tmp, "spectra.csv")
    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["id"] + [str(int(x)) for x in ref.SHAPE.wavelengths])
        for name, v in rows:
            w.writerow([name] + [repr(float(x)) for x in v])
    out = subprocess.run([exe, "colour", path], check=True, capture_output=True, text=True).stdout
    ours = {r["id"]: r for r in csv.DictReader(io.StringIO(out))}
    worst = {}
    for name, v in rows:
        xyz, rgb, enc = ref.colours(v)
        o = ours[name]
        oxyz = np.array([float(o[k]) for k in "XYZ"])
        orgb = np.array([float(o[k]) for k in "RGB"])
        oenc = np.array([float(o[k]) for k in ("sR", "sG", "sB")])
        kind = name.split("_")[0]
        e_xyz = float(np.max(np.abs(oxyz - xyz)) / np.max(np.abs(xyz)))
        e_rgb = float(np.max(np.abs(orgb - rgb)) / np.max(np.abs(rgb)))
        e_enc = float(np.max(np.abs(oenc - enc)))
        w = worst.setdefault(kind, [0.0, 0.0, 0.0, ""])
        if e_xyz > w[0]:
            w[0], w[3] = e_xyz, name
        w[1] = max(w[1], e_rgb)
        w[2] = max(w[2], e_enc)
    labels = {"bb": "blackbodies 1000-40000 K", "cc": "ColorChecker 24 under D65", "mono": "monochromatic lines", "rnd": "random spectra"}
    for kind, (ex, er, ee, at) in worst.items():
        record(f"{labels[kind]}: XYZ relative (worst {at})", ex, 1e-6)
        record(f"{labels[kind]}: linear sRGB relative", er, 1e-6)
        record(f"{labels[kind]}: encoded sRGB (clipped) abs", ee, 1e-6)


def render(exe, tmp, name, body):
    cfg = os.path.join(tmp, name + ".toml")
    with open(cfg, "w") as f:
        f.write(body)
    subprocess.run([exe, "render", "-q", cfg], check=True)
    return os.path.join(tmp, name + ".exr")


def read_exr(path):
    with OpenEXR.File(path, separate_channels=True) as f:
        header = dict(f.header())
        ch = {k: np.asarray(v.pixels, dtype=np.float64) for k, v in f.channels().items()}
    return header, ch


def chromaticity(xyz):
    return xyz[..., :2] / np.sum(xyz, axis=-1, keepdims=True)


def sky_toml(name, r, kelvin, spectral):
    mass = 8.57e36
    rs = 2 * 6.674e-11 * mass / 2.99792458e8**2
    return f"""
[image]
width = 32
height = 32
png = "{name}.png"
exr = "{name}.exr"
exr_xyz = true
[camera]
position = [0.0, {-r * rs!r}, 0.0]
look_at = [0.0, {-2 * r * rs!r}, 0.0]
fov = 60.0
[black_hole]
mass = {mass!r}
[sky]
blackbody = {kelvin!r}
[spectral]
enabled = true
wavelengths = 81
{spectral}
"""


def blackbody_xy(kelvin):
    sd = colour.sd_blackbody(kelvin, ref.SHAPE)
    ones = colour.SpectralDistribution(dict(zip(ref.SHAPE.wavelengths, np.ones(81))))
    xyz = colour.colorimetry.sd_to_XYZ_integration(sd, ref.cmfs(), ones, k=1)
    return colour.XYZ_to_xy(xyz), xyz[1]


def check_renders(exe, tmp):
    worst_off = 0.0
    worst_layers = 0.0
    for t in [2000.0, 5800.0, 12000.0]:
        exr = render(exe, tmp, f"off_{int(t)}", sky_toml(f"off_{int(t)}", 10.0, t, "shift = false\nexr_layers = true"))
        header, ch = read_exr(exr)
        assert "chromaticities" in header, "EXR lacks the chromaticities attribute"
        xyz = np.stack([ch["X"], ch["Y"], ch["Z"]], axis=-1).reshape(-1, 3)
        want, _ = blackbody_xy(t)
        worst_off = max(worst_off, float(np.max(np.abs(chromaticity(xyz) - want))))
        # The same through the RGB channels and colour's sRGB -> XYZ.
        rgb = np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).reshape(-1, 3)
        xyz_rgb = colour.RGB_to_XYZ(rgb, "sRGB", apply_cctf_decoding=False)
        worst_off = max(worst_off, float(np.max(np.abs(chromaticity(xyz_rgb) - want))))
        # Spectral layers integrate to the XYZ layer.
        names = sorted((k for k in ch if k.startswith("S0.")), key=lambda k: float(k[3:-2].replace(",", ".")))
        assert len(names) == 81, names[:3]
        spec = np.stack([ch[k] for k in names], axis=-1).reshape(-1, 81)
        xyz_layers = spec @ ref.cmfs().values * 5.0
        worst_layers = max(worst_layers, float(np.max(np.abs(xyz_layers - xyz)) / np.max(xyz)))
        assert header.get("spectralLayoutVersion") == "1.0"
    record("rendered sky, shift off, 2000/5800/12000 K: xy abs", worst_off, 1e-4)
    record("EXR spectral layers -> XYZ vs XYZ layer (rel)", worst_layers, 1e-5)
    g = 1.0 / np.sqrt(1.0 - 1.0 / 3.0)
    t = 5800.0
    exr = render(exe, tmp, "blue", sky_toml("blue", 3.0, t, "shift = true\nbeaming = true"))
    _, ch = read_exr(exr)
    xyz = np.stack([ch["X"], ch["Y"], ch["Z"]], axis=-1).reshape(-1, 3)
    want, y_gt = blackbody_xy(g * t)
    _, y_t = blackbody_xy(t)
    record("camera at 3 r_s, shift + beaming: sky xy vs B(gT) abs", float(np.max(np.abs(chromaticity(xyz) - want))), 1e-4)
    record("camera at 3 r_s, shift + beaming: Y vs Y(B(gT))/Y(B(T)) rel", float(np.max(np.abs(xyz[:, 1] / (y_gt / y_t) - 1.0))), 1e-3)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--blackhole", default=os.path.join(ROOT, "target/release/blackhole"))
    a = ap.parse_args()
    # The binary relative to the checkout: the report says nothing of the
    # machine it ran on.
    shown = os.path.relpath(os.path.abspath(a.blackhole), ROOT)
    if shown.startswith(".."):
        shown = os.path.basename(a.blackhole)
    print(f"colour-science {colour.__version__}, numpy {np.__version__}, binary {shown}")
    with tempfile.TemporaryDirectory() as tmp:
        check_cie_data()
        check_pipeline(a.blackhole, tmp)
        check_renders(a.blackhole, tmp)
    width = max(len(r[0]) for r in RESULTS)
    print(f"{'check':<{width}}  {'largest error':>13}  {'target':>8}")
    for check, worst, target, ok in sorted(RESULTS, key=lambda r: -r[1] / max(r[2], 1e-300)):
        print(f"{check:<{width}}  {worst:>13.3e}  {target:>8.0e}  {'ok' if ok else 'FAILED'}")
    failed = [r for r in RESULTS if not r[3]]
    print("all targets met" if not failed else f"{len(failed)} target(s) missed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
