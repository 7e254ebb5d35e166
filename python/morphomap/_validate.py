"""Argument conversion shared by the public functions.

Every array goes to the C++ core as a float64, C-contiguous copy or view, so the core can take it
without copying. Errors name the argument: ``TypeError`` for a wrong kind of object, ``ValueError``
for a wrong shape or value. Where the C++ core checks a value (the options of the mappings, the
diffusion and the extension), Python only converts it (``as_real``, ``as_integer``) and the
core's message is the one users see; the rules here are for values that never reach the core.
"""

from __future__ import annotations

import numbers

import numpy as np


def as_points(value, name: str, dim: int = 2, *, allow_nan: bool = False) -> np.ndarray:
    """Return ``value`` as a C-contiguous float64 array of shape (N, dim).

    Integer arrays are converted; booleans, strings, objects and complex numbers are refused.
    """
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name}: expected an array of shape (N, {dim}), got {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (ValueError, TypeError) as error:  # ragged nested lists
        raise ValueError(f"{name}: cannot be read as an array of shape (N, {dim}): {error}") from None
    if array.dtype == bool or not (np.issubdtype(array.dtype, np.integer) or np.issubdtype(array.dtype, np.floating)):
        raise TypeError(f"{name}: expected real numbers, got an array of dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] != dim:
        raise ValueError(f"{name}: expected shape (N, {dim}), got {array.shape}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    if not allow_nan and not np.isfinite(array).all():
        row = int(np.flatnonzero(~np.isfinite(array).all(axis=1))[0])
        raise ValueError(f"{name}: row {row} has a non-finite coordinate")
    return array


def _as_kind(value, name: str, default, kind, convert, what: str):
    if value is None:
        return default
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, kind):
        raise TypeError(f"{name}: expected {what}, got {type(value).__name__}")
    return convert(value)


def as_real(value, name: str, default: float) -> float:
    """``value`` as a float (``default`` for None) for the C++ core to check; TypeError for a
    non-number."""
    return _as_kind(value, name, default, numbers.Real, float, "a number")


def as_integer(value, name: str, default: int) -> int:
    """``value`` as an int (``default`` for None) for the C++ core to check; TypeError for a
    non-integer."""
    return _as_kind(value, name, default, numbers.Integral, int, "an integer")


def as_count(value, name: str, minimum: int) -> int:
    """Return ``value`` as a Python int of at least ``minimum``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__}")
    value = int(value)
    if value < minimum:
        raise ValueError(f"{name}: must be at least {minimum}, got {value}")
    return value


def as_flag(value, name: str) -> bool:
    """Return ``value`` as a bool; only True and False are accepted."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")
    return bool(value)


def as_choice(value, name: str, choices: tuple[str, ...]) -> str:
    """Return ``value`` if it is one of ``choices``."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def as_point(value, name: str, dim: int = 2, *, allow_nan: bool = False) -> np.ndarray:
    """Return one point given as a sequence of ``dim`` numbers (finite unless ``allow_nan``) as a
    float64 ``(dim,)`` array."""
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name}: expected {dim} coordinates, got {type(value).__name__}")
    array = np.asarray(value)
    if array.shape != (dim,):
        raise ValueError(f"{name}: expected {dim} coordinates, got shape {array.shape}")
    return as_points(array.reshape(1, dim), name, dim, allow_nan=allow_nan)[0]


def as_length(value, name: str, default: float, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float > 0 (>= 0 with ``allow_zero``), or ``default`` for None."""
    if value is None:
        return default
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__}")
    value = float(value)
    if not np.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        raise ValueError(f"{name}: must be a finite number {'>=' if allow_zero else '>'} 0, got {value}")
    return value


def as_faces(value, name: str, vertex_count: int | None) -> np.ndarray:
    """Return ``value`` as a C-contiguous int64 (F, 3) array of indices into ``vertex_count`` vertices
    (None: the range is the core's check, as for closed surfaces)."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name}: expected an integer array of shape (F, 3), got {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (ValueError, TypeError) as error:
        raise ValueError(f"{name}: cannot be read as an array of shape (F, 3): {error}") from None
    if array.dtype == bool or not np.issubdtype(array.dtype, np.integer):
        if array.size == 0 and array.dtype == np.float64:  # an empty list
            array = array.astype(np.int64)
        else:
            raise TypeError(f"{name}: expected integer vertex indices, got an array of dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{name}: expected shape (F, 3), got {array.shape}")
    if array.size and vertex_count is not None:
        low, high = array.min(), array.max()
        if low < 0 or high >= vertex_count:
            bad = low if low < 0 else high
            raise ValueError(f"{name}: vertex index {int(bad)} is outside 0..{vertex_count - 1}")
    return np.ascontiguousarray(array, dtype=np.int64)
