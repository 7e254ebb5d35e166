"""The pieces of diffusion mapping: the region mesh, the potential and the streamlines."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._validate import as_flag, as_points, as_real


@dataclass(frozen=True)
class DiffusionSolution:
    """The Laplace problem between two curves, solved.

    vertices : (V, 2) float and triangles : (T, 3) int64
        The region mesh (counter-clockwise triangles); every point of both curves is a vertex.
    potential : (V,) float
        c at the vertices: P1 finite elements with c = 1 on C1 and c = 0 on C2.
    ends : (N, 2) float
        Where the streamline of -grad c from each point of C1 meets C2 (NaN if it does not).
    streamlines : list of (K, 2) float
        With ``streamlines=True``: the polyline of each streamline, from C1 to C2.
    seconds : dict
        Time spent meshing (the region and its Dirichlet vertices), solving and tracing.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    potential: np.ndarray
    ends: np.ndarray
    streamlines: list
    seconds: dict


def solve_diffusion(c1, c2, *, closed=True, mesh_size=None, mesh_fraction=0.02, streamlines=False):
    """Solve Laplace's equation between C1 (c = 1) and C2 (c = 0) and trace the streamlines.

    The region: closed curves nested (an annulus) or crossing (each lobe of the symmetric
    difference); open curves joined start to start and end to end by straight edges without flux.
    The mesh: a triangular lattice (equilateral triangles) of spacing ``mesh_size`` (default:
    ``mesh_fraction`` times the mean gap, twice the region's area over its boundary length, but no
    finer than a lattice of max(40000, 20 per curve point) vertices over the region would be) inside
    the region, joined to both curves, whose points are all vertices, by CGAL's constrained
    Delaunay mesher (smallest angle about 20.7 degrees, graded from the curves' point spacing).
    Laplace's equation is solved with P1 elements; the gradient is recovered at the vertices and
    interpolated linearly, and the streamlines cross the mesh triangle by triangle in RK4 steps.

    Returns
    -------
    DiffusionSolution
    """
    found = _core.solve_diffusion(
        as_points(c1, "c1"), as_points(c2, "c2"), as_flag(closed, "closed"),
        as_real(mesh_size, "mesh_size", 0.0), as_real(mesh_fraction, "mesh_fraction", 0.02),
        as_flag(streamlines, "streamlines"))
    return DiffusionSolution(**found)
