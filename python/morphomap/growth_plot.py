"""Growth kinematics drawn and written: heat maps on the boundary with the principal directions of
growth as crosses (3D), kymographs of position along the outline against time (2D), and files
(a CSV table; per step a VTU of the surface with the values as cell data for ParaView)."""

from __future__ import annotations

import os

import numpy as np

from .figure_style import colour_bar, colour_scale, orient_axes, resolve_y_down, speed_unit, time_stamp, unit_name
from .growth import Growth, series_growth
from .io.atomic import atomic_path, atomic_text
from .plot import _new_axes, offscreen_figure, save_figure

#: What a heat map or kymograph can show, and the label of its colour bar (None: a ratio).
QUANTITIES = {
    "areal_growth": "areal growth (area ratio)",
    "areal_growth_rate": "areal growth rate (ln ratio per time)",
    "anisotropy": "anisotropy (lambda1 / lambda2)",
    "normal_velocity": "normal velocity",
}

#: At most this many crosses of principal directions are drawn (evenly chosen): more hide the map.
MAX_CROSSES = 600


def _values(growth: Growth, quantity: str) -> np.ndarray:
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity: expected one of {', '.join(map(repr, QUANTITIES))}, got {quantity!r}")
    return getattr(growth, quantity)


def _label(quantity, dim, unit, time_unit):
    if quantity == "normal_velocity":
        return f"normal velocity ({speed_unit(unit, time_unit)})"
    if dim == 2 and quantity == "areal_growth":
        return "growth (length ratio)"
    return QUANTITIES[quantity]


def push_forward(before, after, directions) -> np.ndarray:
    """Unit directions ``(F, k, 3)`` given in triangles ``before`` ``(F, 3, 3)`` as the map of each
    triangle onto ``after`` carries them (NaN stays NaN)."""
    u, v = before[:, 1] - before[:, 0], before[:, 2] - before[:, 0]
    gram = np.stack([np.stack([np.einsum("ij,ij->i", u, u), np.einsum("ij,ij->i", u, v)], -1),
                     np.stack([np.einsum("ij,ij->i", v, u), np.einsum("ij,ij->i", v, v)], -1)], -2)
    result = np.full_like(directions, np.nan)
    ok = np.abs(np.linalg.det(gram)) > 0
    for j in range(directions.shape[1]):
        d = directions[ok, j]
        right = np.stack([np.einsum("ij,ij->i", u[ok], d), np.einsum("ij,ij->i", v[ok], d)], -1)
        alpha, beta = np.linalg.solve(gram[ok], right[..., None])[..., 0].T
        moved = alpha[:, None] * (after[ok, 1] - after[ok, 0]) + beta[:, None] * (after[ok, 2] - after[ok, 0])
        result[ok, j] = moved / np.linalg.norm(moved, axis=1)[:, None]
    return result


def plot_growth_map(growth: Growth, quantity="areal_growth", *, corners=None, ax=None, crosses=True,
                    scale="robust", unit=None, time_unit=None, y_down=False):
    """A heat map of one growth quantity on the boundary; in 3D with the principal directions of
    growth as crosses (arms along lambda1 and lambda2, lengths in proportion to them; none where
    the growth is isotropic), as MorphoGraphX draws them.

    Parameters
    ----------
    growth : Growth
    quantity : one of :data:`QUANTITIES`
    corners : (F, k, d) float, optional
        Where to draw the elements (default: where they were before, ``growth.before[growth.cells]``);
        the crosses are carried onto them.
    ax : matplotlib axes (3D in 3D), optional
    scale : {"robust", "linear", "log"}
        The colour scale (:func:`morphomap.figure_style.colour_scale`).
    unit, time_unit, y_down : as the other figures (:mod:`morphomap.figure_style`).

    Returns
    -------
    the axes
    """
    from matplotlib.collections import LineCollection
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    values = _values(growth, quantity)
    reference = growth.before[growth.cells]
    corners = reference if corners is None else np.asarray(corners, dtype=float)
    if corners.shape != reference.shape:
        raise ValueError(f"corners: expected {reference.shape} (one row of corners per element), got {corners.shape}")
    dim = growth.dim
    ax = _new_axes("3d" if dim == 3 else None) if ax is None else ax
    colours = colour_scale(values, scale, diverging=quantity == "normal_velocity")
    known = np.isfinite(corners).all(axis=(1, 2))
    if dim == 2:
        artist = LineCollection(corners[known], cmap=colours.cmap, norm=colours.norm, linewidths=3)
        artist.set_array(values[known])
        ax.add_collection(artist)
        ax.set_aspect("equal")
        ax.autoscale_view()
    else:
        artist = Poly3DCollection(corners[known], cmap=colours.cmap, norm=colours.norm, edgecolor="none")
        artist.set_array(values[known])
        ax.add_collection3d(artist)
        shown = corners[known].reshape(-1, 3)
        low, high = shown.min(axis=0), shown.max(axis=0)
        centre, half = (low + high) / 2, 0.52 * (high - low).max()
        ax.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
               zlim=(centre[2] - half, centre[2] + half))
        segments = _crosses(growth, reference, corners) if crosses else ()
        if len(segments):  # (matplotlib refuses an empty 3D collection)
            ax.add_collection3d(Line3DCollection(segments, colors="black", linewidths=0.8))
    colour_bar(ax, artist, colours, _label(quantity, dim, unit, time_unit))
    orient_axes(ax, dim, y_down=y_down, unit=unit)
    return ax


def _crosses(growth, reference, corners):
    """Line segments of the principal directions at the centroids of (at most MAX_CROSSES) triangles."""
    directions = growth.directions if corners is reference else push_forward(reference, corners, growth.directions)
    chosen = np.flatnonzero(np.isfinite(directions).all(axis=(1, 2)) & np.isfinite(corners).all(axis=(1, 2)))
    if not len(chosen):
        return np.zeros((0, 2, 3))
    chosen = chosen[np.linspace(0, len(chosen) - 1, min(len(chosen), MAX_CROSSES)).astype(int)]
    edge = np.median(np.linalg.norm(corners[chosen, 1] - corners[chosen, 0], axis=1))
    centre = corners[chosen].mean(axis=1)
    relative = growth.stretches[chosen] / growth.stretches[chosen, :1]
    segments = []
    for j in range(2):
        arm = 0.35 * edge * relative[:, j, None] * directions[chosen, j]
        segments.append(np.stack([centre - arm, centre + arm], axis=1))
    return np.concatenate(segments)


def plot_kymograph(series, quantity="areal_growth_rate", *, accumulated=False, ax=None, scale="robust", unit=None,
                   found=None):
    """A 2D series' growth as position along the outline (arc length from the followed curve's
    first point, on frame k) against time, one row per step, as morphodynamics draws edge
    velocities: where along the outline the organ grows, and when.

    Parameters
    ----------
    series : Series (2D)
    quantity : one of :data:`QUANTITIES` but ``"anisotropy"`` (a curve has one direction)
    accumulated : bool
        The values from each piece's birth (else over each step).
    ax, scale, unit : as :func:`plot_growth_map` (unit default: the series').
    found : SeriesGrowth, optional
        The series' growth where the caller has it (computed here otherwise).

    Returns
    -------
    the axes
    """
    if series.dim != 2:
        raise ValueError("series: a kymograph is of a 2D series (position along an outline)")
    if quantity == "anisotropy":
        raise ValueError("quantity: a curve has no anisotropy; use 'areal_growth', 'areal_growth_rate' or "
                         "'normal_velocity'")
    found = series_growth(series) if found is None else found
    rows = found.accumulated if accumulated else found.steps
    unit = getattr(series, "unit", None) if unit is None else unit
    values = np.concatenate([_values(g, quantity) for g in rows])
    colours = colour_scale(values, scale, diverging=quantity == "normal_velocity")
    ax = _new_axes(None) if ax is None else ax
    artist = None
    for k, (g, cells) in enumerate(zip(rows, series.cells)):
        points = series.trajectories[k]
        lengths = np.linalg.norm(points[cells[:, 1]] - points[cells[:, 0]], axis=1)
        edges = np.concatenate([[0.0], np.nancumsum(lengths)])
        x = np.vstack([edges, edges])
        y = np.array([[k], [k + 1]]) * series.dt * np.ones_like(edges)
        artist = ax.pcolormesh(x, y, _values(g, quantity)[None, :], cmap=colours.cmap, norm=colours.norm,
                               shading="flat")
    time_unit = getattr(series, "time_unit", None)
    ax.set(xlabel=f"position along the outline ({unit_name(unit)})",
           ylabel=f"time ({time_unit})" if time_unit else "time", ylim=(len(rows) * series.dt, 0))
    what = _label(quantity, 2, unit, time_unit) + (", since birth" if accumulated else ", per step")
    colour_bar(ax, artist, colours, what)
    return ax


def write_growth(series, folder, *, figures=True) -> list:
    """The growth kinematics of a series into ``folder``; returns the paths written.

    - ``growth.csv``: step, piece, its corners, areal growth, its rate, lambda1 (lambda2 in 3D),
      anisotropy, normal velocity, tangential speed, each over the step and accumulated since the
      piece's birth;
    - 3D: ``growth_KK.vtu`` per step, the surface of frame k + 1 (the followed points) with those
      values as cell data and the principal directions carried onto it (``major``, ``minor``);
    - with ``figures``: ``kymograph.png`` (2D, the accumulated rate along the outline against
      time) or ``growth.png`` (3D, the accumulated areal growth on the last frame with its crosses).
    """
    found = series_growth(series)
    paths = [_write_table(series, found, os.path.join(folder, "growth.csv"))]
    if series.dim == 3:
        for k, (step, total) in enumerate(zip(found.steps, found.accumulated)):
            paths.append(_write_vtu(series, k, step, total, os.path.join(folder, f"growth_{k:02d}.vtu")))
    if figures:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        figure = offscreen_figure(8, 6)
        FigureCanvasAgg(figure)
        if series.dim == 2:
            name = "kymograph.png"
            plot_kymograph(series, "areal_growth_rate", accumulated=True, ax=figure.add_subplot(), found=found)
        else:
            name = "growth.png"
            k = len(series.fields) - 1
            ax = figure.add_subplot(projection="3d")
            corners = series.trajectories[k + 1][series.cells[k]]
            y_down = resolve_y_down(None, getattr(series, "y_down", False))
            plot_growth_map(found.accumulated[k], "areal_growth", corners=corners, ax=ax, unit=series.unit,
                            time_unit=series.time_unit, y_down=y_down)
            ax.set_title(f"areal growth since birth, frame {k + 1} "
                         f"({time_stamp(k + 1, series.dt, series.time_unit, len(series.frames))})")
        path = os.path.join(folder, name)
        save_figure(figure, path, dpi=100)
        paths.append(path)
    return paths


def _columns(g):
    speed = np.linalg.norm(g.tangential_velocity, axis=1)
    second = g.stretches[:, 1] if g.stretches.shape[1] > 1 else np.full(len(speed), np.nan)
    return np.column_stack([g.areal_growth, g.areal_growth_rate, g.stretches[:, 0], second, g.anisotropy,
                            g.normal_velocity, speed])


def _write_table(series, found, path):
    names = ("areal_growth", "areal_growth_rate", "lambda1", "lambda2", "anisotropy", "normal_velocity",
             "tangential_speed")
    corners = "a,b" if series.dim == 2 else "a,b,c"
    with atomic_text(path) as handle:
        handle.write(f"step,piece,{corners}," + ",".join(names) + "," + ",".join(f"accumulated_{n}" for n in names)
                     + "\n")
        for k, (step, total) in enumerate(zip(found.steps, found.accumulated)):
            table = np.column_stack([_columns(step), _columns(total)])
            for i, (cell, row) in enumerate(zip(series.cells[k].tolist(), table.tolist())):
                handle.write(f"{k},{i}," + ",".join(map(str, cell)) + "," + ",".join(repr(v) for v in row) + "\n")
    return path


def _write_vtu(series, k, step, total, path):
    import meshio

    cells = np.asarray(series.cells[k])
    points = series.trajectories[k + 1]
    used = np.unique(cells)
    index = np.full(len(points), -1)
    index[used] = np.arange(len(used))
    data = {}
    for prefix, g in (("", step), ("accumulated_", total)):
        for name, column in zip(("areal_growth", "areal_growth_rate", "lambda1", "lambda2", "anisotropy",
                                 "normal_velocity"), _columns(g).T):
            data[prefix + name] = [column]
    reference = total.before[total.cells]
    moved = push_forward(reference, points[cells], total.directions)
    data["major"], data["minor"] = [np.nan_to_num(moved[:, 0])], [np.nan_to_num(moved[:, 1])]
    mesh = meshio.Mesh(np.nan_to_num(points[used]), [("triangle", index[cells])], cell_data=data)
    with atomic_path(path) as temporary:
        mesh.write(temporary, file_format="vtu")
    return path
