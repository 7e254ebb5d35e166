"""Closed surfaces from and to mesh files (STL, PLY, OBJ, OFF), through trimesh."""

from __future__ import annotations

import os

import meshio
import numpy as np
import trimesh

from .. import _core
from ..prepared import as_surface
from .atomic import atomic_path
from .suffixes import SURFACE_SUFFIXES


def _suffix(path, name: str) -> str:
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a file name, got {type(path).__name__}")
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in SURFACE_SUFFIXES:
        raise ValueError(
            f"{name}: unknown mesh format {suffix or '(no suffix)'!r}: use one of {', '.join(SURFACE_SUFFIXES)}"
        )
    return suffix


def _require_closed_outward(vertices, faces, name: str) -> None:
    """The checks map_surfaces applies: closed, one piece, consistently oriented, outwards."""
    volume = _core.check_closed_surface(vertices, faces, name)
    if not volume > 0:
        raise ValueError(
            f"{name}: the faces are oriented inwards (enclosed volume {volume:g}): "
            f"reverse every face (trimesh: mesh.invert())"
        )


def read_surface(path):
    """Read a closed triangle surface from an STL, PLY, OBJ or OFF file.

    Vertices that coincide exactly are merged (STL stores each triangle with its own corners) and
    vertices no face uses are dropped; the surface must then be closed, one connected component,
    consistently oriented with its normals outwards, else ``ValueError`` names the file and the
    problem (use :func:`morphomap.split_components` for a file holding several objects).

    Returns a ``trimesh.Trimesh``.
    """
    _suffix(path, "path")
    if not os.path.isfile(path):
        raise ValueError(f"path: no such file: {os.fspath(path)}")
    try:
        mesh = trimesh.load(os.fspath(path), force="mesh", process=False)
    except Exception as error:  # trimesh raises many kinds for unreadable files
        raise ValueError(f"path: cannot read {os.fspath(path)} as a triangle mesh: {error}") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ValueError(f"path: {os.fspath(path)} holds no triangles")
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    mesh.remove_unreferenced_vertices()
    vertices, faces = as_surface(mesh, os.path.basename(os.fspath(path)))
    _require_closed_outward(vertices, faces, os.path.basename(os.fspath(path)))
    return trimesh.Trimesh(vertices, faces, process=False)


def write_surface(path, mesh) -> None:
    """Write a closed triangle surface (a ``trimesh.Trimesh`` or a ``(vertices, faces)`` pair) to an
    STL, PLY, OBJ or OFF file, chosen by the suffix: PLY binary with double coordinates (exact),
    OBJ and OFF as text with 15 decimals, STL binary in float32 as the format defines it. The
    write is atomic: a failed or interrupted write leaves the previous file as it was."""
    suffix = _suffix(path, "path")
    vertices, faces = as_surface(mesh, "mesh")
    surface = trimesh.Trimesh(np.asarray(vertices), np.asarray(faces), process=False)
    with atomic_path(path) as temporary:
        if suffix == ".ply":
            # trimesh writes PLY coordinates as float32; meshio keeps doubles.
            mesh = meshio.Mesh(surface.vertices, [("triangle", surface.faces.astype(np.int32))])
            meshio.write(temporary, mesh, file_format="ply", binary=True)
        else:
            # The text formats get every digit that matters; STL is float32 by its definition.
            surface.export(temporary, file_type=suffix[1:], **({"digits": 15} if suffix != ".stl" else {}))
