"""Crossings among segments against an exact O(n²) brute force."""

from fractions import Fraction

import numpy as np
import pytest

import morphomap as mm


def _sign(x):
    return (x > 0) - (x < 0)


def _orient(a, b, c):
    return _sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def _on(a, b, c):
    """c, collinear with a and b, lies on the closed segment ab."""
    return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])


def _meet(a, b, c, d):
    o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return True
    return (o1 == 0 and _on(a, b, c)) or (o2 == 0 and _on(a, b, d)) or (o3 == 0 and _on(c, d, a)) or (
        o4 == 0 and _on(c, d, b)
    )


def _cross(s, t):
    """Common point other than an end point shared by both (exact)."""
    a, b = s
    c, d = t
    if not _meet(a, b, c, d):
        return False
    for x, u in ((a, b), (b, a)):
        for y, w in ((c, d), (d, c)):
            if x == y:
                # Only x in common unless both run on from x along one line in the same direction.
                dot = (u[0] - x[0]) * (w[0] - x[0]) + (u[1] - x[1]) * (w[1] - x[1])
                return _orient(x, u, w) == 0 and dot > 0
    return True


def brute_force(starts, ends):
    segs = {}
    for i, (s, e) in enumerate(zip(starts, ends)):
        if np.isfinite(s).all() and np.isfinite(e).all():
            segs[i] = ((Fraction(s[0]), Fraction(s[1])), (Fraction(e[0]), Fraction(e[1])))
    keys = sorted(segs)
    return [(i, j) for k, i in enumerate(keys) for j in keys[k + 1 :] if _cross(segs[i], segs[j])]


def check(starts, ends):
    expected = brute_force(starts, ends)
    pairs = mm.crossing_pairs(starts, ends)
    assert pairs.dtype == np.int64 and pairs.shape == (len(expected), 2)
    assert [tuple(p) for p in pairs.tolist()] == expected
    assert mm.count_crossings(starts, ends) == len(expected)
    return len(expected)


@pytest.mark.parametrize("seed", range(10))
def test_random_segments(seed):
    rng = np.random.default_rng(seed)
    n = 150
    starts = rng.uniform(0, 1, (n, 2))
    ends = starts + rng.normal(0, 0.15, (n, 2))
    assert check(starts, ends) > 0


@pytest.mark.parametrize("seed", range(30))
def test_random_grid_segments(seed):
    # Integer grid coordinates force shared ends, T-junctions, collinear overlaps and points.
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 120))
    size = int(rng.integers(2, 8))
    starts = rng.integers(0, size, (n, 2)).astype(float)
    ends = rng.integers(0, size, (n, 2)).astype(float)
    # Some segments share their start with an earlier one, some are points, some rows are NaN.
    share = rng.random(n) < 0.2
    starts[share] = starts[rng.integers(0, n, share.sum())]
    point = rng.random(n) < 0.1
    ends[point] = starts[point]
    missing = rng.random(n) < 0.05
    ends[missing, rng.integers(0, 2)] = np.nan
    check(starts, ends)


def test_fans_and_junctions():
    # A fan of vectors from one point: no crossings; a T-junction: one.
    t = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    ends = np.column_stack([np.cos(t), np.sin(t)])
    assert check(np.zeros((50, 2)), ends) == 0
    assert check(ends, np.zeros((50, 2))) == 0
    assert check(np.array([[0.0, 0], [1, 0]]), np.array([[2.0, 0], [1, 1]])) == 1


def test_displacement_field():
    # Radial vectors from a circle to a bigger one do not cross; reversing the order of the ends
    # makes almost every pair cross.
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    starts = np.column_stack([np.cos(t), np.sin(t)])
    assert mm.count_crossings(starts, 2 * starts) == 0
    assert mm.count_crossings(starts, 2 * starts[::-1]) > 0
    assert mm.crossing_pairs(starts, 2 * starts).shape == (0, 2)


def test_errors():
    with pytest.raises(ValueError, match="^ends"):
        mm.crossing_pairs(np.zeros((3, 2)), np.zeros((2, 2)))
    with pytest.raises(ValueError, match="^starts"):
        mm.count_crossings(np.zeros((3, 3)), np.zeros((3, 2)))
