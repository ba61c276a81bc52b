"""FITS output of an image (astropy, the ``fits`` extra).

An observed scene writes what the Event Horizon Telescope's tools read
(ehtim's ``load_fits``): one file a frequency, the flux density in Jy per
pixel as the primary HDU, on RA---SIN / DEC--SIN axes in degrees about
the source (East to the left, CDELT1 < 0), with OBSRA, OBSDEC, FREQ, MJD,
OBJECT and BUNIT JY/PIXEL; several frequencies give ``x.230GHz.fits``,
``x.345GHz.fits``... beside the name asked for (their EXR channels' names).
``cube=True`` writes them all in one file instead, a (frequency, y, x)
cube with a FREQ axis, which ehtim does not read (it takes a 3-D primary
HDU for Stokes I, Q, U, V).

Otherwise the primary HDU is the spectral cube (wavelength axis ``WAVE``
in metres) when the render kept spectra, else the linear sRGB planes;
both with the celestial WCS of the pixels (galactic longitude and
latitude, TAN about the camera's look direction). XYZ and every
observable follow as image HDUs with the same celestial WCS. Rows are
stored bottom-up, as FITS viewers show them.
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


def write(image, path, cube=False):
    try:
        from astropy.io import fits
    except ImportError as e:  # pragma: no cover - the message is the point
        raise BlackholeError(
            f"{path}: FITS output needs astropy (pip install 'blackhole[fits]')"
        ) from e
    path = os.fspath(path)
    if image.flux is not None:
        _write_observed(fits, image, path, cube)
        return
    if cube:
        raise BlackholeError(f"{path}: cube=True is for observed scenes' frequencies; this image has none")
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


def _sky_header(header, image, hz):
    """ehtim's keywords (ehtim/io/save.py: save_im_fits) for the image at
    frequency `hz`, after the image's celestial WCS."""
    sky = image.sky
    for key, value in image.wcs.items():
        header[key] = value
    header["OBSRA"] = (sky["ra"], "source right ascension (deg, J2000)")
    header["OBSDEC"] = (sky["dec"], "source declination (deg, J2000)")
    header["FREQ"] = (hz, "observed frequency (Hz)")
    header["MJD"] = (sky["mjd"], "Modified Julian Date")
    header["OBJECT"] = sky["source"]
    header["TELESCOP"] = "VLBI"
    header["BUNIT"] = ("JY/PIXEL", "flux density in each pixel")
    header["DISTANCE"] = (sky["distance_pc"], "source distance (pc)")
    header["ORIGIN"] = "blackhole"


def _write_observed(fits, image, path, cube):
    """An observed scene: each frequency's flux density (Jy per pixel) in a
    file of ehtim's layout, or all of them in one cube."""
    sky = image.sky
    hz = [float(f) for f in sky["frequencies"]]
    flux = image.flux
    if cube:
        data = np.ascontiguousarray(np.transpose(flux, (2, 0, 1))[:, ::-1, :])
        primary = fits.PrimaryHDU(data)
        h = primary.header
        _sky_header(h, image, hz[0])
        h["WCSAXES"] = 3
        steps = np.diff(hz)
        even = len(hz) == 1 or np.allclose(steps, steps[0], rtol=1e-12)
        h["CTYPE3"] = "FREQ" if even else "CHANNEL"
        h["CUNIT3"] = "Hz" if even else ""
        h["CRPIX3"] = 1.0
        h["CRVAL3"] = hz[0] if even else 1.0
        h["CDELT3"] = (float(steps[0]) if len(hz) > 1 else 1.0) if even else 1.0
        for k, f in enumerate(hz, start=1):
            h[f"FREQ{k}"] = (f, f"Hz, plane {k}")
        _write_each([(path, fits.HDUList([primary]))])
        return
    files = []
    stem, ext = os.path.splitext(path)
    for k, f in enumerate(hz):
        primary = fits.PrimaryHDU(np.ascontiguousarray(flux[::-1, :, k]))
        _sky_header(primary.header, image, f)
        primary.header["STOKES"] = "I"
        name = path if len(hz) == 1 else f"{stem}.{sky['channels'][k][3:]}{ext}"
        files.append((name, fits.HDUList([primary])))
    _write_each(files)


def _write_each(files):
    """Each (path, HDUList) atomically; a failure names the file."""
    for path, hdus in files:
        try:
            _write_atomic(hdus, path)
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
