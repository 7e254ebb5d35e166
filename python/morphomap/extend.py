"""The displacement inside the domain a boundary encloses: what a PDE solver moves its mesh by."""

from __future__ import annotations


import numpy as np

from . import _core
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
    """

    __slots__ = ("points", "cells", "displacement", "inverted", "min_jacobian", "boundary_distance")

    def __init__(self, points, cells, displacement, inverted, min_jacobian, boundary_distance):
        for name, value in (("points", points), ("cells", cells), ("displacement", displacement)):
            array = np.array(value, copy=True)
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        object.__setattr__(self, "inverted", int(inverted))
        object.__setattr__(self, "min_jacobian", float(min_jacobian))
        object.__setattr__(self, "boundary_distance", float(boundary_distance))

    def __setattr__(self, name, value):
        raise AttributeError("InteriorField is immutable")

    @property
    def dim(self) -> int:
        return self.points.shape[1]

    def velocity(self, dt) -> np.ndarray:
        """The mean velocity ``displacement / dt`` over a time step ``dt`` > 0, at every node."""
        return self.displacement / as_length(dt, "dt", 1.0)

    def __repr__(self) -> str:
        kind = "triangles" if self.dim == 2 else "tetrahedra"
        return (f"InteriorField({len(self.points)} nodes, {len(self.cells)} {kind}, {self.inverted} inverted, "
                f"min jacobian {self.min_jacobian:.3g})")


def extend_field(field, boundary=None, *, method="harmonic", mesh=None, mesh_size=None, poisson_ratio=0.3,
                 substeps=1, untangle=False) -> InteriorField:
    """Extend a boundary displacement field to the domain the source boundary encloses.

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
    mesh : (points, cells), optional
        The solver's own mesh: triangles (2D) or tetrahedra (3D). Its boundary nodes (on an edge
        or face of one cell only) are projected onto the source boundary and take the field
        there (:meth:`DisplacementField.at`); ``boundary_distance`` says how far they were. 2D
        without a mesh: the domain is meshed with CGAL's constrained Delaunay mesher, every
        point of C1 a node. 3D without a mesh: the region S1 (the field's start triangles, a
        closed surface) encloses is meshed with CGAL's Mesh_3, its surface nodes on S1's
        triangles, and a tetrahedron with four corners on S1 (which would move with the boundary
        field alone) split to get a node inside, unless all six of its edges lie on S1; the mesher's
        random choices are fixed, so the same field gives the same mesh.
    mesh_size : float, optional
        Without a mesh, 2D: the largest edge (default: graded from C1's point spacing); 3D: the
        edge length of the tetrahedra and surface triangles (default: S1's mean edge).
    poisson_ratio : float
        ``"elastic"`` only: 0 <= nu < 0.5 (near 0.5 the interior resists changes of volume).
    substeps : int
        Move the mesh in this many equal steps of the boundary displacement, each solved on the
        mesh as the steps before have moved it (the returned displacement is their sum). Large
        growth steps invert cells under a single solve; substeps let the interior follow (the
        kidney pair, diffusion field: 17 of 345,011 triangles inverted by one solve, none with 4
        substeps; bench/README.md). Cells that the boundary field itself folds stay inverted.
    untangle : bool
        After the solve(s), move the free (interior) corners of the cells still inverted, each to
        the point that maximises the smallest area (volume) ratio of its cells (a small linear
        program per node, in sweeps until none is inverted or nothing moves). Those few nodes'
        displacement is then no longer the method's solution; cells with every corner on the
        boundary, and cells that the boundary field itself folds, stay inverted (the lung-like
        pair, diffusion field, default mesh: the one tetrahedron that substeps left inverted is
        untangled; bench/README.md).

    Returns
    -------
    InteriorField
    """
    if not isinstance(field, DisplacementField):
        raise TypeError(f"field: expected a DisplacementField, got {type(field).__name__}")
    as_choice(method, "method", EXTENSION_METHODS)
    # Types here; the core checks the values (its messages are the ones users see).
    options = dict(method=method, poisson_ratio=as_real(poisson_ratio, "poisson_ratio", 0.3),
                   substeps=as_integer(substeps, "substeps", 1), untangle=as_flag(untangle, "untangle"))
    if mesh is not None:
        if not (isinstance(mesh, (tuple, list)) and len(mesh) == 2):
            raise TypeError("mesh: expected a (points, cells) pair")
        points = as_points(mesh[0], "mesh points", field.dim)
        cells = np.asarray(mesh[1])
        if cells.ndim != 2 or cells.shape[1] != field.dim + 1 or not np.issubdtype(cells.dtype, np.integer):
            raise ValueError(f"mesh cells: expected integer indices of shape (C, {field.dim + 1}), got {cells.dtype} "
                             f"{cells.shape}")
        cells = np.ascontiguousarray(cells, dtype=np.int64)
    if field.dim == 3:
        if field.faces is None:
            raise ValueError("field: a 3D field needs its faces")
        if mesh is None:
            points, cells = np.zeros((0, 3)), np.zeros((0, 4), dtype=np.int64)
        result = _core.extend_field_3d(field.starts, field.ends, field.faces, points, cells,
                                       mesh_size=as_real(mesh_size, "mesh_size", 0.0), **options)
    else:
        source = field.source if boundary is None else boundary
        if source is None:
            raise ValueError("boundary: this field does not know the curve it was made from: pass boundary=C1")
        if mesh is None:
            points, cells = np.zeros((0, 2)), np.zeros((0, 3), dtype=np.int64)
        result = _core.extend_field_2d(field.starts, field.ends, as_points(source, "boundary", 2), points, cells,
                                       mesh_size=as_real(mesh_size, "mesh_size", 0.0), **options)
    return InteriorField(**result)
