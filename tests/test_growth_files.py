"""Growth kinematics written and drawn: the CSV table, per-step VTU surfaces that meshio and
ParaView open, heat maps with crosses, kymographs with units."""

import csv
import os

import matplotlib
import meshio
import numpy as np
import pytest
import trimesh

import morphomap as mm
from morphomap.examples.growing_frames import frames, surfaces
from morphomap.growth_plot import MAX_CROSSES, plot_growth_map, plot_kymograph, push_forward, write_growth
from test_solver_files import paraview_command, run_client

matplotlib.use("Agg")


def test_write_growth_3d_table_and_surfaces(tmp_path):
    series = mm.map_series(surfaces(3), reseed=None)
    paths = write_growth(series, tmp_path)
    assert {os.path.basename(p) for p in paths} == {
        "growth.csv", "growth_00.vtu", "growth_01.vtu", "growth.png"}
    found = mm.growth(series)
    with open(tmp_path / "growth.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == sum(len(c) for c in series.cells[:2])
    first = [r for r in rows if r["step"] == "1"]
    np.testing.assert_allclose([float(r["accumulated_areal_growth"]) for r in first],
                               found.accumulated[1].areal_growth, rtol=1e-15)
    np.testing.assert_allclose([float(r["anisotropy"]) for r in first], found.steps[1].anisotropy, rtol=1e-15)
    surface = meshio.read(tmp_path / "growth_01.vtu")
    np.testing.assert_allclose(surface.cell_data["accumulated_areal_growth"][0], found.accumulated[1].areal_growth)
    # The surface is frame 2 (the followed points there): its area is the accumulated growth's.
    area = trimesh.Trimesh(surface.points, surface.cells_dict["triangle"], process=False).area_faces
    before = found.accumulated[1]
    np.testing.assert_allclose(area / before.measure(), before.areal_growth, rtol=1e-9)
    major = surface.cell_data["major"][0]
    lengths = np.linalg.norm(major, axis=1)
    assert np.all((np.abs(lengths - 1) < 1e-9) | (lengths == 0))  # unit, or 0 where isotropic


def test_push_forward_carries_directions_by_the_linear_map():
    triangle = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    shear = np.array([[1.0, 0.5, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    directions = np.array([[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    moved = push_forward(triangle, triangle @ shear.T, directions)
    np.testing.assert_allclose(moved[0, 0], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(moved[0, 1], np.array([0.5, 2.0, 0.0]) / np.hypot(0.5, 2.0), atol=1e-12)


def test_heat_map_has_a_labelled_colour_bar_and_crosses_where_anisotropic():
    sphere = trimesh.creation.icosphere(3)
    vertices = np.asarray(sphere.vertices)
    g = mm.growth(mm.DisplacementField(vertices, vertices * [1, 1, 1.6], "normal", sphere.faces))
    ax = plot_growth_map(g, "anisotropy", unit="um")
    figure = ax.figure
    bar = figure.axes[-1]
    assert "anisotropy" in bar.get_ylabel() and ax.get_xlabel() == "x (µm)"
    figure.canvas.draw()  # a 3D collection has its (projected) segments once drawn
    crosses = ax.collections[-1]
    anisotropic = np.isfinite(g.directions).all(axis=(1, 2)).sum()
    assert len(crosses.get_segments()) == 2 * min(anisotropic, MAX_CROSSES)
    with pytest.raises(ValueError, match="quantity"):
        plot_growth_map(g, "volume")
    iso = mm.growth(mm.DisplacementField(vertices, vertices * 1.2, "normal", sphere.faces))
    assert len(plot_growth_map(iso).collections) == 1  # the triangles; no direction: no cross


def test_kymograph_rows_are_steps_and_axes_carry_units():
    series = mm.map_series(frames(4, points=160), dt=2.0)
    series.unit, series.time_unit = "um", "h"
    ax = plot_kymograph(series, "normal_velocity")
    assert ax.get_xlabel() == "position along the outline (µm)" and ax.get_ylabel() == "time (h)"
    assert ax.get_ylim() == (6.0, 0.0)  # time runs down, as in morphodynamics' kymographs
    meshes = ax.collections
    assert len(meshes) == 3
    found = mm.growth(series)
    np.testing.assert_allclose(meshes[1].get_array().ravel(), found.steps[1].normal_velocity)
    assert "µm/h" in ax.figure.axes[-1].get_ylabel()
    with pytest.raises(ValueError, match="anisotropy"):
        plot_kymograph(series, "anisotropy")
    with pytest.raises(ValueError, match="2D"):
        plot_kymograph(mm.map_series(surfaces(2)))


def test_paraview_opens_the_growth_surface_with_its_cell_data(tmp_path):
    command = paraview_command()
    series = mm.map_series(surfaces(3), reseed=None)
    write_growth(series, tmp_path, figures=False)
    got = run_client(command, f"""
        import json
        from paraview.simple import GetActiveViewOrCreate, OpenDataFile, ResetCamera, SaveScreenshot, Show, ColorBy

        view = GetActiveViewOrCreate("RenderView")
        source = OpenDataFile({str(tmp_path)!r} + "/growth_01.vtu")
        source.UpdatePipeline()
        display = Show(source, view)
        ColorBy(display, ("CELLS", "accumulated_areal_growth"))
        ResetCamera(view)
        SaveScreenshot("growth.png", view, ImageResolution=[320, 240])
        arrays = source.CellData
        print(json.dumps({{"arrays": sorted(arrays.keys()),
                          "range": arrays["accumulated_areal_growth"].GetRange(),
                          "major": arrays["major"].GetNumberOfComponents()}}))
    """, tmp_path)
    found = mm.growth(series).accumulated[1].areal_growth
    assert {"accumulated_areal_growth", "anisotropy", "major", "minor", "normal_velocity"} <= set(got["arrays"])
    assert got["range"] == pytest.approx([found.min(), found.max()])
    assert got["major"] == 3
    image = matplotlib.image.imread(tmp_path / "growth.png")[..., :3]
    assert (np.abs(image - image[0, 0]).max(axis=2) > 0.05).mean() > 0.01
