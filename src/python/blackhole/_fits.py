"""FITS output of an image (astropy, the ``fits`` extra).

An observed scene's primary HDU is its flux cube in Jy per pixel, on sky
offsets in micro-arcseconds and the observed frequencies. Otherwise the
primary HDU is the spectral cube (wavelength axis ``WAVE`` in metres)
when the render kept spectra, else the linear sRGB planes; both with the
celestial WCS of the pixels (galactic longitude and latitude, TAN about the
camera's look direction). XYZ and every observable follow as image HDUs
with the same celestial WCS. Rows are stored bottom-up, as FITS viewers
show them.
"""

import os
import tempfile

import numpy as np

from . import BlackholeError


def _celestial(header, wcs):
    for key, value in wcs.items():
        header[key] = value


def _planes(header, wcs):
    """The celestial WCS of a cube of colour planes, its third axis the
    plane's number."""
    header["WCSAXES"] = 3
    _celestial(header, wcs)
    header["CRPIX3"] = 1.0
    header["CRVAL3"] = 1.0
    header["CD3_3"] = 1.0


def write(image, path):
    try:
        from astropy.io import fits
    except ImportError as e:  # pragma: no cover - the message is the point
        raise BlackholeError(
            f"{path}: FITS output needs astropy (pip install 'blackhole[fits]')"
        ) from e
    path = os.fspath(path)
    if image.flux is not None:
        _write_observed(fits, image, path)
        return
    wcs = image.wcs
    # SI only for the physical disk; else dimensionless, the film's scale.
    units = ("W m-2 sr-1 nm-1", "SI spectral radiance") if image.si_units else ("", "film scale: Y = 1 is display white")
    spectra = image.spectra
    if spectra is not None:
        nm = image.wavelengths
        cube = np.ascontiguousarray(np.transpose(spectra, (2, 0, 1))[:, ::-1, :])
        primary = fits.PrimaryHDU(cube)
        h = primary.header
        h["WCSAXES"] = 3
        _celestial(h, wcs)
        h["CTYPE3"] = "WAVE"
        h["CUNIT3"] = "m"
        h["CRPIX3"] = 1.0
        h["CRVAL3"] = float(nm[0]) * 1e-9
        # The celestial axes use CDi_j, so this one does too.
        h["CD3_3"] = (float(nm[1] - nm[0]) if len(nm) > 1 else 1.0) * 1e-9
        h["SPECSYS"] = ("TOPOCENT", "as the camera receives it")
        h["BUNIT"] = units
    else:
        cube = np.ascontiguousarray(np.transpose(image.rgb, (2, 0, 1))[:, ::-1, :])
        primary = fits.PrimaryHDU(cube)
        h = primary.header
        _planes(h, wcs)
        h["PLANES"] = ("R,G,B", "linear sRGB (Rec. 709 primaries, D65)")
        h["BUNIT"] = ("", "relative radiance: Y = 1 is display white")
    h["ORIGIN"] = "blackhole"
    hdus = [primary]
    xyz = fits.ImageHDU(
        np.ascontiguousarray(np.transpose(image.xyz, (2, 0, 1))[:, ::-1, :]), name="XYZ"
    )
    _planes(xyz.header, wcs)
    xyz.header["PLANES"] = ("X,Y,Z", "CIE 1931 XYZ, Y = 1 is display white")
    hdus.append(xyz)
    units_of = {"g": "", "radius": "r_s", "order": "", "time": "r_s/c", "class": ""}
    for name, plane in image.observables.items():
        hdu = fits.ImageHDU(np.ascontiguousarray(plane[::-1, :]), name=f"OBS.{name.upper()}")
        _celestial(hdu.header, wcs)
        hdu.header["BUNIT"] = units_of[name]
        hdus.append(hdu)
    try:
        _write_atomic(fits.HDUList(hdus), path)
    except OSError as e:
        raise BlackholeError(f"cannot write {path}: {e.strerror or e}") from e


def _write_observed(fits, image, path):
    """An observed scene: the flux cube (frequency, y, x) in Jy per pixel,
    its axes the sky offsets from the hole's direction in micro-arcseconds
    (x to the image's right, y up) and the frequency."""
    cube = np.ascontiguousarray(np.transpose(image.flux, (2, 0, 1))[:, ::-1, :])
    primary = fits.PrimaryHDU(cube)
    h = primary.header
    w, _ = image.size
    wcs = image.wcs
    scale = image.pixel_uas
    h["WCSAXES"] = 3
    for axis, name in ((1, "X"), (2, "Y")):
        h[f"CTYPE{axis}"] = (f"OFFSET-{name}", "sky offset from the hole's direction")
        h[f"CUNIT{axis}"] = "uas"
        h[f"CRVAL{axis}"] = 0.0
        h[f"CDELT{axis}"] = scale
    h["CRPIX1"] = wcs["CRPIX1"]
    h["CRPIX2"] = wcs["CRPIX2"]
    hz = [float(f) for f in image.frequencies]
    steps = np.diff(hz)
    h["CTYPE3"] = "FREQ" if len(hz) == 1 or np.allclose(steps, steps[0]) else "CHANNEL"
    h["CUNIT3"] = "Hz" if h["CTYPE3"] == "FREQ" else ""
    h["CRPIX3"] = 1.0
    h["CRVAL3"] = hz[0] if h["CTYPE3"] == "FREQ" else 1.0
    h["CDELT3"] = (float(steps[0]) if len(hz) > 1 else 1.0) if h["CTYPE3"] == "FREQ" else 1.0
    for k, f in enumerate(hz, start=1):
        h[f"FREQ{k}"] = (f, f"Hz, plane {k}")
    h["BUNIT"] = ("Jy/pixel", "flux density in each pixel")
    h["ORIGIN"] = "blackhole"
    try:
        _write_atomic(fits.HDUList([primary]), path)
    except OSError as e:
        raise BlackholeError(f"cannot write {path}: {e.strerror or e}") from e


def _write_atomic(hdus, path):
    """A temporary beside `path`, renamed over it once whole, with the mode
    the other outputs get (0666 less the umask)."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    if os.path.isdir(path):
        raise IsADirectoryError(21, "a folder of that name exists", path)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    os.close(fd)
    try:
        hdus.writeto(tmp, overwrite=True)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
