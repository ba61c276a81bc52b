"""Observed scenes ([medium] and [observe]) from Python: each pixel's flux
density in janskys at each frequency, summing to the total the render
reports, and following the emission law across frequencies."""

import numpy as np
import pytest

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


def test_fits_holds_janskys_on_sky_offsets_and_frequencies(tmp_path):
    pytest.importorskip("astropy")
    from astropy.io import fits

    scene = blackhole.load(
        GOLD,
        set={"image.width": 20, "image.height": 16, "image.samples": 1, "observe.frequency": [230e9, 345e9]},
    )
    img = scene.render()
    # 30 M at 1000 M over 16 rows, seen from 7778 pc: M is 5.156 uas.
    assert abs(img.pixel_uas / (30 / 16 * 5.1561) - 1) < 1e-3
    path = tmp_path / "gold.fits"
    img.write(path)
    with fits.open(path) as f:
        h = f[0].header
        cube = f[0].data
        assert h["BUNIT"] == "Jy/pixel" and h["CTYPE3"] == "FREQ" and h["CUNIT1"] == "uas"
        assert h["CRVAL3"] == 230e9 and h["CDELT3"] == 115e9
        assert cube.shape == (2, 16, 20)
        # Rows bottom-up.
        assert np.array_equal(cube[0], img.flux[::-1, :, 0])
        assert np.allclose(cube.sum(axis=(1, 2), dtype=np.float64), img.stats["flux_jy"], rtol=1e-6)


def test_the_ring_of_sgr_a_is_the_one_the_eht_measured():
    # configs/sgra.toml: a RIAF around a hole of Sgr A*'s mass at its
    # distance; its ring lands within the EHT's 51.8 +- 2.3 uas, about the
    # hole (the look direction) to within a few uas (spin and inclination
    # shift the photon ring by a fraction of G M / c^2, 5 uas).
    img = blackhole.load(CONFIGS / "sgra.toml", set={"image.width": 96, "image.height": 96, "image.samples": 1}).render()
    ring = img.ring
    assert abs(ring["diameter_uas"] - 51.8) < 2.3, ring
    assert np.hypot(*ring["center_uas"]) < 5.0, ring
    assert 0 < ring["spread_uas"] < 5.0, ring
    assert blackhole.load(GOLD, set={"image.width": 8, "image.height": 8}).render().ring is not None
    assert blackhole.load(CONFIGS / "quick.toml", set={"image.width": 16, "image.height": 12}).render().ring is None
