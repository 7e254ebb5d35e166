"""The paper's quality measures of a displacement field."""

from __future__ import annotations

from dataclasses import dataclass

from . import _core
from ._validate import as_flag, as_points
from .field import DisplacementField


@dataclass(frozen=True)
class CurveQuality:
    """Quality measures of a 2D displacement field; see :func:`quality` for the formulas."""

    qm1: float
    qm2: float
    qm: float
    crossings: int


def quality(field, c1, c2, *, closed=True) -> CurveQuality:
    r"""Quality measures QM1, QM2, QM and crossings of a 2D displacement field.

    As in the paper's section "Quantitative Evaluation of the Mapping Algorithms". Only 2D fields
    are accepted for now; the 3D measures are not available yet.

    Parameters
    ----------
    field : DisplacementField
        A 2D field of vectors :math:`p_i \to P_i`; every valid start point must lie on ``c1`` and
        every valid end point on ``c2`` (within :math:`10^{-6}` of the curve's bounding-box
        diagonal).
    c1, c2 : (N, 2) float
        The curves at time t and t + dt.
    closed : bool
        Whether both curves are closed.

    Returns
    -------
    CurveQuality
        ``qm1``, ``qm2``, ``qm`` (float, NaN when there is nothing to average over) and
        ``crossings`` (int).

    Notes
    -----
    The pairs are the consecutive vectors :math:`(i, i+1)` in field order, wrapping round to
    :math:`(M-1, 0)` on closed curves; a pair involving an invalid (NaN) row is skipped. Over the
    :math:`K` remaining pairs:

    - :math:`l_i` is the arc length along ``c1`` between :math:`p_i` and :math:`p_{i+1}`, and
      :math:`L_i` that along ``c2`` between :math:`P_i` and :math:`P_{i+1}`, the shorter way round
      on a closed curve (forward at an exact tie).
    - :math:`\alpha = \mathrm{perimeter}(C_2) / \mathrm{perimeter}(C_1)` (the curve lengths when
      open).
    - :math:`\mathrm{QM}_1 = \frac{1}{K_1} \sum_i \left(\frac{L_i}{\alpha l_i} - 1\right)^2`
      over the :math:`K_1` pairs with :math:`l_i > 0`: a pair of coincident start points has no
      ratio and is left out of QM1 (only).
    - :math:`A_i` is the absolute shoelace area of the polygon :math:`p_i`, the vertices of ``c1``
      strictly between :math:`p_i` and :math:`p_{i+1}` along the arc of :math:`l_i`,
      :math:`p_{i+1}`, :math:`P_{i+1}`, the vertices of ``c2`` strictly between :math:`P_{i+1}`
      and :math:`P_i` along the arc of :math:`L_i`, :math:`P_i`.
    - :math:`\mathrm{QM}_2 = \frac{1}{K} \sum_i \left(\frac{A_i}{\langle A \rangle} - 1\right)^2`
      with :math:`\langle A \rangle = \frac{1}{K} \sum_i A_i`.
    - :math:`\mathrm{QM} = \mathrm{QM}_1 \cdot \mathrm{QM}_2`.
    - ``crossings`` is :func:`morphomap.count_crossings` of the vectors: pairs whose segments
      cross (vectors sharing only an end point do not count).

    Runs in C++ on all cores without the GIL; each area walks only the curve vertices between two
    consecutive points.
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    if field.dim != 2:
        raise ValueError(f"field: expected a 2D displacement field, got {field.dim}D")
    c1 = as_points(c1, "c1")
    c2 = as_points(c2, "c2")
    closed = as_flag(closed, "closed")
    qm1, qm2, qm, crossings = _core.curve_quality(field.starts, field.ends, c1, c2, closed)
    return CurveQuality(float(qm1), float(qm2), float(qm), int(crossings))
