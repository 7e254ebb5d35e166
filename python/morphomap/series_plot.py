"""Pictures of a time series: trajectories coloured by time, growth maps, an animation."""

from __future__ import annotations

import os

import matplotlib.animation as animation
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

from .figure_style import (C1_COLOUR, TIME_MAP, colour_bar, colour_scale, orient_axes, resolve_y_down, speed_unit,
                           time_stamp, unit_name)
from .io.atomic import atomic_path
from .plot import _new_axes, offscreen_figure, save_figure

#: At most this many trajectories are drawn in 3D (evenly chosen): more only hide the surfaces.
MAX_TRAJECTORIES_3D = 1500

#: The growth maps :func:`plot_growth` draws.
GROWTH_MAPS = ("stretch", "accumulated_stretch", "normal_speed", "accumulated_normal_speed")

_LABELS = {
    "stretch": "stretch over the step",
    "accumulated_stretch": "stretch since frame 0",
    "normal_speed": "normal speed",
    "accumulated_normal_speed": "mean normal speed since birth",
}


def _style(series, y_down, unit) -> tuple:
    """``(y_down, unit)`` for a figure of ``series``: as given, else as the series says its frames
    came (y-down and the image's unit for frames traced from images)."""
    y_down = resolve_y_down(y_down, getattr(series, "y_down", False))
    unit = getattr(series, "unit", None) if unit is None else unit
    unit_name(unit)  # a bad unit refused before anything is drawn
    return y_down, unit


def _bar_label(series, quantity, unit) -> str:
    """The colour bar's label of a growth map, with its unit."""
    if quantity.endswith("stretch"):
        return f"{_LABELS[quantity]} ({'length' if series.dim == 2 else 'area'} ratio)"
    return f"{_LABELS[quantity]} ({speed_unit(unit, getattr(series, 'time_unit', None))})"


def _check_axes(ax, dim):
    if ax is None:
        return _new_axes("3d" if dim == 3 else None)
    if (dim == 3) != hasattr(ax, "plot_trisurf"):
        wanted = "a 3D axes (projection='3d')" if dim == 3 else "a 2D axes"
        raise TypeError(f"ax: expected {wanted} for a {dim}D series")
    return ax


def _frame_points(series, t):
    frame = series.frames[t]
    return np.asarray(frame if series.dim == 2 else frame.vertices, dtype=float)


def _draw_frame(ax, series, t, colour, alpha, width=1.0):
    if series.dim == 2:
        points = _frame_points(series, t)
        closed = np.vstack([points, points[:1]])
        ax.plot(*closed.T, color=colour, alpha=alpha, lw=width)
    else:
        frame = series.frames[t]
        ax.plot_trisurf(*np.asarray(frame.vertices).T, triangles=np.asarray(frame.faces), color=colour, alpha=alpha,
                        linewidth=0)


def _limits(ax, series, frames, y_down, unit):
    """Equal, fixed limits around ``frames``, the axes labelled and oriented."""
    everything = np.vstack([_frame_points(series, t) for t in frames])
    low, high = everything.min(axis=0), everything.max(axis=0)
    centre, half = (low + high) / 2, 0.52 * (high - low).max()
    if series.dim == 2:
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_aspect("equal")
    else:
        ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
               zlim=(centre[2] - half, centre[2] + half))
        ax.set_box_aspect((1, 1, 1))
    orient_axes(ax, series.dim, y_down=y_down, unit=unit)


def _trajectory_lines(ax, series, last, norm):
    """The trajectories from frame 0 to frame ``last`` as one collection, each step's piece
    coloured by the frame it ends on."""
    points = np.arange(series.trajectories.shape[1])
    if series.dim == 3 and len(points) > MAX_TRAJECTORIES_3D:
        points = points[np.linspace(0, len(points) - 1, MAX_TRAJECTORIES_3D).astype(int)]
    path = series.trajectories[: last + 1, points]
    if series.dim == 2:
        # One line per step, its pieces apart by NaN: a collection of single pieces costs matplotlib
        # a Path object per piece (15 million for 134 hourly limb frames: minutes per animation).
        colours = ScalarMappable(norm, TIME_MAP)
        for j in range(1, last + 1):
            pieces = np.stack([path[j - 1], path[j], np.full_like(path[j], np.nan)], axis=1).reshape(-1, 2)
            ax.plot(*pieces.T, color=colours.to_rgba(j), lw=0.9)
        return colours
    segments = np.stack([path[:-1], path[1:]], axis=2).reshape(-1, 2, series.dim)
    times = np.repeat(np.arange(1, last + 1), len(points)).astype(float)
    drawn = np.isfinite(segments).all(axis=(1, 2))
    lines = Line3DCollection(segments[drawn], cmap=TIME_MAP, norm=norm, linewidths=0.9)
    lines.set_array(times[drawn])
    ax.add_collection3d(lines)
    return lines


def plot_trajectories(series, ax=None, *, title=None, y_down=None, unit=None):
    """Draw the followed points' paths over all frames, coloured by time; returns the ``Axes``.

    Every frame's boundary is drawn thin and grey (3D: the first and last surfaces, translucent),
    each point's path as line pieces from frame to frame, coloured by the frame the piece ends on
    (a colour bar gives the frame); in 3D at most :data:`MAX_TRAJECTORIES_3D` paths, evenly chosen.

    Parameters
    ----------
    series : Series
    ax : matplotlib.axes.Axes, optional
        Where to draw (a 3D axes for a 3D series), by default a new figure.
    title : str, optional
    y_down : bool, optional
        Draw the frames as their images look (2D: y down; 3D: seen along the stack); by default
        as :attr:`Series.y_down` says (True for frames traced from images).
    unit : str, optional
        The coordinates' unit for the axis labels; by default :attr:`Series.unit`, else ``"units"``.
    """
    y_down, unit = _style(series, y_down, unit)
    ax = _check_axes(ax, series.dim)
    last = len(series.frames) - 1
    for t in range(len(series.frames)) if series.dim == 2 else (0, last):
        _draw_frame(ax, series, t, "0.6", 0.7 if series.dim == 2 else 0.12, 0.6)
    lines = _trajectory_lines(ax, series, last, Normalize(0, last))
    ax.figure.colorbar(lines, ax=ax, shrink=0.7, label="frame")
    _limits(ax, series, range(len(series.frames)), y_down, unit)
    ax.set_title(title if title is not None else f"trajectories of {series.trajectories.shape[1]} points")
    return ax


def growth_map(series, quantity, step):
    """``(values, cells, points)``: the growth map ``quantity`` of step ``step`` as one value per
    piece (2D) or triangle (3D) of ``series.cells[step]``, placed at the end of the step (point
    values, the normal speeds, are averaged over each piece's corners)."""
    if quantity not in GROWTH_MAPS:
        raise ValueError(f"quantity: expected one of {', '.join(map(repr, GROWTH_MAPS))}, got {quantity!r}")
    step = series._step(step)
    cells = series.cells[step]
    if quantity in ("stretch", "accumulated_stretch"):
        values = getattr(series, quantity)(step)
    else:
        values = getattr(series, quantity)[step][cells].mean(axis=1)
    return values, cells, series.trajectories[step + 1]


def plot_growth(series, quantity="accumulated_stretch", step=-1, ax=None, *, title=None, scale="robust", y_down=None,
                unit=None):
    """Draw a growth map as colour on the boundary; returns the ``Axes``.

    Parameters
    ----------
    series : Series
    quantity : str
        One of :data:`GROWTH_MAPS`.
    step : int
        The step (default the last), drawn on the followed boundary at its end, frame
        ``step + 1``: in 2D the pieces between the followed points as coloured lines, in 3D the
        followed triangles coloured. Pieces with an unknown value (a lost point) are left out.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a 3D axes for a 3D series), by default a new figure.
    title : str, optional
    scale : {"robust", "linear", "log"}
        The colour scale (:func:`morphomap.figure_style.colour_scale`): by default from the 2nd
        to the 98th percentile, so that one outlier leaves the rest readable (arrows on the colour
        bar mark values beyond it); ``"log"`` for stretches. A sequential colour map, or a
        diverging one centred on 0 for normal speeds that change sign. The colour bar is labelled
        with the quantity and its unit.
    y_down, unit : optional
        As in :func:`plot_trajectories`.
    """
    values, cells, points = growth_map(series, quantity, step)
    y_down, unit = _style(series, y_down, unit)
    shown = np.isfinite(values) & np.isfinite(points[cells]).all(axis=(1, 2))
    values, cells = values[shown], cells[shown]
    # Growing here, shrinking there: normal speeds are coloured either side of 0.
    colours = colour_scale(values, scale, diverging=quantity.endswith("normal_speed"))
    ax = _check_axes(ax, series.dim)
    if series.dim == 2:
        artist = LineCollection(points[cells], cmap=colours.cmap, norm=colours.norm, linewidths=3)
        artist.set_array(values)
        ax.add_collection(artist)
    else:
        artist = Poly3DCollection(points[cells], cmap=colours.cmap, norm=colours.norm, linewidths=0)
        artist.set_array(values)
        ax.add_collection3d(artist)
    colour_bar(ax, artist, colours, _bar_label(series, quantity, unit))
    step = series._step(step)
    _limits(ax, series, (step, step + 1), y_down, unit)
    when = f"at frame {step + 1}" if quantity.startswith("accumulated") else f"frames {step} to {step + 1}"
    ax.set_title(title if title is not None else f"{_LABELS[quantity]}, {when}")
    return ax


def plot_frame(series, t, ax=None, *, y_down=None, unit=None, title=None):
    """Draw one picture of :func:`animate`: frame ``t``'s boundary, the paths of the followed points
    so far coloured by time and the points where they are, with limits fixed over all frames;
    returns the ``Axes``.

    The title stamps the time, ``t * series.dt`` in :attr:`Series.time_unit` (a movie's frame
    interval in seconds is given in s, min, h or d, whichever suits the series): e.g.
    ``"t = 1.5 h (frame 3 of 4): 120 points"``; without a known unit, the bare number.
    ``y_down``, ``unit``: as in :func:`plot_trajectories`.
    """
    y_down, unit = _style(series, y_down, unit)
    last = len(series.frames) - 1
    if isinstance(t, (bool, np.bool_)) or not isinstance(t, (int, np.integer)):
        raise TypeError(f"t: expected an integer, got {type(t).__name__}")
    if not 0 <= t <= last:
        raise ValueError(f"t: expected a frame 0..{last}, got {t}")
    ax = _check_axes(ax, series.dim)
    _draw_frame(ax, series, t, C1_COLOUR, 1.0 if series.dim == 2 else 0.25, 1.6)
    if t:
        _trajectory_lines(ax, series, t, Normalize(0, max(last, 1)))
    now = series.trajectories[t]
    now = now[np.isfinite(now).all(axis=1)]
    ax.scatter(*now.T, s=3 if series.dim == 2 else 1, color="black")
    _limits(ax, series, range(len(series.frames)), y_down, unit)
    stamp = time_stamp(t, series.dt, getattr(series, "time_unit", None), last)
    ax.set_title(title if title is not None else f"{stamp} (frame {t} of {last}): {len(now)} points")
    return ax


def animate(series, path, *, fps=2, dpi=90, y_down=None, unit=None):
    """Write an animation of the series to ``path``: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg).

    One picture per frame, drawn by :func:`plot_frame` (stamped with its time): that frame's
    boundary, the paths of the followed points so far coloured by time and the points where they
    are. Fixed limits over all frames. Written atomically. ``y_down``, ``unit``: as in
    :func:`plot_trajectories`.
    """
    y_down, unit = _style(series, y_down, unit)
    name = str(path)
    suffix = name.lower().rsplit(".", 1)[-1] if "." in name else ""
    if suffix == "gif":
        writer = animation.PillowWriter(fps=fps)
    elif suffix == "mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise ValueError(f"path: writing {name} needs ffmpeg, which is not installed; write a .gif instead")
        writer = animation.FFMpegWriter(fps=fps)
    else:
        raise ValueError(f"path: expected a .gif or .mp4 file, got {name!r}")
    figure = Figure(figsize=(6, 6))
    FigureCanvasAgg(figure)
    ax = figure.add_subplot(projection="3d" if series.dim == 3 else None)
    with atomic_path(name) as temporary:
        with writer.saving(figure, temporary, dpi):
            for t in range(len(series.frames)):
                ax.clear()
                plot_frame(series, t, ax, y_down=y_down, unit=unit)
                writer.grab_frame()


def write_figures(series, folder) -> list:
    """The figures of :meth:`Series.write` into ``folder``: the trajectories, the accumulated growth
    maps at the last frame and the animation (GIF; MP4 when ffmpeg is there). Returns the paths."""
    paths = []
    for name, draw in (("trajectories", lambda ax: series.plot_trajectories(ax)),
                       ("stretch", lambda ax: series.plot_growth("accumulated_stretch", -1, ax)),
                       ("normal_speed", lambda ax: series.plot_growth("accumulated_normal_speed", -1, ax))):
        figure = offscreen_figure(7, 6)
        FigureCanvasAgg(figure)
        draw(figure.add_subplot(projection="3d" if series.dim == 3 else None))
        path = os.path.join(folder, f"{name}.png")
        save_figure(figure, path, dpi=100)
        paths.append(path)
    for suffix in ("gif", "mp4"):
        if suffix == "mp4" and not animation.writers.is_available("ffmpeg"):
            continue
        path = os.path.join(folder, f"series.{suffix}")
        series.animate(path)
        paths.append(path)
    return paths
