"""Fields and interior displacements in the files PDE solvers and viewers read, one writer per format.

:mod:`morphomap.io.formats` picks the writer by suffix. ``.vtu`` (VTK unstructured grid, written by
meshio: ParaView), ``.vtp`` (VTK PolyData, boundary fields only, written with the optional ``vtk``
package: ``pip install morphomap[vtk]``; meshio has no PolyData writer), ``.xdmf`` (+ ``.h5``
beside it, :mod:`morphomap.io.xdmf`: dolfinx, ParaView), ``.txt`` (a COMSOL interpolation table,
spreadsheet format), ``.pvd`` (a ParaView collection of ``.vtu`` files, for series).

Point data: ``displacement`` (and ``velocity`` when a time step is given); for boundary fields
also ``end``, ``valid`` (1/0) and ``method``. Vectors have 3 components everywhere (z = 0 in 2D:
ParaView's Warp By Vector needs 3); the points of VTK files too, while XDMF keeps a 2D mesh's
``XY`` geometry (dolfinx reads it as a mesh of the plane). ``method`` is categorical: the index
into :data:`morphomap.field.METHOD_NAMES`, named in the file by field data ``method=NAME`` holding
each code (VTK files; in XDMF the grid's ``Information``, where meshio reads it as field data):
meshio, which reads these files back, takes no string arrays.

**dolfinx**: ``XDMFFile(comm, "u.xdmf", "r").read_mesh()`` reads the mesh with its defaults;
:func:`morphomap.io.fenicsx.read_function` gives the displacement (velocity) as a ``Function``.

**ParaView**: File > Open picks its own reader for every kind (open ``.xdmf`` files by their full
path: Debian 12's ParaView 5.11 Xdmf3 readers join a bare file name and the ``.h5`` name wrongly);
Warp By Vector with ``displacement``.

**COMSOL**: Definitions > Functions > Interpolation, Data source: File, the ``.txt``; Number of
arguments 2 (3 in 3D), one function per column (``ux``, ``uy``[, ``uz``], and ``vx``, ``vy``[,
``vz``] when written with a time step: "Use spreadsheet format"); then prescribe the mesh
displacement (Deformed Geometry / Moving Mesh: Prescribed Mesh Displacement) as ``ux(X, Y)``,
``uy(X, Y)`` in the material frame, scaled by the fraction of the time step.

Writes are atomic: into a temporary folder beside the target, then renamed into place (the named
file last, since it may refer to the others).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from .._validate import as_length
from ..field import METHOD_NAMES
from .atomic import atomic_text
from .xdmf import Frame, write_xdmf

CELL_TYPES = {2: "triangle", 3: "tetra"}


def atomic_files(path, write):
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


def pad3(values):
    """VTK's points and vectors are 3D: 2D ones get a zero third component."""
    values = np.asarray(values)
    return np.column_stack([values, np.zeros(len(values))]) if values.ndim == 2 and values.shape[1] == 2 else values


def velocity(displacement, dt):
    """``{"velocity": displacement / dt}``, or nothing without a time step."""
    return {} if dt is None else {"velocity": displacement / as_length(dt, "dt", 1.0)}


class Content:
    """What a writer writes: a mesh (points, cells of one type), point data and, for ``method``,
    the names of the field's methods per point."""

    __slots__ = ("points", "cells", "cell_type", "point_data", "methods", "header")

    def __init__(self, points, cells, cell_type, point_data, methods=None, header=""):
        self.points, self.cells, self.cell_type = points, cells, cell_type
        self.point_data, self.methods, self.header = point_data, methods, header


def field_content(field, dt=None) -> Content:
    """A boundary field as mesh content: the start points (rows whose start is unknown, from a
    reverse mapping that missed, are left out); 3D fields with their triangles, 2D as points."""
    placed = np.isfinite(field.starts).all(axis=1)
    vectors = field.vectors[placed]
    point_data = {"displacement": vectors, "end": field.ends[placed], "valid": field.valid[placed].astype(np.int64),
                  **velocity(vectors, dt)}
    methods = field.method[placed]
    if field.faces is not None and placed.all():
        return Content(field.starts, field.faces, "triangle", point_data, methods)
    return Content(field.starts[placed], np.arange(int(placed.sum()))[:, None], "vertex", point_data, methods)


def interior_content(interior, dt=None) -> Content:
    return Content(interior.points, interior.cells, CELL_TYPES[interior.dim],
                   {"displacement": interior.displacement, **velocity(interior.displacement, dt)})


def _with_methods(content):
    """Point data with ``method`` as codes, and field data naming each code (``method=NAME``:
    the code): meshio reads no string arrays back, so the file itself says what a code means."""
    point_data = {k: pad3(v) for k, v in content.point_data.items()}
    if content.methods is None:
        return point_data, {}
    point_data["method"] = np.array([METHOD_NAMES.index(m) for m in content.methods.tolist()], dtype=np.int64)
    return point_data, {f"method={name}": np.array([k]) for k, name in enumerate(METHOD_NAMES)}


def _vtu(temporary, content):
    point_data, field_data = _with_methods(content)
    mesh = meshio.Mesh(pad3(content.points), [(content.cell_type, content.cells)], point_data=point_data,
                       field_data=field_data)
    meshio.write(temporary, mesh, file_format="vtu")


def write_vtu(path, content) -> None:
    atomic_files(path, lambda temporary: _vtu(temporary, content))


def _frame(content):
    point_data, _ = _with_methods(content)
    categories = {} if content.methods is None else {"method": METHOD_NAMES}
    return Frame(content.points, content.cells, content.cell_type, point_data, categories)


def write_xdmf_file(path, content, time=None) -> None:
    atomic_files(path, lambda temporary: write_xdmf(temporary, [_frame(content)], None if time is None else [time]))


def write_xdmf_series(path, contents, times) -> None:
    """One moving mesh: every step with the first one's cells (a ValueError says which differs)."""
    for k, content in enumerate(contents[1:], start=1):
        if not np.array_equal(content.cells, contents[0].cells):
            raise ValueError(f"interiors: step {k} has other cells than step 0, and an XDMF series is one moving "
                             "mesh: extend every step on the same mesh, or write a .pvd (one .vtu per step)")
    atomic_files(path, lambda temporary: write_xdmf(temporary, [_frame(c) for c in contents], list(times)))


def write_pvd_series(path, contents, times) -> None:
    """A ParaView collection: ``STEM_0000.vtu``, ... beside ``STEM.pvd``, each at its time."""
    stem = os.path.splitext(os.path.basename(os.fspath(path)))[0]

    def write(temporary):
        folder = os.path.dirname(temporary)
        entries = []
        for k, (content, time) in enumerate(zip(contents, times)):
            name = f"{stem}_{k:04d}.vtu"
            _vtu(os.path.join(folder, name), content)
            entries.append(f'    <DataSet timestep="{float(time)!r}" part="0" file={quoteattr(name)}/>\n')
        with open(temporary, "w", encoding="utf-8") as handle:
            handle.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
                         + "".join(entries) + "  </Collection>\n</VTKFile>\n")

    atomic_files(path, write)


def write_poly_data(path, content) -> None:
    """A boundary field as VTK PolyData (triangles, or vertices for a curve's points)."""
    try:
        from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter
    except ImportError as error:
        raise ImportError("path: .vtp files need the optional vtk package (pip install vtk)") from error

    poly = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(pad3(content.points), dtype=np.float64), deep=True))
    poly.SetPoints(vtk_points)
    cells = content.cells
    corners = cells.shape[1]
    offsets = np.arange(0, corners * len(cells) + 1, corners, dtype=np.int64)
    cell_array = vtkCellArray()
    cell_array.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                       numpy_to_vtkIdTypeArray(np.ascontiguousarray(cells, dtype=np.int64).ravel(), deep=True))
    (poly.SetPolys if corners == 3 else poly.SetVerts)(cell_array)
    point_data, field_data = _with_methods(content)
    for data, arrays in ((poly.GetPointData(), point_data), (poly.GetFieldData(), field_data)):
        for name, values in arrays.items():
            array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
            array.SetName(name)
            data.AddArray(array)

    def write(temporary):
        writer = vtkXMLPolyDataWriter()
        writer.SetFileName(temporary)
        writer.SetInputData(poly)
        if writer.Write() != 1:
            raise OSError(f"VTK could not write {path}")

    atomic_files(path, write)


def write_comsol(path, content) -> None:
    """A COMSOL interpolation table: node, displacement[, velocity] per row. Only the rows whose
    vector is valid (an interpolation table has no gaps)."""
    dim = content.points.shape[1]
    data = content.point_data
    keep = data["valid"].astype(bool) if "valid" in data else np.ones(len(content.points), dtype=bool)
    names = [["x", "y", "z"][:dim], ["ux", "uy", "uz"][:dim]]
    columns = [content.points[keep], data["displacement"][keep]]
    if "velocity" in data:
        names.append(["vx", "vy", "vz"][:dim])
        columns.append(data["velocity"][keep])
    what = "start point" if content.methods is not None else "node"
    with atomic_text(path) as handle:
        handle.write(f"% {content.header.format(count=int(keep.sum()), dim=dim)}, columns: {what}, displacement"
                     f"{', velocity' if 'velocity' in data else ''} (the inputs' length unit)\n")
        handle.write("% " + " ".join(sum(names, [])) + "\n")
        for row in np.column_stack(columns).tolist():
            handle.write(" ".join(repr(float(v)) for v in row) + "\n")
