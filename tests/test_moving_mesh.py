"""One solver mesh carried through a series: map_series(interior=...), Series.extend, extend_series."""

import os

import numpy as np
import pytest
import trimesh

import morphomap as mm
from morphomap.examples.growing_frames import frames, surfaces
from morphomap.extend import measure_ratios
from morphomap.io.fenicsx import read_point_data, read_times
from morphomap.moving_mesh import boundary_nodes, min_angles
from conftest import SHARED_CASES, require_cases

LIMB = SHARED_CASES / "limb-bud" / "2d"


def _circle(radius, count=160):
    t = 2 * np.pi * np.arange(count) / count
    return radius * np.column_stack([np.cos(t), np.sin(t)])


def test_min_angles_of_regular_cells():
    triangle = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    assert min_angles(triangle, [[0, 1, 2]]) == pytest.approx([60.0])
    right = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    assert min_angles(right, [[0, 1, 2]]) == pytest.approx([45.0])
    tetrahedron = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], dtype=float)
    assert min_angles(tetrahedron, [[0, 1, 2, 3]]) == pytest.approx([np.degrees(np.arccos(1 / 3))])
    corner = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)  # dihedral angles 90 and 54.7
    assert min_angles(corner, [[0, 1, 2, 3]]) == pytest.approx([np.degrees(np.arccos(1 / np.sqrt(3)))])
    flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    assert min_angles(flat, [[0, 1, 2, 3]]) == pytest.approx([0.0], abs=1e-6)


def test_boundary_nodes_of_a_square_of_two_triangles_and_a_fan():
    assert boundary_nodes([[0, 1, 2], [0, 2, 3]]).tolist() == [0, 1, 2, 3]
    fan = [[4, i, (i + 1) % 4] for i in range(4)]  # node 4 in the middle
    assert boundary_nodes(fan).tolist() == [0, 1, 2, 3]


@pytest.mark.parametrize("dim", [2, 3])
def test_uniform_growth_moves_the_mesh_by_the_same_scaling(dim):
    # Truth: concentric circles (spheres) scaled by 1.1 per frame, each field the exact scaling of
    # its start points. The boundary map is linear between them, so the harmonic extension is the
    # scaling itself: every node of frame k sits at 1.1^k times its place at frame 0.
    scale = 1.1
    if dim == 2:
        shapes = [_circle(scale ** k) for k in range(4)]
        fields = [mm.DisplacementField(a, b, "normal", source=a) for a, b in zip(shapes, shapes[1:])]
    else:
        sphere = trimesh.creation.icosphere(2)
        shapes = [(sphere.vertices * scale ** k, sphere.faces) for k in range(4)]
        fields = [mm.DisplacementField(a[0], b[0], "normal", sphere.faces) for a, b in zip(shapes, shapes[1:])]
    moving = mm.extend_series(fields, frames=shapes)
    assert isinstance(moving, mm.MovingMesh) and len(moving.steps) == 3
    start = moving.points(0)
    for k in range(4):
        np.testing.assert_allclose(moving.points(k), start * scale ** k, atol=1e-9)
    for q in moving.quality:
        assert q.inverted == 0 and q.min_jacobian == pytest.approx(scale ** dim, rel=1e-9)
        # A scaling keeps every angle.
        assert q.min_angle == pytest.approx(min_angles(start, moving.cells).min(), rel=1e-9)


def test_map_series_sets_the_mesh_quality_of_its_rows():
    series = mm.map_series(frames(3), reseed=None, interior=True)
    assert isinstance(series.interior, mm.MovingMesh)
    assert [row.mesh for row in series.quality] == series.interior.quality


@pytest.mark.parametrize("dim", [2, 3])
def test_a_budding_series_keeps_the_mesh_on_the_frames_and_untangled(dim):
    shapes = frames(8) if dim == 2 else surfaces(8)
    series = mm.map_series(shapes, reseed=None, interior=True)
    moving = series.interior
    cells = moving.cells
    nodes = boundary_nodes(cells)
    size = 2 * (1 + 0.08 * 7 + 0.25 * 7)  # the last frame's extent
    for k, step in enumerate(moving.steps):
        assert step.cells is cells or np.array_equal(step.cells, cells)
        assert measure_ratios(step.points, cells, step.displacement).min() > 0
        np.testing.assert_array_equal(step.points + step.displacement, moving.points(k + 1))
        # The boundary stays on the frames: without moving the ends onto frame k + 1 the chords'
        # offsets add up (2% of the size by the sixth 3D step, which extend_field then refuses).
        assert moving.quality[k].boundary_distance < 2e-3 * size
    last = series.frames[-1]
    if dim == 2:
        off = mm.closest_points(moving.points(-1)[nodes], last).distances
    else:
        off = mm.SurfaceIndex(last.vertices, last.faces).closest_points(moving.points(-1)[nodes]).distances
    assert off.max() < 2e-3 * size


def test_write_gives_the_mesh_quality_and_files_dolfinx_reads(tmp_path):
    series = mm.map_series(frames(4), dt=0.5, reseed=None, interior=True)
    paths = series.write(tmp_path, figures=False)
    names = {os.path.basename(p) for p in paths}
    assert {"interior.xdmf", "interior.h5", "interior.pvd", "interior_0000.vtu", "interior_0002.vtu"} <= names
    lines = (tmp_path / "quality.csv").read_text().splitlines()
    assert lines[0].endswith(",inverted,min_jacobian,min_angle,boundary_distance,substeps,untangled")
    for line, q in zip(lines[1:], series.quality):
        values = line.split(",")
        assert int(values[-6]) == q.mesh.inverted == 0
        assert float(values[-4]) == q.mesh.min_angle
    assert read_times(tmp_path / "interior.xdmf") == [0.0, 0.5, 1.0]
    for k, step in enumerate(series.interior.steps):
        np.testing.assert_array_equal(read_point_data(tmp_path / "interior.xdmf", time=0.5 * k)[:, :2],
                                      step.displacement)


def test_the_solvers_own_mesh_is_carried_and_checked():
    shapes = frames(3)
    made = mm.extend_field(mm.map_curves(shapes[0], shapes[1]))
    series = mm.map_series(shapes, reseed=None, interior=(made.points, made.cells))
    np.testing.assert_array_equal(series.interior.points(0), made.points)
    with pytest.raises(ValueError, match=r"fields\[0\]: mesh: .*units"):
        mm.map_series(shapes, reseed=None, interior=(made.points * 100, made.cells))


def test_bad_arguments_are_named():
    shapes = frames(3)
    with pytest.raises(TypeError, match="interior"):
        mm.map_series(shapes, interior="yes")
    series = mm.map_series(shapes, reseed=None)
    assert series.interior is None and series.quality[0].mesh is None
    with pytest.raises(TypeError, match="fields"):
        mm.extend_series([])
    with pytest.raises(ValueError, match="frames: expected 3"):
        mm.extend_series(series.fields, frames=shapes[:2])
    moving = series.extend()
    with pytest.raises(ValueError, match="frame"):
        moving.points(3)
    with pytest.raises(TypeError, match="frame"):
        moving.points(1.0)


def test_limb_bud_hourly_outlines_carry_one_mesh_without_inverted_cells():
    require_cases(LIMB)
    frames_read = [mm.read_curve(LIMB / f"limb_h{h}.csv") for h in range(300, 311)]
    series = mm.map_series(frames_read, reseed=None, interior=True)
    for q in series.quality:
        assert q.mesh.inverted == 0 and q.mesh.min_jacobian > 0
        assert q.mesh.boundary_distance < 1e-9
        assert q.mesh.min_angle > 1.0


@pytest.mark.parametrize("hours", [(268, 278), (288, 298), (298, 308), (338, 348)])
def test_limb_bud_corner_triangles_get_a_free_node(hours):
    # Where the outline meets its flank segment, a triangle of the mesh made for the extension had
    # its three corners on C1; the boundary field brings them into line and no interior solve could
    # help. Each such triangle is split, so extend_field clears these pairs by default.
    require_cases(LIMB)
    c1, c2 = (mm.make_simple(mm.read_curve(LIMB / f"limb_h{h}.csv"))[0] for h in hours)
    interior = mm.extend_field(mm.map_curves(c1, c2))
    assert interior.inverted == 0
    on_boundary = np.zeros(len(interior.points), dtype=bool)
    on_boundary[boundary_nodes(interior.cells)] = True
    assert not on_boundary[interior.cells].all(axis=1).any()


def test_series_command_carries_a_mesh(tmp_path):
    import meshio

    from conftest import morphomap

    shapes = frames(3)
    paths = []
    for k, shape in enumerate(shapes):
        paths.append(str(tmp_path / f"f{k}.csv"))
        mm.write_curve(paths[-1], shape)
    done = morphomap("series", *paths, "--interior", "--out", str(tmp_path / "out"), "--no-progress")
    assert done.returncode == 0, done.stderr
    assert "mesh: 0 inverted" in done.stderr
    assert (tmp_path / "out" / "interior.pvd").exists() and (tmp_path / "out" / "interior.xdmf").exists()
    made = mm.extend_field(mm.map_curves(shapes[0], shapes[1]))
    meshio.write(tmp_path / "solver.vtu", meshio.Mesh(made.points, [("triangle", made.cells)]))
    done = morphomap("series", *paths, "--interior", "--mesh", str(tmp_path / "solver.vtu"), "--out",
                     str(tmp_path / "own"), "--no-progress")
    assert done.returncode == 0, done.stderr
    np.testing.assert_allclose(read_point_data(tmp_path / "own" / "interior.xdmf", time=0.0)[:, :2],
                               mm.map_series(shapes, interior=(made.points, made.cells)).interior.steps[0].displacement)
    done = morphomap("series", *paths, "--mesh", str(tmp_path / "solver.vtu"), "--out", str(tmp_path / "x"))
    assert done.returncode == 2 and "--mesh: only with --interior" in done.stderr
