"""The paper's quality measures of a displacement field."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from ._validate import as_flag
from .field import DisplacementField
from .prepared import PreparedCurve, PreparedSurface, as_curve, as_surface


@dataclass(frozen=True)
class CurveQuality:
    """Quality measures of a 2D displacement field; see :func:`quality` for the formulas."""

    qm1: float
    qm2: float
    qm: float
    crossings: int


@dataclass(frozen=True)
class SurfaceQuality:
    """Quality measures of a 3D displacement field; see :func:`quality` for the formulas."""

    qm1: float
    qm2: float
    qm: float
    folds: int


def quality(field, c1, c2, *, closed=True):
    r"""Quality measures of a displacement field: QM1, QM2, QM and crossings (2D) or folds (3D).

    2D as in the paper's section "Quantitative Evaluation of the Mapping Algorithms"; 3D (a field
    with ``faces``, from :func:`map_surfaces`) with our own analogues, see the Notes.

    Parameters
    ----------
    field : DisplacementField
        A 2D field of vectors :math:`p_i \to P_i`; every valid start point must lie on ``c1`` and
        every valid end point on ``c2`` (within :math:`10^{-6}` of the curve's bounding-box
        diagonal).
    c1, c2 : (N, 2) float or PreparedCurve
        The curves at time t and t + dt (two :class:`PreparedCurve`, prepared as ``closed`` says,
        skip their checks and reuse their indices; one alone is used as its points). 3D: the
        closed surfaces S1 and S2, each a ``trimesh.Trimesh``, a ``(vertices, faces)`` pair or a
        :class:`PreparedSurface`.
    closed : bool
        Whether both curves are closed (2D only).

    Returns
    -------
    CurveQuality or SurfaceQuality
        ``qm1``, ``qm2``, ``qm`` (float, NaN when there is nothing to average over) and
        ``crossings`` (2D) or ``folds`` (3D) (int).

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

    **3D** (ours; the paper gives no formula). The elements are the triangles of ``field.faces``
    (indices of the field's rows); a triangle with an invalid vector is skipped. Over the
    :math:`K` remaining triangles :math:`j` with corners :math:`p_0, p_1, p_2` and images
    :math:`P_0, P_1, P_2`:

    - :math:`a_j = |(p_1 - p_0) \times (p_2 - p_0)| / 2` and :math:`A_j` the same of the images.
    - :math:`\alpha = \mathrm{area}(S_2) / \mathrm{area}(S_1)` (sums of triangle areas).
    - :math:`\mathrm{QM}_1 = \frac{1}{K_1} \sum_j \left(\frac{A_j}{\alpha a_j} - 1\right)^2`
      over the :math:`K_1` triangles with :math:`a_j > 0`.
    - :math:`V_j`, the volume swept between the start triangle and its image: the solid with the
      two triangles as caps and the three vector quads as sides, split into the tetrahedra
      :math:`(p_0 p_1 p_2 P_0)`, :math:`(p_1 p_2 P_0 P_1)`, :math:`(p_2 P_0 P_1 P_2)`;
      :math:`V_j` is the sum of their absolute volumes.
    - :math:`\mathrm{QM}_2 = \frac{1}{K} \sum_j \left(\frac{V_j}{\langle V \rangle} - 1\right)^2`
      with :math:`\langle V \rangle = \frac{1}{K} \sum_j V_j`;
      :math:`\mathrm{QM} = \mathrm{QM}_1 \cdot \mathrm{QM}_2`.
    - ``folds``: the number of triangles whose image is turned over relative to the surfaces
      (where the map from S1 to S2 reverses orientation):
      :math:`(n_j \cdot \nu^1_j)(N_j \cdot \nu^2_j) < 0`, with
      :math:`n_j = (p_1 - p_0) \times (p_2 - p_0)`, :math:`N_j` the same of the images (corners
      in the order of the face row), :math:`\nu^1_j` the outward unit normal of the face of S1
      closest to the centroid where the centroid lies on S1 (within :math:`10^{-9}` of the
      triangle's longest edge: the triangle lies on S1, as a face of it or inside a flat part),
      else the sum of the outward unit normals of the faces of S1 closest to
      :math:`p_0, p_1, p_2` and to their centroid (at a sharp crease the corners' faces may all
      lie on its other side); :math:`\nu^2_j` the same on S2 for the images. A triangle lying
      on its surface as that surface is oriented has :math:`n \cdot \nu > 0`, so tilt in
      space does not count (a bud that grows out sideways, a rotation, a scaling), a locally
      mirrored image does; triangles with a zero-area start
      or image are not folds.

    Both surfaces must be closed; valid start points must lie on S1 and valid end points on S2
    (within :math:`10^{-6}` of the surface's bounding-box diagonal).
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    if field.dim == 3:
        if field.faces is None:
            raise ValueError(
                "field: expected a 2D field, or a 3D field with faces (the connectivity of its start points)"
            )
        faces = np.ascontiguousarray(field.faces, dtype=np.int64)
        if isinstance(c1, PreparedSurface) and isinstance(c2, PreparedSurface):
            found = _core.prepared_surface_quality(field.starts, field.ends, faces, c1._prepared, c2._prepared)
        else:
            v1, f1 = as_surface(c1, "s1", core_checks=True)
            v2, f2 = as_surface(c2, "s2", core_checks=True)
            found = _core.surface_quality(field.starts, field.ends, faces, v1, f1, v2, f2)
        return SurfaceQuality(**found)
    if field.dim != 2:
        raise ValueError(f"field: expected a 2D displacement field, got {field.dim}D")
    if isinstance(c1, PreparedCurve) and isinstance(c2, PreparedCurve):
        found = _core.prepared_curve_quality(field.starts, field.ends, c1._prepared, c2._prepared,
                                             as_flag(closed, "closed"))
    else:
        c1 = as_curve(c1, "c1")
        c2 = as_curve(c2, "c2")
        closed = as_flag(closed, "closed")
        found = _core.curve_quality(field.starts, field.ends, c1, c2, closed)
    return CurveQuality(**found)
