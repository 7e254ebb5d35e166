"""Fields and interior displacements in solver files, opened by the real clients.

FEniCSx (Debian's python3-dolfinx, the system Python) and ParaView (pvpython, Debian's
python3-paraview) run as subprocesses; .ci/run installs both, so that in CI these never skip.
"""

import json
import os
import shutil
import subprocess
import textwrap

import meshio
import numpy as np
import pytest
import trimesh

import morphomap as mm
import morphomap.io.fenicsx
from conftest import circle, require_client

A2, B2 = np.array([[1.2, 0.3], [-0.1, 0.9]]), np.array([0.3, -0.2])
SYSTEM_PYTHON = "/usr/bin/python3"


def affine_interior():
    c1 = circle(80)
    field = mm.DisplacementField(c1, c1 @ A2.T + B2, "normal", source=c1)
    return field, mm.extend_field(field, mesh_size=0.15)


def run_client(command, script, tmp_path):
    (tmp_path / "client.py").write_text(textwrap.dedent(script))
    done = subprocess.run([*command, str(tmp_path / "client.py")], capture_output=True, text=True, timeout=300,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def dolfinx_available():
    if not os.path.exists(SYSTEM_PYTHON):
        return False
    return subprocess.run([SYSTEM_PYTHON, "-c", "import dolfinx, h5py"], capture_output=True).returncode == 0


def test_meshio_round_trips_every_format(tmp_path):
    field, interior = affine_interior()
    for suffix in (".vtu", ".xdmf"):
        mm.write_interior(tmp_path / f"u{suffix}", interior, dt=0.5)
        back = meshio.read(tmp_path / f"u{suffix}")
        assert np.allclose(back.points[:, :2], interior.points)
        assert np.array_equal(back.cells_dict["triangle"], interior.cells)
        assert np.allclose(back.point_data["displacement"][:, :2], interior.displacement)
        assert np.allclose(back.point_data["velocity"][:, :2], interior.displacement / 0.5)
        mm.write_field(tmp_path / f"f{suffix}", field)
        back = meshio.read(tmp_path / f"f{suffix}")
        assert np.allclose(back.points[:, :2], field.starts)
        assert np.allclose(back.point_data["displacement"][:, :2], field.vectors)
        assert back.point_data["valid"].tolist() == [1] * len(field)
    # 3D fields carry their triangles.
    s1 = trimesh.creation.icosphere(2)
    field3 = mm.map_surfaces(s1, s1.copy().apply_scale(1.5), "normal")
    mm.write_field(tmp_path / "f3.vtu", field3)
    back = meshio.read(tmp_path / "f3.vtu")
    assert np.array_equal(back.cells_dict["triangle"], field3.faces)
    assert np.allclose(back.point_data["displacement"], field3.vectors)
    # .xdmf leaves its .h5 beside it and nothing else.
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["u.vtu", "u.xdmf", "u.h5", "f.vtu", "f.xdmf", "f.h5", "f3.vtu"])


def test_comsol_table(tmp_path):
    field, interior = affine_interior()
    mm.write_interior(tmp_path / "u.txt", interior)
    lines = (tmp_path / "u.txt").read_text().splitlines()
    assert lines[0].startswith("% morphomap interior displacement") and lines[1] == "% x y ux uy"
    table = np.loadtxt(tmp_path / "u.txt", comments="%")
    assert np.array_equal(table[:, :2], interior.points) and np.array_equal(table[:, 2:], interior.displacement)
    ends = field.ends.copy()
    ends[3] = np.nan
    mm.write_field(tmp_path / "f.txt", mm.DisplacementField(field.starts, ends, "normal"))
    table = np.loadtxt(tmp_path / "f.txt", comments="%")
    assert len(table) == len(field) - 1  # an interpolation table has no gaps


def test_writes_are_atomic(tmp_path, monkeypatch):
    _, interior = affine_interior()
    mm.write_interior(tmp_path / "u.xdmf", interior)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}

    def broken(*args, **kwargs):
        raise OSError("disk full")

    mm.write_interior(tmp_path / "u.vtu", interior)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    monkeypatch.setattr(meshio, "write", broken)
    with pytest.raises(OSError, match="disk full"):
        mm.write_interior(tmp_path / "u.vtu", interior)
    # XDMF: the .h5 written, then the XML fails: neither file is replaced.
    import xml.etree.ElementTree as ElementTree

    monkeypatch.setattr(ElementTree, "tostring", broken)
    with pytest.raises(OSError, match="disk full"):
        mm.write_interior(tmp_path / "u.xdmf", interior)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    with pytest.raises(ValueError, match="unknown format '.stl'"):
        mm.write_interior(tmp_path / "u.stl", interior)


# The system Python has dolfinx but not morphomap's other dependencies: the client loads the
# dolfinx helper by its file, which imports only numpy, h5py and dolfinx.
LOAD_HELPER = f"""
import importlib.util
spec = importlib.util.spec_from_file_location("fenicsx_helper", {morphomap.io.fenicsx.__file__!r})
helper = importlib.util.module_from_spec(spec)
spec.loader.exec_module(helper)
"""


def test_fenicsx_reads_the_mesh_and_the_displacement(tmp_path):
    # FEniCSx reads the mesh with its default call, the helper gives the displacement as a P1
    # vector function, and dolfinx integrates div u over the domain: (trace A - 2) times the area
    # for an affine map; the nodal values are the affine map's at dolfinx's own coordinates.
    require_client(dolfinx_available(), "FEniCSx (python3-dolfinx, python3-h5py)")
    _, interior = affine_interior()
    mm.write_interior(tmp_path / "u.xdmf", interior, dt=0.5)
    got = run_client([SYSTEM_PYTHON], LOAD_HELPER + """
import json
import numpy as np
import ufl
from dolfinx import fem, io
from mpi4py import MPI

with io.XDMFFile(MPI.COMM_WORLD, "u.xdmf", "r") as xdmf:
    mesh = xdmf.read_mesh()
u = helper.read_function("u.xdmf", mesh=mesh)
v = helper.read_function("u.xdmf", "velocity")
area = fem.assemble_scalar(fem.form(fem.Constant(mesh, 1.0) * ufl.dx))
divergence = fem.assemble_scalar(fem.form(ufl.div(u) * ufl.dx))
x = u.function_space.tabulate_dof_coordinates()[:, :2]
print(json.dumps({"nodes": mesh.geometry.x.shape[0], "gdim": mesh.geometry.dim, "area": area,
                  "divergence": divergence, "x": x.tolist(), "u": u.x.array.reshape(-1, 2).tolist(),
                  "v": v.x.array.reshape(-1, 2).tolist()}))
""", tmp_path)
    assert got["nodes"] == len(interior.points) and got["gdim"] == 2
    x, u = np.array(got["x"]), np.array(got["u"])
    assert np.abs(u - (x @ A2.T + B2 - x)).max() < 1e-10
    assert np.abs(np.array(got["v"]) - u / 0.5).max() < 1e-10
    assert got["divergence"] == pytest.approx((np.trace(A2) - 2) * got["area"], rel=1e-10)


def test_fenicsx_reads_fields_3d_interiors_and_series_with_defaults(tmp_path):
    # Every XDMF kind opens with read_mesh() and no name: a 3D boundary field (triangles; a 2D
    # one is points, which dolfinx makes no mesh of), a 3D interior (tetrahedra), and a series
    # on one moving mesh, each step by its time value.
    require_client(dolfinx_available(), "FEniCSx (python3-dolfinx, python3-h5py)")
    field, interior = affine_interior()
    s1 = trimesh.creation.icosphere(2)
    field3 = mm.map_surfaces(s1, s1.copy().apply_scale(1.3), "normal")
    mm.write_field(tmp_path / "f.xdmf", field3)
    interior3 = mm.extend_field(field3, mesh_size=0.3)
    mm.write_interior(tmp_path / "u3.xdmf", interior3)
    steps = [interior, mm.extend_field(field, mesh=(interior.points, interior.cells), substeps=2)]
    mm.io.write_interior_series(tmp_path / "series.xdmf", steps, [0.0, 0.25])
    got = run_client([SYSTEM_PYTHON], LOAD_HELPER + """
import json
from dolfinx import io
from mpi4py import MPI

out = {}
for name in ("f.xdmf", "u3.xdmf", "series.xdmf"):
    with io.XDMFFile(MPI.COMM_WORLD, name, "r") as xdmf:
        mesh = xdmf.read_mesh()
    out[name] = {"nodes": mesh.geometry.x.shape[0], "cells": mesh.topology.index_map(mesh.topology.dim).size_local}
    if name != "f.xdmf":
        times = (0.0, 0.25) if name == "series.xdmf" else (None,)
        for time in times:
            u = helper.read_function(name, mesh=mesh, time=time)
            values = u.x.array.reshape(-1, mesh.geometry.dim)
            out[name][str(time)] = {"u": values.tolist(), "dof_x": u.function_space.tabulate_dof_coordinates().tolist()}
try:
    helper.read_function("series.xdmf", time=0.3)
except ValueError as error:
    out["wrong time"] = str(error)
print(json.dumps(out))
""", tmp_path)
    assert got["f.xdmf"]["nodes"] == len(field3) and got["f.xdmf"]["cells"] == len(field3.faces)
    assert got["u3.xdmf"]["nodes"] == len(interior3.points) and got["u3.xdmf"]["cells"] == len(interior3.cells)
    for name, time, expected in (("u3.xdmf", None, interior3), ("series.xdmf", 0.0, steps[0]),
                                 ("series.xdmf", 0.25, steps[1])):
        read = got[name][str(time)]
        dim = expected.dim
        # Each dof's value is the displacement of the node of `expected` at the dof's position.
        positions = np.array(read["dof_x"])[:, :dim]
        nearest = np.argmin(((positions[:, None, :] - expected.points[None, :, :]) ** 2).sum(axis=2), axis=1)
        assert np.abs(positions - expected.points[nearest]).max() < 1e-12
        assert np.abs(np.array(read["u"]) - expected.displacement[nearest]).max() < 1e-12
    assert "time: 0.3 is not a time of series.xdmf: use one of 0, 0.25" in got["wrong time"]


def test_paraview_reads_the_arrays(tmp_path):
    require_client(shutil.which("pvpython") is not None, "ParaView (pvpython, python3-paraview)")
    field, interior = affine_interior()
    mm.write_interior(tmp_path / "u.vtu", interior, dt=2.0)
    mm.write_interior(tmp_path / "u.xdmf", interior)
    mm.write_field(tmp_path / "f.vtu", field)
    got = run_client(["pvpython"], """
        import json
        from paraview import servermanager
        from paraview.simple import OpenDataFile, XDMFReader
        from vtk.util.numpy_support import vtk_to_numpy

        out = {}
        for name in ("u.vtu", "u.xdmf", "f.vtu"):
            # VTK files with the reader File > Open picks; XDMF with the "XDMF Reader": Debian 12's
            # ParaView 5.11 Xdmf3 readers abort on HDF5-backed XDMF (dolfinx's own files too).
            source = XDMFReader(FileNames=[name]) if name.endswith(".xdmf") else OpenDataFile(name)
            source.UpdatePipeline()
            data = servermanager.Fetch(source)
            if data.IsA("vtkMultiBlockDataSet"):
                data = data.GetBlock(0)
            arrays = data.GetPointData()
            out[name] = {"points": vtk_to_numpy(data.GetPoints().GetData()).tolist(), "cells": data.GetNumberOfCells(),
                         **{arrays.GetArrayName(k): vtk_to_numpy(arrays.GetArray(k)).tolist()
                            for k in range(arrays.GetNumberOfArrays())}}
        print(json.dumps(out))
    """, tmp_path)
    for name in ("u.vtu", "u.xdmf"):
        assert got[name]["cells"] == len(interior.cells)
        assert np.allclose(np.array(got[name]["points"])[:, :2], interior.points)
        assert np.allclose(np.array(got[name]["displacement"])[:, :2], interior.displacement)
    assert np.allclose(np.array(got["u.vtu"]["velocity"])[:, :2], interior.displacement / 2.0)
    assert np.allclose(np.array(got["f.vtu"]["displacement"])[:, :2], field.vectors)
    assert got["f.vtu"]["valid"] == [1] * len(field)


def test_vtp_boundary_fields_open_in_vtk_and_paraview(tmp_path):
    import importlib.util

    require_client(importlib.util.find_spec("vtk") is not None, "VTK (pip install vtk, the .vtp writer)")
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    field, _ = affine_interior()
    s1 = trimesh.creation.icosphere(2)
    field3 = mm.map_surfaces(s1, s1.copy().apply_scale(1.5), "normal")
    mm.write_field(tmp_path / "f.vtp", field, dt=0.5)
    mm.write_field(tmp_path / "f3.vtp", field3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.vtp", "f3.vtp"]  # nothing left behind
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "f3.vtp"))
    reader.Update()
    poly = reader.GetOutput()
    assert np.allclose(vtk_to_numpy(poly.GetPoints().GetData()), field3.starts)
    assert np.array_equal(vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3), field3.faces)
    assert np.allclose(vtk_to_numpy(poly.GetPointData().GetArray("displacement")), field3.vectors)
    with pytest.raises(ValueError, match="path: unknown format '.vtp'"):
        mm.write_interior(tmp_path / "u.vtp", mm.extend_field(field, mesh_size=0.3))

    require_client(shutil.which("pvpython") is not None, "ParaView (pvpython, python3-paraview)")
    got = run_client(["pvpython"], """
        import json
        from paraview import servermanager
        from paraview.simple import OpenDataFile
        from vtk.util.numpy_support import vtk_to_numpy

        out = {}
        for name in ("f.vtp", "f3.vtp"):
            source = OpenDataFile(name)
            source.UpdatePipeline()
            data = servermanager.Fetch(source)
            arrays = data.GetPointData()
            out[name] = {"points": vtk_to_numpy(data.GetPoints().GetData()).tolist(), "cells": data.GetNumberOfCells(),
                         **{arrays.GetArrayName(k): vtk_to_numpy(arrays.GetArray(k)).tolist()
                            for k in range(arrays.GetNumberOfArrays())}}
        print(json.dumps(out))
    """, tmp_path)
    assert got["f.vtp"]["cells"] == len(field) and got["f3.vtp"]["cells"] == len(field3.faces)
    assert np.allclose(np.array(got["f.vtp"]["points"])[:, :2], field.starts)
    assert np.allclose(np.array(got["f.vtp"]["displacement"])[:, :2], field.vectors)
    assert np.allclose(np.array(got["f.vtp"]["velocity"])[:, :2], field.vectors / 0.5)
    assert got["f.vtp"]["valid"] == [1] * len(field)
    assert np.allclose(np.array(got["f3.vtp"]["displacement"]), field3.vectors)


def paraview_command():
    """pvpython under a virtual X server of its own (ParaView's Debian build renders offscreen
    through X), or on the display there is where xvfb-run is missing: not on the display that
    pytest-xvfb shares with napari's Qt tests, where pvpython can abort creating its window
    (vtkXOpenGLRenderWindow::CreateAWindow)."""
    require_client(shutil.which("pvpython") is not None, "ParaView (pvpython, python3-paraview)")
    if shutil.which("xvfb-run") is not None:
        return ["xvfb-run", "-a", "-s", "-screen 0 640x480x24", "pvpython"]
    require_client(bool(os.environ.get("DISPLAY")), "a virtual X server for offscreen rendering (xvfb, xauth)")
    return ["pvpython"]


def test_paraview_warps_and_renders_every_file_kind(tmp_path):
    # Each file opened as File > Open does (OpenDataFile picks the reader), warped by its
    # displacement and rendered to a PNG; the PNG shows the mesh, not only the background.
    import matplotlib.image

    command = paraview_command()
    field, interior = affine_interior()
    s1 = trimesh.creation.icosphere(2)
    field3 = mm.map_surfaces(s1, s1.copy().apply_scale(1.3), "normal")
    interior3 = mm.extend_field(field3, mesh_size=0.3)
    steps = [interior, mm.extend_field(field, mesh=(interior.points, interior.cells), substeps=2)]
    written = {"u.vtu": lambda p: mm.write_interior(p, interior, dt=0.5),
               "u.xdmf": lambda p: mm.write_interior(p, interior, dt=0.5),
               "u3.xdmf": lambda p: mm.write_interior(p, interior3),
               "f.vtu": lambda p: mm.write_field(p, field),
               "f.xdmf": lambda p: mm.write_field(p, field),
               "f3.vtu": lambda p: mm.write_field(p, field3),
               "f3.xdmf": lambda p: mm.write_field(p, field3),
               "series.xdmf": lambda p: mm.io.write_interior_series(p, steps, [0.0, 0.25]),
               "series.pvd": lambda p: mm.io.write_interior_series(p, steps, [0.0, 0.25])}
    for name, write in written.items():
        write(tmp_path / name)
    got = run_client(command, f"""
        import json
        from paraview import servermanager
        from paraview.simple import (GetActiveViewOrCreate, OpenDataFile, ResetCamera, SaveScreenshot, Show,
                                     UpdatePipeline, WarpByVector)

        out = {{}}
        view = GetActiveViewOrCreate("RenderView")
        for name in {list(written)!r}:
            # The full path, as File > Open gives it (Debian's Xdmf3 readers misjoin a bare name).
            source = OpenDataFile({str(tmp_path)!r} + "/" + name)
            times = list(source.TimestepValues or [])
            source.UpdatePipeline(times[-1] if times else 0.0)
            arrays = source.PointData
            warp = WarpByVector(Input=source, Vectors=["POINTS", "displacement"])
            warp.UpdatePipeline(times[-1] if times else 0.0)
            components = arrays["displacement"].GetNumberOfComponents()
            method = sorted(arrays.keys())
            display = Show(warp, view)
            display.PointSize = 4  # a 2D boundary field is points
            ResetCamera(view)
            SaveScreenshot(name + ".png", view, ImageResolution=[320, 240])
            display.Visibility = 0
            out[name] = {{"reader": source.GetXMLName(), "times": times, "components": components,
                         "arrays": method, "bounds": warp.GetDataInformation().GetBounds()}}
        print(json.dumps(out))
    """, tmp_path)
    for name in written:
        assert got[name]["components"] == 3, name  # Warp By Vector's assertion
        image = matplotlib.image.imread(tmp_path / f"{name}.png")[..., :3]
        background = image[0, 0]
        drawn = np.abs(image - background).max(axis=2) > 0.05
        assert drawn.mean() > 0.01, f"{name}: {drawn.mean():.4f} of the pixels drawn"
    assert got["series.pvd"]["times"] == [0.0, 0.25] and got["series.xdmf"]["times"] == [0.0, 0.25]
    assert "method" in got["f.vtu"]["arrays"] and "velocity" in got["u.xdmf"]["arrays"]
    # Warped by the affine map's displacement: x reaches b_x + |A's first row| on the image of the
    # unit circle (its inscribed polygon a little less).
    for name in ("u.vtu", "u.xdmf", "f.vtu"):
        assert B2[0] + 0.99 * np.linalg.norm(A2[0]) < got[name]["bounds"][1] <= B2[0] + np.linalg.norm(A2[0]) + 1e-9
