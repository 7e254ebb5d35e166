"""How every figure morphomap draws is oriented, labelled and coloured: one owner per rule.

- **Orientation.** Data traced from an image (:func:`morphomap.boundary_from_mask`,
  :func:`morphomap.movie.movie_frames`) has x = column and y = row, so it is drawn y-down, row 0
  at the top, as the image looks; other data y-up. ``y_down=None`` in a figure means exactly
  that choice; ``True`` / ``False`` force it. In 3D no axis is flipped (that would mirror the
  object): the camera is placed below the stack instead, looking along +z, so x runs right and
  y runs down the screen as in the image's slices.
- **Units.** Axes are labelled with the unit of the coordinates (``"x (µm)"``), ``"units"`` where
  it is not known; time stamps carry the frame interval's unit.
- **Colour scales.** Maps of stretch, growth and vector length span the 2nd to 98th percentiles
  of their values (a single outlier does not wash out the rest), or a log scale; the colour bar
  is labelled and shows arrows where values are clipped.
- **Colours.** The paper's colours for fields: C1 green, C2 blue, vectors red.
- **Method names.** Figures name methods by string, never by the core's integer codes.
"""

from __future__ import annotations

from typing import NamedTuple, Optional

import numpy as np

from ._validate import as_flag
from .field import METHOD_NAMES

C1_COLOUR = "tab:green"
C2_COLOUR = "tab:blue"
VECTOR_COLOUR = "red"
CROSSING_COLOUR = "darkorange"
MISS_COLOUR = "grey"

#: Colour maps: values of one sign, values either side of 0, and time.
SEQUENTIAL_MAP = "viridis"
DIVERGING_MAP = "coolwarm"
TIME_MAP = "plasma"

#: The colour scales of :func:`colour_scale`.
SCALES = ("robust", "linear", "log")
#: The percentiles a ``"robust"`` colour scale spans.
PERCENTILES = (2.0, 98.0)

#: The axis label's unit where the coordinates' unit is not known.
NO_UNIT = "units"
#: How units are written on axes (the names :func:`morphomap.read_image` gives them).
_UNIT_NAMES = {"um": "µm", "pixel": "pixels"}

#: The camera (elevation, azimuth) of a 3D figure of image data: below the stack, tilted by 30
#: degrees to show depth, so that x runs right and y down the screen.
IMAGE_VIEW_3D = (-60.0, -90.0)

#: Time units for stamps, in seconds, largest first.
_TIME_UNITS = (("d", 86400.0), ("h", 3600.0), ("min", 60.0), ("s", 1.0))


def unit_name(unit: Optional[str]) -> str:
    """How ``unit`` is written on an axis: ``"um"`` as ``"µm"``, None as :data:`NO_UNIT`."""
    if unit is None:
        return NO_UNIT
    if not isinstance(unit, str):
        raise TypeError(f"unit: expected a string or None, got {type(unit).__name__}")
    return _UNIT_NAMES.get(unit, unit)


def resolve_y_down(y_down, from_image: bool) -> bool:
    """``y_down`` as given, or (None) whether the data came from an image."""
    return bool(from_image) if y_down is None else as_flag(y_down, "y_down")


def orient_axes(ax, dim: int, *, y_down: bool, unit: Optional[str]) -> None:
    """Label the axes with the unit and turn them the way the data is to be seen (see the module
    notes). Call after the limits are set; calling it twice does no harm."""
    name = unit_name(unit)
    letters = "xyz"[:dim]
    ax.set(**{f"{letter}label": f"{letter} ({name})" for letter in letters})
    if dim == 2:
        ax.yaxis.set_inverted(y_down)
    elif y_down:
        ax.view_init(*IMAGE_VIEW_3D)


class ColourScale(NamedTuple):
    """What :func:`colour_scale` returns: the norm, the colour map's name, and which ends of the
    colour bar get arrows (values beyond the scale: ``"neither"``, ``"min"``, ``"max"``, ``"both"``)."""

    norm: object  # a matplotlib.colors.Normalize
    cmap: str
    extend: str


def colour_scale(values, scale: str = "robust", *, diverging: bool = False) -> ColourScale:
    """The colour scale for ``values`` (NaN ignored).

    Parameters
    ----------
    values : array of float
    scale : {"robust", "linear", "log"}
        ``"robust"``: from the 2nd to the 98th percentile (:data:`PERCENTILES`); ``"linear"``:
        from the smallest to the largest value; ``"log"``: logarithmic over the robust range
        (values must be positive, as stretches are).
    diverging : bool
        Values that may change sign (normal speeds): where they do, a diverging map centred on 0.

    Raises
    ------
    ValueError
        An unknown ``scale``, or ``"log"`` for values that are not all positive.
    """
    # matplotlib here, not at the top: the command line names methods through this module
    # without paying for matplotlib where no picture is drawn.
    from matplotlib.colors import LogNorm, Normalize, TwoSlopeNorm

    if scale not in SCALES:
        raise ValueError(f"scale: expected one of {', '.join(map(repr, SCALES))}, got {scale!r}")
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if scale == "log" and (values <= 0).any():
        raise ValueError(f"scale: 'log' needs positive values, got a smallest value of {values.min():g}")
    if len(values) == 0:
        return ColourScale(Normalize(0.0, 1.0), SEQUENTIAL_MAP, "neither")
    smallest, largest = float(values.min()), float(values.max())
    low, high = (smallest, largest) if scale == "linear" else map(float, np.percentile(values, PERCENTILES))
    if high <= low:  # one value (outliers aside, which still must not set the scale): a band around it
        low, high = (low / 2, high * 2) if scale == "log" else (low - 0.5 * abs(low or 1), high + 0.5 * abs(high or 1))
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[
        (smallest < low, largest > high)]
    if scale == "log":
        return ColourScale(LogNorm(low, high), SEQUENTIAL_MAP, extend)
    if diverging and low < 0 < high:
        return ColourScale(TwoSlopeNorm(0.0, low, high), DIVERGING_MAP, extend)
    return ColourScale(Normalize(low, high), SEQUENTIAL_MAP, extend)


def colour_bar(ax, artist, colours: ColourScale, label: str):
    """A labelled colour bar for ``artist`` beside ``ax``, with arrows where values are clipped."""
    return ax.figure.colorbar(artist, ax=ax, shrink=0.7, label=label, extend=colours.extend)


def time_unit_for(span_seconds: float) -> tuple:
    """``(name, seconds)``: the largest of d, h, min, s in which ``span_seconds`` is at least 2."""
    for name, seconds in _TIME_UNITS:
        if span_seconds >= 2 * seconds:
            return name, seconds
    return "s", 1.0


def time_stamp(t: int, dt: float, time_unit: Optional[str], span_frames: int = 1) -> str:
    """``"t = 3.0 h"``: the time of frame ``t``, ``dt`` apart. ``time_unit`` ``"s"`` is given in
    the unit that suits the whole series (``span_frames`` frames: s, min, h or d); another unit as
    it is; None (unknown) without a unit."""
    time = t * dt
    if time_unit == "s":
        time_unit, seconds = time_unit_for(max(span_frames, 1) * dt)
        time = time / seconds
    number = f"{time:.1f}" if abs(time) < 100 else f"{time:.0f}"
    return f"t = {number}" + (f" {time_unit}" if time_unit else "")


def speed_unit(unit: Optional[str], time_unit: Optional[str]) -> str:
    """The unit of a speed: ``"µm/s"``; ``"units/time"`` where neither is known."""
    return f"{unit_name(unit)}/{time_unit or 'time'}"


def method_names(methods) -> np.ndarray:
    """A field's methods as names: strings pass, the core's integer codes become their names."""
    methods = np.asarray(methods)
    if methods.dtype.kind in "iu":
        if methods.size and (methods.min() < 0 or methods.max() >= len(METHOD_NAMES)):
            raise ValueError(f"methods: codes expected in 0..{len(METHOD_NAMES) - 1}, got {methods.min()}.."
                             f"{methods.max()}")
        return np.asarray(METHOD_NAMES)[methods]
    return methods.astype(str)


def method_summary(methods) -> str:
    """``"normal 38, diffusion 2"``: how many vectors each method gave, by name."""
    names, counts = np.unique(method_names(methods), return_counts=True)
    return ", ".join(f"{name} {count}" for name, count in zip(names.tolist(), counts.tolist()))


def movie_provenance(movie, dt) -> dict:
    """What a figure of a series needs to know about frames read from a movie: their unit (pixels
    where the movie has no spacing), that they are drawn y-down, and the unit of ``dt`` (seconds
    where it is the movie's frame interval, unknown where the caller gave it)."""
    return {"unit": movie.unit or "pixel", "y_down": True,
            "time_unit": "s" if dt is None and movie.dt is not None else None}
