"""GRMHD snapshots from Python: the dump `blackhole torus` writes, read by
h5py (the HDF5 C library), and the plasma the renderer sees at cell
centres against the primitives and ipole's formulae evaluated here
independently; the same dump rewritten by h5py with electrons, chunked and
compressed, read back; and the mass unit fitted to a flux."""

import subprocess

import numpy as np
import pytest

import blackhole
from conftest import CONFIGS, need

try:
    import h5py
except ImportError:
    h5py = None


@pytest.fixture(autouse=True)
def _h5py():
    """h5py (validation/python/requirements.txt), the HDF5 C library's
    reader and writer: the dumps' other client."""
    need(h5py is not None, "h5py is not installed (pip install h5py==3.16.0)")

# CODATA, cgs (as the renderer's).
MP, ME, C = 1.67262192369e-24, 9.1093837015e-28, 2.99792458e10
MASS_KG = 1.292506e40


def scene_text(dump, extra="", mass=MASS_KG, m_unit=1e27):
    return f"""
[image]
width = 8
height = 8
png = "unused.png"
[camera]
position = [1e15, 0.0, 1e16]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov = 3.0
[black_hole]
mass = {mass!r}
spin = 0.9375
[sky]
color = [0.0, 0.0, 0.0]
[medium]
kind = "grmhd"
dump = "{dump}"
m_unit = {m_unit!r}
{extra}
[observe]
distance = "16.8 Mpc"
frequency = "230 GHz"
"""


def ks_metric(a, r, th):
    """Kerr-Schild g_mu nu (t, r, theta, phi) and g^t mu, M = 1."""
    s, c = np.sin(th), np.cos(th)
    sig = r * r + a * a * c * c
    z = 2 * r / sig
    g = np.zeros((4, 4))
    g[0, 0] = -(1 - z)
    g[0, 1] = g[1, 0] = z
    g[0, 3] = g[3, 0] = -z * a * s * s
    g[1, 1] = 1 + z
    g[1, 3] = g[3, 1] = -a * s * s * (1 + z)
    g[2, 2] = sig
    g[3, 3] = s * s * (sig + a * a * s * s * (1 + z))
    return g, np.array([-(1 + z), z, 0.0, 0.0])


def four_vectors(a, r, th, d2, prim):
    """u^mu, b^mu (KS, code units) from MKS primitives, as ipole's
    load_iharm_data builds them."""
    jac = np.array([r, 0.0, 0.0, 0.0, d2, 0.0, 0.0, 0.0, 1.0]).reshape(3, 3)  # MKS: dtheta/dX1 = 0
    v = jac @ prim[2:5]
    B = jac @ prim[5:8]
    g, gt = ks_metric(a, r, th)
    vv = v @ g[1:, 1:] @ v
    ufac = np.sqrt(-(1 + abs(vv)) / gt[0])
    u = np.array([-ufac * gt[0], *(v - ufac * gt[1:])])
    ul = g @ u
    bt = B @ ul[1:]
    b = np.array([bt, *((B + u[1:] * bt) / u[0])])
    return u, b, b @ g @ b


@pytest.fixture(scope="module")
def dumps(exe, tmp_path_factory):
    d = tmp_path_factory.mktemp("grmhd")
    mks = d / "mks.h5"
    subprocess.run([exe, "torus", str(mks), "--grid", "32x16x4", "-q"], check=True)
    # The same torus rewritten by h5py, with electrons (KEL, KTOT),
    # /prims chunked and deflated: a file as the C library writes it.
    rng = np.random.default_rng(7)
    elec = d / "electrons.h5"
    with h5py.File(mks, "r") as src, h5py.File(elec, "w") as dst:
        src.copy("header", dst)
        dst["t"] = src["t"][()]
        dst["dump_cadence"] = src["dump_cadence"][()]
        p = src["prims"][()]
        kel = rng.uniform(0.5, 2.0, p.shape[:3] + (1,))
        dst.create_dataset("prims", data=np.concatenate([p, kel, kel], axis=3), chunks=(8, 8, 4, 10), compression="gzip")
        del dst["header/n_prim"], dst["header/has_electrons"]
        dst["header/n_prim"] = np.int32(10)
        dst["header/has_electrons"] = np.int32(1)
    return mks, elec


def cells(h):
    """Some cell centres (i, j, k) and their r, theta, phi."""
    n1, n2, n3 = (int(h[f"header/n{k}"][()]) for k in (1, 2, 3))
    geom = h["header/geom"]
    start = [geom[f"startx{k}"][()] for k in (1, 2, 3)]
    dx = [geom[f"dx{k}"][()] for k in (1, 2, 3)]
    hs = geom["mks/hslope"][()]
    picks = [(i, j, k) for i in (3, 9, 14, 20, 27) for j in (2, 6, 8, 11) for k in (0, 3)]
    x = np.array([[start[d] + (c[d] + 0.5) * dx[d] for d in range(3)] for c in picks])
    r = np.exp(x[:, 0])
    th = np.pi * x[:, 1] + 0.5 * (1 - hs) * np.sin(2 * np.pi * x[:, 1])
    d2 = np.pi * (1 + (1 - hs) * np.cos(2 * np.pi * x[:, 1]))
    return picks, x, r, th, d2


def test_the_plasma_at_cell_centres_is_the_dumps_by_the_formulae(dumps):
    mks, elec = dumps
    with h5py.File(mks, "r") as h:
        assert h["header/metric"][()] == b"MKS"
        a = h["header/geom/mks/a"][()]
        gam = h["header/gam"][()]
        prims = h["prims"][()]
        picks, x, r, th, d2 = cells(h)
    r_high, r_low, beta_crit = 20.0, 1.0, 1.0
    scene = blackhole.loads(scene_text(mks, f"r_high = {r_high}\nr_low = {r_low}\nbeta_crit = {beta_crit}"))
    got = scene.plasma(list(r), list(th), list(x[:, 2]))
    L = got["cm_per_m"]
    rho_unit = 1e27 / L**3
    b_unit = C * np.sqrt(4 * np.pi * rho_unit)
    # The cells are kept in single precision (each value to 6e-8 of
    # itself; u and b^mu are built from the primitives so rounded): to
    # 3e-7 of each value, or of the largest component of a vector.
    close = 3e-7
    for n, (i, j, k) in enumerate(picks):
        p = prims[i, j, k]
        u, b, bsq = four_vectors(a, r[n], th[n], d2[n], p)
        assert np.allclose(got["native"][n], x[n], rtol=0, atol=1e-12)
        assert got["n_e"][n] == pytest.approx(p[0] * rho_unit / (MP + ME), rel=close)
        assert got["b"][n] == pytest.approx(np.sqrt(bsq) * b_unit, rel=close)
        # (below 1.2e-38 single precision keeps 1.4e-45 absolute)
        assert got["sigma"][n] == pytest.approx(max(bsq / p[0], 1e-40), rel=close, abs=1e-44)
        assert np.allclose(got["u"][n], u, rtol=0, atol=close * np.max(np.abs(u)))
        assert np.allclose(got["b_mu"][n], b * b_unit, rtol=0, atol=close * np.max(np.abs(b)) * b_unit)
        # R-high/R-low (Moscibrodzka et al. 2016), gam_e = 4/3, gam_p = 5/3.
        # An unmagnetised cell (bsq = 0) takes the floor, as ipole's (its
        # R there is inf / inf).
        if bsq > 0:
            beta = p[1] * (gam - 1) / (0.5 * bsq) / beta_crit
            ratio = (r_high * beta**2 + r_low) / (1 + beta**2)
            te = (MP / ME) * (1 / 3) * (2 / 3) / ((2 / 3) + (1 / 3) * ratio) * p[1] / p[0]
        else:
            te = 0.0
        assert got["theta_e"][n] == pytest.approx(max(te, 1e-3), rel=close)
    # The dump's own electrons, from h5py's chunked, deflated file.
    with h5py.File(elec, "r") as h:
        prims = h["prims"][()]
    scene = blackhole.loads(scene_text(elec, 'electrons = "dump"'))
    got = scene.plasma(list(r), list(th), list(x[:, 2]))
    for n, (i, j, k) in enumerate(picks):
        p = prims[i, j, k]
        te = (MP / ME) * p[8] * p[0] ** (1 / 3)
        assert got["theta_e"][n] == pytest.approx(max(te, 1e-3), rel=close)
        assert got["n_e"][n] == pytest.approx(p[0] * rho_unit / (MP + ME), rel=close)


def test_the_mass_unit_is_fitted_from_python():
    scene = blackhole.load(CONFIGS / "m87_torus.toml", set={"image.width": 24, "image.height": 24})
    fit = scene.fit_m_unit()
    assert abs(fit["jy"] / 0.5 - 1) < 1e-3
    assert 1 < fit["slope"] < 5 and len(fit["tries"]) >= 2
    img = fit["scene"].render()
    assert img.stats["m_unit"] == fit["m_unit"]
    assert img.stats["flux_jy"][0] == pytest.approx(fit["jy"], rel=1e-12)
    # render() fits medium.flux itself, as the command line does.
    again = scene.render()
    assert abs(again.stats["flux_jy"][0] / 0.5 - 1) < 1e-3
    # Another target, given here.
    other = scene.fit_m_unit(flux=0.25)
    assert abs(other["jy"] / 0.25 - 1) < 1e-3 and other["m_unit"] < fit["m_unit"]
    with pytest.raises(blackhole.BlackholeError, match="grmhd"):
        blackhole.load(CONFIGS / "quick.toml").fit_m_unit(flux=1.0)


def test_the_plasma_along_one_of_ipoles_rays(exe, tmp_path):
    # ipole's own trace of one ray (pixel (3, 4) of 8 x 8 at the reference
    # settings of mks163_230; validation/reference/ipole_torus), every
    # 20th step where it found gas: its n_e, Theta_e, |b| and sigma,
    # interpolated from the same cells, are ours at its points to 1e-6
    # (its constants differ from ours in the seventh digit).
    dump = tmp_path / "mks.h5"
    subprocess.run([exe, "torus", str(dump), "-q"], check=True)
    ref = np.genfromtxt(CONFIGS.parent / "validation/reference/ipole_torus/trace_mks163_230.csv", delimiter=",", names=True)
    scene = blackhole.loads(scene_text(dump, "r_high = 1.0\nr_low = 1.0", mass=1.2332169547497754e40, m_unit=1e29))
    got = scene.plasma(list(ref["r"]), list(ref["theta"]), list(ref["phi"]))
    assert len(ref) > 600
    for key, col in [("n_e", "n_e"), ("theta_e", "theta_e"), ("b", "b_gauss"), ("sigma", "sigma")]:
        ours = np.array(got[key])
        assert np.allclose(ours, ref[col], rtol=1e-6, atol=1e-12 * np.max(ref[col])), key
    # Unmagnetised cells along it (b = 0) at ipole's floor of Theta_e.
    cold = ref["b_gauss"] == 0
    # (the floor as single precision holds it, to 5e-8)
    assert np.any(cold) and np.allclose(np.array(got["theta_e"])[cold], 1e-3, rtol=1e-7, atol=0)
