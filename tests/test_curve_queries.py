"""Closest points and line intersections against brute force and closed-form answers."""

import numpy as np
import pytest

import morphomap as mm
from conftest import circle


def segments_of(curve, closed):
    a = curve if closed else curve[:-1]
    b = np.roll(curve, -1, axis=0) if closed else curve[1:]
    return a, b


def brute_closest(queries, curve, closed):
    """Closest point by checking every segment; ties go to the lowest segment."""
    a, b = segments_of(curve, closed)
    e = b - a
    lengths = np.hypot(e[:, 0], e[:, 1])
    starts = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    len2 = np.einsum("ij,ij->i", e, e)
    out = []
    for q in queries:
        t = np.where(len2 > 0, ((q - a) * e).sum(axis=1) / np.where(len2 > 0, len2, 1), 0.0)
        t = np.clip(t, 0.0, 1.0)
        p = a + t[:, None] * e
        d2 = ((q - p) ** 2).sum(axis=1)
        i = int(np.argmin(d2))
        out.append((p[i], np.sqrt(d2[i]), i, starts[i] + t[i] * lengths[i], np.sort(d2)[:2]))
    return out


def brute_line(origin, direction, curve, closed):
    """Nearest intersection of the whole line with every segment (non-parallel ones)."""
    a, b = segments_of(curve, closed)
    e = b - a
    lengths = np.hypot(e[:, 0], e[:, 1])
    starts = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    u = direction / np.hypot(*direction)
    w = a - origin
    denom = u[0] * e[:, 1] - u[1] * e[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (w[:, 0] * u[1] - w[:, 1] * u[0]) / denom
        t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / denom
    ok = (denom != 0) & (s >= 0) & (s <= 1)
    if not ok.any():
        return None
    idx = np.flatnonzero(ok)
    order = np.lexsort((idx, t[idx] < 0, np.abs(t[idx])))
    i = idx[order[0]]
    second = np.abs(t[idx[order[1]]]) if len(idx) > 1 else np.inf
    return a[i] + s[i] * e[i], t[i], i, starts[i] + s[i] * lengths[i], second - abs(t[i])


@pytest.mark.parametrize("closed", [True, False])
def test_closest_points_equal_brute_force(rng, wobbly, closed):
    queries = rng.uniform(-2, 2, size=(400, 2))
    hits = mm.closest_points(queries, wobbly, closed=closed)
    for k, (p, d, i, s, two) in enumerate(brute_closest(queries, wobbly, closed)):
        assert np.abs(hits.points[k] - p).max() <= 1e-12
        assert abs(hits.distances[k] - d) <= 1e-12
        assert abs(hits.arc_lengths[k] - s) <= 1e-12
        if two[1] - two[0] > 1e-12:  # a clear winner: the same segment
            assert hits.segments[k] == i


@pytest.mark.parametrize("closed", [True, False])
def test_line_intersections_equal_brute_force(rng, wobbly, closed):
    origins = rng.uniform(-1.5, 1.5, size=(400, 2))
    directions = rng.normal(size=(400, 2))
    hits = mm.line_intersections(origins, directions, wobbly, closed=closed)
    misses = 0
    for k in range(len(origins)):
        expected = brute_line(origins[k], directions[k], wobbly, closed)
        if expected is None:
            misses += 1
            assert np.isnan(hits.points[k]).all() and np.isnan(hits.distances[k]) and hits.segments[k] == -1
            continue
        p, t, i, s, margin = expected
        assert np.abs(hits.points[k] - p).max() <= 1e-12
        assert abs(hits.distances[k] - t) <= 1e-12
        assert abs(hits.arc_lengths[k] - s) <= 1e-12
        if margin > 1e-12:
            assert hits.segments[k] == i
    assert misses < len(origins)  # the test exercises hits, not only misses


def test_lines_from_ellipse_centre_match_analytic_hits():
    """Rays from inside an ellipse: distance equals the analytic ray-ellipse hit to chord error."""
    a, b, n = 2.0, 1.0, 4000
    t = 2 * np.pi * np.arange(n) / n
    curve = np.column_stack([a * np.cos(t), b * np.sin(t)])
    origins = np.tile([0.3, -0.2], (50, 1))
    angles = np.linspace(0, 2 * np.pi, 50, endpoint=False) + 0.01
    directions = np.column_stack([np.cos(angles), np.sin(angles)])
    hits = mm.line_intersections(origins, directions, curve)
    # Solve |o + t u|_ellipse = 1 for t of either sign, keep the smaller |t|.
    ox, oy = origins[:, 0], origins[:, 1]
    ux, uy = directions[:, 0], directions[:, 1]
    qa = ux**2 / a**2 + uy**2 / b**2
    qb = 2 * (ox * ux / a**2 + oy * uy / b**2)
    qc = ox**2 / a**2 + oy**2 / b**2 - 1
    root = np.sqrt(qb**2 - 4 * qa * qc)
    roots = np.stack([(-qb + root) / (2 * qa), (-qb - root) / (2 * qa)])
    nearest = roots[np.argmin(np.abs(roots), axis=0), np.arange(50)]
    # Chord error: sagitta h^2 k / 8 with chords h <= a dt and curvature k <= a / b^2, divided by
    # the cosine between ray and normal (> 1/4 for rays from this inner point).
    sagitta = (a * 2 * np.pi / n) ** 2 * (a / b**2) / 8
    assert np.abs(hits.distances - nearest).max() <= 4 * sagitta
    assert np.abs(hits.distances - nearest).max() > 0  # the polyline is not the ellipse


def test_closest_points_on_circle_are_radial():
    curve = circle(20000, radius=3.0)
    queries = np.array([[0.5, 0.1], [10.0, -4.0], [-1.0, 2.0]])
    hits = mm.closest_points(queries, curve)
    radial = 3.0 * queries / np.hypot(queries[:, 0], queries[:, 1])[:, None]
    chord_error = 3.0 * (1 - np.cos(np.pi / 20000))
    assert np.abs(hits.points - radial).max() <= 2 * np.sqrt(2 * 3.0 * chord_error)
    assert np.abs(hits.distances - np.abs(np.hypot(queries[:, 0], queries[:, 1]) - 3.0)).max() <= chord_error


def test_collinear_line_along_an_edge():
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    hits = mm.line_intersections([[-1.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [1.0, 0.0]], square)
    assert hits.distances[0] == pytest.approx(1.0)  # enters the bottom edge at (0, 0)
    assert hits.points[1].tolist() == [1.0, 0.0] and hits.distances[1] == 0.0  # origin on the edge


def test_repeated_points_and_closing_duplicate_are_allowed():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    index = mm.CurveIndex(square)
    assert len(index) == 5  # the closing duplicate is dropped, the inner repeat kept
    hits = index.closest_points([[0.5, -1.0], [2.0, 0.5]])
    assert hits.segments.tolist() == [0, 2]
    assert hits.arc_lengths.tolist() == [0.5, 1.5]


def test_index_is_reusable_and_threads_agree(rng, wobbly):
    index = mm.CurveIndex(wobbly)
    queries = rng.uniform(-2, 2, size=(20000, 2))
    first = index.closest_points(queries)
    again = index.closest_points(queries[::-1])
    assert np.array_equal(first.points, again.points[::-1])


def test_lines_through_vertices_do_not_slip_between_segments():
    inner, outer = circle(400, 1.0), circle(400, 2.0)
    hits = mm.line_intersections(inner, inner, outer)  # radial lines through the vertices of outer
    assert np.abs(hits.distances - 1.0).max() < 1e-12
    assert np.abs(hits.points - outer).max() < 1e-12
