"""Observed scenes ([medium] and [observe]) from Python: each pixel's flux
density in janskys at each frequency, summing to the total the render
reports, and following the emission law across frequencies."""

import numpy as np
import pytest

import blackhole
from conftest import CONFIGS, need

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


def _ehtim():
    """ehtim from PyPI (validation/python/requirements.txt), the EHT's own
    imaging library: the real client of our FITS files."""
    try:
        import ehtim
    except ImportError:
        need(False, "ehtim is not installed (pip install ehtim==1.3.2)")
    return ehtim


def test_ehtim_reads_our_fits_as_we_wrote_it(tmp_path, capfd):
    # ehtim.image.load_fits on an observed scene's FITS: its total flux,
    # pixel size (degrees in the file, radians in ehtim), frequency,
    # position and name are ours; several frequencies give a file each.
    eh = _ehtim()
    scene = blackhole.load(
        GOLD,
        set={
            "image.width": 40,
            "image.height": 32,
            "image.samples": 1,
            "observe.frequency": ["230 GHz", "345.5 GHz"],
            "observe.ra": 266.41684,
            "observe.dec": -29.00781,
            "observe.source": "SgrA",
        },
    )
    img = scene.render()
    path = tmp_path / "gold.fits"
    img.write(path)
    assert not path.exists()
    totals = img.stats["flux_jy"]
    for k, (name, hz) in enumerate([("gold.230GHz.fits", 230e9), ("gold.345,5GHz.fits", 345.5e9)]):
        im = eh.image.load_fits(str(tmp_path / name))
        assert abs(im.total_flux() / totals[k] - 1) < 1e-6
        assert abs(im.psize / (img.pixel_uas * eh.RADPERUAS) - 1) < 1e-9
        assert abs(im.rf / hz - 1) < 1e-9
        assert (im.xdim, im.ydim) == (40, 32)
        assert abs(im.ra - 266.41684 / 15) < 1e-9 and abs(im.dec + 29.00781) < 1e-9
        assert im.source == "SgrA" and im.mjd == 51544
        # ehtim's array is North up, East left, as ours.
        assert np.allclose(im.imarr(), img.flux[:, :, k], rtol=1e-6, atol=0)
    # One frequency: the name asked for.
    one = blackhole.load(GOLD, set={"image.width": 16, "image.height": 16, "image.samples": 1}).render()
    one.write(tmp_path / "one.fits")
    im = eh.image.load_fits(str(tmp_path / "one.fits"))
    assert abs(im.total_flux() / one.stats["flux_jy"][0] - 1) < 1e-6


def test_a_bright_side_to_the_east_lands_east_in_ehtim(tmp_path):
    # Gold's test 3 rotates: the side of the flow coming towards the camera
    # is Doppler-boosted. Whichever side of our image it is on (left is
    # East, as on the sky), ehtim puts the brightness's centroid there.
    eh = _ehtim()
    for up in ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]):
        img = blackhole.load(
            GOLD,
            set={"image.width": 48, "image.height": 48, "image.samples": 1, "camera.up": up},
        ).render()
        flux = img.flux[:, :, 0].astype(np.float64)
        columns = np.arange(48) - 23.5
        ours = (flux.sum(axis=0) * columns).sum() / flux.sum()
        assert abs(ours) > 2.0, ours
        path = tmp_path / "side.fits"
        img.write(path)
        im = eh.image.load_fits(str(path))
        arr = im.imarr()
        # ehtim's RA offset of each column (radians, positive East).
        xlist = (np.arange(0, -im.xdim, -1) + im.xdim / 2.0 - 0.5) * im.psize
        east = (arr.sum(axis=0) * xlist).sum() / arr.sum()
        assert (east > 0) == (ours < 0), (up, ours, east)


def test_the_wcs_is_the_one_in_the_file(tmp_path):
    pytest.importorskip("astropy")
    from astropy.io import fits

    scene = blackhole.load(
        CONFIGS / "sgra.toml",
        set={"image.width": 24, "image.height": 20, "image.samples": 1},
    )
    img = scene.render()
    wcs = img.wcs
    assert wcs["CTYPE1"] == "RA---SIN" and wcs["CTYPE2"] == "DEC--SIN"
    assert wcs["CDELT1"] < 0 and abs(-wcs["CDELT1"] * 3.6e9 / img.pixel_uas - 1) < 1e-12
    assert (wcs["CRVAL1"], wcs["CRVAL2"]) == (img.sky["ra"], img.sky["dec"])
    img.write(tmp_path / "sgra.fits")
    with fits.open(tmp_path / "sgra.fits") as f:
        h = f[0].header
        for key, value in wcs.items():
            # A FITS card keeps a float to about 14 digits.
            if isinstance(value, float):
                assert abs(h[key] - value) <= 1e-12 * abs(value), key
            else:
                assert h[key] == value, key
        assert h["BUNIT"] == "JY/PIXEL" and h["FREQ"] == 230e9
        assert np.array_equal(f[0].data, img.flux[::-1, :, 0])
    # The cube, a documented choice: every frequency in one file.
    two = blackhole.load(
        GOLD,
        set={"image.width": 20, "image.height": 16, "image.samples": 1, "observe.frequency": [230e9, 345e9]},
    ).render()
    two.write(tmp_path / "cube.fits", cube=True)
    with fits.open(tmp_path / "cube.fits") as f:
        h = f[0].header
        assert f[0].data.shape == (2, 16, 20) and h["CTYPE3"] == "FREQ" and h["CDELT3"] == 115e9
        assert np.allclose(f[0].data.sum(axis=(1, 2), dtype=np.float64), two.stats["flux_jy"], rtol=1e-6)
    with pytest.raises(blackhole.BlackholeError, match="cube=True"):
        blackhole.load(CONFIGS / "quick.toml", set={"image.width": 8, "image.height": 8}).render().write(
            tmp_path / "q.fits", cube=True
        )


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
    assert blackhole.load(GOLD, set={"image.width": 8, "image.height": 8, "image.adaptive": False}).render().ring is not None
    assert blackhole.load(CONFIGS / "quick.toml", set={"image.width": 16, "image.height": 12}).render().ring is None
