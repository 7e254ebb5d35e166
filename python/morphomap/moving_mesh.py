"""One solver mesh carried through a series: each step's boundary field extended inside and the
mesh moved by it, so that a PDE on the growing domain runs on the same nodes and cells throughout."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._core import GeometryError
from ._progress import progress_over
from ._validate import as_length, as_points
from .extend import BOUNDARY_TOLERANCE, InteriorField, extend_field, measure_ratios
from .field import DisplacementField
from .io.formats import write_interior_series
from .prepared import as_surface
from .queries import CurveIndex
from .surfaces import SurfaceIndex


@dataclass(frozen=True)
class MeshStep:
    """The mesh's quality over one step of a :class:`MovingMesh`.

    ``inverted`` and ``min_jacobian`` are :class:`InteriorField`'s (cells the step's motion turns
    over, the smallest area or volume ratio); ``min_angle`` is the smallest angle in degrees of
    the mesh as moved to frame ``step + 1`` (triangle corners in 2D, dihedral angles of the
    tetrahedra in 3D): the one that governs a solver's conditioning as the domain grows;
    ``boundary_distance`` how far the mesh's boundary nodes lay from frame ``step``;
    ``substeps`` and ``untangled`` how the step was solved (:func:`morphomap.extend_field`).
    """

    step: int
    inverted: int
    min_jacobian: float
    min_angle: float
    boundary_distance: float
    substeps: int
    untangled: bool


def min_angles(points, cells) -> np.ndarray:
    """The smallest angle of each cell in degrees, ``(C,)``: of its three corners for triangles
    ``(C, 3)``, of its six dihedral angles for tetrahedra ``(C, 4)``. 0 for a flat cell."""
    points, cells = np.asarray(points, dtype=float), np.asarray(cells)
    corners = points[cells]
    if cells.shape[1] == 3:
        angles = []
        for i in range(3):
            u = corners[:, (i + 1) % 3] - corners[:, i]
            v = corners[:, (i + 2) % 3] - corners[:, i]
            angles.append(_angle(u, v))
        return np.degrees(np.min(angles, axis=0))
    # Dihedral angle along the edge shared by the faces opposite corners i and j: pi minus the
    # angle between those faces' outward normals.
    normals = []
    for i in range(4):
        a, b, c = (corners[:, j] for j in range(4) if j != i)
        n = np.cross(b - a, c - a)
        flip = np.einsum("ij,ij->i", n, corners[:, i] - a) > 0  # pointing at the opposite corner
        normals.append(np.where(flip[:, None], -n, n))
    dihedral = [np.pi - _angle(normals[i], normals[j]) for i in range(4) for j in range(i + 1, 4)]
    return np.degrees(np.min(dihedral, axis=0))


def _angle(u, v):
    lengths = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
    cosine = np.einsum("ij,ij->i", u, v) / np.where(lengths > 0, lengths, 1.0)
    return np.where(lengths > 0, np.arccos(np.clip(cosine, -1.0, 1.0)), 0.0)


class MovingMesh:
    """A mesh of frame 0's domain moved through a series, one step per field.

    Attributes
    ----------
    steps : list of InteriorField
        Step k: the nodes at frame k (``points``) and the displacement that moves them to frame
        k + 1, the extension of the series' field k.
    cells : (C, d + 1) int64
        Triangles (2D) or tetrahedra (3D), the same for every frame.
    quality : list of MeshStep
        One row per step.
    dt : float
        The time between two frames.
    """

    def __init__(self, steps, dt=1.0):
        self.steps = list(steps)
        self.cells = self.steps[0].cells
        self.dt = float(dt)
        self.quality = [MeshStep(k, s.inverted, s.min_jacobian,
                                 float(min_angles(s.points + s.displacement, s.cells).min()),
                                 s.boundary_distance, s.substeps, s.untangled)
                        for k, s in enumerate(self.steps)]

    @property
    def dim(self) -> int:
        return self.cells.shape[1] - 1

    def points(self, frame: int) -> np.ndarray:
        """The node positions at frame ``frame`` (0 .. number of steps), ``(P, d)``."""
        count = len(self.steps)
        if isinstance(frame, (bool, np.bool_)) or not isinstance(frame, (int, np.integer)):
            raise TypeError(f"frame: expected an integer, got {type(frame).__name__}")
        if not -count - 1 <= frame <= count:
            raise ValueError(f"frame: expected 0..{count} (or negative from the end), got {frame}")
        frame = int(frame) % (count + 1)
        if frame < count:
            return self.steps[frame].points.copy()
        return self.steps[-1].points + self.steps[-1].displacement

    def write(self, path) -> None:
        """Write the motion as ``.xdmf`` (one moving mesh: dolfinx reads the mesh with its default
        ``read_mesh()`` and step k with :func:`morphomap.io.fenicsx.read_function` at
        ``time=k * dt``) or ``.pvd`` (ParaView, one ``.vtu`` per step beside it); atomic."""
        write_interior_series(path, self.steps, [k * self.dt for k in range(len(self.steps))])

    def __repr__(self) -> str:
        kind = "triangles" if self.dim == 2 else "tetrahedra"
        inverted = sum(q.inverted for q in self.quality)
        return (f"MovingMesh({len(self.steps)} steps, {len(self.cells)} {kind}, {inverted} inverted, "
                f"smallest angle {min(q.min_angle for q in self.quality):.3g} degrees)")


def boundary_nodes(cells) -> np.ndarray:
    """The nodes on the boundary of a triangle or tetrahedron mesh (on a side of one cell only)."""
    cells = np.asarray(cells)
    corners = cells.shape[1]
    sides = np.sort(np.concatenate([np.delete(cells, i, axis=1) for i in range(corners)]), axis=1)
    unique, counts = np.unique(sides, axis=0, return_counts=True)
    return np.unique(unique[counts == 1])


def _onto(step: InteriorField, frame, nodes) -> InteriorField:
    """The step with its boundary nodes' ends moved to their closest points on ``frame`` (the
    next frame: a curve, or a (vertices, faces) surface), but for the nodes of cells that move
    would turn over (a thin cell along the boundary), which keep the field's end.

    The boundary field is linear between its vectors, so a boundary node's end lies on a chord of
    the next frame, off it by up to the chord's sagitta; the next step projects the node back onto
    that frame but moves it by the field there, so the offset would be carried along and each
    step's added to it (a bud growing out of a sphere: 2% of its size after 5 steps;
    bench/README.md "Interior motion through a series")."""
    ends = step.points[nodes] + step.displacement[nodes]
    if step.dim == 2:
        found = CurveIndex(frame).closest_points(ends).points
    else:
        found = SurfaceIndex(*frame).closest_points(ends).points
    before = measure_ratios(step.points, step.cells, step.displacement) > 0
    moves = np.ones(len(nodes), dtype=bool)
    position = np.full(len(step.points), -1)
    position[nodes] = np.arange(len(nodes))
    while True:
        displacement = np.array(step.displacement)
        displacement[nodes[moves]] = found[moves] - step.points[nodes[moves]]
        ratios = measure_ratios(step.points, step.cells, displacement)
        turned = step.cells[before & ~(ratios > 0)]
        if len(turned) == 0:
            break
        # Each round keeps at least one more node at its end, so this ends.
        moves[position[turned[position[turned] >= 0]]] = False
    return InteriorField(step.points, step.cells, displacement, int((ratios <= 0).sum()), float(ratios.min()),
                         step.boundary_distance, step.substeps, step.untangled, step.attempts)


def extend_series(fields, mesh=None, *, frames=None, method="harmonic", mesh_size=None, dt=1.0,
                  progress=None) -> MovingMesh:
    """Carry one mesh through consecutive fields: extend field k on the mesh as the steps before
    moved it (:func:`morphomap.extend_field`, which leaves no cell inverted unasked), then move it,
    its boundary nodes onto the next frame.

    Parameters
    ----------
    fields : sequence of DisplacementField
        ``fields[k]`` maps frame k onto frame k + 1 (:attr:`morphomap.Series.fields`).
    mesh : (points, cells), optional
        The solver's mesh of frame 0's domain (in the frames' units); by default one made by
        :func:`morphomap.extend_field` with ``mesh_size``.
    frames : sequence, optional
        The boundaries the fields map between (``fields[k]``: ``frames[k]`` onto
        ``frames[k + 1]``), curves ``(N, 2)`` or surfaces (``trimesh.Trimesh`` or
        ``(vertices, faces)``). The mesh's boundary nodes end each step at their closest points
        on frame k + 1 (unless that would invert a cell), so the mesh's boundary stays on the
        organ rather than on the field's chords, which would add up step after step. By default
        the next field's source boundary (the last step then keeps its ends as the field puts them).
    method, mesh_size :
        As :func:`morphomap.extend_field` (``mesh_size`` only without a ``mesh``).
    dt : float
        The time between two frames (the times written with :meth:`MovingMesh.write`).
    progress : bool, optional
        A progress bar (tqdm) counting the steps: by default on a terminal for calls longer than
        3 seconds.

    Returns
    -------
    MovingMesh

    Raises
    ------
    GeometryError, ValueError
        A step that cannot be extended without inverted cells, or a mesh far from frame 0, named
        ``"fields[k]: ..."``.
    """
    fields = list(fields)
    if not fields or not all(isinstance(f, DisplacementField) for f in fields):
        raise TypeError("fields: expected a non-empty sequence of DisplacementField")
    if len({f.dim for f in fields}) != 1:
        raise ValueError("fields: mix 2D and 3D fields; expected the fields of one series")
    dt = as_length(dt, "dt", 1.0)
    if frames is not None:
        frames = list(frames)
        if len(frames) != len(fields) + 1:
            raise ValueError(f"frames: expected {len(fields) + 1} (one more than the fields), got {len(frames)}")
        # Where each step's ends go: frame k + 1, checked before any work.
        targets = [as_points(f, f"frames[{k}]", 2) if fields[0].dim == 2 else as_surface(f, f"frames[{k}]")
                   for k, f in enumerate(frames)][1:]
    else:
        targets = [_field_frame(f) for f in fields[1:]] + [None]
    steps = []
    for k in progress_over(range(len(fields)), len(fields), progress, "extend_series", "step"):
        try:
            # The units check is for the caller's mesh; later steps move the mesh made here.
            step = extend_field(fields[k], method=method, mesh=mesh, mesh_size=None if mesh is not None else mesh_size,
                                boundary_tolerance=BOUNDARY_TOLERANCE if k == 0 else np.inf)
        except (ValueError, GeometryError) as error:
            raise type(error)(f"fields[{k}]: {error}") from None
        if targets[k] is not None:
            step = _onto(step, targets[k], boundary_nodes(step.cells))
        steps.append(step)
        mesh = (step.points + step.displacement, step.cells)
    return MovingMesh(steps, dt)


def _field_frame(field):
    """The boundary a field was made from: its source curve, or its start triangles."""
    if field.dim == 2:
        return field.source
    return None if field.faces is None else (field.starts, field.faces)


__all__ = ["InteriorField", "MeshStep", "MovingMesh", "extend_series", "min_angles"]
