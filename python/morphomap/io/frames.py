"""One frame of a time series from a file: a curve, a surface, or the boundary in a mask."""

from __future__ import annotations

import os
from typing import NamedTuple, Optional

# The readers come through the package's lazy names (morphomap/__init__.py): a curve file is read
# without the mesh and image readers' trimesh, scipy and scikit-image (about 0.55 s).
import morphomap

from .suffixes import IMAGE_SUFFIXES, SURFACE_SUFFIXES


class SourcedBoundary(NamedTuple):
    """What :func:`read_sourced_boundary` returns."""

    boundary: object  # an (N, 2) curve or a trimesh.Trimesh surface
    from_image: bool  # traced from a mask: x is the column, y the row (figures draw it y-down)
    unit: Optional[str]  # the unit of its coordinates: the image's, "pixel"; None where not known


def read_boundary(path, *, spacing=None, label=None, smooth=None, edge_length=None, report=None):
    """``(boundary, from_image)``: :func:`read_sourced_boundary` without the unit."""
    return read_sourced_boundary(path, spacing=spacing, label=label, smooth=smooth, edge_length=edge_length,
                                 report=report)[:2]


def read_sourced_boundary(path, *, spacing=None, label=None, smooth=None, edge_length=None, report=None):
    """``(boundary, from_image, unit)``: the curve in a CSV file, the surface in a mesh file (STL, PLY,
    OBJ, OFF), or the boundary of the mask in an image file (a 2D mask gives a curve, a 3D stack a
    surface), at ``spacing`` (one value or one per axis), else the spacing the file states, else 1.

    ``smooth``: as :func:`boundary_from_mask` and :func:`surface_from_mask` take it; None is
    each one's default (a sub-pixel outline of a 2D mask, a 3D stack unsmoothed).
    ``report``, given, is called with one line saying which spacing was used (with its unit, when
    it comes from the file: micrometres, :func:`read_image`'s default).

    An image with a T axis (a movie) or a C axis (RGB or channels) is refused with a ValueError
    saying so: a movie is mapped by ``morphomap series`` / :func:`map_series`, an RGB picture is
    segmented first.

    ``unit`` is the unit of the boundary's coordinates for figures: the image's where its spacing
    came from the file, ``"pixel"`` where neither the file nor ``spacing`` gives one, None for
    curve and mesh files and for a ``spacing`` given (whose unit is the caller's).
    """
    name = os.fspath(path)
    if name.lower().endswith(SURFACE_SUFFIXES):
        return SourcedBoundary(morphomap.read_surface(name), False, None)
    if not name.lower().endswith(IMAGE_SUFFIXES):
        return SourcedBoundary(morphomap.read_curve(name), False, None)
    image = morphomap.read_image(name)
    data, axes = image.data, image.axes
    if "T" in axes:
        raise ValueError(f"{name}: a movie (axes {axes}, {data.shape[axes.index('T')]} time points), not one frame: "
                         f"map it with `morphomap series` / map_series, which take the movie")
    if "C" in axes:
        raise ValueError(f"an RGB/multichannel image, not a mask: {name} (axes {axes}, shape {data.shape}): "
                         f"segment it first and save the mask or label image as one greyscale image")
    if data.ndim not in (2, 3):
        raise ValueError(f"a {data.ndim}D image (shape {data.shape}): expected a 2D mask or a 3D stack")
    unit = ""
    if spacing is not None:
        spacing, source, coordinates = tuple(spacing) if hasattr(spacing, "__len__") else (spacing,), "--spacing", None
    elif image.spacing is not None:
        spacing, source, unit = tuple(float(v) for v in image.spacing), "the file", f", in {image.unit}"
        coordinates = image.unit
    else:
        spacing, source, coordinates = (1.0,), "no spacing in the file, none given", "pixel"
    if report is not None:
        kind = "pixel" if data.ndim == 2 else "voxel"
        report(f"{name}: {kind} spacing {' x '.join(f'{v:g}' for v in spacing)} ({source}){unit}")
    if data.ndim == 2:
        return SourcedBoundary(morphomap.boundary_from_mask(data, spacing, label=label, smooth=smooth), True,
                               coordinates)
    return SourcedBoundary(morphomap.surface_from_mask(data, spacing, label=label,
                                                       smooth=0.0 if smooth is None else smooth,
                                                       edge_length=edge_length), True, coordinates)
