"""Crossings among segments, such as the vectors of a displacement field."""

from __future__ import annotations

import numpy as np

from . import _core
from ._validate import as_points


def _segments(starts, ends):
    starts = as_points(starts, "starts", allow_nan=True)
    ends = as_points(ends, "ends", allow_nan=True)
    if starts.shape != ends.shape:
        raise ValueError(f"ends: expected shape {starts.shape} like starts, got {ends.shape}")
    return starts, ends


def crossing_pairs(starts, ends) -> np.ndarray:
    """Pairs ``(i, j)``, ``i < j``, of segments ``starts[i] -> ends[i]`` that cross: ``(K, 2)`` int64.

    Two segments cross when they have a point in common, unless their only common point is an end
    point of both (vectors that share a start or an end). Rows with NaN are skipped. Exact
    predicates; candidate pairs from a box-intersection search.
    """
    return _core.crossing_pairs(*_segments(starts, ends))


def count_crossings(starts, ends) -> int:
    """Number of crossing pairs, as defined in :func:`crossing_pairs`."""
    return _core.count_crossings(*_segments(starts, ends))
