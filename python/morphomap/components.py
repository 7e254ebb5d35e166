"""Several objects in one curve array or one mesh, separated (the way out of the mapping's
"several components" errors)."""

from __future__ import annotations

import numpy as np
import trimesh

from ._validate import as_points
from .curves import signed_area
from .prepared import as_surface


def _loops(points: np.ndarray, gap: float | None) -> list[np.ndarray]:
    # Runs between jumps longer than `gap`, then loops closed where a point returns to one met
    # before on the way (the rule the mapping's check uses): each loop from the first visit to
    # the return, the walk going on from the first visit.
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    if gap is None:
        moving = steps[steps > 0]
        gap = 20.0 * float(np.median(moving)) if len(moving) else np.inf
    cuts = np.flatnonzero(steps > gap) + 1
    loops = []
    for run in np.split(points, cuts):
        seen: dict[tuple, int] = {}
        walk: list[int] = []
        for i, p in enumerate(map(tuple, run.tolist())):
            if walk and p == tuple(run[walk[-1]]):
                continue
            if p not in seen:
                seen[p] = len(walk)
                walk.append(i)
                continue
            at = seen[p]
            if len(walk) - at >= 3:
                loops.append(run[walk[at:]])
            for k in walk[at + 1:]:
                del seen[tuple(run[k])]
            del walk[at + 1:]
        if len(walk) >= 3:
            loops.append(run[walk])
    return loops


def split_components(value, *, gap=None):
    """Split one curve array or one triangle mesh into its separate objects, largest first.

    Parameters
    ----------
    value : (N, 2) float, trimesh.Trimesh or (vertices, faces)
        Points of closed curves stacked into one array (as when the contours of a mask with
        several objects, each repeating its first point at its end, are concatenated), or a mesh
        with several shells (an organ with debris).
    gap : float, optional
        Curves only: consecutive points further apart than this start a new object (default:
        20 times the median distance between consecutive points). Within a run, a loop is closed
        wherever a point returns to one met before.

    Returns
    -------
    list
        Curves: ``(K, 2)`` arrays of at least 3 points, by enclosed area, largest first (the
        closing repeat dropped). Meshes: ``trimesh.Trimesh`` (or ``(vertices, faces)`` pairs for a
        pair given) of each connected component, by surface area, largest first.
    """
    if isinstance(value, np.ndarray) or (isinstance(value, (list, tuple)) and len(value) != 2):
        points = as_points(value, "value")
        if gap is not None and (not np.isfinite(gap) or gap <= 0):
            raise ValueError(f"gap: must be a finite length > 0, got {gap}")
        return sorted(_loops(points, gap), key=lambda loop: abs(signed_area(loop)), reverse=True)
    vertices, faces = as_surface(value, "value")
    parts = trimesh.Trimesh(vertices, faces, process=False).split(only_watertight=False)
    parts = sorted(parts, key=lambda part: part.area, reverse=True)
    if isinstance(value, trimesh.Trimesh):
        return list(parts)
    return [(np.asarray(part.vertices), np.asarray(part.faces)) for part in parts]
