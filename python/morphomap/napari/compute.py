"""What the widget runs off the viewer's thread: a labels movie as napari holds it, mapped by
:func:`morphomap.map_series`; or two single-frame labels layers (an earlier and a later time
point), stacked by :func:`pair_movie` into a movie of 2 frames and mapped the same way.

Nothing here imports napari or Qt, so that the mapping a viewer shows can be run (and tested) as
plain Python: :func:`map_labels` takes the layer's array and scale as they are.
"""

from __future__ import annotations

from typing import NamedTuple, Optional

import numpy as np

from ..images.read import Image
from ..mapping import CURVE_METHODS
from ..movie import OBJECTS, REGISTRATIONS, movie_frames
from ..series import map_series
from ..surfaces import SURFACE_METHODS

#: The objects the widget offers: those of :func:`morphomap.movie.movie_frames`, and one label's value.
CHOICES = OBJECTS + ("label",)
#: Drift removal as the widget offers it: none, or a registration of :func:`map_series`.
DRIFT = ("none",) + REGISTRATIONS


class Options(NamedTuple):
    """The widget's settings, as :func:`map_labels` takes them.

    Attributes
    ----------
    objects : {"union", "largest", "follow", "label"}
        Which object each frame gives (:func:`morphomap.movie.movie_frames`); ``"label"``: the
        pixels of value ``label`` in every frame (labels linked across frames).
    label : int or None
        The object's value for ``"label"``; for ``"follow"``, the first frame's object (None: its
        largest).
    smooth : float or None
        The Gaussian width in the layer's units (None: the mask readers' default).
    method : str
        The mapping algorithm of every pair.
    drift : {"none", "translation", "rigid"}
        The drift removal (``register`` of :func:`map_series`).
    """

    objects: str = "union"
    label: Optional[int] = None
    smooth: Optional[float] = None
    method: str = "auto"
    drift: str = "none"


class Frame(NamedTuple):
    """One labels layer of the two-layer mode as the widget reads it off the viewer.

    Attributes
    ----------
    name : str
        The layer's name, for messages.
    data : (rows, columns) or (planes, rows, columns) array
        One frame: no time axis.
    scale, translate : sequence of float
        The layer's placement, one value per axis of ``data``.
    axes : str, optional
        The file's axes where morphomap's reader opened it (``metadata["axes"]``, ``"TYX"`` for a
        2D movie); None for a layer made otherwise.
    unit : str, optional
        The unit of ``scale`` (``metadata["unit"]``).
    """

    name: str
    data: object
    scale: tuple
    translate: tuple
    axes: Optional[str] = None
    unit: Optional[str] = None


def spatial_dim(ndim: int, axes: Optional[str] = None, *, single_frame: bool = False) -> int:
    """2 (curves) or 3 (surfaces): the spatial dimension of a labels layer of ``ndim`` axes, a
    movie with time first, or with ``single_frame`` one frame (a layer of 3 axes is then a 3D
    stack, unless ``axes`` names a T axis)."""
    timed = not single_frame or "T" in (axes or "")
    return 3 if ndim - timed >= 3 else 2


def _one_frame(frame: Frame) -> np.ndarray:
    data = np.asarray(frame.data)
    if frame.axes and "T" in frame.axes:
        raise ValueError(f"labels {frame.name!r}: a movie (axes {frame.axes}, shape {data.shape}); two-layer "
                         f"mode takes one frame per layer: choose 'none' as the later layer to map the movie as "
                         f"a series, or add the two time points as layers of their own")
    if data.ndim == 4:
        raise ValueError(f"labels {frame.name!r}: has 4 axes {data.shape}, a 3D movie; two-layer mode takes "
                         f"one frame per layer: choose 'none' as the later layer to map the movie as a series, "
                         f"or add the two time points as layers of their own")
    if data.ndim not in (2, 3):
        raise ValueError(f"labels {frame.name!r}: expected one frame, (rows, columns) or (planes, rows, columns), "
                         f"got {data.ndim} axes {data.shape}")
    return data


def _same(values, other) -> bool:
    return np.allclose(np.asarray(values, dtype=float), np.asarray(other, dtype=float), rtol=1e-9, atol=0.0)


def pair_movie(earlier: Frame, later: Frame) -> tuple:
    """Two single-frame labels layers as a movie of 2 frames, for :func:`map_labels`.

    Both must be one frame (no time axis: a layer of 3 axes is a 3D stack, unless ``axes`` names
    a T axis), of the same shape, scale and translate (the mapping goes pixel to pixel), and of
    the same unit where both state one. A movie is refused, not cut to one of its time points.

    Returns
    -------
    (data, spacing, unit)
        ``data`` the two frames stacked, time first (earlier, later); ``spacing`` the pixel
        size, in napari's order; ``unit`` the one stated (or None).

    Raises
    ------
    ValueError
        Naming both layers, what differs, and what to do.
    """
    first, second = _one_frame(earlier), _one_frame(later)
    names = f"labels {earlier.name!r} and {later.name!r}"
    if first.ndim != second.ndim and (first.shape[1:] == second.shape or second.shape[1:] == first.shape):
        more, less = (earlier, later) if first.ndim > second.ndim else (later, earlier)
        raise ValueError(f"{names}: {more.name!r} has one axis more than {less.name!r}, "
                         f"{np.shape(more.data)} and {np.shape(less.data)}: a movie of 2D frames? Two-layer mode "
                         f"takes one frame per layer: choose 'none' as the later layer to map the movie as a "
                         f"series, or add the two time points as layers of their own")
    if first.shape != second.shape:
        raise ValueError(f"{names}: differ in shape, {first.shape} and {second.shape}; two-layer mode maps "
                         f"pixel to pixel: give both the same shape (crop, pad or resample one onto the other's "
                         f"grid)")
    if not _same(earlier.scale, later.scale):
        raise ValueError(f"{names}: differ in scale (pixel size), {tuple(earlier.scale)} and "
                         f"{tuple(later.scale)}; set the same scale on both layers, or resample one onto the "
                         f"other's grid")
    if not _same(earlier.translate, later.translate):
        raise ValueError(f"{names}: differ in translate, {tuple(earlier.translate)} and "
                         f"{tuple(later.translate)}; the mapping goes pixel to pixel: set the same translate on "
                         f"both layers")
    if earlier.unit and later.unit and earlier.unit != later.unit:
        raise ValueError(f"{names}: differ in unit, {earlier.unit!r} and {later.unit!r}; give both scales in one "
                         f"unit (convert one layer's scale)")
    data, spacing = check_labels(np.stack([first, second]), earlier.scale)
    return data, spacing, earlier.unit or later.unit


def methods(dim: int) -> tuple:
    """The mapping algorithms for curves (``dim=2``) or surfaces (``dim=3``)."""
    return CURVE_METHODS if dim == 2 else SURFACE_METHODS


def check_labels(data, spacing) -> tuple:
    """``(data, spacing)`` checked: a labels movie ``(T, rows, columns)`` or ``(T, planes, rows,
    columns)`` of integers or booleans with at least 2 time points, and one positive, finite
    spacing per spatial axis, in napari's order ((plane,) row, column)."""
    data = np.asarray(data)
    if data.ndim not in (3, 4):
        raise ValueError(f"labels: expected a movie with time first, (T, rows, columns) or (T, planes, rows, "
                         f"columns), got {data.ndim} axes {data.shape}")
    if not (np.issubdtype(data.dtype, np.integer) or data.dtype == bool):
        raise TypeError(f"labels: expected integer labels or a boolean mask, got {data.dtype}")
    if data.shape[0] < 2:
        raise ValueError(f"labels: has {data.shape[0]} time point; expected at least 2")
    spacing = np.asarray(spacing, dtype=float).ravel()
    if spacing.shape != (data.ndim - 1,) or not np.all(np.isfinite(spacing)) or np.any(spacing <= 0):
        raise ValueError(f"spacing: expected {data.ndim - 1} positive sizes ((plane,) row, column), got "
                         f"{spacing.tolist()}")
    return data, tuple(spacing.tolist())


def check_options(options: Options, dim: int) -> Options:
    """``options`` checked against what the widget offers for a ``dim``-D movie."""
    if options.objects not in CHOICES:
        raise ValueError(f"objects: expected one of {', '.join(CHOICES)}, got {options.objects!r}")
    if options.objects == "label" and options.label is None:
        raise ValueError("label: choose the object's value (objects='label' takes the pixels of one label)")
    if options.method not in methods(dim):
        raise ValueError(f"method: {options.method!r} does not map {'curves' if dim == 2 else 'surfaces'}; "
                         f"expected one of {', '.join(methods(dim))}")
    if options.drift not in DRIFT:
        raise ValueError(f"drift: expected one of {', '.join(DRIFT)}, got {options.drift!r}")
    return options


def map_labels(data, spacing, options: Options = Options(), *, dt=None, unit=None):
    """Map a labels movie as a napari Labels layer holds it.

    Parameters
    ----------
    data : (T, rows, columns) or (T, planes, rows, columns) integer or bool array
        The layer's data, time first: a 2D movie gives curves, a 3D one surfaces.
    spacing : sequence of float
        The pixel size per spatial axis in napari's order, ``(sy, sx)`` or ``(sz, sy, sx)``: the
        layer's scale without its time axis.
    options : Options
        The object, smoothing, method and drift removal.
    dt : float, optional
        The time between frames (the file's frame interval); default 1.
    unit : str, optional
        The unit of ``spacing`` (``"um"``), for :meth:`morphomap.series.Series.write`'s figures.

    Returns
    -------
    morphomap.series.Series
        As :func:`morphomap.map_series` returns it, in physical (x, y[, z]) coordinates.
    """
    data, spacing = check_labels(data, spacing)
    dim = data.ndim - 1
    options = check_options(options, dim)
    image = Image(data, "TYX" if dim == 2 else "TZYX", spacing, unit, dt)
    objects = None if options.objects == "label" else options.objects
    label = options.label if options.objects in ("label", "follow") else None
    movie = movie_frames(image, label=label, objects=objects, smooth=options.smooth)
    register = None if options.drift == "none" else options.drift
    return map_series(movie, options.method, register=register, progress=False)
