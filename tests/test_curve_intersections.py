"""Curve-curve intersections against an exact brute force of the same perturbation rule."""

from fractions import Fraction
import math

import numpy as np
import pytest

import morphomap as mm


def _sign(x):
    return (x > 0) - (x < 0)


def _cross(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _shifted_point(a, b, c):
    """Sign of orient(a, b, c + εv), v = (1, δ): c shifted right, then infinitesimally up."""
    o = _sign(_cross(a, b, c))
    if o:
        return o
    return -_sign(b[1] - a[1]) if b[1] != a[1] else _sign(b[0] - a[0])


def _shifted_segment(a, b, c):
    """Sign of orient(a + εv, b + εv, c)."""
    o = _sign(_cross(a, b, c))
    if o:
        return o
    return _sign(b[1] - a[1]) if b[1] != a[1] else -_sign(b[0] - a[0])


def _distinct(points, closed):
    """Exact consecutive repeats dropped (and a closing repeat), as exact Fractions."""
    out = []
    for p in points:
        p = (Fraction(p[0]), Fraction(p[1]))
        if not out or p != out[-1]:
            out.append(p)
    while closed and len(out) > 1 and out[-1] == out[0]:
        out.pop()
    return out


def brute_force(c1, c2, closed):
    """All crossings in O(n·m), exact: [(point, position on c1, position on c2)] in order along c1.

    A position is (segment, t) with t exact, moved to (next segment, 0) at t = 1, which orders
    crossings as arc length does.
    """
    a, b = _distinct(c1, closed), _distinct(c2, closed)
    na = len(a) if closed else len(a) - 1
    nb = len(b) if closed else len(b) - 1

    def position(k, t, n, count):
        if t == 1 and (closed or k + 1 < count):
            return ((k + 1) % count, Fraction(0))
        return (k, t)

    found = []
    for i in range(na):
        p1, p2 = a[i], a[(i + 1) % len(a)]
        for j in range(nb):
            q1, q2 = b[j], b[(j + 1) % len(b)]
            if _shifted_point(p1, p2, q1) == _shifted_point(p1, p2, q2):
                continue
            if _shifted_segment(q1, q2, p1) == _shifted_segment(q1, q2, p2):
                continue
            o1, o2 = _cross(q1, q2, p1), _cross(q1, q2, p2)
            t1 = o1 / (o1 - o2)
            r1, r2 = _cross(p1, p2, q1), _cross(p1, p2, q2)
            t2 = r1 / (r1 - r2)
            point = (p1[0] + t1 * (p2[0] - p1[0]), p1[1] + t1 * (p2[1] - p1[1]))
            found.append((point, position(i, t1, na, na), position(j, t2, nb, nb)))
    found.sort(key=lambda x: (x[1], x[2]))
    # Drop pairs at one point that are neighbours along both curves, until none is left.
    changed = True
    while changed and len(found) >= 2:
        changed = False
        k = len(found)
        by2 = sorted(range(k), key=lambda r: (found[r][2], found[r][1]))
        rank2 = {r: n for n, r in enumerate(by2)}

        def neighbours2(u, w):
            lo, hi = sorted((rank2[u], rank2[w]))
            return hi == lo + 1 or (closed and lo == 0 and hi == k - 1)

        drop = [False] * k
        for r in range(k if closed and k > 2 else k - 1):
            r2 = (r + 1) % k
            if drop[r] or drop[r2] or found[r][0] != found[r2][0] or not neighbours2(r, r2):
                continue
            drop[r] = drop[r2] = True
            changed = True
        found = [x for x, d in zip(found, drop) if not d]
    return found


def _arc(points, closed, position):
    """Arc length (float) at a position (segment, t) of the curve without repeats."""
    pts = [(float(p[0]), float(p[1])) for p in _distinct(points, closed)]
    k, t = position
    s = sum(math.dist(pts[i], pts[(i + 1) % len(pts)]) for i in range(k))
    return s + float(t) * math.dist(pts[k], pts[(k + 1) % len(pts)])


def check_against_brute_force(c1, c2, closed):
    expected = brute_force(c1, c2, closed)
    points, s1, s2 = mm.curve_intersections(c1, c2, closed=closed, return_arc_lengths=True)
    assert points.shape == (len(expected), 2)
    if closed:
        assert len(expected) % 2 == 0
    scale = 1 + np.abs(np.concatenate([c1, c2])).max()
    for row, (point, pos1, pos2) in zip(points, expected):
        assert np.allclose(row, [float(point[0]), float(point[1])], rtol=0, atol=1e-12 * scale)
    assert np.allclose(s1, [_arc(c1, closed, e[1]) for e in expected], rtol=0, atol=1e-9 * scale)
    assert np.allclose(s2, [_arc(c2, closed, e[2]) for e in expected], rtol=0, atol=1e-9 * scale)
    return len(expected)


def _random_star(rng, n, centre, radius):
    t = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = radius * rng.uniform(0.5, 1.5, n)
    return np.column_stack([centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)])


@pytest.mark.parametrize("seed", range(20))
def test_random_polygons(seed):
    rng = np.random.default_rng(seed)
    c1 = _random_star(rng, int(rng.integers(3, 40)), (0, 0), 1.0)
    c2 = _random_star(rng, int(rng.integers(3, 40)), rng.uniform(-1, 1, 2), rng.uniform(0.3, 1.5))
    check_against_brute_force(c1, c2, True)
    check_against_brute_force(c1, c2, False)


@pytest.mark.parametrize("seed", range(60))
def test_random_grid_polygons(seed):
    # Small integer grids force vertices on edges, shared vertices and collinear overlaps; the
    # curves need not be simple.
    rng = np.random.default_rng(1000 + seed)
    size = int(rng.integers(2, 5))
    c1 = rng.integers(0, size, (int(rng.integers(3, 12)), 2)).astype(float)
    c2 = rng.integers(0, size, (int(rng.integers(3, 12)), 2)).astype(float)
    for closed in (True, False):
        needed = 3 if closed else 2
        if min(len(_distinct(c1, closed)), len(_distinct(c2, closed))) < needed:
            with pytest.raises(ValueError):
                mm.curve_intersections(c1, c2, closed=closed)
        else:
            check_against_brute_force(c1, c2, closed)


def test_grid_squares_and_halves():
    # Coordinates in halves: crossings at non-vertex points that also meet other segments there.
    rng = np.random.default_rng(7)
    total = 0
    for _ in range(40):
        c1 = rng.integers(0, 5, (8, 2)) / 2.0
        c2 = rng.integers(0, 5, (8, 2)) / 2.0
        if len({tuple(p) for p in c1}) >= 3 and len({tuple(p) for p in c2}) >= 3:
            total += check_against_brute_force(c1, c2, True)
    assert total > 0


def _ellipse(a, b, n, t0=0.0, extra=()):
    t = np.sort(np.concatenate([t0 + 2 * np.pi * np.arange(n) / n, np.asarray(extra, float)]))
    return np.column_stack([a * np.cos(t), b * np.sin(t)])


def test_ellipses():
    c = 2 / np.sqrt(5)
    expected = np.array([[c, c], [-c, c], [-c, -c], [c, -c]])
    signs = [(1, 1), (-1, 1), (-1, -1), (1, -1)]
    t1 = [math.atan2(2 * sy, sx) % (2 * np.pi) for sx, sy in signs]
    t2 = [math.atan2(sy, 2 * sx) % (2 * np.pi) for sx, sy in signs]
    # Vertices on the crossings: exact to rounding.
    points = mm.curve_intersections(_ellipse(2, 1, 20000, extra=t1), _ellipse(1, 2, 20000, extra=t2))
    assert np.abs(points - expected).max() < 1e-9
    # Generic vertices: limited by the chord sagitta (see test_curve_intersections.cpp).
    points, s1, s2 = mm.curve_intersections(
        _ellipse(2, 1, 20000, 0.123), _ellipse(1, 2, 20000, 0.456), return_arc_lengths=True
    )
    assert np.abs(points - expected).max() < 4.5e-7
    assert np.all(np.diff(s1) > 0) and s2.shape == (4,)


def test_touching_and_overlaps():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    # A vertex touching from inside and outside: no crossing either way round.
    for c2 in ([[1, 0.5], [0.5, 0.8], [0.5, 0.2]], [[1, 0.5], [2, 0], [2, 1]]):
        assert len(mm.curve_intersections(square, np.array(c2, float))) == 0
        assert len(mm.curve_intersections(np.array(c2, float), square)) == 0
    # Shared stretches: a defined, even answer (see the C++ header for the rule).
    def rect(x0, y0, x1, y1):
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)

    assert len(mm.curve_intersections(square, rect(1, 0.25, 2, 0.75))) == 0
    assert len(mm.curve_intersections(square, rect(0, 0.25, 0.5, 0.75))) == 0
    np.testing.assert_array_equal(mm.curve_intersections(square, rect(-1, 0.25, 0, 0.75)), [[0, 0.75], [0, 0.25]])
    np.testing.assert_array_equal(mm.curve_intersections(square, square), [[1, 0], [0, 1]])


def test_shapes_and_errors():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    far = square + 10
    points = mm.curve_intersections(square, far)
    assert points.shape == (0, 2)
    points, s1, s2 = mm.curve_intersections(square, far, return_arc_lengths=True)
    assert s1.shape == (0,) and s2.shape == (0,)
    with pytest.raises(ValueError, match="^c1"):
        mm.curve_intersections([[0, 0], [1, 1]], square)
    with pytest.raises(ValueError, match="^c2"):
        mm.curve_intersections(square, [[0, 0], [np.nan, 1], [1, 0]])
