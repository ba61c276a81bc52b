#!/usr/bin/env python3
"""Generate the CIE colour tables that the ``blackhole`` renderer embeds.

All tables come from the Python package *colour-science* (pinned in
``validation/requirements.txt``).  The output is deterministic: the same
colour-science version always produces byte-identical files.

Usage (from the repository root)::

    python3 -m pip install -r validation/requirements.txt
    python3 validation/generate_cie_data.py            # writes cie_data/
    python3 validation/generate_cie_data.py --out DIR  # writes DIR/

Files written (each CSV has a header row, ``\\n`` line endings, no index):

* ``cie1931_2deg_1nm.csv`` -- ``wavelength_nm,x_bar,y_bar,z_bar``, 360..830 nm, 1 nm
* ``cie1931_2deg_5nm.csv`` -- same, 360..830 nm, 5 nm (every 5th row of the 1 nm table)
* ``d65_5nm.csv``          -- ``wavelength_nm,relative_spd``, colour's native D65 table
* ``d65_1nm.csv``          -- same, interpolated to 1 nm with colour's default
  interpolator for D65 (``LinearInterpolator``)
* ``README.md``            -- provenance, colour-science version, value format

Numbers are written with Python's ``repr(float)``: the shortest decimal
string that parses back to exactly the same IEEE-754 float64, so a Rust
``str::parse::<f64>()`` recovers colour-science's values bit for bit.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

# colour-science warns at import time about optional packages (matplotlib,
# ...) that we do not need; keep the generator's output clean.
os.environ.setdefault("COLOUR_SCIENCE__FILTER_USAGE_WARNINGS", "True")
warnings.filterwarnings("ignore", module="colour")

import numpy as np  # noqa: E402

import colour  # noqa: E402
from colour import SpectralShape  # noqa: E402

CMFS_NAME = "CIE 1931 2 Degree Standard Observer"
ILLUMINANT_NAME = "D65"

DEFAULT_OUT = Path(__file__).resolve().parent.parent / "cie_data"


def fmt(value: float) -> str:
    """Shortest round-trip decimal representation of a float64."""
    v = float(value)
    if not np.isfinite(v):
        raise ValueError(f"non-finite value {v!r}")
    return repr(v)


def fmt_wavelength(value: float) -> str:
    v = float(value)
    if v != round(v):
        raise ValueError(f"non-integral wavelength {v!r}")
    return str(int(round(v)))


def write_csv(path: Path, header: list[str], wavelengths, columns) -> int:
    rows = [",".join(header)]
    for i, wl in enumerate(wavelengths):
        rows.append(",".join([fmt_wavelength(wl)] + [fmt(col[i]) for col in columns]))
    text = "\n".join(rows) + "\n"
    # newline="" -> no platform newline translation: identical bytes everywhere.
    with open(path, "w", encoding="ascii", newline="") as handle:
        handle.write(text)
    return len(rows) - 1


def cmfs_tables():
    cmfs = colour.MSDS_CMFS[CMFS_NAME]
    shape = cmfs.shape
    if (shape.start, shape.end, shape.interval) != (360, 830, 1):
        raise RuntimeError(f"unexpected {CMFS_NAME} shape {shape}")
    wl_1 = np.asarray(cmfs.wavelengths, dtype=np.float64)
    val_1 = np.asarray(cmfs.values, dtype=np.float64)

    # The CIE 5 nm table is the 1 nm table sampled every 5 nm.
    wl_5 = wl_1[::5]
    val_5 = val_1[::5]
    if wl_5[0] != 360 or wl_5[-1] != 830 or not np.all(np.diff(wl_5) == 5):
        raise RuntimeError("5 nm decimation did not land on 360..830 step 5")

    # colour-science ships no separate 5 nm CIE 1931 table; the 5 nm CMFs it
    # uses internally (sd_to_XYZ's mi_5nm_omission_method) come from
    # reshape_msds(cmfs, SpectralShape(360, 830, 5), "Interpolate").  Check
    # that this agrees with the decimated table.
    cmfs_5_colour = colour.colorimetry.reshape_msds(
        cmfs, SpectralShape(360, 830, 5), "Interpolate", copy=True
    )
    if not np.array_equal(cmfs_5_colour.wavelengths, wl_5):
        raise RuntimeError("colour's 5 nm CMFs have a different wavelength grid")
    # Sprague interpolation evaluated at its own knots reproduces them up to
    # float64 rounding only (a few ulp), hence the relative tolerance.
    other = np.asarray(cmfs_5_colour.values, dtype=np.float64)
    max_abs = float(np.max(np.abs(other - val_5)))
    nonzero = val_5 != 0
    max_rel = float(np.max(np.abs(other - val_5)[nonzero] / np.abs(val_5[nonzero])))
    if max_rel > 1e-12 or max_abs > 1e-12 * float(np.max(val_5)):
        raise RuntimeError(
            f"decimated 5 nm CMFs differ from colour's 5 nm CMFs by {max_abs:g} "
            f"(absolute), {max_rel:g} (relative, non-zero entries)"
        )
    return wl_1, val_1, wl_5, val_5, (max_abs, max_rel)


def d65_tables():
    sd = colour.SDS_ILLUMINANTS[ILLUMINANT_NAME]
    shape = sd.shape
    if shape.interval != 5:
        raise RuntimeError(f"unexpected D65 interval {shape.interval}")
    wl_5 = np.asarray(sd.wavelengths, dtype=np.float64)
    val_5 = np.asarray(sd.values, dtype=np.float64)

    # colour-science 0.4.7 has no 1 nm D65 table; interpolate with the
    # interpolator colour attaches to this distribution (interpolate() with
    # interpolator=None uses sd.interpolator when it is not Sprague/cubic).
    interpolator = sd.interpolator
    sd_1 = sd.copy().interpolate(SpectralShape(shape.start, shape.end, 1))
    wl_1 = np.asarray(sd_1.wavelengths, dtype=np.float64)
    val_1 = np.asarray(sd_1.values, dtype=np.float64)
    # Interpolation must reproduce the 5 nm knots.
    if not np.array_equal(val_1[::5], val_5):
        raise RuntimeError("1 nm D65 does not pass through the 5 nm values")
    return wl_1, val_1, wl_5, val_5, interpolator, (shape.start, shape.end)


def readme_text(info: dict) -> str:
    return f"""# CIE colour tables

Generated by `validation/generate_cie_data.py` from the Python package
**colour-science {info['colour_version']}** (numpy {info['numpy_version']}).
Do not edit by hand: regenerate.

## Regenerate

From the repository root:

```sh
python3 -m pip install -r validation/requirements.txt
python3 validation/generate_cie_data.py
```

(`--out DIR` writes somewhere else.) The output is deterministic: the same
colour-science version produces byte-identical files.

## Files

| file | columns | range | rows | source |
| --- | --- | --- | --- | --- |
| `cie1931_2deg_1nm.csv` | `wavelength_nm,x_bar,y_bar,z_bar` | {info['cmf1_range']} nm, 1 nm | {info['cmf1_rows']} | `colour.MSDS_CMFS['{CMFS_NAME}']` (colour's native table, 1 nm) |
| `cie1931_2deg_5nm.csv` | `wavelength_nm,x_bar,y_bar,z_bar` | {info['cmf5_range']} nm, 5 nm | {info['cmf5_rows']} | every 5th row of the 1 nm table |
| `d65_5nm.csv` | `wavelength_nm,relative_spd` | {info['d65_5_range']} nm, 5 nm | {info['d65_5_rows']} | `colour.SDS_ILLUMINANTS['{ILLUMINANT_NAME}']` (colour's native table, 5 nm) |
| `d65_1nm.csv` | `wavelength_nm,relative_spd` | {info['d65_1_range']} nm, 1 nm | {info['d65_1_rows']} | the 5 nm D65 interpolated to 1 nm (see below) |

Notes:

- **CMFs, 5 nm.** colour-science has no separate 5 nm CIE 1931 table. The
  5 nm table here is the 1 nm table sampled at multiples of 5 nm. colour's own
  5 nm CMFs (what `sd_to_XYZ` uses for 5 nm spectra,
  `reshape_msds(cmfs, SpectralShape(360, 830, 5), "Interpolate")`) equal it
  to float64 rounding: max |difference| {info['cmf5_max_diff'][0]:.3g}, max
  relative difference over non-zero entries {info['cmf5_max_diff'][1]:.3g}
  (checked at generation time; the Sprague interpolator reproduces its knots
  only to a few ulp).
- **D65, 1 nm: interpolated, not taken from the CIE's 1 nm table.**
  colour-science {info['colour_version']} ships D65 only at 5 nm, {info['d65_5_range']} nm
  (the CIE's D65 table runs to 830 nm; colour's stops at 780 nm, so these
  files do too). `d65_1nm.csv` is
  `SDS_ILLUMINANTS['D65'].copy().interpolate(SpectralShape({info['d65_start']}, {info['d65_end']}, 1))`,
  i.e. colour's default interpolator for this distribution, which is
  `{info['d65_interpolator']}` (piecewise linear between the 5 nm values,
  passing exactly through them).
- D65 is normalised to 100 at 560 nm; `y_bar` peaks at 1.0 at 555 nm.

## Value format

- ASCII CSV, comma separated, one header row, `\\n` line endings, no quoting.
- `wavelength_nm` is an integer (nanometres, in air as tabulated by the CIE).
- Every other value is Python's `repr(float)` of colour-science's float64
  value: the shortest decimal string that parses back to the identical
  IEEE-754 float64 (it may use exponent notation, e.g. `3.917e-06`). Rust's
  `str::parse::<f64>()` recovers colour-science's numbers bit for bit.
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        help=f"output folder (default: {DEFAULT_OUT})",
    )
    args = parser.parse_args(argv)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)

    cwl1, cval1, cwl5, cval5, cmf5_max_diff = cmfs_tables()
    dwl1, dval1, dwl5, dval5, d65_interp, (d_start, d_end) = d65_tables()

    header_cmf = ["wavelength_nm", "x_bar", "y_bar", "z_bar"]
    header_spd = ["wavelength_nm", "relative_spd"]
    n_c1 = write_csv(out / "cie1931_2deg_1nm.csv", header_cmf, cwl1, cval1.T)
    n_c5 = write_csv(out / "cie1931_2deg_5nm.csv", header_cmf, cwl5, cval5.T)
    n_d1 = write_csv(out / "d65_1nm.csv", header_spd, dwl1, [dval1])
    n_d5 = write_csv(out / "d65_5nm.csv", header_spd, dwl5, [dval5])

    def rng(wl):
        return f"{fmt_wavelength(wl[0])}-{fmt_wavelength(wl[-1])}"

    info = {
        "colour_version": colour.__version__,
        "numpy_version": np.__version__,
        "cmf1_range": rng(cwl1),
        "cmf1_rows": n_c1,
        "cmf5_range": rng(cwl5),
        "cmf5_rows": n_c5,
        "cmf5_max_diff": cmf5_max_diff,
        "d65_1_range": rng(dwl1),
        "d65_1_rows": n_d1,
        "d65_5_range": rng(dwl5),
        "d65_5_rows": n_d5,
        "d65_start": fmt_wavelength(d_start),
        "d65_end": fmt_wavelength(d_end),
        "d65_interpolator": d65_interp.__name__,
    }
    with open(out / "README.md", "w", encoding="utf-8", newline="") as handle:
        handle.write(readme_text(info))

    for name, n in [
        ("cie1931_2deg_1nm.csv", n_c1),
        ("cie1931_2deg_5nm.csv", n_c5),
        ("d65_1nm.csv", n_d1),
        ("d65_5nm.csv", n_d5),
    ]:
        print(f"wrote {out / name} ({n} rows)")
    print(f"wrote {out / 'README.md'} (colour-science {colour.__version__})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
