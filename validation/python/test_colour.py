"""The colour functions against colour-science, cell by cell, as
validation/check_colour.py checks the command line: blackbodies, the
ColorChecker under D65, monochromatic lines and random spectra through
spectrum -> XYZ -> linear sRGB -> encoded sRGB, within 1e-6."""

import sys

import numpy as np
import pytest

import blackhole
from conftest import ROOT, need

sys.path.insert(0, str(ROOT / "validation"))
try:
    import colour_reference as ref
except ImportError:  # colour-science missing
    ref = None


@pytest.fixture(autouse=True)
def _colour_science():
    need(ref is not None, "colour-science is not installed (pip install -r validation/requirements.txt)")


def test_pipeline_matches_colour_science():
    rows = ref.spectra()
    values = np.array([v for _, v in rows])
    assert np.array_equal(blackhole.wavelengths(values.shape[1]), ref.SHAPE.wavelengths)
    xyz = blackhole.spectrum_to_xyz(values)
    rgb = blackhole.xyz_to_srgb(xyz)
    enc = blackhole.srgb_encode(rgb)
    for k, (name, v) in enumerate(rows):
        want_xyz, want_rgb, want_enc = ref.colours(v)
        assert np.max(np.abs(xyz[k] - want_xyz)) / np.max(np.abs(want_xyz)) < 1e-6, name
        assert np.max(np.abs(rgb[k] - want_rgb)) / np.max(np.abs(want_rgb)) < 1e-6, name
        assert np.max(np.abs(enc[k] - want_enc)) < 1e-6, name


def test_uplift_round_trips_in_gamut_colours():
    """The RGB uplift's emission spectrum of an in-gamut colour integrates
    back to that colour (what lets RGB textures enter spectral renders)."""
    nm = blackhole.wavelengths(401)  # 1 nm
    rng = np.random.default_rng(7)
    rgb = rng.uniform(0.05, 0.95, (40, 3))
    spectra = blackhole.rgb_to_spectrum(rgb, nm, kind="emission")
    back = blackhole.xyz_to_srgb(blackhole.spectrum_to_xyz(spectra))
    # The table is interpolated between 64 grid points a side: 3.4e-4 here.
    assert np.max(np.abs(back - rgb)) < 1e-3
