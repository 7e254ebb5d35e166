"""Pictures of displacement fields in the style of the paper's figures (needs matplotlib)."""

from __future__ import annotations

import os
import sys

import matplotlib
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from ._validate import as_flag, as_points
from .crossings import crossing_pairs
from .field import DisplacementField
from .figure_style import (C1_COLOUR, C2_COLOUR, CROSSING_COLOUR, MISS_COLOUR, VECTOR_COLOUR,  # noqa: F401
                           colour_bar, colour_scale, orient_axes, resolve_y_down, unit_name)
from .io.atomic import atomic_path
from .prepared import as_surface


def _headless() -> bool:
    """True when no backend was chosen and there is no display to show windows on."""
    if os.environ.get("MPLBACKEND") or "matplotlib.pyplot" in sys.modules:
        return False
    if sys.platform.startswith(("win", "darwin")):
        return False
    return not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _new_axes(projection=None):
    if _headless():
        matplotlib.use("Agg")
    # pyplot only after the backend is chosen, and only where a figure is wanted on screen.
    import matplotlib.pyplot as plt

    figure = plt.figure(figsize=(6, 6))
    return figure.add_subplot(projection=projection)


def _closed_line(points, closed):
    return np.vstack([points, points[:1]]) if closed and len(points) else points


def plot_field(field, c1, c2, ax=None, *, closed=True, title=None, y_down=None, unit=None):
    """Draw a displacement field between two curves (2D) or surfaces (3D); returns the ``Axes``.

    3D fields are drawn by :func:`plot_field_3d` (``c1``, ``c2`` are then the surfaces); the rest
    of this describes 2D.

    C1 is drawn in green, C2 in blue, the vectors as thin red lines with a small dot at each end
    point (as in the paper's figures). Vectors that cross another vector
    (:func:`morphomap.crossing_pairs`) are drawn thicker in orange; start points without a target
    (invalid rows; where the start is NaN but the end is not, the end point on C2) are marked
    with a grey ``x``; rows that are NaN at both ends are counted in the legend but cannot be placed.
    Equal aspect, a legend naming the counts.

    Parameters
    ----------
    field : DisplacementField
        A 2D field.
    c1, c2 : (N, 2) float
        The curves the field maps between.
    ax : matplotlib.axes.Axes, optional
        Where to draw; by default a new figure (with matplotlib's Agg backend when there is no
        display and no backend was chosen). Nothing is shown: save it with ``ax.figure.savefig``.
    closed : bool
        Draw the curves closed.
    title : str, optional
    y_down : bool, optional
        Draw y growing downwards, the way an image looks: for curves from
        :func:`morphomap.boundary_from_mask`, whose y is the image row (``morphomap map --plot``
        does so for masks). None (the default): y-up, as curves carry no mark of an image.
    unit : str, optional
        The unit of the coordinates, for the axis labels (``"um"`` is written ``"µm"``); by
        default ``"units"``.

    Artists added: two lines (C1, C2) and two collections (the vectors, their end points), plus one
    collection for crossing vectors and one for misses when there are any.
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    if field.dim == 3:
        return plot_field_3d(field, c1, c2, ax=ax, title=title, y_down=y_down, unit=unit)
    y_down = resolve_y_down(y_down, False)
    unit_name(unit)  # a bad unit refused before anything is drawn
    c1 = as_points(c1, "c1")
    c2 = as_points(c2, "c2")
    closed = as_flag(closed, "closed")
    if title is not None and not isinstance(title, str):
        raise TypeError(f"title: expected a string, got {type(title).__name__}")
    if ax is None:
        ax = _new_axes()

    starts, ends, valid = field.starts, field.ends, field.valid
    pairs = crossing_pairs(starts, ends)
    crossing = np.zeros(len(field), dtype=bool)
    crossing[pairs.ravel()] = True
    plain = valid & ~crossing
    segments = np.stack([starts, ends], axis=1)

    ax.plot(*_closed_line(c1, closed).T, color=C1_COLOUR, lw=1.6, label="$C_1$", zorder=2)
    ax.plot(*_closed_line(c2, closed).T, color=C2_COLOUR, lw=1.6, label="$C_2$", zorder=2)
    ax.add_collection(LineCollection(segments[plain], colors=VECTOR_COLOUR, linewidths=0.7, zorder=3,
                                     label=f"vectors ({int(valid.sum())})"))
    ax.scatter(*ends[valid].reshape(-1, 2).T, s=4, color=VECTOR_COLOUR, zorder=4, linewidths=0)
    if crossing.any():
        ax.add_collection(LineCollection(segments[crossing], colors=CROSSING_COLOUR, linewidths=1.6, zorder=5,
                                         label=f"crossing ({len(pairs)} pairs)"))
    missed = ~valid
    if missed.any():
        marks = np.where(np.isfinite(starts[missed]).all(axis=1, keepdims=True), starts[missed], ends[missed])
        marks = marks[np.isfinite(marks).all(axis=1)]
        ax.scatter(*marks.reshape(-1, 2).T, marker="x", s=22, color=MISS_COLOUR, linewidths=1.0, zorder=6,
                   label=f"no target ({int(missed.sum())})")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    orient_axes(ax, 2, y_down=y_down, unit=unit)
    ax.legend(loc="best", fontsize="small", framealpha=0.8)
    if title is not None:
        ax.set_title(title)
    return ax


#: At most this many vectors are drawn in 3D (evenly chosen): more only hide the surfaces.
MAX_VECTORS_3D = 4000


def plot_field_3d(field, s1, s2, ax=None, *, title=None, y_down=None, unit=None):
    """Draw a 3D displacement field between two surfaces; returns the matplotlib 3D ``Axes``.

    S1 is drawn in translucent green, S2 in translucent blue, the vectors as lines coloured by their
    length (a colour bar gives the scale, robust: :func:`morphomap.figure_style.colour_scale`; at
    most :data:`MAX_VECTORS_3D` of them, evenly chosen, so that the surfaces stay visible), start
    points without a target as grey ``x``. Equal aspect.

    ``s1``, ``s2``: ``trimesh.Trimesh`` or ``(vertices, faces)`` pairs; ``ax``: a 3D axes
    (``projection="3d"``), by default a new figure. ``y_down``: seen as the image's slices look
    (x right, y down; for surfaces from :func:`morphomap.surface_from_mask`), by default not;
    ``unit``: the coordinates' unit for the labels (default ``"units"``).
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    if field.dim != 3:
        raise ValueError(f"field: expected a 3D field, got {field.dim}D")
    surfaces = [as_surface(s1, "s1"), as_surface(s2, "s2")]
    y_down = resolve_y_down(y_down, False)
    unit_name(unit)  # a bad unit refused before anything is drawn
    if title is not None and not isinstance(title, str):
        raise TypeError(f"title: expected a string, got {type(title).__name__}")
    if ax is None:
        ax = _new_axes("3d")
    elif not hasattr(ax, "plot_trisurf"):
        raise TypeError("ax: expected a 3D axes (projection='3d')")
    for (vertices, faces), colour, name in zip(surfaces, (C1_COLOUR, C2_COLOUR), ("$S_1$", "$S_2$")):
        ax.plot_trisurf(*vertices.T, triangles=faces, color=colour, alpha=0.18, linewidth=0, label=name)
    valid = np.flatnonzero(field.valid)
    shown = valid[np.linspace(0, len(valid) - 1, min(len(valid), MAX_VECTORS_3D)).astype(int)] if len(valid) else valid
    lengths = np.linalg.norm(field.vectors[shown], axis=1)
    drawn = f", {len(shown)} drawn)" if len(shown) < len(valid) else ")"
    colours = colour_scale(lengths)
    lines = Line3DCollection(np.stack([field.starts[shown], field.ends[shown]], axis=1), cmap=colours.cmap,
                             norm=colours.norm, linewidths=0.8, label=f"vectors ({len(valid)}" + drawn)
    lines.set_array(lengths)
    ax.add_collection3d(lines)
    colour_bar(ax, lines, colours, f"vector length ({unit_name(unit)})")
    missed = ~field.valid & np.isfinite(field.starts).all(axis=1)
    if missed.any():
        ax.scatter(
            *field.starts[missed].T, marker="x", s=14, color=MISS_COLOUR, label=f"no target ({int(missed.sum())})"
        )
    everything = np.vstack([surfaces[0][0], surfaces[1][0]])
    low, high = everything.min(axis=0), everything.max(axis=0)
    centre, half = (low + high) / 2, (high - low).max() / 2
    ax.set(
        xlim=(centre[0] - half, centre[0] + half),
        ylim=(centre[1] - half, centre[1] + half),
        zlim=(centre[2] - half, centre[2] + half),
    )
    orient_axes(ax, 3, y_down=y_down, unit=unit)
    ax.set_box_aspect((1, 1, 1))
    ax.legend(loc="upper left", fontsize="small", framealpha=0.8)
    if title is not None:
        ax.set_title(title)
    return ax


def offscreen_figure(width: float, height: float) -> Figure:
    """A figure of ``width`` x ``height`` inches with constrained layout, without pyplot: nothing
    is shown, and it is freed with its last reference (for pictures written to files)."""
    return Figure(figsize=(width, height), layout="constrained")


def save_figure(figure, path, **options) -> None:
    """``figure.savefig(path, **options)``, written atomically (the format from the suffix)."""
    with atomic_path(path) as temporary:
        figure.savefig(temporary, **options)
