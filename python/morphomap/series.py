"""Time series: every consecutive pair of frames mapped, material points followed through them."""

from __future__ import annotations

import functools
import os
import time
import warnings
from dataclasses import dataclass, field as dataclass_field

import numpy as np
import trimesh

from ._core import GeometryError
from ._progress import progress_over
from ._validate import as_length
from .carry import IndexedCurve, carry_curve, carry_surface
from .curves import normals
from .figure_style import movie_provenance
from .io.csv_files import write_field_csv
from .io.meshes import write_surface
from .io.atomic import atomic_text
from .mapping import map_curves
from .movie import Movie, describe_motion, is_movie_path, movie_frames, register_frames
from .moving_mesh import MeshStep, MovingMesh, extend_series
from .prepared import PreparedCurve, PreparedSurface, as_surface
from .quality import quality
from .reseed import reseed_curve, reseed_surface
from .growth import element_measures
from .growth_plot import write_growth
from .series_plot import animate, plot_growth, plot_trajectories, write_figures
from .simple import make_simple
from .surfaces import SurfaceIndex, map_surfaces, surface_normals


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
    mesh: MeshStep | None = None  # the moving solver mesh over the step (Series.extend)


class Series:
    """What :func:`map_series` returns.

    Attributes
    ----------
    frames : list
        The boundaries, as curves ``(N, 2)`` or ``trimesh.Trimesh``.
    fields : list of DisplacementField
        One per consecutive pair: ``fields[k]`` maps frame k onto frame k + 1.
    trajectories : (T, M, d) float
        The material points followed through the frames, each lying on every frame it is alive
        on (:mod:`morphomap.carry`: in 2D a point keeps its place along the curve between the
        neighbouring vectors of ``fields[k]``, placed by arc length on frame k and among their
        ends on frame k + 1; in 3D the vectors interpolated in the start triangles, then the
        closest point of frame k + 1): first the points of frame 0 (its curve points or surface vertices), then
        the points born later where the followed points spread apart (see ``reseed`` in
        :func:`map_series`), in the order they were born. A row is NaN before the point's birth and
        from the step where it is lost (its field has no vector there).
    born : (M,) int
        The frame each point was born in (0 for the points of frame 0).
    cells : list of T int arrays
        The pieces of boundary between the followed points on each frame, after that frame's new
        points: in 2D ``(P, 2)`` pairs of consecutive points along the curve (piece i runs from
        ``cells[t][i, 0]`` to ``cells[t][i, 1]``); in 3D ``(F, 3)`` triangles, oriented outwards.
    dt : float
        The time between two frames.
    normal_speed : (T - 1, M) float
        Growth map, per step and point: ``(p(k+1) - p(k)) . n(k) / dt``, ``n(k)`` the unit outward
        normal of the followed boundary at p(k) (2D: the normalised sum of the normals of the two
        pieces meeting there, :func:`morphomap.normals`; 3D: the angle-weighted normal of the
        triangles, :func:`morphomap.surface_normals`). NaN where the point is not alive at both
        frames.
    accumulated_normal_speed : (T - 1, M) float
        Growth map from the point's birth to frame k + 1: the sum of its normal displacements over
        those steps divided by the time elapsed.
    quality : list of StepQuality
        One row per step.
    motion : (T, d + 1, d + 1) float or None
        With ``register``: the rigid motion (homogeneous matrix) that took each frame as given onto
        the frame as mapped, the identity for frame 0 (:func:`morphomap.movie.register_frames`);
        None without.
    interior : MovingMesh or None
        After :meth:`extend` (or ``map_series(..., interior=...)``): a solver mesh of frame 0's
        domain moved through the frames; None before.
    unit : str or None
        The unit of the coordinates, for the figures' axes (``"um"``, or ``"pixel"`` for a movie
        without a spacing); None where not known (the figures then say ``"units"``).
    y_down : bool
        The frames were traced from images (x the column, y the row): the figures draw them as the
        images look, y down (:mod:`morphomap.figure_style`). Set it for frames given as curves
        traced from masks.
    time_unit : str or None
        The unit of ``dt``, for the animation's time stamps and the speeds' unit: ``"s"`` for a
        movie's frame interval; None where not known.
    """

    def __init__(self, frames, fields, trajectories, quality, *, born=None, cells=None, stretches=None,
                 accumulated=None, normal_speed=None, accumulated_normal_speed=None, dt=1.0, motion=None,
                 unit=None, y_down=False, time_unit=None):
        self.frames, self.fields, self.trajectories, self.quality = frames, fields, trajectories, quality
        self.motion = motion
        self.interior = None
        self.unit, self.y_down, self.time_unit = unit, y_down, time_unit
        self.born = np.zeros(trajectories.shape[1], dtype=np.int64) if born is None else born
        self.cells, self._stretches, self._accumulated = cells, stretches, accumulated
        self.normal_speed, self.accumulated_normal_speed, self.dt = normal_speed, accumulated_normal_speed, dt

    @property
    def dim(self) -> int:
        return self.trajectories.shape[2]

    def _step(self, step) -> int:
        steps = len(self.fields)
        if isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, np.integer)):
            raise TypeError(f"step: expected an integer, got {type(step).__name__}")
        if not -steps <= step < steps:
            raise ValueError(f"step: expected 0..{steps - 1} (or negative from the end), got {step}")
        return int(step) % steps

    def stretch(self, step: int) -> np.ndarray:
        """Growth map of step ``step``: the local stretch of each piece of ``cells[step]`` carried
        to frame ``step + 1``, in 2D the length ratio L_i / l_i of the piece, in 3D the area ratio
        of the triangle. NaN where a corner is lost."""
        return self._stretches[self._step(step)].copy()

    def accumulated_stretch(self, step: int) -> np.ndarray:
        """Growth map from frame 0 to frame ``step + 1``, on the pieces of ``cells[step]``: the
        product of the stretches of the piece and of the pieces it was cut from (a piece that new
        points split passes its accumulated stretch on to its parts). NaN where a point was lost."""
        return self._accumulated[self._step(step)].copy()

    def extend(self, mesh=None, *, method="harmonic", mesh_size=None, progress=None) -> MovingMesh:
        """Carry one solver mesh of frame 0's domain through the frames (:func:`morphomap.extend_series`
        on :attr:`fields`): each step's field extended inside on the mesh as moved so far, with no
        inverted cell unasked. Sets :attr:`interior` and the mesh quality of every row of
        :attr:`quality` (``mesh``), and returns the :class:`MovingMesh`.

        Parameters
        ----------
        mesh : (points, cells), optional
            The solver's mesh of frame 0's domain, in the frames' units; by default made by CGAL.
        method, mesh_size : as :func:`morphomap.extend_field`.
        progress : bool, optional
            A progress bar counting the steps (the rule of :func:`map_series`).
        """
        moving = extend_series(self.fields, mesh, frames=self.frames, method=method, mesh_size=mesh_size,
                               dt=self.dt, progress=progress)
        self.interior = moving
        for row, step in zip(self.quality, moving.quality):
            row.mesh = step
        return moving

    def plot_trajectories(self, ax=None, **options):
        """The followed points' paths coloured by time: :func:`morphomap.series_plot.plot_trajectories`."""
        return plot_trajectories(self, ax, **options)

    def plot_growth(self, quantity="accumulated_stretch", step=-1, ax=None, **options):
        """A growth map as colour on the boundary: :func:`morphomap.series_plot.plot_growth`."""
        return plot_growth(self, quantity, step, ax, **options)

    def animate(self, path, *, fps=2, dpi=90, **options) -> None:
        """Write an animation (``.gif``; ``.mp4`` when ffmpeg is installed) of the frames and the
        followed points: :func:`morphomap.series_plot.animate`."""
        animate(self, path, fps=fps, dpi=dpi, **options)

    def write(self, folder, *, figures=True) -> list:
        """Write into ``folder`` (created) and return the paths:

        - ``field_KK.csv`` per step (3D: with ``field_KK.faces.csv``), and in 3D ``frame_TT.ply``
          per frame (the surfaces, as mapped);
        - ``trajectories.csv`` (frame, point, coordinates; NaN before a point's birth and once lost)
          and ``points.csv`` (point, the frame it was born in);
        - ``quality.csv``, one row per step;
        - ``stretch.csv`` (step, piece, its corner points, stretch, accumulated stretch) and
          ``normal_speed.csv`` (step, point, normal speed, accumulated normal speed) with the
          growth maps;
        - the growth kinematics (:func:`morphomap.growth_plot.write_growth`): ``growth.csv``, in 3D
          ``growth_KK.vtu`` per step, and with ``figures`` ``kymograph.png`` (2D) or ``growth.png`` (3D);
        - with ``register``: ``motion.csv`` (frame, the matrix of :attr:`motion` row by row, and
          the translation and rotation in words);
        - with :attr:`interior`: ``interior.xdmf`` (+ ``interior.h5``; dolfinx reads the mesh with
          ``read_mesh()`` and step k at ``time=k * dt``) and ``interior.pvd`` (+ one ``.vtu`` per
          step, for ParaView), and the mesh quality per step in ``quality.csv`` (inverted cells,
          smallest area/volume ratio, smallest angle in degrees, boundary distance, substeps,
          untangled);
        - with ``figures``: ``trajectories.png``, ``stretch.png`` and ``normal_speed.png`` (the
          accumulated maps at the last frame), ``series.gif``, and ``series.mp4`` when ffmpeg is
          installed.

        Writes are atomic.
        """
        os.makedirs(folder, exist_ok=True)
        paths = []
        for k, field in enumerate(self.fields):
            path = os.path.join(folder, f"field_{k:02d}.csv")
            paths.extend(write_field_csv(path, field))
        if self.dim == 3:  # the frames as surfaces, for ParaView and MeshLab beside the fields
            for t, frame in enumerate(self.frames):
                path = os.path.join(folder, f"frame_{t:02d}.ply")
                write_surface(path, frame)
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
        mesh = ",inverted,min_jacobian,min_angle,boundary_distance,substeps,untangled" if self.interior else ""
        with atomic_text(path) as handle:
            handle.write(f"step,qm1,qm2,qm,{defects},misses,seconds,methods{mesh}\n")
            for q in self.quality:
                methods = " ".join(f"{k}:{v}" for k, v in q.methods.items())
                handle.write(f"{q.step},{q.qm1!r},{q.qm2!r},{q.qm!r},{q.defects},{q.misses},{q.seconds:.3f},{methods}")
                if mesh:
                    m = q.mesh
                    handle.write(f",{m.inverted},{m.min_jacobian!r},{m.min_angle!r},{m.boundary_distance!r},"
                                 f"{m.substeps},{str(m.untangled).lower()}")
                handle.write("\n")
        paths.append(path)
        if self.interior is not None:
            for name in ("interior.xdmf", "interior.pvd"):
                self.interior.write(os.path.join(folder, name))
            # With the files beside them: interior.h5, and one interior_KKKK.vtu per step.
            paths.extend(sorted(os.path.join(folder, name) for name in os.listdir(folder)
                                if name.startswith("interior.") or name.startswith("interior_")))
        path = os.path.join(folder, "points.csv")
        with atomic_text(path) as handle:
            handle.write("point,born\n")
            handle.writelines(f"{i},{b}\n" for i, b in enumerate(self.born.tolist()))
        paths.append(path)
        path = os.path.join(folder, "stretch.csv")
        corners = "a,b" if self.dim == 2 else "a,b,c"
        with atomic_text(path) as handle:
            handle.write(f"step,piece,{corners},stretch,accumulated_stretch\n")
            for k in range(len(self.fields)):
                for i, (cell, r, g) in enumerate(zip(self.cells[k].tolist(), self._stretches[k].tolist(),
                                                     self._accumulated[k].tolist())):
                    handle.write(f"{k},{i}," + ",".join(map(str, cell)) + f",{r!r},{g!r}\n")
        paths.append(path)
        path = os.path.join(folder, "normal_speed.csv")
        with atomic_text(path) as handle:
            handle.write("step,point,normal_speed,accumulated_normal_speed\n")
            for k in range(len(self.fields)):
                rows = np.flatnonzero(np.isfinite(self.normal_speed[k]) | np.isfinite(self.accumulated_normal_speed[k]))
                for i, v, m in zip(rows.tolist(), self.normal_speed[k, rows].tolist(),
                                   self.accumulated_normal_speed[k, rows].tolist()):
                    handle.write(f"{k},{i},{v!r},{m!r}\n")
        paths.append(path)
        if self.motion is not None:
            path = os.path.join(folder, "motion.csv")
            dim = self.dim
            entries = ",".join(f"m{i}{j}" for i in range(dim + 1) for j in range(dim + 1))
            with atomic_text(path) as handle:
                handle.write(f"frame,{entries},description\n")
                for k, (matrix, line) in enumerate(zip(self.motion, describe_motion(self.motion))):
                    values = ",".join(repr(float(v)) for v in matrix.ravel())
                    handle.write(f"{k},{values},\"{line}\"\n")
            paths.append(path)
        paths.extend(write_growth(self, folder, figures=figures))
        if figures:
            paths.extend(write_figures(self, folder))
        return paths

    def __repr__(self) -> str:
        lost = int(np.isnan(self.trajectories[-1]).any(axis=1).sum())
        new = int((self.born > 0).sum())
        return (f"Series({len(self.frames)} frames in {self.dim}D, {len(self.fields)} fields, "
                f"{self.trajectories.shape[1]} points followed ({new} born after frame 0), {lost} lost)")


def map_series(frames, method="auto", *, dt=None, reseed=2.0, register=None, label=None, objects=None,
               interior=None, progress=None, **options) -> Series:
    """Map every consecutive pair of a time series and follow the points of the first frame.

    Parameters
    ----------
    frames : a movie file, a :class:`morphomap.movie.Movie`, or a sequence of at least 2 curves
        ``(N, 2)`` or surfaces (``trimesh.Trimesh`` or ``(vertices, faces)``), all of one kind.
        A file (an ImageJ hyperstack or OME-TIFF of masks or labels with a T axis, 2D or 3D) is
        read by :func:`morphomap.movie.movie_frames` with ``label`` and ``objects``: one boundary
        per time point in the file's spacing (µm), its frame interval as ``dt``. Curves as labs
        trace them (repeated points, one-pixel spurs and necks, a first point across the closing
        segment) are made simple once each, up front, by :func:`morphomap.make_simple`, with a
        ``UserWarning`` naming the frame and what changed; :attr:`Series.frames` holds the
        repaired curves. A curve it cannot repair is passed on as given (its pair's error names
        it).
    method : the mapping algorithm for every pair (``"auto"`` by default).
    dt : float, optional
        The time between two frames (for the normal speeds); default: a movie's frame interval
        (seconds), else 1.
    reseed : float or None
        Keep the boundary sampled: on every frame after the first, where two neighbouring followed
        points are more than ``reseed`` times the spacing of frame 0 apart (the median distance
        between neighbouring points: consecutive curve points, or surface edges), new material
        points are born on that frame's boundary between them, spaced at most the spacing of
        frame 0 apart. 2D: the distance is the arc length along the frame between the two points'
        closest points (the shorter way round), and the new points are equally spaced along that
        arc. 3D: every triangle edge longer than the limit is split at its middle, moved onto the
        frame's surface (the two triangles sharing it become four), until no edge is longer. New
        points are followed from then on (their rows of ``trajectories`` are NaN before; ``born`` gives their frame).
        ``None`` follows only the points of frame 0. Default 2.
    register : {"translation", "rigid"}, optional
        Remove the sample's drift first: each frame moved (and with ``"rigid"`` turned) onto the
        previous one (:func:`morphomap.movie.register_frames`); :attr:`Series.frames` are the
        frames as moved and :attr:`Series.motion` says by how much.
    label, objects : optional
        Only with a movie file: which object each frame gives (:func:`morphomap.movie.movie_frames`).
    interior : True or (points, cells), optional
        Also carry a solver mesh of frame 0's domain through the frames (:meth:`Series.extend`):
        ``True`` for one made by CGAL, or the solver's own mesh. Then :attr:`Series.interior`
        holds it and each row of :attr:`Series.quality` its mesh quality over the step.
    progress : bool, optional
        One progress bar (tqdm) on stderr counting the pairs; by default shown when stderr is a
        terminal and the call runs longer than 3 seconds, ``True``: at once, ``False``: never. The
        pairs' own bars (:func:`map_surfaces`' ``progress``) stay off, so that two bars never
        fight over the line.
    **options : passed to :func:`map_curves` (2D) or :func:`map_surfaces` (3D).

    Returns
    -------
    Series
        With the fields, trajectories, growth maps (``stretch``, ``accumulated_stretch``,
        ``normal_speed``, ``accumulated_normal_speed``) and the quality per step.
        ``fields[k]`` is ``map_curves(frames[k], frames[k + 1], method, **options)`` (or
        ``map_surfaces``), the field of the frame's own points; the followed points are carried
        by it onto frame k + 1 (see :attr:`Series.trajectories`).

    Raises
    ------
    ValueError, GeometryError
        A frame or pair that cannot be mapped, named: ``"frames[k] -> frames[k + 1]: ..."``
    """
    source = {}  # where the frames came from, for the figures: unit, orientation, time unit
    if is_movie_path(frames) or isinstance(frames, Movie):
        movie = frames if isinstance(frames, Movie) else movie_frames(frames, label=label, objects=objects)
        frames = movie.frames
        source = movie_provenance(movie, dt)
        dt = movie.dt if dt is None else dt
    elif label is not None or objects is not None:
        raise ValueError("label/objects: only for a movie file (frames given as a path); pick the object "
                         "before passing the frames")
    frames = list(frames)
    if len(frames) < 2:
        raise ValueError(f"frames: expected at least 2, got {len(frames)}")
    curves = [isinstance(f, np.ndarray) and f.ndim == 2 and f.shape[1] == 2 for f in frames]
    if any(curves) and not all(curves):
        raise ValueError("frames: mix curves and surfaces; expected all of one kind")
    dt = as_length(dt, "dt", 1.0)
    if interior is False:
        interior = None
    if not (interior is None or interior is True or (isinstance(interior, (tuple, list)) and len(interior) == 2)):
        raise TypeError(f"interior: expected True (a mesh made by CGAL) or the solver's (points, cells) mesh of "
                        f"frame 0, got {type(interior).__name__}")
    if reseed is not None:
        reseed = as_length(reseed, "reseed", 2.0)
        if reseed <= 1:
            raise ValueError(f"reseed: the factor must be > 1 (or None to switch re-seeding off), got {reseed}")
    if not curves[0]:
        frames = [trimesh.Trimesh(*as_surface(f, f"frames[{k}]"), process=False) for k, f in enumerate(frames)]
    closed = bool(options.get("closed", True)) if curves[0] else True
    if curves[0]:
        frames = _simple_frames(frames, closed)
    motion = None
    if register is not None:
        frames, motion = register_frames(frames, register)
    boundary = _CurveBoundary(frames, closed) if curves[0] else _SurfaceBoundary(frames)
    positions = [boundary.first.copy()]  # per frame: every point born so far
    born = np.zeros(len(boundary.first), dtype=np.int64)
    cells, growth = [boundary.cells], [np.ones(len(boundary.cells))]
    stretches, accumulated, speeds, mean_speeds = [], [], [], []
    normal_distance = np.zeros(len(born))  # summed since each point's birth
    fields, table = [], []
    # Frames are checked and indexed once each (frame k is the target of one pair and the source
    # of the next): PreparedCurve or PreparedSurface, two at a time, named as the pair's mapping
    # names its curves or surfaces, so that a bad frame is reported as before, with its pair.
    prepare = functools.partial(PreparedCurve, closed=closed) if curves[0] else PreparedSurface
    roles = ("c1", "c2") if curves[0] else ("s1", "s2")
    prepared = None
    carried = None  # frame k, indexed for carrying the followed points off it
    for k in progress_over(range(len(frames) - 1), len(frames) - 1, progress, "map_series", "pair"):
        start = time.perf_counter()
        try:
            a = prepared if prepared is not None else prepare(frames[k], roles[0])
            b = prepared = prepare(frames[k + 1], roles[1])
            field = (map_curves(a, b, method, **options) if curves[0]
                     else map_surfaces(a, b, method, progress=False, **options))
        except (ValueError, GeometryError) as error:
            raise type(error)(f"frames[{k}] -> frames[{k + 1}]: {error}") from None
        q = quality(field, a, b, **({"closed": closed} if curves[0] else {}))
        seconds = time.perf_counter() - start
        names, counts = np.unique(field.method, return_counts=True)
        table.append(StepQuality(k, q.qm1, q.qm2, q.qm, q.crossings if curves[0] else q.folds,
                                 int((~field.valid).sum()), seconds, dict(zip(names.tolist(), counts.tolist()))))
        fields.append(field)
        now = positions[k]
        alive = np.isfinite(now).all(axis=1)
        moved = np.full_like(now, np.nan)
        if curves[0]:
            carried = carried if carried is not None else IndexedCurve(frames[k], closed)
            target = IndexedCurve(frames[k + 1], closed)
            moved[alive] = carry_curve(field, now[alive], carried, target)
            carried = target
        elif alive.any():
            target = SurfaceIndex(frames[k + 1].vertices, frames[k + 1].faces)
            moved[alive] = carry_surface(field, now[alive], target)[0]
        # Growth over the step, on the pieces and points of frame k.
        ratio = boundary.measure(cells[k], moved) / boundary.measure(cells[k], now)
        stretches.append(ratio)
        accumulated.append(growth[k] * ratio)
        normal_step = np.einsum("ij,ij->i", moved - now, boundary.normals(cells[k], now))
        normal_distance = normal_distance + normal_step
        speeds.append(normal_step / dt)
        mean_speeds.append(normal_distance / ((k + 1 - born) * dt))
        # Frame k + 1: the pieces without the points lost, then new points where they spread apart.
        piece, piece_growth = boundary.without_lost(cells[k], accumulated[-1], np.isfinite(moved).all(axis=1))
        if reseed is not None:
            new, piece, piece_growth = boundary.reseed(moved, piece, piece_growth, k + 1, reseed)
            moved = np.vstack([moved, new])
            born = np.concatenate([born, np.full(len(new), k + 1)])
            normal_distance = np.concatenate([normal_distance, np.zeros(len(new))])
        positions.append(moved)
        cells.append(boundary.as_cells(piece))
        growth.append(piece_growth)
    trajectories = np.full((len(frames), len(born), boundary.dim), np.nan)
    for t, p in enumerate(positions):
        trajectories[t, : len(p)] = p
    speed_table = np.full((len(fields), len(born)), np.nan)
    mean_table = np.full((len(fields), len(born)), np.nan)
    for k, (v, m) in enumerate(zip(speeds, mean_speeds)):
        speed_table[k, : len(v)], mean_table[k, : len(m)] = v, m
    series = Series(frames, fields, trajectories, table, born=born, cells=cells, stretches=stretches,
                    accumulated=accumulated, normal_speed=speed_table, accumulated_normal_speed=mean_table, dt=dt,
                    motion=motion, **source)
    if interior is not None:
        series.extend(None if interior is True else interior, progress=progress)
    return series


def _simple_frames(frames, closed: bool) -> list:
    """The curves made simple once each (:func:`morphomap.make_simple`), warning per frame repaired.
    A curve it refuses (one that crosses itself, non-finite points) is kept as given: its pair's
    mapping reports it, named with the pair."""
    simple = []
    for k, frame in enumerate(frames):
        try:
            points, changes = make_simple(frame, closed=closed)
        except (ValueError, TypeError):
            simple.append(frame)
            continue
        if changes:
            warnings.warn(f"frames[{k}]: {changes}", UserWarning, stacklevel=3)
        simple.append(points)
    return simple


class _CurveBoundary:
    """The followed points of a curve series: a chain of points in order along the curve."""

    dim = 2

    def __init__(self, frames, closed):
        self.frames, self.closed = frames, closed
        self.first = np.asarray(frames[0], dtype=float)
        self.cells = self.as_cells(np.arange(len(self.first)))
        self.spacing = float(np.median(self.measure(self.cells, self.first)))

    def as_cells(self, chain):
        after = np.roll(chain, -1) if self.closed else chain[1:]
        return np.column_stack([chain[: len(after)], after])

    def measure(self, cells, points):
        return element_measures(points, cells)

    def chain(self, cells):
        """The points in order along the followed curve (none when no piece is left)."""
        if self.closed or len(cells) == 0:
            return cells[:, 0]
        return np.append(cells[:, 0], cells[-1, 1])

    def normals(self, cells, points):
        chain = self.chain(cells)
        result = np.full_like(points, np.nan)
        if len(chain) >= (3 if self.closed else 2):
            result[chain] = normals(points[chain], closed=self.closed)
        return result

    def without_lost(self, cells, growth, alive):
        """The chain of the points still alive; a piece that spanned a lost point has an unknown
        accumulated stretch (NaN)."""
        chain = self.chain(cells)
        keep = alive[chain]
        if keep.all():
            return chain, growth
        positions = np.flatnonzero(keep)
        following = np.roll(positions, -1) if self.closed else positions[1:]
        intact = (following - positions[: len(following)]) % len(chain) == 1
        return chain[keep], np.where(intact, growth[positions[: len(following)]], np.nan)

    def reseed(self, points, chain, growth, frame, factor):
        return reseed_curve(points, chain, growth, np.asarray(self.frames[frame], dtype=float), self.spacing,
                            factor * self.spacing, self.closed)


class _SurfaceBoundary:
    """The followed points of a surface series: triangles over the points, split where they grow."""

    dim = 3

    def __init__(self, frames):
        self.frames = frames
        self.first = np.asarray(frames[0].vertices, dtype=float)
        self.cells = np.asarray(frames[0].faces, dtype=np.int64)
        corners = self.first[self.cells]
        self.spacing = float(np.median(np.linalg.norm(corners[:, [1, 2, 0]] - corners, axis=2)))

    def as_cells(self, faces):
        return faces

    def measure(self, cells, points):
        return element_measures(points, cells)

    def normals(self, cells, points):
        return surface_normals(np.nan_to_num(points), cells)

    def without_lost(self, cells, growth, alive):
        """The triangles whose three corners are alive (where a point is lost the followed surface
        has a hole)."""
        keep = alive[cells].all(axis=1)
        return cells[keep], growth[keep]

    def reseed(self, points, faces, growth, frame, factor):
        surface = self.frames[frame]
        return reseed_surface(points, faces, growth, (np.asarray(surface.vertices), np.asarray(surface.faces)),
                              factor * self.spacing)
