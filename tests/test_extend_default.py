"""extend_field and `morphomap extend` hand a solver no inverted cells unasked, and refuse a solver
mesh in other units than the boundaries."""

import meshio
import numpy as np
import pytest
from scipy.spatial import Delaunay

import morphomap as mm
from conftest import circle, morphomap
from morphomap.extend import measure_ratios


def growing_mask(k, size=200):
    """Frame k of a disc that grows two narrow buds, the second from frame 4 on: one solve of the
    harmonic extension inverts cells at the base of a new bud (frames 0 -> 1 and 3 -> 4)."""
    y, x = np.mgrid[0:size, 0:size]
    r, t = np.hypot(x - size / 2, y - size / 2), np.arctan2(y - size / 2, x - size / 2)

    def bud(at, length):
        return length * np.exp(-((t - at) ** 2) / (2 * 0.06 ** 2))

    return (r < 30 + 2 * k + bud(0.3, 12 * k) + bud(-2.0, 16 * max(k - 3, 0))).astype(np.uint8)


@pytest.mark.parametrize("k", [0, 3])
def test_the_default_leaves_no_inverted_cell_where_one_solve_does(k):
    c1, c2 = (mm.boundary_from_mask(growing_mask(j)) for j in (k, k + 1))
    field = mm.map_curves(c1, c2)
    once = mm.extend_field(field, substeps=1, untangle=False)
    assert once.inverted >= 1 and once.min_jacobian < 0  # what a single solve hands over
    interior = mm.extend_field(field)
    assert interior.inverted == 0 and interior.min_jacobian > 0
    assert (measure_ratios(interior.points, interior.cells, interior.displacement) > 0).all()
    # It says what it did: the single solve first, then more until none was inverted.
    assert interior.attempts[0][:3] == (1, False, once.inverted) and interior.attempts[-1][2] == 0
    assert (interior.substeps, interior.untangled) == interior.attempts[-1][:2] and interior.substeps > 1
    assert f"{interior.substeps} substeps" in repr(interior)


def test_the_command_line_extends_the_growing_frames_without_inverted_cells(tmp_path):
    for k in (0, 1, 3, 4):
        np.save(tmp_path / f"frame{k}.npy", growing_mask(k))
    for a, b in ((0, 1), (3, 4)):
        out = tmp_path / f"u{a}.xdmf"
        done = morphomap("extend", tmp_path / f"frame{a}.npy", tmp_path / f"frame{b}.npy", "-o", out)
        assert done.returncode == 0, done.stderr
        assert "0 inverted" in done.stderr and "substeps" in done.stderr
        assert "(tried 1 substep: " in done.stderr  # the report of what it tried
        mesh = meshio.read(out)
        cells = mesh.cells_dict["triangle"]
        ratios = measure_ratios(mesh.points[:, :2], cells, mesh.point_data["displacement"][:, :2])
        assert (ratios > 0).all()
    # Asked for one solve, it is written as solved, its inverted cells counted.
    done = morphomap("extend", tmp_path / "frame0.npy", tmp_path / "frame1.npy", "--substeps", "1",
                     "--no-untangle", "-o", tmp_path / "once.txt")
    assert done.returncode == 0 and "0 inverted" not in done.stderr, done.stderr


def test_a_folding_boundary_field_is_refused_with_the_count_and_where():
    # A mirror image: the boundary itself turns over, so no substeps or untangling can help.
    c1 = circle(60)
    field = mm.DisplacementField(c1, c1 * [-1.0, 1.0] + [0.1, 0.0], "normal", source=c1)
    with pytest.raises(mm.GeometryError,
                       match=r"extend_field: \d+ cells stay inverted by the motion .* centred at \(-?\d.*"
                             r"inverted cells per try: 1 substep: \d+, 4 substeps: (\d+|no solution).*"
                             r"pass substeps=K and untangle=True"):
        mm.extend_field(field, mesh_size=0.2)
    asked = mm.extend_field(field, mesh_size=0.2, substeps=1, untangle=True)
    assert asked.inverted > 0 and asked.attempts == ((1, True, asked.inverted, asked.min_jacobian),)


def disc_mesh(c1, scale=1.0):
    points = np.vstack([c1, 0.5 * c1, [[0.0, 0.0]]])
    return scale * points, Delaunay(points).simplices


def test_a_solver_mesh_in_other_units_is_refused():
    c1 = circle(80, radius=50.0)  # microns
    field = mm.DisplacementField(c1, 1.1 * c1, "normal", source=c1)
    assert mm.extend_field(field, mesh=disc_mesh(c1)).boundary_distance < 1e-9
    for scale in (1 / 0.65, 2.0):  # pixels of 0.65 microns; a mesh twice C1's size
        with pytest.raises(ValueError, match=r"mesh: its boundary nodes lie up to [\d.]+ from C1, which spans "
                                             r"141\.4 \(the mesh spans [\d.]+\): more than boundary_tolerance=0\.02 "
                                             r"of C1's size\. Are the mesh and the boundaries in the same units"):
            mm.extend_field(field, mesh=disc_mesh(c1, scale))
    # A solver's smooth outline a little off the polygon C1 passes.
    assert mm.extend_field(field, mesh=disc_mesh(c1, 1.005)).boundary_distance > 0
    with pytest.raises(ValueError, match="boundary_tolerance: expected a fraction > 0"):
        mm.extend_field(field, mesh=disc_mesh(c1), boundary_tolerance=0)


def test_the_command_line_refuses_a_mesh_in_pixels(tmp_path):
    c1 = circle(80, radius=50.0)
    mm.write_curve(tmp_path / "c1.csv", c1)
    mm.write_curve(tmp_path / "c2.csv", 1.1 * c1)
    points, cells = disc_mesh(c1, 1 / 0.65)
    meshio.write(tmp_path / "pixels.vtu", meshio.Mesh(np.column_stack([points, np.zeros(len(points))]),
                                                      [("triangle", cells)]))
    done = morphomap("extend", tmp_path / "c1.csv", tmp_path / "c2.csv", "--mesh", tmp_path / "pixels.vtu",
                     "-o", tmp_path / "u.xdmf")
    assert done.returncode == 2 and "same units" in done.stderr and not (tmp_path / "u.xdmf").exists()
    done = morphomap("extend", tmp_path / "c1.csv", tmp_path / "c2.csv", "-o", tmp_path / "u.vtk")
    assert done.returncode == 2 and "unknown format '.vtk'" in done.stderr and ".xdmf" in done.stderr
