"""Reading segmented images with the pixel or voxel size their files state.

TIFF through tifffile (single pages, multi-page stacks, ImageJ hyperstacks, OME-TIFF), PNG
through Pillow, ``.npy`` through numpy: the readers the field uses, so that a stack and its
voxel size come in as Fiji shows them.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree
from typing import NamedTuple, Optional

import numpy as np
import tifffile


class Image(NamedTuple):
    """An image and its spacing, unpacked as ``data, spacing = read_image(path)``."""

    data: np.ndarray
    #: The pixel / voxel size in the file's unit, in the array's axis order ((sy, sx) or
    #: (sz, sy, sx)); None where the file states none.
    spacing: Optional[tuple]


def _tiff_spacing(tif, stack: bool):
    """(sz, sy, sx) for a stack, (sy, sx) for a page: from OME-XML's PhysicalSize*, else from the
    resolution tags (pixels per ImageJ's unit, or per inch / centimetre, then in microns) with
    ImageJ's z ``spacing``; None where the file states no size."""
    if tif.is_ome and tif.ome_metadata:
        pixels = next((e for e in ElementTree.fromstring(tif.ome_metadata).iter() if e.tag.endswith("Pixels")), None)
        if pixels is not None and "PhysicalSizeX" in pixels.attrib:
            sx = float(pixels.attrib["PhysicalSizeX"])
            sy = float(pixels.attrib.get("PhysicalSizeY", sx))
            sz = float(pixels.attrib.get("PhysicalSizeZ", 1.0))
            return (sz, sy, sx) if stack else (sy, sx)
    tags = tif.pages[0].tags
    if "XResolution" not in tags or "YResolution" not in tags:
        return None

    def per_unit(tag):
        value = tags[tag].value
        return value[0] / value[1] if isinstance(value, tuple) else float(value)

    x_res, y_res = per_unit("XResolution"), per_unit("YResolution")
    if not (x_res > 0 and y_res > 0):
        return None
    imagej = tif.imagej_metadata or {}
    if imagej:
        scale = 1.0  # pixels per ImageJ's unit: the spacing is in that unit
    else:
        unit = int(tags["ResolutionUnit"].value) if "ResolutionUnit" in tags else 1
        scale = {2: 25400.0, 3: 10000.0}.get(unit)  # inch, centimetre -> microns
        if scale is None:
            return None  # no unit: an aspect ratio, not a size
    sy, sx = scale / y_res, scale / x_res
    return (float(imagej.get("spacing", 1.0)), sy, sx) if stack else (sy, sx)


def read_image(path) -> Image:
    """Read a segmented image (mask or label image) and the spacing its file states.

    PNG (its pHYs resolution, in microns), TIFF (single pages, multi-page stacks, ImageJ
    hyperstacks with their ``spacing`` and unit, OME-TIFF with its PhysicalSize*, in the
    file's unit) and ``.npy`` (no spacing). Returns ``Image(data, spacing)``: ``spacing`` in
    the array's axis order, or None where the file states none (then give it to
    :func:`boundary_from_mask`). Channels and time points of a hyperstack stay axes of
    ``data``; pick one before contouring.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path: expected a file name, got {type(path).__name__}")
    name = os.fspath(path)
    if not os.path.isfile(name):
        raise ValueError(f"path: no such file: {name}")
    suffix = os.path.splitext(name)[1].lower()
    if suffix == ".npy":
        return Image(np.load(name, allow_pickle=False), None)
    if suffix in (".tif", ".tiff"):
        with tifffile.TiffFile(name) as tif:
            data = tif.asarray()
            spacing = _tiff_spacing(tif, stack=data.ndim >= 3 and len(tif.series[0].pages) > 1)
        return Image(data, spacing)
    if suffix == ".png":
        from PIL import Image as PILImage  # Pillow: not a declared dependency (matplotlib brings it)

        with PILImage.open(name) as picture:
            data = np.asarray(picture)
            dpi = picture.info.get("dpi")
        spacing = None
        # A pHYs chunk of 72 dpi is a screen default that image programs write, not a size.
        if dpi and dpi[0] > 0 and dpi[1] > 0 and tuple(round(float(d)) for d in dpi) != (72, 72):
            spacing = (25400.0 / float(dpi[1]), 25400.0 / float(dpi[0]))
        return Image(data, spacing)
    raise ValueError(f"path: {name}: expected a .png, .tif, .tiff or .npy image")
