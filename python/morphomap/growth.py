"""Growth kinematics: how fast each patch of boundary grows, how anisotropically, in which
direction, and how it moves (normal and tangential velocity), from one field or a whole series.

For each element of the boundary (a segment in 2D, a triangle in 3D) with corners ``p_i`` before
and ``q_i`` after, the map between them is linear on the element. Its deformation gradient
restricted to the boundary, ``F = E' E^+`` (``E``, ``E'`` the element's edge vectors before and
after, ``E^+`` the pseudo-inverse), maps the element's tangent plane before onto the one after:

- **principal stretches** ``lambda1 >= lambda2``: the singular values of ``F`` on the plane (the
  square roots of the eigenvalues of the right Cauchy-Green tensor ``C = F^T F``); in 2D the one
  stretch ``|q_b - q_a| / |p_b - p_a|``;
- **principal directions of growth** (PDGs): the right singular vectors, unit tangents of the
  element *before* that stretch by ``lambda1`` and ``lambda2`` (NaN where the two stretches agree
  to 1e-6 of the larger: a uniform scaling or a rotation has no preferred direction);
- **areal growth** ``J = lambda1 * lambda2`` = area after / area before (2D: the length ratio),
  and its **rate** ``ln(J) / t`` over the time ``t`` between the two configurations;
- **anisotropy** ``lambda1 / lambda2`` (1: isotropic; NaN in 2D, where a curve has one direction);
- **velocity** of the element: the mean of its corners' displacements over ``t``, split along the
  element's unit normal before (``normal_velocity``, outward positive: outward on a closed curve or
  an outward-oriented surface, to the right of travel on an open curve) and the rest in its tangent
  plane (``tangential_velocity``).

For a series the values are per step (frame k to k + 1, on the pieces ``series.cells[k]``) and
accumulated along the trajectories: from the frame where the element's last corner was born to
frame k + 1, computed from the corners' positions at those two frames (the composition of the
steps' piecewise-linear maps, exactly).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._validate import as_length
from .curves import signed_area
from .field import DisplacementField


@dataclass(frozen=True)
class Growth:
    """Growth per element (segment in 2D, triangle in 3D); see :mod:`morphomap.growth`.

    Attributes
    ----------
    cells : (F, 2) or (F, 3) int
        The elements' corners (indices into ``before``).
    before : (P, d) float
        The corners' positions at the start (``cells`` index them).
    stretches : (F, 1) or (F, 2) float
        Principal stretches, ``lambda1 >= lambda2`` (2D: the length ratio).
    directions : (F, 1, d) or (F, 2, d) float
        Unit principal directions of growth in the element before (NaN where isotropic).
    areal_growth : (F,) float
        ``lambda1 * lambda2`` (2D: ``lambda1``).
    areal_growth_rate : (F,) float
        ``ln(areal_growth) / elapsed``.
    anisotropy : (F,) float
        ``lambda1 / lambda2`` (NaN in 2D).
    normal_velocity : (F,) float
    tangential_velocity : (F, d) float
    elapsed : (F,) float
        The time over which each element's values were taken.
    """

    cells: np.ndarray
    before: np.ndarray
    stretches: np.ndarray
    directions: np.ndarray
    areal_growth: np.ndarray
    areal_growth_rate: np.ndarray
    anisotropy: np.ndarray
    normal_velocity: np.ndarray
    tangential_velocity: np.ndarray
    elapsed: np.ndarray

    @property
    def dim(self) -> int:
        return self.before.shape[1]

    def measure(self) -> np.ndarray:
        """Each element's length (2D) or area (3D) before, ``(F,)``."""
        return element_measures(self.before, self.cells)

    def by_region(self, labels, *, per=None) -> dict:
        """Values over regions of the boundary, weighted by the elements' length or area before.

        Parameters
        ----------
        labels : (F,) or (P,) int
            A region per element, or per point of ``before`` (an element then takes its corners'
            most common label; ties: the lowest). :func:`distance_bands` gives bands by distance
            from a tip.
        per : {"elements", "points"}, optional
            Which ``labels`` are; needed only where the two counts are equal.

        Returns
        -------
        dict of str to arrays, one entry per region (sorted):
            ``region``, ``elements`` (count), ``measure`` (total length or area before),
            ``areal_growth`` (total after over total before), ``areal_growth_rate``,
            ``anisotropy``, ``normal_velocity`` and ``tangential_speed`` (the magnitude of the
            tangential velocity), each a weighted mean over the region's elements with values.
        """
        element = self._element_labels(labels, per)
        weights = self.measure()
        regions = np.unique(element)
        table = {name: np.full(len(regions), np.nan) for name in
                 ("measure", "areal_growth", "areal_growth_rate", "anisotropy", "normal_velocity", "tangential_speed")}
        table["region"], table["elements"] = regions, np.zeros(len(regions), dtype=np.int64)
        speed = np.linalg.norm(self.tangential_velocity, axis=1)
        for i, region in enumerate(regions):
            inside = (element == region) & np.isfinite(self.areal_growth) & (weights > 0)
            table["elements"][i] = int((element == region).sum())
            if not inside.any():
                continue
            w = weights[inside]
            table["measure"][i] = w.sum()
            table["areal_growth"][i] = (w * self.areal_growth[inside]).sum() / w.sum()
            elapsed = (w * self.elapsed[inside]).sum() / w.sum()
            table["areal_growth_rate"][i] = np.log(table["areal_growth"][i]) / elapsed
            for name, values in (("anisotropy", self.anisotropy), ("normal_velocity", self.normal_velocity),
                                 ("tangential_speed", speed)):
                known = np.isfinite(values[inside])
                if known.any():
                    table[name][i] = (w[known] * values[inside][known]).sum() / w[known].sum()
        return table

    def _element_labels(self, labels, per):
        labels = np.asarray(labels)
        if labels.ndim != 1 or not np.issubdtype(labels.dtype, np.integer):
            raise TypeError(f"labels: expected one integer label per element or per point, got {labels.dtype} "
                            f"{labels.shape}")
        counts = {"elements": len(self.cells), "points": len(self.before)}
        if per is None:
            matches = [name for name, n in counts.items() if n == len(labels)]
            if len(matches) != 1:
                raise ValueError(f"labels: {len(labels)} labels for {counts['elements']} elements and "
                                 f"{counts['points']} points: " + ("pass per='elements' or per='points'" if matches
                                                                   else "give one per element or one per point"))
            per = matches[0]
        if per not in counts:
            raise ValueError(f"per: expected 'elements' or 'points', got {per!r}")
        if len(labels) != counts[per]:
            raise ValueError(f"labels: expected {counts[per]} (one per {per[:-1]}), got {len(labels)}")
        if per == "elements":
            return labels
        corners = labels[self.cells]
        # The most common corner label; with all different, the lowest.
        sorted_corners = np.sort(corners, axis=1)
        repeated = sorted_corners[:, 1:] == sorted_corners[:, :-1]
        return np.where(repeated.any(axis=1), sorted_corners[:, 1:][np.arange(len(corners)), repeated.argmax(axis=1)],
                        sorted_corners[:, 0])


def element_measures(points, cells) -> np.ndarray:
    """The length of each segment ``(F, 2)`` or the area of each triangle ``(F, 3)`` of ``cells``
    over ``points`` ``(P, d)``, ``(F,)`` (NaN where a corner is)."""
    corners = points[cells]
    if cells.shape[1] == 2:
        return np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1)
    return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)


def distance_bands(points, tip, width) -> np.ndarray:
    """Region labels by distance from a tip point: band ``k`` holds the points ``k * width`` to
    ``(k + 1) * width`` from ``tip`` (Euclidean), ``(P,)`` int. For :meth:`Growth.by_region`."""
    points = np.asarray(points, dtype=float)
    tip = np.asarray(tip, dtype=float)
    if points.ndim != 2 or tip.shape != (points.shape[1],):
        raise ValueError(f"tip: expected one point of {points.shape[-1]} coordinates, got shape {tip.shape}")
    if width is None:
        raise TypeError("width: expected the width of a band, a number > 0")
    width = as_length(width, "width", 1.0)
    return np.floor(np.linalg.norm(points - tip, axis=1) / width).astype(np.int64)


def element_growth(before, after, cells, elapsed, *, counter_clockwise=True) -> Growth:
    """:class:`Growth` of elements ``cells`` (segments ``(F, 2)`` or triangles ``(F, 3)``) between
    the same points ``before`` and ``after`` ``(P, d)``, over ``elapsed`` (a time, or one per element)."""
    before, after = np.asarray(before, dtype=float), np.asarray(after, dtype=float)
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    elapsed = np.broadcast_to(np.asarray(elapsed, dtype=float), (len(cells),))
    if not (np.all(elapsed > 0) and np.all(np.isfinite(elapsed))):
        raise ValueError("dt: must be a finite time > 0")
    # The kernel takes one time for all; per-element times scale the velocities afterwards.
    if before.shape[1] == 2:
        raw = _core.curve_growth(before, after, cells, 1.0, counter_clockwise)
        stretches = raw["stretch"][:, None]
        directions = raw["direction"][:, None, :]
        anisotropy = np.full(len(cells), np.nan)
    else:
        raw = _core.surface_growth(before, after, cells, 1.0)
        stretches = raw["stretches"]
        directions = np.stack([raw["major"], raw["minor"]], axis=1)
        anisotropy = stretches[:, 0] / stretches[:, 1]
    areal = np.prod(stretches, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        rate = np.log(areal) / elapsed
    return Growth(cells, before, stretches, directions, areal, rate, anisotropy, raw["normal_velocity"] / elapsed,
                  raw["tangential_velocity"] / elapsed[:, None], np.array(elapsed))


def field_growth(field: DisplacementField, dt=1.0) -> Growth:
    """:class:`Growth` of one field's elements: in 2D the segments between consecutive start
    points (closed round the end when the field's curve is), in 3D the field's triangles."""
    dt = as_length(dt, "dt", 1.0)
    if field.dim == 3:
        if field.faces is None:
            raise ValueError("field: a 3D field needs its faces")
        return element_growth(field.starts, field.ends, field.faces, dt)
    count = len(field.starts)
    first = np.arange(count)
    segments = np.column_stack([first, np.roll(first, -1)]) if field.closed else np.column_stack([first[:-1],
                                                                                                 first[1:]])
    outline = field.starts if field.source is None else field.source
    outward = (not field.closed) or signed_area(outline) > 0
    return element_growth(field.starts, field.ends, segments, dt, counter_clockwise=outward)


@dataclass(frozen=True)
class SeriesGrowth:
    """Growth through a series: ``steps[k]`` frame k to k + 1 and ``accumulated[k]`` from each
    element's birth to frame k + 1, both on the pieces ``series.cells[k]``."""

    steps: list
    accumulated: list
    dt: float


def series_growth(series, dt=None) -> SeriesGrowth:
    """:class:`SeriesGrowth` of a :class:`morphomap.Series` (its ``dt`` unless given)."""
    dt = series.dt if dt is None else as_length(dt, "dt", 1.0)
    steps, accumulated = [], []
    positions = series.trajectories
    for k, cells in enumerate(series.cells[: len(series.fields)]):
        cells = np.asarray(cells, dtype=np.int64)
        if series.dim == 2:
            frame = np.asarray(series.frames[k], dtype=float)
            outward = signed_area(frame) > 0 or not series.fields[k].closed
        else:
            outward = True
        steps.append(element_growth(positions[k], positions[k + 1], cells, dt, counter_clockwise=outward))
        start = series.born[cells].max(axis=1)
        corners = cells.shape[1]
        before = positions[np.repeat(start, corners), cells.ravel()]
        after = positions[k + 1][cells.ravel()]
        flat = np.arange(len(cells) * corners).reshape(len(cells), corners)
        accumulated.append(element_growth(before, after, flat, (k + 1 - start) * dt, counter_clockwise=outward))
    return SeriesGrowth(steps, accumulated, dt)


def growth(field_or_series, *, dt=None):
    """Growth kinematics per element of a field (one step) or of a series (per step and
    accumulated along the trajectories); see :mod:`morphomap.growth` for the formulas.

    Parameters
    ----------
    field_or_series : DisplacementField or Series
    dt : float, optional
        The time between the two boundaries (a series: between two frames); default 1 for a
        field, the series' own ``dt``.

    Returns
    -------
    Growth (a field) or SeriesGrowth (a series)
    """
    if isinstance(field_or_series, DisplacementField):
        return field_growth(field_or_series, 1.0 if dt is None else dt)
    if hasattr(field_or_series, "trajectories") and hasattr(field_or_series, "cells"):
        return series_growth(field_or_series, dt)
    raise TypeError(f"field_or_series: expected a DisplacementField or a Series, got {type(field_or_series).__name__}")
