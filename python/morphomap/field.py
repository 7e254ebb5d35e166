"""The result of a mapping: an immutable displacement field."""

from __future__ import annotations

import numpy as np

from . import _core
from ._validate import as_faces, as_flag, as_points

#: The names a field's methods can take, in the core's code order (files store the codes): the
#: paper's four, their ``reverse_`` forms (ran from C2 to C1 and flipped), then the order-preserving
#: ``"optimal"`` matching (beyond the paper) and its reverse. The core's registry (``method_name``).
METHOD_NAMES = tuple(_core.METHOD_NAMES)


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, copy=True)
    array.flags.writeable = False
    return array


class DisplacementField:
    """Vectors from start points on C1 to end points on C2.

    Attributes
    ----------
    starts, ends : (M, d) float
        ``d`` is 2 or 3. A row whose algorithm found nothing keeps the point it came from: NaN in
        ``ends`` where a start point found no target (a normal that never meets C2, say), NaN in
        ``starts`` where a reverse vector's point of C2 found nothing on C1.
    vectors : (M, d) float
        ``ends - starts``.
    valid : (M,) bool
        False where the row is NaN.
    method : (M,) str
        The basic algorithm that produced each vector (``"minimal_distance"``, ``"normal"``,
        ``"diffusion"``, ``"uniform"``, ``"optimal"``), with ``"reverse_"`` before it where the
        vector was found from C2 back to C1 (the paper's reverse mapping, e.g.
        ``"reverse_diffusion"``).
    candidates : tuple of Candidate or None
        ``method="best"`` only: every candidate it tried, with its quality, crossings (folds in
        3D), misses and seconds, and which one won (see :mod:`morphomap.best`); None otherwise.
    piece_candidates : tuple of PieceCandidate or None
        ``method="best"`` in 2D: every candidate on every piece between the curves' split points,
        with the piece's winner (empty when the pair is one piece or ``n`` was given); None
        otherwise.
    faces : (F, 3) int64 or None
        3D only: the connectivity of the start points.
    source : (N, 2) float or None
        2D: the source curve C1 the field was made from (as given to :func:`map_curves`), which
        :meth:`at` places points on; None for a field read from a file.
    closed : bool
        2D: whether ``source`` is a closed curve.

    Vectors are in the order of the points of the curve or surface the algorithm mapped from.
    """

    __slots__ = ("_starts", "_ends", "_method", "_faces", "_source", "_closed", "_candidates", "_piece_candidates")

    def __init__(self, starts, ends, method, faces=None, *, source=None, closed=True, candidates=None):
        starts = np.asarray(starts)
        dim = starts.shape[1] if starts.ndim == 2 else 2
        starts = as_points(starts, "starts", dim, allow_nan=True)
        ends = as_points(ends, "ends", dim, allow_nan=True)
        if dim not in (2, 3):
            raise ValueError(f"starts: expected 2 or 3 columns, got {dim}")
        if ends.shape != starts.shape:
            raise ValueError(f"ends: expected shape {starts.shape} like starts, got {ends.shape}")
        if isinstance(method, str):
            method = np.full(len(starts), method)
        method = np.asarray(method)
        if method.shape != (len(starts),):
            raise ValueError(f"method: expected {len(starts)} names, got shape {method.shape}")
        unknown = set(method.tolist()) - set(METHOD_NAMES)
        if unknown:
            raise ValueError(f"method: unknown algorithm names {sorted(unknown)}")
        self._starts = _frozen(starts)
        self._ends = _frozen(ends)
        self._method = _frozen(method.astype(f"<U{max(map(len, METHOD_NAMES))}"))
        self._faces = None if faces is None else _frozen(as_faces(faces, "faces", len(starts)))
        self._source = None if source is None else _frozen(as_points(source, "source", 2))
        self._closed = as_flag(closed, "closed")
        self._candidates = None if candidates is None else tuple(candidates)
        self._piece_candidates = None

    @classmethod
    def _from_core(cls, record, **source):
        """The field from the core's record: starts, ends, methods (codes and the core's table of their
        names) and, in 3D, faces."""
        methods = record["methods"]
        names = np.asarray(methods["names"])[np.asarray(methods["codes"], dtype=np.int64)]
        return cls(record["starts"], record["ends"], names, record.get("faces"), **source)

    @property
    def starts(self) -> np.ndarray:
        return self._starts

    @property
    def ends(self) -> np.ndarray:
        return self._ends

    @property
    def vectors(self) -> np.ndarray:
        return self._ends - self._starts

    @property
    def valid(self) -> np.ndarray:
        return np.isfinite(self._starts).all(axis=1) & np.isfinite(self._ends).all(axis=1)

    @property
    def method(self) -> np.ndarray:
        return self._method

    @property
    def faces(self):
        return self._faces

    @property
    def source(self):
        return self._source

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def candidates(self):
        return self._candidates

    @property
    def piece_candidates(self):
        return self._piece_candidates

    def _with_candidates(self, candidates, piece_candidates=None) -> "DisplacementField":
        """The same field carrying the tables of ``method="best"``."""
        field = DisplacementField(self._starts, self._ends, self._method, self._faces, source=self._source,
                                  closed=self._closed, candidates=candidates)
        field._piece_candidates = None if piece_candidates is None else tuple(piece_candidates)
        return field

    def at(self, points, source=None, *, closed=None, return_distances=False):
        """The displacement at ``points`` of the source boundary, whatever made the field.

        2D: each point is projected onto the source curve C1 and placed by arc length among the
        valid start points (placed on C1 the same way); the vectors of its two neighbours are
        interpolated linearly in arc length (round the end on a closed curve; before the first or
        after the last start of an open curve, that start's vector). The vectors' order does not
        matter, so reverse and crossing fields work too. ``source`` defaults to the curve the
        field was made from (:attr:`source`); a field read from a file needs it passed.

        3D: each point is projected onto the start triangles (:attr:`faces` over :attr:`starts`)
        and the vectors at the corners are interpolated with the barycentric weights.

        Exact at the start points. Points off the boundary are projected onto it: with
        ``return_distances=True`` the distances ``(P,)`` come back too, so that a solver's nodes
        can be checked. Rows are NaN where the neighbouring vectors have no target.

        Returns ``(P, d)`` float (and ``(P,)`` distances).
        """
        points = as_points(points, "points", self.dim)
        if self.dim == 3:
            if self._faces is None:
                raise ValueError("field: a 3D field needs its faces to interpolate (read it from a CSV with faces)")
            at = _core.displacement_at_3d(self._starts, self._ends, self._faces, points)
        else:
            if source is None:
                source = self._source
                closed = self._closed if closed is None else closed
            if source is None:
                raise ValueError("source: this field does not know the curve it was made from: pass source=C1")
            closed = as_flag(True if closed is None else closed, "closed")
            at = _core.displacement_at_2d(self._starts, self._ends, as_points(source, "source", 2), closed, points)
        return (at["displacements"], at["distances"]) if return_distances else at["displacements"]

    @property
    def dim(self) -> int:
        return self._starts.shape[1]

    def __len__(self) -> int:
        return len(self._starts)

    def __repr__(self) -> str:
        names, counts = np.unique(self._method, return_counts=True)
        made = ", ".join(f"{n}: {c}" for n, c in zip(names, counts))
        missed = len(self) - int(self.valid.sum())
        return (f"DisplacementField({len(self)} vectors in {self.dim}D, {len(self) - missed} valid, "
                f"{missed} missed; {made})")
