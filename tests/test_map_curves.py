"""2D mapping against closed-form answers and the paper's figures."""

import numpy as np
import pytest

import morphomap as mm
from conftest import circle, ellipse


def ray_ellipse(origins, directions, a, b):
    """Nearest intersection (either direction) of lines with the ellipse x^2/a^2 + y^2/b^2 = 1."""
    ox, oy = origins.T
    ux, uy = directions.T
    qa = ux**2 / a**2 + uy**2 / b**2
    qb = 2 * (ox * ux / a**2 + oy * uy / b**2)
    qc = ox**2 / a**2 + oy**2 / b**2 - 1
    root = np.sqrt(qb**2 - 4 * qa * qc)
    roots = np.stack([(-qb + root) / (2 * qa), (-qb - root) / (2 * qa)])
    t = roots[np.argmin(np.abs(roots), axis=0), np.arange(len(ox))]
    return origins + t[:, None] * directions


def test_normal_mapping_of_circle_in_ellipse_hits_the_analytic_ellipse():
    a, b, n2 = 2.177, 1.0, 20000
    c1, c2 = circle(100, 0.95), ellipse(n2, a, b)
    field = mm.map_curves(c1, c2, "normal")
    assert np.array_equal(field.starts, c1) and field.valid.all()
    assert set(field.method) == {"normal"}
    radial = c1 / np.hypot(c1[:, 0], c1[:, 1])[:, None]  # the normals of a regular polygon's vertices
    expected = ray_ellipse(c1, radial, a, b)
    # Polyline error: the sagitta of chords of length <= a * 2 pi / n2 at curvature <= a / b^2,
    # over the cosine between ray and ellipse normal (>= 0.3 here).
    sagitta = (a * 2 * np.pi / n2) ** 2 * (a / b**2) / 8
    error = np.hypot(*(field.ends - expected).T).max()
    assert error <= sagitta / 0.3
    assert np.allclose(np.hypot(field.ends[:, 0] / a, field.ends[:, 1] / b), 1.0, atol=sagitta)


def test_minimal_distance_equals_brute_force():
    c1, c2 = circle(100, 0.95), ellipse(3000, 2.177, 1.0)
    field = mm.map_curves(c1, c2, "minimal_distance")
    # Brute force: every segment of C2.
    a, e = c2, np.roll(c2, -1, axis=0) - c2
    for start, end in zip(field.starts, field.ends):
        t = np.clip(((start - a) * e).sum(axis=1) / (e * e).sum(axis=1), 0, 1)
        d = np.hypot(*(a + t[:, None] * e - start).T)
        assert abs(np.hypot(*(end - start)) - d.min()) <= 1e-12


def protrusion_pair():
    """Figure 6: a straight line C1 and a line C2 with a tall protrusion between A and B."""
    x = np.linspace(-3, 3, 121)
    c1 = np.column_stack([x, np.zeros_like(x)])
    left = np.column_stack([np.linspace(-3, -0.5, 51), np.ones(51)])
    up = np.column_stack([np.full(40, -0.5), np.linspace(1, 3, 41)[1:]])
    top = np.column_stack([np.linspace(-0.5, 0.5, 21)[1:], np.full(20, 3.0)])
    down = np.column_stack([np.full(40, 0.5), np.linspace(3, 1, 41)[1:]])
    right = np.column_stack([np.linspace(0.5, 3, 51)[1:], np.ones(50)])
    return c1, np.vstack([left, up, top, down, right])


def test_figure6_minimal_distance_misses_the_protrusion_and_reverse_covers_it():
    c1, c2 = protrusion_pair()
    forward = mm.map_curves(c1, c2, "minimal_distance", closed=False)
    assert (forward.ends[:, 1] <= 1.0 + 1e-12).all()  # no end point above A-B
    backward = mm.map_curves(c1, c2, "minimal_distance", closed=False, reverse=True)
    assert len(backward) == len(c2)
    assert np.allclose(backward.ends, c2)  # every point of C2, the protrusion too, is reached
    assert (np.abs(backward.starts[:, 1]) <= 1e-12).all()  # starts on C1


def test_figure7_normal_mapping_crosses_and_reverse_normal_does_not():
    theta = np.linspace(-1.0, 1.0, 41)
    c1 = np.column_stack([np.sin(theta), 1 - np.cos(theta)])  # concave towards C2
    # Alike, but far: beyond the centre of curvature (0, 1) of C1, where its normals meet.
    c2 = np.column_stack([2 * np.sin(theta), 5 - 2 * np.cos(theta)])
    forward = mm.map_curves(c1, c2, "normal", closed=False)
    backward = mm.map_curves(c1, c2, "normal", closed=False, reverse=True)
    valid = int(forward.valid.sum())
    assert valid > 15 and mm.count_crossings(forward.starts, forward.ends) == valid * (valid - 1) // 2
    assert mm.count_crossings(backward.starts, backward.ends) == 0
    assert backward.valid.sum() >= 5


def test_transform_recovers_a_similarity():
    t = 2 * np.pi * np.arange(300) / 300
    r = 1 + 0.25 * np.cos(t) + 0.15 * np.sin(2 * t) + 0.08 * np.cos(3 * t + 0.4)  # no symmetry
    c1 = np.column_stack([r * np.cos(t), r * np.sin(t)])
    angle, scale, shift = np.radians(20), 1.3, np.array([0.25, -0.1])
    rot = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    c2 = scale * c1 @ rot.T + shift
    # split=False: the aligned C1 lies on C2 and crosses it at rounding level everywhere.
    field = mm.map_curves(c1, c2, "normal", transform=True, split=False)
    size = np.sqrt(abs(mm.signed_area(c2)))
    assert np.allclose(field.starts, c1, atol=1e-12)  # carried back onto the original C1
    assert np.hypot(*(field.ends - c2).T).max() <= 1e-3 * size


def test_split_ellipses_fix_the_intersections_and_do_not_cross():
    c1, c2 = ellipse(400, 2.0, 1.0), ellipse(400, 1.0, 2.0)
    # Normal mapping is left out: C1's normals near (+-2, 0) meet at its centres of curvature
    # (+-1.5, 0) before they reach C2, so they cross with or without the split.
    assert len(mm.map_curves(c1, c2, "normal", split=True)) == 404
    for method in ("minimal_distance", "uniform"):
        field = mm.map_curves(c1, c2, method, split=True)
        assert len(field) == 404
        fixed = field.starts[np.all(field.starts == field.ends, axis=1)]
        assert len(fixed) == 4
        assert np.allclose(np.abs(fixed), 2 / np.sqrt(5), atol=1e-4)  # polyline vs ellipse
        assert mm.count_crossings(field.starts, field.ends) == 0, method
        assert field.valid.all()


def test_uniform_open_curves_keep_end_points_and_proportions():
    c1 = np.column_stack([np.linspace(0, 1, 11), np.zeros(11)])
    c2 = np.column_stack([np.linspace(0, 3, 7), np.ones(7)])
    field = mm.map_curves(c1, c2, "uniform", closed=False)
    assert np.allclose(field.ends, np.column_stack([np.linspace(0, 3, 11), np.ones(11)]), atol=1e-14)


def test_uniform_closed_best_shift_and_anchor():
    c1 = circle(64, 1.0)
    c2 = np.roll(circle(64, 2.0), 5, axis=0)  # the same circle starting elsewhere
    field = mm.map_curves(c1, c2, "uniform")
    assert np.allclose(field.ends, 2 * c1, atol=1e-12)  # radial: the shift that minimises sum d^2
    anchored = mm.map_curves(c1, c2, "uniform", anchor=c1[3])
    partner = mm.closest_points(c1[3:4], c2).points[0]  # the anchor's partner on C2
    assert np.allclose(anchored.ends[3], partner, atol=1e-12)
    steps = np.hypot(*np.diff(anchored.ends, axis=0).T)
    assert np.allclose(steps, steps[0], rtol=0, atol=1e-12)  # equal arcs, the same offset on each edge
    clockwise = mm.map_curves(c1, c2[::-1], "uniform")  # opposite orientation is followed
    assert np.allclose(clockwise.ends, 2 * c1, atol=1e-12)


def test_n_resamples_both_curves():
    field = mm.map_curves(circle(10, 1.0), ellipse(500, 2.0, 1.5), "normal", n=50)
    assert len(field) == 50
    assert np.allclose(np.hypot(*field.starts.T), 1.0, atol=1 - np.cos(np.pi / 10))


def test_reverse_vectors_start_on_c1_in_c2_order():
    c1, c2 = circle(50, 1.0), ellipse(80, 2.0, 1.5)
    field = mm.map_curves(c1, c2, "minimal_distance", reverse=True)
    assert len(field) == 80 and np.allclose(field.ends, c2)
    assert np.allclose(np.hypot(*field.starts.T), 1.0, atol=1 - np.cos(np.pi / 50))


def test_bad_arguments_are_named():
    c = circle(10)
    with pytest.raises(ValueError, match="method: expected one of"):
        mm.map_curves(c, c, "closest")
    with pytest.raises(ValueError, match="c2: row 1 has a non-finite"):
        mm.map_curves(c, np.where(np.arange(10)[:, None] == 1, np.nan, c), "normal")
    with pytest.raises(ValueError, match="c1: the closed curve encloses zero area"):
        mm.map_curves([[0, 0], [1, 0], [2, 0]], c, "normal")
    with pytest.raises(ValueError, match="anchor: expected 2 coordinates"):
        mm.map_curves(c, 2 * c, "uniform", anchor=[1, 2, 3])
    with pytest.raises(TypeError, match="n: expected an integer"):
        mm.map_curves(c, c, "normal", n=2.5)
