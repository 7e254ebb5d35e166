"""Overlap area against shapely (exact grid polygons with shared edges and vertices included) and
the aligning similarity of the paper's Appendix A."""

import math

import numpy as np
import pytest

import morphomap as mm
from conftest import circle

shapely = pytest.importorskip("shapely")
from shapely.geometry import Polygon  # noqa: E402


def _shoelace(p):
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _reference(a, b):
    return Polygon(a).intersection(Polygon(b)).area


def _kidney(n):
    """A kidney-like blob with no rotational or mirror symmetry."""
    t = 2 * np.pi * np.arange(n) / n
    r = 1.0 + 0.25 * np.cos(t) - 0.3 * np.cos(2 * t - 0.4) + 0.08 * np.sin(3 * t)
    return np.column_stack([1.2 * r * np.cos(t), r * np.sin(t)])


def _grid_polygon(rng, span):
    """A simple star-shaped polygon with integer vertices (collinear runs and all)."""
    while True:
        points = np.unique(rng.integers(0, span, size=(rng.integers(3, 12), 2)), axis=0).astype(float)
        if len(points) < 3:
            continue
        centre = points.mean(axis=0) + rng.uniform(-0.01, 0.01, 2)
        p = points[np.argsort(np.arctan2(*(points - centre).T[::-1]))]
        if not mm.is_self_intersecting(p) and Polygon(p).area > 0:
            return p


def test_unit_squares():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert mm.overlap_area(square, square + [0.3, 0.4]) == pytest.approx(0.7 * 0.6, abs=1e-15)
    assert mm.overlap_area(square[::-1], square + [0.3, 0.4]) == pytest.approx(0.42, abs=1e-15)
    assert mm.overlap_area(square, square) == pytest.approx(1.0, abs=1e-15)
    assert mm.overlap_area(square, square + [1, 1]) == 0.0  # corners touch
    assert mm.overlap_area(square, square + [1, 0]) == 0.0  # edges touch
    assert mm.overlap_area(square, square + [0.5, 0]) == pytest.approx(0.5, abs=1e-15)


def test_circle_with_itself(wobbly):
    c = circle(1000, radius=2.0, centre=(5.0, -3.0))
    assert mm.overlap_area(c, c) == pytest.approx(_shoelace(c), abs=1e-12)
    assert mm.overlap_area(wobbly, wobbly[::-1]) == pytest.approx(_shoelace(wobbly), abs=1e-12)


def test_regular_polygons_against_shapely(rng):
    for trial in range(100):
        n, m = 3 + trial % 37, 3 + (7 * trial) % 53
        a = circle(n, radius=rng.uniform(0.5, 1.5), centre=rng.uniform(-1, 1, 2))
        b = circle(m, radius=rng.uniform(0.5, 1.5), centre=rng.uniform(-1, 1, 2))
        b = b @ np.array([[0.6, -0.8], [0.8, 0.6]])
        assert mm.overlap_area(a, b) == pytest.approx(_reference(a, b), abs=1e-12)


def test_disjoint_and_nested():
    a = circle(64)
    assert mm.overlap_area(a, circle(40, 0.5, (3.0, 0.0))) == 0.0
    inner = circle(40, 0.5, (0.2, 0.1))
    assert mm.overlap_area(a, inner) == pytest.approx(_shoelace(inner), abs=1e-14)
    assert mm.overlap_area(inner[::-1], a) == pytest.approx(_shoelace(inner), abs=1e-14)


def test_star_and_circle(wobbly):
    for shift in (0.0, 0.4, 1.1):
        c = circle(2000, 1.05, (shift, 0.2))
        assert mm.overlap_area(wobbly, c) == pytest.approx(_reference(wobbly, c), abs=1e-12)


def test_grid_polygons_against_shapely():
    """Integer vertices: shared edges, shared vertices, vertices on edges, touching corners."""
    rng = np.random.default_rng(7)
    for trial in range(1500):
        span = int(rng.integers(3, 8))
        a = _grid_polygon(rng, span)
        kind = trial % 4
        if kind == 0:
            b = a + rng.integers(-2, 3, size=2)
        elif kind == 1:
            b = _grid_polygon(rng, span)
        elif kind == 2:
            b = np.column_stack([-a[:, 1], a[:, 0]]) + rng.integers(0, 6, size=2)
        else:
            b = a[:, ::-1].copy()
        if rng.random() < 0.5:
            b = b[::-1]
        b = np.roll(b, int(rng.integers(0, len(b))), axis=0)
        expected = _reference(a, b)
        assert mm.overlap_area(a, b) == pytest.approx(expected, abs=1e-12)
        assert mm.overlap_area(b, a) == pytest.approx(expected, abs=1e-12)


def test_similarity_round_trip(rng):
    s = mm.Similarity(centre=[0.3, -1.2], scale=1.7, angle=2.1, translation=[-4.0, 0.5])
    p = rng.normal(size=(50, 2))
    np.testing.assert_allclose(s.apply_inverse(s.apply(p)), p, atol=1e-13)
    np.testing.assert_allclose(s.apply(s.apply_inverse(p)), p, atol=1e-13)
    np.testing.assert_allclose(s.apply([[0.3, -1.2]]), [[-3.7, -0.7]], atol=1e-15)
    with pytest.raises(Exception):
        s.scale = 2.0  # frozen
    with pytest.raises(ValueError):
        s.centre[0] = 1.0  # read-only
    with pytest.raises(ValueError, match="scale"):
        mm.Similarity([0, 0], 0.0, 0.0, [0, 0]).apply_inverse(p)


def test_align_closed_recovers_a_similarity():
    c1 = _kidney(1000)
    shift = np.array([0.16, -0.12]) * math.sqrt(_shoelace(c1))  # 0.2 of the size
    truth = mm.Similarity(centre=[0.1, 0.05], scale=1.3, angle=math.radians(23.7), translation=shift)
    c2 = truth.apply(c1)
    size2 = math.sqrt(_shoelace(c2))
    for target in (c2, c2[::-1]):
        found = mm.align_curves(c1, target)
        assert isinstance(found, mm.Similarity)
        assert np.max(np.linalg.norm(found.apply(c1) - c2, axis=1)) / size2 < 1e-3
        assert found.scale == pytest.approx(1.3, abs=1e-12)
        assert math.degrees(found.angle) == pytest.approx(23.7, abs=0.01)
    # The moved curve overlaps C2 almost entirely.
    assert mm.overlap_area(found.apply(c1), c2) == pytest.approx(_shoelace(c2), rel=1e-5)


def test_align_open_end_points():
    t = np.linspace(0, 3, 40)
    c1 = np.column_stack([t, np.sin(2 * t)])
    u = np.linspace(0, 1, 25)
    c2 = np.column_stack([5 + np.cos(u), -2 + 7 * u])
    found = mm.align_curves(c1, c2, closed=False)
    moved = found.apply(c1)
    np.testing.assert_allclose(moved[[0, -1]], c2[[0, -1]], atol=1e-12, rtol=0)


def test_bad_input():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    with pytest.raises(ValueError, match="^a:"):
        mm.overlap_area([[0, 0], [1, 0]], square)
    with pytest.raises(ValueError, match="^b:"):
        mm.overlap_area(square, [[0, 0], [1, 0], [2, 0]])  # zero area
    with pytest.raises(ValueError, match="^b:"):
        mm.overlap_area(square, [[0, 0], [np.nan, 0], [2, 1]])
    with pytest.raises(ValueError, match="^c2:"):
        mm.align_curves(square, [[0, 0], [1, 1], [2, 2]])
    with pytest.raises(ValueError, match="^c1:"):
        mm.align_curves([[0, 0], [1, 1], [1, 0], [0, 1]], square)  # bow tie
    with pytest.raises(ValueError, match="^c1:"):
        mm.align_curves([[0, 0], [1, 1], [0, 0]], square, closed=False)  # end points coincide
    with pytest.raises(ValueError, match="^c2:"):
        mm.align_curves(square, [[0, 0], [1, 1], [0, 0]], closed=False)
    with pytest.raises(ValueError, match="^tolerance:"):
        mm.align_curves(square, square, tolerance=0.0)
    with pytest.raises(TypeError, match="^tolerance:"):
        mm.align_curves(square, square, tolerance="small")
    with pytest.raises(TypeError, match="^closed:"):
        mm.align_curves(square, square, closed=1)
