"""Observed scenes ([medium] and [observe]) from Python: each pixel's flux
density in janskys at each frequency, summing to the total the render
reports, and following the emission law across frequencies."""

import numpy as np

import blackhole
from conftest import CONFIGS

GOLD = CONFIGS / "gold2020.toml"


def test_flux_maps_sum_to_the_total_and_follow_the_emission_law():
    # Test 1 (alpha = -3, no absorption): the flux scales as nu^3 exactly.
    scene = blackhole.load(
        GOLD,
        set={
            "image.width": 24,
            "image.height": 24,
            "image.samples": 1,
            "medium.test": 1,
            "observe.frequency": [230e9, 460e9],
        },
    )
    img = scene.render()
    assert img.spectra is None and img.wavelengths is None
    assert list(img.frequencies) == [230e9, 460e9]
    flux = img.flux
    assert flux.shape == (24, 24, 2) and flux.dtype == np.float32
    total = img.stats["flux_jy"]
    assert np.allclose(flux.sum(axis=(0, 1), dtype=np.float64), total, rtol=1e-6)
    assert abs(total[1] / total[0] - 8.0) < 1e-9
    # The published value at 128 x 128 is 1.6465 Jy; 24 x 24 is coarse
    # but lands within a few per cent.
    assert abs(total[0] / 1.6465 - 1.0) < 0.05


def test_other_renders_have_no_flux():
    img = blackhole.load(CONFIGS / "quick.toml", set={"image.width": 16, "image.height": 12}).render()
    assert img.flux is None and img.frequencies is None and img.stats["flux_jy"] is None
