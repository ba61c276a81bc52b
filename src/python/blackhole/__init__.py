"""blackhole: a spectral renderer of a black hole as a gravitational lens.

Scenes come from TOML files, text or dicts with the command line's
overrides; renders return numpy arrays that view the film without copies::

    import blackhole
    scene = blackhole.load("configs/quick.toml", set={"image.width": 64})
    img = scene.render(backend="cpu")
    img.rgb        # linear sRGB, float32 (H, W, 3)
    img.write("quick.exr")

The user guide (GUIDE.md, "Python") describes the whole API.
"""

from ._native import (
    BlackholeError,
    Image,
    Scene,
    __version__,
    deflection,
    disk_shift,
    load,
    loads,
    rgb_to_spectrum,
    shadow_angle,
    shadow_curve,
    spectrum_to_xyz,
    wavelengths,
    xyz_to_srgb,
)
from ._native import srgb_encode_values as srgb_encode

#: The per-pixel maps a scene can ask for (``image.observables``).
OBSERVABLES = ("g", "radius", "order", "time", "class")

#: Codes of the ``class`` observable.
CLASSES = {0: "sky", 1: "disk", 2: "object", 3: "captured", 4: "out of steps", 5: "not finite"}

__all__ = [
    "BlackholeError",
    "CLASSES",
    "Image",
    "OBSERVABLES",
    "Scene",
    "__version__",
    "deflection",
    "disk_shift",
    "load",
    "loads",
    "rgb_to_spectrum",
    "shadow_angle",
    "shadow_curve",
    "spectrum_to_xyz",
    "srgb_encode",
    "wavelengths",
    "xyz_to_srgb",
]
