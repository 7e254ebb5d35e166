"""The field anywhere on its source boundary, against exact answers."""

import numpy as np
import pytest
import trimesh

import morphomap as mm
from conftest import circle


@pytest.mark.parametrize(
    "method, options",
    [("auto", {}), ("normal", {"reverse": True}), ("diffusion", {"reverse": True}), ("uniform", {}),
     ("minimal_distance", {}), ("auto", {"n": 300})],
)
def test_exact_at_the_start_points_whatever_the_order(method, options):
    # Reverse normal vectors come in C2's order and cross: at() does not rely on the order.
    c1, c2 = mm.load_example("kidney")
    field = mm.map_curves(c1, c2, method, **options)
    valid = field.valid
    assert np.abs(field.at(field.starts[valid]) - field.vectors[valid]).max() < 1e-9


def test_affine_map_of_a_polygon_is_exact_between_the_starts():
    # Starts at the polygon's vertices, ends an affine image: arc length is linear along each
    # side, so the interpolation is the affine map itself.
    c1 = np.array([[0.0, 0], [3, 0], [3, 1], [1, 2], [0, 1.5]])
    A, b = np.array([[1.2, 0.3], [-0.2, 0.9]]), np.array([0.5, -1.0])
    field = mm.DisplacementField(c1, c1 @ A.T + b, "normal", source=c1)
    t = np.random.default_rng(2).random(200)
    side = np.random.default_rng(3).integers(0, 5, 200)
    points = c1[side] + t[:, None] * (np.roll(c1, -1, axis=0)[side] - c1[side])
    expected = points @ A.T + b - points
    assert np.abs(field.at(points) - expected).max() < 1e-12


def test_concentric_circles_give_the_radial_field():
    # Normal mapping between circles r = 1 and 2: u = x at the starts; between them the chord
    # interpolation is second order in the spacing.
    c1, c2 = circle(400, 1.0), circle(400, 2.0)
    field = mm.map_curves(c1, c2, "normal")
    t = np.random.default_rng(4).uniform(0, 2 * np.pi, 500)
    points = np.column_stack([np.cos(t), np.sin(t)])
    displacements, distances = field.at(points, return_distances=True)
    assert np.abs(displacements - points).max() < 2e-4
    assert distances.max() < 1.5e-4  # the points are on the circle, C1 is its 400-gon
    # Off the curve: projected, the distance said.
    _, far = field.at(1.5 * points[:5], return_distances=True)
    assert np.allclose(far, 0.5, atol=1e-3)


def test_open_curves_and_fields_from_files(tmp_path):
    c1 = np.column_stack([np.linspace(0, 1, 11), np.zeros(11)])
    ends = c1 + [[0.0, 1.0]] + c1[:, :1] * [[1.0, 0.0]]  # u = (x, 1)
    field = mm.DisplacementField(c1[2:9], ends[2:9], "normal", source=c1, closed=False)
    # Beyond the first and last start of an open curve: their vectors.
    got = field.at([[0.0, 0.0], [0.55, 0.0], [1.0, 0.0]])
    assert np.allclose(got, [[0.2, 1.0], [0.55, 1.0], [0.8, 1.0]])
    mm.write_field(tmp_path / "f.csv", field)
    back = mm.read_field(tmp_path / "f.csv")
    with pytest.raises(ValueError, match="source: this field does not know the curve"):
        back.at([[0.5, 0.0]])
    assert np.allclose(back.at([[0.55, 0.0]], source=c1, closed=False), [[0.55, 1.0]])
    with pytest.raises(ValueError, match="points"):
        field.at([[np.nan, 0.0]])


def test_surfaces_barycentric_and_exact():
    s1 = trimesh.creation.icosphere(3)
    field = mm.map_surfaces(s1, s1.copy().apply_scale(1.3), "normal")
    assert np.abs(field.at(field.starts) - field.vectors).max() < 1e-12
    # An affine field over the start triangles is reproduced exactly inside them.
    A, b = np.array([[1.1, 0.2, 0.0], [0.0, 0.9, 0.1], [0.3, 0.0, 1.2]]), np.array([0.1, 0.2, -0.3])
    affine = mm.DisplacementField(s1.vertices, s1.vertices @ A.T + b, "normal", faces=s1.faces)
    weights = np.random.default_rng(5).dirichlet([1, 1, 1], len(s1.faces))
    points = np.einsum("fk,fkd->fd", weights, s1.vertices[s1.faces])
    displacements, distances = affine.at(points, return_distances=True)
    assert np.abs(displacements - (points @ A.T + b - points)).max() < 1e-12
    assert distances.max() < 1e-12
    # A corner without a target makes its triangles' answers NaN, and only theirs.
    ends = np.array(s1.vertices @ A.T + b)
    ends[0] = np.nan
    holed = mm.DisplacementField(s1.vertices, ends, "normal", faces=s1.faces)
    near = np.isin(s1.faces, [0]).any(axis=1)
    got = holed.at(s1.triangles_center)
    assert np.isnan(got[near]).all() and np.isfinite(got[~near]).all()
