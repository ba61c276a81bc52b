"""Shared fixtures of the Python package's tests (run by .ci/run after
``pip install .``): the repository, the command line built by
``cargo build --release`` for side-by-side checks, and whether a Vulkan
device (lavapipe in CI) is there for the GPU backend."""

import glob
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "configs"
IN_CI = bool(os.environ.get("CI"))


def need(ok, reason):
    """Skips with `reason` where a component is missing, fails in CI."""
    if ok:
        return
    if IN_CI:
        pytest.fail(f"{reason} (CI installs it)")
    pytest.skip(reason)


@pytest.fixture(scope="session")
def exe():
    path = pathlib.Path(os.environ.get("BLACKHOLE_EXE", ROOT / "target" / "release" / "blackhole"))
    need(path.exists(), f"the command line {path} is not built (cargo build --release)")
    return path


@pytest.fixture(scope="session")
def gpu():
    """The GPU backend can open a device (lavapipe is enough)."""
    need(
        bool(glob.glob("/usr/share/vulkan/icd.d/*.json")),
        "no Vulkan driver (apt install mesa-vulkan-drivers)",
    )


def run_cli(exe, *args):
    r = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r
