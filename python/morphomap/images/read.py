"""Reading segmented images with their axes, pixel or voxel size and frame interval as their files state.

TIFF through tifffile (single pages, multi-page stacks, ImageJ hyperstacks, OME-TIFF), PNG
through Pillow, ``.npy`` through numpy: the readers the field uses, so that a stack or a movie
comes in with the axes, sizes and time step Fiji shows for it.
"""

from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from typing import Optional

import numpy as np
import tifffile


@dataclass(frozen=True)
class Image:
    """An image as its file stores it, with what the file states about its axes, size and time.

    Attributes
    ----------
    data : ndarray
        The pixels as stored, one axis per letter of ``axes``.
    axes : str
        One letter per axis of ``data``: T (time), Z, Y, X, C (channels or RGB samples), in the
        file's order, e.g. ``"YX"``, ``"ZYX"``, ``"TYX"``, ``"TZYX"``, ``"YXC"``, ``"TCYX"``.
    spacing : tuple of float or None
        The size of a pixel along each spatial axis present, in the order of ``axes`` among Z, Y
        and X: ``(sy, sx)`` or ``(sz, sy, sx)``, in ``unit``. None where the file states no size.
    unit : str or None
        The unit of ``spacing`` (the one :func:`read_image` was asked for, ``"um"`` by default);
        None when ``spacing`` is None.
    frame_interval : float or None
        Seconds between time points; None where the file states none or there is no T axis.
    """

    data: np.ndarray
    axes: str
    spacing: Optional[tuple]
    unit: Optional[str]
    frame_interval: Optional[float]


#: Lengths in microns, by the names files give them (ImageJ's ``unit``, OME's ``PhysicalSize*Unit``).
_MICRONS = {"nm": 1e-3, "um": 1.0, "mm": 1e3, "cm": 1e4, "m": 1e6, "inch": 25400.0}
_LENGTH_NAMES = {"nanometer": "nm", "nanometers": "nm", "nanometre": "nm", "nanometres": "nm",
                 "µm": "um", "μm": "um", "\\u00b5m": "um", "micron": "um", "microns": "um",
                 "micrometer": "um", "micrometers": "um", "micrometre": "um", "micrometres": "um",
                 "millimeter": "mm", "millimeters": "mm", "centimeter": "cm", "centimeters": "cm",
                 "meter": "m", "meters": "m", "metre": "m", "metres": "m", "in": "inch", "inches": "inch"}
#: What ImageJ writes for an image without a size: its pixel is the unit.
_UNCALIBRATED = ("", "pixel", "pixels", "px")
#: The units :func:`read_image` gives its spacing in.
OUTPUT_UNITS = ("um", "nm", "mm", "cm", "m")
#: Durations in seconds, by the names files give them (ImageJ's ``tunit``, OME's ``TimeIncrementUnit``).
_SECONDS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0, "h": 3600.0, "d": 86400.0}
_TIME_NAMES = {"sec": "s", "secs": "s", "second": "s", "seconds": "s", "msec": "ms", "millisecond": "ms",
               "milliseconds": "ms", "µs": "us", "μs": "us", "microsecond": "us", "microseconds": "us",
               "mins": "min", "minute": "min", "minutes": "min", "hr": "h", "hrs": "h", "hour": "h",
               "hours": "h", "day": "d", "days": "d"}
#: tifffile's axis letters (TIFF.AXES) as read_image's: samples are channels; I and Q are
#: tifffile's generic pages (a stack without axes metadata), placed by _place_pages.
_AXIS_LETTERS = {"T": "T", "Z": "Z", "Y": "Y", "X": "X", "C": "C", "S": "C", "I": "?", "Q": "?"}


def _length_unit(name, path) -> str:
    """The canonical name of a length unit a file states; ValueError naming it and the file."""
    key = str(name).strip().lower()
    key = _LENGTH_NAMES.get(key, key)
    if key not in _MICRONS:
        raise ValueError(f"{path}: unknown length unit {name!r}: expected one of nm, um (µm, micron), mm, cm, m, "
                         f"inch or pixel")
    return key


def _seconds(value, name, path) -> Optional[float]:
    """``value`` in the time unit ``name``, in seconds; None for a missing or zero interval."""
    key = str(name).strip().lower()
    key = _TIME_NAMES.get(key, key)
    if key not in _SECONDS:
        raise ValueError(f"{path}: unknown time unit {name!r}: expected one of s (sec), ms, us, min, h or d")
    seconds = float(value) * _SECONDS[key]
    return seconds if seconds > 0 else None


def _place_pages(axes: str, count: int, path) -> str:
    """The axes with tifffile's generic pages placed: as Z, with a warning, where no Z is stated."""
    if "?" not in axes:
        return axes
    # Beside a stated Z, or twice, generic pages could be time or channels alike: no guess.
    if axes.count("?") > 1 or "Z" in axes:
        raise ValueError(f"{path}: pages of unstated meaning beside the axes {axes.replace('?', 'Q')}: save the "
                         f"file with its axes (ImageJ hyperstack or OME-TIFF metadata)")
    warnings.warn(f"{path}: the file does not say what its {count} pages are: assumed a z-stack of {count} "
                  f"pages. If they are time points (a movie) or channels, save the file with its axes (e.g. "
                  f"ImageJ hyperstack axes 'TYX', as tifffile.imwrite(..., imagej=True, metadata={{'axes': "
                  f"'TYX'}}) writes them, or OME-TIFF)", UserWarning,
                  stacklevel=5)  # the line that called read_image, through _tiff_axes and _read_tiff
    return axes.replace("?", "Z")


def _tiff_axes(series, path) -> str:
    """The axes of tifffile's series in read_image's letters; ValueError for any other axis."""
    axes = ""
    for letter in series.axes.upper():
        if letter not in _AXIS_LETTERS:
            raise ValueError(f"{path}: an axis {letter!r} (tifffile's axes {series.axes}): expected the axes T, Z, "
                             f"C, Y and X only")
        axes += _AXIS_LETTERS[letter]
    count = series.shape[axes.index("?")] if "?" in axes else 0
    return _place_pages(axes, count, path)


def _imagej_calibration(tif, path, spatial):
    """ImageJ's calibration: x and y from the resolution tags (pixels per ImageJ's ``unit``; ``yunit``
    and ``zunit`` where given), z from its ``spacing`` (1 where absent, ImageJ's default), the
    frame interval ``finterval`` in ``tunit`` (``sec`` where absent). Microns per axis, or None
    for an image in pixels; seconds or None."""
    meta = tif.imagej_metadata or {}
    interval = _seconds(meta["finterval"], meta.get("tunit", "sec"), path) if "finterval" in meta else None
    unit = str(meta.get("unit", "")).strip()
    if unit.lower() in _UNCALIBRATED:
        return None, interval
    x_res, y_res, _ = _resolution(tif.pages[0])
    if not (x_res > 0 and y_res > 0):
        return None, interval
    per_axis = {"X": _MICRONS[_length_unit(unit, path)] / x_res,
                "Y": _MICRONS[_length_unit(meta.get("yunit", unit), path)] / y_res}
    if "Z" in spatial:
        per_axis["Z"] = float(meta.get("spacing", 1.0)) * _MICRONS[_length_unit(meta.get("zunit", unit), path)]
    return per_axis, interval


def _ome_calibration(tif, path, spatial):
    """OME-XML's ``PhysicalSizeX/Y/Z`` in their ``PhysicalSize*Unit`` (µm where absent; z one x
    where absent) and ``TimeIncrement`` in ``TimeIncrementUnit`` (s where absent), of the first
    image. Microns per axis or None (where the file states no x size); seconds or None."""
    root = ElementTree.fromstring(tif.ome_metadata)
    pixels = next((e for e in root.iter() if e.tag.rsplit("}", 1)[-1] == "Pixels"), None)
    if pixels is None:
        return None, None
    attrib = pixels.attrib
    interval = None
    if "TimeIncrement" in attrib:
        interval = _seconds(attrib["TimeIncrement"], attrib.get("TimeIncrementUnit", "s"), path)
    if "PhysicalSizeX" not in attrib:
        return None, interval

    def size(axis, default):
        value = attrib.get(f"PhysicalSize{axis}", default[0])
        return float(value) * _MICRONS[_length_unit(attrib.get(f"PhysicalSize{axis}Unit", default[1]), path)]

    x = (attrib["PhysicalSizeX"], attrib.get("PhysicalSizeXUnit", "µm"))
    per_axis = {"X": size("X", x), "Y": size("Y", x)}
    if "Z" in spatial:
        per_axis["Z"] = size("Z", ("1", x[1]))
    return per_axis, interval


#: TIFF's ResolutionUnit (tifffile's RESUNIT) in microns: inch and centimetre, and tifffile's
#: millimetre and micrometre; NONE makes the resolution an aspect ratio, not a size.
_RESOLUTION_UNITS = {2: 25400.0, 3: 10000.0, 4: 1000.0, 5: 1.0}


def _resolution(page):
    """(pixels per unit along x, along y, TIFF's ResolutionUnit code) from the page's tags; 0 for
    a missing resolution. Read from the tags: tifffile's ``TiffPage.resolution`` is younger than
    the tifffile the package supports."""
    tags = page.tags

    def per_unit(name):
        value = tags[name].value if name in tags else 0
        return value[0] / value[1] if isinstance(value, tuple) and value[1] else float(value or 0)

    unit = int(tags["ResolutionUnit"].value) if "ResolutionUnit" in tags else 1
    return per_unit("XResolution"), per_unit("YResolution"), unit


def _plain_calibration(tif, spatial):
    """A plain TIFF's resolution tags, in pixels per inch or centimetre (z 1 µm, the tags stating
    none); None where they state no unit."""
    x_res, y_res, code = _resolution(tif.pages[0])
    scale = _RESOLUTION_UNITS.get(code)
    if scale is None or not (x_res > 0 and y_res > 0):
        return None
    per_axis = {"X": scale / x_res, "Y": scale / y_res}
    if "Z" in spatial:
        per_axis["Z"] = 1.0
    return per_axis


def _read_tiff(name):
    """(data, axes, microns per spatial axis or None, seconds or None) of a TIFF's first series."""
    with tifffile.TiffFile(name) as tif:
        series = tif.series[0]
        data = series.asarray()
        axes = _tiff_axes(series, name)
        spatial = "".join(a for a in axes if a in "ZYX")
        if tif.is_ome and tif.ome_metadata:
            per_axis, interval = _ome_calibration(tif, name, spatial)
        elif tif.is_imagej:
            per_axis, interval = _imagej_calibration(tif, name, spatial)
        else:
            per_axis, interval = _plain_calibration(tif, spatial), None
    if data.ndim != len(axes):
        raise ValueError(f"{name}: {data.ndim} axes in the data, {len(axes)} in the file's axes {axes}")
    return data, axes, per_axis, interval


def _read_png(name):
    """(data, axes, microns per axis or None): greyscale, palette and label PNGs are YX, RGB(A)
    YXC; the size from the pHYs chunk."""
    from PIL import Image as PILImage  # Pillow: not a declared dependency (matplotlib brings it)

    with PILImage.open(name) as picture:
        data = np.asarray(picture)
        dpi = picture.info.get("dpi")
    per_axis = None
    # A pHYs chunk of 72 dpi is a screen default that image programs write, not a size.
    if dpi and dpi[0] > 0 and dpi[1] > 0 and tuple(round(float(d)) for d in dpi) != (72, 72):
        per_axis = {"Y": 25400.0 / float(dpi[1]), "X": 25400.0 / float(dpi[0])}
    return data, "YX" if data.ndim == 2 else "YXC", per_axis


def _read_npy(name):
    data = np.load(name, allow_pickle=False)
    if data.ndim not in (2, 3):
        raise ValueError(f"{name}: a {data.ndim}D array: a .npy states no axes, so expected a 2D mask (YX) or a "
                         f"3D stack (ZYX); save a movie or a multichannel image as a TIFF with its axes")
    return data, "YX" if data.ndim == 2 else "ZYX"


def read_image(path, *, unit="um") -> Image:
    """Read a segmented image (mask, label image, stack or movie) with the axes, spacing and frame
    interval its file states.

    Parameters
    ----------
    path : str or path-like
        A ``.tif`` / ``.tiff`` (tifffile: single pages, multi-page stacks, ImageJ hyperstacks,
        OME-TIFF), a ``.png`` (Pillow) or a ``.npy`` (numpy) file.
    unit : {"um", "nm", "mm", "cm", "m"}
        The unit to give the spacing in (``"µm"`` and ``"micron"`` name ``"um"``).

    Returns
    -------
    Image
        ``data`` as stored; ``axes``, one letter per axis of ``data`` among T, Z, Y, X and C (C:
        channels or RGB samples); ``spacing``, one size per spatial axis in the order of
        ``axes`` (``(sy, sx)`` or ``(sz, sy, sx)``), converted to ``unit``; ``unit``; and
        ``frame_interval``, the seconds between time points. ``spacing`` and ``unit`` are None
        where the file states no size, ``frame_interval`` None where it states no interval or
        there is no T axis.

        - ImageJ TIFF: the hyperstack axes; x and y sizes from the resolution tags in ImageJ's
          ``unit`` (an image in pixels, or without a unit, has no size), z from its
          ``spacing`` (1 where absent, as in ImageJ); ``finterval`` in ``tunit`` (sec where
          absent).
        - OME-TIFF: the OME axes; ``PhysicalSizeX/Y/Z`` in their units (µm where absent; z 1
          of x's unit where absent); ``TimeIncrement`` in its unit (s where absent).
        - Other TIFF: the axes tifffile reads (its own shaped metadata included); x and y from
          the resolution tags where they give an inch or centimetre unit (z 1 µm).
        - PNG: ``"YX"`` (greyscale, palette, labels) or ``"YXC"`` (RGB, RGBA); the size from
          the pHYs chunk, except the 72 dpi screen default.
        - ``.npy``: ``"YX"`` or ``"ZYX"`` by the number of axes; no size.

        Channels and time points stay axes of ``data``: pick one before contouring.

    Raises
    ------
    ValueError
        For a missing file, an unsupported suffix, an axis other than T, Z, Y, X and C, a
        length or time unit that is not known (naming it and the file), or an unknown ``unit``.

    Warns
    -----
    UserWarning
        For a multi-page TIFF whose file does not say what its pages are (tifffile's generic
        ``I`` or ``Q`` axis): it is read as a z-stack (axis Z), never silently, and the warning
        says how to save a movie so that its pages are time points.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a file name, got {type(path).__name__}")
    wanted = _LENGTH_NAMES.get(str(unit).strip().lower(), str(unit).strip().lower())
    if wanted not in OUTPUT_UNITS:
        raise ValueError(f"unit: expected one of {', '.join(OUTPUT_UNITS)}, got {unit!r}")
    name = os.fspath(path)
    if not os.path.isfile(name):
        raise ValueError(f"path: no such file: {name}")
    suffix = os.path.splitext(name)[1].lower()
    interval = None
    if suffix == ".npy":
        (data, axes), per_axis = _read_npy(name), None
    elif suffix in (".tif", ".tiff"):
        data, axes, per_axis, interval = _read_tiff(name)
    elif suffix == ".png":
        data, axes, per_axis = _read_png(name)
    else:
        raise ValueError(f"path: {name}: expected a .png, .tif, .tiff or .npy image")
    spacing = None
    if per_axis is not None:
        scale = _MICRONS[wanted]
        spacing = tuple(float(per_axis[a]) / scale for a in axes if a in "ZYX")
    return Image(data, axes, spacing, None if spacing is None else wanted, interval if "T" in axes else None)
