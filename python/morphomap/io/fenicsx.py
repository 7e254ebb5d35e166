"""The displacement of a morphomap XDMF file as a dolfinx ``Function``, in one call.

The mesh reads with dolfinx's default call; the point data with :func:`read_function`::

    from mpi4py import MPI
    from dolfinx import io
    from morphomap.io.fenicsx import read_function

    with io.XDMFFile(MPI.COMM_WORLD, "u.xdmf", "r") as xdmf:
        mesh = xdmf.read_mesh()
    u = read_function("u.xdmf", mesh=mesh)                  # P1 vector Function: the displacement
    v = read_function("u.xdmf", "velocity", mesh=mesh)      # written with dt=...
    u3 = read_function("series.xdmf", mesh=mesh, time=3.0)  # one step of a series

dolfinx is imported only when a function here is called, and this module imports nothing of
morphomap beyond the standard library, numpy and h5py, so that it also loads (by its file) in a
Python that has dolfinx but not morphomap's other dependencies.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree

import h5py
import numpy as np


def _grid(root, path, time):
    """The grid holding the data: the one named ``mesh``, or the step whose Time is ``time``."""
    if time is None:
        grid = root.find("./Domain/Grid[@Name='mesh']")
        if grid is None:
            raise ValueError(f"path: {path} has no grid named 'mesh': write it with morphomap.write_interior")
        return grid
    steps = [(float(g.find("Time").get("Value")), g) for g in root.iter("Grid") if g.find("Time") is not None]
    if not steps:
        raise ValueError(f"time: {path} holds no time values: call read_function without time=")
    found, grid = min(steps, key=lambda step: abs(step[0] - float(time)))
    if abs(found - float(time)) > 1e-9 * max(1.0, abs(float(time))):
        known = ", ".join(f"{t:g}" for t in sorted({t for t, _ in steps}))
        raise ValueError(f"time: {time} is not a time of {path}: use one of {known}")
    return grid


def read_times(path) -> list:
    """The ``Time`` values of a series file, in order (empty for a file without times)."""
    root = ElementTree.parse(os.fspath(path)).getroot()
    series = root.find("./Domain/Grid[@CollectionType='Temporal']")
    grids = series.findall("Grid") if series is not None else root.findall("./Domain/Grid")
    return [float(g.find("Time").get("Value")) for g in grids if g.find("Time") is not None]


def read_point_data(path, name="displacement", *, time=None):
    """Point data ``name`` of a morphomap XDMF file as numpy: ``(P, 3)`` vectors or ``(P,)``, in the
    file's node order (without dolfinx). ``time``: a step of a series (default: the grid ``mesh``)."""
    path = os.fspath(path)
    grid = _grid(ElementTree.parse(path).getroot(), path, time)
    attribute = grid.find(f"Attribute[@Name='{name}']")
    if attribute is None:
        names = ", ".join(a.get("Name") for a in grid.findall("Attribute"))
        raise ValueError(f"name: {path} has no point data {name!r}: it has {names or 'none'}")
    file, dataset = attribute.find("DataItem").text.strip().rsplit(":", 1)
    with h5py.File(os.path.join(os.path.dirname(os.path.abspath(path)), file), "r") as h5:
        return h5[dataset][...]


def read_function(path, name="displacement", *, mesh=None, time=None, comm=None):
    """A dolfinx ``Function`` (continuous P1; vector valued for vectors) of point data ``name``.

    Parameters
    ----------
    path : str or path
        An ``.xdmf`` written by :func:`morphomap.write_interior` (or its series writer).
    name : str
        ``"displacement"``, or ``"velocity"`` when the file was written with ``dt``.
    mesh : dolfinx.mesh.Mesh, optional
        The mesh read from this file (``XDMFFile(comm, path, "r").read_mesh()``), whose input
        node order places the values; by default read here.
    time : float, optional
        A step of a series: the point data at that ``Time`` value.
    comm : MPI communicator, optional
        For reading the mesh; default ``MPI.COMM_WORLD``.

    Returns
    -------
    dolfinx.fem.Function
        Values ``(P, gdim)`` per node (vectors' zero z dropped on a 2D mesh) or ``(P,)``.
    """
    from dolfinx import fem, io

    if mesh is None:
        if comm is None:
            from mpi4py import MPI

            comm = MPI.COMM_WORLD
        with io.XDMFFile(comm, os.fspath(path), "r") as xdmf:
            mesh = xdmf.read_mesh()
    values = read_point_data(path, name, time=time)
    gdim = mesh.geometry.dim
    shape = (gdim,) if values.ndim == 2 else ()
    if hasattr(fem, "functionspace"):
        space = fem.functionspace(mesh, ("Lagrange", 1, shape))
    elif shape:
        space = fem.VectorFunctionSpace(mesh, ("Lagrange", 1))
    else:
        space = fem.FunctionSpace(mesh, ("Lagrange", 1))
    if values.ndim == 2:
        values = values[:, :gdim]
    nodes = np.asarray(mesh.geometry.input_global_indices)
    if len(values) <= nodes.max(initial=-1):
        raise ValueError(f"mesh: has input nodes up to {nodes.max()} but {path} holds {len(values)} values of "
                         f"{name!r}: pass the mesh read from this file")
    # P1 dofs and P1 geometry nodes sit at the same corners of each cell, in the same order.
    cells = np.asarray(getattr(space.dofmap.list, "array", space.dofmap.list)).reshape(-1)
    corners = np.asarray(getattr(mesh.geometry.dofmap, "array", mesh.geometry.dofmap)).reshape(-1)
    function = fem.Function(space, name=name)
    block = function.x.array.reshape(-1, space.dofmap.index_map_bs)
    block[cells] = values[nodes[corners]].reshape(len(corners), -1)
    return function
