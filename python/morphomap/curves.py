"""Geometry of 2D curves: resampling, arc length, area, orientation, normals, intersections.

A curve is an ``(N, 2)`` array of points in order, closed unless ``closed=False``. A closed curve
does not repeat its first point at the end; if it does, the duplicate is dropped.
"""

from __future__ import annotations

import numpy as np

from . import _core
from ._validate import as_choice, as_flag, as_integer, as_points

RESAMPLE_METHODS = ("linear", "spline", "pchip")


def resample(points, n, *, closed=True, method="linear") -> np.ndarray:
    """Resample a curve to ``n`` points equally spaced in arc length (the paper's interparc).

    Parameters
    ----------
    points : (N, 2) float
        The curve. Exact consecutive repeats are dropped first.
    n : int
        Number of points wanted: at least 2 for an open curve, 3 for a closed one.
    closed : bool
        Closed curves start at ``points[0]`` and do not repeat it at the end; open curves keep both
        end points.
    method : {"linear", "spline", "pchip"}
        ``"linear"`` measures along the polyline; ``"spline"`` along a C2 cubic spline through the
        points (chord-length parameter, periodic when closed, natural ends when open);
        ``"pchip"`` along a shape-preserving piecewise cubic (Fritsch–Carlson). The spacing is
        measured along the interpolant's own arc length.

    Returns
    -------
    (n, 2) float
    """
    closed = as_flag(closed, "closed")
    method = as_choice(method, "method", RESAMPLE_METHODS)
    n = as_integer(n, "n", 0)  # the core checks the count
    return _core.resample(as_points(points, "points"), n, closed, method)


def arc_lengths(points, *, closed=True) -> np.ndarray:
    """Cumulative arc length at each point, 0 at the first: ``(N,)`` float."""
    return _core.arc_lengths(as_points(points, "points"), as_flag(closed, "closed"))


def perimeter(points, *, closed=True) -> float:
    """Length of the curve, with the closing segment when closed."""
    return _core.perimeter(as_points(points, "points"), as_flag(closed, "closed"))


def signed_area(points) -> float:
    """Signed area of the closed curve (shoelace formula); positive when counter-clockwise."""
    return _core.signed_area(as_points(points, "points"))


def orientation(points) -> int:
    """+1 for a counter-clockwise closed curve, -1 for a clockwise one."""
    return _core.orientation(as_points(points, "points"))


def normals(points, *, closed=True) -> np.ndarray:
    """Unit normal at each point: ``(N, 2)`` float.

    The normalised sum of the unit normals of the two segments meeting at the point (one segment at
    the ends of an open curve). Outward on a closed curve whatever its orientation; to the right of
    the direction of travel on an open curve.
    """
    return _core.normals(as_points(points, "points"), as_flag(closed, "closed"))


def is_self_intersecting(points, *, closed=True) -> bool:
    """True when two non-adjacent segments of the curve touch or cross (exact predicates)."""
    return _core.is_self_intersecting(as_points(points, "points"), as_flag(closed, "closed"))


def curve_intersections(c1, c2, *, closed=True, return_arc_lengths=False):
    """Points where ``c2`` crosses ``c1``, in order along ``c1``.

    Crossings are decided with exact predicates under a symbolic perturbation (C2 shifted by an
    infinitesimal vector to the right, then up), so every contact has a defined answer: a touch at
    one point where C2 does not pass to the other side of C1 is not a crossing, and where it does
    it is one. A shared (collinear) stretch that C2 passes through gives one crossing at an end of
    the stretch; one that C2 leaves on the side it came from gives none or two (at both ends),
    depending on the side the perturbation moves C2 to. Two closed curves cross an even number of
    times. Both curves are closed unless ``closed=False``.

    Returns
    -------
    points : (K, 2) float
    arc_lengths1, arc_lengths2 : (K,) float
        Only with ``return_arc_lengths=True``: the arc-length parameter of each point on ``c1`` and
        on ``c2``, measured from their first points.
    """
    closed = as_flag(closed, "closed")
    found = _core.curve_intersections(as_points(c1, "c1"), as_points(c2, "c2"), closed)
    if as_flag(return_arc_lengths, "return_arc_lengths"):
        return found["points"], found["arc_lengths1"], found["arc_lengths2"]
    return found["points"]
