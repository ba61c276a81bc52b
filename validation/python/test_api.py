"""The package's surface: scenes from files, text and dicts with the
command line's overrides and messages; bad input raises BlackholeError
(a fuzz of 100 dicts), never crashes; renders are the same from any
thread and thread count; Ctrl-C stops a render; progress is reported."""

import math
import os
import random
import signal
import threading
import time

import numpy as np
import pytest

import blackhole
from conftest import CONFIGS, ROOT

QUICK = CONFIGS / "quick.toml"
# Uniform sampling: the tests count samples.
SMALL = {"image.width": 32, "image.height": 24, "image.adaptive": False}


def test_load_overrides_and_info():
    scene = blackhole.load(QUICK, set=SMALL, unset=["disk.intensity"])
    assert scene.size == (32, 24)
    info = scene.info()
    assert info["schwarzschild radius r_s"].startswith("1.272787e10 m")
    assert "photon sphere (1.5 r_s)" in info
    img = scene.render()
    assert img.xyz.shape == (24, 32, 3) and img.xyz.dtype == np.float32
    assert img.srgb8.dtype == np.uint8
    assert not img.xyz.flags.writeable  # a view of the film
    assert img.xyz.base is not None
    s = img.stats
    assert s["samples"] == 32 * 24
    assert s["sky"] + s["disk"] + s["objects"] + s["captured"] + s["abandoned"] + s["non_finite"] == s["samples"]
    assert s["disk_share"] == pytest.approx(s["disk"] / s["samples"])
    assert s["seconds"] > 0


def test_text_and_dict_give_the_file_scene():
    text = QUICK.read_text()
    a = blackhole.load(QUICK, set=SMALL).render()
    b = blackhole.loads(text, base=CONFIGS, set=SMALL).render()
    import tomllib

    table = tomllib.loads(text)
    c = blackhole.loads(table, base=CONFIGS, set=SMALL).render()
    assert np.array_equal(a.xyz, b.xyz) and np.array_equal(a.xyz, c.xyz)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: blackhole.load(QUICK, set={"image.widht": 3}), "unknown key `widht` in [image] (did you mean `width`?)"),
        (lambda: blackhole.load(QUICK, set={"image.width": 0}), "image.width"),
        (lambda: blackhole.load(QUICK, unset=["camera.nothing"]), "`camera.nothing` is not set"),
        (lambda: blackhole.load(CONFIGS / "missing.toml"), "missing.toml"),
        (lambda: blackhole.loads("[image\nwidth = 3"), "<string>"),
        (lambda: blackhole.loads({"image": {"width": object()}}), "image.width: a object is not a scene value"),
        (lambda: blackhole.loads({"image": {1: 2}}), "the key 1 is not a string"),
        (lambda: blackhole.loads(3), "loads takes TOML text or a dict"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(backend="tpu"), 'backend "tpu"'),
        (lambda: blackhole.load(QUICK, set=SMALL).render(threads=0), "threads 0"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(time=1.0), "--time"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(tile=(3, 3)), "--tile 3/3"),
        (lambda: blackhole.load(QUICK, set={"image.observables": ["g", "g"]}), "expected each observable once"),
        (lambda: blackhole.load(QUICK, set={"image.observables": ["mass"]}), "unknown observable \"mass\""),
        (lambda: blackhole.shadow_angle(0.5), "outside the horizon"),
        (lambda: blackhole.deflection(1.0), "critical"),
        (lambda: blackhole.spectrum_to_xyz(np.ones((2, 1))), "expected 2 to"),
        (lambda: blackhole.loads(_self_containing(), base=CONFIGS), "nested more than 64 levels"),
        (lambda: blackhole.loads(QUICK.read_text(), base=QUICK), "expected a folder"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(threads=-1), "threads -1"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(tile=(-1, 2)), "tile (-1, 2)"),
        (lambda: blackhole.load(QUICK, set=SMALL).render(tile=(1, 2, 3)), "expected (i, n)"),
        (lambda: blackhole.wavelengths(-1), "-1 wavelengths"),
        (lambda: blackhole.load(QUICK, unset=3), "unset: expected a key"),
    ],
)
def test_bad_input_raises_the_cli_message(call, message):
    with pytest.raises(blackhole.BlackholeError) as e:
        call()
    assert message in str(e.value)


def _self_containing():
    loop = []
    loop.append(loop)
    return {"image": {"observables": loop}}


def test_numpy_values_and_lists_are_scene_values():
    scene = blackhole.load(
        QUICK,
        set={
            "image.width": np.int64(32),
            "image.height": np.uint16(24),
            "image.exr_xyz": np.bool_(True),
            "camera.position": np.array([0.0, -2.2e11, 3.0e10]),
            "camera.fov": np.float32(55.0),
        },
        unset="disk.intensity",
    )
    assert scene.size == (32, 24)
    tile = scene.render(tile=[0, 2])
    assert tile.rows == (0, 12)


def test_write_refuses_unknown_extensions_and_writes_nothing(tmp_path):
    img = blackhole.load(QUICK, set=SMALL).render()
    with pytest.raises(blackhole.BlackholeError, match=r"expected a \.png, \.exr or \.fits"):
        img.write(tmp_path / "x.jpg")
    (tmp_path / "a_file").write_text("")
    (tmp_path / "a_folder.fits").mkdir()
    with pytest.raises(blackhole.BlackholeError, match="a_folder.fits"):
        img.write(tmp_path / "a_folder.fits")
    for ext in ("png", "exr", "fits"):
        with pytest.raises(blackhole.BlackholeError):
            img.write(tmp_path / "a_file" / f"x.{ext}")
    assert sorted(os.listdir(tmp_path)) == ["a_file", "a_folder.fits"]
    # Every output gets the same mode (0666 less the umask).
    for ext in ("png", "exr", "fits"):
        img.write(tmp_path / f"ok.{ext}")
    modes = {os.stat(tmp_path / f"ok.{ext}").st_mode & 0o777 for ext in ("png", "exr", "fits")}
    assert len(modes) == 1


def _mutations(rng, base):
    """A scene dict with one part damaged the way a user might."""
    import copy

    d = copy.deepcopy(base)
    junk = [None, -1, 0, 1e308, float("nan"), "x", [], {}, [1, "a"], True, {"a": {"b": 1}}, 2**70]
    table = rng.choice(list(d))
    kind = rng.randrange(5)
    if kind == 0:
        d.pop(table)
    elif kind == 1 and isinstance(d[table], dict) and d[table]:
        d[table][rng.choice(list(d[table]))] = rng.choice(junk)
    elif kind == 2:
        d[table] = rng.choice(junk)
    elif kind == 3:
        d.setdefault(table, {})
        if isinstance(d[table], dict):
            d[table]["unknown_" + str(rng.randrange(100))] = 1
    else:
        d[rng.choice(["object", "cloud", "light", "stereo", "bloom", "animation"])] = rng.choice(junk + [[{"kind": "sphere"}]])
    return d


def test_fuzz_of_100_dicts_raises_or_renders():
    import tomllib

    base = tomllib.loads(QUICK.read_text())
    base["image"].update(width=8, height=6)
    rng = random.Random(23)
    raised = rendered = 0
    for _ in range(100):
        d = _mutations(rng, base)
        try:
            img = blackhole.loads(d, base=CONFIGS).render()
        except blackhole.BlackholeError as e:
            assert str(e), d
            raised += 1
        else:
            assert img.xyz.shape[2] == 3
            rendered += 1
    assert raised > 50 and raised + rendered == 100


def test_threads_give_the_same_pixels():
    scene = blackhole.load(QUICK, set={"image.width": 64, "image.height": 48, "image.samples": 2})
    one = scene.render(threads=1).xyz
    many = scene.render(threads=3).xyz
    assert np.array_equal(one, many)
    # Two renders in two Python threads at once (the GIL is released).
    out = [None, None]

    def work(i):
        out[i] = scene.render().xyz

    ts = [threading.Thread(target=work, args=(i,)) for i in (0, 1)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert np.array_equal(out[0], one) and np.array_equal(out[1], one)


def test_progress_and_ctrl_c(tmp_path):
    seen = []
    scene = blackhole.load(QUICK, set=SMALL)
    scene.render(progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1] == (24, 24) and all(t == 24 for _, t in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)
    # A render of minutes, interrupted after half a second.
    big = blackhole.load(QUICK, set={"image.width": 4096, "image.height": 4096, "image.samples": 16})
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        big.render()
    assert time.monotonic() - start < 30
    # A callback that raises stops the render too, with its exception.
    def stop(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        big.render(progress=stop)


def test_gpu_render_stops(gpu):
    """A raising callback stops a GPU render between its bands of rows, and
    the device is fine for the next render."""
    big = blackhole.load(QUICK, set={"image.width": 2048, "image.height": 2048, "image.samples": 4})

    def stop(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        big.render(backend="gpu", progress=stop)
    small = blackhole.load(QUICK, set=SMALL)
    assert np.array_equal(small.render(backend="gpu").srgb8, small.render(backend="gpu").srgb8)


def test_colour_helpers_shapes():
    nm = blackhole.wavelengths(81)
    assert nm[0] == 380 and nm[-1] == 780 and len(nm) == 81
    flat = np.ones((2, 3, 81))
    xyz = blackhole.spectrum_to_xyz(flat)
    assert xyz.shape == (2, 3, 3)
    # A flat spectrum of 1: Y is the area under ybar, 106.9 (GUIDE, colour).
    assert xyz[0, 0, 1] == pytest.approx(106.86, abs=0.01)
    rgb = blackhole.xyz_to_srgb(xyz / xyz[..., 1:2])
    assert rgb.shape == (2, 3, 3)
    enc = blackhole.srgb_encode(np.array([-1.0, 0.0, 0.0031308, 1.0, 2.0]))
    assert enc[0] == 0 and enc[1] == 0 and enc[3] == 1 and enc[4] == 1
    spec = blackhole.rgb_to_spectrum(np.array([[1.0, 1.0, 1.0]]), nm, kind="reflectance")
    assert spec.shape == (1, 81) and np.allclose(spec, 1.0, atol=0.02)
    # The image's own float32 arrays and plain lists are taken.
    img = blackhole.load(QUICK, set=SMALL).render()
    assert np.allclose(blackhole.xyz_to_srgb(img.xyz), img.rgb, rtol=1e-5, atol=1e-6)
    assert blackhole.srgb_encode([0.0, 1.0]).tolist() == [0.0, 1.0]


def test_closed_form_helpers_at_their_edges():
    # Spin 0: Schwarzschild's circle of 3 sqrt(3) M.
    c = np.array(blackhole.shadow_curve(0.0, 90.0, 64))
    assert np.allclose(np.hypot(c[:, 0], c[:, 1]), 3 * math.sqrt(3) / 2, rtol=1e-15)
    # Seen from the axis, a circle whose radius the curve approaches.
    axis = np.array(blackhole.shadow_curve(0.9, 0.0, 64))
    near = np.array(blackhole.shadow_curve(0.9, 0.02, 4096))
    r_axis = np.hypot(axis[:, 0], axis[:, 1])
    assert np.ptp(r_axis) < 1e-12
    assert np.allclose(np.hypot(near[:, 0], near[:, 1]), r_axis[0], rtol=5e-4)
    # The weak field: 2 r_s / b, continuous where the series takes over.
    assert blackhole.deflection(1e12) == pytest.approx(math.degrees(2e-12), rel=1e-12)
    # (The elliptic form just below 1e4 r_s, within 3e-12 of the series.)
    assert blackhole.deflection(1e4 * (1 - 1e-13)) == pytest.approx(blackhole.deflection(1e4), rel=1e-10)


def test_gpu_render_prints_nothing_without_a_runtime_folder(gpu):
    """Mesa's Vulkan layer complains on stderr when XDG_RUNTIME_DIR is
    unset; the package gives itself a private one at import, so a GPU render
    in a fresh interpreter without it prints nothing."""
    import subprocess
    import sys

    code = (
        "import blackhole\n"
        f"s = blackhole.load({str(QUICK)!r}, set={{'image.width': 16, 'image.height': 12}})\n"
        "s.render(backend='gpu')\n"
        "s.render(backend='gpu')\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "XDG_RUNTIME_DIR"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stderr == "", r.stderr


def test_readme_example_runs_and_writes_nothing_into_the_checkout(monkeypatch):
    """The README's Python example, run from the repository's root as it
    says, works and leaves no file behind in the checkout."""
    text = (ROOT / "README.md").read_text()
    start = text.index("```python\n") + len("```python\n")
    code = text[start : text.index("```", start)]
    monkeypatch.chdir(ROOT)
    before = set(os.listdir(ROOT))
    exec(compile(code, "README.md", "exec"), {})
    assert set(os.listdir(ROOT)) == before
