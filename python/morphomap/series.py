"""Time series: every consecutive pair of frames mapped, material points followed through them."""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field as dataclass_field

import numpy as np

from .field import DisplacementField


@dataclass
class StepQuality:
    """The quality of one step's field (QM1, QM2, QM; crossings in 2D, folds in 3D)."""

    step: int
    qm1: float
    qm2: float
    qm: float
    defects: int
    misses: int
    seconds: float
    methods: dict = dataclass_field(default_factory=dict)


class Series:
    """What :func:`map_series` returns.

    Attributes
    ----------
    frames : list
        The boundaries, as curves ``(N, 2)`` or ``trimesh.Trimesh``.
    fields : list of DisplacementField
        One per consecutive pair: ``fields[k]`` maps frame k onto frame k + 1.
    trajectories : (T, M, d) float
        The points of frame 0 (its curve points or surface vertices) carried through every field
        (``field.at``), NaN from the step where one is lost (its field has no vector there).
    quality : list of StepQuality
        One row per step.
    """

    def __init__(self, frames, fields, trajectories, quality):
        self.frames, self.fields, self.trajectories, self.quality = frames, fields, trajectories, quality

    @property
    def dim(self) -> int:
        return self.trajectories.shape[2]

    def stretch(self, step: int) -> np.ndarray:
        """The local stretch of step ``step`` along the followed points: in 2D the length ratio of
        each piece between consecutive trajectories (closed curve), L_i / l_i; in 3D the area
        ratio of each triangle of frame 0's surface."""
        before, after = self.trajectories[step], self.trajectories[step + 1]
        if self.dim == 2:
            def lengths(p):
                return np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)

            return lengths(after) / lengths(before)
        faces = np.asarray(self.frames[0].faces)

        def areas(p):
            corners = p[faces]
            return 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)

        return areas(after) / areas(before)

    def write(self, folder) -> list:
        """Write ``field_KK.csv`` per step, ``trajectories.csv`` (step, point, coordinates) and
        ``quality.csv`` into ``folder`` (created); returns the paths. Writes are atomic."""
        from ._atomic import atomic_text
        from .io import write_field

        os.makedirs(folder, exist_ok=True)
        paths = []
        for k, field in enumerate(self.fields):
            path = os.path.join(folder, f"field_{k:02d}.csv")
            write_field(path, field)
            paths.append(path)
        axes = "xyz"[: self.dim]
        path = os.path.join(folder, "trajectories.csv")
        with atomic_text(path) as handle:
            handle.write("frame,point," + ",".join(axes) + "\n")
            for t, points in enumerate(self.trajectories):
                for i, p in enumerate(points.tolist()):
                    handle.write(f"{t},{i}," + ",".join(repr(float(v)) for v in p) + "\n")
        paths.append(path)
        path = os.path.join(folder, "quality.csv")
        defects = "crossings" if self.dim == 2 else "folds"
        with atomic_text(path) as handle:
            handle.write(f"step,qm1,qm2,qm,{defects},misses,seconds,methods\n")
            for q in self.quality:
                methods = " ".join(f"{k}:{v}" for k, v in q.methods.items())
                handle.write(f"{q.step},{q.qm1!r},{q.qm2!r},{q.qm!r},{q.defects},{q.misses},{q.seconds:.3f},{methods}\n")
        paths.append(path)
        return paths

    def __repr__(self) -> str:
        lost = int(np.isnan(self.trajectories[-1]).any(axis=1).sum())
        return (f"Series({len(self.frames)} frames in {self.dim}D, {len(self.fields)} fields, "
                f"{self.trajectories.shape[1]} points followed, {lost} lost)")


def _progress(iterable, total, enabled, description):
    if enabled is False or (enabled is None and not sys.stderr.isatty()):
        return iterable
    try:
        from tqdm import tqdm
    except ImportError:  # progress is a courtesy, never a requirement
        return iterable
    return tqdm(iterable, total=total, desc=description, unit="pair")


def map_series(frames, method="auto", *, progress=None, **options) -> Series:
    """Map every consecutive pair of a time series and follow the points of the first frame.

    Parameters
    ----------
    frames : sequence of at least 2 curves ``(N, 2)`` or surfaces (``trimesh.Trimesh`` or
        ``(vertices, faces)``), all of one kind.
    method : the mapping algorithm for every pair (``"auto"`` by default).
    progress : bool, optional
        A progress bar (tqdm) on stderr; by default when stderr is a terminal.
    **options : passed to :func:`map_curves` (2D) or :func:`map_surfaces` (3D).

    Returns
    -------
    Series
    """
    from .mapping import map_curves
    from .quality import quality
    from .surfaces import as_surface, map_surfaces

    frames = list(frames)
    if len(frames) < 2:
        raise ValueError(f"frames: expected at least 2, got {len(frames)}")
    curves = [isinstance(f, np.ndarray) and f.ndim == 2 and f.shape[1] == 2 for f in frames]
    if any(curves) and not all(curves):
        raise ValueError("frames: mix curves and surfaces; expected all of one kind")
    if not curves[0]:
        import trimesh

        frames = [trimesh.Trimesh(*as_surface(f, f"frames[{k}]"), process=False) for k, f in enumerate(frames)]
    first = frames[0] if curves[0] else np.asarray(frames[0].vertices)
    trajectories = np.full((len(frames), len(first), first.shape[1]), np.nan)
    trajectories[0] = first
    fields, table = [], []
    for k in _progress(range(len(frames) - 1), len(frames) - 1, progress, "map_series"):
        a, b = frames[k], frames[k + 1]
        start = time.perf_counter()
        try:
            field = map_curves(a, b, method, **options) if curves[0] else map_surfaces(a, b, method, **options)
        except ValueError as error:
            raise ValueError(f"frames[{k}] -> frames[{k + 1}]: {error}") from None
        q = quality(field, a, b)
        seconds = time.perf_counter() - start
        names, counts = np.unique(field.method, return_counts=True)
        table.append(StepQuality(k, q.qm1, q.qm2, q.qm, q.crossings if curves[0] else q.folds,
                                 int((~field.valid).sum()), seconds, dict(zip(names.tolist(), counts.tolist()))))
        fields.append(field)
        alive = np.isfinite(trajectories[k]).all(axis=1)
        if alive.any():
            trajectories[k + 1, alive] = trajectories[k, alive] + field.at(trajectories[k, alive])
    return Series(frames, fields, trajectories, table)
