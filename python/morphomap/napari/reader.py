"""The plugin's reader: label movies and stacks (TIFF, OME-TIFF) and closed mesh files, as napari
layers at the file's scale.

napari asks :func:`get_reader` for a path; it answers with a function that reads it, or None for
a file that is not ours (an RGB or multichannel image, a float image: not labels), so that
napari offers the file to other readers.
"""

from __future__ import annotations

import os

import numpy as np

from ..images.read import read_image
from ..io.meshes import read_surface
from .layers import to_pixels

#: The suffixes of the files read as label images and as surfaces.
IMAGES = (".tif", ".tiff")
MESHES = (".stl", ".ply", ".obj", ".off")


def get_reader(path):
    """napari's reader hook: a function that reads ``path`` into layers, or None where the path
    is not one file morphomap reads."""
    if isinstance(path, (list, tuple)):
        return None  # a stack of separate files: napari's own reader stacks them
    if not isinstance(path, (str, os.PathLike)):
        return None
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix in IMAGES:
        return read_labels
    if suffix in MESHES:
        return read_mesh
    return None


def labels_layer(image, name=None) -> tuple:
    """A :class:`morphomap.images.read.Image` of labels as a Labels layer data tuple: its axes in
    the file's order (time first where it has one), its spacing as the layer's spatial scale
    (time at scale 1: one step per frame), and in ``metadata`` its ``axes``, ``unit`` and
    ``frame_interval`` (seconds) for the widget."""
    if "C" in image.axes:
        raise ValueError(f"path: axes {image.axes}: a channel axis is not labels; save one channel of labels")
    if not (np.issubdtype(image.data.dtype, np.integer) or image.data.dtype == bool):
        raise TypeError(f"path: pixels of type {image.data.dtype}, not labels (integers) or a mask")
    order = [a for a in "TZYX" if a in image.axes]
    data = np.transpose(image.data, [image.axes.index(a) for a in order])
    spacing = dict(zip([a for a in image.axes if a in "ZYX"], image.spacing or ()))
    scale = [1.0 if a == "T" else float(spacing.get(a, 1.0)) for a in order]
    metadata = {"axes": "".join(order), "unit": image.unit, "frame_interval": image.frame_interval}
    options = {"scale": scale, "metadata": metadata}
    if name is not None:
        options["name"] = name
    return data, options, "labels"


def read_labels(path) -> list:
    """A TIFF of labels (ImageJ hyperstack, OME-TIFF, plain stack) as one Labels layer, by
    :func:`morphomap.read_image`; an RGB or non-integer image is not ours: napari's own reader
    takes it."""
    image = read_image(path)
    if "C" in image.axes or not (np.issubdtype(image.data.dtype, np.integer) or image.data.dtype == bool):
        return [(image.data, {"name": _name(path)}, "image")]
    return [labels_layer(image, _name(path))]


def read_mesh(path) -> list:
    """A closed surface (STL, PLY, OBJ, OFF; :func:`morphomap.read_surface`) as a Surface layer.
    The file's coordinates are physical (x, y, z); the layer holds them as (z, y, x) at scale 1,
    so that it lies on a stack shown at its voxel size."""
    mesh = read_surface(path)
    vertices = to_pixels(mesh.vertices, (1.0, 1.0, 1.0))
    return [((vertices, np.asarray(mesh.faces, dtype=np.int64)), {"name": _name(path)}, "surface")]


def _name(path) -> str:
    name = os.path.basename(os.fspath(path))
    for suffix in (".ome.tiff", ".ome.tif") + IMAGES + MESHES:
        if name.lower().endswith(suffix):
            return name[: -len(suffix)]
    return name
