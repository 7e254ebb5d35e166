"""Arc length, area, orientation, normals and self-intersection of one curve."""

from fractions import Fraction

import numpy as np
import pytest

import morphomap as mm

SQUARE = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)


def circle(n, radius=1.0, clockwise=False):
    t = 2 * np.pi * np.arange(n) / n
    p = radius * np.column_stack([np.cos(t), np.sin(t)])
    return p[::-1].copy() if clockwise else p


def test_lengths_and_area():
    np.testing.assert_array_equal(mm.arc_lengths(SQUARE), [0, 1, 2, 3])
    assert mm.perimeter(SQUARE) == 4 and mm.perimeter(SQUARE, closed=False) == 3
    assert mm.signed_area(SQUARE) == 1 and mm.signed_area(SQUARE[::-1]) == -1
    assert mm.orientation(SQUARE) == 1 and mm.orientation(SQUARE[::-1]) == -1
    c = circle(1000, 2.0)
    assert mm.perimeter(c) == pytest.approx(4 * np.pi, rel=1e-5)
    assert mm.signed_area(c) == pytest.approx(4 * np.pi, rel=1e-5)
    s = mm.arc_lengths(c)
    assert s.shape == (1000,) and np.all(np.diff(s) > 0)
    assert s[-1] + np.linalg.norm(c[0] - c[-1]) == pytest.approx(mm.perimeter(c))


def test_exact_orientation():
    # The shoelace sum in doubles is lost this far from the origin; the sign is exact.
    far = 1e16
    tri = np.array([[far, far], [far + 2, far], [far, far + 2]])
    assert mm.orientation(tri) == 1 and mm.orientation(tri[::-1]) == -1
    with pytest.raises(ValueError, match="^points"):
        mm.orientation(np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float))  # figure eight


@pytest.mark.parametrize("clockwise", [False, True])
def test_normals_circle(clockwise):
    c = circle(100, clockwise=clockwise)
    n = mm.normals(c)
    assert n.shape == c.shape
    np.testing.assert_allclose(n, c, atol=1e-14)  # symmetric vertices: exactly radial
    rng = np.random.default_rng(1)
    t = 2 * np.pi * (np.arange(100) + rng.uniform(-0.01, 0.01, 100)) / 100
    p = np.column_stack([np.cos(t), np.sin(t)])
    if clockwise:
        p = p[::-1]
    n = mm.normals(p)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1, atol=1e-15)
    assert np.abs(n - p).max() < 1e-3


def test_normals_open_and_repeats():
    h = np.sqrt(0.5)
    np.testing.assert_allclose(mm.normals(SQUARE[::-1]), [[-h, h], [h, h], [h, -h], [-h, -h]], atol=1e-15)
    line = np.array([[0, 0], [1, 0], [1, 0], [2, 0]], float)
    np.testing.assert_array_equal(mm.normals(line, closed=False), [[0, -1]] * 4)
    closing = np.vstack([SQUARE, SQUARE[:1]])
    n = mm.normals(closing)
    assert n.shape == (5, 2)
    np.testing.assert_array_equal(n[4], n[0])


def _orient(a, b, c):
    v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    return (v > 0) - (v < 0)


def _brute_self_intersecting(points, closed):
    """O(n²) exact reference: non-adjacent segments meet, or adjacent ones fold back."""
    q = []
    for p in points:
        p = (Fraction(p[0]), Fraction(p[1]))
        if not q or p != q[-1]:
            q.append(p)
    while closed and len(q) > 1 and q[-1] == q[0]:
        q.pop()
    m = len(q)
    segs = m if closed else m - 1

    def on(a, b, c):
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    for i in range(segs):
        for j in range(i + 1, segs):
            a, b, c, d = q[i], q[(i + 1) % m], q[j], q[(j + 1) % m]
            if j == i + 1 or (closed and i == 0 and j == segs - 1):
                x, u, w = (b, a, d) if j == i + 1 else (a, b, c)
                dot = (u[0] - x[0]) * (w[0] - x[0]) + (u[1] - x[1]) * (w[1] - x[1])
                if _orient(u, x, w) == 0 and dot > 0:
                    return True
                continue
            o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
            if (o1 * o2 < 0 and o3 * o4 < 0) or (o1 == 0 and on(a, b, c)) or (o2 == 0 and on(a, b, d)):
                return True
            if (o3 == 0 and on(c, d, a)) or (o4 == 0 and on(c, d, b)):
                return True
    return False


@pytest.mark.parametrize("seed", range(40))
def test_self_intersection_against_brute_force(seed):
    rng = np.random.default_rng(seed)
    p = rng.integers(0, int(rng.integers(3, 8)), (int(rng.integers(3, 9)), 2)).astype(float)
    for closed in (True, False):
        try:
            got = mm.is_self_intersecting(p, closed=closed)
        except ValueError:
            continue
        assert got == _brute_self_intersecting(p, closed)


def test_self_intersection():
    assert not mm.is_self_intersecting(circle(10000))
    assert mm.is_self_intersecting(np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float))
    assert mm.is_self_intersecting(np.array([[0, 0], [2, 0], [1, 0]], float), closed=False)
    assert not mm.is_self_intersecting(np.array([[0, 0], [1, 0], [2, 0]], float), closed=False)


def test_errors():
    with pytest.raises(ValueError, match="^points"):
        mm.arc_lengths([[0, 0], [1, 1]])
    with pytest.raises(ValueError, match="^points"):
        mm.normals([[0, 0], [np.nan, 1], [1, 0]])
    with pytest.raises(ValueError, match="^points"):
        mm.perimeter([[1, 1], [1, 1], [1, 1]])
