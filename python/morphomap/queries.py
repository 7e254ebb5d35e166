"""Closest points and line intersections of many queries against one polyline."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import _core
from ._validate import as_flag, as_points


class CurveHits(NamedTuple):
    """One row per query; NaN (segments: -1) where a line meets nothing.

    points : (M, 2) float, the point found on the curve.
    distances : (M,) float, Euclidean distance for closest points; for lines the signed distance
        from the origin along the unit direction.
    segments : (M,) int64, segment i runs from point i to point i+1 (wrapping when closed).
    arc_lengths : (M,) float, arc-length parameter of the point from the curve's first point.
    """

    points: np.ndarray
    distances: np.ndarray
    segments: np.ndarray
    arc_lengths: np.ndarray


class CurveIndex:
    """A polyline with a bounding-volume hierarchy over its segments, for many queries.

    Build it once and query it many times; queries run in C++ on all cores without the GIL.

    Parameters
    ----------
    curve : (N, 2) float
        Closed unless ``closed=False``; repeated points (zero-length segments) are allowed.
    """

    def __init__(self, curve, *, closed=True):
        self._index = _core.CurveIndex(as_points(curve, "curve"), as_flag(closed, "closed"))

    @property
    def closed(self) -> bool:
        return self._index.closed

    def __len__(self) -> int:
        return self._index.size

    def closest_points(self, queries) -> CurveHits:
        """Closest point on the curve to each query point (ties: the lowest segment).

        queries : (M, 2) float
        """
        return CurveHits(**self._index.closest_points(as_points(queries, "queries")))

    def line_intersections(self, origins, directions) -> CurveHits:
        """Nearest intersection of each whole line ``origin + t * direction`` (t of either sign).

        origins, directions : (M, 2) float; directions need not be unit, but not zero.
        Ties in ``|t|`` go to the positive side, then to the lowest segment.
        """
        origins = as_points(origins, "origins")
        directions = as_points(directions, "directions")
        return CurveHits(**self._index.line_intersections(origins, directions))


def closest_points(queries, curve, *, closed=True) -> CurveHits:
    """Closest point on ``curve`` to each of ``queries``; see :class:`CurveIndex`."""
    return CurveIndex(curve, closed=closed).closest_points(queries)


def line_intersections(origins, directions, curve, *, closed=True) -> CurveHits:
    """Nearest intersection of each line with ``curve``; see :class:`CurveIndex`."""
    return CurveIndex(curve, closed=closed).line_intersections(origins, directions)
