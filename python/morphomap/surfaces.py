"""Closed triangle surfaces (3D): queries, vertex normals and displacement fields between two."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import _core
from ._progress import StageBar, as_progress
from ._validate import as_choice, as_faces, as_flag, as_points, as_real
from .chooser import BEST, CHOOSERS
from .field import DisplacementField
from .prepared import PreparedSurface, as_surface

#: What ``method`` takes: the methods with a 3D form in the core's method table, then ``"best"``,
#: which is Python's.
SURFACE_METHODS = tuple(row.name for row in _core.METHODS if row.surfaces) + (BEST,)
# The stages the core reports (SurfaceMappingOptions::on_stage), in order, for the progress bar.
DIFFUSION_STAGES = ("mesh", "solve", "trace")
_STAGES = {"diffusion": DIFFUSION_STAGES, "auto": ("normal",) + DIFFUSION_STAGES,
           "optimal": ("normal",) + DIFFUSION_STAGES + ("optimal",)}


class SurfaceHits(NamedTuple):
    """One row per query; NaN (faces: -1) where a line meets nothing.

    points : (M, 3) float, the point found on the surface.
    distances : (M,) float, Euclidean distance for closest points; for lines the signed distance
        from the origin along the unit direction.
    faces : (M,) int64, the triangle the point lies on.
    """

    points: np.ndarray
    distances: np.ndarray
    faces: np.ndarray


class SurfaceIndex:
    """A triangle surface prepared for many closest-point and line queries (Embree).

    The triangles go into an Embree scene placed in a unit box; every answer is refined in double
    precision on the original triangles. Queries run in C++ on all cores without the GIL. The
    surface need not be closed.

    Parameters
    ----------
    vertices : (V, 3) float
    faces : (F, 3) int
        Indices into ``vertices``; at least one face.
    """

    def __init__(self, vertices, faces):
        vertices = as_points(vertices, "vertices", 3)
        self._index = _core.SurfaceIndex(vertices, as_faces(faces, "faces", len(vertices)))

    def closest_points(self, queries) -> SurfaceHits:
        """Closest point on the surface to each query point (ties: the lowest face).

        queries : (M, 3) float
        """
        return SurfaceHits(**self._index.closest_points(as_points(queries, "queries", 3)))

    def line_intersections(self, origins, directions) -> SurfaceHits:
        """Nearest intersection of each whole line ``origin + t * direction`` (t of either sign).

        origins, directions : (M, 3) float; directions need not be unit, but not zero.
        Ties in ``|t|`` go to the positive side, then to the lowest face.
        """
        origins = as_points(origins, "origins", 3)
        directions = as_points(directions, "directions", 3)
        return SurfaceHits(**self._index.line_intersections(origins, directions))


def surface_normals(vertices, faces) -> np.ndarray:
    """Unit normal at each vertex: the angle-weighted mean of the normals of its triangles.

    vertices : (V, 3) float; faces : (F, 3) int. Returns (V, 3) float, outward on a closed surface
    with consistently oriented faces; NaN at a vertex that no non-degenerate face uses.
    """
    vertices = as_points(vertices, "vertices", 3)
    return _core.vertex_normals(vertices, as_faces(faces, "faces", len(vertices)))


def map_surfaces(s1, s2, method="auto", *, reverse=False, mesh_size=None, repeatable=True,
                 skip_below=None, workers=None, progress=None) -> DisplacementField:
    """Map closed surface ``s1`` (time t) onto closed surface ``s2`` (time t + dt).

    Parameters
    ----------
    s1, s2 : trimesh.Trimesh or (vertices (V, 3) float, faces (F, 3) int) or PreparedSurface
        Closed, consistently oriented triangle surfaces: every edge used by exactly two faces in
        opposite directions, finite coordinates, no zero-area face. Two :class:`PreparedSurface`
        skip the checks and index building they have done once.
    method : {"auto", "normal", "minimal_distance", "diffusion", "optimal", "best"}
        ``"minimal_distance"``: each vertex of ``s1`` to its closest point on ``s2``.
        ``"normal"``: the line through each vertex along its angle-weighted normal, both
        directions, to its nearest intersection with ``s2``; NaN where it meets nothing.
        ``"diffusion"``: streamlines of Laplace's equation in the region between the surfaces
        (c = 1 on S1, 0 on S2) from each vertex to S2; nested or crossing surfaces (see
        :func:`solve_diffusion_3d`), without self-intersections. Where the surfaces touch or
        coincide over a patch, its vertices map to their closest point (``field.method`` says
        ``"minimal_distance"``) and the rest of the region is meshed with S1 pulled back half an
        edge from S2 there. The streamlines never cross, but their discrete form can turn over a sliver
        narrower than the mesh's distance to the surfaces: the ends of such triangles are moved
        into the kernel of their image fan on S2 (a few tenths of an edge at most in the fuzz
        suite), so that the field has no folds where that succeeds; ``quality`` counts any left.
        ``"auto"`` (the default): a field of every vertex of ``s1`` with no folded triangle (see
        :func:`quality`, ``folds``), or :class:`GeometryError` saying how many vertices each way
        left unmapped and how many triangles folded, and where; never a folded field. Tried in
        turn, the first such field returned: normal mapping; between nested surfaces the normal
        field with diffusion within two mean gaps of where it failed (its ends blended into the
        normal ones and put on ``s2``); where ``s1`` has more than 10,000 vertices (a surface
        contoured from voxels, say), ``"auto"`` on copies of both surfaces remeshed at the edge
        length that gives ``s1`` about 5,000 vertices, carried back: each vertex of ``s1`` located
        on the copy of ``s1``, its end the same barycentric combination of that triangle's ends,
        put on ``s2`` along the copy of ``s2``'s normal (or at its closest point where that meets
        ``s2`` far off), and, where a few triangles fold, the last resort on it at once; reverse
        diffusion carried onto ``s1``'s vertices (the paper's choice; diffusion first where
        ``s2`` has fewer vertices); diffusion; the last resort on the complete field with the
        fewest folded triangles so far; minimal distance; normal mapping and minimal distance
        from ``s2``'s vertices, carried onto ``s1``'s (not after the coarse copies, whose
        candidates include them); the last resort on the least folded of all, where that is
        another. With ``reverse=True`` the same ways run from ``s2``, each carried onto ``s1``
        and judged there, without the coarse copies. A diffusion field with a few folded
        triangles left has the ends around them (up to 4 edges away) re-placed by the harmonic
        interpolation of the ends around, put on ``s2``, if that leaves no fold. The last resort
        moves the ends within 10 edges of the folded triangles along
        ``s2`` by the descent of ``"optimal"``, a folded triangle's area ratio counting negative,
        until none is folded (at most 5,000 ends and 40 steps; those vectors are labelled
        ``"optimal"``); where folds remain, on a field of at most 10,000 vertices (an ``s1``
        mapped without coarse copies, or the copies), it moves every end along ``s2`` to lower
        a distortion energy with a barrier at zero area (the untangling of Garanzha et al. 2021,
        at most 30 rounds; kept only where every image keeps some area; every vector labelled
        ``"optimal"``), else gives up.
        ``field.method`` says which way each vector came.
        ``"optimal"`` (beyond the paper): ``"auto"``'s field, then its ends moved along ``s2`` so
        that every triangle's image keeps its share of ``s2``'s area: E = sum_j (A'_j / (alpha
        A_j) - 1)^2 over the triangles (A_j, A'_j a triangle's area on ``s1`` and its image's,
        alpha = area(s2) / area(s1)), which is QM1 of the 3D quality measure and zero for any
        similarity (the radial map between concentric spheres is returned as it is). The gradient
        at an end q of triangle j is 2 (r_j - 1) / (alpha A_j) dA'_j/dq, dA'/dq = n' x (q_l -
        q_k) / 2 (n' the image's unit normal, (q, q_k, q_l) in order round it); each step moves
        every end by minus its gradient over a diagonal Gauss-Newton curvature, within ``s2``'s
        tangent plane, then onto ``s2`` by closest point, its share of the step cut where a
        triangle would fold and halved until E falls: every step keeps the field fold-free and
        every end on ``s2``. Stops when a step lowers E by less than 1e-6 of it. Every vector
        is labelled ``"optimal"``. Seconds on 10^4 triangles: a local descent, so it lowers QM
        (6.6x on the lung-like pair, 3,000x on the paper's Figure 12 pair; bench/README.md) without reaching the
        global optimum of a diffeomorphic registration.
        ``"best"`` (beyond the paper): normal, minimal distance and diffusion, each plain and
        reversed, ``"optimal"`` and ``"auto"``; the one without folds or misses of lowest QM, with the table
        of them all in ``field.candidates`` (:func:`morphomap.best.map_best_surfaces`). The pair
        of surfaces is one subproblem: the choice is per pair, not per piece as in 2D.
    reverse : bool
        Map S2 -> S1 with the chosen algorithm and carry the result onto S1's vertices: each vertex
        of S1 is located on the image of S2's triangles, and its end is the point of S2's triangle
        with the same barycentric coordinates (NaN where the reversed field left a hole there).
        As every field of this function, one vector per vertex of S1 in its order, with S1's faces.
    mesh_size : float, optional
        The tetrahedral mesh of diffusion mapping (also within ``"auto"``), as in
        :func:`solve_diffusion_3d`.
    repeatable : bool
        Diffusion mapping (also within ``"auto"`` and ``"best"``): ``False`` meshes on all cores,
        faster but not the same field bit for bit from run to run (see :func:`solve_diffusion_3d`).
    skip_below, workers : optional
        ``"best"`` only: see :mod:`morphomap.best`.
    progress : bool, optional
        ``"diffusion"`` and ``"auto"``: a progress bar (tqdm) on stderr naming the stage (auto's
        ``normal``, then diffusion's ``mesh``, ``solve``, ``trace``; where ``"auto"`` falls back
        to whole-surface diffusion after the local one, or to forward after reverse, the bar goes
        back to ``mesh``; it says ``coarse copies`` while a large ``s1`` is mapped through them,
        whose own stages follow, and ``untangle`` during the last resort). By default shown when
        stderr is a terminal and the call runs longer than 3 seconds; ``True``: at once;
        ``False``: never. The other methods are quick and show none; ``"best"`` takes only
        ``False`` or ``None`` (its candidates run side by side).

    Returns
    -------
    DisplacementField
        3D, with ``faces``: the connectivity of the start points.
    """
    method = as_choice(method, "method", SURFACE_METHODS)
    reverse = as_flag(reverse, "reverse")
    repeatable = as_flag(repeatable, "repeatable")  # before "best" runs its candidates
    progress = as_progress(progress)
    if method == BEST:
        if progress:
            raise ValueError(f"progress: method {BEST!r} runs its candidates side by side and shows no bar; "
                             "leave it None or False")
        if reverse:
            raise ValueError(f"reverse: method {BEST!r} tries the reversed forms itself; leave it False")
        return CHOOSERS["surfaces"](s1, s2, mesh_size=mesh_size, repeatable=repeatable, skip_below=skip_below,
                                    workers=workers)
    if skip_below is not None or workers is not None:
        raise ValueError(f"skip_below/workers: only for method {BEST!r}")
    prepared = isinstance(s1, PreparedSurface) and isinstance(s2, PreparedSurface)
    if not prepared:
        v1, f1 = as_surface(s1, "s1", core_checks=True)
        v2, f2 = as_surface(s2, "s2", core_checks=True)
    size = as_real(mesh_size, "mesh_size", 0.0)
    bar = StageBar(progress, "map_surfaces", _STAGES.get(method, ()))
    try:
        if prepared:
            record = _core.map_prepared_surfaces(s1._prepared, s2._prepared, method, reverse, size, repeatable,
                                                 bar.callback)
        else:
            record = _core.map_surfaces(v1, f1, v2, f2, method, reverse, size, repeatable, bar.callback)
    finally:
        bar.close()
    return DisplacementField._from_core(record)
