"""Carrying followed boundary points from one frame onto the next, so that they lie on it.

A field maps the points of frame k; the points a series follows lie between them. Interpolating
the vectors linearly (:meth:`DisplacementField.at`) puts such a point on the chord between two
neighbouring ends, off frame k + 1 wherever the frame bends between them, and the error grows
from frame to frame. Here a followed point keeps its place *along* the boundary instead: in 2D
it goes to the point of frame k + 1 whose arc length lies as far between the neighbouring ends'
arc lengths as the point's lies between their starts' along frame k; in 3D to the closest point
of frame k + 1 to the interpolated position. Either way it lies on frame k + 1, and at a start
point it is that vector's own end.
"""

from __future__ import annotations

import numpy as np

from .queries import CurveIndex


def _knots(curve: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """The curve's vertices (closed: the first repeated at the end) and their arc lengths."""
    vertices = np.vstack([curve, curve[:1]]) if closed else curve
    return vertices, np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(vertices, axis=0), axis=1))])


def point_at_arc_length(curve: np.ndarray, along: np.ndarray, closed: bool) -> np.ndarray:
    """``(P, 2)`` points of ``curve`` at arc lengths ``along`` ``(P,)`` from its first point
    (closed: taken round the perimeter; open: clamped to the ends)."""
    vertices, knots = _knots(curve, closed)
    along = np.mod(along, knots[-1]) if closed else np.clip(along, 0.0, knots[-1])
    return np.column_stack([np.interp(along, knots, vertices[:, 0]), np.interp(along, knots, vertices[:, 1])])


class IndexedCurve:
    """A frame's curve with its closest-point index and its length, built once per frame.

    points : (N, 2) float; closed : bool.
    """

    def __init__(self, points, closed: bool):
        self.points, self.closed = np.asarray(points, dtype=float), closed
        self.index = CurveIndex(self.points, closed=closed)
        self.length = float(_knots(self.points, closed)[1][-1])

    def arc_lengths(self, points: np.ndarray) -> np.ndarray:
        """``(P,)`` arc length from the first point of each point's closest point."""
        return self.index.closest_points(points).arc_lengths

    def at(self, along: np.ndarray) -> np.ndarray:
        """``(P, 2)`` points at arc lengths ``along`` (closed: round the perimeter; open: clamped)."""
        return point_at_arc_length(self.points, along, self.closed)


def carry_curve(field, points: np.ndarray, source: IndexedCurve, target: IndexedCurve) -> np.ndarray:
    """Where the points ``(P, 2)`` of the source curve go on the target curve under ``field``.

    Each point is placed by arc length along the source between its two neighbouring valid start
    points; their ends are placed by arc length along the target, and the point goes to the
    target's point at the same fraction between them (closed: the shorter way round from one end
    to the other; open: before the first or after the last start, that start's end). Exact at
    the start points (to rounding); NaN where the field has no valid vector. Returns ``(P, 2)``.
    """
    moved = np.full_like(points, np.nan)
    valid = field.valid
    if not valid.any() or len(points) == 0:
        return moved
    starts, ends = source.arc_lengths(field.starts[valid]), target.arc_lengths(field.ends[valid])
    order = np.argsort(starts, kind="stable")
    starts, ends = starts[order], ends[order]
    along = source.arc_lengths(points)
    if source.closed:
        # The neighbours round the first point: the last start, and the first one a perimeter on.
        starts, ends = np.append(starts, starts[0] + source.length), np.append(ends, ends[0])
        along = np.where(along < starts[0], along + source.length, along)
    elif len(starts) == 1:
        return target.at(np.full(len(along), ends[0]))
    right = np.clip(np.searchsorted(starts, along, side="right"), 1, len(starts) - 1)
    left = right - 1
    gap = starts[right] - starts[left]
    fraction = np.clip(np.divide(along - starts[left], gap, out=np.zeros_like(along), where=gap > 0), 0.0, 1.0)
    step = ends[right] - ends[left]
    if target.closed:
        step = np.mod(step + 0.5 * target.length, target.length) - 0.5 * target.length
    return target.at(ends[left] + fraction * step)


def carry_surface(field, points: np.ndarray, target_index) -> tuple[np.ndarray, np.ndarray]:
    """Where the points ``(P, 3)`` of the source surface go under ``field``: the vectors
    interpolated in the start triangles (:meth:`DisplacementField.at`), then the closest point
    of the target surface (``target_index``, a :class:`~morphomap.SurfaceIndex`). Returns the
    points ``(P, 3)`` and how far each interpolated position was from the target ``(P,)``
    (NaN where the field has no valid vector there)."""
    moved = points + field.at(points)
    distances = np.full(len(points), np.nan)
    alive = np.isfinite(moved).all(axis=1)
    if alive.any():
        hits = target_index.closest_points(moved[alive])
        moved[alive], distances[alive] = hits.points, hits.distances
    return moved, distances
