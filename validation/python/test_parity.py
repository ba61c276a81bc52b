"""The arrays are the command line's files, bit for bit: the same scene
rendered by ``blackhole render`` (EXR and PNG read back) and by
``scene.render``, on the CPU and on the GPU."""

import numpy as np
import OpenEXR
import pytest
from PIL import Image as PILImage

import blackhole
from conftest import CONFIGS, run_cli

OBS = ["g", "radius", "order", "time", "class"]


def settings(tmp_path, tag):
    return {
        "image.width": 48,
        "image.height": 27,
        "image.samples": 2,
        "image.adaptive": False,
        "image.png": str(tmp_path / f"{tag}.png"),
        "image.exr": str(tmp_path / f"{tag}.exr"),
        "image.exr_xyz": True,
        "image.exr_half": False,
        "spectral.exr_layers": True,
        "image.observables": OBS,
    }


def cli_set(s):
    out = []
    for k, v in s.items():
        if isinstance(v, bool):
            v = str(v).lower()
        elif isinstance(v, list):
            v = "[" + ",".join(f'"{x}"' for x in v) + "]"
        out += ["--set", f"{k}={v}"]
    return out


def channels(path):
    return OpenEXR.File(str(path)).channels()


def same(a, b):
    """Bit for bit, NaN where NaN."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape and a.dtype == b.dtype
    assert np.array_equal(a.view(np.uint32), b.view(np.uint32))


@pytest.mark.parametrize("backend", ["cpu", "gpu"])
def test_arrays_are_the_cli_files(exe, tmp_path, backend, request):
    if backend == "gpu":
        request.getfixturevalue("gpu")
    config = CONFIGS / "spectral_side.toml"
    s = settings(tmp_path, "cli")
    run_cli(exe, "render", "-q", config, "--backend", backend, *cli_set(s))
    img = blackhole.load(config, set=settings(tmp_path, "py")).render(backend=backend)
    ch = channels(tmp_path / "cli.exr")
    same(img.rgb, ch["RGB"].pixels)
    same(img.xyz, np.stack([ch[c].pixels for c in "XYZ"], axis=-1))
    nm = img.wavelengths
    assert img.spectra.shape == (27, 48, len(nm))
    # Spectral channels "S0.<nm with a decimal comma>nm".
    layer = {float(n[3:-2].replace(",", ".")): c for n, c in ch.items() if n.startswith("S0.")}
    assert sorted(layer) == list(nm)
    for k in range(len(nm)):
        same(img.spectra[:, :, k], layer[nm[k]].pixels)
    for o in OBS:
        same(img.observables[o], ch[f"obs.{o}"].pixels)
    png = np.asarray(PILImage.open(tmp_path / "cli.png").convert("RGB"))
    assert np.array_equal(img.srgb8, png)
    # And the image's own files are the command line's.
    img.write(tmp_path / "py.png")
    img.write(tmp_path / "py.exr")
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "cli.exr").read_bytes()
    assert img.stats["samples"] == 48 * 27 * 2
    assert img.stats["backend"].startswith(backend)


def test_rgb_render_and_tile(exe, tmp_path):
    """An RGB scene, and a tile: its rows of the whole image."""
    config = CONFIGS / "quick.toml"
    s = {"image.width": 40, "image.height": 30, "image.png": str(tmp_path / "q.png")}
    run_cli(exe, "render", "-q", config, *cli_set(s))
    scene = blackhole.load(config, set=s)
    whole = scene.render()
    png = np.asarray(PILImage.open(tmp_path / "q.png").convert("RGB"))
    assert np.array_equal(whole.srgb8, png)
    assert whole.spectra is None and whole.wavelengths is None
    tile = scene.render(tile=(1, 3))
    assert tile.rows == (10, 20)
    same(tile.xyz, whole.xyz[10:20])
