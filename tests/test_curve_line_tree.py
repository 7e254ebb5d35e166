"""CurveIndex.line_intersections through its float32 line tree equals an exhaustive double scan.

The reference repeats the per-segment test of cpp/src/curves/curve_index.cpp (`visit`: the crossing test
with its 1e-12 slack at segment ends, segments lying on the line, ties to the positive side and
then the lower segment) over every segment, so the answers must be identical, not just close:
any box the float tree culls wrongly shows up as a different hit.
"""

import numpy as np
import pytest

import morphomap as mm


def exhaustive(origins, directions, curve, closed=True):
    a = curve if closed else curve[:-1]
    b = np.roll(curve, -1, axis=0) if closed else curve[1:]
    ax, ay = a[:, 0], a[:, 1]
    ex, ey = b[:, 0] - ax, b[:, 1] - ay
    distances = np.full(len(origins), np.nan)
    segments = np.full(len(origins), -1)
    points = np.full((len(origins), 2), np.nan)
    for k, ((ox, oy), (dx, dy)) in enumerate(zip(origins, directions)):
        norm = np.sqrt(dx * dx + dy * dy)
        ux, uy = dx / norm, dy / norm
        wx, wy = ax - ox, ay - oy
        denom = ux * ey - uy * ex
        along = wx * uy - wy * ux
        slack = 1e-12 * np.abs(denom)
        with np.errstate(all="ignore"):
            rejected = np.where(denom > 0, (along < -slack) | (along > denom + slack),
                                (along > slack) | (along < denom - slack))
            s = np.clip(along / denom, 0, 1)
            t = (wx * ey - wy * ex) / denom
            # Segments on the line: the point of [t0, t1] nearest the origin.
            on_line = (denom == 0) & (ux * wy - uy * wx == 0)
            t0 = ux * wx + uy * wy
            t1 = t0 + ux * ex + uy * ey
            t_on = np.where(np.minimum(t0, t1) > 0, np.minimum(t0, t1),
                            np.where(np.maximum(t0, t1) < 0, np.maximum(t0, t1), 0.0))
            s_on = np.where(t1 != t0, (t_on - t0) / (t1 - t0), 0.0)
        t = np.where(on_line, t_on, t)
        s = np.where(on_line, s_on, s)
        hit = np.flatnonzero(((denom != 0) & ~rejected) | on_line)
        if len(hit) == 0:
            continue
        i = hit[np.lexsort((hit, t[hit] < 0, np.abs(t[hit])))[0]]
        distances[k], segments[k] = t[i], i
        points[k] = ax[i] + s[i] * ex[i], ay[i] + s[i] * ey[i]
    return distances, segments, points


def assert_same(curve, origins, directions, closed=True):
    hits = mm.CurveIndex(curve, closed=closed).line_intersections(origins, directions)
    distances, segments, points = exhaustive(origins, directions, curve, closed)
    assert np.isfinite(distances).any()  # the case exercises hits
    np.testing.assert_array_equal(hits.segments, segments)
    np.testing.assert_array_equal(hits.distances, distances)
    np.testing.assert_array_equal(hits.points, points)


def wobbly(n):
    s = 2 * np.pi * np.arange(n) / n
    r = 1.0 + 0.3 * np.sin(5 * s) + 0.1 * np.cos(11 * s)
    return np.column_stack([r * np.cos(s), r * np.sin(s)])


def random_lines(rng, q, lo=-1.6, hi=1.6):
    angles = rng.uniform(0, 2 * np.pi, q)
    return rng.uniform(lo, hi, (q, 2)), np.column_stack([np.cos(angles), np.sin(angles)])


@pytest.mark.parametrize("n", [3, 17, 1000])
@pytest.mark.parametrize("closed", [True, False])
def test_random_lines_and_lines_through_vertices(rng, n, closed):
    curve = wobbly(n)
    origins, directions = random_lines(rng, 500)
    assert_same(curve, origins, directions, closed)
    vertices = curve[rng.integers(0, n, 500)]
    assert_same(curve, origins, vertices - origins, closed)  # aimed at a vertex
    assert_same(curve, vertices, directions, closed)  # from a vertex
    assert_same(curve, vertices + [0.3, 0.0], np.tile([1.0, 0.0], (500, 1)), closed)  # axis-parallel
    assert_same(curve, vertices - [0.0, 0.2], np.tile([0.0, 1.0], (500, 1)), closed)


@pytest.mark.parametrize("far", [1e8, 1e20, 1e300])
def test_origins_far_along_the_line(rng, far):
    origins, directions = random_lines(rng, 500)
    assert_same(wobbly(1000), origins - far * directions, directions)


@pytest.mark.parametrize("shift, size", [(1e12, 1.0), (1e6, 1e-3), (0.0, 1e-100), (0.0, 1e100), (-3e15, 7.0)])
def test_shifted_and_scaled_curves(rng, shift, size):
    curve = wobbly(1000)
    origins, directions = random_lines(rng, 500)
    assert_same(shift + size * curve, shift + size * origins, directions)
    assert_same(shift + size * curve, shift + size * curve[rng.integers(0, 1000, 500)], directions)


def test_collinear_points_and_lines_along_edges(rng):
    side = np.linspace(0, 1, 50, endpoint=False)
    square = np.concatenate([np.column_stack([side, 0 * side]), np.column_stack([1 + 0 * side, side]),
                             np.column_stack([1 - side, 1 + 0 * side]), np.column_stack([0 * side, 1 - side])])
    origins, directions = random_lines(rng, 600, -0.5, 1.5)
    origins[:200, 1] = 0.0
    directions[:200] = [1.0, 0.0]  # along the bottom edge
    origins[200:400, 0] = 1.0
    directions[200:400] = [0.0, 1.0]  # along the right edge
    assert_same(square, origins, directions)
    assert_same(square, origins, np.tile([1.0, 1.0], (600, 1)))  # diagonals through the corners
    straight = np.column_stack([np.linspace(0, 1, 100), np.linspace(0, 2, 100)])  # flat boxes
    assert_same(straight, origins, directions, closed=False)
    assert_same(straight, straight[rng.integers(0, 100, 600)], np.tile([1.0, 2.0], (600, 1)), closed=False)
    assert_same(np.repeat(wobbly(40), 3, axis=0), origins, directions)


def test_answers_do_not_depend_on_the_batch(rng):
    index = mm.CurveIndex(wobbly(3000))
    origins, directions = random_lines(rng, 5000)
    whole = index.line_intersections(origins, directions)
    backwards = index.line_intersections(origins[::-1], directions[::-1])
    one = [index.line_intersections(origins[k:k + 1], directions[k:k + 1]).distances[0] for k in range(0, 5000, 97)]
    np.testing.assert_array_equal(whole.distances, backwards.distances[::-1])
    np.testing.assert_array_equal(whole.segments, backwards.segments[::-1])
    np.testing.assert_array_equal(whole.distances[::97], one)
