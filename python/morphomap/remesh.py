"""A closed surface remeshed with near-uniform triangles (CGAL's isotropic remeshing)."""

from __future__ import annotations

import trimesh

from . import _core
from ._validate import as_integer, as_real
from .prepared import as_surface


def remesh_surface(surface, edge_length, *, iterations=3):
    """The same closed surface with near-uniform triangles of edge length about ``edge_length``.

    CGAL's isotropic remeshing in the C++ core (edge splits, collapses, flips and tangential
    relaxation, every new vertex projected back onto the input), as :func:`surface_from_mask`
    uses; for coarse surfaces with long thin triangles, such as an open surface closed by a flat
    cap. ``map_surfaces`` refines such input itself for diffusion (see its ``method``); remesh
    first to have the field on the even vertices.

    Parameters
    ----------
    surface : trimesh.Trimesh or (vertices (V, 3) float, faces (F, 3) int)
        Closed, manifold, one piece; zero-area faces are removed first. The orientation is kept.
    edge_length : float
        Target edge length, in the surface's units (> 0).
    iterations : int
        Remeshing rounds (>= 1); three bring the smallest angles above 20 degrees on contoured masks.

    Returns
    -------
    trimesh.Trimesh
    """
    vertices, faces = as_surface(surface, "surface")
    if edge_length is None:
        raise TypeError("edge_length: expected a positive number, got None")
    remeshed = _core.remesh_surface(vertices, faces, as_real(edge_length, "edge_length", 0.0),
                                    as_integer(iterations, "iterations", 3))
    return trimesh.Trimesh(remeshed["vertices"], remeshed["faces"], process=False)
