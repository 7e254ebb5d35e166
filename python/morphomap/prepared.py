"""Curves and surfaces as the mappings and the quality measures take them: arrays, meshes, or
prepared once (checked and indexed) for several calls. Below both mappings, so that each of them,
the quality measures and the repair of traced contours read one definition."""

from __future__ import annotations

import warnings

import numpy as np

from . import _core
from ._validate import as_faces, as_flag, as_points
from .simple import simple_curve


class PreparedCurve:
    """A curve checked and indexed once, for several mappings of it (beyond the paper).

    :func:`map_curves` and :func:`quality` take it wherever they take a curve; given two, they
    skip their checks (simple: one loop, no self-intersection) and reuse the curves' query
    indices, with the same results bit for bit. :func:`map_series` prepares each 2D frame once:
    frame k is the target of one pair and the source of the next.

    Parameters
    ----------
    points : (N, 2) float
        A simple curve, as :func:`map_curves` wants (checked here; copied as given).
    name : str
        How error messages name it.
    closed : bool
        Whether it is closed; the calls it is passed to must ask for the same (``ValueError``
        naming the argument otherwise).
    """

    def __init__(self, points, name: str = "curve", *, closed=True):
        # A copy, read-only: the core holds its own, and a caller editing the array afterwards must
        # not leave the two sides of a mixed call on different curves. Finiteness is the core's rule.
        self.points = np.array(as_points(points, str(name), allow_nan=True), copy=True)
        self.closed = as_flag(closed, "closed")
        try:
            self._prepared = _core.PreparedCurve(self.points, self.closed, str(name))
        except ValueError as error:
            # As map_curves: a traced contour is kept as make_simple repairs it, with a warning.
            points, changes = simple_curve(self.points, self.closed, str(name))
            if not changes:
                raise error from None
            warnings.warn(f"{name}: prepared as morphomap.make_simple makes it simple (pass its result to "
                          f"silence this): {changes}", UserWarning, stacklevel=2)
            self.points = points
            self._prepared = _core.PreparedCurve(self.points, self.closed, str(name))
        self.points.flags.writeable = False


def as_curve(value, name: str, *, allow_nan: bool = False) -> np.ndarray:
    """The points of a curve given as an array or as a :class:`PreparedCurve`."""
    return value.points if isinstance(value, PreparedCurve) else as_points(value, name, allow_nan=allow_nan)


def repaired_curves(c1, c2, closed: bool, stacklevel: int):
    """``c1`` and ``c2`` as :func:`make_simple` makes them (a :class:`PreparedCurve` is
    simple already and stays as it is), with one ``UserWarning`` naming each curve repaired
    and what was changed; and the changes, ``None`` for a curve left as it was.

    Raises ``ValueError`` naming ``c1`` or ``c2`` where one meets itself genuinely."""
    curves, changes, told = [], [], []
    for value, name in ((c1, "c1"), (c2, "c2")):
        if isinstance(value, PreparedCurve):
            curves.append(value)
            changes.append(None)
            continue
        points, changed = simple_curve(value, closed, name)
        curves.append(points if changed else value)
        changes.append(changed if changed else None)
        if changed:
            told.append(f"{name}: {changed}")
    if told:
        warnings.warn("mapped the curves as morphomap.make_simple makes them simple (pass its result to silence "
                      "this): " + "; ".join(told), UserWarning, stacklevel=stacklevel + 1)
    return curves, changes


def as_surface(value, name: str, *, core_checks: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(vertices, faces)`` of a ``trimesh.Trimesh`` or a ``(vertices, faces)`` pair.

    ``core_checks``: the values go to the core's ``check_closed_surface``, which checks that the
    vertices are finite and the face indices in range with the same messages; only types and
    shapes are checked here. Otherwise they are checked here."""
    if hasattr(value, "vertices") and hasattr(value, "faces") and not isinstance(value, (tuple, list)):
        vertices, faces = value.vertices, value.faces
    elif isinstance(value, (tuple, list)) and len(value) == 2:
        vertices, faces = value
    else:
        raise TypeError(f"{name}: expected a trimesh.Trimesh or a (vertices, faces) pair, got {type(value).__name__}")
    vertices = as_points(vertices, f"{name} vertices", 3, allow_nan=core_checks)
    return vertices, as_faces(faces, f"{name} faces", None if core_checks else len(vertices))


class PreparedSurface:
    """A closed surface checked and indexed once, for several mappings of it (beyond the paper).

    :func:`map_surfaces` and :func:`quality` take it wherever they take a surface; given two, they
    skip their checks (closed, oriented outwards) and reuse the surfaces' Embree scenes, with the
    same results bit for bit. :func:`map_series` prepares each frame once: frame k is the target of
    one pair and the source of the next.

    Parameters
    ----------
    surface : trimesh.Trimesh or (vertices (V, 3) float, faces (F, 3) int)
        Closed with outward faces, as :func:`map_surfaces` wants (checked here, by the core; copied).
    name : str
        How error messages name it.
    """

    def __init__(self, surface, name: str = "surface"):
        # Copies, read-only: the core holds its own, and a caller editing the mesh afterwards must not
        # leave the two sides of a mixed call on different surfaces.
        converted = as_surface(surface, name, core_checks=True)  # the core checks them (below)
        self.vertices, self.faces = (np.array(array, copy=True) for array in converted)
        self.vertices.flags.writeable = self.faces.flags.writeable = False
        self._prepared = _core.PreparedSurface(self.vertices, self.faces, str(name))
