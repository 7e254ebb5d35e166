"""A series' results as napari layer data, drawn over the labels movie they came from.

morphomap's arrays are ``(x, y[, z])`` in physical units, with x = column * sx, y = row * sy,
z = plane * sz (:func:`morphomap.boundary_from_mask`, :func:`morphomap.surface_from_mask`).
napari's layers are indexed ``(t, [plane,] row, column)``. :func:`to_pixels` is the one
conversion: every layer here holds pixel indices with the time index first and is shown at the
labels layer's ``scale`` and ``translate``, so that it lies on the image.

With drift removal (``series.motion``) the series lives in the frames as moved onto each other;
each frame's points are moved back by the inverse of its motion so that they lie on the image, and
the displacement vectors of a step turn with their start frame (the drift-free growth, drawn where
it starts on the image).

Each function returns a napari *layer data tuple* ``(data, keyword arguments, layer type)``, plain
numpy, so that it can be checked without a viewer.
"""

from __future__ import annotations

import numpy as np

from ..growth import series_growth

#: The name of the growth quantity the boundaries are coloured by (see :func:`piece_growth`).
GROWTH = "areal growth since birth"


def piece_growth(series, t: int, found=None) -> tuple:
    """The growth quantity shown on frame ``t``, one value per piece of the followed boundary:
    ``(cells, values)``, ``cells`` indexing ``series.trajectories[t]``; ``found`` the series'
    :class:`morphomap.growth.SeriesGrowth` where the caller has it (computed here otherwise).

    This is the one place where the colouring quantity is chosen (named by :data:`GROWTH`): the
    areal growth of each piece since its birth (:func:`morphomap.growth`, ``accumulated``; 2D the
    length ratio, 3D the area ratio), 1 on frame 0. Another quantity of
    :class:`morphomap.growth.Growth` (its rate, anisotropy) replaces it here.
    """
    if t == 0:
        return series.cells[0], np.ones(len(series.cells[0]))
    found = series_growth(series) if found is None else found
    return series.cells[t - 1], found.accumulated[t - 1].areal_growth


def to_pixels(points, spacing) -> np.ndarray:
    """Physical ``(..., d)`` points ``(x, y[, z])`` as napari's pixel indices ``(row, column)`` or
    ``(plane, row, column)``: the axes reversed and divided by ``spacing``, given in napari's
    order ``(sy, sx)`` or ``(sz, sy, sx)``."""
    points = np.asarray(points, dtype=float)
    spacing = np.asarray(spacing, dtype=float)
    if points.ndim < 1 or spacing.shape != (points.shape[-1],):
        raise ValueError(f"spacing: expected one size per coordinate ({points.shape[-1:]}), got {spacing.tolist()}")
    return points[..., ::-1] / spacing


def _on_image(series, t: int, points) -> np.ndarray:
    """Frame ``t``'s physical points moved back onto the image (undoing ``series.motion[t]``)."""
    points = np.asarray(points, dtype=float)
    if series.motion is None:
        return points
    back = np.linalg.inv(series.motion[t])
    d = points.shape[-1]
    return points @ back[:d, :d].T + back[:d, d]


def _turned(series, t: int, vectors) -> np.ndarray:
    """Vectors of frame ``t`` turned as :func:`_on_image` turns its points."""
    vectors = np.asarray(vectors, dtype=float)
    if series.motion is None:
        return vectors
    d = vectors.shape[-1]
    return vectors @ np.linalg.inv(series.motion[t][:d, :d]).T


def _with_time(t, points) -> np.ndarray:
    return np.column_stack([np.full(len(points), float(t)), points])


def _placement(scale, translate) -> dict:
    return {"scale": tuple(float(v) for v in scale), "translate": tuple(float(v) for v in translate)}


def vectors_layer(series, spacing, scale, translate, name="displacement") -> tuple:
    """The displacement of each step as a Vectors layer: step k's valid vectors at time index k,
    from their start on frame k, coloured by their length (feature ``"length"``, physical units)."""
    rows, lengths, steps = [], [], []
    for k, field in enumerate(series.fields):
        valid = field.valid
        starts = to_pixels(_on_image(series, k, field.starts[valid]), spacing)
        moves = _turned(series, k, field.vectors[valid])
        rows.append(np.stack([_with_time(k, starts), _with_time(0, to_pixels(moves, spacing))], axis=1))
        lengths.append(np.linalg.norm(moves, axis=1))
        steps.append(np.full(len(starts), k))
    dim = series.dim + 1
    data = np.concatenate(rows) if rows else np.zeros((0, 2, dim))
    options = {"name": name, "features": {"length": np.concatenate(lengths), "step": np.concatenate(steps)},
               "edge_color": "length", "edge_colormap": "viridis", "vector_style": "arrow", "edge_width": 0.6,
               "length": 1.0, "opacity": 1.0, **_placement(scale, translate)}
    return data, options, "vectors"


def tracks_layer(series, spacing, scale, translate, name="trajectories") -> tuple:
    """The followed points as a Tracks layer: rows ``(track id, t, [plane,] row, column)``, a
    point's id its column of ``series.trajectories``, rows where it is not alive (NaN) left out."""
    frames, count, _ = series.trajectories.shape
    placed = np.stack([to_pixels(_on_image(series, t, series.trajectories[t]), spacing) for t in range(frames)])
    alive = np.isfinite(placed).all(axis=2).T  # (points, frames): each track's rows in time order
    ids = np.broadcast_to(np.arange(count)[:, None], alive.shape)[alive]
    times = np.broadcast_to(np.arange(frames)[None, :], alive.shape)[alive]
    data = np.column_stack([ids, times, placed.transpose(1, 0, 2)[alive]]).astype(float)
    options = {"name": name, "tail_length": frames, "tail_width": 1, "color_by": "track_id",
               "colormap": "hsv", **_placement(scale, translate)}
    return data, options, "tracks"


def boundaries_layer(series, spacing, scale, translate, name="boundaries") -> tuple:
    """2D: the boundary of each frame as a closed outline (a Shapes polygon at its time index)."""
    outlines = [_with_time(t, to_pixels(_on_image(series, t, frame), spacing)) for t, frame in enumerate(series.frames)]
    options = {"name": name, "shape_type": "polygon", "edge_color": "white", "face_color": "transparent",
               "edge_width": 0.4, "opacity": 1.0, **_placement(scale, translate)}
    return outlines, options, "shapes"


def growth_points_layer(series, spacing, scale, translate, name="growth") -> tuple:
    """2D: the growth quantity (:func:`piece_growth`) at the middle of each followed piece, per
    frame, as Points coloured by it (feature ``"growth"``)."""
    rows, values = [], []
    found = series_growth(series)
    for t in range(len(series.frames)):
        cells, value = piece_growth(series, t, found)
        points = series.trajectories[t]
        middles = 0.5 * (points[cells[:, 0]] + points[cells[:, 1]]) if len(cells) else np.zeros((0, 2))
        keep = np.isfinite(middles).all(axis=1) & np.isfinite(value)
        rows.append(_with_time(t, to_pixels(_on_image(series, t, middles[keep]), spacing)))
        values.append(value[keep])
    data = np.concatenate(rows)
    growth = np.concatenate(values)
    options = {"name": name, "features": {"growth": growth}, "face_color": "growth", "face_colormap": "plasma",
               "border_width": 0, "size": 0.8, "metadata": {"quantity": GROWTH}, **_placement(scale, translate)}
    return data, options, "points"


def growth_surface_layer(series, spacing, scale, translate, name="growth") -> tuple:
    """3D: the followed surface of every frame in one Surface layer with vertices ``(t, plane,
    row, column)``, so that the current time shows its own, each vertex coloured by the mean of
    the growth quantity (:func:`piece_growth`) of its triangles."""
    vertices, faces, values, offset = [], [], [], 0
    found = series_growth(series)
    for t in range(len(series.frames)):
        cells, value = piece_growth(series, t, found)
        points = series.trajectories[t]
        keep = np.isfinite(points[cells]).all(axis=(1, 2)) & np.isfinite(value)
        cells, value = cells[keep], value[keep]
        used, local = np.unique(cells, return_inverse=True)
        local = local.reshape(cells.shape)
        total = np.bincount(local.ravel(), weights=np.repeat(value, 3), minlength=len(used))
        counts = np.bincount(local.ravel(), minlength=len(used))
        vertices.append(_with_time(t, to_pixels(_on_image(series, t, points[used]), spacing)))
        faces.append(local + offset)
        values.append(total / np.maximum(counts, 1))
        offset += len(used)
    data = (np.concatenate(vertices), np.concatenate(faces).astype(np.int64), np.concatenate(values))
    options = {"name": name, "colormap": "plasma", "metadata": {"quantity": GROWTH}, **_placement(scale, translate)}
    return data, options, "surface"


def series_layers(series, spacing, scale, translate) -> list:
    """Every layer of a series: displacement vectors, trajectories, then the boundaries (2D:
    outlines and growth points; 3D: the growth surface)."""
    layers = [vectors_layer(series, spacing, scale, translate), tracks_layer(series, spacing, scale, translate)]
    if series.dim == 2:
        layers += [boundaries_layer(series, spacing, scale, translate),
                   growth_points_layer(series, spacing, scale, translate)]
    else:
        layers.append(growth_surface_layer(series, spacing, scale, translate))
    return layers
