"""XDMF files (+ an HDF5 file beside them) that dolfinx and ParaView read with their default calls.

Layout: the first frame's grid, named ``mesh`` (what ``XDMFFile.read_mesh()`` looks for by
default), directly under the domain, with its point data; for a series also a temporal collection
of one grid per frame, each with its ``Time`` value, its own node positions and its point data.
Vectors have 3 components (z = 0 in 2D: ParaView's filters assume 3) while a 2D mesh keeps ``XY``
geometry (dolfinx reads it as a mesh of the plane). Integer point data whose values name
categories (``method``) have their names in the grid's ``Information`` element, as meshio reads
field data: each ``NAME=CATEGORY`` with its value (meshio allows nothing beside an attribute's data).

meshio's XDMF writers name the single grid ``Grid`` and give every step of a series the same
node positions; a growing domain moves its nodes, so this module writes the XML itself.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ElementTree

import h5py
import numpy as np

TOPOLOGY = {"vertex": "Polyvertex", "triangle": "Triangle", "tetra": "Tetrahedron"}


class Frame:
    """One frame of an XDMF file.

    Parameters
    ----------
    points : (P, d) float
        Node positions, d = 2 or 3.
    cells : (C, k) int
        Corners of each cell (k = 1 vertex, 3 triangle, 4 tetrahedron).
    cell_type : "vertex", "triangle" or "tetra"
    point_data : dict of str to (P,) or (P, d) arrays
        Vectors are padded to 3 components here.
    categories : dict of str to sequence of str, optional
        For an integer array of ``point_data``: the name of each value (value k names[k]).
    """

    __slots__ = ("points", "cells", "cell_type", "point_data", "categories")

    def __init__(self, points, cells, cell_type, point_data, categories=None):
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.cells = np.ascontiguousarray(cells, dtype=np.int64)
        self.cell_type = cell_type
        self.point_data = {name: _three(np.asarray(values)) for name, values in point_data.items()}
        self.categories = dict(categories or {})


def _three(values):
    if values.ndim == 2 and values.shape[1] == 2:
        return np.column_stack([values, np.zeros(len(values))])
    return values


def _item(parent, h5_name, dataset, array):
    kind = "Int" if np.issubdtype(array.dtype, np.integer) else "Float"
    item = ElementTree.SubElement(parent, "DataItem", Dimensions=" ".join(map(str, array.shape)), NumberType=kind,
                                  Precision=str(array.dtype.itemsize), Format="HDF")
    item.text = f"{h5_name}:{dataset}"


def _grid(parent, h5, h5_name, frame, name, group, time, shared):
    """One uniform grid; its datasets go under ``group`` in the HDF5 file (``shared`` names the
    group whose topology it reuses, or None to write its own)."""
    grid = ElementTree.SubElement(parent, "Grid", Name=name, GridType="Uniform")
    cells_group = shared or group
    if shared is None:
        h5[f"{group}/topology"] = frame.cells
    topology = ElementTree.SubElement(grid, "Topology", TopologyType=TOPOLOGY[frame.cell_type],
                                      NumberOfElements=str(len(frame.cells)))
    if frame.cell_type == "vertex":
        topology.set("NodesPerElement", "1")
    _item(topology, h5_name, f"{cells_group}/topology", frame.cells)
    h5[f"{group}/geometry"] = frame.points
    geometry = ElementTree.SubElement(grid, "Geometry", GeometryType="XY" if frame.points.shape[1] == 2 else "XYZ")
    _item(geometry, h5_name, f"{group}/geometry", frame.points)
    if time is not None:
        ElementTree.SubElement(grid, "Time", Value=repr(float(time)))
    names = [(f"{key}={name}", k) for key, names in frame.categories.items() for k, name in enumerate(names)]
    if names:
        information = ElementTree.SubElement(grid, "Information", Name="categories", Value=str(len(names)))
        information.text = "<main>" + "".join(f'<map key="{n}" dim="0">{k}</map>' for n, k in names) + "</main>"
    for key, values in frame.point_data.items():
        h5[f"{group}/{key}"] = values
        attribute = ElementTree.SubElement(grid, "Attribute", Name=key, Center="Node",
                                           AttributeType="Vector" if values.ndim == 2 else "Scalar")
        _item(attribute, h5_name, f"{group}/{key}", values)


def write_xdmf(path, frames, times=None) -> None:
    """Write ``frames`` (a list of :class:`Frame`) as ``path`` (``.xdmf``) and the ``.h5`` beside it.

    ``times`` (one per frame; None for a single frame without a time) become the ``Time`` values.
    Frames of a series share their cells (one mesh moving); the first frame is the grid ``mesh``.
    Not atomic by itself: the callers write into a scratch folder and rename.
    """
    path = os.fspath(path)
    h5_name = os.path.splitext(os.path.basename(path))[0] + ".h5"
    root = ElementTree.Element("Xdmf", Version="3.0")
    domain = ElementTree.SubElement(root, "Domain")
    with h5py.File(os.path.join(os.path.dirname(path), h5_name), "w") as h5:
        # In a series the times are the collection's: a Time on the grid 'mesh' as well makes
        # ParaView's Xdmf3 reader draw nothing at that time.
        first_time = times[0] if times is not None and len(frames) == 1 else None
        _grid(domain, h5, h5_name, frames[0], "mesh", "/mesh", first_time, None)
        if len(frames) > 1:
            series = ElementTree.SubElement(domain, "Grid", Name="series", GridType="Collection",
                                            CollectionType="Temporal")
            for k, (frame, time) in enumerate(zip(frames, times)):
                _grid(series, h5, h5_name, frame, f"step {k}", f"/step{k}", time, "/mesh")
    ElementTree.indent(root)
    with open(path, "w", encoding="utf-8") as handle:
        handle.write('<?xml version="1.0"?>\n' + ElementTree.tostring(root, encoding="unicode") + "\n")
