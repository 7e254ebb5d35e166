"""The paper's transformation of C1 (Appendix A): a similarity that brings C1 close to C2.

Map the moved curve ``Similarity.apply(c1)`` onto ``c2`` with any mapping algorithm, then take the
starting points of the displacement vectors back onto C1 with ``Similarity.apply_inverse``.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from . import _core
from ._validate import as_flag, as_points


@dataclass(frozen=True)
class Similarity:
    """``x -> centre + translation + scale * R(angle) @ (x - centre)``.

    centre, translation : (2,) float, read-only
    scale : float
    angle : float, radians, counter-clockwise
    """

    centre: np.ndarray
    scale: float
    angle: float
    translation: np.ndarray

    def __post_init__(self):
        for name in ("centre", "translation"):
            value = np.array(getattr(self, name), dtype=np.float64)
            if value.shape != (2,):
                raise ValueError(f"{name}: expected shape (2,), got {value.shape}")
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "scale", float(self.scale))
        object.__setattr__(self, "angle", float(self.angle))

    def apply(self, points) -> np.ndarray:
        """The points moved: ``(N, 2)`` float."""
        return self._apply(points, inverse=False)

    def apply_inverse(self, points) -> np.ndarray:
        """The points moved back (the inverse of :meth:`apply`): ``(N, 2)`` float."""
        return self._apply(points, inverse=True)

    def _apply(self, points, *, inverse: bool) -> np.ndarray:
        p = as_points(points, "points", allow_nan=True)
        return _core.apply_similarity(self.centre, self.scale, self.angle, self.translation, p, inverse)


def overlap_area(a, b) -> float:
    """Area of the intersection of the regions enclosed by the closed curves ``a`` and ``b``.

    Computed exactly from the crossings of the two boundaries (no rasterising); either
    orientation. Each curve must be simple (not checked). Touching boundaries and shared stretches
    are handled exactly.
    """
    return _core.overlap_area(as_points(a, "a"), as_points(b, "b"))


def align_curves(c1, c2, *, closed=True, tolerance=1e-6) -> Similarity:
    """The similarity that brings ``c1`` close to ``c2`` (the paper's Appendix A).

    Closed curves (simple, non-zero area): ``c1`` is scaled about its area centroid to the area of
    ``c2``, moved centroid onto centroid when that overlaps more, then moved by greedy rigid steps
    (translations by r in eight directions, rotations by ±theta about its centroid) that increase
    the overlap area, halving r and theta when no step helps, until r falls below
    ``tolerance * sqrt(area(c2))``. r starts at ``0.1 * sqrt(area(c2))``, theta at 10 degrees. The
    result is a local maximum of the overlap.

    Open curves (``closed=False``): the similarity that takes the first and last points of ``c1``
    onto those of ``c2``; ``tolerance`` is not used.
    """
    closed = as_flag(closed, "closed")
    if isinstance(tolerance, (bool, np.bool_)) or not isinstance(tolerance, numbers.Real):
        raise TypeError(f"tolerance: expected a real number, got {type(tolerance).__name__}")
    # The value rule (positive and finite) is the C++ core's.
    found = _core.align_curves(as_points(c1, "c1"), as_points(c2, "c2"), closed, float(tolerance))
    return Similarity(**found)
