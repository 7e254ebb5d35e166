"""Diffusion mapping in 3D: the Laplace problem in the region between two closed surfaces."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._progress import StageBar
from ._validate import as_flag, as_real
from .prepared import as_surface
from .surfaces import DIFFUSION_STAGES


@dataclass(frozen=True)
class ShellDiffusionSolution:
    """The Laplace problem between two closed surfaces, solved.

    vertices : (V, 3) float and tetrahedra : (T, 4) int64
        The tetrahedral mesh of the region (CGAL Mesh_3, positively oriented). Its boundary
        approximates the surfaces; their vertices are not mesh vertices.
    potential : (V,) float
        c at the vertices: P1 finite elements with c = 1 on S1 and c = 0 on S2.
    ends : (N, 3) float
        For each vertex of S1, where its streamline of -grad c meets S2 (NaN if it does not); for a
        vertex that touches S2, its closest point there. Unless ``streamlines=True``, the
        streamlines are traced from the corners of the mesh's facets on S1 and each vertex's end
        is interpolated linearly over its facet, then put onto S2: faster for a finely
        triangulated S1, and closer to the exact map than a streamline per vertex (bench/README.md,
        "Exits interpolated from the mesh's source corners"). A vertex whose facet has a corner
        whose streamline was lost, and every vertex with ``streamlines=True``, is traced itself.
    touching : (N,) bool
        The vertices of S1 that touch S2 (within 1% of the finer mean edge): cut out of the region.
    streamlines : list of (K, 3) float
        With ``streamlines=True``: the polyline of each streamline, from the vertex of S1 to its end.
    seconds : dict
        Wall-clock time of the stages: ``mesh``, ``solve`` and ``trace``.
    """

    vertices: np.ndarray
    tetrahedra: np.ndarray
    potential: np.ndarray
    ends: np.ndarray
    touching: np.ndarray
    streamlines: list
    seconds: dict


def solve_diffusion_3d(s1, s2, *, mesh_size=None, streamlines=False, progress=None,
                       repeatable=True) -> ShellDiffusionSolution:
    """Solve Laplace's equation between S1 (c = 1) and S2 (c = 0) and trace the streamlines.

    Parameters
    ----------
    s1, s2 : trimesh.Trimesh or (vertices, faces)
        Closed, consistently oriented triangle surfaces without self-intersections. Either one
        lies inside the other (the region is the shell between them) or they cross: then the
        region is both pieces of their symmetric difference (S1 outside S2, bounded by that part
        of S1 and the part of S2 inside S1; and S2 outside S1), meshed with the crossing curves
        as edges, where c = 0. Where the surfaces touch or coincide over a patch (as frames
        contoured on one voxel grid do where the tissue did not move), the patch is cut out: the
        vertices of S1 within 1% of the finer mean edge of S2 map to their closest point there
        (``touching``), and those within half that edge are pulled back from S2 along S1's normals,
        to half an edge away on the side their surroundings lie, before the region is meshed
        (their streamlines start there). Where the surfaces also cross around such a patch, it
        is left to the crossing region: its vertices on S2 are lifted off by that 1% (they still
        map to their closest point), and a coincident patch left between the crossing curves is
        cut out of both pieces. Surfaces that lie apart or only touch from outside, faces of S1
        lying on S2 where the surfaces also cross, or a contact patch that the pull-back would
        fold into itself, raise ValueError;
        ``map_surfaces(..., method="auto")`` falls back to normal mapping there.
    mesh_size : float, optional
        Largest tetrahedron size. Default: a quarter of the mean gap (the region's volume over the
        mean area of the surfaces); in a thin shell, where that is finer than half the surfaces'
        spacing (mean edge, or 1.5% of the diagonal if larger), half that spacing but at most half
        the gap (frames a voxel apart: 8x fewer tetrahedra, bench/README.md, "Thin shells"). Near each
        surface the mesh follows its mean edge length (or ``mesh_size`` if smaller), but no finer
        than 1.5% of the surface's bounding diagonal (where the surface curves more tightly, the
        boundary facets still follow it to a fifth of that size), and grows by a tenth of the
        distance away from it.
    streamlines : bool
        Keep the polyline of each streamline.
    progress : bool, optional
        A progress bar (tqdm) on stderr naming the stage (mesh, solve, trace); by default when
        stderr is a terminal and the call runs longer than 3 seconds.
    repeatable : bool
        True (default): the same input gives the same mesh, potential and ends, bit for bit, in
        any process and with any number of threads (the mesher runs on one core with fixed
        random choices). False: the mesher runs in CGAL's parallel mode on all cores (nested
        surfaces; crossing ones still mesh on one core). It is faster, but the mesh depends on
        how the threads ran, so the ends differ from run to run within the discretisation error.

    Returns
    -------
    ShellDiffusionSolution
        ``ends[i]`` is the image of vertex ``i`` of S1 on S2.
    """
    v1, f1 = as_surface(s1, "s1", core_checks=True)
    v2, f2 = as_surface(s2, "s2", core_checks=True)
    size, keep = as_real(mesh_size, "mesh_size", 0.0), as_flag(streamlines, "streamlines")
    repeat = as_flag(repeatable, "repeatable")
    bar = StageBar(progress, "solve_diffusion_3d", DIFFUSION_STAGES)
    try:
        solved = _core.solve_diffusion_3d(v1, f1, v2, f2, size, keep, repeat, bar.callback)
    finally:
        bar.close()
    return ShellDiffusionSolution(**solved)
