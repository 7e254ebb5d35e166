"""Fields and interior displacements in the files PDE solvers and viewers read.

By suffix: ``.vtu`` (VTK unstructured grid: ParaView), ``.vtp`` (VTK PolyData, boundary fields
only: their triangles or points), ``.xdmf`` (+ ``.h5`` beside it: FEniCSx, ParaView), ``.txt`` (a
COMSOL interpolation table, spreadsheet format). meshio writes ``.vtu`` and XDMF; ``.vtp`` needs
the optional ``vtk`` package (``pip install morphomap[vtk]``; meshio has no PolyData writer).
Point data: ``displacement`` (and ``velocity`` when a time step is given), for boundary fields
also ``end``, ``valid`` (1/0) and ``method`` (an index into :data:`morphomap.field.METHOD_NAMES`,
written into the file's comments or field data). 2D vectors
get a zero third component in VTK files (ParaView's vectors are 3D) and stay 2D in XDMF (FEniCSx
meshes of the plane).

**ParaView**: open ``.xdmf`` files with the "XDMF Reader" (``XDMFReader(FileNames=[...])`` in
pvpython): the Xdmf3 readers of Debian 12's ParaView 5.11 abort on any HDF5-backed XDMF file,
dolfinx's own included.

**COMSOL**: Definitions > Functions > Interpolation, Data source: File, the ``.txt``; Number of
arguments 2 (3 in 3D), one function per displacement column (``ux``, ``uy``[, ``uz``]: "Use
spreadsheet format", columns 3, 4[, 5]); then prescribe the mesh displacement
(Deformed Geometry / Moving Mesh: Prescribed Mesh Displacement) as ``ux(X, Y)``, ``uy(X, Y)``
in the material frame, scaled by the fraction of the time step.

Writes are atomic: into a temporary folder beside the target, then renamed into place (for
``.xdmf`` the ``.h5`` first, then the ``.xdmf`` that refers to it).
"""

from __future__ import annotations

import os
import shutil
import tempfile

import numpy as np

from .._validate import as_length
from ..field import METHOD_NAMES, DisplacementField

SOLVER_SUFFIXES = (".vtu", ".xdmf", ".txt")
FIELD_SUFFIXES = SOLVER_SUFFIXES + (".vtp",)  # PolyData: a boundary, not a volume


def _atomic_files(path, write):
    """write(temporary path) in a scratch folder beside `path`, then everything it wrote renamed
    into place, the file named `path` last (it may refer to the others)."""
    target = os.path.abspath(os.fspath(path))
    folder, name = os.path.split(target)
    scratch = tempfile.mkdtemp(dir=folder, prefix=f".{name}.")
    try:
        write(os.path.join(scratch, name))
        written = sorted(os.listdir(scratch), key=lambda f: f == name)
        for file in written:
            os.replace(os.path.join(scratch, file), os.path.join(folder, file))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _flat_to_3d(points, point_data):
    """VTK's points and vectors are 3D: 2D ones get a zero third component."""
    if points.shape[1] != 2:
        return points, point_data
    pad = lambda v: np.column_stack([v, np.zeros(len(v))]) if v.ndim == 2 and v.shape[1] == 2 else v  # noqa: E731
    return pad(points), {k: pad(v) for k, v in point_data.items()}


def _poly_data_file(path, points, cells, point_data, field_data):
    try:
        from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    except ImportError as error:
        raise ImportError("path: .vtp files need the optional vtk package (pip install vtk)") from error

    points, point_data = _flat_to_3d(points, point_data)
    poly = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, dtype=np.float64), deep=True))
    poly.SetPoints(vtk_points)
    corners = cells.shape[1]
    offsets = np.arange(0, corners * len(cells) + 1, corners, dtype=np.int64)
    cell_array = vtkCellArray()
    cell_array.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                       numpy_to_vtkIdTypeArray(np.ascontiguousarray(cells, dtype=np.int64).ravel(), deep=True))
    (poly.SetPolys if corners == 3 else poly.SetVerts)(cell_array)
    for name, values in point_data.items():
        array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        array.SetName(name)
        poly.GetPointData().AddArray(array)
    for name, values in field_data.items():
        array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
        array.SetName(name)
        poly.GetFieldData().AddArray(array)

    def write(temporary):
        writer = vtkXMLPolyDataWriter()
        writer.SetFileName(temporary)
        writer.SetInputData(poly)
        if writer.Write() != 1:
            raise OSError(f"VTK could not write {path}")

    _atomic_files(path, write)


def _mesh_file(path, points, cells, cell_type, point_data, field_data=None):
    import meshio

    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix == ".vtp":
        _poly_data_file(path, points, cells, point_data, field_data or {})
        return
    if suffix == ".vtu":
        points, point_data = _flat_to_3d(points, point_data)
    mesh = meshio.Mesh(points, [(cell_type, cells)], point_data=point_data, field_data=field_data or {})
    _atomic_files(path, lambda temporary: meshio.write(temporary, mesh,
                                                       file_format="xdmf" if suffix == ".xdmf" else "vtu"))


def _comsol_table(path, header, points, displacement):
    from .atomic import atomic_text

    columns = ["x", "y", "z"][: points.shape[1]] + ["ux", "uy", "uz"][: points.shape[1]]
    with atomic_text(path) as handle:
        for line in header:
            handle.write(f"% {line}\n")
        handle.write("% " + " ".join(columns) + "\n")
        for row in np.column_stack([points, displacement]).tolist():
            handle.write(" ".join(repr(float(v)) for v in row) + "\n")


def _velocity(displacement, dt):
    return {} if dt is None else {"velocity": displacement / as_length(dt, "dt", 1.0)}


def write_field_for_solver(path, field: DisplacementField, dt=None) -> None:
    """A boundary field as ``.vtu``, ``.vtp``, ``.xdmf`` or a COMSOL ``.txt`` (see the module's notes).

    The points are the start points (rows whose start is unknown, from a reverse mapping that
    missed, are left out); 3D fields carry their triangles, 2D fields are written as points.
    The COMSOL table holds the valid vectors only (an interpolation table has no gaps).
    """
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    placed = np.isfinite(field.starts).all(axis=1)
    vectors = field.vectors
    if suffix == ".txt":
        valid = field.valid
        _comsol_table(path, [f"morphomap displacement field: {int(valid.sum())} vectors from C1 to C2 "
                             f"({field.dim}D), columns: start point, displacement (the inputs' length unit)"],
                      field.starts[valid], vectors[valid])
        return
    codes = np.array([METHOD_NAMES.index(m) for m in field.method.tolist()], dtype=np.int64)
    point_data = {"displacement": vectors[placed], "end": field.ends[placed],
                  "valid": field.valid[placed].astype(np.int64), "method": codes[placed],
                  **_velocity(vectors[placed], dt)}
    field_data = {name: np.array([k, 0]) for k, name in enumerate(METHOD_NAMES)}
    if field.faces is not None and placed.all():
        _mesh_file(path, field.starts, field.faces, "triangle", point_data, field_data)
    else:
        index = np.arange(int(placed.sum()))[:, None]
        _mesh_file(path, field.starts[placed], index, "vertex", point_data, field_data)


def write_interior(path, interior, dt=None) -> None:
    """An :class:`InteriorField` as ``.vtu``, ``.xdmf`` (the mesh and ``displacement``, with
    ``velocity`` when ``dt`` is given) or a COMSOL ``.txt`` table of node, displacement."""
    from ..extend import InteriorField

    if not isinstance(interior, InteriorField):
        raise TypeError(f"interior: expected an InteriorField, got {type(interior).__name__}")
    suffix = os.path.splitext(os.fspath(path))[1].lower()
    if suffix not in SOLVER_SUFFIXES:
        raise ValueError(f"path: unknown format {suffix or '(no suffix)'!r}: use one of {', '.join(SOLVER_SUFFIXES)}")
    if suffix == ".txt":
        _comsol_table(
            path,
            [
                f"morphomap interior displacement: {len(interior.points)} mesh nodes ({interior.dim}D), "
                "columns: node, displacement (the inputs' length unit)"
            ],
            interior.points,
            interior.displacement,
        )
        return
    cell_type = "triangle" if interior.dim == 2 else "tetra"
    _mesh_file(
        path,
        interior.points,
        interior.cells,
        cell_type,
        {"displacement": interior.displacement, **_velocity(interior.displacement, dt)},
    )
