"""The observables against closed forms (PHYSICS.md sections 3, 4 and 7):
a camera on the axis sees the disk face on, so every photon reaching it
has L_z = 0; its g is the gas's clock rate and the camera's, and the
radius map follows from Schwarzschild's orbit equation. And the FITS
file's WCS and spectra."""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

import blackhole
from conftest import ROOT

MASS = 8.57e36
R_S = 2 * 6.674e-11 * MASS / 299792458.0**2
R_O = 40.0  # the camera's radius (r_s)
SIZE = 96
FOV = 34.0  # degrees: the disk out to 10 r_s and the secondary ring


def face_on(spin=0.0, observables=("g", "radius", "order", "time", "class")):
    return {
        "image": {
            "width": SIZE,
            "height": SIZE,
            "png": "unused.png",
            "observables": list(observables),
            # Uniform sampling: pixels against per-ray closed forms.
            "adaptive": False,
        },
        "camera": {
            "position": [0.0, 0.0, R_O * R_S],
            "look_at": [0.0, 0.0, 0.0],
            "up": [0.0, 1.0, 0.0],
            "fov": FOV,
        },
        "black_hole": {"mass": MASS, "spin": spin},
        "physics": {"model": "gr"},
        # Point lookups: a footprint near the shadow lights hits inside the
        # material's edge with the edge's light, off this radius's formula.
        "disk": {
            "radius": 10.0,
            "texture": str(ROOT / "spectral_assets" / "disk_rgba.png"),
            "filter": "nearest",
        },
        "sky": {"color": [0.0, 0.0, 0.0]},
    }


def pixel_angles():
    """The angle (rad) of each pixel centre's ray from the view axis."""
    h = math.tan(math.radians(FOV) / 2)
    c = (np.arange(SIZE) + 0.5) / SIZE * 2 - 1
    sx, sy = np.meshgrid(c * h, -c * h)
    return np.arctan(np.hypot(sx, sy))


def sweeps(b, r_from, r_to):
    """The angles light of impact parameter b (r_s) sweeps from r_from to
    r_to (r_s): on its way in, and (where it has a periapsis) on its way out
    past it; (du/dphi)^2 = 1/b^2 - u^2 + u^3."""
    f = lambda u: 1 / b**2 - u * u + u**3
    u0, u1 = 1 / r_from, 1 / r_to
    if f(2 / 3) > 0:
        # No periapsis: it falls in.
        integrand = lambda u: 1 / math.sqrt(f(u))
        return [quad(integrand, u0, u1, epsabs=1e-13, epsrel=1e-12)[0]]
    up = brentq(f, 1e-15, 2 / 3, xtol=1e-15)
    # The square-root singularity at periapsis, by u = up - t^2 (float32
    # radii may sit a rounding below it).
    slope = 2 * up - 3 * up * up  # -f'(up) > 0

    def g(t):
        v = f(up - t * t)
        return 2 * t / math.sqrt(v) if v > 1e-12 * t * t * slope else 2 / math.sqrt(slope)

    leg = lambda u: quad(g, 0, math.sqrt(max(up - u, 0.0)), epsabs=1e-13, epsrel=1e-12, limit=200)[0]
    return [leg(u0) - leg(u1), leg(u0) + leg(u1)]


def ring_radius(b, r_from, angle):
    """The radius (r_s) where light of impact parameter b (r_s) from
    r_from has swept `angle`, or None where it falls in first."""
    f = lambda u: 1 / b**2 - u * u + u**3
    if f(2 / 3) > 0:
        inward = lambda r: sweeps(b, r_from, r)[0] - angle
        return brentq(inward, 1.0 + 1e-9, r_from, xtol=1e-13) if inward(1.0 + 1e-9) > 0 else None
    rp = 1 / brentq(f, 1e-15, 2 / 3, xtol=1e-15)
    if sweeps(b, r_from, rp)[0] >= angle:
        return brentq(lambda r: sweeps(b, r_from, r)[0] - angle, rp, r_from, xtol=1e-13)
    return brentq(lambda r: sweeps(b, r_from, r)[1] - angle, rp, 1e6, xtol=1e-13)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_sweep_reproduces_physics_md_section_4():
    """The test's own geometry: a far observer sees the ring of r = 6M at
    b = 6.932148 M directly, 5.478914 M on the other side of the hole."""
    far = 1e9
    assert sweeps(6.932148 / 2, far, 3.0)[0] == pytest.approx(math.pi / 2, abs=2e-6)
    assert sweeps(5.478914 / 2, far, 3.0)[1] == pytest.approx(3 * math.pi / 2, abs=2e-6)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_face_on_schwarzschild():
    # In closed form (a time map would have the rays integrated, their
    # crossings then within the integrator's tolerance).
    img = blackhole.loads(face_on(observables=("g", "radius", "order", "class"))).render()
    assert img.stats["closed"] == SIZE * SIZE
    o = img.observables
    g, r, order, cls = o["g"], o["radius"], o["order"], o["class"]
    psi = pixel_angles()
    # A static camera: b = r_o sin(psi) / sqrt(1 - r_s / r_o).
    b = R_O * np.sin(psi) / math.sqrt(1 - 1 / R_O)
    disk = np.isfinite(r)
    assert (cls[disk] == 1).all() and (cls[~disk] != 1).all()
    # PHYSICS.md 3: face on, g = sqrt(1 - 3M/r) / sqrt(1 - r_s/r_o).
    rd = r[disk].astype(np.float64)
    want = np.sqrt(1 - 1.5 / rd) / math.sqrt(1 - 1 / R_O)
    assert np.max(np.abs(g[disk] / want - 1)) < 2e-6
    helper = np.array([blackhole.disk_shift(x, observer=R_O) for x in rd])
    assert np.max(np.abs(helper / want - 1)) < 1e-12
    # Sky light is blueshifted by the camera's clock.
    sky = cls == 0
    assert sky.any()
    assert np.allclose(g[sky], 1 / math.sqrt(1 - 1 / R_O), rtol=1e-6)
    # The radius map: the direct image sweeps pi/2 from the camera to the
    # plane, the first lensed image 3 pi/2 round the hole, and so on.
    direct, lensed = disk & (order == 0), disk & (order == 1)
    assert direct.sum() > 2000 and lensed.sum() > 20
    assert set(np.unique(order[disk])) <= {0.0, 1.0, 2.0}
    # Image order n sweeps (2n + 1) pi / 2, round the hole past periapsis
    # from n = 1.
    # (the radius, not the angle, is compared: near periapsis the angle
    # changes infinitely fast with the radius).
    # (Every lensed pixel, a sample of the direct image's.)
    rng = np.random.default_rng(1)
    for n in (0, 1, 2):
        mask = disk & (order == n)
        if n == 0:
            keep = rng.choice(np.flatnonzero(mask), 150, replace=False)
            mask = np.zeros_like(mask)
            mask.flat[keep] = True
        angle = (2 * n + 1) * math.pi / 2
        worst = max(
            (abs(rr / ring_radius(float(bb), R_O, angle) - 1) for bb, rr in zip(b[mask], r[mask])),
            default=0.0,
        )
        assert worst < 1e-6, (n, worst)
    # The lensed pixels lie in the narrow band just outside the shadow
    # (PHYSICS.md 4: 5.48 to 5.87 M far away, the critical 3 sqrt(3) M).
    assert (b[lensed] > 3 * math.sqrt(3) / 2).all() and (b[lensed] < 3.0).all()


def test_travel_time():
    """The time map: at least the straight path's length from the disk to
    the camera, and the closed form's (Kerr, which keeps time) and the
    integrator's agree."""
    scene = face_on(spin=0.5, observables=("radius", "order", "time"))
    # A little off the axis, near which the closed form hands rays to the
    # integrator.
    scene["camera"]["position"][1] = 0.1 * R_S
    closed = blackhole.loads(scene).render()
    scene["physics"]["closed_form"] = False
    integrated = blackhole.loads(scene).render()
    assert closed.stats["closed"] == SIZE * SIZE and integrated.stats["closed"] == 0
    oc, oi = closed.observables, integrated.observables
    direct = (oc["order"] == 0) & (oi["order"] == 0)
    assert direct.sum() > 2000
    r, t = oc["radius"][direct], oc["time"][direct]
    straight = np.sqrt(R_O**2 + r.astype(np.float64) ** 2)
    assert (t > straight).all() and (t < straight + 10).all()
    # Measured 3.6e-7 (float32 maps).
    assert np.max(np.abs(oi["time"][direct] / t - 1)) < 2e-6


def test_face_on_kerr():
    """PHYSICS.md 7: seen from the axis, g = 1 / u^t of the prograde
    orbit, times the camera's lapse 1 / sqrt(1 - 2Mr/(r^2 + a^2))."""
    a = 0.9
    assert blackhole.disk_shift(3.0, spin=a) == pytest.approx(0.743444059, abs=1e-9)
    assert blackhole.disk_shift(5.0, spin=a) == pytest.approx(0.845936299, abs=1e-9)
    img = blackhole.loads(face_on(spin=a, observables=("g", "radius", "order"))).render()
    o = img.observables
    disk = np.isfinite(o["radius"])
    assert disk.sum() > 2000
    rm = 2 * o["radius"][disk].astype(np.float64)  # Boyer-Lindquist r in M
    ut = (rm**1.5 + a) / (rm**0.75 * np.sqrt(rm**1.5 - 3 * rm**0.5 + 2 * a))
    ro = 2 * R_O
    lapse = math.sqrt(1 - 2 * ro / (ro * ro + a * a))
    want = 1 / (ut * lapse)
    assert np.max(np.abs(o["g"][disk] / want - 1)) < 2e-6


def test_fits_wcs_and_spectra(tmp_path):
    pytest.importorskip("astropy")
    from astropy.io import fits
    from astropy.wcs import WCS

    scene = blackhole.load(
        ROOT / "configs" / "spectral_side.toml",
        set={
            "image.width": 40,
            "image.height": 24,
            "spectral.exr_layers": True,
            "image.exr_half": False,
            "image.observables": ["g", "class"],
        },
    )
    img = scene.render()
    img.write(tmp_path / "x.fits")
    img.write(tmp_path / "x.exr")
    with fits.open(tmp_path / "x.fits") as f:
        cube = f[0].data.copy()
        w = WCS(f[0].header)
        assert [h.name for h in f] == ["PRIMARY", "XYZ", "OBS.G", "OBS.CLASS"]
        # FITS rows are bottom-up.
        assert np.array_equal(cube[:, ::-1, :], np.transpose(img.spectra, (2, 0, 1)))
        assert np.array_equal(f["OBS.G"].data[::-1], img.observables["g"], equal_nan=True)
        # The film's scale, not SI (only the physical disk's is).
        assert f[0].header["BUNIT"] == ""
    # A pixel's spectrum is the EXR's spectral layer there (pixel (30, 5)
    # from the top: FITS row 24 - 5).
    import OpenEXR

    ch = OpenEXR.File(str(tmp_path / "x.exr")).channels()
    layer = {float(n[3:-2].replace(",", ".")): c.pixels for n, c in ch.items() if n.startswith("S0.")}
    exr = np.array([layer[x][5, 30] for x in img.wavelengths], dtype=np.float32)
    assert np.array_equal(cube[:, 24 - 1 - 5, 30], exr)
    # The wavelength axis in metres.
    nm = img.wavelengths
    spec = w.sub([3])
    got = spec.pixel_to_world_values(np.arange(len(nm)))
    assert np.allclose(got, nm * 1e-9, rtol=1e-12, atol=0)
    # The pixel scale from the field of view: tan-plane units per pixel
    # 2 tan(fov / 2) / height, in degrees at the centre.
    cel = w.celestial
    fov = 40.0  # spectral_side.toml's camera
    scale = math.degrees(2 * math.tan(math.radians(fov) / 2) / 24)
    assert np.allclose(np.abs(cel.pixel_scale_matrix).max(axis=1), scale, rtol=1e-12)
    # And each pixel's sky direction is the camera's ray through its centre
    # (galactic axes of the scene: l = atan2(-x, y), b = asin z).
    cam = np.array([0.0, -2.5e11, 1.5e10])  # the shipped camera (look_at the hole)
    fwd = -cam / np.linalg.norm(cam)
    right = np.cross(fwd, [0, 0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    h = math.tan(math.radians(fov) / 2)
    for i, j in ((0, 0), (39, 23), (20, 12), (5, 17)):
        # Pixel (i, j) from the top; FITS row 23 - j.
        sx = ((i + 0.5) / 40 * 2 - 1) * h * 40 / 24
        sy = (1 - (j + 0.5) / 24 * 2) * h
        d = fwd + right * sx + up * sy
        d /= np.linalg.norm(d)
        l, b = cel.pixel_to_world_values(i, 23 - j)
        l, b = math.radians(l), math.radians(b)
        want = np.array([-math.cos(b) * math.sin(l), math.cos(b) * math.cos(l), math.sin(b)])
        assert np.allclose(d, want, atol=1e-12), (i, j)


def test_the_footprint_observables_come_back_as_arrays():
    # magnification is finite where the sky is seen and NaN in the shadow;
    # sky comes as three channels and as one (H, W, 3) array of unit vectors.
    scene = blackhole.load(
        ROOT / "configs" / "quick.toml",
        set={
            "image.width": 32,
            "image.height": 24,
            "image.adaptive": False,
            "image.observables": ["magnification", "sky", "class"],
        },
    )
    img = scene.render()
    obs = img.observables
    sky = obs["sky"]
    assert sky.shape == (24, 32, 3)
    assert np.array_equal(sky[..., 0], obs["sky.x"], equal_nan=True)
    seen = ~np.isnan(sky[..., 0])
    assert seen.any() and (~seen).any()
    assert np.allclose(np.linalg.norm(sky[seen], axis=-1), 1.0, atol=1e-5)
    # Class 0 (sky) pixels have a magnification; captured ones none.
    cls = obs["class"]
    assert np.isfinite(obs["magnification"][cls == 0]).all()
    assert np.isnan(obs["magnification"][cls == 3]).all()
