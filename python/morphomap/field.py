"""The result of a mapping: an immutable displacement field."""

from __future__ import annotations

import numpy as np

from ._validate import as_points

#: Names of the basic algorithms, indexed by the codes the C++ core uses.
METHOD_NAMES = ("minimal_distance", "normal", "diffusion", "uniform")


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, copy=True)
    array.flags.writeable = False
    return array


class DisplacementField:
    """Vectors from start points on C1 to end points on C2.

    Attributes
    ----------
    starts, ends : (M, d) float
        ``d`` is 2 or 3. ``ends`` rows are NaN where the algorithm found no target for that start
        point (a normal that never meets C2, say); a reverse mapping's missing rows are NaN in
        ``starts`` too.
    vectors : (M, d) float
        ``ends - starts``.
    valid : (M,) bool
        False where the row is NaN.
    method : (M,) str
        The basic algorithm that produced each vector (``"minimal_distance"``, ``"normal"``,
        ``"diffusion"``, ``"uniform"``); meaningful for ``method="auto"``.
    faces : (F, 3) int64 or None
        3D only: the connectivity of the start points.

    Vectors are in the order of the points of the curve or surface the algorithm mapped from.
    """

    __slots__ = ("_starts", "_ends", "_method", "_faces")

    def __init__(self, starts, ends, method, faces=None):
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
        self._faces = None if faces is None else _frozen(np.asarray(faces, dtype=np.int64))

    @classmethod
    def _from_core(cls, starts, ends, codes, faces=None):
        return cls(starts, ends, np.asarray(METHOD_NAMES)[np.asarray(codes, dtype=np.int64)], faces)

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
    def dim(self) -> int:
        return self._starts.shape[1]

    def __len__(self) -> int:
        return len(self._starts)

    def __repr__(self) -> str:
        names, counts = np.unique(self._method, return_counts=True)
        made = ", ".join(f"{n}: {c}" for n, c in zip(names, counts))
        return f"DisplacementField({len(self)} vectors in {self.dim}D, {int(self.valid.sum())} valid; {made})"
