"""The displacement inside the domain a boundary encloses: what a PDE solver moves its mesh by."""

from __future__ import annotations

import numpy as np

from . import _core
from ._core import GeometryError
from ._validate import as_choice, as_flag, as_integer, as_length, as_points, as_real
from .field import DisplacementField

EXTENSION_METHODS = ("harmonic", "elastic")


class InteriorField:
    """A displacement at every node of a mesh of the domain enclosed by the source boundary.

    Attributes
    ----------
    points : (P, d) float
        The mesh nodes (the user's mesh, or the one made by :func:`extend_field`).
    cells : (C, d + 1) int64
        Triangles (2D) or tetrahedra (3D).
    displacement : (P, d) float
        At every node: the boundary field at the boundary nodes, the method's solution inside.
    inverted : int
        Cells that the motion ``x -> x + displacement`` turns over or flattens.
    min_jacobian : float
        The smallest ratio of a cell's signed area (volume) after the motion to before
        (<= 0 for an inverted cell).
    boundary_distance : float
        The farthest a boundary node of the mesh lies from the source boundary (it was projected
        onto it to take the field's displacement).
    substeps : int
        The substeps the displacement was solved in.
    untangled : bool
        Whether the inner corners of inverted cells were moved (``untangle``).
    attempts : tuple of (substeps, untangle, inverted, min_jacobian)
        What :func:`extend_field` tried, in order, and the inverted cells each left (None and
        NaN for a try whose substeps flattened a cell: no solution); this field is the try that
        left the fewest.
    """

    __slots__ = ("points", "cells", "displacement", "inverted", "min_jacobian", "boundary_distance", "substeps",
                 "untangled", "attempts")

    def __init__(self, points, cells, displacement, inverted, min_jacobian, boundary_distance, substeps=1,
                 untangled=False, attempts=()):
        for name, value in (("points", points), ("cells", cells), ("displacement", displacement)):
            array = np.array(value, copy=True)
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        object.__setattr__(self, "inverted", int(inverted))
        object.__setattr__(self, "min_jacobian", float(min_jacobian))
        object.__setattr__(self, "boundary_distance", float(boundary_distance))
        object.__setattr__(self, "substeps", int(substeps))
        object.__setattr__(self, "untangled", bool(untangled))
        object.__setattr__(self, "attempts", tuple(tuple(a) for a in attempts))

    def __setattr__(self, name, value):
        raise AttributeError("InteriorField is immutable")

    def _with_attempts(self, attempts) -> "InteriorField":
        """The same field with what :func:`extend_field` tried."""
        return InteriorField(**{name: getattr(self, name) for name in self.__slots__ if name != "attempts"},
                             attempts=attempts)

    @property
    def dim(self) -> int:
        return self.points.shape[1]

    def velocity(self, dt) -> np.ndarray:
        """The mean velocity ``displacement / dt`` over a time step ``dt`` > 0, at every node."""
        return self.displacement / as_length(dt, "dt", 1.0)

    def __repr__(self) -> str:
        kind = "triangles" if self.dim == 2 else "tetrahedra"
        how = f"{self.substeps} substep{'s' if self.substeps > 1 else ''}" + (", untangled" if self.untangled else "")
        return (f"InteriorField({len(self.points)} nodes, {len(self.cells)} {kind}, {self.inverted} inverted, "
                f"min jacobian {self.min_jacobian:.3g}, {how})")


#: The (substeps, untangle) that :func:`extend_field` tries in order, until no cell is inverted:
#: substeps first, since they keep the method's solution; untangling, which moves a few inner
#: nodes off it, only where substeps alone leave inverted cells. A value the caller gives replaces
#: that entry's. (The kidney bud, diffusion field: 17 inverted by one solve, none with 4 substeps;
#: the lung-like pair: one tetrahedron left by substeps, untangled; bench/README.md.)
AUTO_STEPS = ((1, False), (4, False), (4, True), (16, True))

#: A solver mesh whose boundary nodes lie farther from C1 than this fraction of C1's size (its
#: bounding box diagonal) is refused: a mesh in other units, or of another domain, is far off,
#: while a mesh of C1's own domain has its boundary on C1 up to the meshing of a smooth outline.
BOUNDARY_TOLERANCE = 0.02


def extend_field(field, boundary=None, *, method="harmonic", mesh=None, mesh_size=None, poisson_ratio=0.3,
                 substeps=None, untangle=None, boundary_tolerance=BOUNDARY_TOLERANCE) -> InteriorField:
    """Extend a boundary displacement field to the domain the source boundary encloses.

    By default no cell of the returned mesh is inverted by the motion: the solve is repeated with
    more substeps, then with untangling (:data:`AUTO_STEPS`), until none is, and the result says
    what was done (``substeps``, ``untangled``, ``attempts``); where none of those clears them (a
    boundary field that itself folds), a :class:`GeometryError` gives their count and where they are.

    Parameters
    ----------
    field : DisplacementField
        From :func:`map_curves` (2D) or :func:`map_surfaces` (3D).
    boundary : (N, 2) float, optional
        2D: the source curve C1 (closed); by default the curve the field was made from.
        3D: unused (the field's start triangles are the boundary).
    method : "harmonic" or "elastic"
        ``"harmonic"``: each component of the displacement solves the Laplace equation inside.
        ``"elastic"``: the displacement solves isotropic linear elasticity with the given
        ``poisson_ratio``. Either way P1 finite elements in the C++ core, equal to the field on
        the boundary: an affine boundary map extends to the same affine map.
    mesh : (points (P, d), cells (C, d + 1)), optional
        The solver's own mesh: triangles (2D) or tetrahedra (3D). Its boundary nodes (on an edge
        or face of one cell only) are projected onto the source boundary and take the field
        there (:meth:`DisplacementField.at`); ``boundary_distance`` says how far they were. 2D
        without a mesh: the domain is meshed with CGAL's constrained Delaunay mesher, every
        point of C1 a node, and a triangle with its three corners on C1 (which would move with
        the boundary field alone) split at its longest inner edge. 3D without a mesh: the region
        S1 (the field's start triangles, a closed surface) encloses is meshed with CGAL's Mesh_3,
        its surface nodes on S1's triangles, and a tetrahedron with four corners on S1 (which
        would move with the boundary field alone) split to get a node inside, unless all six of
        its edges lie on S1; the mesher's random choices are fixed, so the same field gives the
        same mesh.
    mesh_size : float, optional
        Without a mesh, 2D: the largest edge (default: graded from C1's point spacing); 3D: the
        edge length of the tetrahedra and surface triangles (default: S1's mean edge).
    poisson_ratio : float
        ``"elastic"`` only: 0 <= nu < 0.5 (near 0.5 the interior resists changes of volume).
    substeps : int, optional
        Move the mesh in this many equal steps of the boundary displacement, each solved on the
        mesh as the steps before have moved it (the returned displacement is their sum). Large
        growth steps invert cells under a single solve; substeps let the interior follow. Default:
        chosen (:data:`AUTO_STEPS`).
    untangle : bool, optional
        After the solve(s), move the free (interior) corners of the cells still inverted, each to
        the point that maximises the smallest area (volume) ratio of its cells (a small linear
        program per node, in sweeps until none is inverted or nothing moves). Those few nodes'
        displacement is then no longer the method's solution; cells with every corner on the
        boundary, and cells that the boundary field itself folds, stay inverted. Default: only
        where substeps leave inverted cells. With both ``substeps`` and ``untangle`` given, the
        field is returned as solved, inverted cells counted in ``inverted``, never refused.
    boundary_tolerance : float
        With a ``mesh``: the farthest its boundary nodes may lie from C1 (S1), as a fraction of
        C1's size (the diagonal of its bounding box); farther is a ``ValueError`` (a mesh in
        other units, or of another domain).

    Returns
    -------
    InteriorField
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    as_choice(method, "method", EXTENSION_METHODS)
    # Types here; the core checks the values (its messages are the ones users see).
    options = dict(method=method, poisson_ratio=as_real(poisson_ratio, "poisson_ratio", 0.3),
                   mesh_size=as_real(mesh_size, "mesh_size", 0.0))
    given_substeps = None if substeps is None else as_integer(substeps, "substeps", 1)
    given_untangle = None if untangle is None else as_flag(untangle, "untangle")
    tolerance = as_real(boundary_tolerance, "boundary_tolerance", BOUNDARY_TOLERANCE)
    if not tolerance > 0:
        raise ValueError(f"boundary_tolerance: expected a fraction > 0 of C1's size, got {tolerance}")
    if mesh is not None:
        if not (isinstance(mesh, (tuple, list)) and len(mesh) == 2):
            raise TypeError("mesh: expected a (points, cells) pair")
        points = as_points(mesh[0], "mesh points", field.dim)
        cells = np.asarray(mesh[1])
        if cells.ndim != 2 or cells.shape[1] != field.dim + 1 or not np.issubdtype(cells.dtype, np.integer):
            raise ValueError(f"mesh cells: expected integer indices of shape (C, {field.dim + 1}), got {cells.dtype} "
                             f"{cells.shape}")
        cells = np.ascontiguousarray(cells, dtype=np.int64)
    else:
        points, cells = np.zeros((0, field.dim)), np.zeros((0, field.dim + 1), dtype=np.int64)
    if field.dim == 3:
        if field.faces is None:
            raise ValueError("field: a 3D field needs its faces")
        outline = field.starts

        def solve(points, cells, steps, tangle):
            return _core.extend_field_3d(field.starts, field.ends, field.faces, points, cells, substeps=steps,
                                         untangle=tangle, **options)
    else:
        source = field.source if boundary is None else boundary
        if source is None:
            raise ValueError("boundary: this field does not know the curve it was made from: pass boundary=C1")
        outline = as_points(source, "boundary", 2)

        def solve(points, cells, steps, tangle):
            return _core.extend_field_2d(field.starts, field.ends, outline, points, cells, substeps=steps,
                                         untangle=tangle, **options)

    plan = []
    for steps, tangle in AUTO_STEPS:
        chosen = (steps if given_substeps is None else given_substeps,
                  tangle if given_untangle is None else given_untangle)
        if chosen not in plan:
            plan.append(chosen)
    attempts, best = [], None
    for steps, tangle in plan:
        try:
            tried = InteriorField(**solve(points, cells, steps, tangle), substeps=steps, untangled=tangle)
        except GeometryError:
            if not attempts:  # the first try: the core's own message (a bad mesh, say)
                raise
            # A substep that flattens a cell has no solution: a try that clears nothing.
            attempts.append((steps, tangle, None, float("nan")))
            continue
        if not attempts and mesh is not None:
            _check_units(tried.boundary_distance, outline, points, tolerance)
        attempts.append((steps, tangle, tried.inverted, tried.min_jacobian))
        if best is None or tried.inverted < best.inverted:
            best = tried
        if tried.inverted == 0:
            break
        # The same mesh for the next try (the one made here, or the caller's).
        points, cells = tried.points, tried.cells
    interior = best._with_attempts(attempts)
    if interior.inverted and len(plan) > 1:
        raise GeometryError(_inverted_message(interior))
    return interior


def _size(points):
    finite = points[np.isfinite(points).all(axis=1)]
    return float(np.linalg.norm(finite.max(axis=0) - finite.min(axis=0))) if len(finite) else 0.0


def _check_units(distance, outline, mesh_points, tolerance):
    """Refuse a solver mesh whose boundary is far from C1 (S1): another unit or another domain."""
    size = _size(outline)
    if distance > tolerance * size:
        raise ValueError(
            f"mesh: its boundary nodes lie up to {distance:.4g} from C1, which spans {size:.4g} (the mesh spans "
            f"{_size(mesh_points):.4g}): more than boundary_tolerance={tolerance:g} of C1's size. Are the mesh and "
            "the boundaries in the same units (pixels against microns, say)? Scale the mesh to C1's units, or "
            "pass a mesh of the domain C1 encloses")


def measure_ratios(points, cells, displacement):
    """Per cell: its signed area (2D) or volume (3D) after the motion over before, ``(C,)``
    (<= 0 for a cell the motion turns over or flattens)."""
    def measure(x):
        corners = x[cells]
        return np.linalg.det(corners[:, 1:] - corners[:, :1])

    return measure(points + displacement) / measure(points)


def _inverted_message(interior):
    ratios = measure_ratios(interior.points, interior.cells, interior.displacement)
    turned = np.flatnonzero(ratios <= 0)
    centres = interior.points[interior.cells[turned]].mean(axis=1)
    where = "; ".join("(" + ", ".join(f"{v:.4g}" for v in c) + ")" for c in centres[:5])
    more = f" and {len(turned) - 5} more" if len(turned) > 5 else ""
    tried = ", ".join(f"{s} substep{'s' if s > 1 else ''}{' + untangle' if u else ''}: "
                      f"{'no solution (a substep flattened a cell)' if n is None else n}"
                      for s, u, n, _ in interior.attempts)
    return (f"extend_field: {interior.inverted} cells stay inverted by the motion (smallest area/volume ratio "
            f"{interior.min_jacobian:.3g}), centred at {where}{more}; inverted cells per try: {tried}. The boundary "
            "field itself folds or crosses there (check quality(field, c1, c2)); pass substeps=K and untangle=True "
            "to get the field with them counted instead")
